// An independent checker for a 2D Delaunay triangulation, written for the tests without
// reference to stratmesh's implementation. All geometric decisions use the exact predicates
// of exact.h (the filtered variants are exact too: they only skip the big integers when a
// double evaluation provably has the right sign).
//
// Given the input points (x, y doubles, 2 per point), the triangles (3 indices each) and
// optionally the duplicate_of array, check_triangulation() verifies:
//   - every index < n; every triangle strictly counter-clockwise;
//   - each directed edge occurs at most once (so each undirected edge lies in one or two
//     triangles, two with opposite directions);
//   - the edges in one triangle only (the boundary) form one closed cycle equal to the
//     convex hull, computed here independently (Andrew's monotone chain, collinear hull
//     points kept); every boundary edge has all points on its left or on it;
//   - the triangle count is 2m - h - 2 (m distinct points, h points on the hull boundary);
//   - every distinct point (its lowest index) is a vertex and no duplicate is;
//   - duplicate_of maps every point to the lowest index with identical coordinates;
//   - no point lies strictly inside any triangle's circumcircle (brute force for small
//     inputs; for large ones a uniform grid over the points, visiting every cell that a
//     rigorous enclosure of the circumdisc reaches, so the check is complete; a triangle too
//     ill-conditioned to enclose is tested against every point. Extreme slivers, whose
//     circles are so large that rounding alone exceeds the cell size, make it slow, never
//     incomplete);
//   - each interior edge is locally Delaunay under the symbolic perturbation the library
//     documents (point lifted off the paraboloid by an infinitesimal that grows with its
//     lexicographic (x, y) rank), which makes the triangulation unique.
// Together, the first four items prove the triangles tile the convex hull exactly once: with
// all triangles positively oriented and interior edges cancelling, the winding number of
// the boundary (the hull, traversed once) counts the triangles covering each point.

#ifndef STRATMESH_TESTS_SUPPORT_DELAUNAY_CHECK_H
#define STRATMESH_TESTS_SUPPORT_DELAUNAY_CHECK_H

#include "support/exact.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

namespace delaunay_check {

struct Options {
    bool empty_circles = true;         // the circumcircle test
    bool perturbed_local = true;       // local Delaunay with the symbolic perturbation
    size_t brute_force_limit = 2000;   // circumcircle test by brute force up to this many points
};

struct Report {
    size_t failure_count = 0;
    std::vector<std::string> failures;  // the first few, for the log
    size_t distinct_points = 0;         // m
    size_t hull_points = 0;             // h: points on the hull boundary, collinear ones too
    size_t expected_triangles = 0;      // 2m - h - 2 (0 if the points are collinear)
    bool collinear = false;             // all distinct points on one line (or fewer than 3)
    size_t incircle_tests = 0;          // circumcircle tests made
    size_t brute_force_triangles = 0;   // triangles whose circumcircle was tested against all points
    bool used_grid = false;

