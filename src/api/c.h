// ==== C interface ==========================================================================
//
// The same fixed-workspace functions for C99 callers: stratmesh_-prefixed functions over
// plain structs, enum constants prefixed STRATMESH_. A C file includes this header as it
// is and sees only this section; a C++ file sees it next to the C++ interface. The
// implementation is C++: compile stratmesh.cpp with a C++17 compiler (g++ -std=c++17 -c
// stratmesh.cpp) and link it, or link CMake's target stratmesh::stratmesh (libstratmesh.a);
// link the program with the C++ compiler driver (or add -lstdc++ -lm), so that whatever
// the C++ compiler's code refers to is found. Defining STRATMESH_IMPLEMENTATION in a C file
// is an error. Each function wraps the C++ one of the same name (stratmesh_reconstruct is
// stratmesh::reconstruct) and converts its structs, field for field: the contracts, the
// statuses and the results are the C++ ones, documented above; a C++ program can call
// either.
//
//   STRATMESH_C_API     0 or 1, where the implementation is compiled and where the header
//                       is included alike. Default 1, or 0 with STRATMESH_SMALL_CODE,
//                       whose build is held to a code budget: define it to 1 there to
//                       have the C functions. With 0 this section declares nothing and
//                       the implementation defines nothing of it.

#if !defined(STRATMESH_C_API)
#if defined(STRATMESH_SMALL_CODE)
#define STRATMESH_C_API 0
#else
#define STRATMESH_C_API 1
#endif
#endif

#if STRATMESH_C_API

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// stratmesh::Status, value for value (the C++ part asserts it). Every function that does
// work returns one; stratmesh_status_string() names it.
typedef enum stratmesh_status {
    STRATMESH_STATUS_OK = 0,
    STRATMESH_STATUS_INVALID_ARGUMENT,
    STRATMESH_STATUS_TOO_MANY_POINTS,
    STRATMESH_STATUS_NOT_COMPILED,
    STRATMESH_STATUS_INVALID_POINT,
    STRATMESH_STATUS_TOO_FEW_POINTS,
    STRATMESH_STATUS_COLLINEAR,
    STRATMESH_STATUS_INVALID_AXIS,
    STRATMESH_STATUS_INVALID_LAYERS,
    STRATMESH_STATUS_INVALID_ORIGIN,
    STRATMESH_STATUS_FLAT_CLOUD,
    STRATMESH_STATUS_NOT_COLUMNAR,
    STRATMESH_STATUS_DEGENERATE,
    STRATMESH_STATUS_SEPARATE_CLUSTERS,
    STRATMESH_STATUS_OUT_OF_ORDER,
    STRATMESH_STATUS_OUT_OF_MEMORY,
    STRATMESH_STATUS_TRIANGLE_CAPACITY,
    STRATMESH_STATUS_INTERNAL_ERROR
} stratmesh_status;

// stratmesh::Scalar: the type of a cloud's coordinates (stratmesh_cloud::scalar).
typedef enum stratmesh_scalar {
    STRATMESH_SCALAR_FLOAT64 = 0,
    STRATMESH_SCALAR_FLOAT32 = 1
} stratmesh_scalar;

// stratmesh::Axis: the direction the layers are stacked along (stratmesh_options::axis).
typedef enum stratmesh_axis {
    STRATMESH_AXIS_AUTOMATIC = 0,  // the cloud's principal direction
    STRATMESH_AXIS_X,
    STRATMESH_AXIS_Y,
    STRATMESH_AXIS_Z,
    STRATMESH_AXIS_DIRECTION       // stratmesh_options::direction
} stratmesh_axis;

// stratmesh::Flags: bits of stratmesh_options::flags, each documented at its C++ name
// (STRATMESH_FLAG_ADD_CAPS is stratmesh::add_caps).
enum stratmesh_flags {
    STRATMESH_FLAG_SKIP_INVALID_POINTS = 1 << 0,
    STRATMESH_FLAG_ADD_CAPS = 1 << 1,
    STRATMESH_FLAG_ORIGIN_GIVEN = 1 << 2,
    STRATMESH_FLAG_DROP_OUTLIERS = 1 << 3,
    STRATMESH_FLAG_SURFACE_FLIPS = 1 << 4,
    STRATMESH_FLAG_ENDS_ARE_CUTS = 1 << 5
};

// stratmesh::Parts: what reconstruction meshes where the cloud parts into branches
// (stratmesh_options::parts).
typedef enum stratmesh_parts {
    STRATMESH_PARTS_AUTOMATIC = 0,
    STRATMESH_PARTS_ONE_TUBE,
    STRATMESH_PARTS_APART
} stratmesh_parts;

