// >>c interface =============================================================================
// The C functions over the C++ ones.
//
// The C functions convert their structs field for field and call the C++ ones; the enum
// values are asserted equal, so a status, an axis or a flag passes as it is. The layer
// array is the one exception: stratmesh_layer_info and LayerInfo are asserted to have the
// same layout, and the caller's array is handed to the C++ report as it is, since a copy
// would need a second array. Callbacks go through small adapters, because a C function
// pointer's type is not the C++ one (the C enums in its signature, its language linkage).

#if STRATMESH_C_API

#define STRATMESH_C_SAME(c_value, cpp_value)                                                \
    static_assert(static_cast<uint32_t>(c_value) == static_cast<uint32_t>(cpp_value),    \
                  #c_value " differs from " #cpp_value);
STRATMESH_C_SAME(STRATMESH_STATUS_OK, stratmesh::Status::ok)
STRATMESH_C_SAME(STRATMESH_STATUS_INVALID_ARGUMENT, stratmesh::Status::invalid_argument)
STRATMESH_C_SAME(STRATMESH_STATUS_TOO_MANY_POINTS, stratmesh::Status::too_many_points)
STRATMESH_C_SAME(STRATMESH_STATUS_NOT_COMPILED, stratmesh::Status::not_compiled)
STRATMESH_C_SAME(STRATMESH_STATUS_INVALID_POINT, stratmesh::Status::invalid_point)
STRATMESH_C_SAME(STRATMESH_STATUS_TOO_FEW_POINTS, stratmesh::Status::too_few_points)
STRATMESH_C_SAME(STRATMESH_STATUS_COLLINEAR, stratmesh::Status::collinear)
STRATMESH_C_SAME(STRATMESH_STATUS_INVALID_AXIS, stratmesh::Status::invalid_axis)
STRATMESH_C_SAME(STRATMESH_STATUS_INVALID_LAYERS, stratmesh::Status::invalid_layers)
STRATMESH_C_SAME(STRATMESH_STATUS_INVALID_ORIGIN, stratmesh::Status::invalid_origin)
STRATMESH_C_SAME(STRATMESH_STATUS_FLAT_CLOUD, stratmesh::Status::flat_cloud)
STRATMESH_C_SAME(STRATMESH_STATUS_NOT_COLUMNAR, stratmesh::Status::not_columnar)
STRATMESH_C_SAME(STRATMESH_STATUS_DEGENERATE, stratmesh::Status::degenerate)
STRATMESH_C_SAME(STRATMESH_STATUS_SEPARATE_CLUSTERS, stratmesh::Status::separate_clusters)
STRATMESH_C_SAME(STRATMESH_STATUS_OUT_OF_ORDER, stratmesh::Status::out_of_order)
STRATMESH_C_SAME(STRATMESH_STATUS_OUT_OF_MEMORY, stratmesh::Status::out_of_memory)
STRATMESH_C_SAME(STRATMESH_STATUS_TRIANGLE_CAPACITY, stratmesh::Status::triangle_capacity)
STRATMESH_C_SAME(STRATMESH_STATUS_INTERNAL_ERROR, stratmesh::Status::internal_error)
STRATMESH_C_SAME(STRATMESH_SCALAR_FLOAT64, stratmesh::Scalar::float64)
STRATMESH_C_SAME(STRATMESH_SCALAR_FLOAT32, stratmesh::Scalar::float32)
STRATMESH_C_SAME(STRATMESH_AXIS_AUTOMATIC, stratmesh::Axis::automatic)
STRATMESH_C_SAME(STRATMESH_AXIS_X, stratmesh::Axis::x)
STRATMESH_C_SAME(STRATMESH_AXIS_Y, stratmesh::Axis::y)
STRATMESH_C_SAME(STRATMESH_AXIS_Z, stratmesh::Axis::z)
STRATMESH_C_SAME(STRATMESH_AXIS_DIRECTION, stratmesh::Axis::direction)
STRATMESH_C_SAME(STRATMESH_FLAG_SKIP_INVALID_POINTS, stratmesh::skip_invalid_points)
STRATMESH_C_SAME(STRATMESH_FLAG_ADD_CAPS, stratmesh::add_caps)
STRATMESH_C_SAME(STRATMESH_FLAG_ORIGIN_GIVEN, stratmesh::origin_given)
STRATMESH_C_SAME(STRATMESH_FLAG_DROP_OUTLIERS, stratmesh::drop_outliers)
STRATMESH_C_SAME(STRATMESH_FLAG_SURFACE_FLIPS, stratmesh::surface_flips)
STRATMESH_C_SAME(STRATMESH_FLAG_ENDS_ARE_CUTS, stratmesh::ends_are_cuts)
STRATMESH_C_SAME(STRATMESH_CLOSED_BOTTOM, stratmesh::closed_bottom)
STRATMESH_C_SAME(STRATMESH_CLOSED_TOP, stratmesh::closed_top)
STRATMESH_C_SAME(STRATMESH_PHASE_VALIDATE, stratmesh::Phase::validate)
STRATMESH_C_SAME(STRATMESH_PHASE_LAYERS, stratmesh::Phase::layers)
STRATMESH_C_SAME(STRATMESH_PHASE_TRIANGULATE, stratmesh::Phase::triangulate)
STRATMESH_C_SAME(STRATMESH_PHASE_STITCH, stratmesh::Phase::stitch)
STRATMESH_C_SAME(STRATMESH_PHASE_MANIFOLD, stratmesh::Phase::manifold)
STRATMESH_C_SAME(STRATMESH_PHASE_DONE, stratmesh::Phase::done)
STRATMESH_C_SAME(STRATMESH_PARTS_AUTOMATIC, stratmesh::Parts::automatic)
STRATMESH_C_SAME(STRATMESH_PARTS_ONE_TUBE, stratmesh::Parts::one_tube)
STRATMESH_C_SAME(STRATMESH_PARTS_APART, stratmesh::Parts::apart)
STRATMESH_C_SAME(STRATMESH_PARTS_OUTCOME_ONE_TUBE, stratmesh::PartsOutcome::one_tube)
STRATMESH_C_SAME(STRATMESH_PARTS_OUTCOME_JOINED, stratmesh::PartsOutcome::joined)
STRATMESH_C_SAME(STRATMESH_PARTS_OUTCOME_KEPT_APART, stratmesh::PartsOutcome::kept_apart)
STRATMESH_C_SAME(STRATMESH_PARTS_OUTCOME_UNDONE, stratmesh::PartsOutcome::undone)
#undef STRATMESH_C_SAME
static_assert(STRATMESH_POOR_MISFIT_FRACTION == stratmesh::kPoorMisfitFraction,
              "STRATMESH_POOR_MISFIT_FRACTION differs from stratmesh::kPoorMisfitFraction");

// A status added to the list needs its C constant too.
#define STRATMESH_C_COUNT(name, message) +1
static_assert(0 STRATMESH_STATUS_LIST(STRATMESH_C_COUNT) == STRATMESH_STATUS_INTERNAL_ERROR + 1,
              "stratmesh_status needs one constant per stratmesh::Status");
#undef STRATMESH_C_COUNT

// The layer array is shared, not copied: the same fields at the same places.
#define STRATMESH_C_FIELD(field)                                                            \
    static_assert(offsetof(stratmesh_layer_info, field) == offsetof(stratmesh::LayerInfo, field), \
                  "stratmesh_layer_info::" #field " is not where LayerInfo has it");
STRATMESH_C_FIELD(bottom)
STRATMESH_C_FIELD(top)
STRATMESH_C_FIELD(centre)
STRATMESH_C_FIELD(radius)
STRATMESH_C_FIELD(point_count)
STRATMESH_C_FIELD(triangle_count)
STRATMESH_C_FIELD(fold_count)
STRATMESH_C_FIELD(closed_ends)
#undef STRATMESH_C_FIELD
static_assert(sizeof(stratmesh_layer_info) == sizeof(stratmesh::LayerInfo) &&
                  alignof(stratmesh_layer_info) == alignof(stratmesh::LayerInfo),
              "stratmesh_layer_info and LayerInfo differ in size or alignment");

// The C stream: the C++ stream's report and the C callback, at the first aligned address
// of the caller's workspace; the C++ stream takes the rest.
struct stratmesh_stream {
    stratmesh::Stream* stream;
    stratmesh::Report report;          // the C++ stream's, converted after every call
    stratmesh_report* user_report;
    stratmesh_triangle_callback emit;
    void* emit_user;
    size_t prefix;                     // bytes of the caller's workspace before the C++ one
};

namespace stratmesh {
namespace detail {

// A batch of jobs as the C runner sees it: the C++ job and its context.
struct CJobBatch {
    JobFunction job;
    void* context;
};

extern "C" {
static void c_run_job(void* batch, uint32_t index) {
    const CJobBatch* b = static_cast<const CJobBatch*>(batch);
    b->job(b->context, index);
}
}

// The adapters' user pointer is the caller's stratmesh_options, alive during the call.
static inline void c_progress(void* user, Phase phase, double fraction) {
    const stratmesh_options* c = static_cast<const stratmesh_options*>(user);
    c->progress(c->progress_user, static_cast<stratmesh_phase>(phase), fraction);
}

static inline void c_run_jobs(void* user, uint32_t count, JobFunction job, void* context) {
    const stratmesh_options* c = static_cast<const stratmesh_options*>(user);
    CJobBatch batch = {job, context};
    c->run_jobs(c->jobs_user, count, c_run_job, &batch);
}

static inline void c_emit(void* user, const uint32_t* triangles, size_t count) {
    const stratmesh_stream* s = static_cast<const stratmesh_stream*>(user);
    s->emit(s->emit_user, triangles, count);
}

static inline Options c_options(const stratmesh_options* c) {
    Options o;
    std::memset(&o, 0, sizeof o);
    if (!c) return o;
    o.axis = static_cast<Axis>(c->axis);
    o.cuts = c->cuts;
    o.cut_count = c->cut_count;
    o.layer_count = c->layer_count;
    o.layer_height = c->layer_height;
    o.flags = c->flags;
    o.parts = static_cast<Parts>(c->parts);
    for (int i = 0; i < 3; ++i) {
        o.direction[i] = c->direction[i];
        o.origin[i] = c->origin[i];
    }
    void* user = const_cast<stratmesh_options*>(c);
    if (c->progress) {
        o.progress = c_progress;
        o.progress_user = user;
    }
    if (c->run_jobs) {
        o.run_jobs = c_run_jobs;
        o.jobs_user = user;
    }
    return o;
}

static inline Cloud c_cloud(const stratmesh_cloud& c) {
    return Cloud{c.xyz, c.count, c.stride_bytes, static_cast<Scalar>(c.scalar)};
}

// The C++ report into the C one; the layer array is the caller's already.
static inline void c_report(const Report& r, stratmesh_report& c) {
    c.triangle_count = r.triangle_count;
    for (int i = 0; i < 3; ++i) {
        c.axis[i] = r.axis[i];
        c.axis_origin[i] = r.axis_origin[i];
    }
    c.points.in_count = r.points.in_count;
    c.points.used_count = r.points.used_count;
    c.points.duplicate_count = r.points.duplicate_count;
    c.points.rejected_count = r.points.rejected_count;
    c.points.outlier_count = r.points.outlier_count;
    c.points.unused_count = r.points.unused_count;
    c.points.first_invalid_index = r.points.first_invalid_index;
    c.points.held_count = r.points.held_count;
    c.layers.planned_count = r.layers.planned_count;
    c.layers.used_count = r.layers.used_count;
    c.layers.parallel_count = r.layers.parallel_count;
    c.layers.skeleton_node_count = r.layers.skeleton_node_count;
    c.caps.closed_count = r.caps.closed_count;
    c.caps.open_count = r.caps.open_count;
    c.caps.triangle_count = r.caps.triangle_count;
    c.caps.wall_flip_count = r.caps.wall_flip_count;
    c.parts.outcome = static_cast<uint32_t>(r.parts.outcome);
    c.parts.gap = r.parts.parting.gap;
    c.parts.above = r.parts.parting.above;
    c.parts.above_branch_count = r.parts.parting.above_branch_count;
    c.parts.below = r.parts.parting.below;
    c.parts.below_branch_count = r.parts.parting.below_branch_count;
    c.parts.part_count = r.parts.part_count;
    c.parts.joined_side_count = r.parts.joined_side_count;
    c.parts.apart_side_count = r.parts.apart_side_count;
    c.parts.grafted_branch_count = r.parts.grafted_branch_count;
    c.parts.junction_triangle_count = r.parts.junction_triangle_count;
    c.parts.removed_triangle_count = r.parts.removed_triangle_count;
    c.diagnostics.fold_count = r.diagnostics.fold_count;
    c.diagnostics.illegal_removed_count = r.diagnostics.illegal_removed_count;
    c.diagnostics.diagonal_swap_count = r.diagnostics.diagonal_swap_count;
    const Diagnostics& d = r.diagnostics;
    c.diagnostics.point_spacing = d.point_spacing;
    c.diagnostics.area_per_point = d.area_per_point;
    c.diagnostics.fit_sample_count = d.fit_sample_count;
    c.diagnostics.misfit_area_fraction = d.misfit_area_fraction;
    c.diagnostics.misfit_area = d.misfit_area;
    c.diagnostics.crossing_pair_count = d.crossing_pair_count;
    c.diagnostics.crossing_check_complete = d.crossing_check_complete ? 1 : 0;
    for (int i = 0; i < 3; ++i) {
        c.diagnostics.misfit_box_min[i] = d.misfit_box_min[i];
        c.diagnostics.misfit_box_max[i] = d.misfit_box_max[i];
        c.diagnostics.crossing_box_min[i] = d.crossing_box_min[i];
        c.diagnostics.crossing_box_max[i] = d.crossing_box_max[i];
    }
    c.detail = r.detail;
    c.workspace_used_bytes = r.workspace_used_bytes;
}

// A C++ report that writes the layers into the C report's array.
static inline void c_report_start(Report& r, const stratmesh_report* c) {
    std::memset(&r, 0, sizeof r);
    if (!c || !c->layers.info) return;
    r.layers.info = reinterpret_cast<LayerInfo*>(c->layers.info);
    r.layers.info_capacity = c->layers.info_capacity;
}

// The stream's C report, its workspace counted from the start of the caller's buffer.
static inline void c_stream_report(const stratmesh_stream& s) {
    if (!s.user_report) return;
    c_report(s.report, *s.user_report);
    s.user_report->workspace_used_bytes += s.prefix;
}

static inline ByteRange c_report_bytes(const stratmesh_report* c) {
    return byte_range(c, sizeof *c);
}

static inline ByteRange c_layer_bytes(const stratmesh_report* c) {
    return c ? byte_range(c->layers.info, saturating_product(c->layers.info_capacity,
                                                             sizeof(stratmesh_layer_info)))
             : ByteRange{0, 0};
}

}  // namespace detail
}  // namespace stratmesh

const char* stratmesh_status_string(uint32_t status) {
    return stratmesh::status_string(static_cast<stratmesh::Status>(status));
}

double stratmesh_orient2d(const double a[2], const double b[2], const double c[2]) {
    return stratmesh::orient2d(a, b, c);
}

double stratmesh_incircle(const double a[2], const double b[2], const double c[2],
                          const double d[2]) {
    return stratmesh::incircle(a, b, c, d);
}

size_t stratmesh_delaunay_2d_workspace_size(size_t point_count) {
    return stratmesh::delaunay_2d_workspace_size(point_count);
}

size_t stratmesh_delaunay_2d_max_triangles(size_t point_count) {
    return stratmesh::delaunay_2d_max_triangles(point_count);
}

stratmesh_status stratmesh_delaunay_2d(const double* xy, size_t point_count,
                                       size_t stride_bytes, void* workspace,
                                       size_t workspace_bytes, uint32_t* triangles,
                                       size_t triangle_capacity,
                                       stratmesh_delaunay_2d_info* info,
                                       uint32_t* duplicate_of) {
    static_assert(sizeof(stratmesh_delaunay_2d_info) == sizeof(stratmesh::Delaunay2dInfo), "");
    stratmesh::Delaunay2dInfo cpp_info;
    std::memset(&cpp_info, 0, sizeof cpp_info);
    // The C++ info is on the stack: the C one is checked against the buffers here.
    if (info) {
        const size_t point_bytes = 2 * sizeof(double);
        const stratmesh::detail::ByteRange ranges[] = {
            stratmesh::detail::byte_range(info, sizeof *info),
            stratmesh::detail::strided_range(xy, point_count,
                                             stride_bytes < point_bytes ? point_bytes : stride_bytes,
                                             point_bytes),
            stratmesh::detail::byte_range(workspace, workspace_bytes),
            stratmesh::detail::byte_range(
                triangles, stratmesh::detail::saturating_product(triangle_capacity, 3 * sizeof(uint32_t))),
            stratmesh::detail::byte_range(
                duplicate_of, stratmesh::detail::saturating_product(point_count, sizeof(uint32_t)))};
        if (stratmesh::detail::any_overlap(ranges, 5)) return STRATMESH_STATUS_INVALID_ARGUMENT;
    }
    const stratmesh::Status status =
        stratmesh::delaunay_2d(xy, point_count, stride_bytes, workspace, workspace_bytes,
                               triangles, triangle_capacity, info ? &cpp_info : nullptr,
                               duplicate_of);
    if (info) {
        info->triangle_count = cpp_info.triangle_count;
        info->duplicate_count = cpp_info.duplicate_count;
        info->hull_vertex_count = cpp_info.hull_vertex_count;
        info->first_invalid_index = cpp_info.first_invalid_index;
        info->workspace_used_bytes = cpp_info.workspace_used_bytes;
    }
    return static_cast<stratmesh_status>(status);
}

size_t stratmesh_reconstruct_workspace_size(size_t point_count,
                                            const stratmesh_options* options) {
    return stratmesh::reconstruct_workspace_size(point_count,
                                                 stratmesh::detail::c_options(options));
}

size_t stratmesh_reconstruct_max_triangles(size_t point_count,
                                           const stratmesh_options* options) {
    return stratmesh::reconstruct_max_triangles(point_count,
                                                stratmesh::detail::c_options(options));
}

stratmesh_status stratmesh_reconstruct(const stratmesh_cloud* cloud,
                                       const stratmesh_options* options, void* workspace,
                                       size_t workspace_bytes, uint32_t* triangles,
                                       size_t triangle_capacity, size_t* triangle_count,
                                       stratmesh_report* report) {
    namespace detail = stratmesh::detail;
    if (!cloud) return STRATMESH_STATUS_INVALID_ARGUMENT;
    const stratmesh::Cloud points = detail::c_cloud(*cloud);
    // The C++ report is on the stack: the C one is checked against the buffers here, as
    // reconstruct() checks its own (and not when the count is refused first).
    if (report && points.count <= detail::kMaxPoints - 1) {
        const detail::ByteRange ranges[] = {
            detail::c_report_bytes(report),
            detail::cloud_bytes(points),
            detail::byte_range(workspace, workspace_bytes),
            detail::byte_range(triangles, detail::saturating_product(triangle_capacity,
                                                                     3 * sizeof(uint32_t))),
            detail::byte_range(triangle_count, sizeof(size_t)),
            detail::c_layer_bytes(report)};
        if (detail::any_overlap(ranges, 6)) return STRATMESH_STATUS_INVALID_ARGUMENT;
    }
    stratmesh::Report rep;
    detail::c_report_start(rep, report);
    const stratmesh::Status status =
        stratmesh::reconstruct(points, detail::c_options(options), workspace, workspace_bytes,
                               triangles, triangle_capacity, triangle_count,
                               report ? &rep : nullptr);
    if (report) detail::c_report(rep, *report);
    return static_cast<stratmesh_status>(status);
}

size_t stratmesh_stream_workspace_size(size_t max_points_held,
                                       const stratmesh_options* options) {
    const size_t bytes = stratmesh::stream_workspace_size(max_points_held,
                                                          stratmesh::detail::c_options(options));
    const size_t handle = sizeof(stratmesh_stream) + alignof(stratmesh_stream) - 1;
    return bytes == 0 || bytes > SIZE_MAX - handle ? 0 : bytes + handle;
}

stratmesh_status stratmesh_stream_open(const stratmesh_options* options, void* workspace,
                                       size_t workspace_bytes,
                                       stratmesh_triangle_callback emit, void* emit_user,
                                       stratmesh_report* report, stratmesh_stream** stream) {
    namespace detail = stratmesh::detail;
    if (!options || !workspace || !emit || !stream) return STRATMESH_STATUS_INVALID_ARGUMENT;
    *stream = nullptr;
    if (report) {
        const detail::ByteRange ranges[] = {detail::byte_range(workspace, workspace_bytes),
                                            detail::c_report_bytes(report),
                                            detail::c_layer_bytes(report)};
        if (detail::any_overlap(ranges, 3)) return STRATMESH_STATUS_INVALID_ARGUMENT;
    }
    const size_t align = alignof(stratmesh_stream);
    const size_t pad = (align - reinterpret_cast<uintptr_t>(workspace) % align) % align;
    if (workspace_bytes < pad + sizeof(stratmesh_stream)) return STRATMESH_STATUS_OUT_OF_MEMORY;
    unsigned char* bytes = static_cast<unsigned char*>(workspace) + pad;
    stratmesh_stream* s = reinterpret_cast<stratmesh_stream*>(bytes);
    std::memset(static_cast<void*>(s), 0, sizeof *s);
    s->user_report = report;
    s->emit = emit;
    s->emit_user = emit_user;
    detail::c_report_start(s->report, report);
    const stratmesh::Status status = stratmesh::stream_open(
        detail::c_options(options), bytes + sizeof *s, workspace_bytes - pad - sizeof *s,
        detail::c_emit, s, report ? &s->report : nullptr, &s->stream);
    if (status != stratmesh::Status::ok) return static_cast<stratmesh_status>(status);
    s->prefix = pad + sizeof *s;
    detail::c_stream_report(*s);
    *stream = s;
    return STRATMESH_STATUS_OK;
}

stratmesh_status stratmesh_stream_push(stratmesh_stream* stream,
                                       const stratmesh_cloud* points, double top) {
    if (!stream || !points) return STRATMESH_STATUS_INVALID_ARGUMENT;
    const stratmesh::Status status =
        stratmesh::stream_push(stream->stream, stratmesh::detail::c_cloud(*points), top);
    stratmesh::detail::c_stream_report(*stream);
    return static_cast<stratmesh_status>(status);
}

stratmesh_status stratmesh_stream_close(stratmesh_stream* stream) {
    if (!stream) return STRATMESH_STATUS_INVALID_ARGUMENT;
    const stratmesh::Status status = stratmesh::stream_close(stream->stream);
    stratmesh::detail::c_stream_report(*stream);
    return static_cast<stratmesh_status>(status);
}

#endif  // STRATMESH_C_API
