// find_parting(): where a cloud parts into branches along its axis. The pieces it reports
// are checked against single linkage computed here by brute force, the cut against the
// shapes' geometry, and the shapes that do not fork must not part.
#include "stratmesh.h"
#include "support/library_options.h"
#include "support/shapes.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

using library_options::axis_options;
using library_options::cloud_of;
using shapes::Pose;
using shapes::Shape;
using stratmesh::Cloud;
using stratmesh::Options;
using stratmesh::Parting;
using stratmesh::Scalar;
using stratmesh::Status;

namespace {

struct PartingRun {
    Status status;
    Parting parting;
    size_t workspace_bytes;
};

PartingRun find_parting_of(const Cloud& cloud, const Options& options,
                           uint8_t* branch_of = nullptr) {
    PartingRun run;
    run.workspace_bytes = stratmesh::find_parting_workspace_size(cloud.count, options);
    std::vector<unsigned char> workspace(run.workspace_bytes);
    run.status = stratmesh::find_parting(cloud, options, workspace.data(), workspace.size(),
                                         &run.parting, branch_of);
    return run;
}

// The single-linkage pieces (points nearer than `gap` join) of the points on one side of
// `cut` along the unit `axis` (at or above it, or below it) that count: at least `least`
// points and a twentieth of the side, the nearest within a gap of the cut; by brute force
// over every pair. piece[i] numbers point i's piece, largest first, or is -1;
// starts_at_cut[i] tells whether point i's piece, counted or not, has a point within a gap
// of the cut.
struct Pieces {
    std::vector<size_t> sizes;
    std::vector<int> piece;
    std::vector<bool> starts_at_cut;
};

Pieces pieces_beyond(const Shape& s, const double axis[3], double cut, bool above, double gap,
                     size_t least_points) {
    std::vector<size_t> side;
    std::vector<double> distance(s.size(), 0);
    for (size_t i = 0; i < s.size(); ++i) {
        const double* p = s.point(i);
        const double h = p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
        if ((h >= cut) != above) continue;
        side.push_back(i);
        distance[i] = std::fabs(h - cut);
    }
    std::vector<size_t> parent(s.size());
    for (size_t i = 0; i < parent.size(); ++i) parent[i] = i;
    auto root = [&](size_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    };
    for (size_t a = 0; a < side.size(); ++a)
        for (size_t b = a + 1; b < side.size(); ++b) {
            const double* p = s.point(side[a]);
            const double* q = s.point(side[b]);
            double d2 = 0;
            for (int c = 0; c < 3; ++c) d2 += (p[c] - q[c]) * (p[c] - q[c]);
            if (d2 < gap * gap) parent[root(side[a])] = root(side[b]);
        }
    std::vector<size_t> size(s.size(), 0);
    std::vector<double> nearest(s.size(), std::numeric_limits<double>::infinity());
    for (size_t i : side) {
        ++size[root(i)];
        nearest[root(i)] = std::min(nearest[root(i)], distance[i]);
    }
    const size_t least = std::max(least_points, (side.size() + 19) / 20);
    std::vector<size_t> roots;
    for (size_t i : side)
        if (root(i) == i && size[i] >= least && nearest[i] <= gap) roots.push_back(i);
    std::stable_sort(roots.begin(), roots.end(), [&](size_t a, size_t b) { return size[a] > size[b]; });
    Pieces out;
    out.piece.assign(s.size(), -1);
    out.starts_at_cut.assign(s.size(), false);
    for (size_t i : side) out.starts_at_cut[i] = nearest[root(i)] <= gap;
    for (size_t k = 0; k < roots.size(); ++k) out.sizes.push_back(size[roots[k]]);
    for (size_t i : side)
        for (size_t k = 0; k < roots.size(); ++k)
            if (root(i) == roots[k]) out.piece[i] = static_cast<int>(k);
    return out;
}

// Each labelled branch is one of the brute-force pieces, and each piece one branch; every
// point not on the side is in the trunk.
void check_labels(const Pieces& pieces, const std::vector<uint8_t>& label, uint8_t first,
                  uint32_t branches) {
    REQUIRE(pieces.sizes.size() == branches);
    std::vector<int> piece_of_branch(branches, -2);
    for (size_t i = 0; i < label.size(); ++i) {
        const bool in_branch = label[i] >= first && label[i] < first + branches;
        if (!in_branch) {
            CHECK(pieces.piece[i] == -1);
            continue;
        }
        int& mapped = piece_of_branch[label[i] - first];
        if (mapped == -2) mapped = pieces.piece[i];
        CHECK(pieces.piece[i] == mapped);
        CHECK(mapped >= 0);
    }
    for (uint32_t k = 0; k < branches; ++k)
        for (uint32_t m = k + 1; m < branches; ++m) CHECK(piece_of_branch[k] != piece_of_branch[m]);
}

// The branches find_parting() reported on one side, as sizes.
std::vector<size_t> reported(const uint32_t* points, uint32_t branches) {
    return std::vector<size_t>(points, points + branches);
}

}  // namespace

