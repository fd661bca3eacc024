// delaunay_2d: every result is verified by the independent checker in
// support/delaunay_check.h (exact predicates, independent hull, brute-force or grid-based
// circumcircle test), plus the documented contract of the API: statuses, counts,
// duplicate mapping, strides, capacities, workspace bounds and determinism.
#include "stratmesh.h"
#include "support/delaunay_check.h"
#include "support/exact.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <vector>

namespace {

using stratmesh::Delaunay2dInfo;
using stratmesh::Status;

const uint32_t kSentinel = 0xA5A5A5A5u;
const size_t kInfoSentinel = 987654321;

class Random {
public:
    explicit Random(uint64_t seed) : engine_(seed) {}
    double unit() { return static_cast<double>(engine_() >> 11) * 0x1p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
    size_t below(size_t n) { return static_cast<size_t>(engine_() % n); }
    double gaussian() {  // Box-Muller
        double u1 = 1 - unit(), u2 = unit();
        return std::sqrt(-2 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    }

private:
    std::mt19937_64 engine_;
};

// ---- point sets ---------------------------------------------------------------------------

std::vector<double> uniform_points(size_t n, uint64_t seed, double lo = 0, double hi = 1) {
    Random rng(seed);
    std::vector<double> xy(2 * n);
    for (double& v : xy) v = rng.uniform(lo, hi);
    return xy;
}

std::vector<double> clustered_points(size_t n, uint64_t seed, size_t blobs, double sigma) {
    Random rng(seed);
    std::vector<double> centres(2 * blobs);
    for (double& v : centres) v = rng.uniform(0, 1);
    std::vector<double> xy(2 * n);
    for (size_t i = 0; i < n; ++i) {
        size_t b = rng.below(blobs);
        xy[2 * i] = centres[2 * b] + sigma * rng.gaussian();
        xy[2 * i + 1] = centres[2 * b + 1] + sigma * rng.gaussian();
    }
    return xy;
}

std::vector<double> grid_points(int nx, int ny, double spacing) {
    std::vector<double> xy;
    for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
            xy.push_back(spacing * i);
            xy.push_back(spacing * j);
        }
    }
    return xy;
}

// The 108 lattice points on x^2 + y^2 = 1105^2, shifted by (cx, cy).
std::vector<double> lattice_circle(double cx, double cy) {
    std::vector<double> xy;
    for (int64_t x = -1105; x <= 1105; ++x) {
        int64_t y2 = 1105 * 1105 - x * x;
        int64_t y = static_cast<int64_t>(std::llround(std::sqrt(static_cast<double>(y2))));
        if (y * y != y2) continue;
        xy.push_back(cx + static_cast<double>(x));
        xy.push_back(cy + static_cast<double>(y));
        if (y != 0) {
            xy.push_back(cx + static_cast<double>(x));
            xy.push_back(cy - static_cast<double>(y));
        }
    }
    return xy;
}

size_t point_count(const std::vector<double>& xy) { return xy.size() / 2; }

// Moves whole points (x, y pairs) into a random order.
std::vector<double> shuffled_points(const std::vector<double>& xy, uint64_t seed) {
    std::vector<size_t> order(point_count(xy));
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::mt19937_64 engine(seed);
    std::shuffle(order.begin(), order.end(), engine);
    std::vector<double> out(xy.size());
    for (size_t i = 0; i < order.size(); ++i) {
        out[2 * i] = xy[2 * order[i]];
        out[2 * i + 1] = xy[2 * order[i] + 1];
    }
    return out;
}

// ---- running the library ------------------------------------------------------------------

struct Run {
    Status status = Status::internal_error;
    Delaunay2dInfo info{};
    std::vector<uint32_t> triangles;     // 3 * capacity entries, sentinel-filled before the call
    std::vector<uint32_t> duplicate_of;  // n entries
    size_t count() const { return info.triangle_count; }
};

Delaunay2dInfo sentinel_info() {
    return Delaunay2dInfo{kInfoSentinel, kInfoSentinel, kInfoSentinel, kInfoSentinel, kInfoSentinel};
}

// Runs delaunay_2d on compact points with exactly-sized heap buffers (so AddressSanitizer
// sees any overrun). capacity defaults to delaunay_2d_max_triangles(n).
Run triangulate(const std::vector<double>& xy, size_t capacity = std::numeric_limits<size_t>::max()) {
    const size_t n = point_count(xy);
    Run r;
    std::vector<unsigned char> work(stratmesh::delaunay_2d_workspace_size(n));
    if (capacity == std::numeric_limits<size_t>::max()) capacity = stratmesh::delaunay_2d_max_triangles(n);
    r.triangles.assign(3 * capacity, kSentinel);
    r.duplicate_of.assign(n, kSentinel);
    r.info = sentinel_info();
    r.status = stratmesh::delaunay_2d(xy.data(), n, 2 * sizeof(double), work.data(), work.size(),
                                      r.triangles.data(), capacity, &r.info, r.duplicate_of.data());
    return r;
}

size_t untouched_after(const std::vector<uint32_t>& v, size_t from) {
    size_t bad = 0;
    for (size_t k = from; k < v.size(); ++k) bad += v[k] != kSentinel;
    return bad;
}

// Checks an ok result with the independent checker and against the reported counts.
delaunay_check::Report expect_delaunay(const std::vector<double>& xy, const Run& r,
                                       const delaunay_check::Options& options = delaunay_check::Options()) {
    const size_t n = point_count(xy);
    REQUIRE(r.status == Status::ok);
    REQUIRE(3 * r.count() <= r.triangles.size());
    delaunay_check::Report report = delaunay_check::check_triangulation(
        xy.data(), n, r.triangles.data(), r.count(), r.duplicate_of.data(), options);
    INFO(report.summary());
    CHECK(report.ok());
    CHECK(!report.collinear);
    CHECK(r.info.triangle_count == report.expected_triangles);
    CHECK(r.info.hull_vertex_count == report.hull_points);
    CHECK(r.info.duplicate_count == n - report.distinct_points);
    CHECK(r.count() <= stratmesh::delaunay_2d_max_triangles(n));
    CHECK(untouched_after(r.triangles, 3 * r.count()) == 0);
    return report;
}

// A failed call wrote no triangle and reported no triangle.
void expect_nothing_written(const Run& r) {
    CHECK(r.info.triangle_count == 0);
    CHECK(untouched_after(r.triangles, 0) == 0);
}

// Triangles as coordinate triples, each rotated to start at its lexicographically smallest
// corner (keeping the cyclic order), then sorted: independent of indices and output order.
using CoordTriangle = std::array<std::array<double, 2>, 3>;
std::vector<CoordTriangle> by_coordinates(const std::vector<double>& xy, const uint32_t* tris, size_t count) {
    std::vector<CoordTriangle> out;
    for (size_t t = 0; t < count; ++t) {
        CoordTriangle c;
        for (size_t k = 0; k < 3; ++k) {
            uint32_t v = tris[3 * t + k];
            c[k] = {xy[2 * static_cast<size_t>(v)] + 0.0, xy[2 * static_cast<size_t>(v) + 1] + 0.0};
        }
        std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
        out.push_back(c);
    }
    std::sort(out.begin(), out.end());
    return out;
}

// The same for index triples.
using IndexTriangle = std::array<uint32_t, 3>;
std::vector<IndexTriangle> by_indices(const uint32_t* tris, size_t count) {
    std::vector<IndexTriangle> out;
    for (size_t t = 0; t < count; ++t) {
        IndexTriangle c{tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]};
        std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
        out.push_back(c);
    }
    std::sort(out.begin(), out.end());
    return out;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

// ==== The checker rejects what it must ======================================================

TEST_CASE("checker: rejects corrupted triangulations") {
    std::vector<double> xy = uniform_points(40, 100);
    const double x5 = xy[10], y5 = xy[11];
    xy.insert(xy.end(), {x5, y5});  // point 40 duplicates point 5
    Run r = triangulate(xy);
    expect_delaunay(xy, r);
    const size_t n = point_count(xy);
    std::vector<uint32_t> tris(r.triangles.begin(), r.triangles.begin() + static_cast<std::ptrdiff_t>(3 * r.count()));
    auto failures = [&](const std::vector<uint32_t>& t, size_t count, const uint32_t* dup,
                        delaunay_check::Options o = delaunay_check::Options()) {
        return delaunay_check::check_triangulation(xy.data(), n, t.data(), count, dup, o).failure_count;
    };
    CHECK(failures(tris, r.count(), r.duplicate_of.data()) == 0);

    std::vector<uint32_t> clockwise = tris;
    std::swap(clockwise[0], clockwise[1]);
    CHECK(failures(clockwise, r.count(), nullptr) > 0);

    CHECK(failures(tris, r.count() - 1, nullptr) > 0);  // a triangle missing

    std::vector<uint32_t> uses_duplicate = tris;
    for (uint32_t& v : uses_duplicate) {
        if (v == 5) v = 40;
    }
    CHECK(failures(uses_duplicate, r.count(), nullptr) > 0);

    std::vector<uint32_t> out_of_range = tris;
    out_of_range[4] = static_cast<uint32_t>(n);
    CHECK(failures(out_of_range, r.count(), nullptr) > 0);

    std::vector<uint32_t> wrong_duplicates = r.duplicate_of;
    wrong_duplicates[40] = 40;
    CHECK(failures(tris, r.count(), wrong_duplicates.data()) > 0);

    std::vector<uint32_t> twice = tris;
    twice.insert(twice.end(), tris.begin(), tris.begin() + 3);
    CHECK(failures(twice, r.count() + 1, nullptr) > 0);
}

TEST_CASE("checker: a flipped edge breaks the circumcircle test, by brute force and by grid") {
    for (size_t n : {60u, 2500u}) {
        CAPTURE(n);
        std::vector<double> xy = uniform_points(n, 101);
        Run r = triangulate(xy);
        expect_delaunay(xy, r);
        std::vector<uint32_t> tris(r.triangles.begin(), r.triangles.begin() + static_cast<std::ptrdiff_t>(3 * r.count()));
        // Find triangles (u, v, w) and (v, u, x) whose quadrilateral u, x, v, w is strictly
        // convex and flip their shared edge to w-x: still a triangulation, no longer Delaunay.
        bool flipped = false;
        for (size_t s = 0; s < r.count() && !flipped; ++s) {
            for (size_t t = s + 1; t < r.count() && !flipped; ++t) {
                for (size_t i = 0; i < 3 && !flipped; ++i) {
                    for (size_t j = 0; j < 3 && !flipped; ++j) {
                        uint32_t u = tris[3 * s + i], v = tris[3 * s + (i + 1) % 3], w = tris[3 * s + (i + 2) % 3];
                        if (tris[3 * t + j] != v || tris[3 * t + (j + 1) % 3] != u) continue;
                        uint32_t x = tris[3 * t + (j + 2) % 3];
                        auto p = [&](uint32_t k) { return xy.data() + 2 * static_cast<size_t>(k); };
                        if (exact_ref::exact_orient2d_sign(p(u), p(x), p(w)) <= 0 ||
                            exact_ref::exact_orient2d_sign(p(x), p(v), p(w)) <= 0)
                            continue;
                        const uint32_t a[3] = {u, x, w}, b[3] = {x, v, w};
                        std::copy(a, a + 3, tris.begin() + static_cast<std::ptrdiff_t>(3 * s));
                        std::copy(b, b + 3, tris.begin() + static_cast<std::ptrdiff_t>(3 * t));
                        flipped = true;
                    }
                }
            }
        }
        REQUIRE(flipped);
        delaunay_check::Options circles_only;
        circles_only.perturbed_local = false;
        circles_only.brute_force_limit = n;
        delaunay_check::Report brute = delaunay_check::check_triangulation(xy.data(), n, tris.data(), r.count(), nullptr, circles_only);
        CHECK(brute.failure_count > 0);
        CHECK(!brute.used_grid);
        circles_only.brute_force_limit = 0;
        delaunay_check::Report grid = delaunay_check::check_triangulation(xy.data(), n, tris.data(), r.count(), nullptr, circles_only);
        CHECK(grid.failure_count > 0);
        CHECK(grid.used_grid);
        CHECK(grid.failure_count == brute.failure_count);
        delaunay_check::Options local_only;
        local_only.empty_circles = false;
        CHECK(delaunay_check::check_triangulation(xy.data(), n, tris.data(), r.count(), nullptr, local_only).failure_count > 0);
    }
}

TEST_CASE("checker: the grid circumcircle test finds exactly the violations brute force finds") {
    // Corrupt a valid triangulation by replacing every 50th triangle with one spanning three
    // far-apart points, whose circumcircle holds many points. (The result is no longer a
    // triangulation; the structural failures are the same in both modes, so the totals
    // differ only if the grid misses or double-counts a point inside a circle.)
    const size_t n = 2500;
    std::vector<double> xy = clustered_points(n, 102, 6, 0.02);
    Run r = triangulate(xy);
    expect_delaunay(xy, r);
    std::vector<uint32_t> tris(r.triangles.begin(), r.triangles.begin() + static_cast<std::ptrdiff_t>(3 * r.count()));
    uint32_t left = 0, right = 0, top = 0;
    for (uint32_t i = 1; i < n; ++i) {
        if (xy[2 * i] < xy[2 * left]) left = i;
        if (xy[2 * i] > xy[2 * right]) right = i;
        if (xy[2 * i + 1] > xy[2 * top + 1]) top = i;
    }
    REQUIRE(exact_ref::exact_orient2d_sign(&xy[2 * left], &xy[2 * right], &xy[2 * top]) > 0);
    for (size_t t = 0; t < r.count(); t += 50) {
        tris[3 * t] = left;
        tris[3 * t + 1] = right;
        tris[3 * t + 2] = top;
    }
    delaunay_check::Options o;
    o.perturbed_local = false;
    o.brute_force_limit = n;
    delaunay_check::Report brute = delaunay_check::check_triangulation(xy.data(), n, tris.data(), r.count(), nullptr, o);
    o.brute_force_limit = 0;
    delaunay_check::Report grid = delaunay_check::check_triangulation(xy.data(), n, tris.data(), r.count(), nullptr, o);
    CHECK(!brute.used_grid);
    CHECK(grid.used_grid);
    CHECK(brute.failure_count > 1000);
    CHECK(grid.failure_count == brute.failure_count);
    CHECK(grid.incircle_tests < brute.incircle_tests);
}

// ==== Valid triangulations of many kinds of input ===========================================

TEST_CASE("uniform random points") {
    for (size_t n : {3u, 4u, 5u, 6u, 7u, 10u, 17u, 100u, 1000u, 5000u, 30000u}) {
        for (uint64_t seed = 1; seed <= (n < 100 ? 20u : 2u); ++seed) {
            CAPTURE(n);
            CAPTURE(seed);
            std::vector<double> xy = uniform_points(n, seed * 1000 + n, -1, 1);
            Run r = triangulate(xy);
            delaunay_check::Report report = expect_delaunay(xy, r);
            CHECK(report.distinct_points == n);
        }
    }
}

TEST_CASE("clustered points (Gaussian blobs)") {
    for (size_t n : {500u, 20000u}) {
        CAPTURE(n);
        std::vector<double> xy = clustered_points(n, 7 + n, 9, 0.01);
        Run r = triangulate(xy);
        expect_delaunay(xy, r);
    }
    // Blobs so tight that neighbours differ in the last few bits only.
    std::vector<double> xy = clustered_points(3000, 8, 4, 1e-13);
    Run r = triangulate(xy);
    expect_delaunay(xy, r);
}

TEST_CASE("regular grids: integers and spacing 0.1") {
    for (double spacing : {1.0, 0.1}) {
        for (int side : {2, 3, 5, 17, 40}) {
            CAPTURE(spacing);
            CAPTURE(side);
            std::vector<double> xy = grid_points(side, side + 1, spacing);
            Run r = triangulate(xy);
            delaunay_check::Report report = expect_delaunay(xy, r);
            // side x (side + 1) points: (side - 1) x side cells of two triangles each, and
            // 2 (side - 1) + 2 side points on the boundary of the rectangle.
            CHECK(r.count() == static_cast<size_t>(2 * (side - 1) * side));
            CHECK(report.hull_points == static_cast<size_t>(2 * (side - 1) + 2 * side));
        }
    }
    // A grid far from the origin with a spacing that is not representable.
    std::vector<double> xy;
    for (int j = 0; j < 30; ++j)
        for (int i = 0; i < 30; ++i) {
            xy.push_back(1e6 + 0.1 * i);
            xy.push_back(-3e5 + 0.1 * j);
        }
    Run r = triangulate(xy);
    expect_delaunay(xy, r);
}

TEST_CASE("points on a circle") {
    // Rounded cos/sin: nearly cocircular, never exactly.
    for (size_t n : {8u, 64u, 256u}) {
        CAPTURE(n);
        std::vector<double> xy;
        for (size_t i = 0; i < n; ++i) {
            double angle = 6.283185307179586 * static_cast<double>(i) / static_cast<double>(n);
            xy.push_back(std::cos(angle));
            xy.push_back(std::sin(angle));
        }
        Run r = triangulate(xy);
        expect_delaunay(xy, r);
        xy.push_back(0);
        xy.push_back(0);
        Run with_centre = triangulate(xy);
        expect_delaunay(xy, with_centre);
    }
    // Exactly cocircular: 108 lattice points on a circle of radius 1105, all on the hull.
    std::vector<double> xy = lattice_circle(0, 0);
    REQUIRE(point_count(xy) == 108);
    Run r = triangulate(xy);
    delaunay_check::Report report = expect_delaunay(xy, r);
    CHECK(report.hull_points == 108);
    CHECK(r.count() == 106);
    // The same around a centre far away, with the centre itself added.
    std::vector<double> shifted = lattice_circle(123456789, -987654);
    shifted.push_back(123456789);
    shifted.push_back(-987654);
    Run rs = triangulate(shifted);
    expect_delaunay(shifted, rs);
    CHECK(rs.count() == 108);
}

TEST_CASE("points on two parallel lines") {
    for (int per_line : {2, 3, 10, 200}) {
        CAPTURE(per_line);
        std::vector<double> xy;
        for (int i = 0; i < per_line; ++i) {
            xy.push_back(0.1 * i);
            xy.push_back(0.0);
            xy.push_back(0.1 * i + 0.05);
            xy.push_back(0.3);
        }
        Run r = triangulate(xy);
        delaunay_check::Report report = expect_delaunay(xy, r);
        // Every point is on the hull: 2m - m - 2 = m - 2 triangles.
        CHECK(report.hull_points == static_cast<size_t>(2 * per_line));
        CHECK(r.count() == static_cast<size_t>(2 * per_line - 2));
    }
}

TEST_CASE("three points give one counter-clockwise triangle") {
    const std::vector<std::vector<double>> inputs = {
        {0, 0, 1, 0, 0, 1}, {0, 0, 0, 1, 1, 0}, {5, 5, -1e-300, 0, 1e300, 7}, {0.1, 0.2, 0.3, 0.4, 0.5, 0.7}};
    for (const std::vector<double>& xy : inputs) {
        Run r = triangulate(xy);
        expect_delaunay(xy, r);
        CHECK(r.count() == 1);
        CHECK(r.info.hull_vertex_count == 3);
    }
}

TEST_CASE("four cocircular points: one diagonal, the same for every input order") {
    const double square[4][2] = {{0.1, 0.1}, {0.7, 0.1}, {0.7, 0.3}, {0.1, 0.3}};
    int perm[4] = {0, 1, 2, 3};
    std::vector<CoordTriangle> first;
    do {
        std::vector<double> xy;
        for (int k : perm) {
            xy.push_back(square[k][0]);
            xy.push_back(square[k][1]);
        }
        Run r = triangulate(xy);
        expect_delaunay(xy, r);
        CHECK(r.count() == 2);
        std::vector<CoordTriangle> now = by_coordinates(xy, r.triangles.data(), r.count());
        if (first.empty()) first = now;
        CHECK(now == first);
    } while (std::next_permutation(perm, perm + 4));
}

TEST_CASE("points on a convex hull with many collinear boundary points") {
    std::vector<double> xy;
    for (int i = 0; i < 25; ++i) {
        double t = 0.04 * i;
        const double side[4][2] = {{t, 0}, {1, t}, {1 - t, 1}, {0, 1 - t}};
        for (const auto& p : side) {
            xy.push_back(p[0]);
            xy.push_back(p[1]);
        }
    }
    std::vector<double> inner = uniform_points(200, 9, 0.1, 0.9);
    xy.insert(xy.end(), inner.begin(), inner.end());
    Run r = triangulate(xy);
    delaunay_check::Report report = expect_delaunay(xy, r);
    CHECK(report.hull_points == 100);
}

TEST_CASE("nearly collinear points triangulate into valid slivers") {
    std::vector<double> xy;
    for (int i = 0; i < 300; ++i) {
        double x = 0.1 * i;
        xy.push_back(x);
        xy.push_back(0.3 * x + 1.7);  // rounded: almost, not exactly, on one line
    }
    Run r = triangulate(xy);
    delaunay_check::Report report =
        delaunay_check::check_triangulation(xy.data(), 300, r.triangles.data(), r.count(), r.duplicate_of.data());
    if (report.collinear) {
        CHECK(r.status == Status::collinear);
    } else {
        expect_delaunay(xy, r);
    }
    // Points a few ulps off an exact line.
    Random rng(10);
    std::vector<double> near_line;
    for (int i = 0; i < 200; ++i) {
        double t = rng.uniform(0, 1);
        double y = 2 * t;
        int steps = static_cast<int>(rng.below(5)) - 2;
        for (int s = 0; s < std::abs(steps); ++s) y = std::nextafter(y, steps > 0 ? 3.0 : -3.0);
        near_line.push_back(t);
        near_line.push_back(y);
    }
    Run rl = triangulate(near_line);
    expect_delaunay(near_line, rl);
}

TEST_CASE("scaling by a power of two keeps the same triangles, at huge and tiny magnitudes") {
    std::vector<double> xy = uniform_points(400, 11, -1, 1);
    std::vector<double> grid = grid_points(12, 9, 0.1);
    xy.insert(xy.end(), grid.begin(), grid.end());
    Run base = triangulate(xy);
    expect_delaunay(xy, base);
    std::vector<IndexTriangle> expected = by_indices(base.triangles.data(), base.count());
    for (int power : {-190, -150, -100, 100, 150, 190}) {
        CAPTURE(power);
        std::vector<double> s(xy.size());
        for (size_t k = 0; k < xy.size(); ++k) s[k] = std::ldexp(xy[k], power);
        Run r = triangulate(s);
        expect_delaunay(s, r);
        CHECK(by_indices(r.triangles.data(), r.count()) == expected);
    }
}

// ==== Degenerate inputs and statuses ========================================================

TEST_CASE("collinear inputs: status collinear, no triangle") {
    std::vector<std::vector<double>> inputs;
    inputs.push_back({0, 0, 1, 1, 2, 2});
    inputs.push_back({0, 0, 2, 2, 1, 1, 0, 0, 2, 2});  // with duplicates
    std::vector<double> horizontal, vertical, diagonal, steep;
    Random rng(12);
    for (int i = 0; i < 100; ++i) {
        horizontal.insert(horizontal.end(), {0.1 * i, 0.7});
        vertical.insert(vertical.end(), {-0.3, 0.1 * (99 - i)});
        diagonal.insert(diagonal.end(), {0.1 * i, 0.1 * i});
        double t = rng.uniform(-1e6, 1e6);
        steep.insert(steep.end(), {t, 2 * t});  // y = 2x exactly
    }
    inputs.push_back(horizontal);
    inputs.push_back(vertical);
    inputs.push_back(diagonal);
    inputs.push_back(steep);
    for (const std::vector<double>& xy : inputs) {
        Run r = triangulate(xy);
        CHECK(r.status == Status::collinear);
        expect_nothing_written(r);
        delaunay_check::Report report =
            delaunay_check::check_triangulation(xy.data(), point_count(xy), nullptr, 0, nullptr);
        CHECK(report.collinear);
        CHECK(report.distinct_points >= 3);
    }
}

TEST_CASE("fewer than three distinct points: too_few_points") {
    const double z = 0.0, nz = -0.0;
    const std::vector<std::vector<double>> inputs = {
        {},
        {1, 2},
        {1, 2, 3, 4},
        {1, 2, 1, 2, 3, 4},
        {5, 5, 5, 5, 5, 5, 5, 5, 5, 5},
        {z, z, nz, z, z, nz, nz, nz},          // one point, four spellings of zero
        {z, z, 1, 1, nz, nz, 1, 1, nz, z},     // two points
    };
    for (const std::vector<double>& xy : inputs) {
        CAPTURE(xy.size());
        Run r = triangulate(xy);
        CHECK(r.status == Status::too_few_points);
        expect_nothing_written(r);
    }
    // Null pointers are fine with zero points.
    Delaunay2dInfo info = sentinel_info();
    CHECK(stratmesh::delaunay_2d(nullptr, 0, 16, nullptr, 0, nullptr, 0, &info, nullptr) == Status::too_few_points);
    CHECK(info.triangle_count == 0);
}

TEST_CASE("duplicates map to the lowest index with identical coordinates, -0.0 equal to +0.0") {
    for (uint64_t seed = 1; seed <= 12; ++seed) {
        CAPTURE(seed);
        Random rng(seed);
        std::vector<double> base = uniform_points(60, seed, -1, 1);
        // Points with zero coordinates, to be repeated with the other sign of zero.
        base.insert(base.end(), {0.0, 0.5, 0.25, 0.0, 0.0, 0.0, -0.0, -0.75});
        std::vector<double> xy = base;
        size_t copies = 10 + rng.below(100);
        for (size_t k = 0; k < copies; ++k) {
            size_t i = rng.below(point_count(xy));
            double x = xy[2 * i], y = xy[2 * i + 1];
            if (x == 0 && rng.below(2)) x = -x;
            if (y == 0 && rng.below(2)) y = -y;
            xy.push_back(x);
            xy.push_back(y);
        }
        xy = shuffled_points(xy, seed);
        Run r = triangulate(xy);
        delaunay_check::Report report = expect_delaunay(xy, r);  // checks duplicate_of too
        CHECK(report.distinct_points == point_count(base));
        CHECK(r.info.duplicate_count == copies);
        // Directly: each entry is the lowest index with equal coordinates.
        const size_t n = point_count(xy);
        size_t mismatches = 0;
        for (size_t i = 0; i < n; ++i) {
            size_t lowest = i;
            for (size_t j = 0; j < i; ++j) {
                if (xy[2 * j] == xy[2 * i] && xy[2 * j + 1] == xy[2 * i + 1]) {
                    lowest = j;
                    break;
                }
            }
            mismatches += r.duplicate_of[i] != lowest;
        }
        CHECK(mismatches == 0);
    }
    // Explicit signed zeros: (0, 0), (-0, 0), (0, -0), (-0, -0) are one point.
    std::vector<double> xy = {1, 0, -0.0, 0.0, 0, 1, 0.0, -0.0, -0.0, -0.0, 0.0, 0.0, -1, -1};
    Run r = triangulate(xy);
    expect_delaunay(xy, r);
    CHECK(r.duplicate_of == std::vector<uint32_t>({0, 1, 2, 1, 1, 1, 6}));
    CHECK(r.info.duplicate_count == 3);
}

TEST_CASE("NaN and infinite coordinates: invalid_point with the first offending index") {
    const double bad_values[] = {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(),
                                 HUGE_VAL, -HUGE_VAL};
    for (double bad : bad_values) {
        for (size_t at : {0u, 1u, 7u, 19u}) {
            for (size_t coordinate = 0; coordinate < 2; ++coordinate) {
                CAPTURE(bad);
                CAPTURE(at);
                CAPTURE(coordinate);
                std::vector<double> xy = uniform_points(20, 13);
                xy[2 * at + coordinate] = bad;
                if (at < 19) xy[2 * 19 + 1] = std::numeric_limits<double>::quiet_NaN();  // a later one too
                Run r = triangulate(xy);
                CHECK(r.status == Status::invalid_point);
                CHECK(r.info.first_invalid_index == at);
                expect_nothing_written(r);
            }
        }
    }
}

TEST_CASE("null pointers with non-zero counts, and strides too small: invalid_argument") {
    std::vector<double> xy = uniform_points(10, 14);
    std::vector<unsigned char> work(stratmesh::delaunay_2d_workspace_size(10));
    std::vector<uint32_t> tris(3 * stratmesh::delaunay_2d_max_triangles(10), kSentinel);
    Delaunay2dInfo info = sentinel_info();
    auto call = [&](const double* p, size_t stride, void* w, uint32_t* t, size_t capacity) {
        info = sentinel_info();
        return stratmesh::delaunay_2d(p, 10, stride, w, work.size(), t, capacity, &info, nullptr);
    };
    const size_t capacity = stratmesh::delaunay_2d_max_triangles(10);
    CHECK(call(nullptr, 16, work.data(), tris.data(), capacity) == Status::invalid_argument);
    CHECK(info.triangle_count == 0);
    CHECK(call(xy.data(), 16, nullptr, tris.data(), capacity) == Status::invalid_argument);
    CHECK(info.triangle_count == 0);
    CHECK(call(xy.data(), 16, work.data(), nullptr, capacity) == Status::invalid_argument);
    CHECK(info.triangle_count == 0);
    for (size_t stride : {0u, 1u, 8u, 15u}) {
        CAPTURE(stride);
        CHECK(call(xy.data(), stride, work.data(), tris.data(), capacity) == Status::invalid_argument);
        CHECK(info.triangle_count == 0);
    }
    CHECK(untouched_after(tris, 0) == 0);
    CHECK(call(xy.data(), 16, work.data(), tris.data(), capacity) == Status::ok);
    // No info and no duplicate_of are fine.
    CHECK(stratmesh::delaunay_2d(xy.data(), 10, 16, work.data(), work.size(), tris.data(), capacity, nullptr,
                                 nullptr) == Status::ok);
}

// Every buffer is carved out of one arena so that any two can be made to share bytes:
// each overlap is refused before anything is written; buffers laid end to end are fine.
TEST_CASE("buffers that share memory: invalid_argument, nothing written anywhere") {
    const size_t n = 40;
    const std::vector<double> points = uniform_points(n, 15);
    const size_t point_bytes = points.size() * sizeof(double);
    const size_t work_bytes = stratmesh::delaunay_2d_workspace_size(n);
    const size_t capacity = stratmesh::delaunay_2d_max_triangles(n);
    const size_t tri_bytes = 3 * capacity * sizeof(uint32_t);
    const size_t dup_bytes = n * sizeof(uint32_t);
    const size_t info_bytes = sizeof(Delaunay2dInfo);
    // Offsets of the five buffers laid end to end, 8-byte aligned: points, workspace,
    // triangles, duplicate_of, info.
    const size_t sizes[5] = {point_bytes, work_bytes, tri_bytes, dup_bytes, info_bytes};
    size_t offsets[5];
    size_t total = 0;
    for (size_t k = 0; k < 5; ++k) {
        offsets[k] = total;
        total += (sizes[k] + 7) / 8 * 8;
    }
    std::vector<uint64_t> arena_words(2 * total / 8 + 8);  // room to move any buffer past the end
    unsigned char* arena = reinterpret_cast<unsigned char*>(arena_words.data());

    auto call = [&](const size_t at[5]) {
        std::memset(arena, 0x5A, arena_words.size() * 8);
        std::memcpy(arena + at[0], points.data(), point_bytes);
        std::vector<unsigned char> before(arena, arena + arena_words.size() * 8);
        Status status = stratmesh::delaunay_2d(
            reinterpret_cast<const double*>(arena + at[0]), n, 2 * sizeof(double), arena + at[1], work_bytes,
            reinterpret_cast<uint32_t*>(arena + at[2]), capacity, reinterpret_cast<Delaunay2dInfo*>(arena + at[4]),
            reinterpret_cast<uint32_t*>(arena + at[3]));
        bool unchanged = std::memcmp(before.data(), arena, before.size()) == 0;
        return std::make_pair(status, unchanged);
    };

    std::pair<Status, bool> apart = call(offsets);
    CHECK(apart.first == Status::ok);

    const char* names[5] = {"points", "workspace", "triangles", "duplicate_of", "info"};
    for (size_t a = 0; a < 5; ++a) {
        for (size_t b = 0; b < 5; ++b) {
            if (a == b) continue;
            // Buffer b moved onto the last aligned 8 bytes of buffer a.
            size_t moved[5];
            std::memcpy(moved, offsets, sizeof moved);
            moved[b] = offsets[a] + (sizes[a] - 1) / 8 * 8;
            REQUIRE(moved[b] + sizes[b] <= arena_words.size() * 8);
            CAPTURE(names[a]);
            CAPTURE(names[b]);
            std::pair<Status, bool> shared = call(moved);
            CHECK(shared.first == Status::invalid_argument);
            CHECK(shared.second);
        }
    }
}

TEST_CASE("more points than 32-bit indices: too_many_points, nothing read") {
    // 2^32 - 1 points: one more than indices can address, and still a size_t on 32-bit
    // targets, where the sizes say no buffer can hold them.
    const size_t beyond = size_t{0xFFFFFFFFu};
    CHECK(stratmesh::delaunay_2d_workspace_size(beyond) == 0);
    if (sizeof(size_t) <= 4) CHECK(stratmesh::delaunay_2d_max_triangles(beyond) == 0);
    else CHECK(stratmesh::delaunay_2d_max_triangles(beyond) == 2 * beyond - 5);
    double xy[6] = {0, 0, 1, 0, 0, 1};
    unsigned char work[64];
    uint32_t tris[3];
    Delaunay2dInfo info = sentinel_info();
    const size_t too_many = size_t{0xFFFFFFFFu};
    CHECK(stratmesh::delaunay_2d(xy, too_many, 16, work, sizeof work, tris, 1, &info, nullptr) ==
          Status::too_many_points);
    CHECK(info.triangle_count == 0);
}

// ==== Strides =================================================================================

TEST_CASE("strided input: 40-byte records") {
    struct Record {
        double id, x, y, z, weight;
    };
    static_assert(sizeof(Record) == 40, "no padding expected");
    std::vector<double> xy = clustered_points(3000, 15, 5, 0.05);
    std::vector<double> grid = grid_points(10, 10, 0.1);
    xy.insert(xy.end(), grid.begin(), grid.end());
    xy.insert(xy.end(), {0.3, 0.4, 0.3, 0.4});  // a duplicate
    const size_t n = point_count(xy);
    std::vector<Record> records(n);
    for (size_t i = 0; i < n; ++i) records[i] = Record{std::nan(""), xy[2 * i], xy[2 * i + 1], HUGE_VAL, -1};
    Run compact = triangulate(xy);
    expect_delaunay(xy, compact);

    std::vector<unsigned char> work(stratmesh::delaunay_2d_workspace_size(n));
    std::vector<uint32_t> tris(3 * stratmesh::delaunay_2d_max_triangles(n), kSentinel);
    std::vector<uint32_t> dup(n, kSentinel);
    Delaunay2dInfo info = sentinel_info();
    Status s = stratmesh::delaunay_2d(&records[0].x, n, sizeof(Record), work.data(), work.size(), tris.data(),
                                      tris.size() / 3, &info, dup.data());
    REQUIRE(s == Status::ok);
    CHECK(info.triangle_count == compact.count());
    CHECK(tris == compact.triangles);
    CHECK(dup == compact.duplicate_of);
}

TEST_CASE("strided input: odd 27-byte stride from an unaligned buffer") {
    std::vector<double> xy = uniform_points(2000, 16);
    xy.insert(xy.end(), {xy[6], xy[7]});  // a duplicate of point 3
    const size_t n = point_count(xy);
    const size_t stride = 3 * 8 + 3;
    // One byte of offset, then records of 27 bytes; the last record ends right after its y,
    // so the buffer is exactly as long as the reads need.
    std::vector<unsigned char> buffer(1 + (n - 1) * stride + 2 * sizeof(double), 0xFF);
    for (size_t i = 0; i < n; ++i) {
        std::memcpy(&buffer[1 + i * stride], &xy[2 * i], sizeof(double));
        std::memcpy(&buffer[1 + i * stride + sizeof(double)], &xy[2 * i + 1], sizeof(double));
    }
    Run compact = triangulate(xy);
    expect_delaunay(xy, compact);
    std::vector<unsigned char> work(stratmesh::delaunay_2d_workspace_size(n));
    std::vector<uint32_t> tris(3 * stratmesh::delaunay_2d_max_triangles(n), kSentinel);
    std::vector<uint32_t> dup(n, kSentinel);
    Delaunay2dInfo info = sentinel_info();
    // The API takes const double* but documents that no alignment is needed.
    const double* unaligned = reinterpret_cast<const double*>(buffer.data() + 1);
    Status s = stratmesh::delaunay_2d(unaligned, n, stride, work.data(), work.size(), tris.data(), tris.size() / 3,
                                      &info, dup.data());
    REQUIRE(s == Status::ok);
    CHECK(info.triangle_count == compact.count());
    CHECK(info.duplicate_count == 1);
    CHECK(tris == compact.triangles);
    CHECK(dup == compact.duplicate_of);
    // An invalid value in a record's y is found at the right index.
    double nan = std::nan("");
    std::memcpy(&buffer[1 + 1234 * stride + sizeof(double)], &nan, sizeof nan);
    info = sentinel_info();
    CHECK(stratmesh::delaunay_2d(unaligned, n, stride, work.data(), work.size(), tris.data(), tris.size() / 3, &info,
                                 nullptr) == Status::invalid_point);
    CHECK(info.first_invalid_index == 1234);
}

// ==== Capacity and workspace ==================================================================

TEST_CASE("triangle capacity too small: triangle_capacity, the count needed, nothing written") {
    std::vector<double> xy = uniform_points(50, 17);
    xy.insert(xy.end(), {xy[0], xy[1]});
    Run full = triangulate(xy);
    expect_delaunay(xy, full);
    const size_t needed = full.count();
    for (size_t capacity : {size_t{0}, size_t{1}, needed / 2, needed - 1}) {
        CAPTURE(capacity);
        Run r = triangulate(xy, capacity);
        CHECK(r.status == Status::triangle_capacity);
        CHECK(r.info.triangle_count == needed);
        CHECK(untouched_after(r.triangles, 0) == 0);
    }
    // Capacity 0 with a null triangle array.
    std::vector<unsigned char> work(stratmesh::delaunay_2d_workspace_size(51));
    Delaunay2dInfo info = sentinel_info();
    CHECK(stratmesh::delaunay_2d(xy.data(), 51, 16, work.data(), work.size(), nullptr, 0, &info, nullptr) ==
          Status::triangle_capacity);
    CHECK(info.triangle_count == needed);
    // Exactly enough.
    Run exact = triangulate(xy, needed);
    expect_delaunay(xy, exact);
    CHECK(exact.triangles == std::vector<uint32_t>(full.triangles.begin(), full.triangles.begin() + static_cast<std::ptrdiff_t>(3 * needed)));
}

TEST_CASE("coordinates spanning 2^1029, beyond the exact range: internal_error or at most 2n - 5 triangles") {
    // The fuzzer's reproducer of known bug F: contradictory signs left a hull of 2 edges,
    // and delaunay_2d returned triangle_capacity with delaunay_2d_max_triangles() of room.
    const std::vector<double> xy = {0x1p+465, 0, -0x1.3e8p+641, -0x1.8000000000003p+960,
                                    0, 0x1.ff8p-69, 0, 0};
    Run r = triangulate(xy);
    CHECK((r.status == Status::ok || r.status == Status::internal_error));
    if (r.status == Status::ok) {
        CHECK(r.count() <= stratmesh::delaunay_2d_max_triangles(4));
        for (size_t k = 0; k < 3 * r.count(); ++k) CHECK(r.triangles[k] < 4);
    } else {
        CHECK(r.count() == 0);
        CHECK(untouched_after(r.triangles, 0) == 0);
    }
}

namespace {
// Runs delaunay_2d with a fresh heap buffer of exactly `bytes` bytes (at `offset` into its
// allocation, which still ends where the workspace ends).
Status run_with_workspace(const std::vector<double>& xy, size_t bytes, size_t offset, std::vector<uint32_t>& tris,
                          Delaunay2dInfo& info) {
    std::unique_ptr<unsigned char[]> buffer(new unsigned char[bytes + offset]);
    std::fill(tris.begin(), tris.end(), kSentinel);
    info = sentinel_info();
    return stratmesh::delaunay_2d(xy.data(), point_count(xy), 16, buffer.get() + offset, bytes, tris.data(),
                                  tris.size() / 3, &info, nullptr);
}
}  // namespace

TEST_CASE("workspace too small: out_of_memory for every size below the need, ok at the bound (n = 20)") {
    std::vector<double> xy = uniform_points(20, 18);
    const size_t bound = stratmesh::delaunay_2d_workspace_size(20);
    Run reference = triangulate(xy);
    expect_delaunay(xy, reference);
    std::vector<uint32_t> tris(reference.triangles.size());
    Delaunay2dInfo info{};
    size_t first_ok = bound + 1, unexpected = 0, wrong_output = 0, written_on_failure = 0, oom_after_ok = 0;
    for (size_t bytes = 0; bytes <= bound; ++bytes) {
        Status s = run_with_workspace(xy, bytes, 0, tris, info);
        if (s == Status::ok) {
            if (first_ok > bound) first_ok = bytes;
            wrong_output += tris != reference.triangles;
        } else if (s == Status::out_of_memory) {
            if (first_ok <= bound && bytes >= first_ok + 16) ++oom_after_ok;  // beyond alignment slack
            written_on_failure += info.triangle_count != 0 || untouched_after(tris, 0) != 0;
        } else {
            ++unexpected;
        }
    }
    CHECK(unexpected == 0);
    CHECK(wrong_output == 0);
    CHECK(written_on_failure == 0);
    CHECK(oom_after_ok == 0);
    CHECK(first_ok <= bound);
    // The bound is the true need up to the alignment padding of an arbitrary buffer.
    CHECK(first_ok + 64 > bound);
    // Any alignment works at the bound, and no alignment makes a too-small buffer work.
    for (size_t offset = 0; offset < 32; ++offset) {
        CAPTURE(offset);
        CHECK(run_with_workspace(xy, bound, offset, tris, info) == Status::ok);
        CHECK(tris == reference.triangles);
        for (size_t bytes : {size_t{0}, size_t{1}, offset, size_t{15}, size_t{16}, size_t{17}, bound - 64}) {
            CAPTURE(bytes);
            CHECK(run_with_workspace(xy, bytes, offset, tris, info) == Status::out_of_memory);
            CHECK(untouched_after(tris, 0) == 0);
        }
    }
}

TEST_CASE("workspace too small: several sizes for larger inputs") {
    for (size_t n : {1000u, 100000u}) {
        CAPTURE(n);
        std::vector<double> xy = clustered_points(n, 19 + n, 7, 0.05);
        const size_t bound = stratmesh::delaunay_2d_workspace_size(n);
        Run reference = triangulate(xy);
        expect_delaunay(xy, reference, [] {
            delaunay_check::Options o;
            o.empty_circles = false;  // covered elsewhere; this test is about memory
            return o;
        }());
        std::vector<uint32_t> tris(reference.triangles.size());
        Delaunay2dInfo info{};
        for (size_t bytes : {size_t{0}, size_t{1}, size_t{100}, 8 * n, bound / 2, bound - 4096, bound - 64}) {
            CAPTURE(bytes);
            CHECK(run_with_workspace(xy, bytes, 0, tris, info) == Status::out_of_memory);
            CHECK(info.triangle_count == 0);
            CHECK(untouched_after(tris, 0) == 0);
        }
        for (size_t offset : {0u, 1u, 7u, 8u, 15u}) {
            CAPTURE(offset);
            CHECK(run_with_workspace(xy, bound, offset, tris, info) == Status::ok);
            CHECK(tris == reference.triangles);
        }
    }
}

TEST_CASE("workspace bound: at most 72 bytes per point plus a small constant") {
    size_t previous = 0;
    for (size_t n : {size_t{0}, size_t{1}, size_t{3}, size_t{10}, size_t{1000}, size_t{123457}, size_t{1000000},
                     size_t{100000000}, size_t{0xFFFFFFFEu}}) {
        CAPTURE(n);
        size_t bound = stratmesh::delaunay_2d_workspace_size(n);
        if (n > (SIZE_MAX - 16384) / 72) {
            // 32-bit targets: no size_t can count that much workspace, and the bound says so.
            CHECK(bound == 0);
            continue;
        }
        CHECK(bound > 0);
        CHECK(bound <= 72 * n + 16384);
        CHECK(bound >= previous);
        previous = bound;
        CHECK(stratmesh::delaunay_2d_max_triangles(n) == (n >= 3 ? 2 * n - 5 : 0));
    }
}

// ==== Determinism ===========================================================================

TEST_CASE("determinism: shuffled degenerate grid with duplicates gives the same triangles") {
    // A grid through the origin (so zeros occur), cocircular everywhere, with repeated
    // points, some with the other sign of zero.
    std::vector<double> xy;
    for (int j = -6; j <= 6; ++j)
        for (int i = -7; i <= 7; ++i) xy.insert(xy.end(), {0.1 * i, 0.1 * j});
    for (int k = 0; k < 40; ++k) {
        size_t i = static_cast<size_t>(k * 37) % point_count(xy);
        double x = xy[2 * i], y = xy[2 * i + 1];
        xy.insert(xy.end(), {x == 0 ? -x : x, y == 0 ? -y : y});
    }
    std::vector<CoordTriangle> expected;
    for (uint64_t seed = 0; seed < 8; ++seed) {
        CAPTURE(seed);
        std::vector<double> input = seed == 0 ? xy : shuffled_points(xy, seed);
        Run r = triangulate(input);
        expect_delaunay(input, r);
        std::vector<CoordTriangle> got = by_coordinates(input, r.triangles.data(), r.count());
        if (seed == 0) expected = got;
        CHECK(got == expected);
    }
    // Also an integer grid and the exactly cocircular lattice points.
    for (const std::vector<double>& base : {grid_points(9, 9, 1.0), lattice_circle(3, 4)}) {
        std::vector<CoordTriangle> first;
        for (uint64_t seed = 0; seed < 5; ++seed) {
            std::vector<double> input = shuffled_points(base, seed + 100);
            Run r = triangulate(input);
            expect_delaunay(input, r);
            std::vector<CoordTriangle> got = by_coordinates(input, r.triangles.data(), r.count());
            if (seed == 0) first = got;
            CHECK(got == first);
        }
    }
}

TEST_CASE("determinism: two runs on the same input give identical output arrays") {
    std::vector<double> xy = clustered_points(5000, 20, 3, 0.1);
    std::vector<double> grid = grid_points(20, 20, 0.05);
    xy.insert(xy.end(), grid.begin(), grid.end());
    xy.insert(xy.end(), grid.begin(), grid.begin() + 40);  // duplicates
    Run a = triangulate(xy);
    Run b = triangulate(xy);
    REQUIRE(a.status == Status::ok);
    REQUIRE(b.status == Status::ok);
    CHECK(a.triangles == b.triangles);
    CHECK(a.duplicate_of == b.duplicate_of);
    CHECK(a.info.triangle_count == b.info.triangle_count);
    CHECK(a.info.hull_vertex_count == b.info.hull_vertex_count);
    CHECK(a.info.duplicate_count == b.info.duplicate_count);
}

// ==== Scale ===================================================================================

TEST_CASE("one million uniform points") {
    const size_t n = 1000000;
    std::vector<double> xy = uniform_points(n, 21);
    auto start = std::chrono::steady_clock::now();
    Run r = triangulate(xy);
    double library_seconds = seconds_since(start);
    REQUIRE(r.status == Status::ok);
    start = std::chrono::steady_clock::now();
    delaunay_check::Report report = expect_delaunay(xy, r);
    double check_seconds = seconds_since(start);
    MESSAGE("1e6 points: delaunay_2d " << library_seconds << " s, checks " << check_seconds << " s ("
                                       << report.incircle_tests << " circumcircle tests, "
                                       << report.brute_force_triangles << " triangles by brute force)");
    CHECK(report.used_grid);
    CHECK(report.distinct_points == n);
    CHECK(r.count() == 2 * n - report.hull_points - 2);
    // The grid keeps the circumcircle test near-linear: a few dozen points per triangle.
    CHECK(report.incircle_tests < 40 * r.count());
}

// The reported peak is exact: a buffer of that many bytes works, one byte less does not
// (fresh heap buffers of exactly those sizes, so AddressSanitizer sees any overrun).
TEST_CASE("workspace: the reported peak suffices and one byte less is out_of_memory") {
    std::vector<double> xy;
    for (int i = 0; i < 2000; ++i) {
        xy.push_back(std::sin(i * 1.7) * 10 + i % 7);
        xy.push_back(std::cos(i * 2.3) * 10 + i % 11);
    }
    const size_t n = xy.size() / 2;
    std::vector<uint32_t> triangles(3 * stratmesh::delaunay_2d_max_triangles(n));
    auto run = [&](size_t bytes, stratmesh::Delaunay2dInfo& info) {
        std::unique_ptr<unsigned char[]> workspace(new unsigned char[bytes ? bytes : 1]);
        return stratmesh::delaunay_2d(xy.data(), n, 2 * sizeof(double), workspace.get(), bytes,
                                      triangles.data(), triangles.size() / 3, &info, nullptr);
    };
    stratmesh::Delaunay2dInfo full = {};
    REQUIRE(run(stratmesh::delaunay_2d_workspace_size(n), full) == stratmesh::Status::ok);
    REQUIRE(full.workspace_used_bytes > 0);
    CHECK(full.workspace_used_bytes <= stratmesh::delaunay_2d_workspace_size(n));
    stratmesh::Delaunay2dInfo exact = {};
    CHECK(run(full.workspace_used_bytes, exact) == stratmesh::Status::ok);
    CHECK(exact.triangle_count == full.triangle_count);
    stratmesh::Delaunay2dInfo short_by_one = {};
    CHECK(run(full.workspace_used_bytes - 1, short_by_one) == stratmesh::Status::out_of_memory);
}
