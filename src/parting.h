// >>parting ==============================================================================
// find_parting(): where the cloud parts into branches.
//
// find_parting(): the cuts lie every half gap along the axis (at most one per point), and
// each point falls in the step between two of them. Two sweeps, one from the top down for
// the cuts above which the cloud parts and one from the bottom up for those below, add the
// points a step at a time to a union-find of pieces (union by size, path halving: no
// recursion), each point joining the pieces of those already added within the gap, found
// in its block of 3 x 3 x 3 grid cells of side gap. Which points lie on a cut's side is
// decided by their step, so it is the same for both sweeps and any order; within a step
// the points go in grid order, which lies in the frame with its cells sorted by height
// first, so that a point's neighbours are near in memory and their blocks were just used.
// After each step, the pieces that count are checked for branches at the cut the step
// reaches; the points within two gaps of it are those of the last four steps.

#if !defined(STRATMESH_SMALL_CODE)
namespace stratmesh {
namespace detail {

// The gap, in median nearest-neighbour distances: points of one branch lie closer, the
// branches of a fork farther apart.
const double kPartingGap = 4.0;

const uint32_t kStepsPerGap = 2;

// The points the scale (the median distance to the nearest neighbour) is measured on:
// enough for the median within a few percent.
const size_t kScaleSample = 2048;

// The blocks of the grid cells met last, by a hash of the cell: a step's points share
// cells, and each block costs 18 searches to find.
const uint32_t kBlockCacheSize = 2048;

const uint64_t kNoCell = ~uint64_t{0};  // no key: keys take 63 bits

const uint32_t kNotAdded = ~uint32_t{0};

// The most points a sweep may compare, on average per point: a surface's block of cells
// holds about 40; a cloud crowded beyond this (many repeats of the same points, a solid
// volume of points) is not searched, so that no cloud costs time quadratic in its size.
const uint64_t kPartingChecksPerPoint = 1024;

struct CachedBlock {
    uint64_t cell;
    CellBlock block;
};

// The size from which a piece of a side of `points` points counts: kSmallestBranch, and a
// twentieth of the side.
static inline uint32_t counting_size(size_t points, uint32_t smallest) {
    const size_t twentieth = (points + 19) / 20;
    return twentieth > smallest ? static_cast<uint32_t>(twentieth) : smallest;
}

// The sweep's state. Pieces are named by the order in which their root was added. A
// point's level is its height as the sweep sees it: the frame height, negated for the sweep
// from the bottom up, so that both sweeps go down and a cut's side lies above it.
// `listed` holds every root whose piece counts (see counting_size), and others that
// branches_at drops: a root joins it when its piece grows to the size that counts at that
// moment, which never exceeds the size that counts at the next cut.
struct PartingSweep {
    const Local* position;    // grid order, in the frame
    const GridItem* cells;    // grid order
    size_t count;
    double gap;               // in frame units
    double sign;              // +1 from the top, -1 from the bottom
    uint32_t* added;          // order -> grid position
    uint32_t* order_of;       // grid position -> order, or kNotAdded
    uint32_t* parent;         // order -> order
    uint32_t* size;           // root -> points
    double* lowest;           // root -> its lowest level
    double* highest;          // root -> its highest level
    CachedBlock* blocks;      // kBlockCacheSize of them
    size_t fingers[18];       // block_around's
    uint32_t* listed;         // roots, see above
    unsigned char* is_listed; // order -> whether it is in `listed`
    size_t listed_count;
    uint32_t counting;        // counting_size(points added so far)
    uint32_t smallest;        // the fewest points a branch holds (kSmallestBranch)
    uint64_t checks_left;     // see kPartingChecksPerPoint
    bool crowded;             // the checks ran out: the sweep stopped