// stratmesh::ClosedEnd: bits of stratmesh_layer_info::closed_ends.
enum stratmesh_closed_end {
    STRATMESH_CLOSED_BOTTOM = 1 << 0,
    STRATMESH_CLOSED_TOP = 1 << 1
};

// stratmesh::Phase: the phases reported to stratmesh_options::progress, in order.
typedef enum stratmesh_phase {
    STRATMESH_PHASE_VALIDATE = 0,
    STRATMESH_PHASE_LAYERS,
    STRATMESH_PHASE_TRIANGULATE,
    STRATMESH_PHASE_STITCH,
    STRATMESH_PHASE_MANIFOLD,
    STRATMESH_PHASE_DONE
} stratmesh_phase;

// stratmesh::PartsOutcome: how reconstruction met a cloud that parts into branches
// (stratmesh_part_counts::outcome).
typedef enum stratmesh_parts_outcome {
    STRATMESH_PARTS_OUTCOME_ONE_TUBE = 0,
    STRATMESH_PARTS_OUTCOME_JOINED,
    STRATMESH_PARTS_OUTCOME_KEPT_APART,
    STRATMESH_PARTS_OUTCOME_UNDONE
} stratmesh_parts_outcome;

// The name of a status (a stratmesh_status value) and a one-line explanation
// (stratmesh::status_string); never NULL, "unknown status" for a value outside the list.
// An integer, so that any value a caller holds can be named without undefined behaviour.
const char* stratmesh_status_string(uint32_t status);

// Exact-sign predicates on double[2] points (stratmesh::orient2d, stratmesh::incircle):
// twice the signed area of abc, and positive when d lies inside the circle through the
// counter-clockwise a, b, c.
double stratmesh_orient2d(const double a[2], const double b[2], const double c[2]);
double stratmesh_incircle(const double a[2], const double b[2], const double c[2],
                          const double d[2]);

// stratmesh::Delaunay2dInfo.
typedef struct stratmesh_delaunay_2d_info {
    size_t triangle_count;        // written (or needed, on TRIANGLE_CAPACITY)
    size_t duplicate_count;       // points repeating an earlier point's coordinates
    size_t hull_vertex_count;     // points on the convex hull, collinear ones too
    size_t first_invalid_index;   // the first NaN/Inf point, on INVALID_POINT
    size_t workspace_used_bytes;  // peak workspace bytes
} stratmesh_delaunay_2d_info;

// Workspace bytes and most triangles for stratmesh_delaunay_2d of point_count points
// (stratmesh::delaunay_2d_workspace_size and _max_triangles): bounds, so that a caller
// sizes its buffers once; 0 when no buffer can serve that many points.
size_t stratmesh_delaunay_2d_workspace_size(size_t point_count);
size_t stratmesh_delaunay_2d_max_triangles(size_t point_count);

// The Delaunay triangulation of point_count points (x, y doubles, the next point
// stride_bytes later), as stratmesh::delaunay_2d: info and duplicate_of may be NULL.
stratmesh_status stratmesh_delaunay_2d(const double* xy, size_t point_count,
                                       size_t stride_bytes, void* workspace,
                                       size_t workspace_bytes, uint32_t* triangles,
                                       size_t triangle_capacity,
                                       stratmesh_delaunay_2d_info* info,
                                       uint32_t* duplicate_of);

// stratmesh::Cloud: x, y, z of the first point at xyz, each next point stride_bytes
// further (0: packed), scalar a stratmesh_scalar. Read in place, any alignment.
typedef struct stratmesh_cloud {
    const void* xyz;
    size_t count;
    size_t stride_bytes;
    uint32_t scalar;  // stratmesh_scalar
} stratmesh_cloud;

// One job of a batch (stratmesh::JobFunction): job(context, index).
typedef void (*stratmesh_job_function)(void* context, uint32_t index);

// Runs job(context, i) for every i in [0, count) on any threads and returns when all have
// finished (stratmesh::JobRunner, same contract).
typedef void (*stratmesh_job_runner)(void* user, uint32_t count, stratmesh_job_function job,
                                     void* context);

