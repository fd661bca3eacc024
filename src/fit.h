// >>fit ==================================================================================
// How well the finished surface fits its cloud (Diagnostics): misfit area and crossings.
//
// Measured once the surface is final, from the cloud alone, in the memory the meshing
// used. A sample of the triangles (caps left out: a cap spans its loop by design), every
// k-th of them up to kMisfitSampleLimit, each compared with the cloud around its centroid:
//  - misfit, where its normal parts from the cloud's own there by more than 45 degrees
//    (the normal of the kFitNeighbours points nearest the centroid: the direction in which
//    they spread least), as where a layer folds and its triangles run across the surface
//    or a sliver bridges a crease, or where its centroid lies farther than kMisfitSpacings
//    times the cloud's spacing from every point, as where a web spans a gap. The misfit
//    share of the sample's area estimates the share of the surface that does not follow
//    the cloud: on single columns it stays near zero, on a fold or a limb wrapped in one
//    tube it is a tenth of the surface or more;
//  - crossing, where it and another triangle that shares no corner with it pierce each
//    other (an edge of one through the other's inside, by more than rounding: coplanar
//    triangles do not count), caps included. The triangles are swept in the order of their
//    boxes along the side where they overlap least, each tested against those after it
//    whose boxes meet its own. Surfaces of at most kCrossingCheckLimit triangles are
//    checked whole, larger ones not (their misfit share judges them); past an average of
//    kCrossingBudget box tests a triangle the check stops, incomplete.
// The cloud's spacing is the outliers' scale (nearest_spacing), the grid's cells twice
// that. A cloud that spans more than the largest double is not measured. Deterministic:
// sums in the sample's order, no libm beyond sqrt.

