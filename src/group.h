// >>group ================================================================================
// A group of layers: triangulated, stitched to the loop below, flipped and sealed.

namespace stratmesh {
namespace detail {

// Where the sink and the chain's swap count stood: a chunk or a band is undone back to it.
struct SinkMark {
    size_t count, folds, swaps;
};

static inline SinkMark mark_sink(const SurfaceChain& c, const TriangleSink& sink) {
    return {sink.count, sink.folds, c.swaps};
}

static inline void rewind_sink(SurfaceChain& c, TriangleSink& sink, const SinkMark& m) {
    sink.count = m.count;
    sink.folds = m.folds;
    c.swaps = m.swaps;
}

// One try at the group of planned layers [first, last]: its points (loaded unless a job
// triangulated it ahead), its loops, its chunk and how it went.
struct GroupTry {
    uint32_t first, last;
    bool final;             // it takes the last planned layer of a complete queue
    const uint32_t* ids;    // its points' reader indices
    const Local* staged;    // their staged coordinates, or null
    size_t n;
    double h0, h1;
    uint32_t ends;          // the surface's ends it holds (kLowPole, kHighPole)
    // By the job ahead: its triangles come from there. Read with kParallelLayers, so that
    // a build without jobs drops what only their results reach.
    bool triangulated;
    size_t mark;            // the arena before the try
    LoadedLayer layer;
    LayerLoops loops;
    SinkMark chunk;         // the sink before its chunk
    Status status;
};

// Sets up the try for planned layers [g.first, g.last] and loads their points, unless the
// layer done ahead is the group. False if the arena is too small.
static inline bool load_group(const SurfaceChain& c, const LayerQueue& q, const LayerAhead* ahead,
                              Arena& arena, GroupTry& g) {
    g.ids = q.ids + q.start[g.first];
    g.staged = q.staged ? q.staged + q.start[g.first] : nullptr;
    g.n = q.start[g.last + 1] - q.start[g.first];
    g.h0 = q.bounds[g.first];
    g.h1 = q.bounds[g.last + 1];
    g.mark = arena.mark();
    // The surface's ends: its first group, and the group that takes the last planned layer.
    g.ends = (c.top_count == 0 ? kLowPole : 0) | (g.final ? kHighPole : 0);
    g.triangulated = kParallelLayers && ahead && ahead->done && g.last == g.first &&
                     ahead->ends == g.ends;
    g.layer = {g.ids, g.n, nullptr, g.triangulated ? ahead->cylinder : Cylinder{},
               kSurfaceFlips && c.frame.surface_flips, g.ends, c.frame.cut_ends};
    return g.triangulated ||
           load_layer(c.reader, c.frame, g.ids, g.staged, g.n, g.h0, g.h1, arena, g.layer);
}

// What a loaded group that does not take the last planned layer grows by before it is
// triangulated: nothing, the next planned layer, all the rest of the queue, or what the
// queue has yet to receive (the group waits).
enum class Growth { none, next_layer, rest, wait };

// A crescent, the group or the next planned layer (see kRingGap), joins the next layer; a
// rest too small or thin to stand joins the group once the queue is complete.
static inline Growth group_growth(const SurfaceChain& c, const LayerQueue& q,
                                  const LayerAhead* ahead, const GroupTry& g) {
    if (g.final) return Growth::none;
    if (kCrescentLayers &&
        joins_crescent(c, q, g.first, g.last,
                       kParallelLayers && g.triangulated ? ahead->fitted : g.layer.cyl,
                       kParallelLayers && g.triangulated ? ahead->sectors : layer_sectors(g.layer)))
        return Growth::next_layer;
    const size_t rest = q.start[q.planned] - q.start[g.last + 1];
    const double rest_height = q.bounds[q.planned] - q.bounds[g.last + 1];
    if (rest >= kMinLayerPoints && thick_enough(rest, rest_height, g.layer.cyl.radius))
        return Growth::none;
    return q.complete ? Growth::rest : Growth::wait;
}

// Whether an entry of either loop of the band was peeled.
static inline bool band_loops_peeled(const SurfaceChain& c, const LayerLoops& loops) {
    for (uint32_t i = 0; i < c.top_count; ++i)
        if (c.top_unused[i] & kPassBits) return true;
    for (uint32_t j = 0; j < loops.bottom_count; ++j)
        if (loops.bottom_flags[j] & kPassBits) return true;
    return false;
}

// The entries of the band's loops marked kUnpeeled.
static inline size_t band_loops_unpeeled(const SurfaceChain& c, const LayerLoops& loops) {
    return count_unpeeled(c.top_unused, c.top_count) +
           count_unpeeled(loops.bottom_flags, loops.bottom_count);
}

// Stitches the triangulated group to the chain's top loop, if any. A band between peeled
// loops that folds (a peeled loop can dip where the other cannot follow) is stitched again
// with the peel groups around its folds put back (kLocalUnpeel; see "peeling" in >>layer
// triangulation and kUnpeelRounds); where it still folds, or no peeled entry is near a
// fold, between the loops as they were before peeling, with all their peeled triangles
// put back.
static inline void stitch_to_chain(SurfaceChain& c, GroupTry& g, Arena& arena, TriangleSink& sink) {
    if (g.status != Status::ok || c.top_count == 0) return;
    const SinkMark band = mark_sink(c, sink);
    // Rounds before the last put back the groups marked; the last, all.
    for (uint32_t round = 0; round < kUnpeelRounds; ++round) {
        const bool last_round = round + 1 == kUnpeelRounds;
        if (kLocalUnpeel && (round == 0 || last_round)) {
            mark_unpeeled(c.top_unused, c.top_count, last_round);
            mark_unpeeled(g.loops.bottom_flags, g.loops.bottom_count, last_round);
        }
        rewind_sink(c, sink, band);
        const size_t marked = kLocalUnpeel ? band_loops_unpeeled(c, g.loops) : 0;
        if (!stitch_layers(c.reader, c.frame, c.top_cylinder, c.top, c.top_unused, c.top_count,
                           g.layer, g.loops, last_round, arena, sink, &c.swaps)) {
            g.status = Status::out_of_memory;
            return;
        }
        if (sink.folds == band.folds || !band_loops_peeled(c, g.loops)) return;
        if (kLocalUnpeel && band_loops_unpeeled(c, g.loops) == marked && round + 2 < kUnpeelRounds)
            round = kUnpeelRounds - 2;  // no group near a fold: the last round
    }
}

// The group's chunk before the safety net: its layer's triangles (the job's or made here)
// and the band to the chain's top loop.
static inline void make_chunk(SurfaceChain& c, const LayerAhead* ahead, Arena& arena,
                              TriangleSink& sink, GroupResult& result, GroupTry& g) {
    g.chunk = mark_sink(c, sink);
    g.loops = {c.bottom, 0, c.next_top, 0, c.bottom_flags, c.next_unused, 0, 0};
    if (kParallelLayers && g.triangulated) {
        g.status = take_ahead(*ahead, sink, g.loops, result.counts);
    } else {
        find_closed_ends(g.layer, g.ends);
        g.status = triangulate_layer(c.reader, g.layer, arena, sink, g.loops, result.counts);
    }
    stitch_to_chain(c, g, arena, sink);
    result.folds = sink.folds - g.chunk.folds;
}

// Folding layers (kFoldMerge): the group's last layer and folds before any layer was
// joined, the layers joined in the current try, and whether the group is settled.
struct FoldMerge {
    uint32_t single_last, joined;
    size_t single_folds;
    bool settled;
};

// Whether the try just made is dropped for another, with g.last set for that one (see
// "Folding layers" at add_group). Decided before the chunk is named (naming counts its
// points).
static inline bool try_joined(FoldMerge& m, size_t folds, GroupTry& g) {
    if (!kFoldMerge || m.settled ||
        !(m.joined > 0 || (g.status == Status::ok && folds > 0 && !g.final)))
        return false;
    if (m.joined > 0 && g.status == Status::ok && folds < m.single_folds) {
        m.settled = true;
        return false;
    }
    if (m.joined == 0) {
        m.single_last = g.last;
        m.single_folds = folds;
    }
    if (!g.final && m.joined < kFoldMergeReach) {
        ++m.joined;
        ++g.last;
    } else {
        m.settled = true;
        g.last = m.single_last;
    }
    return true;
}

// For a group a job triangulated: whether its chunk is finished as it is (it failed, it is
// past the caller's capacity, where only the count goes on and triangle_capacity follows,
// or its triangles in reader indices go in as they are, the chunk needing no safety net).
// Else one the job left in reader indices is loaded and triangulated again, in order, to
// the same triangles; one left in layer-local indices (not replayable) goes through the
// safety net as it is.
static inline bool replay_ahead(SurfaceChain& c, const LayerAhead* ahead, Arena& arena,
                                TriangleSink& sink, GroupResult& result, GroupTry& g) {
    if (g.status != Status::ok || sink.count > sink.capacity ||
        (ahead->replayable &&
         replay_chunk(c, g.layer, g.loops, *ahead, g.chunk.count, arena, sink)))
        return true;
    if (!ahead->replayable) return false;
    rewind_sink(c, sink, g.chunk);
    if (!load_layer(c.reader, c.frame, g.ids, g.staged, g.n, g.h0, g.h1, arena, g.layer)) {
        g.status = Status::out_of_memory;
        return true;
    }
    g.triangulated = false;
    make_chunk(c, ahead, arena, sink, result, g);
    return false;
}

// The chunk's safety net, into output indices; a chunk triangulated here whose border and
// band show it sound is only renamed.
static inline void seal_chunk(SurfaceChain& c, Arena& arena, TriangleSink& sink, GroupTry& g) {
    if (g.status != Status::ok || sink.count > sink.capacity) return;
    if (kNetShortcut && !(kParallelLayers && g.triangulated) &&
        chunk_is_sound(c, g.layer, g.loops, sink.triangles + 3 * g.loops.border_start,
                       sink.count - g.loops.border_start, g.loops.interior_used, arena))
        name_chunk_points(c, g.layer, sink.triangles + 3 * g.chunk.count,
                          sink.count - g.chunk.count);
    else
        g.status = finish_chunk(c, g.layer, g.loops, g.chunk.count, arena, sink);
}

// The flips across the seam below the sealed chunk, then its output indices.
static inline void flip_chunk_seam(const SurfaceChain& c, Arena& arena, TriangleSink& sink,
                                   GroupTry& g) {
    if (g.status != Status::ok || sink.count > sink.capacity) return;
    uint32_t* chunk = sink.triangles + 3 * g.chunk.count;
    const size_t in_chunk = sink.count - g.chunk.count;
    if (kSurfaceFlips && g.layer.surface_flips && c.top_count > 0 &&
        !flip_seam(c, g.layer, g.loops, chunk, in_chunk, arena)) {
        g.status = Status::out_of_memory;
        return;
    }
    name_output_points(c, chunk, in_chunk);
}

// The finished group's top loop, in reader indices, becomes the chain's, and its counts
// join the chain's and the result.
static inline void advance_chain(SurfaceChain& c, const GroupTry& g, GroupResult& result) {
    for (uint32_t i = 0; i < g.loops.top_count; ++i) g.loops.top[i] = g.ids[g.loops.top[i]];
    uint32_t* top = c.top;
    unsigned char* unused = c.top_unused;
    c.top = g.loops.top;
    c.top_unused = c.next_unused;
    c.top_count = g.loops.top_count;
    c.next_top = top;
    c.next_unused = unused;
    c.top_cylinder = g.layer.cyl;
    c.duplicates += result.counts.duplicates;
    c.collisions += result.counts.collisions;
    ++c.groups;
    result.last = g.last;
    result.points = g.n;
    result.cylinder = g.layer.cyl;
}

// Finishes the group's chunk (see replay_ahead, seal_chunk, flip_chunk_seam) and, if that
// went well, adds the group to the chain.
static inline void finish_group(SurfaceChain& c, const LayerAhead* ahead, Arena& arena,
                                TriangleSink& sink, GroupResult& result, GroupTry& g) {
    const bool finished =
        kParallelLayers && g.triangulated && replay_ahead(c, ahead, arena, sink, result, g);
    result.triangles = sink.count - g.chunk.count;
    arena.rewind(g.mark);  // the layer's points are no longer needed: the net takes their room
    if (!finished) seal_chunk(c, arena, sink, g);
    flip_chunk_seam(c, arena, sink, g);
    if (g.status == Status::ok) advance_chain(c, g, result);
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
static inline Status add_group(SurfaceChain& c, const LayerQueue& q, uint32_t first, Arena& arena,
                               TriangleSink& sink, GroupResult& result, const LayerAhead* ahead) {
    result.waiting = false;
    GroupTry g;
    g.first = g.last = first;
    FoldMerge merge = {first, 0, 0, false};
    for (;;) {
        g.final = q.complete && g.last + 1 == q.planned;
        if (!g.final && g.last + 1 >= q.planned) {
            result.waiting = true;
            return Status::ok;
        }
        if (!load_group(c, q, ahead, arena, g)) return Status::out_of_memory;
        const Growth growth = group_growth(c, q, ahead, g);
        if (growth != Growth::none) {
            arena.rewind(g.mark);
            result.waiting = growth == Growth::wait;
            if (result.waiting) return Status::ok;
            g.last = growth == Growth::rest ? q.planned - 1 : g.last + 1;
            continue;
        }
        g.status = Status::not_columnar;
        // Tiny or thin layers make coarse, folding bands: they join the next layer if any.
        if (group_stands(g.n, g.h1 - g.h0, g.layer.cyl.radius, g.final)) {
            make_chunk(c, ahead, arena, sink, result, g);
            if (try_joined(merge, result.folds, g)) {
                rewind_sink(c, sink, g.chunk);
                arena.rewind(g.mark);
                continue;
            }
            finish_group(c, ahead, arena, sink, result, g);
        }
        arena.rewind(g.mark);
        if (g.status != Status::not_columnar) return g.status;
        if (g.final) {
            c.trailing += g.n;
            result.last = g.last;
            return Status::not_columnar;
        }
        ++g.last;
    }
}

// The scratch of a group of up to `count` points: its points, then the triangulation or the
// band, then the safety net.
static inline Arena group_scratch(size_t count) {
    size_t total = count + 1;
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
    return group;
}

// The scratch of planning the layers of `count` points: the automatic layers' profile,
// then each point's layer while the points are grouped.
static inline Arena planning_scratch(size_t count) {
    Arena planning = Arena::measuring();
    ProfileBin* bins = nullptr;
    BinRange* ranges = nullptr;
    double* cuts = nullptr;
    allocate_profile(planning, profile_bin_count(count), &bins, &ranges, &cuts);
    planning.rewind(0);
    planning.alloc<uint32_t>(count);
    planning.alloc<uint32_t>(count);  // grouping in jobs: its tables (see group_by_layer_in_jobs)
    return planning;
}

// The largest scratch any phase takes on top of the plan, for groups of up to `count`
// points; 0 if that is beyond what size_t can count. With `close`, the caps: every point
// on a boundary loop, as many triangles as the output can hold.
static inline size_t reconstruct_scratch_size(size_t count, bool close) {
    const Arena group = group_scratch(count), planning = planning_scratch(count);
    Arena caps = Arena::measuring();
    if (close) {
        CapGraph graph;
        CapLoop loop;
        allocate_cap_graph(graph, count, 2 * count, caps);
        allocate_cap_loop(loop, count, caps);
    }
    if (group.failed || planning.failed || caps.failed) return 0;  // beyond size_t
    size_t most = group.high_water;
    if (planning.high_water > most) most = planning.high_water;
    if (caps.high_water > most) most = caps.high_water;
    return most;
}

}  // namespace detail
}  // namespace stratmesh
