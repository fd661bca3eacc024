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
