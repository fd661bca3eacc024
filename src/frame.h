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
