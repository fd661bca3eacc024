// The manifold safety net (the paper's illegal-triangle removal) on its own, fed triangle
// sets that break manifoldness on purpose: its output is always edge- and vertex-manifold
// and consistently oriented, keeps the order of the survivors, and leaves a manifold input
// untouched (the fast path and the general repair must agree). This suite compiles the
// implementation itself, to reach the internal function.
#define STRATMESH_IMPLEMENTATION
#include "stratmesh.h"
#include "support/mesh_check.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <algorithm>
#include <random>
#include <vector>

namespace {

struct NetResult {
    std::vector<uint32_t> triangles;
    size_t removed = 0;
};

NetResult run_net(std::vector<uint32_t> tris, size_t point_count) {
    size_t count = tris.size() / 3;
    std::vector<unsigned char> work(64 * (point_count + tris.size()) + 4096);
    stratmesh::detail::Arena arena = stratmesh::detail::Arena::over(work.data(), work.size());
    NetResult r;
    r.removed = stratmesh::detail::enforce_manifold(tris.data(), count, point_count, arena);
    tris.resize(3 * count);
    r.triangles = tris;
    return r;
}

// Topology only: the points are placed on a circle so that the checker has coordinates.
mesh_check::Result topology(const std::vector<uint32_t>& tris, size_t point_count) {
    static std::vector<double> xyz;
    xyz.clear();
    for (size_t i = 0; i < point_count; ++i) {
        double t = 0.37 * static_cast<double>(i);
        xyz.insert(xyz.end(), {std::cos(t), std::sin(t), 0.01 * static_cast<double>(i)});
    }
    mesh_check::Input in;
    in.points = xyz.data();
    in.point_count = point_count;
    in.triangles = tris.data();
    in.triangle_count = tris.size() / 3;
    in.self_intersections = false;
    return mesh_check::check(in);
}

void check_manifold(const NetResult& r, size_t point_count) {
    const mesh_check::Result m = topology(r.triangles, point_count);
    CHECK(m.bad_indices == 0);
    CHECK(m.nonmanifold_edges == 0);
    CHECK(m.inconsistent_edges == 0);
    CHECK(m.nonmanifold_vertices == 0);
}

// Whether `kept` is `all` with some triangles taken out, in the same order.
bool is_ordered_subset(const std::vector<uint32_t>& kept, const std::vector<uint32_t>& all) {
    size_t at = 0;
    for (size_t k = 0; k < kept.size(); k += 3) {
        while (at < all.size() && !(all[at] == kept[k] && all[at + 1] == kept[k + 1] && all[at + 2] == kept[k + 2]))
            at += 3;
        if (at >= all.size()) return false;
        at += 3;
    }
    return true;
}

// A closed fan of `spokes` triangles around vertex 0 (rim 1 .. spokes), counter-clockwise.
std::vector<uint32_t> fan(uint32_t spokes, uint32_t first_rim = 1) {
    std::vector<uint32_t> t;
    for (uint32_t i = 0; i < spokes; ++i)
        t.insert(t.end(), {0, first_rim + i, first_rim + (i + 1) % spokes});
    return t;
}

}  // namespace

TEST_CASE("safety net: a manifold input comes out unchanged, small fans and large ones") {
    for (uint32_t spokes : {3u, 6u, 16u, 17u, 40u}) {
        INFO(spokes << " triangles around the centre");
        const std::vector<uint32_t> closed = fan(spokes);
        NetResult r = run_net(closed, spokes + 1);
        CHECK(r.removed == 0);
        CHECK(r.triangles == closed);
        std::vector<uint32_t> open = closed;
        open.resize(open.size() - 3);  // a chain: the centre on the boundary
        r = run_net(open, spokes + 1);
        CHECK(r.removed == 0);
        CHECK(r.triangles == open);
    }
}

TEST_CASE("safety net: repeated, flipped and bow-tie triangles are removed until manifold") {
    const uint32_t n = 12;
    std::vector<uint32_t> base = fan(n);
    SUBCASE("a triangle repeated") {
        std::vector<uint32_t> t = base;
        t.insert(t.end(), {0, 1, 2});
        NetResult r = run_net(t, n + 1);
        CHECK(r.removed == 1);
        CHECK(r.triangles == base);  // the later copy goes
    }
    SUBCASE("a triangle flipped against its neighbours") {
        std::vector<uint32_t> t = base;
        std::swap(t[4], t[5]);
        NetResult r = run_net(t, n + 1);
        CHECK(r.removed >= 1);
        check_manifold(r, n + 1);
        CHECK(is_ordered_subset(r.triangles, t));
    }
    SUBCASE("two fans sharing only their centre (a bow tie)") {
        std::vector<uint32_t> t = base;
        std::vector<uint32_t> second = fan(5, n + 1);
        t.insert(t.end(), second.begin(), second.end());
        NetResult r = run_net(t, n + 6);
        CHECK(r.removed == 5);  // the smaller fan goes
        CHECK(r.triangles == base);
    }
    SUBCASE("two large fans sharing only their centre") {
        std::vector<uint32_t> t = fan(20);
        std::vector<uint32_t> second = fan(18, 21);
        t.insert(t.end(), second.begin(), second.end());
        NetResult r = run_net(t, 39);
        CHECK(r.removed == 18);
        CHECK(r.triangles == fan(20));
    }
    SUBCASE("three triangles on one edge") {
        std::vector<uint32_t> t = {0, 1, 2, 1, 0, 3, 1, 0, 4};
        NetResult r = run_net(t, 5);
        CHECK(r.removed >= 1);
        check_manifold(r, 5);
    }
}