    double level(uint32_t t) const { return sign * position[added[t]].h; }
    uint32_t root(uint32_t t) { return find_root(parent, t); }
    void join(uint32_t a, uint32_t b) {
        a = root(a);
        b = root(b);
        if (a == b) return;
        if (size[a] < size[b] || (size[a] == size[b] && b < a)) {
            const uint32_t t = a;
            a = b;
            b = t;
        }
        parent[b] = a;
        size[a] += size[b];
        if (lowest[b] < lowest[a]) lowest[a] = lowest[b];
        if (highest[b] > highest[a]) highest[a] = highest[b];
        if (size[a] >= counting && !is_listed[a]) {
            is_listed[a] = 1;
            listed[listed_count++] = a;  // at most one entry per point: `count` of room
        }
    }
    // Adds the point at grid position j as the t-th, joined to the points added before it.
    void add(uint32_t t, uint32_t j) {
        added[t] = j;
        order_of[j] = t;
        parent[t] = t;
        size[t] = 1;
        lowest[t] = highest[t] = level(t);
        is_listed[t] = 0;
        counting = counting_size(t + 1, smallest);
        const uint64_t cell = cells[j].cell;
        CachedBlock& cached = blocks[(cell * 0x9E3779B97F4A7C15u) >> 53];  // 11 bits
        if (cached.cell != cell) cached = {cell, block_around(cells, count, j, fingers)};
        const CellBlock& block = cached.block;
        const size_t checks = block.points();
        if (checks > checks_left) {
            crowded = true;
            return;
        }
        checks_left -= checks;
        const Local p = position[j];
        for (uint32_t k = 0; k < block.count; ++k)
            for (size_t i = block.begin[k]; i < block.end[k]; ++i) {
                if (order_of[i] >= t) continue;  // not added yet (or p itself)
                const Local q = position[i];
                const double dx = q.x - p.x, dy = q.y - p.y, dh = q.h - p.h;
                if (dx * dx + dy * dy + dh * dh < gap * gap) join(t, order_of[i]);
            }
    }
};

// The widest run of empty sectors (of kSectors) around a branch's centre at the cut: a
// quarter turn. An arc of a ring seen from its centroid leaves more than that open.
const uint32_t kBranchArcSectors = kSectors / 4;

// A piece that counts at a cut: its root and its points' sums within the two gaps above.
struct BranchCandidate {
    uint32_t root;
    double sum[2][2];
    uint32_t slice_points[2];
};

// Whether the `added` points added so far, on the side of the cut at level `cut`, part into
// branches there; if so their sizes and roots go to `sizes` and `roots`, largest first, and
// their count is returned (else 0). The points of orders [slab_start, added) are those
// within two gaps of the cut.
static inline uint32_t branches_at(PartingSweep& s, uint32_t added, uint32_t slab_start, double cut,
                            uint32_t* sizes, uint32_t* roots) {
    BranchCandidate found[kMaxBranches];
    uint32_t pieces = 0;
    bool bump = false;
    size_t kept = 0;
    const uint32_t counting = counting_size(added, s.smallest);
    for (size_t k = 0; k < s.listed_count; ++k) {
        const uint32_t r = s.listed[k];
        if (s.parent[r] != r || s.size[r] < counting) {  // merged since, or too small now
            s.is_listed[r] = 0;
            continue;
        }
        s.listed[kept++] = r;
        if (s.lowest[r] - cut > s.gap) continue;  // apart from the cut: left aside
        if (s.highest[r] - cut < 2 * s.gap)
            bump = true;
        else if (pieces < kMaxBranches)  // disjoint twentieths of the side: never more
            found[pieces++] = {r, {{0, 0}, {0, 0}}, {0, 0}};
    }
    s.listed_count = kept;
    if (bump || pieces < 2) return 0;
    for (uint32_t t = slab_start; t < added; ++t) {
        const uint32_t r = s.root(t);
        for (uint32_t k = 0; k < pieces; ++k) {
            if (found[k].root != r) continue;
            const Local l = s.position[s.added[t]];
            const int slice = s.level(t) - cut < s.gap ? 0 : 1;
            found[k].sum[slice][0] += l.x;
            found[k].sum[slice][1] += l.y;
            ++found[k].slice_points[slice];
        }
    }
    // A branch's points within a gap of the cut go around its centre there: the arcs of a
    // rim that sparse flanks break apart near an open end do not.
    uint32_t held[kMaxBranches] = {};
    for (uint32_t t = slab_start; t < added; ++t) {
        if (!(s.level(t) - cut < s.gap)) continue;
        const uint32_t r = s.root(t);
        for (uint32_t k = 0; k < pieces; ++k) {
            if (found[k].root != r) continue;
            const Local l = s.position[s.added[t]];
            const double n = found[k].slice_points[0];
            held[k] |= 1u << sector_around(l.x - found[k].sum[0][0] / n, l.y - found[k].sum[0][1] / n);
        }
    }
    for (uint32_t k = 0; k < pieces; ++k)
        if (widest_gap(held[k]) > kBranchArcSectors) return 0;
    for (uint32_t k = 0; k < pieces; ++k) {
        const BranchCandidate& b = found[k];
        if (b.slice_points[1] == 0) continue;
        double d2 = 0;
        for (int c = 0; c < 2; ++c) {
            const double d = b.sum[0][c] / b.slice_points[0] - b.sum[1][c] / b.slice_points[1];
            d2 += d * d;
        }
        if (!(d2 < 4 * s.gap * s.gap)) return 0;
    }
    for (uint32_t k = 0; k < pieces; ++k) {
        uint32_t largest = k;
        for (uint32_t m = k + 1; m < pieces; ++m)
            if (s.size[found[m].root] > s.size[found[largest].root]) largest = m;
        const BranchCandidate t = found[k];
        found[k] = found[largest];
        found[largest] = t;
        sizes[k] = s.size[found[k].root];
        roots[k] = found[k].root;
    }
    return pieces;
}

// The points' steps: step k holds the points between the cuts at lo + k step_height and
// lo + (k + 1) step_height (the cut at lo + k step_height is cut k, for k in [1, steps)).
// by_step lists the grid positions step by step, each step in grid order, from
// step_start[k] to step_start[k + 1].
struct PartingSteps {
    uint32_t steps;
    double lo, step_height;
    uint32_t* step_start;     // steps + 1 entries
    uint32_t* by_step;
};

// Where one side of the cloud parts: the branches' count (0: nowhere), the cut's index,
// and the branches' sizes and roots, largest first.
struct SideParting {
    uint32_t branches;
    uint32_t cut_index;
    uint32_t added;           // the points on the side of that cut
    uint32_t sizes[kMaxBranches];
    uint32_t roots[kMaxBranches];
};

// One sweep: down from the top (`from_top`) or up from the bottom; the last cut of the
// sweep where the cloud parts (the lowest above, the highest below). With `stop` (a cut
// index, 0 for none), it stops once that cut is tried: the roots then name the pieces as
// the union-find holds them, for labelling.
static inline SideParting sweep_for_parting(PartingSweep& s, const PartingSteps& p, bool from_top,
                                     uint32_t stop) {
    s.sign = from_top ? 1 : -1;
    s.listed_count = 0;
    s.counting = s.smallest;
    for (uint32_t k = 0; k < kBlockCacheSize; ++k) s.blocks[k].cell = kNoCell;
    for (size_t j = 0; j < s.count; ++j) s.order_of[j] = kNotAdded;
    for (size_t& f : s.fingers) f = 0;
    s.checks_left = kPartingChecksPerPoint * s.count;
    const double top = from_top ? p.lo + p.steps * p.step_height : -p.lo;
    SideParting best = {};
    uint32_t added = 0;
    for (uint32_t m = 0; m + 1 < p.steps; ++m) {
        // Add step k, then try the cut on its far side: cut k from the top, k + 1 from below.
        const uint32_t k = from_top ? p.steps - 1 - m : m;
        for (uint32_t i = p.step_start[k]; i < p.step_start[k + 1] && !s.crowded; ++i)
            s.add(added++, p.by_step[i]);
        if (s.crowded) return SideParting{};
        const uint32_t cut_index = from_top ? k : k + 1;
        const double cut = s.sign * (p.lo + cut_index * p.step_height);
        // A side thinner than four gaps is a rim, which falls apart into arcs.
        if (top - cut < 4 * s.gap || added == 0) continue;
        const uint32_t slab = 2 * kStepsPerGap;  // two gaps
        const uint32_t slab_step = from_top ? (cut_index + slab < p.steps ? cut_index + slab : p.steps)
                                            : (cut_index > slab ? cut_index - slab : 0);
        const uint32_t slab_start = from_top ? static_cast<uint32_t>(s.count) - p.step_start[slab_step]
                                             : p.step_start[slab_step];
        SideParting here = {};
        here.branches = branches_at(s, added, slab_start, cut, here.sizes, here.roots);
        here.cut_index = cut_index;
        here.added = added;
        if (here.branches > 0) best = here;
        if (cut_index == stop) break;
    }
    return best;
}

// With find_parting's branch_of: sweeps again to the side's cut and labels the points
// there by their piece, keeping the labels already given (the side above is labelled
// first). `first` is the label of the side's largest branch. A piece that is no branch but
// starts at the cut (within a gap of it) goes on the trunk across it: the top of a skull's
// crown between two horns, where the cut lies just below it, too small to count as a bump
// (the bust with horns of 50,000 points: 147 such points, which left the split undone).
static inline void label_branches(PartingSweep& s, const PartingSteps& p, bool from_top,
                           uint32_t cut_index, uint8_t first, uint8_t* branch_of) {
    const SideParting side = sweep_for_parting(s, p, from_top, cut_index);
    const double cut = s.sign * (p.lo + cut_index * p.step_height);
    for (uint32_t t = 0; t < side.added; ++t) {
        const uint32_t r = s.root(t);
        uint8_t label = s.lowest[r] - cut > s.gap ? kBeyondBranches : kInTrunk;
        for (uint32_t k = 0; k < side.branches; ++k)
            if (side.roots[k] == r) label = static_cast<uint8_t>(first + k);
        uint8_t& l = branch_of[s.cells[s.added[t]].index];
        if (l == kInTrunk) l = label;
    }
}

struct PartingMemory {
    GridItem* items;          // with spare: the cell sort's arrays
    GridItem* spare;
    Local* position;
    PartingSteps steps;
    PartingSweep sweep;
};

// Allocated after the scale is measured, whose grid is given back first.
static inline void allocate_parting(PartingMemory& m, size_t count, Arena& arena) {
    m.items = arena.alloc<GridItem>(count);
    m.spare = arena.alloc<GridItem>(count);
    m.position = arena.alloc<Local>(count);
    m.steps.step_start = arena.alloc<uint32_t>(count + 2);
    m.steps.by_step = arena.alloc<uint32_t>(count);
    m.sweep.added = arena.alloc<uint32_t>(count);
    m.sweep.order_of = arena.alloc<uint32_t>(count);
    m.sweep.parent = arena.alloc<uint32_t>(count);
    m.sweep.size = arena.alloc<uint32_t>(count);
    m.sweep.lowest = arena.alloc<double>(count);
    m.sweep.highest = arena.alloc<double>(count);
    m.sweep.blocks = arena.alloc<CachedBlock>(kBlockCacheSize);
    m.sweep.listed = arena.alloc<uint32_t>(count);
    m.sweep.is_listed = arena.alloc<unsigned char>(count);
}

// The valid points in the frame, in cells of side `side` sorted by height, then across;
// returns their count. `low` is their lowest frame coordinates.
static inline size_t grid_in_frame(const CloudReader& reader, size_t count, const Frame& frame,
                            Local low, double side, PartingMemory& m) {
    size_t n = 0;
    uint64_t any = 0, every = ~uint64_t{0};
    for (size_t i = 0; i < count; ++i) {
        if (!reader.valid(i)) continue;
        const Local l = frame.local(reader.point(i));
        const uint64_t cell = cell_key(cell_coordinate(l.h - low.h, side),
                                       cell_coordinate(l.x - low.x, side),
                                       cell_coordinate(l.y - low.y, side));
        m.items[n++] = {cell, static_cast<uint32_t>(i)};
        any |= cell;
        every &= cell;
    }
    sort_items(m.items, m.spare, n, any, every);
    for (size_t j = 0; j < n; ++j) m.position[j] = frame.local(reader.point(m.items[j].index));
    return n;
}

// The steps of the n points in grid order (a counting sort), every half gap from lo to hi,
// fewer where that would make more steps than points.
static inline void split_into_steps(const Local* position, size_t n, double lo, double hi, double gap,
                             PartingSteps& p) {
    const double most = static_cast<double>(n);
    double steps = std::ceil((hi - lo) / (gap / kStepsPerGap));
    if (!(steps <= most)) steps = most;
    if (steps < 1) steps = 1;
    p.steps = static_cast<uint32_t>(steps);
    p.lo = lo;
    p.step_height = (hi - lo) / steps;
    std::memset(p.step_start, 0, sizeof(uint32_t) * (p.steps + 2));
    auto step_of = [&](double h) {
        const double k = std::floor((h - lo) / p.step_height);
        return k < 0 ? 0u : k >= steps ? p.steps - 1 : static_cast<uint32_t>(k);
    };
    for (size_t j = 0; j < n; ++j) ++p.step_start[step_of(position[j].h) + 2];
    for (uint32_t k = 0; k < p.steps; ++k) p.step_start[k + 2] += p.step_start[k + 1];
    for (size_t j = 0; j < n; ++j)
        p.by_step[p.step_start[step_of(position[j].h) + 1]++] = static_cast<uint32_t>(j);
}

// The median distance from a point to its nearest distinct neighbour, on every k-th point
// in cell order, at most kScaleSample of them; 0 where more than half find none. The
// cells are those of side `decile` (nearest_spacing's), within which nine points in ten
// find theirs; a point looks at kNearestCandidates points at most, its own cell first.
// Exact where nearest_spacing is not: that one is rounded up to a half-octave, too coarse
// for a threshold that tells a notch from a gap.
static inline double median_nearest_distance(const CloudReader& reader, size_t count, const CloudBox& box,
                                      double decile, CellScratch& g, GridItem* sample,
                                      GridItem* sample_spare) {
    const size_t n = sort_into_cells(reader, count, box.low, decile, g);
    const GridItem* items = g.items;
    for (size_t i = 0; i < n; ++i) g.sorted[i] = reader.point(items[i].index);
    const uint32_t step = sample_step(n, kScaleSample / 2);
    size_t sampled = 0;
    uint64_t any = 0, every = ~uint64_t{0};
    for (size_t i = 0; i < n && sampled < kScaleSample; ++i) {
        const Vec3 p = g.sorted[i];
        if (!sampled_point(p, step)) continue;
        const CellBlock block = block_around(items, n, i);
        double nearest = DBL_MAX;
        uint32_t seen = 0;
        for (uint32_t k = 0; k < block.count && seen < kNearestCandidates; ++k)
            for (size_t j = block.begin[k]; j < block.end[k] && seen < kNearestCandidates; ++j) {
                const Vec3 d = g.sorted[j] - p;
                const double q = dot(d, d);
                ++seen;
                if (q > 0 && q < nearest) nearest = q;
            }
        uint64_t key = 0;  // a positive double's bits sort as the double does
        std::memcpy(&key, &nearest, sizeof key);
        sample[sampled++] = {key, 0};
        any |= key;
        every &= key;
    }
    sort_items(sample, sample_spare, sampled, any, every);
    double median = DBL_MAX;
    if (sampled > 0) std::memcpy(&median, &sample[sampled / 2].cell, sizeof median);
    return median < DBL_MAX ? std::sqrt(median) : 0;
}

static inline Status out_of_workspace(Report& rep) {
    rep.detail = "the workspace is smaller than find_parting_workspace_size()";
    return Status::out_of_memory;
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {
namespace detail {

static inline size_t parting_workspace_size(size_t point_count, const TubeRequest& request) {
    if (point_count > kMaxPoints - 1) return 0;
    Arena arena = Arena::measuring();
    if (request.drop_outliers) arena.alloc<unsigned char>(point_count / 8 + 1);
    const size_t mark = arena.mark();
    allocate_cell_scratch(arena, point_count);  // the outliers' and the scale's grid
    arena.alloc<GridItem>(2 * kScaleSample);
    arena.rewind(mark);
    // Axis::automatic is resolved first, as reconstruct() resolves it.
    arena.alloc<unsigned char>(axis_workspace_size(point_count, request));
    arena.rewind(mark);
    PartingMemory m;
    allocate_parting(m, point_count, arena);
    return arena.failed ? 0 : arena.required_bytes();
}

// find_parting() along the axis of `request` (its origin, outliers and invalid points as
// it says) with the fewest points a branch holds given: a sample of the cloud is searched
// with fewer (see search_parting).
static inline Status find_parting_with(const Cloud& cloud, const TubeRequest& request, void* workspace,
                                size_t workspace_bytes, Parting* parting, uint8_t* branch_of,
                                uint32_t smallest) {
    if (!parting) return Status::invalid_argument;
    // Checked before anything is written (a count beyond the limit is refused below).
    const bool countable = cloud.count <= kMaxPoints - 1;
    const ByteRange buffers[] = {countable ? cloud_bytes(cloud) : ByteRange{0, 0},
                                 byte_range(workspace, workspace_bytes),
                                 byte_range(parting, sizeof *parting),
                                 byte_range(branch_of, countable ? cloud.count : 0)};
    if (any_overlap(buffers, 4)) return Status::invalid_argument;
    std::memset(parting, 0, sizeof *parting);
    Report rep = {};
    size_t no_triangles = 0;
    Arena arena = Arena::over(workspace, workspace_bytes);
    auto finish = [&](Status status) {
        parting->workspace_used_bytes = arena.peak_from_buffer();
        parting->detail = rep.detail;
        return status;
    };
    Status status = check_reconstruct_arguments(cloud, nullptr, 0, &no_triangles, workspace, rep);
    if (status != Status::ok) return finish(status);
    // The caller's Options, for find_parting() (reconstruct() has checked its own).
    rep.detail = request.caller ? options_refusal(*request.caller) : nullptr;
    if (rep.detail) return finish(Status::invalid_argument);
    if (branch_of) std::memset(branch_of, kInTrunk, cloud.count);
    CloudReader reader = reader_of(cloud);
    CloudSums sums = sum_cloud(reader, cloud.count);
    status = reject_invalid_points(reader, cloud.count, sums, *request.caller, rep);
    if (status != Status::ok) return finish(status);
    if (request.drop_outliers) {
        if (!find_outliers(reader, cloud.count, arena, rep)) return finish(out_of_workspace(rep));
        sums = sum_cloud(reader, cloud.count);
    }
    const TubeInput in = {reader, cloud.count, sums};
    TubeRequest along = request;
    status = resolve_axis(in, arena, along, &rep.detail);
    if (status != Status::ok) return finish(status);
    Frame frame;
    status = choose_frame(sums, along, frame);
    if (status != Status::ok) return finish(status);
    parting->axis[0] = frame.axis.x;
    parting->axis[1] = frame.axis.y;
    parting->axis[2] = frame.axis.z;
    if (sums.distinct < 3) {
        rep.detail = "fewer than 3 distinct valid points";
        return finish(Status::too_few_points);
    }
    const size_t mark = arena.mark();
    CellScratch scale_grid = allocate_cell_scratch(arena, cloud.count);
    if (arena.failed) return finish(out_of_workspace(rep));
    GridItem* sample = arena.alloc<GridItem>(2 * kScaleSample);
    if (arena.failed) return finish(out_of_workspace(rep));
    const CloudBox box = box_of(reader, cloud.count);
    const double decile = nearest_spacing(reader, cloud.count, box, scale_grid, kScaleSample);
    const double spacing = decile > 0 ? median_nearest_distance(reader, cloud.count, box, decile,
                                                                scale_grid, sample,
                                                                sample + kScaleSample)
                                      : 0;
    arena.rewind(mark);
    PartingMemory m;
    allocate_parting(m, cloud.count, arena);
    if (arena.failed) return finish(out_of_workspace(rep));
    Local low = {DBL_MAX, DBL_MAX, DBL_MAX}, high = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t i = 0; i < cloud.count; ++i) {
        if (!reader.valid(i)) continue;
        const Local l = frame.local(reader.point(i));
        low = {l.x < low.x ? l.x : low.x, l.y < low.y ? l.y : low.y, l.h < low.h ? l.h : low.h};
        high = {l.x > high.x ? l.x : high.x, l.y > high.y ? l.y : high.y, l.h > high.h ? l.h : high.h};
    }
    if (!(high.h > low.h)) {
        rep.detail = "every point has the same height along the axis";
        return finish(Status::flat_cloud);
    }
    const double gap = kPartingGap * spacing;
    if (!(gap > 0) || !is_finite(gap * frame.scale)) {
        rep.detail = "the cloud has no scale (too many of its points have no distinct "
                     "neighbour near them: repeats, scattered points): no parting is reported";
        return finish(Status::ok);
    }
    parting->gap = gap;
    PartingSweep& s = m.sweep;
    s.crowded = false;
    s.smallest = smallest;
    s.gap = gap * frame.scale;
    s.count = grid_in_frame(reader, cloud.count, frame, low, s.gap, m);
    s.cells = m.items;
    s.position = m.position;
    split_into_steps(m.position, s.count, low.h, high.h, s.gap, m.steps);
    const SideParting above = sweep_for_parting(s, m.steps, true, 0);
    const SideParting below = sweep_for_parting(s, m.steps, false, 0);
    auto report_side = [&](const SideParting& side, double* cut, uint32_t* branches,
                           uint32_t* points) {
        *branches = side.branches;
        if (side.branches) *cut = frame.user_height(m.steps.lo + side.cut_index * m.steps.step_height);
        for (uint32_t k = 0; k < side.branches; ++k) points[k] = side.sizes[k];
    };
    report_side(above, &parting->above, &parting->above_branch_count, parting->above_point_counts);
    report_side(below, &parting->below, &parting->below_branch_count, parting->below_point_counts);
    if (s.crowded) {
        parting->above_branch_count = parting->below_branch_count = 0;
        parting->above = 0;
        rep.detail = "the cloud is too crowded to search (over 1024 points within a gap of "
                     "each, on average: repeated or solid): no parting is reported";
        return finish(Status::ok);
    }
    if (branch_of && above.branches)
        label_branches(s, m.steps, true, above.cut_index, kFirstAboveBranch, branch_of);
    if (branch_of && below.branches)
        label_branches(s, m.steps, false, below.cut_index, kFirstBelowBranch, branch_of);
    return finish(Status::ok);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

size_t find_parting_workspace_size(size_t point_count, const Options& options) {
    return detail::parting_workspace_size(point_count, detail::tube_request(options));
}

Status find_parting(const Cloud& cloud, const Options& options, void* workspace,
                    size_t workspace_bytes, Parting* parting, uint8_t* branch_of) {
    return detail::find_parting_with(cloud, detail::tube_request(options), workspace,
                                     workspace_bytes, parting, branch_of, kSmallestBranch);
}

}  // namespace stratmesh

#endif  // STRATMESH_SMALL_CODE
