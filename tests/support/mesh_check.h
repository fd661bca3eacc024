// An independent checker for a triangle mesh of a columnar surface, written for the tests
// without reference to stratmesh's implementation. Everything is checked exhaustively (no
// sampling):
//   - indices in range; degenerate triangles (a repeated index); zero-area triangles;
//   - edges: each undirected edge with its triangles; an edge in more than two triangles,
//     or in two that run it the same way (inconsistent orientation), is non-manifold;
//     boundary edges (one triangle) and the boundary loops they form;
//   - vertices: a used vertex whose incident triangles form more than one fan (triangles
//     linked through the edges at that vertex) is non-manifold;
//   - connected components of triangles (through shared edges);
//   - Euler characteristic V - E + F, V counting the vertices used;
//   - unused points, against an optional mask of the points expected to be used;
//   - orientation against an axis: a triangle faces outward when its normal
//     (b - a) x (c - a) has a positive dot product with centroid - (closest axis point);
//     the smallest cosine of that angle tells a flat sliver (about 0) from a real fold;
//   - deviation from an analytic surface (a callback giving a signed distance-like value)
//     at every triangle centroid and every edge midpoint, also reported over the triangles
//     and edges that touch no boundary vertex;
//   - self-intersections: every pair of triangles sharing no vertex whose bounding boxes
//     meet (found through a uniform grid over the bounding boxes, each pair tested once)
//     is tested with a triangle-triangle intersection test; pairs sharing exactly one
//     vertex are tested too, for an overlap beyond that vertex. Pairs sharing an edge are
//     not: they can only overlap folded flat onto each other, which the orientation count
//     shows. The grid costs about 5 ms for 4000 triangles and 60 ms for 40000.
//
// The intersection test, in doubles, follows Moller's interval-overlap idea written here
// from scratch: the signed distances of one triangle's vertices to the other's plane
// (snapped to zero within a tiny relative tolerance, and exactly zero for a shared vertex)
// give, on the line where the planes meet, the interval each triangle covers; the triangles
// intersect when the intervals overlap in a segment of positive length. Coplanar triangles
// intersect when they overlap with positive area (2D separating-axis test over the six edge
// normals, after dropping the normal's largest component). Touching in a single point
// does not count.