    bool ok() const { return failure_count == 0; }
    std::string summary() const {
        std::ostringstream s;
        s << failure_count << " failure(s)";
        for (const std::string& f : failures) s << "\n  " << f;
        return s.str();
    }
};

namespace detail {

inline const double* point(const double* xy, uint32_t i) { return xy + 2 * static_cast<size_t>(i); }

// Lexicographic (x, y) order; -0.0 and +0.0 compare equal, as they must.
inline bool lex_less(const double* p, const double* q) {
    return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
}
inline bool same_point(const double* p, const double* q) { return p[0] == q[0] && p[1] == q[1]; }

class Failures {
public:
    explicit Failures(Report& r) : report_(r) {}
    template <class F> void add(F&& describe) {
        ++report_.failure_count;
        if (report_.failures.size() < 12) {
            std::ostringstream s;
            describe(s);
            report_.failures.push_back(s.str());
        }
    }

private:
    Report& report_;
};

// The in-circle sign of d against counter-clockwise a, b, c, with zeros resolved by the
// documented symbolic perturbation. Derivation, independent of the library: incircle(a, b,
// c, d) equals the 4x4 determinant with rows (x, y, x^2 + y^2, 1) for a, b, c, d. Raising
// point i's lift by delta_i adds delta_i times the cofactor of its lift entry, which is
// (-1)^i times the orientation of the other three points in their order. With delta growing
// with the lexicographic rank, the highest-ranked point with a non-zero cofactor decides.
inline int perturbed_incircle_sign(const double* a, const double* b, const double* c,
                                   const double* d, const uint32_t rank[4]) {
    int s = exact_ref::filtered_incircle_sign(a, b, c, d);
    if (s != 0) return s;
    const double* p[4] = {a, b, c, d};
    int by_rank[4] = {0, 1, 2, 3};
    std::sort(by_rank, by_rank + 4, [&](int i, int j) { return rank[i] > rank[j]; });
    for (int k : by_rank) {
        const double* others[3];
        int m = 0;
        for (int j = 0; j < 4; ++j)
            if (j != k) others[m++] = p[j];
        int cofactor = exact_ref::filtered_orient2d_sign(others[0], others[1], others[2]);
        if (k % 2 == 1) cofactor = -cofactor;
        if (cofactor != 0) return cofactor;
    }
    return 0;
}

// A disc that certainly contains the circumcircle of a, b, c (strictly counter-clockwise),
// or false when the computation is too ill-conditioned to bound (the caller then tests all
// points). The circumcentre is a + u with
//   u = (cy |b|^2 - by |c|^2, bx |c|^2 - cx |b|^2) / (2 D),  D = bx cy - by cx,
// b and c taken relative to a. Every rounded quantity carries an explicit error bound,
// loose by a factor of two or more.
inline bool circumdisc_enclosure(const double* a, const double* b, const double* c,
                                 double& centre_x, double& centre_y, double& radius) {
    const double u = exact_ref::detail::kUnitRoundoff;
    double bx = b[0] - a[0], by = b[1] - a[1];
    double cx = c[0] - a[0], cy = c[1] - a[1];
    // The relative error bounds below need products of three differences to stay normal.
    for (double v : {bx, by, cx, cy}) {
        double m = std::fabs(v);
        if (m != 0 && !(m >= 0x1p-200 && m <= 0x1p200)) return false;
    }
    double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    double d1 = bx * cy, d2 = by * cx;
    double det = d1 - d2;
    double det_err = 8 * u * (std::fabs(d1) + std::fabs(d2));
    if (!(std::fabs(det) > 4 * det_err)) return false;
    double nx1 = cy * b2, nx2 = by * c2;
    double ny1 = bx * c2, ny2 = cx * b2;
    double nx = nx1 - nx2, ny = ny1 - ny2;
    double nx_err = 16 * u * (std::fabs(nx1) + std::fabs(nx2));
    double ny_err = 16 * u * (std::fabs(ny1) + std::fabs(ny2));
    double ux = nx / (2 * det), uy = ny / (2 * det);
    // With det_err <= |det| / 2: |N/(2D) - N'/(2D')| <= N_err/|D'| + 2 |u| D_err/|D'|, plus
    // the division's own rounding; doubled.
    double ad = std::fabs(det);
    double ux_err = 2 * (nx_err / ad + 2 * std::fabs(ux) * det_err / ad + u * std::fabs(ux));
    double uy_err = 2 * (ny_err / ad + 2 * std::fabs(uy) * det_err / ad + u * std::fabs(uy));
    double r = std::sqrt(ux * ux + uy * uy) * (1 + 8 * u) + 2 * (ux_err + uy_err);
    centre_x = a[0] + ux;
    centre_y = a[1] + uy;
    // The true centre is within ux_err, uy_err of a + (ux, uy), so the true disc lies in the
    // disc of radius |(ux, uy)| + 2 (ux_err + uy_err) about it; the rounding of a + (ux, uy)
    // moves the centre by at most u (|centre_x| + |centre_y|). Doubled again.
    radius = r * (1 + 8 * u) + 8 * u * (std::fabs(centre_x) + std::fabs(centre_y));
    return std::isfinite(radius) && std::isfinite(centre_x) && std::isfinite(centre_y);
}

// A uniform grid of buckets over the distinct points. cell_x/cell_y are monotone in their
// argument (rounded subtraction, multiplication by a positive number and floor all are), so a
// point whose coordinate lies in [lo, hi] is in a cell between cell(lo) and cell(hi).
class Grid {
public:
    Grid(const double* xy, const std::vector<uint32_t>& points, double min_x, double min_y,
         double max_x, double max_y) {
        x0_ = min_x;
        y0_ = min_y;
        y1_ = max_y;
        double w = max_x - min_x, h = max_y - min_y;
        double cell = std::sqrt(w * h / static_cast<double>(points.size()));
        // About one point per cell; at most 2m cells along a thin side's length.
        const double most = 2.0 * static_cast<double>(points.size()) + 1;
        gx_ = static_cast<uint32_t>(std::min(most, std::max(1.0, std::floor(w / cell))));
        gy_ = static_cast<uint32_t>(std::min(most, std::max(1.0, std::floor(h / cell))));
        inv_x_ = static_cast<double>(gx_) / w;
        inv_y_ = static_cast<double>(gy_) / h;
        cell_h_ = h / static_cast<double>(gy_);
        // Rows hold points whose y rounds into them; allow for that rounding and more.
        row_slack_ = 1e-9 * (std::fabs(min_y) + std::fabs(max_y) + h);
        start_.assign(static_cast<size_t>(gx_) * gy_ + 1, 0u);
        for (uint32_t i : points) ++start_[cell_index(point(xy, i)) + 1];
        for (size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
        items_.resize(points.size());
        std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
        for (uint32_t i : points) items_[fill[cell_index(point(xy, i))]++] = i;
    }

    uint32_t cell_x(double x) const { return clamp_cell((x - x0_) * inv_x_, gx_); }
    uint32_t cell_y(double y) const { return clamp_cell((y - y0_) * inv_y_, gy_); }

    // Calls visit(point) for every point in every cell that the disc (cx, cy, r) may reach.
    // Rounding is bounded explicitly (u = 2^-53 per operation, generously multiplied) so that
    // the cells visited cover the disc even for the huge circles of sliver triangles.
    template <class Visit> void for_each_near(double cx, double cy, double r, Visit&& visit) const {
        const double u = exact_ref::detail::kUnitRoundoff;
        const double ey = 4 * u * (std::fabs(cy) + r);
        uint32_t j0 = cell_y(cy - r - ey), j1 = cell_y(cy + r + ey);
        for (uint32_t j = j0; j <= j1; ++j) {
            // The row's y-range; the last row ends at the points' largest y (clamping puts
            // nothing else there: the grid spans exactly the points' bounding box).
            double lo = y0_ + static_cast<double>(j) * cell_h_ - row_slack_;
            double hi = j + 1 == gy_ ? y1_ + row_slack_ : y0_ + static_cast<double>(j + 1) * cell_h_ + row_slack_;
            // A lower bound on the distance from the centre's y to the row.
            double dy = cy < lo ? lo - cy : (cy > hi ? cy - hi : 0.0);
            dy = std::max(0.0, dy - 4 * u * (std::fabs(lo) + std::fabs(hi) + std::fabs(cy)));
            if (dy > r) continue;
            // An upper bound on the disc's half chord over the row: sqrt((r - dy)(r + dy)),
            // each of the four roundings relative, widened by 8 u.
            double half = std::sqrt((r - dy) * (r + dy)) * (1 + 8 * u);
            double ex = 4 * u * (std::fabs(cx) + half);
            uint32_t i0 = cell_x(cx - half - ex), i1 = cell_x(cx + half + ex);
            for (uint32_t i = i0; i <= i1; ++i) {
                size_t cell = static_cast<size_t>(j) * gx_ + i;
                for (uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) visit(items_[k]);
            }
        }
    }

private:
    static uint32_t clamp_cell(double t, uint32_t count) {
        if (!(t > 0)) return 0;
        if (t >= static_cast<double>(count)) return count - 1;
        return static_cast<uint32_t>(t);
    }
    size_t cell_index(const double* p) const {
        return static_cast<size_t>(cell_y(p[1])) * gx_ + cell_x(p[0]);
    }

    double x0_ = 0, y0_ = 0, y1_ = 0, inv_x_ = 0, inv_y_ = 0, cell_h_ = 0, row_slack_ = 0;
    uint32_t gx_ = 1, gy_ = 1;
    std::vector<uint32_t> start_, items_;
};

struct HalfEdge {
    uint32_t to;
    uint32_t opposite;  // the third vertex of the triangle the edge belongs to
};

}  // namespace detail

// Checks triangles[0 .. 3 * count) as the Delaunay triangulation of xy[0 .. 2n).
// duplicate_of may be null.
inline Report check_triangulation(const double* xy, size_t n, const uint32_t* triangles,
                                  size_t count, const uint32_t* duplicate_of,
                                  const Options& options = Options()) {
    using detail::point;
    Report report;
    detail::Failures fail(report);
    for (size_t i = 0; i < 2 * n; ++i) {
        if (!std::isfinite(xy[i])) {
            fail.add([&](std::ostream& s) { s << "input coordinate " << i << " is not finite"; });
            return report;
        }
    }
    const uint32_t n32 = static_cast<uint32_t>(n);

    // Distinct points: sort by (x, y, index); the first of each run of identical points is
    // its lowest index. rank = lexicographic rank of the point's coordinates.
    std::vector<uint32_t> sorted(n);
    for (uint32_t i = 0; i < n32; ++i) sorted[i] = i;
    std::sort(sorted.begin(), sorted.end(), [&](uint32_t i, uint32_t j) {
        const double* p = point(xy, i);
        const double* q = point(xy, j);
        if (detail::lex_less(p, q)) return true;
        if (detail::lex_less(q, p)) return false;
        return i < j;
    });
    std::vector<uint32_t> lowest(n), rank(n);
    std::vector<uint32_t> distinct;  // lowest indices, in lexicographic order
    for (size_t k = 0; k < n; ++k) {
        uint32_t i = sorted[k];
        if (k == 0 || !detail::same_point(point(xy, sorted[k - 1]), point(xy, i))) distinct.push_back(i);
        lowest[i] = distinct.back();
        rank[i] = static_cast<uint32_t>(distinct.size() - 1);
    }
    const size_t m = distinct.size();
    report.distinct_points = m;
    if (duplicate_of) {
        for (size_t i = 0; i < n; ++i) {
            if (duplicate_of[i] != lowest[i]) {
                fail.add([&](std::ostream& s) {
                    s << "duplicate_of[" << i << "] = " << duplicate_of[i] << ", expected " << lowest[i];
                });
            }
        }
    }

    // Independent convex hull of the distinct points, counter-clockwise from the
    // lexicographically smallest, collinear boundary points included.
    std::vector<uint32_t> hull;
    report.collinear = true;
    if (m >= 3) {
        const double* first = point(xy, distinct.front());
        const double* last = point(xy, distinct.back());
        for (uint32_t i : distinct) {
            if (exact_ref::filtered_orient2d_sign(first, last, point(xy, i)) != 0) {
                report.collinear = false;
                break;
            }
        }
    }
    if (!report.collinear) {
        std::vector<uint32_t> chain;
        auto turns_right = [&](uint32_t p, uint32_t q, uint32_t r) {
            return exact_ref::filtered_orient2d_sign(point(xy, p), point(xy, q), point(xy, r)) < 0;
        };
        for (uint32_t i : distinct) {  // lower chain, left to right
            while (chain.size() >= 2 && turns_right(chain[chain.size() - 2], chain.back(), i)) chain.pop_back();
            chain.push_back(i);
        }
        size_t lower_size = chain.size();
        for (size_t k = m - 1; k-- > 0;) {  // upper chain, right to left
            uint32_t i = distinct[k];
            while (chain.size() > lower_size && turns_right(chain[chain.size() - 2], chain.back(), i))
                chain.pop_back();
            chain.push_back(i);
        }
        chain.pop_back();  // the start again
        hull = chain;
        report.hull_points = hull.size();
        report.expected_triangles = 2 * m - hull.size() - 2;
    }

    if (count != report.expected_triangles) {
        fail.add([&](std::ostream& s) {
            s << "triangle count " << count << ", expected 2m - h - 2 = " << report.expected_triangles
              << " (m = " << m << ", h = " << report.hull_points << ")";
        });
    }

    // Indices, duplicates, orientation, usage.
    std::vector<char> used(n, 0);
    std::vector<char> valid(count, 1);
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* v = triangles + 3 * t;
        bool in_range = true;
        for (int k = 0; k < 3; ++k) {
            if (v[k] >= n32) {
                in_range = false;
                fail.add([&](std::ostream& s) { s << "triangle " << t << " has index " << v[k] << " >= n"; });
            }
        }
        if (!in_range) {
            valid[t] = 0;
            continue;
        }
        for (int k = 0; k < 3; ++k) {
            used[v[k]] = 1;
            if (lowest[v[k]] != v[k]) {
                fail.add([&](std::ostream& s) {
                    s << "triangle " << t << " uses duplicate point " << v[k] << " (of " << lowest[v[k]] << ")";
                });
            }
        }
        if (exact_ref::filtered_orient2d_sign(point(xy, v[0]), point(xy, v[1]), point(xy, v[2])) <= 0) {
            valid[t] = 0;
            fail.add([&](std::ostream& s) {
                s << "triangle " << t << " (" << v[0] << ", " << v[1] << ", " << v[2]
                  << ") is not strictly counter-clockwise";
            });
        }
    }
    if (!report.collinear) {
        for (uint32_t i : distinct) {
            if (!used[i]) fail.add([&](std::ostream& s) { s << "point " << i << " is not a vertex"; });
        }
    }