TEST_CASE("find_parting: the prongs of a forked tube part above its dome, as single linkage finds them") {
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        const Shape s = shapes::forked_tube(20000, pose);
        CAPTURE(shapes::pose_name(pose));
        std::vector<uint8_t> label(s.size(), 77);
        const PartingRun run = find_parting_of(cloud_of(s), axis_options(s), label.data());
        REQUIRE(run.status == Status::ok);
        const Parting& p = run.parting;
        double axis[3];
        s.axis_direction(axis);
        for (int c = 0; c < 3; ++c) CHECK(p.axis[c] == doctest::Approx(axis[c]));
        CHECK(p.below_branch_count == 0);  // the trunk's open end
        REQUIRE(p.above_branch_count == 2);
        // The prongs leave the trunk's dome, whose pole is at local z = 1.5; below z = 1.2
        // the dome joins them, and its crown ends within two gaps of any cut above that.
        CHECK(p.gap > 0);
        CHECK(p.gap < 0.3);  // the prongs lie 0.86 apart above the dome
        CHECK(p.above >= s.along_axis(1.2));
        CHECK(p.above <= s.along_axis(1.5) + 2 * p.gap);
        // The pieces are single linkage's at the reported gap, largest first (a prong's
        // thin tip may break off, sampled too sparsely to stay joined: it is left aside).
        CHECK(p.above_point_counts[0] >= p.above_point_counts[1]);
        const Pieces pieces = pieces_beyond(s, axis, p.above, true, p.gap, stratmesh::kSmallestBranch);
        CHECK(reported(p.above_point_counts, p.above_branch_count) == pieces.sizes);
        // Each point's label: a prong's points, the trunk's (below the cut, and the dome's
        // crown above it: a piece too small to count that starts at the cut), those left
        // aside above the cut (a prong's tip broken off).
        check_labels(pieces, label, stratmesh::kFirstAboveBranch, p.above_branch_count);
        size_t crown = 0;
        for (size_t i = 0; i < s.size(); ++i) {
            const double* q = s.point(i);
            const double h = q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2];
            if (h < p.above) CHECK(label[i] == stratmesh::kInTrunk);
            if (h >= p.above && pieces.piece[i] < 0) {
                CHECK(label[i] == (pieces.starts_at_cut[i] ? stratmesh::kInTrunk
                                                           : stratmesh::kBeyondBranches));
                crown += pieces.starts_at_cut[i];
            }
        }
        CHECK(crown > 0);  // the case this checks arises
        CHECK(run.parting.workspace_used_bytes <= run.workspace_bytes);
        CHECK(run.parting.detail == nullptr);
    }
}

TEST_CASE("find_parting: the knobs under a tube part below the pole of its dome") {
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        const Shape s = shapes::knobbed_tube(20000, pose);
        CAPTURE(shapes::pose_name(pose));
        std::vector<uint8_t> label(s.size(), 77);
        const PartingRun run = find_parting_of(cloud_of(s), axis_options(s), label.data());
        REQUIRE(run.status == Status::ok);
        const Parting& p = run.parting;
        double axis[3];
        s.axis_direction(axis);
        CHECK(p.above_branch_count == 0);
        REQUIRE(p.below_branch_count == 2);
        // Below the dome's pole (local z = -1) the section is two discs 0.3 apart; the
        // knobs end at z = -1.7.
        CHECK(p.below <= s.along_axis(-1.0) + p.gap);
        CHECK(p.below >= s.along_axis(-1.7) + 4 * p.gap);
        CHECK(p.below_point_counts[1] * 5 >= p.below_point_counts[0] * 4);
        const Pieces pieces = pieces_beyond(s, axis, p.below, false, p.gap, stratmesh::kSmallestBranch);
        CHECK(reported(p.below_point_counts, p.below_branch_count) == pieces.sizes);
        check_labels(pieces, label, stratmesh::kFirstBelowBranch, p.below_branch_count);
    }
}