#ifndef STRATMESH_TESTS_SUPPORT_MESH_CHECK_H
#define STRATMESH_TESTS_SUPPORT_MESH_CHECK_H

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace mesh_check {

struct Input {
    const double* points = nullptr;  // x, y, z per point, packed
    size_t point_count = 0;
    const uint32_t* triangles = nullptr;  // 3 indices per triangle
    size_t triangle_count = 0;
    double axis_point[3] = {0, 0, 0};
    double axis_direction[3] = {0, 0, 1};  // any non-zero length
    // Optional: which points should be vertices (all of them when null).
    const std::vector<char>* expected_used = nullptr;
    // Optional: signed distance-like deviation of a point from the true surface.
    std::function<double(const double*)> surface;
    bool self_intersections = true;
};

struct Result {
    size_t bad_indices = 0;             // triangles with an index >= point_count (others skipped)
    size_t degenerate = 0;              // a repeated index
    size_t zero_area = 0;               // distinct indices but an exactly zero normal
    size_t edges = 0;                   // distinct undirected edges
    size_t boundary_edges = 0;          // in one triangle
    size_t nonmanifold_edges = 0;       // in more than two triangles
    size_t inconsistent_edges = 0;      // in two triangles running it the same way
    size_t nonmanifold_vertices = 0;    // incident triangles form more than one fan
    size_t boundary_loops = 0;          // connected pieces of the boundary edges
    bool simple_boundary = true;        // every boundary vertex: one boundary edge in, one out
    std::vector<size_t> loop_sizes;     // edges per boundary loop
    size_t components = 0;              // of triangles, through shared edges
    size_t vertices_used = 0;
    long long euler = 0;                // V - E + F
    size_t unused_expected = 0;         // expected to be used, but not a vertex
    size_t used_unexpected = 0;         // a vertex, but not expected to be used
    size_t outward = 0, inward = 0;     // by the sign of normal . radial direction
    double outward_fraction = 0;
    double min_outward_cosine = 1;      // of the angle between normal and radial direction
    size_t most_inward_triangle = 0;    // where that minimum is
    double max_centroid_deviation = 0;  // |surface(centroid)|, worst triangle
    double max_midpoint_deviation = 0;  // |surface(midpoint)|, worst edge
    double max_interior_deviation = 0;  // the same, over triangles and edges off the boundary
    size_t worst_triangle = 0;
    size_t intersecting_pairs = 0;      // triangles sharing no vertex that intersect
    size_t vertex_overlaps = 0;         // triangles sharing one vertex, overlapping beyond it
    size_t pairs_tested = 0;            // triangle-triangle tests run
    std::vector<std::pair<size_t, size_t>> intersection_examples;  // the first few

    bool oriented() const { return nonmanifold_edges == 0 && inconsistent_edges == 0; }
    bool manifold() const { return oriented() && nonmanifold_vertices == 0; }
    double max_deviation() const { return std::max(max_centroid_deviation, max_midpoint_deviation); }

    std::string summary() const {
        std::ostringstream s;
        s << "triangles: bad " << bad_indices << ", degenerate " << degenerate << ", zero-area "
          << zero_area << "; edges " << edges << " (boundary " << boundary_edges
          << ", non-manifold " << nonmanifold_edges << ", inconsistent " << inconsistent_edges
          << "); non-manifold vertices " << nonmanifold_vertices << "; boundary loops "
          << boundary_loops << (simple_boundary ? "" : " (not simple)") << " [";
        for (size_t k = 0; k < loop_sizes.size() && k < 8; ++k) s << (k ? " " : "") << loop_sizes[k];
        s << "]; components " << components << "; V " << vertices_used << " E " << edges
          << " Euler " << euler << "; unused expected " << unused_expected
          << ", used unexpected " << used_unexpected << "; outward " << outward << ", inward "
          << inward << " (min cosine " << min_outward_cosine << " at " << most_inward_triangle << "); deviation centroid " << max_centroid_deviation << " midpoint "
          << max_midpoint_deviation << " interior " << max_interior_deviation << "; intersecting pairs " << intersecting_pairs
          << ", vertex overlaps " << vertex_overlaps << " (" << pairs_tested << " tests)";
        for (const auto& e : intersection_examples) s << " [" << e.first << "," << e.second << "]";
        return s.str();
    }
};

namespace detail {

struct V3 {
    double x, y, z;
};
inline V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 add(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 mul(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double norm(V3 a) { return std::sqrt(dot(a, a)); }
inline double component(V3 a, int k) { return k == 0 ? a.x : k == 1 ? a.y : a.z; }

class UnionFind {
public:
    explicit UnionFind(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), size_t{0}); }
    size_t find(size_t a) {
        while (parent_[a] != a) {
            parent_[a] = parent_[parent_[a]];
            a = parent_[a];
        }
        return a;
    }
    bool unite(size_t a, size_t b) {
        a = find(a);
        b = find(b);
        if (a == b) return false;
        if (a < b) std::swap(a, b);
        parent_[a] = b;
        return true;
    }

private:
    std::vector<size_t> parent_;
};

// The interval covered on the line of direction d by triangle t, whose vertices have signed
// distances s[] to the other triangle's plane (not all of the same strict sign).
inline void line_interval(const V3 t[3], const double s[3], V3 d, double& lo, double& hi) {
    lo = HUGE_VAL;
    hi = -HUGE_VAL;
    auto take = [&](double v) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    };
    for (int i = 0; i < 3; ++i) {
        if (s[i] == 0) take(dot(t[i], d));
        int j = (i + 1) % 3;
        if ((s[i] < 0 && s[j] > 0) || (s[i] > 0 && s[j] < 0)) {
            double f = s[i] / (s[i] - s[j]);
            take(dot(add(t[i], mul(sub(t[j], t[i]), f)), d));
        }
    }
}

// Positive-area overlap of two coplanar triangles with normal n.
inline bool coplanar_overlap(const V3 p[3], const V3 q[3], V3 n, double tolerance) {
    int drop = 0;
    double big = std::fabs(n.x);
    if (std::fabs(n.y) > big) drop = 1, big = std::fabs(n.y);
    if (std::fabs(n.z) > big) drop = 2;
    int u = (drop + 1) % 3, v = (drop + 2) % 3;
    double a[3][2], b[3][2];
    for (int i = 0; i < 3; ++i) {
        a[i][0] = component(p[i], u), a[i][1] = component(p[i], v);
        b[i][0] = component(q[i], u), b[i][1] = component(q[i], v);
    }
    auto separated_along = [&](const double (*tri)[2], int e) {
        const double* s = tri[e];
        const double* t = tri[(e + 1) % 3];
        double nx = t[1] - s[1], ny = s[0] - t[0];
        double amin = HUGE_VAL, amax = -HUGE_VAL, bmin = HUGE_VAL, bmax = -HUGE_VAL;
        for (int i = 0; i < 3; ++i) {
            double pa = a[i][0] * nx + a[i][1] * ny, pb = b[i][0] * nx + b[i][1] * ny;
            amin = std::min(amin, pa), amax = std::max(amax, pa);
            bmin = std::min(bmin, pb), bmax = std::max(bmax, pb);
        }
        double slack = tolerance * std::sqrt(nx * nx + ny * ny);
        return amax <= bmin + slack || bmax <= amin + slack;
    };
    for (int e = 0; e < 3; ++e)
        if (separated_along(a, e) || separated_along(b, e)) return false;
    return true;
}

// A triangle prepared for intersection tests: vertices, plane normal and its length.
struct Prepared {
    V3 v[3];
    V3 normal;
    double length;
};

inline Prepared prepare(V3 a, V3 b, V3 c) {
    Prepared t = {{a, b, c}, cross(sub(b, a), sub(c, a)), 0};
    t.length = norm(t.normal);
    return t;
}

// Whether triangles p and q intersect in more than a point. shared_p / shared_q: the
// position in p and in q of their one shared vertex, or -1.
inline bool triangles_intersect(const Prepared& tp, const Prepared& tq, int shared_p, int shared_q) {
    const V3* p = tp.v;
    const V3* q = tq.v;
    if (tp.length == 0 || tq.length == 0) return false;  // zero-area triangles are counted apart
    // A bound on the distances involved: the extent of both triangles together.
    double extent = 0;
    for (int k = 0; k < 3; ++k) {
        double lo = HUGE_VAL, hi = -HUGE_VAL;
        for (int i = 0; i < 3; ++i) {
            double a = component(p[i], k), b = component(q[i], k);
            lo = std::min(lo, std::min(a, b));
            hi = std::max(hi, std::max(a, b));
        }
        extent = std::max(extent, hi - lo);
    }
    extent *= 1.7320508075688772;  // the diagonal
    const double rel = 1e-12;
    double sp[3], sq[3];
    const double tol_p = rel * tq.length * extent, tol_q = rel * tp.length * extent;
    for (int i = 0; i < 3; ++i) {
        sp[i] = dot(tq.normal, sub(p[i], q[0]));
        if (std::fabs(sp[i]) <= tol_p || i == shared_p) sp[i] = 0;
    }
    auto one_side = [](const double* s) {
        return (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0);
    };
    if (one_side(sp)) return false;
    for (int i = 0; i < 3; ++i) {
        sq[i] = dot(tp.normal, sub(q[i], p[0]));
        if (std::fabs(sq[i]) <= tol_q || i == shared_q) sq[i] = 0;
    }
    if (one_side(sq)) return false;
    bool coplanar = (sp[0] == 0 && sp[1] == 0 && sp[2] == 0) || (sq[0] == 0 && sq[1] == 0 && sq[2] == 0);
    if (coplanar) return coplanar_overlap(p, q, tq.normal, rel * extent);
    V3 d = cross(tp.normal, tq.normal);
    double d_len = norm(d);
    if (d_len == 0) return coplanar_overlap(p, q, tq.normal, rel * extent);
    d = mul(d, 1.0 / d_len);
    // Measure along the line from a point near both triangles, for precision.
    V3 origin = p[0];
    V3 pp[3], qq[3];
    for (int i = 0; i < 3; ++i) pp[i] = sub(p[i], origin), qq[i] = sub(q[i], origin);
    double p_lo, p_hi, q_lo, q_hi;
    line_interval(pp, sp, d, p_lo, p_hi);
    line_interval(qq, sq, d, q_lo, q_hi);
    double overlap = std::min(p_hi, q_hi) - std::max(p_lo, q_lo);
    return overlap > rel * extent;
}

// Convenience for tests of the test: the same on plain vertex arrays.
inline bool triangles_intersect(const V3 p[3], const V3 q[3], int shared_p = -1, int shared_q = -1) {
    return triangles_intersect(prepare(p[0], p[1], p[2]), prepare(q[0], q[1], q[2]), shared_p, shared_q);
}

}  // namespace detail

