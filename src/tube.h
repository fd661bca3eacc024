// >>tube =================================================================================
// One tube: its layers triangulated, stitched and sealed group by group, then capped.
//
// Choose the frame and the layers, group the points by layer, then for each layer: fit its
// cylinder, triangulate it on its annulus, stitch it to the layer below. A layer that
// cannot be triangulated around its axis (too few points, or a gap in its angular
// coverage) is merged with the next one; trailing points that never form such a layer stay
// unused and are reported. The manifold safety net runs on each chunk as it is sealed.

namespace stratmesh {
namespace detail {

// ---- reconstruct -----------------------------------------------------------------------------

// Workspace that lives through the whole call, then the largest scratch of any phase.
struct ReconstructMemory {
    double* bounds;        // layer bounds
    uint32_t* layer_start; // first position in `order` of each layer
    uint32_t* order;       // valid points grouped by layer
    SurfaceChain chain;
};

static inline bool plan_reconstruct(ReconstructMemory& m, size_t count, size_t layer_limit,
                                    Arena& arena) {
    m.bounds = arena.alloc<double>(layer_limit + 1);
    m.layer_start = arena.alloc<uint32_t>(layer_limit + 2);
    m.order = arena.alloc<uint32_t>(count);
    return allocate_chain(m.chain, count, arena);
}

static inline void describe_layer(const Frame& frame, const Cylinder& cyl, double bottom,
                                  double top, size_t points, size_t triangles, size_t folds,
                                  LayerInfo& info) {
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

// The workspace bound of mesh_tube() (with read_cloud()) for point_count points.
static inline size_t tube_workspace_size(size_t point_count, const TubeRequest& request) {
    if (point_count > kMaxPoints - 1) return 0;
    Arena arena = Arena::measuring();
    // drop_outliers, as find_outliers allocates: the bitmap stays, the grid comes and goes
    // before the rest is allocated.
    size_t outlier_bytes = 0;
    if (kDropOutliers && request.drop_outliers) {
        Arena grid = Arena::measuring();
        grid.alloc<unsigned char>(point_count / 8 + 1);
        allocate_cell_scratch(grid, point_count);
        if (grid.failed) return 0;
        outlier_bytes = grid.required_bytes();
        arena.alloc<unsigned char>(point_count / 8 + 1);
    }
    ReconstructMemory m;
    const size_t layer_limit = planned_layer_limit(point_count, request.layers);
    plan_reconstruct(m, point_count, layer_limit, arena);
    size_t scratch = reconstruct_scratch_size(point_count, request.caps);
    // With a runner, the layers done ahead (at most one per kMinLayerPoints points, plus the
    // last) stay while the groups are formed.
    if (has_runner(jobs_of(request)) &&
        !plan_parallel_workspace(point_count, layer_limit, arena, &scratch))
        return 0;
    if (arena.failed || scratch == 0 || scratch > SIZE_MAX - arena.required_bytes()) return 0;
    const size_t bytes = arena.required_bytes() + scratch;
    return bytes > outlier_bytes ? bytes : outlier_bytes;
}

// The chain's counts into the report, with the reason when a valid point is not a vertex.
static inline void report_chain(const SurfaceChain& chain, size_t valid, Report& rep) {
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
static inline size_t repeats_of_vertices(const CloudReader& reader, size_t count,
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

// Plans the layers of a tube along the frame's axis and groups its points by layer.
static inline Status plan_tube_layers(const TubeInput& in, const TubeRequest& request, const Frame& frame,
                               double lo, double hi, Arena& arena, ReconstructMemory& m,
                               LayerPlan& plan, Local** staged, Report& rep) {
    const size_t valid = in.sums.valid;
    const size_t layer_limit = planned_layer_limit(in.count, request.layers);
    if (!plan_reconstruct(m, in.count, layer_limit, arena)) return Status::out_of_memory;
    notify(request, Phase::layers, 0);
    plan = {m.bounds, 0, (hi - lo) * kCutTolerance};
    if (automatic_layers(request.layers)) {
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
        plan_layers(request.layers, lo, hi, in.count, frame, plan);
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
    if (kStagePoints && !has_runner(jobs_of(request)))
        *staged = static_cast<Local*>(arena.room_at_end(saturating_product(valid, sizeof(Local))));
    if (!group_by_layer_in_jobs(jobs_of(request), in.reader, in.count, frame, plan, layer, m.layer_start,
                                m.order, arena))
        group_by_layer(in.reader, in.count, frame, plan, layer, *staged, m.layer_start, m.order);
    arena.rewind(mark);
    return Status::ok;
}

// Triangulates the planned layers one group after another, each stitched to the one below,
// into `sink`; the layers used go to the report.
static inline Status triangulate_tube(const TubeInput& in, const TubeRequest& request, const Frame& frame,
                               const LayerPlan& plan, Local* staged, Arena& arena,
                               ReconstructMemory& m, TriangleSink& sink, Report& rep) {
    notify(request, Phase::triangulate, 0);
    SurfaceChain& chain = m.chain;
    chain.frame = frame;
    chain.reader = in.reader;
    chain.output_id = nullptr;
    const LayerQueue queue = {m.order, staged, m.layer_start, plan.bounds, plan.count, true};
    ParallelLayers parallel;
    rep.layers.parallel_count = start_parallel_layers(jobs_of(request), in.reader, frame, queue, arena, parallel);
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
        notify(request, Phase::triangulate, static_cast<double>(first) / plan.count);
    }
    rep.points.duplicate_count = chain.duplicates;
    if (rep.layers.used_count == 0) {
        rep.detail = "no layer's points surround the axis: the cloud is not columnar around "
                     "it (try another axis)";
        return Status::not_columnar;
    }
    notify(request, Phase::stitch, 1);
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
static inline bool has_no_area(const CloudReader& reader, const Frame& frame, const uint32_t* tri,
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

// Closes the tube's boundary loops with caps (add_caps) and fills the caps' report.
static inline Status cap_tube(const TubeInput& in, const TubeRequest& request, const Frame& frame,
                       Arena& arena, uint32_t* triangles, size_t capacity, size_t& count,
                       size_t* triangle_count, Report& rep) {
    notify(request, Phase::manifold, 0);
    if (!request.caps) return Status::ok;
    CapTally caps = {0, 0, 0, 0};
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
static inline Status mesh_tube(const TubeInput& in, const TubeRequest& request, Arena& arena,
                        uint32_t* triangles, size_t triangle_capacity, size_t* triangle_count,
                        Report& rep) {
    Frame frame;
    Status status = choose_frame(in.sums, request, frame);
    if (status != Status::ok) return status;
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
    status = plan_tube_layers(in, request, frame, lo, hi, arena, m, plan, &staged, rep);
    if (status != Status::ok) return status;
    TriangleSink sink = {triangles, triangle_capacity, 0, 0};
    status = triangulate_tube(in, request, frame, plan, staged, arena, m, sink, rep);
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
    status = cap_tube(in, request, frame, arena, triangles, triangle_capacity, count,
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
    notify(request, Phase::done, 1);
    return Status::ok;
}

}  // namespace detail
}  // namespace stratmesh
