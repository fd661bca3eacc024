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
