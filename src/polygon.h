// >>polygon ==============================================================================
// Simple polygons on the exact predicates: crossing edges, winding, ear clipping.

namespace stratmesh {
namespace detail {

static inline bool same_point(const double* a, const double* b) { return a[0] == b[0] && a[1] == b[1]; }

// For p collinear with a and b: whether it lies on the closed segment ab.
static inline bool on_segment(const double* a, const double* b, const double* p) {
    for (int k = 0; k < 2; ++k) {
        double low = a[k] < b[k] ? a[k] : b[k], high = a[k] < b[k] ? b[k] : a[k];
        if (p[k] < low || p[k] > high) return false;
    }
    return true;
}

// -1, 0 or 1 as x is below, at or above y: the sign of x - y, without rounding.
static inline int compare(double x, double y) { return (x > y) - (x < y); }

// Whether the closed segments pq and rs share a point.
static inline bool segments_meet(const double* p, const double* q, const double* r, const double* s) {
    double d1 = orient2d_robust(r, s, p), d2 = orient2d_robust(r, s, q);
    double d3 = orient2d_robust(p, q, r), d4 = orient2d_robust(p, q, s);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
        return true;
    return (d1 == 0 && on_segment(r, s, p)) || (d2 == 0 && on_segment(r, s, q)) ||
           (d3 == 0 && on_segment(p, q, r)) || (d4 == 0 && on_segment(p, q, s));
}

// Whether the closed polygon xy[0 .. length) is simple: no repeated point, no edge folding
// back onto the next, no two other edges meeting. Edges are swept in order of their
// smaller x; each is tested against those whose x range reaches into its own.
static inline bool polygon_is_simple(const double* xy, uint32_t length, uint64_t* sweep) {
    if (length < 3) return false;
    auto at = [&](uint32_t i) { return xy + 2 * static_cast<size_t>(i); };
    for (uint32_t i = 0; i < length; ++i) {
        const double* a = at(i == 0 ? length - 1 : i - 1);
        const double* b = at(i);
        const double* c = at(i + 1 == length ? 0 : i + 1);
        if (same_point(b, c)) return false;
        // Collinear neighbours on the same side of b: the two edges overlap.
        if (orient2d_robust(a, b, c) == 0 && compare(a[0], b[0]) == compare(c[0], b[0]) &&
            compare(a[1], b[1]) == compare(c[1], b[1]))
            return false;
    }
    for (uint32_t e = 0; e < length; ++e) {
        const double* a = at(e);
        const double* b = at(e + 1 == length ? 0 : e + 1);
        sweep[e] = uint64_t{sweep_key(a[0] < b[0] ? a[0] : b[0])} << 32 | e;
    }
    heap_sort(sweep, length);
    for (uint32_t i = 0; i < length; ++i) {
        uint32_t e = static_cast<uint32_t>(sweep[i]), e_end = e + 1 == length ? 0 : e + 1;
        const double* a = at(e);
        const double* b = at(e_end);
        const uint32_t right = sweep_key(a[0] < b[0] ? b[0] : a[0]);
        double low = a[1] < b[1] ? a[1] : b[1], high = a[1] < b[1] ? b[1] : a[1];
        for (uint32_t j = i + 1; j < length && (sweep[j] >> 32) <= right; ++j) {
            uint32_t f = static_cast<uint32_t>(sweep[j]), f_end = f + 1 == length ? 0 : f + 1;
            if (f == e_end || f_end == e) continue;  // neighbours: checked above
            const double* c = at(f);
            const double* d = at(f_end);
            if ((c[1] < low && d[1] < low) || (c[1] > high && d[1] > high)) continue;
            if (segments_meet(a, b, c, d)) return false;
        }
    }
    return true;
}

// Whether p lies in the closed triangle abc (counter-clockwise).
static inline bool in_closed_triangle(const double* a, const double* b, const double* c, const double* p) {
    return orient2d_robust(a, b, p) >= 0 && orient2d_robust(b, c, p) >= 0 &&
           orient2d_robust(c, a, p) >= 0;
}

// Whether corners i and j of the simple counter-clockwise polygon xy[0 .. length) see each
// other through it: the segment leaves both corners into the polygon and meets no edge that
// does not end at i or j (touching one counts as meeting it).
static inline bool diagonal_inside(const double* xy, uint32_t length, uint32_t i, uint32_t j) {
    auto point = [xy](uint32_t k) { return xy + 2 * static_cast<size_t>(k); };
    auto within_corner = [&](uint32_t a, uint32_t b) {
        const double* pa = point(a);
        const double* pb = point(b);
        const double* before = point(a == 0 ? length - 1 : a - 1);
        const double* after = point(a + 1 == length ? 0 : a + 1);
        if (orient2d_robust(before, pa, after) > 0)
            return orient2d_robust(pa, pb, before) > 0 && orient2d_robust(pb, pa, after) > 0;
        return !(orient2d_robust(pa, pb, after) >= 0 && orient2d_robust(pb, pa, before) >= 0);
    };
    if (!within_corner(i, j) || !within_corner(j, i)) return false;
    const double* pi = point(i);
    const double* pj = point(j);
    for (uint32_t a = 0; a < length; ++a) {
        const uint32_t b = a + 1 == length ? 0 : a + 1;
        if (a == i || a == j || b == i || b == j) continue;
        const double oa = orient2d_robust(pi, pj, point(a));
        const double ob = orient2d_robust(pi, pj, point(b));
        if ((oa > 0 && ob > 0) || (oa < 0 && ob < 0)) continue;
        const double oi = orient2d_robust(point(a), point(b), pi);
        const double oj = orient2d_robust(point(a), point(b), pj);
        if ((oi > 0 && oj > 0) || (oi < 0 && oj < 0)) continue;
        return false;
    }
    return true;
}

// The turning direction of the simple polygon xy[0 .. length): orient2d at its
// lexicographically lowest corner, which is strictly convex; positive counter-clockwise.
static inline double simple_polygon_turn(const double* xy, uint32_t length) {
    auto at = [xy](uint32_t i) { return xy + 2 * static_cast<size_t>(i); };
    uint32_t lowest = 0;
    for (uint32_t i = 1; i < length; ++i)
        if (lex_less(at(i), at(lowest))) lowest = i;
    return orient2d_robust(at(lowest == 0 ? length - 1 : lowest - 1), at(lowest),
                           at(lowest + 1 == length ? 0 : lowest + 1));
}

// A corner of a polygon whose corners are computed as they are read.
struct Point2 {
    double xy[2];
};

// How many times the closed polygon of corners point(0), ..., point(length - 1) winds around
// p, counter-clockwise positive: an edge that crosses the line through p along x (half-open:
// from at or below p to above it, or back) counts +1 going up with p on its left, -1 going
// down with p on its right, by orient2d. Odd where the even-odd rule has p inside; for p on
// the polygon, the count of a region beside it.
template <class PointAt>
long winding_number(PointAt point, uint32_t length, const double* p) {
    long winding = 0;
    Point2 a = point(length - 1);
    for (uint32_t i = 0; i < length; ++i) {
        const Point2 b = point(i);
        if (a.xy[1] <= p[1]) {
            if (b.xy[1] > p[1] && orient2d_robust(a.xy, b.xy, p) > 0) ++winding;
        } else if (b.xy[1] <= p[1] && orient2d_robust(a.xy, b.xy, p) < 0) {
            --winding;
        }
        a = b;
    }
    return winding;
}

// ---- ear clipping
//
// The caps, their pockets and the small gaps a graft closes are all triangulated by
// clipping ears off a simple counter-clockwise polygon: a strictly convex corner whose
// closed triangle holds no other corner, and whose diagonal the caller allows (the
// callers forbid those already edges of the surface: the edge would join three
// triangles). Only corners that are not strictly convex need testing for containment (in
// a simple polygon, a triangle holding a corner holds one of those); clipping only narrows
// the corners beside an ear, so the list of them only shrinks. The walk goes on from the
// corner before each ear, or, where the caller asks, from the first corner left; it gives
// up once every corner left has failed in a row.

// The clipping's arrays, an entry per corner.
struct EarRing {
    uint32_t* prev;        // the neighbours in the polygon left to clip
    uint32_t* next;
    uint32_t* reflex;      // corners not strictly convex when last looked at
    unsigned char* flags;  // kReflex while in `reflex` and not strictly convex
};

const unsigned char kReflex = 1;

// What a caller of EarClipper decides: which diagonals may not be made, and what becomes of
// each ear.
class EarRules {
public:
    // Whether the diagonal between corners a and b may not be made.
    virtual bool forbidden(uint32_t a, uint32_t b) const = 0;
    // The ear (p, v, n), counter-clockwise: one of length - 2, the last of them the three
    // corners left at the end.
    virtual void take(uint32_t p, uint32_t v, uint32_t n) = 0;

protected:
    ~EarRules() = default;
};

// Where the walk goes on after an ear: from the corner before it, or from the first
// corner left (in the corners' order).
enum class EarWalk { from_previous, from_first };

class EarClipper {
public:
    // The polygon: corner i at xy[2 i], xy[2 i + 1], for i < length.
    EarClipper(const double* xy, uint32_t length, const EarRing& ring)
        : xy_(xy), length_(length), ring_(ring) {}

