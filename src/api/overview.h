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