TEST_CASE("find_parting: no tube that does not fork parts, at any size or pose") {
    using Make = Shape (*)(size_t, Pose);
    const Make makers[] = {
        [](size_t n, Pose p) { return shapes::cylinder(n, p); },
        [](size_t n, Pose p) { return shapes::elliptic_tube(n, p); },
        [](size_t n, Pose p) { return shapes::bumpy_tube(n, p); },
        [](size_t n, Pose p) { return shapes::cone(n, p); },
        [](size_t n, Pose p) { return shapes::vase(n, p); },
        [](size_t n, Pose p) { return shapes::head(n, p); },
        [](size_t n, Pose p) { return shapes::noisy_tube(n, p); },
        [](size_t n, Pose p) { return shapes::scan_grid(n, p); },
    };
    for (Make make : makers)
        for (size_t n : {size_t{500}, size_t{5000}, size_t{40000}})
            for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
                const Shape s = make(n, pose);
                CAPTURE(s.name);
                CAPTURE(n);
                CAPTURE(shapes::pose_name(pose));
                std::vector<uint8_t> label(s.size(), 77);
                const PartingRun run = find_parting_of(cloud_of(s), axis_options(s), label.data());
                REQUIRE(run.status == Status::ok);
                CHECK(run.parting.gap > 0);
                CHECK(run.parting.above_branch_count == 0);
                CHECK(run.parting.below_branch_count == 0);
                CHECK(std::count(label.begin(), label.end(), stratmesh::kInTrunk) ==
                      static_cast<std::ptrdiff_t>(s.size()));
            }
}

TEST_CASE("find_parting: the arcs of a rim broken apart near an open end are no branches") {
    // A grid tube (spacing 0.5, radius 10, 80 rows) whose lowest 20 rows have three empty
    // channels 3 wide: below the cut there, single linkage makes three arcs of about 400
    // points each, thick and tall enough to count, but none goes around a centre of its own.
    std::vector<double> xyz;
    const double radius = 10, spacing = 0.5, pi = 3.14159265358979323846;
    const int around = static_cast<int>(2 * pi * radius / spacing);
    for (int row = 0; row < 80; ++row)
        for (int k = 0; k < around; ++k) {
            const double angle = 2 * pi * k / around, arc = angle * radius;
            const double channel = std::fmod(arc, 2 * pi * radius / 3);
            if (row < 20 && channel < 3) continue;
            xyz.insert(xyz.end(), {radius * std::cos(angle), radius * std::sin(angle), row * spacing});
        }
    const size_t n = xyz.size() / 3;
    Options o = {};
    o.axis = stratmesh::Axis::z;
    const Cloud cloud = {xyz.data(), n, 0, Scalar::float64};
    std::vector<uint8_t> label(n, 77);
    const PartingRun run = find_parting_of(cloud, o, label.data());
    REQUIRE(run.status == Status::ok);
    REQUIRE(run.parting.gap > 0);
    // The channels do split the band: brute-force single linkage below a cut inside it.
    Shape s;
    s.xyz = xyz;
    const double z_axis[3] = {0, 0, 1};
    const Pieces pieces = pieces_beyond(s, z_axis, 8, false, run.parting.gap, stratmesh::kSmallestBranch);
    CHECK(pieces.sizes.size() == 3);
    CHECK(run.parting.below_branch_count == 0);
    CHECK(run.parting.above_branch_count == 0);
    CHECK(std::count(label.begin(), label.end(), stratmesh::kInTrunk) == static_cast<std::ptrdiff_t>(n));
}