    // Directed edges, grouped by their start (compressed rows), each row sorted by target.
    std::vector<uint32_t> row(n + 1, 0u);
    for (size_t t = 0; t < count; ++t) {
        if (!valid[t]) continue;
        for (int k = 0; k < 3; ++k) ++row[triangles[3 * t + static_cast<size_t>(k)] + 1];
    }
    for (size_t i = 1; i <= n; ++i) row[i] += row[i - 1];
    std::vector<detail::HalfEdge> edges(row[n]);
    {
        std::vector<uint32_t> fill(row.begin(), row.end() - 1);
        for (size_t t = 0; t < count; ++t) {
            if (!valid[t]) continue;
            const uint32_t* v = triangles + 3 * t;
            for (int k = 0; k < 3; ++k) {
                uint32_t from = v[k], to = v[(k + 1) % 3], opposite = v[(k + 2) % 3];
                edges[fill[from]++] = detail::HalfEdge{to, opposite};
            }
        }
    }
    for (size_t i = 0; i < n; ++i) {
        auto begin = edges.begin() + row[i], end = edges.begin() + row[i + 1];
        std::sort(begin, end, [](const detail::HalfEdge& x, const detail::HalfEdge& y) { return x.to < y.to; });
        for (auto e = begin; e != end && e + 1 != end; ++e) {
            if (e->to == (e + 1)->to) {
                fail.add([&](std::ostream& s) { s << "directed edge " << i << "->" << e->to << " occurs twice"; });
            }
        }
    }
    auto find_edge = [&](uint32_t from, uint32_t to) -> const detail::HalfEdge* {
        auto begin = edges.begin() + row[from], end = edges.begin() + row[from + 1];
        auto it = std::lower_bound(begin, end, to,
                                   [](const detail::HalfEdge& x, uint32_t key) { return x.to < key; });
        return (it != end && it->to == to) ? &*it : nullptr;
    };

