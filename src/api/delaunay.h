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
