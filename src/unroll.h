// >>unroll ===============================================================================
// A layer onto its annulus (cylinder and closed ends).
//
// Each layer is projected on a cylinder around its own centre, unrolled to (u, v) =
// (r theta, h) and rolled up again by the conformal map exp((v - v0)/r + i theta) onto a
// planar annulus: the bottom of the layer on the inner side, the top on the outer side.
// The map is conformal, so small triangles keep their shape and the 2D Delaunay criterion
// there is the unrolled one; and the seam along the cut generatrix is closed by
// construction: there is no cut. With a virtual vertex at the annulus centre, the Delaunay
// triangles not touching it are the layer's surface; its link is the layer's bottom loop,
// the convex hull its top loop. No trigonometry is needed: the direction of a point from
// the centre gives e^{i theta} directly.
//
// Centre: the mean of per-sector mean positions (kSectors sectors around the centroid), so
// a side scanned more densely does not pull the centre towards it. Radius: the mean
// distance of the points from that centre: it sets the unrolled aspect (arc length r theta
// against height), so triangles are well shaped on the surface, not only in the plane. A
// layer that folds around that centre may be unrolled around another (see "the centre
// search" in >>layer triangulation); the radius stays.
//
// Closed ends. A scan of a closed object (a bone, a bust on its base, a head's crown) has
// points across its ends, at about one height: on the cylinder a flat base puts every point
// of a radius on one place of the annulus, and a dome's top folds. So where the first or
// the last layer of the surface holds such an end (see find_closed_ends), the points beyond
// a pole height, one radius in from the end (at most three quarters of the layer), are
// projected from the pole (the point of the axis at that height) instead, onto the sphere
// around it, and that sphere is mapped stereographically: the direction at angle phi from
// the end's side of the axis goes to radius e^{(pole - h0)/r} tan(phi / 2) on the annulus
// (the bottom; the top inverts it). At the pole height both maps agree, with the same
// derivative, so the picture stays conformal across it for a dome of the layer's radius;
// the end's point nearest the axis becomes the centre's link (the bottom) or the hull (the
// top): the surface's boundary loop is a small loop around the pole instead of the end's
// rim, and the end is meshed across. On a flat-ended cylinder of 10,000 points the mean
// distance to the true surface fell 7.5 times with one layer (to CGAL's advancing front's),
// 5.6 times over 1 to 24 layers; on half-sphere ends 20%. Open ends are not touched.