// stratmesh::Options, field for field, with uint32_t for the enums so that the layout
// does not depend on the compiler's enum size. All zero means defaults: `stratmesh_options
// options = {0};` (or memset) is always valid. Each field is documented at its C++ name.
typedef struct stratmesh_options {
    uint32_t axis;                  // stratmesh_axis
    double direction[3];            // for STRATMESH_AXIS_DIRECTION
    // At most one of the cuts, layer_count and layer_height; none: automatic layers.
    const double* cuts;             // explicit cut heights, dot(point, axis)
    size_t cut_count;
    uint32_t layer_count;           // equal-height layers
    double layer_height;            // layers of about this height
    uint32_t flags;                 // stratmesh_flags bits
    uint32_t parts;                 // stratmesh_parts
    double origin[3];               // with STRATMESH_FLAG_ORIGIN_GIVEN
    // Optional: called with each phase as it starts and with the fraction done; must not
    // call back into stratmesh.
    void (*progress)(void* user, stratmesh_phase phase, double fraction);
    void* progress_user;
    // Optional, reconstruction only: runs the layers' jobs on the caller's threads.
    stratmesh_job_runner run_jobs;
    void* jobs_user;
} stratmesh_options;

// stratmesh::LayerInfo: one layer of the output (stratmesh_layer_counts::info).
typedef struct stratmesh_layer_info {
    double bottom, top;       // extent along the axis, as dot(point, axis)
    double centre[3];         // a point on the unrolling cylinder's axis
    double radius;            // the unrolling radius
    uint32_t point_count;     // distinct valid points in the layer
    uint32_t triangle_count;  // its triangles and its band below, before the safety net
    uint32_t fold_count;      // of those, triangles facing the axis
    uint32_t closed_ends;     // stratmesh_closed_end bits
} stratmesh_layer_info;

// stratmesh::PointCounts: in_count = used_count + duplicate_count + rejected_count +
// unused_count on every status.
typedef struct stratmesh_point_counts {
    size_t in_count;             // points given (the stream: pushed so far)
    size_t used_count;           // vertices of the output
    size_t duplicate_count;      // same coordinates as a lower-indexed point
    size_t rejected_count;       // NaN/Inf (with SKIP_INVALID_POINTS) and outliers
    size_t outlier_count;        // of rejected_count: left out by DROP_OUTLIERS
    size_t unused_count;         // valid but not a vertex (detail says why)
    size_t first_invalid_index;  // on INVALID_POINT: the first NaN/Inf point
    size_t held_count;           // the stream only: the most points held at once
} stratmesh_point_counts;

// stratmesh::LayerCounts. The caller points info at info_capacity entries (or leaves it
// NULL); the first min(used_count, info_capacity) are filled.
typedef struct stratmesh_layer_counts {
    size_t planned_count;   // layers planned, before merging
    size_t used_count;      // layers of the output
    size_t parallel_count;  // of those, triangulated by run_jobs' jobs
    stratmesh_layer_info* info;
    size_t info_capacity;
    size_t skeleton_node_count;  // 0: stacked along the axis; else the bent skeleton's nodes
} stratmesh_layer_counts;

// stratmesh::CapCounts, with STRATMESH_FLAG_ADD_CAPS; all 0 without it.
typedef struct stratmesh_cap_counts {
    size_t closed_count;     // boundary loops closed by a cap
    size_t open_count;       // loops left open
    size_t triangle_count;   // the caps' triangles, the last of the output
    size_t wall_flip_count;  // the surface's edges flipped so that a loop could be capped
} stratmesh_cap_counts;

// stratmesh::PartCounts, flattened: the counts and where the cloud parts (the gap, the
// cuts and their branch counts of stratmesh::Parting). The per-branch point counts and the
// per-part details are left to the C++ interface.
typedef struct stratmesh_part_counts {
    uint32_t outcome;                 // stratmesh_parts_outcome
    double gap;                       // Parting::gap: the linking distance
    double above;                     // the lowest cut above which the cloud parts
    uint32_t above_branch_count;      // (0: it does not part above any cut)
    double below;                     // the highest cut below which it parts
    uint32_t below_branch_count;
    size_t part_count;                // parts meshed apart (0: one tube)
    size_t joined_side_count;         // sides whose branches were joined
    size_t apart_side_count;          // sides left apart
    size_t grafted_branch_count;      // branches grafted onto the trunk's closed end
    size_t junction_triangle_count;   // triangles the junctions added
    size_t removed_triangle_count;    // trunk triangles the grafts took out
} stratmesh_part_counts;

// stratmesh::Diagnostics: what a user checks before trusting the mesh.
typedef struct stratmesh_diagnostics {
    size_t fold_count;             // output triangles whose normal faces the axis (with
                                   // the surface flips, before them)
    size_t illegal_removed_count;  // triangles removed by the manifold safety net
    size_t diagonal_swap_count;    // band diagonals swapped when stitching layers
    double point_spacing;          // the fit (stratmesh::Diagnostics says each)
    double area_per_point;
    size_t fit_sample_count;
    double misfit_area_fraction;
    double misfit_area;
    double misfit_box_min[3];
    double misfit_box_max[3];
    size_t crossing_pair_count;
    int crossing_check_complete;   // 1: every pair checked
    double crossing_box_min[3];
    double crossing_box_max[3];
} stratmesh_diagnostics;

