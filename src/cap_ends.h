// >>cap ends =============================================================================
// cap_ends() for a surface the caller holds.
//
// cap_ends() is reconstruct()'s last step on a surface the caller holds: the same checks of
// the cloud, the same frame (chosen from the whole cloud), the same caps.

#if !defined(STRATMESH_SMALL_CODE)
namespace stratmesh {
namespace detail {

// Caps the boundary loops of the surface of `count` triangles (`in` reads the whole cloud)
// in the frame along the request's axis, which is resolved.
static inline Status cap_surface(const TubeInput& in, const TubeRequest& request, Arena& arena,
                          uint32_t* triangles, size_t capacity, size_t& count, CapTally& caps,
                          size_t* needed) {
    Frame frame;
    const Status status = choose_frame(in.sums, request, frame);
    if (status != Status::ok) return status;
    return cap_boundary_loops(triangles, count, capacity, in.reader, in.count, frame, arena,
                              caps, needed);
}

}  // namespace detail

size_t cap_ends_workspace_size(size_t point_count, size_t triangle_count) {
    if (point_count > detail::kMaxPoints - 1) return 0;
    detail::Arena arena = detail::Arena::measuring();
    detail::CapGraph graph;
    detail::CapLoop loop;
    detail::allocate_cap_graph(graph, point_count, triangle_count, arena);
    detail::allocate_cap_loop(loop, point_count, arena);  // every point on a loop at most
    // Axis::automatic is resolved first, as reconstruct() resolves it.
    const size_t axis = detail::axis_workspace_size(point_count, detail::tube_request(Options{}));
    if (arena.failed || axis == 0) return 0;
    return arena.required_bytes() > axis ? arena.required_bytes() : axis;
}

Status cap_ends(const Cloud& cloud, const Options& options, void* workspace,
                size_t workspace_bytes, uint32_t* triangles, size_t triangle_capacity,
                size_t* triangle_count, Report* report) {
    if (detail::reconstruct_buffers_overlap(cloud, workspace, workspace_bytes, triangles,
                                            triangle_capacity, triangle_count, report))
        return Status::invalid_argument;
    Report checks = {};  // what the shared checks write, copied out in part
    detail::CapTally caps = {0, 0, 0, 0};
    detail::Arena arena = detail::Arena::over(workspace, workspace_bytes);
    const size_t given = triangle_count ? *triangle_count : 0;
    size_t count = given, needed = 0;
    auto finish = [&](Status status) {
        if (report) {
            report->caps.closed_count = caps.closed;
            report->caps.open_count = caps.left_open;
            report->caps.triangle_count = caps.triangles;
            report->caps.wall_flip_count = caps.wall_flips;
            report->workspace_used_bytes = arena.peak_from_buffer();
            report->detail = checks.detail;
        }
        if (status == Status::ok) *triangle_count = count;
        if (status == Status::triangle_capacity) *triangle_count = needed;
        return status;
    };
    Status status = detail::check_reconstruct_arguments(cloud, triangles, triangle_capacity,
                                                        triangle_count, workspace, checks);
    if (status != Status::ok) return finish(status);
    if (const char* refusal = detail::options_refusal(options)) {
        checks.detail = refusal;
        return finish(Status::invalid_argument);
    }
    if (given > triangle_capacity) {
        checks.detail = "triangle_count is above triangle_capacity";
        return finish(Status::invalid_argument);
    }
    const detail::CloudReader reader = detail::reader_of(cloud);
    const detail::CloudSums sums = detail::sum_cloud(reader, cloud.count);
    status = detail::reject_invalid_points(reader, cloud.count, sums, options, checks);
    if (status != Status::ok) return finish(status);
    for (size_t k = 0; k < 3 * given; ++k)
        if (triangles[k] >= cloud.count || !reader.valid(triangles[k])) {
            checks.detail = "a triangle names a point outside the cloud, or an invalid one";
            return finish(Status::invalid_argument);
        }
    const detail::TubeInput in = {reader, cloud.count, sums};
    detail::TubeRequest along = detail::tube_request(options);
    status = detail::resolve_axis(in, arena, along, &checks.detail);
    if (status != Status::ok) return finish(status);
    status = detail::cap_surface(in, along, arena, triangles, triangle_capacity, count, caps,
                                 &needed);
    if (status == Status::invalid_origin)
        checks.detail = detail::origin_refusal(along.origin, sums);
    else if (status == Status::out_of_memory)
        checks.detail = "the workspace is smaller than cap_ends_workspace_size()";
    else if (status == Status::triangle_capacity)
        checks.detail = detail::kCapsTooLargeDetail;
    else if (caps.left_open > 0)
        checks.detail = detail::kLoopLeftOpenDetail;
    return finish(status);
}

}  // namespace stratmesh

#endif  // STRATMESH_SMALL_CODE
