// >>layer triangulation ==================================================================
// One layer triangulated on its annulus, its loops peeled and its edges flipped.

namespace stratmesh {
namespace detail {

// Puts the layer's points in insertion order (order[k] is the layer-local index of the k-th)
// and rolls them onto the annulus into xy, after the centre at xy[0..1]. The order is taken
// on the unrolled strip (angle, height), where the points are spread evenly: on the annulus
// their density falls off with the radius squared and a curve over its bounding box would
// lump the inner rings together. The strip has the cylinder's proportions (angle in
// radians, height over the radius), as the curve's cells are square. False if the arena
// is too small.
static inline bool roll_in_insertion_order(LoadedLayer& layer, uint32_t* order, double* xy,
                                           Arena& arena) {
    const size_t count = layer.count;
    Local* points = layer.points;
    const Cylinder& cyl = layer.cyl;
    const double quarter_turn = 1.57079632679489661923;  // pseudo_angle's unit, in radians
    BoundingBox2d box = {{0, 0}, {4 * quarter_turn, 0}};
    double* strip = xy + 2;
    for (size_t i = 0; i < count; ++i) {
        const Local& p = points[i];
        strip[2 * i] = quarter_turn * pseudo_angle(p.x - cyl.cx, p.y - cyl.cy);
        strip[2 * i + 1] = (p.h - cyl.h0) * cyl.scale;
        if (strip[2 * i + 1] > box.max[1]) box.max[1] = strip[2 * i + 1];
    }
    if (!spatial_order(reinterpret_cast<const unsigned char*>(strip), 2 * sizeof(double), count,
                       box, order, arena))
        return false;
    // The points in insertion order, so that unrolling them and the fold test read them in
    // sequence, not at random (the copy's room is free again before the triangulation
    // takes it).
    size_t copy_mark = arena.mark();
    Local* sorted = arena.alloc<Local>(count);
    if (arena.failed) return false;
    for (size_t k = 0; k < count; ++k) sorted[k] = points[order[k]];
    std::memcpy(points, sorted, count * sizeof(Local));
    arena.rewind(copy_mark);
    xy[0] = xy[1] = 0;
    for (size_t k = 0; k < count; ++k) roll(cyl, points[k], xy + 2 * (k + 1));
    return true;
}

// Peels the layer's loops (see "peeling"): the passes and the slope of a loop. The
// surface's end loops of a layer that folds peel further; its other loops not at all.
static inline void peel_layer_loops(Triangulation& tr, const LoadedLayer& layer, size_t folds,
                                    uint32_t* flags, LayerLoops& loops) {
    auto passes = [&layer, folds](uint32_t end) {
        if (folds == 0) return kPeelPasses;
        return (layer.ends & end) ? kFoldedEndPeelPasses : 0;
    };
    auto slope = [&layer, folds](uint32_t end) {
        if (!(layer.ends & end)) return kInnerPeelSlope;
        return folds == 0 ? kPeelSlope : kFoldedEndPeelSlope;
    };
    const uint32_t capacity = static_cast<uint32_t>(layer.count);
    loops.bottom_count = peel_loop(tr, layer.points, flags, loops.bottom, loops.bottom_count,
                                   capacity, false, slope(kLowPole), passes(kLowPole));
    loops.top_count = peel_loop(tr, layer.points, flags, loops.top, loops.top_count, capacity,
                                true, slope(kHighPole), passes(kHighPole));
}

// Writes the surface triangles to the sink in layer-local indices, those at the bottom loop
// (the border) last, so that a chunk's triangles at its loop vertices are one stretch of
// the sink with the band (see chunk_is_sound); counts the points off that loop with one.
static inline void emit_layer(const Triangulation& tr, const uint32_t* order, uint32_t* flags,
                              size_t total, TriangleSink& sink, LayerLoops& loops) {
    for (uint32_t at_border = 0; at_border < 2; ++at_border) {
        if (at_border) loops.border_start = sink.count;
        for (uint32_t t = 0; t < tr.triangle_count; ++t) {
            const uint32_t* v = tr.vertex + 3 * t;
            if (!on_surface(tr, t) ||
                ((flags[v[0]] | flags[v[1]] | flags[v[2]]) & kOnBottomLoop) != at_border)
                continue;
            if (kNetShortcut) {
                flags[v[0]] |= kEmitted;
                flags[v[1]] |= kEmitted;
                flags[v[2]] |= kEmitted;
            }
            sink.write(order[v[0] - 1], order[v[1] - 1], order[v[2] - 1]);
        }
    }
    loops.interior_used = 0;
    for (size_t v = 1; kNetShortcut && v < total; ++v)
        loops.interior_used += (flags[v] & (kOnBottomLoop | kEmitted)) == kEmitted;
}

// Triangulates a loaded layer rolled onto the annulus of its cylinder plus the centre (the
// centre moved first if the layer folds less around another: see choose_centre).
// Emits the surface triangles and fills the loops, in layer-local indices. Returns ok,
// not_columnar (the layer does not surround its axis, or is degenerate: the caller merges
// it with the next one), out_of_memory or internal_error. Its scratch is released; the
// layer's points are left in insertion order (layer.points[k] is layer-local point
// order[k], an order not kept).
static inline Status triangulate_layer(const CloudReader& cloud, LoadedLayer& layer, Arena& arena,
                                       TriangleSink& sink, LayerLoops& loops, CoincidentPoints& counts) {
    const size_t count = layer.count, total = count + 1;  // vertex 0 is the centre
    choose_centre(layer, arena);
    size_t mark = arena.mark();
    uint32_t* order = arena.alloc<uint32_t>(count);  // vertex - 1 -> layer-local index
    double* xy = arena.alloc<double>(2 * total);
    if (arena.failed || !roll_in_insertion_order(layer, order, xy, arena))
        return Status::out_of_memory;
    Triangulation tr;
    tr.xy = xy;
    if (!allocate_triangulation(tr, total, arena)) return Status::out_of_memory;
    counts = CoincidentPoints{0, 0};
    LayerDuplicates classify = {&cloud, layer.ids, order, &counts};
    DuplicateSink duplicates = {LayerDuplicates::report, &classify};
    uint32_t inserted = 0;
    Status status = triangulate_points(tr, static_cast<uint32_t>(total), duplicates, &inserted);
    if (status == Status::internal_error) return status;
    // The flip stack's room is free now: a flag per vertex (kOnBottomLoop, kOnTopLoop,
    // kEmitted).
    uint32_t* flags = tr.stack;
    std::memset(flags, 0, total * sizeof(uint32_t));
    if (status != Status::ok || !centre_link(tr, loops.bottom, &loops.bottom_count, flags)) {
        arena.rewind(mark);
        return Status::not_columnar;
    }
    hull_loop(tr, loops.top, &loops.top_count, flags);
    size_t folds = count_folds(tr, layer.points, 1, layer.cyl, nullptr);
    if (folds == 0 || kPeelFoldedEnds) peel_layer_loops(tr, layer, folds, flags, loops);
    name_loop(tr, order, flags, loops.bottom, loops.bottom_count, loops.bottom_flags, false);
    name_loop(tr, order, flags, loops.top, loops.top_count, loops.top_flags, true);
    // The folds stay those of the unrolling: the flips may turn triangles to face the axis
    // where the surface does (see "flips on the surface").
    if (kSurfaceFlips && layer.surface_flips)
        flip_layer_on_surface(tr, layer.points, layer.cyl, flags, xy, total);
    emit_layer(tr, order, flags, total, sink, loops);
    sink.folds += folds;
    arena.rewind(mark);
    return Status::ok;
}

}  // namespace detail
}  // namespace stratmesh
