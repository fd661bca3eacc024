// The polygon module the caps, their pockets and the grafts' gap fill share: ear clipping,
// winding, simplicity, on the exact predicates. This suite compiles the implementation
// itself, to reach them.
#define STRATMESH_IMPLEMENTATION
#include "stratmesh.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace detail = stratmesh::detail;

namespace {

using Triangle = std::vector<uint32_t>;

// The ears as the clipper hands them over; a diagonal is forbidden where `forbidden` holds
// its pair of corners (either way round).
class Recorder final : public detail::EarRules {
public:
    std::set<std::pair<uint32_t, uint32_t>> forbidden_pairs;
    std::vector<Triangle> ears;

private:
    bool forbidden(uint32_t a, uint32_t b) const override {
        return forbidden_pairs.count({a < b ? a : b, a < b ? b : a}) != 0;
    }
    void take(uint32_t p, uint32_t v, uint32_t n) override { ears.push_back({p, v, n}); }
};

// Clips the polygon xy (corner i at xy[2 i]) with the module, from corner `start`.
bool clip(const std::vector<double>& xy, uint32_t start, detail::EarWalk walk, Recorder& rules) {
    const uint32_t n = static_cast<uint32_t>(xy.size() / 2);
    std::vector<uint32_t> prev(n), next(n), reflex(n);
    std::vector<unsigned char> flags(n);
    detail::EarClipper clipper(xy.data(), n, {prev.data(), next.data(), reflex.data(), flags.data()});
    return clipper.clip(start, walk, rules);
}

// A star-shaped polygon around the origin: n corners at increasing angles, counter-
// clockwise, at random radii; with `grid`, rounded to a lattice that coarse (collinear
// corners, corners on other corners' diagonals), else nudged by a few units in the last
// place (orientations a rounded determinant gets wrong).
std::vector<double> star(std::mt19937_64& random, uint32_t n, double grid) {
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<double> angles(n);
    for (uint32_t i = 0; i < n; ++i)
        angles[i] = 6.283185307179586 * (i + 0.9 * unit(random)) / n;
    std::vector<double> xy;
    for (uint32_t i = 0; i < n; ++i) {
        const double r = 0.2 + unit(random);
        double x = r * std::cos(angles[i]), y = r * std::sin(angles[i]);
        if (grid > 0) {
            x = std::round(x * grid) / grid;
            y = std::round(y * grid) / grid;
        } else {
            x = std::nextafter(x, random() % 2 ? 2.0 : -2.0);
            y = std::nextafter(y, random() % 2 ? 2.0 : -2.0);
        }
        xy.push_back(x);
        xy.push_back(y);
    }
    return xy;
}

bool simple(const std::vector<double>& xy) {
    std::vector<uint64_t> sweep(xy.size() / 2);
    return detail::polygon_is_simple(xy.data(), static_cast<uint32_t>(xy.size() / 2), sweep.data());
}

// The same walk with the ear test at its plainest: every corner left is tested for
// containment, and the polygon left is an array: the way the pockets (from_previous) and
// the gap fill (from_first) clipped before they shared the module.
bool clip_plainly(const std::vector<double>& xy, uint32_t start, detail::EarWalk walk,
                  const Recorder& rules, std::vector<Triangle>& ears) {
    std::vector<uint32_t> left;
    for (uint32_t i = 0; i < xy.size() / 2; ++i) left.push_back(i);
    auto at = [&](uint32_t corner) { return &xy[2 * corner]; };
    auto forbidden = [&](uint32_t a, uint32_t b) {
        return rules.forbidden_pairs.count({a < b ? a : b, a < b ? b : a}) != 0;
    };
    auto is_ear = [&](size_t k) {
        const size_t m = left.size();
        const uint32_t a = left[(k + m - 1) % m], v = left[k], b = left[(k + 1) % m];
        if (!(detail::orient2d_robust(at(a), at(v), at(b)) > 0) || forbidden(a, b)) return false;
        for (uint32_t other : left)
            if (other != a && other != v && other != b &&
                detail::in_closed_triangle(at(a), at(v), at(b), at(other)))
                return false;
        return true;
    };
    size_t k = start;
    while (left.size() > 3) {
        size_t tried = 0;
        while (tried <= left.size() && !is_ear(k)) {
            k = (k + 1) % left.size();
            ++tried;
        }
        if (tried > left.size()) return false;
        const size_t m = left.size();
        ears.push_back({left[(k + m - 1) % m], left[k], left[(k + 1) % m]});
        left.erase(left.begin() + static_cast<long>(k));
        k = walk == detail::EarWalk::from_first ? 0 : (k + m - 2) % (m - 1);
    }
    if (walk == detail::EarWalk::from_first) k = 1;
    if (!(detail::orient2d_robust(at(left[(k + 2) % 3]), at(left[k]), at(left[(k + 1) % 3])) > 0))
        return false;
    ears.push_back({left[(k + 2) % 3], left[k], left[(k + 1) % 3]});
    return true;
}

}  // namespace