namespace stratmesh {
namespace detail {

const double kMisfitCosine = 0.70710678118654752;  // cos(kMisfitDegrees)
static_assert(kMisfitDegrees == 45.0, "kMisfitCosine is the cosine of kMisfitDegrees");
// The grid's cells, in spacings: the 27 around a centroid hold a few dozen points.
const double kFitCellSpacings = 2.0;
// A centroid over a gap: its nearest point at least this share of the way to the farthest
// of its kFitNeighbours nearest (on a surface sampled without a gap, far less).
const double kGapShare = 0.6;
// Points whose scatter's middle eigenvalue is under kSurfaceSpread times its least, or
// under kCurveSpread times its largest, spread along a curve (a contour), not a surface.
const double kSurfaceSpread = 3.0;
const double kCurveSpread = 0.1;
// The most box tests a triangle the crossing check makes, on average, before it stops.
const size_t kCrossingBudget = 1024;
// A volume under this share of the product of its three edges' lengths is taken as zero.
const double kFlatVolume = 1e-12;

// The cloud's and the surface's points as the measure takes them: times a power of two
// that brings the cloud's extent near 1 (exact), so that no square overflows.
struct FitFrame {
    double scale;
    Vec3 point(const CloudReader& reader, uint32_t i) const { return scaled(reader.point(i), scale); }
};

struct Box3f {
    Vec3 low, high;
    void add(Vec3 p) {
        low = {p.x < low.x ? p.x : low.x, p.y < low.y ? p.y : low.y, p.z < low.z ? p.z : low.z};
        high = {p.x > high.x ? p.x : high.x, p.y > high.y ? p.y : high.y, p.z > high.z ? p.z : high.z};
    }
    bool meets(const Box3f& o) const {
        return low.x <= o.high.x && o.low.x <= high.x && low.y <= o.high.y && o.low.y <= high.y &&
               low.z <= o.high.z && o.low.z <= high.z;
    }
};

// The memory of the measure: the points in cells, then the triangles in sweep order.
struct FitMemory {
    CellScratch points;
    GridItem* sweep;
    GridItem* spare;
};

static inline bool allocate_fit(FitMemory& m, size_t point_count, size_t triangle_count, Arena& arena) {
    m.points = allocate_cell_scratch(arena, point_count);
    const size_t swept = triangle_count <= kCrossingCheckLimit ? triangle_count : 0;
    m.sweep = arena.alloc<GridItem>(swept);
    m.spare = arena.alloc<GridItem>(swept);
    return !arena.failed;
}

static inline size_t fit_workspace_size(size_t point_count, size_t triangle_count) {
    Arena arena = Arena::measuring();
    FitMemory m;
    return allocate_fit(m, point_count, triangle_count, arena) ? arena.required_bytes() : 0;
}

// The unit normal of the points p[0 .. n): the eigenvector of their scatter's least
// eigenvalue, by power steps on the scatter's adjugate (whose largest eigenvalue that one
// is), from its longest row: on a surface the least eigenvalue lies far below the others,
// and two steps settle it. Zero where the points spread along a curve rather than a
// surface, as on one contour of a CT stack: they have no normal to judge by.
static inline Vec3 cloud_normal(const Vec3* p, uint32_t n) {
    Vec3 mean = {0, 0, 0};
    for (uint32_t i = 0; i < n; ++i) mean = {mean.x + p[i].x, mean.y + p[i].y, mean.z + p[i].z};
    mean = scaled(mean, 1.0 / n);
    Vec3 row[3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (uint32_t i = 0; i < n; ++i) {
        const Vec3 d = p[i] - mean;
        row[0] = {row[0].x + d.x * d.x, row[0].y + d.x * d.y, row[0].z + d.x * d.z};
        row[1] = {row[1].x + d.y * d.x, row[1].y + d.y * d.y, row[1].z + d.y * d.z};
        row[2] = {row[2].x + d.z * d.x, row[2].y + d.z * d.y, row[2].z + d.z * d.z};
    }
    const Vec3 adjugate[3] = {cross(row[1], row[2]), cross(row[2], row[0]), cross(row[0], row[1])};
    Vec3 v = adjugate[0];
    for (const Vec3& a : adjugate)
        if (dot(a, a) > dot(v, v)) v = a;
    for (int step = 0; step < 2 && normalize(v); ++step)
        v = {dot(adjugate[0], v), dot(adjugate[1], v), dot(adjugate[2], v)};
    if (!normalize(v)) return {0, 0, 0};
    // The other two eigenvalues are the roots of x^2 - sum x + product, from the trace and
    // the adjugate's trace (the sum of the products of pairs).
    const double least = dot(v, {dot(row[0], v), dot(row[1], v), dot(row[2], v)});
    const double sum = row[0].x + row[1].y + row[2].z - least;
    const double product = adjugate[0].x + adjugate[1].y + adjugate[2].z - least * sum;
    const double square = sum * sum - 4 * product;
    const double middle = (sum - std::sqrt(square > 0 ? square : 0)) / 2;
    const double largest = sum - middle;
    return middle >= kSurfaceSpread * least && middle >= kCurveSpread * largest ? v : Vec3{0, 0, 0};
}

static inline void corners(const FitFrame& f, const CloudReader& reader, const uint32_t* v, Vec3* out) {
    for (int k = 0; k < 3; ++k) out[k] = f.point(reader, v[k]);
}

// The item of `items` (sorted by cell) in `cell`, or failing that the first after it
// (n: past the end).
static inline size_t item_at_cell(const GridItem* items, size_t n, uint64_t cell) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (items[mid].cell < cell) lo = mid + 1; else hi = mid;
    }
    return lo;
}

// The kFitNeighbours points nearest `q` among those of the cells around `cell`, q's
// (sorted nearest first into near[], their squared distances in d2[]); returns how many.
static inline uint32_t nearest_points(const FitFrame& f, const CloudReader& reader, const GridItem* items,
                                      size_t n, uint64_t cell, Vec3 q, Vec3* near, double* d2) {
    const size_t hint = item_at_cell(items, n, cell);
    const CellBlock block = block_of_cell(items, n, cell, hint < n ? hint : n - 1);
    uint32_t found = 0;
    for (uint32_t r = 0; r < block.count; ++r)
        for (size_t i = block.begin[r]; i < block.end[r]; ++i) {
            const Vec3 p = f.point(reader, items[i].index);
            const Vec3 d = p - q;
            const double dd = dot(d, d);
            if (found == kFitNeighbours && !(dd < d2[found - 1])) continue;
            uint32_t k = found < kFitNeighbours ? found++ : found - 1;
            for (; k > 0 && d2[k - 1] > dd; --k) {
                d2[k] = d2[k - 1];
                near[k] = near[k - 1];
            }
            d2[k] = dd;
            near[k] = p;
        }
    return found;
}

// The cell of side `side` from `low` that holds p, as sort_into_cells keys it.
static inline uint64_t cell_of(Vec3 p, Vec3 low, double side) {
    return cell_key(cell_coordinate(p.x - low.x, side), cell_coordinate(p.y - low.y, side),
                    cell_coordinate(p.z - low.z, side));
}

// The sampled triangles' misfit: adds their areas, and the misfit ones' areas and box, to
// the diagnostics (areas in the frame's units, squared).
struct MisfitTally {
    double area, misfit;
    Box3f where;
    size_t samples;
};

// Whether the triangle abc (unit normal `normal`, centroid `centroid`) misfits the cloud
// around it. `near` has room for kFitNeighbours + 3 points.
static inline bool misfits(const FitFrame& f, const CloudReader& reader, const FitMemory& m,
                           size_t n, Vec3 low, double side, double far, const Vec3* corner,
                           Vec3 normal, Vec3 centroid, Vec3* near) {
    double d2[kFitNeighbours];
    const uint32_t found = nearest_points(f, reader, m.points.items, n, cell_of(centroid, low, side),
                                          centroid, near, d2);
    if (found == 0) return true;  // no point in the cells around: a web over a wide gap
    const Vec3 around = cloud_normal(near, found);
    if (dot(around, around) > 0)
        // A surface around: the triangle misfits across it, or over a gap in it (its
        // centroid far from every point, and the nearest hardly nearer than the rest).
        return abs_value(dot(normal, around)) < kMisfitCosine ||
               (d2[0] > far * far && d2[0] > kGapShare * kGapShare * d2[found - 1]);
    // The points around lie along a curve (the contours of a CT stack): the triangle's
    // corners, on the rows it joins, make the surface to judge by.
    for (uint32_t k = 0; k < 3; ++k) near[found + k] = corner[k];
    const Vec3 rows = cloud_normal(near, found + 3);
    return dot(rows, rows) > 0 && abs_value(dot(normal, rows)) < kMisfitCosine;
}

// Tallies every step-th triangle of tri[0 .. count): its area, and whether it misfits.
static inline void tally_misfit(const FitFrame& f, const CloudReader& reader, const FitMemory& m,
                                size_t n, Vec3 low, double side, double spacing, const uint32_t* tri,
                                size_t count, size_t step, MisfitTally& t) {
    Vec3 near[kFitNeighbours + 3];
    for (size_t k = 0; k < count; k += step) {
        Vec3 c[3];
        corners(f, reader, tri + 3 * k, c);
        Vec3 normal = cross(c[1] - c[0], c[2] - c[0]);
        const double area = std::sqrt(dot(normal, normal)) / 2;
        const Vec3 centroid = scaled(c[0] + c[1] + c[2], 1.0 / 3);
        ++t.samples;
        t.area += area;
        if (!normalize(normal) ||
            !misfits(f, reader, m, n, low, side, kMisfitSpacings * spacing, c, normal, centroid, near))
            continue;
        t.misfit += area;
        for (const Vec3& p : c) t.where.add(p);
    }
}

// The sign of the volume of (o, u, v, w), 0 within rounding (kFlatVolume).
static inline int volume_sign(Vec3 o, Vec3 u, Vec3 v, Vec3 w) {
    const Vec3 a = u - o, b = v - o, c = w - o;
    const double volume = dot(cross(a, b), c);
    const double size = std::sqrt(dot(a, a) * dot(b, b) * dot(c, c));
    return volume > kFlatVolume * size ? 1 : volume < -kFlatVolume * size ? -1 : 0;
}

// Whether segment pq pierces triangle abc's inside.
static inline bool segment_crosses(Vec3 p, Vec3 q, Vec3 a, Vec3 b, Vec3 c) {
    const int sp = volume_sign(a, b, c, p), sq = volume_sign(a, b, c, q);
    if (sp == 0 || sq != -sp) return false;
    const int s1 = volume_sign(p, q, a, b), s2 = volume_sign(p, q, b, c), s3 = volume_sign(p, q, c, a);
    return s1 != 0 && s1 == s2 && s2 == s3;
}

static inline bool triangles_cross(const Vec3* u, const Vec3* v) {
    for (int k = 0; k < 3; ++k) {
        if (segment_crosses(u[k], u[(k + 1) % 3], v[0], v[1], v[2])) return true;
        if (segment_crosses(v[k], v[(k + 1) % 3], u[0], u[1], u[2])) return true;
    }
    return false;
}


static inline Box3f box_of_corners(const Vec3* c) {
    Box3f b = {c[0], c[0]};
    b.add(c[1]);
    b.add(c[2]);
    return b;
}

static inline bool share_a_corner(const uint32_t* u, const uint32_t* v) {
    for (int a = 0; a < 3; ++a)
        if (u[a] == v[0] || u[a] == v[1] || u[a] == v[2]) return true;
    return false;
}

// The side (0, 1 or 2) along which the triangles' boxes overlap least: the least sum of
// their extents along it over the cloud's extent `size` there.
static inline int sweep_side(const FitFrame& f, const CloudReader& reader, const uint32_t* tri,
                             size_t count, Vec3 size) {
    Vec3 sum = {0, 0, 0};
    for (size_t t = 0; t < count; ++t) {
        Vec3 c[3];
        corners(f, reader, tri + 3 * t, c);
        const Box3f box = box_of_corners(c);
        sum = sum + (box.high - box.low);
    }
    const double sums[3] = {sum.x, sum.y, sum.z}, sizes[3] = {size.x, size.y, size.z};
    double share[3];
    for (int k = 0; k < 3; ++k) share[k] = sizes[k] > 0 ? sums[k] / sizes[k] : DBL_MAX;
    int side = 0;
    for (int k = 1; k < 3; ++k)
        if (share[k] < share[side]) side = k;
    return side;
}

// The sweep: the triangles in the order of their boxes' low ends along `side` (0, 1 or 2),
// from `low`. Keys are the bits of a non-negative double, which order as the values do.
static inline void sort_sweep(const FitFrame& f, const CloudReader& reader, const uint32_t* tri,
                                size_t count, int side, double low, FitMemory& m) {
    uint64_t any = 0, every = ~uint64_t{0};
    for (size_t t = 0; t < count; ++t) {
        Vec3 c[3];
        corners(f, reader, tri + 3 * t, c);
        const double from = coordinate(box_of_corners(c).low, side) - low;
        uint64_t key;
        const double start = from > 0 ? from : 0;
        std::memcpy(&key, &start, sizeof key);
        m.sweep[t] = {key, static_cast<uint32_t>(t)};
        any |= key;
        every &= key;
    }
    sort_items(m.sweep, m.spare, count, any, every);
}

struct CrossingTally {
    size_t pairs;
    bool complete;
    Box3f where;
};

// The crossing pairs (each once), their boxes' union in t.where; stops, incomplete, past
// kCrossingBudget box tests a triangle.
static inline void count_crossings(const FitFrame& f, const CloudReader& reader, const uint32_t* tri,
                                   const GridItem* items, size_t count, int side, double low,
                                   CrossingTally& t) {
    size_t budget = kCrossingBudget * count;
    for (size_t k = 0; k < count; ++k) {
        const uint32_t s = items[k].index;
        Vec3 u[3], v[3];
        corners(f, reader, tri + 3 * size_t{s}, u);
        const Box3f box = box_of_corners(u);
        const double to = coordinate(box.high, side) - low;
        uint64_t last;
        std::memcpy(&last, &to, sizeof last);
        for (size_t i = k + 1; i < count && items[i].cell <= last; ++i) {
            const uint32_t o = items[i].index;
            if (budget-- == 0) {
                t.complete = false;
                return;
            }
            if (share_a_corner(tri + 3 * size_t{s}, tri + 3 * size_t{o})) continue;
            corners(f, reader, tri + 3 * size_t{o}, v);
            if (!box.meets(box_of_corners(v)) || !triangles_cross(u, v)) continue;
            ++t.pairs;
            t.where.add(box.low);
            t.where.add(box.high);
        }
    }
}

// The box `b` in the cloud's units into min and max (left zero when b is empty).
static inline void put_box(const Box3f& b, double to_cloud, double* min, double* max) {
    if (!(b.low.x <= b.high.x)) return;
    const Vec3 lo = scaled(b.low, to_cloud), hi = scaled(b.high, to_cloud);
    const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
    for (int k = 0; k < 3; ++k) {
        min[k] = l[k];
        max[k] = h[k];
    }
}

// Measures the surface's fit (see above) into rep.diagnostics; false if the workspace is
// too small. triangles[0 .. count - caps) are the walls, the rest caps: the caps are
// checked for crossings, not for misfit.
static inline bool measure_fit(const CloudReader& reader, size_t point_count, const CloudSums& sums,
                               const uint32_t* triangles, size_t count, size_t caps, Arena& arena,
                               Report& rep) {
    const size_t walls = caps < count ? count - caps : 0;
    Diagnostics& d = rep.diagnostics;
    if (walls == 0) return true;
    const size_t mark = arena.mark();
    FitMemory m;
    if (!allocate_fit(m, point_count, count, arena)) return false;
    const Vec3 size = Vec3{sums.highest[0], sums.highest[1], sums.highest[2]} -
                      Vec3{sums.lowest[0], sums.lowest[1], sums.lowest[2]};
    const double extent = largest_of(size);
    const CloudBox box = box_of(reader, point_count);
    const double spacing =
        is_finite(extent) ? nearest_spacing(reader, point_count, box, m.points, kMisfitSampleLimit) : 0;
    if (!(spacing > 0)) {
        arena.rewind(mark);
        return true;
    }
    const FitFrame f = {scale_for_extent(extent)};
    // The points' cells keyed from the reader's coordinates: the scaled ones key alike, the
    // scale being a power of two.
    const size_t n = sort_into_cells(reader, point_count, box.low, kFitCellSpacings * spacing, m.points);
    const double side = kFitCellSpacings * spacing * f.scale;
    const Vec3 low = scaled(box.low, f.scale);
    const size_t step = walls > kMisfitSampleLimit ? (walls + kMisfitSampleLimit - 1) / kMisfitSampleLimit : 1;
    const Box3f none = {{DBL_MAX, DBL_MAX, DBL_MAX}, {-DBL_MAX, -DBL_MAX, -DBL_MAX}};
    MisfitTally t = {0, 0, none, 0};
    tally_misfit(f, reader, m, n, low, side, spacing * f.scale, triangles, walls, step, t);
    CrossingTally crossed = {0, count <= kCrossingCheckLimit, none};
    if (crossed.complete) {
        const int along = sweep_side(f, reader, triangles, count, scaled(size, f.scale));
        const double from = coordinate(low, along);
        sort_sweep(f, reader, triangles, count, along, from, m);
        count_crossings(f, reader, triangles, m.sweep, count, along, from, crossed);
    }
    d.crossing_pair_count = crossed.pairs;
    const double to_cloud = 1 / f.scale;
    const double vertices = static_cast<double>(rep.points.used_count);
    d.point_spacing = spacing;
    // The sample's area stands for every step-th triangle's.
    d.area_per_point = vertices > 0 ? t.area * static_cast<double>(step) * to_cloud * to_cloud /
                                          (vertices * spacing * spacing)
                                    : 0;
    d.crossing_check_complete = crossed.complete;
    d.fit_sample_count = t.samples;
    d.misfit_area_fraction = t.area > 0 ? t.misfit / t.area : 0;
    d.misfit_area = t.misfit * static_cast<double>(step) * to_cloud * to_cloud;
    put_box(t.where, to_cloud, d.misfit_box_min, d.misfit_box_max);
    put_box(crossed.where, to_cloud, d.crossing_box_min, d.crossing_box_max);
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh
