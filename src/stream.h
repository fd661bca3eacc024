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
