// >>reconstruct =============================================================================
// One tube: chunks of layers, seam flips, parallel layers.
//
// Validate, choose the frame and the layers, group the points by layer, then for each
// layer: fit its cylinder, triangulate it on its annulus, stitch it to the layer below.
// A layer that cannot be triangulated around its axis (too few points, or a gap in its
// angular coverage) is merged with the next one; trailing points that never form such a
// layer stay unused and are reported. Last, the manifold safety net.

namespace stratmesh {
namespace detail {

// ---- the surface, chunk by chunk -----------------------------------------------------------
//
// Both reconstruct() and the stream grow the surface the same way, from a queue of planned
// layers (height ranges with their points, bottom to top). A run of planned layers becomes
// one triangulated layer (a "group"); its chunk is its own triangles and the band to the
// group below, run through the manifold safety net on its own. The grouping rule: a group
// is the next planned layer, extended by the following ones while it has fewer than
// kMinLayerPoints points, is thinner than kMinLayerRows rows of points around its own radius,
// does not surround its axis, or it or the next planned layer is a crescent that the two
// together narrow (see kRingGap); when the points after it are too few or thin to stand on
// their own (compared with the group's radius), everything left joins it. Every decision
// reads only the group and the layers after it (the crescent test only the next one), and a
// larger rest only ever passes the rest test more easily, so a stream that waits until the
// rest passes, or ends, decides exactly as reconstruct() does over the whole cloud.

struct LayerQueue {
    const uint32_t* ids;    // reader indices of the planned layers' points, layer after layer
    // ids' points in frame coordinates, or null: in the workspace's end room (see
    // group_by_layer), valid as long as the arena has not reached them.
    const Local* staged;
    const uint32_t* start;  // start[k]: first position in ids of planned layer k, k <= planned
    const double* bounds;   // planned layer k spans heights bounds[k] .. bounds[k + 1];
                            // bounds[planned] is the highest point so far
    uint32_t planned;       // planned layers known
    bool complete;          // no planned layer will be added
};

struct SurfaceChain {
    Frame frame;
    CloudReader reader;
    const uint32_t* output_id;  // reader index -> output index; null: the same
    // The last group's top loop (reader indices) with, per point, kUnusedBelow and the loop
    // edges its own chunk has (kHasNextEdge, kHasPreviousEdge); two sets of buffers, swapped
    // per group.
    uint32_t* top;
    unsigned char* top_unused;
    uint32_t top_count;
    Cylinder top_cylinder;
    uint32_t* next_top;
    unsigned char* next_unused;
    uint32_t* bottom;
    unsigned char* bottom_flags;
    size_t groups, duplicates, collisions, swaps, removed, used, trailing;
};

inline bool allocate_chain(SurfaceChain& c, size_t points, Arena& arena) {
    c.top = arena.alloc<uint32_t>(points);
    c.next_top = arena.alloc<uint32_t>(points);
    c.bottom = arena.alloc<uint32_t>(points);
    c.bottom_flags = arena.alloc<unsigned char>(points);
    c.top_unused = arena.alloc<unsigned char>(points);
    c.next_unused = arena.alloc<unsigned char>(points);
    c.top_count = 0;
    c.groups = c.duplicates = c.collisions = c.swaps = c.removed = c.used = c.trailing = 0;
    return !arena.failed;
}

// Per top-loop point of a group (SurfaceChain::top_unused): its own chunk left it without a
// triangle; its own chunk (after the safety net) has the loop edge to the next loop point,
// and the one from the previous.
const unsigned char kUnusedBelow = 1, kHasNextEdge = 2, kHasPreviousEdge = 4;

inline void count_corners(const uint32_t* tri, size_t count, uint32_t* degree, size_t vertices) {
    std::memset(degree, 0, vertices * sizeof(uint32_t));
    for (size_t k = 0; k < 3 * count; ++k) ++degree[tri[k]];
}

// For the loop whose point i has id `id_of(i)` (n points, in loop order): which of the
// loop's edges the triangles use, as kHasNextEdge / kHasPreviousEdge bits added to flags[i].
// position[v] is v's place in the loop or kNoIndex, for every id v in the triangles.
inline void mark_loop_edges(const uint32_t* tri, size_t count, const uint32_t* position,
                            uint32_t n, unsigned char* flags) {
    for (size_t t = 0; t < count; ++t)
        for (size_t k = 0; k < 3; ++k) {
            uint32_t i = position[tri[3 * t + k]], j = position[tri[3 * t + (k + 1) % 3]];
            if (i == kNoIndex || j == kNoIndex) continue;
            if (j == (i + 1) % n) {
                flags[i] |= kHasNextEdge;
                flags[j] |= kHasPreviousEdge;
            } else if (i == (j + 1) % n) {
                flags[j] |= kHasNextEdge;
                flags[i] |= kHasPreviousEdge;
            }
        }
}

// Keeps the seam between two chunks manifold. A point of the loop below has one chain of
// triangles on each side (the safety net ran on each chunk); two chains around a point form
// one fan when they share an edge, which can only be one of the loop's two edges at it. As
// built they share both; where the net removed triangles on either side they may share
// none, and then the point's triangles on this side go and the net runs again, until every
// loop point with triangles on both sides shares an edge. `below` flags the loop points
// from their own chunk; seam ids are below_count + i. Returns the triangles removed, or
// SIZE_MAX if the arena is too small.
inline size_t seal_seam(uint32_t* tri, size_t& count, size_t below_count, size_t vertices,
                        const unsigned char* below, uint32_t* degree, Arena& arena) {
    const uint32_t n = static_cast<uint32_t>(vertices - below_count);
    size_t mark = arena.mark();
    uint32_t* position = arena.alloc<uint32_t>(vertices);
    unsigned char* above = arena.alloc<unsigned char>(n);
    if (arena.failed) return SIZE_MAX;
    for (size_t v = 0; v < vertices; ++v)
        position[v] = v < below_count ? kNoIndex : static_cast<uint32_t>(v - below_count);
    size_t removed = 0;
    for (;;) {
        count_corners(tri, count, degree, vertices);
        std::memset(above, 0, n);
        mark_loop_edges(tri, count, position, n, above);
        auto loose = [&](uint32_t v) {
            if (v < below_count || degree[v] == 0) return false;
            const unsigned char lower = below[v - below_count], upper = above[v - below_count];
            return !(lower & kUnusedBelow) && !(lower & upper & (kHasNextEdge | kHasPreviousEdge));
        };
        size_t kept = 0;
        for (size_t t = 0; t < count; ++t) {
            const uint32_t* v = tri + 3 * t;
            if (loose(v[0]) || loose(v[1]) || loose(v[2])) continue;
            for (size_t k = 0; k < 3; ++k) tri[3 * kept + k] = v[k];
            ++kept;
        }
        if (kept == count) break;
        removed += count - kept;
        count = kept;
        size_t more = enforce_manifold(tri, count, vertices, arena);
        if (more == SIZE_MAX) return SIZE_MAX;
        removed += more;
    }
    arena.rewind(mark);
    return removed;
}

// Whether the safety net would remove nothing from the chunk: whether the fans of the
// vertices the band joins (the layer's bottom loop, the loop below) are whole. The others
// are by construction (see >>manifold).
inline bool loop_fans_are_one_piece(const uint32_t* tri, size_t count, size_t below,
                                    size_t vertices, const LayerLoops& loops, Arena& arena) {
    size_t mark = arena.mark();
    unsigned char* checked = arena.alloc<unsigned char>(vertices);
    if (arena.failed) return false;
    std::memset(checked, 0, below);
    std::memset(checked + below, 1, vertices - below);
    for (uint32_t i = 0; i < loops.bottom_count; ++i) checked[loops.bottom[i]] = 1;
    bool whole = fans_are_one_piece(tri, count, vertices, checked, arena);
    arena.rewind(mark);
    return whole;
}

// Triangles of a chunk from layer-local and band indices to reader indices, and on to
// output indices unless the seam's flips (see "flips across the seam"), which read the
// points, come between: then name_output_points does that step.
inline void name_chunk_points(const SurfaceChain& c, const LoadedLayer& layer, uint32_t* tri,
                              size_t count) {
    for (size_t k = 0; k < 3 * count; ++k) {
        uint32_t l = tri[k];
        uint32_t id = l < layer.count ? layer.ids[l] : c.top[l - layer.count];
        tri[k] = !kSurfaceFlips && c.output_id ? c.output_id[id] : id;
    }
}

// A final chunk's triangles from reader indices to output indices (with kSurfaceFlips).
inline void name_output_points(const SurfaceChain& c, uint32_t* tri, size_t count) {
    if (!kSurfaceFlips || !c.output_id) return;
    for (size_t k = 0; k < 3 * count; ++k) tri[k] = c.output_id[tri[k]];
}

// Whether the safety net and seal_seam would leave a chunk as it is, judged from its
// triangles at the loop vertices alone: `at_loops` (count of them, in layer-local and band
// indices) holds the layer's triangles at its bottom loop and the band, and interior_used
// counts the layer's points with a triangle off that loop. It holds when the seam below is
// as built and the fans of the loop vertices are whole (see >>manifold); then the chunk's
// points that became vertices are counted and the next seam's flags set, as finish_chunk
// would. Otherwise nothing changes.
inline bool chunk_is_sound(SurfaceChain& c, const LoadedLayer& layer, const LayerLoops& loops,
                           const uint32_t* at_loops, size_t count, size_t interior_used,
                           Arena& arena) {
    // The seam is as built when every loop point below has both its loop edges there or no
    // triangle at all: then seal_seam would find nothing to do either, since the band has
    // every edge of the loop.
    const unsigned char whole = kHasNextEdge | kHasPreviousEdge;
    for (uint32_t i = 0; i < c.top_count; ++i)
        if (!(c.top_unused[i] & kUnusedBelow) && (c.top_unused[i] & whole) != whole) return false;
    const size_t below = layer.count, vertices = below + c.top_count;
    size_t mark = arena.mark();
    uint32_t* degree = arena.alloc<uint32_t>(vertices);
    if (arena.failed || !loop_fans_are_one_piece(at_loops, count, below, vertices, loops, arena)) {
        arena.failed = false;
        arena.rewind(mark);
        return false;
    }
    count_corners(at_loops, count, degree, vertices);
    size_t used = interior_used;
    for (uint32_t i = 0; i < c.top_count; ++i)
        used += degree[below + i] > 0 && (c.top_unused[i] & kUnusedBelow);
    // A bottom-loop vertex's triangles are all here; kNoIndex marks one without any.
    for (uint32_t i = 0; i < loops.bottom_count; ++i) {
        uint32_t& d = degree[loops.bottom[i]];
        used += d > 0;
        d = d > 0 ? 1 : kNoIndex;
    }
    for (uint32_t i = 0; i < loops.top_count; ++i)
        c.next_unused[i] = static_cast<unsigned char>(
            (c.next_unused[i] & kPassBits) |
            (degree[loops.top[i]] == kNoIndex ? kUnusedBelow : whole));
    c.used += used;
    arena.rewind(mark);
    return true;
}

// The safety net over the chunk sink[chunk_start ..), then its indices from layer-local and
// band indices to output indices; counts the points that became vertices.
inline Status finish_chunk(SurfaceChain& c, const LoadedLayer& layer, const LayerLoops& loops,
                           size_t chunk_start, Arena& arena, TriangleSink& sink) {
    uint32_t* tri = sink.triangles + 3 * chunk_start;
    size_t count = sink.count - chunk_start;
    const size_t below = layer.count, vertices = layer.count + c.top_count;
    size_t mark = arena.mark();
    uint32_t* degree = arena.alloc<uint32_t>(vertices);
    if (arena.failed) return Status::out_of_memory;
    size_t removed = 0;
    if (!(kNetShortcut && loop_fans_are_one_piece(tri, count, below, vertices, loops, arena)))
        removed = enforce_manifold(tri, count, vertices, arena);
    if (removed == SIZE_MAX) return Status::out_of_memory;
    const unsigned char whole = kHasNextEdge | kHasPreviousEdge;
    bool seam_as_built = removed == 0;
    for (uint32_t i = 0; i < c.top_count; ++i)
        seam_as_built = seam_as_built && ((c.top_unused[i] & whole) == whole);
    if (!seam_as_built) {
        size_t more = seal_seam(tri, count, below, vertices, c.top_unused, degree, arena);
        if (more == SIZE_MAX) return Status::out_of_memory;
        removed += more;
    }
    count_corners(tri, count, degree, vertices);
    sink.count = chunk_start + count;
    c.removed += removed;
    for (uint32_t i = 0; i < c.top_count; ++i)
        c.used += degree[below + i] > 0 && (c.top_unused[i] & kUnusedBelow);
    for (size_t l = 0; l < below; ++l) c.used += degree[l] > 0;
    // The next seam's lower side: this chunk's triangles at the new top loop.
    for (uint32_t i = 0; i < loops.top_count; ++i)
        c.next_unused[i] = static_cast<unsigned char>((c.next_unused[i] & kPassBits) |
                                                      (degree[loops.top[i]] == 0 ? kUnusedBelow
                                                       : removed == 0 ? whole : 0));
    if (removed > 0) {
        uint32_t* position = degree;  // reused: the counts are taken
        for (size_t v = 0; v < vertices; ++v) position[v] = kNoIndex;
        for (uint32_t i = 0; i < loops.top_count; ++i) position[loops.top[i]] = i;
        mark_loop_edges(tri, count, position, loops.top_count, c.next_unused);
    }
    name_chunk_points(c, layer, tri, count);
    arena.rewind(mark);
    return Status::ok;
}

// A group whose points leave more than kRingGap of the kSectors sectors around a centre
// empty in a row (over 34 degrees) is a crescent: the end of a tube cut at a slant to the
// axis, one side of a half cylinder, or a section that splits in two. Triangulated alone,
// its annulus closes the gap with a membrane across the tube (on the bundled bust along
// its automatic axis, which leans 13 degrees, with 16 layers: twice the area of that end
// and 5 times the mean distance to the true surface, with no fold to show for it). So a
// group joins the next planned layer when either is a crescent and the two together leave
// a gap at least two sectors narrower than the wider of theirs, all seen from the centre
// fitted to both (a crescent's own centre lies off the axis, towards its arc): a slanted
// end is taken in from below, and from above as the rings below reach it. A half cylinder,
// whose gap no neighbour narrows, keeps its layers. The gaps are read on a sample of each
// layer, and a gap that chance leaves among that many points of a ring (crescent_gap) is
// not a crescent, so sparse layers keep theirs too. Without the merge a slanted end is
// closed across by a membrane, far from the true surface.
const uint32_t kRingGap = 3;

// sectors_held by planned layers [first, last] around (cx, cy), read from the cloud.
inline uint32_t planned_sectors(const SurfaceChain& c, const LayerQueue& q, uint32_t first,
                                uint32_t last, double cx, double cy) {
    const uint32_t* ids = q.ids + q.start[first];
    return sectors_held([&c, ids](size_t i) { return c.frame.local(c.reader.point(ids[i])); },
                        q.start[last + 1] - q.start[first], cx, cy);
}

// The widest gap of `held` when it exceeds kRingGap and chance alone would leave a gap
// that wide among the count points sampled from a ring less than once in a hundred (m
// points uniform on a circle leave g of its 32 sectors empty in a row with probability
// below m (1 - g/32)^(m-1)): a sparse layer's gaps are not crescents, nor is an empty
// one. Else 0.
inline uint32_t crescent_gap(uint32_t held, size_t count) {
    const uint32_t gap = widest_gap(held);
    if (gap <= kRingGap || count == 0) return 0;
    const size_t stride = gap_sample_stride(count);
    const size_t sampled = (count + stride - 1) / stride;  // the points sectors_held read
    const double stays_empty = 1 - static_cast<double>(gap) / kSectors;
    double chance = static_cast<double>(sampled);
    for (size_t i = 1; i < sampled && chance >= 0.01; ++i) chance *= stays_empty;
    return chance < 0.01 ? gap : 0;
}

// Whether the group [first, last] joins the next planned layer (see kRingGap). First a
// look from the group's fitted centre; where it or the next layer leaves a gap, the gaps
// are taken again from the centre fitted to both, which a crescent does not pull aside.
inline bool joins_crescent(const SurfaceChain& c, const LayerQueue& q, uint32_t first,
                           uint32_t last, const Cylinder& fitted, uint32_t own) {
    const size_t own_count = q.start[last + 1] - q.start[first];
    const size_t next_count = q.start[last + 2] - q.start[last + 1];
    uint32_t next = planned_sectors(c, q, last + 1, last + 1, fitted.cx, fitted.cy);
    if (!crescent_gap(own, own_count) && !crescent_gap(next, next_count)) return false;
    const uint32_t* ids = q.ids + q.start[first];
    const Cylinder both =
        fit_cylinder([&c, ids](size_t i) { return c.frame.local(c.reader.point(ids[i])); },
                     own_count + next_count, 0, 1);
    own = planned_sectors(c, q, first, last, both.cx, both.cy);
    next = planned_sectors(c, q, last + 1, last + 1, both.cx, both.cy);
    const uint32_t own_gap = crescent_gap(own, own_count);
    const uint32_t next_gap = crescent_gap(next, next_count);
    const uint32_t gap = own_gap > next_gap ? own_gap : next_gap;
    return gap > 0 && widest_gap(own | next) + 1 < gap;
}

// Whether a group of n points over `height` around `radius` is triangulated on its own
// (else it joins the next planned layer; the final group only needs 3 points).
inline bool group_stands(size_t n, double height, double radius, bool final) {
    return n >= 3 && (final || (n >= kMinLayerPoints && thick_enough(n, height, radius)));
}

// A planned layer triangulated ahead by a job (see "parallel layers" below): what
// triangulate_layer gave, kept until the group is formed in order.
struct LayerAhead {
    bool done;               // triangulate_layer ran: status, and on ok all below
    Status status;
    Cylinder cylinder;
    Cylinder fitted;         // the cylinder before the centre search, and its layer_sectors
    uint32_t sectors;
    uint32_t ends;           // the ends of the surface it was taken for (find_closed_ends)
    LayerCounts counts;
    size_t triangle_count, folds;
    uint32_t* triangles;     // as the sink writes them; in reader indices if replayable
    uint32_t* bottom;        // the loops in layer-local indices
    uint32_t* top;
    unsigned char* bottom_flags;  // LayerLoops::bottom_flags, top_flags
    unsigned char* top_flags;
    uint32_t bottom_count, top_count;
    // For replay_chunk: the triangles touching the bottom loop, in layer-local indices (at
    // most border_capacity), and the vertices off the bottom loop with a triangle.
    bool replayable;         // the border fits and every top-loop vertex off the bottom
                             // loop has a triangle (else the triangles stay layer-local)
    uint32_t* border;
    size_t border_count, border_capacity, interior_used;
};

// What one step of the queue did.
struct GroupResult {
    uint32_t last;           // the group is planned layers [first, last]
    bool waiting;            // the queue must grow (or complete) before this group is known
    size_t points;           // its points, duplicates included
    LayerCounts counts;
    size_t triangles, folds; // its chunk, before the safety net
    Cylinder cylinder;
};

// What triangulate_layer would do now, from a job's result.
inline Status take_ahead(const LayerAhead& ahead, TriangleSink& sink, LayerLoops& loops,
                         LayerCounts& counts) {
    if (ahead.status != Status::ok) return ahead.status;
    if (sink.count < sink.capacity) {
        size_t room = sink.capacity - sink.count;
        size_t copied = ahead.triangle_count < room ? ahead.triangle_count : room;
        std::memcpy(sink.triangles + 3 * sink.count, ahead.triangles, 3 * copied * sizeof(uint32_t));
    }
    sink.count += ahead.triangle_count;
    sink.folds += ahead.folds;
    std::memcpy(loops.bottom, ahead.bottom, ahead.bottom_count * sizeof(uint32_t));
    std::memcpy(loops.top, ahead.top, ahead.top_count * sizeof(uint32_t));
    std::memcpy(loops.bottom_flags, ahead.bottom_flags, ahead.bottom_count);
    std::memcpy(loops.top_flags, ahead.top_flags, ahead.top_count);
    loops.bottom_count = ahead.bottom_count;
    loops.top_count = ahead.top_count;
    counts = ahead.counts;
    return Status::ok;
}

// finish_chunk for a layer a job triangulated, whose triangles are already in reader
// indices, followed in the sink by the band (from chunk_start + ahead.triangle_count): when
// chunk_is_sound holds for the border the job kept and the band, only the band is named in
// reader indices. Returns false when it does not (nothing changed): the caller then builds
// the chunk again in order, to the same triangles, and runs finish_chunk.
inline bool replay_chunk(SurfaceChain& c, const LoadedLayer& layer, const LayerLoops& loops,
                         const LayerAhead& ahead, size_t chunk_start, Arena& arena,
                         TriangleSink& sink) {
    if (!ahead.replayable || c.output_id) return false;
    uint32_t* band = sink.triangles + 3 * (chunk_start + ahead.triangle_count);
    const size_t band_count = sink.count - chunk_start - ahead.triangle_count;
    const size_t count = ahead.border_count + band_count;
    size_t mark = arena.mark();
    uint32_t* tri = arena.alloc<uint32_t>(3 * count);
    if (arena.failed) {
        arena.failed = false;
        arena.rewind(mark);
        return false;
    }
    std::memcpy(tri, ahead.border, 3 * ahead.border_count * sizeof(uint32_t));
    std::memcpy(tri + 3 * ahead.border_count, band, 3 * band_count * sizeof(uint32_t));
    const bool sound = chunk_is_sound(c, layer, loops, tri, count, ahead.interior_used, arena);
    arena.rewind(mark);
    if (sound) name_chunk_points(c, layer, band, band_count);
    return sound;
}

// ---- flips across the seam ----
//
// With the surface_flips flag. A layer's flips on the surface (see "flips on the surface")
// run before its band is stitched and never move a loop's edge, so the band and the layer's
// triangles at its bottom loop keep the unrolled Delaunay's choice, and every cut would
// cost closeness to the surface (twice as much as with the seam's flips). Once a chunk is
// final, its seam (the triangles with a corner on the loop below or on the layer's bottom
// loop) is flipped by the same rules, with three limits that keep everything outside the
// seam as it is:
//  - only edges between two seam triangles, so the loop below's edges, the edges to the
//    rest of the chunk and the chunk before (which the stream has handed out) stay;
//  - only flips where p or q is a loop point: a loop point's triangles in the chunk are all
//    in the seam, so whether pq is an edge already is read from its fan (the loop below's
//    other side, in the chunk before, has no point of this layer), and a chord between two
//    points of one loop (the loop below, the layer's bottom or top loop) is refused, as it
//    would stand where the next band or a cap goes; both new triangles keep that corner,
//    so they stay in the seam;
//  - only gentle flips (kGentleFlip), which need no crossing test, and none that makes or
//    unmakes a fold (the layer's cylinder), so Report::diagnostics.fold_count keeps its count.
// Vertex normals come from every triangle of the chunk. The seam's memory, at most about
// 72 bytes per vertex of the chunk and 4 per point read, fits in the safety net's room
// (reconstruct_scratch_size: 91 per point) because a seam of more triangles than three
// quarters of the chunk's vertices is left as it is: a thin layer, mostly loop.

const uint32_t kLoopBelow = 1, kBottomLoopPoint = 2, kTopLoopPoint = 4, kLoopBits = 3;

struct Seam {
    uint32_t* chunk;        // the chunk's triangles, reader indices
    uint32_t* slot;         // seam triangle s is chunk triangle slot[s]
    uint32_t* vertex;       // 3 per seam triangle: its seam points
    uint32_t* twin;         // 3 per seam triangle: the opposite half-edge, or kNoIndex
    uint32_t* degree;       // per seam point: its seam triangles
    uint32_t* ids;          // per seam point: its reader index
    unsigned char* loop;    // per seam point: kLoopBelow, kBottomLoopPoint, kTopLoopPoint
    float* fixed_normal;    // 3 per seam point: the sum over its triangles off the seam
    float* normal;          // 3 per seam point
    // Per reader index of the chunk's points and loops (the rest unset): its loop bits,
    // and above them (seam point + 1) << kLoopBits once it is one.
    uint32_t* tag;
    uint32_t triangles, points;

