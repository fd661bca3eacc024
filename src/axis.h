// >>axis ====================================================================================
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
inline void principal_directions(const double m[3][3], Vec3 out[3]) {
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
inline void scatter_of(const double* xyz, size_t count, double m[3][3]) {
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
inline double variance_along(const double m[3][3], Vec3 v) {
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
inline uint32_t axis_candidates(const double* xyz, size_t count, Vec3* out) {
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
// folding).
inline double sample_surface(const double* xyz, const uint32_t* tri, size_t count,
                             size_t unused) {
    double area = 0;
    for (size_t t = 0; t < count; ++t) {
        const double* a = xyz + 3 * tri[3 * t];
        const double* b = xyz + 3 * tri[3 * t + 1];
        const double* c = xyz + 3 * tri[3 * t + 2];
        const Vec3 n = cross(Vec3{b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                             Vec3{c[0] - a[0], c[1] - a[1], c[2] - a[2]});
        area += std::sqrt(dot(n, n)) / 2;
    }
    const double per_triangle = count > 0 ? area / static_cast<double>(count) : 0;
    return area + 2 * per_triangle * static_cast<double>(unused);
}

// The mean squared cosine between the triangles' normals and the unit axis, weighted by
// their areas: 0 where the surface runs along the axis, 1 where it lies across it.
inline double normals_along(const double* xyz, const uint32_t* tri, size_t count, Vec3 axis) {
    double along = 0, area = 0;
    for (size_t t = 0; t < count; ++t) {
        const double* a = xyz + 3 * tri[3 * t];
        const double* b = xyz + 3 * tri[3 * t + 1];
        const double* c = xyz + 3 * tri[3 * t + 2];
        const Vec3 n = cross(Vec3{b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                             Vec3{c[0] - a[0], c[1] - a[1], c[2] - a[2]});
        const double length = std::sqrt(dot(n, n));
        if (length == 0) continue;
        const double cosine = dot(n, axis) / length;
        along += cosine * cosine * length;
        area += length;
    }
    return area > 0 ? along / area : 1;
}

// Workspace for choose_axis() on a cloud of `valid` kept points, given the flags.
inline size_t axis_workspace_size(size_t valid, const Options& options);

// Meshes the sample along one candidate; DBL_MAX if it cannot.
// *along (optional) receives the share of the sample surface's normals along the axis.
inline double try_axis(const double* sample, size_t count, Vec3 axis, const Options& options,
                       Arena& arena, double* along) {
    Options trial = {};
    trial.axis = Axis::direction;
    trial.direction[0] = axis.x;
    trial.direction[1] = axis.y;
    trial.direction[2] = axis.z;
    trial.flags = options.flags & open_ends;
    trial.layer_count = 1;
    const size_t mark = arena.mark();
    uint32_t* tri = arena.alloc<uint32_t>(6 * count);
    if (arena.failed) return DBL_MAX;
    const Cloud cloud = {sample, count, 0, Scalar::float64};
    TubeInput in = {reader_of(cloud), count, {}, 0};
    in.sums = sum_cloud(in.reader, count);
    Report rep = {};
    size_t triangles = 0;
    const Status status = mesh_tube(in, trial, arena, tri, 2 * count, &triangles, rep);
    arena.rewind(mark);
    if (status != Status::ok) return DBL_MAX;
    if (along) *along = normals_along(sample, tri, triangles, axis);
    return sample_surface(sample, tri, triangles, in.sums.valid - rep.points.used_count -
                                                      rep.points.duplicate_count);
}

// Every k-th kept point of `in`, packed, at most `most` of them (and about that many), in
// `arena`; null if the workspace is too small. *taken receives their count. Where every
// point is kept, the sample is read by index, without a pass over the cloud.
inline double* sample_points(const TubeInput& in, size_t most, Arena& arena, size_t* taken) {
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
inline bool choose_axis(const TubeInput& in, const Options& options, Arena& arena, Vec3& axis) {
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
    double best = try_axis(sample, taken, candidates[0], options, arena, &along);
    for (uint32_t k = 1; k < tries && !(along < kAlongSurface); ++k) {
        const double score = try_axis(sample, taken, candidates[k], options, arena, nullptr);
        if (score < best) {
            best = score;
            axis = candidates[k];
        }
    }
    arena.rewind(mark);
    return !arena.failed;
}

inline size_t axis_workspace_size(size_t valid, const Options& options) {
    const size_t count = valid < kAxisSample ? valid : kAxisSample;
    Options trial = {};
    trial.flags = options.flags & open_ends;
    trial.layer_count = 1;
    const size_t tube = tube_workspace_size(count, trial);
    if (tube == 0) return 0;
    const size_t shape = valid < kAxisShapeSample ? valid : kAxisShapeSample;
    Arena arena = Arena::measuring();
    arena.alloc<double>(3 * (shape > count ? shape : count));
    arena.alloc<uint32_t>(6 * count);
    return arena.failed ? 0 : arena.required_bytes() + tube;
}

}  // namespace detail

namespace detail {

// Whether the kept points of `in` lie on a line up to rounding (see kLineVariance), judged
// on a sample. False also if the workspace is too small for the sample.
inline bool on_a_line(const TubeInput& in, Arena& arena) {
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

// The bins along the bounding box's longest side in which why_no_area() looks for groups.
const uint32_t kNoAreaBins = 4096;

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

inline Vec3 half_offset(Vec3 p, Vec3 first) { return scaled(p, 0.5) - scaled(first, 0.5); }

// Whether a group spans a surface of its own: 3 points or more, off one line.
inline bool spans_surface(const PointGroup& g) {
    if (g.count < 3) return false;
    const double n = g.count;
    double m[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m[r][c] = g.products[r][c] - g.sum[r] * g.sum[c] / n;
    const double along = variance_along(m, principal_direction(m));
    return along > 0 && m[0][0] + m[1][1] + m[2][2] - along > kLineVariance * along;
}

inline double coordinate(Vec3 p, int k) { return k == 0 ? p.x : k == 1 ? p.y : p.z; }

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
inline void add_to_group(PointGroup& g, Vec3 p, int pass) {
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

// The groups of why_no_area(): `group_of` numbers the runs of occupied bins from 1 (0:
// empty); each point joins its bin's group, its box first, its moments after.
inline uint32_t gather_groups(const TubeInput& in, const Binning& binning, uint32_t* group_of,
                              PointGroup* groups) {
    std::memset(group_of, 0, binning.bins * sizeof(uint32_t));
    for (size_t i = 0; i < in.count; ++i)
        if (in.reader.valid(i)) group_of[binning.of(in.reader.point(i))] = 1;
    uint32_t count = 0;
    for (uint32_t b = 0; b < binning.bins; ++b) {
        const bool occupied = group_of[b] != 0;
        if (occupied && (b == 0 || group_of[b - 1] == 0)) ++count;
        group_of[b] = occupied ? count : 0;
    }
    std::memset(static_cast<void*>(groups), 0, count * sizeof(PointGroup));
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t i = 0; i < in.count; ++i) {
            if (!in.reader.valid(i)) continue;
            const Vec3 p = in.reader.point(i);
            add_to_group(groups[group_of[binning.of(p)] - 1], p, pass);
        }
        for (uint32_t k = 0; pass == 0 && k < count; ++k)
            groups[k].scale = scale_for_extent(largest_of(groups[k].high - groups[k].low));
    }
    return count;
}

// Why the kept points of `in` span no area: binned along their bounding box's longest side,
// they fall into groups (runs of occupied bins, so the points of a collapsed cluster share
// one). None spans a surface (3 points off a line): a line. The largest that does is a
// point beside the cloud (kCollapsedShare) and fewer than kOutlierNeighbours points lie
// outside it: specks that drop_outliers leaves out; more: clusters far apart. Unexplained
// otherwise, or when the workspace cannot hold the groups.
inline NoArea why_no_area(const TubeInput& in, Arena& arena) {
    const Vec3 low = {in.sums.lowest[0], in.sums.lowest[1], in.sums.lowest[2]};
    const Vec3 high = {in.sums.highest[0], in.sums.highest[1], in.sums.highest[2]};
    const Vec3 half_side = scaled(high, 0.5) - scaled(low, 0.5);
    Binning binning;
    binning.span = largest_of(half_side);
    binning.side = binning.span == half_side.x ? 0 : binning.span == half_side.y ? 1 : 2;
    binning.start = coordinate(low, binning.side) * 0.5;
    binning.bins = in.sums.valid < kNoAreaBins ? static_cast<uint32_t>(in.sums.valid) : kNoAreaBins;
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
inline Status explain_no_area(const TubeInput& in, Status status, Arena& arena, Report& rep) {
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

// The options along the axis to use: Axis::automatic resolved by choose_axis().
inline Status resolve_axis(const TubeInput& in, const Options& options, Arena& arena,
                           Options& along, Report& rep) {
    along = options;
    if (options.axis != Axis::automatic) return Status::ok;
    if (!kAxisTrials) {
        rep.detail = kNotCompiledDetail;
        return Status::not_compiled;
    }
    if (in.sums.distinct < 3) {  // no surface along any axis: mesh_tube says so
        along.axis = Axis::z;
        return Status::ok;
    }
    Vec3 axis;
    if (!choose_axis(in, options, arena, axis)) {
        rep.detail = "the workspace is smaller than reconstruct_workspace_size()";
        return Status::out_of_memory;
    }
    along.axis = Axis::direction;
    along.direction[0] = axis.x;
    along.direction[1] = axis.y;
    along.direction[2] = axis.z;
    return Status::ok;
}

}  // namespace detail

}  // namespace stratmesh