TEST_CASE("find_parting: the same answer for the points in any order, and read as strided float32") {
    const Shape s = shapes::forked_tube(12000, Pose::tilted);
    const PartingRun first = find_parting_of(cloud_of(s), axis_options(s));
    REQUIRE(first.status == Status::ok);
    REQUIRE(first.parting.above_branch_count == 2);

    // Reversed, then every 7th point to the front.
    Shape moved = s;
    const size_t n = s.size();
    std::vector<size_t> order;
    for (size_t i = n; i-- > 0;)
        if (i % 7 == 0) order.push_back(i);
    for (size_t i = n; i-- > 0;)
        if (i % 7 != 0) order.push_back(i);
    for (size_t k = 0; k < n; ++k)
        std::memcpy(moved.xyz.data() + 3 * k, s.point(order[k]), 3 * sizeof(double));
    const PartingRun second = find_parting_of(cloud_of(moved), axis_options(moved));
    REQUIRE(second.status == Status::ok);
    CHECK(second.parting.gap == first.parting.gap);
    // The frame's origin, a sum over the points, may differ in its last bits.
    CHECK(second.parting.above == doctest::Approx(first.parting.above).epsilon(1e-12));
    CHECK(second.parting.above_branch_count == first.parting.above_branch_count);
    CHECK(reported(second.parting.above_point_counts, 2) == reported(first.parting.above_point_counts, 2));

    // float32 records of 4 floats (the 4th a NaN the reader must skip over).
    std::vector<float> records(4 * n);
    for (size_t i = 0; i < n; ++i) {
        for (size_t c = 0; c < 3; ++c) records[4 * i + c] = static_cast<float>(s.point(i)[c]);
        records[4 * i + 3] = std::numeric_limits<float>::quiet_NaN();
    }
    const PartingRun single = find_parting_of(Cloud{records.data(), n, 4 * sizeof(float), Scalar::float32},
                                              axis_options(s));
    REQUIRE(single.status == Status::ok);
    CHECK(single.parting.above_branch_count == 2);
    CHECK(single.parting.above == doctest::Approx(first.parting.above).epsilon(0.01));
}

TEST_CASE("find_parting: clouds it cannot measure or search get nothing found and a reason") {
    const Shape few = shapes::forked_tube(300, Pose::z);
    SUBCASE("each point 80 times: no distinct neighbour near most points, no scale") {
        Shape repeated = few;
        repeated.xyz.clear();
        for (int copy = 0; copy < 80; ++copy)
            repeated.xyz.insert(repeated.xyz.end(), few.xyz.begin(), few.xyz.end());
        const PartingRun run = find_parting_of(cloud_of(repeated), axis_options(repeated));
        REQUIRE(run.status == Status::ok);
        CHECK(run.parting.gap == 0);
        CHECK(run.parting.above_branch_count + run.parting.below_branch_count == 0);
        REQUIRE(run.parting.detail != nullptr);
        CHECK(std::string(run.parting.detail).find("no scale") != std::string::npos);
    }
    SUBCASE("two dense clusters of 5,000 points in a sparse tube of 12,000: too crowded") {
        // The median spacing is the tube's, and every cluster point has the 5,000 others
        // of its cluster within a gap: a search would compare 5e7 pairs.
        Shape crowded = shapes::forked_tube(12000, Pose::z);
        shapes::Rng rng(7);
        for (int cluster = 0; cluster < 2; ++cluster)
            for (int i = 0; i < 5000; ++i)
                for (int c = 0; c < 3; ++c)
                    crowded.xyz.push_back((c == 2 ? cluster : 0) + rng.uniform(0, 1e-3));
        const PartingRun run = find_parting_of(cloud_of(crowded), axis_options(crowded));
        REQUIRE(run.status == Status::ok);
        CHECK(run.parting.gap > 0);
        CHECK(run.parting.above_branch_count + run.parting.below_branch_count == 0);
        REQUIRE(run.parting.detail != nullptr);
        CHECK(std::string(run.parting.detail).find("crowded") != std::string::npos);
    }
    SUBCASE("the same tube without them is searched") {
        const PartingRun run = find_parting_of(cloud_of(few), axis_options(few));
        REQUIRE(run.status == Status::ok);
        CHECK(run.parting.gap > 0);
        CHECK(run.parting.detail == nullptr);
    }
}

