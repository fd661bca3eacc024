// >>chain ================================================================================
// The surface as a chain of chunks: a group of layers with its band, sealed to the one below.

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

static inline bool allocate_chain(SurfaceChain& c, size_t points, Arena& arena) {
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

static inline void count_corners(const uint32_t* tri, size_t count, uint32_t* degree,
                                 size_t vertices) {
    std::memset(degree, 0, vertices * sizeof(uint32_t));
    for (size_t k = 0; k < 3 * count; ++k) ++degree[tri[k]];
}

// For the loop whose point i has id `id_of(i)` (n points, in loop order): which of the
// loop's edges the triangles use, as kHasNextEdge / kHasPreviousEdge bits added to flags[i].
// position[v] is v's place in the loop or kNoIndex, for every id v in the triangles.
static inline void mark_loop_edges(const uint32_t* tri, size_t count, const uint32_t* position,
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
static inline size_t seal_seam(uint32_t* tri, size_t& count, size_t below_count, size_t vertices,
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
static inline bool loop_fans_are_one_piece(const uint32_t* tri, size_t count, size_t below,
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
static inline void name_chunk_points(const SurfaceChain& c, const LoadedLayer& layer, uint32_t* tri,
                                     size_t count) {
    for (size_t k = 0; k < 3 * count; ++k) {
        uint32_t l = tri[k];
        uint32_t id = l < layer.count ? layer.ids[l] : c.top[l - layer.count];
        tri[k] = !kSurfaceFlips && c.output_id ? c.output_id[id] : id;
    }
}

// A final chunk's triangles from reader indices to output indices (with kSurfaceFlips).
static inline void name_output_points(const SurfaceChain& c, uint32_t* tri, size_t count) {
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
static inline bool chunk_is_sound(SurfaceChain& c, const LoadedLayer& layer,
                                  const LayerLoops& loops, const uint32_t* at_loops, size_t count,
                                  size_t interior_used, Arena& arena) {
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
static inline Status finish_chunk(SurfaceChain& c, const LoadedLayer& layer,
                                  const LayerLoops& loops, size_t chunk_start, Arena& arena,
                                  TriangleSink& sink) {
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
static inline uint32_t planned_sectors(const SurfaceChain& c, const LayerQueue& q, uint32_t first,
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
static inline uint32_t crescent_gap(uint32_t held, size_t count) {
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
static inline bool joins_crescent(const SurfaceChain& c, const LayerQueue& q, uint32_t first,
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
static inline bool group_stands(size_t n, double height, double radius, bool final) {
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
    CoincidentPoints counts;
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
    CoincidentPoints counts;
    size_t triangles, folds; // its chunk, before the safety net
    Cylinder cylinder;
};

// What triangulate_layer would do now, from a job's result.
static inline Status take_ahead(const LayerAhead& ahead, TriangleSink& sink, LayerLoops& loops,
                                CoincidentPoints& counts) {
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
static inline bool replay_chunk(SurfaceChain& c, const LoadedLayer& layer, const LayerLoops& loops,
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

}  // namespace detail
}  // namespace stratmesh
