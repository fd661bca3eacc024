// >>outliers =============================================================================
// Points far from the rest of the cloud, left out with drop_outliers.

namespace stratmesh {
namespace detail {

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
static inline uint64_t cell_coordinate(double offset, double side) {
    const double c = std::floor(offset / side);
    if (!(c > 0)) return 0;
    return c < static_cast<double>(kCellTop) ? static_cast<uint64_t>(c) : kCellTop;
}

static inline uint64_t cell_key(uint64_t x, uint64_t y, uint64_t z) {
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
static inline CellScratch allocate_cell_scratch(Arena& arena, size_t count) {
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
static inline void sort_items(GridItem*& items, GridItem*& spare, size_t n, uint64_t any, uint64_t every) {
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
static inline size_t sort_into_cells(const CloudReader& reader, size_t count, Vec3 low, double side,
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
static inline size_t first_in_cell(const GridItem* items, size_t count, uint64_t cell, size_t from) {
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

// The items of the cells around `cell` (empty or not), searched from items[hint]. With
// `fingers` (18 valid positions, updated), each range end is searched from where the same
// end was found last: a caller that goes through cells in key order then finds each a few
// items on.
static inline CellBlock block_of_cell(const GridItem* items, size_t count, uint64_t cell,
                                      size_t hint, size_t* fingers = nullptr) {
    const size_t member = hint;
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

// The items of the cells around items[member]'s.
static inline CellBlock block_around(const GridItem* items, size_t count, size_t member,
                                     size_t* fingers = nullptr) {
    return block_of_cell(items, count, items[member].cell, member, fingers);
}

// The samples of the scale measures are taken by a hash of the coordinates, about one
// point in `step`, so that they do not depend on the order of the points.
static inline uint32_t sample_step(size_t count, size_t most) {
    const size_t step = count > most ? (count + most - 1) / most : 1;
    return step < UINT32_MAX ? static_cast<uint32_t>(step) : UINT32_MAX;
}

static inline bool sampled_point(Vec3 p, uint32_t step) {
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
static inline double nearest_distance_decile(const CloudReader& reader, const CellScratch& g,
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

static inline CloudBox box_of(const CloudReader& reader, size_t count) {
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
static inline double crowded_cell_side(const CloudReader& reader, const GridItem* items, size_t n) {
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

static inline double nearest_spacing(const CloudReader& reader, size_t count, const CloudBox& box,
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
static inline size_t drop_outliers_of(CloudReader& reader, size_t count, unsigned char* dropped,
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

// The drop_outliers step: the bitmap stays in `arena` for the whole call (reader.dropped),
// the grid's scratch is given back. False if the workspace is too small.
static inline bool find_outliers(CloudReader& reader, size_t count, Arena& arena, Report& rep) {
    unsigned char* dropped = arena.alloc<unsigned char>(count / 8 + 1);
    const size_t mark = arena.mark();
    CellScratch g = allocate_cell_scratch(arena, count);
    if (arena.failed) return false;
    std::memset(dropped, 0, count / 8 + 1);
    rep.points.outlier_count = drop_outliers_of(reader, count, dropped, g);
    rep.points.rejected_count += rep.points.outlier_count;
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh
