// >>cloud ================================================================================
// Reading the cloud: invalid points refused or counted, outliers left out, sums.

namespace stratmesh {
namespace detail {

// What one pass over the cloud learns, for reject_invalid_points and choose_frame: how many
// points are valid, how many distinct positions they take (counted up to 3), and their sums
// and extremes. Coordinates near the top of the double range overflow the sum: then the
// sum of the points scaled down by 2^-40 (exactly), which leaves room for 2^32 points, is
// used.
struct CloudSums {
    size_t valid;
    uint32_t distinct;
    double total[3], small_total[3], lowest[3], highest[3];
};

// Counts the distinct positions among points given one by one, up to 3 (two are kept: the
// third ends the count).
struct DistinctPoints {
    uint32_t count;
    Vec3 seen[2];
    void add(Vec3 p) {
        if (count >= 3) return;
        for (uint32_t k = 0; k < count; ++k)
            if (p.x == seen[k].x && p.y == seen[k].y && p.z == seen[k].z) return;
        if (count < 2) seen[count] = p;
        ++count;
    }
};

static inline CloudSums sum_cloud(const CloudReader& cloud, size_t count) {
    CloudSums s = {0, 0, {0, 0, 0}, {0, 0, 0}, {DBL_MAX, DBL_MAX, DBL_MAX},
                   {-DBL_MAX, -DBL_MAX, -DBL_MAX}};
    DistinctPoints distinct = {0, {}};
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        const Vec3 p = cloud.point(i);
        distinct.add(p);
        const double c[3] = {p.x, p.y, p.z};
        for (int k = 0; k < 3; ++k) {
            s.total[k] += c[k];
            s.small_total[k] += c[k] * 0x1p-40;
            if (c[k] < s.lowest[k]) s.lowest[k] = c[k];
            if (c[k] > s.highest[k]) s.highest[k] = c[k];
        }
        ++s.valid;
    }
    s.distinct = distinct.count;
    return s;
}

// The bytes the cloud's coordinates lie in.
static inline ByteRange cloud_bytes(const Cloud& cloud) {
    const size_t point_bytes = 3 * (cloud.scalar == Scalar::float32 ? sizeof(float) : sizeof(double));
    return strided_range(cloud.xyz, cloud.count, cloud.stride_bytes ? cloud.stride_bytes : point_bytes,
                         point_bytes);
}

// True if any two of the caller's buffers share a byte (the report and its layer array
// included): checked before anything is written. A count beyond the limit is refused as
// too_many_points instead.
static inline bool reconstruct_buffers_overlap(const Cloud& cloud, void* workspace,
                                        size_t workspace_bytes, uint32_t* triangles,
                                        size_t triangle_capacity, size_t* triangle_count,
                                        const Report* report) {
    if (cloud.count > kMaxPoints - 1) return false;
    const ByteRange buffers[] = {
        cloud_bytes(cloud),
        byte_range(workspace, workspace_bytes),
        byte_range(triangles, saturating_product(triangle_capacity, 3 * sizeof(uint32_t))),
        byte_range(triangle_count, sizeof(size_t)),
        byte_range(report, sizeof(Report)),
        byte_range(report ? report->layers.info : nullptr,
                   report ? saturating_product(report->layers.info_capacity, sizeof(LayerInfo)) : 0),
        byte_range(kFindParts && report ? report->parts.info : nullptr,
                   kFindParts && report ? saturating_product(report->parts.info_capacity, sizeof(PartInfo)) : 0)};
    return any_overlap(buffers, 7);
}

static inline Status check_reconstruct_arguments(const Cloud& cloud, uint32_t* triangles,
                                          size_t triangle_capacity, size_t* triangle_count,
                                          void* workspace, Report& rep) {
    rep.detail = "an argument is invalid: a null pointer with a non-zero count, a stride "
                 "smaller than one point, an unknown scalar type or a null triangle_count";
    if (!triangle_count) return Status::invalid_argument;
    if (cloud.count > kMaxPoints - 1) {
        rep.detail = "more points than 32-bit triangle indices can address";
        return Status::too_many_points;
    }
    size_t scalar = cloud.scalar == Scalar::float32 ? sizeof(float)
                  : cloud.scalar == Scalar::float64 ? sizeof(double) : 0;
    if (scalar == 0) return Status::invalid_argument;
    if (cloud.stride_bytes != 0 && cloud.stride_bytes < 3 * scalar)
        return Status::invalid_argument;
    if (cloud.count > 0 && (!cloud.xyz || !workspace)) return Status::invalid_argument;
    if (triangle_capacity > 0 && !triangles) return Status::invalid_argument;
    rep.detail = nullptr;
    return Status::ok;
}

// Reads a cloud that passed check_reconstruct_arguments.
static inline CloudReader reader_of(const Cloud& cloud) {
    size_t scalar = cloud.scalar == Scalar::float32 ? sizeof(float) : sizeof(double);
    return {static_cast<const unsigned char*>(cloud.xyz),
            cloud.stride_bytes ? cloud.stride_bytes : 3 * scalar, cloud.scalar == Scalar::float32, nullptr};
}

const char* const kInvalidPointDetail =
    "a point has a NaN or infinite coordinate (see first_invalid_index; the "
    "skip_invalid_points flag skips such points instead)";

// Where a cloud of `count` points (`sums` is its sum_cloud) is refused with invalid_point:
// at its first point with a NaN or infinite coordinate, unless the skip_invalid_points flag
// is given. `count` if it is not refused.
static inline size_t refused_at(const CloudReader& reader, size_t count, const CloudSums& sums,
                         const Options& options) {
    if (sums.valid == count || (options.flags & skip_invalid_points)) return count;
    size_t first = 0;
    while (reader.valid(first)) ++first;
    return first;
}

// Counts the points with a NaN or infinite coordinate in rep.points.rejected_count, or refuses the
// cloud (see refused_at).
static inline Status reject_invalid_points(const CloudReader& reader, size_t count,
                                    const CloudSums& sums, const Options& options, Report& rep) {
    const size_t first = refused_at(reader, count, sums, options);
    if (first < count) {
        rep.points.first_invalid_index = first;
        rep.points.rejected_count = count;
        rep.detail = kInvalidPointDetail;
        return Status::invalid_point;
    }
    rep.points.rejected_count += count - sums.valid;
    return Status::ok;
}

// A cloud as a tube reads it: in place, the points left out (outliers, or the points of
// other parts) marked in the reader's optional bitmap, and the sums of the points kept.
struct TubeInput {
    CloudReader reader;
    size_t count;
    CloudSums sums;
};

// Whether this build holds every feature the flags ask for (STRATMESH_SMALL_CODE leaves
// some out).
static inline bool flags_compiled(const Options& options) {
    const uint32_t f = options.flags;
    return (kDropOutliers || !(f & drop_outliers)) && (kSurfaceFlips || !(f & surface_flips)) &&
           (kClosedEnds || !(f & ends_are_cuts));
}

const char* const kNotCompiledDetail =
    "the options ask for a feature this build leaves out (STRATMESH_SMALL_CODE)";

}  // namespace detail
}  // namespace stratmesh
