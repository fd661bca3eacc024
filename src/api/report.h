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