    // The seam point of reader index id (one of the chunk's), or kNoIndex.
    uint32_t point_of(uint32_t id) const {
        return (tag[id] >> kLoopBits) == 0 ? kNoIndex : (tag[id] >> kLoopBits) - 1;
    }
};

// The seam of a chunk (see above). False with seam.triangles = 0 when it is left as it is;
// false with arena.failed when the arena is too small.
inline bool find_seam(const SurfaceChain& c, const LoadedLayer& layer, const LayerLoops& loops,
                      uint32_t* chunk, size_t count, Arena& arena, Seam& seam) {
    seam.chunk = chunk;
    seam.triangles = 0;
    // The tags, over reader indices up to the largest of the chunk's and the loops'.
    uint32_t largest = 0;
    for (size_t k = 0; k < 3 * count; ++k) largest = chunk[k] > largest ? chunk[k] : largest;
    for (uint32_t i = 0; i < c.top_count; ++i) largest = c.top[i] > largest ? c.top[i] : largest;
    for (uint32_t i = 0; i < layer.count; ++i)
        largest = layer.ids[i] > largest ? layer.ids[i] : largest;
    seam.tag = arena.alloc<uint32_t>(size_t{largest} + 1);
    const size_t vertices = layer.count + c.top_count;
    // More seam triangles: left as it is (and the tags' seam points fit above the bits).
    size_t most = 3 * vertices / 4;
    if (most > (kNoIndex >> kLoopBits) / 3) most = (kNoIndex >> kLoopBits) / 3;
    seam.slot = arena.alloc<uint32_t>(most);
    if (arena.failed) return false;
    for (size_t k = 0; k < 3 * count; ++k) seam.tag[chunk[k]] = 0;
    for (uint32_t i = 0; i < c.top_count; ++i) seam.tag[c.top[i]] = kLoopBelow;
    for (uint32_t i = 0; i < loops.bottom_count; ++i) seam.tag[layer.ids[loops.bottom[i]]] = 0;
    for (uint32_t i = 0; i < loops.top_count; ++i) seam.tag[layer.ids[loops.top[i]]] = 0;
    for (uint32_t i = 0; i < loops.bottom_count; ++i)
        seam.tag[layer.ids[loops.bottom[i]]] |= kBottomLoopPoint;
    for (uint32_t i = 0; i < loops.top_count; ++i)
        seam.tag[layer.ids[loops.top[i]]] |= kTopLoopPoint;
    size_t triangles = 0;
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* v = chunk + 3 * t;
        if (!((seam.tag[v[0]] | seam.tag[v[1]] | seam.tag[v[2]]) & (kLoopBelow | kBottomLoopPoint)))
            continue;
        if (triangles == most) return false;
        seam.slot[triangles++] = static_cast<uint32_t>(t);
    }
    if (triangles == 0) return false;
    seam.triangles = static_cast<uint32_t>(triangles);
    seam.vertex = arena.alloc<uint32_t>(3 * triangles);
    seam.twin = arena.alloc<uint32_t>(3 * triangles);
    seam.ids = arena.alloc<uint32_t>(3 * triangles);
    if (arena.failed) return false;
    uint32_t points = 0;
    for (size_t s = 0; s < triangles; ++s)
        for (uint32_t j = 0; j < 3; ++j) {
            const uint32_t id = chunk[3 * size_t{seam.slot[s]} + j];
            if ((seam.tag[id] >> kLoopBits) == 0) {
                seam.ids[points] = id;
                seam.tag[id] |= (points + 1) << kLoopBits;
                ++points;
            }
            seam.vertex[3 * s + j] = (seam.tag[id] >> kLoopBits) - 1;
        }
    seam.points = points;
    seam.degree = arena.alloc<uint32_t>(points);
    seam.loop = arena.alloc<unsigned char>(points);
    seam.fixed_normal = arena.alloc<float>(3 * size_t{points});
    seam.normal = arena.alloc<float>(3 * size_t{points});
    if (arena.failed) return false;
    for (uint32_t v = 0; v < points; ++v) {
        seam.loop[v] = static_cast<unsigned char>(seam.tag[seam.ids[v]] & 7u);
        seam.degree[v] = 0;
    }
    for (size_t i = 0; i < 3 * triangles; ++i) ++seam.degree[seam.vertex[i]];
    // Twins through each point's outgoing half-edges.
    size_t mark = arena.mark();
    uint32_t* first = arena.alloc<uint32_t>(size_t{points} + 1);
    uint32_t* outgoing = arena.alloc<uint32_t>(3 * triangles);
    if (arena.failed) return false;
    std::memset(first, 0, (size_t{points} + 1) * sizeof(uint32_t));
    for (size_t e = 0; e < 3 * triangles; ++e) ++first[seam.vertex[e] + 1];
    for (uint32_t v = 0; v < points; ++v) first[v + 1] += first[v];
    for (uint32_t e = 0; e < 3 * triangles; ++e) outgoing[first[seam.vertex[e]]++] = e;
    for (uint32_t v = points; v > 0; --v) first[v] = first[v - 1];
    first[0] = 0;
    for (uint32_t e = 0; e < 3 * triangles; ++e) {
        const uint32_t a = seam.vertex[e], b = seam.vertex[next_edge(e)];
        seam.twin[e] = kNoIndex;
        for (uint32_t i = first[b]; i < first[b + 1]; ++i)
            if (seam.vertex[next_edge(outgoing[i])] == a) seam.twin[e] = outgoing[i];
    }
    arena.rewind(mark);
    return true;
}

// Seam point v's normal.
inline Vec3 seam_normal(const Seam& seam, uint32_t v) {
    const float* n = seam.normal + 3 * size_t{v};
    return Vec3{static_cast<double>(n[0]), static_cast<double>(n[1]),
                static_cast<double>(n[2])};
}

// Adds triangle v's unit normal to sums[3 k] for each corner k of it that is a seam point.
inline void add_seam_normal(const SurfaceChain& c, const Seam& seam, const uint32_t* v,
                            float* sums) {
    const uint32_t at[3] = {seam.point_of(v[0]), seam.point_of(v[1]), seam.point_of(v[2])};
    if (at[0] == kNoIndex && at[1] == kNoIndex && at[2] == kNoIndex) return;
    Vec3 n = normal_of(c.frame.local(c.reader.point(v[0])), c.frame.local(c.reader.point(v[1])),
                       c.frame.local(c.reader.point(v[2])));
    const double length = std::sqrt(dot(n, n));
    if (length == 0) return;
    n = scaled(n, 1 / length);
    for (uint32_t k : at) {
        if (k == kNoIndex) continue;
        float* sum = sums + 3 * size_t{k};
        sum[0] += static_cast<float>(n.x);
        sum[1] += static_cast<float>(n.y);
        sum[2] += static_cast<float>(n.z);
    }
}

// The sums of the unit normals of the chunk's triangles off the seam, at the seam's points.
inline void sum_fixed_normals(const SurfaceChain& c, const Seam& seam, size_t count) {
    std::memset(seam.fixed_normal, 0, 3 * size_t{seam.points} * sizeof(float));
    uint32_t next = 0;  // seam.slot is increasing
    for (size_t t = 0; t < count; ++t) {
        if (next < seam.triangles && seam.slot[next] == t) {
            ++next;
            continue;
        }
        add_seam_normal(c, seam, seam.chunk + 3 * t, seam.fixed_normal);
    }
}

// The seam's vertex normals over every triangle of the chunk (see VertexNormals): the fixed
// sums and the seam's own triangles, made unit.
inline void estimate_seam_normals(const SurfaceChain& c, const Seam& seam) {
    std::memcpy(seam.normal, seam.fixed_normal, 3 * size_t{seam.points} * sizeof(float));
    for (uint32_t s = 0; s < seam.triangles; ++s)
        add_seam_normal(c, seam, seam.chunk + 3 * size_t{seam.slot[s]}, seam.normal);
    for (uint32_t k = 0; k < seam.points; ++k) {
        float* sum = seam.normal + 3 * size_t{k};
        const Vec3 n = seam_normal(seam, k);
        const double length = std::sqrt(dot(n, n));
        if (length == 0) continue;
        sum[0] = static_cast<float>(n.x / length);
        sum[1] = static_cast<float>(n.y / length);
        sum[2] = static_cast<float>(n.z / length);
    }
}

// Whether seam point x's triangles, walked around it from half-edge `from` (leaving x) both
// ways, are all of its seam triangles and none has an edge to y.
inline bool fan_misses(const Seam& seam, uint32_t from, uint32_t x, uint32_t y) {
    uint32_t seen = 0;
    auto clear = [&seam, y](uint32_t g) {
        return seam.vertex[next_edge(g)] != y && seam.vertex[prev_edge(g)] != y;
    };
    uint32_t g = from;
    for (uint32_t steps = 0;; ++steps) {
        if (steps == kFanLimit || !clear(g)) return false;
        ++seen;
        const uint32_t h = seam.twin[prev_edge(g)];
        if (h == from) return seen == seam.degree[x];
        if (h == kNoIndex) break;
        g = h;
    }
    g = from;
    for (uint32_t steps = 0;; ++steps) {
        const uint32_t back = seam.twin[g];
        if (back == kNoIndex) break;
        g = next_edge(back);
        if (steps == kFanLimit || !clear(g)) return false;
        ++seen;
    }
    return seen == seam.degree[x];
}

// Flips half-edge e of the seam if that helps (see above and flip_on_surface).
inline bool flip_seam_edge(const SurfaceChain& c, Seam& seam, const Cylinder& cyl, uint32_t e) {
    const uint32_t f = seam.twin[e];
    if (f == kNoIndex) return false;
    const uint32_t a = seam.vertex[e], b = seam.vertex[next_edge(e)];
    const uint32_t p = seam.vertex[prev_edge(e)], q = seam.vertex[prev_edge(f)];
    if (p == q || (seam.loop[p] & seam.loop[q]) ||
        !((seam.loop[p] | seam.loop[q]) & (kLoopBelow | kBottomLoopPoint)))
        return false;
    const bool p_anchors = (seam.loop[p] & (kLoopBelow | kBottomLoopPoint)) != 0;
    if (p_anchors ? !fan_misses(seam, prev_edge(e), p, q) : !fan_misses(seam, prev_edge(f), q, p))
        return false;
    const Local la = c.frame.local(c.reader.point(seam.ids[a]));
    const Local lb = c.frame.local(c.reader.point(seam.ids[b]));
    const Local lp = c.frame.local(c.reader.point(seam.ids[p]));
    const Local lq = c.frame.local(c.reader.point(seam.ids[q]));
    if (!flip_wanted(la, lb, lp, lq, seam_normal(seam, a), seam_normal(seam, b),
                     seam_normal(seam, p), seam_normal(seam, q)))
        return false;
    // The chunk's triangles face outwards counter-clockwise, as do the new (p, a, q) and
    // (q, b, p).
    if (faces_axis(la, lb, lp, cyl) || faces_axis(lb, la, lq, cyl) ||
        faces_axis(lp, la, lq, cyl) || faces_axis(lq, lb, lp, cyl) ||
        doubled_area(lp, la, lq) == 0 || doubled_area(lq, lb, lp) == 0)
        return false;
    if (!gentle_flip(la, lb, lp, lq)) return false;
    const uint32_t t = e / 3, u = f / 3;
    const uint32_t xa = seam.twin[next_edge(e)], xb = seam.twin[prev_edge(e)];
    const uint32_t xc = seam.twin[next_edge(f)], xd = seam.twin[prev_edge(f)];
    const uint32_t corners[6] = {p, a, q, q, b, p};
    for (uint32_t j = 0; j < 3; ++j) {
        seam.vertex[3 * t + j] = corners[j];
        seam.vertex[3 * u + j] = corners[3 + j];
        seam.chunk[3 * size_t{seam.slot[t]} + j] = seam.ids[corners[j]];
        seam.chunk[3 * size_t{seam.slot[u]} + j] = seam.ids[corners[3 + j]];
    }
    auto link = [&seam](uint32_t g, uint32_t h) {
        seam.twin[g] = h;
        if (h != kNoIndex) seam.twin[h] = g;
    };
    link(3 * t, xb);
    link(3 * t + 1, xc);
    link(3 * u, xd);
    link(3 * u + 1, xa);
    link(3 * t + 2, 3 * u + 2);
    --seam.degree[a];
    --seam.degree[b];
    ++seam.degree[p];
    ++seam.degree[q];
    return true;
}

// Flips a final chunk's seam (reader indices) on the surface, sweep after sweep as
// flip_layer_on_surface does. Returns false if the arena is too small.
inline bool flip_seam(const SurfaceChain& c, const LoadedLayer& layer, const LayerLoops& loops,
                      uint32_t* chunk, size_t count, Arena& arena) {
    size_t mark = arena.mark();
    Seam seam;
    if (!find_seam(c, layer, loops, chunk, count, arena, seam)) {
        arena.rewind(mark);
        return !arena.failed;
    }
    sum_fixed_normals(c, seam, count);
    for (uint32_t sweep = 0; sweep < kSurfaceFlipSweeps; ++sweep) {
        if (sweep < kNormalSweeps) estimate_seam_normals(c, seam);
        size_t flipped = 0;
        for (uint32_t s = 0; s < seam.triangles; ++s)
            for (uint32_t e = 3 * s; e < 3 * s + 3; ++e) {
                const uint32_t f = seam.twin[e];
                if (f == kNoIndex || f > e || !flip_seam_edge(c, seam, layer.cyl, e)) continue;
                ++flipped;
                break;
            }
        if (flipped == 0) break;
    }
    arena.rewind(mark);
    return true;
}

// Forms the group starting at planned layer `first`, triangulates it, stitches it to the
// chain's top loop and finishes the chunk. `ahead` (optional) is planned layer `first`
// triangulated ahead: used when the group is that layer alone. Returns ok (also when
// waiting), not_columnar when the rest of the queue cannot form a layer (counted in
// c.trailing), or an error.
//
// Folding layers (kFoldMerge): a group whose triangles or band face the axis anywhere,
// with a planned layer above it, is triangulated and stitched again with that layer
// joined (then, if that folds no less, with the next one too: kFoldMergeReach), and the
// first longer group that has fewer such triangles than the group alone is kept (else the
// group is made again, as it was). Where cuts run through a part that is not star-shaped
// (the notch between a femur's condyles, a thumb beside the fist), the thin layers there
// fold, their loops skip across the notch, and the bands between such loops cross the
// layers next to them; a taller layer gives the centre search more of the section to
// choose a centre from, and has one band fewer (on a femur in 40 layers, it takes the
// crossing pairs at its notch from dozens to none). It costs up to four
// triangulations more, only where a layer folds (at most seven times that layer's time);
// the stream waits for the layers above as it does for crescents, and makes the same
// groups.
inline Status add_group(SurfaceChain& c, const LayerQueue& q, uint32_t first, Arena& arena,
                        TriangleSink& sink, GroupResult& result, const LayerAhead* ahead) {
    result.waiting = false;
    uint32_t last = first;
    // Folding layers: the group's last layer and folds before any layer was joined, the
    // layers joined in the current try, and whether the group is settled.
    uint32_t single_last = first, joined = 0;
    size_t single_folds = 0;
    bool merge_settled = false;
    for (;;) {
        const bool final = q.complete && last + 1 == q.planned;
        if (!final && last + 1 >= q.planned) {
            result.waiting = true;
            return Status::ok;
        }
        const uint32_t* ids = q.ids + q.start[first];
        const size_t n = q.start[last + 1] - q.start[first];
        const double h0 = q.bounds[first], h1 = q.bounds[last + 1];
        size_t mark = arena.mark();
        // The surface's ends: its first group, and the group that takes the last planned layer.
        const uint32_t ends = (c.top_count == 0 ? kLowPole : 0) | (final ? kHighPole : 0);
        const bool triangulated = kParallelLayers && ahead && ahead->done && last == first &&
                                  ahead->ends == ends;
        LoadedLayer layer = {ids, n, nullptr, triangulated ? ahead->cylinder : Cylinder{},
                             kSurfaceFlips && c.frame.surface_flips, ends,
                             c.frame.cut_ends};
        const Local* staged = q.staged ? q.staged + q.start[first] : nullptr;
        if (!triangulated && !load_layer(c.reader, c.frame, ids, staged, n, h0, h1, arena, layer))
            return Status::out_of_memory;
        if (!final) {
            // Crescents (see kRingGap), the group or the next planned layer.
            if (kCrescentLayers &&
                joins_crescent(c, q, first, last, triangulated ? ahead->fitted : layer.cyl,
                               triangulated ? ahead->sectors : layer_sectors(layer))) {
                arena.rewind(mark);
                ++last;
                continue;
            }
            size_t rest = q.start[q.planned] - q.start[last + 1];
            double rest_height = q.bounds[q.planned] - q.bounds[last + 1];
            if (!(rest >= kMinLayerPoints && thick_enough(rest, rest_height, layer.cyl.radius))) {
                arena.rewind(mark);
                if (!q.complete) {
                    result.waiting = true;
                    return Status::ok;
                }
                last = q.planned - 1;  // a remainder too small or thin to stand joins this group
                continue;
            }
        }
        Status status = Status::not_columnar;
        // Tiny or thin layers make coarse, folding bands: they join the next layer if any.
        if (group_stands(n, h1 - h0, layer.cyl.radius, final)) {
            const size_t chunk_start = sink.count, folds = sink.folds, swaps = c.swaps;
            LayerLoops loops = {c.bottom, 0, c.next_top, 0, c.bottom_flags, c.next_unused,
                                0, 0};
            // A band between peeled loops that folds (a peeled loop can dip where the other
            // cannot follow) is stitched again with the peel groups around its folds put
            // back (kLocalUnpeel; see "peeling" in >>layer triangulation and kUnpeelRounds);
            // where it still folds, or no peeled entry is near a fold, between the loops as
            // they were before peeling, with all their peeled triangles put back.
            auto stitch = [&]() {
                if (status != Status::ok || c.top_count == 0) return;
                const size_t band_start = sink.count, band_folds = sink.folds;
                const size_t band_swaps = c.swaps;
                auto peeled = [&]() {
                    for (uint32_t i = 0; i < c.top_count; ++i)
                        if (c.top_unused[i] & kPassBits) return true;
                    for (uint32_t j = 0; j < loops.bottom_count; ++j)
                        if (loops.bottom_flags[j] & kPassBits) return true;
                    return false;
                };
                auto unpeeled = [&]() {
                    return count_unpeeled(c.top_unused, c.top_count) +
                           count_unpeeled(loops.bottom_flags, loops.bottom_count);
                };
                // Rounds before the last put back the groups marked; the last, all.
                for (uint32_t round = 0; round < kUnpeelRounds; ++round) {
                    if (kLocalUnpeel && (round == 0 || round + 1 == kUnpeelRounds)) {
                        mark_unpeeled(c.top_unused, c.top_count, round + 1 == kUnpeelRounds);
                        mark_unpeeled(loops.bottom_flags, loops.bottom_count,
                                      round + 1 == kUnpeelRounds);
                    }
                    sink.count = band_start;
                    sink.folds = band_folds;
                    c.swaps = band_swaps;
                    const size_t marked = kLocalUnpeel ? unpeeled() : 0;
                    if (!stitch_layers(c.reader, c.frame, c.top_cylinder, c.top, c.top_unused,
                                       c.top_count, layer, loops, round + 1 == kUnpeelRounds,
                                       arena, sink, &c.swaps)) {
                        status = Status::out_of_memory;
                        return;
                    }
                    if (sink.folds == band_folds || !peeled()) return;
                    if (kLocalUnpeel && unpeeled() == marked && round + 2 < kUnpeelRounds)
                        round = kUnpeelRounds - 2;  // no group near a fold: the last round
                }
            };
            auto triangulate_here = [&]() {
                find_closed_ends(layer, ends);
                status = triangulate_layer(c.reader, layer, arena, sink, loops, result.counts);
                stitch();
            };
            if (triangulated) {
                status = take_ahead(*ahead, sink, loops, result.counts);
                stitch();
            } else {
                triangulate_here();
            }
            result.folds = sink.folds - folds;
            // Folding layers: decided before the chunk is named (naming counts its points).
            if (kFoldMerge && !merge_settled &&
                (joined > 0 || (status == Status::ok && result.folds > 0 && !final))) {
                if (joined > 0 && status == Status::ok && result.folds < single_folds) {
                    merge_settled = true;
                } else {
                    sink.count = chunk_start;
                    sink.folds = folds;
                    c.swaps = swaps;
                    arena.rewind(mark);
                    if (joined == 0) {
                        single_last = last;
                        single_folds = result.folds;
                    }
                    if (!final && joined < kFoldMergeReach) {
                        ++joined;
                        ++last;
                    } else {
                        merge_settled = true;
                        last = single_last;
                    }
                    continue;
                }
            }
            // A job's result in reader indices goes in as it is when its chunk needs no
            // safety net; else the layer is loaded and triangulated again, in order, to the
            // same triangles. One the job left in layer-local indices (not replayable) goes
            // through finish_chunk. Past the caller's capacity only the count goes on
            // (triangle_capacity follows).
            bool finished = false, retriangulate = !triangulated;
            if (triangulated) {
                finished = status != Status::ok || sink.count > sink.capacity ||
                           (ahead->replayable &&
                            replay_chunk(c, layer, loops, *ahead, chunk_start, arena, sink));
                if (!finished && ahead->replayable) {
                    sink.count = chunk_start;
                    sink.folds = folds;
                    c.swaps = swaps;
                    if (!load_layer(c.reader, c.frame, ids, staged, n, h0, h1, arena, layer))
                        return Status::out_of_memory;
                    triangulate_here();
                    retriangulate = true;
                }
            }
            result.triangles = sink.count - chunk_start;
            // The layer's points are no longer needed: the safety net takes their room. A
            // chunk triangulated here whose border and band show it sound is only renamed.
            arena.rewind(mark);
            if (!finished && status == Status::ok && sink.count <= sink.capacity) {
                uint32_t* chunk = sink.triangles + 3 * chunk_start;
                if (kNetShortcut && retriangulate &&
                    chunk_is_sound(c, layer, loops, sink.triangles + 3 * loops.border_start,
                                   sink.count - loops.border_start, loops.interior_used, arena))
                    name_chunk_points(c, layer, chunk, sink.count - chunk_start);
                else
                    status = finish_chunk(c, layer, loops, chunk_start, arena, sink);
            }
            if (status == Status::ok && sink.count <= sink.capacity) {
                uint32_t* chunk = sink.triangles + 3 * chunk_start;
                const size_t in_chunk = sink.count - chunk_start;
                if (kSurfaceFlips && layer.surface_flips && c.top_count > 0 &&
                    !flip_seam(c, layer, loops, chunk, in_chunk, arena))
                    return Status::out_of_memory;
                name_output_points(c, chunk, in_chunk);
            }
            if (status == Status::ok) {
                for (uint32_t i = 0; i < loops.top_count; ++i) loops.top[i] = ids[loops.top[i]];
                uint32_t* top = c.top;
                unsigned char* unused = c.top_unused;
                c.top = loops.top;
                c.top_unused = c.next_unused;
                c.top_count = loops.top_count;
                c.next_top = top;
                c.next_unused = unused;
                c.top_cylinder = layer.cyl;
                c.duplicates += result.counts.duplicates;
                c.collisions += result.counts.collisions;
                ++c.groups;
                result.last = last;
                result.points = n;
                result.cylinder = layer.cyl;
            }
        }
        arena.rewind(mark);
        if (status != Status::not_columnar) return status;
        if (final) {
            c.trailing += n;
            result.last = last;
            return Status::not_columnar;
        }
        ++last;
    }
}

// ---- reconstruct -----------------------------------------------------------------------------

// Workspace that lives through the whole call, then the largest scratch of any phase.
struct ReconstructMemory {
    double* bounds;        // layer bounds
    uint32_t* layer_start; // first position in `order` of each layer
    uint32_t* order;       // valid points grouped by layer
    SurfaceChain chain;
};

inline bool plan_reconstruct(ReconstructMemory& m, size_t count, size_t layer_limit,
                             Arena& arena) {
    m.bounds = arena.alloc<double>(layer_limit + 1);
    m.layer_start = arena.alloc<uint32_t>(layer_limit + 2);
    m.order = arena.alloc<uint32_t>(count);
    return allocate_chain(m.chain, count, arena);
}

// The largest scratch any phase takes on top of the plan, for groups of up to `count`
// points; 0 if that is beyond what size_t can count.
inline size_t reconstruct_scratch_size(size_t count, bool close) {
    size_t total = count + 1;
    // A group: its points, then the triangulation or the band, then the safety net.
    Arena group = Arena::measuring();
    group.alloc<Local>(count);
    size_t loaded = group.mark();
    group.alloc<uint32_t>(count);
    group.alloc<double>(2 * total);
    size_t mark = group.mark();
    for (int k = 0; k < 3; ++k) group.alloc<uint32_t>(count);  // the spatial sort
    group.rewind(mark);
    group.alloc<Local>(count);  // the points reordered
    group.rewind(mark);
    Triangulation tr;
    allocate_triangulation(tr, total, group);
    group.rewind(loaded);
    group.alloc<uint32_t>(count);  // the band: both loops' indices (together at most count)
    group.alloc<Local>(count);  // loop A's points
    group.alloc<double>(2 * count);
    group.alloc<double>(2);  // the second loop's alignment
    group.alloc<unsigned char>(count);
    group.alloc<double>(kIncircleScratch);
    group.rewind(0);
    // The chunk's safety net, once the group's points are released: its vertices are the
    // group's and the loop below's, at most `count` (the stream's window holds both), with
    // at most 2 triangles each.
    size_t triangles = 2 * count;
    group.alloc<uint32_t>(count);  // finish_chunk's triangles per vertex
    group.alloc<uint32_t>(count);  // seal_seam's loop positions and flags
    group.alloc<unsigned char>(count);
    group.alloc<uint32_t>(count);
    group.alloc<unsigned char>(triangles);
    mark = group.mark();
    group.alloc<uint32_t>(count);
    group.rewind(mark);
    group.alloc<uint32_t>(count + 1);
    group.alloc<uint32_t>(3 * triangles);
    group.alloc<uint64_t>(triangles);
    for (int k = 0; k < 4; ++k) group.alloc<uint32_t>(triangles);

    // (Counting the repeats of the vertices again, repeats_of_vertices takes a bit and at
    // most 16 bytes a point, less than a group's points take above: covered.)

    // Planning the layers: the automatic layers' profile, then each point's layer while the
    // points are grouped.
    Arena planning = Arena::measuring();
    ProfileBin* bins = nullptr;
    BinRange* ranges = nullptr;
    double* cuts = nullptr;
    allocate_profile(planning, profile_bin_count(count), &bins, &ranges, &cuts);
    planning.rewind(0);
    planning.alloc<uint32_t>(count);
    planning.alloc<uint32_t>(count);  // grouping in jobs: its tables (see group_by_layer_in_jobs)

    // The caps: every point on a boundary loop, as many triangles as the output can hold.
    Arena caps = Arena::measuring();
    if (close) {
        CapGraph graph;
        CapLoop loop;
        allocate_cap_graph(graph, count, triangles, caps);
        allocate_cap_loop(loop, count, caps);
    }

    if (group.failed || planning.failed || caps.failed) return 0;  // beyond size_t
    size_t most = group.high_water;
    if (planning.high_water > most) most = planning.high_water;
    if (caps.high_water > most) most = caps.high_water;
    return most;
}

// ---- parallel layers -----------------------------------------------------------------------
//
// With Options::run_jobs, every planned layer that could stand as a group on its own (at
// least kMinLayerPoints points, or the last one) is loaded and, if group_stands, triangulated
// ahead by a job, into its own part of the workspace; the job also keeps the triangles at
// its bottom loop and turns the rest to reader indices (keep_border). Then the groups are
// formed in order as always; a group that is one planned layer takes the job's result
// (add_group), stitches it and, when the safety net has nothing to do there, finishes the
// chunk reading only the band and that border (replay_chunk); any other group (merged
// layers, a chunk the net must repair) is triangulated then. So the result is the
// sequential one whatever the jobs' order and threads, and what runs in order is a small
// part of each layer's work. Jobs are contiguous runs of such layers with about equal point
// counts, each with the scratch of its largest layer.

#if !defined(STRATMESH_NO_PARALLEL_LAYERS)

struct ParallelLayers {
    bool ready;                  // the jobs ran
    const CloudReader* reader;
    const Frame* frame;
    const LayerQueue* queue;
    uint32_t slots;              // layers done ahead
    LayerAhead* ahead;           // per slot
    uint32_t* layer_of_slot;
    uint32_t* slot_of_layer;     // kNoIndex: not done ahead
    uint32_t job_count;
    uint32_t first_slot[kMaxJobs + 1];
    unsigned char* scratch[kMaxJobs];
    size_t scratch_bytes[kMaxJobs];