TEST_CASE("polygon: ear clipping cuts a simple polygon into n - 2 counter-clockwise ears that tile it") {
    std::mt19937_64 random(20261207);
    int clipped = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const uint32_t n = 3 + static_cast<uint32_t>(random() % 40);
        const double grid = trial % 3 == 0 ? 0 : trial % 3 == 1 ? 6 : 40;
        const std::vector<double> xy = star(random, n, grid);
        if (!simple(xy) || !(detail::simple_polygon_turn(xy.data(), n) > 0)) continue;
        CAPTURE(trial);
        Recorder rules;
        const uint32_t start = static_cast<uint32_t>(random() % n);
        REQUIRE(clip(xy, start, trial % 2 ? detail::EarWalk::from_first : detail::EarWalk::from_previous, rules));
        ++clipped;
        REQUIRE(rules.ears.size() == n - 2);
        // Every ear turns counter-clockwise, each polygon edge is the side of one ear, in its
        // direction, and every other side is a diagonal two ears share, once each way. So
        // the ears, all of positive area, add up to the polygon: they cover each of its
        // points exactly once and nothing outside it.
        std::map<std::pair<uint32_t, uint32_t>, int> sides;
        for (const Triangle& t : rules.ears) {
            CHECK(detail::orient2d_robust(&xy[2 * t[0]], &xy[2 * t[1]], &xy[2 * t[2]]) > 0);
            for (size_t e = 0; e < 3; ++e) ++sides[{t[e], t[(e + 1) % 3]}];
        }
        for (const auto& side : sides) {
            const uint32_t a = side.first.first, b = side.first.second;
            CHECK(side.second == 1);
            if ((a + 1) % n != b) CHECK(sides.count({b, a}) == 1);
        }
        for (uint32_t i = 0; i < n; ++i) CHECK(sides.count({i, (i + 1) % n}) == 1);
    }
    CHECK(clipped > 1000);
}

TEST_CASE("polygon: the ears the clipper takes, and where it gives up, are those of the plain walk") {
    // Forbidden diagonals make the walk skip corners and at times fail: the reflex list and
    // the linked ring must change neither which ears it takes nor in which order.
    std::mt19937_64 random(7);
    int failed = 0, compared = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const uint32_t n = 3 + static_cast<uint32_t>(random() % 24);
        const std::vector<double> xy = star(random, n, trial % 2 ? 0 : 5);
        if (!simple(xy) || !(detail::simple_polygon_turn(xy.data(), n) > 0)) continue;
        CAPTURE(trial);
        Recorder rules;
        for (uint32_t a = 0; a < n; ++a)
            for (uint32_t b = a + 2; b < n; ++b)
                if (random() % 4 == 0) rules.forbidden_pairs.insert({a, b});
        const detail::EarWalk walk = trial % 3 == 0 ? detail::EarWalk::from_first : detail::EarWalk::from_previous;
        const uint32_t start = walk == detail::EarWalk::from_first ? 0 : static_cast<uint32_t>(random() % n);
        std::vector<Triangle> plain;
        const bool closed = clip(xy, start, walk, rules);
        CHECK(closed == clip_plainly(xy, start, walk, rules, plain));
        CHECK(rules.ears == plain);
        failed += !closed;
        ++compared;
    }
    CHECK(compared > 1000);
    CHECK(failed > 100);
}

TEST_CASE("polygon: winding numbers by the exact predicate") {
    // A regular pentagram, {5/2}: twice around its centre, once around a point of a tip, not
    // around a point outside; turned clockwise, the opposite.
    std::vector<double> pentagram;
    for (int i = 0; i < 5; ++i) {
        const double angle = 6.283185307179586 * (2 * i) / 5 + 0.1;
        pentagram.push_back(std::cos(angle));
        pentagram.push_back(std::sin(angle));
    }
    for (double sense : {1.0, -1.0}) {
        auto corner = [&](uint32_t i) {
            const uint32_t k = sense > 0 ? i : 4 - i;
            return detail::Point2{{pentagram[2 * k], pentagram[2 * k + 1]}};
        };
        const double centre[2] = {0, 0}, tip[2] = {0.9 * std::cos(0.1), 0.9 * std::sin(0.1)},
                     outside[2] = {1.5, 0};
        CHECK(detail::winding_number(corner, 5, centre) == static_cast<long>(2 * sense));
        CHECK(detail::winding_number(corner, 5, tip) == static_cast<long>(sense));
        CHECK(detail::winding_number(corner, 5, outside) == 0);
    }
    // One unit in the last place either side of a nearly flat edge, (1, a) to (3, 3 a): a
    // straight corner at (1, a) on the way from (0, 0).
    const double a = 0x1p-40;
    const double flat[8] = {0, 0, 1, a, 3, 3 * a, 0, 1};
    auto corner = [&](uint32_t i) { return detail::Point2{{flat[2 * i], flat[2 * i + 1]}}; };
    const double above[2] = {2, std::nextafter(2 * a, 1.0)}, below[2] = {2, std::nextafter(2 * a, 0.0)};
    CHECK(detail::winding_number(corner, 4, above) == 1);
    CHECK(detail::winding_number(corner, 4, below) == 0);
}

TEST_CASE("polygon: simplicity and the turn of a simple polygon") {
    const double square[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    const double clockwise[8] = {0, 0, 0, 1, 1, 1, 1, 0};
    const double bow_tie[8] = {0, 0, 1, 1, 1, 0, 0, 1};
    const double folded[8] = {0, 0, 2, 0, 1, 0, 1, 1};  // its second edge runs back over the first
    uint64_t sweep[4];
    CHECK(detail::polygon_is_simple(square, 4, sweep));
    CHECK(detail::simple_polygon_turn(square, 4) > 0);
    CHECK(detail::polygon_is_simple(clockwise, 4, sweep));
    CHECK(detail::simple_polygon_turn(clockwise, 4) < 0);
    CHECK_FALSE(detail::polygon_is_simple(bow_tie, 4, sweep));
    CHECK_FALSE(detail::polygon_is_simple(folded, 4, sweep));
}