TEST_CASE("safety net: random triangle soups always come out manifold and in order") {
    std::mt19937 rng(5);
    for (int round = 0; round < 300; ++round) {
        const uint32_t points = 4 + static_cast<uint32_t>(rng() % 30);
        const size_t triangles = 1 + rng() % 80;
        std::vector<uint32_t> t;
        while (t.size() < 3 * triangles) {
            uint32_t a = static_cast<uint32_t>(rng() % points), b = static_cast<uint32_t>(rng() % points),
                     c = static_cast<uint32_t>(rng() % points);
            if (a != b && b != c && a != c) t.insert(t.end(), {a, b, c});
        }
        INFO("round " << round);
        NetResult r = run_net(t, points);
        CHECK(r.triangles.size() + 3 * r.removed == t.size());
        check_manifold(r, points);
        CHECK(is_ordered_subset(r.triangles, t));
    }
}

namespace {

uint64_t corner(uint32_t leaving, uint32_t arriving) {
    return static_cast<uint64_t>(leaving) << 32 | arriving;
}

// The corners of a cycle around a vertex through neighbours x[0 .. k) (each corner leaves
// along x[i + 1] and arrives from x[i]), or of a chain through x[0 .. k] (k corners).
std::vector<uint64_t> cycle(const std::vector<uint32_t>& x) {
    std::vector<uint64_t> c;
    for (size_t i = 0; i < x.size(); ++i) c.push_back(corner(x[(i + 1) % x.size()], x[i]));
    return c;
}
std::vector<uint64_t> chain(const std::vector<uint32_t>& x) {
    std::vector<uint64_t> c;
    for (size_t i = 0; i + 1 < x.size(); ++i) c.push_back(corner(x[i + 1], x[i]));
    return c;
}

bool one_piece(std::vector<uint64_t> corners, std::mt19937& rng) {
    std::shuffle(corners.begin(), corners.end(), rng);
    return stratmesh::detail::fan_is_one_piece(corners.data(), corners.size());
}

}  // namespace

TEST_CASE("safety net: the fan test on its own, small fans and large ones") {
    std::mt19937 rng(11);
    for (uint32_t k = 3; k <= 48; ++k) {
        INFO(k << " neighbours");
        std::vector<uint32_t> x(2 * k + 2);
        for (size_t i = 0; i < x.size(); ++i) x[i] = static_cast<uint32_t>(7 * i + 3 + rng() % 5);
        const std::vector<uint32_t> first(x.begin(), x.begin() + k);
        const std::vector<uint32_t> second(x.begin() + k, x.begin() + 2 * k);
        CHECK(one_piece(cycle(first), rng));
        CHECK(one_piece(chain(first), rng));
        std::vector<uint64_t> cycle_twice = cycle(first), chain_and_cycle = chain(first),
                             two_chains = chain(first), reversed = cycle(first),
                             repeated = cycle(first), cut_twice = cycle(first);
        for (uint64_t c : cycle(second)) cycle_twice.push_back(c);
        for (uint64_t c : cycle(second)) chain_and_cycle.push_back(c);
        for (uint64_t c : chain(second)) two_chains.push_back(c);
        reversed[k / 2] = corner(first[k / 2], first[(k / 2 + 1) % k]);
        repeated.push_back(repeated[k / 3]);
        cut_twice.erase(cut_twice.begin() + k / 2);
        cut_twice.erase(cut_twice.begin());
        CHECK_FALSE(one_piece(cycle_twice, rng));
        CHECK_FALSE(one_piece(chain_and_cycle, rng));
        CHECK_FALSE(one_piece(two_chains, rng));
        CHECK_FALSE(one_piece(reversed, rng));
        CHECK_FALSE(one_piece(repeated, rng));
        if (k >= 4) CHECK_FALSE(one_piece(cut_twice, rng));
    }
}