    // Clips the polygon from corner `start`, handing every ear to rules.take; false, after
    // the ears taken so far, where every corner left fails.
    bool clip(uint32_t start, EarWalk walk, EarRules& rules) {
        const uint32_t length = length_;
        reflex_count_ = 0;
        for (uint32_t i = 0; i < length; ++i) {
            ring_.prev[i] = i == 0 ? length - 1 : i - 1;
            ring_.next[i] = i + 1 == length ? 0 : i + 1;
            ring_.flags[i] = convex(i) ? 0 : kReflex;
            if (ring_.flags[i]) ring_.reflex[reflex_count_++] = i;
        }
        uint32_t remaining = length, v = start, first = 0, misses = 0;
        while (remaining > 3) {
            if (!is_ear(v, rules)) {
                v = ring_.next[v];
                if (++misses > remaining) return false;
                continue;
            }
            const uint32_t p = ring_.prev[v], n = ring_.next[v];
            rules.take(p, v, n);
            ring_.next[p] = n;
            ring_.prev[n] = p;
            settle(p);
            settle(n);
            if (v == first) first = n;
            --remaining;
            misses = 0;
            v = walk == EarWalk::from_first ? first : p;
        }
        // The last triangle, from the first corner left where the walk starts there.
        if (walk == EarWalk::from_first) v = ring_.next[first];
        if (!convex(v)) return false;
        rules.take(ring_.prev[v], v, ring_.next[v]);
        return true;
    }

private:
    const double* point(uint32_t i) const { return xy_ + 2 * static_cast<size_t>(i); }

