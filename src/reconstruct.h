// >>reconstruct ==========================================================================
// reconstruct() in its steps: validate, a bent skeleton, axis, parts or one tube.

namespace stratmesh {
namespace detail {

// Reads a cloud that passed check_reconstruct_arguments: refuses or counts its NaN and
// infinite points, leaves out its outliers (drop_outliers; the bitmap stays in `arena`)
// and sums what is kept.
static inline Status read_cloud(const Cloud& cloud, const Options& options, Arena& arena, Report& rep,
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

// Whether reconstruct() looks for branches.
static inline bool searches_parts(const TubeRequest& request) {
    return kFindParts && request.parts != Parts::one_tube;
}

static inline Status mesh_cloud(const Cloud& cloud, const TubeInput& in, const TubeRequest& request,
                         Arena& arena, uint32_t* triangles, size_t capacity,
                         size_t* triangle_count, Report& rep) {
#if !defined(STRATMESH_SMALL_CODE)
    if (searches_parts(request))
        return reconstruct_default(cloud, in, request, arena, triangles, capacity,
                                   triangle_count, rep);
#else
    (void)cloud;
#endif
    return mesh_tube(in, request, arena, triangles, capacity, triangle_count, rep);
}

// reconstruct()'s body; `rep` arrives zeroed but for its caller's arrays.
// Report::points.unused_count is left to the caller, who derives it so the counts add up on
// every path.
static inline Status run_reconstruction(const Cloud& cloud, const Options& options, void* workspace,
                                 size_t workspace_bytes, uint32_t* triangles,
                                 size_t triangle_capacity, size_t* triangle_count,
                                 Report& rep) {
    Status status = check_reconstruct_arguments(cloud, triangles, triangle_capacity,
                                                triangle_count, workspace, rep);
    if (status != Status::ok) return status;
    const char* refusal = options_refusal(options);
    if (!refusal) refusal = layer_choice_refusal(options);
    if (refusal) {
        rep.detail = refusal;
        return Status::invalid_argument;
    }
    notify(options, Phase::validate, 0);
    Arena arena = Arena::over(workspace, workspace_bytes);
    TubeInput in = {};
    TubeRequest request = tube_request(options);
    status = read_cloud(cloud, options, arena, rep, in);
    const size_t read = arena.mark();  // the outliers' bitmap stays: the reader needs it
    const char* far_origin =
        status == Status::ok ? origin_refusal(request.origin, in.sums) : nullptr;
    if (far_origin) {
        rep.detail = far_origin;
        status = Status::invalid_origin;
    }
    // A cloud on a line up to rounding is refused whatever the axis: a line has no surface,
    // and along it a layer would only seem not to surround its axis.
    if (status == Status::ok && kDegenerateCheck && in.sums.distinct >= 3 && on_a_line(in, arena))
        status = Status::degenerate;
    bool bent = false, unbranched = false;
#if !defined(STRATMESH_SMALL_CODE)
    if (status == Status::ok && follows_bends(request))
        status = mesh_if_bent(in, request, arena, triangles, triangle_capacity, triangle_count,
                              rep, &bent, &unbranched);
#endif
    if (unbranched) request.parts = Parts::one_tube;  // one ring at every distance: no branch
    if (status == Status::ok && !bent) status = resolve_axis(in, arena, request, &rep.detail);
    if (status == Status::ok && !bent)
        status = mesh_cloud(cloud, in, request, arena, triangles, triangle_capacity,
                            triangle_count, rep);
    if (kMeasureFit) arena.rewind(read);  // the surface is final: the scratch is free
    // A few far points or far clusters collapse the rest, so that no layer surrounds its
    // centre either: they are the reason then too.
    if (kDegenerateCheck && (status == Status::degenerate || status == Status::not_columnar)) {
        arena.rewind(read);
        status = explain_no_area(in, status, arena, rep);
    }
    if (kMeasureFit && status == Status::ok &&
        !measure_fit(in.reader, in.count, in.sums, triangles, *triangle_count,
                     rep.caps.triangle_count, arena, rep)) {
        *triangle_count = 0;
        rep.triangle_count = 0;
        status = Status::out_of_memory;
    }
    rep.workspace_used_bytes = arena.peak_from_buffer();
    return status;
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

size_t reconstruct_max_triangles(size_t point_count, const Options& options) {
    // A manifold surface through V vertices, open or closed, has at most 2V triangles; the
    // junctions of branches add at most four per branch beyond that.
    const size_t junctions =
        detail::searches_parts(detail::tube_request(options)) ? 8 * size_t{kMaxBranches} : 0;
    return point_count > (SIZE_MAX - junctions) / 2 ? 0 : 2 * point_count + junctions;
}

size_t reconstruct_workspace_size(size_t point_count, const Options& options) {
    const detail::TubeRequest request = detail::tube_request(options);
    size_t most = detail::tube_workspace_size(point_count, request);
    if (most == 0) return 0;
    // The axis is chosen, and the parts meshed, once the outliers are known.
    detail::Arena arena = detail::Arena::measuring();
    if (detail::kDropOutliers && (options.flags & drop_outliers))
        arena.alloc<unsigned char>(point_count / 8 + 1);
    const size_t read = arena.required_bytes();
    size_t steps[detail::kMeasureFit ? 5 : 4] = {};
    if (detail::kAxisTrials && options.axis == Axis::automatic)
        steps[0] = detail::axis_workspace_size(point_count, request);
    // A refusal for no area is explained with the groups of why_no_area().
    if (detail::kDegenerateCheck) steps[detail::kMeasureFit ? 3 : 2] = detail::no_area_workspace_size(point_count);
#if !defined(STRATMESH_SMALL_CODE)
    if (detail::searches_parts(request))
        steps[1] = detail::parts_workspace_size(point_count, request);
    if (detail::follows_bends(request)) {
        steps[detail::kMeasureFit ? 4 : 3] = detail::bent_workspace_size(point_count, request);
        if (steps[detail::kMeasureFit ? 4 : 3] == 0) return 0;
    }
#endif
    // The fit is measured once the surface is final (far less than meshing it takes).
    if (detail::kMeasureFit) {
        steps[detail::kMeasureFit ? 2 : 0] = detail::fit_workspace_size(
            point_count, reconstruct_max_triangles(point_count, options));
        if (steps[detail::kMeasureFit ? 2 : 0] == 0) return 0;
    }
    for (size_t bytes : steps) {
        if (bytes > SIZE_MAX - read) return 0;
        most = read + bytes > most ? read + bytes : most;
    }
    return most;
}

Status reconstruct(const Cloud& cloud, const Options& options, void* workspace,
                   size_t workspace_bytes, uint32_t* triangles, size_t triangle_capacity,
                   size_t* triangle_count, Report* report) {
    if (detail::reconstruct_buffers_overlap(cloud, workspace, workspace_bytes, triangles,
                                            triangle_capacity, triangle_count, report))
        return Status::invalid_argument;
    Report local_report;
    Report& rep = report ? *report : local_report;
    // The caller's arrays, kept as they are (as two values, not copies of the groups: the
    // small build's stack frame stays within a short instruction's reach).
    LayerInfo* const layer_info = report ? report->layers.info : nullptr;
    const size_t layer_capacity = layer_info ? report->layers.info_capacity : 0;
    PartInfo* const part_info = report && detail::kFindParts ? report->parts.info : nullptr;
    const size_t part_capacity = part_info ? report->parts.info_capacity : 0;
    std::memset(&rep, 0, sizeof rep);
    rep.layers.info = layer_info;
    rep.layers.info_capacity = layer_capacity;
    rep.parts.info = part_info;
    rep.parts.info_capacity = part_capacity;
    rep.points.in_count = cloud.count;
    if (triangle_count) *triangle_count = 0;
    Status status = detail::run_reconstruction(cloud, options, workspace, workspace_bytes,
                                               triangles, triangle_capacity, triangle_count,
                                               rep);
    rep.points.unused_count = rep.points.in_count - rep.points.used_count -
                              rep.points.duplicate_count - rep.points.rejected_count;
    return status;
}

}  // namespace stratmesh