    const LayerAhead* ahead_of(uint32_t layer) const {
        uint32_t slot = slot_of_layer[layer];
        return slot == kNoIndex ? nullptr : ahead + slot;
    }
};

// Room for the results of `slots` layers holding `points` points in all, out of `layers`
// planned layers.
inline bool allocate_ahead(ParallelLayers& p, uint32_t slots, size_t points, size_t layers,
                           Arena& arena, uint32_t** triangles, uint32_t** loops,
                           unsigned char** loop_flags, uint32_t** borders) {
    p.ahead = arena.alloc<LayerAhead>(slots);
    p.layer_of_slot = arena.alloc<uint32_t>(slots);
    p.slot_of_layer = arena.alloc<uint32_t>(layers);
    *triangles = arena.alloc<uint32_t>(3 * 2 * points);
    *loops = arena.alloc<uint32_t>(2 * points);
    *loop_flags = arena.alloc<unsigned char>(2 * points);
    *borders = arena.alloc<uint32_t>(3 * (points / 4 + 4 * static_cast<size_t>(slots)));
    return !arena.failed;
}

// The border a layer of n points may keep for replay_chunk: its bottom loop holds a few
// times the square root of n points in a sound layer, with two or three triangles each.
// A thin layer's border can be most of its triangles: it is finished in order instead.
inline size_t border_capacity(size_t n) { return n / 4 + 4; }

inline bool may_stand_alone(const LayerQueue& q, uint32_t k) {
    size_t n = q.start[k + 1] - q.start[k];
    return n >= kMinLayerPoints || (k + 1 == q.planned && n >= 3);
}

// The job scratch bound: a run of layers needs the scratch of its largest, and scratch grows
// linearly with rounding, so jobs over n points in all need at most this.
inline size_t job_scratch_bound(size_t points) {
    size_t whole = reconstruct_scratch_size(points, false), one = reconstruct_scratch_size(0, false);
    const size_t slack = 1024;  // the rounding of every allocation, with room to spare
    if (whole == 0 || one > (SIZE_MAX - whole) / kMaxJobs - slack) return 0;
    return whole + kMaxJobs * (one + slack);
}

// What replay_chunk needs of a job's layer (see LayerAhead), then, if it can replay them,
// its triangles in reader indices (`ids`).
inline void keep_border(LayerAhead& a, const uint32_t* ids, size_t n, Arena& arena) {
    const unsigned char on_bottom = 1, has_triangle = 2;
    unsigned char* flags = arena.alloc<unsigned char>(n);
    a.replayable = flags != nullptr;
    a.border_count = a.interior_used = 0;
    if (!flags) return;
    std::memset(flags, 0, n);
    for (uint32_t i = 0; i < a.bottom_count; ++i) flags[a.bottom[i]] = on_bottom;
    for (size_t t = 0; t < a.triangle_count; ++t) {
        uint32_t* v = a.triangles + 3 * t;
        if ((flags[v[0]] | flags[v[1]] | flags[v[2]]) & on_bottom) {
            if (a.border_count < a.border_capacity)
                std::memcpy(a.border + 3 * a.border_count, v, 3 * sizeof(uint32_t));
            ++a.border_count;
        }
        for (size_t k = 0; k < 3; ++k) flags[v[k]] |= has_triangle;
    }
    for (size_t v = 0; v < n; ++v) a.interior_used += flags[v] == has_triangle;
    for (uint32_t i = 0; i < a.top_count; ++i) a.replayable = a.replayable && flags[a.top[i]] != 0;
    a.replayable = a.replayable && a.border_count <= a.border_capacity;
    if (!a.replayable) return;
    for (size_t k = 0; k < 3 * a.triangle_count; ++k) a.triangles[k] = ids[a.triangles[k]];
}

inline void run_layer_job(void* context, uint32_t index) {
    const ParallelLayers& p = *static_cast<const ParallelLayers*>(context);
    if (index >= p.job_count) return;  // a runner's mistake: no job of ours
    const LayerQueue& q = *p.queue;
    Arena arena = Arena::over(p.scratch[index], p.scratch_bytes[index]);
    for (uint32_t slot = p.first_slot[index]; slot < p.first_slot[index + 1]; ++slot) {
        LayerAhead& a = p.ahead[slot];
        const uint32_t k = p.layer_of_slot[slot];
        const size_t n = q.start[k + 1] - q.start[k];
        arena.rewind(0);
        LoadedLayer layer;
        if (!load_layer(*p.reader, *p.frame, q.ids + q.start[k], nullptr, n, q.bounds[k],
                        q.bounds[k + 1], arena, layer) ||
            !group_stands(n, q.bounds[k + 1] - q.bounds[k], layer.cyl.radius, k + 1 == q.planned))
            continue;
        a.fitted = layer.cyl;
        a.sectors = kCrescentLayers ? layer_sectors(layer) : 0;
        // The ends as add_group will see them if this layer is a group of its own.
        a.ends = (k == 0 ? kLowPole : 0) | (k + 1 == q.planned ? kHighPole : 0);
        find_closed_ends(layer, a.ends);
        TriangleSink sink = {a.triangles, 2 * n, 0, 0};
        LayerLoops loops = {a.bottom, 0, a.top, 0, a.bottom_flags, a.top_flags, 0, 0};
        a.status = triangulate_layer(*p.reader, layer, arena, sink, loops, a.counts);
        // An annulus through n points has at most 2n triangles; anything else is redone in order.
        if ((a.status != Status::ok && a.status != Status::not_columnar) || sink.count > sink.capacity)
            continue;
        a.cylinder = layer.cyl;
        a.triangle_count = sink.count;
        a.folds = sink.folds;
        a.bottom_count = loops.bottom_count;
        a.top_count = loops.top_count;
        if (a.status == Status::ok) keep_border(a, q.ids + q.start[k], n, arena);
        a.done = true;
    }
}

// Plans the jobs over the queue, carves their results and scratch from the arena and runs
// them. Returns with p.ready false (and the arena as it was) when there is nothing to gain or
// no room: the groups are then triangulated in order. The results stay in the arena; the
// jobs' scratch is released.
inline void triangulate_ahead(const Options& options, ParallelLayers& p, Arena& arena) {
    p.ready = false;
    const LayerQueue& q = *p.queue;
    uint32_t slots = 0;
    size_t points = 0;
    for (uint32_t k = 0; k < q.planned; ++k)
        if (may_stand_alone(q, k)) {
            ++slots;
            points += q.start[k + 1] - q.start[k];
        }
    if (slots < 2) return;
    const size_t mark = arena.mark();
    auto give_up = [&]() {
        arena.failed = false;
        arena.rewind(mark);
    };
    uint32_t* triangles = nullptr;
    uint32_t* loops = nullptr;
    unsigned char* loop_flags = nullptr;
    uint32_t* borders = nullptr;
    if (!allocate_ahead(p, slots, points, q.planned, arena, &triangles, &loops, &loop_flags,
                        &borders))
        return give_up();
    p.slots = slots;
    uint32_t slot = 0;
    size_t at = 0, border_at = 0;
    for (uint32_t k = 0; k < q.planned; ++k) {
        p.slot_of_layer[k] = kNoIndex;
        if (!may_stand_alone(q, k)) continue;
        const size_t n = q.start[k + 1] - q.start[k];
        LayerAhead& a = p.ahead[slot];
        a.done = false;
        a.triangles = triangles + 6 * at;
        a.bottom = loops + 2 * at;
        a.top = loops + 2 * at + n;
        a.bottom_flags = loop_flags + 2 * at;
        a.top_flags = loop_flags + 2 * at + n;
        a.border = borders + 3 * border_at;
        a.border_capacity = border_capacity(n);
        border_at += a.border_capacity;
        at += n;
        p.layer_of_slot[slot] = k;
        p.slot_of_layer[k] = slot++;
    }
    const size_t results = arena.mark();
    // Jobs: runs of slots with about equal point counts. A slot goes to the share of the
    // points its middle falls in, so equal layers get a job each (a threshold on a running
    // count would put a layer slightly under the mean together with the next).
    const uint32_t most = slots < kMaxJobs ? slots : kMaxJobs;
    uint32_t job = 0;
    uint64_t share_of_job = 0, before = 0;
    p.first_slot[0] = 0;
    for (uint32_t s = 0; s < slots; ++s) {
        const uint32_t k = p.layer_of_slot[s];
        const uint64_t n = q.start[k + 1] - q.start[k];
        const uint64_t share = (before + n / 2) * most / points;
        if (s > 0 && share > share_of_job) {
            p.first_slot[++job] = s;
            share_of_job = share;
        }
        before += n;
    }
    p.job_count = job + 1;
    p.first_slot[p.job_count] = slots;
    for (uint32_t j = 0; j < p.job_count; ++j) {
        size_t largest = 0;
        for (uint32_t s = p.first_slot[j]; s < p.first_slot[j + 1]; ++s) {
            uint32_t k = p.layer_of_slot[s];
            size_t n = q.start[k + 1] - q.start[k];
            if (n > largest) largest = n;
        }
        p.scratch_bytes[j] = reconstruct_scratch_size(largest, false) + Arena::kAlign;
        p.scratch[j] = arena.alloc<unsigned char>(p.scratch_bytes[j]);
    }
    if (arena.failed) return give_up();
    options.run_jobs(options.jobs_user, p.job_count, run_layer_job, &p);
    arena.rewind(results);
    p.ready = true;
}

// Starts the jobs for reconstruct(); returns the layers they triangulated.
inline size_t start_parallel_layers(const Options& options, const CloudReader& reader,
                                    const Frame& frame, const LayerQueue& queue, Arena& arena,
                                    ParallelLayers& parallel) {
    parallel.ready = false;
    if (!options.run_jobs) return 0;
    parallel.reader = &reader;
    parallel.frame = &frame;
    parallel.queue = &queue;
    triangulate_ahead(options, parallel, arena);
    size_t done = 0;
    for (uint32_t slot = 0; parallel.ready && slot < parallel.slots; ++slot)
        done += parallel.ahead[slot].done;
    return done;
}

// What the layers done ahead add to the workspace bound: their results, which stay, in
// `arena`; the jobs' scratch, which comes and goes before the groups' own, in *scratch.
inline bool plan_parallel_workspace(size_t point_count, size_t layer_limit, Arena& arena,
                                    size_t* scratch) {
    ParallelLayers p;
    uint32_t* triangles = nullptr;
    uint32_t* loops = nullptr;
    unsigned char* loop_flags = nullptr;
    uint32_t* borders = nullptr;
    size_t slots = point_count / kMinLayerPoints + 1;
    allocate_ahead(p, static_cast<uint32_t>(slots), point_count, layer_limit, arena, &triangles,
                   &loops, &loop_flags, &borders);
    size_t jobs = job_scratch_bound(point_count);
    if (jobs > *scratch) *scratch = jobs;
    return jobs != 0;
}

#else  // STRATMESH_NO_PARALLEL_LAYERS: Options::run_jobs is ignored.

struct ParallelLayers {
    bool ready;
    const LayerAhead* ahead_of(uint32_t) const { return nullptr; }
};

inline size_t start_parallel_layers(const Options&, const CloudReader&, const Frame&,
                                    const LayerQueue&, Arena&, ParallelLayers& parallel) {
    parallel.ready = false;
    return 0;
}

inline bool plan_parallel_workspace(size_t, size_t, Arena&, size_t*) { return true; }

#endif  // STRATMESH_NO_PARALLEL_LAYERS

inline void notify(const Options& options, Phase phase, double fraction) {
    if (options.progress) options.progress(options.progress_user, phase, fraction);
}

// The bytes the cloud's coordinates lie in.
inline ByteRange cloud_bytes(const Cloud& cloud) {
    const size_t point_bytes = 3 * (cloud.scalar == Scalar::float32 ? sizeof(float) : sizeof(double));
    return strided_range(cloud.xyz, cloud.count, cloud.stride_bytes ? cloud.stride_bytes : point_bytes,
                         point_bytes);
}

// True if any two of the caller's buffers share a byte (the report and its layer array
// included): checked before anything is written. A count beyond the limit is refused as
// too_many_points instead.
inline bool reconstruct_buffers_overlap(const Cloud& cloud, void* workspace,
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

inline Status check_reconstruct_arguments(const Cloud& cloud, uint32_t* triangles,
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

// The drop_outliers step: the bitmap stays in `arena` for the whole call (reader.dropped),
// the grid's scratch is given back. False if the workspace is too small.
inline bool find_outliers(CloudReader& reader, size_t count, Arena& arena, Report& rep) {
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

// Reads a cloud that passed check_reconstruct_arguments.
inline CloudReader reader_of(const Cloud& cloud) {
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
inline size_t refused_at(const CloudReader& reader, size_t count, const CloudSums& sums,
                         const Options& options) {
    if (sums.valid == count || (options.flags & skip_invalid_points)) return count;
    size_t first = 0;
    while (reader.valid(first)) ++first;
    return first;
}

// Counts the points with a NaN or infinite coordinate in rep.points.rejected_count, or refuses the
// cloud (see refused_at).
inline Status reject_invalid_points(const CloudReader& reader, size_t count,
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

// The lowest and highest frame height of the valid points.
inline void height_range(const CloudReader& cloud, size_t count, const Frame& frame, double* lo,
                         double* hi) {
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        const double h = frame.height(cloud.point(i));
        if (h < *lo) *lo = h;
        if (h > *hi) *hi = h;
    }
}

// height_range without a pass over the cloud, where the axis is a coordinate axis (and
// the frame not halved): a height is then (p_k - origin_k) * scale plus zeros, exactly
// that value, and rounding keeps the order, so the lowest and highest coordinates along
// the axis give the same two heights, bit for bit. False otherwise.
inline bool height_range_from_extremes(const Frame& frame, double* lo, double* hi) {
    const double axis[3] = {frame.axis.x, frame.axis.y, frame.axis.z};
    const double low[3] = {frame.low.x, frame.low.y, frame.low.z};
    const double high[3] = {frame.high.x, frame.high.y, frame.high.z};
    const double origin[3] = {frame.origin.x, frame.origin.y, frame.origin.z};
    for (int k = 0; k < 3; ++k) {
        if (frame.halved || axis[k] != 1 || axis[(k + 1) % 3] != 0 || axis[(k + 2) % 3] != 0)
            continue;
        *lo = (low[k] - origin[k]) * frame.scale;
        *hi = (high[k] - origin[k]) * frame.scale;
        return true;
    }
    return false;
}

// Groups the valid points by layer (input order within a layer): a counting sort, with each
// point's layer kept in `layer` (count entries of scratch) between its two passes. With
// `staged` (optional, as many entries as valid points), the points in frame coordinates
// go there in the same order.
inline void group_by_layer(const CloudReader& cloud, size_t count, const Frame& frame,
                           const LayerPlan& plan, uint32_t* layer, Local* staged,
                           ReconstructMemory& m) {
    std::memset(m.layer_start, 0, sizeof(uint32_t) * (plan.count + 2));
    const double per_height =
        kFastLoops ? plan.count / (plan.bounds[plan.count] - plan.bounds[0]) : 0;
    for (size_t i = 0; i < count; ++i) {
        layer[i] = cloud.valid(i) ? layer_of(plan, frame.height(cloud.point(i)), per_height)
                                  : kNoIndex;
        if (layer[i] != kNoIndex) ++m.layer_start[layer[i] + 2];
    }
    for (uint32_t k = 0; k < plan.count; ++k) m.layer_start[k + 2] += m.layer_start[k + 1];
    for (size_t i = 0; i < count; ++i) {
        if (layer[i] == kNoIndex) continue;
        const uint32_t position = m.layer_start[layer[i] + 1]++;
        m.order[position] = static_cast<uint32_t>(i);
        if (staged) staged[position] = frame.local(cloud.point(i));
    }
}

// ---- passes over all points as jobs ----
//
// With Options::run_jobs, a pass over all points that gives the same bits in any order
// (grouping the points by layer) is cut into kPassRuns runs of consecutive points, run as
// jobs. As for the layers' jobs (see JobRunner), a run the runner skips is done in order
// afterwards, and a run done again changes nothing.
const uint32_t kPassRuns = 16;

// The first point of run k of `count` points.
inline size_t run_start(size_t count, uint32_t k) {
    return static_cast<size_t>(static_cast<uint64_t>(count) * k / kPassRuns);
}

template <class Pass> struct PassJobs {
    Pass* pass;
    bool done[kPassRuns];
};

template <class Pass> inline void run_pass_job(void* context, uint32_t index) {
    PassJobs<Pass>& jobs = *static_cast<PassJobs<Pass>*>(context);
    if (index >= kPassRuns) return;  // a runner's mistake: no run of ours
    jobs.pass->run(index);
    jobs.done[index] = true;
}

template <class Pass> inline void run_pass(const Options& options, Pass& pass) {
    PassJobs<Pass> jobs = {&pass, {}};
    options.run_jobs(options.jobs_user, kPassRuns, run_pass_job<Pass>, &jobs);
    for (uint32_t k = 0; k < kPassRuns; ++k)
        if (!jobs.done[k]) pass.run(k);
}

// group_by_layer's counting sort, run by run: first each point's layer and each run's count
// per layer, then (once `first` holds each run's first position per layer) the scatter. The
// positions come out as in group_by_layer.
struct GroupingPass {
    const CloudReader* cloud;
    const Frame* frame;
    const LayerPlan* plan;
    double per_height;
    size_t count;
    uint32_t* layer;
    uint32_t* order;
    uint32_t* counts;    // per run, per layer: its points there
    uint32_t* first;     // per run, per layer: its first position there
    uint32_t* next;      // per run, per layer: the scatter's next position
    bool scatter;

    void run(uint32_t k) {
        const size_t layers = plan->count, begin = run_start(count, k), end = run_start(count, k + 1);
        if (!scatter) {
            uint32_t* c = counts + k * layers;
            std::memset(c, 0, layers * sizeof(uint32_t));
            for (size_t i = begin; i < end; ++i) {
                layer[i] = cloud->valid(i) ? layer_of(*plan, frame->height(cloud->point(i)), per_height)
                                           : kNoIndex;
                if (layer[i] != kNoIndex) ++c[layer[i]];
            }
            return;
        }
        uint32_t* n = next + k * layers;
        std::memcpy(n, first + k * layers, layers * sizeof(uint32_t));
        for (size_t i = begin; i < end; ++i)
            if (layer[i] != kNoIndex) order[n[layer[i]]++] = static_cast<uint32_t>(i);
    }
};

// group_by_layer without staging, as jobs; false (nothing done) where its three tables of a
// count per run and layer would take more than one count per point, or do not fit.
inline bool group_by_layer_in_jobs(const Options& options, const CloudReader& cloud,
                                   size_t count, const Frame& frame, const LayerPlan& plan,
                                   uint32_t* layer, ReconstructMemory& m, Arena& arena) {
    const size_t table = kPassRuns * static_cast<size_t>(plan.count);
    if (!kParallelLayers || !options.run_jobs || 3 * table > count) return false;
    const size_t mark = arena.mark();
    GroupingPass pass = {&cloud, &frame, &plan, 0, count, layer, m.order,
                         arena.alloc<uint32_t>(table), arena.alloc<uint32_t>(table),
                         arena.alloc<uint32_t>(table), false};
    if (arena.failed) {
        arena.failed = false;
        arena.rewind(mark);
        return false;
    }
    pass.per_height = kFastLoops ? plan.count / (plan.bounds[plan.count] - plan.bounds[0]) : 0;
    run_pass(options, pass);
    // Layer by layer, run by run: the positions of a counting sort in input order.
    uint32_t position = 0;
    for (uint32_t l = 0; l < plan.count; ++l) {
        m.layer_start[l] = position;
        for (uint32_t k = 0; k < kPassRuns; ++k) {
            pass.first[k * plan.count + l] = position;
            position += pass.counts[k * plan.count + l];
        }
    }
    m.layer_start[plan.count] = position;
    pass.scatter = true;
    run_pass(options, pass);
    arena.rewind(mark);
    return true;
}

STRATMESH_SMALL_NOINLINE inline void report_frame(const Frame& frame, Report& rep) {
    rep.axis[0] = frame.axis.x;
    rep.axis[1] = frame.axis.y;
    rep.axis[2] = frame.axis.z;
    rep.axis_origin[0] = frame.origin.x;
    rep.axis_origin[1] = frame.origin.y;
    rep.axis_origin[2] = frame.origin.z;
}

inline void describe_layer(const Frame& frame, const Cylinder& cyl, double bottom, double top,
                           size_t points, size_t triangles, size_t folds, LayerInfo& info) {
    info.bottom = frame.user_height(bottom);
    info.top = frame.user_height(top);
    double mid = (bottom + top) / 2 / frame.scale, cx = cyl.cx / frame.scale, cy = cyl.cy / frame.scale;
    Vec3 c = {frame.origin.x + frame.e1.x * cx + frame.e2.x * cy + frame.axis.x * mid,
              frame.origin.y + frame.e1.y * cx + frame.e2.y * cy + frame.axis.y * mid,
              frame.origin.z + frame.e1.z * cx + frame.e2.z * cy + frame.axis.z * mid};
    info.centre[0] = c.x;
    info.centre[1] = c.y;
    info.centre[2] = c.z;
    info.radius = cyl.radius / frame.scale;
    info.point_count = static_cast<uint32_t>(points);
    info.triangle_count = static_cast<uint32_t>(triangles);
    info.fold_count = static_cast<uint32_t>(folds);
    info.closed_ends = cyl.poles;
}

}  // namespace detail



namespace detail {

// The workspace bound of mesh_tube() (with read_cloud()) for point_count points.
inline size_t tube_workspace_size(size_t point_count, const Options& options) {
    if (point_count > kMaxPoints - 1) return 0;
    Arena arena = Arena::measuring();
    // drop_outliers, as find_outliers allocates: the bitmap stays, the grid comes and goes
    // before the rest is allocated.
    size_t outlier_bytes = 0;
    if (kDropOutliers && (options.flags & drop_outliers)) {
        Arena grid = Arena::measuring();
        grid.alloc<unsigned char>(point_count / 8 + 1);
        allocate_cell_scratch(grid, point_count);
        if (grid.failed) return 0;
        outlier_bytes = grid.required_bytes();
        arena.alloc<unsigned char>(point_count / 8 + 1);
    }
    ReconstructMemory m;
    const size_t layer_limit = planned_layer_limit(point_count, options);
    plan_reconstruct(m, point_count, layer_limit, arena);
    size_t scratch = reconstruct_scratch_size(point_count,
                                                      (options.flags & close_ends) != 0);
    // With a runner, the layers done ahead (at most one per kMinLayerPoints points, plus the
    // last) stay while the groups are formed.
    if (options.run_jobs &&
        !plan_parallel_workspace(point_count, layer_limit, arena, &scratch))
        return 0;
    if (arena.failed || scratch == 0 || scratch > SIZE_MAX - arena.required_bytes()) return 0;
    const size_t bytes = arena.required_bytes() + scratch;
    return bytes > outlier_bytes ? bytes : outlier_bytes;
}

// The chain's counts into the report, with the reason when a valid point is not a vertex.
inline void report_chain(const SurfaceChain& chain, size_t valid, Report& rep) {
    rep.points.duplicate_count = chain.duplicates;
    rep.diagnostics.illegal_removed_count = chain.removed;
    rep.points.used_count = chain.used;
    rep.diagnostics.diagonal_swap_count = chain.swaps;
    if (chain.trailing > 0)
        rep.detail = "the points of the last layers do not surround the axis: they are not "
                     "vertices";
    else if (chain.collisions > 0)
        rep.detail = "some points share their place on the unrolled layer with another point "
                     "(the layer is not star-shaped around its centre there): not vertices";
    else if (valid - rep.points.duplicate_count > chain.used)
        rep.detail = "the manifold safety net removed the triangles of some points";
}

// The repeats of the output's vertices among the points that are not vertices: what
// Report::points.duplicate_count counts. The layers count a repeat as they triangulate it;
// where a point then ends with no triangle (the safety net removed them, or the layer left
// it out), its repeats are unused too, so where some points are not vertices they are
// counted again from the output, with a hash table of the vertices' coordinates in the
// workspace. Returns SIZE_MAX if the workspace is too small.
inline size_t repeats_of_vertices(const CloudReader& reader, size_t count,
                                  const uint32_t* triangles, size_t triangle_count,
                                  Arena& arena) {
    const size_t mark = arena.mark();
    unsigned char* used = arena.alloc<unsigned char>(count / 8 + 1);
    size_t slots = 1;
    while (slots < 2 * count + 2) slots *= 2;
    uint32_t* table = arena.alloc<uint32_t>(slots);
    if (arena.failed) return SIZE_MAX;
    std::memset(used, 0, count / 8 + 1);
    std::memset(table, 0xFF, slots * sizeof(uint32_t));
    auto slot_of = [&](Vec3 p) { return coordinate_hash(p.x, p.y + p.z * 0.5) & (slots - 1); };
    auto same = [](Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
    for (size_t k = 0; k < 3 * triangle_count; ++k) {
        const uint32_t v = triangles[k];
        if ((used[v >> 3] >> (v & 7)) & 1) continue;
        used[v >> 3] |= static_cast<unsigned char>(1u << (v & 7));
        const Vec3 p = reader.point(v);
        size_t s = slot_of(p);
        while (table[s] != kNoIndex) s = (s + 1) & (slots - 1);
        table[s] = v;
    }
    size_t repeats = 0;
    for (size_t i = 0; i < count; ++i) {
        if (((used[i >> 3] >> (i & 7)) & 1) || !reader.valid(i)) continue;
        const Vec3 p = reader.point(i);
        for (size_t s = slot_of(p); table[s] != kNoIndex; s = (s + 1) & (slots - 1))
            if (same(reader.point(table[s]), p)) {
                ++repeats;
                break;
            }
    }
    arena.rewind(mark);
    return repeats;
}

// A cloud as a tube reads it: in place, the points left out (outliers, or the points of
// other parts) marked in the reader's optional bitmap, and the sums of the points kept.
struct TubeInput {
    CloudReader reader;
    size_t count;
    CloudSums sums;
    uint32_t cut_ends;  // ends that are cuts, never closed (Frame::cut_ends), besides open_ends
};

// Whether this build holds every feature the flags ask for (STRATMESH_SMALL_CODE leaves
// some out).
inline bool flags_compiled(const Options& options) {
    const uint32_t f = options.flags;
    return (kDropOutliers || !(f & drop_outliers)) && (kSurfaceFlips || !(f & surface_flips)) &&
           (kClosedEnds || !(f & open_ends));
}

// Reads a cloud that passed check_reconstruct_arguments: refuses or counts its NaN and
// infinite points, leaves out its outliers (drop_outliers; the bitmap stays in `arena`)
// and sums what is kept.
inline Status read_cloud(const Cloud& cloud, const Options& options, Arena& arena, Report& rep,
                         TubeInput& in) {
    in.reader = reader_of(cloud);
    in.count = cloud.count;
    // One pass serves the check for invalid points, the frame and the distinct points.
    in.sums = sum_cloud(in.reader, cloud.count);
    Status status = reject_invalid_points(in.reader, cloud.count, in.sums, options, rep);
    if (status != Status::ok) return status;
    status = validate_layer_options(options);
    if (status != Status::ok) return status;
    if (!flags_compiled(options)) {
        rep.detail = kNotCompiledDetail;
        return Status::not_compiled;
    }
    if (kDropOutliers && (options.flags & drop_outliers)) {
        if (!find_outliers(in.reader, cloud.count, arena, rep)) return Status::out_of_memory;
        in.sums = sum_cloud(in.reader, cloud.count);  // without the outliers
    }
    return Status::ok;
}

// Plans the layers of a tube along the frame's axis and groups its points by layer.
inline Status plan_tube_layers(const TubeInput& in, const Options& options, const Frame& frame,
                               double lo, double hi, Arena& arena, ReconstructMemory& m,
                               LayerPlan& plan, Local** staged, Report& rep) {
    const size_t valid = in.sums.valid;
    const size_t layer_limit = planned_layer_limit(in.count, options);
    if (!plan_reconstruct(m, in.count, layer_limit, arena)) return Status::out_of_memory;
    notify(options, Phase::layers, 0);
    plan = {m.bounds, 0, (hi - lo) * kCutTolerance};
    if (automatic_layers(options)) {
        const size_t mark = arena.mark();
        const uint32_t bins = profile_bin_count(valid);
        ProfileBin* profile = nullptr;
        BinRange* ranges = nullptr;
        double* cuts = nullptr;
        allocate_profile(arena, bins, &profile, &ranges, &cuts);
        if (arena.failed) return Status::out_of_memory;
        plan_automatic_layers(in.reader, in.count, valid, frame, lo, hi, profile, ranges, cuts,
                              bins, plan);
        arena.rewind(mark);
    } else {
        plan_layers(options, lo, hi, in.count, frame, plan);
    }
    rep.layers.planned_count = plan.count;
    // Without a runner, the grouped points are also staged in the workspace's end room when
    // there is room: each layer is then loaded in sequence instead of gathered from the
    // whole cloud, for as long as the layers before it leave that room untouched. Either
    // way the same coordinates are loaded.
    *staged = nullptr;
    const size_t mark = arena.mark();
    uint32_t* layer = arena.alloc<uint32_t>(in.count);
    if (arena.failed) return Status::out_of_memory;
    if (kStagePoints && !(kParallelLayers && options.run_jobs))
        *staged = static_cast<Local*>(arena.room_at_end(saturating_product(valid, sizeof(Local))));
    if (!group_by_layer_in_jobs(options, in.reader, in.count, frame, plan, layer, m, arena))
        group_by_layer(in.reader, in.count, frame, plan, layer, *staged, m);
    arena.rewind(mark);
    return Status::ok;
}

// Triangulates the planned layers one group after another, each stitched to the one below,
// into `sink`; the layers used go to the report.
inline Status triangulate_tube(const TubeInput& in, const Options& options, const Frame& frame,
                               const LayerPlan& plan, Local* staged, Arena& arena,
                               ReconstructMemory& m, TriangleSink& sink, Report& rep) {
    notify(options, Phase::triangulate, 0);
    SurfaceChain& chain = m.chain;
    chain.frame = frame;
    chain.reader = in.reader;
    chain.output_id = nullptr;
    const LayerQueue queue = {m.order, staged, m.layer_start, plan.bounds, plan.count, true};
    ParallelLayers parallel;
    rep.layers.parallel_count = start_parallel_layers(options, in.reader, frame, queue, arena, parallel);
    for (uint32_t first = 0; first < plan.count;) {
        GroupResult group;
        const Status status = add_group(chain, queue, first, arena, sink, group,
                                        parallel.ready ? parallel.ahead_of(first) : nullptr);
        if (status == Status::not_columnar) break;
        if (status != Status::ok) return status;
        if (rep.layers.used_count < rep.layers.info_capacity)
            describe_layer(frame, group.cylinder, plan.bounds[first], plan.bounds[group.last + 1],
                           group.points - group.counts.duplicates, group.triangles, group.folds,
                           rep.layers.info[rep.layers.used_count]);
        ++rep.layers.used_count;
        first = group.last + 1;
        notify(options, Phase::triangulate, static_cast<double>(first) / plan.count);
    }
    rep.points.duplicate_count = chain.duplicates;
    if (rep.layers.used_count == 0) {
        rep.detail = "no layer's points surround the axis: the cloud is not columnar around "
                     "it (try another axis)";
        return Status::not_columnar;
    }
    notify(options, Phase::stitch, 1);
    if (sink.count == 0) {
        rep.detail = "every point lies on the boundary of its layer: too few points to span a "
                     "surface";
        return Status::too_few_points;
    }
    return Status::ok;
}

// A surface this much smaller than the square of the cloud's extent has no area: its
// points lie on a line up to rounding, or a few points far away set the extent and the rest
// collapse in the frame (a speck at 1e30 beside a tube of size 1). Its triangles would be
// slivers of no area, so the cloud is refused instead (Status::degenerate; see
// explain_no_area() for why).
const double kLeastArea = 0x1p-40;
// The triangles whose areas estimate the surface's: enough to see area where there is some.
const size_t kAreaSample = 1024;

// Whether the triangles, every k-th of them, have next to no area beside the square of the
// cloud's own extent (about frame.cloud_share in the frame).
inline bool has_no_area(const CloudReader& reader, const Frame& frame, const uint32_t* tri,
                        size_t count) {
    const size_t step = count > kAreaSample ? count / kAreaSample : 1;
    double area = 0;
    size_t seen = 0;
    for (size_t t = 0; t < count; t += step, ++seen) {
        const Vec3 a = scaled(reader.point(tri[3 * t]), frame.scale);
        const Vec3 n = cross(scaled(reader.point(tri[3 * t + 1]), frame.scale) - a,
                             scaled(reader.point(tri[3 * t + 2]), frame.scale) - a);
        area += std::sqrt(dot(n, n)) / 2;
    }
    return seen > 0 && area * (static_cast<double>(count) / static_cast<double>(seen)) <
                           kLeastArea * frame.cloud_share * frame.cloud_share;
}

// Closes the tube's boundary loops with caps (close_ends) and fills the caps' report.
inline Status cap_tube(const TubeInput& in, const Options& options, const Frame& frame,
                       Arena& arena, uint32_t* triangles, size_t capacity, size_t& count,
                       size_t* triangle_count, Report& rep) {
    notify(options, Phase::manifold, 0);
    if (!(options.flags & close_ends)) return Status::ok;
    CapCounts caps = {0, 0, 0, 0};
    size_t needed = 0;
    const Status status = cap_boundary_loops(triangles, count, capacity, in.reader, in.count,
                                             frame, arena, caps, &needed);
    rep.caps.closed_count = caps.closed;
    rep.caps.open_count = caps.left_open;
    rep.caps.triangle_count = caps.triangles;
    rep.caps.wall_flip_count = caps.wall_flips;
    if (status == Status::triangle_capacity) {
        *triangle_count = needed;
        rep.triangle_count = needed;
        rep.detail = kCapsTooLargeDetail;
    }
    return status;
}

// One tube through the kept points of `in`: the frame, the layers, their triangulation and
// stitching, the caps. `rep` holds the counts of read_cloud; Report::points.unused_count
// is left to the caller.
inline Status mesh_tube(const TubeInput& in, const Options& options, Arena& arena,
                        uint32_t* triangles, size_t triangle_capacity, size_t* triangle_count,
                        Report& rep) {
    Frame frame;
    Status status = choose_frame(in.sums, options, frame);
    if (status != Status::ok) return status;
    if (kClosedEnds) frame.cut_ends |= in.cut_ends;
    report_frame(frame, rep);
    if (in.sums.distinct < 3) {
        rep.detail = "fewer than 3 distinct valid points";
        return Status::too_few_points;
    }
    double lo = DBL_MAX, hi = -DBL_MAX;
    if (!kFastLoops || !height_range_from_extremes(frame, &lo, &hi))
        height_range(in.reader, in.count, frame, &lo, &hi);
    if (!(hi > lo)) {
        rep.detail = "every point has the same height along the axis";
        return Status::flat_cloud;
    }
    ReconstructMemory m;
    LayerPlan plan;
    Local* staged = nullptr;
    status = plan_tube_layers(in, options, frame, lo, hi, arena, m, plan, &staged, rep);
    if (status != Status::ok) return status;
    TriangleSink sink = {triangles, triangle_capacity, 0, 0};
    status = triangulate_tube(in, options, frame, plan, staged, arena, m, sink, rep);
    if (status != Status::ok) return status;
    if (sink.count > triangle_capacity) {
        *triangle_count = sink.count;
        rep.triangle_count = sink.count;
        rep.detail = "the triangle array is too small; triangle_count says how many are needed";
        return Status::triangle_capacity;
    }
    if (kDegenerateCheck && has_no_area(in.reader, frame, triangles, sink.count))
        return Status::degenerate;
    size_t count = sink.count;
    status = cap_tube(in, options, frame, arena, triangles, triangle_capacity, count,
                      triangle_count, rep);
    if (status != Status::ok) return status;
    *triangle_count = count;
    rep.triangle_count = count;
    rep.diagnostics.fold_count = sink.folds;
    if (in.sums.valid - m.chain.duplicates > m.chain.used) {  // some points are not vertices
        const size_t repeats = repeats_of_vertices(in.reader, in.count, triangles, count, arena);
        if (repeats == SIZE_MAX) return Status::out_of_memory;
        m.chain.duplicates = repeats;
    }
    report_chain(m.chain, in.sums.valid, rep);
    if (!rep.detail && rep.caps.open_count > 0) rep.detail = kLoopLeftOpenDetail;
    notify(options, Phase::done, 1);
    return Status::ok;
}


}  // namespace detail

}  // namespace stratmesh