namespace stratmesh {
namespace detail {

const uint32_t kSectors = 32;

// e^x with + - * only, so every platform computes the same bits. Arguments are clamped to
// [-64, 64] (a NaN counts as -64): the callers stay within kMaxTurns + 1, except for
// clouds so extreme that a radius overflows or underflows, which must not reach the
// float-to-integer conversion below with an out-of-range value. x = k ln2 / 32 + r with
// |r| <= ln2 / 64 and k = 32 q + j, so e^x = 2^q 2^(j / 32) e^r: the table's 2^(j / 32)
// are correctly rounded, and e^r's series to r^6 / 6! is within 4e-18 of it; within two
// ulp of glibc's exp over [-64, 64] (tests; one measured). The series to r^13 / 13! that
// a reduction to |r| <= ln2 / 2 needs took a fifth of triangulate_layer's own time on a
// tube.
static inline double exp_portable(double x) {
    if (!(x > -64)) x = -64;
    if (x > 64) x = 64;
    // ln2 / 32 in two parts, the first with 32 significant bits: k times it is exact.
    const double step_hi = 6.93147180369123816490e-01 / 32;
    const double step_lo = 1.90821492927058770002e-10 / 32;
    // floor(y) by truncation (|y| < 2956 here): std::floor is a library call per point on
    // x86-64's baseline, which has no rounding instruction (one instruction on ARM).
    const double y = x * (32 * 1.44269504088896338700) + 0.5;
    double k = kFastLoops ? static_cast<double>(static_cast<int32_t>(y)) : std::floor(y);
    if (kFastLoops && k > y) k -= 1;
    const double r = (x - k * step_hi) - k * step_lo;
    static constexpr double inverse_factorials[6] = {1.0 / 720.0, 1.0 / 120.0, 1.0 / 24.0,
                                                     1.0 / 6.0,   0.5,         1.0};
    double p = 0;
    for (double c : inverse_factorials) p = (p + c) * r;
    static constexpr double two_to_thirty_seconds[32] = {
        0x1.0000000000000p+0, 0x1.059b0d3158574p+0, 0x1.0b5586cf9890fp+0, 0x1.11301d0125b51p+0,
        0x1.172b83c7d517bp+0, 0x1.1d4873168b9aap+0, 0x1.2387a6e756238p+0, 0x1.29e9df51fdee1p+0,
        0x1.306fe0a31b715p+0, 0x1.371a7373aa9cbp+0, 0x1.3dea64c123422p+0, 0x1.44e086061892dp+0,
        0x1.4bfdad5362a27p+0, 0x1.5342b569d4f82p+0, 0x1.5ab07dd485429p+0, 0x1.6247eb03a5585p+0,
        0x1.6a09e667f3bcdp+0, 0x1.71f75e8ec5f74p+0, 0x1.7a11473eb0187p+0, 0x1.82589994cce13p+0,
        0x1.8ace5422aa0dbp+0, 0x1.93737b0cdc5e5p+0, 0x1.9c49182a3f090p+0, 0x1.a5503b23e255dp+0,
        0x1.ae89f995ad3adp+0, 0x1.b7f76f2fb5e47p+0, 0x1.c199bdd85529cp+0, 0x1.cb720dcef9069p+0,
        0x1.d5818dcfba487p+0, 0x1.dfc97337b9b5fp+0, 0x1.ea4afa2a490dap+0, 0x1.f50765b6e4540p+0};
    // k + 32 * 96 > 0: its low five bits are j, the others q + 96.
    const int32_t m = static_cast<int32_t>(k) + 32 * 96;
    const double table = two_to_thirty_seconds[m & 31];
    uint64_t bits = static_cast<uint64_t>((m >> 5) - 96 + 1023) << 52;
    double two_q;
    std::memcpy(&two_q, &bits, sizeof two_q);
    return (table + table * p) * two_q;
}

// A monotone stand-in for the polar angle of (dx, dy), in [0, 4): no trigonometry. The
// quadrant picks one of three values by index, not by branch: points in no angular order
// (a layer as the scanner wrote it) would mispredict half of the branches.
STRATMESH_SMALL_NOINLINE static inline double pseudo_angle(double dx, double dy) {
    double sum = abs_value(dx) + abs_value(dy);
    double t = sum > 0 ? dy / sum : 0;  // in [-1, 1]
    if (!kFastLoops) return dx >= 0 ? (t < 0 ? 4 + t : t) : 2 - t;
    const double angles[3] = {t, 4 + t, 2 - t};
    const bool left = !(dx >= 0);
    return angles[2 * static_cast<int>(left) + static_cast<int>(!left & (t < 0))];
}

// The polar angle of (dx, dy) in [0, 2 pi), with + - * / only (the same bits everywhere):
// two argument reductions bring the tangent below tan(pi / 12), where the odd Taylor series
// to x^21 is accurate to about 1e-15.
static inline double polar_angle(double dx, double dy) {
    const double pi = 3.14159265358979323846;
    const double sqrt3 = 1.73205080756887729353;
    double ax = abs_value(dx), ay = abs_value(dy);
    if (ax == 0 && ay == 0) return 0;
    bool swapped = ay > ax;
    double x = swapped ? ax / ay : ay / ax;  // in [0, 1]
    bool shifted = x > 0.26794919243112270;  // tan(pi / 12)
    if (shifted) x = (x * sqrt3 - 1) / (x + sqrt3);
    double x2 = x * x, term = x, sum = x;
    for (int k = 3; k <= 21; k += 2) {
        term *= -x2;
        sum += term / k;
    }
    if (shifted) sum += pi / 6;
    if (swapped) sum = pi / 2 - sum;
    if (dx < 0) sum = pi - sum;
    if (dy < 0) sum = 2 * pi - sum;
    return sum >= 2 * pi ? 0 : sum;
}

struct Cylinder {
    double cx, cy;   // centre across the axis
    double radius;   // unrolling radius
    double h0;       // height mapped to the unit circle
    double scale;    // 1 / max(radius, height / kMaxTurns)
    uint32_t poles;  // kLowPole, kHighPole: the ends projected from a pole (closed ends)
    double pole_low, pole_high;  // the poles' heights: below pole_low, above pole_high
};

const uint32_t kLowPole = closed_bottom, kHighPole = closed_top;

// Direction components smaller than this become 0. No scan resolves angles of 1e-18
// radians, and it keeps the annulus inside the predicates' exact range: radii in
// [e^-64, e^64] (2^-92 to 2^92; beyond a pole, tan(phi / 2) is kept in [2^-60, 1], so
// radii stay in [2^-60, e^24 2^60]) times components in [2^-60, 1] give coordinates, and
// coordinate differences, within a span of 2^296 < 2^320. Without it a cloud with one far
// outlier puts components near 2^-900 on the annulus, where the signs are not exact.
const double kSmallestDirection = 0x1p-60;

// The annulus radius of a point of height h at distance r from the axis: e^{(h - h0) *
// scale}, or beyond a pole the stereographic radius of its direction from the pole (see
// "closed ends" above).
static inline double annulus_radius(const Cylinder& c, double h, double r) {
    const bool low = kClosedEnds && (c.poles & kLowPole) && h < c.pole_low;
    const bool high = kClosedEnds && (c.poles & kHighPole) && h > c.pole_high;
    if (!low && !high) return exp_portable((h - c.h0) * c.scale);
    const double pole = low ? c.pole_low : c.pole_high, depth = low ? pole - h : h - pole;
    // tan(phi / 2) = sin(phi) / (1 + cos(phi)), phi from the axis beyond the pole.
    double half_tangent = r > 0 && is_finite(r) ? r / (depth + std::sqrt(r * r + depth * depth)) : 0;
    if (!(half_tangent > kSmallestDirection)) half_tangent = kSmallestDirection;
    const double at_pole = exp_portable((pole - c.h0) * c.scale);
    return low ? at_pole * half_tangent : at_pole / half_tangent;
}

// The point's place on the annulus: annulus_radius times its direction from the centre
// (points on the centre line take direction e1).
static inline void roll(const Cylinder& c, const Local& p, double* out) {
    double dx = p.x - c.cx, dy = p.y - c.cy;
    double r = std::sqrt(dx * dx + dy * dy);
    double rho = annulus_radius(c, p.h, r);
    if (r > 0 && is_finite(r)) {
        double u = dx / r, v = dy / r;
        out[0] = abs_value(u) < kSmallestDirection ? 0.0 : rho * u;
        out[1] = abs_value(v) < kSmallestDirection ? 0.0 : rho * v;
    } else {
        out[0] = rho;
        out[1] = 0;
    }
}

// The sectors around (cx, cy) that hold some of the points: bit k for sector k (kSectors
// is 32). Every k-th point, at most about kGapSamplePoints of them: a gap of a few sectors
// shows as well in a thousand points as in a million, and the look at every layer's
// neighbour then costs 1% of a tube's time instead of 10%.
const size_t kGapSamplePoints = 1024;

static inline size_t gap_sample_stride(size_t count) { return count / kGapSamplePoints + 1; }

// The sector of direction (dx, dy): kSectors of equal pseudo-angle, counter-clockwise.
static inline uint32_t sector_around(double dx, double dy) {
    const uint32_t s = static_cast<uint32_t>(pseudo_angle(dx, dy) * (kSectors / 4.0));
    return s < kSectors ? s : kSectors - 1;
}

template <class PointAt>
static inline uint32_t sectors_held(const PointAt& point_at, size_t count, double cx, double cy) {
    uint32_t held = 0;
    const size_t stride = gap_sample_stride(count);
    for (size_t i = 0; i < count; i += stride) {
        const Local& p = point_at(i);
        held |= 1u << sector_around(p.x - cx, p.y - cy);
    }
    return held;
}

// The most sectors in a row, around the circle, missing from `held`: 0 for a ring, about
// half of them for a half cylinder.
static inline uint32_t widest_gap(uint32_t held) {
    uint32_t widest = 0, run = 0;
    for (uint32_t k = 0; k < 2 * kSectors && widest < kSectors; ++k) {
        run = (held >> (k % kSectors)) & 1 ? 0 : run + 1;
        if (run > widest) widest = run;
    }
    return widest;
}

// Centre and radius of count points (frame coordinates; point_at(i) gives point i) for
// heights [h0, h1].
template <class PointAt>
static inline Cylinder fit_cylinder(const PointAt& point_at, size_t count, double h0, double h1) {
    double mx = 0, my = 0;
    for (size_t i = 0; i < count; ++i) {
        const Local& p = point_at(i);
        mx += p.x;
        my += p.y;
    }
    double inv = count ? 1.0 / static_cast<double>(count) : 0.0;
    mx *= inv;
    my *= inv;
    // Sector means around the centroid: sector from the signs and ratio of (dx, dy).
    double sx[kSectors] = {}, sy[kSectors] = {};
    uint32_t sn[kSectors] = {};
    for (size_t i = 0; i < count; ++i) {
        const Local& p = point_at(i);
        const uint32_t s = sector_around(p.x - mx, p.y - my);
        sx[s] += p.x;
        sy[s] += p.y;
        ++sn[s];
    }
    double cx = 0, cy = 0;
    uint32_t used = 0;
    for (uint32_t s = 0; s < kSectors; ++s) {
        if (!sn[s]) continue;
        cx += sx[s] / sn[s];
        cy += sy[s] / sn[s];
        ++used;
    }
    Cylinder c;
    c.cx = used ? cx / used : mx;
    c.cy = used ? cy / used : my;
    double rsum = 0;
    for (size_t i = 0; i < count; ++i) {
        const Local& p = point_at(i);
        double dx = p.x - c.cx, dy = p.y - c.cy;
        rsum += std::sqrt(dx * dx + dy * dy);
    }
    c.radius = rsum * inv;
    c.h0 = h0;
    double floor_radius = (h1 - h0) / kMaxTurns;
    double r = c.radius > floor_radius ? c.radius : floor_radius;
    c.scale = r > 0 && is_finite(r) ? 1.0 / r : 1.0;
    if (!is_finite(c.scale)) c.scale = 1.0;  // a subnormal radius
    c.poles = 0;
    c.pole_low = c.pole_high = h0;
    return c;
}

// Triangle abc's normal, twice its area long.
static inline Vec3 normal_of(const Local& pa, const Local& pb, const Local& pc) {
    return cross(Vec3{pb.x - pa.x, pb.y - pa.y, pb.h - pa.h},
                 Vec3{pc.x - pa.x, pc.y - pa.y, pc.h - pa.h});
}

static inline double doubled_area(const Local& pa, const Local& pb, const Local& pc) {
    Vec3 n = normal_of(pa, pb, pc);
    return std::sqrt(dot(n, n));
}

// Whether triangle abc (counter-clockwise seen from outside) has its normal pointing
// towards the cylinder's axis (beyond a pole: towards the pole): a fold.
static inline bool faces_axis(const Local& pa, const Local& pb, const Local& pc, const Cylinder& cyl) {
    Vec3 n = normal_of(pa, pb, pc);
    // From the axis (beyond a pole: the pole) to the centroid, three times over: only the
    // sign of its product with n counts, so no division.
    double rx = (pa.x + pb.x + pc.x) - 3 * cyl.cx;
    double ry = (pa.y + pb.y + pc.y) - 3 * cyl.cy;
    double h = pa.h + pb.h + pc.h, rh = 0;
    if (kClosedEnds && (cyl.poles & kLowPole) && h < 3 * cyl.pole_low) rh = h - 3 * cyl.pole_low;
    if (kClosedEnds && (cyl.poles & kHighPole) && h > 3 * cyl.pole_high)
        rh = h - 3 * cyl.pole_high;
    return n.x * rx + n.y * ry + n.z * rh < 0;
}

// Whether triangle t of a layer's triangulation is on the surface: neither a ghost nor at
// vertex 0, the centre (nor peeled: see peel_loop).
static inline bool on_surface(const Triangulation& tr, uint32_t t) {
    const uint32_t* v = tr.vertex + 3 * t;
    return !tr.is_ghost(t) && v[0] != 0 && v[1] != 0 && v[2] != 0;
}

// Asks for the cache line holding p ahead of its use, where the compiler offers a way
// (GCC, Clang): a hint, which changes nothing but the time.
static inline void prefetch(const void* p) {
#if defined(__GNUC__) || defined(__clang__)
    __builtin_prefetch(p);
#else
    (void)p;
#endif
}

// The surface triangles of a layer's triangulation that face its axis; vertex v is
// points[(v - 1) * stride]. Adds their doubled areas to *area if given. The triangles'
// slots are not in the points' order: with kFastLoops the corners a few triangles ahead
// are prefetched, as the loop otherwise waits on the cache for most of them.
static inline size_t count_folds(const Triangulation& tr, const Local* points, size_t stride,
                          const Cylinder& cyl, double* area) {
    size_t folds = 0;
    const uint32_t ahead = 12;
    for (uint32_t t = 0; t < tr.triangle_count; ++t) {
        if (kFastLoops && t + ahead < tr.triangle_count) {
            const uint32_t* w = tr.vertex + 3 * (t + ahead);
            for (uint32_t i = 0; i < 3; ++i)
                if (w[i] != 0 && w[i] != kGhost) prefetch(points + (w[i] - 1) * stride);
        }
        const uint32_t* v = tr.vertex + 3 * t;
        if (!on_surface(tr, t)) continue;
        const Local &a = points[(v[2] - 1) * stride], &b = points[(v[1] - 1) * stride],
                    &c = points[(v[0] - 1) * stride];
        folds += faces_axis(a, b, c, cyl);
        if (area) *area += doubled_area(a, b, c);
    }
    return folds;
}

// Where reconstructed triangles go: the caller's array, filled in order. Triangles are
// built counter-clockwise on the annulus, where the outside of the surface faces down,
// so they are written reversed. Counting continues past the capacity so the caller can
// be told what is needed; nothing is written past it.
struct TriangleSink {
    uint32_t* triangles;
    size_t capacity;
    size_t count;
    size_t folds;

    // Writes abc, given counter-clockwise on the annulus (so written reversed).
    void write(uint32_t a, uint32_t b, uint32_t c) {
        if (count < capacity) {
            triangles[3 * count] = a;
            triangles[3 * count + 1] = c;
            triangles[3 * count + 2] = b;
        }
        ++count;
    }

    // Writes abc and counts it if it is a fold (the vertices in frame coordinates).
    void emit(uint32_t a, uint32_t b, uint32_t c, const Local& pa, const Local& pb,
              const Local& pc, const Cylinder& cyl) {
        write(a, b, c);
        if (faces_axis(pa, pc, pb, cyl)) ++folds;
    }
};

}  // namespace detail
}  // namespace stratmesh
