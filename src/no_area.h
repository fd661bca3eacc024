// >>no area ==============================================================================
// Why a surface through the points would have no area: a line, far points, far clusters.

namespace stratmesh {
namespace detail {

// Whether the kept points of `in` lie on a line up to rounding (see kLineVariance), judged
// on a sample. False also if the workspace is too small for the sample.
static inline bool on_a_line(const TubeInput& in, Arena& arena) {
    const size_t mark = arena.mark();
    size_t taken = 0;
    const double* sample = sample_points(in, kAxisSample, arena, &taken);
    arena.rewind(mark);
    if (!sample) return false;
    double m[3][3];
    scatter_of(sample, taken, m);
    const double along = variance_along(m, principal_direction(m));
    return !(m[0][0] + m[1][1] + m[2][2] - along > kLineVariance * along);
}

// Why a cloud's surface has no area (explain_no_area()).
enum class NoArea : uint32_t { unexplained, line, few_far_points, far_clusters };

// The bins along the bounding box's longest side in which why_no_area() looks for groups:
// one for kPointsABin points, at least 3 (the two ends and between), at most kNoAreaBins,
// so that its groups take a few bytes a point.
const uint32_t kNoAreaBins = 4096;
const size_t kPointsABin = 16;

static inline uint32_t no_area_bins(size_t point_count) {
    const size_t bins = point_count / kPointsABin;
    return bins < 3 ? 3u : bins > kNoAreaBins ? kNoAreaBins : static_cast<uint32_t>(bins);
}

// A group whose largest side is under this share of the cloud's is a point beside the
// cloud: its surface has no area there (kLeastArea is this share squared).
const double kCollapsedShare = 0x1p-20;

// One group of why_no_area(): its points' offsets from its first point (halved, so that
// nothing overflows), their box, and their moments at the scale of that box (so that a
// group far from the others keeps its own digits).
struct PointGroup {
    Vec3 first, low, high;
    double scale;
    double sum[3];
    double products[3][3];
    uint32_t count;
};

static inline Vec3 half_offset(Vec3 p, Vec3 first) { return scaled(p, 0.5) - scaled(first, 0.5); }

// Whether a group spans a surface of its own: 3 points or more, off one line.
static inline bool spans_surface(const PointGroup& g) {
    if (g.count < 3) return false;
    const double n = g.count;
    double m[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m[r][c] = g.products[r][c] - g.sum[r] * g.sum[c] / n;
    const double along = variance_along(m, principal_direction(m));
    return along > 0 && m[0][0] + m[1][1] + m[2][2] - along > kLineVariance * along;
}

// The points' positions along their bounding box's longest side, in up to kNoAreaBins bins.
struct Binning {
    int side;
    double start, span;  // halved coordinates
    uint32_t bins;
    uint32_t of(Vec3 p) const {
        const double t = (coordinate(p, side) * 0.5 - start) / span * bins;
        return t >= bins ? bins - 1 : t > 0 ? static_cast<uint32_t>(t) : 0u;
    }
};

// Adds a point's half offset to its group's box (first pass) or moments (second pass).
static inline void add_to_group(PointGroup& g, Vec3 p, int pass) {
    if (pass == 0 && g.count++ == 0) g.first = p;
    const Vec3 h = half_offset(p, g.first);
    if (pass == 0) {
        g.low = {h.x < g.low.x ? h.x : g.low.x, h.y < g.low.y ? h.y : g.low.y, h.z < g.low.z ? h.z : g.low.z};
        g.high = {h.x > g.high.x ? h.x : g.high.x, h.y > g.high.y ? h.y : g.high.y,
                  h.z > g.high.z ? h.z : g.high.z};
        return;
    }
    const Vec3 d = scaled(h, g.scale);
    const double c[3] = {d.x, d.y, d.z};
    for (int r = 0; r < 3; ++r) {
        g.sum[r] += c[r];
        for (int s = 0; s < 3; ++s) g.products[r][s] += c[r] * c[s];
    }
}

// Numbers the runs of occupied bins (non-zero) from 1, empty bins 0; returns the runs.
static inline uint32_t number_runs(uint32_t* group_of, uint32_t bins) {
    uint32_t count = 0;
    for (uint32_t b = 0; b < bins; ++b) {
        const bool occupied = group_of[b] != 0;
        if (occupied && (b == 0 || group_of[b - 1] == 0)) ++count;
        group_of[b] = occupied ? count : 0;
    }
    return count;
}

// The groups of why_no_area(): the occupied bins first, numbered by run (number_runs()),
// then each point joins its bin's group, its box first, its moments after. One loop over
// the points serves the three passes.
static inline uint32_t gather_groups(const TubeInput& in, const Binning& binning, uint32_t* group_of,
                              PointGroup* groups) {
    std::memset(group_of, 0, binning.bins * sizeof(uint32_t));
    uint32_t count = 0;
    for (int pass = -1; pass < 2; ++pass) {
        for (size_t i = 0; i < in.count; ++i) {
            if (!in.reader.valid(i)) continue;
            const Vec3 p = in.reader.point(i);
            uint32_t& group = group_of[binning.of(p)];
            if (pass < 0)
                group = 1;
            else
                add_to_group(groups[group - 1], p, pass);
        }
        if (pass < 0) {
            count = number_runs(group_of, binning.bins);
            std::memset(static_cast<void*>(groups), 0, count * sizeof(PointGroup));
        }
        for (uint32_t k = 0; pass == 0 && k < count; ++k)
            groups[k].scale = scale_for_extent(largest_of(groups[k].high - groups[k].low));
    }
    return count;
}

// The bytes why_no_area() takes for point_count points.
static inline size_t no_area_workspace_size(size_t point_count) {
    Arena arena = Arena::measuring();
    const size_t bins = no_area_bins(point_count);
    arena.alloc<uint32_t>(bins);
    arena.alloc<PointGroup>(bins);
    return arena.required_bytes();
}

// Why the kept points of `in` span no area: binned along their bounding box's longest side,
// they fall into groups (runs of occupied bins, so the points of a collapsed cluster share
// one). None spans a surface (3 points off a line): a line. The largest that does is a
// point beside the cloud (kCollapsedShare) and fewer than kOutlierNeighbours points lie
// outside it: specks that drop_outliers leaves out; more: clusters far apart. Unexplained
// otherwise, or when the workspace cannot hold the groups.
static inline NoArea why_no_area(const TubeInput& in, Arena& arena) {
    const Vec3 low = {in.sums.lowest[0], in.sums.lowest[1], in.sums.lowest[2]};
    const Vec3 high = {in.sums.highest[0], in.sums.highest[1], in.sums.highest[2]};
    const Vec3 half_side = scaled(high, 0.5) - scaled(low, 0.5);
    Binning binning;
    binning.span = largest_of(half_side);
    binning.side = binning.span == half_side.x ? 0 : binning.span == half_side.y ? 1 : 2;
    binning.start = coordinate(low, binning.side) * 0.5;
    binning.bins = no_area_bins(in.sums.valid);
    if (!(binning.span > 0) || binning.bins == 0) return NoArea::line;
    const size_t mark = arena.mark();
    uint32_t* group_of = arena.alloc<uint32_t>(binning.bins);
    PointGroup* groups = arena.alloc<PointGroup>(binning.bins);
    if (arena.failed) {
        arena.rewind(mark);
        return NoArea::unexplained;
    }
    const uint32_t count = gather_groups(in, binning, group_of, groups);
    const PointGroup* largest = nullptr;
    for (uint32_t g = 0; g < count; ++g)
        if (spans_surface(groups[g]) && (!largest || groups[g].count > largest->count))
            largest = &groups[g];
    const bool collapsed =
        largest && largest_of(largest->high - largest->low) < kCollapsedShare * binning.span;
    const size_t outside = largest ? in.sums.valid - largest->count : 0;
    arena.rewind(mark);
    if (!largest) return NoArea::line;
    if (!collapsed || outside == 0) return NoArea::unexplained;
    return outside < kOutlierNeighbours ? NoArea::few_far_points : NoArea::far_clusters;
}

// The status and detail of a cloud refused as degenerate or not_columnar, where
// why_no_area() tells a reason: the same status and detail where it tells none.
static inline Status explain_no_area(const TubeInput& in, Status status, Arena& arena, Report& rep) {
    switch (why_no_area(in, arena)) {
    case NoArea::line:
        if (status != Status::degenerate) return status;
        rep.detail = "the points lie on a line up to rounding: no surface passes through them";
        return Status::degenerate;
    case NoArea::few_far_points:
        rep.detail = "a few points lie so far from the rest that the rest collapse to a point "
                     "beside them: drop_outliers leaves such points out";
        return Status::degenerate;
    case NoArea::far_clusters:
        rep.detail = "the points form clusters so far apart that each collapses to a point "
                     "beside the others: mesh each cluster on its own";
        return Status::separate_clusters;
    default:
        if (status != Status::degenerate) return status;
        rep.detail = "the surface through the points has no area beside the cloud's extent";
        return Status::degenerate;
    }
}

}  // namespace detail
}  // namespace stratmesh
