#if !defined(STRATMESH_SMALL_CODE)

// ---- Where the cloud parts into branches ----
//
// One tube cannot follow an object that forks (the horns on a head, the fingers of a hand,
// the condyles at a femur's end): it wraps the branches and the gaps between them.
// find_parting() finds where along the axis the cloud parts: the lowest cut above which
// the points make two separate branches or more, and the highest below which they do.
// reconstruct() uses it by default; a caller can also mesh each side on its own, the
// branches with ends_are_cuts, and join them with join_branches().
//
// Points join one piece when they lie within Parting::gap of each other (single linkage).
// The gap is four times the median distance from a point to its nearest distinct
// neighbour (on every k-th point in the order of a grid, at most 2,048 of them): the
// points of one branch lie closer, the branches of a fork farther apart. Cuts are tried
// every half gap along the axis (at most one per point). A side of a cut parts when it is
// four gaps thick or more (a thinner one is a rim, which falls apart into arcs). Its pieces
// count from kSmallestBranch points and a twentieth of the side's (specks and scraps do not
// make a branch); of those, the ones whose nearest point lies within a gap of the cut start
// there, the others are left aside (a patch that a hole in the scan cut off, the tip of a
// thin branch sampled too sparsely to stay joined to it). The side parts when two pieces
// or more start at the cut and every one of them is a branch: its farthest point lies two
// gaps or more from the cut (else it is a bump, or the crown of a skull between two horns),
// and the centroids of its points within a gap of the cut and within the next gap lie less
// than two gaps apart across the axis (else it is a cap joined to a branch, whose section
// jumps). So horns above a skull are found; the condyles of a femur, which part for only
// a gap below their notch, are not, as a bump would not be.

// Bytes of workspace find_parting() needs for point_count points (about 100 a point);
// 0 if that is beyond what this platform can address.
size_t find_parting_workspace_size(size_t point_count, const Options& options);


// Finds where the cloud parts into branches (see above). options: axis, direction, and
// the flags skip_invalid_points and drop_outliers (outliers are left out first); the rest
// is not used. The same axis as reconstruct() with these options. Deterministic; another
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
// find_parting's branch_of its own reconstruct(), as reconstruct() does by default),
// into one surface. At each side that parts, the trunk's boundary loop nearest the
// branches (the highest of the loops whose points are all kInTrunk, seen from that side)
// is joined to each branch's loop nearest the cut: the trunk's loop is split at the gaps
// between the branches, in their order around the trunk's centre (the vertex whose angle
// is nearest the middle of each gap); each arc is zipped to its branch's whole loop, which
// is opened at its point nearest the trunk's centre (the two chains merged in the order of
// their angle around the branch's centre, which crosses itself far less than shortest
// diagonals first, as contour stitching does); and the crotch is closed by a triangle per
// gap, from the trunk's vertex there to the two branches' opening points, and a fan over
// those points where three branches or more meet.
//
//       trunk's loop   ... m0 ---- branch 1's arc ---- m1 ---- branch 2's arc ---- m0 ...
//       branch loops   p1 (opened) around to p1        p2 (opened) around to p2
//       crotch         (p1, m1, p2) and (p2, m0, p1)
//
// The new triangles run each loop's edges against the surface's direction, and every
// vertex keeps one fan, so a surface that is an oriented edge- and vertex-manifold (as
// reconstruct()'s) stays one, whatever the geometry. The geometry decides whether a side
// is joined (else it is counted in apart_side_count, the reason in detail): the trunk's
// loop must lie within four gaps of the cut (a trunk closed there keeps only its far
// loop), at least two branches must have a loop there whose points are all theirs, each
// branch's centre must lie within the trunk loop's mean radius across the axis, and the
// gaps must follow one another along the trunk's loop.
//
// Where that fails (branches standing on a closed end, as horns on a skull: no trunk loop
// goes around them), each branch is grafted instead: the trunk's triangles under the
// branch's loop (seen along the axis, facing the branch, within four gaps below it) are
// taken out as a disc that keeps every vertex on a triangle, and the hole's loop is zipped
// to the branch's by angle around the branch's centre. Such a disc never takes a triangle
// with a corner on the surface's boundary, so where a small gap in the trunk's end (at
// most 32 vertices) has a corner on the triangle under the branch's centre, the gap is
// closed first (its loop triangulated, no vertex added) and the disc may take that
// triangle; what the hole leaves of the closing stays, one gap fewer. The surface stays an
// oriented edge- and vertex-manifold and every point stays a vertex; the band can cross
// the trunk's triangles beside the stump where the stump's wall leans over the hole. A
// graft needs the cut square to the fork: with the axis tilted two degrees within the
// fork's plane, the cut runs lower under one branch, no triangle of the trunk's end faces
// it under its loop, and that side stays apart. reconstruct() therefore cuts square to the
// trunk's own axis.
struct JoinReport {
    size_t joined_side_count;        // 0, 1 or 2
    size_t apart_side_count;         // sides that part whose loops could not be joined (detail)
    size_t grafted_branch_count;     // branches joined through a hole in the trunk's closed end
    size_t junction_triangle_count;  // triangles the junctions added
    size_t removed_triangle_count;   // the trunk's triangles the holes took out
    size_t workspace_used_bytes;     // peak workspace bytes, from the start of the buffer
    const char* detail;              // a static sentence on why, on failure or a side left apart
};

// Bytes of workspace join_branches() needs for a surface of triangle_count triangles over
// point_count points: 9 bytes a point, plus the larger of 12 a point and 12 a triangle (the
// loops' tracing) and 8 a point, 1 a triangle, 56 for each triangle up to 65,536 and 15,600
// for the gaps' closings (the grafts); 0 if that is beyond what this platform can address.
size_t join_branches_workspace_size(size_t point_count, size_t triangle_count);

// The most triangles join_branches() adds: one per vertex of a loop it zips, four per
// branch (each point on one loop at most) and 1,200 for the gaps the grafts close.
size_t join_branches_max_triangles(size_t point_count);

// Takes the grafts' holes out of triangles[0 .. 3 * *triangle_count) (indices into
// `cloud`; the triangles kept stay in their order, removed_triangle_count fewer), appends the
// junctions' triangles and sets *triangle_count to the new total. parting and branch_of:
// find_parting()'s on the same cloud (its axis is used); options: skip_invalid_points is
// used, the rest only checked (a flag bit Flags does not define, or a Parts value outside
// the enum, is invalid_argument). report (optional) is filled on every status. Returns ok
// (a side counts as joined when all its branches are; the others in apart_side_count, their branches grafted where
// they could be, the rest of their triangles left as they were); invalid_argument (a
// null triangle_count, branch_of, workspace or triangles where needed; a bad stride or
// scalar; *triangle_count above triangle_capacity; an index outside the cloud or naming an
// invalid point; buffers sharing a byte); too_many_points; invalid_point (a NaN or infinite point
// without skip_invalid_points); invalid_axis (a parting whose axis is zero or not finite);
// out_of_memory (a workspace below join_branches_workspace_size()); triangle_capacity
// (*triangle_count set to the triangles needed; nothing written). On every status but ok
// the triangles are unchanged. On a surface that is not a vertex-manifold the call stays
// within its buffers, but the junctions may join edges that were already full.
Status join_branches(const Cloud& cloud, const Options& options, const Parting& parting,
                     const uint8_t* branch_of, void* workspace, size_t workspace_bytes,
                     uint32_t* triangles, size_t triangle_capacity, size_t* triangle_count,
                     JoinReport* report);
#endif