// stratmesh::kPoorMisfitFraction: a surface with a crossing pair, or a misfit share above
// this, is poor.
#define STRATMESH_POOR_MISFIT_FRACTION 0.05

// stratmesh::Report, its groups as nested structs, so that C code reads the same counts
// under the same names. stratmesh_reconstruct fills it on every status, counts adding up,
// except when it refuses overlapping buffers (INVALID_ARGUMENT: nothing written); the
// stream fills it when it opens and after every push and close. Set layers.info and
// layers.info_capacity before the call for per-layer details (all zero: none).
typedef struct stratmesh_report {
    size_t triangle_count;
    double axis[3];                 // unit axis used
    double axis_origin[3];          // a point on it
    stratmesh_point_counts points;
    stratmesh_layer_counts layers;
    stratmesh_cap_counts caps;
    stratmesh_part_counts parts;
    stratmesh_diagnostics diagnostics;
    const char* detail;             // a static sentence on why something failed or was dropped
    size_t workspace_used_bytes;    // the least workspace that suffices for this input
} stratmesh_report;

// Workspace bytes that always suffice for stratmesh_reconstruct of point_count points
// with these options (NULL: the defaults), and the most triangles it can produce
// (stratmesh::reconstruct_workspace_size and _max_triangles): bounds, so that a caller
// sizes its buffers before it has the points; 0 when no buffer can serve that many.
size_t stratmesh_reconstruct_workspace_size(size_t point_count,
                                            const stratmesh_options* options);
size_t stratmesh_reconstruct_max_triangles(size_t point_count,
                                           const stratmesh_options* options);

// Reconstructs the surface through a columnar cloud (stratmesh::reconstruct): triangles
// receives 3 * *triangle_count indices into the cloud, counter-clockwise seen from
// outside. options NULL means the defaults; report may be NULL. A NULL cloud, or a report
// sharing a byte with the cloud's points, the workspace, the triangles, *triangle_count or
// the report's layer array, returns STRATMESH_STATUS_INVALID_ARGUMENT and writes nothing;
// every other status is the C++ function's.
stratmesh_status stratmesh_reconstruct(const stratmesh_cloud* cloud,
                                       const stratmesh_options* options, void* workspace,
                                       size_t workspace_bytes, uint32_t* triangles,
                                       size_t triangle_capacity, size_t* triangle_count,
                                       stratmesh_report* report);

// A stream in the caller's workspace (stratmesh::Stream, with the C report it updates):
// opaque, valid from stratmesh_stream_open until stratmesh_stream_close or until the
// workspace is reused. Nothing to free.
typedef struct stratmesh_stream stratmesh_stream;

// Receives the stream's final triangles: 3 * count global indices, valid during the call
// only (stratmesh::TriangleCallback). Must not call back into the same stream.
typedef void (*stratmesh_triangle_callback)(void* user, const uint32_t* triangles,
                                            size_t count);

// Workspace bytes for a stream that holds at most max_points_held points at once
// (stratmesh::stream_workspace_size, plus the C handle and its report); 0 if beyond what
// this platform can address.
size_t stratmesh_stream_workspace_size(size_t max_points_held,
                                       const stratmesh_options* options);

// Opens a stream in the workspace (stratmesh::stream_open): options (not NULL) as there,
// emit receives the triangles, report (optional) is updated after every call on the
// stream and must stay valid until the stream is closed; its workspace_used_bytes counts
// from the start of this workspace, the handle included. On success *stream is the handle.
// Returns the C++ statuses; OUT_OF_MEMORY also when the workspace cannot hold the handle.
stratmesh_status stratmesh_stream_open(const stratmesh_options* options, void* workspace,
                                       size_t workspace_bytes,
                                       stratmesh_triangle_callback emit, void* emit_user,
                                       stratmesh_report* report, stratmesh_stream** stream);

// Pushes the next layer, its points and its top (stratmesh::stream_push); a NULL stream or
// points returns INVALID_ARGUMENT. May call emit.
stratmesh_status stratmesh_stream_push(stratmesh_stream* stream,
                                       const stratmesh_cloud* points, double top);

// Forms and emits the last layers and completes the report (stratmesh::stream_close).
stratmesh_status stratmesh_stream_close(stratmesh_stream* stream);

#ifdef __cplusplus
}  // extern "C"
#endif

#endif  // STRATMESH_C_API