TEST_CASE("find_parting: bad input gets a status, and the workspace bound is exact enough") {
    const Shape s = shapes::forked_tube(20000, Pose::z);
    const Options o = axis_options(s);
    const size_t bytes = stratmesh::find_parting_workspace_size(s.size(), o);
    REQUIRE(bytes > 0);
    std::vector<unsigned char> workspace(bytes + 64);
    Parting p;

    SUBCASE("a null parting") {
        CHECK(stratmesh::find_parting(cloud_of(s), o, workspace.data(), bytes, nullptr, nullptr) ==
              Status::invalid_argument);
    }
    SUBCASE("a workspace one byte short, then just large enough") {
        CHECK(stratmesh::find_parting(cloud_of(s), o, workspace.data(), bytes, &p, nullptr) == Status::ok);
        const size_t used = p.workspace_used_bytes;
        CHECK(used <= bytes);
        CHECK(stratmesh::find_parting(cloud_of(s), o, workspace.data(), used - 1, &p, nullptr) ==
              Status::out_of_memory);
        CHECK(p.detail != nullptr);
        CHECK(stratmesh::find_parting(cloud_of(s), o, workspace.data(), used, &p, nullptr) == Status::ok);
    }
    SUBCASE("no workspace, a null cloud, an unknown scalar, a short stride") {
        CHECK(stratmesh::find_parting(cloud_of(s), o, nullptr, 0, &p, nullptr) == Status::invalid_argument);
        CHECK(stratmesh::find_parting(Cloud{nullptr, 10, 0, Scalar::float64}, o, workspace.data(),
                                      bytes, &p, nullptr) == Status::invalid_argument);
        CHECK(stratmesh::find_parting(Cloud{s.xyz.data(), s.size(), 0, static_cast<Scalar>(7)}, o,
                                      workspace.data(), bytes, &p, nullptr) == Status::invalid_argument);
        CHECK(stratmesh::find_parting(Cloud{s.xyz.data(), s.size(), 8, Scalar::float64}, o,
                                      workspace.data(), bytes, &p, nullptr) == Status::invalid_argument);
    }
    SUBCASE("the parting inside the workspace or the cloud is refused before anything is written") {
        const std::vector<unsigned char> before = workspace;
        Parting* inside = reinterpret_cast<Parting*>(workspace.data());
        CHECK(stratmesh::find_parting(cloud_of(s), o, workspace.data(), bytes, inside, nullptr) ==
              Status::invalid_argument);
        CHECK(workspace == before);
        std::vector<double> copy = s.xyz;
        CHECK(stratmesh::find_parting(Cloud{copy.data(), s.size(), 0, Scalar::float64}, o,
                                      workspace.data(), bytes,
                                      reinterpret_cast<Parting*>(copy.data() + 6), nullptr) ==
              Status::invalid_argument);
        CHECK(copy == s.xyz);
        std::vector<uint8_t> label(s.size());
        CHECK(stratmesh::find_parting(cloud_of(s), o, workspace.data(), bytes, &p,
                                      workspace.data() + 100) == Status::invalid_argument);
        CHECK(stratmesh::find_parting(cloud_of(s), o, workspace.data(), bytes,
                                      reinterpret_cast<Parting*>(label.data()), label.data()) ==
              Status::invalid_argument);
    }
    SUBCASE("a NaN point: refused, or skipped with skip_invalid_points") {
        std::vector<double> xyz = s.xyz;
        xyz[3 * 17 + 1] = std::numeric_limits<double>::quiet_NaN();
        const Cloud cloud{xyz.data(), s.size(), 0, Scalar::float64};
        CHECK(stratmesh::find_parting(cloud, o, workspace.data(), bytes, &p, nullptr) == Status::invalid_point);
        Options skip = o;
        skip.flags = stratmesh::skip_invalid_points;
        CHECK(stratmesh::find_parting(cloud, skip, workspace.data(), bytes, &p, nullptr) == Status::ok);
    }
    SUBCASE("too few distinct points, every point at one height, a zero axis") {
        const double two[] = {0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0};
        CHECK(stratmesh::find_parting(Cloud{two, 4, 0, Scalar::float64}, o, workspace.data(),
                                      bytes, &p, nullptr) == Status::too_few_points);
        const double flat[] = {0, 0, 5, 1, 0, 5, 0, 1, 5, 1, 1, 5};
        CHECK(stratmesh::find_parting(Cloud{flat, 4, 0, Scalar::float64}, o, workspace.data(),
                                      bytes, &p, nullptr) == Status::flat_cloud);
        Options zero = {};
        zero.axis = stratmesh::Axis::direction;
        CHECK(stratmesh::find_parting(cloud_of(s), zero, workspace.data(), bytes, &p, nullptr) ==
              Status::invalid_axis);
    }
    SUBCASE("outliers left out first with drop_outliers") {
        Options drop = o;
        drop.flags = stratmesh::drop_outliers;
        const size_t drop_bytes = stratmesh::find_parting_workspace_size(s.size(), drop);
        std::vector<unsigned char> larger(drop_bytes);
        std::vector<double> xyz = s.xyz;
        for (size_t c = 0; c < 3; ++c) xyz[3 * 5 + c] = 1e3;  // far from the rest
        CHECK(stratmesh::find_parting(Cloud{xyz.data(), s.size(), 0, Scalar::float64}, drop,
                                      larger.data(), larger.size(), &p, nullptr) == Status::ok);
        CHECK(p.above_branch_count == 2);
    }
    CHECK(stratmesh::find_parting_workspace_size(size_t{0xFFFFFFFFu}, o) == 0);
}
