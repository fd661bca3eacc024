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