inline Result check(const Input& in) {
    using namespace detail;
    Result r;
    const size_t n = in.point_count;
    auto pt = [&](uint32_t i) { return V3{in.points[3 * size_t{i}], in.points[3 * size_t{i} + 1], in.points[3 * size_t{i} + 2]}; };

    // Triangles to analyse: indices in range and distinct.
    std::vector<size_t> good;
    good.reserve(in.triangle_count);
    for (size_t t = 0; t < in.triangle_count; ++t) {
        const uint32_t* v = in.triangles + 3 * t;
        if (v[0] >= n || v[1] >= n || v[2] >= n) {
            ++r.bad_indices;
            continue;
        }
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
            ++r.degenerate;
            continue;
        }
        good.push_back(t);
    }
    auto tri = [&](size_t t) { return in.triangles + 3 * t; };

    // Used vertices.
    std::vector<char> used(n, 0);
    for (size_t t : good)
        for (int k = 0; k < 3; ++k) used[tri(t)[k]] = 1;
    for (size_t i = 0; i < n; ++i) {
        r.vertices_used += used[i] ? 1u : 0u;
        bool expected = in.expected_used ? (*in.expected_used)[i] != 0 : true;
        if (expected && !used[i]) ++r.unused_expected;
        if (!expected && used[i]) ++r.used_unexpected;
    }

    // Edges: (low, high, triangle, forward) sorted by (low, high, triangle): a counting
    // sort by the low end, then a small sort within each bucket.
    struct HalfEdge {
        uint32_t lo, hi;
        size_t triangle;
        bool forward;  // the triangle runs lo -> hi
    };
    std::vector<HalfEdge> half(3 * good.size());
    {
        std::vector<size_t> bucket(n + 1, 0);
        for (size_t t : good)
            for (int k = 0; k < 3; ++k) ++bucket[std::min(tri(t)[k], tri(t)[(k + 1) % 3]) + 1];
        for (size_t i = 0; i < n; ++i) bucket[i + 1] += bucket[i];
        std::vector<size_t> fill(bucket.begin(), bucket.end() - 1);
        for (size_t t : good)
            for (int k = 0; k < 3; ++k) {
                uint32_t a = tri(t)[k], b = tri(t)[(k + 1) % 3];
                half[fill[std::min(a, b)]++] = {std::min(a, b), std::max(a, b), t, a < b};
            }
        for (size_t i = 0; i < n; ++i)
            std::sort(half.begin() + static_cast<std::ptrdiff_t>(bucket[i]),
                      half.begin() + static_cast<std::ptrdiff_t>(bucket[i + 1]),
                      [](const HalfEdge& x, const HalfEdge& y) {
                          return x.hi != y.hi ? x.hi < y.hi : x.triangle < y.triangle;
                      });
    }
    UnionFind triangles_uf(in.triangle_count);
    UnionFind boundary_uf(n);
    std::vector<int> boundary_out(n, 0), boundary_in(n, 0);
    std::vector<char> on_boundary(n, 0);
    for (size_t s = 0; s < half.size();) {
        size_t e = s;
        while (e < half.size() && half[e].lo == half[s].lo && half[e].hi == half[s].hi) ++e;
        ++r.edges;
        size_t k = e - s;
        for (size_t j = s + 1; j < e; ++j) triangles_uf.unite(half[s].triangle, half[j].triangle);
        if (k == 1) {
            ++r.boundary_edges;
            uint32_t a = half[s].forward ? half[s].lo : half[s].hi;
            uint32_t b = half[s].forward ? half[s].hi : half[s].lo;
            ++boundary_out[a];
            ++boundary_in[b];
            on_boundary[a] = on_boundary[b] = 1;
            boundary_uf.unite(a, b);
        } else if (k > 2) {
            ++r.nonmanifold_edges;
        } else if (half[s].forward == half[s + 1].forward) {
            ++r.inconsistent_edges;
        }
        s = e;
    }
    std::vector<size_t> loop_edges(n, 0);
    for (size_t i = 0; i < n; ++i) {
        if (!on_boundary[i]) continue;
        if (boundary_out[i] != 1 || boundary_in[i] != 1) r.simple_boundary = false;
        size_t root = boundary_uf.find(i);
        if (root == i) ++r.boundary_loops;
        loop_edges[root] += static_cast<size_t>(boundary_out[i]);
    }
    for (size_t i = 0; i < n; ++i)
        if (on_boundary[i] && boundary_uf.find(i) == i) r.loop_sizes.push_back(loop_edges[i]);
    for (size_t t : good)
        if (triangles_uf.find(t) == t) ++r.components;
    r.euler = static_cast<long long>(r.vertices_used) - static_cast<long long>(r.edges) +
              static_cast<long long>(good.size());

    // Vertex fans: the incident triangles of v, linked when they share an edge at v.
    std::vector<size_t> offsets(n + 1, 0);
    for (size_t t : good)
        for (int k = 0; k < 3; ++k) ++offsets[tri(t)[k] + 1];
    for (size_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i];
    std::vector<size_t> incident(offsets[n]);
    {
        std::vector<size_t> fill(offsets.begin(), offsets.end() - 1);
        for (size_t t : good)
            for (int k = 0; k < 3; ++k) incident[fill[tri(t)[k]]++] = t;
    }
    std::vector<std::pair<uint32_t, size_t>> spokes;  // (other vertex, local triangle)
    for (size_t v = 0; v < n; ++v) {
        size_t begin = offsets[v], count = offsets[v + 1] - begin;
        if (count < 2) continue;
        spokes.clear();
        for (size_t j = 0; j < count; ++j) {
            const uint32_t* c = tri(incident[begin + j]);
            for (int k = 0; k < 3; ++k)
                if (c[k] != v) spokes.push_back({c[k], j});
        }
        std::sort(spokes.begin(), spokes.end());
        UnionFind fan(count);
        size_t pieces = count;
        for (size_t j = 1; j < spokes.size(); ++j)
            if (spokes[j].first == spokes[j - 1].first && fan.unite(spokes[j].second, spokes[j - 1].second))
                --pieces;
        if (pieces > 1) ++r.nonmanifold_vertices;
    }

    // Orientation, zero areas and deviation.
    V3 axis_point = {in.axis_point[0], in.axis_point[1], in.axis_point[2]};
    V3 axis = {in.axis_direction[0], in.axis_direction[1], in.axis_direction[2]};
    axis = mul(axis, 1.0 / norm(axis));
    for (size_t t : good) {
        V3 a = pt(tri(t)[0]), b = pt(tri(t)[1]), c = pt(tri(t)[2]);
        V3 normal = cross(sub(b, a), sub(c, a));
        if (normal.x == 0 && normal.y == 0 && normal.z == 0) ++r.zero_area;
        V3 centroid = mul(add(add(a, b), c), 1.0 / 3.0);
        V3 from_axis = sub(centroid, axis_point);
        V3 radial = sub(from_axis, mul(axis, dot(from_axis, axis)));
        double along_radial = dot(normal, radial);
        if (along_radial > 0) ++r.outward; else ++r.inward;
        double lengths = norm(normal) * norm(radial);
        double cosine = lengths > 0 ? along_radial / lengths : 0.0;
        if (cosine < r.min_outward_cosine) r.min_outward_cosine = cosine, r.most_inward_triangle = t;
        if (in.surface) {
            double c3[3] = {centroid.x, centroid.y, centroid.z};
            double dev = std::fabs(in.surface(c3));
            if (!(dev <= r.max_centroid_deviation)) r.max_centroid_deviation = dev, r.worst_triangle = t;
            bool interior = !on_boundary[tri(t)[0]] && !on_boundary[tri(t)[1]] && !on_boundary[tri(t)[2]];
            if (interior && !(dev <= r.max_interior_deviation)) r.max_interior_deviation = dev;
        }
    }
    r.outward_fraction = good.empty() ? 0.0 : static_cast<double>(r.outward) / static_cast<double>(good.size());
    if (in.surface) {
        for (size_t s = 0; s < half.size(); ++s) {
            if (s > 0 && half[s].lo == half[s - 1].lo && half[s].hi == half[s - 1].hi) continue;
            V3 m = mul(add(pt(half[s].lo), pt(half[s].hi)), 0.5);
            double m3[3] = {m.x, m.y, m.z};
            double dev = std::fabs(in.surface(m3));
            if (!(dev <= r.max_midpoint_deviation)) r.max_midpoint_deviation = dev;
            bool interior = !on_boundary[half[s].lo] && !on_boundary[half[s].hi];
            if (interior && !(dev <= r.max_interior_deviation)) r.max_interior_deviation = dev;
        }
    }

    // Self-intersections through a uniform grid over the triangles' bounding boxes.
    if (in.self_intersections && good.size() > 1) {
        struct Box {
            double lo[3], hi[3];
        };
        std::vector<Box> boxes(good.size());
        Box all = {{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
        double mean_size = 0;
        for (size_t g = 0; g < good.size(); ++g) {
            Box& b = boxes[g];
            for (int k = 0; k < 3; ++k) b.lo[k] = HUGE_VAL, b.hi[k] = -HUGE_VAL;
            for (int j = 0; j < 3; ++j) {
                const double* p = in.points + 3 * size_t{tri(good[g])[j]};
                for (int k = 0; k < 3; ++k) b.lo[k] = std::min(b.lo[k], p[k]), b.hi[k] = std::max(b.hi[k], p[k]);
            }
            double size = 0;
            for (int k = 0; k < 3; ++k) {
                all.lo[k] = std::min(all.lo[k], b.lo[k]);
                all.hi[k] = std::max(all.hi[k], b.hi[k]);
                size = std::max(size, b.hi[k] - b.lo[k]);
            }
            mean_size += size;
        }
        mean_size /= static_cast<double>(good.size());
        std::vector<Prepared> prepared(good.size());
        for (size_t g = 0; g < good.size(); ++g)
            prepared[g] = prepare(pt(tri(good[g])[0]), pt(tri(good[g])[1]), pt(tri(good[g])[2]));
        double cell = mean_size > 0 ? mean_size : 1.0;
        size_t dims[3];
        auto fit = [&]() {
            size_t total = 1;
            for (int k = 0; k < 3; ++k) {
                double cells = std::floor((all.hi[k] - all.lo[k]) / cell) + 1;
                dims[k] = static_cast<size_t>(std::min(cells, 1e6));
                total *= dims[k];
            }
            return total;
        };
        while (fit() > 4 * good.size() + 64) cell *= 1.25;
        auto cell_of = [&](double v, int k) {
            double c = std::floor((v - all.lo[k]) / cell);
            if (c < 0) c = 0;
            size_t i = static_cast<size_t>(c);
            return i >= dims[k] ? dims[k] - 1 : i;
        };
        auto cell_index = [&](size_t x, size_t y, size_t z) { return (z * dims[1] + y) * dims[0] + x; };
        std::vector<size_t> lo_cell(3 * good.size()), hi_cell(3 * good.size());
        size_t cell_count = dims[0] * dims[1] * dims[2];
        std::vector<size_t> start(cell_count + 1, 0);
        for (size_t g = 0; g < good.size(); ++g) {
            for (int k = 0; k < 3; ++k) {
                lo_cell[3 * g + size_t(k)] = cell_of(boxes[g].lo[k], k);
                hi_cell[3 * g + size_t(k)] = cell_of(boxes[g].hi[k], k);
            }
            for (size_t z = lo_cell[3 * g + 2]; z <= hi_cell[3 * g + 2]; ++z)
                for (size_t y = lo_cell[3 * g + 1]; y <= hi_cell[3 * g + 1]; ++y)
                    for (size_t x = lo_cell[3 * g]; x <= hi_cell[3 * g]; ++x) ++start[cell_index(x, y, z) + 1];
        }
        for (size_t c = 0; c < cell_count; ++c) start[c + 1] += start[c];
        std::vector<size_t> members(start[cell_count]);
        {
            std::vector<size_t> fill(start.begin(), start.end() - 1);
            for (size_t g = 0; g < good.size(); ++g)
                for (size_t z = lo_cell[3 * g + 2]; z <= hi_cell[3 * g + 2]; ++z)
                    for (size_t y = lo_cell[3 * g + 1]; y <= hi_cell[3 * g + 1]; ++y)
                        for (size_t x = lo_cell[3 * g]; x <= hi_cell[3 * g]; ++x)
                            members[fill[cell_index(x, y, z)]++] = g;
        }
        for (size_t z = 0; z < dims[2]; ++z)
            for (size_t y = 0; y < dims[1]; ++y)
                for (size_t x = 0; x < dims[0]; ++x) {
                    size_t c = cell_index(x, y, z);
                    for (size_t i = start[c]; i < start[c + 1]; ++i)
                        for (size_t j = i + 1; j < start[c + 1]; ++j) {
                            size_t g = members[i], h = members[j];
                            // Test each pair once: in the cell where both ranges start.
                            if (std::max(lo_cell[3 * g], lo_cell[3 * h]) != x ||
                                std::max(lo_cell[3 * g + 1], lo_cell[3 * h + 1]) != y ||
                                std::max(lo_cell[3 * g + 2], lo_cell[3 * h + 2]) != z)
                                continue;
                            bool apart = false;
                            for (int k = 0; k < 3 && !apart; ++k)
                                apart = boxes[g].hi[k] < boxes[h].lo[k] || boxes[h].hi[k] < boxes[g].lo[k];
                            if (apart) continue;
                            const uint32_t* a = tri(good[g]);
                            const uint32_t* b = tri(good[h]);
                            int shared = 0, shared_a = -1, shared_b = -1;
                            for (int u = 0; u < 3; ++u)
                                for (int w = 0; w < 3; ++w)
                                    if (a[u] == b[w]) ++shared, shared_a = u, shared_b = w;
                            if (shared > 1) continue;  // edge neighbours (or duplicates: see edges)
                            ++r.pairs_tested;
                            if (!triangles_intersect(prepared[g], prepared[h], shared_a, shared_b)) continue;
                            if (shared == 0) ++r.intersecting_pairs; else ++r.vertex_overlaps;
                            if (r.intersection_examples.size() < 6)
                                r.intersection_examples.push_back({good[g], good[h]});
                        }
                }
    }
    return r;
}

}  // namespace mesh_check

#endif  // STRATMESH_TESTS_SUPPORT_MESH_CHECK_H