    bool convex(uint32_t i) const {
        return orient2d_robust(point(ring_.prev[i]), point(i), point(ring_.next[i])) > 0;
    }

    void settle(uint32_t i) {
        if ((ring_.flags[i] & kReflex) && convex(i)) ring_.flags[i] = 0;
    }

    // Strictly convex, a diagonal the rules allow, and no other corner in the closed
    // triangle; the reflex list drops the corners clipped or turned convex on the way.
    bool is_ear(uint32_t v, const EarRules& rules) {
        if (ring_.flags[v] & kReflex) return false;
        const uint32_t p = ring_.prev[v], n = ring_.next[v];
        if (rules.forbidden(p, n)) return false;
        bool empty = true;
        uint32_t kept = 0;
        for (uint32_t k = 0; k < reflex_count_; ++k) {
            const uint32_t r = ring_.reflex[k];
            if (ring_.flags[r] != kReflex) continue;
            ring_.reflex[kept++] = r;
            if (empty && r != p && r != n &&
                in_closed_triangle(point(p), point(v), point(n), point(r)))
                empty = false;
        }
        reflex_count_ = kept;
        return empty;
    }

    const double* xy_;
    uint32_t length_;
    EarRing ring_;
    uint32_t reflex_count_ = 0;
};

}  // namespace detail
}  // namespace stratmesh
