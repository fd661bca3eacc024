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