    // Boundary edges and local (perturbed) Delaunay of interior edges.
    const uint32_t kNone = 0xFFFFFFFFu;
    std::vector<uint32_t> boundary_next(n, kNone);
    size_t boundary_edges = 0;
    for (uint32_t from = 0; from < n32; ++from) {
        for (uint32_t k = row[from]; k < row[from + 1]; ++k) {
            const detail::HalfEdge& e = edges[k];
            const detail::HalfEdge* twin = find_edge(e.to, from);
            if (!twin) {
                ++boundary_edges;
                if (boundary_next[from] != kNone) {
                    fail.add([&](std::ostream& s) { s << "two boundary edges leave point " << from; });
                }
                boundary_next[from] = e.to;
                continue;
            }
            if (!options.perturbed_local || from > e.to) continue;
            const uint32_t r[4] = {rank[from], rank[e.to], rank[e.opposite], rank[twin->opposite]};
            int s = detail::perturbed_incircle_sign(point(xy, from), point(xy, e.to), point(xy, e.opposite),
                                                    point(xy, twin->opposite), r);
            if (s >= 0) {
                fail.add([&](std::ostream& out) {
                    out << "edge " << from << "-" << e.to << " is not locally Delaunay (perturbed): "
                        << twin->opposite << " against triangle (" << from << ", " << e.to << ", "
                        << e.opposite << "), sign " << s;
                });
            }
        }
    }

