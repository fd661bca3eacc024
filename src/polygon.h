// >>polygon ==============================================================================
// Simple polygons on the exact predicates: crossing edges, containment.

namespace stratmesh {
namespace detail {

inline bool same_point(const double* a, const double* b) { return a[0] == b[0] && a[1] == b[1]; }

// For p collinear with a and b: whether it lies on the closed segment ab.
inline bool on_segment(const double* a, const double* b, const double* p) {
    for (int k = 0; k < 2; ++k) {
        double low = a[k] < b[k] ? a[k] : b[k], high = a[k] < b[k] ? b[k] : a[k];
        if (p[k] < low || p[k] > high) return false;
    }
    return true;
}

// -1, 0 or 1 as x is below, at or above y: the sign of x - y, without rounding.
inline int compare(double x, double y) { return (x > y) - (x < y); }

// Whether the closed segments pq and rs share a point.
inline bool segments_meet(const double* p, const double* q, const double* r, const double* s) {
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
inline bool polygon_is_simple(const double* xy, uint32_t length, uint64_t* sweep) {
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
inline bool in_closed_triangle(const double* a, const double* b, const double* c, const double* p) {
    return orient2d_robust(a, b, p) >= 0 && orient2d_robust(b, c, p) >= 0 &&
           orient2d_robust(c, a, p) >= 0;
}

}  // namespace detail
}  // namespace stratmesh
