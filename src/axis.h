// >>axis =================================================================================
// The automatic axis.
//
// The automatic axis. The method needs the direction along which the cloud's sections are
// loops around one centre line, and the direction of largest variance is often another: a
// head is longest from front to back, a squat bone across. The candidates are the three
// principal directions of the cloud (from a sample of kAxisShapeSample points) and then x,
// y and z (skipping any within about ten degrees of one before it). A smaller sample is
// meshed as one tube along the first: where the surface runs along it (its triangles'
// normals lie across it, as on a tube or a limb), it is the axis. Otherwise each candidate
// meshes the sample and the one whose surface is smallest wins: where the layers cannot
// follow the surface they fold and bridge gaps with webs, and both add area. The samples
// are every k-th kept point in input order, so the choice is deterministic.

namespace stratmesh {
namespace detail {

// Points meshed per candidate: enough to see an object's limbs and ends, few enough that
// six candidates cost a small part of a large run.
const size_t kAxisSample = 512;

// Points the principal directions are measured on: enough for a tube's axis within a
// fraction of a degree.
const size_t kAxisShapeSample = 16384;

// The share of the sample surface's normals along the first candidate (the mean squared
// cosine, weighted by area) below which the surface runs along it: about 0.04 on a tube,
// 0.16 to 0.5 on heads, bones and hands.
const double kAlongSurface = 0.1;

// A candidate whose direction is within about 10 degrees of an earlier one is not tried.
const double kSameAxisCosine = 0.985;

const uint32_t kMostAxisCandidates = 6;

// The three principal directions of a symmetric 3x3 matrix, largest variance first: power
// iteration, then again on the matrix without the first direction's share.
static inline void principal_directions(const double m[3][3], Vec3 out[3]) {
    out[0] = principal_direction(m);
    const Vec3 v = out[0];
    const double mv[3] = {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
                          m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    const double lambda = mv[0] * v.x + mv[1] * v.y + mv[2] * v.z;
    const double c[3] = {v.x, v.y, v.z};
    double rest[3][3];
    for (int r = 0; r < 3; ++r)
        for (int s = 0; s < 3; ++s) rest[r][s] = m[r][s] - lambda * c[r] * c[s];
    Vec3 second = principal_direction(rest);
    second = second - scaled(v, dot(second, v));
    if (!normalize(second)) {
        // Any direction across the first.
        second = abs_value(v.x) < 0.5 ? cross(v, Vec3{1, 0, 0}) : cross(v, Vec3{0, 1, 0});
        normalize(second);
    }
    out[1] = second;
    out[2] = cross(v, second);
}

// The scatter matrix of `count` points, packed, about their mean.
static inline void scatter_of(const double* xyz, size_t count, double m[3][3]) {
    // Scaled by the power of two that brings the largest coordinate near 1 (exactly, so
    // directions and ratios keep their bits): squares of coordinates near either end of the
    // double range would overflow or vanish. A multiplication where the factor is a normal
    // double, ldexp (a call) only where it is not.
    double largest = 0;
    for (size_t i = 0; i < 3 * count; ++i)
        largest = abs_value(xyz[i]) > largest ? abs_value(xyz[i]) : largest;
    int exponent = 0;
    std::frexp(largest, &exponent);
    const double factor = exponent > -1000 && exponent < 1000 ? std::ldexp(1.0, -exponent) : 0;
    auto unit = [&](double v) { return factor != 0 ? v * factor : std::ldexp(v, -exponent); };
    Vec3 mean = {0, 0, 0};
    for (size_t i = 0; i < count; ++i)
        mean = Vec3{mean.x + unit(xyz[3 * i]), mean.y + unit(xyz[3 * i + 1]),
                    mean.z + unit(xyz[3 * i + 2])};
    mean = scaled(mean, 1.0 / static_cast<double>(count));
    for (int r = 0; r < 3; ++r)
        for (int s = 0; s < 3; ++s) m[r][s] = 0;
    for (size_t i = 0; i < count; ++i) {
        const double d[3] = {unit(xyz[3 * i]) - mean.x, unit(xyz[3 * i + 1]) - mean.y,
                             unit(xyz[3 * i + 2]) - mean.z};
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s) m[r][s] += d[r] * d[s];
    }
}

// The variance of the scatter matrix along the unit direction v.
static inline double variance_along(const double m[3][3], Vec3 v) {
    const double c[3] = {v.x, v.y, v.z};
    double sum = 0;
    for (int r = 0; r < 3; ++r)
        for (int s = 0; s < 3; ++s) sum += c[r] * m[r][s] * c[s];
    return sum;
}

// A sample whose variance across its principal direction is this small a share of the
// variance along it (a width a millionth of its length) lies on a line up to rounding: no
// surface passes through it (Status::degenerate). Well above the rounding of the variances'
// difference.
const double kLineVariance = 0x1p-40;

// The candidates for the axis of a sample of `count` points, packed.
static inline uint32_t axis_candidates(const double* xyz, size_t count, Vec3* out) {
    double m[3][3];
    scatter_of(xyz, count, m);
    Vec3 all[6];
    principal_directions(m, all);
    all[3] = Vec3{1, 0, 0};
    all[4] = Vec3{0, 1, 0};
    all[5] = Vec3{0, 0, 1};
    uint32_t kept = 0;
    for (const Vec3& a : all) {
        bool repeat = false;
        for (uint32_t k = 0; k < kept; ++k) repeat = repeat || abs_value(dot(a, out[k])) > kSameAxisCosine;
        if (!repeat) out[kept++] = a;
    }
    return kept;
}

// What a candidate's sample surface measures: its area, plus the area of a triangle per
// sample point left out (a layer that cannot follow the surface drops points instead of
// folding). *along (optional) receives the mean squared cosine between the triangles'
// normals and the unit axis, weighted by their areas: 0 where the surface runs along the
// axis, 1 where it lies across it.
static inline double sample_surface(const double* xyz, const uint32_t* tri, size_t count,
                             size_t unused, Vec3 axis, double* along) {
    double area = 0, along_sum = 0, normals = 0;
    for (size_t t = 0; t < count; ++t) {
        const double* a = xyz + 3 * tri[3 * t];
        const double* b = xyz + 3 * tri[3 * t + 1];
        const double* c = xyz + 3 * tri[3 * t + 2];
        const Vec3 n = cross(Vec3{b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                             Vec3{c[0] - a[0], c[1] - a[1], c[2] - a[2]});
        const double length = std::sqrt(dot(n, n));
        area += length / 2;
        if (length == 0) continue;
        const double cosine = dot(n, axis) / length;
        along_sum += cosine * cosine * length;
        normals += length;
    }
    if (along) *along = normals > 0 ? along_sum / normals : 1;
    const double per_triangle = count > 0 ? area / static_cast<double>(count) : 0;
    return area + 2 * per_triangle * static_cast<double>(unused);
}

// What a candidate's sample is meshed as: one layer along `axis`, its ends cut where the
// tube's are, nothing else asked for and no callback.
static inline TubeRequest trial_request(const TubeRequest& tube, Vec3 axis) {
    TubeRequest trial = {};
    trial.axis = Axis::direction;
    trial.direction[0] = axis.x;
    trial.direction[1] = axis.y;
    trial.direction[2] = axis.z;
    trial.cut_ends = tube.cut_ends;
    trial.layers.count = 1;
    return trial;
}

// Meshes the sample along one candidate; DBL_MAX if it cannot.
// *along (optional) receives the share of the sample surface's normals along the axis.
static inline double try_axis(const double* sample, size_t count, Vec3 axis, const TubeRequest& request,
                       Arena& arena, double* along) {
    const TubeRequest trial = trial_request(request, axis);
    const size_t mark = arena.mark();
    uint32_t* tri = arena.alloc<uint32_t>(6 * count);
    if (arena.failed) return DBL_MAX;
    const Cloud cloud = {sample, count, 0, Scalar::float64};
    TubeInput in = {reader_of(cloud), count, {}};
    in.sums = sum_cloud(in.reader, count);
    Report rep = {};
    size_t triangles = 0;
    const Status status = mesh_tube(in, trial, arena, tri, 2 * count, &triangles, rep);
    arena.rewind(mark);
    if (status != Status::ok) return DBL_MAX;
    return sample_surface(sample, tri, triangles,
                          in.sums.valid - rep.points.used_count - rep.points.duplicate_count,
                          axis, along);
}

// Every k-th kept point of `in`, packed, at most `most` of them (and about that many), in
// `arena`; null if the workspace is too small. *taken receives their count. Where every
// point is kept, the sample is read by index, without a pass over the cloud.
static inline double* sample_points(const TubeInput& in, size_t most, Arena& arena, size_t* taken) {
    const size_t count = in.sums.valid < most ? in.sums.valid : most;
    double* sample = arena.alloc<double>(3 * count);
    *taken = 0;
    if (!sample || count == 0) return sample;
    // The k-th of `count` is kept point number k * valid / count (64 bits: no overflow).
    const uint64_t valid = in.sums.valid;
    auto put = [&](size_t i) {
        const Vec3 p = in.reader.point(i);
        sample[3 * *taken] = p.x;
        sample[3 * *taken + 1] = p.y;
        sample[3 * *taken + 2] = p.z;
        ++*taken;
    };
    if (in.sums.valid == in.count && !in.reader.dropped) {
        for (uint64_t k = 0; k < count; ++k) put(static_cast<size_t>(k * valid / count));
        return sample;
    }
    for (size_t i = 0, seen = 0; i < in.count && *taken < count; ++i) {
        if (!in.reader.valid(i)) continue;
        if (seen++ == *taken * valid / count) put(i);
    }
    return sample;
}

// The axis for Axis::automatic: the candidate whose sample surface is smallest (see above).
// False if the workspace is too small.
static inline bool choose_axis(const TubeInput& in, const TubeRequest& request, Arena& arena,
                        Vec3& axis) {
    const size_t mark = arena.mark();
    size_t taken = 0;
    const double* shape = sample_points(in, kAxisShapeSample, arena, &taken);
    if (!shape) return false;
    Vec3 candidates[kMostAxisCandidates];
    const uint32_t tries = axis_candidates(shape, taken, candidates);
    arena.rewind(mark);
    const double* sample = sample_points(in, kAxisSample, arena, &taken);
    if (!sample) return false;
    axis = candidates[0];
    double along = 1;
    double best = try_axis(sample, taken, candidates[0], request, arena, &along);
    for (uint32_t k = 1; k < tries && !(along < kAlongSurface); ++k) {
        const double score = try_axis(sample, taken, candidates[k], request, arena, nullptr);
        if (score < best) {
            best = score;
            axis = candidates[k];
        }
    }
    arena.rewind(mark);
    return !arena.failed;
}

// Workspace for choose_axis() on a cloud of `valid` kept points.
static inline size_t axis_workspace_size(size_t valid, const TubeRequest& request) {
    const size_t count = valid < kAxisSample ? valid : kAxisSample;
    const size_t tube = tube_workspace_size(count, trial_request(request, Vec3{0, 0, 1}));
    if (tube == 0) return 0;
    const size_t shape = valid < kAxisShapeSample ? valid : kAxisShapeSample;
    Arena arena = Arena::measuring();
    arena.alloc<double>(3 * (shape > count ? shape : count));
    arena.alloc<uint32_t>(6 * count);
    return arena.failed ? 0 : arena.required_bytes() + tube;
}

// Axis::automatic in `request` resolved by choose_axis(); any other axis stays. *detail
// receives the reason where it fails.
static inline Status resolve_axis(const TubeInput& in, Arena& arena, TubeRequest& request,
                           const char** detail) {
    if (request.axis != Axis::automatic) return Status::ok;
    if (!kAxisTrials) {
        *detail = kNotCompiledDetail;
        return Status::not_compiled;
    }
    if (in.sums.distinct < 3) {  // no surface along any axis: mesh_tube says so
        request.axis = Axis::z;
        return Status::ok;
    }
    Vec3 axis;
    if (!choose_axis(in, request, arena, axis)) {
        *detail = "the workspace is smaller than reconstruct_workspace_size()";
        return Status::out_of_memory;
    }
    const double direction[3] = {axis.x, axis.y, axis.z};
    set_direction(request, direction);
    return Status::ok;
}

}  // namespace detail
}  // namespace stratmesh