    // The boundary is one cycle, and it is the hull.
    if (!report.collinear && count > 0) {
        std::vector<uint32_t> cycle;
        uint32_t start = hull.front();
        uint32_t v = start;
        while (cycle.size() <= boundary_edges) {
            cycle.push_back(v);
            v = boundary_next[v];
            if (v == kNone || v == start) break;
        }
        if (v != start || cycle.size() != boundary_edges) {
            fail.add([&](std::ostream& s) {
                s << "the boundary is not a single closed cycle through the hull's first point ("
                  << boundary_edges << " boundary edges, walk of " << cycle.size() << ")";
            });
        } else if (cycle != hull) {
            fail.add([&](std::ostream& s) {
                s << "the boundary cycle (" << cycle.size() << " points) differs from the convex hull ("
                  << hull.size() << " points)";
            });
        }
        // Every boundary edge has all points on its left or on it. Checking the hull's
        // corners suffices: the point farthest to the right of a line is a corner. Small
        // inputs check every point anyway.
        std::vector<uint32_t> witnesses;
        if (n * boundary_edges <= 4000000) {
            witnesses = distinct;
        } else {
            for (size_t k = 0; k < hull.size(); ++k) {
                uint32_t prev = hull[(k + hull.size() - 1) % hull.size()], next = hull[(k + 1) % hull.size()];
                if (exact_ref::filtered_orient2d_sign(point(xy, prev), point(xy, hull[k]), point(xy, next)) > 0)
                    witnesses.push_back(hull[k]);
            }
        }
        for (uint32_t from = 0; from < n32; ++from) {
            uint32_t to = boundary_next[from];
            if (to == kNone) continue;
            for (uint32_t w : witnesses) {
                if (exact_ref::filtered_orient2d_sign(point(xy, from), point(xy, to), point(xy, w)) < 0) {
                    fail.add([&](std::ostream& s) {
                        s << "point " << w << " lies right of boundary edge " << from << "->" << to;
                    });
                    break;
                }
            }
        }
    }

