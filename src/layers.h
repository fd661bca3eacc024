// >>layers ==================================================================================
// The frame, the outliers, grouping by layer, automatic layers.
//
// The cloud is read in place (float or double, any stride) and expressed in a frame whose
// third axis is the stacking axis and whose origin is the centroid, so that clouds far
// from the origin (georeferenced scans) keep their millimetres. Layers are height ranges
// along the axis; the points are grouped by layer, in input order within a layer.

namespace stratmesh {
namespace detail {

struct Vec3 {
    double x, y, z;
};

inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Vec3 scaled(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }

struct CloudReader {
    const unsigned char* base;
    size_t stride;
    bool is_float;
    const unsigned char* dropped;  // optional bitmap: points left out as outliers

    Vec3 point(size_t i) const {
        const unsigned char* p = base + i * stride;
        if (is_float) {
            float v[3];
            std::memcpy(v, p, sizeof v);
            return {static_cast<double>(v[0]), static_cast<double>(v[1]),
                    static_cast<double>(v[2])};
        }
        double v[3];
        std::memcpy(v, p, sizeof v);
        return {v[0], v[1], v[2]};
    }
    bool valid(size_t i) const {
        if (kDropOutliers && dropped && ((dropped[i >> 3] >> (i & 7)) & 1)) return false;
        // One test for three coordinates: a product by zero is zero exactly when the
        // coordinate is finite, and it never overflows.
        Vec3 p = point(i);
        return p.x * 0 + p.y * 0 + p.z * 0 == 0;
    }
};

// ---- outliers ----
//
// With drop_outliers, points far from the rest of the cloud (stray returns, flying pixels at
// depth edges, dust) are left out before anything else, so they neither tilt the automatic
// axis nor stretch the layers nor become spikes of the surface. The scale is the cloud's
// own: d, the distance to the nearest distinct point that nine points in ten do not exceed.
// A point is an outlier when fewer than kOutlierNeighbours points, itself included, lie in
// its block of 3 x 3 x 3 cells of side kOutlierReach d: nothing within 4 d of it (at most
// 12 d), or a speck of fewer than 8 points. A surface sample has a hundred or more points
// in that block; one a quarter as dense (the far side of a scan) still about thirty.
//
// d is measured on a grid of cells that hold about 4 points on average: first cells twice
// the spacing of the points spread over the square of the bounding box's diagonal, finer
// while they hold more than kCrowdedCell on average, four times coarser while more than a
// tenth of the points find no neighbour within a cell; each of at most about kDecileSample
// points looks at kNearestCandidates points at most, its own cell's row first, so that no
// cell costs more. A far outlier stretches the bounding box, and so the first grid, which
// can then miss a nearer one: the rounds repeat without the outliers found, at most
// kOutlierRounds times. Clouds of fewer than 16 points lose none. Duplicates of an outlier
// are outliers too. Deterministic (the same cells and counts on every platform); radix
// sorts of the cell keys and binary searches for a cell's neighbours, no recursion; 56
// bytes a point of workspace while it runs (less than the reconstruction takes next),
// then a bit a point. Measured: 20 far strays and 50 inside the head added to the bundled
// bust: 66 of the 70 left out (the other 4 lie 8 to 21 mm from the bust, within the
// block around it: d = 2.2 mm), none of the bust's own points (nor any of the real clouds'
// or the test shapes'); about 0.1 s on 300,000 points, a third of the reconstruction.
const uint32_t kOutlierNeighbours = 8;
const double kOutlierReach = 4.0;
const uint32_t kOutlierRounds = 3;
const uint32_t kGridTries = 8;
const uint32_t kCrowdedCell = 8;
const uint32_t kNearestCandidates = 64;
const size_t kDecileSample = 16384;
const uint32_t kNearestBins = 64;  // half-octaves of the squared distance, the last: none
const uint32_t kCellBits = 21;     // per axis, so a cell key takes 63 bits
const uint64_t kCellTop = (uint64_t{1} << kCellBits) - 1;

struct GridItem {
    uint64_t cell;
    uint32_t index;
};

// A cell's coordinate along one axis, clamped to [0, kCellTop] (clamping keeps cells next
// to each other next to each other, so no neighbour is missed; a clamped cell only holds
// more points).
inline uint64_t cell_coordinate(double offset, double side) {
    const double c = std::floor(offset / side);
    if (!(c > 0)) return 0;
    return c < static_cast<double>(kCellTop) ? static_cast<uint64_t>(c) : kCellTop;
}

inline uint64_t cell_key(uint64_t x, uint64_t y, uint64_t z) {
    return (x << (2 * kCellBits)) | (y << kCellBits) | z;
}

// The grid's scratch, each array with room for every point: the items, the radix sort's
// spare, and the points' coordinates in the items' order.
struct CellScratch {
    GridItem* items;
    GridItem* spare;
    Vec3* sorted;
};

// One allocation sequence for the call and for reconstruct_workspace_size().
inline CellScratch allocate_cell_scratch(Arena& arena, size_t count) {
    CellScratch g;
    g.items = arena.alloc<GridItem>(count);
    g.spare = arena.alloc<GridItem>(count);
    g.sorted = arena.alloc<Vec3>(count);
    return g;
}

// Sorts items[0 .. n) by key (ties in their given order; the result may be in either
// array: the pointers are swapped as the passes go). An LSD radix sort, a byte a pass,
// skipping the bytes that every key shares: `any` and `every` are the keys' bitwise or
// and and.
inline void sort_items(GridItem*& items, GridItem*& spare, size_t n, uint64_t any, uint64_t every) {
    for (uint32_t shift = 0; shift < 64; shift += 8) {
        if ((((any ^ every) >> shift) & 0xFFu) == 0) continue;
        size_t histogram[256] = {};
        for (size_t i = 0; i < n; ++i) ++histogram[(items[i].cell >> shift) & 0xFFu];
        size_t total = 0;
        for (size_t& h : histogram) {
            const size_t c = h;
            h = total;
            total += c;
        }
        for (size_t i = 0; i < n; ++i) spare[histogram[(items[i].cell >> shift) & 0xFFu]++] = items[i];
        GridItem* t = items;
        items = spare;
        spare = t;
    }
}

// The valid points in g.items, sorted by their cell of side `side` from `low` and by index
// within a cell; returns their count. Most key bytes are shared: a grid rarely spans more
// than 2^8 cells an axis.
inline size_t sort_into_cells(const CloudReader& reader, size_t count, Vec3 low, double side,
                              CellScratch& g) {
    size_t n = 0;
    uint64_t any = 0, every = ~uint64_t{0};
    for (size_t i = 0; i < count; ++i) {
        if (!reader.valid(i)) continue;
        const Vec3 p = reader.point(i);
        const uint64_t cell = cell_key(cell_coordinate(p.x - low.x, side),
                                       cell_coordinate(p.y - low.y, side),
                                       cell_coordinate(p.z - low.z, side));
        g.items[n++] = {cell, static_cast<uint32_t>(i)};
        any |= cell;
        every &= cell;
    }
    sort_items(g.items, g.spare, n, any, every);
    return n;
}

// The first item at or after `cell`, searched from items[from] outward (from < count):
// the steps double until they pass it, then halve. The cells around a point's lie near it
// in the array, so the search stays in memory the point's cell brought in.
inline size_t first_in_cell(const GridItem* items, size_t count, uint64_t cell, size_t from) {
    size_t lo = from, hi = from;  // the answer lies in [lo, hi] once the steps pass it
    if (items[from].cell < cell) {
        for (size_t step = 1; hi < count && items[hi].cell < cell; step *= 2) {
            lo = hi + 1;
            hi = count - from > step ? from + step : count;
        }
    } else {
        for (size_t step = 1; lo > 0 && items[lo - 1].cell >= cell; step *= 2) {
            hi = lo - 1;
            lo = from > step ? from - step : 0;
        }
    }
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (items[mid].cell < cell) lo = mid + 1; else hi = mid;
    }
    return lo;
}

// The ranges of `items` in the 27 cells around `cell` (fewer at the grid's edges): a cell's
// neighbours along z follow it in key order, so they are 9 ranges, one per row, the
// cell's own row first (its points are the nearest candidates when few are looked at).
struct CellBlock {
    size_t begin[9], end[9];
    uint32_t count;
    size_t points() const {
        size_t n = 0;
        for (uint32_t k = 0; k < count; ++k) n += end[k] - begin[k];
        return n;
    }
};

// `member` is an item of `cell`. With `fingers` (18 valid positions, updated), each range
// end is searched from where the same end was found last: a caller that goes through cells
// in key order then finds each a few items on.
inline CellBlock block_around(const GridItem* items, size_t count, size_t member,
                              size_t* fingers = nullptr) {
    const uint64_t cell = items[member].cell;
    CellBlock b;
    b.count = 0;
    const uint64_t x = cell >> (2 * kCellBits), y = (cell >> kCellBits) & kCellTop, z = cell & kCellTop;
    const uint64_t z_low = z > 0 ? z - 1 : 0, z_high = z < kCellTop ? z + 1 : kCellTop;
    for (uint32_t m = 0; m < 9; ++m) {
        const uint32_t k = (m + 4) % 9;  // 4: the row (x, y) itself
        const uint64_t row_x = x + k % 3, row_y = y + k / 3;  // x - 1 .. x + 1, shifted by one
        if (row_x < 1 || row_x - 1 > kCellTop || row_y < 1 || row_y - 1 > kCellTop) continue;
        size_t* finger = fingers ? fingers + 2 * k : nullptr;
        b.begin[b.count] = first_in_cell(items, count, cell_key(row_x - 1, row_y - 1, z_low),
                                         finger ? finger[0] : member);
        b.end[b.count] = first_in_cell(items, count, cell_key(row_x - 1, row_y - 1, z_high) + 1,
                                       finger ? finger[1] : member);
        if (finger) {
            finger[0] = b.begin[b.count] < count ? b.begin[b.count] : count - 1;
            finger[1] = b.end[b.count] < count ? b.end[b.count] : count - 1;
        }
        if (b.end[b.count] > b.begin[b.count]) ++b.count;
    }
    return b;
}

// The samples of the scale measures are taken by a hash of the coordinates, about one
// point in `step`, so that they do not depend on the order of the points.
inline uint32_t sample_step(size_t count, size_t most) {
    const size_t step = count > most ? (count + most - 1) / most : 1;
    return step < UINT32_MAX ? static_cast<uint32_t>(step) : UINT32_MAX;
}

inline bool sampled_point(Vec3 p, uint32_t step) {
    double z = p.z + 0.0;
    uint64_t bz;
    std::memcpy(&bz, &z, sizeof bz);
    const uint32_t h = mix32(coordinate_hash(p.x, p.y) ^ static_cast<uint32_t>(bz) ^
                             mix32(static_cast<uint32_t>(bz >> 32)));
    return step == 1 || h % step == 0;
}

// The distance that nine points in ten do not exceed to their nearest distinct point, as
// the top of its half-octave; 0 when more than a tenth find none within a cell. Measured
// on about `most_sampled` points (see sample_step): a decile needs no more.
inline double nearest_distance_decile(const CloudReader& reader, const CellScratch& g,
                                      size_t count, double side, size_t most_sampled) {
    const GridItem* items = g.items;
    for (size_t i = 0; i < count; ++i) g.sorted[i] = reader.point(items[i].index);
    const uint32_t step = sample_step(count, most_sampled);
    size_t histogram[kNearestBins] = {}, sampled = 0;
    for (size_t first = 0; first < count;) {
        size_t last = first;
        while (last < count && items[last].cell == items[first].cell) ++last;
        bool has_block = false;
        CellBlock block;
        for (size_t i = first; i < last; ++i) {
            const Vec3 p = g.sorted[i];
            if (!sampled_point(p, step)) continue;
            if (!has_block) block = block_around(items, count, first);
            has_block = true;
            ++sampled;
            double nearest = side * side;
            uint32_t seen = 0;
            for (uint32_t k = 0; k < block.count && seen < kNearestCandidates; ++k)
                for (size_t j = block.begin[k]; j < block.end[k] && seen < kNearestCandidates; ++j) {
                    const Vec3 d = g.sorted[j] - p;
                    const double q = dot(d, d);
                    ++seen;
                    if (q > 0 && q < nearest) nearest = q;  // not itself, nor a duplicate
                }
            int e = 0;
            std::frexp(nearest / (side * side), &e);  // in [2^(e-1), 2^e): e <= 0 if found
            const uint32_t bin = e > 0 ? kNearestBins - 1
                                : static_cast<uint32_t>(-e) < kNearestBins - 2 ? static_cast<uint32_t>(-e)
                                                                               : kNearestBins - 2;
            ++histogram[bin];
        }
        first = last;
    }
    size_t above = histogram[kNearestBins - 1];
    if (10 * above > sampled) return 0;
    for (uint32_t b = 0; b + 1 < kNearestBins; ++b) {
        above += histogram[b];
        if (10 * above > sampled) return side * std::sqrt(std::ldexp(1.0, -static_cast<int>(b)));
    }
    return side * std::sqrt(std::ldexp(1.0, -static_cast<int>(kNearestBins - 2)));
}

// The valid points' bounding box and count.
struct CloudBox {
    Vec3 low, high;
    size_t valid;
};

inline CloudBox box_of(const CloudReader& reader, size_t count) {
    CloudBox box = {{DBL_MAX, DBL_MAX, DBL_MAX}, {-DBL_MAX, -DBL_MAX, -DBL_MAX}, 0};
    for (size_t i = 0; i < count; ++i) {
        if (!reader.valid(i)) continue;
        const Vec3 p = reader.point(i);
        const Vec3 lo = box.low, hi = box.high;
        box.low = {p.x < lo.x ? p.x : lo.x, p.y < lo.y ? p.y : lo.y, p.z < lo.z ? p.z : lo.z};
        box.high = {p.x > hi.x ? p.x : hi.x, p.y > hi.y ? p.y : hi.y, p.z > hi.z ? p.z : hi.z};
        ++box.valid;
    }
    return box;
}

// The cloud's scale d (see "outliers" above): the distance that nine points in ten do not
// exceed to their nearest distinct point, on grids of cells of about 4 points; 0 where no
// grid serves. A box wider than the double range (points near +-1e308) gives an infinite
// side, which is refused: such a cloud has no scale.
// Where one cell of the grid (items sorted by cell) holds more than half the points: the
// cell side that spreads its points as nearest_spacing spreads the whole cloud's first
// (from its points' own box); 0 otherwise, or if they are all at one place.
inline double crowded_cell_side(const CloudReader& reader, const GridItem* items, size_t n) {
    for (size_t first = 0; first < n;) {
        size_t last = first;
        while (last < n && items[last].cell == items[first].cell) ++last;
        if (2 * (last - first) > n) {
            Vec3 low = reader.point(items[first].index), high = low;
            for (size_t i = first + 1; i < last; ++i) {
                const Vec3 p = reader.point(items[i].index);
                low = {p.x < low.x ? p.x : low.x, p.y < low.y ? p.y : low.y, p.z < low.z ? p.z : low.z};
                high = {p.x > high.x ? p.x : high.x, p.y > high.y ? p.y : high.y,
                        p.z > high.z ? p.z : high.z};
            }
            const Vec3 half = scaled(high, 0.5) - scaled(low, 0.5);
            return 4 * std::sqrt(dot(half, half)) / std::sqrt(static_cast<double>(last - first));
        }
        first = last;
    }
    return 0;
}

inline double nearest_spacing(const CloudReader& reader, size_t count, const CloudBox& box,
                              CellScratch& g, size_t most_sampled) {
    const Vec3 half = scaled(box.high - box.low, 0.5);
    double side = 4 * std::sqrt(dot(half, half)) / std::sqrt(static_cast<double>(box.valid));
    double nearest = 0;
    for (uint32_t tries = 0; nearest == 0 && tries < kGridTries; ++tries) {
        if (!(side * side > 0) || !is_finite(side * side)) break;
        const size_t n = sort_into_cells(reader, count, box.low, side, g);
        size_t occupied = 0;
        for (size_t i = 0; i < n; ++i) occupied += i == 0 || g.items[i].cell != g.items[i - 1].cell;
        if (n > kCrowdedCell * occupied) {  // as on a surface: cells of 4 points on average
            const double shrink = std::sqrt(4 * static_cast<double>(occupied) / static_cast<double>(n));
            side *= shrink > 0.0625 ? shrink : 0.0625;
            // Most points in one cell, far smaller than the whole (a speck far away set the
            // box): the cells follow that cell's own points instead.
            const double crowd = crowded_cell_side(reader, g.items, n);
            if (crowd > 0 && crowd < side) side = crowd;
            continue;
        }
        nearest = nearest_distance_decile(reader, g, n, side, most_sampled);
        side *= 4;
    }
    return nearest;
}

// Marks the outliers in `dropped` (zeroed, a bit per point) and returns how many; from
// here on reader.valid() leaves them out. See "outliers" above.
inline size_t drop_outliers_of(CloudReader& reader, size_t count, unsigned char* dropped,
                               CellScratch& g) {
    reader.dropped = dropped;
    size_t total = 0;
    for (uint32_t round = 0; round < kOutlierRounds; ++round) {
        const CloudBox box = box_of(reader, count);
        if (box.valid < 2 * kOutlierNeighbours) break;
        const double nearest = nearest_spacing(reader, count, box, g, kDecileSample);
        if (!(nearest > 0)) break;
        const size_t n = sort_into_cells(reader, count, box.low, kOutlierReach * nearest, g);
        const GridItem* items = g.items;
        size_t found = 0;
        for (size_t first = 0; first < n;) {
            size_t last = first;
            while (last < n && items[last].cell == items[first].cell) ++last;
            if (block_around(items, n, first).points() < kOutlierNeighbours)
                for (size_t i = first; i < last; ++i) {
                    dropped[items[i].index >> 3] |= static_cast<unsigned char>(1u << (items[i].index & 7));
                    ++found;
                }
            first = last;
        }
        total += found;
        if (found == 0) break;
    }
    return total;
}

// Coordinates in the reconstruction frame: (x, y) across the axis, h along it.
struct Local {
    double x, y, h;
};

struct Frame {
    Vec3 origin, e1, e2, axis;  // (e1, e2, axis) is right-handed and orthonormal
    // A power of two that brings the cloud's extent near 1, so that squared distances
    // neither overflow (a cloud at 1e200) nor underflow (at 1e-200); being a power of two,
    // it changes no rounding and the triangles do not depend on it.
    double scale;
    // Set when the cloud spans more than the largest double (coordinates of both signs
    // near 1e308): p - origin would overflow, so halves are subtracted instead.
    bool halved;
    Vec3 half_origin;
    // Layers are flipped on the surface (the surface_flips flag; see "flips on the surface"
    // in >>layer triangulation).
    bool surface_flips;
    // The surface's ends (kLowPole, kHighPole) never taken for a closed one: both with the
    // open_ends flag, the end of a branch at its cut (see mesh_parts); 0 without kClosedEnds.
    uint32_t cut_ends;
    // The valid points' lowest and highest coordinates (set by choose_frame with kFastLoops).
    Vec3 low, high;
    // The cloud's own extent over the frame's, which also covers the way to a given origin:
    // 1 without origin_given.
    double cloud_share;
    // (p - origin) * scale, without overflow.
    Vec3 offset(Vec3 p) const {
        if (halved) return scaled(scaled(p, 0.5) - half_origin, 2 * scale);
        return scaled(p - origin, scale);
    }
    Local local(Vec3 p) const {
        Vec3 d = offset(p);
        return {dot(d, e1), dot(d, e2), dot(d, axis)};
    }
    // local(p).h alone, the same bits.
    double height(Vec3 p) const { return dot(offset(p), axis); }
    // A frame height back as the user's coordinate along the axis, dot(point, axis).
    double user_height(double h) const { return h / scale + dot(origin, axis); }
};

// The power of two 2^-e with 2^e just above `extent`, within [2^-1000, 2^1000].
inline double scale_for_extent(double extent) {
    if (!(extent > 0) || !is_finite(extent)) return 1;
    int exponent = 0;
    std::frexp(extent, &exponent);
    if (exponent > 1000) exponent = 1000;
    if (exponent < -1000) exponent = -1000;
    return std::ldexp(1.0, -exponent);
}

// False unless v's squared length is a normal double (v's length between about 1.5e-154
// and 1.3e154): a subnormal square has lost the bits that make the result unit.
inline double largest_of(Vec3 v) {
    const double xy = v.x > v.y ? v.x : v.y;
    return xy > v.z ? xy : v.z;
}

inline bool normalize(Vec3& v) {
    const double square = dot(v, v);
    if (!(square >= DBL_MIN) || !is_finite(square)) return false;
    const double len = std::sqrt(square);
    v = scaled(v, 1.0 / len);
    return true;
}

// A direction of any finite non-zero length made unit: first scaled by the power of two
// that brings its largest component into [1, 2) (exact: a component that falls below the
// smallest subnormal is negligible beside it), so that its square neither overflows nor
// underflows. False for zero, NaN or infinite components.
inline bool unit_direction(Vec3& v) {
    if (!is_finite(v.x) || !is_finite(v.y) || !is_finite(v.z)) return false;
    const double largest = largest_of({abs_value(v.x), abs_value(v.y), abs_value(v.z)});
    if (largest == 0) return false;
    int exponent = 0;
    std::frexp(largest, &exponent);
    v = {std::ldexp(v.x, 1 - exponent), std::ldexp(v.y, 1 - exponent), std::ldexp(v.z, 1 - exponent)};
    return normalize(v);
}

// The principal direction of a symmetric 3x3 matrix by power iteration from its largest
// column; a fixed number of steps keeps the cost bounded and the result deterministic.
inline Vec3 principal_direction(const double m[3][3]) {
    Vec3 cols[3] = {{m[0][0], m[1][0], m[2][0]}, {m[0][1], m[1][1], m[2][1]},
                    {m[0][2], m[1][2], m[2][2]}};
    Vec3 v = cols[0];
    for (const Vec3& c : cols)
        if (dot(c, c) > dot(v, v)) v = c;
    if (!normalize(v)) return {0, 0, 1};
    for (int step = 0; step < 100; ++step) {
        Vec3 w = {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
                  m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                  m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
        if (!normalize(w)) break;
        v = w;
    }
    // The sign of an eigenvector is arbitrary: point it along its largest component.
    double big = v.x;
    if (abs_value(v.y) > abs_value(big)) big = v.y;
    if (abs_value(v.z) > abs_value(big)) big = v.z;
    return big < 0 ? scaled(v, -1.0) : v;
}

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

inline CloudSums sum_cloud(const CloudReader& cloud, size_t count) {
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

// The frame of the points summed in `sums`: centroid origin, axis from the options (an
// explicit one: Axis::automatic is resolved before, see choose_axis), e1/e2 completing it.
// How far a given origin may lie from the cloud's bounding box, per coordinate, in
// multiples of the box's largest side. Seen from farther, the whole cloud lies within
// 2^-32 radians of one direction and its offsets from the origin keep fewer than 21 of
// their 53 bits for the cloud's own shape: no unrolling around it means anything.
const double kOriginReach = 0x1p32;

// Whether `origin` lies within kOriginReach times the largest side of the box [low, high]
// of it (halves, so that nothing overflows). A box of one point reaches everywhere.
inline bool origin_in_reach(Vec3 origin, Vec3 low, Vec3 high) {
    const Vec3 half_low = scaled(low, 0.5), half_high = scaled(high, 0.5);
    const Vec3 half_origin = scaled(origin, 0.5);
    const Vec3 side = half_high - half_low;
    const Vec3 below = half_low - half_origin, above = half_origin - half_high;
    const Vec3 way = {below.x > above.x ? below.x : above.x, below.y > above.y ? below.y : above.y,
                      below.z > above.z ? below.z : above.z};
    const double reach = largest_of(side);
    return reach == 0 || largest_of(way) <= kOriginReach * reach;
}

// Why a given origin (origin_given) cannot serve as the frame's, or null if it can: it is
// NaN or infinite, or lies beyond kOriginReach of the valid points summed in `sums`.
inline const char* origin_refusal(const Options& options, const CloudSums& sums) {
    if (!(options.flags & origin_given)) return nullptr;
    const Vec3 given = {options.origin[0], options.origin[1], options.origin[2]};
    if (!(is_finite(given.x) && is_finite(given.y) && is_finite(given.z)))
        return "the given origin is NaN or infinite";
    const Vec3 low = {sums.lowest[0], sums.lowest[1], sums.lowest[2]};
    const Vec3 high = {sums.highest[0], sums.highest[1], sums.highest[2]};
    if (sums.valid > 0 && !origin_in_reach(given, low, high))
        return "the given origin lies farther from the cloud than 2^32 times the cloud's size: "
               "no unrolling around it means anything (give a nearer origin, or none)";
    return nullptr;
}

inline Status choose_frame(const CloudSums& sums, const Options& options, Frame& frame) {
    const size_t valid = sums.valid;
    const Vec3 sum = {sums.total[0], sums.total[1], sums.total[2]};
    const Vec3 small_sum = {sums.small_total[0], sums.small_total[1], sums.small_total[2]};
    const Vec3 low = {sums.lowest[0], sums.lowest[1], sums.lowest[2]};
    const Vec3 high = {sums.highest[0], sums.highest[1], sums.highest[2]};
    if (kFastLoops) {
        frame.low = low;
        frame.high = high;
    }
    if (!(is_finite(sum.x) && is_finite(sum.y) && is_finite(sum.z)))
        frame.origin = scaled(scaled(small_sum, 1.0 / static_cast<double>(valid)), 0x1p40);
    else
        frame.origin = valid ? scaled(sum, 1.0 / static_cast<double>(valid)) : Vec3{0, 0, 0};
    Vec3 size = valid ? high - low : Vec3{0, 0, 0};
    Vec3 half_size = valid ? scaled(high, 0.5) - scaled(low, 0.5) : Vec3{0, 0, 0};
    const double own_half_extent = largest_of(half_size);
    if (options.flags & origin_given) {
        if (origin_refusal(options, sums)) return Status::invalid_origin;
        const Vec3 given = {options.origin[0], options.origin[1], options.origin[2]};
        // The extent covers the way from the given origin to the cloud, so the frame's
        // coordinates stay near 1 however far the origin is.
        Vec3 way = scaled(frame.origin, 0.5) - scaled(given, 0.5);
        way = {abs_value(way.x), abs_value(way.y), abs_value(way.z)};
        half_size = {half_size.x + way.x, half_size.y + way.y, half_size.z + way.z};
        size = {size.x + 2 * way.x, size.y + 2 * way.y, size.z + 2 * way.z};
        frame.origin = given;
    }
    const double half_extent = largest_of(half_size);
    frame.cloud_share = half_extent > 0 ? own_half_extent / half_extent : 1;
    frame.halved = !(is_finite(size.x) && is_finite(size.y) && is_finite(size.z));
    if (frame.halved) size = half_size;
    frame.half_origin = scaled(frame.origin, 0.5);
    double extent = size.x > size.y ? size.x : size.y;
    if (size.z > extent) extent = size.z;
    frame.scale = scale_for_extent(extent) * (frame.halved ? 0.5 : 1.0);
    Vec3 axis = {0, 0, 1};
    switch (options.axis) {
    case Axis::x: axis = {1, 0, 0}; break;
    case Axis::y: axis = {0, 1, 0}; break;
    case Axis::z: axis = {0, 0, 1}; break;
    case Axis::direction:
        axis = {options.direction[0], options.direction[1], options.direction[2]};
        if (!unit_direction(axis)) return Status::invalid_axis;
        break;
    default: return Status::invalid_axis;
    }
    // e1: the coordinate axis least aligned with the stacking axis, made orthogonal.
    Vec3 helper = {1, 0, 0};
    if (abs_value(axis.x) > abs_value(axis.y) || abs_value(axis.x) > abs_value(axis.z))
        helper = abs_value(axis.y) < abs_value(axis.z) ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
    Vec3 e1 = cross(helper, axis);
    if (!normalize(e1)) return Status::invalid_axis;
    frame.axis = axis;
    frame.surface_flips = kSurfaceFlips && (options.flags & surface_flips);
    frame.cut_ends = kClosedEnds && (options.flags & open_ends) ? closed_bottom | closed_top : 0u;
    frame.e1 = e1;
    frame.e2 = cross(axis, e1);
    return Status::ok;
}

// Layer boundaries: bounds[0] = lowest height, bounds[count] = highest, layer i holds the
// heights in [bounds[i] - tolerance, bounds[i+1] - tolerance) (the last layer includes its
// top). The tolerance (2^-40 of the height range) puts a point that lies on a cut up to
// rounding into the layer above, as one exactly on it: with a tilted axis the heights of
// a planar contour (a CT slice, a scan row) differ in their last bits, and a cut on that
// plane would otherwise split the contour between two layers.
struct LayerPlan {
    double* bounds;
    uint32_t count;
    double tolerance;
};

const double kCutTolerance = 0x1p-40;

const size_t kMaxAutomaticLayers = 256;
// Heights are divided by at least layer height / kMaxTurns when unrolled, so exp() stays
// far from overflow and the annulus from extreme ratios in very tall, thin layers; a layer
// up to kMaxTurns radii tall unrolls undistorted (see >>unroll).
const double kMaxTurns = 24.0;
// A layer with fewer points is merged with the next one (the last layer only needs 3).
const size_t kMinLayerPoints = 16;
// A layer also needs about one and a half rows of points: thinner ones make bands of a few
// points that fold and cross. With n points over height h around radius r (the layer's
// own), the spacing is about sqrt(2 pi r h / n), so the rows number sqrt(h n / (2 pi r)).
// A stack of planar contours one per layer, as far apart as a few point spacings along the
// contour, passes.
const double kMinLayerRows = 1.5;

inline bool thick_enough(size_t points, double height, double radius) {
    const double two_pi = 6.28318530717958647693;
    return static_cast<double>(points) * height >= kMinLayerRows * kMinLayerRows * two_pi * radius;
}

// The number of layers the options can ask for, before empty layers are dropped.
inline size_t planned_layer_limit(size_t point_count, const Options& options) {
    if (options.cuts && options.cut_count > 0) return options.cut_count + 1;
    if (options.layer_count > 0)
        return options.layer_count < point_count ? options.layer_count : (point_count > 0 ? point_count : 1);
    // A target height: never more layers than points.
    if (options.layer_height > 0) return point_count > 0 ? point_count : 1;
    return kMaxAutomaticLayers;
}

inline Status validate_layer_options(const Options& options) {
    if (options.cuts && options.cut_count > 0) {
        if (options.cut_count > kMaxPoints) return Status::invalid_layers;
        for (size_t i = 0; i < options.cut_count; ++i)
            if (!is_finite(options.cuts[i])) return Status::invalid_layers;
    } else if (options.cut_count > 0) {
        return Status::invalid_argument;
    }
    if (!is_finite(options.layer_height) || options.layer_height < 0)
        return Status::invalid_layers;
    return Status::ok;
}

inline bool automatic_layers(const Options& options) {
    return !(options.cuts && options.cut_count > 0) && options.layer_count == 0 &&
           options.layer_height == 0;
}

// Fills plan.bounds (room for planned_layer_limit + 1 entries) for heights [lo, hi] from
// the user's layer options (not automatic_layers): the cuts are coordinates along the axis
// (Frame::user_height of frame heights), layer_height a length in the cloud's units.
inline void plan_layers(const Options& options, double lo, double hi, size_t point_count,
                        const Frame& frame, LayerPlan& plan) {
    const double cut_offset = dot(frame.origin, frame.axis);
    double* b = plan.bounds;
    uint32_t n = 0;
    b[n++] = lo;
    if (options.cuts && options.cut_count > 0) {
        // The cuts inside (lo, hi], sorted, repeats dropped.
        size_t inside = 0;
        for (size_t i = 0; i < options.cut_count; ++i) {
            double c = (options.cuts[i] - cut_offset) * frame.scale;
            if (c > lo && c <= hi) b[1 + inside++] = c;
        }
        heap_sort(b + 1, inside);
        for (size_t i = 0; i < inside; ++i)
            if (b[1 + i] > b[n - 1]) b[n++] = b[1 + i];
    } else {
        double height = hi - lo;
        double layers = 1;
        if (options.layer_count > 0) {
            layers = options.layer_count;
        } else if (options.layer_height > 0) {
            layers = std::ceil(height / (options.layer_height * frame.scale));
        }
        double limit = static_cast<double>(point_count);
        if (!(layers >= 1)) layers = 1;
        if (layers > limit) layers = limit;
        uint32_t count = static_cast<uint32_t>(layers);
        for (uint32_t i = 1; i < count; ++i) {
            double c = lo + height * (static_cast<double>(i) / static_cast<double>(count));
            if (c > b[n - 1] && c < hi) b[n++] = c;
        }
    }
    b[n] = hi;
    plan.count = n;
}

// ---- automatic layers ----------------------------------------------------------------------
//
// The paper's layering rule, made mechanical. The cloud's height range is cut into equal
// bins (about 256 points each, at most kMaxAutomaticLayers); each bin gets its centroid
// across the axis, its mean radius around that centroid and its inner radius (the smallest
// of kProfileSectors sector-mean radii: the cross-section holds a disc about that wide
// around its centroid when it is star-shaped). Then, starting from one layer over
// everything:
//   - a layer is well unrolled when one centre line serves all its cross-sections (every
//     bin's centroid lies within kCentreDrift inner radii of the layer's centre, the
//     count-weighted mean of its bins' centroids, give or take three standard errors of
//     the bin's centroid, so sampling noise alone never cuts) and it is at most kMaxTurns
//     mean radii
//     tall (taller layers unroll with distorted aspect), and it holds at most an eighth of
//     the points (kLayerPointsShare), or kFewestLayerPoints if that is more, so that a
//     large cloud comes in layers that a job runner can triangulate side by side, the same
//     layers whatever the runner;
//   - a layer that is not is cut in two at the bin boundary where the surface changes
//     least: the smallest sum of centroid drift and radius change between the two bins
//     (relative to the radius), plus a penalty where the bins are denser than average, so
//     dense detailed parts (a face, a joint) stay inside one layer. Only boundaries that
//     leave each side a quarter of the layer's bins are candidates, so the splitting
//     depth stays logarithmic.
// The result is the fewest layers that pass, cut where the shape is calm; O(n) passes over
// the points plus O(bins^2) on the profile, deterministic.

const uint32_t kProfileSectors = 8;
const double kCentreDrift = 0.75;
const size_t kLayerPointsShare = 8;
const size_t kFewestLayerPoints = size_t{1} << 16;
const size_t kPointsPerProfileBin = 256;
const double kDensityWeight = 0.5;

struct ProfileBin {
    uint32_t count;
    uint32_t sectors_seen;                  // direction sectors holding a point
    double cx, cy;                          // centroid across the axis
    double mean_radius, inner_radius;       // around the centroid (inner: occupied sectors)
    double square_sum;                      // sum of squared distances from the centroid
    double sector_sum[kProfileSectors];     // sum of distances per direction sector
    uint32_t sector_count[kProfileSectors];
};

// A range of bins [first, end) waiting to be judged.
struct BinRange {
    uint32_t first, end;
};

inline uint32_t profile_bin_count(size_t valid_points) {
    size_t bins = valid_points / kPointsPerProfileBin;
    if (bins > kMaxAutomaticLayers) bins = kMaxAutomaticLayers;
    return bins < 1 ? 1u : static_cast<uint32_t>(bins);
}

// The scratch the automatic planner takes (released before the layers are built).
inline void allocate_profile(Arena& arena, uint32_t bins, ProfileBin** profile, BinRange** ranges,
                             double** cuts) {
    *profile = arena.alloc<ProfileBin>(bins);
    *ranges = arena.alloc<BinRange>(bins);
    *cuts = arena.alloc<double>(bins);
}

inline uint32_t sector_of(double dx, double dy) {
    uint32_t s = (dx < 0 ? 4u : 0u) + (dy < 0 ? 2u : 0u);
    return s + (abs_value(dx) < abs_value(dy) ? 1u : 0u);
}

inline void build_profile(const CloudReader& cloud, size_t count, const Frame& frame, double lo,
                          double hi, ProfileBin* profile, uint32_t bins) {
    std::memset(static_cast<void*>(profile), 0, sizeof(ProfileBin) * bins);
    const double per_height = static_cast<double>(bins) / (hi - lo);
    auto bin_of = [&](double h) {
        double b = (h - lo) * per_height;
        return b >= static_cast<double>(bins - 1) ? bins - 1 : (b > 0 ? static_cast<uint32_t>(b) : 0u);
    };
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        Local p = frame.local(cloud.point(i));
        ProfileBin& bin = profile[bin_of(p.h)];
        ++bin.count;
        bin.cx += p.x;
        bin.cy += p.y;
    }
    for (uint32_t b = 0; b < bins; ++b) {
        if (profile[b].count == 0) continue;
        profile[b].cx /= profile[b].count;
        profile[b].cy /= profile[b].count;
    }
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        Local p = frame.local(cloud.point(i));
        ProfileBin& bin = profile[bin_of(p.h)];
        double dx = p.x - bin.cx, dy = p.y - bin.cy;
        uint32_t s = sector_of(dx, dy);
        bin.sector_sum[s] += std::sqrt(dx * dx + dy * dy);
        bin.square_sum += dx * dx + dy * dy;
        ++bin.sector_count[s];
    }
    for (uint32_t b = 0; b < bins; ++b) {
        ProfileBin& bin = profile[b];
        double total = 0, inner = DBL_MAX;
        for (uint32_t s = 0; s < kProfileSectors; ++s) {
            total += bin.sector_sum[s];
            if (bin.sector_count[s] == 0) continue;
            ++bin.sectors_seen;
            double mean = bin.sector_sum[s] / bin.sector_count[s];
            if (mean < inner) inner = mean;
        }
        bin.mean_radius = bin.count ? total / bin.count : 0.0;
        bin.inner_radius = bin.count ? inner : 0.0;
    }
}

inline bool well_unrolled(const ProfileBin* profile, BinRange range, double bin_height,
                          size_t most_points) {
    double cx = 0, cy = 0, radius = 0;
    size_t points = 0;
    for (uint32_t b = range.first; b < range.end; ++b) {
        cx += profile[b].cx * profile[b].count;
        cy += profile[b].cy * profile[b].count;
        radius += profile[b].mean_radius * profile[b].count;
        points += profile[b].count;
    }
    if (points == 0) return true;
    cx /= static_cast<double>(points);
    cy /= static_cast<double>(points);
    radius /= static_cast<double>(points);
    if (bin_height * (range.end - range.first) > kMaxTurns * radius) return false;
    if (points > most_points) return false;
    for (uint32_t b = range.first; b < range.end; ++b) {
        // Too few points to say, or an arc rather than a ring (the slanted end of a scan):
        // such a bin's centroid says nothing about where the centre line must run.
        if (profile[b].count < kPointsPerProfileBin / 4 || profile[b].sectors_seen < kProfileSectors)
            continue;
        double dx = profile[b].cx - cx, dy = profile[b].cy - cy;
        double standard_error = std::sqrt(profile[b].square_sum / (2.0 * profile[b].count * profile[b].count));
        double limit = kCentreDrift * profile[b].inner_radius + 3 * standard_error;
        if (dx * dx + dy * dy > limit * limit) return false;
    }
    return true;
}

// How much the surface changes between bins b - 1 and b, plus the density penalty.
inline double cut_cost(const ProfileBin* profile, uint32_t b, double mean_count) {
    const ProfileBin& below = profile[b - 1];
    const ProfileBin& above = profile[b];
    double radius = below.mean_radius > above.mean_radius ? below.mean_radius : above.mean_radius;
    if (!(radius > 0)) return 0;  // an empty stretch: the calmest place of all
    double dx = above.cx - below.cx, dy = above.cy - below.cy;
    double change = (std::sqrt(dx * dx + dy * dy) + abs_value(above.mean_radius - below.mean_radius)) / radius;
    double density = (below.count + above.count) / (2 * mean_count) - 1;
    return change + (density > 0 ? kDensityWeight * density : 0.0);
}

// Fills plan.bounds for heights [lo, hi] by the rule above; profile, ranges and cuts hold
// `bins` entries each.
inline void plan_automatic_layers(const CloudReader& cloud, size_t count, size_t valid,
                                  const Frame& frame, double lo, double hi, ProfileBin* profile,
                                  BinRange* ranges, double* cuts, uint32_t bins, LayerPlan& plan) {
    build_profile(cloud, count, frame, lo, hi, profile, bins);
    const double bin_height = (hi - lo) / bins;
    const double mean_count = static_cast<double>(valid) / bins;
    const size_t share = valid / kLayerPointsShare;
    const size_t most_points = share > kFewestLayerPoints ? share : kFewestLayerPoints;
    size_t pending = 0, cut_count = 0;
    ranges[pending++] = {0, bins};
    while (pending > 0) {
        BinRange r = ranges[--pending];
        uint32_t width = r.end - r.first;
        if (width < 2 || well_unrolled(profile, r, bin_height, most_points)) continue;
        uint32_t margin = width / 4 > 0 ? width / 4 : 1;
        uint32_t best = r.first + margin;
        double best_cost = DBL_MAX;
        for (uint32_t b = r.first + margin; b <= r.end - margin; ++b) {
            double cost = cut_cost(profile, b, mean_count);
            if (cost < best_cost) {
                best_cost = cost;
                best = b;
            }
        }
        cuts[cut_count++] = lo + bin_height * best;
        // Each split turns one range into two, so at most `bins` are ever pending.
        ranges[pending++] = {r.first, best};
        ranges[pending++] = {best, r.end};
    }
    heap_sort(cuts, cut_count);
    double* bounds = plan.bounds;
    uint32_t n = 0;
    bounds[n++] = lo;
    for (size_t i = 0; i < cut_count; ++i)
        if (cuts[i] > bounds[n - 1] && cuts[i] < hi) bounds[n++] = cuts[i];
    bounds[n] = hi;
    plan.count = n;
}

// The layer of height h: the last k with h >= bounds[k] - tolerance, or 0. `per_height` is
// count / (bounds[count] - bounds[0]). With kFastLoops, the layer h would be in if the
// layers were equal, which they are unless cuts or the automatic plan set them, is tried
// first, with one branch that a million points in no order still predict (a binary
// search's would not); the search is for the rest.
inline uint32_t layer_of(const LayerPlan& plan, double h, double per_height) {
    const double* bounds = plan.bounds;
    const double tolerance = plan.tolerance;
    const uint32_t last = plan.count - 1;
    const double guess = (h - bounds[0]) * per_height;
    const uint32_t k = guess > 0 ? (guess < last ? static_cast<uint32_t>(guess) : last) : 0;
    if (kFastLoops && ((k == 0) | (h >= bounds[k] - tolerance)) &
                          ((k == last) | (h < bounds[k + 1] - tolerance)))
        return k;
    uint32_t lo = 0, hi = plan.count;  // answer in [lo, hi)
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (h >= plan.bounds[mid] - plan.tolerance)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

}  // namespace detail
}  // namespace stratmesh
