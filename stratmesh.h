// stratmesh.h - stratified surface reconstruction of columnar point clouds, in fixed memory.
// Version 0.1.0. MIT licence (text at the end of this file).
//
// stratmesh turns a 3D point cloud of a roughly columnar object (a head, a limb, a bone,
// a pipe, a tree stem) into a triangle mesh that interpolates the points, by the method of
// Y. Xiao, Z. Deng and B. Li, "A Surface Reconstruction Algorithm Based on 3D Point Cloud
// Stratified Sliced", Sensors & Transducers, 2014: the cloud is sliced into layers across
// an axis, each layer is projected onto a cylinder and unrolled onto a plane, triangulated
// there by an exact 2D Delaunay triangulation, mapped back, and the layers are stitched
// into one manifold surface. No heap, no exceptions, no globals: all working memory is a
// buffer the caller sizes in advance.
//
// ==== Quick start ==========================================================================
//
//     #define STRATMESH_IMPLEMENTATION    // in exactly one .cpp file
//     #include "stratmesh.h"
//
//     // A mesh through n scanned points stored as x, y, z floats.
//     stratmesh::Options options = {};               // all zero: the defaults
//     stratmesh::Cloud cloud = {xyz, n, 0, stratmesh::Scalar::float32};  // 0: packed
//     std::vector<unsigned char> work(stratmesh::reconstruct_workspace_size(n, options));
//     std::vector<uint32_t> tris(3 * stratmesh::reconstruct_max_triangles(n, options));
//     stratmesh::Report report = {};
//     size_t count = 0;
//     stratmesh::Status s = stratmesh::reconstruct(cloud, options, work.data(), work.size(),
//                                                  tris.data(), tris.size() / 3, &count,
//                                                  &report);
//     if (s != stratmesh::Status::ok) puts(stratmesh::status_string(s));
//     // tris[0 .. 3 * count) index the cloud, counter-clockwise seen from outside.
//
//     // The 2D Delaunay triangulation on its own, of points stored as x0, y0, x1, y1, ...
//     std::vector<unsigned char> work2(stratmesh::delaunay_2d_workspace_size(m));
//     std::vector<uint32_t> tris2(3 * stratmesh::delaunay_2d_max_triangles(m));
//     stratmesh::Delaunay2dInfo info;
//     s = stratmesh::delaunay_2d(xy, m, 2 * sizeof(double), work2.data(), work2.size(),
//                                tris2.data(), tris2.size() / 3, &info, nullptr);
//
// (std::vector is only the caller's choice here: any buffer will do, static or stack.)
//
// What the defaults do (all-zero Options): the axis is chosen automatically (the direction
// along which the cloud's sections are loops around one centre line, tried on a sample),
// the layers are chosen automatically, the cloud is searched for where it parts into
// branches and, where it does, the trunk and each branch are meshed along their own axes
// and joined into one surface; the ends stay open (add_caps caps them) and the layers stay
// Delaunay on their unrolled annulus, as in the paper (surface_flips refines them on the
// surface, at a cost in time).
//
// ==== Integration ==========================================================================
//
// Either define STRATMESH_IMPLEMENTATION before including this header in one source file
// (every other file includes it plainly), or compile stratmesh.cpp, which does exactly
// that, and link it (CMake: target stratmesh::stratmesh). Including the header several
// times, with or without the macro, is safe.
//
// From C (C99): include the header as it is; it then declares the C interface only
// (stratmesh_reconstruct and the rest, see "C interface" at the end of the declarations).
// Compile stratmesh.cpp with a C++17 compiler and link it with the C program.
//
// Only C++17 headers that need no runtime support are used: <cstddef>, <cstdint>,
// <cstring>, <cfloat>, <climits> and <cmath> (for sqrt, floor, ceil, frexp and ldexp, which
// IEEE-754 defines exactly, so every platform computes the same bits). Builds with
// -fno-exceptions -fno-rtti; the library never allocates and never throws.
//
// ==== Configuration macros =================================================================
//
//   STRATMESH_ASSERT(cond)   default: nothing (assertions compiled out).
//                            Define it (e.g. to assert(cond)) to check internal
//                            invariants in debug builds. Bad *data* never reaches an
//                            assert: it returns a Status.
//   STRATMESH_NO_PARALLEL_LAYERS   default: not defined. Define it where the implementation
//                            is compiled to leave out the parallel-layers code:
//                            Options::run_jobs is then ignored and everything runs in
//                            order, with the same result. For single-core targets.
//   STRATMESH_C_API          0 or 1; default 1, or 0 with STRATMESH_SMALL_CODE. Declares
//                            and compiles the C interface (see "C interface"); define it
//                            alike where the implementation is compiled and where the
//                            header is included.
//   STRATMESH_SMALL_CODE     default: not defined. The reduced build, for targets where
//                            code size comes first (CI holds it within 32 KiB of
//                            Cortex-M7 code at -Os): it meshes one tube along the axis
//                            the caller gives, as the paper does. It leaves out:
//                            - what only makes it faster (parallel layers, the safety
//                              net's shortcut, the staging of grouped points, the
//                              predicates' integer stages): same bytes, slower;
//                            - the search for branches (as if Options::parts were
//                              always Parts::one_tube), the automatic axis
//                              (Axis::automatic returns Status::not_compiled), the
//                              check for a degenerate
//                              cloud, find_parting(), join_branches() and cap_ends()
//                              (not declared);
//                            - closed ends (a dome or a flat base is unrolled on the
//                              cylinder like the rest) and the merging of a layer next
//                              to a slanted end, so the layers and triangles at such
//                              ends differ from the full build's;
//                            - the caps' lowering and raising along the axis, their
//                              pockets, restarts, exhaustive search and fin flips: its
//                              caps are the Delaunay triangulation of each loop's
//                              projection, and more loops stay open;
//                            - the finer peeling of loops where layers fold: where the
//                              object forks at its end (horns), a web of triangles may
//                              stay between the branches' tips;
//                            - the measure of webs (Report::diagnostics' web fields
//                              stay 0);
//                            - the C interface, unless STRATMESH_C_API is 1;
//                            - the flags drop_outliers, surface_flips and ends_are_cuts,
//                              which also return not_compiled (filter the cloud before
//                              it reaches the device).
//
// ==== Memory ===============================================================================
//
// Every function that needs working memory takes (void* workspace, size_t workspace_bytes)
// and has a *_workspace_size() companion that returns a size that is always sufficient
// (a bound: a given input may need less). The workspace needs no particular alignment.
// A workspace smaller than the call turns out to need returns Status::out_of_memory; the
// library never writes outside the workspace and the output arrays it is given, whatever
// the input.
//
// What a call needs follows from its arguments through those functions alone:
// delaunay_2d_workspace_size() and delaunay_2d_max_triangles(); reconstruct_workspace_size()
// (which grows with add_caps, drop_outliers, a jobs runner and the search for branches)
// and reconstruct_max_triangles() (with the search for branches); stream_workspace_size()
// of the points held at once, whatever the size of the whole cloud; and the bounds of
// cap_ends(), find_parting() and join_branches(). Report::workspace_used_bytes tells what
// a run used.
//
// The whole workspace belongs to the call while it runs, including what it does not need:
// without a runner, reconstruct keeps the points grouped by layer in spare workspace when
// they fit, instead of reading the cloud at random once per layer. The
// output is the same either way, and Report::workspace_used_bytes leaves that room out (it
// is the least workspace that suffices).
//
// Stack: no recursion anywhere. The exact
// incircle's expansions live in the workspace when called from the triangulation, and on
// the stack only when you call incircle() yourself. CI bounds the reduced build's stack on
// a Cortex-M7 from its call graph.
//
// ==== Errors ===============================================================================
//
// Every public function returns a Status; status_string() names it. Status values are
// grouped by what detects them: argument checks, the data, memory, and internal_error,
// which means an invariant failed (a bug: please report it with the input). Nothing is
// thrown and nothing aborts.
//
// ==== Threading ============================================================================
//
// No global or static mutable state. Functions are reentrant: threads may run them at
// once with separate workspaces. The library starts no thread; Options::run_jobs lets the
// caller run a reconstruction's layers on its own threads. A Stream belongs to one thread
// at a time, and its callback must not call back into the stream.
//
// ==== Robustness contract ==================================================================
//
// - orient2d and incircle return values whose sign is exact for every finite double input
//   whose non-zero coordinates and coordinate differences span at most 2^320 in magnitude
//   within one call for incircle (2^800 for orient2d): say 1e-45 next to 1e+50. Beyond
//   that, products of differences cannot all be represented and the sign may be wrong
//   (subnormal and tiny inputs are fine: they are rescaled). A floating-point filter with
//   a proven error bound decides almost every call; fixed-width integers decide most of
//   the rest, and expansion arithmetic the remainder. Floating-point contraction (fused
//   multiply-add) is pinned off, whatever the compiler's flags, so every platform
//   computes the same signs.
// - delaunay_2d produces the Delaunay triangulation of the distinct input points. Where
//   four or more points are cocircular, the triangulation is made unique by a symbolic
//   perturbation (each point is lifted off the paraboloid by an infinitesimal amount that
//   grows with its lexicographic (x, y) rank), so the set of triangles depends only on
//   the coordinates: not on the input order, not on the architecture. Exact duplicates
//   are not triangulated twice: each is mapped to the lowest index with the same
//   coordinates. Every other point is a vertex of the output. Beyond the predicates' exact
//   range the signs can contradict each other: delaunay_2d then still writes at most
//   delaunay_2d_max_triangles() triangles of valid indices, or returns internal_error,
//   but the triangles need not be Delaunay.
// - NaN or infinite coordinates are refused (Status::invalid_point, with the index), or
//   skipped and counted with the skip_invalid_points flag of reconstruct.
// - reconstruct keeps its own predicate calls inside that exact range, whatever the cloud:
//   the frame is rescaled by a power of two (even for a cloud spanning more than the
//   largest double) and the unrolled coordinates are bounded, so a far outlier or a cloud
//   at 1e-300 cannot break a sign. A cloud whose surface would have no area (points on a
//   line up to rounding, or a few points so far away that the rest collapse to one) is
//   refused with Status::degenerate rather than meshed into slivers, and one whose points
//   form clusters so far apart that each collapses to a point with
//   Status::separate_clusters.
// - reconstruct's output is edge- and vertex-manifold and consistently oriented for every
//   input it accepts: the layers and the bands between them form one annulus by
//   construction, and a safety net, run on each layer with its band below as soon as they
//   are built, removes (and counts) any triangle that would break that, keeping the seams
//   between them manifold too. The stream's output has the same guarantee. The output is
//   free of self-intersections where every layer is star-shaped around its centre, caps
//   included; where a layer is not, it may cross itself, and
//   Report::diagnostics.fold_count counts the triangles facing the axis there.
// - The same input gives the same bytes on every platform and for every thread count. A
//   reordered cloud gives another mesh, as valid: the frame's origin and the layers'
//   centres are sums taken in input order, whose last bits depend on the order.

#ifndef STRATMESH_H
#define STRATMESH_H

#define STRATMESH_VERSION_MAJOR 0
#define STRATMESH_VERSION_MINOR 1
#define STRATMESH_VERSION_PATCH 0
#define STRATMESH_VERSION_STRING "0.1.0"

// The C++ interface; a C compiler sees only the C interface below it (see "C interface").
#ifdef __cplusplus

#include <cstddef>
#include <cstdint>

namespace stratmesh {

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

// ==== Predicates ===========================================================================
//
// Points are double[2] (x, y). The returned value's sign is exact (see the robustness
// contract above); its magnitude is an approximation of the determinant.

// Twice the signed area of triangle abc: positive if a, b, c turn counter-clockwise,
// negative if clockwise, zero if collinear.
double orient2d(const double a[2], const double b[2], const double c[2]);

// Positive if d lies inside the circle through a, b, c (which must be counter-clockwise),
// negative if outside, zero if the four points are cocircular. If a, b, c are clockwise
// the sign is reversed.
double incircle(const double a[2], const double b[2], const double c[2], const double d[2]);

// ==== 2D Delaunay triangulation ============================================================

struct Delaunay2dInfo {
    size_t triangle_count;      // triangles written (or needed, on triangle_capacity)
    size_t duplicate_count;     // points that repeat an earlier point's coordinates
    size_t hull_vertex_count;   // points on the convex hull boundary, collinear ones too
    size_t first_invalid_index; // index of the first NaN/Inf point, on invalid_point
    size_t workspace_used_bytes;      // peak workspace bytes, from the start of the buffer
};

// A size in bytes that is always enough workspace for delaunay_2d of point_count points;
// 0 if no workspace can serve that many (more than 2^32 - 2 points, or more bytes than
// this platform's size_t can count, as on 32-bit targets near 2^32 points).
size_t delaunay_2d_workspace_size(size_t point_count);

// The most triangles delaunay_2d can produce for point_count points: 2n - 5 for n >= 3
// (0 if that does not fit in size_t).
size_t delaunay_2d_max_triangles(size_t point_count);

// Delaunay triangulation of 2D points.
//
// xy              first point's x; y follows it; the next point starts stride_bytes later.
//                 Needs no alignment.
// point_count     number of points, at most 2^32 - 2.
// stride_bytes    distance between consecutive points, at least 2 * sizeof(double).
// workspace       at least delaunay_2d_workspace_size(point_count) bytes.
// triangles       receives 3 * triangle_count indices into the input, each triangle
//                 counter-clockwise. Triangles appear in an unspecified but deterministic
//                 order; the set of triangles depends only on the coordinates.
// triangle_capacity  how many triangles fit in `triangles`; delaunay_2d_max_triangles()
//                 always suffices. When too small: Status::triangle_capacity, nothing
//                 written, info->triangle_count says how many are needed.
// info            optional; receives counts (see Delaunay2dInfo).
// duplicate_of    optional array of point_count entries: receives, for each point, the
//                 index of the lowest-indexed point with the same coordinates (itself if
//                 it has no lower twin; -0.0 and +0.0 are the same). Meaningful on ok;
//                 unspecified otherwise.
//
// Returns ok; invalid_argument (a null pointer with a non-zero count, a stride too small,
// or any two of the span of xy's points, the workspace, the triangle array, duplicate_of
// and *info sharing a byte: then nothing at all is written); too_many_points;
// invalid_point; too_few_points (fewer than 3 distinct points); collinear (no triangle
// exists); out_of_memory; triangle_capacity; internal_error (only for coordinates beyond
// the predicates' exact range: see Robustness contract). On every status but ok,
// triangle_count is 0 (except triangle_capacity) and no triangle is written.
Status delaunay_2d(const double* xy, size_t point_count, size_t stride_bytes,
                   void* workspace, size_t workspace_bytes,
                   uint32_t* triangles, size_t triangle_capacity,
                   Delaunay2dInfo* info, uint32_t* duplicate_of);

// ==== Surface reconstruction ===============================================================

enum class Scalar : uint32_t { float64 = 0, float32 = 1 };

// A point cloud in the caller's memory: x, y, z of the first point at `xyz`, each next
// point `stride_bytes` further (0 means packed: 3 scalars). No alignment needed, so
// interleaved scanner records (normals, colours, intensity) are read in place.
struct Cloud {
    const void* xyz;
    size_t count;
    size_t stride_bytes;
    Scalar scalar;
};

// The direction the layers are stacked along.
enum class Axis : uint32_t {
    // The direction along which the cloud's sections are loops around one centre line:
    // the first principal direction where a sample's surface runs along it (a tube, a
    // limb), else whichever of the principal directions and x, y, z gives a sample the
    // smallest surface (a layer that cannot follow the surface folds and adds area). The
    // reduced build (STRATMESH_SMALL_CODE) returns Status::not_compiled.
    automatic = 0,
    x,
    y,
    z,
    direction       // Options::direction
};

enum Flags : uint32_t {
    // NaN/Inf points are skipped and counted (Report::points.rejected_count) instead of refused with
    // Status::invalid_point.
    skip_invalid_points = 1u << 0,
    // Closes the surface's boundary loops with caps over the loops' own vertices (no new
    // vertex), so that a tube becomes a closed, edge- and vertex-manifold, consistently
    // oriented surface (Euler characteristic 2, normals outward: the bottom cap faces -axis,
    // the top one +axis): what solid modelling, printing and volumes need. No cap repeats an
    // edge of the surface; where the surface's fins (triangles with two edges on the loop)
    // leave no such cap, the edge under a fin may be flipped (two triangles change in place,
    // same corners, same count; Report::caps.wall_flip_count). A loop whose projection
    // across the axis is not a simple polygon, or that no cap closes, stays open: the call
    // still returns ok, Report::caps.open_count counts it and Report::detail says so.
    // reconstruct_max_triangles() still suffices. The stream refuses the flag: cap_ends()
    // caps its surface afterwards.
    add_caps = 1u << 1,
    // The frame's reference point is Options::origin instead of the centroid of the cloud
    // (reconstruct) or of the first layer (the stream). The reference point changes only
    // rounding, but a stream and a reconstruct() that are to give the same triangles need
    // the same one.
    origin_given = 1u << 2,
    // Points far from the rest of the cloud (stray returns, flying pixels, small specks)
    // are left out before anything else and counted (Report::points.outlier_count, part of
    // rejected_count), so that they neither tilt the automatic axis nor stretch the layers
    // nor become spikes. For raw sensor clouds whose outliers are a small share of the
    // points; off by default, since without it every valid point is a vertex.
    // reconstruct_workspace_size() includes what it needs. The stream refuses it
    // (invalid_argument); the reduced build returns not_compiled.
    drop_outliers = 1u << 3,
    // After each layer is triangulated on its unrolled annulus (the paper's method), its
    // edges are flipped on the surface itself, by the empty-circle rule with angles
    // measured in 3D and toward the direction in which the surface curves least, and so is
    // each seam between layers once they are stitched: the unrolling squeezes whatever lies
    // almost across the axis (the underside of an ear, a chin), and there the flips join
    // the points that are near on the surface. No vertex or loop changes; a flip never
    // turns a triangle over against its neighbours nor makes an angle wider than a fixed
    // obtuse limit (unless it narrows one), and never makes two triangles of the layer
    // cross or touch; it may turn a triangle to face the axis where the surface does (the
    // fold counts stay the unrolling's). The stream gives the same triangles as
    // reconstruct() with it. Off by default: it costs time. The reduced build returns
    // not_compiled.
    surface_flips = 1u << 4,
    // No end of the surface is taken for a closed one (see ClosedEnd): the end layers are
    // unrolled on the cylinder like the others, never around a pole, so the surface's loops
    // lie where the cylinder's picture puts them (a flat end's points on its rim, a dome
    // up to its highest points). For a cloud cut out of a larger object (a region of
    // interest, a branch meshed on its own), whose ends are cuts however many points lie
    // across them. The reduced build, which has no closed ends, returns not_compiled.
    ends_are_cuts = 1u << 5,
};

// What reconstruct() meshes where the cloud parts into branches (Options::parts; see
// PartCounts and find_parting()): one tube cannot follow a fork, it wraps the branches and
// the gaps between them. The stream and the reduced build (STRATMESH_SMALL_CODE) always
// mesh one tube.
enum class Parts : uint32_t {
    // Looks for where the cloud parts, meshes the trunk and its branches apart and joins
    // them; keeps that where it is whole and smaller than one tube, else meshes one tube.
    automatic = 0,
    // One tube through every point, without looking: the paper's single column.
    one_tube,
    // The parts, joined where they can be, kept even where a side could not be joined or
    // points past a cut belong to no branch (left apart or unused, as Report::parts says).
    apart,
};

// Phases reported to Options::progress, in the order they run. Each layer is stitched to
// the one below as soon as it is triangulated, so stitching time falls within
// `triangulate`; `stitch` is announced once, when the last band is done. The caps of
// add_caps are made within `manifold`.
enum class Phase : uint32_t { validate = 0, layers, triangulate, stitch, manifold, done };

// One job of a batch run by Options::run_jobs: job(context, index).
typedef void (*JobFunction)(void* context, uint32_t index);

// Runs job(context, i) once for every i in [0, count), in any order, on any threads (the
// caller's pool, RTOS tasks, std::thread, or a plain loop), and returns when all have
// finished. Jobs are independent: each writes only its own part of the workspace. A
// runner that skips a job only loses time (its layers are done in order afterwards), one
// that runs a job again after it finished changes nothing, and an index outside
// [0, count) is ignored; the same job on two threads at once is a data race.
typedef void (*JobRunner)(void* user, uint32_t count, JobFunction job, void* context);

// The layer rules' thresholds (see Options::cuts), shared with the stream: a point on a
// cut, up to this share of the cloud's height, belongs to the layer above; a layer with
// fewer points than kMinLayerPoints (the last needs 3), or thinner than kMinLayerRows rows
// of points around its radius, joins the next one, since thinner layers make bands that
// fold and cross.
const double kCutTolerance = 0x1p-40;
const size_t kMinLayerPoints = 16;
const double kMinLayerRows = 1.5;

// All zero means defaults: `Options options = {};` is always valid.
struct Options {
    Axis axis;
    double direction[3];     // for Axis::direction; any finite non-zero length
    // Layers, in at most one of three ways (more than one: invalid_argument): explicit cut
    // positions along the axis, as the coordinate dot(point, axis) (with Axis::z, a cut at
    // 68 is the plane z = 68; a point on a cut, up to kCutTolerance of the cloud's height,
    // belongs to the layer above; any order, repeats and cuts outside the cloud are
    // ignored); or layer_count equal-height layers; or layers of about layer_height. With
    // none of them the layers are automatic: the fewest such that one centre line serves
    // each, cut where the cross-section changes least and not through dense detail (the
    // paper's rule), and small enough for jobs to triangulate side by side. Planned layers
    // are then merged where the method needs it: a layer with fewer than kMinLayerPoints
    // points, thinner than kMinLayerRows rows of points around its radius, or whose points
    // do not surround its centre joins the next one (a remainder like that joins the
    // last); a layer next to a slanted end of the tube (a crescent) joins it; a layer with
    // triangles facing the axis is joined with the next one or two where that leaves
    // fewer. Report::layers gives the planned and used counts and the layers used.
    const double* cuts;
    size_t cut_count;
    uint32_t layer_count;
    double layer_height;
    uint32_t flags;          // Flags bits; any other bit is invalid_argument
    Parts parts;             // a value outside Parts is invalid_argument
    double origin[3];        // with the origin_given flag
    // Optional progress callback: called with each phase as it starts, and with the
    // fraction of that phase done from time to time. Must not call back into stratmesh.
    void (*progress)(void* user, Phase phase, double fraction);
    void* progress_user;
    // Optional, reconstruct() only: with a runner, the layers are triangulated as
    // independent jobs (at most kMaxJobs of them, each over a run of consecutive layers with
    // its own scratch in the workspace); grouping layers, stitching them and the safety net
    // stay in order. The triangles and the report are the same bytes whatever the runner
    // does (see JobRunner), Report::layers.parallel_count aside.
    // reconstruct_workspace_size() grows with a runner (see there); a workspace too small
    // for the jobs' scratch runs them in order instead (Report::layers.parallel_count says how
    // many layers were triangulated by jobs). Jobs call no user code, not even progress.
    JobRunner run_jobs;
    void* jobs_user;
};

// The most jobs reconstruct() hands to Options::run_jobs at once, so that the jobs' state
// has a fixed size and their scratch, which reconstruct_workspace_size() covers, a bound.
const uint32_t kMaxJobs = 64;

// LayerInfo::closed_ends. The surface's first layer (closed_bottom) or last layer
// (closed_top) that holds a closed end of the object (a dome, a skull, a flat base: points
// across the end, not only around its rim) is meshed across that end, up to a small loop
// around its pole: the layer is unrolled around a pole inside the end rather than on the
// cylinder, which would fold the end's points onto its rim. The small loop is a boundary
// (add_caps caps it). An end left open as a tube's rim, any other layer, and every layer
// of the reduced build report 0.
enum ClosedEnd : uint32_t { closed_bottom = 1u << 0, closed_top = 1u << 1 };

struct LayerInfo {
    double bottom, top;      // extent along the axis, as dot(point, axis)
    double centre[3];        // the axis of the unrolling cylinder passes through this
                             // (the fitted centre, or the one the centre search chose)
    double radius;           // the unrolling cylinder's radius: the layer's mean distance
                             // from its centre line, raised for a layer many radii tall
                             // (so that its unrolled heights stay in range)
    uint32_t point_count;    // distinct valid points in the layer
    uint32_t triangle_count; // the layer's own triangles plus the band joining it to the
                             // layer below, before the safety net
    uint32_t fold_count;     // of those, triangles facing the axis
    uint32_t closed_ends;    // ClosedEnd bits: which of the layer's ends closes the surface
};

// ==== Where the cloud parts ================================================================

// The most branches a side can hold: each counts with a twentieth of the side's points.
const uint32_t kMaxBranches = 20;
// The fewest points a branch holds.
const uint32_t kSmallestBranch = 64;

struct Parting {
    double gap;               // the linking distance, in the cloud's units; 0 if the cloud
                              // has no scale (too many points without a neighbour in the
                              // grid, as drop_outliers measures it): nothing is found then
    double axis[3];           // unit axis used, as Report::axis
    // The lowest cut, as dot(point, axis), above which the points part into
    // above_branch_count branches (0: no cut where they do; `above` is then 0).
    double above;
    uint32_t above_branch_count;
    // The highest cut below which the points part into below_branch_count branches.
    double below;
    uint32_t below_branch_count;
    // The branches' point counts, largest first (above_branch_count and below_branch_count of them).
    uint32_t above_point_counts[kMaxBranches];
    uint32_t below_point_counts[kMaxBranches];
    size_t workspace_used_bytes;    // peak workspace bytes, from the start of the buffer
    const char* detail;       // a static sentence on why, when the call failed or, with
                              // ok, searched nothing (a cloud without a scale, gap 0, or
                              // one so crowded that the search would cost more than a
                              // bounded number of distance checks per point)
};

// Labels of find_parting()'s branch_of: a point in no branch (the trunk, a NaN point, every
// point where the cloud does not part), in the k-th branch above the cut (k from 0, largest
// first: kFirstAboveBranch + k) or below it (kFirstBelowBranch + k), or beyond a cut but in
// no branch (a piece left aside: apart from the cut, or too small to count and more than a
// gap from it). A piece beyond the cut that is no branch but starts within a gap of it
// (the top of a crown between horns, cut just below) is the trunk's: kInTrunk.
const uint8_t kInTrunk = 0;
const uint8_t kFirstAboveBranch = 1;
const uint8_t kFirstBelowBranch = 1 + kMaxBranches;
const uint8_t kBeyondBranches = 255;

// How reconstruct() met a cloud that parts into branches (PartCounts::outcome).
enum class PartsOutcome : uint32_t {
    one_tube = 0,  // one tube through every point: nothing parts, or Parts::one_tube
    joined,        // the trunk and its branches meshed apart and joined into one surface
    kept_apart,    // with Parts::apart: meshed apart, kept though not all joined
    undone,        // meshed apart, but a side could not be joined, a part was refused,
                   // points belong to no part, or the joined surface was no smaller than
                   // the one tube's: meshed as one tube instead
};

// One part meshed apart (PartCounts::info).
struct PartInfo {
    uint32_t label;          // its points' branch label: kInTrunk, kFirstAboveBranch + k,
                             // kFirstBelowBranch + k
    Status status;           // its reconstruction's status (not ok: its points unused)
    size_t point_count;
    size_t layer_count;
    size_t triangle_count;
    size_t fold_count;
    size_t merged_end_layer_count;  // the trunk's layers merged into a closed end under its
                                    // branches (see reconstruct())
};

// Report::parts.
struct PartCounts {
    PartsOutcome outcome;
    Parting parting;         // where the cloud parts along Report::axis (all zero with
                             // Parts::one_tube)
    size_t part_count;       // parts meshed apart: the trunk and its branches (0: one tube)
    size_t joined_side_count;     // sides whose branches were joined (see join_branches())
    size_t apart_side_count;      // sides left apart
    size_t grafted_branch_count;  // branches grafted onto the trunk's closed end
    size_t junction_triangle_count;  // triangles the junctions added
    size_t removed_triangle_count;   // trunk triangles the grafts took out
    // Optional per-part details: the caller points `info` at an array of `info_capacity`
    // entries; the first min(part_count, info_capacity) are filled, the trunk first.
    PartInfo* info;
    size_t info_capacity;
};

// Report::points. in_count = used_count + duplicate_count + rejected_count + unused_count,
// on every status.
struct PointCounts {
    size_t in_count;         // points given (the stream: pushed so far)
    size_t used_count;       // vertices of the output
    size_t duplicate_count;  // same coordinates as a lower-indexed point: merged into it
    size_t rejected_count;   // NaN/Inf (with skip_invalid_points), and outliers
    size_t outlier_count;    // of rejected_count: left out by the drop_outliers flag
    size_t unused_count;     // valid but not a vertex (Report::detail says why); repeats of
                             // a point that is itself unused count here, not as duplicates
    size_t first_invalid_index;  // on Status::invalid_point: the first NaN/Inf point
    size_t held_count;       // the stream only: the most points it held at once (compare
                             // with the max_points_held given to stream_workspace_size())
};

// Report::layers.
struct LayerCounts {
    size_t planned_count;    // layers planned (cuts + 1, layer_count, or the automatic plan),
                             // before too small, thin, open or folding ones are merged
    size_t used_count;       // layers of the output
    size_t parallel_count;   // planned layers that Options::run_jobs' jobs triangulated
                             // ahead (0 without a runner, or when the workspace was too
                             // small for the jobs); merges may redo some, so it can exceed
                             // used_count
    // Optional per-layer details: the caller points `info` at an array of `info_capacity`
    // entries; the first min(used_count, info_capacity) are filled.
    LayerInfo* info;
    size_t info_capacity;
    // 0 where the layers are stacked along Report::axis. Otherwise the object bends and
    // the layers are cross-sections of its skeleton, a polyline of this many nodes through
    // the centres of its rings (see reconstruct()): Report::axis is the skeleton's direction
    // at its start, Report::axis_origin the start, LayerInfo::bottom and top are arc lengths
    // along it from there, and LayerInfo::centre lies on it.
    size_t skeleton_node_count;
};

// Report::caps, with add_caps (and from cap_ends()); all 0 without it.
struct CapCounts {
    size_t closed_count;     // boundary loops closed by a cap
    size_t open_count;       // loops left open: their projection across the axis is not a
                             // simple polygon, or every cap found would repeat an edge
    size_t triangle_count;   // the caps' triangles: the last ones of the output, included
                             // in Report::triangle_count
    size_t wall_flip_count;  // the surface's edges flipped under fins so that a loop could
                             // be capped, each changing two triangles in place (see
                             // add_caps); 0 in STRATMESH_SMALL_CODE
};

// The fit of a surface to its cloud (Diagnostics). A sampled triangle misfits where its
// normal parts from the cloud's own near its centroid (the direction in which the
// kFitNeighbours nearest points spread least) by more than kMisfitDegrees, as where a layer
// folds across the surface, or where its centroid lies farther than kMisfitSpacings point
// spacings from every point, as where a web spans a gap between limbs.
constexpr double kMisfitDegrees = 45.0;
constexpr double kMisfitSpacings = 2.0;
constexpr uint32_t kFitNeighbours = 12;
// At most kMisfitSampleLimit triangles are sampled for misfit (every k-th); a surface of
// at most kCrossingCheckLimit triangles is checked whole for crossing pairs, a larger one
// not (crossing_check_complete false), as the check's cost grows faster than the cloud.
constexpr size_t kMisfitSampleLimit = 4096;
constexpr size_t kCrossingCheckLimit = 16384;
// A surface with a crossing pair, or whose misfit share exceeds this, is poor: the
// threshold that parts single columns from folded and webbed surfaces (the command line's
// verdict; docs/design.md, "The fit measure").
constexpr double kPoorMisfitFraction = 0.05;

// Report::diagnostics: what a user checks before trusting the mesh.
struct Diagnostics {
    size_t fold_count;             // output triangles whose normal faces the axis (with
                                   // surface_flips, as unrolled: before the flips)
    size_t illegal_removed_count;  // triangles removed by the manifold safety net
    size_t diagonal_swap_count;    // band diagonals swapped when stitching layers
    // The fit, measured by reconstruct() on ok from the cloud alone, in the same bytes on
    // every platform and runner; all zero from the stream (it never holds the whole
    // surface), cap_ends() and the reduced build (STRATMESH_SMALL_CODE).
    double point_spacing;          // nine points in ten have their nearest neighbour within
                                   // it (cloud units)
    double area_per_point;         // the walls' area (caps left out; from the sample) over
                                   // the vertices, in squared point spacings: near 1 where
                                   // the surface follows the cloud, larger over gaps
    size_t fit_sample_count;       // wall triangles measured (caps span their loops by design)
    double misfit_area_fraction;   // the misfit samples' share of the samples' area
    double misfit_area;            // the misfit area it implies, in cloud units squared
    double misfit_box_min[3];      // the box of the misfit samples' corners (zeros without)
    double misfit_box_max[3];
    size_t crossing_pair_count;    // triangle pairs that share no corner and cross, caps
                                   // included
    bool crossing_check_complete;  // every pair was checked
    double crossing_box_min[3];    // the box of the crossing triangles (zeros without)
    double crossing_box_max[3];
};

struct Report {
    size_t triangle_count;
    double axis[3];          // unit axis used
    double axis_origin[3];   // a point on it
    PointCounts points;
    LayerCounts layers;
    CapCounts caps;
    PartCounts parts;
    Diagnostics diagnostics;
    const char* detail;      // a static sentence on why, when something failed or was dropped
    // The workspace bytes this call used at its peak, counted from the start of the
    // buffer: a buffer of exactly this size at the same address suffices for the same
    // input, one byte less does not. Compare with reconstruct_workspace_size().
    size_t workspace_used_bytes;
};

// A size in bytes that is always enough workspace for reconstruct() of point_count
// points with these options. It assumes the worst layout (every point in one layer);
// Report::workspace_used_bytes tells what a run really needed, which follows its largest
// layer, or the measure of webs at the end. With Options::run_jobs it also covers the layers
// triangulated ahead and the jobs' scratch. 0 if no workspace can serve that many points
// (as for delaunay_2d_workspace_size).
size_t reconstruct_workspace_size(size_t point_count, const Options& options);

// The most triangles reconstruct() can produce for point_count points: 2 * point_count
// (a manifold surface through n vertices has at most 2n triangles), plus four per branch
// on either side of a cut (8 * kMaxBranches) for the junctions where the options search
// for branches; 0 if that does not fit in size_t.
size_t reconstruct_max_triangles(size_t point_count, const Options& options);

// Reconstructs a triangle mesh through the points of a columnar cloud: one surface,
// edge- and vertex-manifold, consistently oriented, an open tube (two boundary loops) on
// columnar input, closed by caps with the add_caps flag, with every valid distinct
// point a vertex unless the report says why not. Where the cloud's end is closed (points
// across it: a dome, a flat base), the surface goes across it too, and that end's loop is
// a small one around the axis (see ClosedEnd).
//
// It meshes one tube (layer by layer, each unrolled and triangulated, stitched to the layer
// below and passed through the manifold safety net), or, unless Parts::one_tube, the trunk
// and the branches where the cloud parts (each around its own automatic axis; the trunk
// along the cloud's axis where the options lay out the layers) joined into one surface:
// see Parts, PartCounts, find_parting() and join_branches(). With Parts::automatic the
// joined parts are kept only where every part was meshed, every side joined, every point
// is in a part and their surface is smaller than the one tube's: a tube that wraps
// branches bridges the gaps between them with webs, and a join that folds adds area too.
// Report::parts.parting.axis is the axis of the cut kept, which is squared to the trunk's
// own axis where the two differ. The caps (add_caps) come last.
//
// Before any of that, where the options leave the axis, the origin and the layers to it and
// look for parts (the defaults), an object that bends without branching (an elbow, a U
// bend, a coil, a bowed bone) is meshed as one tube across its skeleton: one ring around
// the object at every distance along its surface from one end, the rings' centres a curve
// at least 8 ring radii long that strays 2 radii or more from a straight line and turns
// nowhere tighter than 1.5 radii. Each point is then placed across and along that curve and
// the layers are its cross-sections; LayerCounts::skeleton_node_count says so. A branching
// or looped object (two rings at one distance) goes on as above; a straight one with one
// ring at every distance is one tube along the automatic axis, without the search for
// parts (Report::parts then finds none).
//
// cloud           the points (see Cloud), at most 2^32 - 3. They are only read.
// options         see Options; `Options options = {};` gives the defaults.
// workspace       at least reconstruct_workspace_size(cloud.count, options) bytes; any
//                 alignment.
// triangles       receives 3 * (*triangle_count) indices into the cloud, each triangle
//                 counter-clockwise seen from outside (normals point away from the axis).
//                 Triangles come layer by layer, bottom to top: each layer's own triangles,
//                 then the band joining it to the layer below; then the caps (add_caps),
//                 one loop after another. The order is deterministic.
// triangle_capacity  triangles that fit in `triangles`; reconstruct_max_triangles() always
//                 suffices. When too small: Status::triangle_capacity and *triangle_count
//                 says how many are needed (with add_caps, counting every loop as closed;
//                 the array's contents are then unspecified; nothing is written past the
//                 capacity).
// triangle_count  required; receives the number of triangles (0 on failure).
// report          optional; see Report. Filled on every status, counts adding up (except
//                 when buffers overlap: see invalid_argument below).
//
// Returns ok; invalid_argument (a null pointer with a non-zero count, a stride smaller than
// one point, an unknown Scalar, cut_count without cuts, more than one of cuts, layer_count
// and layer_height, a flag bit Flags does not define, a Parts value outside the enum (these
// three with Report::detail saying which), a null triangle_count, or any two
// of the span of the cloud's points, the workspace, the triangle array, *triangle_count,
// *report and the report's layer array sharing a byte: then nothing at all is written, not
// even the report); invalid_origin (with origin_given, an origin that is NaN or infinite,
// or farther from the cloud's bounding box, along some coordinate, than 2^32 times the
// box's largest side: seen from there the cloud's shape keeps too few digits to unroll);
// too_many_points; invalid_point (Report::points.first_invalid_index, unless
// skip_invalid_points); invalid_axis (an unknown Axis, or Axis::direction zero, NaN or
// infinite); invalid_layers (a NaN or infinite cut, more than 2^32 - 2 cuts, a negative or
// non-finite layer_height);
// not_compiled (Axis::automatic, drop_outliers, surface_flips or ends_are_cuts in the reduced
// build);
// too_few_points (fewer than 3 valid points, or no surface spans them); degenerate (the
// surface would have no area: see the robustness contract; Report::detail says whether the
// points lie on a line or a few far points collapse the rest, which drop_outliers leaves
// out); separate_clusters (the points form clusters so far apart that each collapses to a
// point beside the others: mesh each on its own); flat_cloud (no extent along the axis);
// not_columnar (no layer's points surround its centre: try another axis);
// out_of_memory; triangle_capacity; internal_error.
Status reconstruct(const Cloud& cloud, const Options& options,
                   void* workspace, size_t workspace_bytes,
                   uint32_t* triangles, size_t triangle_capacity, size_t* triangle_count,
                   Report* report);

// ==== Streaming reconstruction =============================================================
//
// For clouds that arrive layer by layer (a CT slice, a turntable turn, a lidar ring) or do
// not fit in memory at once (a pipe, a tunnel, a tree stem): push the points of one layer
// at a time, bottom to top along the axis; triangles come out through a callback as soon
// as they are final. The stream holds only the layers it still needs: the top loop of the
// last finished layer, the layer being formed and the pushes after it, so its memory
// follows the largest layers, not the cloud.
//
//     stratmesh::Options options = {};
//     options.axis = stratmesh::Axis::z;                   // required: not automatic
//     std::vector<unsigned char> work(stratmesh::stream_workspace_size(3 * max_layer, options));
//     stratmesh::Stream* stream = nullptr;
//     stratmesh::stream_open(options, work.data(), work.size(), on_triangles, &mesh, &report,
//                            &stream);
//     for (each layer) stratmesh::stream_push(stream, layer_cloud, layer_top);
//     stratmesh::stream_close(stream);
//
// The stream meshes one tube (it cannot know where a cloud parts before it has seen it):
// the same triangles as reconstruct() with Parts::one_tube. A push is one planned
// layer, as between two cuts, and
// the stream forms layers from pushes by the rules reconstruct() applies to its planned
// layers (a push too small, too thin, not surrounding its axis or next to a crescent joins
// the next; a last rest too small or thin joins the layer below it), waiting for later
// pushes where a rule needs them. So reconstruct() of the concatenated pushes, with
// Options::cuts at the tops of all pushes but the last, the same axis, the same origin
// (flag origin_given), Parts::one_tube and the points of each push in the same order,
// gives the same triangles in the same order, with the same global indices,
// provided no point lies within kCutTolerance of the height range below a cut (reconstruct()
// counts such a point in the layer above) and no cut lies outside the points' height
// range. The stream makes no caps (the add_caps flag is refused): cap_ends() closes its
// surface afterwards (below).
//
// Memory: stream_workspace_size(max_points_held) bytes. The stream holds the last layer's
// top loop, the layer being formed (pushes that join it included) and the pushes after it
// until they can form a layer. A layer that folds waits for the two pushes after it (it
// may join them), so when every push holds at least kMinLayerPoints points and
// kMinLayerRows rows of points and none is a crescent, three times the largest push
// suffices where no layer folds, and more where layers fold.
// A push that would hold more returns out_of_memory and changes nothing; Report::points.held_count
// says what a run needed.

struct Stream;  // lives in the caller's workspace

// Receives final triangles: 3 * count global indices (the position of the point among all
// points pushed so far, invalid ones included), counter-clockwise seen from outside. The
// array is only valid during the call. Must not call back into the stream it came from
// (it is mid-push); any other stream, or reconstruct() with another workspace, is fine.
typedef void (*TriangleCallback)(void* user, const uint32_t* triangles, size_t count);

// Bytes for a stream that holds at most max_points_held points at once; 0 if that is
// beyond what this platform can address.
size_t stream_workspace_size(size_t max_points_held, const Options& options);

// Opens a stream in the workspace. options: axis (x, y, z or direction; automatic needs
// the whole cloud and is refused with invalid_axis), flags skip_invalid_points and
// origin_given; the layer options and the progress callback are not used (the pushes are
// the layers). emit receives the triangles; report (optional) is updated after every push
// and at close, and must stay valid until then (its layer array too). On success *stream
// is the handle, valid until stream_close or until the workspace is reused.
// Returns ok, invalid_argument (a null emit or stream, a null workspace, a workspace that
// shares a byte with the report or its layer array; or, with Report::detail saying which
// and nothing else written to the report: add_caps or drop_outliers, a flag bit Flags does
// not define, a Parts value outside the enum, more than one of cuts, layer_count and
// layer_height),
// invalid_origin (a NaN or infinite origin), invalid_axis, out_of_memory (a workspace too
// small to hold kMinLayerPoints points).
// The stream uses as many points as the workspace holds.
Status stream_open(const Options& options, void* workspace, size_t workspace_bytes,
                   TriangleCallback emit, void* emit_user, Report* report, Stream** stream);

// Pushes the next layer: its points (any stride and scalar, as for reconstruct) and its top,
// the height (dot(point, axis)) where the next layer begins. Every point must lie between
// the previous push's top and this one's (up to 2^-40 of their size; the first push has no
// lower limit; a push without valid points has a top all the same), and top must not be
// below the previous top; the top of the last push only bounds its points (the last layer
// ends at its highest point). May call emit.
// Returns ok; invalid_argument (null stream, points in the workspace, a null pointer with a
// non-zero count, a bad stride or scalar); invalid_point (NaN/Inf without
// skip_invalid_points, or a point more than 2^60 times the first layer's size away);
// invalid_layers (a NaN or infinite top); invalid_origin (the first push with valid points
// lies farther from the given origin than reconstruct() accepts: see there);
// out_of_order; too_many_points (2^32 - 3 points in
// all); out_of_memory (more than the workspace can hold: the push is refused and the stream
// unchanged); and, from triangulating, the errors of reconstruct(), after which the stream
// only returns that status. A refused push changes nothing but Report::detail, which says
// why.
Status stream_push(Stream* stream, const Cloud& points, double top);

// Forms and emits the last layers and completes the report. Returns ok or the status of
// reconstruct() for the same cloud (too_few_points, flat_cloud, not_columnar, ...). The
// stream cannot be pushed to afterwards.
Status stream_close(Stream* stream);

// ---- Caps for a surface you hold ----
//
// cap_ends() closes the boundary loops of a surface the caller holds with caps, as the
// add_caps flag does inside reconstruct(): made for the stream, whose triangles leave
// through the callback before its last loop is known. Collect them, close the stream, then
//
//     size_t count = tris.size() / 3;  // the triangles collected from the callback
//     std::vector<unsigned char> work(stratmesh::cap_ends_workspace_size(n, count));
//     tris.resize(3 * stratmesh::reconstruct_max_triangles(n, options));  // 2n suffice
//     stratmesh::cap_ends(all_points, options, work.data(), work.size(), tris.data(),
//                         tris.size() / 3, &count, &report);
//
// With the stream's triangles, the same Options and `cloud` the concatenated pushes (every
// point pushed, in order: the triangles' global indices), the result is reconstruct()'s
// with add_caps for the same cuts, triangle for triangle, wherever the stream gives
// reconstruct()'s triangles (origin_given; see the stream above): the caps come last.
// The frame is chosen from the whole cloud as reconstruct() chooses it, so the caps do not
// depend on how the cloud was pushed. Any other surface works too: each boundary loop is
// projected across the axis and capped if that projection is a simple polygon (see
// add_caps). The result is edge- and vertex-manifold and consistently oriented if the
// input was (as stratmesh's output is); on any other input the call stays within its
// buffers but the caps may join edges that were already full.

#if !defined(STRATMESH_SMALL_CODE)
// Bytes of workspace cap_ends() needs for a surface of triangle_count triangles over
// point_count points; 0 if that is beyond what this platform can address.
size_t cap_ends_workspace_size(size_t point_count, size_t triangle_count);

// Appends caps to triangles[0 .. 3 * *triangle_count) (global indices into `cloud`) and
// sets *triangle_count to the new total. Where a loop can be capped only so, the edge under
// a fin of the surface is flipped (see add_caps): two of the given triangles then
// change, in place. options: axis, direction, origin (with
// origin_given) and skip_invalid_points as given to the stream or reconstruct(); the rest
// is not used. report (optional): only Report::caps, workspace_used_bytes (this call's)
// and detail are set, the rest left as it is: the stream's report can be passed, its
// counts kept (its workspace_used_bytes replaced).
// Returns ok (loops that cannot be capped stay open: Report::caps.open_count);
// invalid_argument (a null triangle_count, triangles or workspace where needed, a bad
// stride or scalar, a flag bit Flags does not define, a Parts value outside the enum,
// *triangle_count above triangle_capacity, an index outside the cloud or
// naming an invalid point, buffers sharing a byte); too_many_points; invalid_point (a NaN
// or infinite point without skip_invalid_points); invalid_axis; invalid_origin (as for
// reconstruct()); out_of_memory (a workspace below cap_ends_workspace_size());
// triangle_capacity (*triangle_count set to the
// triangles needed; nothing written). On every status but ok the triangles are unchanged.
Status cap_ends(const Cloud& cloud, const Options& options, void* workspace,
                size_t workspace_bytes, uint32_t* triangles, size_t triangle_capacity,
                size_t* triangle_count, Report* report);
#endif

#if !defined(STRATMESH_SMALL_CODE)

// ---- Where the cloud parts into branches ----
//
// One tube cannot follow an object that forks (the horns on a head, the fingers of a hand):
// it wraps the branches and the gaps between them. find_parting() finds where along the
// axis the cloud parts: the lowest cut above which the points make two separate branches
// or more, and the highest below which they do. Points join one piece when they lie within
// Parting::gap of each other (single linkage, the gap scaled to the cloud's spacing). A
// piece is a branch when it holds at least kSmallestBranch points and 1 / kMaxBranches of
// its side's, starts at the cut and goes on beyond it (a bump, a rim or a crown between
// horns is none). reconstruct() uses it by default; a caller can also mesh each side on its
// own, the branches with ends_are_cuts, and join them with join_branches(). docs/design.md
// gives the rule in full.

// Bytes of workspace that always suffice for find_parting() of point_count points; 0 if
// that is beyond what this platform can address.
size_t find_parting_workspace_size(size_t point_count, const Options& options);


// Finds where the cloud parts into branches (see above). options: axis, direction, and
// the flags skip_invalid_points and drop_outliers (outliers are left out first); the rest
// is only checked. The same axis as reconstruct() with these options. Deterministic; another
// order of the points changes only rounding (the frame's origin is their centroid) and
// which points sample the scale. Returns ok (parting filled, whether or not
// a cut was found); invalid_argument (a null parting, or workspace with points; a bad
// stride or scalar; a flag bit Flags does not define, a Parts value outside the enum;
// buffers sharing a byte); too_many_points; invalid_point (a NaN or
// infinite point without skip_invalid_points); invalid_axis; too_few_points (fewer than 3
// distinct valid points); flat_cloud (every point at the same height); out_of_memory (a
// workspace below find_parting_workspace_size()). On a status other than ok only
// workspace_used_bytes and detail are meaningful.
// branch_of (optional, cloud.count bytes): on ok, each point's label (see kInTrunk), so
// that the caller can mesh the trunk and each branch apart. Where the two sides overlap
// (the cloud is apart all along, as two tubes side by side), a point keeps the label of the
// side above. It must not share a byte with the other buffers (invalid_argument).
Status find_parting(const Cloud& cloud, const Options& options, void* workspace,
                    size_t workspace_bytes, Parting* parting, uint8_t* branch_of);

// ---- Joining the branches to the trunk ----
//
// join_branches() joins a trunk and its branches, meshed apart (each label of
// find_parting's branch_of its own reconstruct(), as reconstruct() does by default), into
// one surface, at each side that parts: where the trunk's boundary loop nearest the
// branches goes around them, that loop is split at the gaps between the branches and each
// arc is zipped to its branch's loop nearest the cut, the crotch closed by a triangle per
// gap; where it does not (branches standing on a closed end, as horns on a skull), each
// branch is grafted onto a hole taken out of the trunk's triangles under its loop, a small
// gap of the trunk's end in the way (at most kMostGapCorners corners) closed first. The new
// triangles run each loop's edges against the surface's direction and every vertex keeps
// one fan, so a surface that is an oriented edge- and vertex-manifold (as reconstruct()'s)
// stays one, and every point stays a vertex; a graft's band can cross the trunk's
// triangles beside the stump where the stump's wall leans over the hole. A side whose
// geometry allows neither (the trunk's loop far from the cut, fewer than two branch loops
// there, a branch outside the trunk's loop, gaps out of order along it, a cut that is not
// square to the fork) stays apart, counted in JoinReport::apart_side_count with the reason
// in detail. docs/design.md describes the zip and the graft.

// The most corners of a gap in the trunk's end that a graft closes, and so the most
// triangles those closings add in all (two sides of kMaxBranches branches).
const uint32_t kMostGapCorners = 32;
const size_t kMostGapTriangles = 2 * size_t{kMaxBranches} * (kMostGapCorners - 2);

// What join_branches() did, as Report::parts counts it for reconstruct().
struct JoinReport {
    size_t joined_side_count;        // 0, 1 or 2
    size_t apart_side_count;         // sides that part but could not be joined (detail)
    size_t grafted_branch_count;     // branches joined through a hole in the trunk's end
    size_t junction_triangle_count;  // triangles the junctions added
    size_t removed_triangle_count;   // the trunk's triangles the holes took out
    size_t workspace_used_bytes;     // peak workspace bytes, from the start of the buffer
    const char* detail;              // a static sentence on why, on failure or a side apart
};

// Bytes of workspace that always suffice for join_branches() on a surface of
// triangle_count triangles over point_count points; 0 if that is beyond what this platform
// can address.
size_t join_branches_workspace_size(size_t point_count, size_t triangle_count);

// The most triangles join_branches() adds: point_count + 4 * kMaxBranches +
// kMostGapTriangles (one per vertex of a loop it zips, each point on one loop at most; four
// per branch for the crotches; the gaps the grafts close).
size_t join_branches_max_triangles(size_t point_count);

// Takes the grafts' holes out of triangles[0 .. 3 * *triangle_count) (indices into
// `cloud`; the triangles kept stay in their order, removed_triangle_count fewer), appends
// the junctions' triangles and sets *triangle_count to the new total. parting and
// branch_of: find_parting()'s on the same cloud (its axis is used); options:
// skip_invalid_points is used, the rest only checked (a flag bit Flags does not define, or
// a Parts value outside the enum, is invalid_argument). report (optional) is filled on
// every status. Returns ok (a side counts as joined when all its branches are; the others
// in apart_side_count, their branches grafted where they could be, the rest of their
// triangles left as they were); invalid_argument (a null triangle_count, branch_of,
// workspace or triangles where needed; a bad stride or scalar; *triangle_count above
// triangle_capacity; an index outside the cloud or naming an invalid point; buffers
// sharing a byte); too_many_points; invalid_point (a NaN or infinite point without
// skip_invalid_points); invalid_axis (a parting whose axis is zero or not finite);
// out_of_memory (a workspace below join_branches_workspace_size()); triangle_capacity
// (*triangle_count set to the triangles needed; nothing written). On every status but ok
// the triangles are unchanged. On a surface that is not a vertex-manifold the call stays
// within its buffers, but the junctions may join edges that were already full.
Status join_branches(const Cloud& cloud, const Options& options, const Parting& parting,
                     const uint8_t* branch_of, void* workspace, size_t workspace_bytes,
                     uint32_t* triangles, size_t triangle_capacity, size_t* triangle_count,
                     JoinReport* report);
#endif

} // namespace stratmesh

#endif // __cplusplus

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
#endif // STRATMESH_H

// ===========================================================================================
// ==== Implementation =======================================================================
// ===========================================================================================
//
// Sections in the order the data flows; search for ">>name" to jump to one. Each is a file
// of src/ in the repository, from which tools/amalgamate.py writes this header.
//
//   >>config              build switches: what STRATMESH_SMALL_CODE leaves out; the
//                         floating-point environment
//   >>arena               the bump allocator over the caller's workspace
//   >>predicates          orient2d and incircle: filter, integer and expansion stages
//   >>spatial sort        the insertion order of the Delaunay triangulation
//   >>delaunay            the incremental 2D Delaunay triangulation (delaunay_2d)
//   >>points              the cloud's points as the library reads them, and the vector
//                         arithmetic on them
//   >>outliers            points far from the rest of the cloud, left out with
//                         drop_outliers
//   >>cloud               reading the cloud: invalid points refused or counted, outliers
//                         left out, sums
//   >>jobs                the caller's callbacks: progress, and batches of jobs for the
//                         runner
//   >>request             what one tube is asked for: axis, layers, ends, caps, origin,
//                         read once from Options
//   >>frame               the frame the layers are cut in: its axis, origin and scale
//   >>layer plan          cuts along the axis: explicit, equal, by height or automatic;
//                         points grouped by layer
//   >>unroll              a layer onto its annulus (cylinder and closed ends)
//   >>layer               one layer on its annulus: its loops and their peeling, closed
//                         ends, the centre search
//   >>stitch              the band between two layers' loops
//   >>manifold            the safety net that keeps the surface a manifold
//   >>chain               the surface as a chain of chunks: a group of layers with its
//                         band, sealed to the one below
//   >>flips               flips on the surface: within a layer, and across the seam
//                         between layers
//   >>layer triangulation one layer triangulated on its annulus, its loops peeled and its
//                         edges flipped
//   >>surface loops       the boundary loops of a surface, traced from its triangles
//   >>polygon             simple polygons on the exact predicates: crossing edges,
//                         winding, ear clipping
//   >>caps                closing a boundary loop: pockets, lowered caps, fins
//   >>fit                 how well the finished surface fits its cloud (Diagnostics):
//                         misfit area and crossings
//   >>group               a group of layers: triangulated, stitched to the loop below,
//                         flipped and sealed
//   >>parallel layers     layers triangulated ahead as jobs on the caller's runner
//   >>tube                one tube: its layers triangulated, stitched and sealed group by
//                         group, then capped
//   >>stream              the same surface, layer by layer, in bounded memory
//   >>axis                the automatic axis
//   >>no area             why a surface through the points would have no area: a line, far
//                         points, far clusters
//   >>cap ends            cap_ends() for a surface the caller holds
//   >>parting             find_parting(): where the cloud parts into branches
//   >>join branches       join_branches(): zips and grafts
//   >>parts               reconstruct()'s default: trunk and branches, meshed and joined
//   >>skeleton            objects that bend: layers across a skeleton of geodesic rings,
//                         not one straight axis
//   >>reconstruct         reconstruct() in its steps: validate, a bent skeleton, axis,
//                         parts or one tube
//   >>c interface         the C functions over the C++ ones
//   >>config restore      undoes what >>config set: its helper macros and the pinned
//                         contraction

#if defined(STRATMESH_IMPLEMENTATION) && !defined(__cplusplus)
#error "the stratmesh implementation is C++17: compile stratmesh.cpp with a C++ compiler and link it; C files include stratmesh.h without STRATMESH_IMPLEMENTATION"
#elif defined(STRATMESH_IMPLEMENTATION) && !defined(STRATMESH_IMPLEMENTATION_DONE)
#define STRATMESH_IMPLEMENTATION_DONE

// >>config ==================================================================================
// Build switches: what STRATMESH_SMALL_CODE leaves out; the floating-point environment.

#include <cfloat>
#include <climits>
#include <cmath>
#include <cstring>

#ifndef STRATMESH_ASSERT
#define STRATMESH_ASSERT(cond) ((void)0)
#endif

static_assert(sizeof(double) == 8 && DBL_MANT_DIG == 53 && FLT_RADIX == 2,
              "stratmesh needs IEEE-754 binary64 doubles");
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0
#error "stratmesh needs FLT_EVAL_METHOD == 0 (x87 extended precision breaks the predicates; use SSE2)"
#endif

// The error-free transformations below are only exact if every product is rounded on its
// own. A fused multiply-add contracted from a*b - c changes the rounding and silently
// breaks them, so contraction is switched off for the whole implementation, whatever
// flags the user compiles with (GCC contracts by default outside strict ISO mode, clang
// within expressions).
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")
#elif defined(_MSC_VER)
#pragma fp_contract(off)
#endif

namespace stratmesh {

const char* status_string(Status status) {
    switch (status) {
#define STRATMESH_STATUS_CASE(name, message) \
    case Status::name: return #name ": " message;
        STRATMESH_STATUS_LIST(STRATMESH_STATUS_CASE)
#undef STRATMESH_STATUS_CASE
    }
    return "unknown status";
}

namespace detail {

static const uint32_t kNoIndex = 0xFFFFFFFFu;

#if defined(STRATMESH_SMALL_CODE) && !defined(STRATMESH_NO_PARALLEL_LAYERS)
#define STRATMESH_NO_PARALLEL_LAYERS
#endif
#if defined(STRATMESH_NO_PARALLEL_LAYERS)
const bool kParallelLayers = false;
#else
const bool kParallelLayers = true;  // lets the compiler drop what only jobs' results reach
#endif
#if defined(STRATMESH_SMALL_CODE)
const bool kNetShortcut = false;
const bool kStagePoints = false;
const bool kFastExactStages = false;
const bool kLiftedCaps = false;
const bool kCrescentLayers = false;
const bool kClosedEnds = false;
const uint32_t kCapEarStarts = 1;
const uint32_t kCapSearchCorners = 0;
const bool kCapFinFlips = false;
const bool kDropOutliers = false;
const bool kSurfaceFlips = false;
const bool kFindParts = false;
const bool kAxisTrials = false;
const bool kDegenerateCheck = false;
const bool kLocalUnpeel = false;
const bool kPeelFoldedEnds = false;
const bool kFoldMerge = false;
const uint32_t kFoldMergeReach = 0;
const bool kFastLoops = false;
const bool kMeasureFit = false;
#else
const bool kNetShortcut = true;  // a chunk whose loop fans are whole skips the net
const bool kStagePoints = true;  // reconstruct() keeps the grouped points in spare workspace
// The predicates settle near-ties in integers, then from exact differences, before the
// general exact stage.
const bool kFastExactStages = true;
// Caps are lowered (bottom) and raised (top) along the axis before the Delaunay criterion
// settles their diagonals (see >>caps); without it, Delaunay caps only.
const bool kLiftedCaps = true;
// A crescent layer (the slanted end of a tube) joins its neighbour (see kRingGap).
const bool kCrescentLayers = true;
// A closed end of the surface is unrolled around a pole (see "closed ends" in >>unroll).
const bool kClosedEnds = true;
// A cap whose ear clipping gets stuck is clipped again from other corners (see >>caps).
const uint32_t kCapEarStarts = 8;
// A loop of at most this many corners that no clipping closes is searched exhaustively for
// a cap (see >>caps; its table takes a byte per pair of corners: 32 KiB).
const uint32_t kCapSearchCorners = 256;
// A loop that no cap closes as the wall stands may have the wall's edges under its fins
// flipped, where its cap needs their chords (see >>caps).
const bool kCapFinFlips = true;
// The drop_outliers flag (see "outliers" in >>layers); without it, the flag is refused.
const bool kDropOutliers = true;
// Layers are flipped on the surface (see "flips on the surface" in >>layer triangulation).
const bool kSurfaceFlips = true;
const bool kFindParts = true;
const bool kAxisTrials = true;
const bool kDegenerateCheck = true;
// A band that folds between peeled loops gets back only the peeled triangles around its
// folds (see add_group); without it, all of them.
const bool kLocalUnpeel = true;
// The surface's end loops are peeled in layers that fold too (see "peeling" in >>layer
// triangulation).
const bool kPeelFoldedEnds = true;
// A layer that folds is tried again with the next one joined (see "folding layers" at
// add_group).
const bool kFoldMerge = true;
// The most planned layers joined to a folding one (see kFoldMerge).
const uint32_t kFoldMergeReach = 2;
// Per-point loops in forms that cost code for speed, the same bits either way: the equal-
// layer guess in layer_of, pseudo_angle without branches, floor by truncation in
// exp_portable, the height range from choose_frame's extremes, count_folds' prefetching.
const bool kFastLoops = true;
// reconstruct() measures the fit of its output to the cloud (Diagnostics; see >>fit).
const bool kMeasureFit = true;
#endif
static const size_t kMaxPoints = 0xFFFFFFFEu;

// Kept out of line: STRATMESH_NOINLINE always, the predicates' exact stages, so that the
// filtered call, which settles nearly all, keeps its registers (inlined, the exact stage
// made it spill: 125 instructions a filtered incircle instead of about 70);
// STRATMESH_FAST_NOINLINE in the full build, for the same reason (the small build inlines
// it into its one caller, where a call costs more code); STRATMESH_SMALL_NOINLINE in the
// small build: inlined at each caller, these few functions grow the Cortex-M7 code past
// its 32 KiB (examples/firmware/build.sh).
#if defined(__GNUC__) || defined(__clang__)
#define STRATMESH_NOINLINE __attribute__((noinline))
#elif defined(_MSC_VER)
#define STRATMESH_NOINLINE __declspec(noinline)
#else
#define STRATMESH_NOINLINE
#endif
#if defined(STRATMESH_SMALL_CODE)
#define STRATMESH_SMALL_NOINLINE STRATMESH_NOINLINE
#if defined(__GNUC__) || defined(__clang__)
#define STRATMESH_FAST_NOINLINE __attribute__((always_inline))
#else
#define STRATMESH_FAST_NOINLINE
#endif
#else
#define STRATMESH_SMALL_NOINLINE
#define STRATMESH_FAST_NOINLINE STRATMESH_NOINLINE
#endif

#if defined(__GNUC__) || defined(__clang__)
static inline double abs_value(double x) { return __builtin_fabs(x); }
#else
static inline double abs_value(double x) { return x < 0 ? -x : x; }
#endif
static inline bool is_finite(double x) { return x - x == 0; }

// Sorts in place so that no element comes before one it is `before`: heapsort, O(n log n)
// on any input (a million cuts, a huge fan) with no recursion and no memory.
template <class T, class Before> void sift_down(T* v, size_t root, size_t count, Before before) {
    for (;;) {
        size_t child = 2 * root + 1;
        if (child >= count) return;
        if (child + 1 < count && before(v[child], v[child + 1])) ++child;
        if (!before(v[root], v[child])) return;
        T t = v[root];
        v[root] = v[child];
        v[child] = t;
        root = child;
    }
}

// A union-find's root of i, halving the path on the way (no recursion); parent[i] == i at
// a root.
static inline uint32_t find_root(uint32_t* parent, uint32_t i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

template <class T, class Before> void heap_sort(T* v, size_t count, Before before) {
    for (size_t i = count / 2; i-- > 0;) sift_down(v, i, count, before);
    for (size_t end = count; end-- > 1;) {
        T t = v[0];
        v[0] = v[end];
        v[end] = t;
        sift_down(v, 0, end, before);
    }
}

// Sorts ascending.
template <class T> void heap_sort(T* v, size_t count) {
    heap_sort(v, count, [](const T& a, const T& b) { return a < b; });
}

static inline double read_double(const unsigned char* p) {
    double v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

}  // namespace detail
}  // namespace stratmesh

// >>arena ================================================================================
// The bump allocator over the caller's workspace.
//
// A bump allocator over the caller's buffer. A "measuring" arena (null base) only adds up
// sizes, so *_workspace_size() runs the very allocation sequence the real call runs and
// the two cannot disagree.

namespace stratmesh {
namespace detail {

struct Arena {
    static const size_t kAlign = 16;

    unsigned char* base;
    size_t capacity;
    size_t used;
    size_t high_water;
    bool failed;
    size_t pad;  // bytes skipped at the start of the caller's buffer to align `base`

    static Arena over(void* buffer, size_t bytes) {
        Arena a = {nullptr, 0, 0, 0, false, 0};
        if (!buffer) return a;
        uintptr_t start = reinterpret_cast<uintptr_t>(buffer);
        a.pad = (kAlign - start % kAlign) % kAlign;
        if (bytes < a.pad) {
            a.base = static_cast<unsigned char*>(buffer);
            return a;
        }
        a.base = static_cast<unsigned char*>(buffer) + a.pad;
        a.capacity = bytes - a.pad;
        return a;
    }
    static Arena measuring() { return Arena{nullptr, SIZE_MAX, 0, 0, false, 0}; }

    // The peak, counted from the start of the caller's buffer: a buffer of this size at
    // the same address would have been enough.
    size_t peak_from_buffer() const { return high_water ? pad + high_water : 0; }

    bool is_measuring() const { return base == nullptr && capacity == SIZE_MAX; }

    // The bytes to ask the caller for: what was used, plus the worst alignment padding.
    size_t required_bytes() const { return high_water + kAlign - 1; }

    template <class T> T* alloc(size_t count) { return static_cast<T*>(take(count, sizeof(T))); }

    // alloc's one body, whatever the type (one copy of the code, not one per type).
    void* take(size_t count, size_t size) {
        if (failed) return nullptr;
        if (count > (SIZE_MAX - kAlign) / size) {
            failed = true;
            return nullptr;
        }
        size_t bytes = (count * size + kAlign - 1) / kAlign * kAlign;
        if (bytes > capacity - used) {
            failed = true;
            return nullptr;
        }
        size_t offset = used;
        used += bytes;
        if (used > high_water) high_water = used;
        if (is_measuring()) return reinterpret_cast<void*>(kAlign);  // never dereferenced
        return base + offset;
    }

    size_t mark() const { return used; }
    void rewind(size_t m) { used = m; }

    // The last `bytes` of the buffer (aligned), if they lie above everything allocated so
    // far, for data that stays valid only while the arena does not reach it (see
    // untouched); null if there is no such room. Allocations may later take it.
    void* room_at_end(size_t bytes) const {
        if (is_measuring() || bytes > capacity - used) return nullptr;
        size_t offset = (capacity - bytes) / kAlign * kAlign;
        return offset >= used ? base + offset : nullptr;
    }
    // Whether the arena has never reached p (in room_at_end's room).
    bool untouched(const void* p) const {
        return static_cast<const unsigned char*>(p) >= base + high_water;
    }
};

// The caller's buffers as address ranges, so that arguments sharing memory are refused:
// the input is read while the workspace and outputs are written, and an overlap would
// corrupt the result silently. Empty buffers overlap nothing; lengths that would run past
// the end of the address space are cut there.
struct ByteRange {
    uintptr_t begin, end;
};

static inline size_t saturating_product(size_t a, size_t b) {
    return b != 0 && a > SIZE_MAX / b ? SIZE_MAX : a * b;
}

static inline ByteRange byte_range(const void* p, size_t bytes) {
    uintptr_t begin = reinterpret_cast<uintptr_t>(p);
    if (!p) return {0, 0};
    return {begin, bytes > UINTPTR_MAX - begin ? UINTPTR_MAX : begin + bytes};
}

// Bytes covered by `count` records `stride` apart whose last one is `record_bytes` long.
static inline ByteRange strided_range(const void* p, size_t count, size_t stride, size_t record_bytes) {
    if (count == 0) return {0, 0};
    size_t span = saturating_product(count - 1, stride);
    return byte_range(p, span > SIZE_MAX - record_bytes ? SIZE_MAX : span + record_bytes);
}

static inline bool ranges_overlap(ByteRange a, ByteRange b) {
    return a.begin < a.end && b.begin < b.end && a.begin < b.end && b.begin < a.end;
}

// True if any two of the `count` ranges overlap.
static inline bool any_overlap(const ByteRange* ranges, size_t count) {
    for (size_t i = 0; i < count; ++i)
        for (size_t j = i + 1; j < count; ++j)
            if (ranges_overlap(ranges[i], ranges[j])) return true;
    return false;
}

}  // namespace detail
}  // namespace stratmesh

// >>predicates ===========================================================================
// orient2d and incircle: filter, integer and expansion stages.
//
// This work is based on:
//   J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
//   Predicates", Discrete & Computational Geometry 18:305-363, 1997.
//   O. Devillers, M. Teillaud, "Perturbations for Delaunay and weighted Delaunay 3D
//   triangulations", Computational Geometry 44(3), 2011 (the symbolic perturbation).
//
// An expansion is an array of doubles, sorted by increasing magnitude, nonoverlapping,
// whose exact sum is the represented value; its sign is the sign of its last component.
// Error bounds use eps = 2^-53 (half an ulp of 1) and are derived in Shewchuk's paper:
// for a determinant evaluated in floating point, |computed - exact| <= bound * permanent,
// where the permanent is the same expression with absolute values everywhere.

namespace stratmesh {
namespace detail {

constexpr double kEps = DBL_EPSILON / 2;

constexpr double kSplitter = 134217729.0; // 2^27 + 1: splits a double into two 26-bit halves

constexpr double kOrientBoundA = (3.0 + 16.0 * kEps) * kEps;

constexpr double kIncircleBoundA = (10.0 + 96.0 * kEps) * kEps;

// a + b = x + y exactly, with x = fl(a + b).
static inline void two_sum(double a, double b, double& x, double& y) {
    x = a + b;
    double bv = x - a;
    double av = x - bv;
    y = (a - av) + (b - bv);
}

// a - b = x + y exactly, with x = fl(a - b).
static inline void two_diff(double a, double b, double& x, double& y) {
    x = a - b;
    double bv = a - x;
    double av = x + bv;
    y = (a - av) + (bv - b);
}

static inline void split(double a, double& hi, double& lo) {
    double c = kSplitter * a;
    double big = c - a;
    hi = c - big;
    lo = a - hi;
}

// a * b = x + y exactly, with x = fl(a * b) (Dekker's product, Veltkamp's split).
static inline void two_product(double a, double b, double& x, double& y) {
    x = a * b;
    double ahi, alo, bhi, blo;
    split(a, ahi, alo);
    split(b, bhi, blo);
    double err1 = x - ahi * bhi;
    double err2 = err1 - alo * bhi;
    double err3 = err2 - ahi * blo;
    y = alo * blo - err3;
}

// (a1 + a0) - (b1 + b0) as a four-component expansion out[0..3], least significant first.
static inline void two_two_diff(double a1, double a0, double b1, double b0, double* out) {
    double i, j, z;
    two_diff(a0, b0, i, out[0]);
    two_sum(a1, i, j, z);
    two_diff(z, b1, i, out[1]);
    two_sum(j, i, out[3], out[2]);
}

// ax*by - ay*bx as a four-component expansion.
static inline void cross_exact(double ax, double ay, double bx, double by, double* out) {
    double p1, p0, q1, q0;
    two_product(ax, by, p1, p0);
    two_product(ay, bx, q1, q0);
    two_two_diff(p1, p0, q1, q0, out);
}

// h = e + f; returns the length of h with zero components removed (at least 1). h needs
// room for elen + flen components and must not alias e or f.
static inline int expansion_sum(int elen, const double* e, int flen, const double* f, double* h) {
    int ei = 0, fi = 0, hi = 0;
    double q = 0, hh = 0;
    bool first = true;
    while (ei < elen || fi < flen) {
        double next;
        if (fi >= flen || (ei < elen && abs_value(e[ei]) < abs_value(f[fi]))) {
            next = e[ei++];
        } else {
            next = f[fi++];
        }
        if (first) {
            q = next;
            first = false;
            continue;
        }
        double s;
        two_sum(q, next, s, hh);
        q = s;
        if (hh != 0) h[hi++] = hh;
    }
    if (q != 0 || hi == 0) h[hi++] = q;
    return hi;
}

// Removes the zero components of e in place; returns the new length (at least 1).
static inline int compress_zeros(int len, double* e) {
    int kept = 0;
    for (int i = 0; i < len; ++i)
        if (e[i] != 0) e[kept++] = e[i];
    if (kept == 0) e[kept++] = 0;
    return kept;
}

// h = b * e; returns the length of h (at most 2 * elen) with zeros removed. h must not
// alias e.
static inline int expansion_scale(int elen, const double* e, double b, double* h) {
    if (b == 0 || (elen == 1 && e[0] == 0)) {
        h[0] = 0;
        return 1;
    }
    double q, hh;
    two_product(e[0], b, q, hh);
    int hi = 0;
    if (hh != 0) h[hi++] = hh;
    for (int i = 1; i < elen; ++i) {
        double p1, p0, sum;
        two_product(e[i], b, p1, p0);
        two_sum(q, p0, sum, hh);
        if (hh != 0) h[hi++] = hh;
        two_sum(p1, sum, q, hh);
        if (hh != 0) h[hi++] = hh;
    }
    if (q != 0 || hi == 0) h[hi++] = q;
    return hi;
}

// h = e * f; h and tmp each need room for 2 * elen * flen components, scaled for 2 * elen.
static inline int expansion_product(int elen, const double* e, int flen, const double* f, double* h,
                             double* tmp, double* scaled) {
    int len = expansion_scale(elen, e, f[0], h);
    for (int j = 1; j < flen; ++j) {
        int slen = expansion_scale(elen, e, f[j], scaled);
        len = expansion_sum(len, h, slen, scaled, tmp);
        std::memcpy(h, tmp, sizeof(double) * static_cast<size_t>(len));
    }
    return len;
}

static inline void expansion_negate(int len, double* e) {
    for (int i = 0; i < len; ++i) e[i] = -e[i];
}

// The most significant non-zero component (0 if the expansion is zero).
static inline double expansion_top(int len, const double* e) {
    for (int i = len - 1; i >= 0; --i)
        if (e[i] != 0) return e[i];
    return 0;
}

// orient2d from the raw coordinates: a x b + b x c + c x a, exactly.
static inline double orient2d_exact(const double* a, const double* b, const double* c) {
    double ab[4], bc[4], ca[4], s[8], t[12];
    cross_exact(a[0], a[1], b[0], b[1], ab);
    cross_exact(b[0], b[1], c[0], c[1], bc);
    cross_exact(c[0], c[1], a[0], a[1], ca);
    int slen = expansion_sum(4, ab, 4, bc, s);
    int tlen = expansion_sum(slen, s, 4, ca, t);
    return expansion_top(tlen, t);
}

// The exact stages are exact only if no product underflows or overflows. Their terms are
// products of 2 (orient) or 4 (incircle) coordinates or differences, so when points are a
// few ulps apart near 1e-70, or very large, they are first scaled by a power of two that
// centres the magnitudes in play: exact, and the determinant's sign does not change.
// `values` are the coordinates and differences involved; `limit` the largest safe binary
// exponent for the degree. Returns the factor, or 0 when no scaling is needed (or none
// can help: magnitudes spread over more than the double range allows).
static inline double rescaling_factor(const double* values, int count, int limit) {
    double largest = 0, smallest = DBL_MAX;
    for (int i = 0; i < count; ++i) {
        double v = abs_value(values[i]);
        if (v == 0 || !is_finite(v)) continue;
        if (v > largest) largest = v;
        if (v < smallest) smallest = v;
    }
    if (largest == 0) return 0;
    int high = 0, low = 0;
    std::frexp(largest, &high);
    std::frexp(smallest, &low);
    if (high <= limit && low >= -limit) return 0;
    if (high - low > 2 * limit) return 0;
    // Centre the magnitudes, but never by a power of two that is itself out of range
    // (points that are all subnormal would ask for about 2^1070).
    int shift = -(high + low) / 2;
    if (shift > 1000) shift = 1000;
    if (shift < -1000) shift = -1000;
    return std::ldexp(1.0, shift);
}

// The filters' error bounds ignore underflow, which adds an absolute error of at most a
// few 2^-1075: a result is only trusted beyond this.
constexpr double kUnderflowGuard = 0x1p-1000;

// Points the first `count` entries of `points` at scaled copies in `storage`, unless
// factor is 0 (no scaling needed).
static inline void rescale_points(double factor, const double** points, double (*storage)[2],
                           int count) {
    if (factor == 0) return;
    for (int k = 0; k < count; ++k) {
        storage[k][0] = points[k][0] * factor;
        storage[k][1] = points[k][1] * factor;
        points[k] = storage[k];
    }
}

// Integer stages. Exact zeros are the common case on grids: every rectangle of grid points
// is cocircular and grid lines make collinear triples, and proving those zeros with
// expansion products costs several times more than this. Every double is an integer times
// a power of two, so when the differences a predicate uses span at most 62 bits, from the
// highest set bit of any to the lowest set bit of any, scaling them all by one power of
// two makes them integers below 2^62, and the determinant (of degree 2 or 4 in them) an
// integer below 2^125 or 2^252. Fixed-width integer arithmetic gets it exactly, whatever
// the magnitudes and without underflow, so these stages need no rescaling.

// floor(log2(|v|)) for a finite non-zero double.
static inline int top_bit_exponent(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    int biased = static_cast<int>((bits >> 52) & 0x7FF);
    if (biased != 0) return biased - 1023;
    // Subnormal: the conversion of the mantissa (below 2^52) to double is exact, and its
    // exponent field tells where the top bit is.
    double mantissa = static_cast<double>(bits & ((uint64_t(1) << 52) - 1));
    std::memcpy(&bits, &mantissa, sizeof bits);
    return static_cast<int>((bits >> 52) & 0x7FF) - 1023 - 1074;
}

// 2^e for -1022 <= e <= 1023.
static inline double power_of_two(int e) {
    uint64_t bits = static_cast<uint64_t>(e + 1023) << 52;
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
}

// Unsigned integers as little-endian arrays of 64-bit words.
struct Uint128 {
    uint64_t word[2];
};

struct Uint256 {
    uint64_t word[4];
};

// a * b exactly. Where the compiler has a 128-bit type this is one instruction on 64-bit
// targets; elsewhere it is built from 32-bit halves. Both are exact, so results agree.
static inline Uint128 multiply_wide(uint64_t a, uint64_t b) {
    Uint128 r;
#if defined(__SIZEOF_INT128__)
    __extension__ typedef unsigned __int128 uint128_type;
    uint128_type p = static_cast<uint128_type>(a) * b;
    r.word[0] = static_cast<uint64_t>(p);
    r.word[1] = static_cast<uint64_t>(p >> 64);
#else
    const uint64_t mask = 0xFFFFFFFFu;
    uint64_t a0 = a & mask, a1 = a >> 32, b0 = b & mask, b1 = b >> 32;
    uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    uint64_t middle = (p00 >> 32) + (p01 & mask) + (p10 & mask);
    r.word[0] = (middle << 32) | (p00 & mask);
    r.word[1] = p11 + (p01 >> 32) + (p10 >> 32) + (middle >> 32);
#endif
    return r;
}

// a + b + carry; carry becomes the carry out (the carry in is 0 or 1).
static inline uint64_t add_with_carry(uint64_t a, uint64_t b, uint64_t& carry) {
    uint64_t s = a + b;
    uint64_t out = s < a;
    uint64_t t = s + carry;
    carry = out | (t < s);
    return t;
}

// sum += term or sum -= term, two's complement modulo 2^(64 N); term is zero-extended.
template <size_t N, size_t M>
static inline void words_accumulate(uint64_t (&sum)[N], const uint64_t (&term)[M], bool subtract) {
    uint64_t flip = subtract ? ~uint64_t(0) : 0;
    uint64_t carry = subtract ? 1 : 0;
    for (size_t k = 0; k < N; ++k)
        sum[k] = add_with_carry(sum[k], (k < M ? term[k] : 0) ^ flip, carry);
}

// Makes a two's complement number its magnitude; returns whether it was negative.
template <size_t N>
static inline bool words_to_magnitude(uint64_t (&value)[N]) {
    if ((value[N - 1] >> 63) == 0) return false;
    uint64_t carry = 1;
    for (size_t k = 0; k < N; ++k) {
        value[k] = ~value[k] + carry;
        carry = carry & (value[k] == 0);
    }
    return true;
}

// a * b for a, b < 2^127 (the top word cannot overflow).
static inline Uint256 multiply_wide(const Uint128& a, const Uint128& b) {
    Uint128 p00 = multiply_wide(a.word[0], b.word[0]);
    Uint128 p01 = multiply_wide(a.word[0], b.word[1]);
    Uint128 p10 = multiply_wide(a.word[1], b.word[0]);
    Uint128 p11 = multiply_wide(a.word[1], b.word[1]);
    Uint256 r;
    uint64_t carry = 0, carry2 = 0;
    r.word[0] = p00.word[0];
    r.word[1] = add_with_carry(p00.word[1], p01.word[0], carry);
    r.word[1] = add_with_carry(r.word[1], p10.word[0], carry2);
    carry += carry2;
    carry2 = 0;
    r.word[2] = add_with_carry(p01.word[1], p10.word[1], carry);
    r.word[2] = add_with_carry(r.word[2], p11.word[0], carry2);
    r.word[3] = p11.word[1] + carry + carry2;
    return r;
}

// Up to six differences as integers below 2^62: value[i] * 2^shift is
// (-1)^negative[i] * magnitude[i].
struct ScaledIntegers {
    uint64_t magnitude[6];
    bool negative[6];
    int shift;
};

// Scales `count` (at most 6) exact, hence finite, differences into integers; false when
// they span more than 62 bits, or all lie below 2^-962 (the factor would leave the double
// range; rare enough to leave to the expansions).
static inline bool to_integers(const double* values, int count, ScaledIntegers& out) {
    double largest = 0;
    for (int i = 0; i < count; ++i)
        if (abs_value(values[i]) > largest) largest = abs_value(values[i]);
    out.shift = largest == 0 ? 0 : 61 - top_bit_exponent(largest);
    if (out.shift > 1023) return false;
    double scale = power_of_two(out.shift);
    for (int i = 0; i < count; ++i) {
        // Exact unless it underflows (only when scaling down), which the test below
        // catches: what underflowed is not a non-zero integer.
        double scaled = values[i] * scale;
        int64_t n = static_cast<int64_t>(scaled);
        if (static_cast<double>(n) != scaled || (n == 0 && values[i] != 0)) return false;
        out.negative[i] = n < 0;
        out.magnitude[i] = n < 0 ? 0 - static_cast<uint64_t>(n) : static_cast<uint64_t>(n);
    }
    return true;
}

// u0 v1 - u1 v0 for four of the integers, given by index: its magnitude (below 2^125)
// and whether it is negative.
static inline Uint128 integer_cross(const ScaledIntegers& z, int u0, int u1, int v0, int v1,
                             bool* negative) {
    Uint128 cross = {{0, 0}};
    Uint128 left = multiply_wide(z.magnitude[u0], z.magnitude[v1]);
    Uint128 right = multiply_wide(z.magnitude[u1], z.magnitude[v0]);
    words_accumulate(cross.word, left.word, z.negative[u0] != z.negative[v1]);
    words_accumulate(cross.word, right.word, z.negative[u1] == z.negative[v0]);
    *negative = words_to_magnitude(cross.word);
    return cross;
}

// (-1)^negative * magnitude * 2^exponent as a double. Only the sign is exact: a non-zero
// value is kept from rounding to zero or infinity.
template <size_t N>
static inline double to_signed_double(const uint64_t (&magnitude)[N], bool negative, int exponent) {
    double value = 0;
    for (size_t k = N; k-- > 0;) value = value * 0x1p64 + static_cast<double>(magnitude[k]);
    if (value == 0) return 0;
    value = std::ldexp(value, exponent);
    if (value == 0) value = DBL_TRUE_MIN;
    if (!is_finite(value)) value = DBL_MAX;
    return negative ? -value : value;
}

// orient2d from exact differences u = a - c, v = b - c: u x v, or false when the integer
// stage does not apply.
static inline bool orient2d_from_integer_differences(const double differences[4], double* det) {
    ScaledIntegers z;
    if (!to_integers(differences, 4, z)) return false;
    bool negative = false;
    Uint128 cross = integer_cross(z, 0, 1, 2, 3, &negative);
    *det = to_signed_double(cross.word, negative, -2 * z.shift);
    return true;
}

// incircle from exact differences to d, rows (dx, dy): the 3x3 determinant of rows
// (dx, dy, dx^2 + dy^2) expanded along the lifts, or false when the integer stage does
// not apply.
static inline bool incircle_from_integer_differences(const double rows[3][2], double* det) {
    ScaledIntegers z;
    if (!to_integers(&rows[0][0], 6, z)) return false;
    uint64_t sum[4] = {0, 0, 0, 0};
    for (int i = 0; i < 3; ++i) {
        // The lift of row i times the minor of the other two rows u, v: u x v.
        Uint128 lift = multiply_wide(z.magnitude[2 * i], z.magnitude[2 * i]);
        Uint128 square = multiply_wide(z.magnitude[2 * i + 1], z.magnitude[2 * i + 1]);
        words_accumulate(lift.word, square.word, false);
        int u = 2 * ((i + 1) % 3), v = 2 * ((i + 2) % 3);
        bool minor_negative = false;
        Uint128 minor = integer_cross(z, u, u + 1, v, v + 1, &minor_negative);
        words_accumulate(sum, multiply_wide(lift, minor).word, minor_negative);
    }
    bool negative = words_to_magnitude(sum);
    *det = to_signed_double(sum, negative, -4 * z.shift);
    return true;
}

// orient2d once the filter has failed: the differences are tried for exactness (in the
// integer stage, then with rescaling in expansions), then the raw coordinates are used
// (with STRATMESH_SMALL_CODE at once, after the rescaling: kFastExactStages). Kept apart
// from the filter so that the common, filtered call stays small.
STRATMESH_NOINLINE static inline double orient2d_beyond_filter(const double* a, const double* b,
                                                         const double* c) {
    double differences[4], tails[4], det = 0;
    two_diff(a[0], c[0], differences[0], tails[0]);
    two_diff(a[1], c[1], differences[1], tails[1]);
    two_diff(b[0], c[0], differences[2], tails[2]);
    two_diff(b[1], c[1], differences[3], tails[3]);
    bool exact = tails[0] == 0 && tails[1] == 0 && tails[2] == 0 && tails[3] == 0;
    if (kFastExactStages && exact && orient2d_from_integer_differences(differences, &det))
        return det;
    const double magnitudes[10] = {differences[0], differences[2], differences[1],
                                   differences[3], a[0], a[1], b[0], b[1], c[0], c[1]};
    double factor = rescaling_factor(magnitudes, 10, 400);
    const double* points[3] = {a, b, c};
    double scaled[3][2];
    rescale_points(factor, points, scaled, 3);
    a = points[0];
    b = points[1];
    c = points[2];
    double acx, acy, bcx, bcy, t0, t1, t2, t3;
    two_diff(a[0], c[0], acx, t0);
    two_diff(b[0], c[0], bcx, t1);
    two_diff(a[1], c[1], acy, t2);
    two_diff(b[1], c[1], bcy, t3);
    if (kFastExactStages && t0 == 0 && t1 == 0 && t2 == 0 && t3 == 0) {
        double d[4];
        cross_exact(acx, acy, bcx, bcy, d);
        return expansion_top(4, d);
    }
    return orient2d_exact(a, b, c);
}

// Sign-exact orient2d: the filter decides unless |det| is within the rounding error.
static inline double orient2d_robust(const double* a, const double* b, const double* c) {
    double acx = a[0] - c[0], bcx = b[0] - c[0];
    double acy = a[1] - c[1], bcy = b[1] - c[1];
    double left = acx * bcy;
    double right = acy * bcx;
    double det = left - right;
    double bound = kOrientBoundA * (abs_value(left) + abs_value(right)) + kUnderflowGuard;
    if (det > bound || -det > bound) return det;
    return orient2d_beyond_filter(a, b, c);
}

// Scratch, in doubles, for the exact incircle below.
const int kIncircleScratch = 1024;

// incircle from the raw coordinates: the 4x4 determinant with rows (x, y, x^2 + y^2, 1),
// expanded along the lift column. Needs kIncircleScratch doubles of scratch.
static inline double incircle_exact(const double* a, const double* b, const double* c,
                             const double* d, double* scratch) {
    const double* p[4] = {a, b, c, d};
    double* acc = scratch;         // 384
    double* acc2 = scratch + 384;  // 384
    double* term = scratch + 768;  // 96
    double* tmp = scratch + 864;   // 96
    double* scaled = scratch + 960; // 24
    double* orient = scratch + 984; // 12
    double* cross = scratch + 996;  // 8
    double lift[4], lp[2], lq[2];
    int acc_len = 0;
    for (int skip = 0; skip < 4; ++skip) {
        // orient2d of the other three points, in their order.
        const double* q[3];
        for (int k = 0, m = 0; k < 4; ++k)
            if (k != skip) q[m++] = p[k];
        double ab[4], bc[4], ca[4];
        cross_exact(q[0][0], q[0][1], q[1][0], q[1][1], ab);
        cross_exact(q[1][0], q[1][1], q[2][0], q[2][1], bc);
        cross_exact(q[2][0], q[2][1], q[0][0], q[0][1], ca);
        int clen = expansion_sum(4, ab, 4, bc, cross);
        int olen = expansion_sum(clen, cross, 4, ca, orient);
        two_product(p[skip][0], p[skip][0], lp[1], lp[0]);
        two_product(p[skip][1], p[skip][1], lq[1], lq[0]);
        int llen = expansion_sum(2, lp, 2, lq, lift);
        int tlen = expansion_product(olen, orient, llen, lift, term, tmp, scaled);
        // Cofactor signs of the lift column: +, -, +, -.
        if (skip % 2 == 1) expansion_negate(tlen, term);
        if (acc_len == 0) {
            std::memcpy(acc, term, sizeof(double) * static_cast<size_t>(tlen));
            acc_len = tlen;
        } else {
            acc_len = expansion_sum(acc_len, acc, tlen, term, acc2);
            std::memcpy(acc, acc2, sizeof(double) * static_cast<size_t>(acc_len));
        }
    }
    return expansion_top(acc_len, acc);
}

// An expansion rounded to a double-double hi + lo, |lo| <= eps |hi|: the components are
// summed smallest first with error-free sums, so the result is off by a few eps^2 of the
// value. (Taking the expansion's two largest components instead is not enough: a
// nonoverlapping expansion may hold a lone high bit followed by a component nearly as
// large.)
static inline void to_double_double(const double* e, int len, double* hi, double* lo) {
    double h = 0, l = 0;
    for (int k = 0; k < len; ++k) {
        double s, err;
        two_sum(h, e[k], s, err);
        h = s;
        l += err;
    }
    two_sum(h, l, *hi, *lo);
}

// incircle when the six coordinate differences are exact doubles but span too many bits
// for the integer stage: the 3x3 determinant of rows (dx, dy, L = dx^2 + dy^2), expanded
// along L. Each lift L and minor M = u x v is formed exactly (cheap). First the three
// products L M are summed in double-double arithmetic from the lifts and minors rounded
// to double-doubles (each off by a few eps^2): each product is then off by about
// 12 eps^2 |L M| and the sum adds about 6 eps^2 per term, so a result beyond
// 64 eps^2 sum |L M| has the right sign. That settles near-cocircular points whose
// determinant is not zero; exact zeros take the exact products. Needs 264 doubles of
// scratch.
static inline double incircle_from_differences(const double rows[3][2], double* scratch) {
    double lift[3][4], minor[3][4];
    int lift_len[3], minor_len[3];
    double hi = 0, lo = 0, magnitude = 0;
    for (int i = 0; i < 3; ++i) {
        const double* u = rows[(i + 1) % 3];
        const double* v = rows[(i + 2) % 3];
        cross_exact(u[0], u[1], v[0], v[1], minor[i]);
        minor_len[i] = compress_zeros(4, minor[i]);
        double sx[2], sy[2];
        two_product(rows[i][0], rows[i][0], sx[1], sx[0]);
        two_product(rows[i][1], rows[i][1], sy[1], sy[0]);
        lift_len[i] = expansion_sum(2, sx, 2, sy, lift[i]);
        double l1, l0, m1, m0, t1, t0, s, e;
        to_double_double(lift[i], lift_len[i], &l1, &l0);
        to_double_double(minor[i], minor_len[i], &m1, &m0);
        two_product(l1, m1, t1, t0);
        double cross = l1 * m0 + l0 * m1 + t0;
        two_sum(hi, t1, s, e);
        hi = s;
        lo += e + cross;
        magnitude += abs_value(l1) * abs_value(m1);
    }
    double approximate = hi + lo;
    double bound = 64 * kEps * kEps * magnitude + kUnderflowGuard;
    if (approximate > bound || -approximate > bound) return approximate;
    double* det = scratch;            // 96
    double* det2 = scratch + 96;      // 96
    double* product = scratch + 192;  // 32
    double* tmp = scratch + 224;      // 32
    double* scaled = scratch + 256;   // 8
    int det_len = 0;
    for (int i = 0; i < 3; ++i) {
        int len = expansion_product(minor_len[i], minor[i], lift_len[i], lift[i], product, tmp,
                                    scaled);
        if (det_len == 0) {
            std::memcpy(det, product, sizeof(double) * static_cast<size_t>(len));
            det_len = len;
        } else {
            det_len = expansion_sum(det_len, det, len, product, det2);
            std::memcpy(det, det2, sizeof(double) * static_cast<size_t>(det_len));
        }
    }
    return expansion_top(det_len, det);
}

// The differences of a, b, c to d, as rows; whether all six are exact.
static inline bool differences_to(const double* a, const double* b, const double* c, const double* d,
                           double rows[3][2]) {
    const double* p[3] = {a, b, c};
    bool exact = true;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 2; ++k) {
            double tail;
            two_diff(p[i][k], d[k], rows[i][k], tail);
            exact = exact && tail == 0;
        }
    return exact;
}

// incircle once the filter has failed. The integer stage goes first: the differences of
// nearby points are nearly always exact and narrow enough, and it needs no rescaling
// (there is no underflow to avoid); then the differences after rescaling; then the raw
// coordinates (with STRATMESH_SMALL_CODE only these: kFastExactStages). Kept apart from
// the filter so that the common, filtered call stays small.
STRATMESH_NOINLINE static inline double incircle_beyond_filter(const double* a, const double* b,
                                                         const double* c, const double* d,
                                                         double* scratch) {
    double rows[3][2], det = 0;
    const bool exact = differences_to(a, b, c, d, rows);
    if (kFastExactStages && exact && incircle_from_integer_differences(rows, &det))
        return det;
    const double magnitudes[14] = {rows[0][0], rows[1][0], rows[2][0], rows[0][1],
                                   rows[1][1], rows[2][1], a[0], a[1], b[0], b[1],
                                   c[0], c[1], d[0], d[1]};
    double factor = rescaling_factor(magnitudes, 14, 160);
    const double* points[4] = {a, b, c, d};
    double scaled[4][2];
    rescale_points(factor, points, scaled, 4);
    a = points[0];
    b = points[1];
    c = points[2];
    d = points[3];
    if (kFastExactStages && differences_to(a, b, c, d, rows))
        return incircle_from_differences(rows, scratch);
    return incircle_exact(a, b, c, d, scratch);
}

// Sign-exact incircle using `scratch` (kIncircleScratch doubles) when the filter fails.
static inline double incircle_robust(const double* a, const double* b, const double* c,
                              const double* d, double* scratch) {
    double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
    double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
    double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
    double alift = adx * adx + ady * ady;
    double cdxady = cdx * ady, adxcdy = adx * cdy;
    double blift = bdx * bdx + bdy * bdy;
    double adxbdy = adx * bdy, bdxady = bdx * ady;
    double clift = cdx * cdx + cdy * cdy;
    double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) +
                 clift * (adxbdy - bdxady);
    double permanent = (abs_value(bdxcdy) + abs_value(cdxbdy)) * alift +
                       (abs_value(cdxady) + abs_value(adxcdy)) * blift +
                       (abs_value(adxbdy) + abs_value(bdxady)) * clift;
    double bound = kIncircleBoundA * permanent + kUnderflowGuard;
    if (det > bound || -det > bound) return det;
    return incircle_beyond_filter(a, b, c, d, scratch);
}

// Lexicographic order on (x, y): the rank that sets each point's perturbation.
static inline bool lex_less(const double* p, const double* q) {
    return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
}

// The sign of incircle(a, b, c, d) for counter-clockwise abc, with ties broken by the
// symbolic perturbation: point i is lifted by eps^(4 - rank(i)), the lexicographically
// largest point the most. A tie is settled by the largest point whose cofactor (the
// orientation of the other three) is non-zero; d's cofactor is -orient(a, b, c) < 0, so
// the loop always ends. Never returns 0 for four distinct points. The tie is settled out of
// line (STRATMESH_FAST_NOINLINE), so that the filtered test inlines into its callers.
STRATMESH_FAST_NOINLINE static inline int incircle_tie(const double* a, const double* b,
                                                const double* c, const double* d) {
    const double* p[4] = {a, b, c, d};
    // Sort the four points by decreasing lexicographic rank (insertion sort, 4 items).
    int order[4] = {0, 1, 2, 3};
    for (int i = 1; i < 4; ++i)
        for (int j = i; j > 0 && lex_less(p[order[j - 1]], p[order[j]]); --j) {
            int s = order[j];
            order[j] = order[j - 1];
            order[j - 1] = s;
        }
    for (int k = 0; k < 4; ++k) {
        double o = 0;
        switch (order[k]) {
        case 0: o = orient2d_robust(b, c, d); break;
        case 1: o = orient2d_robust(a, d, c); break;
        case 2: o = orient2d_robust(a, b, d); break;
        default: return -1;
        }
        if (o > 0) return 1;
        if (o < 0) return -1;
    }
    return -1;
}

STRATMESH_SMALL_NOINLINE static inline int incircle_perturbed(const double* a, const double* b,
                                                       const double* c, const double* d,
                                                       double* scratch) {
    const double det = incircle_robust(a, b, c, d, scratch);
    if (det > 0) return 1;
    if (det < 0) return -1;
    return incircle_tie(a, b, c, d);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

double orient2d(const double a[2], const double b[2], const double c[2]) {
    return detail::orient2d_robust(a, b, c);
}

double incircle(const double a[2], const double b[2], const double c[2], const double d[2]) {
    double scratch[detail::kIncircleScratch];
    return detail::incircle_robust(a, b, c, d, scratch);
}

}  // namespace stratmesh

// >>spatial sort =========================================================================
// The insertion order of the Delaunay triangulation.
//
// This work is based on:
//   N. Amenta, S. Choi, G. Rote, "Incremental constructions con BRIO", SoCG 2003.
//
// Points are inserted in a biased randomized insertion order: rounds of doubling size,
// each round ordered along a Hilbert curve. The curve keeps every walk short; the rounds
// spread the early points over the whole domain so that later points land in
// well-shaped triangles (a pure curve order makes long slivers at the growing front and
// costs about 40% more flips). The "random" round of a point is a hash of its
// coordinates, so exact duplicates share a round and a curve cell, and the stable sort
// keeps them in input order: the first inserted is the lowest index.

namespace stratmesh {
namespace detail {

const uint32_t kHilbertBits = 13;  // per axis; 5 bits of the 32-bit key are left for rounds

// The curve as a state machine. At each level the remaining sub-square is the unit
// square under one of four transforms (complemented or not, x and y swapped or not; the
// two commute): the quadrant's bits, seen through the transform, give the curve digit
// (3 rx) ^ ry, and a quadrant with ry = 0 swaps the transform (and complements it if
// rx = 1). The table runs two levels a step: entry (state << 4 | x bits << 2 | y bits)
// holds the two digits in its low 4 bits and the next state above them. Built at compile
// time from that rule, so it is a constant, not state.
struct HilbertTable {
    unsigned char entry[64];
    constexpr HilbertTable() : entry() {
        for (uint32_t i = 0; i < 64; ++i) {
            uint32_t complement = (i >> 4) & 1u, swapped = i >> 5, digits = 0;
            for (uint32_t level = 2; level-- > 0;) {
                uint32_t bx = (i >> (2 + level)) & 1u, by = (i >> level) & 1u;
                uint32_t rx = (swapped ? by : bx) ^ complement;
                uint32_t ry = (swapped ? bx : by) ^ complement;
                digits = (digits << 2) | ((3u * rx) ^ ry);
                complement ^= rx & (ry ^ 1u);
                swapped ^= ry ^ 1u;
            }
            entry[i] = static_cast<unsigned char>(digits | (complement << 4) | (swapped << 5));
        }
    }
};

constexpr HilbertTable kHilbertTable{};

static inline uint32_t hilbert_index(uint32_t x, uint32_t y) {
    // kHilbertBits is odd: a zero level is put on top, entered with x and y swapped so
    // that it leaves the identity transform (its digit is 0), and the 14 levels run in
    // seven steps.
    static_assert(kHilbertBits % 2 == 1, "the levels are paired under one zero level");
    uint32_t state = 2, d = 0;
    for (uint32_t shift = kHilbertBits + 1; shift >= 2;) {
        shift -= 2;
        uint32_t bx = (x >> shift) & 3u, by = (y >> shift) & 3u;
        uint32_t e = kHilbertTable.entry[(state << 4) | (bx << 2) | by];
        d = (d << 4) | (e & 15u);
        state = e >> 4;
    }
    return d;
}

static inline uint32_t quantize(double v, double lo, double scale) {
    const double top = static_cast<double>((1u << kHilbertBits) - 1);
    double q = (v - lo) * scale;
    if (!(q > 0)) return 0;
    if (q >= top) return (1u << kHilbertBits) - 1;
    return static_cast<uint32_t>(q);
}

static inline uint32_t mix32(uint32_t h) {
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return h;
}

// A hash of the point's coordinates (-0 and +0 hash alike).
static inline uint32_t coordinate_hash(double x, double y) {
    uint64_t bx, by;
    x += 0.0;
    y += 0.0;
    std::memcpy(&bx, &x, sizeof bx);
    std::memcpy(&by, &y, sizeof by);
    uint32_t h = mix32(static_cast<uint32_t>(bx) ^ 0x9E3779B9u);
    h = mix32(h ^ static_cast<uint32_t>(bx >> 32));
    h = mix32(h ^ static_cast<uint32_t>(by));
    return mix32(h ^ static_cast<uint32_t>(by >> 32));
}

// Stable LSD radix sort of `order` by `keys` (both count long), 8 bits a pass.
static inline void radix_sort(uint32_t* keys, uint32_t* order, uint32_t* keys_tmp,
                       uint32_t* order_tmp, size_t count) {
    for (uint32_t shift = 0; shift < 32; shift += 8) {
        size_t histogram[256];
        std::memset(histogram, 0, sizeof histogram);
        for (size_t i = 0; i < count; ++i) ++histogram[(keys[i] >> shift) & 0xFFu];
        size_t total = 0;
        for (size_t& h : histogram) {
            size_t c = h;
            h = total;
            total += c;
        }
        for (size_t i = 0; i < count; ++i) {
            size_t slot = histogram[(keys[i] >> shift) & 0xFFu]++;
            keys_tmp[slot] = keys[i];
            order_tmp[slot] = order[i];
        }
        uint32_t* t = keys; keys = keys_tmp; keys_tmp = t;
        t = order; order = order_tmp; order_tmp = t;
    }
    // An even number of passes: the sorted data is back in the caller's arrays.
}

struct BoundingBox2d {
    double min[2], max[2];
};

// The number of trailing zero bits of h, at most `limit` (< 32). The loop over the bits,
// whose length is random, mispredicts its exit on about every other point; GCC and Clang
// count them in an instruction or two (2.5% of delaunay_2d's time on 1e6 points).
static inline uint32_t trailing_zeros(uint32_t h, uint32_t limit) {
#if defined(__GNUC__) || defined(__clang__)
    const uint32_t zeros = h ? static_cast<uint32_t>(__builtin_ctz(h)) : 32;
    return zeros < limit ? zeros : limit;
#else
    uint32_t zeros = 0;
    while (zeros < limit && (h & (1u << zeros)) == 0) ++zeros;
    return zeros;
#endif
}

// Fills order[0..count) with the indices of the points (x, y doubles, stride bytes apart)
// in BRIO order over `box`; scratch from the arena.
static inline bool spatial_order(const unsigned char* xy, size_t stride, size_t count,
                          const BoundingBox2d& box, uint32_t* order, Arena& arena) {
    size_t mark = arena.mark();
    uint32_t* keys = arena.alloc<uint32_t>(count);
    uint32_t* keys_tmp = arena.alloc<uint32_t>(count);
    uint32_t* order_tmp = arena.alloc<uint32_t>(count);
    if (arena.failed) return false;
    // One scale for both axes, the longer side's: square cells keep the curve local in the
    // plane's own metric, and a long strip is ordered along its length. (Separate scales
    // made a layer's unrolled strip, six times longer than high, a grid of cells six times
    // wider than high: a walk crossed 5.8 triangles on the bumpy tube instead of 4.1.)
    double width = box.max[0] - box.min[0], height = box.max[1] - box.min[1];
    double range = width > height ? width : height;
    double scale = (range > 0 && is_finite(range)) ? ((1u << kHilbertBits) - 1) / range : 0.0;
    if (!is_finite(scale)) scale = 0.0;
    // Rounds: the last holds about half the points, the first about 64.
    uint32_t rounds = 0;
    while (rounds < 24 && (count >> (rounds + 7)) > 0) ++rounds;
    const uint32_t curve_mask = (1u << (2 * kHilbertBits)) - 1;
    for (size_t i = 0; i < count; ++i) {
        const unsigned char* p = xy + i * stride;
        double x = read_double(p), y = read_double(p + sizeof(double));
        uint32_t h = coordinate_hash(x, y);
        const uint32_t zeros = trailing_zeros(h, rounds);
        uint32_t round = rounds - zeros;
        uint32_t curve = hilbert_index(quantize(x, box.min[0], scale),
                                       quantize(y, box.min[1], scale));
        // Odd rounds run the curve backwards, so each round starts where the last ended.
        if (round % 2 == 1) curve = curve_mask - curve;
        keys[i] = (round << (2 * kHilbertBits)) | curve;
        order[i] = static_cast<uint32_t>(i);
    }
    radix_sort(keys, order, keys_tmp, order_tmp, count);
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh

// >>delaunay =============================================================================
// The incremental 2D Delaunay triangulation (delaunay_2d).
//
// This work is based on:
//   C. L. Lawson, "Software for C1 surface interpolation", 1977 (edge flips).
//   P. J. Green, R. Sibson, "Computing Dirichlet tessellations in the plane", 1978.
//   O. Devillers, S. Pion, M. Teillaud, "Walking in a triangulation", 2002.
//
// Incremental insertion with Lawson flips on compact arrays. Triangle t owns half-edges
// 3t, 3t+1, 3t+2; half-edge e runs from vertex[e] to vertex[next(e)] and twin[e] is the
// opposite half-edge. Real triangles are counter-clockwise. The outside of the convex
// hull is covered by "ghost" triangles (a, b, kGhost), one per hull edge a->b (seen with
// the outside on its left), so every half-edge has a twin and points outside the hull are
// inserted like any other: a ghost (a, b, G) "contains" p when orient(a, b, p) > 0, and
// an edge to G is flipped when p sees the next hull edge. With m points there are always
// 2m - 2 triangles, ghosts included.

namespace stratmesh {
namespace detail {

static const uint32_t kGhost = kNoIndex;

static inline uint32_t next_edge(uint32_t e) { return e % 3 == 2 ? e - 2 : e + 1; }

static inline uint32_t prev_edge(uint32_t e) { return e % 3 == 0 ? e + 2 : e - 1; }

struct Triangulation {
    const double* xy;     // 2 per vertex, vertices in insertion order
    uint32_t* vertex;     // 3 per triangle
    uint32_t* twin;       // 3 per triangle
    uint32_t triangle_count;
    uint32_t triangle_capacity;
    uint32_t* stack;      // half-edges waiting for the flip test
    uint32_t stack_capacity;
    double* scratch;      // for exact incircle
    uint32_t hint;        // triangle to start the next walk from

    const double* point(uint32_t v) const { return xy + 2 * static_cast<size_t>(v); }

    bool is_ghost(uint32_t t) const {
        return vertex[3 * t] == kGhost || vertex[3 * t + 1] == kGhost ||
               vertex[3 * t + 2] == kGhost;
    }

    void link(uint32_t e, uint32_t f) {
        twin[e] = f;
        twin[f] = e;
    }

    void set_triangle(uint32_t t, uint32_t a, uint32_t b, uint32_t c) {
        vertex[3 * t] = a;
        vertex[3 * t + 1] = b;
        vertex[3 * t + 2] = c;
    }
};

// Memory for a triangulation of up to `count` points (the points themselves excluded).
static inline bool allocate_triangulation(Triangulation& tr, size_t count, Arena& arena) {
    size_t triangles = count >= 3 ? 2 * count - 2 : 4;
    tr.vertex = arena.alloc<uint32_t>(3 * triangles);
    tr.twin = arena.alloc<uint32_t>(3 * triangles);
    tr.stack = arena.alloc<uint32_t>(count + 4);
    tr.scratch = arena.alloc<double>(kIncircleScratch);
    tr.triangle_count = 0;
    tr.triangle_capacity = static_cast<uint32_t>(triangles);
    tr.stack_capacity = static_cast<uint32_t>(count + 4);
    tr.hint = 0;
    return !arena.failed;
}

// The first triangle (a, b, c), counter-clockwise, and its three ghosts.
static inline void start_triangulation(Triangulation& tr, uint32_t a, uint32_t b, uint32_t c) {
    tr.set_triangle(0, a, b, c);
    tr.set_triangle(1, b, a, kGhost);
    tr.set_triangle(2, c, b, kGhost);
    tr.set_triangle(3, a, c, kGhost);
    tr.link(0, 3);  // a->b with b->a
    tr.link(1, 6);  // b->c with c->b
    tr.link(2, 9);  // c->a with a->c
    tr.link(4, 11); // a->G with G->a
    tr.link(7, 5);  // b->G with G->b
    tr.link(10, 8); // c->G with G->c
    tr.triangle_count = 4;
    tr.hint = 0;
}

enum class Location { inside, on_edge, on_vertex, outside, failed };

// Walks from the hint to the triangle containing p. On return `edge` is: for inside, any
// half-edge of the triangle; for on_edge, the half-edge p lies on; for on_vertex, a
// half-edge starting at the vertex p coincides with; for outside, the hull half-edge of
// the ghost triangle p is in (p strictly on its outer side).
static inline Location locate(const Triangulation& tr, const double* p, uint32_t& edge) {
    uint32_t t = tr.hint;
    if (tr.is_ghost(t)) {
        for (uint32_t k = 0; k < 3; ++k) {
            uint32_t e = 3 * t + k;
            if (tr.vertex[e] != kGhost && tr.vertex[next_edge(e)] != kGhost) {
                t = tr.twin[e] / 3;
                break;
            }
        }
    }
    uint32_t came_from = kNoIndex;
    for (uint32_t steps = 0; steps <= tr.triangle_count; ++steps) {
        double o[3];
        bool moved = false;
        for (uint32_t k = 0; k < 3; ++k) {
            uint32_t e = 3 * t + (k + steps) % 3;
            if (e == came_from) {
                o[e % 3] = 1;
                continue;
            }
            o[e % 3] = orient2d_robust(tr.point(tr.vertex[e]), tr.point(tr.vertex[next_edge(e)]), p);
            if (o[e % 3] < 0) {
                uint32_t f = tr.twin[e];
                uint32_t u = f / 3;
                if (tr.is_ghost(u)) {
                    edge = f;
                    return Location::outside;
                }
                came_from = f;
                t = u;
                moved = true;
                break;
            }
        }
        if (moved) continue;
        int zeros = (o[0] == 0) + (o[1] == 0) + (o[2] == 0);
        if (zeros == 0) {
            edge = 3 * t;
            return Location::inside;
        }
        if (zeros == 1) {
            edge = 3 * t + (o[0] == 0 ? 0u : o[1] == 0 ? 1u : 2u);
            return Location::on_edge;
        }
        // Two zero edges meet at the vertex p coincides with: the start of the later one.
        uint32_t k = (o[0] != 0) ? 2u : (o[1] != 0) ? 0u : 1u;
        edge = 3 * t + k;
        return Location::on_vertex;
    }
    return Location::failed;
}

static inline bool push_edge(Triangulation& tr, uint32_t& top, uint32_t e) {
    STRATMESH_ASSERT(top < tr.stack_capacity);
    if (top >= tr.stack_capacity) return false;
    tr.stack[top++] = e;
    return true;
}

// Splits the triangle of half-edge e = (a, b, c) into (a, b, p), (b, c, p), (c, a, p).
static inline void split_triangle(Triangulation& tr, uint32_t t, uint32_t p, uint32_t& top) {
    uint32_t a = tr.vertex[3 * t], b = tr.vertex[3 * t + 1], c = tr.vertex[3 * t + 2];
    uint32_t o1 = tr.twin[3 * t + 1], o2 = tr.twin[3 * t + 2];
    uint32_t t1 = tr.triangle_count, t2 = tr.triangle_count + 1;
    tr.triangle_count += 2;
    tr.set_triangle(t, a, b, p);
    tr.set_triangle(t1, b, c, p);
    tr.set_triangle(t2, c, a, p);
    tr.link(3 * t1, o1);
    tr.link(3 * t2, o2);
    tr.link(3 * t + 1, 3 * t1 + 2);  // b->p with p->b
    tr.link(3 * t + 2, 3 * t2 + 1);  // p->a with a->p
    tr.link(3 * t1 + 1, 3 * t2 + 2); // c->p with p->c
    push_edge(tr, top, 3 * t);
    push_edge(tr, top, 3 * t1);
    push_edge(tr, top, 3 * t2);
    tr.hint = t;
}

// Splits the edge e = a->b (in triangle (a, b, c), twin in (b, a, d)) at p.
static inline void split_edge(Triangulation& tr, uint32_t e, uint32_t p, uint32_t& top) {
    uint32_t f = tr.twin[e];
    uint32_t t = e / 3, u = f / 3;
    uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)], c = tr.vertex[prev_edge(e)];
    uint32_t d = tr.vertex[prev_edge(f)];
    uint32_t x1 = tr.twin[next_edge(e)], x2 = tr.twin[prev_edge(e)];  // b->c, c->a
    uint32_t y1 = tr.twin[next_edge(f)], y2 = tr.twin[prev_edge(f)];  // a->d, d->b
    uint32_t t1 = tr.triangle_count, u1 = tr.triangle_count + 1;
    tr.triangle_count += 2;
    tr.set_triangle(t, c, a, p);
    tr.set_triangle(t1, c, p, b);
    tr.set_triangle(u, d, b, p);
    tr.set_triangle(u1, d, p, a);
    tr.link(3 * t, x2);
    tr.link(3 * t1 + 2, x1);
    tr.link(3 * u, y2);
    tr.link(3 * u1 + 2, y1);
    tr.link(3 * t + 1, 3 * u1 + 1);  // a->p with p->a
    tr.link(3 * t + 2, 3 * t1);      // p->c with c->p
    tr.link(3 * t1 + 1, 3 * u + 1);  // p->b with b->p
    tr.link(3 * u + 2, 3 * u1);      // p->d with d->p
    push_edge(tr, top, 3 * t);
    push_edge(tr, top, 3 * t1 + 2);
    push_edge(tr, top, 3 * u);
    push_edge(tr, top, 3 * u1 + 2);
    tr.hint = t;
}

// Whether edge e, in triangle (a, b, p) with p the point just inserted, must be flipped.
static inline bool must_flip(const Triangulation& tr, uint32_t e) {
    uint32_t f = tr.twin[e];
    uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)], p = tr.vertex[prev_edge(e)];
    uint32_t q = tr.vertex[prev_edge(f)];
    if (a != kGhost && b != kGhost) {
        if (q == kGhost) return false;  // a hull edge: nothing beyond it
        return incircle_perturbed(tr.point(a), tr.point(b), tr.point(p), tr.point(q),
                                  tr.scratch) > 0;
    }
    // An edge to the ghost vertex: flip when p strictly sees the neighbouring hull edge.
    if (b == kGhost) return orient2d_robust(tr.point(a), tr.point(q), tr.point(p)) > 0;
    return orient2d_robust(tr.point(q), tr.point(b), tr.point(p)) > 0;
}

// Flips e = a->b of (a, b, p) with its twin in (b, a, q) into (p, a, q) and (q, b, p) (the
// new triangles keep e's two triangle slots), and with kQueue queues the two edges that may
// now fail the Delaunay test.
template <bool kQueue> static inline void flip_edge(Triangulation& tr, uint32_t e, uint32_t* top) {
    uint32_t f = tr.twin[e];
    uint32_t t = e / 3, u = f / 3;
    uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)], p = tr.vertex[prev_edge(e)];
    uint32_t q = tr.vertex[prev_edge(f)];
    uint32_t xa = tr.twin[next_edge(e)];  // b->p
    uint32_t xb = tr.twin[prev_edge(e)];  // p->a
    uint32_t xc = tr.twin[next_edge(f)];  // a->q
    uint32_t xd = tr.twin[prev_edge(f)];  // q->b
    tr.set_triangle(t, p, a, q);
    tr.set_triangle(u, q, b, p);
    tr.link(3 * t, xb);
    tr.link(3 * t + 1, xc);
    tr.link(3 * u, xd);
    tr.link(3 * u + 1, xa);
    tr.link(3 * t + 2, 3 * u + 2);
    if (!kQueue) return;
    push_edge(tr, *top, 3 * t + 1);
    push_edge(tr, *top, 3 * u);
}

// Inserts vertex p. Returns the vertex it duplicates, p itself if it was inserted, or
// kNoIndex if an invariant failed.
static inline uint32_t insert_vertex(Triangulation& tr, uint32_t p) {
    uint32_t edge = 0;
    Location where = locate(tr, tr.point(p), edge);
    uint32_t top = 0;
    switch (where) {
    case Location::failed: return kNoIndex;
    case Location::on_vertex: return tr.vertex[edge];
    case Location::inside:
    case Location::outside: split_triangle(tr, edge / 3, p, top); break;
    case Location::on_edge: split_edge(tr, edge, p, top); break;
    }
    uint32_t flips = 0;
    while (top > 0) {
        uint32_t e = tr.stack[--top];
        if (!must_flip(tr, e)) continue;
        if (top + 2 > tr.stack_capacity || ++flips > tr.triangle_capacity) return kNoIndex;
        flip_edge<true>(tr, e, &top);
    }
    return p;
}

// Receives each point that repeats an earlier vertex: duplicate(point, vertex).
struct DuplicateSink {
    void (*report)(void* context, uint32_t point, uint32_t vertex);
    void* context;
};

// Builds the Delaunay triangulation of xy[0 .. count) (2 doubles per point, already in
// insertion order), reporting duplicates to `sink`. Counts the vertices in *inserted.
static inline Status triangulate_points(Triangulation& tr, uint32_t count, DuplicateSink sink,
                                 uint32_t* inserted) {
    *inserted = 0;
    if (count < 3) return Status::too_few_points;
    const double* p0 = tr.point(0);
    uint32_t i1 = 1;
    while (i1 < count && tr.point(i1)[0] == p0[0] && tr.point(i1)[1] == p0[1]) ++i1;
    if (i1 == count) return Status::too_few_points;
    uint32_t i2 = i1 + 1;
    while (i2 < count && orient2d_robust(p0, tr.point(i1), tr.point(i2)) == 0) ++i2;
    if (i2 == count) {
        // All on one line: are there at least three distinct points on it?
        const double* p1 = tr.point(i1);
        for (uint32_t k = i1 + 1; k < count; ++k) {
            const double* q = tr.point(k);
            if ((q[0] != p0[0] || q[1] != p0[1]) && (q[0] != p1[0] || q[1] != p1[1]))
                return Status::collinear;
        }
        return Status::too_few_points;
    }
    if (orient2d_robust(p0, tr.point(i1), tr.point(i2)) > 0)
        start_triangulation(tr, 0, i1, i2);
    else
        start_triangulation(tr, 0, i2, i1);
    uint32_t n_inserted = 3;
    for (uint32_t k = 1; k < count; ++k) {
        if (k == i1 || k == i2) continue;
        uint32_t v = insert_vertex(tr, k);
        if (v == kNoIndex) return Status::internal_error;
        if (v == k)
            ++n_inserted;
        else if (sink.report)
            sink.report(sink.context, k, v);
    }
    *inserted = n_inserted;
    STRATMESH_ASSERT(tr.triangle_count == 2 * n_inserted - 2);
    return tr.triangle_count == 2 * n_inserted - 2 ? Status::ok : Status::internal_error;
}

// The memory plan of delaunay_2d, shared by the call and by its size function.
struct Delaunay2dMemory {
    uint32_t* order;      // insertion position -> input index
    double* xy;           // points in insertion order
    Triangulation tr;
};

// Writes duplicates straight into the caller's duplicate_of, in input indices.
struct DuplicateMap {
    const uint32_t* order;
    uint32_t* duplicate_of;
    static void report(void* context, uint32_t point, uint32_t vertex) {
        DuplicateMap* m = static_cast<DuplicateMap*>(context);
        m->duplicate_of[m->order[point]] = m->order[vertex];
    }
};

static inline bool plan_delaunay_2d(Delaunay2dMemory& m, size_t count, Arena& arena,
                             const unsigned char* xy, size_t stride,
                             const BoundingBox2d* box) {
    m.order = arena.alloc<uint32_t>(count);
    if (arena.failed) return false;
    if (box) {
        if (!spatial_order(xy, stride, count, *box, m.order, arena)) return false;
    } else {
        // Measuring: the sort's scratch is released before the rest is taken.
        size_t mark = arena.mark();
        arena.alloc<uint32_t>(count);
        arena.alloc<uint32_t>(count);
        arena.alloc<uint32_t>(count);
        arena.rewind(mark);
    }
    m.xy = arena.alloc<double>(2 * count);
    m.tr.xy = m.xy;
    return allocate_triangulation(m.tr, count, arena);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

size_t delaunay_2d_workspace_size(size_t point_count) {
    if (point_count > detail::kMaxPoints) return 0;
    detail::Arena arena = detail::Arena::measuring();
    detail::Delaunay2dMemory m;
    detail::plan_delaunay_2d(m, point_count, arena, nullptr, 0, nullptr);
    return arena.failed ? 0 : arena.required_bytes();
}

size_t delaunay_2d_max_triangles(size_t point_count) {
    if (point_count > SIZE_MAX / 2) return 0;
    return point_count >= 3 ? 2 * point_count - 5 : 0;
}

}  // namespace stratmesh

namespace stratmesh {
namespace detail {

// True if any two of the caller's buffers share a byte: checked before anything is
// written. A count beyond the limit is refused as too_many_points instead, whatever its
// span would cover.
static inline bool delaunay_buffers_overlap(const double* xy, size_t point_count, size_t stride_bytes,
                                     void* workspace, size_t workspace_bytes,
                                     uint32_t* triangles, size_t triangle_capacity,
                                     Delaunay2dInfo* info, uint32_t* duplicate_of) {
    if (point_count > kMaxPoints) return false;
    const ByteRange buffers[] = {
        strided_range(xy, point_count, stride_bytes, 2 * sizeof(double)),
        byte_range(workspace, workspace_bytes),
        byte_range(triangles, saturating_product(triangle_capacity, 3 * sizeof(uint32_t))),
        byte_range(duplicate_of, saturating_product(point_count, sizeof(uint32_t))),
        byte_range(info, sizeof(Delaunay2dInfo))};
    return any_overlap(buffers, 5);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

Status delaunay_2d(const double* xy, size_t point_count, size_t stride_bytes,
                   void* workspace, size_t workspace_bytes,
                   uint32_t* triangles, size_t triangle_capacity,
                   Delaunay2dInfo* info, uint32_t* duplicate_of) {
    if (detail::delaunay_buffers_overlap(xy, point_count, stride_bytes, workspace,
                                         workspace_bytes, triangles, triangle_capacity, info,
                                         duplicate_of))
        return Status::invalid_argument;
    Delaunay2dInfo local = {0, 0, 0, 0, 0};
    Delaunay2dInfo& out = info ? *info : local;
    out = local;
    if (point_count > detail::kMaxPoints) return Status::too_many_points;
    if (point_count > 0 && (!xy || !workspace)) return Status::invalid_argument;
    if (stride_bytes < 2 * sizeof(double)) return Status::invalid_argument;
    if (triangle_capacity > 0 && !triangles) return Status::invalid_argument;
    if (point_count < 3) return Status::too_few_points;

    const unsigned char* base = reinterpret_cast<const unsigned char*>(xy);
    detail::BoundingBox2d box = {{DBL_MAX, DBL_MAX}, {-DBL_MAX, -DBL_MAX}};
    for (size_t i = 0; i < point_count; ++i) {
        const unsigned char* p = base + i * stride_bytes;
        for (size_t k = 0; k < 2; ++k) {
            double v = detail::read_double(p + k * sizeof(double));
            if (!detail::is_finite(v)) {
                out.first_invalid_index = i;
                return Status::invalid_point;
            }
            if (v < box.min[k]) box.min[k] = v;
            if (v > box.max[k]) box.max[k] = v;
        }
    }

    detail::Arena arena = detail::Arena::over(workspace, workspace_bytes);
    detail::Delaunay2dMemory m;
    if (!detail::plan_delaunay_2d(m, point_count, arena, base, stride_bytes, &box))
        {
        out.workspace_used_bytes = arena.peak_from_buffer();
        return Status::out_of_memory;
    }
    for (size_t k = 0; k < point_count; ++k) {
        const unsigned char* p = base + m.order[k] * stride_bytes;
        m.xy[2 * k] = detail::read_double(p);
        m.xy[2 * k + 1] = detail::read_double(p + sizeof(double));
    }
    if (duplicate_of) {
        for (size_t i = 0; i < point_count; ++i) duplicate_of[i] = static_cast<uint32_t>(i);
    }
    detail::DuplicateMap map = {m.order, duplicate_of};
    detail::DuplicateSink sink = {duplicate_of ? detail::DuplicateMap::report : nullptr, &map};
    uint32_t inserted = 0;
    Status status = detail::triangulate_points(m.tr, static_cast<uint32_t>(point_count),
                                               sink, &inserted);
    out.workspace_used_bytes = arena.peak_from_buffer();
    if (status != Status::ok) return status;

    size_t ghosts = 0;
    for (uint32_t t = 0; t < m.tr.triangle_count; ++t) ghosts += m.tr.is_ghost(t);
    // A triangulation's hull has 3 edges or more; fewer means contradictory predicate
    // signs (coordinates beyond the exact range), and then 2n - 5 would not bound `real`.
    if (ghosts < 3) return Status::internal_error;
    size_t real = m.tr.triangle_count - ghosts;
    out.hull_vertex_count = ghosts;
    out.duplicate_count = point_count - inserted;
    out.triangle_count = real;
    if (real > triangle_capacity) return Status::triangle_capacity;

    uint32_t* dst = triangles;
    for (uint32_t t = 0; t < m.tr.triangle_count; ++t) {
        if (m.tr.is_ghost(t)) continue;
        for (uint32_t k = 0; k < 3; ++k) *dst++ = m.order[m.tr.vertex[3 * t + k]];
    }
    return Status::ok;
}

}  // namespace stratmesh

// >>points ===============================================================================
// The cloud's points as the library reads them, and the vector arithmetic on them.
//
// The cloud is read in place (float or double, any stride): CloudReader turns point i into
// doubles and says whether it is valid (finite, and not left out as an outlier).

namespace stratmesh {
namespace detail {

struct Vec3 {
    double x, y, z;
};

static inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }

static inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

static inline Vec3 scaled(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }

struct CloudReader {
    const unsigned char* base;
    size_t stride;
    bool is_float;
    const unsigned char* dropped;  // optional bitmap: points left out as outliers

    Vec3 point(size_t i) const {
        const unsigned char* p = base + i * stride;
        if (is_float) {
            float v[3];
            std::memcpy(v, p, sizeof v);
            return {static_cast<double>(v[0]), static_cast<double>(v[1]),
                    static_cast<double>(v[2])};
        }
        double v[3];
        std::memcpy(v, p, sizeof v);
        return {v[0], v[1], v[2]};
    }
    bool valid(size_t i) const {
        if (kDropOutliers && dropped && ((dropped[i >> 3] >> (i & 7)) & 1)) return false;
        // One test for three coordinates: a product by zero is zero exactly when the
        // coordinate is finite, and it never overflows.
        Vec3 p = point(i);
        return p.x * 0 + p.y * 0 + p.z * 0 == 0;
    }
};

// The coordinate axis along which d is shortest (x where it ties for that, else z over y):
// crossed with d, it gives a direction well across d.
static inline Vec3 axis_least_along(Vec3 d) {
    if (abs_value(d.x) > abs_value(d.y) || abs_value(d.x) > abs_value(d.z))
        return abs_value(d.y) < abs_value(d.z) ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
    return {1, 0, 0};
}

static inline double largest_of(Vec3 v) {
    const double xy = v.x > v.y ? v.x : v.y;
    return xy > v.z ? xy : v.z;
}

static inline double coordinate(Vec3 p, int k) { return k == 0 ? p.x : k == 1 ? p.y : p.z; }

// False unless v's squared length is a normal double (v's length between about 1.5e-154
// and 1.3e154): a subnormal square has lost the bits that make the result unit.

static inline bool normalize(Vec3& v) {
    const double square = dot(v, v);
    if (!(square >= DBL_MIN) || !is_finite(square)) return false;
    const double len = std::sqrt(square);
    v = scaled(v, 1.0 / len);
    return true;
}

// A direction of any finite non-zero length made unit: first scaled by the power of two
// that brings its largest component into [1, 2) (exact: a component that falls below the
// smallest subnormal is negligible beside it), so that its square neither overflows nor
// underflows. False for zero, NaN or infinite components.
static inline bool unit_direction(Vec3& v) {
    if (!is_finite(v.x) || !is_finite(v.y) || !is_finite(v.z)) return false;
    const double largest = largest_of({abs_value(v.x), abs_value(v.y), abs_value(v.z)});
    if (largest == 0) return false;
    int exponent = 0;
    std::frexp(largest, &exponent);
    v = {std::ldexp(v.x, 1 - exponent), std::ldexp(v.y, 1 - exponent), std::ldexp(v.z, 1 - exponent)};
    return normalize(v);
}

}  // namespace detail
}  // namespace stratmesh

// >>outliers =============================================================================
// Points far from the rest of the cloud, left out with drop_outliers.

namespace stratmesh {
namespace detail {

// ---- outliers ----
//
// With drop_outliers, points far from the rest of the cloud (stray returns, flying pixels at
// depth edges, dust) are left out before anything else, so they neither tilt the automatic
// axis nor stretch the layers nor become spikes of the surface. The scale is the cloud's
// own: d, the distance to the nearest distinct point that nine points in ten do not exceed.
// A point is an outlier when fewer than kOutlierNeighbours points, itself included, lie in
// its block of 3 x 3 x 3 cells of side kOutlierReach d: nothing within 4 d of it (at most
// 12 d), or a speck of fewer than 8 points. A surface sample has a hundred or more points
// in that block; one a quarter as dense (the far side of a scan) still about thirty.
//
// d is measured on a grid of cells that hold about 4 points on average: first cells twice
// the spacing of the points spread over the square of the bounding box's diagonal, finer
// while they hold more than kCrowdedCell on average, four times coarser while more than a
// tenth of the points find no neighbour within a cell; each of at most about kDecileSample
// points looks at kNearestCandidates points at most, its own cell's row first, so that no
// cell costs more. A far outlier stretches the bounding box, and so the first grid, which
// can then miss a nearer one: the rounds repeat without the outliers found, at most
// kOutlierRounds times. Clouds of fewer than 16 points lose none. Duplicates of an outlier
// are outliers too. Deterministic (the same cells and counts on every platform); radix
// sorts of the cell keys and binary searches for a cell's neighbours, no recursion; 56
// bytes a point of workspace while it runs (less than the reconstruction takes next),
// then a bit a point. Measured: 20 far strays and 50 inside the head added to the bundled
// bust: 66 of the 70 left out (the other 4 lie 8 to 21 mm from the bust, within the
// block around it: d = 2.2 mm), none of the bust's own points (nor any of the real clouds'
// or the test shapes'); about 0.1 s on 300,000 points, a third of the reconstruction.
const uint32_t kOutlierNeighbours = 8;

const double kOutlierReach = 4.0;

const uint32_t kOutlierRounds = 3;

const uint32_t kGridTries = 8;

const uint32_t kCrowdedCell = 8;

const uint32_t kNearestCandidates = 64;

const size_t kDecileSample = 16384;

const uint32_t kNearestBins = 64;  // half-octaves of the squared distance, the last: none

const uint32_t kCellBits = 21;     // per axis, so a cell key takes 63 bits

const uint64_t kCellTop = (uint64_t{1} << kCellBits) - 1;

struct GridItem {
    uint64_t cell;
    uint32_t index;
};

// A cell's coordinate along one axis, clamped to [0, kCellTop] (clamping keeps cells next
// to each other next to each other, so no neighbour is missed; a clamped cell only holds
// more points).
static inline uint64_t cell_coordinate(double offset, double side) {
    const double c = std::floor(offset / side);
    if (!(c > 0)) return 0;
    return c < static_cast<double>(kCellTop) ? static_cast<uint64_t>(c) : kCellTop;
}

static inline uint64_t cell_key(uint64_t x, uint64_t y, uint64_t z) {
    return (x << (2 * kCellBits)) | (y << kCellBits) | z;
}

// The grid's scratch, each array with room for every point: the items, the radix sort's
// spare, and the points' coordinates in the items' order.
struct CellScratch {
    GridItem* items;
    GridItem* spare;
    Vec3* sorted;
};

// One allocation sequence for the call and for reconstruct_workspace_size().
static inline CellScratch allocate_cell_scratch(Arena& arena, size_t count) {
    CellScratch g;
    g.items = arena.alloc<GridItem>(count);
    g.spare = arena.alloc<GridItem>(count);
    g.sorted = arena.alloc<Vec3>(count);
    return g;
}

// Sorts items[0 .. n) by key (ties in their given order; the result may be in either
// array: the pointers are swapped as the passes go). An LSD radix sort, a byte a pass,
// skipping the bytes that every key shares: `any` and `every` are the keys' bitwise or
// and and.
static inline void sort_items(GridItem*& items, GridItem*& spare, size_t n, uint64_t any, uint64_t every) {
    for (uint32_t shift = 0; shift < 64; shift += 8) {
        if ((((any ^ every) >> shift) & 0xFFu) == 0) continue;
        size_t histogram[256] = {};
        for (size_t i = 0; i < n; ++i) ++histogram[(items[i].cell >> shift) & 0xFFu];
        size_t total = 0;
        for (size_t& h : histogram) {
            const size_t c = h;
            h = total;
            total += c;
        }
        for (size_t i = 0; i < n; ++i) spare[histogram[(items[i].cell >> shift) & 0xFFu]++] = items[i];
        GridItem* t = items;
        items = spare;
        spare = t;
    }
}

// The valid points in g.items, sorted by their cell of side `side` from `low` and by index
// within a cell; returns their count. Most key bytes are shared: a grid rarely spans more
// than 2^8 cells an axis.
static inline size_t sort_into_cells(const CloudReader& reader, size_t count, Vec3 low, double side,
                              CellScratch& g) {
    size_t n = 0;
    uint64_t any = 0, every = ~uint64_t{0};
    for (size_t i = 0; i < count; ++i) {
        if (!reader.valid(i)) continue;
        const Vec3 p = reader.point(i);
        const uint64_t cell = cell_key(cell_coordinate(p.x - low.x, side),
                                       cell_coordinate(p.y - low.y, side),
                                       cell_coordinate(p.z - low.z, side));
        g.items[n++] = {cell, static_cast<uint32_t>(i)};
        any |= cell;
        every &= cell;
    }
    sort_items(g.items, g.spare, n, any, every);
    return n;
}

// The first item at or after `cell`, searched from items[from] outward (from < count):
// the steps double until they pass it, then halve. The cells around a point's lie near it
// in the array, so the search stays in memory the point's cell brought in.
static inline size_t first_in_cell(const GridItem* items, size_t count, uint64_t cell, size_t from) {
    size_t lo = from, hi = from;  // the answer lies in [lo, hi] once the steps pass it
    if (items[from].cell < cell) {
        for (size_t step = 1; hi < count && items[hi].cell < cell; step *= 2) {
            lo = hi + 1;
            hi = count - from > step ? from + step : count;
        }
    } else {
        for (size_t step = 1; lo > 0 && items[lo - 1].cell >= cell; step *= 2) {
            hi = lo - 1;
            lo = from > step ? from - step : 0;
        }
    }
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (items[mid].cell < cell) lo = mid + 1; else hi = mid;
    }
    return lo;
}

// The ranges of `items` in the 27 cells around `cell` (fewer at the grid's edges): a cell's
// neighbours along z follow it in key order, so they are 9 ranges, one per row, the
// cell's own row first (its points are the nearest candidates when few are looked at).
struct CellBlock {
    size_t begin[9], end[9];
    uint32_t count;
    size_t points() const {
        size_t n = 0;
        for (uint32_t k = 0; k < count; ++k) n += end[k] - begin[k];
        return n;
    }
};

// The items of the cells around `cell` (empty or not), searched from items[hint]. With
// `fingers` (18 valid positions, updated), each range end is searched from where the same
// end was found last: a caller that goes through cells in key order then finds each a few
// items on.
static inline CellBlock block_of_cell(const GridItem* items, size_t count, uint64_t cell,
                                      size_t hint, size_t* fingers = nullptr) {
    const size_t member = hint;
    CellBlock b;
    b.count = 0;
    const uint64_t x = cell >> (2 * kCellBits), y = (cell >> kCellBits) & kCellTop, z = cell & kCellTop;
    const uint64_t z_low = z > 0 ? z - 1 : 0, z_high = z < kCellTop ? z + 1 : kCellTop;
    for (uint32_t m = 0; m < 9; ++m) {
        const uint32_t k = (m + 4) % 9;  // 4: the row (x, y) itself
        const uint64_t row_x = x + k % 3, row_y = y + k / 3;  // x - 1 .. x + 1, shifted by one
        if (row_x < 1 || row_x - 1 > kCellTop || row_y < 1 || row_y - 1 > kCellTop) continue;
        size_t* finger = fingers ? fingers + 2 * k : nullptr;
        b.begin[b.count] = first_in_cell(items, count, cell_key(row_x - 1, row_y - 1, z_low),
                                         finger ? finger[0] : member);
        b.end[b.count] = first_in_cell(items, count, cell_key(row_x - 1, row_y - 1, z_high) + 1,
                                       finger ? finger[1] : member);
        if (finger) {
            finger[0] = b.begin[b.count] < count ? b.begin[b.count] : count - 1;
            finger[1] = b.end[b.count] < count ? b.end[b.count] : count - 1;
        }
        if (b.end[b.count] > b.begin[b.count]) ++b.count;
    }
    return b;
}

// The items of the cells around items[member]'s.
static inline CellBlock block_around(const GridItem* items, size_t count, size_t member,
                                     size_t* fingers = nullptr) {
    return block_of_cell(items, count, items[member].cell, member, fingers);
}

// The samples of the scale measures are taken by a hash of the coordinates, about one
// point in `step`, so that they do not depend on the order of the points.
static inline uint32_t sample_step(size_t count, size_t most) {
    const size_t step = count > most ? (count + most - 1) / most : 1;
    return step < UINT32_MAX ? static_cast<uint32_t>(step) : UINT32_MAX;
}

static inline bool sampled_point(Vec3 p, uint32_t step) {
    double z = p.z + 0.0;
    uint64_t bz;
    std::memcpy(&bz, &z, sizeof bz);
    const uint32_t h = mix32(coordinate_hash(p.x, p.y) ^ static_cast<uint32_t>(bz) ^
                             mix32(static_cast<uint32_t>(bz >> 32)));
    return step == 1 || h % step == 0;
}

// The distance that nine points in ten do not exceed to their nearest distinct point, as
// the top of its half-octave; 0 when more than a tenth find none within a cell. Measured
// on about `most_sampled` points (see sample_step): a decile needs no more.
static inline double nearest_distance_decile(const CloudReader& reader, const CellScratch& g,
                                      size_t count, double side, size_t most_sampled) {
    const GridItem* items = g.items;
    for (size_t i = 0; i < count; ++i) g.sorted[i] = reader.point(items[i].index);
    const uint32_t step = sample_step(count, most_sampled);
    size_t histogram[kNearestBins] = {}, sampled = 0;
    for (size_t first = 0; first < count;) {
        size_t last = first;
        while (last < count && items[last].cell == items[first].cell) ++last;
        bool has_block = false;
        CellBlock block;
        for (size_t i = first; i < last; ++i) {
            const Vec3 p = g.sorted[i];
            if (!sampled_point(p, step)) continue;
            if (!has_block) block = block_around(items, count, first);
            has_block = true;
            ++sampled;
            double nearest = side * side;
            uint32_t seen = 0;
            for (uint32_t k = 0; k < block.count && seen < kNearestCandidates; ++k)
                for (size_t j = block.begin[k]; j < block.end[k] && seen < kNearestCandidates; ++j) {
                    const Vec3 d = g.sorted[j] - p;
                    const double q = dot(d, d);
                    ++seen;
                    if (q > 0 && q < nearest) nearest = q;  // not itself, nor a duplicate
                }
            int e = 0;
            std::frexp(nearest / (side * side), &e);  // in [2^(e-1), 2^e): e <= 0 if found
            const uint32_t bin = e > 0 ? kNearestBins - 1
                                : static_cast<uint32_t>(-e) < kNearestBins - 2 ? static_cast<uint32_t>(-e)
                                                                               : kNearestBins - 2;
            ++histogram[bin];
        }
        first = last;
    }
    size_t above = histogram[kNearestBins - 1];
    if (10 * above > sampled) return 0;
    for (uint32_t b = 0; b + 1 < kNearestBins; ++b) {
        above += histogram[b];
        if (10 * above > sampled) return side * std::sqrt(std::ldexp(1.0, -static_cast<int>(b)));
    }
    return side * std::sqrt(std::ldexp(1.0, -static_cast<int>(kNearestBins - 2)));
}

// The valid points' bounding box and count.
struct CloudBox {
    Vec3 low, high;
    size_t valid;
};

static inline CloudBox box_of(const CloudReader& reader, size_t count) {
    CloudBox box = {{DBL_MAX, DBL_MAX, DBL_MAX}, {-DBL_MAX, -DBL_MAX, -DBL_MAX}, 0};
    for (size_t i = 0; i < count; ++i) {
        if (!reader.valid(i)) continue;
        const Vec3 p = reader.point(i);
        const Vec3 lo = box.low, hi = box.high;
        box.low = {p.x < lo.x ? p.x : lo.x, p.y < lo.y ? p.y : lo.y, p.z < lo.z ? p.z : lo.z};
        box.high = {p.x > hi.x ? p.x : hi.x, p.y > hi.y ? p.y : hi.y, p.z > hi.z ? p.z : hi.z};
        ++box.valid;
    }
    return box;
}

// The cloud's scale d (see "outliers" above): the distance that nine points in ten do not
// exceed to their nearest distinct point, on grids of cells of about 4 points; 0 where no
// grid serves. A box wider than the double range (points near +-1e308) gives an infinite
// side, which is refused: such a cloud has no scale.
// Where one cell of the grid (items sorted by cell) holds more than half the points: the
// cell side that spreads its points as nearest_spacing spreads the whole cloud's first
// (from its points' own box); 0 otherwise, or if they are all at one place.
static inline double crowded_cell_side(const CloudReader& reader, const GridItem* items, size_t n) {
    for (size_t first = 0; first < n;) {
        size_t last = first;
        while (last < n && items[last].cell == items[first].cell) ++last;
        if (2 * (last - first) > n) {
            Vec3 low = reader.point(items[first].index), high = low;
            for (size_t i = first + 1; i < last; ++i) {
                const Vec3 p = reader.point(items[i].index);
                low = {p.x < low.x ? p.x : low.x, p.y < low.y ? p.y : low.y, p.z < low.z ? p.z : low.z};
                high = {p.x > high.x ? p.x : high.x, p.y > high.y ? p.y : high.y,
                        p.z > high.z ? p.z : high.z};
            }
            const Vec3 half = scaled(high, 0.5) - scaled(low, 0.5);
            return 4 * std::sqrt(dot(half, half)) / std::sqrt(static_cast<double>(last - first));
        }
        first = last;
    }
    return 0;
}

static inline double nearest_spacing(const CloudReader& reader, size_t count, const CloudBox& box,
                              CellScratch& g, size_t most_sampled) {
    const Vec3 half = scaled(box.high - box.low, 0.5);
    double side = 4 * std::sqrt(dot(half, half)) / std::sqrt(static_cast<double>(box.valid));
    double nearest = 0;
    for (uint32_t tries = 0; nearest == 0 && tries < kGridTries; ++tries) {
        if (!(side * side > 0) || !is_finite(side * side)) break;
        const size_t n = sort_into_cells(reader, count, box.low, side, g);
        size_t occupied = 0;
        for (size_t i = 0; i < n; ++i) occupied += i == 0 || g.items[i].cell != g.items[i - 1].cell;
        if (n > kCrowdedCell * occupied) {  // as on a surface: cells of 4 points on average
            const double shrink = std::sqrt(4 * static_cast<double>(occupied) / static_cast<double>(n));
            side *= shrink > 0.0625 ? shrink : 0.0625;
            // Most points in one cell, far smaller than the whole (a speck far away set the
            // box): the cells follow that cell's own points instead.
            const double crowd = crowded_cell_side(reader, g.items, n);
            if (crowd > 0 && crowd < side) side = crowd;
            continue;
        }
        nearest = nearest_distance_decile(reader, g, n, side, most_sampled);
        side *= 4;
    }
    return nearest;
}

// Marks the outliers in `dropped` (zeroed, a bit per point) and returns how many; from
// here on reader.valid() leaves them out. See "outliers" above.
static inline size_t drop_outliers_of(CloudReader& reader, size_t count, unsigned char* dropped,
                               CellScratch& g) {
    reader.dropped = dropped;
    size_t total = 0;
    for (uint32_t round = 0; round < kOutlierRounds; ++round) {
        const CloudBox box = box_of(reader, count);
        if (box.valid < 2 * kOutlierNeighbours) break;
        const double nearest = nearest_spacing(reader, count, box, g, kDecileSample);
        if (!(nearest > 0)) break;
        const size_t n = sort_into_cells(reader, count, box.low, kOutlierReach * nearest, g);
        const GridItem* items = g.items;
        size_t found = 0;
        for (size_t first = 0; first < n;) {
            size_t last = first;
            while (last < n && items[last].cell == items[first].cell) ++last;
            if (block_around(items, n, first).points() < kOutlierNeighbours)
                for (size_t i = first; i < last; ++i) {
                    dropped[items[i].index >> 3] |= static_cast<unsigned char>(1u << (items[i].index & 7));
                    ++found;
                }
            first = last;
        }
        total += found;
        if (found == 0) break;
    }
    return total;
}

// The drop_outliers step: the bitmap stays in `arena` for the whole call (reader.dropped),
// the grid's scratch is given back. False if the workspace is too small.
static inline bool find_outliers(CloudReader& reader, size_t count, Arena& arena, Report& rep) {
    unsigned char* dropped = arena.alloc<unsigned char>(count / 8 + 1);
    const size_t mark = arena.mark();
    CellScratch g = allocate_cell_scratch(arena, count);
    if (arena.failed) return false;
    std::memset(dropped, 0, count / 8 + 1);
    rep.points.outlier_count = drop_outliers_of(reader, count, dropped, g);
    rep.points.rejected_count += rep.points.outlier_count;
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh

// >>cloud ================================================================================
// Reading the cloud: invalid points refused or counted, outliers left out, sums.

namespace stratmesh {
namespace detail {

// What one pass over the cloud learns, for reject_invalid_points and choose_frame: how many
// points are valid, how many distinct positions they take (counted up to 3), and their sums
// and extremes. Coordinates near the top of the double range overflow the sum: then the
// sum of the points scaled down by 2^-40 (exactly), which leaves room for 2^32 points, is
// used.
struct CloudSums {
    size_t valid;
    uint32_t distinct;
    double total[3], small_total[3], lowest[3], highest[3];
};

// Counts the distinct positions among points given one by one, up to 3 (two are kept: the
// third ends the count).
struct DistinctPoints {
    uint32_t count;
    Vec3 seen[2];
    void add(Vec3 p) {
        if (count >= 3) return;
        for (uint32_t k = 0; k < count; ++k)
            if (p.x == seen[k].x && p.y == seen[k].y && p.z == seen[k].z) return;
        if (count < 2) seen[count] = p;
        ++count;
    }
};

static inline CloudSums sum_cloud(const CloudReader& cloud, size_t count) {
    CloudSums s = {0, 0, {0, 0, 0}, {0, 0, 0}, {DBL_MAX, DBL_MAX, DBL_MAX},
                   {-DBL_MAX, -DBL_MAX, -DBL_MAX}};
    DistinctPoints distinct = {0, {}};
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        const Vec3 p = cloud.point(i);
        distinct.add(p);
        const double c[3] = {p.x, p.y, p.z};
        for (int k = 0; k < 3; ++k) {
            s.total[k] += c[k];
            s.small_total[k] += c[k] * 0x1p-40;
            if (c[k] < s.lowest[k]) s.lowest[k] = c[k];
            if (c[k] > s.highest[k]) s.highest[k] = c[k];
        }
        ++s.valid;
    }
    s.distinct = distinct.count;
    return s;
}

// The bytes the cloud's coordinates lie in.
static inline ByteRange cloud_bytes(const Cloud& cloud) {
    const size_t point_bytes = 3 * (cloud.scalar == Scalar::float32 ? sizeof(float) : sizeof(double));
    return strided_range(cloud.xyz, cloud.count, cloud.stride_bytes ? cloud.stride_bytes : point_bytes,
                         point_bytes);
}

// True if any two of the caller's buffers share a byte (the report and its layer array
// included): checked before anything is written. A count beyond the limit is refused as
// too_many_points instead.
static inline bool reconstruct_buffers_overlap(const Cloud& cloud, void* workspace,
                                        size_t workspace_bytes, uint32_t* triangles,
                                        size_t triangle_capacity, size_t* triangle_count,
                                        const Report* report) {
    if (cloud.count > kMaxPoints - 1) return false;
    const ByteRange buffers[] = {
        cloud_bytes(cloud),
        byte_range(workspace, workspace_bytes),
        byte_range(triangles, saturating_product(triangle_capacity, 3 * sizeof(uint32_t))),
        byte_range(triangle_count, sizeof(size_t)),
        byte_range(report, sizeof(Report)),
        byte_range(report ? report->layers.info : nullptr,
                   report ? saturating_product(report->layers.info_capacity, sizeof(LayerInfo)) : 0),
        byte_range(kFindParts && report ? report->parts.info : nullptr,
                   kFindParts && report ? saturating_product(report->parts.info_capacity, sizeof(PartInfo)) : 0)};
    return any_overlap(buffers, 7);
}

static inline Status check_reconstruct_arguments(const Cloud& cloud, uint32_t* triangles,
                                          size_t triangle_capacity, size_t* triangle_count,
                                          void* workspace, Report& rep) {
    rep.detail = "an argument is invalid: a null pointer with a non-zero count, a stride "
                 "smaller than one point, an unknown scalar type or a null triangle_count";
    if (!triangle_count) return Status::invalid_argument;
    if (cloud.count > kMaxPoints - 1) {
        rep.detail = "more points than 32-bit triangle indices can address";
        return Status::too_many_points;
    }
    size_t scalar = cloud.scalar == Scalar::float32 ? sizeof(float)
                  : cloud.scalar == Scalar::float64 ? sizeof(double) : 0;
    if (scalar == 0) return Status::invalid_argument;
    if (cloud.stride_bytes != 0 && cloud.stride_bytes < 3 * scalar)
        return Status::invalid_argument;
    if (cloud.count > 0 && (!cloud.xyz || !workspace)) return Status::invalid_argument;
    if (triangle_capacity > 0 && !triangles) return Status::invalid_argument;
    rep.detail = nullptr;
    return Status::ok;
}

// Reads a cloud that passed check_reconstruct_arguments.
static inline CloudReader reader_of(const Cloud& cloud) {
    size_t scalar = cloud.scalar == Scalar::float32 ? sizeof(float) : sizeof(double);
    return {static_cast<const unsigned char*>(cloud.xyz),
            cloud.stride_bytes ? cloud.stride_bytes : 3 * scalar, cloud.scalar == Scalar::float32, nullptr};
}

const char* const kInvalidPointDetail =
    "a point has a NaN or infinite coordinate (see first_invalid_index; the "
    "skip_invalid_points flag skips such points instead)";

// Where a cloud of `count` points (`sums` is its sum_cloud) is refused with invalid_point:
// at its first point with a NaN or infinite coordinate, unless the skip_invalid_points flag
// is given. `count` if it is not refused.
static inline size_t refused_at(const CloudReader& reader, size_t count, const CloudSums& sums,
                         const Options& options) {
    if (sums.valid == count || (options.flags & skip_invalid_points)) return count;
    size_t first = 0;
    while (reader.valid(first)) ++first;
    return first;
}

// Counts the points with a NaN or infinite coordinate in rep.points.rejected_count, or refuses the
// cloud (see refused_at).
static inline Status reject_invalid_points(const CloudReader& reader, size_t count,
                                    const CloudSums& sums, const Options& options, Report& rep) {
    const size_t first = refused_at(reader, count, sums, options);
    if (first < count) {
        rep.points.first_invalid_index = first;
        rep.points.rejected_count = count;
        rep.detail = kInvalidPointDetail;
        return Status::invalid_point;
    }
    rep.points.rejected_count += count - sums.valid;
    return Status::ok;
}

// A cloud as a tube reads it: in place, the points left out (outliers, or the points of
// other parts) marked in the reader's optional bitmap, and the sums of the points kept.
struct TubeInput {
    CloudReader reader;
    size_t count;
    CloudSums sums;
};

// Whether this build holds every feature the flags ask for (STRATMESH_SMALL_CODE leaves
// some out).
static inline bool flags_compiled(const Options& options) {
    const uint32_t f = options.flags;
    return (kDropOutliers || !(f & drop_outliers)) && (kSurfaceFlips || !(f & surface_flips)) &&
           (kClosedEnds || !(f & ends_are_cuts));
}

const char* const kNotCompiledDetail =
    "the options ask for a feature this build leaves out (STRATMESH_SMALL_CODE)";

}  // namespace detail
}  // namespace stratmesh

// >>jobs =================================================================================
// The caller's callbacks: progress, and batches of jobs for the runner.

namespace stratmesh {
namespace detail {

static inline void notify(const Options& options, Phase phase, double fraction) {
    if (options.progress) options.progress(options.progress_user, phase, fraction);
}

// ---- jobs on the caller's runner ----
//
// Every batch of jobs reaches Options::run_jobs through run_jobs below, which holds the
// runner to its contract (see JobRunner): an index outside the batch is ignored, a job run
// again does nothing, and a job the runner skipped is done afterwards as the batch says.

// Whether work is cut into jobs: a runner given, in a build that has them.
static inline bool has_runner(const Options& options) {
    return kParallelLayers && options.run_jobs != nullptr;
}

template <class Job> struct JobBatch {
    const Job* job;
    uint32_t count;
    bool done[kMaxJobs];
};

template <class Job> static inline void run_batch_job(void* context, uint32_t index) {
    JobBatch<Job>& batch = *static_cast<JobBatch<Job>*>(context);
    if (index >= batch.count || batch.done[index]) return;  // no job of ours, or done already
    (*batch.job)(index);
    batch.done[index] = true;
}

// Runs job(k) for k in [0, count), count <= kMaxJobs, on the caller's runner where there is
// one. With `redo_skipped`, each job the runner skipped, or every job without a runner, is
// then run here in order; else it is left undone (the layers not done ahead are
// triangulated by their groups).
template <class Job>
static inline void run_jobs(const Options& options, uint32_t count, bool redo_skipped,
                            const Job& job) {
    JobBatch<Job> batch = {&job, count, {}};
    if (has_runner(options)) options.run_jobs(options.jobs_user, count, run_batch_job<Job>, &batch);
    for (uint32_t k = 0; redo_skipped && k < count; ++k)
        if (!batch.done[k]) job(k);
}

// ---- passes over all points as jobs ----
//
// With a runner, a pass over all points that gives the same bits in any order (grouping
// the points by layer) is cut into kPassRuns runs of consecutive points, run as jobs.
const uint32_t kPassRuns = 16;
static_assert(kPassRuns <= kMaxJobs, "a pass's runs are one batch of jobs");

// The first point of run k of `count` points.
static inline size_t run_start(size_t count, uint32_t k) {
    return static_cast<size_t>(static_cast<uint64_t>(count) * k / kPassRuns);
}

// Runs pass.run(k) for every run k: as jobs with a runner, else in order.
template <class Pass> static inline void run_pass(const Options& options, Pass& pass) {
    run_jobs(options, kPassRuns, true, [&pass](uint32_t k) { pass.run(k); });
}

}  // namespace detail
}  // namespace stratmesh

// >>request ==============================================================================
// What one tube is asked for: axis, layers, ends, caps, origin, read once from Options.
//
// reconstruct() meshes several tubes where the cloud parts: the trunk, each branch, the
// one tube they are weighed against, and the samples the automatic axis is chosen on. Each
// has its own axis, layers, ends and caps; a TubeRequest says them, made once from the
// caller's Options (tube_request()), and each step asks for its tube with a request of its
// own. The caller's Options are only read: for the callbacks and the invalid points.

namespace stratmesh {
namespace detail {

// The layers asked for (see Options::cuts): the cuts, or `count` equal layers, or layers
// of about `height` (at most one of them: layer_choice_refusal()), else automatic.
struct LayerRequest {
    const double* cuts;
    size_t cut_count;
    uint32_t count;
    double height;
};

struct TubeRequest {
    Axis axis;              // Axis::automatic until resolve_axis() chooses
    double direction[3];    // with Axis::direction
    LayerRequest layers;
    uint32_t cut_ends;      // ClosedEnd bits: the ends that are cuts, never closed ones
    bool caps;              // the boundary loops closed (add_caps)
    bool surface_flips;
    bool drop_outliers;     // the cloud is read without its outliers
    const double* origin;   // the frame's reference point, or null for the centroid
    Parts parts;            // Parts::one_tube where this build cannot look for parts
    // The caller's Options: its job runner, or null for none (an axis trial).
    const Options* caller;
    // The Options whose progress callback is told, or null: none (a branch, whose progress
    // would run backwards from part to part; an axis trial).
    const Options* progress;
};

// The bits Flags defines: any other is refused.
const uint32_t kDefinedFlags =
    skip_invalid_points | add_caps | origin_given | drop_outliers | surface_flips | ends_are_cuts;

// Why a call that takes Options refuses them with invalid_argument, or null: a flag bit
// that Flags does not define, or a Parts value outside the enum.
static inline const char* options_refusal(const Options& options) {
    if (options.flags & ~kDefinedFlags) return "Options::flags has a bit that Flags does not define";
    if (static_cast<uint32_t>(options.parts) > static_cast<uint32_t>(Parts::apart))
        return "Options::parts is not a Parts value";
    return nullptr;
}

// Why reconstruct() and the stream refuse the layer options with invalid_argument, or
// null: more than one of the cuts, layer_count and layer_height is given, which would
// leave one of them unused.
static inline const char* layer_choice_refusal(const Options& options) {
    const int given = (options.cut_count > 0 ? 1 : 0) + (options.layer_count > 0 ? 1 : 0) +
                      (options.layer_height > 0 ? 1 : 0);
    return given > 1 ? "give at most one of Options::cuts, layer_count and layer_height" : nullptr;
}

static inline TubeRequest tube_request(const Options& options) {
    const uint32_t f = options.flags;
    return {options.axis,
            {options.direction[0], options.direction[1], options.direction[2]},
            {options.cuts, options.cut_count, options.layer_count, options.layer_height},
            kClosedEnds && (f & ends_are_cuts) ? closed_bottom | closed_top : 0u,
            (f & add_caps) != 0,
            kSurfaceFlips && (f & surface_flips),
            kDropOutliers && (f & drop_outliers),
            (f & origin_given) ? options.origin : nullptr,
            kFindParts ? options.parts : Parts::one_tube,
            &options,
            &options};
}

// Sets the request's axis to a direction.
static inline void set_direction(TubeRequest& request, const double* direction) {
    request.axis = Axis::direction;
    for (int k = 0; k < 3; ++k) request.direction[k] = direction[k];
}

const Options kNoCallbacks = {};

// The Options whose job runner a tube hands its jobs to (none in an axis trial).
static inline const Options& jobs_of(const TubeRequest& request) {
    return request.caller ? *request.caller : kNoCallbacks;
}

// Phase progress, to the caller's callback where the request reports progress.
static inline void notify(const TubeRequest& request, Phase phase, double fraction) {
    if (request.progress) notify(*request.progress, phase, fraction);
}

}  // namespace detail
}  // namespace stratmesh

// >>frame ================================================================================
// The frame the layers are cut in: its axis, origin and scale.
//
// The cloud is expressed in a frame whose third axis is the stacking axis and whose origin
// is the centroid, so that clouds far from the origin (georeferenced scans) keep their
// millimetres; a power of two brings its extent near 1.

namespace stratmesh {
namespace detail {

// Coordinates in the reconstruction frame: (x, y) across the axis, h along it.
struct Local {
    double x, y, h;
};

struct Frame {
    Vec3 origin, e1, e2, axis;  // (e1, e2, axis) is right-handed and orthonormal
    // A power of two that brings the cloud's extent near 1, so that squared distances
    // neither overflow (a cloud at 1e200) nor underflow (at 1e-200); being a power of two,
    // it changes no rounding and the triangles do not depend on it.
    double scale;
    // Set when the cloud spans more than the largest double (coordinates of both signs
    // near 1e308): p - origin would overflow, so halves are subtracted instead.
    bool halved;
    Vec3 half_origin;
    // Layers are flipped on the surface (the surface_flips flag; see "flips on the surface"
    // in >>layer triangulation).
    bool surface_flips;
    // The surface's ends (kLowPole, kHighPole) never taken for a closed one
    // (TubeRequest::cut_ends); 0 without kClosedEnds.
    uint32_t cut_ends;
    // The valid points' lowest and highest coordinates (set by choose_frame with kFastLoops).
    Vec3 low, high;
    // The cloud's own extent over the frame's, which also covers the way to a given origin:
    // 1 without origin_given.
    double cloud_share;
    // (p - origin) * scale, without overflow.
    Vec3 offset(Vec3 p) const {
        if (halved) return scaled(scaled(p, 0.5) - half_origin, 2 * scale);
        return scaled(p - origin, scale);
    }
    Local local(Vec3 p) const {
        Vec3 d = offset(p);
        return {dot(d, e1), dot(d, e2), dot(d, axis)};
    }
    // local(p).h alone, the same bits.
    double height(Vec3 p) const { return dot(offset(p), axis); }
    // A frame height back as the user's coordinate along the axis, dot(point, axis).
    double user_height(double h) const { return h / scale + dot(origin, axis); }
};

// The power of two 2^-e with 2^e just above `extent`, within [2^-1000, 2^1000].
STRATMESH_SMALL_NOINLINE static inline double scale_for_extent(double extent) {
    if (!(extent > 0) || !is_finite(extent)) return 1;
    int exponent = 0;
    std::frexp(extent, &exponent);
    if (exponent > 1000) exponent = 1000;
    if (exponent < -1000) exponent = -1000;
    return std::ldexp(1.0, -exponent);
}

// The principal direction of a symmetric 3x3 matrix by power iteration from its largest
// column; a fixed number of steps keeps the cost bounded and the result deterministic.
static inline Vec3 principal_direction(const double m[3][3]) {
    Vec3 cols[3] = {{m[0][0], m[1][0], m[2][0]}, {m[0][1], m[1][1], m[2][1]},
                    {m[0][2], m[1][2], m[2][2]}};
    Vec3 v = cols[0];
    for (const Vec3& c : cols)
        if (dot(c, c) > dot(v, v)) v = c;
    if (!normalize(v)) return {0, 0, 1};
    for (int step = 0; step < 100; ++step) {
        Vec3 w = {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
                  m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                  m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
        if (!normalize(w)) break;
        v = w;
    }
    // The sign of an eigenvector is arbitrary: point it along its largest component.
    double big = v.x;
    if (abs_value(v.y) > abs_value(big)) big = v.y;
    if (abs_value(v.z) > abs_value(big)) big = v.z;
    return big < 0 ? scaled(v, -1.0) : v;
}

// The frame of the points summed in `sums`: centroid origin, axis from the options (an
// explicit one: Axis::automatic is resolved before, see choose_axis), e1/e2 completing it.
// How far a given origin may lie from the cloud's bounding box, per coordinate, in
// multiples of the box's largest side. Seen from farther, the whole cloud lies within
// 2^-32 radians of one direction and its offsets from the origin keep fewer than 21 of
// their 53 bits for the cloud's own shape: no unrolling around it means anything.
const double kOriginReach = 0x1p32;

// Whether `origin` lies within kOriginReach times the largest side of the box [low, high]
// of it (halves, so that nothing overflows). A box of one point reaches everywhere.
static inline bool origin_in_reach(Vec3 origin, Vec3 low, Vec3 high) {
    const Vec3 half_low = scaled(low, 0.5), half_high = scaled(high, 0.5);
    const Vec3 half_origin = scaled(origin, 0.5);
    const Vec3 side = half_high - half_low;
    const Vec3 below = half_low - half_origin, above = half_origin - half_high;
    const Vec3 way = {below.x > above.x ? below.x : above.x, below.y > above.y ? below.y : above.y,
                      below.z > above.z ? below.z : above.z};
    const double reach = largest_of(side);
    return reach == 0 || largest_of(way) <= kOriginReach * reach;
}

// Why a given origin cannot serve as the frame's, or null if it can (or none is given): it
// is NaN or infinite, or lies beyond kOriginReach of the valid points summed in `sums`.
static inline const char* origin_refusal(const double* origin, const CloudSums& sums) {
    if (!origin) return nullptr;
    const Vec3 given = {origin[0], origin[1], origin[2]};
    if (!(is_finite(given.x) && is_finite(given.y) && is_finite(given.z)))
        return "the given origin is NaN or infinite";
    const Vec3 low = {sums.lowest[0], sums.lowest[1], sums.lowest[2]};
    const Vec3 high = {sums.highest[0], sums.highest[1], sums.highest[2]};
    if (sums.valid > 0 && !origin_in_reach(given, low, high))
        return "the given origin lies farther from the cloud than 2^32 times the cloud's size: "
               "no unrolling around it means anything (give a nearer origin, or none)";
    return nullptr;
}

static inline const char* origin_refusal(const Options& options, const CloudSums& sums) {
    return origin_refusal((options.flags & origin_given) ? options.origin : nullptr, sums);
}

static inline Status choose_frame(const CloudSums& sums, const TubeRequest& request, Frame& frame) {
    const size_t valid = sums.valid;
    const Vec3 sum = {sums.total[0], sums.total[1], sums.total[2]};
    const Vec3 small_sum = {sums.small_total[0], sums.small_total[1], sums.small_total[2]};
    const Vec3 low = {sums.lowest[0], sums.lowest[1], sums.lowest[2]};
    const Vec3 high = {sums.highest[0], sums.highest[1], sums.highest[2]};
    if (kFastLoops) {
        frame.low = low;
        frame.high = high;
    }
    if (!(is_finite(sum.x) && is_finite(sum.y) && is_finite(sum.z)))
        frame.origin = scaled(scaled(small_sum, 1.0 / static_cast<double>(valid)), 0x1p40);
    else
        frame.origin = valid ? scaled(sum, 1.0 / static_cast<double>(valid)) : Vec3{0, 0, 0};
    Vec3 size = valid ? high - low : Vec3{0, 0, 0};
    Vec3 half_size = valid ? scaled(high, 0.5) - scaled(low, 0.5) : Vec3{0, 0, 0};
    const double own_half_extent = largest_of(half_size);
    if (request.origin) {
        if (origin_refusal(request.origin, sums)) return Status::invalid_origin;
        const Vec3 given = {request.origin[0], request.origin[1], request.origin[2]};
        // The extent covers the way from the given origin to the cloud, so the frame's
        // coordinates stay near 1 however far the origin is.
        Vec3 way = scaled(frame.origin, 0.5) - scaled(given, 0.5);
        way = {abs_value(way.x), abs_value(way.y), abs_value(way.z)};
        half_size = {half_size.x + way.x, half_size.y + way.y, half_size.z + way.z};
        size = {size.x + 2 * way.x, size.y + 2 * way.y, size.z + 2 * way.z};
        frame.origin = given;
    }
    const double half_extent = largest_of(half_size);
    frame.cloud_share = half_extent > 0 ? own_half_extent / half_extent : 1;
    frame.halved = !(is_finite(size.x) && is_finite(size.y) && is_finite(size.z));
    if (frame.halved) size = half_size;
    frame.half_origin = scaled(frame.origin, 0.5);
    double extent = size.x > size.y ? size.x : size.y;
    if (size.z > extent) extent = size.z;
    frame.scale = scale_for_extent(extent) * (frame.halved ? 0.5 : 1.0);
    Vec3 axis = {0, 0, 1};
    switch (request.axis) {
    case Axis::x: axis = {1, 0, 0}; break;
    case Axis::y: axis = {0, 1, 0}; break;
    case Axis::z: axis = {0, 0, 1}; break;
    case Axis::direction:
        axis = {request.direction[0], request.direction[1], request.direction[2]};
        if (!unit_direction(axis)) return Status::invalid_axis;
        break;
    default: return Status::invalid_axis;
    }
    // e1: the coordinate axis least aligned with the stacking axis, made orthogonal.
    Vec3 e1 = cross(axis_least_along(axis), axis);
    if (!normalize(e1)) return Status::invalid_axis;
    frame.axis = axis;
    frame.surface_flips = request.surface_flips;
    frame.cut_ends = request.cut_ends;
    frame.e1 = e1;
    frame.e2 = cross(axis, e1);
    return Status::ok;
}

static inline Status choose_frame(const CloudSums& sums, const Options& options, Frame& frame) {
    return choose_frame(sums, tube_request(options), frame);
}

// The lowest and highest frame height of the valid points.
static inline void height_range(const CloudReader& cloud, size_t count, const Frame& frame, double* lo,
                         double* hi) {
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        const double h = frame.height(cloud.point(i));
        if (h < *lo) *lo = h;
        if (h > *hi) *hi = h;
    }
}

// height_range without a pass over the cloud, where the axis is a coordinate axis (and
// the frame not halved): a height is then (p_k - origin_k) * scale plus zeros, exactly
// that value, and rounding keeps the order, so the lowest and highest coordinates along
// the axis give the same two heights, bit for bit. False otherwise.
static inline bool height_range_from_extremes(const Frame& frame, double* lo, double* hi) {
    const double axis[3] = {frame.axis.x, frame.axis.y, frame.axis.z};
    const double low[3] = {frame.low.x, frame.low.y, frame.low.z};
    const double high[3] = {frame.high.x, frame.high.y, frame.high.z};
    const double origin[3] = {frame.origin.x, frame.origin.y, frame.origin.z};
    for (int k = 0; k < 3; ++k) {
        if (frame.halved || axis[k] != 1 || axis[(k + 1) % 3] != 0 || axis[(k + 2) % 3] != 0)
            continue;
        *lo = (low[k] - origin[k]) * frame.scale;
        *hi = (high[k] - origin[k]) * frame.scale;
        return true;
    }
    return false;
}

STRATMESH_SMALL_NOINLINE static inline void report_frame(const Frame& frame, Report& rep) {
    rep.axis[0] = frame.axis.x;
    rep.axis[1] = frame.axis.y;
    rep.axis[2] = frame.axis.z;
    rep.axis_origin[0] = frame.origin.x;
    rep.axis_origin[1] = frame.origin.y;
    rep.axis_origin[2] = frame.origin.z;
}

}  // namespace detail
}  // namespace stratmesh

// >>layer plan ===========================================================================
// Cuts along the axis: explicit, equal, by height or automatic; points grouped by layer.
//
// Layers are height ranges along the axis; the points are grouped by layer, in input order
// within a layer.

namespace stratmesh {
namespace detail {

// Layer boundaries: bounds[0] = lowest height, bounds[count] = highest, layer i holds the
// heights in [bounds[i] - tolerance, bounds[i+1] - tolerance) (the last layer includes its
// top). The tolerance (2^-40 of the height range) puts a point that lies on a cut up to
// rounding into the layer above, as one exactly on it: with a tilted axis the heights of
// a planar contour (a CT slice, a scan row) differ in their last bits, and a cut on that
// plane would otherwise split the contour between two layers.
struct LayerPlan {
    double* bounds;
    uint32_t count;
    double tolerance;
};

const size_t kMaxAutomaticLayers = 256;

// Heights are divided by at least layer height / kMaxTurns when unrolled, so exp() stays
// far from overflow and the annulus from extreme ratios in very tall, thin layers; a layer
// up to kMaxTurns radii tall unrolls undistorted (see >>unroll).
const double kMaxTurns = 24.0;

// Whether a layer holds kMinLayerRows rows of points (see Options::cuts). With n points
// over height h around radius r (the layer's own), the spacing is about sqrt(2 pi r h / n),
// so the rows number sqrt(h n / (2 pi r)). A stack of planar contours one per layer, as far
// apart as a few point spacings along the contour, passes.
static inline bool thick_enough(size_t points, double height, double radius) {
    const double two_pi = 6.28318530717958647693;
    return static_cast<double>(points) * height >= kMinLayerRows * kMinLayerRows * two_pi * radius;
}

// The number of layers a request can ask for, before empty layers are dropped.
static inline size_t planned_layer_limit(size_t point_count, const LayerRequest& layers) {
    if (layers.cuts && layers.cut_count > 0) return layers.cut_count + 1;
    if (layers.count > 0)
        return layers.count < point_count ? layers.count : (point_count > 0 ? point_count : 1);
    // A target height: never more layers than points.
    if (layers.height > 0) return point_count > 0 ? point_count : 1;
    return kMaxAutomaticLayers;
}

static inline Status validate_layer_options(const Options& options) {
    if (options.cuts && options.cut_count > 0) {
        if (options.cut_count > kMaxPoints) return Status::invalid_layers;
        for (size_t i = 0; i < options.cut_count; ++i)
            if (!is_finite(options.cuts[i])) return Status::invalid_layers;
    } else if (options.cut_count > 0) {
        return Status::invalid_argument;
    }
    if (!is_finite(options.layer_height) || options.layer_height < 0)
        return Status::invalid_layers;
    return Status::ok;
}

static inline bool automatic_layers(const LayerRequest& layers) {
    return !(layers.cuts && layers.cut_count > 0) && layers.count == 0 && layers.height == 0;
}

// Fills plan.bounds (room for planned_layer_limit + 1 entries) for heights [lo, hi] from
// the layers asked for (not automatic_layers): the cuts are coordinates along the axis
// (Frame::user_height of frame heights), the height a length in the cloud's units.
static inline void plan_layers(const LayerRequest& layers, double lo, double hi, size_t point_count,
                        const Frame& frame, LayerPlan& plan) {
    const double cut_offset = dot(frame.origin, frame.axis);
    double* b = plan.bounds;
    uint32_t n = 0;
    b[n++] = lo;
    if (layers.cuts && layers.cut_count > 0) {
        // The cuts inside (lo, hi], sorted, repeats dropped.
        size_t inside = 0;
        for (size_t i = 0; i < layers.cut_count; ++i) {
            double c = (layers.cuts[i] - cut_offset) * frame.scale;
            if (c > lo && c <= hi) b[1 + inside++] = c;
        }
        heap_sort(b + 1, inside);
        for (size_t i = 0; i < inside; ++i)
            if (b[1 + i] > b[n - 1]) b[n++] = b[1 + i];
    } else {
        double height = hi - lo;
        double planned = 1;
        if (layers.count > 0) {
            planned = layers.count;
        } else if (layers.height > 0) {
            planned = std::ceil(height / (layers.height * frame.scale));
        }
        double limit = static_cast<double>(point_count);
        if (!(planned >= 1)) planned = 1;
        if (planned > limit) planned = limit;
        uint32_t count = static_cast<uint32_t>(planned);
        for (uint32_t i = 1; i < count; ++i) {
            double c = lo + height * (static_cast<double>(i) / static_cast<double>(count));
            if (c > b[n - 1] && c < hi) b[n++] = c;
        }
    }
    b[n] = hi;
    plan.count = n;
}

// ---- automatic layers ----------------------------------------------------------------------
//
// The paper's layering rule, made mechanical. The cloud's height range is cut into equal
// bins (about 256 points each, at most kMaxAutomaticLayers); each bin gets its centroid
// across the axis, its mean radius around that centroid and its inner radius (the smallest
// of kProfileSectors sector-mean radii: the cross-section holds a disc about that wide
// around its centroid when it is star-shaped). Then, starting from one layer over
// everything:
//   - a layer is well unrolled when one centre line serves all its cross-sections (every
//     bin's centroid lies within kCentreDrift inner radii of the layer's centre, the
//     count-weighted mean of its bins' centroids, give or take three standard errors of
//     the bin's centroid, so sampling noise alone never cuts) and it is at most kMaxTurns
//     mean radii
//     tall (taller layers unroll with distorted aspect), and it holds at most an eighth of
//     the points (kLayerPointsShare), or kFewestLayerPoints if that is more, so that a
//     large cloud comes in layers that a job runner can triangulate side by side, the same
//     layers whatever the runner;
//   - a layer that is not is cut in two at the bin boundary where the surface changes
//     least: the smallest sum of centroid drift and radius change between the two bins
//     (relative to the radius), plus a penalty where the bins are denser than average, so
//     dense detailed parts (a face, a joint) stay inside one layer. Only boundaries that
//     leave each side a quarter of the layer's bins are candidates, so the splitting
//     depth stays logarithmic.
// The result is the fewest layers that pass, cut where the shape is calm; O(n) passes over
// the points plus O(bins^2) on the profile, deterministic.

const uint32_t kProfileSectors = 8;

const double kCentreDrift = 0.75;

const size_t kLayerPointsShare = 8;

const size_t kFewestLayerPoints = size_t{1} << 16;

const size_t kPointsPerProfileBin = 256;

const double kDensityWeight = 0.5;

struct ProfileBin {
    uint32_t count;
    uint32_t sectors_seen;                  // direction sectors holding a point
    double cx, cy;                          // centroid across the axis
    double mean_radius, inner_radius;       // around the centroid (inner: occupied sectors)
    double square_sum;                      // sum of squared distances from the centroid
    double sector_sum[kProfileSectors];     // sum of distances per direction sector
    uint32_t sector_count[kProfileSectors];
};

// A range of bins [first, end) waiting to be judged.
struct BinRange {
    uint32_t first, end;
};

static inline uint32_t profile_bin_count(size_t valid_points) {
    size_t bins = valid_points / kPointsPerProfileBin;
    if (bins > kMaxAutomaticLayers) bins = kMaxAutomaticLayers;
    return bins < 1 ? 1u : static_cast<uint32_t>(bins);
}

// The scratch the automatic planner takes (released before the layers are built).
static inline void allocate_profile(Arena& arena, uint32_t bins, ProfileBin** profile,
                                    BinRange** ranges, double** cuts) {
    *profile = arena.alloc<ProfileBin>(bins);
    *ranges = arena.alloc<BinRange>(bins);
    *cuts = arena.alloc<double>(bins);
}

static inline uint32_t sector_of(double dx, double dy) {
    uint32_t s = (dx < 0 ? 4u : 0u) + (dy < 0 ? 2u : 0u);
    return s + (abs_value(dx) < abs_value(dy) ? 1u : 0u);
}

static inline void build_profile(const CloudReader& cloud, size_t count, const Frame& frame,
                                 double lo, double hi, ProfileBin* profile, uint32_t bins) {
    std::memset(static_cast<void*>(profile), 0, sizeof(ProfileBin) * bins);
    const double per_height = static_cast<double>(bins) / (hi - lo);
    auto bin_of = [&](double h) {
        double b = (h - lo) * per_height;
        return b >= static_cast<double>(bins - 1) ? bins - 1 : (b > 0 ? static_cast<uint32_t>(b) : 0u);
    };
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        Local p = frame.local(cloud.point(i));
        ProfileBin& bin = profile[bin_of(p.h)];
        ++bin.count;
        bin.cx += p.x;
        bin.cy += p.y;
    }
    for (uint32_t b = 0; b < bins; ++b) {
        if (profile[b].count == 0) continue;
        profile[b].cx /= profile[b].count;
        profile[b].cy /= profile[b].count;
    }
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        Local p = frame.local(cloud.point(i));
        ProfileBin& bin = profile[bin_of(p.h)];
        double dx = p.x - bin.cx, dy = p.y - bin.cy;
        uint32_t s = sector_of(dx, dy);
        bin.sector_sum[s] += std::sqrt(dx * dx + dy * dy);
        bin.square_sum += dx * dx + dy * dy;
        ++bin.sector_count[s];
    }
    for (uint32_t b = 0; b < bins; ++b) {
        ProfileBin& bin = profile[b];
        double total = 0, inner = DBL_MAX;
        for (uint32_t s = 0; s < kProfileSectors; ++s) {
            total += bin.sector_sum[s];
            if (bin.sector_count[s] == 0) continue;
            ++bin.sectors_seen;
            double mean = bin.sector_sum[s] / bin.sector_count[s];
            if (mean < inner) inner = mean;
        }
        bin.mean_radius = bin.count ? total / bin.count : 0.0;
        bin.inner_radius = bin.count ? inner : 0.0;
    }
}

static inline bool well_unrolled(const ProfileBin* profile, BinRange range, double bin_height,
                                 size_t most_points) {
    double cx = 0, cy = 0, radius = 0;
    size_t points = 0;
    for (uint32_t b = range.first; b < range.end; ++b) {
        cx += profile[b].cx * profile[b].count;
        cy += profile[b].cy * profile[b].count;
        radius += profile[b].mean_radius * profile[b].count;
        points += profile[b].count;
    }
    if (points == 0) return true;
    cx /= static_cast<double>(points);
    cy /= static_cast<double>(points);
    radius /= static_cast<double>(points);
    if (bin_height * (range.end - range.first) > kMaxTurns * radius) return false;
    if (points > most_points) return false;
    for (uint32_t b = range.first; b < range.end; ++b) {
        // Too few points to say, or an arc rather than a ring (the slanted end of a scan):
        // such a bin's centroid says nothing about where the centre line must run.
        if (profile[b].count < kPointsPerProfileBin / 4 || profile[b].sectors_seen < kProfileSectors)
            continue;
        double dx = profile[b].cx - cx, dy = profile[b].cy - cy;
        double standard_error = std::sqrt(profile[b].square_sum / (2.0 * profile[b].count * profile[b].count));
        double limit = kCentreDrift * profile[b].inner_radius + 3 * standard_error;
        if (dx * dx + dy * dy > limit * limit) return false;
    }
    return true;
}

// How much the surface changes between bins b - 1 and b, plus the density penalty.
static inline double cut_cost(const ProfileBin* profile, uint32_t b, double mean_count) {
    const ProfileBin& below = profile[b - 1];
    const ProfileBin& above = profile[b];
    double radius = below.mean_radius > above.mean_radius ? below.mean_radius : above.mean_radius;
    if (!(radius > 0)) return 0;  // an empty stretch: the calmest place of all
    double dx = above.cx - below.cx, dy = above.cy - below.cy;
    double change = (std::sqrt(dx * dx + dy * dy) + abs_value(above.mean_radius - below.mean_radius)) / radius;
    double density = (below.count + above.count) / (2 * mean_count) - 1;
    return change + (density > 0 ? kDensityWeight * density : 0.0);
}

// Fills plan.bounds for heights [lo, hi] by the rule above; profile, ranges and cuts hold
// `bins` entries each.
static inline void plan_automatic_layers(const CloudReader& cloud, size_t count, size_t valid,
                                         const Frame& frame, double lo, double hi,
                                         ProfileBin* profile, BinRange* ranges, double* cuts,
                                         uint32_t bins, LayerPlan& plan) {
    build_profile(cloud, count, frame, lo, hi, profile, bins);
    const double bin_height = (hi - lo) / bins;
    const double mean_count = static_cast<double>(valid) / bins;
    const size_t share = valid / kLayerPointsShare;
    const size_t most_points = share > kFewestLayerPoints ? share : kFewestLayerPoints;
    size_t pending = 0, cut_count = 0;
    ranges[pending++] = {0, bins};
    while (pending > 0) {
        BinRange r = ranges[--pending];
        uint32_t width = r.end - r.first;
        if (width < 2 || well_unrolled(profile, r, bin_height, most_points)) continue;
        uint32_t margin = width / 4 > 0 ? width / 4 : 1;
        uint32_t best = r.first + margin;
        double best_cost = DBL_MAX;
        for (uint32_t b = r.first + margin; b <= r.end - margin; ++b) {
            double cost = cut_cost(profile, b, mean_count);
            if (cost < best_cost) {
                best_cost = cost;
                best = b;
            }
        }
        cuts[cut_count++] = lo + bin_height * best;
        // Each split turns one range into two, so at most `bins` are ever pending.
        ranges[pending++] = {r.first, best};
        ranges[pending++] = {best, r.end};
    }
    heap_sort(cuts, cut_count);
    double* bounds = plan.bounds;
    uint32_t n = 0;
    bounds[n++] = lo;
    for (size_t i = 0; i < cut_count; ++i)
        if (cuts[i] > bounds[n - 1] && cuts[i] < hi) bounds[n++] = cuts[i];
    bounds[n] = hi;
    plan.count = n;
}

// The layer of height h: the last k with h >= bounds[k] - tolerance, or 0. `per_height` is
// count / (bounds[count] - bounds[0]). With kFastLoops, the layer h would be in if the
// layers were equal, which they are unless cuts or the automatic plan set them, is tried
// first, with one branch that a million points in no order still predict (a binary
// search's would not); the search is for the rest.
static inline uint32_t layer_of(const LayerPlan& plan, double h, double per_height) {
    const double* bounds = plan.bounds;
    const double tolerance = plan.tolerance;
    const uint32_t last = plan.count - 1;
    const double guess = (h - bounds[0]) * per_height;
    const uint32_t k = guess > 0 ? (guess < last ? static_cast<uint32_t>(guess) : last) : 0;
    if (kFastLoops && ((k == 0) | (h >= bounds[k] - tolerance)) &
                          ((k == last) | (h < bounds[k + 1] - tolerance)))
        return k;
    uint32_t lo = 0, hi = plan.count;  // answer in [lo, hi)
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (h >= plan.bounds[mid] - plan.tolerance)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

// Groups the valid points by layer (input order within a layer): a counting sort, with each
// point's layer kept in `layer` (count entries of scratch) between its two passes. With
// `staged` (optional, as many entries as valid points), the points in frame coordinates
// go there in the same order.
static inline void group_by_layer(const CloudReader& cloud, size_t count, const Frame& frame,
                                  const LayerPlan& plan, uint32_t* layer, Local* staged,
                                  uint32_t* layer_start, uint32_t* order) {
    std::memset(layer_start, 0, sizeof(uint32_t) * (plan.count + 2));
    const double per_height =
        kFastLoops ? plan.count / (plan.bounds[plan.count] - plan.bounds[0]) : 0;
    for (size_t i = 0; i < count; ++i) {
        layer[i] = cloud.valid(i) ? layer_of(plan, frame.height(cloud.point(i)), per_height)
                                  : kNoIndex;
        if (layer[i] != kNoIndex) ++layer_start[layer[i] + 2];
    }
    for (uint32_t k = 0; k < plan.count; ++k) layer_start[k + 2] += layer_start[k + 1];
    for (size_t i = 0; i < count; ++i) {
        if (layer[i] == kNoIndex) continue;
        const uint32_t position = layer_start[layer[i] + 1]++;
        order[position] = static_cast<uint32_t>(i);
        if (staged) staged[position] = frame.local(cloud.point(i));
    }
}

// group_by_layer's counting sort, run by run: first each point's layer and each run's count
// per layer, then (once `first` holds each run's first position per layer) the scatter. The
// positions come out as in group_by_layer.
struct GroupingPass {
    const CloudReader* cloud;
    const Frame* frame;
    const LayerPlan* plan;
    double per_height;
    size_t count;
    uint32_t* layer;
    uint32_t* order;
    uint32_t* counts;    // per run, per layer: its points there
    uint32_t* first;     // per run, per layer: its first position there
    uint32_t* next;      // per run, per layer: the scatter's next position
    bool scatter;

    void run(uint32_t k) {
        const size_t layers = plan->count, begin = run_start(count, k), end = run_start(count, k + 1);
        if (!scatter) {
            uint32_t* c = counts + k * layers;
            std::memset(c, 0, layers * sizeof(uint32_t));
            for (size_t i = begin; i < end; ++i) {
                layer[i] = cloud->valid(i) ? layer_of(*plan, frame->height(cloud->point(i)), per_height)
                                           : kNoIndex;
                if (layer[i] != kNoIndex) ++c[layer[i]];
            }
            return;
        }
        uint32_t* n = next + k * layers;
        std::memcpy(n, first + k * layers, layers * sizeof(uint32_t));
        for (size_t i = begin; i < end; ++i)
            if (layer[i] != kNoIndex) order[n[layer[i]]++] = static_cast<uint32_t>(i);
    }
};

// group_by_layer without staging, as jobs; false (nothing done) where its three tables of a
// count per run and layer would take more than one count per point, or do not fit.
static inline bool group_by_layer_in_jobs(const Options& options, const CloudReader& cloud,
                                          size_t count, const Frame& frame, const LayerPlan& plan,
                                          uint32_t* layer, uint32_t* layer_start, uint32_t* order,
                                          Arena& arena) {
    const size_t table = kPassRuns * static_cast<size_t>(plan.count);
    if (!has_runner(options) || 3 * table > count) return false;
    const size_t mark = arena.mark();
    GroupingPass pass = {&cloud, &frame, &plan, 0, count, layer, order,
                         arena.alloc<uint32_t>(table), arena.alloc<uint32_t>(table),
                         arena.alloc<uint32_t>(table), false};
    if (arena.failed) {
        arena.failed = false;
        arena.rewind(mark);
        return false;
    }
    pass.per_height = kFastLoops ? plan.count / (plan.bounds[plan.count] - plan.bounds[0]) : 0;
    run_pass(options, pass);
    // Layer by layer, run by run: the positions of a counting sort in input order.
    uint32_t position = 0;
    for (uint32_t l = 0; l < plan.count; ++l) {
        layer_start[l] = position;
        for (uint32_t k = 0; k < kPassRuns; ++k) {
            pass.first[k * plan.count + l] = position;
            position += pass.counts[k * plan.count + l];
        }
    }
    layer_start[plan.count] = position;
    pass.scatter = true;
    run_pass(options, pass);
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh

// >>unroll ===============================================================================
// A layer onto its annulus (cylinder and closed ends).
//
// Each layer is projected on a cylinder around its own centre, unrolled to (u, v) =
// (r theta, h) and rolled up again by the conformal map exp((v - v0)/r + i theta) onto a
// planar annulus: the bottom of the layer on the inner side, the top on the outer side.
// The map is conformal, so small triangles keep their shape and the 2D Delaunay criterion
// there is the unrolled one; and the seam along the cut generatrix is closed by
// construction: there is no cut. With a virtual vertex at the annulus centre, the Delaunay
// triangles not touching it are the layer's surface; its link is the layer's bottom loop,
// the convex hull its top loop. No trigonometry is needed: the direction of a point from
// the centre gives e^{i theta} directly.
//
// Centre: the mean of per-sector mean positions (kSectors sectors around the centroid), so
// a side scanned more densely does not pull the centre towards it. Radius: the mean
// distance of the points from that centre: it sets the unrolled aspect (arc length r theta
// against height), so triangles are well shaped on the surface, not only in the plane. A
// layer that folds around that centre may be unrolled around another (see "the centre
// search" in >>layer triangulation); the radius stays.
//
// Closed ends. A scan of a closed object (a bone, a bust on its base, a head's crown) has
// points across its ends, at about one height: on the cylinder a flat base puts every point
// of a radius on one place of the annulus, and a dome's top folds. So where the first or
// the last layer of the surface holds such an end (see find_closed_ends), the points beyond
// a pole height, one radius in from the end (at most three quarters of the layer), are
// projected from the pole (the point of the axis at that height) instead, onto the sphere
// around it, and that sphere is mapped stereographically: the direction at angle phi from
// the end's side of the axis goes to radius e^{(pole - h0)/r} tan(phi / 2) on the annulus
// (the bottom; the top inverts it). At the pole height both maps agree, with the same
// derivative, so the picture stays conformal across it for a dome of the layer's radius;
// the end's point nearest the axis becomes the centre's link (the bottom) or the hull (the
// top): the surface's boundary loop is a small loop around the pole instead of the end's
// rim, and the end is meshed across. On a flat-ended cylinder of 10,000 points the mean
// distance to the true surface fell 7.5 times with one layer (to CGAL's advancing front's),
// 5.6 times over 1 to 24 layers; on half-sphere ends 20%. Open ends are not touched.

namespace stratmesh {
namespace detail {

const uint32_t kSectors = 32;

// e^x with + - * only, so every platform computes the same bits. Arguments are clamped to
// [-64, 64] (a NaN counts as -64): the callers stay within kMaxTurns + 1, except for
// clouds so extreme that a radius overflows or underflows, which must not reach the
// float-to-integer conversion below with an out-of-range value. x = k ln2 / 32 + r with
// |r| <= ln2 / 64 and k = 32 q + j, so e^x = 2^q 2^(j / 32) e^r: the table's 2^(j / 32)
// are correctly rounded, and e^r's series to r^6 / 6! is within 4e-18 of it; within two
// ulp of glibc's exp over [-64, 64] (tests; one measured). The series to r^13 / 13! that
// a reduction to |r| <= ln2 / 2 needs took a fifth of triangulate_layer's own time on a
// tube.
static inline double exp_portable(double x) {
    if (!(x > -64)) x = -64;
    if (x > 64) x = 64;
    // ln2 / 32 in two parts, the first with 32 significant bits: k times it is exact.
    const double step_hi = 6.93147180369123816490e-01 / 32;
    const double step_lo = 1.90821492927058770002e-10 / 32;
    // floor(y) by truncation (|y| < 2956 here): std::floor is a library call per point on
    // x86-64's baseline, which has no rounding instruction (one instruction on ARM).
    const double y = x * (32 * 1.44269504088896338700) + 0.5;
    double k = kFastLoops ? static_cast<double>(static_cast<int32_t>(y)) : std::floor(y);
    if (kFastLoops && k > y) k -= 1;
    const double r = (x - k * step_hi) - k * step_lo;
    static constexpr double inverse_factorials[6] = {1.0 / 720.0, 1.0 / 120.0, 1.0 / 24.0,
                                                     1.0 / 6.0,   0.5,         1.0};
    double p = 0;
    for (double c : inverse_factorials) p = (p + c) * r;
    static constexpr double two_to_thirty_seconds[32] = {
        0x1.0000000000000p+0, 0x1.059b0d3158574p+0, 0x1.0b5586cf9890fp+0, 0x1.11301d0125b51p+0,
        0x1.172b83c7d517bp+0, 0x1.1d4873168b9aap+0, 0x1.2387a6e756238p+0, 0x1.29e9df51fdee1p+0,
        0x1.306fe0a31b715p+0, 0x1.371a7373aa9cbp+0, 0x1.3dea64c123422p+0, 0x1.44e086061892dp+0,
        0x1.4bfdad5362a27p+0, 0x1.5342b569d4f82p+0, 0x1.5ab07dd485429p+0, 0x1.6247eb03a5585p+0,
        0x1.6a09e667f3bcdp+0, 0x1.71f75e8ec5f74p+0, 0x1.7a11473eb0187p+0, 0x1.82589994cce13p+0,
        0x1.8ace5422aa0dbp+0, 0x1.93737b0cdc5e5p+0, 0x1.9c49182a3f090p+0, 0x1.a5503b23e255dp+0,
        0x1.ae89f995ad3adp+0, 0x1.b7f76f2fb5e47p+0, 0x1.c199bdd85529cp+0, 0x1.cb720dcef9069p+0,
        0x1.d5818dcfba487p+0, 0x1.dfc97337b9b5fp+0, 0x1.ea4afa2a490dap+0, 0x1.f50765b6e4540p+0};
    // k + 32 * 96 > 0: its low five bits are j, the others q + 96.
    const int32_t m = static_cast<int32_t>(k) + 32 * 96;
    const double table = two_to_thirty_seconds[m & 31];
    uint64_t bits = static_cast<uint64_t>((m >> 5) - 96 + 1023) << 52;
    double two_q;
    std::memcpy(&two_q, &bits, sizeof two_q);
    return (table + table * p) * two_q;
}

// A monotone stand-in for the polar angle of (dx, dy), in [0, 4): no trigonometry. The
// quadrant picks one of three values by index, not by branch: points in no angular order
// (a layer as the scanner wrote it) would mispredict half of the branches.
STRATMESH_SMALL_NOINLINE static inline double pseudo_angle(double dx, double dy) {
    double sum = abs_value(dx) + abs_value(dy);
    double t = sum > 0 ? dy / sum : 0;  // in [-1, 1]
    if (!kFastLoops) return dx >= 0 ? (t < 0 ? 4 + t : t) : 2 - t;
    const double angles[3] = {t, 4 + t, 2 - t};
    const bool left = !(dx >= 0);
    return angles[2 * static_cast<int>(left) + static_cast<int>(!left & (t < 0))];
}

// The polar angle of (dx, dy) in [0, 2 pi), with + - * / only (the same bits everywhere):
// two argument reductions bring the tangent below tan(pi / 12), where the odd Taylor series
// to x^21 is accurate to about 1e-15.
static inline double polar_angle(double dx, double dy) {
    const double pi = 3.14159265358979323846;
    const double sqrt3 = 1.73205080756887729353;
    double ax = abs_value(dx), ay = abs_value(dy);
    if (ax == 0 && ay == 0) return 0;
    bool swapped = ay > ax;
    double x = swapped ? ax / ay : ay / ax;  // in [0, 1]
    bool shifted = x > 0.26794919243112270;  // tan(pi / 12)
    if (shifted) x = (x * sqrt3 - 1) / (x + sqrt3);
    double x2 = x * x, term = x, sum = x;
    for (int k = 3; k <= 21; k += 2) {
        term *= -x2;
        sum += term / k;
    }
    if (shifted) sum += pi / 6;
    if (swapped) sum = pi / 2 - sum;
    if (dx < 0) sum = pi - sum;
    if (dy < 0) sum = 2 * pi - sum;
    return sum >= 2 * pi ? 0 : sum;
}

struct Cylinder {
    double cx, cy;   // centre across the axis
    double radius;   // unrolling radius
    double h0;       // height mapped to the unit circle
    double scale;    // 1 / max(radius, height / kMaxTurns)
    uint32_t poles;  // kLowPole, kHighPole: the ends projected from a pole (closed ends)
    double pole_low, pole_high;  // the poles' heights: below pole_low, above pole_high
};

const uint32_t kLowPole = closed_bottom, kHighPole = closed_top;

// Direction components smaller than this become 0. No scan resolves angles of 1e-18
// radians, and it keeps the annulus inside the predicates' exact range: radii in
// [e^-64, e^64] (2^-92 to 2^92; beyond a pole, tan(phi / 2) is kept in [2^-60, 1], so
// radii stay in [2^-60, e^24 2^60]) times components in [2^-60, 1] give coordinates, and
// coordinate differences, within a span of 2^296 < 2^320. Without it a cloud with one far
// outlier puts components near 2^-900 on the annulus, where the signs are not exact.
const double kSmallestDirection = 0x1p-60;

// The annulus radius of a point of height h at distance r from the axis: e^{(h - h0) *
// scale}, or beyond a pole the stereographic radius of its direction from the pole (see
// "closed ends" above).
static inline double annulus_radius(const Cylinder& c, double h, double r) {
    const bool low = kClosedEnds && (c.poles & kLowPole) && h < c.pole_low;
    const bool high = kClosedEnds && (c.poles & kHighPole) && h > c.pole_high;
    if (!low && !high) return exp_portable((h - c.h0) * c.scale);
    const double pole = low ? c.pole_low : c.pole_high, depth = low ? pole - h : h - pole;
    // tan(phi / 2) = sin(phi) / (1 + cos(phi)), phi from the axis beyond the pole.
    double half_tangent = r > 0 && is_finite(r) ? r / (depth + std::sqrt(r * r + depth * depth)) : 0;
    if (!(half_tangent > kSmallestDirection)) half_tangent = kSmallestDirection;
    const double at_pole = exp_portable((pole - c.h0) * c.scale);
    return low ? at_pole * half_tangent : at_pole / half_tangent;
}

// The point's place on the annulus: annulus_radius times its direction from the centre
// (points on the centre line take direction e1).
static inline void roll(const Cylinder& c, const Local& p, double* out) {
    double dx = p.x - c.cx, dy = p.y - c.cy;
    double r = std::sqrt(dx * dx + dy * dy);
    double rho = annulus_radius(c, p.h, r);
    if (r > 0 && is_finite(r)) {
        double u = dx / r, v = dy / r;
        out[0] = abs_value(u) < kSmallestDirection ? 0.0 : rho * u;
        out[1] = abs_value(v) < kSmallestDirection ? 0.0 : rho * v;
    } else {
        out[0] = rho;
        out[1] = 0;
    }
}

// The sectors around (cx, cy) that hold some of the points: bit k for sector k (kSectors
// is 32). Every k-th point, at most about kGapSamplePoints of them: a gap of a few sectors
// shows as well in a thousand points as in a million, and the look at every layer's
// neighbour then costs 1% of a tube's time instead of 10%.
const size_t kGapSamplePoints = 1024;

static inline size_t gap_sample_stride(size_t count) { return count / kGapSamplePoints + 1; }

// The sector of direction (dx, dy): kSectors of equal pseudo-angle, counter-clockwise.
static inline uint32_t sector_around(double dx, double dy) {
    const uint32_t s = static_cast<uint32_t>(pseudo_angle(dx, dy) * (kSectors / 4.0));
    return s < kSectors ? s : kSectors - 1;
}

template <class PointAt>
static inline uint32_t sectors_held(const PointAt& point_at, size_t count, double cx, double cy) {
    uint32_t held = 0;
    const size_t stride = gap_sample_stride(count);
    for (size_t i = 0; i < count; i += stride) {
        const Local& p = point_at(i);
        held |= 1u << sector_around(p.x - cx, p.y - cy);
    }
    return held;
}

// The most sectors in a row, around the circle, missing from `held`: 0 for a ring, about
// half of them for a half cylinder.
static inline uint32_t widest_gap(uint32_t held) {
    uint32_t widest = 0, run = 0;
    for (uint32_t k = 0; k < 2 * kSectors && widest < kSectors; ++k) {
        run = (held >> (k % kSectors)) & 1 ? 0 : run + 1;
        if (run > widest) widest = run;
    }
    return widest;
}

// Centre and radius of count points (frame coordinates; point_at(i) gives point i) for
// heights [h0, h1].
template <class PointAt>
static inline Cylinder fit_cylinder(const PointAt& point_at, size_t count, double h0, double h1) {
    double mx = 0, my = 0;
    for (size_t i = 0; i < count; ++i) {
        const Local& p = point_at(i);
        mx += p.x;
        my += p.y;
    }
    double inv = count ? 1.0 / static_cast<double>(count) : 0.0;
    mx *= inv;
    my *= inv;
    // Sector means around the centroid: sector from the signs and ratio of (dx, dy).
    double sx[kSectors] = {}, sy[kSectors] = {};
    uint32_t sn[kSectors] = {};
    for (size_t i = 0; i < count; ++i) {
        const Local& p = point_at(i);
        const uint32_t s = sector_around(p.x - mx, p.y - my);
        sx[s] += p.x;
        sy[s] += p.y;
        ++sn[s];
    }
    double cx = 0, cy = 0;
    uint32_t used = 0;
    for (uint32_t s = 0; s < kSectors; ++s) {
        if (!sn[s]) continue;
        cx += sx[s] / sn[s];
        cy += sy[s] / sn[s];
        ++used;
    }
    Cylinder c;
    c.cx = used ? cx / used : mx;
    c.cy = used ? cy / used : my;
    double rsum = 0;
    for (size_t i = 0; i < count; ++i) {
        const Local& p = point_at(i);
        double dx = p.x - c.cx, dy = p.y - c.cy;
        rsum += std::sqrt(dx * dx + dy * dy);
    }
    c.radius = rsum * inv;
    c.h0 = h0;
    double floor_radius = (h1 - h0) / kMaxTurns;
    double r = c.radius > floor_radius ? c.radius : floor_radius;
    c.scale = r > 0 && is_finite(r) ? 1.0 / r : 1.0;
    if (!is_finite(c.scale)) c.scale = 1.0;  // a subnormal radius
    c.poles = 0;
    c.pole_low = c.pole_high = h0;
    return c;
}

// Triangle abc's normal, twice its area long.
static inline Vec3 normal_of(const Local& pa, const Local& pb, const Local& pc) {
    return cross(Vec3{pb.x - pa.x, pb.y - pa.y, pb.h - pa.h},
                 Vec3{pc.x - pa.x, pc.y - pa.y, pc.h - pa.h});
}

static inline double doubled_area(const Local& pa, const Local& pb, const Local& pc) {
    Vec3 n = normal_of(pa, pb, pc);
    return std::sqrt(dot(n, n));
}

// Whether triangle abc (counter-clockwise seen from outside) has its normal pointing
// towards the cylinder's axis (beyond a pole: towards the pole): a fold.
static inline bool faces_axis(const Local& pa, const Local& pb, const Local& pc, const Cylinder& cyl) {
    Vec3 n = normal_of(pa, pb, pc);
    // From the axis (beyond a pole: the pole) to the centroid, three times over: only the
    // sign of its product with n counts, so no division.
    double rx = (pa.x + pb.x + pc.x) - 3 * cyl.cx;
    double ry = (pa.y + pb.y + pc.y) - 3 * cyl.cy;
    double h = pa.h + pb.h + pc.h, rh = 0;
    if (kClosedEnds && (cyl.poles & kLowPole) && h < 3 * cyl.pole_low) rh = h - 3 * cyl.pole_low;
    if (kClosedEnds && (cyl.poles & kHighPole) && h > 3 * cyl.pole_high)
        rh = h - 3 * cyl.pole_high;
    return n.x * rx + n.y * ry + n.z * rh < 0;
}

// Whether triangle t of a layer's triangulation is on the surface: neither a ghost nor at
// vertex 0, the centre (nor peeled: see peel_loop).
static inline bool on_surface(const Triangulation& tr, uint32_t t) {
    const uint32_t* v = tr.vertex + 3 * t;
    return !tr.is_ghost(t) && v[0] != 0 && v[1] != 0 && v[2] != 0;
}

// Asks for the cache line holding p ahead of its use, where the compiler offers a way
// (GCC, Clang): a hint, which changes nothing but the time.
static inline void prefetch(const void* p) {
#if defined(__GNUC__) || defined(__clang__)
    __builtin_prefetch(p);
#else
    (void)p;
#endif
}

// The surface triangles of a layer's triangulation that face its axis; vertex v is
// points[(v - 1) * stride]. Adds their doubled areas to *area if given. The triangles'
// slots are not in the points' order: with kFastLoops the corners a few triangles ahead
// are prefetched, as the loop otherwise waits on the cache for most of them.
static inline size_t count_folds(const Triangulation& tr, const Local* points, size_t stride,
                          const Cylinder& cyl, double* area) {
    size_t folds = 0;
    const uint32_t ahead = 12;
    for (uint32_t t = 0; t < tr.triangle_count; ++t) {
        if (kFastLoops && t + ahead < tr.triangle_count) {
            const uint32_t* w = tr.vertex + 3 * (t + ahead);
            for (uint32_t i = 0; i < 3; ++i)
                if (w[i] != 0 && w[i] != kGhost) prefetch(points + (w[i] - 1) * stride);
        }
        const uint32_t* v = tr.vertex + 3 * t;
        if (!on_surface(tr, t)) continue;
        const Local &a = points[(v[2] - 1) * stride], &b = points[(v[1] - 1) * stride],
                    &c = points[(v[0] - 1) * stride];
        folds += faces_axis(a, b, c, cyl);
        if (area) *area += doubled_area(a, b, c);
    }
    return folds;
}

// Where reconstructed triangles go: the caller's array, filled in order. Triangles are
// built counter-clockwise on the annulus, where the outside of the surface faces down,
// so they are written reversed. Counting continues past the capacity so the caller can
// be told what is needed; nothing is written past it.
struct TriangleSink {
    uint32_t* triangles;
    size_t capacity;
    size_t count;
    size_t folds;

    // Writes abc, given counter-clockwise on the annulus (so written reversed).
    void write(uint32_t a, uint32_t b, uint32_t c) {
        if (count < capacity) {
            triangles[3 * count] = a;
            triangles[3 * count + 1] = c;
            triangles[3 * count + 2] = b;
        }
        ++count;
    }

    // Writes abc and counts it if it is a fold (the vertices in frame coordinates).
    void emit(uint32_t a, uint32_t b, uint32_t c, const Local& pa, const Local& pb,
              const Local& pc, const Cylinder& cyl) {
        write(a, b, c);
        if (faces_axis(pa, pc, pb, cyl)) ++folds;
    }
};

}  // namespace detail
}  // namespace stratmesh

// >>layer ================================================================================
// One layer on its annulus: its loops and their peeling, closed ends, the centre search.

namespace stratmesh {
namespace detail {

struct LayerLoops {
    uint32_t* bottom;  // layer-local indices, counter-clockwise on the annulus
    uint32_t bottom_count;
    uint32_t* top;
    uint32_t top_count;
    // Per loop vertex, set by triangulate_layer: the pass that peeled it onto the loop
    // (kPassBit up; 0 on the centre's link or the hull); the bits below are the seam's
    // (SurfaceChain::top_unused).
    unsigned char* bottom_flags;
    unsigned char* top_flags;
    // From triangulate_layer: where in the sink its triangles at the bottom loop begin (they
    // come last), and how many of its points have a triangle but are off the bottom loop.
    size_t border_start;
    size_t interior_used;
};

// A layer's points that fell on a vertex already there: duplicates (merged into it) and
// collisions (not vertices).
struct CoincidentPoints {
    size_t duplicates;   // same 3D coordinates as an earlier point
    size_t collisions;   // distinct in 3D, same place on the annulus
};

// Classifies the points the layer's triangulation found on an existing vertex.
struct LayerDuplicates {
    const CloudReader* cloud;
    const uint32_t* ids;    // layer-local index -> reader index
    const uint32_t* order;  // vertex - 1 -> layer-local index (vertex 0 is the centre)
    CoincidentPoints* counts;

    static void report(void* context, uint32_t point, uint32_t vertex) {
        LayerDuplicates* d = static_cast<LayerDuplicates*>(context);
        Vec3 p = d->cloud->point(d->ids[d->order[point - 1]]);
        Vec3 v = d->cloud->point(d->ids[d->order[vertex - 1]]);
        if (p.x == v.x && p.y == v.y && p.z == v.z)
            ++d->counts->duplicates;
        else
            ++d->counts->collisions;
    }
};

// Per vertex of a layer's triangulation, in triangulate_layer (the flip stack's room).
const uint32_t kOnBottomLoop = 1, kEmitted = 2, kOnTopLoop = 4;

// See flip_layer_on_surface.
const uint32_t kFlippedBefore = 8, kFlippedNow = 16, kVisited = 32, kNearFold = 64;

const uint32_t kPassShift = 8;  // above it: the peeling pass that put a vertex on its loop

const uint32_t kPassBit = 3;    // where LayerLoops::bottom_flags and top_flags keep that pass

const unsigned char kPassBits = static_cast<unsigned char>(0xF << kPassBit);

// The last pass those 4 bits hold. Only an end loop of a layer that folds peels further,
// and no band puts its peeled triangles back: its later passes are kept as this one.
const uint32_t kLastPass = 0xF;

const unsigned char kUnpeeled = 0x80;  // in those flags: the band puts the peeled triangle back

// Collects the link of the centre (vertex 0) counter-clockwise into loop, one entry per link
// edge u -> w: the half-edge w -> u of the triangle beyond it. Flags its vertices
// kOnBottomLoop. False if the centre touches the hull: the layer does not surround its axis.
static inline bool centre_link(const Triangulation& tr, uint32_t* loop, uint32_t* count,
                        uint32_t* flags) {
    uint32_t start = kNoIndex;
    for (uint32_t e = 0; e < 3 * tr.triangle_count; ++e)
        if (tr.vertex[e] == 0) {
            start = e;
            break;
        }
    if (start == kNoIndex) return false;
    uint32_t n = 0, e = start;
    do {
        uint32_t u = tr.vertex[next_edge(e)];
        if (u == kGhost || tr.vertex[prev_edge(e)] == kGhost || n > tr.triangle_count)
            return false;
        loop[n++] = tr.twin[next_edge(e)];
        flags[u] = kOnBottomLoop;
        e = tr.twin[prev_edge(e)];  // the next triangle counter-clockwise around the centre
    } while (e != start);
    *count = n;
    return true;
}

// Collects the convex hull counter-clockwise into loop, one entry per hull edge a -> b: that
// half-edge, in the triangle inside. Flags its vertices kOnTopLoop. A ghost (a, b, G) holds
// G -> a, then a -> b; the twin of G -> a is a -> G in the ghost (z, a, G), whose next
// half-edge is G -> z: the next ghost along the hull.
static inline void hull_loop(const Triangulation& tr, uint32_t* loop, uint32_t* count, uint32_t* flags) {
    uint32_t start = 0;
    while (tr.vertex[start] != kGhost) ++start;
    uint32_t n = 0, e = start;
    do {
        loop[n++] = tr.twin[next_edge(e)];
        flags[tr.vertex[next_edge(e)]] |= kOnTopLoop;
        e = next_edge(tr.twin[e]);
    } while (e != start && n <= tr.triangle_count);
    *count = n;
}

// Peeling. Both loops are convex hulls, each in its own picture: the top loop on the
// annulus, the bottom loop on the annulus turned inside out (z -> 1/z maps the centre's
// link to the hull). A hull's edges are chords over the points just inside it, several
// spacings long, and the band to the next layer spanned them with long triangles that cut
// through the surface: with 24 layers on a star-shaped tube the bands held 11% of the
// area, at 5 times the mean distance from the true surface. The next layer's points lie
// beyond the chord, so in one triangulation of both layers the chord's sliver would not
// be there. Hence a loop triangle is peeled off the layer when its angle at the inner
// vertex x is obtuse on the surface (in 3D), and x joins the loop, where the band's
// empty-circle swaps settle it with the other layer's points. Only when x is on no loop
// (the loops stay simple and apart), lies between the edge's ends in angle around the
// centre (the loop still turns monotonically), and the two new loop edges rise at most
// kPeelSlope (45 degrees) on the surface's ends (the first layer's bottom loop, the last
// one's top loop: steeper loops made the caps fail on ragged ends), kInnerPeelSlope (63
// degrees) between layers, where the gentler limit left chords several spacings long (a
// steeper limit brings the layers' seams no closer to the surface and crosses more). And
// only in
// a layer without folds: where the layer is not star-shaped around its centre the loops
// are not monotone around the band's centre either, and longer loops gave the bands more
// self-intersections. Except the surface's end loops, which meet no band (kPeelFoldedEnds):
// a layer folds where the object branches, and at the end the branches' tips stand apart
// (the horns of bench/horned_bust.py): the hull runs from tip to tip and the triangles
// under it are a web across the gap, down to where the branches meet. There an end loop
// peels at any slope short of vertical, up to kFoldedEndPeelPasses passes, and most of the
// web goes (on a bust with horns, half the mean distance to the true surface). A cap
// (add_caps) over such a loop, which dips to where the branches meet, can cross them.
// The passes are bounded:
// each peels every loop edge at most once.
// Each loop keeps, per vertex, the pass that put it there (LayerLoops::bottom_flags,
// top_flags), so that the band can put the peeled triangles back: where a band between
// peeled loops folds (a peeled loop can dip where the other cannot follow), add_group
// stitches it again with the peeled triangles around the folds put back
// (put_back_peeled), and if it still folds, between the loops as they were, with all the
// triangles peeled off both put back: the seam as without peeling.
const uint32_t kPeelPasses = 8;

// Stitches of a band (see add_group): the first between the peeled loops; where it folds,
// with kLocalUnpeel, up to two more with the peel groups around the folds put back, then
// one with all; without kLocalUnpeel, one with all.
const uint32_t kUnpeelRounds = kLocalUnpeel ? 4 : 2;

const double kPeelSlope = 1.0;

const double kInnerPeelSlope = 2.0;

const uint32_t kFoldedEndPeelPasses = 64;

const double kFoldedEndPeelSlope = 1e6;

// Whether the triangle of loop entry g (see centre_link and hull_loop) is peeled.
static inline bool peels(const Triangulation& tr, const Local* points, const uint32_t* flags,
                  uint32_t g, bool top, double slope) {
    if (!on_surface(tr, g / 3)) return false;
    uint32_t from = tr.vertex[g], to = tr.vertex[next_edge(g)], x = tr.vertex[prev_edge(g)];
    if (flags[x] & (kOnBottomLoop | kOnTopLoop)) return false;
    if (!top) {  // the bottom loop runs against its entries' half-edges
        uint32_t t = from;
        from = to;
        to = t;
    }
    const Local &a = points[from - 1], &b = points[to - 1], &p = points[x - 1];
    auto gentle = [&p, slope](const Local& q) {
        double dh = q.h - p.h, dx = q.x - p.x, dy = q.y - p.y;
        return dh * dh <= slope * slope * (dx * dx + dy * dy);
    };
    double dot = (a.x - p.x) * (b.x - p.x) + (a.y - p.y) * (b.y - p.y) + (a.h - p.h) * (b.h - p.h);
    return dot < 0 && gentle(a) && gentle(b) &&
           orient2d_robust(tr.xy, tr.xy + 2 * from, tr.xy + 2 * x) > 0 &&
           orient2d_robust(tr.xy, tr.xy + 2 * x, tr.xy + 2 * to) > 0;
}

// Peels the loop's entries loop[0..n) (capacity: the layer's points, which no loop exceeds)
// and returns its new length. A peeled triangle loses its first vertex to the centre, so
// that it is no longer emitted. The pass reads the loop from the array's end, where it never
// meets what it writes: both loops together hold each vertex at most once.
static inline uint32_t peel_loop(Triangulation& tr, const Local* points, uint32_t* flags, uint32_t* loop,
                          uint32_t n, uint32_t capacity, bool top, double slope,
                          uint32_t passes) {
    for (uint32_t pass = 0; pass < passes; ++pass) {
        std::memmove(loop + (capacity - n), loop, n * sizeof(uint32_t));
        const uint32_t* entries = loop + (capacity - n);
        uint32_t m = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t g = entries[i];
            if (m + 2 > capacity - n + i + 1 || !peels(tr, points, flags, g, top, slope)) {
                loop[m++] = g;
                continue;
            }
            const uint32_t kept = kPeelFoldedEnds && pass >= kLastPass ? kLastPass : pass + 1;
            flags[tr.vertex[prev_edge(g)]] |= (top ? kOnTopLoop : kOnBottomLoop) |
                                              kept << kPassShift;
            const uint32_t before = tr.twin[prev_edge(g)], after = tr.twin[next_edge(g)];
            loop[m++] = top ? before : after;
            loop[m++] = top ? after : before;
            tr.vertex[g - g % 3] = 0;
        }
        if (m == n) break;
        n = m;
    }
    return n;
}

// Turns loop entries into the layer-local indices of the loop's vertices, in loop order, and
// sets each vertex's peeling pass in passes (0: on the centre's link or the hull).
static inline void name_loop(const Triangulation& tr, const uint32_t* order, const uint32_t* flags,
                      uint32_t* loop, uint32_t n, unsigned char* passes, bool top) {
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t v = tr.vertex[top ? loop[i] : next_edge(loop[i])];
        passes[i] = static_cast<unsigned char>(flags[v] >> kPassShift << kPassBit);
        loop[i] = order[v - 1];
    }
}

// A layer's points in frame coordinates, read from the cloud once so that the fit, the
// unrolling and the fold test read a compact array instead of the cloud at random, and the
// cylinder fitted to them. Triangles and loops name the points by their position in `ids`
// (layer-local indices).
struct LoadedLayer {
    const uint32_t* ids;  // layer-local index -> reader index
    size_t count;
    Local* points;        // ids' points, until triangulate_layer puts them in its own order
    Cylinder cyl;
    bool surface_flips;   // Frame::surface_flips
    uint32_t ends;        // kLowPole, kHighPole: the surface's ends (see find_closed_ends)
    uint32_t cut_ends;    // Frame::cut_ends
};

// `staged` (optional): the same points in frame coordinates, in the arena's end room
// (LayerQueue::staged), read in sequence instead of the cloud at random while intact.
static inline bool load_layer(const CloudReader& cloud, const Frame& frame, const uint32_t* ids,
                       const Local* staged, size_t count, double h0, double h1, Arena& arena,
                       LoadedLayer& layer) {
    const bool intact = kStagePoints && staged && arena.untouched(staged);
    layer.ids = ids;
    layer.ends = 0;
    layer.count = count;
    if (kSurfaceFlips) layer.surface_flips = frame.surface_flips;
    layer.cut_ends = frame.cut_ends;
    layer.points = arena.alloc<Local>(count);
    if (arena.failed) return false;
    if (intact)
        std::memmove(layer.points, staged, count * sizeof(Local));  // they may overlap
    else
        for (size_t i = 0; i < count; ++i) layer.points[i] = frame.local(cloud.point(ids[i]));
    const Local* points = layer.points;
    layer.cyl =
        fit_cylinder([points](size_t i) -> const Local& { return points[i]; }, count, h0, h1);
    return true;
}

// sectors_held by a loaded layer around its fitted centre (before the centre search moves
// it).
static inline uint32_t layer_sectors(const LoadedLayer& layer) {
    const Local* points = layer.points;
    return sectors_held([points](size_t i) -> const Local& { return points[i]; }, layer.count,
                        layer.cyl.cx, layer.cyl.cy);
}

// ---- closed ends ----
//
// Whether the layer, an end of the surface (`ends`: kLowPole for the first layer, kHighPole
// for the last), holds a closed end there (see "closed ends" in >>unroll): among the points
// within kEndSlab radii of that end (at most a third of the layer), a twentieth or more
// (and at least 3) lie within kAcrossEnd times their mean distance from the axis, and
// either (by share) that share is more than twice the share among the points between the
// two ends' slabs, or (by outline) a twentieth or more (and at least 3) are also within
// kAcrossEnd times the outline of the slab beyond (as thick, next to it) in their sector,
// and that slab surrounds the axis (no octant empty). An open end has none there; a
// section that is not star-shaped around the centre (two lobes) has as many all along the
// layer, and they lie on the outline, not inside it, so it is left as it was (its folds
// are the centre search's). Sets layer.cyl's poles, kPoleDepth radii in from the ends: at
// most half-way when the layer holds both ends, else at most three quarters of the way, so
// the layer's far quarter keeps the cylinder's picture and its loop there still hugs the
// cut (with the pole beyond the layer, one run of the femur's 16 crossed itself in 4
// pairs). Measured over the 16 layerings of bench/layer_sweep.sh: the femur's mean
// distance 4% smaller and 103 self-intersecting pairs (111 before), the hand and the bust
// within 1%, open star-shaped tubes unchanged; poles on every end layer instead made open
// tubes 19% farther from their surface. Thin end layers: a slab of a quarter of the layer
// (at most) missed the dome of the test suite's capsule cut in 12 layers (2 points across
// of 34), and poles at most half-way left a flat end in a thin layer twice as far from its
// surface as in a thick one; a third and three quarters bring a flat-ended cylinder 5%
// closer over 1 to 24 layers (10% with 24), and leave the real clouds within 0.4%.
// By outline finds the ends that split into knobs (a femur's condyles, the test suite's
// knobbed tube), which by share missed: the notch between the knobs rises into the layer
// and gives it as many points near the axis as the end has. Then the knobbed tube with 4
// and 8 layers had 9 to 25 folds and now none; the same 16 layerings of the femur come
// 2.9% closer (geometric mean) with 93 self-intersecting pairs (108 before; 6 layers along
// z: 15 to 0), the hand, the kitten, the busts and the analytic tubes unchanged. By outline
// alone left the femur's top open (a flat cut, few points across), and without the
// octants' rule a bent tube's open ends, which pass beside the axis, were taken for closed.
const double kPoleDepth = 1.0;

const double kEndSlab = 0.5;

const double kAcrossEnd = 0.5;

static inline void find_closed_ends(LoadedLayer& layer, uint32_t ends) {
    layer.ends = ends;
    Cylinder& c = layer.cyl;
    const Local* points = layer.points;
    const size_t n = layer.count;
    ends &= ~layer.cut_ends;
    if (!kClosedEnds || !ends || n == 0) return;
    double lo = points[0].h, hi = lo;
    for (size_t i = 1; i < n; ++i) {
        lo = points[i].h < lo ? points[i].h : lo;
        hi = points[i].h > hi ? points[i].h : hi;
    }
    const double reach = 1 / c.scale, mid = lo + (hi - lo) / 2;
    const double slab = kEndSlab * reach < (hi - lo) / 3 ? kEndSlab * reach : (hi - lo) / 3;
    auto end_of = [&](const Local& p) { return p.h < lo + slab ? 0 : p.h > hi - slab ? 1 : -1; };
    auto distance = [&](const Local& p) {
        const double dx = p.x - c.cx, dy = p.y - c.cy;
        return std::sqrt(dx * dx + dy * dy);
    };
    // Each end in turn. "Across" is measured against the slab's own width, so the narrow
    // open end of a widening layer (a vase) is not taken for a closed one.
    double outline[kSectors];  // per sector: the farthest point beyond the slab
    for (int end = 0; end < 2; ++end) {
        if (!(ends & (1u << end))) continue;
        auto beyond = [&](const Local& p) {
            return end == 0 ? p.h >= lo + slab && p.h < lo + 2 * slab
                            : p.h <= hi - slab && p.h > hi - 2 * slab;
        };
        auto sector = [&](const Local& p) { return sector_around(p.x - c.cx, p.y - c.cy); };
        double in_slab = 0, slab_radius = 0;
        for (double& o : outline) o = 0;
        for (size_t i = 0; i < n; ++i) {
            const double d = distance(points[i]);
            if (end_of(points[i]) == end) {
                in_slab += 1;
                slab_radius += d;
            } else if (beyond(points[i])) {
                double& o = outline[sector(points[i])];
                o = d > o ? d : o;
            }
        }
        if (in_slab == 0) continue;
        const double limit = kAcrossEnd * slab_radius / in_slab;
        double across = 0, inside = 0, across_rest = 0, in_rest = 0;
        for (size_t i = 0; i < n; ++i) {
            const double d = distance(points[i]);
            const int at = end_of(points[i]);
            across += at == end && d < limit;
            inside += at == end && d < limit && d < kAcrossEnd * outline[sector(points[i])];
            across_rest += at < 0 && d < limit;
            in_rest += at < 0;
        }
        // Two ways to be closed. More of the slab across than of the layer between the
        // slabs: a section that is not star-shaped around the centre (two lobes) has as
        // many all along. Or, where that fails, well inside the outline of the slab beyond,
        // sector by sector, which a lobed section's waist (a peanut, a trefoil) is not, but
        // a knobbed end's is (a femur's condyles: the notch between them rises into the
        // layer and brings its points near the axis); that slab must surround the axis (a
        // point in every octant, as sparse layers leave a few sectors empty), which the end
        // of a tube passing beside the axis (a bent tube's) does not.
        bool surrounded = true;
        for (uint32_t octant = 0; octant < 8; ++octant) {
            bool held = false;
            for (uint32_t k = octant * (kSectors / 8); k < (octant + 1) * (kSectors / 8); ++k)
                held = held || outline[k] > 0;
            surrounded = surrounded && held;
        }
        const bool from_rest = across * in_rest > 2 * across_rest * in_slab;
        const bool from_outline = surrounded && inside >= 3 && 20 * inside >= in_slab;
        const bool enough = across >= 3 && 20 * across >= in_slab;
        if (enough && (from_rest || from_outline)) c.poles |= 1u << end;
    }
    const double low_limit = (c.poles & kHighPole) ? mid : hi - (hi - lo) / 4;
    const double high_limit = (c.poles & kLowPole) ? mid : lo + (hi - lo) / 4;
    c.pole_low = lo + kPoleDepth * reach < low_limit ? lo + kPoleDepth * reach : low_limit;
    c.pole_high = hi - kPoleDepth * reach > high_limit ? hi - kPoleDepth * reach : high_limit;
}

// ---- the centre search ----
//
// A layer that is not star-shaped around its centre (a C-shaped cross-section, a condyle
// beside a shaft) folds: rays from the centre cross its surface twice, and the unrolled
// triangulation bridges the two sheets. Another centre may see more of it. The layer's
// sample (every k-th point, at most kCentreSamplePoints) is triangulated around the fitted
// centre; if it folds, around each of the 24 other centres of a 5 x 5 grid (steps of
// kCentreStep radii, the inner ring first) too, and the layer is unrolled around the
// centre whose sample folds least; among centres with as few folds, the one whose sample
// has the least area (bridges add area), and the fitted centre on ties with it. Radius and
// scale stay the fitted ones, and a centre outside the sample's hull is never taken (the
// layer must surround it). The search needs less workspace than the layer's own
// triangulation. Cost: one triangulation of the sample per layer (little: a tube's layers
// do not fold), 25 for a layer that folds, at most about 25,000 insertions per layer on
// large ones. With the band's centre choice in >>stitch it removes most of the crossing
// triangle pairs of scans whose layers fold; smaller samples lose most of that. A layer
// that bridges a concavity without folding (a membrane over the neck between two lobes)
// is not searched: searching every layer costs a third more time on a large tube and
// gives scans no fewer self-intersections.

const size_t kCentreSamplePoints = 1024;

const int32_t kCentreRings = 2;  // the candidates: a 5 x 5 grid around the fitted centre

const double kCentreStep = 0.3;

// The folds of the sample points[0], points[stride], ... (count of them) rolled around
// cyl's centre and triangulated, with the doubled area of its surface in *area; SIZE_MAX
// where the centre does not lie inside the sample's hull (it does not surround that
// centre). Its scratch is released.
static inline size_t sample_folds(const Local* points, size_t count, size_t stride,
                           const Cylinder& cyl, Arena& arena, double* area) {
    *area = 0;
    size_t mark = arena.mark(), folds = SIZE_MAX;
    double* xy = arena.alloc<double>(2 * (count + 1));
    Triangulation tr;
    tr.xy = xy;
    uint32_t inserted = 0;
    if (allocate_triangulation(tr, count + 1, arena)) {
        xy[0] = xy[1] = 0;
        for (size_t k = 0; k < count; ++k) roll(cyl, points[k * stride], xy + 2 * (k + 1));
        if (triangulate_points(tr, static_cast<uint32_t>(count + 1),
                               DuplicateSink{nullptr, nullptr}, &inserted) == Status::ok)
            folds = 0;
    }
    for (uint32_t t = 0; folds == 0 && t < tr.triangle_count; ++t) {
        const uint32_t* v = tr.vertex + 3 * t;
        if (tr.is_ghost(t) && (v[0] == 0 || v[1] == 0 || v[2] == 0)) folds = SIZE_MAX;
    }
    if (folds == 0) folds = count_folds(tr, points, stride, cyl, area);
    arena.rewind(mark);
    return folds;
}

// Moves layer.cyl's centre where a sample of the layer folds least (see above).
static inline void choose_centre(LoadedLayer& layer, Arena& arena) {
    const size_t stride = layer.count / kCentreSamplePoints + 1;
    const size_t count = (layer.count + stride - 1) / stride;
    const Cylinder fitted = layer.cyl;
    size_t fitted_folds = 0, fewest = 0;
    double least = 0;
    // Ring 0 is the fitted centre; rings 1 and 2 are the borders of the 3 x 3 and 5 x 5 grids.
    for (int32_t ring = 0; ring <= kCentreRings; ++ring)
        for (int32_t dy = -ring; dy <= ring; ++dy)
            for (int32_t dx = -ring; dx <= ring; ++dx) {
                if (dx != ring && dx != -ring && dy != ring && dy != -ring) continue;
                Cylinder candidate = fitted;
                candidate.cx += kCentreStep * fitted.radius * dx;
                candidate.cy += kCentreStep * fitted.radius * dy;
                double area = 0;
                const size_t folds =
                    sample_folds(layer.points, count, stride, candidate, arena, &area);
                if (ring == 0) {
                    if (folds == 0) return;
                    fitted_folds = fewest = folds;
                    least = area;
                } else if (folds < fewest ||
                           (folds == fewest && fewest < fitted_folds && area < least)) {
                    // Fewer folds; as few and less area, once the fitted centre is beaten.
                    fewest = folds;
                    least = area;
                    layer.cyl = candidate;
                }
            }
}

}  // namespace detail
}  // namespace stratmesh

// >>stitch ===============================================================================
// The band between two layers' loops.
//
// Two neighbouring layers meet at a cut: the top loop A of the lower layer and the bottom
// loop B of the upper one are closed loops around the axis. Both are unrolled onto one
// strip (u, v) = (R theta, h - cut) around the average of the two cylinders: A below the
// cut, B above it. (Where the band settled on that strip folds, it is settled again around
// each layer's own centre and the band with the least area is kept: once the centre
// search has moved a centre, the midpoint may lie outside what both loops are star-shaped
// around.) A zipper merges the loops by angle: each step adds a triangle on the
// next edge of A or of B, so the band is a manifold annulus by construction. Then the
// paper's diagonal swap: a rung shared by an A-triangle and a B-triangle is swapped when
// the opposite vertex lies in the circumcircle (Lawson flips, which terminate in one fixed
// plane), or when the zipper folded a sliver that the swap unfolds. A swap only ever
// exchanges adjacent A and B steps, so the band stays a band; a clockwise step the swaps
// cannot reach is then untangled across its run (see untangle_runs). The strip is
// periodic: a vertex reached again after a full turn is shifted by the circumference. The
// rung that closes the loop (first A vertex to first B vertex) is kept by both, so the band
// restarts half-way round for a second pass of each. The strip, not the annulus, is used
// here because band triangles are long and flat: on the annulus the circle's curvature would
// flip their orientation relative to the surface. The loops come peeled (see "peeling" in
// >>layer triangulation): they hug the cut, so the band's triangles join points about one
// spacing apart; where a band between peeled loops still folds, add_group stitches it again
// from the loops as they were, with the peeled triangles put back.

namespace stratmesh {
namespace detail {

// Rotates loop[0..n) and its strip coordinates so that entry `first` comes first; the
// entries moved to the end are shifted by `turn` (one period of the strip), so angles
// keep increasing along the loop.
static inline void rotate_loop(uint32_t* loop, double* uv, uint32_t n, uint32_t first,
                               double turn) {
    for (uint32_t i = 0; i < first; ++i) uv[2 * i] += turn;
    // Three reversals rotate in place.
    auto reverse = [&](uint32_t lo, uint32_t hi) {  // the range [lo, hi)
        for (; hi > lo + 1; ++lo) {
            --hi;
            uint32_t t = loop[lo];
            loop[lo] = loop[hi];
            loop[hi] = t;
            for (uint32_t k = 0; k < 2; ++k) {
                double c = uv[2 * lo + k];
                uv[2 * lo + k] = uv[2 * hi + k];
                uv[2 * hi + k] = c;
            }
        }
    };
    reverse(0, first);
    reverse(first, n);
    reverse(0, n);
}

// Rotates loop[0..n) so its smallest angle comes first (angles in [0, turn)).
static inline void rotate_to_first_angle(uint32_t* loop, double* uv, uint32_t n) {
    uint32_t first = 0;
    for (uint32_t i = 1; i < n; ++i)
        if (uv[2 * i] < uv[2 * first]) first = i;
    rotate_loop(loop, uv, n, first, 0);
}

struct Band {
    uint32_t* a;        // loop A, band indices (see stitch_layers)
    double* xa;         // its strip coordinates, angles increasing from the smallest
    uint32_t p;
    uint32_t* b;
    double* xb;
    uint32_t q;
    double turn;        // the strip's period, 2 pi R
    unsigned char* steps;  // p + q: 0 = advance A, 1 = advance B
    double* scratch;       // incircle scratch
    double corner[4][2];   // the current quad, unwrapped

    // Strip coordinates of the i-th vertex of A counted from the start, i <= p.
    const double* pa(uint32_t i, int slot) {
        corner[slot][0] = xa[2 * (i % p)] + (i >= p ? turn : 0);
        corner[slot][1] = xa[2 * (i % p) + 1];
        return corner[slot];
    }
    const double* pb(uint32_t j, int slot) {
        corner[slot][0] = xb[2 * (j % q)] + (j >= q ? turn : 0);
        corner[slot][1] = xb[2 * (j % q) + 1];
        return corner[slot];
    }

    // Whether the steps at t, t+1 (state i, j before t) should be swapped. Counter-clockwise
    // on the strip, an A step makes (a0, a1, b0) and a B step (a0, b1, b0). A swap is
    // taken when the swapped pair is proper and either the current pair is not (the
    // zipper made a folded sliver: untangle it) or the empty-circle test asks for it.
    bool should_swap(uint32_t t, uint32_t i, uint32_t j) {
        const double *a0 = pa(i, 0), *a1 = pa(i + 1, 1), *b0 = pb(j, 2), *b1 = pb(j + 1, 3);
        bool a_then_b = steps[t] == 0;
        // A then B: (a0 a1 b0), (a1 b1 b0). B then A: (a0 b1 b0), (a0 a1 b1).
        bool proper_ab = orient2d_robust(a0, a1, b0) > 0 && orient2d_robust(a1, b1, b0) > 0;
        bool proper_ba = orient2d_robust(a0, b1, b0) > 0 && orient2d_robust(a0, a1, b1) > 0;
        if (a_then_b ? !proper_ba : !proper_ab) return false;
        if (a_then_b ? !proper_ab : !proper_ba) return true;
        if (a_then_b) return incircle_perturbed(a0, a1, b0, b1, scratch) > 0;
        return incircle_perturbed(a0, b1, b0, a1, scratch) > 0;
    }

    // Whether step t (state i, j before it) is counter-clockwise on the strip: an A step
    // makes (a0 a1 b0), a B step (a0 b1 b0).
    bool proper(uint32_t t, uint32_t i, uint32_t j) {
        const double* a0 = pa(i, 0);
        const double* b0 = pb(j, 2);
        return orient2d_robust(a0, steps[t] == 0 ? pa(i + 1, 1) : pb(j + 1, 1), b0) > 0;
    }
};

// A step sequence is a band only if no rung repeats: walking all of A while B stands
// still (or all of B) would return to the rung it started from. That happens exactly when
// the cyclic sequence has a single run of A steps, so a band needs at least two.
static inline bool starts_a_run(const unsigned char* steps, uint32_t length, uint32_t k) {
    return steps[k % length] == 0 && steps[(k + length - 1) % length] == 1;
}

static inline uint32_t count_a_runs(const unsigned char* steps, uint32_t length) {
    uint32_t runs = 0;
    for (uint32_t k = 0; k < length; ++k) runs += starts_a_run(steps, length, k);
    return runs;
}

// Whether swapping steps t and t + 1 keeps at least two runs of A (only the run starts at
// t, t + 1 and t + 2 can change).
static inline bool swap_keeps_band(unsigned char* steps, uint32_t length, uint32_t t,
                                   uint32_t runs) {
    uint32_t before = 0, after = 0;
    for (uint32_t k = t; k < t + 3; ++k) before += starts_a_run(steps, length, k);
    unsigned char s = steps[t];
    steps[t] = steps[t + 1];
    steps[t + 1] = s;
    for (uint32_t k = t; k < t + 3; ++k) after += starts_a_run(steps, length, k);
    steps[t + 1] = steps[t];
    steps[t] = s;
    return runs - before + after >= 2;
}

// Merges the loops by angle; if that walks one loop in a single run (tiny or skewed
// loops), one boundary step is swapped so the band is a band.
static inline void zip_by_angle(Band& band) {
    const uint32_t length = band.p + band.q;
    uint32_t i = 0, j = 0, t = 0;
    while (i < band.p || j < band.q) {
        bool take_a;
        if (i == band.p) take_a = false;
        else if (j == band.q) take_a = true;
        else take_a = band.pa(i + 1, 0)[0] <= band.pb(j + 1, 1)[0];
        band.steps[t++] = take_a ? 0 : 1;
        if (take_a) ++i; else ++j;
    }
    if (count_a_runs(band.steps, length) >= 2) return;
    for (t = 0; t + 1 < length; ++t) {
        if (band.steps[t] == band.steps[t + 1]) continue;
        unsigned char s = band.steps[t];
        band.steps[t] = band.steps[t + 1];
        band.steps[t + 1] = s;
        return;
    }
}

// Lawson flips over the step sequence; returns the number of swaps.
static inline size_t swap_diagonals(Band& band) {
    const uint32_t length = band.p + band.q;
    const size_t limit = 16 * static_cast<size_t>(length) + 64;
    uint32_t runs = count_a_runs(band.steps, length);
    size_t swaps = 0;
    uint32_t t = 0, i = 0, j = 0;
    while (t + 1 < length) {
        if (band.steps[t] != band.steps[t + 1] && swaps < limit && band.should_swap(t, i, j) &&
            swap_keeps_band(band.steps, length, t, runs)) {
            uint32_t before = 0, after = 0;
            for (uint32_t k = t; k < t + 3; ++k) before += starts_a_run(band.steps, length, k);
            unsigned char s = band.steps[t];
            band.steps[t] = band.steps[t + 1];
            band.steps[t + 1] = s;
            for (uint32_t k = t; k < t + 3; ++k) after += starts_a_run(band.steps, length, k);
            runs = runs - before + after;
            ++swaps;
            if (t > 0) {
                --t;
                if (band.steps[t] == 0) --i; else --j;
            }
            continue;
        }
        if (band.steps[t] == 0) ++i; else ++j;
        ++t;
    }
    return swaps;
}

// The swaps only exchange neighbouring A and B steps, so a clockwise step inside a run of
// one loop stays (as does one whose swapped pair is clockwise too). Both loops hug the
// cut, so band triangles are flat, and an A step (a0 a1 b0) turns clockwise, a sliver
// facing the axis, when b0 lies below the line through a0 and a1: behind a0 with a1
// dipping, or past a1 with a1 rising (a B step likewise). Moving the other loop's next
// step back to it, or its previous step forward, across the run hangs the edge from the
// other loop's next (or previous) vertex; only the triangles of that stretch change, and
// the move is kept when they all turn counter-clockwise and the band keeps two runs of A.
// Returns the adjacent exchanges made.
static inline size_t untangle_runs(Band& band) {
    // Longer runs (a fan from one vertex over many of the other loop) are left as they
    // are: this bounds the work at kLongestUntangledRun steps per step of the band.
    const uint32_t kLongestUntangledRun = 64;
    const uint32_t length = band.p + band.q;
    unsigned char* steps = band.steps;
    uint32_t runs = count_a_runs(steps, length);
    // Run starts at lo .. hi + 1: the only ones a change of steps [lo, hi] can move.
    auto starts_near = [&](uint32_t lo, uint32_t hi) {
        uint32_t starts = 0;
        for (uint32_t k = lo; k <= hi + 1; ++k) starts += starts_a_run(steps, length, k);
        return starts;
    };
    size_t moves = 0;
    uint32_t i = 0, j = 0;
    for (uint32_t t = 0; t < length; ++t) {
        const unsigned char kind = steps[t];
        unsigned char taken = kind;  // what step t adds to the state
        if (!band.proper(t, i, j)) {
            uint32_t next = t + 1, previous = t;
            const uint32_t most = kLongestUntangledRun;
            while (next < length && steps[next] == kind && next - t <= most) ++next;
            while (previous > 0 && steps[previous - 1] == kind && t - previous <= most) --previous;
            const uint32_t run = t - previous;  // steps of the run before t
            const bool short_run = next - previous <= most;
            for (int backward = 0; short_run && backward < 2; ++backward) {
                // Steps [lo, hi] change: the other loop's step goes from `from` to t.
                const uint32_t lo = backward ? previous - 1 : t, hi = backward ? t : next;
                const uint32_t from = backward ? lo : hi;
                if (backward ? previous == 0 : next == length) continue;
                const unsigned char other = steps[from];
                const uint32_t starts_before = starts_near(lo, hi);
                for (uint32_t k = lo; k <= hi; ++k) steps[k] = kind;
                steps[t] = other;
                const uint32_t runs_after = runs - starts_before + starts_near(lo, hi);
                bool ok = runs_after >= 2;
                // The state before lo: for a backward move, the run and that step undone.
                uint32_t ik = backward ? i - (kind == 0 ? run : 1) : i;
                uint32_t jk = backward ? j - (kind == 0 ? 1 : run) : j;
                for (uint32_t k = lo; ok && k <= hi; ++k) {
                    ok = band.proper(k, ik, jk);
                    if (steps[k] == 0) ++ik; else ++jk;
                }
                if (ok) {
                    runs = runs_after;
                    moves += hi - lo;
                    taken = backward ? kind : other;  // backward: the same steps up to t
                    break;
                }
                for (uint32_t k = lo; k <= hi; ++k) steps[k] = kind;
                steps[from] = other;
            }
        }
        if (taken == 0) ++i; else ++j;
    }
    return moves;
}

// Rotates the band (its loops and steps) to start half-way round. False if the half-way
// point does not fall between the ends of both loops (the band stays as it is).
static inline bool restart_half_way(Band& band) {
    const uint32_t length = band.p + band.q, half = length / 2;
    uint32_t i_half = 0, j_half = 0;
    for (uint32_t t = 0; t < half; ++t) (band.steps[t] == 0 ? i_half : j_half) += 1;
    if (!(i_half > 0 && i_half < band.p && j_half > 0 && j_half < band.q)) return false;
    rotate_loop(band.a, band.xa, band.p, i_half, band.turn);
    rotate_loop(band.b, band.xb, band.q, j_half, band.turn);
    unsigned char* steps = band.steps;
    auto reverse = [steps](uint32_t lo, uint32_t hi) {  // the range [lo, hi)
        for (; hi > lo + 1; ++lo) {
            --hi;
            unsigned char c = steps[lo];
            steps[lo] = steps[hi];
            steps[hi] = c;
        }
    };
    reverse(0, half);
    reverse(half, length);
    reverse(0, length);
    return true;
}

// Whether every step of the band is counter-clockwise on the strip.
static inline bool band_is_proper(Band& band) {
    uint32_t i = 0, j = 0;
    for (uint32_t t = 0; t < band.p + band.q; ++t) {
        if (!band.proper(t, i, j)) return false;
        if (band.steps[t] == 0) ++i; else ++j;
    }
    return true;
}

// Zips the loops and settles the band: the empty-circle swaps, and the untangling of
// clockwise steps. The closing rung is held fixed by both: the band restarts half-way round
// and swaps again, so the quads around it get their test too, and where a clockwise step is
// left next to it, untangles once more from there.
static inline void settle_band(Band& band, size_t* swaps) {
    zip_by_angle(band);
    *swaps += swap_diagonals(band);
    if (restart_half_way(band)) *swaps += swap_diagonals(band);
    *swaps += untangle_runs(band);
    if (!band_is_proper(band) && restart_half_way(band)) *swaps += untangle_runs(band);
}

// Marks kUnpeeled the peeled entries of a loop's flags[0..n) in the peel groups around entry
// k: the entries between the nearest ones before and after k that were on the loop before
// peeling (pass 0; entry 0 is one). A peeled vertex came off an edge between entries of
// earlier passes in its group, so the group put back whole leaves the loop as it was
// there, and the other groups' peeling as it is.
static inline void unpeel_around(unsigned char* flags, uint32_t n, uint32_t k) {
    auto unpeel = [flags](uint32_t i) {
        if (!(flags[i] & kPassBits)) return false;
        flags[i] |= kUnpeeled;
        return true;
    };
    unpeel(k);
    for (uint32_t i = k; i > 0 && unpeel(i - 1); --i) {}
    for (uint32_t i = (k + 1) % n; i != k && unpeel(i); i = (i + 1) % n) {}
}

// Marks every peeled entry of flags[0..n) kUnpeeled or, with !on, none.
static inline void mark_unpeeled(unsigned char* flags, uint32_t n, bool on) {
    for (uint32_t i = 0; i < n; ++i)
        flags[i] = static_cast<unsigned char>(on && (flags[i] & kPassBits) ? flags[i] | kUnpeeled
                                                                           : flags[i] & ~kUnpeeled);
}

static inline size_t count_unpeeled(const unsigned char* flags, uint32_t n) {
    size_t marked = 0;
    for (uint32_t i = 0; i < n; ++i) marked += (flags[i] & kUnpeeled) != 0;
    return marked;
}

// A band being stitched (see stitch_layers): its loops in band indices, where their points
// come from, and the strip they are unrolled on.
struct Stitch {
    const CloudReader* cloud;
    const Frame* frame;
    const LoadedLayer* layer;
    const LayerLoops* loops;
    unsigned char* a_flags;  // loop A's, every entry (a_length)
    uint32_t a_length;
    uint32_t below;          // the band index of A's entry 0: layer.count
    Local* a_points;         // A's points, every entry
    Cylinder shared;         // the strip's cylinder; its centre is set per trial
    double unrolled_radius;
    Band band;

    // The point of band index id. The layer's points are read again (the loaded ones are in
    // triangulate_layer's order, or were never loaded when a job triangulated the layer):
    // only the loop's are read.
    Local point(uint32_t id) const {
        if (id >= below) return a_points[id - below];
        return frame->local(cloud->point(layer->ids[id]));
    }
    void unroll(uint32_t id, double* uv) const {
        const Local l = point(id);
        uv[0] = unrolled_radius * polar_angle(l.x - shared.cx, l.y - shared.cy);
        uv[1] = l.h - shared.h0;
    }
};

// Emits the triangles peeled off loop A (`top`: the lower layer's top loop) or the layer's
// bottom loop (see "peeling" in >>layer triangulation), with kLocalUnpeel those whose
// vertex is marked kUnpeeled, else all: vertex x, peeled in pass k, came off the edge
// between the nearest loop vertices before and after it from earlier passes (entry 0 is on
// the hull or the link).
static inline void put_back_peeled(const Stitch& st, bool top, TriangleSink& sink) {
    const unsigned char* flags = top ? st.a_flags : st.loops->bottom_flags;
    const uint32_t n = top ? st.a_length : st.loops->bottom_count;
    auto pass = [flags](uint32_t i) { return flags[i] & kPassBits; };
    auto id = [&st, top](uint32_t i) { return top ? st.below + i : st.loops->bottom[i]; };
    for (uint32_t x = 0; x < n; ++x) {
        if (!pass(x) || (kLocalUnpeel && !(flags[x] & kUnpeeled))) continue;
        uint32_t before = x - 1, after = (x + 1) % n;
        while (pass(before) >= pass(x)) --before;
        while (pass(after) >= pass(x)) after = (after + 1) % n;
        // Counter-clockwise on the annulus: the top loop's edge ran before -> after, the
        // bottom loop's after -> before.
        uint32_t u = id(top ? before : after), v = id(top ? after : before), w = id(x);
        sink.emit(u, v, w, st.point(u), st.point(v), st.point(w), st.shared);
    }
}

// Carves the band's loops from the arena and fills them with the entries of A (reader
// indices a_ids) and of the layer's bottom loop that are not left out (see stitch_layers),
// A's points copied. False if the arena is too small.
static inline bool gather_band_loops(Stitch& st, const uint32_t* a_ids, bool unpeel, Arena& arena) {
    const LayerLoops& loops = *st.loops;
    Band& band = st.band;
    band.a = arena.alloc<uint32_t>(st.a_length);
    band.b = arena.alloc<uint32_t>(loops.bottom_count);
    st.a_points = arena.alloc<Local>(st.a_length);
    band.xa = arena.alloc<double>(2 * static_cast<size_t>(st.a_length));
    band.xb = arena.alloc<double>(2 * static_cast<size_t>(loops.bottom_count));
    band.steps = arena.alloc<unsigned char>(static_cast<size_t>(st.a_length) + loops.bottom_count);
    band.scratch = arena.alloc<double>(kIncircleScratch);
    if (arena.failed) return false;
    auto left_out = [unpeel](unsigned char f) {
        return (f & kPassBits) && (unpeel || (kLocalUnpeel && (f & kUnpeeled)));
    };
    band.p = 0;
    for (uint32_t i = 0; i < st.a_length; ++i) {
        if (!left_out(st.a_flags[i])) band.a[band.p++] = st.below + i;
        st.a_points[i] = st.frame->local(st.cloud->point(a_ids[i]));
    }
    band.q = 0;
    for (uint32_t j = 0; j < loops.bottom_count; ++j)
        if (!left_out(loops.bottom_flags[j])) band.b[band.q++] = loops.bottom[j];
    return true;
}

// Unrolls both loops around the centre (cx, cy) and settles the band there.
static inline void settle_band_around(Stitch& st, double cx, double cy, size_t* swaps) {
    Band& band = st.band;
    st.shared.cx = cx;
    st.shared.cy = cy;
    for (uint32_t i = 0; i < band.p; ++i) st.unroll(band.a[i], band.xa + 2 * i);
    for (uint32_t j = 0; j < band.q; ++j) st.unroll(band.b[j], band.xb + 2 * j);
    rotate_to_first_angle(band.a, band.xa, band.p);
    rotate_to_first_angle(band.b, band.xb, band.q);
    settle_band(band, swaps);
}

// Walks the settled band: returns its folds, adds its doubled area to *area and, with a
// sink, writes its triangles there and (kLocalUnpeel) marks the peel groups around the
// folds: those around the state's a[i] and b[j], which hold the triangle's third corner
// too unless it is on the loop since before peeling. B's entry of b[j] is found walking
// loops.bottom along (b is in its order, rotated), once around at most.
static inline size_t walk_band(const Stitch& st, TriangleSink* sink, double* area) {
    const Band& band = st.band;
    const LayerLoops& loops = *st.loops;
    const uint32_t p = band.p, q = band.q;
    size_t folds = 0;
    uint32_t i = 0, j = 0, entry = 0;
    for (uint32_t t = 0; t < p + q; ++t) {
        uint32_t x, y, z;  // counter-clockwise on the annulus
        const uint32_t a0 = band.a[i % p], b0 = band.b[j % q];
        if (band.steps[t] == 0) {
            x = band.a[(i + 1) % p], y = a0, z = b0;
            ++i;
        } else {
            x = b0, y = band.b[(j + 1) % q], z = a0;
            ++j;
        }
        const Local px = st.point(x), py = st.point(y), pz = st.point(z);
        const bool folded = faces_axis(px, pz, py, st.shared);
        folds += folded;
        *area += doubled_area(px, py, pz);
        if (sink) sink->write(x, y, z);
        if (!kLocalUnpeel || !sink || !folded) continue;
        for (uint32_t k = 0; k < loops.bottom_count && loops.bottom[entry] != b0; ++k)
            entry = (entry + 1) % loops.bottom_count;
        unpeel_around(st.a_flags, st.a_length, a0 - st.below);
        unpeel_around(loops.bottom_flags, loops.bottom_count, entry);
    }
    return folds;
}

// Settles the band around the strip's centre: the cylinders' midpoint; where the band
// folds around it (the loops turn back around it: after choose_centre moved one of the
// centres, the midpoint may lie outside what both loops are star-shaped around), the one
// of the midpoint and the two layers' centres whose settled band has the least area. Trial
// 3 settles the band again around that one, unless it was the last tried. Returns the
// swaps of the band kept.
static inline size_t settle_least_area(Stitch& st, const Cylinder& ca, const Cylinder& cb) {
    const Cylinder* centres[3] = {nullptr, &ca, &cb};  // 0: the midpoint
    double least = 0;
    uint32_t best = 0;
    size_t best_swaps = 0;
    for (uint32_t trial = 0; trial < 4 && !(trial == 3 && best == 2); ++trial) {
        const uint32_t k = trial < 3 ? trial : best;
        size_t trial_swaps = 0;
        settle_band_around(st, k ? centres[k]->cx : (ca.cx + cb.cx) / 2,
                           k ? centres[k]->cy : (ca.cy + cb.cy) / 2, &trial_swaps);
        if (trial == 3) break;
        double area = 0;
        const size_t folds = walk_band(st, nullptr, &area);
        if (trial == 0 || area < least) {
            least = area;
            best = k;
            best_swaps = trial_swaps;
        }
        if (folds == 0 && trial == 0) break;
    }
    return best_swaps;
}

// Stitches loop A (the lower layer's top loop: reader indices a_ids with their seam flags,
// cylinder ca) to the loaded upper layer's bottom loop (loops.bottom, layer-local indices;
// the layer's cylinder has the cut as h0). With `unpeel`, both loops as they were before
// peeling, and the peeled triangles put back (with kLocalUnpeel the caller marks them all
// kUnpeeled first); else, with kLocalUnpeel, the entries marked kUnpeeled are left out and
// their peeled triangles put back, and each band triangle that faces the axis marks the
// peel groups around its corners kUnpeeled (unpeel_around) for a next attempt. The band's
// triangles name the upper layer's points by layer-local index and the i-th point of A by
// layer.count + i.
static inline bool stitch_layers(const CloudReader& cloud, const Frame& frame, const Cylinder& ca,
                                 const uint32_t* a_ids, unsigned char* a_flags, uint32_t p,
                                 const LoadedLayer& layer, const LayerLoops& loops, bool unpeel,
                                 Arena& arena, TriangleSink& sink, size_t* swaps) {
    const Cylinder& cb = layer.cyl;
    Stitch st;
    st.cloud = &cloud;
    st.frame = &frame;
    st.layer = &layer;
    st.loops = &loops;
    st.a_flags = a_flags;
    st.a_length = p;
    st.below = static_cast<uint32_t>(layer.count);
    const size_t mark = arena.mark();
    if (!gather_band_loops(st, a_ids, unpeel, arena)) return false;
    st.shared.poles = 0;
    st.shared.radius = (ca.radius + cb.radius) / 2;
    st.shared.h0 = cb.h0;
    st.shared.scale = (ca.scale + cb.scale) / 2;
    st.unrolled_radius = 1 / st.shared.scale;
    const double two_pi = 6.28318530717958647693;
    st.band.turn = two_pi * st.unrolled_radius;
    *swaps += settle_least_area(st, ca, cb);
    if (kLocalUnpeel || unpeel) {
        put_back_peeled(st, true, sink);
        put_back_peeled(st, false, sink);
    }
    double area = 0;
    sink.folds += walk_band(st, &sink, &area);
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh

// >>manifold =============================================================================
// The safety net that keeps the surface a manifold.
//
// The paper's step 5, as a safety net: by construction the layers and bands already form a
// manifold, so on sound input this removes nothing. Around every vertex v, each triangle
// (v, b, c) leaves along v->b and arrives along c->v. The surface is an oriented manifold
// at v when no directed edge repeats (at most two triangles per edge, consistently
// oriented) and the triangles form one fan: one chain or one cycle of triangles, each
// arriving where the next leaves. Triangles on a repeated directed edge go (the later
// one), then every fan but the largest; repeated until nothing changes, since a removal
// can split a neighbour's fan.
//
// It runs on each chunk of the surface (a layer's triangles and the band joining it to the
// layer below) as soon as the chunk is built, so that chunks are final when they leave
// (the stream hands them out at once) and the net's memory follows the largest layer, not
// the cloud. Chunks meet only along the layers' top loops, where each side gives a loop
// vertex one chain of triangles ending on the loop's edges by construction; where the net
// removed triangles, seal_seam makes sure the two sides still share an edge at every loop
// vertex (else the upper side's triangles there go), so they never meet in a vertex alone.
//
// Within a chunk, only the vertices the band joins can break the manifold: a layer's
// triangles are its planar triangulation (exact predicates) without the centre's star and
// the outside of the hull. Around a vertex off the centre's link (the bottom loop) that
// leaves its star minus the two ghost triangles at most: one fan. Off the hull, a
// bottom-loop vertex loses the two triangles on its edge to the centre: one fan too. A
// vertex on both loops can be left with two, and every band vertex is on a loop. So only
// the fans of the loop vertices are checked (fans_are_one_piece), and the net runs over
// the chunk only when one of them fails; on sound input it never does, and the net's
// relabelling and sorting, most of its cost, is skipped. A layer emits its triangles at
// the bottom loop last, so those fans are read from one stretch of the chunk, its border
// and band (chunk_is_sound); the rest of the chunk is only renamed.

namespace stratmesh {
namespace detail {

// In-place sort of packed (key, value) pairs: insertion sort for the small fans of almost
// every vertex, heap sort (O(n log n), no recursion) for large ones.
static inline void sort_pairs(uint64_t* items, size_t count) {
    if (count <= 16) {
        for (size_t i = 1; i < count; ++i) {
            uint64_t item = items[i];
            size_t j = i;
            for (; j > 0 && items[j - 1] > item; --j) items[j] = items[j - 1];
            items[j] = item;
        }
        return;
    }
    heap_sort(items, count);
}

struct Fan {
    uint64_t* key;       // (leaving neighbour << 32 | entry), sorted by leaving neighbour
    uint32_t* arrive;    // per entry: the arriving neighbour
    uint32_t* triangle;  // per entry: its triangle
    uint32_t* label;     // per sorted position: fan piece
    uint32_t* sizes;     // entries per piece
    size_t size;

    uint32_t entry(size_t position) const { return static_cast<uint32_t>(key[position]); }
    uint32_t leaving(size_t position) const { return static_cast<uint32_t>(key[position] >> 32); }
};

// The sorted position of the entry leaving towards `neighbour`, or SIZE_MAX.
static inline size_t position_leaving_to(const Fan& fan, uint32_t neighbour) {
    size_t lo = 0, hi = fan.size;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (fan.leaving(mid) < neighbour) lo = mid + 1; else hi = mid;
    }
    return lo < fan.size && fan.leaving(lo) == neighbour ? lo : SIZE_MAX;
}

// Collects v's live triangles, sorted by leaving edge; marks dead those repeating one.
static inline size_t collect_fan(const uint32_t* tri, const uint32_t* incident, size_t begin,
                          size_t end, uint32_t v, unsigned char* dead, Fan& fan) {
    fan.size = 0;
    for (size_t k = begin; k < end; ++k) {
        uint32_t t = incident[k];
        if (dead[t]) continue;
        const uint32_t* c = tri + 3 * static_cast<size_t>(t);
        uint32_t corner = c[0] == v ? 0u : c[1] == v ? 1u : 2u;
        uint32_t e = static_cast<uint32_t>(fan.size++);
        fan.arrive[e] = c[(corner + 2) % 3];
        fan.triangle[e] = t;
        fan.key[e] = (static_cast<uint64_t>(c[(corner + 1) % 3]) << 32) | e;
    }
    sort_pairs(fan.key, fan.size);
    size_t kept = 0, removed = 0;
    for (size_t k = 0; k < fan.size; ++k) {
        if (kept > 0 && fan.leaving(kept - 1) == fan.leaving(k)) {
            dead[fan.triangle[fan.entry(k)]] = 1;
            ++removed;
            continue;
        }
        fan.key[kept++] = fan.key[k];
    }
    fan.size = kept;
    return removed;
}

// Labels the connected pieces of the fan (each triangle linked to the one leaving where
// it arrives) and returns how many there are.
static inline uint32_t label_fan(Fan& fan) {
    const uint32_t unlabeled = kNoIndex;
    for (size_t k = 0; k < fan.size; ++k) fan.label[k] = unlabeled;
    uint32_t pieces = 0;
    for (size_t k = 0; k < fan.size; ++k) {
        if (fan.label[k] != unlabeled) continue;
        size_t at = k, walked = 0;
        while (at != SIZE_MAX && fan.label[at] == unlabeled) {
            fan.label[at] = pieces;
            ++walked;
            at = position_leaving_to(fan, fan.arrive[fan.entry(at)]);
        }
        uint32_t joined = (at != SIZE_MAX) ? fan.label[at] : pieces;
        if (joined != pieces) {
            // This walk ran into an earlier piece: it belongs to it.
            for (size_t w = k; w != at; w = position_leaving_to(fan, fan.arrive[fan.entry(w)]))
                fan.label[w] = joined;
            fan.sizes[joined] += static_cast<uint32_t>(walked);
        } else {
            fan.sizes[pieces++] = static_cast<uint32_t>(walked);
        }
    }
    return pieces;
}

// Makes v's fan a single oriented piece; returns the number of triangles marked dead.
static inline size_t repair_fan(const uint32_t* tri, const uint32_t* incident, size_t begin,
                         size_t end, uint32_t v, unsigned char* dead, Fan& fan) {
    size_t removed = collect_fan(tri, incident, begin, end, v, dead, fan);
    uint32_t pieces = label_fan(fan);
    if (pieces <= 1) return removed;
    uint32_t best = 0;
    for (uint32_t c = 1; c < pieces; ++c)
        if (fan.sizes[c] > fan.sizes[best]) best = c;
    for (size_t k = 0; k < fan.size; ++k) {
        if (fan.label[k] == best) continue;
        dead[fan.triangle[fan.entry(k)]] = 1;
        ++removed;
    }
    return removed;
}

// Whether a vertex's corners, packed (leaving << 32 | arriving) neighbours, form one chain
// or one cycle with no leaving edge repeated: then the safety net has nothing to do there.
// False sends the vertex to repair_fan, which then decides as if this had not run. The
// corners sit together in memory, where the triangles they come from are scattered, and are
// sorted in place by leaving neighbour; each corner's successor (the corner leaving where it
// arrives) is then found by binary search and kept in place of its arriving neighbour. One
// piece: every corner has one and a walk from any corner comes back after all of them (a
// cycle), or all but one have one and a walk from the corner nobody arrives at takes in all
// of them (a chain).
static inline bool fan_is_one_piece(uint64_t* corners, size_t size) {
    if (size == 0) return true;
    sort_pairs(corners, size);
    auto leaving = [&](size_t i) { return static_cast<uint32_t>(corners[i] >> 32); };
    // The chain's first corner leaves along the one leaving neighbour no corner arrives at:
    // the sum of the leaving neighbours less the arriving ones that some corner leaves along.
    // Each corner's arriving neighbour is replaced by its successor's position (size: none).
    uint64_t first_leaving = 0;
    size_t linked = 0;
    for (size_t i = 0; i < size; ++i) {
        if (i > 0 && leaving(i) == leaving(i - 1)) return false;
        const uint32_t arrive = static_cast<uint32_t>(corners[i]);
        size_t lo = 0, hi = size;
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (leaving(mid) < arrive) lo = mid + 1;
            else hi = mid;
        }
        const size_t next = lo < size && leaving(lo) == arrive ? lo : size;
        first_leaving += leaving(i);
        if (next < size) {
            ++linked;
            first_leaving -= arrive;
        }
        corners[i] = (corners[i] >> 32 << 32) | next;
    }
    auto successor = [&](size_t i) { return static_cast<size_t>(corners[i] & 0xFFFFFFFFu); };
    size_t start = 0;
    if (linked + 1 == size) {
        while (start < size && leaving(start) != first_leaving) ++start;
        if (start == size) return false;
    } else if (linked != size) {
        return false;
    }
    size_t walked = 1;
    for (size_t at = successor(start); at != size && at != start && walked <= size;
         at = successor(at))
        ++walked;
    return walked == size;
}

// Whether every vertex v with checked[v] != 0 passes fan_is_one_piece in tri[0 .. 3 count)
// (indices below point_count): then the safety net would remove nothing at those vertices.
// Lets finish_chunk skip the net where nothing can fail; the arena's failure answers false.
static inline bool fans_are_one_piece(const uint32_t* tri, size_t count, size_t point_count,
                               const unsigned char* checked, Arena& arena) {
    size_t mark = arena.mark();
    uint32_t* offsets = arena.alloc<uint32_t>(point_count + 1);
    if (arena.failed) return false;
    std::memset(offsets, 0, sizeof(uint32_t) * (point_count + 1));
    for (size_t k = 0; k < 3 * count; ++k)
        if (checked[tri[k]]) ++offsets[tri[k] + 1];
    for (size_t v = 0; v < point_count; ++v) offsets[v + 1] += offsets[v];
    uint64_t* corners = arena.alloc<uint64_t>(offsets[point_count]);
    if (arena.failed) return false;
    for (size_t k = 0; k < 3 * count; ++k) {
        if (!checked[tri[k]]) continue;
        const uint32_t* c = tri + (k - k % 3);
        corners[offsets[tri[k]]++] = (static_cast<uint64_t>(c[(k + 1) % 3]) << 32) | c[(k + 2) % 3];
    }
    // Each cursor now sits at the next vertex's start.
    bool one_piece = true;
    for (size_t v = 0, begin = 0; v < point_count && one_piece; begin = offsets[v++])
        one_piece = fan_is_one_piece(corners + begin, offsets[v] - begin);
    arena.rewind(mark);
    return one_piece;
}

// Removes triangles until the mesh tri[0 .. 3 count), whose indices are below point_count,
// is edge- and vertex-manifold and consistently oriented. Compacts the survivors in place
// (keeping their order); returns the number removed, or SIZE_MAX if the arena is too small.
//
// The work runs on relabelled triangles: vertices numbered in the order the triangles
// first name them (input indices are restored at the end). The triangles come out of the
// layers in spatial order, so relabelled fans and their triangles sit close together in
// memory whatever order the input points had; only the relabelling itself reads the input
// indices at random.
static inline size_t enforce_manifold(uint32_t* tri, size_t& count, size_t point_count, Arena& arena) {
    size_t mark = arena.mark();
    uint32_t* original = arena.alloc<uint32_t>(point_count);  // label -> input index
    unsigned char* dead = arena.alloc<unsigned char>(count);
    size_t relabel_mark = arena.mark();
    uint32_t* label = arena.alloc<uint32_t>(point_count);     // input index -> label
    if (arena.failed) return SIZE_MAX;
    for (size_t v = 0; v < point_count; ++v) label[v] = kNoIndex;
    std::memset(dead, 0, count);
    uint32_t labels = 0;
    for (size_t k = 0; k < 3 * count; ++k) {
        uint32_t& l = label[tri[k]];
        if (l == kNoIndex) {
            original[labels] = tri[k];
            l = labels++;
        }
        tri[k] = l;
    }
    arena.rewind(relabel_mark);
    uint32_t* local = tri;
    auto give_up = [&]() {  // out of workspace: hand back the input indices untouched
        for (size_t k = 0; k < 3 * count; ++k) tri[k] = original[tri[k]];
        return SIZE_MAX;
    };
    uint32_t* offsets = arena.alloc<uint32_t>(static_cast<size_t>(labels) + 1);
    uint32_t* incident = arena.alloc<uint32_t>(3 * count);
    uint64_t* corners = arena.alloc<uint64_t>(3 * count);  // per incidence: (leaving, arriving)
    if (arena.failed) return give_up();
    std::memset(offsets, 0, sizeof(uint32_t) * (static_cast<size_t>(labels) + 1));
    for (size_t k = 0; k < 3 * count; ++k) ++offsets[local[k] + 1];
    size_t max_degree = 0;
    for (uint32_t v = 0; v < labels; ++v) {
        if (offsets[v + 1] > max_degree) max_degree = offsets[v + 1];
        offsets[v + 1] += offsets[v];
    }
    // Incidences in triangle order: a forward pass that bumps each vertex's write cursor,
    // kept in `incident`'s own slots by filling from the end of each range.
    for (size_t k = 3 * count; k-- > 0;) {
        const uint32_t* c = local + (k - k % 3);
        const size_t at = --offsets[local[k] + 1];
        incident[at] = static_cast<uint32_t>(k / 3);
        corners[at] = (static_cast<uint64_t>(c[(k + 1) % 3]) << 32) | c[(k + 2) % 3];
    }
    // Now offsets[v + 1] is the start of v's range; shift back to the usual layout.
    for (uint32_t v = 0; v < labels; ++v) offsets[v] = offsets[v + 1];
    offsets[labels] = static_cast<uint32_t>(3 * count);
    Fan fan;
    fan.key = arena.alloc<uint64_t>(max_degree);
    fan.arrive = arena.alloc<uint32_t>(max_degree);
    fan.triangle = arena.alloc<uint32_t>(max_degree);
    fan.label = arena.alloc<uint32_t>(max_degree);
    fan.sizes = arena.alloc<uint32_t>(max_degree);
    if (arena.failed) return give_up();
    size_t removed = 0;
    for (size_t pass = 0; pass <= count; ++pass) {
        size_t before = removed;
        for (uint32_t v = 0; v < labels; ++v)
            if (removed > 0 || !fan_is_one_piece(corners + offsets[v], offsets[v + 1] - offsets[v]))
                removed += repair_fan(local, incident, offsets[v], offsets[v + 1], v, dead, fan);
        if (removed == before) break;
    }
    size_t alive = 0;
    for (size_t t = 0; t < count; ++t) {
        if (dead[t]) continue;
        for (size_t k = 0; k < 3; ++k) tri[3 * alive + k] = original[tri[3 * t + k]];
        ++alive;
    }
    count = alive;
    arena.rewind(mark);
    return removed;
}

}  // namespace detail
}  // namespace stratmesh

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

// >>flips ================================================================================
// Flips on the surface: within a layer, and across the seam between layers.

namespace stratmesh {
namespace detail {

// ---- flips on the surface ----
//
// With the surface_flips flag. The unrolling squeezes whatever lies almost across the axis:
// the underside of an ear, the crease where it meets the head, a chin. There the annulus's
// Delaunay triangles, good in the plane, are long and thin on the surface and run across
// the crease: on a synthetic bust with ears (bench/horned_bust.py --no-horns) the ears had
// 14% of the area and 57% of the distance to the true surface, 2.7 times the distance of
// CGAL's advancing front there, as close as it elsewhere. So once a layer is triangulated
// and its loops are settled, its surface edges are flipped on the surface itself, by two
// rules. An edge ab between triangles abp and baq is flipped to pq
//  - by the empty-circle rule, where the angles at p and q, measured in 3D, sum to more
//    than 180 degrees (in a plane: q inside the circle through a, b, p), unless pq bends
//    the surface more than kBendVeto times what ab did;
//  - for the bend alone, where pq bends it kBendGain times less than ab.
// The bend of an edge ab is |(b - a) . (n_b - n_a)| with n the vertex normals (the mean of
// the unit normals of the triangles around): 8 times the sag at the middle of a curve
// through a and b normal to n_a and n_b. An edge along the direction in which the surface
// curves least bends least, and triangles along it lie nearest the surface: on a cone,
// along its generatrices. The empty-circle rule alone, which wants fat triangles, turned
// the annulus's triangles across that direction on smooth surfaces of revolution (one
// layer, mean distance to the analytic surface: vase 13% and cone 27% farther than
// without flips); with both rules the vase is 3% and the cone 47% closer, the bumpy tube
// 44% (10% with the empty-circle rule alone), the bust with ears 25% (18%). Since
// kBendVeto <= kBendGain, the two rules never flip one quad back and forth with the same
// normals; the normals are estimated anew at the start of each of the first
// kNormalSweeps sweeps and then kept, so that the flips settle (the clouds measured: at
// most 2 flips in the last sweep).
// A flip is kept only if neither new triangle is degenerate, the new triangles' widest
// angle is at most 150 degrees (kWidestAngle) or less wide than the old ones' (the bend
// alone makes needles: without that limit 17% of the bust's triangles had an angle under
// 5 degrees, with it 2%, as without flips), pq is not already an edge nor a chord of a
// loop (where add_caps puts its cap), and neither new triangle meets another surface
// triangle of the layer. A new triangle may face the axis: where the surface does (a
// crown, the underside of a chin) the annulus squeezes it, and forbidding that kept a
// third of the flips that mend its slivers (5th percentile of the smallest angle, with
// and without: femur 6.2 and 8.0 degrees, mannequin head 4.7 and 5.8, lion head 3.5 and
// 5.4). The layer's fold count stays the unrolling's. Near a fold (a corner of a triangle
// facing the axis, from the unrolling or a flip), where the lifted annulus may lie over
// itself, the new triangles are tested against every surface triangle of the layer that
// could reach them (see "the crossing test"); elsewhere the layer is its annulus lifted
// and a flip covers about the place the old pair covered: a gentle one (both new normals
// within 26 degrees of the old pair's, kGentleFlip) is not tested, another against the
// triangles around the quad's corners. Loop edges are never flipped, so the loops, the
// bands and the peeled triangles that add_group may put back are the same as without the
// flips (the band and the triangles at its loops are flipped later, see "flips across the
// seam"). The first sweep visits every edge; later sweeps only the triangles the sweep
// before changed. The sweeps are bounded (kSurfaceFlipSweeps).
const uint32_t kSurfaceFlipSweeps = 8;

const uint32_t kNormalSweeps = 4;  // the sweeps that start with the normals estimated anew

const uint32_t kFanLimit = 64;  // a vertex with more neighbours keeps its edges

const double kFlipMargin = 1e-9;

const double kGentleFlip = 0.9;  // cosine of the largest angle between a new and the mean normal

const double kShrink = 1e-6;

const double kGrow = 1e-9;

const double kBendVeto = 3;  // a flip by the empty-circle rule may bend at most 3 times more

const double kBendGain = 3;  // a flip for the bend alone must bend 3 times less

const double kWidestAngle = -0.86602540378443865;  // cosine of 150 degrees

static inline Vec3 vec_of(const Local& p) { return Vec3{p.x, p.y, p.h}; }

struct Box3 {
    Vec3 low, high;
    bool meets(const Box3& o) const {
        return low.x <= o.high.x && o.low.x <= high.x && low.y <= o.high.y &&
               o.low.y <= high.y && low.z <= o.high.z && o.low.z <= high.z;
    }
};

static inline Box3 box_of(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    Box3 box = {a, a};
    const Vec3 rest[3] = {b, c, d};
    for (const Vec3& p : rest) {
        box.low = Vec3{p.x < box.low.x ? p.x : box.low.x, p.y < box.low.y ? p.y : box.low.y,
                       p.z < box.low.z ? p.z : box.low.z};
        box.high = Vec3{p.x > box.high.x ? p.x : box.high.x, p.y > box.high.y ? p.y : box.high.y,
                        p.z > box.high.z ? p.z : box.high.z};
    }
    return box;
}

// Whether the angles at p and q facing the segment ab sum to more than 180 degrees: then
// sin(angle_p + angle_q), a sum of sine-cosine products, is negative. Two acute angles
// (most edges) are settled by two dot products.
static inline bool flip_helps(Vec3 a, Vec3 b, Vec3 p, Vec3 q) {
    const Vec3 pa = a - p, pb = b - p, qa = a - q, qb = b - q;
    const double cos_p = dot(pa, pb), cos_q = dot(qa, qb);
    if (cos_p >= 0 && cos_q >= 0) return false;
    const Vec3 np = cross(pa, pb), nq = cross(qa, qb);
    const double sin_p = std::sqrt(dot(np, np)), sin_q = std::sqrt(dot(nq, nq));
    const double lengths = std::sqrt(dot(pa, pa) * dot(pb, pb) * dot(qa, qa) * dot(qb, qb));
    return sin_p * cos_q + cos_p * sin_q < -kFlipMargin * lengths;
}

// Whether triangles u and v, each scaled by `scale` about its centroid, overlap along every
// axis that could separate them: their normals, the cross products of their edges, and
// each normal crossed with the triangle's own edges (for coplanar triangles). Triangles
// with a shared corner are shrunk (kShrink) so that it does not count; others are grown
// (kGrow), so that a touch counts too.
static inline bool triangles_meet(const Vec3* u, const Vec3* v, double scale) {
    Vec3 s[3], t[3];
    const Vec3 cu = scaled(Vec3{u[0].x + u[1].x + u[2].x, u[0].y + u[1].y + u[2].y,
                                u[0].z + u[1].z + u[2].z}, 1.0 / 3);
    const Vec3 cv = scaled(Vec3{v[0].x + v[1].x + v[2].x, v[0].y + v[1].y + v[2].y,
                                v[0].z + v[1].z + v[2].z}, 1.0 / 3);
    for (int k = 0; k < 3; ++k) {
        const Vec3 du = u[k] - cu, dv = v[k] - cv;
        s[k] = Vec3{cu.x + du.x * scale, cu.y + du.y * scale, cu.z + du.z * scale};
        t[k] = Vec3{cv.x + dv.x * scale, cv.y + dv.y * scale, cv.z + dv.z * scale};
    }
    Vec3 es[3], et[3];
    for (int k = 0; k < 3; ++k) {
        es[k] = s[(k + 1) % 3] - s[k];
        et[k] = t[(k + 1) % 3] - t[k];
    }
    const Vec3 ns = cross(es[0], es[1]), nt = cross(et[0], et[1]);
    auto separates = [&s, &t](Vec3 axis) {
        double s_lo = dot(s[0], axis), s_hi = s_lo, t_lo = dot(t[0], axis), t_hi = t_lo;
        for (int k = 1; k < 3; ++k) {
            const double ds = dot(s[k], axis), dt = dot(t[k], axis);
            s_lo = ds < s_lo ? ds : s_lo;
            s_hi = ds > s_hi ? ds : s_hi;
            t_lo = dt < t_lo ? dt : t_lo;
            t_hi = dt > t_hi ? dt : t_hi;
        }
        return s_hi < t_lo || t_hi < s_lo;
    };
    if (separates(ns) || separates(nt)) return false;
    for (int i = 0; i < 3; ++i) {
        if (separates(cross(ns, es[i])) || separates(cross(nt, et[i]))) return false;
        for (int j = 0; j < 3; ++j)
            if (separates(cross(es[i], et[j]))) return false;
    }
    return true;
}

// Calls visit(g) for each half-edge g leaving the start of half-edge `from`, counter-clockwise
// around it, until visit returns false. False if a visit did, or the vertex has more than
// kFanLimit neighbours.
template <class Visit>
static inline bool around_vertex(const Triangulation& tr, uint32_t from, Visit visit) {
    uint32_t e = from;
    for (uint32_t steps = 0; steps < kFanLimit; ++steps) {
        if (!visit(e)) return false;
        e = tr.twin[prev_edge(e)];
        if (e == from) return true;
    }
    return false;
}

// The crossing test. A flip is made only if neither new triangle meets a surface triangle
// of the layer but the two it replaces (shared corners aside), in floating point: those
// with a shared corner shrunk by kShrink about their centroids, the others grown by kGrow,
// so that a touch counts. A triangle lies within the ball about any of its corners c
// through c's farther neighbour in it, so a triangle that meets a region has every corner
// within that corner's longest surface edge of it. The layer's vertices (the centre,
// vertex 0, aside) are kept in levels by that edge: level l holds those whose edges are at
// most bound(l) = base * 2^l long, base half the mean surface edge (the last level holds
// the rest, its bound the longest edge), sorted within a level by the cell of a grid whose
// cells are at least as wide as its bound and two mean edges: the vertices of a level
// within its bound of a flip's quad are in a few cells. Each vertex has a half-edge leaving
// it, so that its triangles are at hand. A flip that would give p or q an edge longer than
// its level's bound is not made, so the levels stay as sorted.
const uint32_t kLevels = 16;

const uint32_t kGridCells = 1024;  // cells along a side of a level's grid, at most

const uint32_t kGridColumns = 1024;  // a flip whose region spans more columns is not made

// A flip with more vertices near it is not made (their list is on the stack, 4 KB; the
// scans measured never reach it).
const uint32_t kMostVisited = 1024;

// Per vertex, one word: its level above kSpanBits, and below its longest edge as a share of
// the level's bound, rounded up.
const uint32_t kSpanBits = 27;

const double kSpanScale = 134217728;  // 2^kSpanBits

struct GridLevel {
    uint32_t first, count;  // its vertices: ids[first, first + count)
    double bound, inverse_side;
    uint32_t cells[3];

    uint32_t cell_along(double x, double low_x, uint32_t n) const {
        const double c = (x - low_x) * inverse_side;
        if (!(c > 0)) return 0;
        return c >= n - 1 ? n - 1 : static_cast<uint32_t>(c);
    }
    uint32_t key(uint32_t ix, uint32_t iy, uint32_t iz) const {
        return (ix * cells[1] + iy) * cells[2] + iz;
    }
};

struct LayerGrid {
    const Local* points;
    uint32_t* ids;    // the vertices by level, then cell
    uint32_t* edge;   // per vertex, a half-edge leaving it
    uint32_t* spans;  // per vertex: its level and longest edge (see kSpanBits)
    uint32_t count;
    bool sorted;  // ids and spans are filled only once a flip near a fold needs them
    Vec3 low;
    GridLevel levels[kLevels];

    uint32_t level_of(uint32_t v) const { return spans[v] >> kSpanBits; }
    // At least the longest surface edge at v.
    double span(uint32_t v) const {
        const double share = static_cast<double>((spans[v] & ((1u << kSpanBits) - 1)) + 1);
        return levels[level_of(v)].bound * share / kSpanScale;
    }
    // The word of a vertex at level l whose longest edge is `length`.
    uint32_t span_word(uint32_t l, double length) const {
        const double share = levels[l].bound > 0 ? length / levels[l].bound * kSpanScale : 0;
        const uint32_t most = (1u << kSpanBits) - 1;
        return (l << kSpanBits) | (share >= most ? most : static_cast<uint32_t>(share));
    }
    uint32_t key_of(uint32_t v) const {
        const GridLevel& l = levels[level_of(v)];
        const Local& p = points[v - 1];
        return l.key(l.cell_along(p.x, low.x, l.cells[0]), l.cell_along(p.y, low.y, l.cells[1]),
                     l.cell_along(p.h, low.z, l.cells[2]));
    }
    bool before(uint32_t v, uint32_t w) const {
        if (level_of(v) != level_of(w)) return level_of(v) < level_of(w);
        const uint32_t kv = key_of(v), kw = key_of(w);
        return kv < kw || (kv == kw && v < w);
    }
    // The first position of level l whose vertex's key is at least k.
    uint32_t first_at(const GridLevel& l, uint32_t k) const {
        uint32_t lo = l.first, hi = l.first + l.count;
        while (lo < hi) {
            const uint32_t mid = lo + (hi - lo) / 2;
            if (key_of(ids[mid]) < k)
                lo = mid + 1;
            else
                hi = mid;
        }
        return lo;
    }
    // Whether vertex v may have an edge of `length`.
    bool admits(uint32_t v, double length) const {
        return !sorted || length <= levels[level_of(v)].bound;
    }
    // Vertex v has an edge of `length` (admitted).
    void stretch(uint32_t v, double length) {
        if (!sorted) return;
        const uint32_t word = span_word(level_of(v), length);
        spans[v] = word > spans[v] ? word : spans[v];
    }
};

// The length of edge k of surface triangle t.
static inline double edge_length(const Triangulation& tr, const Local* points, uint32_t t,
                                 uint32_t k) {
    const uint32_t* v = tr.vertex + 3 * t;
    const Vec3 d = vec_of(points[v[(k + 1) % 3] - 1]) - vec_of(points[v[k] - 1]);
    return std::sqrt(dot(d, d));
}

// Sets up the grid of a layer's `vertices` in `ids`, `edge` and `spans`, each with room for
// every vertex: the half-edges now, the rest once a flip needs it (sort_layer_grid).
static inline void link_layer_grid(const Triangulation& tr, const Local* points, size_t vertices,
                                   uint32_t* ids, uint32_t* edge, uint32_t* spans,
                                   LayerGrid& grid) {
    grid.points = points;
    grid.ids = ids;
    grid.edge = edge;
    grid.spans = spans;
    grid.count = static_cast<uint32_t>(vertices - 1);
    grid.sorted = false;
    for (size_t v = 0; v < vertices; ++v) edge[v] = kNoIndex;  // duplicates have none
    for (uint32_t h = 0; h < 3 * tr.triangle_count; ++h)
        if (tr.vertex[h] != kGhost) edge[tr.vertex[h]] = h;
}

// Sorts the grid's vertices by level and cell (see above), once a flip needs it.
static inline void sort_layer_grid(const Triangulation& tr, LayerGrid& grid) {
    const Local* points = grid.points;
    uint32_t* ids = grid.ids;
    uint32_t* spans = grid.spans;
    const size_t vertices = size_t{grid.count} + 1;
    grid.sorted = true;
    for (size_t v = 0; v < vertices; ++v) spans[v] = 0;
    double length_sum = 0, longest = 0;
    size_t edges = 0;
    for (uint32_t t = 0; t < tr.triangle_count; ++t)
        for (uint32_t k = 0; on_surface(tr, t) && k < 3; ++k) {
            const double length = edge_length(tr, points, t, k);
            length_sum += length;
            longest = length > longest ? length : longest;
            ++edges;
        }
    const double mean = edges > 0 ? length_sum / static_cast<double>(edges) : 0;
    Vec3 low = vec_of(points[0]), high = low;
    for (size_t v = 1; v < vertices; ++v) {
        const Vec3 p = vec_of(points[v - 1]);
        low = Vec3{std::fmin(low.x, p.x), std::fmin(low.y, p.y), std::fmin(low.z, p.z)};
        high = Vec3{std::fmax(high.x, p.x), std::fmax(high.y, p.y), std::fmax(high.z, p.z)};
        ids[v - 1] = static_cast<uint32_t>(v);
    }
    grid.low = low;
    const double extent[3] = {high.x - low.x, high.y - low.y, high.z - low.z};
    for (uint32_t l = 0; l < kLevels; ++l) {
        GridLevel& g = grid.levels[l];
        g.bound = std::ldexp(mean / 2, static_cast<int>(l));
        if (l + 1 == kLevels) g.bound = std::fmax(g.bound, longest);
        double side = std::fmax(g.bound, 2 * mean);
        for (double e : extent) side = std::fmax(side, e / kGridCells);
        g.inverse_side = side > 0 ? 1 / side : 0;
        for (int d = 0; d < 3; ++d) {
            const double n = extent[d] * g.inverse_side + 1;
            g.cells[d] = n >= kGridCells ? kGridCells : static_cast<uint32_t>(n);
        }
        g.first = g.count = 0;
    }
    for (uint32_t t = 0; t < tr.triangle_count; ++t)
        for (uint32_t k = 0; on_surface(tr, t) && k < 3; ++k) {
            const double length = edge_length(tr, points, t, k);
            uint32_t l = 0;
            while (l + 1 < kLevels && length > grid.levels[l].bound) ++l;
            const uint32_t word = grid.span_word(l, length);
            const uint32_t a = tr.vertex[3 * t + k], b = tr.vertex[3 * t + (k + 1) % 3];
            spans[a] = word > spans[a] ? word : spans[a];
            spans[b] = word > spans[b] ? word : spans[b];
        }
    heap_sort(ids, grid.count, [&grid](uint32_t v, uint32_t w) { return grid.before(v, w); });
    for (uint32_t i = 0; i < grid.count; ++i) {
        GridLevel& g = grid.levels[grid.level_of(ids[i])];
        if (g.count++ == 0) g.first = i;
    }
}

// Whether clear(g) holds for every half-edge g leaving a vertex within its level's bound of
// `box` (each triangle tested from the first of its corners visited: kVisited marks them);
// false too if a level's region spans more than kGridColumns columns, more than
// kMostVisited vertices are near, or one has more than kFanLimit neighbours.
template <class Clear>
static inline bool region_clear(const Triangulation& tr, const LayerGrid& grid, const Box3& box,
                                uint32_t* flags, Clear clear) {
    uint32_t visited[kMostVisited];
    uint32_t visits = 0;
    auto unmark = [&]() {
        for (uint32_t k = 0; k < visits; ++k) flags[visited[k]] &= ~kVisited;
    };
    auto clear_once = [&](uint32_t g) {
        const uint32_t* c = tr.vertex + 3 * (g / 3);
        return c[0] == kGhost || c[1] == kGhost || c[2] == kGhost ||
               ((flags[c[0]] | flags[c[1]] | flags[c[2]]) & kVisited) || clear(g);
    };
    for (const GridLevel& l : grid.levels) {
        if (l.count == 0) continue;
        const double r = l.bound;
        const uint32_t x0 = l.cell_along(box.low.x - r, grid.low.x, l.cells[0]);
        const uint32_t x1 = l.cell_along(box.high.x + r, grid.low.x, l.cells[0]);
        const uint32_t y0 = l.cell_along(box.low.y - r, grid.low.y, l.cells[1]);
        const uint32_t y1 = l.cell_along(box.high.y + r, grid.low.y, l.cells[1]);
        const uint32_t z0 = l.cell_along(box.low.z - r, grid.low.z, l.cells[2]);
        const uint32_t z1 = l.cell_along(box.high.z + r, grid.low.z, l.cells[2]);
        if (size_t{x1 - x0 + 1} * (y1 - y0 + 1) > kGridColumns) {
            unmark();
            return false;
        }
        for (uint32_t ix = x0; ix <= x1; ++ix)
            for (uint32_t iy = y0; iy <= y1; ++iy) {
                const uint32_t last = l.key(ix, iy, z1), end = l.first + l.count;
                for (uint32_t i = grid.first_at(l, l.key(ix, iy, z0));
                     i < end && grid.key_of(grid.ids[i]) <= last; ++i) {
                    const uint32_t v = grid.ids[i];
                    const Vec3 p = vec_of(grid.points[v - 1]);
                    const Vec3 off = {
                        p.x < box.low.x ? box.low.x - p.x : p.x > box.high.x ? p.x - box.high.x : 0,
                        p.y < box.low.y ? box.low.y - p.y : p.y > box.high.y ? p.y - box.high.y : 0,
                        p.z < box.low.z ? box.low.z - p.z : p.z > box.high.z ? p.z - box.high.z : 0};
                    const double near = grid.span(v) * (1 + kGrow);
                    if (dot(off, off) > near * near || grid.edge[v] == kNoIndex) continue;
                    if (visits == kMostVisited || !around_vertex(tr, grid.edge[v], clear_once)) {
                        unmark();
                        return false;
                    }
                    flags[v] |= kVisited;
                    visited[visits++] = v;
                }
            }
    }
    unmark();
    return true;
}

// The vertex normals, kept in the room of the annulus coordinates (free once the loops are
// settled) as two 16-bit integers a vertex, a unit vector's octahedral encoding (its
// coordinates over their absolute sum, the lower half folded out, to 1/32767): the sum of
// the unit normals of the surface triangles around the vertex, made unit.
struct VertexNormals {
    int16_t* room;
    static constexpr int16_t kNone = INT16_MIN;  // no normal
    static constexpr double kScale = 32767, kUnit = 1 / kScale;

    // The unit normal at vertex v; zero if it has no surface triangle of nonzero area.
    Vec3 at(uint32_t v) const {
        if (room[2 * size_t{v}] == kNone) return Vec3{0, 0, 0};
        const double u = room[2 * size_t{v}] * kUnit, w = room[2 * size_t{v} + 1] * kUnit;
        const double z = 1 - std::fabs(u) - std::fabs(w);
        Vec3 n = z >= 0 ? Vec3{u, w, z}
                        : Vec3{std::copysign(1 - std::fabs(w), u),
                               std::copysign(1 - std::fabs(u), w), z};
        return scaled(n, 1 / std::sqrt(dot(n, n)));
    }
    void put(uint32_t v, Vec3 sum) {
        int16_t* slot = room + 2 * size_t{v};
        const double l1 = std::fabs(sum.x) + std::fabs(sum.y) + std::fabs(sum.z);
        if (!(l1 > 0)) {
            slot[0] = slot[1] = kNone;
            return;
        }
        double u = sum.x / l1, w = sum.y / l1;
        if (sum.z < 0) {
            const double fu = std::copysign(1 - std::fabs(w), u);
            w = std::copysign(1 - std::fabs(u), w);
            u = fu;
        }
        slot[0] = static_cast<int16_t>(std::lround(u * kScale));
        slot[1] = static_cast<int16_t>(std::lround(w * kScale));
    }
    // The normal from the triangles around it (a vertex with more than kFanLimit
    // neighbours has none) of every vertex, or with `changed` of those flagged with it (the
    // corners of the quads flipped since: no other vertex's triangles changed).
    void estimate(const Triangulation& tr, const Local* points, const LayerGrid& grid,
                  const uint32_t* flags, uint32_t changed) {
        put(0, Vec3{0, 0, 0});
        for (uint32_t v = 1; v <= grid.count; ++v) {
            if (changed && !(flags[v] & changed)) continue;
            Vec3 sum = {0, 0, 0};
            const bool fan = grid.edge[v] != kNoIndex && around_vertex(tr, grid.edge[v], [&](uint32_t g) {
                const uint32_t s = g / 3;
                if (!on_surface(tr, s)) return true;
                const uint32_t* c = tr.vertex + 3 * s;
                const Vec3 n = normal_of(points[c[0] - 1], points[c[1] - 1], points[c[2] - 1]);
                const double length = std::sqrt(dot(n, n));
                if (length > 0) sum = sum + scaled(n, 1 / length);
                return true;
            });
            put(v, fan ? sum : Vec3{0, 0, 0});
        }
    }
};

// How much the surface bends along edge ab, with unit normals na and nb at its ends (see
// above).
static inline double bend_along(Vec3 a, Vec3 b, Vec3 na, Vec3 nb) {
    return std::fabs(dot(b - a, nb - na));
}

// The cosine of the widest angle of triangle abc.
static inline double widest_angle_cosine(Vec3 a, Vec3 b, Vec3 c) {
    const Vec3 corner[3] = {a, b, c};
    double widest = 1;
    for (int k = 0; k < 3; ++k) {
        const Vec3 u = corner[(k + 1) % 3] - corner[k], v = corner[(k + 2) % 3] - corner[k];
        const double lengths = std::sqrt(dot(u, u) * dot(v, v));
        const double cosine = lengths > 0 ? dot(u, v) / lengths : -1;
        widest = cosine < widest ? cosine : widest;
    }
    return widest;
}

// Whether the surface wants ab of triangles abp and baq turned into pq, by the two rules
// (see above; na .. nq the corners' unit normals, none zero) without an angle wider than
// kWidestAngle (unless the old pair had a wider one).
static inline bool flip_wanted(const Local& la, const Local& lb, const Local& lp, const Local& lq,
                               Vec3 na, Vec3 nb, Vec3 np, Vec3 nq) {
    if (dot(na, na) == 0 || dot(nb, nb) == 0 || dot(np, np) == 0 || dot(nq, nq) == 0)
        return false;
    const double bend_before = bend_along(vec_of(la), vec_of(lb), na, nb);
    const double bend_after = bend_along(vec_of(lp), vec_of(lq), np, nq);
    if (flip_helps(vec_of(la), vec_of(lb), vec_of(lp), vec_of(lq))
            ? bend_after > kBendVeto * bend_before
            : !(kBendGain * bend_after < bend_before))
        return false;
    const double widest_after =
        std::fmin(widest_angle_cosine(vec_of(lp), vec_of(la), vec_of(lq)),
                  widest_angle_cosine(vec_of(lq), vec_of(lb), vec_of(lp)));
    return !(widest_after < kWidestAngle &&
             widest_after < std::fmin(widest_angle_cosine(vec_of(la), vec_of(lb), vec_of(lp)),
                                      widest_angle_cosine(vec_of(lb), vec_of(la), vec_of(lq))));
}

// Whether both new triangles (p, a, q) and (q, b, p) of that flip have normals within
// kGentleFlip of the old pair's mean.
static inline bool gentle_flip(const Local& la, const Local& lb, const Local& lp, const Local& lq) {
    Vec3 mean = normal_of(la, lb, lp);
    const Vec3 other_normal = normal_of(lb, la, lq);
    mean = Vec3{mean.x + other_normal.x, mean.y + other_normal.y, mean.z + other_normal.z};
    const Vec3 n1 = normal_of(lp, la, lq), n2 = normal_of(lq, lb, lp);
    return dot(n1, mean) > kGentleFlip * std::sqrt(dot(n1, n1) * dot(mean, mean)) &&
           dot(n2, mean) > kGentleFlip * std::sqrt(dot(n2, n2) * dot(mean, mean));
}

// Whether a new triangle of that flip faces away from the old pair's mean normal: turned
// over, a pleat in the surface.
static inline bool turns_over(const Local& la, const Local& lb, const Local& lp, const Local& lq) {
    const Vec3 mean = normal_of(la, lb, lp) + normal_of(lb, la, lq);
    return !(dot(normal_of(lp, la, lq), mean) > 0) || !(dot(normal_of(lq, lb, lp), mean) > 0);
}

// Flips half-edge e of a layer's triangulation on the surface if that helps (see above).
static inline bool flip_on_surface(Triangulation& tr, const Local* points, uint32_t* flags,
                                   VertexNormals& normals, LayerGrid& grid, const Cylinder& cyl,
                                   uint32_t e) {
    const uint32_t f = tr.twin[e];
    const uint32_t t = e / 3, u = f / 3;
    if (!on_surface(tr, u)) return false;
    const uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)], p = tr.vertex[prev_edge(e)];
    const uint32_t q = tr.vertex[prev_edge(f)];
    // A chord of a loop would stand where add_caps puts its cap.
    if (p == q || (flags[p] & flags[q] & (kOnBottomLoop | kOnTopLoop))) return false;
    const Local &la = points[a - 1], &lb = points[b - 1], &lp = points[p - 1], &lq = points[q - 1];
    if (!flip_wanted(la, lb, lp, lq, normals.at(a), normals.at(b), normals.at(p), normals.at(q)))
        return false;
    // The new triangles (p, a, q) and (q, b, p), counter-clockwise on the annulus.
    if (doubled_area(lp, la, lq) == 0 || doubled_area(lq, lb, lp) == 0 ||
        turns_over(la, lb, lp, lq))
        return false;
    if (!around_vertex(tr, prev_edge(e), [&tr, q](uint32_t g) {
            return tr.vertex[next_edge(g)] != q;
        }))
        return false;
    const Vec3 first[3] = {vec_of(lp), vec_of(la), vec_of(lq)};
    const Vec3 second[3] = {vec_of(lq), vec_of(lb), vec_of(lp)};
    const Box3 quad = box_of(first[0], first[1], first[2], second[1]);
    auto clear_of = [&](uint32_t g) {
        const uint32_t s = g / 3;
        if (s == t || s == u || !on_surface(tr, s)) return true;
        const uint32_t* v = tr.vertex + 3 * s;
        const Vec3 other[3] = {vec_of(points[v[0] - 1]), vec_of(points[v[1] - 1]),
                               vec_of(points[v[2] - 1])};
        if (!quad.meets(box_of(other[0], other[1], other[2], other[2]))) return true;
        const auto has = [v](uint32_t x) { return v[0] == x || v[1] == x || v[2] == x; };
        const bool shares_pq = has(p) || has(q);
        return !triangles_meet(first, other, shares_pq || has(a) ? 1 - kShrink : 1 + kGrow) &&
               !triangles_meet(second, other, shares_pq || has(b) ? 1 - kShrink : 1 + kGrow);
    };
    const Vec3 pq = first[2] - first[0];
    const double pq_length = std::sqrt(dot(pq, pq));
    const bool new_fold = faces_axis(lq, la, lp, cyl) || faces_axis(lp, lb, lq, cyl);
    const bool near_fold = new_fold || ((flags[a] | flags[b] | flags[p] | flags[q]) & kNearFold);
    if (near_fold && !grid.sorted) sort_layer_grid(tr, grid);
    if (!grid.admits(p, pq_length) || !grid.admits(q, pq_length)) return false;
    if (near_fold) {
        if (!region_clear(tr, grid, quad, flags, clear_of)) return false;
    } else if (!gentle_flip(la, lb, lp, lq)) {
        // Away from folds the layer is its annulus lifted: a gentle flip covers about the
        // same place as before, another is checked against the triangles around the quad.
        const uint32_t corners[4] = {e, f, prev_edge(e), prev_edge(f)};
        for (uint32_t corner : corners)
            if (!around_vertex(tr, corner, clear_of)) return false;
    }
    flip_edge<false>(tr, e, nullptr);
    // t is (p, a, q) now and u (q, b, p); their corners leave by these half-edges.
    grid.edge[p] = 3 * t;
    grid.edge[a] = 3 * t + 1;
    grid.edge[q] = 3 * u;
    grid.edge[b] = 3 * u + 1;
    grid.stretch(p, pq_length);
    grid.stretch(q, pq_length);
    if (new_fold) {
        flags[a] |= kNearFold;
        flags[b] |= kNearFold;
        flags[p] |= kNearFold;
        flags[q] |= kNearFold;
    }
    return true;
}

// Flips the surface edges of a layer's triangulation, sweep after sweep, until a sweep
// flips none or kSurfaceFlipSweeps have run; after the first sweep, only edges between
// two corners of quads flipped in the sweep before (the edges whose triangles changed).
// `flags` holds a word per vertex (see triangulate_layer); the bits kFlippedBefore,
// kFlippedNow, kVisited and kNearFold are used here and cleared. `room` is the annulus
// coordinates, two doubles a vertex, overwritten by four words a vertex: the normals, the
// grid's order, each vertex's half-edge and its span. Returns the number of flips.
static inline size_t flip_layer_on_surface(Triangulation& tr, const Local* points,
                                           const Cylinder& cyl, uint32_t* flags, double* room,
                                           size_t vertices) {
    // Four words a vertex: the normal, the grid's order, the half-edges and the spans.
    int16_t* normal_room = reinterpret_cast<int16_t*>(room);
    uint32_t* grid_room = reinterpret_cast<uint32_t*>(room) + vertices;
    LayerGrid grid;
    link_layer_grid(tr, points, vertices, grid_room, grid_room + vertices,
                    grid_room + 2 * vertices, grid);
    for (uint32_t t = 0; t < tr.triangle_count; ++t) {
        const uint32_t* v = tr.vertex + 3 * t;
        // Counter-clockwise on the annulus: faces_axis takes the corners the other way.
        if (on_surface(tr, t) && faces_axis(points[v[2] - 1], points[v[1] - 1], points[v[0] - 1], cyl)) {
            flags[v[0]] |= kNearFold;
            flags[v[1]] |= kNearFold;
            flags[v[2]] |= kNearFold;
        }
    }
    VertexNormals normals = {normal_room};
    size_t flips = 0;
    for (uint32_t sweep = 0; sweep < kSurfaceFlipSweeps; ++sweep) {
        if (sweep < kNormalSweeps)
            normals.estimate(tr, points, grid, flags, sweep == 0 ? 0 : kFlippedBefore);
        size_t flipped = 0;
        for (uint32_t t = 0; t < tr.triangle_count; ++t) {
            if (!on_surface(tr, t)) continue;
            const uint32_t* v = tr.vertex + 3 * t;
            // After the first sweep: at least two corners flipped before.
            if (sweep > 0 && ((flags[v[0]] & kFlippedBefore) + (flags[v[1]] & kFlippedBefore) +
                              (flags[v[2]] & kFlippedBefore)) < 2 * kFlippedBefore)
                continue;
            for (uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
                // Each edge once a sweep, from the side of its larger half-edge.
                const uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)];
                if (tr.twin[e] > e || (sweep > 0 && !(flags[a] & flags[b] & kFlippedBefore)) ||
                    !flip_on_surface(tr, points, flags, normals, grid, cyl, e))
                    continue;
                ++flipped;
                // t is (p, a, q) after the flip, and the twin's triangle (q, b, p).
                flags[tr.vertex[3 * t]] |= kFlippedNow;
                flags[tr.vertex[3 * t + 1]] |= kFlippedNow;
                flags[tr.vertex[3 * t + 2]] |= kFlippedNow;
                flags[b] |= kFlippedNow;
                break;
            }
        }
        for (size_t v = 0; v < vertices; ++v)
            flags[v] = (flags[v] & ~(kFlippedBefore | kFlippedNow)) |
                       ((flags[v] & kFlippedNow) ? kFlippedBefore : 0);
        flips += flipped;
        if (flipped == 0) break;
    }
    for (size_t v = 0; v < vertices; ++v) flags[v] &= ~(kFlippedBefore | kNearFold);
    return flips;
}

// ---- flips across the seam ----
//
// With the surface_flips flag. A layer's flips on the surface (see "flips on the surface")
// run before its band is stitched and never move a loop's edge, so the band and the layer's
// triangles at its bottom loop keep the unrolled Delaunay's choice, and every cut would
// cost closeness to the surface (twice as much as with the seam's flips). Once a chunk is
// final, its seam (the triangles with a corner on the loop below or on the layer's bottom
// loop) is flipped by the same rules, with three limits that keep everything outside the
// seam as it is:
//  - only edges between two seam triangles, so the loop below's edges, the edges to the
//    rest of the chunk and the chunk before (which the stream has handed out) stay;
//  - only flips where p or q is a loop point: a loop point's triangles in the chunk are all
//    in the seam, so whether pq is an edge already is read from its fan (the loop below's
//    other side, in the chunk before, has no point of this layer), and a chord between two
//    points of one loop (the loop below, the layer's bottom or top loop) is refused, as it
//    would stand where the next band or a cap goes; both new triangles keep that corner,
//    so they stay in the seam;
//  - only gentle flips (kGentleFlip), which need no crossing test, none that makes or
//    unmakes a fold (the layer's cylinder), so Report::diagnostics.fold_count keeps its
//    count, and none with a corner on a triangle facing the axis (kSeamNearFold), where the
//    layer's flips may have laid the lifted annulus over itself (without that, seam flips
//    made 3 crossing pairs on a lion head scan).
// Vertex normals come from every triangle of the chunk. The seam's memory, at most about
// 72 bytes per vertex of the chunk and 4 per point read, fits in the safety net's room
// (reconstruct_scratch_size: 91 per point) because a seam of more triangles than three
// quarters of the chunk's vertices is left as it is: a thin layer, mostly loop.

const uint32_t kLoopBelow = 1, kBottomLoopPoint = 2, kTopLoopPoint = 4, kLoopBits = 3;

const unsigned char kSeamNearFold = 8;  // in Seam::loop: a corner of a triangle facing the axis

struct Seam {
    uint32_t* chunk;        // the chunk's triangles, reader indices
    uint32_t* slot;         // seam triangle s is chunk triangle slot[s]
    uint32_t* vertex;       // 3 per seam triangle: its seam points
    uint32_t* twin;         // 3 per seam triangle: the opposite half-edge, or kNoIndex
    uint32_t* degree;       // per seam point: its seam triangles
    uint32_t* ids;          // per seam point: its reader index
    unsigned char* loop;    // per seam point: kLoopBelow, kBottomLoopPoint, kTopLoopPoint
    float* fixed_normal;    // 3 per seam point: the sum over its triangles off the seam
    float* normal;          // 3 per seam point
    // Per reader index of the chunk's points and loops (the rest unset): its loop bits,
    // and above them (seam point + 1) << kLoopBits once it is one.
    uint32_t* tag;
    uint32_t triangles, points;

    // The seam point of reader index id (one of the chunk's), or kNoIndex.
    uint32_t point_of(uint32_t id) const {
        return (tag[id] >> kLoopBits) == 0 ? kNoIndex : (tag[id] >> kLoopBits) - 1;
    }
};

// Tags the chunk's points and the loops' with their loop bits, over reader indices up to
// the largest of theirs; room for `most` seam triangles. False if the arena is too small.
static inline bool tag_seam_points(const SurfaceChain& c, const LoadedLayer& layer,
                                   const LayerLoops& loops, size_t count, size_t most, Arena& arena,
                                   Seam& seam) {
    const uint32_t* chunk = seam.chunk;
    uint32_t largest = 0;
    for (size_t k = 0; k < 3 * count; ++k) largest = chunk[k] > largest ? chunk[k] : largest;
    for (uint32_t i = 0; i < c.top_count; ++i) largest = c.top[i] > largest ? c.top[i] : largest;
    for (uint32_t i = 0; i < layer.count; ++i)
        largest = layer.ids[i] > largest ? layer.ids[i] : largest;
    seam.tag = arena.alloc<uint32_t>(size_t{largest} + 1);
    seam.slot = arena.alloc<uint32_t>(most);
    if (arena.failed) return false;
    for (size_t k = 0; k < 3 * count; ++k) seam.tag[chunk[k]] = 0;
    for (uint32_t i = 0; i < c.top_count; ++i) seam.tag[c.top[i]] = kLoopBelow;
    for (uint32_t i = 0; i < loops.bottom_count; ++i) seam.tag[layer.ids[loops.bottom[i]]] = 0;
    for (uint32_t i = 0; i < loops.top_count; ++i) seam.tag[layer.ids[loops.top[i]]] = 0;
    for (uint32_t i = 0; i < loops.bottom_count; ++i)
        seam.tag[layer.ids[loops.bottom[i]]] |= kBottomLoopPoint;
    for (uint32_t i = 0; i < loops.top_count; ++i)
        seam.tag[layer.ids[loops.top[i]]] |= kTopLoopPoint;
    return true;
}

// Numbers the seam triangles' points (seam.ids, and in their tags) and names their corners
// by them, with each point's loop bits and seam triangle count. False if the arena is too
// small.
static inline bool number_seam_points(Arena& arena, Seam& seam) {
    const size_t triangles = seam.triangles;
    seam.vertex = arena.alloc<uint32_t>(3 * triangles);
    seam.twin = arena.alloc<uint32_t>(3 * triangles);
    seam.ids = arena.alloc<uint32_t>(3 * triangles);
    if (arena.failed) return false;
    uint32_t points = 0;
    for (size_t s = 0; s < triangles; ++s)
        for (uint32_t j = 0; j < 3; ++j) {
            const uint32_t id = seam.chunk[3 * size_t{seam.slot[s]} + j];
            if ((seam.tag[id] >> kLoopBits) == 0) {
                seam.ids[points] = id;
                seam.tag[id] |= (points + 1) << kLoopBits;
                ++points;
            }
            seam.vertex[3 * s + j] = (seam.tag[id] >> kLoopBits) - 1;
        }
    seam.points = points;
    seam.degree = arena.alloc<uint32_t>(points);
    seam.loop = arena.alloc<unsigned char>(points);
    seam.fixed_normal = arena.alloc<float>(3 * size_t{points});
    seam.normal = arena.alloc<float>(3 * size_t{points});
    if (arena.failed) return false;
    for (uint32_t v = 0; v < points; ++v) {
        seam.loop[v] = static_cast<unsigned char>(seam.tag[seam.ids[v]] & 7u);
        seam.degree[v] = 0;
    }
    for (size_t i = 0; i < 3 * triangles; ++i) ++seam.degree[seam.vertex[i]];
    return true;
}

// Each seam half-edge's twin, found through each point's outgoing half-edges. False if
// the arena is too small.
static inline bool link_seam_twins(Arena& arena, Seam& seam) {
    const uint32_t points = seam.points, triangles = seam.triangles;
    size_t mark = arena.mark();
    uint32_t* first = arena.alloc<uint32_t>(size_t{points} + 1);
    uint32_t* outgoing = arena.alloc<uint32_t>(3 * size_t{triangles});
    if (arena.failed) return false;
    std::memset(first, 0, (size_t{points} + 1) * sizeof(uint32_t));
    for (size_t e = 0; e < 3 * size_t{triangles}; ++e) ++first[seam.vertex[e] + 1];
    for (uint32_t v = 0; v < points; ++v) first[v + 1] += first[v];
    for (uint32_t e = 0; e < 3 * triangles; ++e) outgoing[first[seam.vertex[e]]++] = e;
    for (uint32_t v = points; v > 0; --v) first[v] = first[v - 1];
    first[0] = 0;
    for (uint32_t e = 0; e < 3 * triangles; ++e) {
        const uint32_t a = seam.vertex[e], b = seam.vertex[next_edge(e)];
        seam.twin[e] = kNoIndex;
        for (uint32_t i = first[b]; i < first[b + 1]; ++i)
            if (seam.vertex[next_edge(outgoing[i])] == a) seam.twin[e] = outgoing[i];
    }
    arena.rewind(mark);
    return true;
}

// The seam of a chunk (see above). False with seam.triangles = 0 when it is left as it is;
// false with arena.failed when the arena is too small.
static inline bool find_seam(const SurfaceChain& c, const LoadedLayer& layer,
                             const LayerLoops& loops, uint32_t* chunk, size_t count, Arena& arena,
                             Seam& seam) {
    seam.chunk = chunk;
    seam.triangles = 0;
    const size_t vertices = layer.count + c.top_count;
    // More seam triangles: left as it is (and the tags' seam points fit above the bits).
    size_t most = 3 * vertices / 4;
    if (most > (kNoIndex >> kLoopBits) / 3) most = (kNoIndex >> kLoopBits) / 3;
    if (!tag_seam_points(c, layer, loops, count, most, arena, seam)) return false;
    size_t triangles = 0;
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* v = chunk + 3 * t;
        if (!((seam.tag[v[0]] | seam.tag[v[1]] | seam.tag[v[2]]) & (kLoopBelow | kBottomLoopPoint)))
            continue;
        if (triangles == most) return false;
        seam.slot[triangles++] = static_cast<uint32_t>(t);
    }
    if (triangles == 0) return false;
    seam.triangles = static_cast<uint32_t>(triangles);
    return number_seam_points(arena, seam) && link_seam_twins(arena, seam);
}

// Seam point v's normal.
static inline Vec3 seam_normal(const Seam& seam, uint32_t v) {
    const float* n = seam.normal + 3 * size_t{v};
    return Vec3{static_cast<double>(n[0]), static_cast<double>(n[1]),
                static_cast<double>(n[2])};
}

// Adds triangle v's unit normal to sums[3 k] for each corner k of it that is a seam point.
static inline void add_seam_normal(const SurfaceChain& c, const Seam& seam, const uint32_t* v,
                                   float* sums) {
    const uint32_t at[3] = {seam.point_of(v[0]), seam.point_of(v[1]), seam.point_of(v[2])};
    if (at[0] == kNoIndex && at[1] == kNoIndex && at[2] == kNoIndex) return;
    Vec3 n = normal_of(c.frame.local(c.reader.point(v[0])), c.frame.local(c.reader.point(v[1])),
                       c.frame.local(c.reader.point(v[2])));
    const double length = std::sqrt(dot(n, n));
    if (length == 0) return;
    n = scaled(n, 1 / length);
    for (uint32_t k : at) {
        if (k == kNoIndex) continue;
        float* sum = sums + 3 * size_t{k};
        sum[0] += static_cast<float>(n.x);
        sum[1] += static_cast<float>(n.y);
        sum[2] += static_cast<float>(n.z);
    }
}

// The sums of the unit normals of the chunk's triangles off the seam, at the seam's points.
static inline void sum_fixed_normals(const SurfaceChain& c, const Seam& seam, size_t count) {
    std::memset(seam.fixed_normal, 0, 3 * size_t{seam.points} * sizeof(float));
    uint32_t next = 0;  // seam.slot is increasing
    for (size_t t = 0; t < count; ++t) {
        if (next < seam.triangles && seam.slot[next] == t) {
            ++next;
            continue;
        }
        add_seam_normal(c, seam, seam.chunk + 3 * t, seam.fixed_normal);
    }
}

// The seam's vertex normals over every triangle of the chunk (see VertexNormals): the fixed
// sums and the seam's own triangles, made unit.
static inline void estimate_seam_normals(const SurfaceChain& c, const Seam& seam) {
    std::memcpy(seam.normal, seam.fixed_normal, 3 * size_t{seam.points} * sizeof(float));
    for (uint32_t s = 0; s < seam.triangles; ++s)
        add_seam_normal(c, seam, seam.chunk + 3 * size_t{seam.slot[s]}, seam.normal);
    for (uint32_t k = 0; k < seam.points; ++k) {
        float* sum = seam.normal + 3 * size_t{k};
        const Vec3 n = seam_normal(seam, k);
        const double length = std::sqrt(dot(n, n));
        if (length == 0) continue;
        sum[0] = static_cast<float>(n.x / length);
        sum[1] = static_cast<float>(n.y / length);
        sum[2] = static_cast<float>(n.z / length);
    }
}

// Marks kSeamNearFold the seam points at a corner of a chunk triangle facing the axis: the
// layer's flips on the surface may leave such triangles where the surface turns to face the
// axis, and a flip beside them, gentle as it is, could cross them.
static inline void mark_near_folds(const SurfaceChain& c, Seam& seam, const Cylinder& cyl,
                                   size_t count) {
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* v = seam.chunk + 3 * t;
        const uint32_t at[3] = {seam.point_of(v[0]), seam.point_of(v[1]), seam.point_of(v[2])};
        if (at[0] == kNoIndex && at[1] == kNoIndex && at[2] == kNoIndex) continue;
        if (!faces_axis(c.frame.local(c.reader.point(v[0])), c.frame.local(c.reader.point(v[1])),
                        c.frame.local(c.reader.point(v[2])), cyl))
            continue;
        for (uint32_t k : at)
            if (k != kNoIndex) seam.loop[k] |= kSeamNearFold;
    }
}

// Whether seam point x's triangles, walked around it from half-edge `from` (leaving x) both
// ways, are all of its seam triangles and none has an edge to y.
static inline bool fan_misses(const Seam& seam, uint32_t from, uint32_t x, uint32_t y) {
    uint32_t seen = 0;
    auto clear = [&seam, y](uint32_t g) {
        return seam.vertex[next_edge(g)] != y && seam.vertex[prev_edge(g)] != y;
    };
    uint32_t g = from;
    for (uint32_t steps = 0;; ++steps) {
        if (steps == kFanLimit || !clear(g)) return false;
        ++seen;
        const uint32_t h = seam.twin[prev_edge(g)];
        if (h == from) return seen == seam.degree[x];
        if (h == kNoIndex) break;
        g = h;
    }
    g = from;
    for (uint32_t steps = 0;; ++steps) {
        const uint32_t back = seam.twin[g];
        if (back == kNoIndex) break;
        g = next_edge(back);
        if (steps == kFanLimit || !clear(g)) return false;
        ++seen;
    }
    return seen == seam.degree[x];
}

// Flips half-edge e of the seam if that helps (see above and flip_on_surface).
static inline bool flip_seam_edge(const SurfaceChain& c, Seam& seam, const Cylinder& cyl,
                                  uint32_t e) {
    const uint32_t f = seam.twin[e];
    if (f == kNoIndex) return false;
    const uint32_t a = seam.vertex[e], b = seam.vertex[next_edge(e)];
    const uint32_t p = seam.vertex[prev_edge(e)], q = seam.vertex[prev_edge(f)];
    if (p == q || (seam.loop[p] & seam.loop[q] & 7u) ||
        !((seam.loop[p] | seam.loop[q]) & (kLoopBelow | kBottomLoopPoint)) ||
        ((seam.loop[a] | seam.loop[b] | seam.loop[p] | seam.loop[q]) & kSeamNearFold))
        return false;
    const bool p_anchors = (seam.loop[p] & (kLoopBelow | kBottomLoopPoint)) != 0;
    if (p_anchors ? !fan_misses(seam, prev_edge(e), p, q) : !fan_misses(seam, prev_edge(f), q, p))
        return false;
    const Local la = c.frame.local(c.reader.point(seam.ids[a]));
    const Local lb = c.frame.local(c.reader.point(seam.ids[b]));
    const Local lp = c.frame.local(c.reader.point(seam.ids[p]));
    const Local lq = c.frame.local(c.reader.point(seam.ids[q]));
    if (!flip_wanted(la, lb, lp, lq, seam_normal(seam, a), seam_normal(seam, b),
                     seam_normal(seam, p), seam_normal(seam, q)))
        return false;
    // The chunk's triangles face outwards counter-clockwise, as do the new (p, a, q) and
    // (q, b, p).
    if (faces_axis(la, lb, lp, cyl) || faces_axis(lb, la, lq, cyl) ||
        faces_axis(lp, la, lq, cyl) || faces_axis(lq, lb, lp, cyl) ||
        doubled_area(lp, la, lq) == 0 || doubled_area(lq, lb, lp) == 0)
        return false;
    if (!gentle_flip(la, lb, lp, lq)) return false;
    const uint32_t t = e / 3, u = f / 3;
    const uint32_t xa = seam.twin[next_edge(e)], xb = seam.twin[prev_edge(e)];
    const uint32_t xc = seam.twin[next_edge(f)], xd = seam.twin[prev_edge(f)];
    const uint32_t corners[6] = {p, a, q, q, b, p};
    for (uint32_t j = 0; j < 3; ++j) {
        seam.vertex[3 * t + j] = corners[j];
        seam.vertex[3 * u + j] = corners[3 + j];
        seam.chunk[3 * size_t{seam.slot[t]} + j] = seam.ids[corners[j]];
        seam.chunk[3 * size_t{seam.slot[u]} + j] = seam.ids[corners[3 + j]];
    }
    auto link = [&seam](uint32_t g, uint32_t h) {
        seam.twin[g] = h;
        if (h != kNoIndex) seam.twin[h] = g;
    };
    link(3 * t, xb);
    link(3 * t + 1, xc);
    link(3 * u, xd);
    link(3 * u + 1, xa);
    link(3 * t + 2, 3 * u + 2);
    --seam.degree[a];
    --seam.degree[b];
    ++seam.degree[p];
    ++seam.degree[q];
    return true;
}

// Flips a final chunk's seam (reader indices) on the surface, sweep after sweep as
// flip_layer_on_surface does. Returns false if the arena is too small.
static inline bool flip_seam(const SurfaceChain& c, const LoadedLayer& layer,
                             const LayerLoops& loops, uint32_t* chunk, size_t count, Arena& arena) {
    size_t mark = arena.mark();
    Seam seam;
    if (!find_seam(c, layer, loops, chunk, count, arena, seam)) {
        arena.rewind(mark);
        return !arena.failed;
    }
    sum_fixed_normals(c, seam, count);
    mark_near_folds(c, seam, layer.cyl, count);
    for (uint32_t sweep = 0; sweep < kSurfaceFlipSweeps; ++sweep) {
        if (sweep < kNormalSweeps) estimate_seam_normals(c, seam);
        size_t flipped = 0;
        for (uint32_t s = 0; s < seam.triangles; ++s)
            for (uint32_t e = 3 * s; e < 3 * s + 3; ++e) {
                const uint32_t f = seam.twin[e];
                if (f == kNoIndex || f > e || !flip_seam_edge(c, seam, layer.cyl, e)) continue;
                ++flipped;
                break;
            }
        if (flipped == 0) break;
    }
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh

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

// >>surface loops ========================================================================
// The boundary loops of a surface, traced from its triangles.

namespace stratmesh {
namespace detail {

// The surface's directed edges between boundary vertices, grouped by first vertex, each
// group sorted; and per vertex the far end of its boundary edge. The output is
// vertex-manifold, so a vertex has at most one boundary edge leaving it.
struct CapGraph {
    size_t* offsets;          // point_count + 1: each vertex's range in `targets`
    uint32_t* targets;        // at most 3 per triangle
    uint32_t* boundary_next;  // per vertex, or kNoIndex

    bool leads_to(uint32_t a, uint32_t b) const {
        size_t lo = offsets[a], hi = offsets[a + 1];
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (targets[mid] < b) lo = mid + 1; else hi = mid;
        }
        return lo < offsets[a + 1] && targets[lo] == b;
    }
    // For boundary vertices a and b only.
    bool has_edge(uint32_t a, uint32_t b) const { return leads_to(a, b) || leads_to(b, a); }
};

// The simplicity sweep keys a loop edge by its smaller x and its index, packed in 64 bits:
// the high 32 bits of an unsigned integer that orders as x does (finite, -0 as +0), then
// the index. Coarser than x, the key still never orders an edge before one whose smaller x
// is below its own, so the sweep meets every pair whose x ranges overlap (and a few more,
// which the exact test settles).
static inline uint32_t sweep_key(double x) {
    x += 0.0;
    uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    bits = (bits >> 63) ? ~bits : bits | (uint64_t{1} << 63);
    return static_cast<uint32_t>(bits >> 32);
}

// The arrays of one loop, sized for all boundary vertices together (every loop fits).
// Positions are the loop's vertices in cap order, 0 .. length - 1.
struct CapLoop {
    uint32_t* ids;            // all loops one after another, each in cap order
    unsigned char* starts;    // per entry of `ids`: kLoopStart, kLoopBroken or 0
    double* xy;               // per position: the projection, mirrored to turn counter-clockwise
    double* height;           // per position, for the flips: the height along the axis (in
                              // the clipping arrays' memory)
    unsigned char* flags;     // per position while clipping, per cap triangle while flipping
    double* scratch;          // for incircle
    uint64_t* sweep;          // per edge (sweep_key); shares its memory with the arrays below
    uint32_t* prev;           // per position: the neighbours in the polygon left to clip
    uint32_t* next;
    uint32_t* reflex;         // positions that were not strictly convex when last checked
    uint32_t* owner;          // per position p: the cap triangle edge (3 t + k) beyond the
                              // polygon edge p -> next[p], or kNoIndex on the loop itself
    uint32_t* corners;        // per cap triangle: 3 positions, counter-clockwise
    uint32_t* across;         // per cap triangle edge k (corner k to k + 1): the edge beyond
    uint32_t* stack;          // cap triangles whose edges are to be checked (before the
                              // cap, the positions on its pockets' hull)
    uint8_t* search;          // per pair of positions i < j: the cap search's choice, k - i
                              // (allocated, and read, only where kCapSearchCorners > 0)
};

const unsigned char kLoopStart = 1, kLoopBroken = 2;

const unsigned char kFinSeen = 1, kFinFlippable = 2, kFinWaived = 4, kFinUsed = 8;

// The allocation sequences of the cap phase: the call runs them with its real sizes,
// reconstruct_workspace_size with the largest possible ones, so the two cannot disagree.
static inline bool allocate_cap_graph(CapGraph& g, size_t point_count, size_t triangle_count,
                               Arena& arena) {
    g.offsets = arena.alloc<size_t>(point_count + 1);
    g.targets = arena.alloc<uint32_t>(3 * triangle_count);
    g.boundary_next = arena.alloc<uint32_t>(point_count);
    return !arena.failed;
}

static inline bool allocate_cap_loop(CapLoop& c, size_t length, Arena& arena) {
    c.ids = arena.alloc<uint32_t>(length);
    c.starts = arena.alloc<unsigned char>(length);
    c.xy = arena.alloc<double>(2 * length);
    c.flags = arena.alloc<unsigned char>(length);
    c.scratch = arena.alloc<double>(kIncircleScratch);
    // The sweep is over before clipping starts: the clipping arrays reuse its memory; and
    // the heights, filled once the clipping is over, reuse the clipping arrays'.
    size_t mark = arena.mark();
    c.sweep = arena.alloc<uint64_t>(length);
    arena.rewind(mark);
    c.height = arena.alloc<double>(length);
    arena.rewind(mark);
    c.prev = arena.alloc<uint32_t>(length);
    c.next = arena.alloc<uint32_t>(length);
    c.reflex = arena.alloc<uint32_t>(length);
    c.owner = arena.alloc<uint32_t>(length);
    c.corners = arena.alloc<uint32_t>(3 * length);
    c.across = arena.alloc<uint32_t>(3 * length);
    c.stack = arena.alloc<uint32_t>(length);
    if (kCapSearchCorners > 0) {
        const size_t searched = length < kCapSearchCorners ? length : kCapSearchCorners;
        c.search = arena.alloc<uint8_t>(searched * (searched - 1) / 2);
    }
    return !arena.failed;
}

// Fills the graph from the triangles; returns the number of boundary vertices. Only edges
// between boundary vertices are kept (the diagonals of a cap join boundary vertices), so
// on a tube the graph is small and built in three streaming passes.
static inline size_t build_cap_graph(const uint32_t* tri, size_t count, size_t point_count,
                              CapGraph& g) {
    // Around an inner vertex the triangles leave towards the same vertices they arrive
    // from; around a boundary vertex (one fan, a chain) the two sets differ by the far
    // ends of its two boundary edges. So the xor of all of them is 0 exactly at inner
    // vertices: the ends differ, since a loop has at least 3 vertices.
    uint32_t* side = g.boundary_next;
    std::memset(side, 0, sizeof(uint32_t) * point_count);
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* c = tri + 3 * t;
        side[c[0]] ^= c[1] ^ c[2];
        side[c[1]] ^= c[2] ^ c[0];
        side[c[2]] ^= c[0] ^ c[1];
    }
    auto kept = [&](uint32_t a, uint32_t b) { return side[a] != 0 && side[b] != 0; };
    std::memset(g.offsets, 0, sizeof(size_t) * (point_count + 1));
    for (size_t k = 0; k < 3 * count; ++k) {
        uint32_t to = tri[k - k % 3 + (k + 1) % 3];
        if (kept(tri[k], to)) ++g.offsets[tri[k] + 1];
    }
    for (size_t v = 0; v < point_count; ++v) g.offsets[v + 1] += g.offsets[v];
    size_t total = g.offsets[point_count];
    // Filled from the end of each range, so offsets[v + 1] ends as the start of v's.
    for (size_t k = 3 * count; k-- > 0;) {
        uint32_t to = tri[k - k % 3 + (k + 1) % 3];
        if (kept(tri[k], to)) g.targets[--g.offsets[tri[k] + 1]] = to;
    }
    for (size_t v = 0; v < point_count; ++v) g.offsets[v] = g.offsets[v + 1];
    g.offsets[point_count] = total;
    size_t boundary = 0;
    for (size_t v = 0; v < point_count; ++v) {
        uint32_t* group = g.targets + g.offsets[v];
        size_t size = g.offsets[v + 1] - g.offsets[v];
        if (size <= 16) {
            for (size_t i = 1; i < size; ++i)
                for (size_t j = i; j > 0 && group[j - 1] > group[j]; --j) {
                    uint32_t s = group[j];
                    group[j] = group[j - 1];
                    group[j - 1] = s;
                }
        } else {
            heap_sort(group, size);
        }
    }
    // Every group is sorted: now the boundary edge leaving each boundary vertex, the one
    // no triangle runs backwards. `side` is read for v just before it is overwritten.
    for (size_t v = 0; v < point_count; ++v) {
        uint32_t a = static_cast<uint32_t>(v);
        uint32_t next = kNoIndex;
        if (side[v] != 0)
            for (size_t k = g.offsets[v]; k < g.offsets[v + 1]; ++k)
                if (!g.leads_to(g.targets[k], a)) next = g.targets[k];
        g.boundary_next[v] = next;
        boundary += next != kNoIndex;
    }
    return boundary;
}

// Chains the boundary edges into loops, stored one after another in cap order (the
// boundary reversed); a chain that does not come back to its start is marked broken.
// Returns the cap triangles all the unbroken loops would need.
static inline size_t trace_boundary_loops(CapGraph& g, size_t point_count, CapLoop& c,
                                   size_t* loop_entries) {
    size_t filled = 0, triangles = 0;
    for (size_t v = 0; v < point_count; ++v) {
        if (g.boundary_next[v] == kNoIndex) continue;
        size_t start = filled;
        uint32_t at = static_cast<uint32_t>(v);
        while (g.boundary_next[at] != kNoIndex) {  // each boundary vertex is taken once
            c.ids[filled] = at;
            c.starts[filled++] = 0;
            uint32_t to = g.boundary_next[at];
            g.boundary_next[at] = kNoIndex;
            at = to;
        }
        size_t length = filled - start;
        bool closed = at == v && length >= 3;
        c.starts[start] = closed ? kLoopStart : kLoopBroken;
        for (size_t i = start, j = filled - 1; i < j; ++i, --j) {
            uint32_t t = c.ids[i];
            c.ids[i] = c.ids[j];
            c.ids[j] = t;
        }
        if (closed) triangles += length - 2;
    }
    *loop_entries = filled;
    return triangles;
}

}  // namespace detail
}  // namespace stratmesh

// >>polygon ==============================================================================
// Simple polygons on the exact predicates: crossing edges, winding, ear clipping.

namespace stratmesh {
namespace detail {

static inline bool same_point(const double* a, const double* b) { return a[0] == b[0] && a[1] == b[1]; }

// For p collinear with a and b: whether it lies on the closed segment ab.
static inline bool on_segment(const double* a, const double* b, const double* p) {
    for (int k = 0; k < 2; ++k) {
        double low = a[k] < b[k] ? a[k] : b[k], high = a[k] < b[k] ? b[k] : a[k];
        if (p[k] < low || p[k] > high) return false;
    }
    return true;
}

// -1, 0 or 1 as x is below, at or above y: the sign of x - y, without rounding.
static inline int compare(double x, double y) { return (x > y) - (x < y); }

// Whether the closed segments pq and rs share a point.
static inline bool segments_meet(const double* p, const double* q, const double* r, const double* s) {
    double d1 = orient2d_robust(r, s, p), d2 = orient2d_robust(r, s, q);
    double d3 = orient2d_robust(p, q, r), d4 = orient2d_robust(p, q, s);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
        return true;
    return (d1 == 0 && on_segment(r, s, p)) || (d2 == 0 && on_segment(r, s, q)) ||
           (d3 == 0 && on_segment(p, q, r)) || (d4 == 0 && on_segment(p, q, s));
}

// Whether the closed polygon xy[0 .. length) is simple: no repeated point, no edge folding
// back onto the next, no two other edges meeting. Edges are swept in order of their
// smaller x; each is tested against those whose x range reaches into its own.
static inline bool polygon_is_simple(const double* xy, uint32_t length, uint64_t* sweep) {
    if (length < 3) return false;
    auto at = [&](uint32_t i) { return xy + 2 * static_cast<size_t>(i); };
    for (uint32_t i = 0; i < length; ++i) {
        const double* a = at(i == 0 ? length - 1 : i - 1);
        const double* b = at(i);
        const double* c = at(i + 1 == length ? 0 : i + 1);
        if (same_point(b, c)) return false;
        // Collinear neighbours on the same side of b: the two edges overlap.
        if (orient2d_robust(a, b, c) == 0 && compare(a[0], b[0]) == compare(c[0], b[0]) &&
            compare(a[1], b[1]) == compare(c[1], b[1]))
            return false;
    }
    for (uint32_t e = 0; e < length; ++e) {
        const double* a = at(e);
        const double* b = at(e + 1 == length ? 0 : e + 1);
        sweep[e] = uint64_t{sweep_key(a[0] < b[0] ? a[0] : b[0])} << 32 | e;
    }
    heap_sort(sweep, length);
    for (uint32_t i = 0; i < length; ++i) {
        uint32_t e = static_cast<uint32_t>(sweep[i]), e_end = e + 1 == length ? 0 : e + 1;
        const double* a = at(e);
        const double* b = at(e_end);
        const uint32_t right = sweep_key(a[0] < b[0] ? b[0] : a[0]);
        double low = a[1] < b[1] ? a[1] : b[1], high = a[1] < b[1] ? b[1] : a[1];
        for (uint32_t j = i + 1; j < length && (sweep[j] >> 32) <= right; ++j) {
            uint32_t f = static_cast<uint32_t>(sweep[j]), f_end = f + 1 == length ? 0 : f + 1;
            if (f == e_end || f_end == e) continue;  // neighbours: checked above
            const double* c = at(f);
            const double* d = at(f_end);
            if ((c[1] < low && d[1] < low) || (c[1] > high && d[1] > high)) continue;
            if (segments_meet(a, b, c, d)) return false;
        }
    }
    return true;
}

// Whether p lies in the closed triangle abc (counter-clockwise).
static inline bool in_closed_triangle(const double* a, const double* b, const double* c, const double* p) {
    return orient2d_robust(a, b, p) >= 0 && orient2d_robust(b, c, p) >= 0 &&
           orient2d_robust(c, a, p) >= 0;
}

// Whether corners i and j of the simple counter-clockwise polygon xy[0 .. length) see each
// other through it: the segment leaves both corners into the polygon and meets no edge that
// does not end at i or j (touching one counts as meeting it).
static inline bool diagonal_inside(const double* xy, uint32_t length, uint32_t i, uint32_t j) {
    auto point = [xy](uint32_t k) { return xy + 2 * static_cast<size_t>(k); };
    auto within_corner = [&](uint32_t a, uint32_t b) {
        const double* pa = point(a);
        const double* pb = point(b);
        const double* before = point(a == 0 ? length - 1 : a - 1);
        const double* after = point(a + 1 == length ? 0 : a + 1);
        if (orient2d_robust(before, pa, after) > 0)
            return orient2d_robust(pa, pb, before) > 0 && orient2d_robust(pb, pa, after) > 0;
        return !(orient2d_robust(pa, pb, after) >= 0 && orient2d_robust(pb, pa, before) >= 0);
    };
    if (!within_corner(i, j) || !within_corner(j, i)) return false;
    const double* pi = point(i);
    const double* pj = point(j);
    for (uint32_t a = 0; a < length; ++a) {
        const uint32_t b = a + 1 == length ? 0 : a + 1;
        if (a == i || a == j || b == i || b == j) continue;
        const double oa = orient2d_robust(pi, pj, point(a));
        const double ob = orient2d_robust(pi, pj, point(b));
        if ((oa > 0 && ob > 0) || (oa < 0 && ob < 0)) continue;
        const double oi = orient2d_robust(point(a), point(b), pi);
        const double oj = orient2d_robust(point(a), point(b), pj);
        if ((oi > 0 && oj > 0) || (oi < 0 && oj < 0)) continue;
        return false;
    }
    return true;
}

// The turning direction of the simple polygon xy[0 .. length): orient2d at its
// lexicographically lowest corner, which is strictly convex; positive counter-clockwise.
static inline double simple_polygon_turn(const double* xy, uint32_t length) {
    auto at = [xy](uint32_t i) { return xy + 2 * static_cast<size_t>(i); };
    uint32_t lowest = 0;
    for (uint32_t i = 1; i < length; ++i)
        if (lex_less(at(i), at(lowest))) lowest = i;
    return orient2d_robust(at(lowest == 0 ? length - 1 : lowest - 1), at(lowest),
                           at(lowest + 1 == length ? 0 : lowest + 1));
}

// A corner of a polygon whose corners are computed as they are read.
struct Point2 {
    double xy[2];
};

// How many times the closed polygon of corners point(0), ..., point(length - 1) winds around
// p, counter-clockwise positive: an edge that crosses the line through p along x (half-open:
// from at or below p to above it, or back) counts +1 going up with p on its left, -1 going
// down with p on its right, by orient2d. Odd where the even-odd rule has p inside; for p on
// the polygon, the count of a region beside it.
template <class PointAt>
long winding_number(PointAt point, uint32_t length, const double* p) {
    long winding = 0;
    Point2 a = point(length - 1);
    for (uint32_t i = 0; i < length; ++i) {
        const Point2 b = point(i);
        if (a.xy[1] <= p[1]) {
            if (b.xy[1] > p[1] && orient2d_robust(a.xy, b.xy, p) > 0) ++winding;
        } else if (b.xy[1] <= p[1] && orient2d_robust(a.xy, b.xy, p) < 0) {
            --winding;
        }
        a = b;
    }
    return winding;
}

// ---- ear clipping
//
// The caps, their pockets and the small gaps a graft closes are all triangulated by
// clipping ears off a simple counter-clockwise polygon: a strictly convex corner whose
// closed triangle holds no other corner, and whose diagonal the caller allows (the
// callers forbid those already edges of the surface: the edge would join three
// triangles). Only corners that are not strictly convex need testing for containment (in
// a simple polygon, a triangle holding a corner holds one of those); clipping only narrows
// the corners beside an ear, so the list of them only shrinks. The walk goes on from the
// corner before each ear, or, where the caller asks, from the first corner left; it gives
// up once every corner left has failed in a row.

// The clipping's arrays, an entry per corner.
struct EarRing {
    uint32_t* prev;        // the neighbours in the polygon left to clip
    uint32_t* next;
    uint32_t* reflex;      // corners not strictly convex when last looked at
    unsigned char* flags;  // kReflex while in `reflex` and not strictly convex
};

const unsigned char kReflex = 1;

// What a caller of EarClipper decides: which diagonals may not be made, and what becomes of
// each ear.
class EarRules {
public:
    // Whether the diagonal between corners a and b may not be made.
    virtual bool forbidden(uint32_t a, uint32_t b) const = 0;
    // The ear (p, v, n), counter-clockwise: one of length - 2, the last of them the three
    // corners left at the end.
    virtual void take(uint32_t p, uint32_t v, uint32_t n) = 0;

protected:
    ~EarRules() = default;
};

// Where the walk goes on after an ear: from the corner before it, or from the first
// corner left (in the corners' order).
enum class EarWalk { from_previous, from_first };

class EarClipper {
public:
    // The polygon: corner i at xy[2 i], xy[2 i + 1], for i < length.
    EarClipper(const double* xy, uint32_t length, const EarRing& ring)
        : xy_(xy), length_(length), ring_(ring) {}

    // Clips the polygon from corner `start`, handing every ear to rules.take; false, after
    // the ears taken so far, where every corner left fails.
    bool clip(uint32_t start, EarWalk walk, EarRules& rules) {
        const uint32_t length = length_;
        reflex_count_ = 0;
        for (uint32_t i = 0; i < length; ++i) {
            ring_.prev[i] = i == 0 ? length - 1 : i - 1;
            ring_.next[i] = i + 1 == length ? 0 : i + 1;
            ring_.flags[i] = convex(i) ? 0 : kReflex;
            if (ring_.flags[i]) ring_.reflex[reflex_count_++] = i;
        }
        uint32_t remaining = length, v = start, first = 0, misses = 0;
        while (remaining > 3) {
            if (!is_ear(v, rules)) {
                v = ring_.next[v];
                if (++misses > remaining) return false;
                continue;
            }
            const uint32_t p = ring_.prev[v], n = ring_.next[v];
            rules.take(p, v, n);
            ring_.next[p] = n;
            ring_.prev[n] = p;
            settle(p);
            settle(n);
            if (v == first) first = n;
            --remaining;
            misses = 0;
            v = walk == EarWalk::from_first ? first : p;
        }
        // The last triangle, from the first corner left where the walk starts there.
        if (walk == EarWalk::from_first) v = ring_.next[first];
        if (!convex(v)) return false;
        rules.take(ring_.prev[v], v, ring_.next[v]);
        return true;
    }

private:
    const double* point(uint32_t i) const { return xy_ + 2 * static_cast<size_t>(i); }

    bool convex(uint32_t i) const {
        return orient2d_robust(point(ring_.prev[i]), point(i), point(ring_.next[i])) > 0;
    }

    void settle(uint32_t i) {
        if ((ring_.flags[i] & kReflex) && convex(i)) ring_.flags[i] = 0;
    }

    // Strictly convex, a diagonal the rules allow, and no other corner in the closed
    // triangle; the reflex list drops the corners clipped or turned convex on the way.
    bool is_ear(uint32_t v, const EarRules& rules) {
        if (ring_.flags[v] & kReflex) return false;
        const uint32_t p = ring_.prev[v], n = ring_.next[v];
        if (rules.forbidden(p, n)) return false;
        bool empty = true;
        uint32_t kept = 0;
        for (uint32_t k = 0; k < reflex_count_; ++k) {
            const uint32_t r = ring_.reflex[k];
            if (ring_.flags[r] != kReflex) continue;
            ring_.reflex[kept++] = r;
            if (empty && r != p && r != n &&
                in_closed_triangle(point(p), point(v), point(n), point(r)))
                empty = false;
        }
        reflex_count_ = kept;
        return empty;
    }

    const double* xy_;
    uint32_t length_;
    EarRing ring_;
    uint32_t reflex_count_ = 0;
};

}  // namespace detail
}  // namespace stratmesh

// >>caps =================================================================================
// Closing a boundary loop: pockets, lowered caps, fins.
//
// With the add_caps flag, each boundary loop of the final surface is closed by a cap
// made of triangles over the loop's own vertices. The loop is triangulated in its
// projection across the axis: first checked to be a simple polygon (a sweep over its edges
// sorted by x, exact orient2d), then ear clipping (see the polygon section), then flips of
// the cap's diagonals. A triangulation of a simple polygon lifts to a surface that is a
// graph over it, so the cap's triangles cannot cross one another; but they can cross the
// wall where it leans over the cap near a ragged loop (a bust's shoulders, the noisy end
// of a scan). So the flips make the bottom cap as low as the loop allows and the top cap
// as high: a diagonal is flipped when the other one, with every vertex at its height along
// the axis, lies more than kCapHeightTie below it (above, on the top cap): the lower or
// upper envelope of the loop, where the quadrilaterals allow. On ties (a planar loop, a CT
// contour) the Delaunay criterion decides, so planar caps are the constrained Delaunay
// triangulation (ear clipping alone leaves slivers). Delaunay caps alone cross a wall
// leaning over a ragged loop several times as often. The flips are bounded
// (kCapFlipsPerCorner per loop vertex): any triangulation of the polygon is valid, so
// stopping early only leaves a cap less low. STRATMESH_SMALL_CODE leaves the heights out:
// Delaunay caps.
//
// Each cap triangle runs the loop's edges against the surface's direction, so the closed
// surface stays consistently oriented (the bottom cap faces -axis, the top one +axis). A
// diagonal that is already an edge of the surface would join three triangles: ears and
// flips that would make one are skipped. Where the wall has fins (triangles with two edges
// on the loop: a scan rounded to a grid makes them), the fin's middle corner has no way
// into the cap but a diagonal to a corner it sees across the loop, which ear clipping
// never makes; so a loop that no clipping closes, of at most kCapSearchCorners corners, is
// searched exhaustively (search_cap). Where fins leave no cap at all, the wall's edges under
// them may be flipped (see "fins flipped out of the way" below). A loop whose projection
// is not simple, or that none of these closes, stays open.
//
// The loops of a star-shaped layer run monotonically in angle around its centre (see the
// unroll section), so their projections are simple but for rounding or the safety net's
// removals.

namespace stratmesh {
namespace detail {

// Heights closer than this to a plane count as on it (frame units: the frame scales the
// cloud to an extent of about 1). A planar loop turned into the frame by a tilted axis gets
// heights that differ by rounding: those are ties, for the Delaunay criterion.
const double kCapHeightTie = 0x1p-40;

// How far d lies below the plane through a, b and w (counter-clockwise across the axis),
// each at its height (heights: a's, b's, w's, d's): the plane's height at d's place, the
// heights weighted by the triangles d makes with the opposite edges, less d's own.
static inline double depth_below_plane(const double* a, const double* b, const double* w,
                                const double* d, const double* heights) {
    auto orient = [d](const double* p, const double* q) {
        return (p[0] - d[0]) * (q[1] - d[1]) - (p[1] - d[1]) * (q[0] - d[0]);
    };
    double oa = orient(b, w), ob = orient(w, a), ow = orient(a, b);
    return ((heights[0] - heights[3]) * oa + (heights[1] - heights[3]) * ob +
            (heights[2] - heights[3]) * ow) /
           (oa + ob + ow);
}

const uint32_t kCapFlipsPerCorner = 64;

// A cap triangle's flag while flipping: on the stack of those to check.
const unsigned char kQueued = 4;

// Ear clipping is greedy: where the surface holds some of a loop's diagonals (its
// triangles with three corners on the loop), the ears taken first can leave a remainder
// whose every ear would repeat one, where another order would not (the bundled bust's
// neck loop, whose single layer's loops are peeled: 6 corners left of 249). So a failed
// clipping starts again from other corners, kCapEarStarts spread around the loop in all
// (see the configuration; 1 with STRATMESH_SMALL_CODE).

// Triangulates one loop, already checked simple and counter-clockwise. ids: the loop's
// vertices, whose diagonals must not be edges of the surface; lower: the cap is a bottom
// one (it faces -axis), to be made as low as the loop allows (a top one as high). Returns
// false if no ear is left (every one would repeat an edge of the surface).
class CapTriangulation final : public EarRules {
public:
    CapTriangulation(CapLoop& c, const uint32_t* ids, uint32_t length, const CapGraph& g,
                     bool lower)
        : c_(c), ids_(ids), length_(length), g_(g), lower_(lower) {}

    // Ear clipping from kCapEarStarts corners, then the search; false if neither closes.
    bool triangulate() {
        for (uint32_t k = 0; k < kCapEarStarts; ++k)
            if (clip_ears(static_cast<uint32_t>(uint64_t{k} * length_ / kCapEarStarts))) return true;
        return kCapSearchCorners > 0 && search_cap();
    }

    // From now on the chords of the fins marked in `fins` (per position, kFinWaived) are
    // allowed as diagonals: the wall's edge there is to be flipped away (see flip_used_fins).
    void waive(const unsigned char* fins) { waived_ = fins; }

    // The fin whose chord is a - b (positions): the position between them, if it is a
    // waived fin; else kNoIndex.
    uint32_t waived_fin(uint32_t a, uint32_t b) const {
        if (!kCapFinFlips || waived_ == nullptr) return kNoIndex;
        const uint32_t after_a = a + 1 == length_ ? 0 : a + 1, after_b = b + 1 == length_ ? 0 : b + 1;
        const uint32_t mid = (after_a + 1 == length_ ? 0 : after_a + 1) == b ? after_a
                           : (after_b + 1 == length_ ? 0 : after_b + 1) == a ? after_b
                                                                             : kNoIndex;
        return mid != kNoIndex && (waived_[mid] & kFinWaived) ? mid : kNoIndex;
    }

    bool clip_ears(uint32_t start) {
        std::memset(c_.owner, 0xFF, sizeof(uint32_t) * length_);  // all kNoIndex
        triangles_ = 0;
        EarClipper clipper(c_.xy, length_, {c_.prev, c_.next, c_.reflex, c_.flags});
        return clipper.clip(start, EarWalk::from_previous, *this);
    }

    // Flips until no diagonal would be lower (higher, on a top cap) flipped, nor, where the
    // heights cannot tell, more Delaunay (or the flip would repeat an edge of the surface),
    // or until the budget of flips is spent.
    void settle_diagonals() {
        uint32_t depth = 0;
        // No overflow: a loop takes more than 64 bytes of workspace per vertex.
        size_t budget = static_cast<size_t>(kCapFlipsPerCorner) * length_;
        for (uint32_t t = 0; t < triangles_; ++t) c_.flags[t] = 0;
        for (uint32_t t = 0; t < triangles_; ++t) queue(t, depth);
        while (depth > 0 && budget > 0) {
            uint32_t t = c_.stack[--depth];
            c_.flags[t] = 0;
            for (uint32_t k = 0; k < 3; ++k) {
                uint32_t u = flip_if_better(t, k);
                if (u == kNoIndex) continue;
                --budget;
                queue(t, depth);
                queue(u, depth);
                break;
            }
        }
    }

    // Triangulates the loop by searching all its triangulations for one whose diagonals
    // are no edges of the surface (dynamic programming over the pairs of corners: the
    // polygon i, i + 1, ..., j closed by diagonal i - j has one if some corner k between
    // makes a triangle i, k, j with both sides closable): what ear clipping misses where
    // fins of the wall leave a corner nothing to join but a corner across the loop. For
    // loops of at most kCapSearchCorners corners (cubic time: about 0.1 s for 256);
    // false if there are more, or none is found.
    bool search_cap() {
        const uint32_t m = length_;
        if (m > kCapSearchCorners || m < 3) return false;
        // choice(i, j): the corner k, stored as k - i, of a triangle i, k, j from which the
        // polygon i .. j closes; 0 if it does not (i - j no diagonal, or no such k).
        auto choice = [this](uint32_t i, uint32_t j) -> uint8_t& {
            return c_.search[static_cast<size_t>(j) * (j - 1) / 2 + i];
        };
        auto closes = [&choice](uint32_t i, uint32_t j) { return j == i + 1 || choice(i, j) != 0; };
        for (uint32_t span = 2; span < m; ++span)
            for (uint32_t i = 0; i + span < m; ++i) {
                const uint32_t j = i + span;
                uint8_t& best = choice(i, j);
                best = 0;
                // i - j must be a diagonal (the loop edge m - 1 -> 0 closes the whole).
                if ((j != m - 1 || i != 0) &&
                    (joined(i, j) || !diagonal_inside(c_.xy, m, i, j)))
                    continue;
                for (uint32_t k = i + 1; k < j && best == 0; ++k)
                    if (closes(i, k) && closes(k, j)) best = static_cast<uint8_t>(k - i);
            }
        if (choice(0, m - 1) == 0) return false;
        // The triangles, from the outermost in: each job is a pair (i, j) and the edge of
        // the triangle already made beyond its side j -> i (kNoIndex for the loop edge).
        triangles_ = 0;
        uint32_t depth = 0;
        auto push = [this, &depth](uint32_t i, uint32_t j, uint32_t beyond) {
            c_.prev[depth] = i;
            c_.next[depth] = j;
            c_.owner[depth++] = beyond;
        };
        push(0, m - 1, kNoIndex);
        while (depth > 0) {
            --depth;
            const uint32_t i = c_.prev[depth], j = c_.next[depth], beyond = c_.owner[depth];
            const uint32_t k = i + choice(i, j);
            const uint32_t t = triangles_++;
            uint32_t* corner = c_.corners + 3 * static_cast<size_t>(t);
            corner[0] = i;
            corner[1] = k;
            corner[2] = j;
            for (uint32_t e = 0; e < 3; ++e) c_.across[3 * static_cast<size_t>(t) + e] = kNoIndex;
            link(3 * t + 2, beyond);
            if (k > i + 1) push(i, k, 3 * t);
            if (j > k + 1) push(k, j, 3 * t + 1);
        }
        return true;
    }

    uint32_t triangles() const { return triangles_; }

private:
    const double* point(uint32_t i) const { return c_.xy + 2 * static_cast<size_t>(i); }

    // Whether positions a and b are joined by an edge of the surface that stays there.
    bool joined(uint32_t a, uint32_t b) const {
        return g_.has_edge(ids_[a], ids_[b]) && waived_fin(a, b) == kNoIndex;
    }

    // The clipping's rules: no diagonal that is an edge of the surface staying there; each
    // ear a cap triangle, its edges p -> v and v -> n linked to the triangles beyond. Its
    // edge n -> p is the polygon's new edge p -> n, with t beyond it, but for the last ear,
    // whose n -> p is an edge of the polygon already.
    bool forbidden(uint32_t a, uint32_t b) const override { return joined(a, b); }

    void take(uint32_t p, uint32_t v, uint32_t n) override {
        const uint32_t t = triangles_++;
        uint32_t* corner = c_.corners + 3 * static_cast<size_t>(t);
        corner[0] = p;
        corner[1] = v;
        corner[2] = n;
        link(3 * t, c_.owner[p]);
        link(3 * t + 1, c_.owner[v]);
        link(3 * t + 2, t + 3 == length_ ? c_.owner[n] : kNoIndex);
        c_.owner[p] = 3 * t + 2;
    }

    void queue(uint32_t t, uint32_t& depth) {
        if (c_.flags[t] & kQueued) return;
        c_.flags[t] = kQueued;
        c_.stack[depth++] = t;
    }

    void link(uint32_t edge, uint32_t other) {
        c_.across[edge] = other;
        if (other != kNoIndex) c_.across[other] = edge;
    }

    // Flips the diagonal on edge k of t if the other diagonal lies lower (higher on a top
    // cap), or on a tie if the vertex beyond lies in t's circumcircle; only where the
    // quadrilateral is strictly convex and the new diagonal is no edge of the surface.
    // Returns the other triangle, or kNoIndex if nothing was flipped.
    uint32_t flip_if_better(uint32_t t, uint32_t k) {
        uint32_t beyond = c_.across[3 * t + k];
        if (beyond == kNoIndex) return kNoIndex;
        uint32_t u = beyond / 3, j = beyond % 3;
        uint32_t* ct = c_.corners + 3 * static_cast<size_t>(t);
        uint32_t* cu = c_.corners + 3 * static_cast<size_t>(u);
        uint32_t a = ct[k], b = ct[(k + 1) % 3], w = ct[(k + 2) % 3], d = cu[(j + 2) % 3];
        const double heights[4] = {c_.height[a], c_.height[b], c_.height[w], c_.height[d]};
        // How much lower (higher, on a top cap) the other diagonal lies: flip if clearly
        // so; on a tie, by the Delaunay criterion. A NaN (a sliver abw) flips nothing.
        double gain =
            kLiftedCaps ? depth_below_plane(point(a), point(b), point(w), point(d), heights) : 0;
        if (!lower_) gain = -gain;
        if (!(gain > kCapHeightTie ||
              (gain >= -kCapHeightTie &&
               incircle_perturbed(point(a), point(b), point(w), point(d), c_.scratch) > 0)))
            return kNoIndex;
        if (orient2d_robust(point(a), point(d), point(w)) <= 0 ||
            orient2d_robust(point(d), point(b), point(w)) <= 0 || joined(w, d))
            return kNoIndex;
        uint32_t beyond_bw = c_.across[3 * t + (k + 1) % 3], beyond_wa = c_.across[3 * t + (k + 2) % 3];
        uint32_t beyond_ad = c_.across[3 * u + (j + 1) % 3], beyond_db = c_.across[3 * u + (j + 2) % 3];
        // t becomes a -> d -> w (d -> w the new diagonal), u becomes d -> b -> w.
        ct[0] = a;
        ct[1] = d;
        ct[2] = w;
        cu[0] = d;
        cu[1] = b;
        cu[2] = w;
        link(3 * t, beyond_ad);
        link(3 * t + 2, beyond_wa);
        link(3 * u, beyond_db);
        link(3 * u + 1, beyond_bw);
        link(3 * t + 1, 3 * u + 2);
        return u;
    }

    CapLoop& c_;
    const uint32_t* ids_;
    uint32_t length_;
    const CapGraph& g_;
    bool lower_;
    uint32_t triangles_ = 0;
    const unsigned char* waived_ = nullptr;
};

// What capping a surface's loops did: loops closed and left open, the caps' triangles and
// the wall edges flipped under fins (Report::caps).
struct CapTally {
    size_t closed, left_open, triangles, wall_flips;
};

// Report::detail for the caps, from reconstruct() and cap_ends() alike.
const char* const kCapsTooLargeDetail =
    "the triangle array is too small for the caps; triangle_count says how many are needed";

const char* const kLoopLeftOpenDetail =
    "a boundary loop's projection across the axis is not a simple polygon (or every cap "
    "found for it would repeat an edge of the surface): it is left open";

// ---- fins flipped out of the way
//
// A loop with fins can have no cap at all: each fin's middle corner needs a diagonal to a
// corner it sees across the loop, and with fins close together those diagonals cross or
// see nothing (a fin under every other edge: most loops the search leaves open on
// sparsely sampled ends). Then the wall gives way: the fin (u, v, m)
// and the wall triangle beyond its chord, (v, u, x), become (u, x, m) and (x, v, m) (m,
// the fin's middle corner, has no other triangle, so m - x is a new edge and the surface
// stays a manifold), and the chord u - v is free for the cap. Only fins whose x is on no
// loop (no new chord) and whose two new triangles face the way the old pair does are
// offered, and only those whose chord the cap then takes are flipped: a loop that closed
// before closes as before, and one that stays open leaves the wall as it was.

// The per point key of a loop's fin chords: at the chord's first corner (position i - 1),
// the fin's position i, for the fins with a flag in `wanted`. `key` is all kNoIndex outside
// these calls: clear_fin_chords puts it back.
static inline void key_fin_chords(uint32_t* key, const uint32_t* ids, uint32_t length,
                           const unsigned char* fins, unsigned char wanted) {
    for (uint32_t i = 0; i < length; ++i)
        if (fins[i] & wanted) key[ids[i == 0 ? length - 1 : i - 1]] = i;
}

static inline void clear_fin_chords(uint32_t* key, const uint32_t* ids, uint32_t length) {
    for (uint32_t i = 0; i < length; ++i) key[ids[i]] = kNoIndex;
}

// The fin position whose chord is a - b (either way round), or kNoIndex.
static inline uint32_t keyed_fin(const uint32_t* key, const uint32_t* ids, uint32_t length,
                          uint32_t a, uint32_t b) {
    for (int side = 0; side < 2; ++side) {
        const uint32_t i = key[side == 0 ? a : b];
        if (i != kNoIndex && ids[i + 1 == length ? 0 : i + 1] == (side == 0 ? b : a)) return i;
    }
    return kNoIndex;
}

// Whether (u, x, m) and (x, v, m) face the way (u, v, m) and (v, u, x) do together.
static inline bool fin_flip_keeps_facing(const CloudReader& cloud, const Frame& frame, uint32_t u,
                                  uint32_t v, uint32_t m, uint32_t x) {
    const Vec3 pu = frame.offset(cloud.point(u)), pv = frame.offset(cloud.point(v));
    const Vec3 pm = frame.offset(cloud.point(m)), px = frame.offset(cloud.point(x));
    const Vec3 fin = cross(pv - pu, pm - pu), beyond = cross(pu - pv, px - pv);
    const Vec3 first = cross(px - pu, pm - pu), second = cross(pv - px, pm - px);
    return dot(first, fin) + dot(first, beyond) > 0 && dot(second, fin) + dot(second, beyond) > 0;
}

// Marks kFinWaived the fins of the loop ids[0 .. length) that may be flipped (above),
// scanning the wall tri[0 .. 3 wall); returns how many.
static inline uint32_t mark_flippable_fins(const uint32_t* tri, size_t wall, const CloudReader& cloud,
                                    const Frame& frame, const CapGraph& g, uint32_t* key,
                                    const uint32_t* ids, uint32_t length, unsigned char* fins) {
    if (length <= 4) return 0;  // a chord two corners apart either way: no single fin
    for (uint32_t i = 0; i < length; ++i)
        fins[i] = g.has_edge(ids[i == 0 ? length - 1 : i - 1], ids[i + 1 == length ? 0 : i + 1])
                      ? kFinSeen | kFinFlippable : 0;
    key_fin_chords(key, ids, length, fins, kFinSeen);
    for (uint32_t i = 0; i < length; ++i) fins[i] = 0;
    for (size_t t = 0; t < wall; ++t) {
        const uint32_t* c = tri + 3 * t;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t a = c[k], b = c[(k + 1) % 3], o = c[(k + 2) % 3];
            const uint32_t i = keyed_fin(key, ids, length, a, b);
            if (i == kNoIndex) continue;
            if (o == ids[i]) {
                fins[i] |= kFinSeen;
            } else if (g.offsets[o + 1] == g.offsets[o] &&  // o is on no loop
                       fin_flip_keeps_facing(cloud, frame, b, a, ids[i], o)) {
                fins[i] |= kFinFlippable;  // beyond a -> b: the fin runs b -> a -> ids[i]
            }
        }
    }
    clear_fin_chords(key, ids, length);
    uint32_t marked = 0;
    for (uint32_t i = 0; i < length; ++i) {
        const bool both = fins[i] == (kFinSeen | kFinFlippable);
        fins[i] = both ? kFinWaived : 0;
        marked += both;
    }
    return marked;
}

// Flips the wall's edge under each fin marked kFinUsed; returns how many it flipped. slots:
// two size_t per position (in the memory of the loop's projection, free once its cap is made).
static inline size_t flip_used_fins(uint32_t* tri, size_t wall, uint32_t* key, const uint32_t* ids,
                             uint32_t length, const unsigned char* fins, double* slots) {
    auto slot = [slots](uint32_t i, uint32_t which) { return slots + 2 * static_cast<size_t>(i) + which; };
    static_assert(sizeof(size_t) <= sizeof(double), "a slot holds a triangle index");
    const size_t unset = ~size_t{0};
    for (uint32_t i = 0; i < length; ++i) {
        std::memcpy(slot(i, 0), &unset, sizeof unset);
        std::memcpy(slot(i, 1), &unset, sizeof unset);
    }
    key_fin_chords(key, ids, length, fins, kFinUsed);
    size_t flipped_count = 0;
    for (size_t t = 0; t < wall; ++t) {
        const uint32_t* c = tri + 3 * t;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t i = keyed_fin(key, ids, length, c[k], c[(k + 1) % 3]);
            if (i != kNoIndex) std::memcpy(slot(i, c[(k + 2) % 3] == ids[i] ? 0 : 1), &t, sizeof t);
        }
    }
    for (uint32_t i = 0; i < length; ++i) {
        if (!(fins[i] & kFinUsed)) continue;
        size_t fin = 0, beyond = 0;
        std::memcpy(&fin, slot(i, 0), sizeof fin);
        std::memcpy(&beyond, slot(i, 1), sizeof beyond);
        if (fin == unset || beyond == unset) continue;  // a soup given to cap_ends() only
        uint32_t* f = tri + 3 * fin;
        uint32_t* w = tri + 3 * beyond;
        uint32_t k = 0;  // w's edge k -> k + 1 is the chord, v -> u
        while (k < 2 && keyed_fin(key, ids, length, w[k], w[(k + 1) % 3]) != i) ++k;
        const uint32_t v = w[k], u = w[(k + 1) % 3], x = w[(k + 2) % 3], m = ids[i];
        const uint32_t flipped[6] = {u, x, m, x, v, m};
        std::memcpy(f, flipped, 3 * sizeof(uint32_t));
        std::memcpy(w, flipped + 3, 3 * sizeof(uint32_t));
        ++flipped_count;
    }
    clear_fin_chords(key, ids, length);
    return flipped_count;
}

// ---- pockets closed before a cap ----
//
// A loop is ragged along the axis: its points dip a little below its highest ones, and
// where the wall flares out toward the end (its lower points inside the loop, seen along
// the axis), a cap over the loop dips with them and crosses the wall's top row (a tilted
// tube widening at its top: 24 to 65 crossing pairs with 60,000 points). So the cap spans
// the loop's upper hull in the loop's own unrolled picture (the angle around its centroid,
// and the height; the lower hull for a bottom loop), which lies above the wall, and each
// pocket between a hull chord and the points dipping under it is first closed by
// triangles of its own, along the wall. Only for a loop that runs once around its
// centroid, monotonically; a pocket whose chord or diagonal would repeat an edge of the
// surface is left for the cap as it is. The pockets and the cap together triangulate the
// loop, so the caps' triangle count is the same.

// The widest pocket closed, in angle around the loop's centroid: a loop's ragged dips span
// a few of its points; wider ones (the low side of a slanted end) are the cap's.
const double kPocketTurn = 3.14159265358979323846 / 8;

// The loop (positions in cap order, the first its highest: see fill_pockets) in its
// annulus picture, as the layers unroll (see >>unroll): around its centroid across the
// axis, at a radius exp((h - h_first) / r) for the height h (-h for a bottom loop) and the
// loop's mean radius r, mirrored so that the loop turns clockwise. False if it does not
// run once around its centroid monotonically.
static inline bool unroll_loop(const CloudReader& cloud, const Frame& frame, const uint32_t* ids,
                        uint32_t length, bool lower, double* xy) {
    double cx = 0, cy = 0, radius = 0;
    for (uint32_t i = 0; i < length; ++i) {
        const Local p = frame.local(cloud.point(ids[i]));
        cx += p.x;
        cy += p.y;
    }
    cx /= length;
    cy /= length;
    const double pi = 3.14159265358979323846;
    double turned = 0, previous = 0;
    for (uint32_t i = 0; i <= length; ++i) {
        const Local p = frame.local(cloud.point(ids[i % length]));
        const double dx = p.x - cx, dy = p.y - cy, angle = std::atan2(dy, dx);
        double step = i == 0 ? 0 : angle - previous;
        step = step > pi ? step - 2 * pi : step < -pi ? step + 2 * pi : step;
        if (i > 0 && !(step * (turned == 0 ? step : turned) > 0)) return false;
        turned += step;
        previous = angle;
        if (i < length) {
            radius += std::sqrt(dx * dx + dy * dy);
            xy[2 * i] = dx;
            xy[2 * i + 1] = lower ? -p.h : p.h;
        }
    }
    if (!(abs_value(abs_value(turned) - 2 * pi) < 1e-9) || !(radius > 0)) return false;
    radius /= length;
    const double first = xy[1];
    for (uint32_t i = 0; i < length; ++i) {
        const Local p = frame.local(cloud.point(ids[i]));
        const double dx = p.x - cx, dy = p.y - cy, d = std::sqrt(dx * dx + dy * dy);
        const double rho = exp_portable((xy[2 * i + 1] - first) / radius);
        const double u = d > 0 ? dx / d : 1, v = d > 0 ? dy / d : 0;
        // Clockwise: mirrored where the loop turns counter-clockwise.
        xy[2 * i] = (turned > 0 ? -u : u) * rho;
        xy[2 * i + 1] = v * rho;
    }
    return true;
}

// A pocket's ears: its corners are the loop's positions from `from` on (mod length); no
// diagonal that is an edge of the surface; each ear appended at tri[3 added] as the cap
// writes its own triangles (in loop order).
class PocketEars final : public EarRules {
public:
    PocketEars(uint32_t* tri, size_t count, const CapGraph& g, const uint32_t* ids,
               uint32_t length, uint32_t from)
        : added(count), tri_(tri), g_(g), ids_(ids), length_(length), from_(from) {}

    size_t added;

private:
    uint32_t id(uint32_t corner) const { return ids_[(from_ + corner) % length_]; }

    bool forbidden(uint32_t a, uint32_t b) const override { return g_.has_edge(id(a), id(b)); }

    void take(uint32_t p, uint32_t v, uint32_t n) override {
        tri_[3 * added] = id(p);
        tri_[3 * added + 1] = id(v);
        tri_[3 * added + 2] = id(n);
        ++added;
    }

    uint32_t* tri_;
    const CapGraph& g_;
    const uint32_t* ids_;
    uint32_t length_, from_;
};

// Closes the pocket of the `corners` positions from `from` on (the last may be the first
// position again), whose points in the annulus picture are run[0 .. 2 corners), by ear
// clipping from its second corner on (it turns counter-clockwise there); appends its
// triangles at tri[3 * count]. False, with count unchanged, where no ear is left whose
// diagonal is not already an edge of the surface.
static inline bool close_pocket(uint32_t* tri, size_t& count, const CapGraph& g, const uint32_t* ids,
                         uint32_t length, const double* run, uint32_t from, uint32_t corners,
                         const EarRing& ring) {
    PocketEars ears(tri, count, g, ids, length, from);
    EarClipper clipper(run, corners, ring);
    if (!clipper.clip(1, EarWalk::from_previous, ears)) return false;
    count = ears.added;
    return true;
}

// Closes the pockets of the loop ids[0 .. length) (see above), rotating ids so that its
// highest position (its lowest, for a bottom loop) comes first, and keeps in ids, in order,
// the positions left for the cap; returns their number. The cap loop's arrays serve as
// scratch.
static inline uint32_t fill_pockets(uint32_t* tri, size_t& count, const CapGraph& g, CapLoop& c,
                             const CloudReader& cloud, const Frame& frame, uint32_t* ids,
                             uint32_t length, bool lower) {
    uint32_t top = 0;
    for (uint32_t i = 1; i < length; ++i) {
        const double h = frame.height(cloud.point(ids[i])), best = frame.height(cloud.point(ids[top]));
        if (lower ? h < best : h > best) top = i;
    }
    // Rotated by three reversals, in place.
    auto reverse = [ids](uint32_t first, uint32_t end) {
        for (; first + 1 < end; ++first, --end) {
            const uint32_t t = ids[first];
            ids[first] = ids[end - 1];
            ids[end - 1] = t;
        }
    };
    reverse(0, top);
    reverse(top, length);
    reverse(0, length);
    double* xy = c.xy;
    if (!unroll_loop(cloud, frame, ids, length, lower, xy)) return length;
    // The convex hull of the clockwise loop from its first position (on the hull, being the
    // farthest out) round to it again: a Graham scan in the loop's order.
    // The first position closes the hull again: scanned last, but not stored twice.
    uint32_t* hull = c.stack;
    uint32_t hull_count = 0;
    for (uint32_t j = 0; j <= length; ++j) {
        const double* pj = xy + 2 * (j % length);
        while (hull_count >= 2 &&
               orient2d_robust(xy + 2 * hull[hull_count - 2], xy + 2 * hull[hull_count - 1], pj) >= 0)
            --hull_count;  // not a strict right turn: off the hull
        if (j < length) hull[hull_count++] = j;
    }
    if (hull_count < 3) return length;  // the cap needs three corners at least
    // The positions a closed pocket takes leave the cap's loop: ids is compacted as the
    // pockets go, behind them (the last pocket reads position 0 again, which stays).
    const EarRing ring = {c.prev, c.next, c.reflex, c.flags};
    uint32_t kept = 0;
    for (uint32_t k = 0; k < hull_count; ++k) {
        const uint32_t from = hull[k], to = k + 1 < hull_count ? hull[k + 1] : length;
        const double* pa = xy + 2 * from;
        const double* pb = xy + 2 * (to % length);
        const double span = std::atan2(abs_value(pa[0] * pb[1] - pa[1] * pb[0]),
                                       pa[0] * pb[0] + pa[1] * pb[1]);
        bool closed = false;
        if (to - from >= 2 && span < kPocketTurn && !g.has_edge(ids[from], ids[to % length])) {
            // The last pocket runs past the loop's end: its points are moved to the front
            // of xy, which nothing reads again, to be a run as the others are.
            if (to == length) {
                const double first[2] = {xy[0], xy[1]};
                std::memmove(xy, xy + 2 * from, sizeof(double) * 2 * (length - from));
                xy[2 * (length - from)] = first[0];
                xy[2 * (length - from) + 1] = first[1];
            }
            closed = close_pocket(tri, count, g, ids, length, to == length ? xy : xy + 2 * from,
                                  from, to - from + 1, ring);
        }
        ids[kept++] = ids[from];
        for (uint32_t j = from + 1; !closed && j < to; ++j) ids[kept++] = ids[j];
    }
    return kept;
}

// Caps every boundary loop of the surface tri[0 .. 3 count) over the cloud's points,
// appending the cap triangles (count grows) and counting into caps (zeroed by the caller);
// each loop is projected across the frame's axis. Returns ok; out_of_memory; or
// triangle_capacity with *needed the triangles every cap closing would take, and nothing
// written.
static inline Status cap_boundary_loops(uint32_t* tri, size_t& count, size_t capacity,
                                 const CloudReader& cloud, size_t point_count,
                                 const Frame& frame, Arena& arena, CapTally& caps,
                                 size_t* needed) {
    auto project = [&](uint32_t id, double* xy, double* height) {
        const Local p = frame.local(cloud.point(id));
        xy[0] = p.x;
        xy[1] = p.y;
        *height = p.h;
    };
    const size_t wall = count;
    size_t mark = arena.mark();
    CapGraph g;
    if (!allocate_cap_graph(g, point_count, count, arena)) return Status::out_of_memory;
    size_t boundary = build_cap_graph(tri, count, point_count, g);
    if (boundary == 0) {
        arena.rewind(mark);
        return Status::ok;
    }
    CapLoop c;
    if (!allocate_cap_loop(c, boundary, arena)) return Status::out_of_memory;
    size_t entries = 0;
    size_t cap_triangles = trace_boundary_loops(g, point_count, c, &entries);
    if (cap_triangles > capacity - count) {
        *needed = count + cap_triangles;
        return Status::triangle_capacity;
    }
    for (size_t start = 0; start < entries;) {
        size_t end = start + 1;
        while (end < entries && c.starts[end] == 0) ++end;
        uint32_t* ids = c.ids + start;
        // Cap triangle edges are numbered 3 t + k in 32 bits.
        const bool usable = c.starts[start] == kLoopStart && end - start <= (kNoIndex - 1) / 3;
        uint32_t length = static_cast<uint32_t>(end - start);
        start = end;
        // The loop's projection across the axis, checked to be a simple polygon, and its
        // turning direction (0: not simple); then the same for the positions its pockets
        // leave to the cap.
        double turn = 0;
        for (bool pockets = kLiftedCaps; usable; pockets = false) {
            double height = 0;
            for (uint32_t i = 0; i < length; ++i)
                project(ids[i], c.xy + 2 * static_cast<size_t>(i), &height);
            if (!polygon_is_simple(c.xy, length, c.sweep)) break;
            turn = simple_polygon_turn(c.xy, length);
            if (!pockets || turn == 0) break;
            const size_t before = count;
            length = fill_pockets(tri, count, g, c, cloud, frame, ids, length, turn < 0);
            caps.triangles += count - before;
            turn = 0;
        }
        if (turn == 0) {
            ++caps.left_open;
            continue;
        }
        if (turn < 0)
            for (uint32_t i = 0; i < length; ++i) c.xy[2 * static_cast<size_t>(i)] = -c.xy[2 * static_cast<size_t>(i)];
        // A loop turning clockwise seen from +axis is capped facing -axis: a bottom cap.
        CapTriangulation cap(c, ids, length, g, turn < 0);
        bool clipped = cap.triangulate();
        // The loop's start markers are read no more: its fins' flags take their place.
        unsigned char* fins = c.starts + (ids - c.ids);
        bool waived = false;
        if (kCapFinFlips && !clipped &&
            mark_flippable_fins(tri, wall, cloud, frame, g, g.boundary_next, ids, length, fins) > 0) {
            cap.waive(fins);
            waived = true;
            clipped = cap.triangulate();
        }
        if (!clipped) {
            ++caps.left_open;
            continue;
        }
        double xy[2];  // c.xy holds them, mirrored
        for (uint32_t i = 0; kLiftedCaps && i < length; ++i) project(ids[i], xy, c.height + i);
        cap.settle_diagonals();
        bool flips = false;
        for (size_t k = 0; k < 3 * static_cast<size_t>(cap.triangles()); ++k) {
            tri[3 * count + k] = ids[c.corners[k]];
            const uint32_t fin = waived ? cap.waived_fin(c.corners[k], c.corners[k - k % 3 + (k + 1) % 3]) : kNoIndex;
            if (fin != kNoIndex) {
                fins[fin] |= kFinUsed;
                flips = true;
            }
        }
        if (flips)
            caps.wall_flips += flip_used_fins(tri, wall, g.boundary_next, ids, length, fins, c.xy);
        count += cap.triangles();
        caps.triangles += cap.triangles();
        ++caps.closed;
    }
    arena.rewind(mark);
    return Status::ok;
}

}  // namespace detail
}  // namespace stratmesh

// >>fit ==================================================================================
// How well the finished surface fits its cloud (Diagnostics): misfit area and crossings.
//
// Measured once the surface is final, from the cloud alone, in the memory the meshing
// used. A sample of the triangles (caps left out: a cap spans its loop by design), every
// k-th of them up to kMisfitSampleLimit, each compared with the cloud around its centroid:
//  - misfit, where its normal parts from the cloud's own there by more than 45 degrees
//    (the normal of the kFitNeighbours points nearest the centroid: the direction in which
//    they spread least), as where a layer folds and its triangles run across the surface
//    or a sliver bridges a crease, or where its centroid lies farther than kMisfitSpacings
//    times the cloud's spacing from every point, as where a web spans a gap. The misfit
//    share of the sample's area estimates the share of the surface that does not follow
//    the cloud: on single columns it stays near zero, on a fold or a limb wrapped in one
//    tube it is a tenth of the surface or more;
//  - crossing, where it and another triangle that shares no corner with it pierce each
//    other (an edge of one through the other's inside, by more than rounding: coplanar
//    triangles do not count), caps included. The triangles are swept in the order of their
//    boxes along the side where they overlap least, each tested against those after it
//    whose boxes meet its own. Surfaces of at most kCrossingCheckLimit triangles are
//    checked whole, larger ones not (their misfit share judges them); past an average of
//    kCrossingBudget box tests a triangle the check stops, incomplete.
// The cloud's spacing is the outliers' scale (nearest_spacing), the grid's cells twice
// that. A cloud that spans more than the largest double is not measured. Deterministic:
// sums in the sample's order, no libm beyond sqrt.

namespace stratmesh {
namespace detail {

const double kMisfitCosine = 0.70710678118654752;  // cos(kMisfitDegrees)
static_assert(kMisfitDegrees == 45.0, "kMisfitCosine is the cosine of kMisfitDegrees");
// The grid's cells, in spacings: the 27 around a centroid hold a few dozen points.
const double kFitCellSpacings = 2.0;
// A centroid over a gap: its nearest point at least this share of the way to the farthest
// of its kFitNeighbours nearest (on a surface sampled without a gap, far less).
const double kGapShare = 0.6;
// Points whose scatter's middle eigenvalue is under kSurfaceSpread times its least, or
// under kCurveSpread times its largest, spread along a curve (a contour), not a surface.
const double kSurfaceSpread = 3.0;
const double kCurveSpread = 0.1;
// The most box tests a triangle the crossing check makes, on average, before it stops.
const size_t kCrossingBudget = 1024;
// A volume under this share of the product of its three edges' lengths is taken as zero.
const double kFlatVolume = 1e-12;

// The cloud's and the surface's points as the measure takes them: times a power of two
// that brings the cloud's extent near 1 (exact), so that no square overflows.
struct FitFrame {
    double scale;
    Vec3 point(const CloudReader& reader, uint32_t i) const { return scaled(reader.point(i), scale); }
};

struct Box3f {
    Vec3 low, high;
    void add(Vec3 p) {
        low = {p.x < low.x ? p.x : low.x, p.y < low.y ? p.y : low.y, p.z < low.z ? p.z : low.z};
        high = {p.x > high.x ? p.x : high.x, p.y > high.y ? p.y : high.y, p.z > high.z ? p.z : high.z};
    }
    bool meets(const Box3f& o) const {
        return low.x <= o.high.x && o.low.x <= high.x && low.y <= o.high.y && o.low.y <= high.y &&
               low.z <= o.high.z && o.low.z <= high.z;
    }
};

// The memory of the measure: the points in cells, then the triangles in sweep order.
struct FitMemory {
    CellScratch points;
    GridItem* sweep;
    GridItem* spare;
};

static inline bool allocate_fit(FitMemory& m, size_t point_count, size_t triangle_count, Arena& arena) {
    m.points = allocate_cell_scratch(arena, point_count);
    const size_t swept = triangle_count <= kCrossingCheckLimit ? triangle_count : 0;
    m.sweep = arena.alloc<GridItem>(swept);
    m.spare = arena.alloc<GridItem>(swept);
    return !arena.failed;
}

static inline size_t fit_workspace_size(size_t point_count, size_t triangle_count) {
    Arena arena = Arena::measuring();
    FitMemory m;
    return allocate_fit(m, point_count, triangle_count, arena) ? arena.required_bytes() : 0;
}

// The unit normal of the points p[0 .. n): the eigenvector of their scatter's least
// eigenvalue, by power steps on the scatter's adjugate (whose largest eigenvalue that one
// is), from its longest row: on a surface the least eigenvalue lies far below the others,
// and two steps settle it. Zero where the points spread along a curve rather than a
// surface, as on one contour of a CT stack: they have no normal to judge by.
static inline Vec3 cloud_normal(const Vec3* p, uint32_t n) {
    Vec3 mean = {0, 0, 0};
    for (uint32_t i = 0; i < n; ++i) mean = {mean.x + p[i].x, mean.y + p[i].y, mean.z + p[i].z};
    mean = scaled(mean, 1.0 / n);
    Vec3 row[3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (uint32_t i = 0; i < n; ++i) {
        const Vec3 d = p[i] - mean;
        row[0] = {row[0].x + d.x * d.x, row[0].y + d.x * d.y, row[0].z + d.x * d.z};
        row[1] = {row[1].x + d.y * d.x, row[1].y + d.y * d.y, row[1].z + d.y * d.z};
        row[2] = {row[2].x + d.z * d.x, row[2].y + d.z * d.y, row[2].z + d.z * d.z};
    }
    const Vec3 adjugate[3] = {cross(row[1], row[2]), cross(row[2], row[0]), cross(row[0], row[1])};
    Vec3 v = adjugate[0];
    for (const Vec3& a : adjugate)
        if (dot(a, a) > dot(v, v)) v = a;
    for (int step = 0; step < 2 && normalize(v); ++step)
        v = {dot(adjugate[0], v), dot(adjugate[1], v), dot(adjugate[2], v)};
    if (!normalize(v)) return {0, 0, 0};
    // The other two eigenvalues are the roots of x^2 - sum x + product, from the trace and
    // the adjugate's trace (the sum of the products of pairs).
    const double least = dot(v, {dot(row[0], v), dot(row[1], v), dot(row[2], v)});
    const double sum = row[0].x + row[1].y + row[2].z - least;
    const double product = adjugate[0].x + adjugate[1].y + adjugate[2].z - least * sum;
    const double square = sum * sum - 4 * product;
    const double middle = (sum - std::sqrt(square > 0 ? square : 0)) / 2;
    const double largest = sum - middle;
    return middle >= kSurfaceSpread * least && middle >= kCurveSpread * largest ? v : Vec3{0, 0, 0};
}

static inline void corners(const FitFrame& f, const CloudReader& reader, const uint32_t* v, Vec3* out) {
    for (int k = 0; k < 3; ++k) out[k] = f.point(reader, v[k]);
}

// The item of `items` (sorted by cell) in `cell`, or failing that the first after it
// (n: past the end).
static inline size_t item_at_cell(const GridItem* items, size_t n, uint64_t cell) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (items[mid].cell < cell) lo = mid + 1; else hi = mid;
    }
    return lo;
}

// The kFitNeighbours points nearest `q` among those of the cells around `cell`, q's
// (sorted nearest first into near[], their squared distances in d2[]); returns how many.
static inline uint32_t nearest_points(const FitFrame& f, const CloudReader& reader, const GridItem* items,
                                      size_t n, uint64_t cell, Vec3 q, Vec3* near, double* d2) {
    const size_t hint = item_at_cell(items, n, cell);
    const CellBlock block = block_of_cell(items, n, cell, hint < n ? hint : n - 1);
    uint32_t found = 0;
    for (uint32_t r = 0; r < block.count; ++r)
        for (size_t i = block.begin[r]; i < block.end[r]; ++i) {
            const Vec3 p = f.point(reader, items[i].index);
            const Vec3 d = p - q;
            const double dd = dot(d, d);
            if (found == kFitNeighbours && !(dd < d2[found - 1])) continue;
            uint32_t k = found < kFitNeighbours ? found++ : found - 1;
            for (; k > 0 && d2[k - 1] > dd; --k) {
                d2[k] = d2[k - 1];
                near[k] = near[k - 1];
            }
            d2[k] = dd;
            near[k] = p;
        }
    return found;
}

// The cell of side `side` from `low` that holds p, as sort_into_cells keys it.
static inline uint64_t cell_of(Vec3 p, Vec3 low, double side) {
    return cell_key(cell_coordinate(p.x - low.x, side), cell_coordinate(p.y - low.y, side),
                    cell_coordinate(p.z - low.z, side));
}

// The sampled triangles' misfit: adds their areas, and the misfit ones' areas and box, to
// the diagnostics (areas in the frame's units, squared).
struct MisfitTally {
    double area, misfit;
    Box3f where;
    size_t samples;
};

// Whether the triangle abc (unit normal `normal`, centroid `centroid`) misfits the cloud
// around it. `near` has room for kFitNeighbours + 3 points.
static inline bool misfits(const FitFrame& f, const CloudReader& reader, const FitMemory& m,
                           size_t n, Vec3 low, double side, double far, const Vec3* corner,
                           Vec3 normal, Vec3 centroid, Vec3* near) {
    double d2[kFitNeighbours];
    const uint32_t found = nearest_points(f, reader, m.points.items, n, cell_of(centroid, low, side),
                                          centroid, near, d2);
    if (found == 0) return true;  // no point in the cells around: a web over a wide gap
    const Vec3 around = cloud_normal(near, found);
    if (dot(around, around) > 0)
        // A surface around: the triangle misfits across it, or over a gap in it (its
        // centroid far from every point, and the nearest hardly nearer than the rest).
        return abs_value(dot(normal, around)) < kMisfitCosine ||
               (d2[0] > far * far && d2[0] > kGapShare * kGapShare * d2[found - 1]);
    // The points around lie along a curve (the contours of a CT stack): the triangle's
    // corners, on the rows it joins, make the surface to judge by.
    for (uint32_t k = 0; k < 3; ++k) near[found + k] = corner[k];
    const Vec3 rows = cloud_normal(near, found + 3);
    return dot(rows, rows) > 0 && abs_value(dot(normal, rows)) < kMisfitCosine;
}

// Tallies every step-th triangle of tri[0 .. count): its area, and whether it misfits.
static inline void tally_misfit(const FitFrame& f, const CloudReader& reader, const FitMemory& m,
                                size_t n, Vec3 low, double side, double spacing, const uint32_t* tri,
                                size_t count, size_t step, MisfitTally& t) {
    Vec3 near[kFitNeighbours + 3];
    for (size_t k = 0; k < count; k += step) {
        Vec3 c[3];
        corners(f, reader, tri + 3 * k, c);
        Vec3 normal = cross(c[1] - c[0], c[2] - c[0]);
        const double area = std::sqrt(dot(normal, normal)) / 2;
        const Vec3 centroid = scaled(c[0] + c[1] + c[2], 1.0 / 3);
        ++t.samples;
        t.area += area;
        if (!normalize(normal) ||
            !misfits(f, reader, m, n, low, side, kMisfitSpacings * spacing, c, normal, centroid, near))
            continue;
        t.misfit += area;
        for (const Vec3& p : c) t.where.add(p);
    }
}

// The sign of the volume of (o, u, v, w), 0 within rounding (kFlatVolume).
static inline int volume_sign(Vec3 o, Vec3 u, Vec3 v, Vec3 w) {
    const Vec3 a = u - o, b = v - o, c = w - o;
    const double volume = dot(cross(a, b), c);
    const double size = std::sqrt(dot(a, a) * dot(b, b) * dot(c, c));
    return volume > kFlatVolume * size ? 1 : volume < -kFlatVolume * size ? -1 : 0;
}

// Whether segment pq pierces triangle abc's inside.
static inline bool segment_crosses(Vec3 p, Vec3 q, Vec3 a, Vec3 b, Vec3 c) {
    const int sp = volume_sign(a, b, c, p), sq = volume_sign(a, b, c, q);
    if (sp == 0 || sq != -sp) return false;
    const int s1 = volume_sign(p, q, a, b), s2 = volume_sign(p, q, b, c), s3 = volume_sign(p, q, c, a);
    return s1 != 0 && s1 == s2 && s2 == s3;
}

static inline bool triangles_cross(const Vec3* u, const Vec3* v) {
    for (int k = 0; k < 3; ++k) {
        if (segment_crosses(u[k], u[(k + 1) % 3], v[0], v[1], v[2])) return true;
        if (segment_crosses(v[k], v[(k + 1) % 3], u[0], u[1], u[2])) return true;
    }
    return false;
}


static inline Box3f box_of_corners(const Vec3* c) {
    Box3f b = {c[0], c[0]};
    b.add(c[1]);
    b.add(c[2]);
    return b;
}

static inline bool share_a_corner(const uint32_t* u, const uint32_t* v) {
    for (int a = 0; a < 3; ++a)
        if (u[a] == v[0] || u[a] == v[1] || u[a] == v[2]) return true;
    return false;
}

// The side (0, 1 or 2) along which the triangles' boxes overlap least: the least sum of
// their extents along it over the cloud's extent `size` there.
static inline int sweep_side(const FitFrame& f, const CloudReader& reader, const uint32_t* tri,
                             size_t count, Vec3 size) {
    Vec3 sum = {0, 0, 0};
    for (size_t t = 0; t < count; ++t) {
        Vec3 c[3];
        corners(f, reader, tri + 3 * t, c);
        const Box3f box = box_of_corners(c);
        sum = sum + (box.high - box.low);
    }
    const double sums[3] = {sum.x, sum.y, sum.z}, sizes[3] = {size.x, size.y, size.z};
    double share[3];
    for (int k = 0; k < 3; ++k) share[k] = sizes[k] > 0 ? sums[k] / sizes[k] : DBL_MAX;
    int side = 0;
    for (int k = 1; k < 3; ++k)
        if (share[k] < share[side]) side = k;
    return side;
}

// The sweep: the triangles in the order of their boxes' low ends along `side` (0, 1 or 2),
// from `low`. Keys are the bits of a non-negative double, which order as the values do.
static inline void sort_sweep(const FitFrame& f, const CloudReader& reader, const uint32_t* tri,
                                size_t count, int side, double low, FitMemory& m) {
    uint64_t any = 0, every = ~uint64_t{0};
    for (size_t t = 0; t < count; ++t) {
        Vec3 c[3];
        corners(f, reader, tri + 3 * t, c);
        const double from = coordinate(box_of_corners(c).low, side) - low;
        uint64_t key;
        const double start = from > 0 ? from : 0;
        std::memcpy(&key, &start, sizeof key);
        m.sweep[t] = {key, static_cast<uint32_t>(t)};
        any |= key;
        every &= key;
    }
    sort_items(m.sweep, m.spare, count, any, every);
}

struct CrossingTally {
    size_t pairs;
    bool complete;
    Box3f where;
};

// The crossing pairs (each once), their boxes' union in t.where; stops, incomplete, past
// kCrossingBudget box tests a triangle.
static inline void count_crossings(const FitFrame& f, const CloudReader& reader, const uint32_t* tri,
                                   const GridItem* items, size_t count, int side, double low,
                                   CrossingTally& t) {
    size_t budget = kCrossingBudget * count;
    for (size_t k = 0; k < count; ++k) {
        const uint32_t s = items[k].index;
        Vec3 u[3], v[3];
        corners(f, reader, tri + 3 * size_t{s}, u);
        const Box3f box = box_of_corners(u);
        const double to = coordinate(box.high, side) - low;
        uint64_t last;
        std::memcpy(&last, &to, sizeof last);
        for (size_t i = k + 1; i < count && items[i].cell <= last; ++i) {
            const uint32_t o = items[i].index;
            if (budget-- == 0) {
                t.complete = false;
                return;
            }
            if (share_a_corner(tri + 3 * size_t{s}, tri + 3 * size_t{o})) continue;
            corners(f, reader, tri + 3 * size_t{o}, v);
            if (!box.meets(box_of_corners(v)) || !triangles_cross(u, v)) continue;
            ++t.pairs;
            t.where.add(box.low);
            t.where.add(box.high);
        }
    }
}

// The box `b` in the cloud's units into min and max (left zero when b is empty).
static inline void put_box(const Box3f& b, double to_cloud, double* min, double* max) {
    if (!(b.low.x <= b.high.x)) return;
    const Vec3 lo = scaled(b.low, to_cloud), hi = scaled(b.high, to_cloud);
    const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
    for (int k = 0; k < 3; ++k) {
        min[k] = l[k];
        max[k] = h[k];
    }
}

// Measures the surface's fit (see above) into rep.diagnostics; false if the workspace is
// too small. triangles[0 .. count - caps) are the walls, the rest caps: the caps are
// checked for crossings, not for misfit.
static inline bool measure_fit(const CloudReader& reader, size_t point_count, const CloudSums& sums,
                               const uint32_t* triangles, size_t count, size_t caps, Arena& arena,
                               Report& rep) {
    const size_t walls = caps < count ? count - caps : 0;
    Diagnostics& d = rep.diagnostics;
    if (walls == 0) return true;
    const size_t mark = arena.mark();
    FitMemory m;
    if (!allocate_fit(m, point_count, count, arena)) return false;
    const Vec3 size = Vec3{sums.highest[0], sums.highest[1], sums.highest[2]} -
                      Vec3{sums.lowest[0], sums.lowest[1], sums.lowest[2]};
    const double extent = largest_of(size);
    const CloudBox box = box_of(reader, point_count);
    const double spacing =
        is_finite(extent) ? nearest_spacing(reader, point_count, box, m.points, kMisfitSampleLimit) : 0;
    if (!(spacing > 0)) {
        arena.rewind(mark);
        return true;
    }
    const FitFrame f = {scale_for_extent(extent)};
    // The points' cells keyed from the reader's coordinates: the scaled ones key alike, the
    // scale being a power of two.
    const size_t n = sort_into_cells(reader, point_count, box.low, kFitCellSpacings * spacing, m.points);
    const double side = kFitCellSpacings * spacing * f.scale;
    const Vec3 low = scaled(box.low, f.scale);
    const size_t step = walls > kMisfitSampleLimit ? (walls + kMisfitSampleLimit - 1) / kMisfitSampleLimit : 1;
    const Box3f none = {{DBL_MAX, DBL_MAX, DBL_MAX}, {-DBL_MAX, -DBL_MAX, -DBL_MAX}};
    MisfitTally t = {0, 0, none, 0};
    tally_misfit(f, reader, m, n, low, side, spacing * f.scale, triangles, walls, step, t);
    CrossingTally crossed = {0, count <= kCrossingCheckLimit, none};
    if (crossed.complete) {
        const int along = sweep_side(f, reader, triangles, count, scaled(size, f.scale));
        const double from = coordinate(low, along);
        sort_sweep(f, reader, triangles, count, along, from, m);
        count_crossings(f, reader, triangles, m.sweep, count, along, from, crossed);
    }
    d.crossing_pair_count = crossed.pairs;
    const double to_cloud = 1 / f.scale;
    const double vertices = static_cast<double>(rep.points.used_count);
    d.point_spacing = spacing;
    // The sample's area stands for every step-th triangle's.
    d.area_per_point = vertices > 0 ? t.area * static_cast<double>(step) * to_cloud * to_cloud /
                                          (vertices * spacing * spacing)
                                    : 0;
    d.crossing_check_complete = crossed.complete;
    d.fit_sample_count = t.samples;
    d.misfit_area_fraction = t.area > 0 ? t.misfit / t.area : 0;
    d.misfit_area = t.misfit * static_cast<double>(step) * to_cloud * to_cloud;
    put_box(t.where, to_cloud, d.misfit_box_min, d.misfit_box_max);
    put_box(crossed.where, to_cloud, d.crossing_box_min, d.crossing_box_max);
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh

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

// >>parallel layers ======================================================================
// Layers triangulated ahead as jobs on the caller's runner.

namespace stratmesh {
namespace detail {

// ---- parallel layers -----------------------------------------------------------------------
//
// With Options::run_jobs, every planned layer that could stand as a group on its own (at
// least kMinLayerPoints points, or the last one) is loaded and, if group_stands, triangulated
// ahead by a job, into its own part of the workspace; the job also keeps the triangles at
// its bottom loop and turns the rest to reader indices (keep_border). Then the groups are
// formed in order as always; a group that is one planned layer takes the job's result
// (add_group), stitches it and, when the safety net has nothing to do there, finishes the
// chunk reading only the band and that border (replay_chunk); any other group (merged
// layers, a chunk the net must repair) is triangulated then. So the result is the
// sequential one whatever the jobs' order and threads, and what runs in order is a small
// part of each layer's work. Jobs are contiguous runs of such layers with about equal point
// counts, each with the scratch of its largest layer.

#if !defined(STRATMESH_NO_PARALLEL_LAYERS)

struct ParallelLayers {
    bool ready;                  // the jobs ran
    const CloudReader* reader;
    const Frame* frame;
    const LayerQueue* queue;
    uint32_t slots;              // layers done ahead
    LayerAhead* ahead;           // per slot
    uint32_t* layer_of_slot;
    uint32_t* slot_of_layer;     // kNoIndex: not done ahead
    uint32_t job_count;
    uint32_t first_slot[kMaxJobs + 1];
    unsigned char* scratch[kMaxJobs];
    size_t scratch_bytes[kMaxJobs];

    const LayerAhead* ahead_of(uint32_t layer) const {
        uint32_t slot = slot_of_layer[layer];
        return slot == kNoIndex ? nullptr : ahead + slot;
    }
};

// Room for the results of `slots` layers holding `points` points in all, out of `layers`
// planned layers.
static inline bool allocate_ahead(ParallelLayers& p, uint32_t slots, size_t points, size_t layers,
                                  Arena& arena, uint32_t** triangles, uint32_t** loops,
                                  unsigned char** loop_flags, uint32_t** borders) {
    p.ahead = arena.alloc<LayerAhead>(slots);
    p.layer_of_slot = arena.alloc<uint32_t>(slots);
    p.slot_of_layer = arena.alloc<uint32_t>(layers);
    *triangles = arena.alloc<uint32_t>(3 * 2 * points);
    *loops = arena.alloc<uint32_t>(2 * points);
    *loop_flags = arena.alloc<unsigned char>(2 * points);
    *borders = arena.alloc<uint32_t>(3 * (points / 4 + 4 * static_cast<size_t>(slots)));
    return !arena.failed;
}

// The border a layer of n points may keep for replay_chunk: its bottom loop holds a few
// times the square root of n points in a sound layer, with two or three triangles each.
// A thin layer's border can be most of its triangles: it is finished in order instead.
static inline size_t border_capacity(size_t n) { return n / 4 + 4; }

static inline bool may_stand_alone(const LayerQueue& q, uint32_t k) {
    size_t n = q.start[k + 1] - q.start[k];
    return n >= kMinLayerPoints || (k + 1 == q.planned && n >= 3);
}

// The job scratch bound: a run of layers needs the scratch of its largest, and scratch grows
// linearly with rounding, so jobs over n points in all need at most this.
static inline size_t job_scratch_bound(size_t points) {
    size_t whole = reconstruct_scratch_size(points, false), one = reconstruct_scratch_size(0, false);
    const size_t slack = 1024;  // the rounding of every allocation, with room to spare
    if (whole == 0 || one > (SIZE_MAX - whole) / kMaxJobs - slack) return 0;
    return whole + kMaxJobs * (one + slack);
}

// What replay_chunk needs of a job's layer (see LayerAhead), then, if it can replay them,
// its triangles in reader indices (`ids`).
static inline void keep_border(LayerAhead& a, const uint32_t* ids, size_t n, Arena& arena) {
    const unsigned char on_bottom = 1, has_triangle = 2;
    unsigned char* flags = arena.alloc<unsigned char>(n);
    a.replayable = flags != nullptr;
    a.border_count = a.interior_used = 0;
    if (!flags) return;
    std::memset(flags, 0, n);
    for (uint32_t i = 0; i < a.bottom_count; ++i) flags[a.bottom[i]] = on_bottom;
    for (size_t t = 0; t < a.triangle_count; ++t) {
        uint32_t* v = a.triangles + 3 * t;
        if ((flags[v[0]] | flags[v[1]] | flags[v[2]]) & on_bottom) {
            if (a.border_count < a.border_capacity)
                std::memcpy(a.border + 3 * a.border_count, v, 3 * sizeof(uint32_t));
            ++a.border_count;
        }
        for (size_t k = 0; k < 3; ++k) flags[v[k]] |= has_triangle;
    }
    for (size_t v = 0; v < n; ++v) a.interior_used += flags[v] == has_triangle;
    for (uint32_t i = 0; i < a.top_count; ++i) a.replayable = a.replayable && flags[a.top[i]] != 0;
    a.replayable = a.replayable && a.border_count <= a.border_capacity;
    if (!a.replayable) return;
    for (size_t k = 0; k < 3 * a.triangle_count; ++k) a.triangles[k] = ids[a.triangles[k]];
}

// Job `job`: triangulates the layers of slots first_slot[job] .. first_slot[job + 1] - 1 in
// the job's own scratch.
static inline void triangulate_job(const ParallelLayers& p, uint32_t job) {
    const LayerQueue& q = *p.queue;
    Arena arena = Arena::over(p.scratch[job], p.scratch_bytes[job]);
    for (uint32_t slot = p.first_slot[job]; slot < p.first_slot[job + 1]; ++slot) {
        LayerAhead& a = p.ahead[slot];
        const uint32_t k = p.layer_of_slot[slot];
        const size_t n = q.start[k + 1] - q.start[k];
        arena.rewind(0);
        LoadedLayer layer;
        if (!load_layer(*p.reader, *p.frame, q.ids + q.start[k], nullptr, n, q.bounds[k],
                        q.bounds[k + 1], arena, layer) ||
            !group_stands(n, q.bounds[k + 1] - q.bounds[k], layer.cyl.radius, k + 1 == q.planned))
            continue;
        a.fitted = layer.cyl;
        a.sectors = kCrescentLayers ? layer_sectors(layer) : 0;
        // The ends as add_group will see them if this layer is a group of its own.
        a.ends = (k == 0 ? kLowPole : 0) | (k + 1 == q.planned ? kHighPole : 0);
        find_closed_ends(layer, a.ends);
        TriangleSink sink = {a.triangles, 2 * n, 0, 0};
        LayerLoops loops = {a.bottom, 0, a.top, 0, a.bottom_flags, a.top_flags, 0, 0};
        a.status = triangulate_layer(*p.reader, layer, arena, sink, loops, a.counts);
        // An annulus through n points has at most 2n triangles; anything else is redone in order.
        if ((a.status != Status::ok && a.status != Status::not_columnar) || sink.count > sink.capacity)
            continue;
        a.cylinder = layer.cyl;
        a.triangle_count = sink.count;
        a.folds = sink.folds;
        a.bottom_count = loops.bottom_count;
        a.top_count = loops.top_count;
        if (a.status == Status::ok) keep_border(a, q.ids + q.start[k], n, arena);
        a.done = true;
    }
}

// Gives each layer that may stand alone a slot: its part of the results carved from the
// arena (false if they do not fit). `points` are the slots' points in all.
static inline bool assign_slots(ParallelLayers& p, uint32_t slots, size_t points, Arena& arena) {
    const LayerQueue& q = *p.queue;
    uint32_t* triangles = nullptr;
    uint32_t* loops = nullptr;
    unsigned char* loop_flags = nullptr;
    uint32_t* borders = nullptr;
    if (!allocate_ahead(p, slots, points, q.planned, arena, &triangles, &loops, &loop_flags,
                        &borders))
        return false;
    p.slots = slots;
    uint32_t slot = 0;
    size_t at = 0, border_at = 0;
    for (uint32_t k = 0; k < q.planned; ++k) {
        p.slot_of_layer[k] = kNoIndex;
        if (!may_stand_alone(q, k)) continue;
        const size_t n = q.start[k + 1] - q.start[k];
        LayerAhead& a = p.ahead[slot];
        a.done = false;
        a.triangles = triangles + 6 * at;
        a.bottom = loops + 2 * at;
        a.top = loops + 2 * at + n;
        a.bottom_flags = loop_flags + 2 * at;
        a.top_flags = loop_flags + 2 * at + n;
        a.border = borders + 3 * border_at;
        a.border_capacity = border_capacity(n);
        border_at += a.border_capacity;
        at += n;
        p.layer_of_slot[slot] = k;
        p.slot_of_layer[k] = slot++;
    }
    return true;
}

// Cuts the slots into jobs: runs of slots with about equal point counts. A slot goes to the
// share of the points its middle falls in, so equal layers get a job each (a threshold on
// a running count would put a layer slightly under the mean together with the next).
static inline void divide_jobs(ParallelLayers& p, size_t points) {
    const LayerQueue& q = *p.queue;
    const uint32_t most = p.slots < kMaxJobs ? p.slots : kMaxJobs;
    uint32_t job = 0;
    uint64_t share_of_job = 0, before = 0;
    p.first_slot[0] = 0;
    for (uint32_t s = 0; s < p.slots; ++s) {
        const uint32_t k = p.layer_of_slot[s];
        const uint64_t n = q.start[k + 1] - q.start[k];
        const uint64_t share = (before + n / 2) * most / points;
        if (s > 0 && share > share_of_job) {
            p.first_slot[++job] = s;
            share_of_job = share;
        }
        before += n;
    }
    p.job_count = job + 1;
    p.first_slot[p.job_count] = p.slots;
}

// Each job's scratch: that of its largest layer. False if they do not fit.
static inline bool allocate_job_scratch(ParallelLayers& p, Arena& arena) {
    const LayerQueue& q = *p.queue;
    for (uint32_t j = 0; j < p.job_count; ++j) {
        size_t largest = 0;
        for (uint32_t s = p.first_slot[j]; s < p.first_slot[j + 1]; ++s) {
            uint32_t k = p.layer_of_slot[s];
            size_t n = q.start[k + 1] - q.start[k];
            if (n > largest) largest = n;
        }
        p.scratch_bytes[j] = reconstruct_scratch_size(largest, false) + Arena::kAlign;
        p.scratch[j] = arena.alloc<unsigned char>(p.scratch_bytes[j]);
    }
    return !arena.failed;
}

// Plans the jobs over the queue, carves their results and scratch from the arena and runs
// them. Returns with p.ready false (and the arena as it was) when there is nothing to gain or
// no room: the groups are then triangulated in order. The results stay in the arena; the
// jobs' scratch is released.
static inline void triangulate_ahead(const Options& options, ParallelLayers& p, Arena& arena) {
    p.ready = false;
    const LayerQueue& q = *p.queue;
    uint32_t slots = 0;
    size_t points = 0;
    for (uint32_t k = 0; k < q.planned; ++k)
        if (may_stand_alone(q, k)) {
            ++slots;
            points += q.start[k + 1] - q.start[k];
        }
    if (slots < 2) return;
    const size_t mark = arena.mark();
    auto give_up = [&]() {
        arena.failed = false;
        arena.rewind(mark);
    };
    if (!assign_slots(p, slots, points, arena)) return give_up();
    const size_t results = arena.mark();
    divide_jobs(p, points);
    if (!allocate_job_scratch(p, arena)) return give_up();
    // A job the runner skips leaves its layers to their groups.
    run_jobs(options, p.job_count, false, [&p](uint32_t job) { triangulate_job(p, job); });
    arena.rewind(results);
    p.ready = true;
}

// Starts the jobs for reconstruct(); returns the layers they triangulated.
static inline size_t start_parallel_layers(const Options& options, const CloudReader& reader,
                                           const Frame& frame, const LayerQueue& queue,
                                           Arena& arena, ParallelLayers& parallel) {
    parallel.ready = false;
    if (!has_runner(options)) return 0;
    parallel.reader = &reader;
    parallel.frame = &frame;
    parallel.queue = &queue;
    triangulate_ahead(options, parallel, arena);
    size_t done = 0;
    for (uint32_t slot = 0; parallel.ready && slot < parallel.slots; ++slot)
        done += parallel.ahead[slot].done;
    return done;
}

// What the layers done ahead add to the workspace bound: their results, which stay, in
// `arena`; the jobs' scratch, which comes and goes before the groups' own, in *scratch.
static inline bool plan_parallel_workspace(size_t point_count, size_t layer_limit, Arena& arena,
                                           size_t* scratch) {
    ParallelLayers p;
    uint32_t* triangles = nullptr;
    uint32_t* loops = nullptr;
    unsigned char* loop_flags = nullptr;
    uint32_t* borders = nullptr;
    size_t slots = point_count / kMinLayerPoints + 1;
    allocate_ahead(p, static_cast<uint32_t>(slots), point_count, layer_limit, arena, &triangles,
                   &loops, &loop_flags, &borders);
    size_t jobs = job_scratch_bound(point_count);
    if (jobs > *scratch) *scratch = jobs;
    return jobs != 0;
}

#else  // STRATMESH_NO_PARALLEL_LAYERS: Options::run_jobs is ignored.

struct ParallelLayers {
    bool ready;
    const LayerAhead* ahead_of(uint32_t) const { return nullptr; }
};

static inline size_t start_parallel_layers(const Options&, const CloudReader&, const Frame&,
                                           const LayerQueue&, Arena&, ParallelLayers& parallel) {
    parallel.ready = false;
    return 0;
}

static inline bool plan_parallel_workspace(size_t, size_t, Arena&, size_t*) { return true; }

#endif  // STRATMESH_NO_PARALLEL_LAYERS

}  // namespace detail
}  // namespace stratmesh

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

// >>stream ===============================================================================
// The same surface, layer by layer, in bounded memory.
//
// The stream is reconstruct()'s loop over planned layers, driven by pushes: each push is
// appended to a window of held points as one planned layer, and add_group runs for as long
// as it can decide. A finished group's chunk goes to the callback; then the window keeps
// only that group's top loop (moved to the front) and the pushes after it.

namespace stratmesh {

struct Stream {
    detail::Arena arena;          // the scratch, after everything below
    detail::ByteRange workspace;  // for the overlap check of pushed points
    Options options;
    TriangleCallback emit;
    void* emit_user;
    Report* user_report;
    size_t capacity;              // points the window holds
    uint32_t slot_capacity;       // pushes it holds
    detail::Vec3* points;         // the window: the last top loop, then the held pushes
    uint32_t* global;             // window position -> global index
    uint32_t* positions;          // 0, 1, 2, ...: window positions as reader indices
    uint32_t* start;              // held push k starts at window position start[k]
    double* bounds;               // its heights: bounds[k] .. bounds[k + 1]
    uint32_t planned;             // pushes held
    size_t fill;                  // window positions in use
    detail::TriangleSink sink;    // one chunk at a time
    detail::SurfaceChain chain;
    bool has_frame;
    double last_top;              // the previous push's top, as a frame height
    // Before the first valid point there is no frame: the top of the pushes until then, as
    // given (a lower limit for the points after them all the same); -DBL_MAX before any.
    double early_top;
    double lowest, highest;       // the points' frame heights so far
    detail::DistinctPoints distinct;  // among the points so far
    Status failure;               // sticky: a triangulation error
    bool closed;
    Report rep;                   // last: the fields above stay near the start (shorter
                                  // instructions reach them on 32-bit ARM)
};

}  // namespace stratmesh

namespace stratmesh {
namespace detail {

// Points more than this many times the first layer's size away from it are refused: the
// frame is scaled to the first layer, and the predicates' exact range must hold.
const double kStreamRange = 0x1p60;

// Everything a stream holds for a window of `capacity` points.
static inline bool layout_stream(Stream& s, size_t capacity, Arena& arena) {
    s.capacity = capacity;
    s.slot_capacity = static_cast<uint32_t>(capacity + 1);
    s.points = arena.alloc<Vec3>(capacity);
    s.global = arena.alloc<uint32_t>(capacity);
    s.positions = arena.alloc<uint32_t>(capacity);
    s.start = arena.alloc<uint32_t>(static_cast<size_t>(s.slot_capacity) + 1);
    s.bounds = arena.alloc<double>(static_cast<size_t>(s.slot_capacity) + 1);
    // A chunk's triangles: at most two per point of the group and the loop below it.
    s.sink = {arena.alloc<uint32_t>(3 * 2 * capacity), 2 * capacity, 0, 0};
    return allocate_chain(s.chain, capacity, arena) && !arena.failed;
}

static inline size_t stream_bytes(size_t capacity) {
    if (capacity > kMaxPoints - 1) return 0;
    Arena arena = Arena::measuring();
    arena.alloc<Stream>(1);
    Stream probe;
    layout_stream(probe, capacity, arena);
    size_t scratch = reconstruct_scratch_size(capacity, false);
    if (arena.failed || scratch == 0 || scratch > SIZE_MAX - arena.required_bytes()) return 0;
    return arena.required_bytes() + scratch;
}

static inline void publish(Stream& s) {
    s.rep.points.unused_count = s.rep.points.in_count - s.rep.points.used_count - s.rep.points.duplicate_count - s.rep.points.rejected_count;
    s.rep.workspace_used_bytes = s.arena.peak_from_buffer();
    if (s.user_report) *s.user_report = s.rep;
}

// A push refused: the stream is as it was; the report says why.
static inline Status refuse_push(Stream& s, Status status, const char* detail) {
    s.rep.detail = detail;
    publish(s);
    return status;
}

// Keeps the last group's top loop (moved to the front of the window) and the pushes after
// planned layer `last`.
static inline void drop_group(Stream& s, uint32_t last) {
    const uint32_t loop = s.chain.top_count;
    const size_t rest_from = s.start[last + 1], rest = s.fill - rest_from;
    size_t mark = s.arena.mark();
    Vec3* loop_points = s.arena.alloc<Vec3>(loop);
    uint32_t* loop_global = s.arena.alloc<uint32_t>(loop);
    // The scratch bound covers a group as large as the window, far more than this.
    for (uint32_t i = 0; i < loop; ++i) {
        loop_points[i] = s.points[s.chain.top[i]];
        loop_global[i] = s.global[s.chain.top[i]];
    }
    std::memmove(s.points + loop, s.points + rest_from, rest * sizeof(Vec3));
    std::memmove(s.global + loop, s.global + rest_from, rest * sizeof(uint32_t));
    std::memcpy(s.points, loop_points, loop * sizeof(Vec3));
    std::memcpy(s.global, loop_global, loop * sizeof(uint32_t));
    for (uint32_t i = 0; i < loop; ++i) s.chain.top[i] = i;
    s.arena.rewind(mark);
    const uint32_t kept = s.planned - (last + 1);
    for (uint32_t k = 0; k <= kept; ++k) {
        s.start[k] = static_cast<uint32_t>(s.start[k + last + 1] - rest_from + loop);
        s.bounds[k] = s.bounds[k + last + 1];
    }
    s.planned = kept;
    s.fill = loop + rest;
}

// Forms, emits and drops every group the held pushes decide.
static inline Status advance(Stream& s, bool complete) {
    while (s.planned > 0) {
        const LayerQueue queue = {s.positions, nullptr, s.start, s.bounds, s.planned, complete};
        GroupResult group;
        s.sink.count = 0;
        Status status = add_group(s.chain, queue, 0, s.arena, s.sink, group, nullptr);
        if (status == Status::not_columnar) return Status::ok;  // the rest is trailing
        if (status == Status::ok && s.sink.count > s.sink.capacity) status = Status::internal_error;
        if (status != Status::ok) return status;
        if (group.waiting) return Status::ok;
        if (s.sink.count > 0) s.emit(s.emit_user, s.sink.triangles, s.sink.count);
        s.rep.triangle_count += s.sink.count;
        if (s.rep.layers.used_count < s.rep.layers.info_capacity)
            describe_layer(s.chain.frame, group.cylinder, s.bounds[0], s.bounds[group.last + 1],
                           group.points - group.counts.duplicates, group.triangles, group.folds,
                           s.rep.layers.info[s.rep.layers.used_count]);
        ++s.rep.layers.used_count;
        drop_group(s, group.last);
    }
    return Status::ok;
}

// Why a push's arguments are refused, with *why, or ok with the pushed cloud's reader: its
// layout, its top and its count are checked.
static inline Status check_push(const Stream& s, const Cloud& points, double top,
                                CloudReader* reader, const char** why) {
    const size_t scalar = points.scalar == Scalar::float32 ? sizeof(float)
                        : points.scalar == Scalar::float64 ? sizeof(double) : 0;
    const size_t stride = points.stride_bytes ? points.stride_bytes : 3 * scalar;
    if (scalar == 0 || stride < 3 * scalar || (points.count > 0 && !points.xyz) ||
        ranges_overlap(strided_range(points.xyz, points.count, stride, 3 * scalar), s.workspace)) {
        *why = "a pushed cloud has a null pointer with a non-zero count, a stride smaller than "
               "one point, an unknown scalar type, or points in the stream's workspace";
        return Status::invalid_argument;
    }
    if (!is_finite(top)) {
        *why = "a pushed layer's top is NaN or infinite";
        return Status::invalid_layers;
    }
    if (points.count > kMaxPoints - 1 - s.rep.points.in_count) {
        *why = "more points pushed than 32-bit triangle indices can address";
        return Status::too_many_points;
    }
    *reader = {static_cast<const unsigned char*>(points.xyz), stride,
               points.scalar == Scalar::float32, nullptr};
    return Status::ok;
}

const char* const kTopBelow = "a pushed layer's top is below the previous layer's top";

// The heights of the push's valid points in the frame, *low to *high, or why the push is
// refused, with *why (and the point's index where one is to blame): a point far beyond the
// first layer, or outside its own layer, between lower_limit and top_height.
static inline Status push_heights(Stream& s, const CloudReader& reader, size_t count,
                                  const Frame& frame, double lower_limit, double top_height,
                                  double* low, double* high, const char** why) {
    auto slack = [](double h) { return 0x1p-40 * (1 + abs_value(h)); };
    *low = DBL_MAX;
    *high = -DBL_MAX;
    for (size_t i = 0; i < count; ++i) {
        if (!reader.valid(i)) continue;
        const Local p = frame.local(reader.point(i));
        if (!(abs_value(p.x) <= kStreamRange && abs_value(p.y) <= kStreamRange &&
              abs_value(p.h) <= kStreamRange)) {
            s.rep.points.first_invalid_index = s.rep.points.in_count + i;
            *why = "a pushed point lies more than 2^60 times the first layer's size away from it";
            return Status::invalid_point;
        }
        if (p.h > top_height + slack(top_height) || p.h < lower_limit - slack(lower_limit)) {
            *why = "a pushed point lies outside its layer: below the previous layer's top or "
                   "above its own";
            return Status::out_of_order;
        }
        if (p.h < *low) *low = p.h;
        if (p.h > *high) *high = p.h;
    }
    return Status::ok;
}

// Holds the checked push as the next planned layer, its valid points from heights `low` to
// `high` in the window; the first push with points sets the stream's frame.
static inline void hold_push(Stream& s, const CloudReader& reader, size_t count, const Frame& frame,
                             double low, double high, double top_height) {
    if (!s.has_frame) {
        s.has_frame = true;
        s.chain.frame = frame;
        s.chain.reader = {reinterpret_cast<const unsigned char*>(s.points), sizeof(Vec3), false,
                          nullptr};
        s.chain.output_id = s.global;
        report_frame(frame, s.rep);
        s.lowest = low;
        s.highest = high;
        s.bounds[0] = low;
        s.start[0] = 0;
    } else {
        s.bounds[s.planned] = s.last_top;  // was the highest point so far
    }
    for (size_t i = 0; i < count; ++i) {
        if (!reader.valid(i)) {
            ++s.rep.points.rejected_count;
            continue;
        }
        const Vec3 p = reader.point(i);
        s.distinct.add(p);
        s.points[s.fill] = p;
        s.global[s.fill] = static_cast<uint32_t>(s.rep.points.in_count + i);
        ++s.fill;
    }
    s.rep.points.in_count += count;
    if (low <= high && high > s.highest) s.highest = high;
    ++s.planned;
    s.start[s.planned] = static_cast<uint32_t>(s.fill);
    s.bounds[s.planned] = s.highest;
    s.last_top = top_height;
    if (s.fill > s.rep.points.held_count) s.rep.points.held_count = s.fill;
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

size_t stream_workspace_size(size_t max_points_held, const Options& options) {
    (void)options;
    return detail::stream_bytes(max_points_held);
}

Status stream_open(const Options& options, void* workspace, size_t workspace_bytes,
                   TriangleCallback emit, void* emit_user, Report* report, Stream** stream) {
    if (!stream || !emit || !workspace) return Status::invalid_argument;
    *stream = nullptr;
    const detail::ByteRange work = detail::byte_range(workspace, workspace_bytes);
    if (report) {
        const detail::ByteRange ranges[] = {
            work, detail::byte_range(report, sizeof(Report)),
            detail::byte_range(report->layers.info,
                               detail::saturating_product(report->layers.info_capacity, sizeof(LayerInfo)))};
        if (detail::any_overlap(ranges, 3)) return Status::invalid_argument;
    }
    const char* refusal = (options.flags & (add_caps | drop_outliers))
                              ? "the stream takes neither add_caps (cap_ends() caps its surface) "
                                "nor drop_outliers (outliers are told from the whole cloud)"
                              : detail::options_refusal(options);
    if (!refusal) refusal = detail::layer_choice_refusal(options);
    if (refusal) {
        if (report) report->detail = refusal;
        return Status::invalid_argument;
    }
    if (options.axis == Axis::automatic) return Status::invalid_axis;
    if (!detail::flags_compiled(options)) return Status::not_compiled;
    // The largest window this workspace holds.
    size_t low = 0, high = workspace_bytes / sizeof(detail::Vec3);
    if (high > detail::kMaxPoints - 1) high = detail::kMaxPoints - 1;
    while (low < high) {
        size_t mid = low + (high - low + 1) / 2;
        size_t bytes = detail::stream_bytes(mid);
        if (bytes != 0 && bytes <= workspace_bytes) low = mid; else high = mid - 1;
    }
    if (low < kMinLayerPoints) return Status::out_of_memory;
    detail::Arena arena = detail::Arena::over(workspace, workspace_bytes);
    Stream* s = arena.alloc<Stream>(1);
    if (!s) return Status::out_of_memory;
    std::memset(static_cast<void*>(s), 0, sizeof *s);
    if (!detail::layout_stream(*s, low, arena)) return Status::out_of_memory;
    s->arena = arena;
    s->workspace = work;
    s->options = options;
    s->options.cuts = nullptr;
    s->options.cut_count = 0;
    s->emit = emit;
    s->emit_user = emit_user;
    s->user_report = report;
    s->rep.layers.info = report ? report->layers.info : nullptr;
    s->rep.layers.info_capacity = s->rep.layers.info ? report->layers.info_capacity : 0;
    s->failure = Status::ok;
    s->early_top = -DBL_MAX;
    for (size_t i = 0; i < low; ++i) s->positions[i] = static_cast<uint32_t>(i);
    // The frame's axis is checked now, on no points.
    detail::Frame frame;
    detail::CloudReader none = {nullptr, 0, false, nullptr};
    Status status = detail::choose_frame(detail::sum_cloud(none, 0), options, frame);
    if (status != Status::ok) return status;
    detail::publish(*s);
    *stream = s;
    return Status::ok;
}

Status stream_push(Stream* stream, const Cloud& points, double top) {
    if (!stream || stream->closed) return Status::invalid_argument;
    Stream& s = *stream;
    if (s.failure != Status::ok) return s.failure;
    // A refusal names its own reason, never the one of a push refused before.
    const char* why = nullptr;
    detail::CloudReader reader;
    Status status = detail::check_push(s, points, top, &reader, &why);
    if (status != Status::ok) return detail::refuse_push(s, status, why);
    // Check everything before anything changes.
    const detail::CloudSums sums = detail::sum_cloud(reader, points.count);
    const size_t first_invalid = detail::refused_at(reader, points.count, sums, s.options);
    if (first_invalid < points.count) {
        s.rep.points.first_invalid_index = s.rep.points.in_count + first_invalid;
        return detail::refuse_push(s, Status::invalid_point, detail::kInvalidPointDetail);
    }
    if (!s.has_frame && top < s.early_top)
        return detail::refuse_push(s, Status::out_of_order, detail::kTopBelow);
    if (!s.has_frame && sums.valid == 0) {  // nothing to place yet: pushes before the first point
        s.rep.points.in_count += points.count;
        s.rep.points.rejected_count += points.count;
        s.early_top = top;
        detail::publish(s);
        return Status::ok;
    }
    detail::Frame frame = s.chain.frame;
    if (!s.has_frame) {
        status = detail::choose_frame(sums, s.options, frame);
        if (status == Status::invalid_origin)
            return detail::refuse_push(s, status, detail::origin_refusal(s.options, sums));
        if (status != Status::ok) return status;
    }
    const double axis_origin = detail::dot(frame.origin, frame.axis);
    const double top_height = (top - axis_origin) * frame.scale;
    // The previous top, which the points must not lie below: the last push's, or before the
    // first point that of the pushes without points (far below all, or -infinity, if none).
    const double lower_limit =
        s.has_frame ? s.last_top : (s.early_top - axis_origin) * frame.scale;
    if (top_height < lower_limit)
        return detail::refuse_push(s, Status::out_of_order, detail::kTopBelow);
    double low = 0, high = 0;
    status = detail::push_heights(s, reader, points.count, frame, lower_limit, top_height, &low,
                                  &high, &why);
    if (status != Status::ok) return detail::refuse_push(s, status, why);
    if (s.fill + sums.valid > s.capacity || s.planned + 1 > s.slot_capacity)
        return detail::refuse_push(s, Status::out_of_memory,
                                   "the stream would hold more points or layers than its workspace: "
                                   "push thicker layers, or give more workspace (see "
                                   "Report::points.held_count)");
    detail::hold_push(s, reader, points.count, frame, low, high, top_height);
    status = detail::advance(s, false);
    if (status != Status::ok) s.failure = status;
    // The counts so far; why a point is not a vertex is only known at the close.
    detail::report_chain(s.chain, s.rep.points.in_count - s.rep.points.rejected_count, s.rep);
    s.rep.detail = nullptr;
    s.rep.diagnostics.fold_count = s.sink.folds;
    detail::publish(s);
    return status;
}

Status stream_close(Stream* stream) {
    if (!stream || stream->closed) return Status::invalid_argument;
    Stream& s = *stream;
    s.closed = true;
    Status status = s.failure;
    const size_t valid = s.rep.points.in_count - s.rep.points.rejected_count;
    if (status == Status::ok && (valid < 3 || s.distinct.count < 3)) {
        s.rep.detail = "fewer than 3 distinct valid points";
        status = Status::too_few_points;
    } else if (status == Status::ok && !(s.highest > s.lowest)) {
        s.rep.detail = "every point has the same height along the axis";
        status = Status::flat_cloud;
    }
    if (status == Status::ok) status = detail::advance(s, true);
    if (status == Status::ok) {
        detail::report_chain(s.chain, valid, s.rep);
        s.rep.diagnostics.fold_count = s.sink.folds;
        if (s.rep.layers.used_count == 0) {
            s.rep.detail = "no layer's points surround the axis: the cloud is not columnar "
                           "around it (try another axis)";
            status = Status::not_columnar;
        } else if (s.rep.triangle_count == 0) {
            s.rep.detail = "every point lies on the boundary of its layer: too few points to "
                           "span a surface";
            status = Status::too_few_points;
        }
    }
    detail::publish(s);
    return status;
}

}  // namespace stratmesh

// >>axis =================================================================================
// The automatic axis.
//
// The automatic axis. The method needs the direction along which the cloud's sections are
// loops around one centre line, and the direction of largest variance is often another: a
// head is longest from front to back, a squat bone across. The candidates are the three
// principal directions of the cloud (from a sample of kAxisShapeSample points) and then x,
// y and z (skipping any within about ten degrees of one before it). A smaller sample is
// meshed as one tube along the first: where the surface runs along it (its triangles'
// normals lie across it, as on a tube or a limb), it is the axis. Otherwise each candidate
// meshes the sample and the one whose surface is smallest wins: where the layers cannot
// follow the surface they fold and bridge gaps with webs, and both add area. The samples
// are every k-th kept point in input order, so the choice is deterministic.

namespace stratmesh {
namespace detail {

// Points meshed per candidate: enough to see an object's limbs and ends, few enough that
// six candidates cost a small part of a large run.
const size_t kAxisSample = 512;

// Points the principal directions are measured on: enough for a tube's axis within a
// fraction of a degree.
const size_t kAxisShapeSample = 16384;

// The share of the sample surface's normals along the first candidate (the mean squared
// cosine, weighted by area) below which the surface runs along it: about 0.04 on a tube,
// 0.16 to 0.5 on heads, bones and hands.
const double kAlongSurface = 0.1;

// A candidate whose direction is within about 10 degrees of an earlier one is not tried.
const double kSameAxisCosine = 0.985;

const uint32_t kMostAxisCandidates = 6;

// The three principal directions of a symmetric 3x3 matrix, largest variance first: power
// iteration, then again on the matrix without the first direction's share.
static inline void principal_directions(const double m[3][3], Vec3 out[3]) {
    out[0] = principal_direction(m);
    const Vec3 v = out[0];
    const double mv[3] = {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
                          m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    const double lambda = mv[0] * v.x + mv[1] * v.y + mv[2] * v.z;
    const double c[3] = {v.x, v.y, v.z};
    double rest[3][3];
    for (int r = 0; r < 3; ++r)
        for (int s = 0; s < 3; ++s) rest[r][s] = m[r][s] - lambda * c[r] * c[s];
    Vec3 second = principal_direction(rest);
    second = second - scaled(v, dot(second, v));
    if (!normalize(second)) {
        // Any direction across the first.
        second = abs_value(v.x) < 0.5 ? cross(v, Vec3{1, 0, 0}) : cross(v, Vec3{0, 1, 0});
        normalize(second);
    }
    out[1] = second;
    out[2] = cross(v, second);
}

// The scatter matrix of `count` points, packed, about their mean.
static inline void scatter_of(const double* xyz, size_t count, double m[3][3]) {
    // Scaled by the power of two that brings the largest coordinate near 1 (exactly, so
    // directions and ratios keep their bits): squares of coordinates near either end of the
    // double range would overflow or vanish. A multiplication where the factor is a normal
    // double, ldexp (a call) only where it is not.
    double largest = 0;
    for (size_t i = 0; i < 3 * count; ++i)
        largest = abs_value(xyz[i]) > largest ? abs_value(xyz[i]) : largest;
    int exponent = 0;
    std::frexp(largest, &exponent);
    const double factor = exponent > -1000 && exponent < 1000 ? std::ldexp(1.0, -exponent) : 0;
    auto unit = [&](double v) { return factor != 0 ? v * factor : std::ldexp(v, -exponent); };
    Vec3 mean = {0, 0, 0};
    for (size_t i = 0; i < count; ++i)
        mean = Vec3{mean.x + unit(xyz[3 * i]), mean.y + unit(xyz[3 * i + 1]),
                    mean.z + unit(xyz[3 * i + 2])};
    mean = scaled(mean, 1.0 / static_cast<double>(count));
    for (int r = 0; r < 3; ++r)
        for (int s = 0; s < 3; ++s) m[r][s] = 0;
    for (size_t i = 0; i < count; ++i) {
        const double d[3] = {unit(xyz[3 * i]) - mean.x, unit(xyz[3 * i + 1]) - mean.y,
                             unit(xyz[3 * i + 2]) - mean.z};
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s) m[r][s] += d[r] * d[s];
    }
}

// The variance of the scatter matrix along the unit direction v.
static inline double variance_along(const double m[3][3], Vec3 v) {
    const double c[3] = {v.x, v.y, v.z};
    double sum = 0;
    for (int r = 0; r < 3; ++r)
        for (int s = 0; s < 3; ++s) sum += c[r] * m[r][s] * c[s];
    return sum;
}

// A sample whose variance across its principal direction is this small a share of the
// variance along it (a width a millionth of its length) lies on a line up to rounding: no
// surface passes through it (Status::degenerate). Well above the rounding of the variances'
// difference.
const double kLineVariance = 0x1p-40;

// The candidates for the axis of a sample of `count` points, packed.
static inline uint32_t axis_candidates(const double* xyz, size_t count, Vec3* out) {
    double m[3][3];
    scatter_of(xyz, count, m);
    Vec3 all[6];
    principal_directions(m, all);
    all[3] = Vec3{1, 0, 0};
    all[4] = Vec3{0, 1, 0};
    all[5] = Vec3{0, 0, 1};
    uint32_t kept = 0;
    for (const Vec3& a : all) {
        bool repeat = false;
        for (uint32_t k = 0; k < kept; ++k) repeat = repeat || abs_value(dot(a, out[k])) > kSameAxisCosine;
        if (!repeat) out[kept++] = a;
    }
    return kept;
}

// What a candidate's sample surface measures: its area, plus the area of a triangle per
// sample point left out (a layer that cannot follow the surface drops points instead of
// folding). *along (optional) receives the mean squared cosine between the triangles'
// normals and the unit axis, weighted by their areas: 0 where the surface runs along the
// axis, 1 where it lies across it.
static inline double sample_surface(const double* xyz, const uint32_t* tri, size_t count,
                             size_t unused, Vec3 axis, double* along) {
    double area = 0, along_sum = 0, normals = 0;
    for (size_t t = 0; t < count; ++t) {
        const double* a = xyz + 3 * tri[3 * t];
        const double* b = xyz + 3 * tri[3 * t + 1];
        const double* c = xyz + 3 * tri[3 * t + 2];
        const Vec3 n = cross(Vec3{b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                             Vec3{c[0] - a[0], c[1] - a[1], c[2] - a[2]});
        const double length = std::sqrt(dot(n, n));
        area += length / 2;
        if (length == 0) continue;
        const double cosine = dot(n, axis) / length;
        along_sum += cosine * cosine * length;
        normals += length;
    }
    if (along) *along = normals > 0 ? along_sum / normals : 1;
    const double per_triangle = count > 0 ? area / static_cast<double>(count) : 0;
    return area + 2 * per_triangle * static_cast<double>(unused);
}

// What a candidate's sample is meshed as: one layer along `axis`, its ends cut where the
// tube's are, nothing else asked for and no callback.
static inline TubeRequest trial_request(const TubeRequest& tube, Vec3 axis) {
    TubeRequest trial = {};
    trial.axis = Axis::direction;
    trial.direction[0] = axis.x;
    trial.direction[1] = axis.y;
    trial.direction[2] = axis.z;
    trial.cut_ends = tube.cut_ends;
    trial.layers.count = 1;
    return trial;
}

// Meshes the sample along one candidate; DBL_MAX if it cannot.
// *along (optional) receives the share of the sample surface's normals along the axis.
static inline double try_axis(const double* sample, size_t count, Vec3 axis, const TubeRequest& request,
                       Arena& arena, double* along) {
    const TubeRequest trial = trial_request(request, axis);
    const size_t mark = arena.mark();
    uint32_t* tri = arena.alloc<uint32_t>(6 * count);
    if (arena.failed) return DBL_MAX;
    const Cloud cloud = {sample, count, 0, Scalar::float64};
    TubeInput in = {reader_of(cloud), count, {}};
    in.sums = sum_cloud(in.reader, count);
    Report rep = {};
    size_t triangles = 0;
    const Status status = mesh_tube(in, trial, arena, tri, 2 * count, &triangles, rep);
    arena.rewind(mark);
    if (status != Status::ok) return DBL_MAX;
    return sample_surface(sample, tri, triangles,
                          in.sums.valid - rep.points.used_count - rep.points.duplicate_count,
                          axis, along);
}

// Every k-th kept point of `in`, packed, at most `most` of them (and about that many), in
// `arena`; null if the workspace is too small. *taken receives their count. Where every
// point is kept, the sample is read by index, without a pass over the cloud.
static inline double* sample_points(const TubeInput& in, size_t most, Arena& arena, size_t* taken) {
    const size_t count = in.sums.valid < most ? in.sums.valid : most;
    double* sample = arena.alloc<double>(3 * count);
    *taken = 0;
    if (!sample || count == 0) return sample;
    // The k-th of `count` is kept point number k * valid / count (64 bits: no overflow).
    const uint64_t valid = in.sums.valid;
    auto put = [&](size_t i) {
        const Vec3 p = in.reader.point(i);
        sample[3 * *taken] = p.x;
        sample[3 * *taken + 1] = p.y;
        sample[3 * *taken + 2] = p.z;
        ++*taken;
    };
    if (in.sums.valid == in.count && !in.reader.dropped) {
        for (uint64_t k = 0; k < count; ++k) put(static_cast<size_t>(k * valid / count));
        return sample;
    }
    for (size_t i = 0, seen = 0; i < in.count && *taken < count; ++i) {
        if (!in.reader.valid(i)) continue;
        if (seen++ == *taken * valid / count) put(i);
    }
    return sample;
}

// The axis for Axis::automatic: the candidate whose sample surface is smallest (see above).
// False if the workspace is too small.
static inline bool choose_axis(const TubeInput& in, const TubeRequest& request, Arena& arena,
                        Vec3& axis) {
    const size_t mark = arena.mark();
    size_t taken = 0;
    const double* shape = sample_points(in, kAxisShapeSample, arena, &taken);
    if (!shape) return false;
    Vec3 candidates[kMostAxisCandidates];
    const uint32_t tries = axis_candidates(shape, taken, candidates);
    arena.rewind(mark);
    const double* sample = sample_points(in, kAxisSample, arena, &taken);
    if (!sample) return false;
    axis = candidates[0];
    double along = 1;
    double best = try_axis(sample, taken, candidates[0], request, arena, &along);
    for (uint32_t k = 1; k < tries && !(along < kAlongSurface); ++k) {
        const double score = try_axis(sample, taken, candidates[k], request, arena, nullptr);
        if (score < best) {
            best = score;
            axis = candidates[k];
        }
    }
    arena.rewind(mark);
    return !arena.failed;
}

// Workspace for choose_axis() on a cloud of `valid` kept points.
static inline size_t axis_workspace_size(size_t valid, const TubeRequest& request) {
    const size_t count = valid < kAxisSample ? valid : kAxisSample;
    const size_t tube = tube_workspace_size(count, trial_request(request, Vec3{0, 0, 1}));
    if (tube == 0) return 0;
    const size_t shape = valid < kAxisShapeSample ? valid : kAxisShapeSample;
    Arena arena = Arena::measuring();
    arena.alloc<double>(3 * (shape > count ? shape : count));
    arena.alloc<uint32_t>(6 * count);
    return arena.failed ? 0 : arena.required_bytes() + tube;
}

// Axis::automatic in `request` resolved by choose_axis(); any other axis stays. *detail
// receives the reason where it fails.
static inline Status resolve_axis(const TubeInput& in, Arena& arena, TubeRequest& request,
                           const char** detail) {
    if (request.axis != Axis::automatic) return Status::ok;
    if (!kAxisTrials) {
        *detail = kNotCompiledDetail;
        return Status::not_compiled;
    }
    if (in.sums.distinct < 3) {  // no surface along any axis: mesh_tube says so
        request.axis = Axis::z;
        return Status::ok;
    }
    Vec3 axis;
    if (!choose_axis(in, request, arena, axis)) {
        *detail = "the workspace is smaller than reconstruct_workspace_size()";
        return Status::out_of_memory;
    }
    const double direction[3] = {axis.x, axis.y, axis.z};
    set_direction(request, direction);
    return Status::ok;
}

}  // namespace detail
}  // namespace stratmesh

// >>no area ==============================================================================
// Why a surface through the points would have no area: a line, far points, far clusters.

namespace stratmesh {
namespace detail {

// Whether the kept points of `in` lie on a line up to rounding (see kLineVariance), judged
// on a sample. False also if the workspace is too small for the sample.
static inline bool on_a_line(const TubeInput& in, Arena& arena) {
    const size_t mark = arena.mark();
    size_t taken = 0;
    const double* sample = sample_points(in, kAxisSample, arena, &taken);
    arena.rewind(mark);
    if (!sample) return false;
    double m[3][3];
    scatter_of(sample, taken, m);
    const double along = variance_along(m, principal_direction(m));
    return !(m[0][0] + m[1][1] + m[2][2] - along > kLineVariance * along);
}

// Why a cloud's surface has no area (explain_no_area()).
enum class NoArea : uint32_t { unexplained, line, few_far_points, far_clusters };

// The bins along the bounding box's longest side in which why_no_area() looks for groups:
// one for kPointsABin points, at least 3 (the two ends and between), at most kNoAreaBins,
// so that its groups take a few bytes a point.
const uint32_t kNoAreaBins = 4096;
const size_t kPointsABin = 16;

static inline uint32_t no_area_bins(size_t point_count) {
    const size_t bins = point_count / kPointsABin;
    return bins < 3 ? 3u : bins > kNoAreaBins ? kNoAreaBins : static_cast<uint32_t>(bins);
}

// A group whose largest side is under this share of the cloud's is a point beside the
// cloud: its surface has no area there (kLeastArea is this share squared).
const double kCollapsedShare = 0x1p-20;

// One group of why_no_area(): its points' offsets from its first point (halved, so that
// nothing overflows), their box, and their moments at the scale of that box (so that a
// group far from the others keeps its own digits).
struct PointGroup {
    Vec3 first, low, high;
    double scale;
    double sum[3];
    double products[3][3];
    uint32_t count;
};

static inline Vec3 half_offset(Vec3 p, Vec3 first) { return scaled(p, 0.5) - scaled(first, 0.5); }

// Whether a group spans a surface of its own: 3 points or more, off one line.
static inline bool spans_surface(const PointGroup& g) {
    if (g.count < 3) return false;
    const double n = g.count;
    double m[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m[r][c] = g.products[r][c] - g.sum[r] * g.sum[c] / n;
    const double along = variance_along(m, principal_direction(m));
    return along > 0 && m[0][0] + m[1][1] + m[2][2] - along > kLineVariance * along;
}

// The points' positions along their bounding box's longest side, in up to kNoAreaBins bins.
struct Binning {
    int side;
    double start, span;  // halved coordinates
    uint32_t bins;
    uint32_t of(Vec3 p) const {
        const double t = (coordinate(p, side) * 0.5 - start) / span * bins;
        return t >= bins ? bins - 1 : t > 0 ? static_cast<uint32_t>(t) : 0u;
    }
};

// Adds a point's half offset to its group's box (first pass) or moments (second pass).
static inline void add_to_group(PointGroup& g, Vec3 p, int pass) {
    if (pass == 0 && g.count++ == 0) g.first = p;
    const Vec3 h = half_offset(p, g.first);
    if (pass == 0) {
        g.low = {h.x < g.low.x ? h.x : g.low.x, h.y < g.low.y ? h.y : g.low.y, h.z < g.low.z ? h.z : g.low.z};
        g.high = {h.x > g.high.x ? h.x : g.high.x, h.y > g.high.y ? h.y : g.high.y,
                  h.z > g.high.z ? h.z : g.high.z};
        return;
    }
    const Vec3 d = scaled(h, g.scale);
    const double c[3] = {d.x, d.y, d.z};
    for (int r = 0; r < 3; ++r) {
        g.sum[r] += c[r];
        for (int s = 0; s < 3; ++s) g.products[r][s] += c[r] * c[s];
    }
}

// Numbers the runs of occupied bins (non-zero) from 1, empty bins 0; returns the runs.
static inline uint32_t number_runs(uint32_t* group_of, uint32_t bins) {
    uint32_t count = 0;
    for (uint32_t b = 0; b < bins; ++b) {
        const bool occupied = group_of[b] != 0;
        if (occupied && (b == 0 || group_of[b - 1] == 0)) ++count;
        group_of[b] = occupied ? count : 0;
    }
    return count;
}

// The groups of why_no_area(): the occupied bins first, numbered by run (number_runs()),
// then each point joins its bin's group, its box first, its moments after. One loop over
// the points serves the three passes.
static inline uint32_t gather_groups(const TubeInput& in, const Binning& binning, uint32_t* group_of,
                              PointGroup* groups) {
    std::memset(group_of, 0, binning.bins * sizeof(uint32_t));
    uint32_t count = 0;
    for (int pass = -1; pass < 2; ++pass) {
        for (size_t i = 0; i < in.count; ++i) {
            if (!in.reader.valid(i)) continue;
            const Vec3 p = in.reader.point(i);
            uint32_t& group = group_of[binning.of(p)];
            if (pass < 0)
                group = 1;
            else
                add_to_group(groups[group - 1], p, pass);
        }
        if (pass < 0) {
            count = number_runs(group_of, binning.bins);
            std::memset(static_cast<void*>(groups), 0, count * sizeof(PointGroup));
        }
        for (uint32_t k = 0; pass == 0 && k < count; ++k)
            groups[k].scale = scale_for_extent(largest_of(groups[k].high - groups[k].low));
    }
    return count;
}

// The bytes why_no_area() takes for point_count points.
static inline size_t no_area_workspace_size(size_t point_count) {
    Arena arena = Arena::measuring();
    const size_t bins = no_area_bins(point_count);
    arena.alloc<uint32_t>(bins);
    arena.alloc<PointGroup>(bins);
    return arena.required_bytes();
}

// Why the kept points of `in` span no area: binned along their bounding box's longest side,
// they fall into groups (runs of occupied bins, so the points of a collapsed cluster share
// one). None spans a surface (3 points off a line): a line. The largest that does is a
// point beside the cloud (kCollapsedShare) and fewer than kOutlierNeighbours points lie
// outside it: specks that drop_outliers leaves out; more: clusters far apart. Unexplained
// otherwise, or when the workspace cannot hold the groups.
static inline NoArea why_no_area(const TubeInput& in, Arena& arena) {
    const Vec3 low = {in.sums.lowest[0], in.sums.lowest[1], in.sums.lowest[2]};
    const Vec3 high = {in.sums.highest[0], in.sums.highest[1], in.sums.highest[2]};
    const Vec3 half_side = scaled(high, 0.5) - scaled(low, 0.5);
    Binning binning;
    binning.span = largest_of(half_side);
    binning.side = binning.span == half_side.x ? 0 : binning.span == half_side.y ? 1 : 2;
    binning.start = coordinate(low, binning.side) * 0.5;
    binning.bins = no_area_bins(in.sums.valid);
    if (!(binning.span > 0) || binning.bins == 0) return NoArea::line;
    const size_t mark = arena.mark();
    uint32_t* group_of = arena.alloc<uint32_t>(binning.bins);
    PointGroup* groups = arena.alloc<PointGroup>(binning.bins);
    if (arena.failed) {
        arena.rewind(mark);
        return NoArea::unexplained;
    }
    const uint32_t count = gather_groups(in, binning, group_of, groups);
    const PointGroup* largest = nullptr;
    for (uint32_t g = 0; g < count; ++g)
        if (spans_surface(groups[g]) && (!largest || groups[g].count > largest->count))
            largest = &groups[g];
    const bool collapsed =
        largest && largest_of(largest->high - largest->low) < kCollapsedShare * binning.span;
    const size_t outside = largest ? in.sums.valid - largest->count : 0;
    arena.rewind(mark);
    if (!largest) return NoArea::line;
    if (!collapsed || outside == 0) return NoArea::unexplained;
    return outside < kOutlierNeighbours ? NoArea::few_far_points : NoArea::far_clusters;
}

// The status and detail of a cloud refused as degenerate or not_columnar, where
// why_no_area() tells a reason: the same status and detail where it tells none.
static inline Status explain_no_area(const TubeInput& in, Status status, Arena& arena, Report& rep) {
    switch (why_no_area(in, arena)) {
    case NoArea::line:
        if (status != Status::degenerate) return status;
        rep.detail = "the points lie on a line up to rounding: no surface passes through them";
        return Status::degenerate;
    case NoArea::few_far_points:
        rep.detail = "a few points lie so far from the rest that the rest collapse to a point "
                     "beside them: drop_outliers leaves such points out";
        return Status::degenerate;
    case NoArea::far_clusters:
        rep.detail = "the points form clusters so far apart that each collapses to a point "
                     "beside the others: mesh each cluster on its own";
        return Status::separate_clusters;
    default:
        if (status != Status::degenerate) return status;
        rep.detail = "the surface through the points has no area beside the cloud's extent";
        return Status::degenerate;
    }
}

}  // namespace detail
}  // namespace stratmesh

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

// >>parting ==============================================================================
// find_parting(): where the cloud parts into branches.
//
// find_parting(): the cuts lie every half gap along the axis (at most one per point), and
// each point falls in the step between two of them. Two sweeps, one from the top down for
// the cuts above which the cloud parts and one from the bottom up for those below, add the
// points a step at a time to a union-find of pieces (union by size, path halving: no
// recursion), each point joining the pieces of those already added within the gap, found
// in its block of 3 x 3 x 3 grid cells of side gap. Which points lie on a cut's side is
// decided by their step, so it is the same for both sweeps and any order; within a step
// the points go in grid order, which lies in the frame with its cells sorted by height
// first, so that a point's neighbours are near in memory and their blocks were just used.
// After each step, the pieces that count are checked for branches at the cut the step
// reaches; the points within two gaps of it are those of the last four steps.

#if !defined(STRATMESH_SMALL_CODE)
namespace stratmesh {
namespace detail {

// The gap, in median nearest-neighbour distances: points of one branch lie closer, the
// branches of a fork farther apart.
const double kPartingGap = 4.0;

const uint32_t kStepsPerGap = 2;

// The points the scale (the median distance to the nearest neighbour) is measured on:
// enough for the median within a few percent.
const size_t kScaleSample = 2048;

// The blocks of the grid cells met last, by a hash of the cell: a step's points share
// cells, and each block costs 18 searches to find.
const uint32_t kBlockCacheSize = 2048;

const uint64_t kNoCell = ~uint64_t{0};  // no key: keys take 63 bits

const uint32_t kNotAdded = ~uint32_t{0};

// The most points a sweep may compare, on average per point: a surface's block of cells
// holds about 40; a cloud crowded beyond this (many repeats of the same points, a solid
// volume of points) is not searched, so that no cloud costs time quadratic in its size.
const uint64_t kPartingChecksPerPoint = 1024;

struct CachedBlock {
    uint64_t cell;
    CellBlock block;
};

// The size from which a piece of a side of `points` points counts: kSmallestBranch, and a
// twentieth of the side.
static inline uint32_t counting_size(size_t points, uint32_t smallest) {
    const size_t twentieth = (points + 19) / 20;
    return twentieth > smallest ? static_cast<uint32_t>(twentieth) : smallest;
}

// The sweep's state. Pieces are named by the order in which their root was added. A
// point's level is its height as the sweep sees it: the frame height, negated for the sweep
// from the bottom up, so that both sweeps go down and a cut's side lies above it.
// `listed` holds every root whose piece counts (see counting_size), and others that
// branches_at drops: a root joins it when its piece grows to the size that counts at that
// moment, which never exceeds the size that counts at the next cut.
struct PartingSweep {
    const Local* position;    // grid order, in the frame
    const GridItem* cells;    // grid order
    size_t count;
    double gap;               // in frame units
    double sign;              // +1 from the top, -1 from the bottom
    uint32_t* added;          // order -> grid position
    uint32_t* order_of;       // grid position -> order, or kNotAdded
    uint32_t* parent;         // order -> order
    uint32_t* size;           // root -> points
    double* lowest;           // root -> its lowest level
    double* highest;          // root -> its highest level
    CachedBlock* blocks;      // kBlockCacheSize of them
    size_t fingers[18];       // block_around's
    uint32_t* listed;         // roots, see above
    unsigned char* is_listed; // order -> whether it is in `listed`
    size_t listed_count;
    uint32_t counting;        // counting_size(points added so far)
    uint32_t smallest;        // the fewest points a branch holds (kSmallestBranch)
    uint64_t checks_left;     // see kPartingChecksPerPoint
    bool crowded;             // the checks ran out: the sweep stopped

    double level(uint32_t t) const { return sign * position[added[t]].h; }
    uint32_t root(uint32_t t) { return find_root(parent, t); }
    void join(uint32_t a, uint32_t b) {
        a = root(a);
        b = root(b);
        if (a == b) return;
        if (size[a] < size[b] || (size[a] == size[b] && b < a)) {
            const uint32_t t = a;
            a = b;
            b = t;
        }
        parent[b] = a;
        size[a] += size[b];
        if (lowest[b] < lowest[a]) lowest[a] = lowest[b];
        if (highest[b] > highest[a]) highest[a] = highest[b];
        if (size[a] >= counting && !is_listed[a]) {
            is_listed[a] = 1;
            listed[listed_count++] = a;  // at most one entry per point: `count` of room
        }
    }
    // Adds the point at grid position j as the t-th, joined to the points added before it.
    void add(uint32_t t, uint32_t j) {
        added[t] = j;
        order_of[j] = t;
        parent[t] = t;
        size[t] = 1;
        lowest[t] = highest[t] = level(t);
        is_listed[t] = 0;
        counting = counting_size(t + 1, smallest);
        const uint64_t cell = cells[j].cell;
        CachedBlock& cached = blocks[(cell * 0x9E3779B97F4A7C15u) >> 53];  // 11 bits
        if (cached.cell != cell) cached = {cell, block_around(cells, count, j, fingers)};
        const CellBlock& block = cached.block;
        const size_t checks = block.points();
        if (checks > checks_left) {
            crowded = true;
            return;
        }
        checks_left -= checks;
        const Local p = position[j];
        for (uint32_t k = 0; k < block.count; ++k)
            for (size_t i = block.begin[k]; i < block.end[k]; ++i) {
                if (order_of[i] >= t) continue;  // not added yet (or p itself)
                const Local q = position[i];
                const double dx = q.x - p.x, dy = q.y - p.y, dh = q.h - p.h;
                if (dx * dx + dy * dy + dh * dh < gap * gap) join(t, order_of[i]);
            }
    }
};

// The widest run of empty sectors (of kSectors) around a branch's centre at the cut: a
// quarter turn. An arc of a ring seen from its centroid leaves more than that open.
const uint32_t kBranchArcSectors = kSectors / 4;

// A piece that counts at a cut: its root and its points' sums within the two gaps above.
struct BranchCandidate {
    uint32_t root;
    double sum[2][2];
    uint32_t slice_points[2];
};

// Whether the `added` points added so far, on the side of the cut at level `cut`, part into
// branches there; if so their sizes and roots go to `sizes` and `roots`, largest first, and
// their count is returned (else 0). The points of orders [slab_start, added) are those
// within two gaps of the cut.
static inline uint32_t branches_at(PartingSweep& s, uint32_t added, uint32_t slab_start, double cut,
                            uint32_t* sizes, uint32_t* roots) {
    BranchCandidate found[kMaxBranches];
    uint32_t pieces = 0;
    bool bump = false;
    size_t kept = 0;
    const uint32_t counting = counting_size(added, s.smallest);
    for (size_t k = 0; k < s.listed_count; ++k) {
        const uint32_t r = s.listed[k];
        if (s.parent[r] != r || s.size[r] < counting) {  // merged since, or too small now
            s.is_listed[r] = 0;
            continue;
        }
        s.listed[kept++] = r;
        if (s.lowest[r] - cut > s.gap) continue;  // apart from the cut: left aside
        if (s.highest[r] - cut < 2 * s.gap)
            bump = true;
        else if (pieces < kMaxBranches)  // disjoint twentieths of the side: never more
            found[pieces++] = {r, {{0, 0}, {0, 0}}, {0, 0}};
    }
    s.listed_count = kept;
    if (bump || pieces < 2) return 0;
    for (uint32_t t = slab_start; t < added; ++t) {
        const uint32_t r = s.root(t);
        for (uint32_t k = 0; k < pieces; ++k) {
            if (found[k].root != r) continue;
            const Local l = s.position[s.added[t]];
            const int slice = s.level(t) - cut < s.gap ? 0 : 1;
            found[k].sum[slice][0] += l.x;
            found[k].sum[slice][1] += l.y;
            ++found[k].slice_points[slice];
        }
    }
    // A branch's points within a gap of the cut go around its centre there: the arcs of a
    // rim that sparse flanks break apart near an open end do not.
    uint32_t held[kMaxBranches] = {};
    for (uint32_t t = slab_start; t < added; ++t) {
        if (!(s.level(t) - cut < s.gap)) continue;
        const uint32_t r = s.root(t);
        for (uint32_t k = 0; k < pieces; ++k) {
            if (found[k].root != r) continue;
            const Local l = s.position[s.added[t]];
            const double n = found[k].slice_points[0];
            held[k] |= 1u << sector_around(l.x - found[k].sum[0][0] / n, l.y - found[k].sum[0][1] / n);
        }
    }
    for (uint32_t k = 0; k < pieces; ++k)
        if (widest_gap(held[k]) > kBranchArcSectors) return 0;
    for (uint32_t k = 0; k < pieces; ++k) {
        const BranchCandidate& b = found[k];
        if (b.slice_points[1] == 0) continue;
        double d2 = 0;
        for (int c = 0; c < 2; ++c) {
            const double d = b.sum[0][c] / b.slice_points[0] - b.sum[1][c] / b.slice_points[1];
            d2 += d * d;
        }
        if (!(d2 < 4 * s.gap * s.gap)) return 0;
    }
    for (uint32_t k = 0; k < pieces; ++k) {
        uint32_t largest = k;
        for (uint32_t m = k + 1; m < pieces; ++m)
            if (s.size[found[m].root] > s.size[found[largest].root]) largest = m;
        const BranchCandidate t = found[k];
        found[k] = found[largest];
        found[largest] = t;
        sizes[k] = s.size[found[k].root];
        roots[k] = found[k].root;
    }
    return pieces;
}

// The points' steps: step k holds the points between the cuts at lo + k step_height and
// lo + (k + 1) step_height (the cut at lo + k step_height is cut k, for k in [1, steps)).
// by_step lists the grid positions step by step, each step in grid order, from
// step_start[k] to step_start[k + 1].
struct PartingSteps {
    uint32_t steps;
    double lo, step_height;
    uint32_t* step_start;     // steps + 1 entries
    uint32_t* by_step;
};

// Where one side of the cloud parts: the branches' count (0: nowhere), the cut's index,
// and the branches' sizes and roots, largest first.
struct SideParting {
    uint32_t branches;
    uint32_t cut_index;
    uint32_t added;           // the points on the side of that cut
    uint32_t sizes[kMaxBranches];
    uint32_t roots[kMaxBranches];
};

// One sweep: down from the top (`from_top`) or up from the bottom; the last cut of the
// sweep where the cloud parts (the lowest above, the highest below). With `stop` (a cut
// index, 0 for none), it stops once that cut is tried: the roots then name the pieces as
// the union-find holds them, for labelling.
static inline SideParting sweep_for_parting(PartingSweep& s, const PartingSteps& p, bool from_top,
                                     uint32_t stop) {
    s.sign = from_top ? 1 : -1;
    s.listed_count = 0;
    s.counting = s.smallest;
    for (uint32_t k = 0; k < kBlockCacheSize; ++k) s.blocks[k].cell = kNoCell;
    for (size_t j = 0; j < s.count; ++j) s.order_of[j] = kNotAdded;
    for (size_t& f : s.fingers) f = 0;
    s.checks_left = kPartingChecksPerPoint * s.count;
    const double top = from_top ? p.lo + p.steps * p.step_height : -p.lo;
    SideParting best = {};
    uint32_t added = 0;
    for (uint32_t m = 0; m + 1 < p.steps; ++m) {
        // Add step k, then try the cut on its far side: cut k from the top, k + 1 from below.
        const uint32_t k = from_top ? p.steps - 1 - m : m;
        for (uint32_t i = p.step_start[k]; i < p.step_start[k + 1] && !s.crowded; ++i)
            s.add(added++, p.by_step[i]);
        if (s.crowded) return SideParting{};
        const uint32_t cut_index = from_top ? k : k + 1;
        const double cut = s.sign * (p.lo + cut_index * p.step_height);
        // A side thinner than four gaps is a rim, which falls apart into arcs.
        if (top - cut < 4 * s.gap || added == 0) continue;
        const uint32_t slab = 2 * kStepsPerGap;  // two gaps
        const uint32_t slab_step = from_top ? (cut_index + slab < p.steps ? cut_index + slab : p.steps)
                                            : (cut_index > slab ? cut_index - slab : 0);
        const uint32_t slab_start = from_top ? static_cast<uint32_t>(s.count) - p.step_start[slab_step]
                                             : p.step_start[slab_step];
        SideParting here = {};
        here.branches = branches_at(s, added, slab_start, cut, here.sizes, here.roots);
        here.cut_index = cut_index;
        here.added = added;
        if (here.branches > 0) best = here;
        if (cut_index == stop) break;
    }
    return best;
}

// With find_parting's branch_of: sweeps again to the side's cut and labels the points
// there by their piece, keeping the labels already given (the side above is labelled
// first). `first` is the label of the side's largest branch. A piece that is no branch but
// starts at the cut (within a gap of it) goes on the trunk across it: the top of a skull's
// crown between two horns, where the cut lies just below it, too small to count as a bump
// (the bust with horns of 50,000 points: 147 such points, which left the split undone).
static inline void label_branches(PartingSweep& s, const PartingSteps& p, bool from_top,
                           uint32_t cut_index, uint8_t first, uint8_t* branch_of) {
    const SideParting side = sweep_for_parting(s, p, from_top, cut_index);
    const double cut = s.sign * (p.lo + cut_index * p.step_height);
    for (uint32_t t = 0; t < side.added; ++t) {
        const uint32_t r = s.root(t);
        uint8_t label = s.lowest[r] - cut > s.gap ? kBeyondBranches : kInTrunk;
        for (uint32_t k = 0; k < side.branches; ++k)
            if (side.roots[k] == r) label = static_cast<uint8_t>(first + k);
        uint8_t& l = branch_of[s.cells[s.added[t]].index];
        if (l == kInTrunk) l = label;
    }
}

struct PartingMemory {
    GridItem* items;          // with spare: the cell sort's arrays
    GridItem* spare;
    Local* position;
    PartingSteps steps;
    PartingSweep sweep;
};

// Allocated after the scale is measured, whose grid is given back first.
static inline void allocate_parting(PartingMemory& m, size_t count, Arena& arena) {
    m.items = arena.alloc<GridItem>(count);
    m.spare = arena.alloc<GridItem>(count);
    m.position = arena.alloc<Local>(count);
    m.steps.step_start = arena.alloc<uint32_t>(count + 2);
    m.steps.by_step = arena.alloc<uint32_t>(count);
    m.sweep.added = arena.alloc<uint32_t>(count);
    m.sweep.order_of = arena.alloc<uint32_t>(count);
    m.sweep.parent = arena.alloc<uint32_t>(count);
    m.sweep.size = arena.alloc<uint32_t>(count);
    m.sweep.lowest = arena.alloc<double>(count);
    m.sweep.highest = arena.alloc<double>(count);
    m.sweep.blocks = arena.alloc<CachedBlock>(kBlockCacheSize);
    m.sweep.listed = arena.alloc<uint32_t>(count);
    m.sweep.is_listed = arena.alloc<unsigned char>(count);
}

// The valid points in the frame, in cells of side `side` sorted by height, then across;
// returns their count. `low` is their lowest frame coordinates.
static inline size_t grid_in_frame(const CloudReader& reader, size_t count, const Frame& frame,
                            Local low, double side, PartingMemory& m) {
    size_t n = 0;
    uint64_t any = 0, every = ~uint64_t{0};
    for (size_t i = 0; i < count; ++i) {
        if (!reader.valid(i)) continue;
        const Local l = frame.local(reader.point(i));
        const uint64_t cell = cell_key(cell_coordinate(l.h - low.h, side),
                                       cell_coordinate(l.x - low.x, side),
                                       cell_coordinate(l.y - low.y, side));
        m.items[n++] = {cell, static_cast<uint32_t>(i)};
        any |= cell;
        every &= cell;
    }
    sort_items(m.items, m.spare, n, any, every);
    for (size_t j = 0; j < n; ++j) m.position[j] = frame.local(reader.point(m.items[j].index));
    return n;
}

// The steps of the n points in grid order (a counting sort), every half gap from lo to hi,
// fewer where that would make more steps than points.
static inline void split_into_steps(const Local* position, size_t n, double lo, double hi, double gap,
                             PartingSteps& p) {
    const double most = static_cast<double>(n);
    double steps = std::ceil((hi - lo) / (gap / kStepsPerGap));
    if (!(steps <= most)) steps = most;
    if (steps < 1) steps = 1;
    p.steps = static_cast<uint32_t>(steps);
    p.lo = lo;
    p.step_height = (hi - lo) / steps;
    std::memset(p.step_start, 0, sizeof(uint32_t) * (p.steps + 2));
    auto step_of = [&](double h) {
        const double k = std::floor((h - lo) / p.step_height);
        return k < 0 ? 0u : k >= steps ? p.steps - 1 : static_cast<uint32_t>(k);
    };
    for (size_t j = 0; j < n; ++j) ++p.step_start[step_of(position[j].h) + 2];
    for (uint32_t k = 0; k < p.steps; ++k) p.step_start[k + 2] += p.step_start[k + 1];
    for (size_t j = 0; j < n; ++j)
        p.by_step[p.step_start[step_of(position[j].h) + 1]++] = static_cast<uint32_t>(j);
}

// The median distance from a point to its nearest distinct neighbour, on every k-th point
// in cell order, at most kScaleSample of them; 0 where more than half find none. The
// cells are those of side `decile` (nearest_spacing's), within which nine points in ten
// find theirs; a point looks at kNearestCandidates points at most, its own cell first.
// Exact where nearest_spacing is not: that one is rounded up to a half-octave, too coarse
// for a threshold that tells a notch from a gap.
static inline double median_nearest_distance(const CloudReader& reader, size_t count, const CloudBox& box,
                                      double decile, CellScratch& g, GridItem* sample,
                                      GridItem* sample_spare) {
    const size_t n = sort_into_cells(reader, count, box.low, decile, g);
    const GridItem* items = g.items;
    for (size_t i = 0; i < n; ++i) g.sorted[i] = reader.point(items[i].index);
    const uint32_t step = sample_step(n, kScaleSample / 2);
    size_t sampled = 0;
    uint64_t any = 0, every = ~uint64_t{0};
    for (size_t i = 0; i < n && sampled < kScaleSample; ++i) {
        const Vec3 p = g.sorted[i];
        if (!sampled_point(p, step)) continue;
        const CellBlock block = block_around(items, n, i);
        double nearest = DBL_MAX;
        uint32_t seen = 0;
        for (uint32_t k = 0; k < block.count && seen < kNearestCandidates; ++k)
            for (size_t j = block.begin[k]; j < block.end[k] && seen < kNearestCandidates; ++j) {
                const Vec3 d = g.sorted[j] - p;
                const double q = dot(d, d);
                ++seen;
                if (q > 0 && q < nearest) nearest = q;
            }
        uint64_t key = 0;  // a positive double's bits sort as the double does
        std::memcpy(&key, &nearest, sizeof key);
        sample[sampled++] = {key, 0};
        any |= key;
        every &= key;
    }
    sort_items(sample, sample_spare, sampled, any, every);
    double median = DBL_MAX;
    if (sampled > 0) std::memcpy(&median, &sample[sampled / 2].cell, sizeof median);
    return median < DBL_MAX ? std::sqrt(median) : 0;
}

static inline Status out_of_workspace(Report& rep) {
    rep.detail = "the workspace is smaller than find_parting_workspace_size()";
    return Status::out_of_memory;
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {
namespace detail {

static inline size_t parting_workspace_size(size_t point_count, const TubeRequest& request) {
    if (point_count > kMaxPoints - 1) return 0;
    Arena arena = Arena::measuring();
    if (request.drop_outliers) arena.alloc<unsigned char>(point_count / 8 + 1);
    const size_t mark = arena.mark();
    allocate_cell_scratch(arena, point_count);  // the outliers' and the scale's grid
    arena.alloc<GridItem>(2 * kScaleSample);
    arena.rewind(mark);
    // Axis::automatic is resolved first, as reconstruct() resolves it.
    arena.alloc<unsigned char>(axis_workspace_size(point_count, request));
    arena.rewind(mark);
    PartingMemory m;
    allocate_parting(m, point_count, arena);
    return arena.failed ? 0 : arena.required_bytes();
}

// find_parting() along the axis of `request` (its origin, outliers and invalid points as
// it says) with the fewest points a branch holds given: a sample of the cloud is searched
// with fewer (see search_parting).
static inline Status find_parting_with(const Cloud& cloud, const TubeRequest& request, void* workspace,
                                size_t workspace_bytes, Parting* parting, uint8_t* branch_of,
                                uint32_t smallest) {
    if (!parting) return Status::invalid_argument;
    // Checked before anything is written (a count beyond the limit is refused below).
    const bool countable = cloud.count <= kMaxPoints - 1;
    const ByteRange buffers[] = {countable ? cloud_bytes(cloud) : ByteRange{0, 0},
                                 byte_range(workspace, workspace_bytes),
                                 byte_range(parting, sizeof *parting),
                                 byte_range(branch_of, countable ? cloud.count : 0)};
    if (any_overlap(buffers, 4)) return Status::invalid_argument;
    std::memset(parting, 0, sizeof *parting);
    Report rep = {};
    size_t no_triangles = 0;
    Arena arena = Arena::over(workspace, workspace_bytes);
    auto finish = [&](Status status) {
        parting->workspace_used_bytes = arena.peak_from_buffer();
        parting->detail = rep.detail;
        return status;
    };
    Status status = check_reconstruct_arguments(cloud, nullptr, 0, &no_triangles, workspace, rep);
    if (status != Status::ok) return finish(status);
    // The caller's Options, for find_parting() (reconstruct() has checked its own).
    rep.detail = request.caller ? options_refusal(*request.caller) : nullptr;
    if (rep.detail) return finish(Status::invalid_argument);
    if (branch_of) std::memset(branch_of, kInTrunk, cloud.count);
    CloudReader reader = reader_of(cloud);
    CloudSums sums = sum_cloud(reader, cloud.count);
    status = reject_invalid_points(reader, cloud.count, sums, *request.caller, rep);
    if (status != Status::ok) return finish(status);
    if (request.drop_outliers) {
        if (!find_outliers(reader, cloud.count, arena, rep)) return finish(out_of_workspace(rep));
        sums = sum_cloud(reader, cloud.count);
    }
    const TubeInput in = {reader, cloud.count, sums};
    TubeRequest along = request;
    status = resolve_axis(in, arena, along, &rep.detail);
    if (status != Status::ok) return finish(status);
    Frame frame;
    status = choose_frame(sums, along, frame);
    if (status != Status::ok) return finish(status);
    parting->axis[0] = frame.axis.x;
    parting->axis[1] = frame.axis.y;
    parting->axis[2] = frame.axis.z;
    if (sums.distinct < 3) {
        rep.detail = "fewer than 3 distinct valid points";
        return finish(Status::too_few_points);
    }
    const size_t mark = arena.mark();
    CellScratch scale_grid = allocate_cell_scratch(arena, cloud.count);
    if (arena.failed) return finish(out_of_workspace(rep));
    GridItem* sample = arena.alloc<GridItem>(2 * kScaleSample);
    if (arena.failed) return finish(out_of_workspace(rep));
    const CloudBox box = box_of(reader, cloud.count);
    const double decile = nearest_spacing(reader, cloud.count, box, scale_grid, kScaleSample);
    const double spacing = decile > 0 ? median_nearest_distance(reader, cloud.count, box, decile,
                                                                scale_grid, sample,
                                                                sample + kScaleSample)
                                      : 0;
    arena.rewind(mark);
    PartingMemory m;
    allocate_parting(m, cloud.count, arena);
    if (arena.failed) return finish(out_of_workspace(rep));
    Local low = {DBL_MAX, DBL_MAX, DBL_MAX}, high = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t i = 0; i < cloud.count; ++i) {
        if (!reader.valid(i)) continue;
        const Local l = frame.local(reader.point(i));
        low = {l.x < low.x ? l.x : low.x, l.y < low.y ? l.y : low.y, l.h < low.h ? l.h : low.h};
        high = {l.x > high.x ? l.x : high.x, l.y > high.y ? l.y : high.y, l.h > high.h ? l.h : high.h};
    }
    if (!(high.h > low.h)) {
        rep.detail = "every point has the same height along the axis";
        return finish(Status::flat_cloud);
    }
    const double gap = kPartingGap * spacing;
    if (!(gap > 0) || !is_finite(gap * frame.scale)) {
        rep.detail = "the cloud has no scale (too many of its points have no distinct "
                     "neighbour near them: repeats, scattered points): no parting is reported";
        return finish(Status::ok);
    }
    parting->gap = gap;
    PartingSweep& s = m.sweep;
    s.crowded = false;
    s.smallest = smallest;
    s.gap = gap * frame.scale;
    s.count = grid_in_frame(reader, cloud.count, frame, low, s.gap, m);
    s.cells = m.items;
    s.position = m.position;
    split_into_steps(m.position, s.count, low.h, high.h, s.gap, m.steps);
    const SideParting above = sweep_for_parting(s, m.steps, true, 0);
    const SideParting below = sweep_for_parting(s, m.steps, false, 0);
    auto report_side = [&](const SideParting& side, double* cut, uint32_t* branches,
                           uint32_t* points) {
        *branches = side.branches;
        if (side.branches) *cut = frame.user_height(m.steps.lo + side.cut_index * m.steps.step_height);
        for (uint32_t k = 0; k < side.branches; ++k) points[k] = side.sizes[k];
    };
    report_side(above, &parting->above, &parting->above_branch_count, parting->above_point_counts);
    report_side(below, &parting->below, &parting->below_branch_count, parting->below_point_counts);
    if (s.crowded) {
        parting->above_branch_count = parting->below_branch_count = 0;
        parting->above = 0;
        rep.detail = "the cloud is too crowded to search (over 1024 points within a gap of "
                     "each, on average: repeated or solid): no parting is reported";
        return finish(Status::ok);
    }
    if (branch_of && above.branches)
        label_branches(s, m.steps, true, above.cut_index, kFirstAboveBranch, branch_of);
    if (branch_of && below.branches)
        label_branches(s, m.steps, false, below.cut_index, kFirstBelowBranch, branch_of);
    return finish(Status::ok);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

size_t find_parting_workspace_size(size_t point_count, const Options& options) {
    return detail::parting_workspace_size(point_count, detail::tube_request(options));
}

Status find_parting(const Cloud& cloud, const Options& options, void* workspace,
                    size_t workspace_bytes, Parting* parting, uint8_t* branch_of) {
    return detail::find_parting_with(cloud, detail::tube_request(options), workspace,
                                     workspace_bytes, parting, branch_of, kSmallestBranch);
}

}  // namespace stratmesh

#endif  // STRATMESH_SMALL_CODE

// >>join branches ========================================================================
// join_branches(): zips and grafts.
//
// join_branches(): the boundary loops of the caller's surface are traced as the caps trace
// them (build_cap_graph, trace_boundary_loops: each loop in cap order, the boundary
// reversed), each side that parts is planned (its loops chosen, the trunk's loop split at
// the gaps), the triangles counted, then written. A side is seen turned half a turn about
// e1 when it is the side below, so that on both its branches lie above its cut and the
// trunk's loop in cap order runs the way the branches' boundary runs: each band is then
// the same zipper, whose triangles (a, a', b) and (a, b', b) run the trunk's loop in cap
// order and the branch's loop against its boundary.

#if !defined(STRATMESH_SMALL_CODE)
namespace stratmesh {
namespace detail {

// The most trunk triangles a graft looks at under one branch's loop (see plan_graft): its
// arrays are sized for them, not for the whole surface.
const size_t kGraftMaxTriangles = size_t{1} << 16;

// The small gaps in the trunk's end a graft may close (see plan_graft): at most
// kMostGapCorners vertices each, within kGapReach times the branch loop's reach of its
// centre, at most one a graft, so at most kMostGapTriangles triangles in all.
const double kGapReach = 1.5;

// A directed edge of a triangle under a branch's loop, and which of them it belongs to.
struct GraftEdge {
    uint32_t from, to, slot;
    bool operator<(const GraftEdge& o) const { return from != o.from ? from < o.from : to < o.to; }
    bool operator>(const GraftEdge& o) const { return o < *this; }
};

struct JoinMemory {
    CapLoop loops;  // only ids and starts
    uint32_t* gap_joins;  // per entry of loops.ids on a loop of at most kMostGapCorners: bit j
                          // set where its vertex and the loop's j-th are joined by an edge of
                          // the caller's surface (the diagonals a gap fill may not make)
    CapGraph graph;  // until the loops are traced; the grafts' arrays then take its memory
    uint32_t* hole_next;     // per point: its successor on a planned hole, kNoIndex if free,
                             // kHeldVertex where no hole may pass (the trunk's boundary)
    uint32_t* holes;         // the planned holes' loops, one after another
    unsigned char* removed;  // per triangle, the caller's then the filled: 1 where a
                             // planned hole takes it out
    uint32_t* filled;        // the triangles that closed gaps in the trunk's end, 3 each
    size_t filled_count;
    uint32_t* under;         // the triangles under the branch's loop being grafted
    GraftEdge* edges;        // 3 per triangle of `under`, sorted
    uint64_t* queue;         // hole edges to grow across, (from << 32) | to
    size_t under_capacity;
    size_t room;  // the arena's mark after the loops
};

const uint32_t kHeldVertex = kNoIndex - 1;

// The arena sequence of the call, shared with join_branches_workspace_size(): the loops,
// then the graph after them, then (allocate_grafts) once the loops are traced and the gaps'
// joins noted, the grafts' arrays in the graph's room.
static inline bool allocate_join(JoinMemory& m, size_t point_count, size_t triangle_count, Arena& arena) {
    m.loops.ids = arena.alloc<uint32_t>(point_count);  // every point on a loop at most
    m.loops.starts = arena.alloc<unsigned char>(point_count);
    m.gap_joins = arena.alloc<uint32_t>(point_count);
    m.room = arena.mark();
    allocate_cap_graph(m.graph, point_count, triangle_count, arena);
    return !arena.failed;
}

static inline bool allocate_grafts(JoinMemory& m, size_t point_count, size_t triangle_count, Arena& arena) {
    arena.rewind(m.room);
    m.under_capacity = triangle_count < kGraftMaxTriangles ? triangle_count : kGraftMaxTriangles;
    m.hole_next = arena.alloc<uint32_t>(point_count);
    m.holes = arena.alloc<uint32_t>(point_count);
    m.removed = arena.alloc<unsigned char>(triangle_count + kMostGapTriangles);
    m.filled = arena.alloc<uint32_t>(3 * kMostGapTriangles);
    m.filled_count = 0;
    m.under = arena.alloc<uint32_t>(m.under_capacity);
    m.edges = arena.alloc<GraftEdge>(3 * m.under_capacity);
    m.queue = arena.alloc<uint64_t>(2 * m.under_capacity + 3);
    return !arena.failed;
}

// A traced loop: its entries in CapLoop::ids, in cap order.
struct TracedLoop {
    const uint32_t* ids;
    uint32_t length;
};

// One side's junction: the trunk's loop, the branches' loops in their order around the
// trunk's centre, where each branch's loop opens (a position in cap order) and the trunk's
// vertex at the gap after each branch (a position on the trunk's loop).
struct SideJunction {
    TracedLoop trunk;
    uint32_t branches;
    TracedLoop branch[kMaxBranches];
    uint32_t opening[kMaxBranches];
    uint32_t gap[kMaxBranches];
    double centre[kMaxBranches][2];  // of each branch's loop, across the axis
    double sense;                    // +1 where the trunk's loop turns counter-clockwise

    size_t triangles() const {
        size_t total = trunk.length + 2 * static_cast<size_t>(branches) - 2;
        for (uint32_t i = 0; i < branches; ++i) total += branch[i].length;
        return total;
    }
};

// Frame coordinates of one side: the side below turned half a turn about e1.
struct SideView {
    const CloudReader& reader;
    const Frame& frame;
    double sign;  // +1 above, -1 below

    Local at(uint32_t id) const {
        const Local l = frame.local(reader.point(id));
        return {l.x, sign * l.y, sign * l.h};
    }
};

static inline double loop_mean_height(const TracedLoop& loop, const SideView& view) {
    double sum = 0;
    for (uint32_t i = 0; i < loop.length; ++i) sum += view.at(loop.ids[i]).h;
    return sum / loop.length;
}

// The label every point of the loop has, or kBeyondBranches where they differ.
static inline uint8_t loop_label(const TracedLoop& loop, const uint8_t* branch_of) {
    const uint8_t label = branch_of[loop.ids[0]];
    for (uint32_t i = 1; i < loop.length; ++i)
        if (branch_of[loop.ids[i]] != label) return kBeyondBranches;
    return label;
}

const double kJoinReach = 4;

// The loops a side's junction starts from: the trunk's highest (its points all kInTrunk;
// not `taken`, the trunk loop the other side joined) and each branch's lowest (ids null
// where a branch has none), with their mean heights in the view.
struct SideLoops {
    TracedLoop trunk;
    double trunk_height;
    TracedLoop branch[kMaxBranches];
    double branch_height[kMaxBranches];
};

static inline void find_side_loops(const CapLoop& loops, size_t entries, const uint8_t* branch_of,
                            uint8_t first_label, uint32_t branches, const SideView& view,
                            const uint32_t* taken, SideLoops& side) {
    side.trunk = {nullptr, 0};
    side.trunk_height = -DBL_MAX;
    for (uint32_t b = 0; b < branches; ++b) side.branch[b] = {nullptr, 0};
    for (size_t start = 0; start < entries;) {
        size_t end = start + 1;
        while (end < entries && loops.starts[end] == 0) ++end;
        const TracedLoop loop = {loops.ids + start, static_cast<uint32_t>(end - start)};
        const bool closed = loops.starts[start] == kLoopStart;
        start = end;
        if (!closed || loop.ids == taken) continue;
        const uint8_t label = loop_label(loop, branch_of);
        const double height = loop_mean_height(loop, view);
        if (label == kInTrunk) {
            if (height > side.trunk_height) {
                side.trunk_height = height;
                side.trunk = loop;
            }
        } else if (label >= first_label && label - first_label < static_cast<int>(branches)) {
            const uint32_t b = static_cast<uint32_t>(label - first_label);
            if (!side.branch[b].ids || height < side.branch_height[b]) {
                side.branch[b] = loop;
                side.branch_height[b] = height;
            }
        }
    }
}

// The trunk's loop seen across the axis: its centre, its mean radius, and the sense it
// turns in (+1 counter-clockwise).
struct TrunkCentre {
    double cx, cy, radius, sense;

    double angle(double x, double y) const { return std::atan2(sense * (y - cy), x - cx); }
};

static inline TrunkCentre trunk_centre(const TracedLoop& trunk, const SideView& view) {
    double cx = 0, cy = 0, area = 0;
    for (uint32_t i = 0; i < trunk.length; ++i) {
        const Local p = view.at(trunk.ids[i]);
        const Local q = view.at(trunk.ids[(i + 1) % trunk.length]);
        cx += p.x;
        cy += p.y;
        area += p.x * q.y - q.x * p.y;
    }
    cx /= trunk.length;
    cy /= trunk.length;
    double radius = 0;
    for (uint32_t i = 0; i < trunk.length; ++i) {
        const Local p = view.at(trunk.ids[i]);
        radius += std::sqrt((p.x - cx) * (p.x - cx) + (p.y - cy) * (p.y - cy));
    }
    radius /= trunk.length;
    return {cx, cy, radius, area < 0 ? -1.0 : 1.0};
}

// Adds the branch's loop to the side's, in the order of their angles around the trunk's
// centre (kept in branch_angle): its centre, and where it opens, its vertex nearest the
// trunk's centre. False (detail set) where its centre is not within the trunk's loop.
static inline bool add_rim_branch(const TracedLoop& loop, const SideView& view,
                           const TrunkCentre& trunk, SideJunction& side, double* branch_angle,
                           const char*& detail) {
    double bx = 0, by = 0, nearest = DBL_MAX;
    uint32_t opening = 0;
    for (uint32_t i = 0; i < loop.length; ++i) {
        const Local p = view.at(loop.ids[i]);
        bx += p.x;
        by += p.y;
        const double d = (p.x - trunk.cx) * (p.x - trunk.cx) + (p.y - trunk.cy) * (p.y - trunk.cy);
        if (d < nearest) {
            nearest = d;
            opening = i;
        }
    }
    bx /= loop.length;
    by /= loop.length;
    if ((bx - trunk.cx) * (bx - trunk.cx) + (by - trunk.cy) * (by - trunk.cy) >=
        trunk.radius * trunk.radius) {
        detail = "a branch's loop is not within the trunk's loop nearest it, across the axis "
                 "(a branch standing on a closed end, not on a rim around the branches)";
        return false;
    }
    const double a = trunk.angle(bx, by);
    uint32_t k = side.branches++;
    for (; k > 0 && branch_angle[k - 1] > a; --k) {
        branch_angle[k] = branch_angle[k - 1];
        side.branch[k] = side.branch[k - 1];
        side.opening[k] = side.opening[k - 1];
        side.centre[k][0] = side.centre[k - 1][0];
        side.centre[k][1] = side.centre[k - 1][1];
    }
    branch_angle[k] = a;
    side.branch[k] = loop;
    side.opening[k] = opening;
    side.centre[k][0] = bx;
    side.centre[k][1] = by;
    return true;
}

// The gap after each branch i: the trunk's vertex nearest in angle to the middle between
// branch i and the next one. False (detail set) where the gaps do not follow one another
// along the trunk's loop as the branches do.
static inline bool place_rim_gaps(const SideView& view, const TrunkCentre& centre,
                           const double* branch_angle, SideJunction& side, const char*& detail) {
    const TracedLoop& trunk = side.trunk;
    const double two_pi = 6.28318530717958647693;
    for (uint32_t i = 0; i < side.branches; ++i) {
        const uint32_t next = (i + 1) % side.branches;
        double span = branch_angle[next] - branch_angle[i];
        if (span <= 0) span += two_pi;
        const double middle = branch_angle[i] + span / 2;
        double nearest = DBL_MAX;
        for (uint32_t j = 0; j < trunk.length; ++j) {
            const Local p = view.at(trunk.ids[j]);
            const double off = std::fabs(std::remainder(centre.angle(p.x, p.y) - middle, two_pi));
            if (off < nearest) {
                nearest = off;
                side.gap[i] = j;
            }
        }
    }
    const uint32_t last = side.gap[side.branches - 1];
    uint32_t before = 0;
    for (uint32_t i = 0; i + 1 < side.branches; ++i) {
        const uint32_t along = (side.gap[i] + trunk.length - last) % trunk.length;
        if (along <= before) {
            detail = "the trunk's loop does not go around a side's branches in their order";
            return false;
        }
        before = along;
    }
    return true;
}

// Plans the rim junction of a side with `branches` branches, from its loops, with its cut
// and gap as heights of the view: false (detail set) if it cannot be joined so.
static inline bool plan_junction(const SideLoops& loops, uint32_t branches, double cut, double gap,
                          const SideView& view, SideJunction& side, const char*& detail) {
    side.trunk = loops.trunk;
    // Loops farther than kJoinReach gaps from the cut are not the junction's: a trunk
    // closed at the cut keeps only its far loop, a branch closed there only its tip's.
    auto near_cut = [&](double height) { return std::fabs(height - cut) <= kJoinReach * gap; };
    if (!side.trunk.ids || !near_cut(loops.trunk_height)) {
        detail = "the trunk has no boundary loop near the cut to join a side's branches to "
                 "(a trunk closed there: the branches stand on a closed end)";
        return false;
    }
    const TrunkCentre centre = trunk_centre(side.trunk, view);
    side.sense = centre.sense;
    double branch_angle[kMaxBranches];
    side.branches = 0;
    for (uint32_t b = 0; b < branches; ++b) {
        if (!loops.branch[b].ids || !near_cut(loops.branch_height[b])) continue;
        if (!add_rim_branch(loops.branch[b], view, centre, side, branch_angle, detail))
            return false;
    }
    if (side.branches < 2) {
        detail = "fewer than two of a side's branches have a boundary loop of their own";
        return false;
    }
    return place_rim_gaps(view, centre, branch_angle, side, detail);
}

// Angles around a centre across the axis, from the direction of a reference point, in
// [0, 2 pi), counter-clockwise where sense is +1.
struct AngleAround {
    const SideView& view;
    double cx, cy;
    Local reference;
    double sense;

    double operator()(uint32_t id) const {
        const Local q = view.at(id);
        const double rx = reference.x - cx, ry = reference.y - cy;
        const double dx = q.x - cx, dy = q.y - cy;
        const double t = std::atan2(sense * (rx * dy - ry * dx), rx * dx + ry * dy);
        return t < 0 ? t + 6.28318530717958647693 : t;
    }
};

// Writes the junction's side.triangles() triangles at out.
static inline void write_junction(const SideJunction& side, const SideView& view, uint32_t* out) {
    const TracedLoop& trunk = side.trunk;
    auto emit = [&out](uint32_t a, uint32_t b, uint32_t c) {
        out[0] = a;
        out[1] = b;
        out[2] = c;
        out += 3;
    };
    auto opening_point = [&](uint32_t i) { return side.branch[i].ids[side.opening[i]]; };
    for (uint32_t i = 0; i < side.branches; ++i) {
        // The trunk's arc from the gap before branch i to the gap after it, in cap order;
        // the branch's loop from its opening round to it again, against its cap order.
        const uint32_t from = side.gap[(i + side.branches - 1) % side.branches];
        const uint32_t steps = (side.gap[i] + trunk.length - from) % trunk.length;
        const TracedLoop& loop = side.branch[i];
        const uint32_t n = loop.length;
        auto a = [&](uint32_t j) { return trunk.ids[(from + j) % trunk.length]; };
        auto b = [&](uint32_t l) { return loop.ids[(side.opening[i] + n - l % n) % n]; };
        // Both chains in the order of their angle around the branch's centre, from the
        // opening on: a zipper by angle lays a band between two curves that go once around
        // a point in triangles that do not overlap, where shortest diagonals can fold.
        const AngleAround turn = {view, side.centre[i][0], side.centre[i][1], view.at(b(0)),
                                  side.sense};
        emit(a(0), b(1), b(0));
        uint32_t j = 0, l = 1;
        while (j < steps || l + 1 < n) {
            const bool along_trunk = l + 1 == n || (j < steps && turn(a(j + 1)) <= turn(b(l + 1)));
            if (along_trunk) {
                emit(a(j), a(j + 1), b(l));
                ++j;
            } else {
                emit(a(j), b(l + 1), b(l));
                ++l;
            }
        }
        emit(a(steps), b(n), b(n - 1));
    }
    // The crotch: a triangle per gap, and a fan over the openings where three or more meet.
    for (uint32_t i = 0; i < side.branches; ++i)
        emit(opening_point(i), trunk.ids[side.gap[i]], opening_point((i + 1) % side.branches));
    for (uint32_t i = 1; i + 1 < side.branches; ++i)
        emit(opening_point(0), opening_point(i), opening_point(i + 1));
}

// ---- grafts ----
//
// A branch standing on a closed end of the trunk (horns on a skull) has no trunk loop
// around it: the trunk's mesh runs over the stump under the branch's loop instead. It is
// grafted: the trunk's triangles under the loop that face the branch are taken out as a
// disc (grown from the one nearest the loop's centre across the edges they share, each
// triangle added bringing a vertex new to the disc, so every vertex keeps a triangle of
// the trunk and the hole's loop is simple), and the hole's loop is zipped to the branch's
// by angle around the branch's centre, as the rim junction zips its arcs. "Under" is seen
// along the axis: the triangle's centroid inside the branch's loop and at most kJoinReach
// gaps below its mean height, its normal within acos(kGraftFacing) of the axis; the hole
// never reaches a vertex of the trunk's boundary nor one of another hole, so the surface
// stays an oriented edge- and vertex-manifold. The trunk's end under a fork is meshed
// across its open top (the pole projection of a closed end), with long triangles and at
// times a small gap; where a gap's vertex is a corner of the triangle under the branch's
// centre, the disc cannot cover the centre. Then the gap is closed (fill_gap) and the
// hole planned again: of 216 axes tilted 0.1 to 15 degrees every way from the trunk of
// the tests' Y, 15 fell back to one tube that way before, none since. Refused (the
// branch left apart) where no such triangle is free, where more than kGraftMaxTriangles
// are under the loop, or where the hole or the branch's loop does not go once around the
// branch's centre in the sense a junction's do.

const double kGraftFacing = 0.25;

struct Graft {
    TracedLoop hole;    // in the direction of the triangles it replaces (in JoinMemory::holes)
    TracedLoop branch;  // in cap order
    double centre[2];
    double side;        // the view's sign: +1 above the cut, -1 below
    size_t removed;     // the trunk's triangles the hole takes out

    size_t triangles() const { return static_cast<size_t>(hole.length) + branch.length; }
};

// How many times the loop winds around (x, y) across the axis, counter-clockwise positive.
static inline long loop_winding(const TracedLoop& loop, const SideView& view, double x, double y) {
    const double p[2] = {x, y};
    auto corner = [&](uint32_t i) {
        const Local q = view.at(loop.ids[i]);
        return Point2{{q.x, q.y}};
    };
    return winding_number(corner, loop.length, p);
}

// The trunk's triangles a graft reads: the caller's, `count` of them, then those that
// closed small gaps in the trunk's end (m.filled, see fill_gap).
static inline const uint32_t* trunk_corners(const uint32_t* tri, size_t count, const JoinMemory& m,
                                     size_t t) {
    return t < count ? tri + 3 * t : m.filled + 3 * (t - count);
}

// The first of the sorted edges m.edges[0 .. 3 * found) not below key.
static inline size_t first_edge_from(const JoinMemory& m, size_t found, const GraftEdge& key) {
    size_t lo = 0, hi = 3 * found;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (m.edges[mid] < key) lo = mid + 1; else hi = mid;
    }
    return lo;
}

// Grows a hole from its edges queued in m.queue[0 .. queued) (from << 32 | to, with
// m.hole_next[from] == to) across the triangles m.under[0 .. found) (their edges sorted in
// m.edges): a triangle (x, y, z) beyond the hole's edge y -> x joins when z is free, and the
// loop then runs y -> z -> x, so every vertex stays on the loop and keeps a triangle of the
// trunk. Returns the triangles taken (marked in m.removed).
static inline size_t grow_hole(const uint32_t* tri, size_t count, JoinMemory& m, size_t found,
                        size_t queued) {
    uint32_t* next = m.hole_next;
    size_t taken = 0;
    for (size_t head = 0; head < queued; ++head) {
        const uint32_t y = static_cast<uint32_t>(m.queue[head] >> 32);
        const uint32_t x = static_cast<uint32_t>(m.queue[head]);
        if (next[y] != x) continue;
        for (size_t lo = first_edge_from(m, found, {x, y, 0}); lo < 3 * found && m.edges[lo].from == x && m.edges[lo].to == y; ++lo) {
            const uint32_t t = m.under[m.edges[lo].slot];
            const uint32_t* c = trunk_corners(tri, count, m, t);
            const uint32_t z = c[0] ^ c[1] ^ c[2] ^ x ^ y;
            if (m.removed[t] || next[z] != kNoIndex) continue;
            next[y] = z;
            next[z] = x;
            m.removed[t] = 1;
            ++taken;
            m.queue[queued++] = (uint64_t{y} << 32) | z;
            m.queue[queued++] = (uint64_t{z} << 32) | x;
            break;
        }
    }
    return taken;
}

// Whether vertex v is a corner of one of m.under[0 .. found), whose edges m.edges holds sorted.
static inline bool corner_under(const JoinMemory& m, size_t found, uint32_t v) {
    const size_t lo = first_edge_from(m, found, {v, 0, 0});
    return lo < 3 * found && m.edges[lo].from == v;
}

// A small gap in the trunk's end beside a branch's stump: a closed boundary loop of the
// trunk of at most kMostGapCorners vertices, each held by no hole, within `reach` of (cx, cy)
// across the axis and within [low, high] along it, one of them a corner of a triangle
// under the branch; the one nearest (cx, cy), {nullptr, 0} if none.
static inline TracedLoop gap_beside(const JoinMemory& m, size_t entries, size_t found,
                             const uint8_t* branch_of, const SideView& view, double cx,
                             double cy, double reach, double low, double high) {
    TracedLoop best = {nullptr, 0};
    double nearest = DBL_MAX;
    for (size_t start = 0; start < entries;) {
        size_t end = start + 1;
        while (end < entries && m.loops.starts[end] == 0) ++end;
        const TracedLoop loop = {m.loops.ids + start, static_cast<uint32_t>(end - start)};
        const bool closed = m.loops.starts[start] == kLoopStart;
        start = end;
        if (!closed || loop.length < 3 || loop.length > kMostGapCorners) continue;
        bool near = true, touches = false;
        double x = 0, y = 0;
        for (uint32_t i = 0; i < loop.length && near; ++i) {
            const uint32_t v = loop.ids[i];
            const Local p = view.at(v);
            near = branch_of[v] == kInTrunk && m.hole_next[v] == kHeldVertex && p.h >= low &&
                   p.h <= high && (p.x - cx) * (p.x - cx) + (p.y - cy) * (p.y - cy) <= reach * reach;
            touches = touches || corner_under(m, found, v);
            x += p.x / loop.length;
            y += p.y / loop.length;
        }
        const double d = (x - cx) * (x - cx) + (y - cy) * (y - cy);
        if (near && touches && d < nearest) {
            nearest = d;
            best = loop;
        }
    }
    return best;
}

static_assert(kMostGapCorners <= 32, "a gap's joins are bits of 32");

// Notes in m.gap_joins, from the graph, which vertices of each loop small enough to be a
// gap are joined by an edge of the caller's surface: the graph keeps the edges between
// boundary vertices, and its memory goes to the grafts.
static inline void note_gap_joins(JoinMemory& m, size_t entries) {
    for (size_t start = 0; start < entries;) {
        size_t end = start + 1;
        while (end < entries && m.loops.starts[end] == 0) ++end;
        const uint32_t* ids = m.loops.ids + start;
        for (size_t i = 0; end - start <= kMostGapCorners && i < end - start; ++i) {
            uint32_t joins = 0;
            for (size_t j = 0; j < end - start; ++j)
                if (m.graph.has_edge(ids[i], ids[j])) joins |= uint32_t{1} << j;
            m.gap_joins[start + i] = joins;
        }
        start = end;
    }
}

// A gap's ears: no diagonal that is an edge of the caller's surface (see note_gap_joins);
// each ear a triangle of m.filled.
class GapEars final : public EarRules {
public:
    GapEars(const uint32_t* ids, const uint32_t* joins, JoinMemory& m)
        : ids_(ids), joins_(joins), m_(m) {}

private:
    bool forbidden(uint32_t a, uint32_t b) const override { return ((joins_[a] >> b) & 1) != 0; }

    void take(uint32_t p, uint32_t v, uint32_t n) override {
        uint32_t* out = m_.filled + 3 * m_.filled_count++;
        out[0] = ids_[p];
        out[1] = ids_[v];
        out[2] = ids_[n];
    }

    const uint32_t* ids_;
    const uint32_t* joins_;
    JoinMemory& m_;
};

// Closes the gap `loop` (in cap order) with triangles in m.filled, by ears clipped in the
// view, each from the first corner left, and frees its vertices for the holes; false
// (nothing added) where the loop is no simple polygon turning counter-clockwise in the view
// (the way the triangles facing a branch turn) or no ear is left whose diagonal is not an
// edge of the surface. count: the caller's triangles, which m.removed numbers first.
static inline bool fill_gap(size_t count, const TracedLoop& loop, const SideView& view, JoinMemory& m) {
    const uint32_t n = loop.length;
    if (m.filled_count + (n - 2) > kMostGapTriangles) return false;
    double xy[2 * kMostGapCorners] = {};
    for (uint32_t i = 0; i < n; ++i) {
        const Local p = view.at(loop.ids[i]);
        xy[2 * i] = p.x;
        xy[2 * i + 1] = p.y;
    }
    uint64_t sweep[kMostGapCorners];
    if (!polygon_is_simple(xy, n, sweep) || !(simple_polygon_turn(xy, n) > 0)) return false;
    uint32_t prev[kMostGapCorners], next[kMostGapCorners], reflex[kMostGapCorners];
    unsigned char flags[kMostGapCorners];
    const size_t first = m.filled_count;
    GapEars ears(loop.ids, m.gap_joins + (loop.ids - m.loops.ids), m);
    EarClipper clipper(xy, n, {prev, next, reflex, flags});
    if (!clipper.clip(0, EarWalk::from_first, ears)) {
        m.filled_count = first;
        return false;
    }
    for (size_t f = first; f < m.filled_count; ++f) m.removed[count + f] = 0;
    for (uint32_t i = 0; i < n; ++i) m.hole_next[loop.ids[i]] = kNoIndex;
    return true;
}

// Where a branch's loop stands in the view: its centre across the axis, the square of its
// reach from there, and the heights a trunk triangle's centroid under it may have.
struct GraftSite {
    double cx, cy, reach, low, high;
};

// The site of the branch's loop, within kJoinReach gaps below its mean height and one gap
// above; false (detail set) where the loop does not go once around its centre.
static inline bool graft_site(const TracedLoop& loop, double gap, const SideView& view,
                       GraftSite& site, const char*& detail) {
    double cx = 0, cy = 0, height = 0;
    for (uint32_t i = 0; i < loop.length; ++i) {
        const Local p = view.at(loop.ids[i]);
        cx += p.x;
        cy += p.y;
        height += p.h;
    }
    cx /= loop.length;
    cy /= loop.length;
    height /= loop.length;
    // In cap order a branch's loop turns clockwise seen from the branch (its cap would face
    // away from it), once around its centre.
    if (loop_winding(loop, view, cx, cy) != -1) {
        detail = "a branch's loop does not go once around its centre, seen along the axis";
        return false;
    }
    double reach = 0;
    for (uint32_t i = 0; i < loop.length; ++i) {
        const Local p = view.at(loop.ids[i]);
        const double d = (p.x - cx) * (p.x - cx) + (p.y - cy) * (p.y - cy);
        if (d > reach) reach = d;
    }
    site = {cx, cy, reach, height - kJoinReach * gap, height + gap};
    return true;
}

// Collects in m.under[0 .. found) the trunk's triangles under the branch's loop that face
// it (see "grafts" above) and no planned hole takes; false (detail set) if there are more
// than m.under holds.
static inline bool find_under(const uint32_t* tri, size_t count, const uint8_t* branch_of,
                       const TracedLoop& loop, const SideView& view, const GraftSite& site,
                       JoinMemory& m, size_t& found, const char*& detail) {
    found = 0;
    for (size_t t = 0; t < count + m.filled_count; ++t) {
        const uint32_t* c = trunk_corners(tri, count, m, t);
        if (m.removed[t] || c[0] == c[1] || c[1] == c[2] || c[2] == c[0]) continue;
        if (branch_of[c[0]] != kInTrunk || branch_of[c[1]] != kInTrunk ||
            branch_of[c[2]] != kInTrunk)
            continue;
        const Local a = view.at(c[0]), b = view.at(c[1]), d = view.at(c[2]);
        const double gx = (a.x + b.x + d.x) / 3, gy = (a.y + b.y + d.y) / 3;
        const double gh = (a.h + b.h + d.h) / 3;
        if (gh < site.low || gh > site.high) continue;
        if ((gx - site.cx) * (gx - site.cx) + (gy - site.cy) * (gy - site.cy) > site.reach) continue;
        const Vec3 normal = cross({b.x - a.x, b.y - a.y, b.h - a.h}, {d.x - a.x, d.y - a.y, d.h - a.h});
        if (!(normal.z > kGraftFacing * std::sqrt(dot(normal, normal)))) continue;
        // Odd: inside by the even-odd rule.
        if (loop_winding(loop, view, gx, gy) % 2 == 0) continue;
        if (found == m.under_capacity) {
            detail = "more of the trunk's triangles lie under a branch's loop than a graft "
                     "takes (kGraftMaxTriangles)";
            return false;
        }
        m.under[found++] = static_cast<uint32_t>(t);
    }
    return true;
}

// The position in m.under[0 .. found) of the triangle nearest the site's centre whose
// corners no hole holds; found if there is none.
static inline size_t hole_seed(const uint32_t* tri, size_t count, const JoinMemory& m, size_t found,
                        const SideView& view, const GraftSite& site) {
    size_t seed = found;
    double nearest = DBL_MAX;
    for (size_t k = 0; k < found; ++k) {
        const uint32_t* c = trunk_corners(tri, count, m, m.under[k]);
        if (m.hole_next[c[0]] != kNoIndex || m.hole_next[c[1]] != kNoIndex ||
            m.hole_next[c[2]] != kNoIndex)
            continue;
        const Local a = view.at(c[0]), b = view.at(c[1]), d = view.at(c[2]);
        const double gx = (a.x + b.x + d.x) / 3 - site.cx, gy = (a.y + b.y + d.y) / 3 - site.cy;
        if (gx * gx + gy * gy < nearest) {
            nearest = gx * gx + gy * gy;
            seed = k;
        }
    }
    return seed;
}

enum class HolePlan { cut, refused, missed_centre };

// Plans the hole under the branch's loop: the disc grown from the seed across the
// triangles under it, its loop written at `hole` and kept in graft.hole, its triangles in
// graft.removed. Refused (detail set, nothing taken) where no triangle is there to take;
// missed_centre where the disc does not go once around the site's centre. found: the
// triangles under the loop, for gap_beside.
static inline HolePlan plan_hole(const uint32_t* tri, size_t count, const uint8_t* branch_of,
                          const TracedLoop& loop, const SideView& view, const GraftSite& site,
                          JoinMemory& m, uint32_t* hole, size_t& found, Graft& graft,
                          const char*& detail) {
    if (!find_under(tri, count, branch_of, loop, view, site, m, found, detail))
        return HolePlan::refused;
    const size_t seed = hole_seed(tri, count, m, found, view, site);
    if (seed == found) {
        detail = "no triangle of the trunk under a branch's loop faces it (and is free to take)";
        return HolePlan::refused;
    }
    for (size_t k = 0; k < found; ++k)
        for (size_t e = 0; e < 3; ++e) {
            const uint32_t* c = trunk_corners(tri, count, m, m.under[k]);
            m.edges[3 * k + e] = {c[e], c[(e + 1) % 3], static_cast<uint32_t>(k)};
        }
    heap_sort(m.edges, 3 * found);
    uint32_t* next = m.hole_next;
    const uint32_t* first = trunk_corners(tri, count, m, m.under[seed]);
    for (size_t e = 0; e < 3; ++e) {
        next[first[e]] = first[(e + 1) % 3];
        m.queue[e] = (uint64_t{first[e]} << 32) | first[(e + 1) % 3];
    }
    m.removed[m.under[seed]] = 1;
    graft.removed = 1 + grow_hole(tri, count, m, found, 3);
    const uint32_t length = static_cast<uint32_t>(graft.removed + 2);
    hole[0] = first[0];
    for (uint32_t i = 1; i < length; ++i) hole[i] = next[hole[i - 1]];
    graft.hole = {hole, length};
    if (loop_winding(graft.hole, view, site.cx, site.cy) == 1) return HolePlan::cut;
    for (uint32_t i = 0; i < length; ++i) next[hole[i]] = kNoIndex;
    for (size_t k = 0; k < found; ++k) m.removed[m.under[k]] = 0;
    detail = "the hole under a branch's loop does not go once around the branch's centre";
    return HolePlan::missed_centre;
}

// Plans the graft of the branch whose loop (nearest the cut) is `loop`, taking the hole's
// triangles out in m.removed and its vertices in m.hole_next, its loop appended to m.holes
// at holes_used; false (nothing taken, detail set) if it cannot be grafted. tri: the
// caller's `count` triangles; entries: the count of m.loops' ids.
static inline bool plan_graft(const uint32_t* tri, size_t count, const uint8_t* branch_of,
                       const TracedLoop& loop, double gap, const SideView& view, JoinMemory& m,
                       size_t entries, size_t& holes_used, Graft& graft, const char*& detail) {
    GraftSite site;
    if (!graft_site(loop, gap, view, site, detail)) return false;
    uint32_t* hole = m.holes + holes_used;
    size_t found = 0;
    HolePlan plan = plan_hole(tri, count, branch_of, loop, view, site, m, hole, found, graft, detail);
    // A disc with no vertex inside never takes a triangle with a corner it may not take.
    // Where such a corner is on a small gap in the trunk's end beside the stump (an end
    // meshed across a fork's open top keeps some among its long triangles) and that
    // triangle covers the branch's centre, the hole misses the centre: the gap is closed
    // and the hole planned again, free to take that triangle now.
    if (plan == HolePlan::missed_centre) {
        const TracedLoop beside =
            gap_beside(m, entries, found, branch_of, view, site.cx, site.cy,
                       kGapReach * std::sqrt(site.reach), site.low, site.high);
        const size_t filled_before = m.filled_count;
        if (beside.ids && fill_gap(count, beside, view, m)) {
            plan = plan_hole(tri, count, branch_of, loop, view, site, m, hole, found, graft, detail);
            if (plan != HolePlan::cut) {
                m.filled_count = filled_before;
                for (uint32_t i = 0; i < beside.length; ++i) m.hole_next[beside.ids[i]] = kHeldVertex;
            }
        }
    }
    if (plan != HolePlan::cut) return false;
    holes_used += graft.hole.length;
    graft.branch = loop;
    graft.centre[0] = site.cx;
    graft.centre[1] = site.cy;
    graft.side = view.sign;
    return true;
}

// Writes the graft's graft.triangles() triangles at out: the hole's loop, counter-clockwise
// from its vertex first in angle after the branch loop's first vertex, and the branch's loop
// against its cap order, merged by angle around the branch's centre.
static inline void write_graft(const Graft& graft, const SideView& view, uint32_t* out) {
    const uint32_t m = graft.hole.length, n = graft.branch.length;
    const uint32_t* branch = graft.branch.ids;
    const AngleAround turn = {view, graft.centre[0], graft.centre[1], view.at(branch[0]), 1.0};
    uint32_t start = 0;
    for (uint32_t i = 1; i < m; ++i)
        if (turn(graft.hole.ids[i]) < turn(graft.hole.ids[start])) start = i;
    auto a = [&](uint32_t j) { return graft.hole.ids[(start + j) % m]; };
    auto b = [&](uint32_t l) { return branch[(n - l % n) % n]; };
    const double two_pi = 6.28318530717958647693;
    auto hole_turn = [&](uint32_t j) { return j == m ? two_pi + turn(a(0)) : turn(a(j)); };
    auto branch_turn = [&](uint32_t l) { return l == n ? two_pi : turn(b(l)); };
    auto emit = [&out](uint32_t p, uint32_t q, uint32_t r) {
        out[0] = p;
        out[1] = q;
        out[2] = r;
        out += 3;
    };
    for (uint32_t j = 0, l = 0; j < m || l < n;) {
        if (l == n || (j < m && hole_turn(j + 1) <= branch_turn(l + 1))) {
            emit(a(j), a(j + 1), b(l));
            ++j;
        } else {
            emit(a(j), b(l + 1), b(l));
            ++l;
        }
    }
}

// The caller's input as join_branches() plans from it: the surface's triangles in the
// cloud's indices, the labels, the frame along the parting's axis, the traced loops'
// entries (in JoinMemory::loops).
struct JoinInput {
    const CloudReader& reader;
    const Frame& frame;
    const Parting& parting;
    const uint32_t* triangles;
    size_t given;
    const uint8_t* branch_of;
    size_t entries;
};

// What join_branches() plans before it writes: each side's rim junction, or the grafts of
// its branches; the triangles they need in all.
struct JoinPlan {
    SideJunction junction[2];
    bool rim[2] = {false, false};
    Graft grafts[2 * kMaxBranches];
    uint32_t graft_count = 0;
    size_t holes_used = 0, removed = 0, needed = 0;
    const uint32_t* taken = nullptr;  // the trunk loop a side's rim joined: not the other's
};

// Plans side k (0 above the cut, 1 below) with `branches` branches: its rim junction where
// a trunk loop goes around them, else a graft for each branch where it stands; counts the
// side into r.
static inline void plan_side(int k, uint32_t branches, const JoinInput& in, JoinMemory& m,
                      JoinPlan& plan, JoinReport& r) {
    const SideView view = {in.reader, in.frame, k == 0 ? 1.0 : -1.0};
    const uint8_t first = static_cast<uint8_t>(k == 0 ? kFirstAboveBranch : kFirstBelowBranch);
    const double cut = (k == 0 ? in.parting.above : in.parting.below) -
                       dot(in.frame.origin, in.frame.axis);
    const double gap = in.parting.gap * in.frame.scale;
    SideLoops loops;
    find_side_loops(m.loops, in.entries, in.branch_of, first, branches, view, plan.taken, loops);
    const char* rim_why = nullptr;  // superseded by the grafts' reasons
    plan.rim[k] = plan_junction(loops, branches, view.sign * cut * in.frame.scale, gap, view,
                                plan.junction[k], rim_why);
    if (plan.rim[k]) {
        plan.taken = plan.junction[k].trunk.ids;
        plan.needed += plan.junction[k].triangles();
        ++r.joined_side_count;
        return;
    }
    // No rim goes around the branches: each is grafted where it stands on the trunk.
    uint32_t grafted = 0;
    for (uint32_t b = 0; b < branches; ++b) {
        const char* graft_why = nullptr;
        Graft& graft = plan.grafts[plan.graft_count];
        if (!loops.branch[b].ids) {
            graft_why = "a branch has no boundary loop of its own to join";
        } else if (plan_graft(in.triangles, in.given, in.branch_of, loops.branch[b], gap, view,
                              m, in.entries, plan.holes_used, graft, graft_why)) {
            plan.needed += graft.triangles();
            plan.removed += graft.removed;
            ++plan.graft_count;
            ++grafted;
            continue;
        }
        if (!r.detail) r.detail = graft_why;
    }
    r.grafted_branch_count += grafted;
    if (grafted == branches)
        ++r.joined_side_count;
    else
        ++r.apart_side_count;
}

// Writes the plan over the caller's triangles: those the holes take out gone, then the
// gaps' triangles, the rims' and the grafts'; counts into r; returns the triangles in all.
static inline size_t write_join(const JoinInput& in, const JoinMemory& m, const JoinPlan& plan,
                         uint32_t* triangles, JoinReport& r) {
    size_t kept = 0;
    for (size_t t = 0; t < in.given; ++t) {
        if (m.removed[t]) continue;
        if (kept != t)
            for (size_t e = 0; e < 3; ++e) triangles[3 * kept + e] = triangles[3 * t + e];
        ++kept;
    }
    r.removed_triangle_count = in.given - kept;
    uint32_t* out = triangles + 3 * kept;
    for (size_t f = 0; f < m.filled_count; ++f) {
        if (m.removed[in.given + f]) continue;
        for (size_t e = 0; e < 3; ++e) out[e] = m.filled[3 * f + e];
        out += 3;
        ++r.junction_triangle_count;
    }
    for (int k = 0; k < 2; ++k) {
        if (!plan.rim[k]) continue;
        const SideView view = {in.reader, in.frame, k == 0 ? 1.0 : -1.0};
        write_junction(plan.junction[k], view, out);
        out += 3 * plan.junction[k].triangles();
        r.junction_triangle_count += plan.junction[k].triangles();
    }
    for (uint32_t g = 0; g < plan.graft_count; ++g) {
        const SideView view = {in.reader, in.frame, plan.grafts[g].side};
        write_graft(plan.grafts[g], view, out);
        out += 3 * plan.grafts[g].triangles();
        r.junction_triangle_count += plan.grafts[g].triangles();
    }
    return kept + r.junction_triangle_count;
}

// join_branches()'s checks of the points and the triangles: ok, or a status with
// checks.detail set.
static inline Status check_join_input(const CloudReader& reader, size_t point_count,
                               const CloudSums& sums, const Options& options,
                               const uint32_t* triangles, size_t given, Report& checks) {
    const Status status = reject_invalid_points(reader, point_count, sums, options, checks);
    if (status != Status::ok) return status;
    for (size_t k = 0; k < 3 * given; ++k)
        if (triangles[k] >= point_count || !reader.valid(triangles[k])) {
            checks.detail = "a triangle names a point outside the cloud, or an invalid one";
            return Status::invalid_argument;
        }
    return Status::ok;
}

// The frame join_branches() sees the sides in: along the parting's axis.
static inline Status join_frame(const CloudSums& sums, const Options& options, const Parting& parting,
                         Frame& frame) {
    Options along = options;
    along.axis = Axis::direction;
    along.flags &= ~static_cast<uint32_t>(origin_given);
    for (int k = 0; k < 3; ++k) along.direction[k] = parting.axis[k];
    return choose_frame(sums, along, frame);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

size_t join_branches_workspace_size(size_t point_count, size_t triangle_count) {
    if (point_count > detail::kMaxPoints - 1) return 0;
    detail::Arena arena = detail::Arena::measuring();
    detail::JoinMemory m;
    detail::allocate_join(m, point_count, triangle_count, arena);
    detail::allocate_grafts(m, point_count, triangle_count, arena);
    return arena.failed ? 0 : arena.required_bytes();
}

size_t join_branches_max_triangles(size_t point_count) {
    return point_count + 4 * static_cast<size_t>(kMaxBranches) + kMostGapTriangles;
}

Status join_branches(const Cloud& cloud, const Options& options, const Parting& parting,
                     const uint8_t* branch_of, void* workspace, size_t workspace_bytes,
                     uint32_t* triangles, size_t triangle_capacity, size_t* triangle_count,
                     JoinReport* report) {
    using namespace detail;
    const bool countable = cloud.count <= kMaxPoints - 1;
    const ByteRange buffers[] = {
        countable ? cloud_bytes(cloud) : ByteRange{0, 0},
        byte_range(workspace, workspace_bytes),
        byte_range(triangles, saturating_product(triangle_capacity, 3 * sizeof(uint32_t))),
        byte_range(triangle_count, sizeof(size_t)),
        byte_range(report, sizeof(JoinReport)),
        byte_range(branch_of, countable ? cloud.count : 0)};
    if (any_overlap(buffers, 6)) return Status::invalid_argument;
    JoinReport r = {0, 0, 0, 0, 0, 0, nullptr};
    Report checks = {};
    Arena arena = Arena::over(workspace, workspace_bytes);
    const size_t given = triangle_count ? *triangle_count : 0;
    size_t needed = given;
    auto finish = [&](Status status) {
        r.workspace_used_bytes = arena.peak_from_buffer();
        if (!r.detail) r.detail = checks.detail;
        if (report) *report = r;
        if (status == Status::triangle_capacity) *triangle_count = needed;
        return status;
    };
    Status status = check_reconstruct_arguments(cloud, triangles, triangle_capacity,
                                                triangle_count, workspace, checks);
    if (status != Status::ok) return finish(status);
    if (const char* refusal = options_refusal(options)) {
        checks.detail = refusal;
        return finish(Status::invalid_argument);
    }
    if (given > triangle_capacity || (cloud.count > 0 && !branch_of)) {
        checks.detail = given > triangle_capacity ? "triangle_count is above triangle_capacity"
                                                  : "branch_of is null";
        return finish(Status::invalid_argument);
    }
    const CloudReader reader = reader_of(cloud);
    const CloudSums sums = sum_cloud(reader, cloud.count);
    status = check_join_input(reader, cloud.count, sums, options, triangles, given, checks);
    if (status != Status::ok) return finish(status);
    Frame frame;
    status = join_frame(sums, options, parting, frame);
    if (status != Status::ok) return finish(status);
    const uint32_t sides[2] = {parting.above_branch_count < kMaxBranches ? parting.above_branch_count : kMaxBranches,
                               parting.below_branch_count < kMaxBranches ? parting.below_branch_count : kMaxBranches};
    if (given == 0 || (sides[0] == 0 && sides[1] == 0)) return finish(Status::ok);
    JoinMemory m;
    if (!allocate_join(m, cloud.count, given, arena)) {
        checks.detail = "the workspace is smaller than join_branches_workspace_size()";
        return finish(Status::out_of_memory);
    }
    build_cap_graph(triangles, given, cloud.count, m.graph);
    size_t entries = 0;
    trace_boundary_loops(m.graph, cloud.count, m.loops, &entries);
    note_gap_joins(m, entries);
    if (!allocate_grafts(m, cloud.count, given, arena)) {
        checks.detail = "the workspace is smaller than join_branches_workspace_size()";
        return finish(Status::out_of_memory);
    }
    std::memset(m.hole_next, 0xFF, sizeof(uint32_t) * cloud.count);
    for (size_t i = 0; i < entries; ++i) m.hole_next[m.loops.ids[i]] = kHeldVertex;
    std::memset(m.removed, 0, given);
    const JoinInput in = {reader, frame, parting, triangles, given, branch_of, entries};
    JoinPlan plan;
    plan.needed = given;
    for (int k = 0; k < 2; ++k)
        if (sides[k] != 0) plan_side(k, sides[k], in, m, plan, r);
    needed = plan.needed + m.filled_count - plan.removed;
    if (needed > triangle_capacity) return finish(Status::triangle_capacity);
    *triangle_count = write_join(in, m, plan, triangles, r);
    return finish(Status::ok);
}

}  // namespace stratmesh

#endif  // STRATMESH_SMALL_CODE

// >>parts ================================================================================
// reconstruct()'s default: trunk and branches, meshed and joined.
//
// reconstruct()'s default where the cloud parts into branches (PartCounts). One tube wraps
// branches and the gaps between them, so where find_parting() finds a cut, the trunk (the
// points labelled kInTrunk) is meshed along the cloud's axis, each branch as a tube of its
// own around its own automatic axis, and join_branches() zips them into one surface (caps
// last, with add_caps, once joined). That is kept only when it is whole: every part
// meshed, every side joined, every point in a part; otherwise, unless Parts::apart, the cloud
// is meshed as one tube after all (PartsOutcome::undone). A part is meshed in place: the
// points of the other parts join the outliers in the reader's bitmap, so its triangles
// index the cloud directly and its frame is the one a copy of its points would get.
//
// The search costs about the reconstruction's time again on a cloud that does not part,
// so a cloud of more than kPartingSample points is searched on a sample first (every k-th
// kept point) and in full only where the sample parts: a branch of fewer than about
// kSmallestBranch * n / kPartingSample points can go unseen.

#if !defined(STRATMESH_SMALL_CODE)
namespace stratmesh {
namespace detail {

const size_t kPartingSample = 4096;

// On the sample a branch counts from this share of kSmallestBranch points: fewer than on
// the whole cloud, so that a branch the whole cloud would count is seen in the sample too
// (a horn of one point in a hundred); the search in full then decides.
const uint32_t kSampleBranchShare = 4;

// The trunk's end layer under branches standing on its closed end is merged with the
// layers next to it until it is this many of their largest radius tall: a closed end
// projects from a pole one radius in from the end, but at most three quarters of the way
// into its layer (kPoleDepth), and a thinner end layer puts the pole so near the end that
// the branches' stumps fold over the crown and their grafts cross the trunk beside them.
const double kPoleLayerRadii = 4.0 / 3.0;

// The trunk's layers, as many as a tube of `count` points can have (each holds at least
// kMinLayerPoints but the last).
static inline size_t most_layers(size_t count) { return count / kMinLayerPoints + 2; }

struct PartsMemory {
    uint8_t* labels;          // find_parting's branch_of for the whole cloud
    unsigned char* mask;      // the points left out of the part being meshed
    LayerInfo* layers;        // the trunk's
    double* cuts;             // the trunk's, merged at its ends (see cuts_for_tall_ends)
    size_t layer_capacity;
};

static inline bool allocate_parts(PartsMemory& m, size_t count, Arena& arena) {
    m.labels = arena.alloc<uint8_t>(count);
    m.mask = arena.alloc<unsigned char>(count / 8 + 1);
    m.layer_capacity = most_layers(count);
    m.layers = arena.alloc<LayerInfo>(m.layer_capacity);
    m.cuts = arena.alloc<double>(m.layer_capacity);
    return !arena.failed;
}

// The reader of the part labelled `label`: every other point left out with the outliers.
static inline TubeInput part_input(const TubeInput& whole, const PartsMemory& m, uint8_t label) {
    const size_t bytes = whole.count / 8 + 1;
    std::memset(m.mask, 0, bytes);
    for (size_t i = 0; i < whole.count; ++i)
        if (m.labels[i] != label) m.mask[i >> 3] |= static_cast<unsigned char>(1u << (i & 7));
    if (whole.reader.dropped)
        for (size_t b = 0; b < bytes; ++b) m.mask[b] |= whole.reader.dropped[b];
    TubeInput in = whole;
    in.reader.dropped = m.mask;
    in.sums = sum_cloud(in.reader, in.count);
    return in;
}

// A point beyond a cut in no branch is most often a sparse point of a branch whose nearest
// neighbour lies more than a gap away (uniform sampling leaves a few in every ten thousand;
// the thin tip of a horn more): within kAdoptionGaps gaps of a part's point, it goes to
// the part of the nearest one, so that the split is kept and the point is a vertex. Farther
// away it is a piece of its own (a speck, a patch a hole cut off), and the split is undone.
// Sought among all points, so at most kMostStrayChecks distance checks in all.
const double kAdoptionGaps = 2.0;

const uint64_t kMostStrayChecks = uint64_t{1} << 26;

// True if the trunk took a point.
static inline bool adopt_stray_points(const TubeInput& whole, double gap, uint8_t* labels) {
    const double reach = kAdoptionGaps * gap;
    uint64_t checks_left = kMostStrayChecks;
    bool trunk_grew = false;
    // Passes until none is adopted: a point can be adopted through one adopted before it
    // (the sparse tip of a horn, point after point).
    for (bool adopted = true; adopted;) {
        adopted = false;
        uint64_t strays = 0;
        for (size_t i = 0; i < whole.count; ++i)
            strays += labels[i] == kBeyondBranches && whole.reader.valid(i);
        if (strays == 0 || strays > checks_left / whole.count) return trunk_grew;
        checks_left -= strays * whole.count;
        for (size_t i = 0; i < whole.count; ++i) {
            if (labels[i] != kBeyondBranches || !whole.reader.valid(i)) continue;
            const Vec3 p = whole.reader.point(i);
            double nearest = reach * reach;
            uint8_t label = kBeyondBranches;
            for (size_t j = 0; j < whole.count; ++j) {
                if (labels[j] == kBeyondBranches || !whole.reader.valid(j)) continue;
                const Vec3 d = whole.reader.point(j) - p;
                const double d2 = dot(d, d);
                if (d2 <= nearest) {
                    nearest = d2;
                    label = labels[j];
                }
            }
            adopted = adopted || label != kBeyondBranches;
            trunk_grew = trunk_grew || label == kInTrunk;
            labels[i] = label;
        }
    }
    return trunk_grew;
}

// Whether every point is in a part (none is left beyond a cut in no branch).
static inline bool every_point_in_a_part(size_t count, const uint8_t* labels) {
    for (size_t i = 0; i < count; ++i)
        if (labels[i] == kBeyondBranches) return false;
    return true;
}

// Where branches stand on a closed end of the trunk (its end layer at a side that parts
// is closed, as a skull's crown under horns), the cuts that merge that end layer with the
// layers next to it until it is kPoleLayerRadii times the largest of their radii tall;
// false where no end needs it. *merged counts the layers merged away.
static inline bool cuts_for_tall_ends(const PartsMemory& m, size_t n, const Parting& parting,
                               size_t* cut_count, size_t* merged) {
    if (n < 2) return false;
    const LayerInfo* layers = m.layers;
    size_t first = 0, last = n - 1;  // the layers kept whole: [first, last]
    if (parting.above_branch_count > 0 && (layers[n - 1].closed_ends & closed_top)) {
        double radius = layers[last].radius;
        while (last > 0 && layers[n - 1].top - layers[last].bottom < kPoleLayerRadii * radius) {
            --last;
            radius = radius > layers[last].radius ? radius : layers[last].radius;
        }
    }
    if (parting.below_branch_count > 0 && (layers[0].closed_ends & closed_bottom)) {
        double radius = layers[first].radius;
        while (first < last && layers[first].top - layers[0].bottom < kPoleLayerRadii * radius) {
            ++first;
            radius = radius > layers[first].radius ? radius : layers[first].radius;
        }
    }
    if (first == 0 && last == n - 1) return false;
    *cut_count = 0;
    for (size_t k = first; k < last; ++k) m.cuts[(*cut_count)++] = layers[k].top;
    *merged = n - 1 - *cut_count;
    return true;
}

// A part meshed into the record of the parts, and where meshed, its counts into the whole's.
static inline void record_part(Report& rep, uint8_t label, Status status, const TubeInput& in,
                        const Report& part, size_t triangles, size_t merged) {
    PartCounts& p = rep.parts;
    if (p.part_count < p.info_capacity)
        p.info[p.part_count] = {label, status, in.sums.valid, part.layers.used_count,
                                status == Status::ok ? triangles : 0,
                                part.diagnostics.fold_count, merged};
    ++p.part_count;
    if (status != Status::ok) return;
    rep.points.used_count += part.points.used_count;
    rep.points.duplicate_count += part.points.duplicate_count;
    rep.diagnostics.fold_count += part.diagnostics.fold_count;
    rep.diagnostics.illegal_removed_count += part.diagnostics.illegal_removed_count;
    rep.diagnostics.diagonal_swap_count += part.diagnostics.diagonal_swap_count;
}

// ---- the steps ---------------------------------------------------------------------------
//
// reconstruct_default() reads top to bottom: search where the cloud parts, square the cut
// to the trunk, adopt the stray points, mesh the one tube for its area, mesh the parts,
// join them, then keep them or undo them. Each step asks for its tubes with a TubeRequest
// of its own, made from the caller's (see >>request).

// What the steps share: the memory, the request the parts are cut along (the caller's,
// along the axis the cut is squared to), and the trunk's own axis once chosen for the
// labels as they stand (`trunk_known`).
struct PartsWork {
    PartsMemory m;
    TubeRequest cut;
    bool trunk_known;
    Status trunk_status;
    TubeRequest trunk;
};

// Finds where the cloud parts along the request's axis (the frame's origin the centroid),
// on a sample first when it is large (see above); the labels are filled where it parts.
// False if the workspace is too small.
static inline bool search_parting(const Cloud& cloud, const TubeInput& whole, const TubeRequest& along,
                           const PartsMemory& m, Arena& arena, Parting& parting) {
    TubeRequest search = along;
    search.origin = nullptr;
    if (whole.sums.valid > kPartingSample) {
        const size_t mark = arena.mark();
        size_t taken = 0;
        const double* sample = sample_points(whole, kPartingSample, arena, &taken);
        if (!sample) return false;
        TubeRequest on_sample = search;  // the sample holds the kept points only
        on_sample.drop_outliers = false;
        const size_t bytes = parting_workspace_size(taken, on_sample);
        void* work = arena.alloc<unsigned char>(bytes);
        if (!work) return false;
        const Status status =
            find_parting_with({sample, taken, 0, Scalar::float64}, on_sample, work, bytes,
                              &parting, nullptr, kSmallestBranch / kSampleBranchShare);
        arena.rewind(mark);
        if (status != Status::ok || parting.above_branch_count + parting.below_branch_count == 0)
            return true;
    }
    const size_t mark = arena.mark();
    const size_t bytes = parting_workspace_size(cloud.count, search);
    void* work = arena.alloc<unsigned char>(bytes);
    if (!work) return false;
    const Status status = find_parting_with(cloud, search, work, bytes, &parting, m.labels,
                                            kSmallestBranch);
    arena.rewind(mark);
    if (status != Status::ok) parting.above_branch_count = parting.below_branch_count = 0;
    return true;
}

// Whether the cloud parts around a trunk: a trunk of fewer points than a branch is no
// trunk, the cloud is apart all along (separate objects) and is meshed as one tube.
static inline bool parts_around_trunk(size_t count, const Parting& parting, const uint8_t* labels) {
    if (parting.above_branch_count + parting.below_branch_count == 0) return false;
    size_t trunk_points = 0;
    for (size_t i = 0; i < count; ++i) trunk_points += labels[i] == kInTrunk;
    return trunk_points >= kSmallestBranch;
}

// The trunk's own automatic axis, chosen once for the labels as they stand: squaring the
// cut asks for it, and the trunk is meshed around it unless a label changed since.
static inline Status trunk_axis(const TubeInput& whole, PartsWork& w, Arena& arena) {
    if (w.trunk_known) return w.trunk_status;
    w.trunk = w.cut;
    w.trunk.axis = Axis::automatic;
    const char* ignored = nullptr;
    const size_t mark = arena.mark();
    w.trunk_status = resolve_axis(part_input(whole, w.m, kInTrunk), arena, w.trunk, &ignored);
    arena.rewind(mark);
    w.trunk_known = true;
    return w.trunk_status;
}

// A fork scanned askew is cut obliquely, lower under one branch than under another, and a
// graft needs the cut square to the fork (see join_branches()). Where the trunk's own axis
// leans from the parting's by more than kSquareCutLeast (and less than kSquareCutMost:
// beyond, the trunk runs another way than its branches, as a body whose legs hang under
// it), the parting is searched again along the mean of the two axes, up to kSquareCutRounds
// times: an oblique cut leaves more of one branch in the trunk, which leans the trunk's
// axis the other way, so the mean comes closer each round. A round is kept only if it
// finds as many branches on each side; the parts are then cut along its axis. Not where
// the caller gave cuts, which are positions along the axis. False if the workspace is too
// small.
const double kSquareCutLeast = 0.99996;  // cos 0.5 degree

const double kSquareCutMost = 0.866;     // cos 30 degrees

const int kSquareCutRounds = 4;

static inline bool square_cut_to_trunk(const Cloud& cloud, const TubeInput& whole, PartsWork& w,
                                Arena& arena, Parting& parting) {
    for (int round = 0; round < kSquareCutRounds && w.cut.layers.cut_count == 0; ++round) {
        if (trunk_axis(whole, w, arena) != Status::ok || w.trunk.axis != Axis::direction) break;
        const Vec3 cut = {parting.axis[0], parting.axis[1], parting.axis[2]};
        Vec3 trunk = {w.trunk.direction[0], w.trunk.direction[1], w.trunk.direction[2]};
        if (!normalize(trunk)) break;
        const double lean = dot(trunk, cut);
        if (!(std::fabs(lean) < kSquareCutLeast && std::fabs(lean) > kSquareCutMost)) break;
        const Vec3 toward = scaled(trunk, lean < 0 ? -1 : 1);  // the parting's way
        const double mean[3] = {cut.x + toward.x, cut.y + toward.y, cut.z + toward.z};
        TubeRequest squared = w.cut;
        set_direction(squared, mean);
        Parting again = {};
        if (!search_parting(cloud, whole, squared, w.m, arena, again)) return false;
        if (again.above_branch_count != parting.above_branch_count ||
            again.below_branch_count != parting.below_branch_count) {
            // The last round's labels back, and with them the trunk's axis chosen on them.
            return search_parting(cloud, whole, w.cut, w.m, arena, parting);
        }
        w.cut = squared;
        w.trunk_known = false;
        parting = again;
    }
    return true;
}

// The area of a surface whose triangles index the cloud.
static inline double surface_area(const CloudReader& reader, const uint32_t* triangles, size_t count) {
    double area = 0;
    for (size_t t = 0; t < count; ++t) {
        const Vec3 a = reader.point(triangles[3 * t]);
        const Vec3 n = cross(reader.point(triangles[3 * t + 1]) - a,
                             reader.point(triangles[3 * t + 2]) - a);
        area += std::sqrt(dot(n, n)) / 2;
    }
    return area;
}

// The one tube's area, to weigh the parts against (DBL_MAX where it has none), where it
// can decide: not where the parts are kept whatever their area, nor where a point in no
// part undoes them whatever it. Its triangles are overwritten by the parts'.
static inline Status one_tube_area(const TubeInput& in, const TubeRequest& request, bool all_in_parts,
                            Arena& arena, uint32_t* triangles, size_t capacity,
                            const Report& before, double* area) {
    *area = DBL_MAX;
    if (request.parts == Parts::apart || !all_in_parts) return Status::ok;
    Report tube = before;
    size_t count = 0;
    const size_t mark = arena.mark();
    const Status status = mesh_tube(in, request, arena, triangles, capacity, &count, tube);
    arena.rewind(mark);
    if (status == Status::ok) *area = surface_area(in.reader, triangles, count);
    return status == Status::out_of_memory ? status : Status::ok;
}

// The trunk along `along`, its end layers under branches merged where they stand on a
// closed end; its triangles start the output.
static inline Status mesh_trunk(const TubeInput& trunk, const TubeRequest& along, const Parting& parting,
                         const PartsMemory& m, Arena& arena, uint32_t* triangles,
                         size_t capacity, size_t* count, Report& part, size_t* merged) {
    part.layers.info = m.layers;
    part.layers.info_capacity = m.layer_capacity;
    const size_t mark = arena.mark();
    Status status = mesh_tube(trunk, along, arena, triangles, capacity, count, part);
    arena.rewind(mark);
    size_t cut_count = 0;
    *merged = 0;
    if (status != Status::ok || part.layers.used_count > m.layer_capacity ||
        !cuts_for_tall_ends(m, part.layers.used_count, parting, &cut_count, merged))
        return status;
    // Again along the same axis, through the layers' own cuts but those merged.
    TubeRequest again = along;
    set_direction(again, part.axis);
    again.layers = {m.cuts, cut_count, cut_count == 0 ? 1u : 0u, 0};
    part = Report{};
    part.layers.info = m.layers;
    part.layers.info_capacity = m.layer_capacity;
    status = mesh_tube(trunk, again, arena, triangles, capacity, count, part);
    arena.rewind(mark);
    return status;
}

// The trunk into the output, around its own axis as the branches (a body whose legs hang
// under it is meshed along the body) unless the caller laid out the layers; its frame and
// layers are the whole's in the report. Where it fails, the outcome is undone.
static inline Status mesh_trunk_part(const TubeInput& whole, PartsWork& w, Arena& arena,
                              uint32_t* triangles, size_t capacity, size_t* count, Report& rep) {
    const Parting& parting = rep.parts.parting;
    const TubeInput trunk = part_input(whole, w.m, kInTrunk);
    const bool own_axis = automatic_layers(w.cut.layers);
    Status status = own_axis ? trunk_axis(whole, w, arena) : Status::ok;
    TubeRequest along = own_axis ? w.trunk : w.cut;
    along.caps = false;  // the caps come once the parts are joined
    // Pointing the parting's way, so that the trunk's top is on the side above.
    const double* d = along.direction;
    if (own_axis && along.axis == Axis::direction &&
        d[0] * parting.axis[0] + d[1] * parting.axis[1] + d[2] * parting.axis[2] < 0)
        for (int k = 0; k < 3; ++k) along.direction[k] = -d[k];
    Report part = {};
    size_t merged = 0;
    if (status == Status::ok)
        status = mesh_trunk(trunk, along, parting, w.m, arena, triangles, capacity, count, part,
                            &merged);
    record_part(rep, kInTrunk, status, trunk, part, *count, merged);
    if (status != Status::ok) {
        rep.parts.outcome = PartsOutcome::undone;
        return status == Status::out_of_memory ? status : Status::ok;
    }
    for (int k = 0; k < 3; ++k) {
        rep.axis[k] = part.axis[k];
        rep.axis_origin[k] = part.axis_origin[k];
    }
    rep.layers.used_count = part.layers.used_count;
    rep.layers.planned_count = part.layers.planned_count;
    rep.layers.parallel_count = part.layers.parallel_count;
    size_t kept = rep.layers.used_count < w.m.layer_capacity ? rep.layers.used_count
                                                              : w.m.layer_capacity;
    kept = kept < rep.layers.info_capacity ? kept : rep.layers.info_capacity;
    if (kept > 0) std::memcpy(rep.layers.info, w.m.layers, kept * sizeof(LayerInfo));
    return Status::ok;
}

// A branch's request: around its own automatic axis and layers, its frame's origin its own
// centroid, no caps (they come once the parts are joined) and no progress (the caller's
// would run backwards from part to part).
static inline TubeRequest branch_request(TubeRequest r) {
    r.axis = Axis::automatic;
    r.layers = LayerRequest{};
    r.origin = nullptr;
    r.caps = false;
    r.progress = nullptr;
    return r;
}

// Each branch into the output after the trunk's `*count` triangles, its end at the cut a
// cut, not a closed end: its low end along its own axis if that runs away from the trunk.
// *all_meshed is cleared where a branch fails (its points stay unused).
static inline Status mesh_branches(const TubeInput& whole, const PartsWork& w, Arena& arena,
                            uint32_t* triangles, size_t capacity, size_t* count, bool* all_meshed,
                            Report& rep) {
    const Parting& parting = rep.parts.parting;
    const TubeRequest branches = branch_request(w.cut);
    const Vec3 parting_axis = {parting.axis[0], parting.axis[1], parting.axis[2]};
    const uint32_t total = parting.above_branch_count + parting.below_branch_count;
    for (uint32_t b = 0; b < total; ++b) {
        const bool above = b < parting.above_branch_count;
        const uint8_t label = static_cast<uint8_t>(
            above ? kFirstAboveBranch + b : kFirstBelowBranch + (b - parting.above_branch_count));
        const TubeInput branch = part_input(whole, w.m, label);
        if (branch.sums.valid == 0) continue;  // the side above took its points
        Report part = {};
        TubeRequest own = branches;
        size_t added = 0;
        const size_t mark = arena.mark();
        Status status = resolve_axis(branch, arena, own, &part.detail);
        const Vec3 own_axis = {own.direction[0], own.direction[1], own.direction[2]};
        own.cut_ends |= (dot(own_axis, parting_axis) > 0) == above ? kLowPole : kHighPole;
        if (status == Status::ok)
            status = mesh_tube(branch, own, arena, triangles + 3 * *count, capacity - *count,
                               &added, part);
        arena.rewind(mark);
        record_part(rep, label, status, branch, part, added, 0);
        if (status == Status::out_of_memory) return status;
        if (status != Status::ok) {
            *all_meshed = false;
            if (!rep.detail) rep.detail = part.detail;
            continue;
        }
        *count += added;
    }
    return Status::ok;
}

// Joins the parts meshed into the output (then caps them, as asked); `whole` tells whether
// every part was meshed and every point is in one. Sets rep.parts.outcome: joined,
// kept_apart, or undone (the output is then to be made again as one tube).
static inline Status join_parts(const Cloud& cloud, const PartsWork& w, bool whole, Arena& arena,
                         uint32_t* triangles, size_t capacity, size_t count,
                         size_t* triangle_count, Report& rep) {
    JoinReport join = {};
    const size_t bytes = join_branches_workspace_size(cloud.count, count);
    const size_t mark = arena.mark();
    void* work = arena.alloc<unsigned char>(bytes);
    if (!work) return Status::out_of_memory;
    size_t joined = count;
    Status status = join_branches(cloud, *w.cut.caller, rep.parts.parting, w.m.labels, work,
                                  bytes, triangles, capacity, &joined, &join);
    arena.rewind(mark);
    if (status == Status::ok) count = joined;
    rep.parts.joined_side_count = join.joined_side_count;
    rep.parts.apart_side_count = join.apart_side_count;
    rep.parts.grafted_branch_count = join.grafted_branch_count;
    rep.parts.junction_triangle_count = join.junction_triangle_count;
    rep.parts.removed_triangle_count = join.removed_triangle_count;
    if (!rep.detail) rep.detail = join.detail;
    whole = whole && status == Status::ok && join.apart_side_count == 0;
    if (!whole && w.cut.parts != Parts::apart) {
        rep.parts.outcome = PartsOutcome::undone;
        return Status::ok;
    }
    rep.parts.outcome = whole ? PartsOutcome::joined : PartsOutcome::kept_apart;
    if (w.cut.caps) {
        // Around the axis the cut was made along, in the frame of the whole cloud.
        const CloudReader reader = reader_of(cloud);
        const TubeInput all = {reader, cloud.count, sum_cloud(reader, cloud.count)};
        CapTally caps = {0, 0, 0, 0};
        size_t needed = 0;
        status = cap_surface(all, w.cut, arena, triangles, capacity, count, caps, &needed);
        arena.rewind(mark);
        if (status != Status::ok) return status;
        rep.caps.closed_count = caps.closed;
        rep.caps.open_count = caps.left_open;
        rep.caps.triangle_count = caps.triangles;
        rep.caps.wall_flip_count = caps.wall_flips;
    }
    *triangle_count = count;
    rep.triangle_count = count;
    return Status::ok;
}

// Whether the parts are kept: joined and smaller than the one tube (a tube that wraps
// branches bridges the gaps between them with webs, which add area, and so does a join
// that folds where the parting misread the cloud, as a neck's torn rim taken for two
// branches), or kept apart as asked. Otherwise the counts start again from `before`, the
// parts' record stays.
static inline bool keep_or_undo(const TubeInput& in, const uint32_t* triangles, size_t count,
                         double tube_area, const Report& before, Report& rep) {
    const PartsOutcome outcome = rep.parts.outcome;
    if (outcome == PartsOutcome::kept_apart ||
        (outcome == PartsOutcome::joined && surface_area(in.reader, triangles, count) < tube_area))
        return true;
    PartCounts parts = rep.parts;
    if (outcome != PartsOutcome::undone) {
        parts.outcome = PartsOutcome::undone;
        rep.detail = "the branches joined made a larger surface than one tube";
    }
    const char* detail = rep.detail;
    rep = before;
    rep.parts = parts;
    rep.detail = detail;
    return false;
}

// The steps where the cloud may part (see above); *kept tells whether the parts are the
// output, else the one tube is to be meshed.
static inline Status mesh_apart(const Cloud& cloud, const TubeInput& in, const TubeRequest& request,
                         Arena& arena, uint32_t* triangles, size_t capacity,
                         size_t* triangle_count, Report& rep, bool* kept) {
    PartsWork w = {};
    w.cut = request;
    Parting& parting = rep.parts.parting;
    if (!allocate_parts(w.m, cloud.count, arena) ||
        !search_parting(cloud, in, w.cut, w.m, arena, parting))
        return Status::out_of_memory;
    if (!parts_around_trunk(cloud.count, parting, w.m.labels)) return Status::ok;
    if (!square_cut_to_trunk(cloud, in, w, arena, parting)) return Status::out_of_memory;
    if (adopt_stray_points(in, parting.gap, w.m.labels)) w.trunk_known = false;
    bool whole = every_point_in_a_part(in.count, w.m.labels);
    const Report before = rep;
    double tube_area = DBL_MAX;
    Status status = one_tube_area(in, request, whole, arena, triangles, capacity, before,
                                  &tube_area);
    size_t count = 0;
    if (status == Status::ok)
        status = mesh_trunk_part(in, w, arena, triangles, capacity, &count, rep);
    if (status != Status::ok) return status;
    if (rep.parts.outcome != PartsOutcome::undone) {
        status = mesh_branches(in, w, arena, triangles, capacity, &count, &whole, rep);
        if (status != Status::ok) return status;
        if (!whole && !rep.detail)
            rep.detail = "points beyond a cut belong to no branch (a piece more than two gaps "
                         "from every part)";
        status = join_parts(cloud, w, whole, arena, triangles, capacity, count, triangle_count,
                            rep);
        if (status != Status::ok) return status;
    }
    *kept = keep_or_undo(in, triangles, *triangle_count, tube_area, before, rep);
    return Status::ok;
}

// reconstruct() with the search for branches: `in` is read and the request's axis is
// resolved. Where the cloud parts, the parts joined are kept only where whole and smaller
// than the one tube's (see keep_or_undo()), else the one tube is.
static inline Status reconstruct_default(const Cloud& cloud, const TubeInput& in,
                                  const TubeRequest& request, Arena& arena,
                                  uint32_t* triangles, size_t capacity, size_t* triangle_count,
                                  Report& rep) {
    if (in.sums.distinct >= 3) {
        const size_t mark = arena.mark();
        bool kept = false;
        const Status status = mesh_apart(cloud, in, request, arena, triangles, capacity,
                                         triangle_count, rep, &kept);
        if (status != Status::ok || kept) return status;
        arena.rewind(mark);
    }
    return mesh_tube(in, request, arena, triangles, capacity, triangle_count, rep);
}

// The workspace reconstruct_default() takes on top of read_cloud()'s.
static inline size_t parts_workspace_size(size_t count, const TubeRequest& request) {
    Arena arena = Arena::measuring();
    PartsMemory m;
    allocate_parts(m, count, arena);
    // The one tube meshed for its area while the parts' memory is held, and the parts (their
    // points read through the mask): the trunk's tube, without caps, takes no more.
    TubeRequest tube = request;
    tube.drop_outliers = false;
    TubeRequest part = tube;
    part.caps = false;
    const size_t triangles = reconstruct_max_triangles(count, *request.caller);
    const size_t sample = count > kPartingSample
                              ? saturating_product(3 * sizeof(double), kPartingSample) + Arena::kAlign +
                                    parting_workspace_size(kPartingSample, part)
                              : 0;
    const TubeRequest branch = branch_request(part);
    const size_t steps[] = {sample, parting_workspace_size(count, request),
                            tube_workspace_size(count, tube),
                            axis_workspace_size(count, branch),
                            tube_workspace_size(count, branch),
                            join_branches_workspace_size(count, triangles),
                            cap_ends_workspace_size(count, triangles)};
    size_t most = sample;
    for (size_t k = 1; k < sizeof steps / sizeof steps[0]; ++k) {
        if (steps[k] == 0) return 0;  // beyond what this platform can address
        most = steps[k] > most ? steps[k] : most;
    }
    if (arena.failed || most > SIZE_MAX - arena.required_bytes() - Arena::kAlign) return 0;
    return arena.required_bytes() + Arena::kAlign + most;
}

}  // namespace detail
}  // namespace stratmesh

#endif  // STRATMESH_SMALL_CODE

// >>skeleton =============================================================================
// Objects that bend: layers across a skeleton of geodesic rings, not one straight axis.
//
// find_skeleton(): on a sample of about kSkeletonSample kept points (by a hash of their
// coordinates), a graph joining each point to its kMostNeighbours nearest within
// kReachDeciles nearest-neighbour deciles (found in a grid of that side), its largest
// connected piece, and the distance along the graph from one end of the object (Dijkstra
// from the point farthest along the graph from an extreme point; its heap an array). Bands
// of that distance, each at least two reaches wide, fall into connected pieces: the
// object's rings around its centre line (Verroust and Lazarus, "Extracting skeletal curves
// from 3D scattered data", 2000). Where every band holds one ring, the centres of circles
// fitted to the rings, smoothed by Taubin's filter (which does not pull a bend inward), are
// the skeleton: a polyline with a frame carried along it without twist.
// The object counts as bent where that polyline is kLongRadii ring radii long or more,
// strays kStrayRadii from its chord, and turns nowhere more tightly than kTightestTurn
// radii (tighter, the straightened coordinates below would fold). Then mesh_if_bent()
// meshes it as one tube in straightened coordinates: each point across its nearest
// skeleton segment (two coordinates in the frame there) and along it (arc length), so the
// layers are the skeleton's cross-sections wherever the object goes, and the triangles
// index the cloud as ever. A band with two rings is a branch (or a handle): such an object
// goes on to the parts (>>parts), as does a straight one.

namespace stratmesh {
namespace detail {

// Points the skeleton is found on: enough for rings of tens of points on a coil of two
// turns, few enough to cost a few milliseconds.
const size_t kSkeletonSample = 4096;
// Points the nearest-neighbour decile is measured on: a decile needs no more.
const size_t kSpacingSample = 2048;
// Neighbours are joined within this many nearest-neighbour deciles: on a uniformly random
// sample of a surface, about 20 points, and a graph in one piece.
const double kReachDeciles = 3.0;
// The most bands (so skeleton nodes): the smallest band is two reaches wide, or this share
// of the object's geodesic length.
const uint32_t kMostBands = 256;
// A piece of a band counts as a ring from this share of the band's points (and at least
// kMinRingPoints): smaller pieces are specks the graph did not join. Small enough that an
// animal's leg beside its body counts.
const uint32_t kRingShare = 32;
const uint32_t kMinRingPoints = 8;
// Bent: at least this long and straying this far from the chord, in ring radii.
const double kLongRadii = 8.0;
const double kStrayRadii = 2.0;
// The tightest turn the straightening follows, as the skeleton's radius of curvature over
// the rings' radius.
const double kTightestTurn = 1.5;
const double kUnreached = DBL_MAX;
// Taubin's smoothing of the skeleton: passes, and the weights in and back out.
const int kSmoothingPasses = 10;
const double kSmoothIn = 0.5;
const double kSmoothOut = -0.53;

// The skeleton: nodes along the object's centre line with a frame each (tangent and a
// normal carried along without twist) and their arc length from the first.
struct Skeleton {
    Vec3* centre;
    Vec3* tangent;
    Vec3* normal;
    double* arc;
    uint32_t count;
};

// The neighbours a point keeps: its nearest within reach. Where the density varies, the
// reach that joins the sparse parts holds hundreds of points in the dense ones.
const uint32_t kMostNeighbours = 16;

// The sample's neighbourhood graph: the points in grid order (cells of side `reach`), and
// each one's neighbours, neighbour[first[j] .. first[j + 1]).
struct SkeletonGraph {
    CellScratch grid;
    size_t count;
    double reach;
    uint32_t* first;
    uint32_t* neighbour;
};

// The nearest points within reach of one point, kept in a max-heap by squared distance
// (ties by index) as the candidates go by.
struct NearestKept {
    double square[kMostNeighbours];
    uint32_t index[kMostNeighbours];
    uint32_t count;
    bool after(uint32_t a, uint32_t b) const {
        return square[a] > square[b] || (square[a] == square[b] && index[a] > index[b]);
    }
    void swap(uint32_t a, uint32_t b) {
        const double s = square[a];
        const uint32_t i = index[a];
        square[a] = square[b], index[a] = index[b];
        square[b] = s, index[b] = i;
    }
    void offer(double q, uint32_t k) {
        uint32_t at;
        if (count < kMostNeighbours) {
            at = count++;
            square[at] = q, index[at] = k;
            while (at > 0 && after(at, (at - 1) / 2)) swap(at, (at - 1) / 2), at = (at - 1) / 2;
            return;
        }
        if (q > square[0] || (q == square[0] && k > index[0])) return;
        square[0] = q, index[0] = k, at = 0;
        for (;;) {
            uint32_t child = 2 * at + 1;
            if (child >= count) break;
            if (child + 1 < count && after(child + 1, child)) ++child;
            if (!after(child, at)) break;
            swap(at, child);
            at = child;
        }
    }
};

// The neighbours of every point: its nearest within reach in the block of cells around its
// cell, the block found once a cell (the cells come in key order, so `fingers` help).
static inline void link_neighbours(SkeletonGraph& g) {
    const double reach2 = g.reach * g.reach;
    size_t fingers[18] = {};
    uint32_t edges = 0;
    for (size_t cell = 0; cell < g.count;) {
        size_t end = cell;
        while (end < g.count && g.grid.items[end].cell == g.grid.items[cell].cell) ++end;
        const CellBlock block = block_around(g.grid.items, g.count, cell, fingers);
        for (size_t j = cell; j < end; ++j) {
            g.first[j] = edges;
            const Vec3 p = g.grid.sorted[j];
            NearestKept nearest;
            nearest.count = 0;
            for (uint32_t b = 0; b < block.count; ++b)
                for (size_t k = block.begin[b]; k < block.end[b]; ++k) {
                    const Vec3 d = g.grid.sorted[k] - p;
                    if (k != j && dot(d, d) <= reach2) nearest.offer(dot(d, d), static_cast<uint32_t>(k));
                }
            for (uint32_t e = 0; e < nearest.count; ++e) g.neighbour[edges + e] = nearest.index[e];
            edges += nearest.count;
        }
        cell = end;
    }
    g.first[g.count] = edges;
}

// Calls visit(k) for every neighbour k of point j.
template <class Visit> void for_each_neighbour(const SkeletonGraph& g, size_t j, Visit visit) {
    for (uint32_t e = g.first[j]; e < g.first[j + 1]; ++e) visit(size_t{g.neighbour[e]});
}

// Union-find (find_root): the lower root index wins.
static inline void join_roots(uint32_t* parent, uint32_t a, uint32_t b) {
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a != b) parent[a > b ? a : b] = a < b ? a : b;  // the lower index: the same on every run
}

// Dijkstra's heap: point indices ordered by distance (then index), with each point's slot.
struct DistanceHeap {
    uint32_t* heap;
    uint32_t* slot;
    const double* distance;
    uint32_t size;
    bool before(uint32_t a, uint32_t b) const {
        return distance[a] < distance[b] || (distance[a] == distance[b] && a < b);
    }
    void place(uint32_t at, uint32_t point) {
        heap[at] = point;
        slot[point] = at;
    }
    void rise(uint32_t at) {
        const uint32_t point = heap[at];
        while (at > 0 && before(point, heap[(at - 1) / 2])) {
            place(at, heap[(at - 1) / 2]);
            at = (at - 1) / 2;
        }
        place(at, point);
    }
    uint32_t pop() {
        const uint32_t top = heap[0], last = heap[--size];
        uint32_t at = 0;
        for (;;) {
            uint32_t child = 2 * at + 1;
            if (child >= size) break;
            if (child + 1 < size && before(heap[child + 1], heap[child])) ++child;
            if (!before(heap[child], last)) break;
            place(at, heap[child]);
            at = child;
        }
        if (size > 0) place(at, last);
        return top;
    }
};

// A ring's circle, fitted in the plane across the centre line (Kasa's algebraic fit: the
// least squares of x^2 + y^2 - 2ax - 2by - c over the ring's points, a linear system):
// the centroid of a ring on a bend lies outward of its centre, where the surface has
// more area.
struct RingFit {
    Vec3 u, v;  // the plane's axes, through the centroid
    double x, y, xx, yy, xy, z, xz, yz;  // sums, z = x^2 + y^2
    bool plane;
    void add(Vec3 d) {
        const double px = dot(d, u), py = dot(d, v), pz = px * px + py * py;
        x += px, y += py, xx += px * px, yy += py * py, xy += px * py;
        z += pz, xz += px * pz, yz += py * pz;
    }
    // The circle's centre in the plane, by Cramer's rule; false where the ring is too
    // flat for it (a determinant lost in rounding) or the centre leaves the ring.
    bool centre(double n, double radius, double& a, double& b) const {
        const double m[3][3] = {{xx, xy, x}, {xy, yy, y}, {x, y, n}};
        const double r[3] = {xz, yz, z};
        const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        const double scale = xx * yy * n;
        if (!(abs_value(det) > 1e-9 * scale)) return false;
        const double det_a = r[0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                             m[0][1] * (r[1] * m[2][2] - m[1][2] * r[2]) +
                             m[0][2] * (r[1] * m[2][1] - m[1][1] * r[2]);
        const double det_b = m[0][0] * (r[1] * m[2][2] - m[1][2] * r[2]) -
                             r[0] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                             m[0][2] * (m[1][0] * r[2] - r[1] * m[2][0]);
        a = det_a / det / 2;
        b = det_b / det / 2;
        return a * a + b * b < radius * radius;
    }
};

struct SkeletonMemory {
    SkeletonGraph graph;
    Vec3* sample;      // the sampled points, in input order
    double* distance;  // geodesic, kUnreached off the largest piece
    uint32_t* heap;
    uint32_t* slot;
    uint32_t* parent;
    uint32_t* size;
    // Per band: points, rings, the sum of their points (then the ring's centre), the mean
    // distance to it, and the sums of the circle fit across the band.
    uint32_t* band_points;
    uint32_t* band_rings;
    Vec3* band_centre;
    double* band_radius;
    RingFit* band_fit;
};

// Room for the sample: a hash picks about one point in sample_step(), so twice that.
static inline size_t skeleton_sample_count(size_t valid) {
    return valid < 2 * kSkeletonSample ? valid : 2 * kSkeletonSample;
}

// One allocation sequence for the call and for the workspace bound: the skeleton that
// stays, then the scratch.
static inline void allocate_skeleton(Skeleton& sk, Arena& arena) {
    sk.centre = arena.alloc<Vec3>(kMostBands + 1);
    sk.tangent = arena.alloc<Vec3>(kMostBands + 1);
    sk.normal = arena.alloc<Vec3>(kMostBands + 1);
    sk.arc = arena.alloc<double>(kMostBands + 1);
    sk.count = 0;
}

static inline void allocate_skeleton_scratch(SkeletonMemory& m, size_t samples, Arena& arena) {
    m.graph.grid = allocate_cell_scratch(arena, samples);
    m.graph.first = arena.alloc<uint32_t>(samples + 1);
    m.graph.neighbour = arena.alloc<uint32_t>(samples * kMostNeighbours);
    m.sample = arena.alloc<Vec3>(samples);
    m.distance = arena.alloc<double>(samples);
    m.heap = arena.alloc<uint32_t>(samples);
    m.slot = arena.alloc<uint32_t>(samples);
    m.parent = arena.alloc<uint32_t>(samples);
    m.size = arena.alloc<uint32_t>(samples);
    m.band_points = arena.alloc<uint32_t>(kMostBands + 1);
    m.band_rings = arena.alloc<uint32_t>(kMostBands + 1);
    m.band_centre = arena.alloc<Vec3>(kMostBands + 1);
    m.band_radius = arena.alloc<double>(kMostBands + 1);
    m.band_fit = arena.alloc<RingFit>(kMostBands + 1);
}

// The geodesic distance over the graph from `source` into m.distance (kUnreached where
// the graph does not reach); returns the point farthest from it (the lowest index of ties).
static inline uint32_t geodesic_distance(SkeletonMemory& m, uint32_t source) {
    const SkeletonGraph& g = m.graph;
    for (size_t j = 0; j < g.count; ++j) m.distance[j] = kUnreached;
    DistanceHeap heap = {m.heap, m.slot, m.distance, 0};
    m.distance[source] = 0;
    heap.place(heap.size++, source);
    uint32_t farthest = source;
    while (heap.size > 0) {
        const uint32_t j = heap.pop();
        m.slot[j] = UINT32_MAX;  // settled
        const double dj = m.distance[j];
        if (dj > m.distance[farthest] || (dj == m.distance[farthest] && j < farthest)) farthest = j;
        for_each_neighbour(g, j, [&](size_t k) {
            const Vec3 d = g.grid.sorted[k] - g.grid.sorted[j];
            const double through = dj + std::sqrt(dot(d, d));
            if (!(through < m.distance[k])) return;
            const bool queued = m.distance[k] != kUnreached;
            m.distance[k] = through;
            if (!queued) heap.place(heap.size++, static_cast<uint32_t>(k));
            heap.rise(m.slot[k]);
        });
    }
    return farthest;
}

// The band of a geodesic distance.
static inline uint32_t band_of(double distance, double width, uint32_t bands) {
    const double b = std::floor(distance / width);
    return b < static_cast<double>(bands - 1) ? static_cast<uint32_t>(b) : bands - 1;
}

// The radius of the circle through three nodes (DBL_MAX where they lie on a line).
static inline double turn_radius(Vec3 a, Vec3 b, Vec3 c) {
    const Vec3 ab = b - a, bc = c - b, ca = a - c;
    const Vec3 n = cross(ab, c - a);
    const double twice_area = std::sqrt(dot(n, n));
    if (!(twice_area > 0)) return DBL_MAX;
    return std::sqrt(dot(ab, ab) * dot(bc, bc) * dot(ca, ca)) / (2 * twice_area);
}

// Moves each band's centre from its points' centroid to the centre of the circle fitted
// across the centre line there (RingFit), the line's direction taken from the centroids
// of the bands on either side.
static inline void fit_ring_circles(SkeletonMemory& m, uint32_t bands, double width) {
    const SkeletonGraph& g = m.graph;
    for (uint32_t b = 0; b < bands; ++b) {
        RingFit& f = m.band_fit[b];
        f = RingFit{};
        if (m.band_points[b] == 0) continue;
        uint32_t lo = b, hi = b;
        while (lo > 0 && (lo == b || m.band_points[lo] == 0)) --lo;
        while (hi + 1 < bands && (hi == b || m.band_points[hi] == 0)) ++hi;
        Vec3 along = m.band_centre[hi] - m.band_centre[lo];
        if (m.band_points[lo] == 0 || m.band_points[hi] == 0 || !normalize(along)) continue;
        f.u = cross(axis_least_along(along), along);
        f.plane = normalize(f.u);
        f.v = cross(along, f.u);
    }
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached) continue;
        const uint32_t b = band_of(m.distance[j], width, bands);
        if (m.band_fit[b].plane) m.band_fit[b].add(g.grid.sorted[j] - m.band_centre[b]);
    }
    for (uint32_t b = 0; b < bands; ++b) {
        const RingFit& f = m.band_fit[b];
        double a = 0, c = 0;
        if (f.plane && f.centre(m.band_points[b], m.band_radius[b], a, c))
            m.band_centre[b] = m.band_centre[b] + scaled(f.u, a) + scaled(f.v, c);
    }
}

// The rings' centres of the bands [first, last] as skeleton nodes, with their
// arc lengths and frames; false where they make no polyline (fewer than four nodes, a
// frame that cannot be carried on).
static inline bool chain_nodes(const SkeletonMemory& m, uint32_t first, uint32_t last, Skeleton& sk) {
    sk.count = 0;
    for (uint32_t b = first; b <= last; ++b)
        if (m.band_points[b] > 0)
            sk.centre[sk.count++] = m.band_centre[b];
    if (sk.count < 4) return false;
    // Taubin's smoothing (a pass of the (1/4, 1/2, 1/4) filter, then one back out by a bit
    // more): it rounds a sharp corner and a ring's noise, where the plain filter would also
    // pull every bend's nodes inward.
    for (int pass = 0; pass < 2 * kSmoothingPasses; ++pass) {
        const double weight = pass % 2 == 0 ? kSmoothIn : kSmoothOut;
        Vec3 before = sk.centre[0];
        for (uint32_t i = 1; i + 1 < sk.count; ++i) {
            const Vec3 here = sk.centre[i];
            const Vec3 pull = scaled(before + sk.centre[i + 1], 0.5) - here;
            sk.centre[i] = here + scaled(pull, weight);
            before = here;
        }
    }
    sk.arc[0] = 0;
    for (uint32_t i = 1; i < sk.count; ++i) {
        const Vec3 d = sk.centre[i] - sk.centre[i - 1];
        sk.arc[i] = sk.arc[i - 1] + std::sqrt(dot(d, d));
        if (!(sk.arc[i] > sk.arc[i - 1])) return false;
    }
    for (uint32_t i = 0; i < sk.count; ++i) {
        const uint32_t lo = i > 0 ? i - 1 : 0, hi = i + 1 < sk.count ? i + 1 : i;
        sk.tangent[i] = sk.centre[hi] - sk.centre[lo];
        if (!normalize(sk.tangent[i])) return false;
    }
    // The first normal: across the tangent, from the coordinate axis least along it.
    sk.normal[0] = cross(axis_least_along(sk.tangent[0]), sk.tangent[0]);
    if (!normalize(sk.normal[0])) return false;
    for (uint32_t i = 1; i < sk.count; ++i) {
        const Vec3 n = sk.normal[i - 1], ti = sk.tangent[i];
        sk.normal[i] = n - scaled(ti, dot(n, ti));
        if (!normalize(sk.normal[i])) return false;
    }
    return true;
}

// Whether the skeleton is bent (see above) for rings of radius `radius`.
static inline bool bent_enough(const Skeleton& sk, double radius) {
    const uint32_t last = sk.count - 1;
    if (!(sk.arc[last] >= kLongRadii * radius)) return false;
    Vec3 chord = sk.centre[last] - sk.centre[0];
    const bool has_chord = normalize(chord);
    double stray = 0;
    for (uint32_t i = 1; i < last; ++i) {
        Vec3 d = sk.centre[i] - sk.centre[0];
        if (has_chord) d = d - scaled(chord, dot(d, chord));
        const double off = std::sqrt(dot(d, d));
        stray = off > stray ? off : stray;
        if (turn_radius(sk.centre[i - 1], sk.centre[i], sk.centre[i + 1]) < kTightestTurn * radius)
            return false;
    }
    return stray >= kStrayRadii * radius;
}

// The skeleton of the kept points of `in` (see above), in `sk`; false where the object is
// not one bent chain of rings. *unbranched: every band held one ring (bent or not).
static inline bool find_skeleton(const TubeInput& in, Arena& arena, Skeleton& sk,
                                 bool* unbranched) {
    *unbranched = false;
    SkeletonMemory m;
    const size_t samples = skeleton_sample_count(in.sums.valid);
    allocate_skeleton_scratch(m, samples, arena);
    if (arena.failed || samples < 4 * kMinRingPoints) return false;
    // By a hash of the coordinates (sampled_point): every k-th point in input order could
    // fall in step with a scanner's rows.
    const uint32_t step = sample_step(in.sums.valid, kSkeletonSample);
    size_t n = 0;
    for (size_t i = 0; i < in.count && n < samples; ++i)
        if (in.reader.valid(i) && sampled_point(in.reader.point(i), step)) m.sample[n++] = in.reader.point(i);
    const CloudReader sample = {reinterpret_cast<const unsigned char*>(m.sample), sizeof(Vec3), false,
                                nullptr};
    const CloudBox box = box_of(sample, n);
    const double decile = nearest_spacing(sample, n, box, m.graph.grid, kSpacingSample);
    SkeletonGraph& g = m.graph;
    g.reach = kReachDeciles * decile;
    if (!(g.reach > 0) || !is_finite(g.reach)) return false;
    g.count = sort_into_cells(sample, n, box.low, g.reach, g.grid);
    for (size_t j = 0; j < g.count; ++j) g.grid.sorted[j] = m.sample[g.grid.items[j].index];
    link_neighbours(g);

    // The largest connected piece, and in it the point farthest from the sample's centre.
    for (size_t j = 0; j < g.count; ++j) m.parent[j] = static_cast<uint32_t>(j), m.size[j] = 0;
    for (size_t j = 0; j < g.count; ++j)
        for_each_neighbour(g, j, [&](size_t k) {
            join_roots(m.parent, static_cast<uint32_t>(j), static_cast<uint32_t>(k));
        });
    uint32_t main = 0;
    for (size_t j = 0; j < g.count; ++j) {
        const uint32_t r = find_root(m.parent, static_cast<uint32_t>(j));
        if (++m.size[r] > m.size[main] || (m.size[r] == m.size[main] && r < main)) main = r;
    }
    const Vec3 middle = scaled(box.low + box.high, 0.5);
    uint32_t extreme = main;
    double farthest = -1;
    for (size_t j = 0; j < g.count; ++j) {
        if (find_root(m.parent, static_cast<uint32_t>(j)) != main) continue;
        const Vec3 d = g.grid.sorted[j] - middle;
        if (dot(d, d) > farthest) farthest = dot(d, d), extreme = static_cast<uint32_t>(j);
    }
    // An end of the object, then the distance from it.
    const uint32_t end = geodesic_distance(m, extreme);
    const uint32_t other_end = geodesic_distance(m, end);
    const double length = m.distance[other_end];
    const double width = length / kMostBands > 2 * g.reach ? length / kMostBands : 2 * g.reach;
    const uint32_t bands = band_of(length, width, kMostBands + 1) + 1;
    if (bands < 4) return false;

    // Rings: the band's pieces joined within the band.
    for (size_t j = 0; j < g.count; ++j) m.parent[j] = static_cast<uint32_t>(j), m.size[j] = 0;
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached) continue;
        const uint32_t bj = band_of(m.distance[j], width, bands);
        for_each_neighbour(g, j, [&](size_t k) {
            if (band_of(m.distance[k], width, bands) == bj)
                join_roots(m.parent, static_cast<uint32_t>(j), static_cast<uint32_t>(k));
        });
    }
    for (uint32_t b = 0; b < bands; ++b)
        m.band_points[b] = 0, m.band_rings[b] = 0, m.band_centre[b] = {0, 0, 0}, m.band_radius[b] = 0;
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached) continue;
        const uint32_t b = band_of(m.distance[j], width, bands);
        ++m.size[find_root(m.parent, static_cast<uint32_t>(j))];
        ++m.band_points[b];
        m.band_centre[b] = m.band_centre[b] + g.grid.sorted[j];
    }
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached || m.parent[j] != j) continue;
        const uint32_t b = band_of(m.distance[j], width, bands);
        if (m.size[j] >= kMinRingPoints && kRingShare * m.size[j] >= m.band_points[b]) ++m.band_rings[b];
        if (m.band_rings[b] > 1) return false;  // a branch, or a handle
    }
    for (uint32_t b = 0; b < bands; ++b)
        if (m.band_points[b] > 0) m.band_centre[b] = scaled(m.band_centre[b], 1.0 / m.band_points[b]);
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached) continue;
        const uint32_t b = band_of(m.distance[j], width, bands);
        const Vec3 d = g.grid.sorted[j] - m.band_centre[b];
        m.band_radius[b] += std::sqrt(dot(d, d)) / m.band_points[b];
    }
    fit_ring_circles(m, bands, width);
    // The rings' median radius, and the bands within one radius of either end left out:
    // a ring there may be part of the end's rim, its centre off the centre line.
    uint32_t with_points = 0;
    for (uint32_t b = 0; b < bands; ++b)
        if (m.band_points[b] > 0) m.distance[with_points++] = m.band_radius[b];
    heap_sort(m.distance, with_points);
    const double radius = m.distance[with_points / 2];
    const double end_bands = std::ceil(radius / width);
    if (!(end_bands < bands / 2.0 - 2)) return false;
    const uint32_t skip = static_cast<uint32_t>(end_bands);
    if (!chain_nodes(m, skip, bands - 1 - skip, sk)) return false;
    *unbranched = true;
    return bent_enough(sk, radius);
}

// The frame across the skeleton at segment j, parameter t clamped to [0, 1] (the frame
// interpolated between the segment's nodes).
static inline void skeleton_frame(const Skeleton& sk, uint32_t j, double t, Vec3& tangent,
                                  Vec3& normal, Vec3& binormal) {
    const double u = t < 0 ? 0 : t > 1 ? 1 : t;
    tangent = scaled(sk.tangent[j], 1 - u) + scaled(sk.tangent[j + 1], u);
    normal = scaled(sk.normal[j], 1 - u) + scaled(sk.normal[j + 1], u);
    if (!normalize(tangent)) tangent = sk.tangent[j];
    normal = normal - scaled(tangent, dot(normal, tangent));
    if (!normalize(normal)) normal = sk.normal[j];
    binormal = cross(tangent, normal);
}

// Point p in straightened coordinates: across its nearest segment of the skeleton (the
// ends' segments reach on beyond their ends) and along it.
static inline Vec3 straightened(const Skeleton& sk, Vec3 p) {
    const uint32_t last = sk.count - 2;  // the last segment
    uint32_t best = 0;
    double best_t = 0, best_d2 = DBL_MAX;
    for (uint32_t j = 0; j <= last; ++j) {
        const Vec3 e = sk.centre[j + 1] - sk.centre[j];
        double t = dot(p - sk.centre[j], e) / dot(e, e);
        if (t < 0 && j > 0) t = 0;
        if (t > 1 && j < last) t = 1;
        const Vec3 d = p - (sk.centre[j] + scaled(e, t));
        if (dot(d, d) < best_d2) best_d2 = dot(d, d), best = j, best_t = t;
    }
    Vec3 tangent, normal, binormal;
    skeleton_frame(sk, best, best_t, tangent, normal, binormal);
    const Vec3 e = sk.centre[best + 1] - sk.centre[best];
    const Vec3 d = p - (sk.centre[best] + scaled(e, best_t));
    const double along = sk.arc[best] + best_t * (sk.arc[best + 1] - sk.arc[best]);
    return {dot(d, normal), dot(d, binormal), along + dot(d, tangent)};
}

// A straightened point back in the cloud's space (on the skeleton's frame at its arc length).
static inline Vec3 unstraightened(const Skeleton& sk, Vec3 q) {
    uint32_t j = 0;
    while (j + 2 < sk.count && q.z > sk.arc[j + 1]) ++j;
    const double t = (q.z - sk.arc[j]) / (sk.arc[j + 1] - sk.arc[j]);
    Vec3 tangent, normal, binormal;
    skeleton_frame(sk, j, t, tangent, normal, binormal);
    const Vec3 on = sk.centre[j] + scaled(sk.centre[j + 1] - sk.centre[j], t);
    return on + scaled(normal, q.x) + scaled(binormal, q.y);
}

// Whether reconstruct() looks for a bent skeleton: where it chooses the axis and the
// layers itself, and looks for parts (the skeleton also says where there are none).
static inline bool follows_bends(const TubeRequest& request) {
    return kFindParts && request.parts != Parts::one_tube && request.axis == Axis::automatic &&
           !request.origin && request.layers.cut_count == 0 && request.layers.count == 0 &&
           !(request.layers.height > 0);
}

// The straightened cloud: three doubles a point, while the tube is meshed.
static inline double* allocate_straightened(size_t count, Arena& arena) {
    return arena.alloc<double>(count > SIZE_MAX / 3 ? SIZE_MAX : 3 * count);
}

// The skeleton, then either the scratch that finds it or the straightened cloud and the tube.
static inline size_t bent_workspace_size(size_t point_count, const TubeRequest& request) {
    Arena arena = Arena::measuring();
    Skeleton sk;
    allocate_skeleton(sk, arena);
    const size_t kept = arena.required_bytes();
    SkeletonMemory m;
    allocate_skeleton_scratch(m, skeleton_sample_count(point_count), arena);
    const size_t scratch = arena.required_bytes() - kept;
    Arena straightened = Arena::measuring();
    allocate_straightened(point_count, straightened);
    TubeRequest along = request;
    along.axis = Axis::z;
    const size_t tube = tube_workspace_size(point_count, along);
    const size_t cloud = straightened.required_bytes();
    if (arena.failed || straightened.failed || tube == 0 || tube > SIZE_MAX - cloud ||
        cloud + tube > SIZE_MAX - kept)
        return 0;
    return kept + (cloud + tube > scratch ? cloud + tube : scratch);
}

// Where the object bends (find_skeleton), meshes it as one tube in straightened
// coordinates and sets *bent; otherwise leaves everything as it was, and sets *unbranched
// where every band held one ring: a straight object that does not branch, which needs no
// search for parts. The report's axis is then the skeleton's tangent at its start
// (axis_origin the start), its layers' bottom and top arc lengths along the skeleton, their
// centres in the cloud's space.
static inline Status mesh_if_bent(const TubeInput& in, const TubeRequest& request, Arena& arena,
                                  uint32_t* triangles, size_t triangle_capacity,
                                  size_t* triangle_count, Report& rep, bool* bent,
                                  bool* unbranched) {
    *bent = false;
    const size_t start = arena.mark();
    Skeleton sk;
    allocate_skeleton(sk, arena);
    const size_t scratch = arena.mark();
    const bool found = !arena.failed && find_skeleton(in, arena, sk, unbranched);
    arena.rewind(scratch);
    double* xyz = found ? allocate_straightened(in.count, arena) : nullptr;
    if (arena.failed) {
        rep.detail = "the workspace is smaller than reconstruct_workspace_size()";
        return Status::out_of_memory;
    }
    if (!found) {
        arena.rewind(start);
        return Status::ok;
    }
    *bent = true;
    for (size_t i = 0; i < in.count; ++i) {
        const Vec3 p = in.reader.point(i);  // left as it is where it is not valid
        const Vec3 q = in.reader.valid(i) ? straightened(sk, p) : p;
        xyz[3 * i] = q.x, xyz[3 * i + 1] = q.y, xyz[3 * i + 2] = q.z;
    }
    TubeInput along = {{reinterpret_cast<const unsigned char*>(xyz), 3 * sizeof(double), false,
                        in.reader.dropped},
                       in.count, {}};
    along.sums = sum_cloud(along.reader, in.count);
    TubeRequest straight = request;
    straight.axis = Axis::z;
    const Status status =
        mesh_tube(along, straight, arena, triangles, triangle_capacity, triangle_count, rep);
    rep.layers.skeleton_node_count = sk.count;
    const Vec3 axis = sk.tangent[0], origin = sk.centre[0];
    rep.axis[0] = axis.x, rep.axis[1] = axis.y, rep.axis[2] = axis.z;
    rep.axis_origin[0] = origin.x, rep.axis_origin[1] = origin.y, rep.axis_origin[2] = origin.z;
    const size_t described = rep.layers.info_capacity < rep.layers.used_count
                                  ? rep.layers.info_capacity : rep.layers.used_count;
    for (size_t l = 0; rep.layers.info && l < described; ++l) {
        double* c = rep.layers.info[l].centre;
        const Vec3 back = unstraightened(sk, {c[0], c[1], c[2]});
        c[0] = back.x, c[1] = back.y, c[2] = back.z;
    }
    return status;
}

}  // namespace detail
}  // namespace stratmesh

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

// >>config restore ==========================================================================
// Undoes what >>config set: its helper macros and the pinned contraction.

#undef STRATMESH_SMALL_NOINLINE
#undef STRATMESH_FAST_NOINLINE
#undef STRATMESH_NOINLINE

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#elif defined(__clang__)
#pragma STDC FP_CONTRACT DEFAULT
#endif

#endif // STRATMESH_IMPLEMENTATION

/*
------------------------------------------------------------------------------------------
MIT License

Copyright (c) 2026 the stratmesh authors

Permission is hereby granted, free of charge, to any person obtaining a copy of this
software and associated documentation files (the "Software"), to deal in the Software
without restriction, including without limitation the rights to use, copy, modify, merge,
publish, distribute, sublicense, and/or sell copies of the Software, and to permit persons
to whom the Software is furnished to do so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all copies or
substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR IMPLIED,
INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS FOR A PARTICULAR
PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT HOLDERS BE LIABLE
FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR
OTHERWISE, ARISING FROM, OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER
DEALINGS IN THE SOFTWARE.
------------------------------------------------------------------------------------------
*/