    // Empty circumcircles.
    if (options.empty_circles && count > 0 && !report.collinear) {
        auto test_point = [&](size_t t, uint32_t p) {
            const uint32_t* v = triangles + 3 * t;
            if (p == v[0] || p == v[1] || p == v[2]) return;
            ++report.incircle_tests;
            if (exact_ref::filtered_incircle_sign(point(xy, v[0]), point(xy, v[1]), point(xy, v[2]),
                                                  point(xy, p)) > 0) {
                fail.add([&](std::ostream& s) {
                    s << "point " << p << " lies inside the circumcircle of triangle " << t << " (" << v[0]
                      << ", " << v[1] << ", " << v[2] << ")";
                });
            }
        };
        double min_x = HUGE_VAL, min_y = HUGE_VAL, max_x = -HUGE_VAL, max_y = -HUGE_VAL;
        for (uint32_t i : distinct) {
            min_x = std::min(min_x, point(xy, i)[0]);
            max_x = std::max(max_x, point(xy, i)[0]);
            min_y = std::min(min_y, point(xy, i)[1]);
            max_y = std::max(max_y, point(xy, i)[1]);
        }
        double w = max_x - min_x, h = max_y - min_y;
        bool grid_usable = m > options.brute_force_limit && w > 1e-100 && h > 1e-100 && w < 1e100 &&
                           h < 1e100 && std::fabs(min_x) < 1e100 && std::fabs(max_x) < 1e100 &&
                           std::fabs(min_y) < 1e100 && std::fabs(max_y) < 1e100;
        if (!grid_usable) {
            for (size_t t = 0; t < count; ++t) {
                if (!valid[t]) continue;
                ++report.brute_force_triangles;
                for (uint32_t p : distinct) test_point(t, p);
            }
        } else {
            report.used_grid = true;
            detail::Grid grid(xy, distinct, min_x, min_y, max_x, max_y);
            for (size_t t = 0; t < count; ++t) {
                if (!valid[t]) continue;
                const uint32_t* v = triangles + 3 * t;
                double cx = 0, cy = 0, r = 0;
                if (!detail::circumdisc_enclosure(point(xy, v[0]), point(xy, v[1]), point(xy, v[2]), cx, cy, r)) {
                    ++report.brute_force_triangles;
                    for (uint32_t p : distinct) test_point(t, p);
                    continue;
                }
                grid.for_each_near(cx, cy, r, [&](uint32_t p) { test_point(t, p); });
            }
        }
    }
    return report;
}

}  // namespace delaunay_check

#endif  // STRATMESH_TESTS_SUPPORT_DELAUNAY_CHECK_H
