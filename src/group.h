// >>group ================================================================================
// A group of layers: triangulated, stitched to the loop below, flipped and sealed.

namespace stratmesh {
namespace detail {

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

}  // namespace detail
}  // namespace stratmesh
