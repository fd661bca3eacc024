// ==== Status ===============================================================================

// One list generates the enum and its messages, so they cannot drift apart.
#define STRATMESH_STATUS_LIST(X)                                                           \
    /* success */                                                                         \
    X(ok, "success")                                                                      \
    /* argument checks: a caller error, detected before any work */                      \
    X(invalid_argument, "a null pointer with a non-zero count, a stride too small, buffers that overlap, or options that are undefined or contradict each other") \
    X(too_many_points, "more points than 32-bit indices can address")                    \
    X(not_compiled, "the options ask for a feature this build leaves out (STRATMESH_SMALL_CODE)") \
    /* the data */                                                                        \
    X(invalid_point, "a coordinate is NaN or infinite")                                   \
    X(too_few_points, "fewer than 3 distinct points")                                     \
    X(collinear, "all points lie on one line")                                            \
    X(invalid_axis, "the axis direction is zero, NaN, infinite, or too long or short to square") \
    X(invalid_layers, "a cut, the layer count or the layer height is NaN, infinite or negative") \
    X(invalid_origin, "the given origin is NaN or infinite, or lies farther from the cloud than 2^32 times its size") \
    X(flat_cloud, "the cloud has no extent along the axis")                               \
    X(not_columnar, "the points do not surround the axis in any layer")                   \
    X(degenerate, "the surface through the points has no area: they lie on a line up to rounding, or a few lie so far from the rest that the rest collapse") \
    X(separate_clusters, "the points form clusters so far apart that no one surface joins them: mesh each cluster on its own") \
    X(out_of_order, "a streamed layer is out of axis order: its top is below the previous one, or a point lies outside its heights") \
    /* memory */                                                                          \
    X(out_of_memory, "the workspace is smaller than its *_workspace_size() bound")         \
    X(triangle_capacity, "the triangle array is too small for the result")               \
    /* bugs */                                                                            \
    X(internal_error, "an internal invariant failed (a bug: please report the input)")

enum class Status : uint32_t {
#define STRATMESH_STATUS_ENUM(name, message) name,
    STRATMESH_STATUS_LIST(STRATMESH_STATUS_ENUM)
#undef STRATMESH_STATUS_ENUM
};

// The status's name followed by a one-line explanation; never null.
const char* status_string(Status status);
