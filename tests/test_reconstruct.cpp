// reconstruct: every mesh is verified by the independent checker in support/mesh_check.h
// (edges, fans, components, boundary loops, Euler characteristic, orientation against the
// true axis, deviation from the analytic surface, self-intersections through a grid) on the
// clouds of support/shapes.h, each along Z, along X and tilted, at two sizes and with every
// way of choosing layers; plus the documented contract of the API: report counts, layer
// details, statuses for bad data, workspace and triangle capacity, strides and float input,
// duplicates, invalid points and determinism.
//
// Measured behaviour the tolerances rest on (g++ 12 -O2, x86-64, library at commit
// aa58fe1; the numbers in the comments below are from that run):
//   - one layer: every property holds exactly for every shape, pose and size, including all
//     triangles facing outward and no self-intersection;
//   - several layers: the bands between layers hold a few triangles facing the axis (at
//     most 2 a run in the matrix below, some of them strongly: normals up to 155 degrees
//     from the outward direction), Report::diagnostics.fold_count counting them within 2, and some of those
//     folds intersect their neighbours. The strict properties were asserted in a test case
//     marked may_fail until untangle_runs left none in the matrix; they now hold strictly,
//     the bounded counts are asserted too;
//   - deviation from the true surface, in point spacings: at most 2.64 with one layer (the
//     boundary loops are coarser than the spacing: the hull and the centre's link on the
//     annulus skip points slightly inside them) and 1.3 off the boundary; up to 3.22
//     through the bands with several layers (noisy tube, 2000 points).
#include "stratmesh.h"
#include "support/library_options.h"
#include "support/mesh_check.h"
#include "support/shapes.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using stratmesh::Axis;
using stratmesh::Cloud;
using stratmesh::LayerInfo;
using stratmesh::Options;
using stratmesh::Report;
using stratmesh::Scalar;
using stratmesh::Status;
using shapes::Pose;
using shapes::Shape;

const size_t kSmall = 2000;
const size_t kLarge = 20000;
const unsigned char kGuardByte = 0xA5;
const size_t kGuardBytes = 64;
const uint32_t kSentinel = 0xDEADBEEFu;
const size_t kGuardTriangles = 8;
const size_t kLayerCapacity = 256;

// ---- running reconstruct with guarded buffers ---------------------------------------------

struct Run {
    Status status = Status::internal_error;
    std::vector<uint32_t> triangles;  // 3 * count indices
    size_t count = 0;
    Report report{};
    std::vector<LayerInfo> layers;    // report.layers.used_count of them (at most kLayerCapacity)
    size_t workspace_bytes = 0;
    size_t max_triangles = 0;
    bool workspace_guard_intact = true;  // nothing written past the workspace
    bool triangle_guard_intact = true;   // nothing written past the capacity
};

bool counts_add_up(const Report& r) {
    return r.points.in_count == r.points.used_count + r.points.duplicate_count + r.points.rejected_count + r.points.unused_count;
}

// reconstruct() with reconstruct_workspace_size() bytes of workspace starting `misalign`
// bytes into a buffer, reconstruct_max_triangles() triangles, and guard zones after both.
Run reconstruct_guarded(const Cloud& cloud, const Options& options, size_t misalign = 0) {
    Run run;
    run.workspace_bytes = stratmesh::reconstruct_workspace_size(cloud.count, options);
    run.max_triangles = stratmesh::reconstruct_max_triangles(cloud.count, options);
    std::vector<unsigned char> workspace(misalign + run.workspace_bytes + kGuardBytes, kGuardByte);
    std::vector<uint32_t> triangles(3 * (run.max_triangles + kGuardTriangles), kSentinel);
    std::vector<LayerInfo> layers(kLayerCapacity);
    run.report.layers.info = layers.data();
    run.report.layers.info_capacity = layers.size();
    run.status = stratmesh::reconstruct(cloud, options, workspace.data() + misalign,
                                        run.workspace_bytes, triangles.data(), run.max_triangles,
                                        &run.count, &run.report);
    for (size_t i = misalign + run.workspace_bytes; i < workspace.size(); ++i)
        if (workspace[i] != kGuardByte) run.workspace_guard_intact = false;
    for (size_t i = 3 * run.max_triangles; i < triangles.size(); ++i)
        if (triangles[i] != kSentinel) run.triangle_guard_intact = false;
    if (run.status == Status::ok && run.count <= run.max_triangles)
        run.triangles.assign(triangles.begin(), triangles.begin() + static_cast<std::ptrdiff_t>(3 * run.count));
    layers.resize(std::min(run.report.layers.used_count, kLayerCapacity));
    run.layers = layers;
    run.report.layers.info = nullptr;  // the array it pointed to is gone
    return run;
}

using library_options::axis_options;
using library_options::cloud_of;

mesh_check::Result check_mesh(const Shape& s, const uint32_t* triangles, size_t count,
                              bool self_intersections,
                              const std::vector<char>* expected_used = nullptr) {
    mesh_check::Input in;
    in.points = s.xyz.data();
    in.point_count = s.size();
    in.triangles = triangles;
    in.triangle_count = count;
    s.axis_point(in.axis_point);
    s.axis_direction(in.axis_direction);
    in.expected_used = expected_used;
    in.surface = [&s](const double* p) { return s.deviation(p); };
    in.self_intersections = self_intersections;
    return mesh_check::check(in);
}

// ---- the ways of choosing layers ----------------------------------------------------------

enum class Layering { single, equal, cuts, height, uneven, automatic };
const Layering kLayerings[] = {Layering::single, Layering::equal, Layering::cuts,
                               Layering::height, Layering::uneven, Layering::automatic};

const char* layering_name(Layering l) {
    switch (l) {
    case Layering::single: return "one layer (layer_count 1)";
    case Layering::equal: return "6 equal layers (layer_count 6)";
    case Layering::cuts: return "explicit cuts";
    case Layering::height: return "layer_height H/8";
    case Layering::uneven: return "uneven cuts (3%, 3%, 79%, 15% of the height)";
    case Layering::automatic: return "automatic layers";
    }
    return "?";
}

// Options for a shape and a layering; explicit cuts are stored in `cuts`, which must
// outlive the options. Cuts are positions along the axis, dot(point, axis). Cuts on contour
// planes are exact for the Z and X poses (see shapes.h); for the tilted pose they are
// placed half-way between planes (cuts on planes there are the subject of their own test).
Options layered_options(const Shape& s, Layering layering, std::vector<double>& cuts) {
    Options o = axis_options(s);
    cuts.clear();
    const double height = s.z_max - s.z_min;
    switch (layering) {
    case Layering::single: o.layer_count = 1; break;
    case Layering::equal: o.layer_count = 6; break;
    case Layering::height: o.layer_height = height / 8; break;
    case Layering::automatic: break;
    case Layering::uneven:
        for (double f : {0.85, 0.03, 0.06}) cuts.push_back(s.along_axis(s.z_min + f * height));
        break;
    case Layering::cuts:
        if (!s.planes.empty()) {
            const std::vector<double>& p = s.planes;
            if (s.pose == Pose::tilted) {
                for (size_t j = 1; j + 1 < p.size(); j += 3) cuts.push_back(s.along_axis((p[j] + p[j + 1]) / 2));
            } else {
                // Every third plane, the top plane (a last layer holding only the top
                // contour), the bottom plane (no layer below it: ignored), a repeat.
                for (size_t j = 1; j < p.size(); j += 3) cuts.push_back(s.along_axis(p[j]));
                cuts.push_back(s.along_axis(p.back()));
                cuts.push_back(s.along_axis(p.front()));
                cuts.push_back(s.along_axis(p[4]));
            }
        } else {
            // Unsorted, with a repeat and two cuts outside the cloud.
            for (double f : {0.5, 0.3, 0.8, 0.1, 0.5, 1.7, -0.4}) cuts.push_back(s.along_axis(s.z_min + f * height));
        }
        break;
    }
    if (!cuts.empty()) {
        o.cuts = cuts.data();
        o.cut_count = cuts.size();
    }
    return o;
}

bool is_single_layer(Layering l) { return l == Layering::single; }

// ---- the property checks shared by the shape matrix ---------------------------------------

// Deviation tolerances in point spacings (plus four standard deviations of noise); measured
// maxima in the header comment.
const double kSingleLayerDeviation = 3.0;
const double kSingleLayerInteriorDeviation = 1.5;
const double kLayeredDeviation = 4.0;

// Several layers: at most this many triangles facing the axis (measured: at most 2 in a run
// of the matrix; the bound allows 3 per band plus 0.1% of the triangles).
size_t fold_allowance(const Run& run) {
    size_t bands = run.report.layers.used_count > 0 ? run.report.layers.used_count - 1 : 0;
    return 3 * bands + run.count / 1000;
}

struct Case {
    std::string name;
    Layering layering = Layering::single;
    size_t points = 0;
    double spacing = 0, noise = 0;
    Run run;
    mesh_check::Result mesh;
    bool checked_intersections = false;
    size_t layer_count_mismatches = 0;  // see count_layer_mismatches
    double ms_reconstruct = 0, ms_check = 0;
};

// Layers whose point count disagrees with the points found in their range along the
// reported axis, counted here from the input: at least those more than a hair inside it,
// at most those within a hair of it (a point on a cut may go either way).
size_t count_layer_mismatches(const Shape& s, const Run& run) {
    const double* axis = run.report.axis;
    std::vector<double> heights(s.size());
    for (size_t i = 0; i < s.size(); ++i) {
        const double* p = &s.xyz[3 * i];
        heights[i] = p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
    }
    if (heights.empty() || run.layers.empty()) return 0;
    const double hair = 1e-9 * (run.layers.back().top - run.layers.front().bottom);
    size_t mismatches = 0;
    for (const LayerInfo& layer : run.layers) {
        size_t inside = 0, around = 0;
        for (double h : heights) {
            inside += h > layer.bottom + hair && h < layer.top - hair;
            around += h >= layer.bottom - hair && h <= layer.top + hair;
        }
        mismatches += layer.point_count < inside || layer.point_count > around;
    }
    return mismatches;
}

double elapsed_ms(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

Case run_case(const Shape& s, Layering layering, bool self_intersections) {
    Case c;
    c.name = s.name + ", " + std::to_string(s.size()) + " points, " + layering_name(layering);
    c.layering = layering;
    c.points = s.size();
    c.spacing = s.spacing;
    c.noise = s.noise;
    std::vector<double> cuts;
    Options o = layered_options(s, layering, cuts);
    auto t0 = std::chrono::steady_clock::now();
    c.run = reconstruct_guarded(cloud_of(s), o);
    c.ms_reconstruct = elapsed_ms(t0);
    c.layer_count_mismatches = count_layer_mismatches(s, c.run);
    auto t1 = std::chrono::steady_clock::now();
    c.mesh = check_mesh(s, c.run.triangles.data(), c.run.count, self_intersections);
    c.ms_check = elapsed_ms(t1);
    c.checked_intersections = self_intersections;
    return c;
}

// The report and layer details, against the documented contract.
void check_report(const Case& c) {
    const Run& run = c.run;
    const Report& r = run.report;
    CHECK(r.points.in_count == c.points);
    CHECK(r.points.in_count == r.points.used_count + r.points.duplicate_count + r.points.rejected_count + r.points.unused_count);
    CHECK(r.points.unused_count == 0);
    CHECK(r.points.duplicate_count == 0);
    CHECK(r.points.rejected_count == 0);
    CHECK(r.points.used_count == c.points);
    CHECK(r.triangle_count == run.count);
    CHECK(r.diagnostics.illegal_removed_count == 0);  // "on sound input this removes nothing"
    CHECK(run.count <= run.max_triangles);
    CHECK(run.workspace_guard_intact);
    CHECK(run.triangle_guard_intact);
    REQUIRE(r.layers.used_count >= 1);
    REQUIRE(run.layers.size() == r.layers.used_count);
    // Layers tile the extent along the axis, in order, and add up.
    size_t points = 0, triangles = 0, folds = 0;
    for (size_t l = 0; l < run.layers.size(); ++l) {
        const LayerInfo& info = run.layers[l];
        CHECK(info.bottom <= info.top);
        if (l > 0) CHECK(info.bottom == run.layers[l - 1].top);
        CHECK(info.radius > 0);
        points += info.point_count;
        triangles += info.triangle_count;
        folds += info.fold_count;
        CHECK(info.closed_ends == 0);  // these shapes are open tubes: both ends are rims
    }
    CHECK(points == r.points.used_count + r.points.unused_count);
    CHECK(c.layer_count_mismatches == 0);
    CHECK(triangles == run.count + r.diagnostics.illegal_removed_count);
    CHECK(folds == r.diagnostics.fold_count);
}

// Topology and coverage: one oriented manifold annulus through every point.
void check_topology(const Case& c) {
    const mesh_check::Result& m = c.mesh;
    CHECK(m.bad_indices == 0);
    CHECK(m.degenerate == 0);
    CHECK(m.zero_area == 0);
    CHECK(m.nonmanifold_edges == 0);
    CHECK(m.inconsistent_edges == 0);
    CHECK(m.nonmanifold_vertices == 0);
    CHECK(m.components == 1);
    CHECK(m.boundary_loops == 2);
    CHECK(m.simple_boundary);
    CHECK(m.euler == 0);
    CHECK(m.vertices_used == c.points);
    CHECK(m.unused_expected == 0);
}

void check_deviation(const Case& c) {
    const mesh_check::Result& m = c.mesh;
    double noise = 4 * c.noise;
    if (is_single_layer(c.layering)) {
        CHECK(m.max_deviation() <= kSingleLayerDeviation * c.spacing + noise);
        CHECK(m.max_interior_deviation <= kSingleLayerInteriorDeviation * c.spacing + noise);
    } else {
        CHECK(m.max_deviation() <= kLayeredDeviation * c.spacing + noise);
    }
}

// Orientation with the measured tolerance (strict with one layer), and the report's folds
// agreeing with the checker's count of triangles facing the true axis.
void check_orientation_bounded(const Case& c) {
    const mesh_check::Result& m = c.mesh;
    if (is_single_layer(c.layering)) {
        CHECK(m.inward == 0);
        CHECK(c.run.report.diagnostics.fold_count == 0);
    } else {
        CHECK(m.inward <= fold_allowance(c.run));
        size_t diff = m.inward > c.run.report.diagnostics.fold_count ? m.inward - c.run.report.diagnostics.fold_count : c.run.report.diagnostics.fold_count - m.inward;
        CHECK(diff <= 2 + m.inward / 10);
    }
}

std::string describe(const Case& c) {
    std::ostringstream s;
    s << c.name << ": status " << stratmesh::status_string(c.run.status) << ", " << c.run.count
      << " triangles, " << c.run.report.layers.used_count << " layers, folds " << c.run.report.diagnostics.fold_count
      << ", removed " << c.run.report.diagnostics.illegal_removed_count << ", unused " << c.run.report.points.unused_count
      << ", spacing " << c.spacing << "; " << c.mesh.summary();
    return s.str();
}

// ---- the shape matrix, computed once per shape and process ------------------------------

// For each shape: every pose and layering at kSmall points with the full check
// (self-intersections included); at kLarge points one pose (rotating through the poses from
// one shape to the next) with one layer, 6 equal layers and explicit cuts, self-
// intersections on the single-layer run only (the grid test costs about 60 ms a run there).
// Each shape has its own test case, so that ctest, which runs every test case in a process
// of its own, computes each shape once; the strict test cases for the library defects
// compute them all again.
struct ShapeRuns {
    std::vector<Case> small, large;
    double seconds = 0;
};

const ShapeRuns& shape_runs(size_t kind) {
    static std::vector<std::unique_ptr<ShapeRuns>> cache(shapes::kinds().size());
    std::unique_ptr<ShapeRuns>& slot = cache.at(kind);
    if (!slot) {
        slot.reset(new ShapeRuns);
        auto t0 = std::chrono::steady_clock::now();
        const Pose poses[] = {Pose::z, Pose::x, Pose::tilted};
        for (Pose pose : poses) {
            Shape s = shapes::kinds()[kind].make(kSmall, pose);
            for (Layering l : kLayerings) slot->small.push_back(run_case(s, l, true));
        }
        Shape big = shapes::kinds()[kind].make(kLarge, poses[kind % 3]);
        slot->large.push_back(run_case(big, Layering::single, true));
        slot->large.push_back(run_case(big, Layering::equal, false));
        slot->large.push_back(run_case(big, Layering::cuts, false));
        slot->seconds = elapsed_ms(t0) / 1000;
    }
    return *slot;
}

template <class F> void for_each_case(size_t kind, F&& check, bool layered_only = false) {
    const ShapeRuns& runs = shape_runs(kind);
    for (const std::vector<Case>* list : {&runs.small, &runs.large})
        for (const Case& c : *list) {
            if (layered_only && is_single_layer(c.layering)) continue;
            if (layered_only && c.run.report.layers.used_count < 2) continue;
            std::string context = describe(c);
            INFO(context);
            REQUIRE(c.run.status == Status::ok);
            check(c);
        }
}

// Everything that must hold for every run of a shape: status, report and layers, one
// manifold annulus through every point, bounded deviation, orientation (strict with one
// layer, the measured tolerance with several), no self-intersection with one layer.
void check_shape(size_t kind) {
    for_each_case(kind, [](const Case& c) {
        check_report(c);
        check_topology(c);
        check_deviation(c);
        check_orientation_bounded(c);
        if (c.checked_intersections && is_single_layer(c.layering)) {
            CHECK(c.mesh.intersecting_pairs == 0);
            CHECK(c.mesh.vertex_overlaps == 0);
        }
    });
    const ShapeRuns& runs = shape_runs(kind);
    double small_rec = 0, small_check = 0, large_rec = 0, large_check = 0;
    for (const Case& c : runs.small) small_rec += c.ms_reconstruct, small_check += c.ms_check;
    for (const Case& c : runs.large) large_rec += c.ms_reconstruct, large_check += c.ms_check;
    MESSAGE(std::string(shapes::kinds()[kind].name) << ": " << runs.small.size() << " runs at " << kSmall
                                     << " points (reconstruct " << small_rec << " ms, check " << small_check
                                     << " ms), " << runs.large.size() << " at " << kLarge << " points (reconstruct "
                                     << large_rec << " ms, check " << large_check << " ms); "
                                     << runs.seconds << " s with the clouds");
}

// ---- helpers for the contract tests -------------------------------------------------------

// A Z-pose cylinder whose reconstruction is the reference of several contract tests.
const Shape& reference_cylinder() {
    static const Shape s = shapes::cylinder(kSmall, Pose::z, 101);
    return s;
}

std::vector<double> copy_points(const Shape& s) { return s.xyz; }

Shape with_points(const Shape& s, std::vector<double> xyz, const std::string& suffix) {
    Shape out = s;
    out.xyz = std::move(xyz);
    out.name += suffix;
    return out;
}

}  // namespace

// ===========================================================================================
// The checker itself, on hand-made meshes.
// ===========================================================================================

namespace {

// A regular tube: columns x rows points on the unit cylinder, z in [0, rows - 1], outward
// counter-clockwise triangles.
void tube_mesh(size_t columns, size_t rows, double z0, std::vector<double>& xyz, std::vector<uint32_t>& tris) {
    size_t base = xyz.size() / 3;
    for (size_t j = 0; j < rows; ++j)
        for (size_t i = 0; i < columns; ++i) {
            double t = 2 * shapes::kPi * static_cast<double>(i) / static_cast<double>(columns);
            xyz.push_back(std::cos(t));
            xyz.push_back(std::sin(t));
            xyz.push_back(z0 + static_cast<double>(j) * 0.5);
        }
    auto id = [&](size_t i, size_t j) { return static_cast<uint32_t>(base + j * columns + i % columns); };
    for (size_t j = 0; j + 1 < rows; ++j)
        for (size_t i = 0; i < columns; ++i) {
            tris.insert(tris.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            tris.insert(tris.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
}

mesh_check::Result check_plain(const std::vector<double>& xyz, const std::vector<uint32_t>& tris,
                               const std::vector<char>* expected = nullptr) {
    mesh_check::Input in;
    in.points = xyz.data();
    in.point_count = xyz.size() / 3;
    in.triangles = tris.data();
    in.triangle_count = tris.size() / 3;
    in.expected_used = expected;
    in.surface = [](const double* p) { return std::sqrt(p[0] * p[0] + p[1] * p[1]) - 1; };
    return mesh_check::check(in);
}

}  // namespace

TEST_CASE("mesh checker: a regular tube is one oriented manifold annulus, outward, on the surface") {
    std::vector<double> xyz;
    std::vector<uint32_t> tris;
    tube_mesh(24, 10, 0, xyz, tris);
    mesh_check::Result r = check_plain(xyz, tris);
    INFO(r.summary());
    CHECK(r.manifold());
    CHECK(r.components == 1);
    CHECK(r.boundary_loops == 2);
    CHECK(r.simple_boundary);
    CHECK(r.loop_sizes == std::vector<size_t>{24, 24});
    CHECK(r.euler == 0);
    CHECK(r.inward == 0);
    CHECK(r.outward == tris.size() / 3);
    CHECK(r.unused_expected == 0);
    CHECK(r.intersecting_pairs == 0);
    CHECK(r.vertex_overlaps == 0);
    CHECK(r.pairs_tested > 0);
    // Chord midpoints of 24 columns sag by 1 - cos(pi / 24), centroids (two vertices on one
    // generatrix) by 1 - |e0 + 2 e1| / 3.
    CHECK(r.max_midpoint_deviation == doctest::Approx(1 - std::cos(shapes::kPi / 24)).epsilon(1e-9));
    CHECK(r.max_centroid_deviation ==
          doctest::Approx(1 - std::sqrt(5 + 4 * std::cos(shapes::kPi / 12)) / 3).epsilon(1e-9));
}

TEST_CASE("mesh checker: flipped, repeated, non-manifold and disconnected pieces are counted") {
    std::vector<double> xyz;
    std::vector<uint32_t> tris;
    tube_mesh(16, 6, 0, xyz, tris);
    SUBCASE("a flipped triangle: inconsistent edges and one inward triangle") {
        std::swap(tris[1], tris[2]);  // its third edge is on the boundary
        mesh_check::Result r = check_plain(xyz, tris);
        CHECK(r.inconsistent_edges == 2);
        CHECK(!r.oriented());
        CHECK(r.inward == 1);
    }
    SUBCASE("a repeated index and an index out of range") {
        tris.insert(tris.end(), {0, 0, 1, 0, 1, 999});
        mesh_check::Result r = check_plain(xyz, tris);
        CHECK(r.degenerate == 1);
        CHECK(r.bad_indices == 1);
        CHECK(r.manifold());
    }
    SUBCASE("an edge in three triangles") {
        xyz.insert(xyz.end(), {0.5, 0.5, 10});
        uint32_t extra = static_cast<uint32_t>(xyz.size() / 3 - 1);
        tris.insert(tris.end(), {tris[0], tris[2], extra});  // on a quad's diagonal
        mesh_check::Result r = check_plain(xyz, tris);
        CHECK(r.nonmanifold_edges == 1);
    }
    SUBCASE("two fans at one vertex (a bowtie) and a second component") {
        // A second tube above the first, sharing one vertex: its triangles around that
        // vertex form a second fan.
        std::vector<uint32_t> more;
        tube_mesh(16, 3, 10, xyz, more);
        for (uint32_t& v : more)
            if (v == 16 * 6) v = 0;  // glue the new tube's first point onto point 0
        tris.insert(tris.end(), more.begin(), more.end());
        mesh_check::Result r = check_plain(xyz, tris);
        CHECK(r.nonmanifold_vertices == 1);
        CHECK(r.components == 2);
        CHECK(r.boundary_loops == 3);  // the glued vertex joins two loops into one piece
        CHECK(!r.simple_boundary);
        CHECK(r.unused_expected == 1);  // the point glued away
    }
    SUBCASE("an expected-use mask") {
        xyz.insert(xyz.end(), {5, 5, 5});
        std::vector<char> mask(xyz.size() / 3, 1);
        mask.back() = 0;
        mask[3] = 0;
        mesh_check::Result r = check_plain(xyz, tris, &mask);
        CHECK(r.unused_expected == 0);
        CHECK(r.used_unexpected == 1);
    }
}

TEST_CASE("mesh checker: triangle-triangle intersection test") {
    using mesh_check::detail::V3;
    using mesh_check::detail::triangles_intersect;
    const V3 a[3] = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
    SUBCASE("crossing") {
        const V3 b[3] = {{0.5, 0.5, -1}, {0.5, 0.5, 1}, {1.5, -1, 0}};
        CHECK(triangles_intersect(a, b));
        CHECK(triangles_intersect(b, a));
    }
    SUBCASE("separated, and near misses") {
        const V3 b[3] = {{0, 0, 0.1}, {2, 0, 0.1}, {0, 2, 0.1}};
        CHECK(!triangles_intersect(a, b));
        const V3 c[3] = {{1.1, 1.1, -1}, {1.1, 1.1, 1}, {3, 3, 0}};  // beyond the hypotenuse
        CHECK(!triangles_intersect(a, c));
    }
    SUBCASE("touching in one point does not count") {
        const V3 b[3] = {{0.5, 0.5, 0}, {0.5, 0.5, 1}, {1, 1, 1}};  // a vertex on a's face
        CHECK(!triangles_intersect(a, b));
    }
    SUBCASE("coplanar: overlapping area counts, touching along an edge does not") {
        const V3 b[3] = {{0.5, 0.5, 0}, {3, 0.5, 0}, {0.5, 3, 0}};
        CHECK(triangles_intersect(a, b));
        const V3 c[3] = {{2, 0, 0}, {0, 2, 0}, {2, 2, 0}};
        CHECK(!triangles_intersect(a, c));
        const V3 d[3] = {{1, 1, 0}, {3, 1, 0}, {1, 3, 0}};  // a's hypotenuse touched at a point
        CHECK(!triangles_intersect(a, d));
    }
    SUBCASE("a shared vertex: overlap beyond it counts") {
        const V3 b[3] = {{0, 0, 0}, {1, 1, -1}, {1, 1, 1}};  // through a's interior from its corner
        CHECK(triangles_intersect(a, b, 0, 0));
        const V3 c[3] = {{0, 0, 0}, {-1, -1, -1}, {-1, -1, 1}};  // only the corner in common
        CHECK(!triangles_intersect(a, c, 0, 0));
    }
    SUBCASE("found through the grid in a mesh: a triangle piercing a tube") {
        std::vector<double> xyz;
        std::vector<uint32_t> tris;
        tube_mesh(32, 12, 0, xyz, tris);
        xyz.insert(xyz.end(), {0, 0, 2.6, 3, 0.1, 2.6, 3, -0.1, 2.7});
        uint32_t first = static_cast<uint32_t>(xyz.size() / 3 - 3);
        tris.insert(tris.end(), {first, first + 1, first + 2});
        mesh_check::Result r = check_plain(xyz, tris);
        CHECK(r.intersecting_pairs >= 1);
        CHECK(r.intersection_examples.size() >= 1);
    }
}

// ===========================================================================================
// The shape matrix.
// ===========================================================================================

TEST_CASE("reconstruction of the cylinder, every pose, size and layering") { check_shape(0); }
TEST_CASE("reconstruction of the elliptic tube, every pose, size and layering") { check_shape(1); }
TEST_CASE("reconstruction of the bumpy tube, every pose, size and layering") { check_shape(2); }
TEST_CASE("reconstruction of the cone, every pose, size and layering") { check_shape(3); }
TEST_CASE("reconstruction of the vase, every pose, size and layering") { check_shape(4); }
TEST_CASE("reconstruction of the cylindrical scan grid, every pose, size and layering") { check_shape(5); }
TEST_CASE("reconstruction of the CT slice stack, every pose, size and layering") { check_shape(6); }
TEST_CASE("reconstruction of the noisy tube, every pose, size and layering") { check_shape(7); }
TEST_CASE("reconstruction of the head, every pose, size and layering") { check_shape(8); }
TEST_CASE("reconstruction of the slanted tube, every pose, size and layering") { check_shape(9); }

// With several layers, the zipper bands used to hold triangles facing the axis: originally
// 16 several-layer runs of the matrix at 2000 points and 1 at 20000 points, one or two
// triangles each; untangling folded slivers and a second swap pass around the band's
// closing rung brought it down to the cone alone (6 runs, one triangle each), and
// untangling clockwise steps inside a run of one loop (untangle_runs) to none. A band joins
// two loops coarser than the point spacing (the lower layer's hull and the upper layer's
// centre link skip points close to the cut), so its triangles are flat slivers on the
// unrolled strip. Examples: cone, 2000 points, axis X, layer_height 0.75: triangle 2305
// (points 1702, 270, 773) faced the axis, cosine -0.91 (before the first fixes); cone,
// 2000 points, axis Z, 6 equal layers: triangle 2348 (points 513, 1462, 1124, two below
// the cut at local height -0.9974, one above, spanning 0.27 rad) cosine -0.014, inside a
// run of three A steps (before untangle_runs).
TEST_CASE("reconstruction with several layers: every triangle faces outward, no self-intersection") {
    for (size_t kind = 0; kind < shapes::kinds().size(); ++kind)
        for_each_case(kind, [](const Case& c) {
            CHECK(c.mesh.inward == 0);
            CHECK(c.run.report.diagnostics.fold_count == 0);
            if (!c.checked_intersections) return;
            CHECK(c.mesh.intersecting_pairs == 0);
            CHECK(c.mesh.vertex_overlaps == 0);
        }, true);
}

// The mean distance of a mesh from the true surface: its triangles' centroids' |deviation|,
// weighted by area. Point i is xyz + 3 i.
template <class Deviation>
double mean_centroid_deviation(const double* xyz, const std::vector<uint32_t>& triangles,
                               const Deviation& deviation) {
    double sum = 0, area = 0;
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const double* p[3] = {xyz + 3 * size_t(triangles[t]), xyz + 3 * size_t(triangles[t + 1]),
                              xyz + 3 * size_t(triangles[t + 2])};
        double u[3], v[3], centroid[3];
        for (int k = 0; k < 3; ++k) {
            u[k] = p[1][k] - p[0][k];
            v[k] = p[2][k] - p[0][k];
            centroid[k] = (p[0][k] + p[1][k] + p[2][k]) / 3;
        }
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
        double a = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        sum += a * std::fabs(deviation(centroid));
        area += a;
    }
    return area > 0 ? sum / area : 0;
}

double mean_centroid_deviation(const Shape& s, const std::vector<uint32_t>& triangles) {
    return mean_centroid_deviation(s.xyz.data(), triangles,
                                   [&s](const double* p) { return s.deviation(p); });
}

// The triangles of a mesh with an angle wider than `degrees`.
size_t triangles_wider_than(const Shape& s, const std::vector<uint32_t>& triangles,
                            double degrees) {
    const double limit = std::cos(degrees * 3.14159265358979323846 / 180);
    size_t wide = 0;
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        bool any = false;
        for (size_t k = 0; k < 3 && !any; ++k) {
            const double* o = s.xyz.data() + 3 * size_t(triangles[t + k]);
            const double* a = s.xyz.data() + 3 * size_t(triangles[t + (k + 1) % 3]);
            const double* b = s.xyz.data() + 3 * size_t(triangles[t + (k + 2) % 3]);
            double dot = 0, aa = 0, bb = 0;
            for (int i = 0; i < 3; ++i) {
                dot += (a[i] - o[i]) * (b[i] - o[i]);
                aa += (a[i] - o[i]) * (a[i] - o[i]);
                bb += (b[i] - o[i]) * (b[i] - o[i]);
            }
            any = dot < limit * std::sqrt(aa * bb);
        }
        wide += any;
    }
    return wide;
}

// A band between two layers used to join loops that skip the points next to the cut (the
// lower layer's hull, the upper layer's centre link), so its triangles spanned chords
// several spacings long and cut through the surface. This test's figure at 20,000 points, 24
// layers over one layer, before the loops were peeled: cylinder 2.78, elliptic tube 3.35,
// bumpy tube 3.02 (8 layers: 1.57, 1.70, 1.61); after: 1.54, 1.45, 1.26, cone 1.64, vase
// 1.12 (8 layers: 1.18, 1.15, 1.12, 1.27, 1.03), most of it from bands whose peeled loops
// were all put back for one fold; with only the peel groups around the folds put back
// (see add_group): 1.19, 1.14, 1.12, 1.30, 1.12 (8 layers: 1.06, 1.06, 1.04, 1.12, 1.03);
// with inner loops also peeled where they rise up to 63 degrees (kInnerPeelSlope, 45 at
// the surface's ends): 1.05, 1.10, 1.02, 1.09, 1.07 (8 layers: 1.02, 0.99, 1.01, 1.07,
// 1.01). The rest is the bands themselves: each seam still joins two fronts.
TEST_CASE("seams: many layers stay about as close to the true surface as one layer") {
    const std::vector<Shape> tubes = {shapes::cylinder(kLarge, Pose::z),
                                      shapes::elliptic_tube(kLarge, Pose::tilted),
                                      shapes::bumpy_tube(kLarge, Pose::x),
                                      shapes::cone(kLarge, Pose::z),
                                      shapes::vase(kLarge, Pose::tilted)};
    for (const Shape& s : tubes) {
        CAPTURE(s.name);
        double one = 0;
        for (size_t layers : {size_t(1), size_t(8), size_t(24)}) {
            CAPTURE(layers);
            Options o = axis_options(s);
            o.layer_count = static_cast<uint32_t>(layers);
            Run run = reconstruct_guarded(cloud_of(s), o);
            REQUIRE(run.status == Status::ok);
            REQUIRE(run.report.layers.used_count == layers);
            double mean = mean_centroid_deviation(s, run.triangles);
            MESSAGE(s.name << ", " << layers << " layers: mean distance " << mean);
            if (layers == 1) one = mean;
            CHECK(mean <= (layers == 8 ? 1.1 : 1.15) * one);
        }
    }
}

// A cross-section that is not star-shaped around its sector-mean centre: the outline of two
// overlapping discs (a shaft and a condyle). From any point of both discs the whole outline
// is visible, and from the fitted centre (in the big disc only) it is not: rays past the
// neck cross the small disc twice. The centre search must move the layer's centre into
// both discs. Before it, this test's figures were a centre at x = 0.53 (outside the small
// disc) and a mean distance of 0.0029; after, 0.89 and 0.0015.
TEST_CASE("centre search: a layer is unrolled around a centre that sees its whole outline") {
    const double big = 1.0, small = 0.7, small_x = 1.5;  // discs at (0, 0) and (small_x, 0)
    shapes::Rng rng(2026);
    std::vector<double> xyz;
    while (xyz.size() < 3 * 4000) {
        const double t = rng.uniform(0, 2 * shapes::kPi), z = rng.uniform(0, 2);
        const bool on_small = rng.uniform() < small / (big + small);  // evenly along the outline
        const double x = on_small ? small_x + small * std::cos(t) : big * std::cos(t);
        const double y = (on_small ? small : big) * std::sin(t);
        if (on_small ? std::hypot(x, y) < big : std::hypot(x - small_x, y) < small) continue;
        xyz.insert(xyz.end(), {x, y, z});
    }
    auto deviation = [&](const double* p) {
        return std::min(std::hypot(p[0], p[1]) - big, std::hypot(p[0] - small_x, p[1]) - small);
    };
    Cloud cloud = {xyz.data(), xyz.size() / 3, 0, Scalar::float64};
    Options o = {};
    o.axis = Axis::z;
    o.layer_count = 1;
    Run run = reconstruct_guarded(cloud, o);
    REQUIRE(run.status == Status::ok);
    REQUIRE(run.layers.size() == 1);
    const double* centre = run.layers[0].centre;
    CAPTURE(centre[0]);
    CAPTURE(centre[1]);
    CHECK(std::hypot(centre[0], centre[1]) < big);
    CHECK(std::hypot(centre[0] - small_x, centre[1]) < small);
    mesh_check::Input in;
    in.points = xyz.data();
    in.point_count = cloud.count;
    in.triangles = run.triangles.data();
    in.triangle_count = run.count;
    in.surface = deviation;
    const mesh_check::Result mesh = mesh_check::check(in);
    CHECK(mesh.nonmanifold_edges == 0);
    CHECK(mesh.nonmanifold_vertices == 0);
    CHECK(mesh.inconsistent_edges == 0);
    CHECK(mesh.components == 1);
    CHECK(mesh.boundary_loops == 2);
    CHECK(mesh.euler == 0);
    CHECK(mesh.unused_expected == 0);
    CHECK(mesh.intersecting_pairs == 0);
    const double mean = mean_centroid_deviation(xyz.data(), run.triangles, deviation);
    MESSAGE("two discs: centre x " << centre[0] << ", mean distance " << mean);
    CHECK(mean <= 0.002);
}

// ===========================================================================================
// Layers.
// ===========================================================================================

TEST_CASE("explicit cuts are positions dot(point, axis), in any order, repeats and outsiders ignored") {
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        Shape s = shapes::vase(kSmall, pose);
        CAPTURE(s.name);
        const double fractions[] = {0.2, 0.45, 0.7};
        std::vector<double> sorted, shuffled;
        for (double f : fractions) sorted.push_back(s.along_axis(s.z_min + f * (s.z_max - s.z_min)));
        shuffled = {sorted[2], sorted[0], 1e9, sorted[1], sorted[0], -1e9, sorted[2]};
        Options a = axis_options(s), b = axis_options(s);
        a.cuts = sorted.data();
        a.cut_count = sorted.size();
        b.cuts = shuffled.data();
        b.cut_count = shuffled.size();
        Run ra = reconstruct_guarded(cloud_of(s), a), rb = reconstruct_guarded(cloud_of(s), b);
        REQUIRE(ra.status == Status::ok);
        REQUIRE(rb.status == Status::ok);
        CHECK(ra.triangles == rb.triangles);
        REQUIRE(ra.report.layers.used_count == 4);
        for (size_t l = 0; l < 3; ++l) {
            CHECK(ra.layers[l].top == doctest::Approx(sorted[l]).epsilon(1e-12));
        }
        CHECK(std::fabs(ra.layers.front().bottom - s.along_axis(s.z_min)) < 0.05);
        CHECK(std::fabs(ra.layers.back().top - s.along_axis(s.z_max)) < 0.05);
        CHECK(ra.report.axis[0] * ra.layers[0].centre[0] + ra.report.axis[1] * ra.layers[0].centre[1] +
                  ra.report.axis[2] * ra.layers[0].centre[2] ==
              doctest::Approx((ra.layers[0].bottom + ra.layers[0].top) / 2));
    }
}

TEST_CASE("a cut on every contour plane: layers of one contour each, the top contour joining the last") {
    for (Pose pose : {Pose::z, Pose::x}) {
        Shape s = shapes::ct_slices(kSmall, pose);
        std::vector<double> cuts;
        for (double z : s.planes) cuts.push_back(s.along_axis(z));
        Options o = axis_options(s);
        o.cuts = cuts.data();
        o.cut_count = cuts.size();
        Case c;
        c.name = s.name + ", a cut on each of the " + std::to_string(s.planes.size()) + " planes";
        c.points = s.size();
        c.spacing = s.spacing;
        c.layering = Layering::cuts;
        c.run = reconstruct_guarded(cloud_of(s), o);
        c.mesh = check_mesh(s, c.run.triangles.data(), c.run.count, true);
        INFO(describe(c));
        REQUIRE(c.run.status == Status::ok);
        // The cut on the top plane would leave that contour alone in a last layer of no
        // height, too thin to stand: it joins the layer below.
        const size_t per_contour = s.size() / s.planes.size();
        REQUIRE(c.run.report.layers.used_count == s.planes.size() - 1);
        for (size_t k = 0; k + 1 < c.run.layers.size(); ++k) CHECK(c.run.layers[k].point_count == per_contour);
        CHECK(c.run.layers.back().point_count == 2 * per_contour);
        check_report(c);
        check_topology(c);
        check_deviation(c);
        CHECK(c.mesh.inward == 0);
        CHECK(c.mesh.intersecting_pairs == 0);
        CHECK(c.mesh.vertex_overlaps == 0);
    }
}

// With a tilted axis, dot(point, axis) of the points of one contour differs in the last
// bits, so a cut placed on a contour plane (the natural choice for CT data) used to split
// the contour between two layers: the two loops then interleaved on one circle and the
// band between them was made of flat, overlapping chord triangles (measured before the
// fix, 2000 points, 20 contours of 100: one cut on plane 12 gave 7 such triangles and 55
// intersecting pairs; a cut on each plane 51 and 293; layer_count 19, 118 and 713; the
// 44-row scan grid with a cut on each row 15 and 142). A point within 2^-40 of the height
// range below a cut now counts as on it, so the whole contour goes to the layer above, as
// with the Z and X axes where the same cuts are exact (see "a cut on every contour plane").
TEST_CASE("cuts on contour planes with a tilted axis") {
    struct Variant {
        const char* name;
        Shape shape;
        std::vector<double> cuts;
        uint32_t layer_count;
    };
    std::vector<Variant> variants;
    {
        Shape s = shapes::ct_slices(kSmall, Pose::tilted);
        variants.push_back({"one cut on plane 12", s, {s.along_axis(s.planes[12])}, 0});
        std::vector<double> all;
        for (double z : s.planes) all.push_back(s.along_axis(z));
        variants.push_back({"a cut on every plane", s, all, 0});
        variants.push_back({"layer_count 19: the planes up to rounding", s, {}, 19});
        Shape g = shapes::scan_grid(kSmall, Pose::tilted);
        std::vector<double> rows;
        for (double z : g.planes) rows.push_back(g.along_axis(z));
        variants.push_back({"scan grid, a cut on every row", g, rows, 0});
    }
    for (const Variant& v : variants) {
        Options o = axis_options(v.shape);
        o.cuts = v.cuts.empty() ? nullptr : v.cuts.data();
        o.cut_count = v.cuts.size();
        o.layer_count = v.layer_count;
        Run run = reconstruct_guarded(cloud_of(v.shape), o);
        mesh_check::Result m = check_mesh(v.shape, run.triangles.data(), run.count, true);
        INFO(v.shape.name << ", " << std::string(v.name) << ": " << run.report.layers.used_count << " layers, folds "
                          << run.report.diagnostics.fold_count << "; " << m.summary());
        REQUIRE(run.status == Status::ok);
        CHECK(m.manifold());  // holds
        CHECK(m.euler == 0);  // holds
        CHECK(m.inward == 0);
        CHECK(m.intersecting_pairs == 0);
        CHECK(m.vertex_overlaps == 0);
    }
}

TEST_CASE("a layer with fewer than 3 points is merged with the next one") {
    Shape s = reference_cylinder();
    // Heights along the axis, sorted: a cut just above the second lowest point leaves two
    // points in the bottom layer.
    std::vector<double> h;
    for (size_t i = 0; i < s.size(); ++i) h.push_back(s.point(i)[2]);
    std::sort(h.begin(), h.end());
    std::vector<double> cuts = {(h[1] + h[2]) / 2, s.along_axis(0.0)};
    Options o = axis_options(s);
    o.cuts = cuts.data();
    o.cut_count = cuts.size();
    Run run = reconstruct_guarded(cloud_of(s), o);
    REQUIRE(run.status == Status::ok);
    CHECK(run.report.layers.used_count == 2);  // three planned, the first merged
    REQUIRE(run.layers.size() == 2);
    CHECK(run.layers[0].bottom == doctest::Approx(h.front()).epsilon(1e-12));
    CHECK(run.layers[0].top == doctest::Approx(cuts[1]).epsilon(1e-12));
    mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, false);
    INFO(m.summary());
    CHECK(m.manifold());
    CHECK(m.boundary_loops == 2);
    CHECK(m.euler == 0);
    CHECK(m.unused_expected == 0);
}

// Layers of a few points each (many layers, or the automatic rule on a thin tube, whose
// layers are four radii tall): every layer is little more than its two loops and the bands
// do most of the work.
namespace {

struct ThinCase {
    const char* name;
    Shape shape;
    uint32_t layer_count;  // 0: automatic
};

std::vector<ThinCase> thin_layer_cases() {
    return {
        {"cylinder, layer_count 100 (20 points a layer)", shapes::cylinder(kSmall, Pose::z), 100},
        {"cylinder, layer_count 400", shapes::cylinder(kSmall, Pose::tilted), 400},
        {"vase, layer_count 200", shapes::vase(kSmall, Pose::z), 200},
        {"vase, layer_count 400", shapes::vase(kSmall, Pose::x), 400},
        {"thin tube (radius 0.01, seed 7), automatic layers", shapes::thin_tube(kSmall, Pose::z, 0.01, 7), 0},
    };
}

Run run_thin(const ThinCase& t) {
    Options o = axis_options(t.shape);
    o.layer_count = t.layer_count;
    return reconstruct_guarded(cloud_of(t.shape), o);
}

}  // namespace

TEST_CASE("many thin layers: the documented guarantees hold (manifold, oriented, counts add up)") {
    for (const ThinCase& t : thin_layer_cases()) {
        Run run = run_thin(t);
        mesh_check::Result m = check_mesh(t.shape, run.triangles.data(), run.count, false);
        INFO(std::string(t.name) << ": " << run.report.layers.used_count << " layers, removed " << run.report.diagnostics.illegal_removed_count
                    << ", unused " << run.report.points.unused_count << ", folds " << run.report.diagnostics.fold_count << "; " << m.summary());
        REQUIRE(run.status == Status::ok);
        CHECK(m.manifold());
        CHECK(m.degenerate == 0);
        CHECK(m.bad_indices == 0);
        CHECK(run.report.points.in_count == run.report.points.used_count + run.report.points.duplicate_count + run.report.points.rejected_count + run.report.points.unused_count);
        CHECK(m.vertices_used == run.report.points.used_count);
        CHECK(run.workspace_guard_intact);
        CHECK(run.triangle_guard_intact);
    }
}

// Layers of a few points used to make bands that fold and intersect, and the safety net
// then removed triangles, opening holes. Measured at 2000 points before layers needed two
// rows of points: cylinder with layer_count 100: 21 triangles facing the axis (cosine
// down to -0.97); layer_count 400 (tilted): 346 layers, 219 facing the axis, 94
// intersecting pairs; vase with layer_count 200: 2 points unused, 97 facing the axis;
// layer_count 400: 6 triangles removed, 3 boundary loops; thin tube of radius 0.01 with
// 149 automatic layers: a 4-edge hole. Now a layer thinner than two rows of points joins
// the next one, and a remainder that thin joins the last layer.
TEST_CASE("many thin layers: one annulus through every point, outward, no self-intersection") {
    for (const ThinCase& t : thin_layer_cases()) {
        Run run = run_thin(t);
        mesh_check::Result m = check_mesh(t.shape, run.triangles.data(), run.count, true);
        INFO(std::string(t.name) << ": " << run.report.layers.used_count << " layers, removed " << run.report.diagnostics.illegal_removed_count
                    << ", unused " << run.report.points.unused_count << ", folds " << run.report.diagnostics.fold_count << "; " << m.summary());
        REQUIRE(run.status == Status::ok);
        CHECK(run.report.diagnostics.illegal_removed_count == 0);
        CHECK(run.report.points.unused_count == 0);
        CHECK(m.components == 1);
        CHECK(m.boundary_loops == 2);
        CHECK(m.euler == 0);
        CHECK(m.inward == 0);
        CHECK(m.intersecting_pairs == 0);
        CHECK(m.vertex_overlaps == 0);
    }
}

// A cut that leaves a handful of points below it (0.2% of the height: 4 to 6 points at
// 2000) does not make a layer of its own: a layer needs 16 points unless it is the last,
// so it joins the next one, and the surface stays a clean annulus.
TEST_CASE("a layer of a few points is merged with the next, and the surface stays a manifold annulus") {
    for (Pose pose : {Pose::z, Pose::tilted}) {
        Shape s = shapes::elliptic_tube(kSmall, pose);
        std::vector<double> cuts;
        for (double f : {0.002, 0.05, 0.5}) cuts.push_back(s.along_axis(s.z_min + f * (s.z_max - s.z_min)));
        Options o = axis_options(s);
        o.cuts = cuts.data();
        o.cut_count = cuts.size();
        Case c;
        c.name = s.name + ", a layer of 0.2% of the height";
        c.points = s.size();
        c.spacing = s.spacing;
        c.layering = Layering::cuts;
        c.run = reconstruct_guarded(cloud_of(s), o);
        c.mesh = check_mesh(s, c.run.triangles.data(), c.run.count, true);
        INFO(describe(c));
        REQUIRE(c.run.status == Status::ok);
        check_report(c);
        check_topology(c);
        REQUIRE(c.run.layers.size() == 3);
        CHECK(c.run.layers[0].point_count >= 16);
        CHECK(c.mesh.max_deviation() < 4 * c.spacing);
    }
}

TEST_CASE("automatic axis: the principal direction of an elongated cloud") {
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        Shape s = shapes::bumpy_tube(kSmall, pose);
        Options o = {};
        o.layer_count = 1;
        Run run = reconstruct_guarded(cloud_of(s), o);
        REQUIRE(run.status == Status::ok);
        double axis[3];
        s.axis_direction(axis);
        double d = axis[0] * run.report.axis[0] + axis[1] * run.report.axis[1] + axis[2] * run.report.axis[2];
        CHECK(std::fabs(d) > 0.999);
        Case c;
        c.name = s.name + ", automatic axis";
        c.points = s.size();
        c.spacing = s.spacing;
        c.run = run;
        c.mesh = check_mesh(s, run.triangles.data(), run.count, true);
        INFO(describe(c));
        check_report(c);
        check_topology(c);
        check_deviation(c);
        CHECK(c.mesh.inward == 0);
        CHECK(c.mesh.intersecting_pairs == 0);
    }
}

// ===========================================================================================
// The paper's experiment: a head-like column cut at anatomical heights.
// ===========================================================================================

namespace {

// Cuts like the paper's: base of the neck, under the jaw, under the nose, over the nose, at
// the eyes, on the forehead (local heights of shapes::head_radius).
Case head_case(Pose pose, size_t n) {
    Shape s = shapes::head(n, pose);
    std::vector<double> cuts;
    for (double z : {0.35, 0.8, 1.38, 1.72, 1.9, 2.15}) cuts.push_back(s.along_axis(z));
    Options o = axis_options(s);
    o.cuts = cuts.data();
    o.cut_count = cuts.size();
    Case c;
    c.name = s.name + ", " + std::to_string(n) + " points, anatomical cuts";
    c.points = s.size();
    c.spacing = s.spacing;
    c.layering = Layering::cuts;
    c.run = reconstruct_guarded(cloud_of(s), o);
    c.mesh = check_mesh(s, c.run.triangles.data(), c.run.count, true);
    return c;
}

}  // namespace

TEST_CASE("head: neck, skull and nose with the paper's anatomical cuts") {
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        Case c = head_case(pose, 6000);
        INFO(describe(c));
        REQUIRE(c.run.status == Status::ok);
        CHECK(c.run.report.layers.used_count == 7);
        check_report(c);
        check_topology(c);
        check_deviation(c);
        check_orientation_bounded(c);
        // Measured: no fold and no self-intersection here, at 2000 to 20000 points.
        CHECK(c.mesh.inward == 0);
        CHECK(c.run.report.diagnostics.fold_count == 0);
        CHECK(c.mesh.intersecting_pairs == 0);
        CHECK(c.mesh.vertex_overlaps == 0);
    }
}

// ===========================================================================================
// The contract: determinism, input formats, duplicates, invalid points, statuses, memory.
// ===========================================================================================

TEST_CASE("determinism: repeated runs, and any workspace alignment, give identical triangles") {
    struct Item {
        Shape shape;
        Layering layering;
    };
    std::vector<Item> items = {
        {shapes::bumpy_tube(kSmall, Pose::tilted), Layering::equal},
        {shapes::scan_grid(kSmall, Pose::z), Layering::single},
        {shapes::ct_slices(kSmall, Pose::x), Layering::cuts},
        {shapes::noisy_tube(kSmall, Pose::x), Layering::height},
        {shapes::vase(kLarge, Pose::tilted), Layering::uneven},
    };
    for (const Item& item : items) {
        std::vector<double> cuts;
        Options o = layered_options(item.shape, item.layering, cuts);
        CAPTURE(item.shape.name);
        Run first = reconstruct_guarded(cloud_of(item.shape), o, 0);
        REQUIRE(first.status == Status::ok);
        for (size_t misalign : {size_t{0}, size_t{1}, size_t{3}, size_t{8}}) {
            CAPTURE(misalign);
            Run again = reconstruct_guarded(cloud_of(item.shape), o, misalign);
            REQUIRE(again.status == Status::ok);
            CHECK(again.triangles == first.triangles);
            CHECK(again.report.diagnostics.fold_count == first.report.diagnostics.fold_count);
            CHECK(again.report.layers.used_count == first.report.layers.used_count);
            CHECK(std::memcmp(again.report.axis_origin, first.report.axis_origin, sizeof first.report.axis_origin) == 0);
        }
    }
}

TEST_CASE("float32 records with a stride of 7 floats give the triangles of the same points as packed doubles") {
    for (Pose pose : {Pose::z, Pose::tilted}) {
        Shape s = shapes::noisy_tube(kSmall, pose);
        const size_t n = s.size();
        std::vector<float> records(7 * n);
        std::vector<double> doubles(3 * n);
        for (size_t i = 0; i < n; ++i) {
            for (size_t k = 0; k < 3; ++k) {
                float f = static_cast<float>(s.xyz[3 * i + k]);
                records[7 * i + k] = f;
                doubles[3 * i + k] = static_cast<double>(f);
            }
            records[7 * i + 3] = 0.6f;  // normal
            records[7 * i + 4] = -0.8f;
            records[7 * i + 5] = 0.0f;
            records[7 * i + 6] = static_cast<float>(i % 255);  // intensity
        }
        for (Layering layering : {Layering::single, Layering::equal}) {
            std::vector<double> cuts;
            Options o = layered_options(s, layering, cuts);
            Run packed = reconstruct_guarded(Cloud{doubles.data(), n, 0, Scalar::float64}, o);
            Run strided = reconstruct_guarded(Cloud{records.data(), n, 7 * sizeof(float), Scalar::float32}, o);
            CAPTURE(s.name);
            INFO("layering: " << std::string(layering_name(layering)));
            REQUIRE(packed.status == Status::ok);
            REQUIRE(strided.status == Status::ok);
            CHECK(strided.triangles == packed.triangles);
            CHECK(strided.report.points.used_count == n);
            // And doubles with the same stride of 56 bytes (7 doubles) read the same.
            std::vector<double> wide(7 * n, 0.0);
            for (size_t i = 0; i < n; ++i)
                for (size_t k = 0; k < 3; ++k) wide[7 * i + k] = doubles[3 * i + k];
            Run wide_run = reconstruct_guarded(Cloud{wide.data(), n, 7 * sizeof(double), Scalar::float64}, o);
            REQUIRE(wide_run.status == Status::ok);
            CHECK(wide_run.triangles == packed.triangles);
        }
    }
}

TEST_CASE("duplicates are merged into the lowest index and counted") {
    const Shape& base = reference_cylinder();
    // Interleave exact copies: every 37th point twice more right after itself, every 101st
    // point once at the end, and a point with x = +0.0 followed by its twin with x = -0.0.
    std::vector<double> xyz;
    std::vector<char> first_of_group;
    size_t copies = 0;
    auto push = [&](const double* p, bool first) {
        xyz.insert(xyz.end(), p, p + 3);
        first_of_group.push_back(first ? 1 : 0);
    };
    for (size_t i = 0; i < base.size(); ++i) {
        push(base.point(i), true);
        if (i % 37 == 0) {
            push(base.point(i), false);
            push(base.point(i), false);
            copies += 2;
        }
    }
    for (size_t i = 0; i < base.size(); i += 101) {
        push(base.point(i), false);
        ++copies;
    }
    // On the cylinder of axis (0.25, -0.5): x = 0 at y = -0.5 + sqrt(1 - 0.0625).
    const double on_axis_side[3] = {0.0, -0.5 + std::sqrt(0.9375), 1.5};
    const double negative_zero[3] = {-0.0, on_axis_side[1], on_axis_side[2]};
    push(on_axis_side, true);
    push(negative_zero, false);
    ++copies;
    Shape s = with_points(base, xyz, ", with duplicates");
    for (Layering layering : {Layering::single, Layering::equal}) {
        std::vector<double> cuts;
        Options o = layered_options(s, layering, cuts);
        Run run = reconstruct_guarded(cloud_of(s), o);
        INFO("layering: " << std::string(layering_name(layering)));
        REQUIRE(run.status == Status::ok);
        CHECK(run.report.points.duplicate_count == copies);
        CHECK(run.report.points.used_count == s.size() - copies);
        CHECK(run.report.points.unused_count == 0);
        CHECK(run.report.points.in_count == run.report.points.used_count + run.report.points.duplicate_count + run.report.points.rejected_count + run.report.points.unused_count);
        mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, false, &first_of_group);
        INFO(m.summary());
        CHECK(m.unused_expected == 0);   // every first occurrence is a vertex
        CHECK(m.used_unexpected == 0);   // no later copy is
        CHECK(m.manifold());
        CHECK(m.components == 1);
        CHECK(m.boundary_loops == 2);
        CHECK(m.euler == 0);
        CHECK(m.degenerate == 0);
        CHECK(m.zero_area == 0);
    }
}

// "points_in = points_used + duplicates + rejected + unused, always", also when reconstruct
// stops after the layers were built. Found failing at commit aa58fe1 (the 2000-point
// reference cylinder plus 200 exact copies, one layer, a capacity of 10 triangles:
// points_in 2200, points_used 0, duplicates 200, unused 2200; six layers with 40% of the
// workspace bound: out_of_memory with the same counts); holds since commit 3d26d49.
TEST_CASE("report counts add up on every status, with duplicates") {
    const Shape& base = reference_cylinder();
    std::vector<double> xyz = copy_points(base);
    for (size_t i = 0; i < base.size(); i += 10) xyz.insert(xyz.end(), base.point(i), base.point(i) + 3);
    const size_t n = xyz.size() / 3;
    const Cloud cloud = {xyz.data(), n, 0, Scalar::float64};
    for (uint32_t layers : {1u, 6u}) {
        Options o = axis_options(base);
        o.layer_count = layers;
        const size_t bound = stratmesh::reconstruct_workspace_size(n, o);
        const size_t capacity = stratmesh::reconstruct_max_triangles(n, o);
        std::vector<uint32_t> tris(3 * capacity);
        auto check_sum = [&](size_t bytes, size_t triangle_capacity) {
            std::unique_ptr<unsigned char[]> work(new unsigned char[bytes]);
            size_t count = 0;
            Report r{};
            Status status = stratmesh::reconstruct(cloud, o, work.get(), bytes, tris.data(), triangle_capacity, &count, &r);
            INFO(layers << " layers, " << bytes << " of " << bound << " workspace bytes, capacity " << triangle_capacity
                        << ": " << std::string(stratmesh::status_string(status)) << "; in " << r.points.in_count << ", used "
                        << r.points.used_count << ", duplicates " << r.points.duplicate_count << ", rejected " << r.points.rejected_count
                        << ", unused " << r.points.unused_count);
            CHECK(r.points.in_count == n);
            CHECK(r.points.in_count == r.points.used_count + r.points.duplicate_count + r.points.rejected_count + r.points.unused_count);
            return status;
        };
        CHECK(check_sum(bound, capacity) == Status::ok);
        CHECK(check_sum(bound, 10) == Status::triangle_capacity);
        for (size_t fifths = 1; fifths < 5; ++fifths) check_sum(bound * fifths / 5, capacity);
        check_sum(bound * 19 / 20, capacity);
    }
}

TEST_CASE("NaN and infinite points: invalid_point with the first index, or skipped and counted") {
    const Shape& base = reference_cylinder();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    struct Bad {
        size_t index;
        size_t coordinate;
        double value;
    };
    const std::vector<Bad> bads = {{777, 0, nan}, {123, 2, inf}, {1999, 1, -inf}, {0, 1, nan}};
    std::vector<double> xyz = copy_points(base);
    for (const Bad& b : bads) xyz[3 * b.index + b.coordinate] = b.value;
    Shape s = with_points(base, xyz, ", with NaN and infinite points");

    SUBCASE("refused by default: invalid_point, first index, nothing written") {
        Options o = axis_options(s);
        o.layer_count = 3;
        Run run = reconstruct_guarded(cloud_of(s), o);
        CHECK(run.status == Status::invalid_point);
        CHECK(run.report.points.first_invalid_index == 0);
        CHECK(run.count == 0);
        CHECK(run.triangle_guard_intact);
        CHECK(run.report.points.in_count == run.report.points.used_count + run.report.points.duplicate_count + run.report.points.rejected_count + run.report.points.unused_count);
        CHECK(run.report.detail != nullptr);
        // Without the point at index 0, the first is 123.
        std::vector<double> later = xyz;
        for (size_t k = 0; k < 3; ++k) later[k] = base.xyz[k];
        Run run2 = reconstruct_guarded(Cloud{later.data(), base.size(), 0, Scalar::float64}, o);
        CHECK(run2.status == Status::invalid_point);
        CHECK(run2.report.points.first_invalid_index == 123);
        // float32 NaN in a strided record.
        std::vector<float> records(4 * base.size(), 0.0f);
        for (size_t i = 0; i < base.size(); ++i)
            for (size_t k = 0; k < 3; ++k) records[4 * i + k] = static_cast<float>(base.xyz[3 * i + k]);
        records[4 * 500 + 2] = std::numeric_limits<float>::quiet_NaN();
        Run run3 = reconstruct_guarded(Cloud{records.data(), base.size(), 4 * sizeof(float), Scalar::float32}, o);
        CHECK(run3.status == Status::invalid_point);
        CHECK(run3.report.points.first_invalid_index == 500);
    }
    SUBCASE("skipped with skip_invalid_points: counted as rejected, never a vertex") {
        for (uint32_t layers : {1u, 6u}) {
            Options o = axis_options(s);
            o.layer_count = static_cast<uint32_t>(layers);
            o.flags = stratmesh::skip_invalid_points;
            Run run = reconstruct_guarded(cloud_of(s), o);
            CAPTURE(layers);
            REQUIRE(run.status == Status::ok);
            CHECK(run.report.points.rejected_count == bads.size());
            CHECK(run.report.points.unused_count == 0);
            CHECK(run.report.points.used_count == s.size() - bads.size());
            CHECK(run.report.points.in_count == run.report.points.used_count + run.report.points.duplicate_count + run.report.points.rejected_count + run.report.points.unused_count);
            std::vector<char> mask(s.size(), 1);
            for (const Bad& b : bads) mask[b.index] = 0;
            // The checker needs finite coordinates: check the mesh on the clean copy.
            mesh_check::Result m = check_mesh(base, run.triangles.data(), run.count, false, &mask);
            INFO(m.summary());
            CHECK(m.used_unexpected == 0);
            CHECK(m.unused_expected == 0);
            CHECK(m.manifold());
            CHECK(m.components == 1);
            CHECK(m.boundary_loops == 2);
            CHECK(m.euler == 0);
        }
    }
}

// Stray points around a shape: `far` single ones at 1 to 3 bounding-box diagonals from its
// centre, and a speck of `speck` points within a tenth of the spacing of one another, two
// diagonals off the centre along each axis; appended after the shape's own points.
std::vector<double> with_strays(const Shape& s, size_t far, size_t speck, uint64_t seed) {
    double low[3] = {1e300, 1e300, 1e300}, high[3] = {-1e300, -1e300, -1e300};
    for (size_t i = 0; i < s.size(); ++i)
        for (size_t k = 0; k < 3; ++k) {
            low[k] = std::min(low[k], s.point(i)[k]);
            high[k] = std::max(high[k], s.point(i)[k]);
        }
    const double diagonal = std::hypot(high[0] - low[0], high[1] - low[1], high[2] - low[2]);
    shapes::Rng rng(seed);
    auto direction = [&rng](double* d) {
        double len = 0;
        do {
            for (size_t k = 0; k < 3; ++k) d[k] = rng.uniform(-1, 1);
            len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        } while (len < 0.1 || len > 1);
        for (size_t k = 0; k < 3; ++k) d[k] /= len;
    };
    std::vector<double> xyz = s.xyz;
    for (size_t i = 0; i < far + speck; ++i) {
        double d[3];
        direction(d);
        const double reach = i < far ? rng.uniform(1, 3) * diagonal : 2 * diagonal;
        for (size_t k = 0; k < 3; ++k) {
            const double centre = (low[k] + high[k]) / 2;
            xyz.push_back(i < far ? centre + reach * d[k] : centre + reach + 0.1 * s.spacing * d[k]);
        }
    }
    return xyz;
}

TEST_CASE("drop_outliers: stray points are left out and counted, the rest is meshed as without them") {
    const std::vector<std::function<Shape(Pose)>> makers = {
        [](Pose p) { return shapes::cylinder(kSmall, p); },
        [](Pose p) { return shapes::bumpy_tube(kSmall, p); },
        [](Pose p) { return shapes::vase(kSmall, p); },
        [](Pose p) { return shapes::scan_grid(kSmall, p); },
        [](Pose p) { return shapes::ct_slices(kSmall, p); },
        [](Pose p) { return shapes::noisy_tube(kSmall, p); },
        [](Pose p) { return shapes::head(kSmall, p); },
        [](Pose p) { return shapes::capsule(kSmall, p); },
        [](Pose p) { return shapes::bumpy_tube(kLarge, p); },
    };
    const size_t far = 12, speck = 5;
    for (const auto& make : makers) {
        for (Pose pose : {Pose::z, Pose::tilted}) {
            const Shape s = make(pose);
            CAPTURE(s.name);
            for (bool automatic : {true, false}) {
                CAPTURE(automatic);
                Options plain = axis_options(s);
                if (automatic) plain.axis = Axis::automatic;
                Options dropping = plain;
                dropping.flags = stratmesh::drop_outliers;
                const Run clean = reconstruct_guarded(cloud_of(s), plain);
                REQUIRE(clean.status == Status::ok);
                // No point of a clean sample is taken for an outlier.
                const Run kept = reconstruct_guarded(cloud_of(s), dropping);
                REQUIRE(kept.status == Status::ok);
                CHECK(kept.report.points.outlier_count == 0);
                CHECK(kept.report.points.rejected_count == 0);
                CHECK(kept.triangles == clean.triangles);
                // Every stray is left out, counted, and the surface is the clean one: the
                // frame, the axis and the layers come from the same points.
                const Shape dirty = with_points(s, with_strays(s, far, speck, 31), ", with strays");
                const Run dropped = reconstruct_guarded(cloud_of(dirty), dropping);
                REQUIRE(dropped.status == Status::ok);
                CHECK(dropped.report.points.outlier_count == far + speck);
                CHECK(dropped.report.points.rejected_count == far + speck);
                CHECK(dropped.report.points.used_count == clean.report.points.used_count);
                CHECK(dropped.report.points.in_count == dropped.report.points.used_count + dropped.report.points.duplicate_count +
                                                      dropped.report.points.rejected_count + dropped.report.points.unused_count);
                CHECK(dropped.triangles == clean.triangles);
                CHECK(dropped.workspace_guard_intact);
                // Without the flag every stray is a vertex, and the surface stays one
                // oriented manifold (its shape is another matter: spikes).
                const Run spiked = reconstruct_guarded(cloud_of(dirty), plain);
                REQUIRE(spiked.status == Status::ok);
                CHECK(spiked.report.points.unused_count == 0);
                CHECK(spiked.report.points.outlier_count == 0);
                mesh_check::Result m = check_mesh(dirty, spiked.triangles.data(), spiked.count, false);
                INFO(m.summary());
                CHECK(m.nonmanifold_edges == 0);
                CHECK(m.nonmanifold_vertices == 0);
                CHECK(m.inconsistent_edges == 0);
            }
        }
    }
}

TEST_CASE("drop_outliers: a speck of 7 points is left out and one of 8 kept, repeats of a stray too") {
    const Shape& s = reference_cylinder();
    // Far from the cylinder, points a hundredth of its spacing apart: one cell of the grid.
    auto with_speck = [&s](size_t points, size_t repeats_of_first) {
        std::vector<double> xyz = s.xyz;
        for (size_t i = 0; i < points; ++i)
            for (size_t k = 0; k < 3; ++k) xyz.push_back(50 + (k == i % 3 ? 0.01 * s.spacing * static_cast<double>(i) : 0));
        for (size_t r = 0; r < repeats_of_first; ++r) xyz.insert(xyz.end(), {50, 50, 50});
        return with_points(s, xyz, ", with a speck");
    };
    Options o = axis_options(s);
    o.flags = stratmesh::drop_outliers;
    for (size_t points : {1u, 7u, 8u, 12u}) {
        CAPTURE(points);
        const Shape speck = with_speck(points, 0);
        const Run run = reconstruct_guarded(cloud_of(speck), o);
        REQUIRE(run.status == Status::ok);
        CHECK(run.report.points.outlier_count == (points < 8 ? points : 0));
        CHECK(run.report.points.in_count == run.report.points.used_count + run.report.points.duplicate_count +
                                          run.report.points.rejected_count + run.report.points.unused_count);
    }
    // A stray read three times: all three copies are outliers, none a duplicate.
    const Run repeated = reconstruct_guarded(cloud_of(with_speck(1, 2)), o);
    REQUIRE(repeated.status == Status::ok);
    CHECK(repeated.report.points.outlier_count == 3);
    CHECK(repeated.report.points.duplicate_count == 0);
    CHECK(repeated.report.points.used_count == s.size());
}

TEST_CASE("drop_outliers: the stream refuses it, and too small a workspace is out_of_memory") {
    const Shape& s = reference_cylinder();
    Options o = axis_options(s);
    o.flags = stratmesh::drop_outliers;
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(s.size(), o));
    stratmesh::Stream* stream = nullptr;
    CHECK(stratmesh::stream_open(o, work.data(), work.size(), [](void*, const uint32_t*, size_t) {},
                                 nullptr, nullptr, &stream) == Status::invalid_argument);
    const size_t bytes = stratmesh::reconstruct_workspace_size(s.size(), o);
    o.flags = 0;
    CHECK(bytes > stratmesh::reconstruct_workspace_size(s.size(), o));  // its bitmap
    o.flags = stratmesh::drop_outliers;
    std::vector<unsigned char> small(s.size() * 8);
    std::vector<uint32_t> triangles(3 * stratmesh::reconstruct_max_triangles(s.size(), o));
    size_t count = 0;
    stratmesh::Report report = {};
    CHECK(stratmesh::reconstruct(cloud_of(s), o, small.data(), small.size(), triangles.data(),
                                 triangles.size() / 3, &count, &report) == Status::out_of_memory);
    CHECK(report.points.in_count == report.points.used_count + report.points.duplicate_count + report.points.rejected_count + report.points.unused_count);
}

TEST_CASE("a flat cloud gives flat_cloud") {
    shapes::Rng rng(5);
    std::vector<double> xyz;
    for (size_t i = 0; i < 500; ++i) {
        double t = rng.uniform(0, 2 * shapes::kPi), r = rng.uniform(0.5, 1.5);
        xyz.insert(xyz.end(), {r * std::cos(t), r * std::sin(t), 4.25});
    }
    Options o = {};
    o.axis = Axis::z;
    Run run = reconstruct_guarded(Cloud{xyz.data(), 500, 0, Scalar::float64}, o);
    CHECK(run.status == Status::flat_cloud);
    CHECK(run.count == 0);
    CHECK(run.triangle_guard_intact);
    CHECK(run.report.points.unused_count == 500);
    CHECK(run.report.points.in_count == run.report.points.used_count + run.report.points.duplicate_count + run.report.points.rejected_count + run.report.points.unused_count);
    CHECK(run.report.detail != nullptr);
    // The same disc stood on its edge (axis X across the disc) is not flat.
    o.axis = Axis::x;
    Run across = reconstruct_guarded(Cloud{xyz.data(), 500, 0, Scalar::float64}, o);
    CHECK(across.status != Status::flat_cloud);
}

// Measured: the unrolling centre of a layer is fitted to its points (the mean of
// per-sector means around their centroid), so a half-cylinder (theta in [0, pi]) is
// surrounded by its points as seen from that centre: reconstruct returns ok and closes the
// tube with a strip across the open side (60 of 3973 triangles there face the true axis at
// 2000 points, one layer). Only a cloud whose points cannot surround any centre (a plane
// through the axis, or points on the axis) gives not_columnar.
// The widest angle around the shape's true axis (degrees) that none of the points of s
// with dot(p, axis) in [bottom, top) falls in.
double widest_empty_angle(const Shape& s, double bottom, double top) {
    std::vector<double> angles;
    double a[3];
    s.axis_direction(a);
    for (size_t i = 0; i < s.size(); ++i) {
        double local[3];
        s.transform.unapply(s.point(i), local);
        const double* p = s.point(i);
        const double h = p[0] * a[0] + p[1] * a[1] + p[2] * a[2];
        if (h >= bottom && h < top) angles.push_back(std::atan2(local[1], local[0]) * 180 / shapes::kPi);
    }
    if (angles.empty()) return 360;
    std::sort(angles.begin(), angles.end());
    double widest = angles.front() + 360 - angles.back();
    for (size_t i = 1; i < angles.size(); ++i) widest = std::max(widest, angles[i] - angles[i - 1]);
    return widest;
}

// Equal layers of a tube cut at a slant: the end layers hold crescents (widest empty angle
// about 80 degrees with 12 layers), which used to be closed by a membrane across the tube.
TEST_CASE("a crescent end layer joins its neighbour, a half cylinder keeps its layers") {
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        for (uint32_t planned : {6u, 12u, 24u}) {
            Shape s = shapes::slanted_tube(kSmall, pose);
            Options o = axis_options(s);
            o.layer_count = planned;
            Run run = reconstruct_guarded(cloud_of(s), o);
            CAPTURE(s.name);
            CAPTURE(planned);
            REQUIRE(run.status == Status::ok);
            CHECK(run.report.layers.used_count < planned);
            double widest = 0;
            for (const LayerInfo& layer : run.layers)
                widest = std::max(widest, widest_empty_angle(s, layer.bottom, layer.top));
            CHECK(widest < 45);
            mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, true);
            INFO(m.summary());
            CHECK(m.manifold());
            CHECK(m.boundary_loops == 2);
            CHECK(m.unused_expected == 0);
            CHECK(m.max_deviation() <= kLayeredDeviation * s.spacing);
            CHECK(m.intersecting_pairs == 0);
        }
    }
    for (uint32_t planned : {6u, 12u}) {
        Shape s = shapes::half_cylinder(kLarge, Pose::tilted);
        Options o = axis_options(s);
        o.layer_count = planned;
        Run run = reconstruct_guarded(cloud_of(s), o);
        REQUIRE(run.status == Status::ok);
        CHECK(run.report.layers.used_count == planned);
    }
}

namespace {

// Reconstructs s as one tube (Parts::one_tube) in `planned` layers along its axis and
// checks what every run must give:
// ok, one manifold tube (one component, two boundary loops) through every point. The mesh
// check (with self-intersections if asked) goes to *m; `flags` are added to the options.
Run reconstruct_tube(const Shape& s, uint32_t planned, bool self_intersections, mesh_check::Result* m,
                     uint32_t flags = 0) {
    Options o = axis_options(s);
    o.layer_count = planned;
    o.flags |= flags;
    o.parts = stratmesh::Parts::one_tube;
    Run run = reconstruct_guarded(cloud_of(s), o);
    REQUIRE(run.status == Status::ok);
    CHECK(run.report.points.unused_count == 0);
    *m = check_mesh(s, run.triangles.data(), run.count, self_intersections);
    INFO(m->summary());
    CHECK(m->manifold());
    CHECK(m->components == 1);
    CHECK(m->boundary_loops == 2);
    CHECK(m->unused_expected == 0);
    return run;
}

// s (a closed shape) cut in `planned` layers along its axis with `flags`: reconstruct_tube's
// checks, an Euler characteristic of 0 and no self-intersection.
Run reconstruct_closed_shape(const Shape& s, uint32_t planned, uint32_t flags) {
    mesh_check::Result m;
    Run run = reconstruct_tube(s, planned, true, &m, flags);
    INFO(m.summary());
    CHECK(m.euler == 0);
    CHECK(m.intersecting_pairs == 0);
    REQUIRE(run.layers.size() == run.report.layers.used_count);
    return run;
}

// How far from s's axis the farthest vertex of run's boundary loops lies.
double widest_boundary_vertex(const Shape& s, const Run& run) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t t = 0; t < run.count; ++t)
        for (size_t k = 0; k < 3; ++k) {
            uint32_t a = run.triangles[3 * t + k], b = run.triangles[3 * t + (k + 1) % 3];
            ++edges[{std::min(a, b), std::max(a, b)}];
        }
    double widest = 0;
    for (const auto& e : edges) {
        if (e.second != 1) continue;
        for (uint32_t v : {e.first.first, e.first.second}) {
            double local[3];
            s.transform.unapply(s.point(v), local);
            widest = std::max(widest, std::hypot(local[0], local[1]));
        }
    }
    return widest;
}

// The flat-ended cylinder (`flat`) or the capsule.
Shape closed_shape(bool flat, Pose pose) {
    return flat ? shapes::closed_cylinder(kSmall, pose) : shapes::capsule(kSmall, pose);
}

}  // namespace

// A closed object scanned all round has points across its ends. The surface must still be
// one manifold annulus through every point, now meshed across each end up to a small loop
// around its pole, outward, and close to the true surface there too. Before the ends were
// unrolled around poles, the flat discs' points lay on one circle of the annulus: the
// loops ran through the whole discs (vertices up to the rim, 1 from the axis), the volume
// was 0.83 of the solid's and the mean distance 0.014 to 0.016 (now 0.0053 to 0.0067,
// bound 0.0089); the capsule's 0.0060 to 0.0065 (now 0.0054 to 0.0063). Boundary vertices
// now lie up to 0.26 from the axis (0.37 on the capsule in 12 layers while the end slab was
// a quarter of the layer: its lower dome was not taken for a closed end).
TEST_CASE("closed ends: a flat-ended cylinder and a capsule are meshed across their ends") {
    for (bool flat : {true, false}) {
        for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
            for (uint32_t planned : {1u, 4u, 12u}) {
                const Shape s = closed_shape(flat, pose);
                CAPTURE(s.name);
                CAPTURE(planned);
                const Run run = reconstruct_closed_shape(s, planned, 0);
                // The report names the ends: the first layer's bottom, the last one's top.
                for (size_t k = 0; k < run.layers.size(); ++k) {
                    const uint32_t ends = (k == 0 ? stratmesh::closed_bottom : 0u) |
                                          (k + 1 == run.layers.size() ? stratmesh::closed_top : 0u);
                    CHECK(run.layers[k].closed_ends == ends);
                }
                // The boundary: small loops around the poles, off the rims.
                const double widest_loop = widest_boundary_vertex(s, run);
                // Outward and covering the ends: the enclosed volume, from the signed
                // tetrahedra to a point on the axis, is the solid's less the two holes.
                double origin[3], volume = 0;
                s.axis_point(origin);
                for (size_t t = 0; t < run.count; ++t) {
                    double p[3][3];
                    for (size_t k = 0; k < 3; ++k)
                        for (size_t d = 0; d < 3; ++d)
                            p[k][d] = s.point(run.triangles[3 * t + k])[d] - origin[d];
                    volume += (p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) -
                               p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
                               p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0])) / 6;
                }
                const double solid = flat ? 6 * shapes::kPi : 4 * shapes::kPi + 4 * shapes::kPi / 3;
                const double mean = mean_centroid_deviation(s, run.triangles);
                MESSAGE(s.name << ", " << planned << " layers: mean distance " << mean
                               << ", boundary up to " << widest_loop << " from the axis, volume "
                               << volume / solid << " of the solid");
                CHECK(widest_loop < 0.3);
                CHECK(volume > 0.97 * solid);
                CHECK(volume < 1.01 * solid);
                CHECK(mean < 0.06 * s.spacing);
            }
        }
    }
}

// ends_are_cuts: a cloud cut out of a larger object has cuts for ends, however many points lie
// across them. With the flag no end of the closed shapes above is unrolled around a pole:
// no layer reports a closed end, and the surface is still one manifold annulus through
// every point. On the cylinder picture a flat end's points come onto its rim, so its loops
// run out to the rim (radius 1; around a pole within 0.3); a dome's top still reaches the
// loop's highest points (0.37 from the axis on the capsule, 0.26 around its pole). A shape
// with no closed end gives the same triangles with or without the flag.
TEST_CASE("ends_are_cuts: no end is unrolled around a pole, on a manifold tube through every point") {
    for (bool flat : {true, false}) {
        for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
            for (uint32_t planned : {1u, 4u, 12u}) {
                const Shape s = closed_shape(flat, pose);
                CAPTURE(s.name);
                CAPTURE(planned);
                const Run run = reconstruct_closed_shape(s, planned, stratmesh::ends_are_cuts);
                for (const LayerInfo& layer : run.layers) CHECK(layer.closed_ends == 0);
                if (flat) CHECK(widest_boundary_vertex(s, run) > 0.9);
            }
        }
    }
    for (Pose pose : {Pose::z, Pose::tilted}) {
        Shape s = shapes::bumpy_tube(kSmall, pose);
        Options o = axis_options(s);
        o.layer_count = 4;
        Run plain = reconstruct_guarded(cloud_of(s), o);
        o.flags |= stratmesh::ends_are_cuts;
        Run open = reconstruct_guarded(cloud_of(s), o);
        REQUIRE(plain.status == Status::ok);
        CHECK(open.status == Status::ok);
        CHECK(open.triangles == plain.triangles);
    }
}


// A tube that forks at its end (two horns on a head): no centre sees both horns' outlines,
// so the top layer folds, and its hull runs from tip to tip over a web of triangles down to
// the dome between the horns. The surface's end loop is peeled even there (kPeelFoldedEnds,
// see "peeling" in the header), which takes much of the web off. Means over the 9 runs
// (g++ 12): before, 1.01 spacings from the true surface and 8.0% of the area farther than 3
// spacings; after, 0.73 and 5.3%. Each run is one manifold tube through every point.
TEST_CASE("a tube forking at its end: the web between the prongs' tips is peeled off") {
    double mean_sum = 0, far_sum = 0;  // over the 9 runs
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        const Shape s = shapes::forked_tube(kLarge / 2, pose);
        for (uint32_t planned : {1u, 4u, 8u}) {
            CAPTURE(s.name);
            CAPTURE(planned);
            mesh_check::Result m;
            const Run run = reconstruct_tube(s, planned, false, &m);
            INFO(m.summary());
            const double mean = mean_centroid_deviation(s, run.triangles) / s.spacing;
            // The web's share of the area: triangles whose centroid is more than 3 spacings
            // off the surface (the mean of a deviation that is 1 there and 0 elsewhere).
            const double far = mean_centroid_deviation(s.xyz.data(), run.triangles, [&s](const double* p) {
                return std::fabs(s.deviation(p)) > 3 * s.spacing ? 1.0 : 0.0;
            });
            MESSAGE(s.name << ", " << planned << " layers: " << run.report.diagnostics.fold_count << " folds, mean distance "
                           << mean << " spacings, " << far << " of the area farther than 3 spacings");
            mean_sum += mean;
            far_sum += far;
        }
    }
    MESSAGE("mean over the runs: distance " << mean_sum / 9 << " spacings, " << far_sum / 9
                                             << " of the area farther than 3 spacings");
#if !defined(STRATMESH_SMALL_CODE)  // which leaves folded layers unpeeled (the header's Config)
    CHECK(mean_sum / 9 < 0.85);
    CHECK(far_sum / 9 < 0.065);
#endif
}

// A closed end that splits into two knobs (a femur's condyles): near the end the cross-
// section is two discs, and above them the notch between the knobs brings points close to
// the axis all along the layer, so the end's share of such points is no larger than the
// rest's, and with that rule alone the end was left open with 4 and 8 layers: 9 to 25 folds,
// up to 9 self-intersecting pairs, mean distance 1.03 to 1.21 spacings (0.83 over the 9
// runs). Now an end also counts as closed by points well inside the outline of the slab
// beyond it (find_closed_ends): no folds, no self-intersection, 0.54 to 0.56 spacings
// (0.43 over the runs). Each run is one manifold tube through every point, closed across
// its knobbed bottom (STRATMESH_SMALL_CODE, without closed ends: 15 to 44 pairs).
TEST_CASE("closed ends: an end split into two knobs is meshed across too") {
    double mean_sum = 0;  // over the 9 runs
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        const Shape s = shapes::knobbed_tube(kLarge / 2, pose);
        for (uint32_t planned : {1u, 4u, 8u}) {
            CAPTURE(s.name);
            CAPTURE(planned);
            mesh_check::Result m;
            const Run run = reconstruct_tube(s, planned, true, &m);
            INFO(m.summary());
            const double mean = mean_centroid_deviation(s, run.triangles) / s.spacing;
            const bool closed = run.layers[0].closed_ends & stratmesh::closed_bottom;
            MESSAGE(s.name << ", " << planned << " layers: " << run.report.diagnostics.fold_count << " folds, "
                           << m.intersecting_pairs << " self-intersecting pairs, bottom "
                           << std::string(closed ? "closed" : "open") << ", mean distance " << mean
                           << " spacings");
#if !defined(STRATMESH_SMALL_CODE)  // which unrolls every end on the cylinder (the header's Config)
            CHECK(closed);
            CHECK(m.intersecting_pairs == 0);
#endif
            mean_sum += mean;
        }
    }
    MESSAGE("mean over the runs: distance " << mean_sum / 9 << " spacings");
#if !defined(STRATMESH_SMALL_CODE)
    CHECK(mean_sum / 9 < 0.6);
#endif
}

// Many thin layers across the knobs: the layers through the notch between them are not
// star-shaped, their loops skip across it and the bands between them crossed the layers
// next to them (12, 16 and 24 planned layers, 3 poses: 138 self-intersecting pairs and
// 104 folds in all). A layer that folds is now tried again with the next one or two
// joined, kept where that folds less (the header's "folding layers" at add_group): 61
// pairs and 32 folds. Each run stays one manifold tube through every point
// (reconstruct_tube).
TEST_CASE("folding layers: a thin layer that folds across a notch is joined with the next one") {
    size_t pairs = 0, folds = 0;
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        const Shape s = shapes::knobbed_tube(kLarge / 2, pose);
        for (uint32_t planned : {12u, 16u, 24u}) {
            CAPTURE(s.name);
            CAPTURE(planned);
            mesh_check::Result m;
            const Run run = reconstruct_tube(s, planned, true, &m);
            INFO(m.summary());
            MESSAGE(s.name << ", " << planned << " planned layers: " << run.report.layers.used_count
                           << " layers, " << run.report.diagnostics.fold_count << " folds, "
                           << m.intersecting_pairs << " self-intersecting pairs");
            pairs += m.intersecting_pairs;
            folds += run.report.diagnostics.fold_count;
        }
    }
    MESSAGE("over the runs: " << pairs << " self-intersecting pairs, " << folds << " folds");
#if !defined(STRATMESH_SMALL_CODE)  // which has no folding-layer merge (the header's Config)
    CHECK(pairs < 70);
    CHECK(folds < 40);
#endif
}

TEST_CASE("the automatic axis serves the method: the shapes' own axis, as close as the explicit one") {
    // A head longer front to back than tall, and tubes and a vase, upright and tilted: the
    // automatic axis lies within 10 degrees of the shape's, and the mesh is within 10% of the
    // explicit axis's mean distance from the true surface (plus a hundredth of a spacing).
    const Shape shapes_tried[] = {shapes::long_head(8000, Pose::z), shapes::long_head(8000, Pose::tilted),
                                  shapes::bumpy_tube(8000, Pose::tilted), shapes::vase(8000, Pose::x)};
    for (const Shape& s : shapes_tried) {
        CAPTURE(s.name);
        CAPTURE(shapes::pose_name(s.pose));
        const Run automatic = reconstruct_guarded(cloud_of(s), Options{});
        const Run explicit_axis = reconstruct_guarded(cloud_of(s), axis_options(s));
        REQUIRE(automatic.status == Status::ok);
        REQUIRE(explicit_axis.status == Status::ok);
        double axis[3];
        s.axis_direction(axis);
        const double cosine = std::fabs(automatic.report.axis[0] * axis[0] + automatic.report.axis[1] * axis[1] +
                                        automatic.report.axis[2] * axis[2]);
        CHECK(cosine > std::cos(10 * 3.14159265358979323846 / 180));
        const double chosen = mean_centroid_deviation(s, automatic.triangles);
        const double given = mean_centroid_deviation(s, explicit_axis.triangles);
        MESSAGE(s.name << " " << shapes::pose_name(s.pose) << ": mean distance " << chosen / s.spacing
                       << " spacings automatic, " << given / s.spacing << " along the shape's axis");
        CHECK(chosen <= 1.1 * given + 0.01 * s.spacing);
        CHECK(automatic.report.points.unused_count == 0);
    }
}

TEST_CASE("clouds whose surface would have no area are refused, not meshed into slivers") {
    SUBCASE("points on a line up to rounding: degenerate, whatever the axis") {
        std::vector<double> xyz;
        for (int i = 0; i < 2000; ++i) xyz.insert(xyz.end(), {0.01 * i, 0.02 * i, 0.03 * i});
        for (stratmesh::Axis axis : {stratmesh::Axis::automatic, stratmesh::Axis::x, stratmesh::Axis::z}) {
            Options o = {};
            o.axis = axis;
            const Run run = reconstruct_guarded(Cloud{xyz.data(), 2000, 0, Scalar::float64}, o);
            CHECK(run.status == Status::degenerate);
            CHECK(run.count == 0);
            CHECK(run.report.detail != nullptr);
            CHECK(run.report.points.in_count == run.report.points.used_count + run.report.points.duplicate_count +
                                                    run.report.points.rejected_count + run.report.points.unused_count);
        }
    }
    SUBCASE("a tube and a speck at 1e30: refused; without the speck, or with it nearer, a tube") {
        const Shape tube = shapes::bumpy_tube(kSmall, Pose::z);
        for (double far : {1e30, 1e3}) {
            std::vector<double> xyz = tube.xyz;
            xyz.insert(xyz.end(), {0, 0, far});
            const Cloud cloud = {xyz.data(), tube.size() + 1, 0, Scalar::float64};
            const Run run = reconstruct_guarded(cloud, Options{});
            CAPTURE(far);
            if (far > 1e20) {
                CHECK((run.status == Status::degenerate || run.status == Status::not_columnar));
                CHECK(run.count == 0);
            } else {
                CHECK(run.status == Status::ok);
            }
            Options dropping = {};
            dropping.flags = stratmesh::drop_outliers;
            const Run dropped = reconstruct_guarded(cloud, dropping);
            REQUIRE(dropped.status == Status::ok);
            CHECK(dropped.report.points.outlier_count == 1);
            CHECK(dropped.report.points.used_count == tube.size());
        }
    }
}

TEST_CASE("a given origin: meshed from up to 2^32 times the cloud's size away, refused beyond") {
    const Shape tube = shapes::bumpy_tube(kSmall, Pose::z);
    double lo = DBL_MAX, hi = -DBL_MAX;  // the tube's largest side is along z
    for (size_t i = 0; i < tube.size(); ++i) {
        lo = std::min(lo, tube.xyz[3 * i + 2]);
        hi = std::max(hi, tube.xyz[3 * i + 2]);
    }
    const double side = hi - lo;
    for (double reach : {1e3, 1e9, 0x1p31, 0x1p33, 1e12, 1e300}) {
        Options o = axis_options(tube);
        o.flags |= stratmesh::origin_given;
        o.origin[0] = reach * side;
        const Run run = reconstruct_guarded(cloud_of(tube), o);
        CAPTURE(reach);
        if (reach <= 0x1p32) {
            REQUIRE(run.status == Status::ok);
            mesh_check::Result m = check_mesh(tube, run.triangles.data(), run.count, false);
            INFO(m.summary());
            CHECK(m.manifold());
            CHECK(m.components == 1);
            CHECK(m.unused_expected == 0);
        } else {
            CHECK(run.status == Status::invalid_origin);
            CHECK(run.count == 0);
            REQUIRE(run.report.detail != nullptr);
            CHECK(std::string(run.report.detail).find("2^32") != std::string::npos);
            CHECK(counts_add_up(run.report));
        }
    }
}

TEST_CASE("clouds with no area: a line, a few far points and far clusters each say which") {
    const Shape tube = shapes::bumpy_tube(kSmall, Pose::z);
    auto run_on = [](const std::vector<double>& xyz, const Options& o) {
        return reconstruct_guarded(Cloud{xyz.data(), xyz.size() / 3, 0, Scalar::float64}, o);
    };
    auto detail_has = [](const Run& run, const char* words) {
        return run.report.detail && std::string(run.report.detail).find(words) != std::string::npos;
    };
    SUBCASE("two tubes 1e9 apart, along any axis: separate_clusters") {
        for (double apart : {1e9, 1e200}) {
            std::vector<double> xyz;
            for (double shift : {0.0, apart})
                for (size_t i = 0; i < tube.size(); ++i)
                    xyz.insert(xyz.end(), {tube.xyz[3 * i] + shift, tube.xyz[3 * i + 1], tube.xyz[3 * i + 2]});
            for (Axis axis : {Axis::automatic, Axis::x, Axis::z}) {
                Options o = {};
                o.axis = axis;
                const Run run = run_on(xyz, o);
                CAPTURE(apart);
                CHECK(run.status == Status::separate_clusters);
                CHECK(detail_has(run, "mesh each cluster on its own"));
                CHECK(counts_add_up(run.report));
            }
        }
    }
    SUBCASE("a tube and three points 1e30 away: degenerate, and drop_outliers meshes the tube") {
        std::vector<double> xyz = tube.xyz;
        for (int k = 0; k < 3; ++k) xyz.insert(xyz.end(), {1e30 + k, 0.0, 0.0});
        const Run run = run_on(xyz, Options{});
        CHECK(run.status == Status::degenerate);
        CHECK(detail_has(run, "drop_outliers"));
        Options dropping = {};
        dropping.flags = stratmesh::drop_outliers;
        const Run dropped = run_on(xyz, dropping);
        CHECK(dropped.status == Status::ok);
        CHECK(dropped.report.points.outlier_count == 3);
    }
    SUBCASE("points on a line: degenerate, saying so") {
        std::vector<double> xyz;
        for (int i = 0; i < 500; ++i) xyz.insert(xyz.end(), {i * 0x1p-4, i * 0x1p-3, 1.0});
        const Run run = run_on(xyz, Options{});
        CHECK(run.status == Status::degenerate);
        CHECK(detail_has(run, "on a line"));
    }
}

TEST_CASE("clouds that do not surround the axis: not_columnar, or ok with a manifold annulus") {
    SUBCASE("half-cylinder: ok, one manifold annulus through every point") {
        for (uint32_t layers : {1u, 6u}) {
            Shape s = shapes::half_cylinder(kSmall, Pose::z);
            Options o = axis_options(s);
            o.layer_count = static_cast<uint32_t>(layers);
            Run run = reconstruct_guarded(cloud_of(s), o);
            CAPTURE(layers);
            REQUIRE((run.status == Status::ok || run.status == Status::not_columnar));
            CHECK(run.status == Status::ok);  // measured
            if (run.status != Status::ok) continue;
            mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, false);
            INFO(m.summary());
            CHECK(m.manifold());
            CHECK(m.components == 1);
            CHECK(m.boundary_loops == 2);
            CHECK(m.euler == 0);
            CHECK(m.unused_expected == 0);
            CHECK(run.report.points.unused_count == 0);
        }
    }
    SUBCASE("a plane through the axis: not_columnar, nothing written") {
        shapes::Rng rng(9);
        std::vector<double> xyz;
        for (size_t i = 0; i < 1000; ++i) xyz.insert(xyz.end(), {rng.uniform(-1, 1), 0.0, rng.uniform(-3, 3)});
        Options o = {};
        o.axis = Axis::z;
        for (uint32_t layers : {1u, 6u}) {
            o.layer_count = static_cast<uint32_t>(layers);
            Run run = reconstruct_guarded(Cloud{xyz.data(), 1000, 0, Scalar::float64}, o);
            CHECK(run.status == Status::not_columnar);
            CHECK(run.count == 0);
            CHECK(run.report.layers.used_count == 0);
            CHECK(run.report.points.unused_count == 1000);
            CHECK(run.report.detail != nullptr);
        }
    }
    SUBCASE("points on the axis: degenerate (a line has no surface)") {
        std::vector<double> xyz;
        for (size_t i = 0; i < 20; ++i) xyz.insert(xyz.end(), {1.0, 2.0, static_cast<double>(i)});
        Options o = {};
        o.axis = Axis::z;
        Run run = reconstruct_guarded(Cloud{xyz.data(), 20, 0, Scalar::float64}, o);
        CHECK(run.status == Status::degenerate);
    }
}

TEST_CASE("statuses for bad arguments and options") {
    const Shape& s = reference_cylinder();
    Cloud cloud = cloud_of(s);
    SUBCASE("zero or NaN axis direction: invalid_axis") {
        Options o = {};
        o.axis = Axis::direction;
        CHECK(reconstruct_guarded(cloud, o).status == Status::invalid_axis);
        o.direction[2] = std::numeric_limits<double>::quiet_NaN();
        CHECK(reconstruct_guarded(cloud, o).status == Status::invalid_axis);
        Options unknown = axis_options(s);
        unknown.axis = static_cast<Axis>(17);
        CHECK(reconstruct_guarded(cloud, unknown).status == Status::invalid_axis);
    }
    SUBCASE("a direction of any finite non-zero length: the same triangles as the unit one") {
        // The direction is scaled by a power of two before it is normalised, which is exact:
        // every length, from subnormal components to near the largest double, gives the unit
        // direction's bits (without the scaling, a square below the smallest normal double
        // lost bits and an infinite one had no length).
        double unit[3];
        s.axis_direction(unit);
        Options o = {};
        o.axis = Axis::direction;
        for (int k = 0; k < 3; ++k) o.direction[k] = unit[k];
        const Run reference = reconstruct_guarded(cloud, o);
        REQUIRE(reference.status == Status::ok);
        for (int exponent : {-1060, -540, -520, -20, 20, 520, 1000, 1023}) {
            CAPTURE(exponent);
            for (int k = 0; k < 3; ++k) o.direction[k] = std::ldexp(unit[k], exponent);
            const Run run = reconstruct_guarded(cloud, o);
            REQUIRE(run.status == Status::ok);
            CHECK(run.triangles == reference.triangles);
        }
    }
    SUBCASE("NaN cut, negative layer height: invalid_layers") {
        Options o = axis_options(s);
        double cut = std::numeric_limits<double>::quiet_NaN();
        o.cuts = &cut;
        o.cut_count = 1;
        CHECK(reconstruct_guarded(cloud, o).status == Status::invalid_layers);
        Options p = axis_options(s);
        p.layer_height = -1;
        CHECK(reconstruct_guarded(cloud, p).status == Status::invalid_layers);
    }
    SUBCASE("a stride too small, a null triangle count: invalid_argument") {
        Options o = axis_options(s);
        Cloud narrow = cloud;
        narrow.stride_bytes = 2 * sizeof(double);
        CHECK(reconstruct_guarded(narrow, o).status == Status::invalid_argument);
        std::vector<unsigned char> work(stratmesh::reconstruct_workspace_size(s.size(), o));
        std::vector<uint32_t> tris(3 * stratmesh::reconstruct_max_triangles(s.size(), o));
        CHECK(stratmesh::reconstruct(cloud, o, work.data(), work.size(), tris.data(), tris.size() / 3, nullptr, nullptr) ==
              Status::invalid_argument);
    }
    SUBCASE("cut_count without cuts: invalid_argument; a NaN or infinite origin: invalid_origin") {
        Options o = axis_options(s);
        o.cut_count = 2;
        CHECK(reconstruct_guarded(cloud, o).status == Status::invalid_argument);
        for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
            Options p = axis_options(s);
            p.flags |= stratmesh::origin_given;
            p.origin[1] = bad;
            const Run run = reconstruct_guarded(cloud, p);
            CHECK(run.status == Status::invalid_origin);
            REQUIRE(run.report.detail != nullptr);
            CHECK(std::string(run.report.detail).find("NaN or infinite") != std::string::npos);
            CHECK(run.count == 0);
            p.flags &= ~uint32_t(stratmesh::origin_given);  // without the flag the origin is not read
            CHECK(reconstruct_guarded(cloud, p).status == Status::ok);
        }
    }
    SUBCASE("fewer than 3 points: too_few_points") {
        Options o = axis_options(s);
        CHECK(reconstruct_guarded(Cloud{s.xyz.data(), 2, 0, Scalar::float64}, o).status == Status::too_few_points);
    }
}

namespace {

// Options that name a flag bit Flags does not define, a Parts value outside the enum, or
// more than one way to lay out the layers (the last three).
std::vector<Options> refused_options(const Shape& s) {
    static const double cut = 0.5;
    std::vector<Options> refused;
    for (uint32_t bit = 6; bit < 32; ++bit) {
        Options o = axis_options(s);
        o.flags = stratmesh::add_caps | (1u << bit);
        refused.push_back(o);
    }
    Options parts = axis_options(s);
    parts.parts = static_cast<stratmesh::Parts>(3);
    refused.push_back(parts);
    for (int pair = 0; pair < 3; ++pair) {
        Options o = axis_options(s);
        if (pair != 0) o.cuts = &cut, o.cut_count = 1;
        if (pair != 1) o.layer_count = 4;
        if (pair != 2) o.layer_height = 1;
        refused.push_back(o);
    }
    return refused;
}

}  // namespace

TEST_CASE("unknown flag bits, a Parts value outside the enum, two ways to lay out the layers: invalid_argument with a detail") {
    const Shape& s = reference_cylinder();
    const Cloud cloud = cloud_of(s);
    const std::vector<Options> refused = refused_options(s);
    for (size_t k = 0; k < refused.size(); ++k) {
        CAPTURE(k);
        const Options& o = refused[k];
        const Run run = reconstruct_guarded(cloud, o);
        CHECK(run.status == Status::invalid_argument);
        REQUIRE(run.report.detail != nullptr);
        CHECK(run.count == 0);
        // The stream refuses the same, saying why in the report.
        Options streamed = o;
        streamed.flags &= ~uint32_t(stratmesh::add_caps);
        std::vector<unsigned char> work(stratmesh::stream_workspace_size(64, streamed));
        Report report = {};
        stratmesh::Stream* stream = nullptr;
        const auto ignore = [](void*, const uint32_t*, size_t) {};
        CHECK(stratmesh::stream_open(streamed, work.data(), work.size(), ignore, nullptr, &report,
                                     &stream) == Status::invalid_argument);
        CHECK(stream == nullptr);
        CHECK(report.detail != nullptr);
    }
    // The calls that take Options but lay out no layers refuse the flags and Parts alike.
    const size_t n = s.size();
    for (size_t k = 0; k + 3 < refused.size(); ++k) {
        CAPTURE(k);
        const Options& o = refused[k];
        std::vector<unsigned char> work(stratmesh::find_parting_workspace_size(n, o));
        stratmesh::Parting parting;
        CHECK(stratmesh::find_parting(cloud, o, work.data(), work.size(), &parting, nullptr) ==
              Status::invalid_argument);
        CHECK(parting.detail != nullptr);
        std::vector<uint32_t> triangles(3 * stratmesh::join_branches_max_triangles(n));
        std::vector<uint8_t> branch_of(n, stratmesh::kInTrunk);
        size_t count = 0;
        work.assign(stratmesh::join_branches_workspace_size(n, 0), 0);
        stratmesh::JoinReport joined;
        CHECK(stratmesh::join_branches(cloud, o, parting, branch_of.data(), work.data(),
                                       work.size(), triangles.data(), triangles.size() / 3,
                                       &count, &joined) == Status::invalid_argument);
        CHECK(joined.detail != nullptr);
        work.assign(stratmesh::cap_ends_workspace_size(n, 0), 0);
        Report capped = {};
        CHECK(stratmesh::cap_ends(cloud, o, work.data(), work.size(), triangles.data(),
                                  triangles.size() / 3, &count, &capped) ==
              Status::invalid_argument);
        CHECK(capped.detail != nullptr);
    }
}

TEST_CASE("progress: every phase in order, fractions in [0, 1]") {
    struct Log {
        std::vector<stratmesh::Phase> phases;
        bool fractions_ok = true;
    } log;
    Options o = axis_options(reference_cylinder());
    o.layer_count = 4;
    o.progress = [](void* user, stratmesh::Phase phase, double fraction) {
        Log* l = static_cast<Log*>(user);
        if (!(fraction >= 0 && fraction <= 1)) l->fractions_ok = false;
        l->phases.push_back(phase);
    };
    o.progress_user = &log;
    Run run = reconstruct_guarded(cloud_of(reference_cylinder()), o);
    REQUIRE(run.status == Status::ok);
    CHECK(log.fractions_ok);
    REQUIRE(!log.phases.empty());
    CHECK(std::is_sorted(log.phases.begin(), log.phases.end()));
    CHECK(log.phases.front() == stratmesh::Phase::validate);
    CHECK(log.phases.back() == stratmesh::Phase::done);
    for (stratmesh::Phase p : {stratmesh::Phase::layers, stratmesh::Phase::triangulate, stratmesh::Phase::stitch,
                               stratmesh::Phase::manifold})
        CHECK(std::find(log.phases.begin(), log.phases.end(), p) != log.phases.end());
}

TEST_CASE("reconstruct_workspace_size suffices, and smaller workspaces give out_of_memory or the same triangles") {
    // Measured (2000-point cylinder): one layer needs 94% to 97% of the bound depending on
    // the library version, six layers 52% (the bound assumes every point in one layer);
    // any size from there up succeeds, so sizes just under the bound need not fail. Every
    // size below the bound must either fail with out_of_memory or give exactly the
    // triangles of the full workspace; sizes that cannot hold the triangulation of the
    // largest layer (72 bytes a point) must fail.
    const Shape& s = reference_cylinder();
    for (uint32_t layers : {1u, 6u}) {
        Options o = axis_options(s);
        o.layer_count = layers;
        Run reference = reconstruct_guarded(cloud_of(s), o);
        REQUIRE(reference.status == Status::ok);
        const size_t bound = stratmesh::reconstruct_workspace_size(s.size(), o);
        CHECK(bound == reference.workspace_bytes);
        CAPTURE(layers);
        CAPTURE(bound);
        std::vector<size_t> sizes = {0, 1, 15, 16, 17, 100, 4096, bound / 8, bound / 4, bound / 3};
        if (layers == 1) sizes.insert(sizes.end(), {bound / 2, bound * 3 / 4, bound * 9 / 10});
        for (size_t k = 1; k <= 12; ++k) sizes.push_back(bound - bound * k / 50);  // 76% .. 98%
        sizes.push_back(bound - 1);
        for (size_t bytes : sizes) {
            CAPTURE(bytes);
            // A fresh heap buffer of exactly this size (new[0] is a valid, empty buffer).
            std::unique_ptr<unsigned char[]> buffer(new unsigned char[bytes]);
            const size_t capacity = stratmesh::reconstruct_max_triangles(s.size(), o);
            std::vector<uint32_t> tris(3 * capacity);
            size_t count = 12345;
            Report report{};
            Status status = stratmesh::reconstruct(cloud_of(s), o, buffer.get(), bytes, tris.data(), capacity, &count, &report);
            CHECK(report.points.in_count == report.points.used_count + report.points.duplicate_count + report.points.rejected_count + report.points.unused_count);
            if (status == Status::ok) {
                tris.resize(3 * count);
                CHECK(tris == reference.triangles);
            } else {
                CHECK(status == Status::out_of_memory);
                CHECK(count == 0);
            }
            bool must_fail = bytes < bound / 3 || (layers == 1 && bytes <= bound / 2);
            if (must_fail) CHECK(status == Status::out_of_memory);
        }
    }
}

// Without a runner, reconstruct() also stages the grouped points in the workspace's spare
// room (at its end) and loads a layer from there only while the layers before it have left
// that room untouched. Counted with an instrumented build (2000 points, five layers): with
// twice the bound every load finds the room intact; at the exact peak a small first layer
// leaves no room at all, and a large one (half or 90% of the height) is loaded from it and
// then takes it, so the four other loads read the cloud; a quarter above the peak, the
// small first layer's run loads four layers from the room and one from the cloud. The
// triangles and the peak must be the same in every case.
TEST_CASE("workspace: points staged in spare room give the same triangles, whichever layers find it intact") {
    const Shape s = shapes::bumpy_tube(kSmall, Pose::tilted);
    const double height = s.z_max - s.z_min;
    const Cloud cloud = cloud_of(s);
    for (double first : {0.05, 0.5, 0.9}) {  // the first layer's share of the height
        CAPTURE(first);
        std::vector<double> cuts;
        for (int k = 0; k < 4; ++k) cuts.push_back(s.along_axis(s.z_min + (first + k * (1 - first) / 4) * height));
        Options o = axis_options(s);
        o.cuts = cuts.data();
        o.cut_count = cuts.size();
        const size_t bound = stratmesh::reconstruct_workspace_size(cloud.count, o);
        const size_t capacity = stratmesh::reconstruct_max_triangles(cloud.count, o);
        auto run = [&](size_t bytes, Report& report) {
            std::unique_ptr<unsigned char[]> storage(new unsigned char[bytes + 16]);
            unsigned char* workspace =
                storage.get() + (16 - reinterpret_cast<uintptr_t>(storage.get()) % 16) % 16;
            std::vector<uint32_t> triangles(3 * capacity);
            size_t count = 0;
            Status status = stratmesh::reconstruct(cloud, o, workspace, bytes, triangles.data(), capacity,
                                                   &count, &report);
            REQUIRE(status == Status::ok);
            triangles.resize(3 * count);
            return triangles;
        };
        Report ample = {};
        const std::vector<uint32_t> reference = run(2 * bound, ample);
        const size_t peak = ample.workspace_used_bytes;
        for (size_t bytes : {peak, peak + peak / 4, peak + peak / 2, bound}) {
            CAPTURE(bytes);
            Report report = {};
            CHECK(run(bytes, report) == reference);
            CHECK(report.workspace_used_bytes == peak);
        }
    }
}

TEST_CASE("a too-small triangle array gives triangle_capacity with the needed count, nothing written past it") {
    for (uint32_t layers : {1u, 6u}) {
        const Shape& s = reference_cylinder();
        Options o = axis_options(s);
        o.layer_count = layers;
        Run reference = reconstruct_guarded(cloud_of(s), o);
        REQUIRE(reference.status == Status::ok);
        const size_t needed = reference.count + reference.report.diagnostics.illegal_removed_count;
        CAPTURE(layers);
        CAPTURE(needed);
        std::vector<unsigned char> work(stratmesh::reconstruct_workspace_size(s.size(), o));
        for (size_t capacity : {size_t{0}, size_t{1}, needed / 2, needed - 1, needed}) {
            CAPTURE(capacity);
            std::vector<uint32_t> tris(3 * (capacity + kGuardTriangles), kSentinel);
            size_t count = 0;
            Report report{};
            Status status = stratmesh::reconstruct(cloud_of(s), o, work.data(), work.size(),
                                                   capacity ? tris.data() : nullptr, capacity, &count, &report);
            bool guard = true;
            for (size_t i = 3 * capacity; i < tris.size(); ++i) guard = guard && tris[i] == kSentinel;
            CHECK(guard);
            if (capacity >= needed) {
                CHECK(status == Status::ok);
                tris.resize(3 * count);
                CHECK(tris == reference.triangles);
            } else {
                CHECK(status == Status::triangle_capacity);
                CHECK(count == needed);
                CHECK(report.triangle_count == needed);
                CHECK(report.points.in_count == report.points.used_count + report.points.duplicate_count + report.points.rejected_count + report.points.unused_count);
            }
        }
    }
}

// The workspace bound against what runs really use: the bound always suffices, the report's
// peak is exact (a buffer of that many bytes works, one byte less returns out_of_memory and
// writes nothing outside it: fresh heap buffers of exactly those sizes, so AddressSanitizer
// sees any overrun), and the bound stays within a small factor of the peak. Adversarial
// layouts included: every point in one layer, (almost) one point per layer, heavy
// duplication.
namespace {
void run_jobs_in_order(void*, uint32_t count, stratmesh::JobFunction job, void* context) {
    for (uint32_t i = 0; i < count; ++i) job(context, i);
}
}  // namespace

TEST_CASE("workspace sizes: never wrap around, 0 beyond what can be served") {
    // A size computed in overflowing arithmetic would come back small: a caller would
    // allocate it and be refused, or worse trust it. Every bound must grow with the count,
    // at least 16 bytes a point, until it is 0 (no workspace can serve that many), and stay
    // 0 above. On 64-bit targets the 32-bit indices end it (about 4.3e9 points); on 32-bit
    // ones the address space.
    Options plain = {};
    Options capped = {};
    capped.flags = stratmesh::add_caps;
    Options jobs = {};
    jobs.run_jobs = run_jobs_in_order;
    struct Bound {
        const char* name;
        std::function<size_t(size_t)> size;
    };
    const Bound bounds[] = {
        {"reconstruct", [&](size_t n) { return stratmesh::reconstruct_workspace_size(n, plain); }},
        {"reconstruct with add_caps", [&](size_t n) { return stratmesh::reconstruct_workspace_size(n, capped); }},
        {"reconstruct with a runner", [&](size_t n) { return stratmesh::reconstruct_workspace_size(n, jobs); }},
        {"stream", [&](size_t n) { return stratmesh::stream_workspace_size(n, plain); }},
#if !defined(STRATMESH_SMALL_CODE)
        {"cap_ends", [](size_t n) { return stratmesh::cap_ends_workspace_size(n, n <= SIZE_MAX / 2 ? 2 * n : n); }},
#endif
        {"delaunay_2d", [](size_t n) { return stratmesh::delaunay_2d_workspace_size(n); }},
    };
    // Ascending on every target (SIZE_MAX / 1024 is below 2^26 where size_t has 32 bits).
    const size_t m = SIZE_MAX;
    std::vector<size_t> counts = {0, 1, 3, 1000, size_t{1} << 20, size_t{1} << 26, m / 1024,
                                  m / 200, m / 64, m / 24, m / 16, m / 2, m - 1, m};
    std::sort(counts.begin(), counts.end());
    for (const Bound& b : bounds) {
        INFO(b.name);
        size_t previous = 0;
        bool ended = false;
        for (size_t n : counts) {
            CAPTURE(n);
            const size_t bytes = b.size(n);
            if (ended) {
                CHECK(bytes == 0);
                continue;
            }
            if (bytes == 0) {
                CHECK(n > 1000);  // every small cloud can be served
                ended = true;
                continue;
            }
            CHECK(bytes >= previous);
            CHECK(bytes / 16 >= n);
            previous = bytes;
        }
        CHECK(ended);
    }
}

TEST_CASE("workspace: the bound suffices, the reported peak is exact, one byte short is out_of_memory") {
    struct Setup {
        const char* name;
        Shape shape;
        Options options;
    };
    std::vector<Setup> setups;
    {
        Shape s = shapes::bumpy_tube(kSmall, Pose::z);
        Options one = axis_options(s);
        one.layer_count = 1;
        setups.push_back({"one layer", s, one});
        Options many = axis_options(s);
        many.layer_count = static_cast<uint32_t>(s.size());  // one point per layer, before merging
        setups.push_back({"a layer per point", s, many});
        Options six = axis_options(s);
        six.layer_count = 6;
        setups.push_back({"six layers", s, six});
        Options one_closed = one;
        one_closed.flags = stratmesh::add_caps;
        setups.push_back({"one layer, add_caps", s, one_closed});
        Options six_closed = six;
        six_closed.flags = stratmesh::add_caps;
        setups.push_back({"six layers, add_caps", s, six_closed});
        Options six_dropping = six;
        six_dropping.flags = stratmesh::drop_outliers;
        setups.push_back({"six layers, drop_outliers", s, six_dropping});
    }
    {
        Shape s = shapes::cylinder(kSmall, Pose::tilted);
        const size_t distinct = s.size() / 10;  // every point repeated about ten times
        for (size_t i = distinct; i < s.size(); ++i)
            for (size_t k = 0; k < 3; ++k) s.xyz[3 * i + k] = s.xyz[3 * (i % distinct) + k];
        setups.push_back({"heavy duplicates", s, axis_options(s)});
        Options closed = axis_options(s);
        closed.flags = stratmesh::add_caps;
        setups.push_back({"heavy duplicates, add_caps", s, closed});
    }
    for (const Setup& setup : setups) {
        INFO(setup.name);
        const Cloud cloud = cloud_of(setup.shape);
        const size_t bound = stratmesh::reconstruct_workspace_size(cloud.count, setup.options);
        const size_t capacity = stratmesh::reconstruct_max_triangles(cloud.count, setup.options);
        std::vector<uint32_t> triangles(3 * capacity);
        auto run = [&](size_t bytes, Report& report) {
            // The buffer starts on a 16-byte boundary, so the arena skips no padding and the
            // peak does not depend on where it lands (new[] gives only 8 on 32-bit ARM).
            std::unique_ptr<unsigned char[]> storage(new unsigned char[bytes + 16]);
            unsigned char* workspace =
                storage.get() + (16 - reinterpret_cast<uintptr_t>(storage.get()) % 16) % 16;
            size_t count = 0;
            return stratmesh::reconstruct(cloud, setup.options, workspace, bytes,
                                          triangles.data(), capacity, &count, &report);
        };
        Report full = {};
        REQUIRE(run(bound, full) == Status::ok);
        const size_t peak = full.workspace_used_bytes;
        REQUIRE(peak > 0);
        CHECK(peak <= bound);
        Report exact = {};
        CHECK(run(peak, exact) == Status::ok);
        CHECK(exact.triangle_count == full.triangle_count);
        Report short_by_one = {};
        CHECK(run(peak - 1, short_by_one) == Status::out_of_memory);
        CHECK(short_by_one.points.in_count == short_by_one.points.used_count + short_by_one.points.duplicate_count +
                                           short_by_one.points.rejected_count + short_by_one.points.unused_count);
        // The bound is the peak of the worst layout, every point in one layer; with more
        // layers the peak follows the largest layer.
        const double ratio = static_cast<double>(bound) / static_cast<double>(peak);
        if (setup.options.layer_count == 1) CHECK(ratio < 1.2);
        MESSAGE(std::string(setup.name) << ": bound " << bound << " B, peak " << peak << " B, bound / peak "
                           << ratio);
    }
}

// ===========================================================================================
// Malformed clouds and arguments: every case gets its documented status, counts that add
// up, nothing written past the buffers, and a manifold annulus through every point when
// the status is ok.

namespace {

// A unit-radius cylinder (reference_cylinder() unless given) scaled by `scale` about the
// origin and moved by `offset`, with its analytic surface moved along (the radius is 1
// everywhere, so the scaled radius is `scale`).
Shape moved_cylinder(double scale, const double offset[3], const Shape& base = reference_cylinder()) {
    Shape s = base;
    for (size_t i = 0; i < s.xyz.size(); ++i) s.xyz[i] = s.xyz[i] * scale + offset[i % 3];
    for (int k = 0; k < 3; ++k) s.transform.t[k] = s.transform.t[k] * scale + offset[k];
    s.radius = [scale](double, double) { return scale; };
    s.z_min *= scale;
    s.z_max *= scale;
    s.spacing *= scale;
    return s;
}

// Checks the promise of an ok run: one manifold annulus, outward, every point a vertex.
void check_annulus_through_every_point(const Shape& s, const Run& run) {
    REQUIRE(run.status == Status::ok);
    CHECK(run.workspace_guard_intact);
    CHECK(run.triangle_guard_intact);
    CHECK(counts_add_up(run.report));
    CHECK(run.report.points.unused_count == 0);
    mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, false);
    INFO(m.summary());
    CHECK(m.bad_indices == 0);
    CHECK(m.manifold());
    CHECK(m.components == 1);
    CHECK(m.boundary_loops == 2);
    CHECK(m.euler == 0);
    CHECK(m.unused_expected == 0);
}

}  // namespace

TEST_CASE("buffers that share memory: invalid_argument, nothing written, not even the report") {
    const Shape& s = reference_cylinder();
    Options o = axis_options(s);
    o.layer_count = 3;
    const size_t cloud_bytes = s.xyz.size() * sizeof(double);
    const size_t work_bytes = stratmesh::reconstruct_workspace_size(s.size(), o);
    const size_t capacity = stratmesh::reconstruct_max_triangles(s.size(), o);
    const size_t tri_bytes = 3 * capacity * sizeof(uint32_t);
    // One arena: cloud, workspace, triangles, count, layers, each 8-byte aligned.
    const size_t layer_bytes = 4 * sizeof(LayerInfo);
    const size_t cloud_at = 0, work_at = cloud_bytes, tri_at = (work_at + work_bytes + 7) / 8 * 8,
                 count_at = tri_at + tri_bytes, layers_at = count_at + 8, total = layers_at + layer_bytes;
    std::vector<uint64_t> words(total / 8 + 1);
    unsigned char* arena = reinterpret_cast<unsigned char*>(words.data());

    struct Placement {
        const char* what;
        size_t work, tri, count, layers;
    };
    const Placement placements[] = {
        {"apart", work_at, tri_at, count_at, layers_at},
        {"workspace over the cloud's last point", cloud_bytes - 8, tri_at, count_at, layers_at},
        {"triangles inside the workspace", work_at, work_at + 64, count_at, layers_at},
        {"triangle_count inside the triangles", work_at, tri_at, tri_at + 8, layers_at},
        {"layer array inside the cloud", work_at, tri_at, count_at, 0},
    };
    for (const Placement& p : placements) {
        CAPTURE(p.what);
        std::memset(arena, 0x5A, words.size() * 8);
        std::memcpy(arena + cloud_at, s.xyz.data(), cloud_bytes);
        std::vector<unsigned char> before(arena, arena + words.size() * 8);
        Report report;
        std::memset(&report, 0x3C, sizeof report);
        report.layers.info = reinterpret_cast<LayerInfo*>(arena + p.layers);
        report.layers.info_capacity = 4;
        // The parts' array is an input too: none (garbage could overlap on 32-bit targets).
        report.parts.info = nullptr;
        report.parts.info_capacity = 0;
        const Report report_before = report;
        Cloud cloud = {arena + cloud_at, s.size(), 0, Scalar::float64};
        Status status = stratmesh::reconstruct(cloud, o, arena + p.work, work_bytes,
                                               reinterpret_cast<uint32_t*>(arena + p.tri), capacity,
                                               reinterpret_cast<size_t*>(arena + p.count), &report);
        if (p.work == work_at && p.tri == tri_at && p.count == count_at && p.layers == layers_at) {
            CHECK(status == Status::ok);
            CHECK(report.layers.used_count == 3);
            continue;
        }
        CHECK(status == Status::invalid_argument);
        CHECK(std::memcmp(before.data(), arena, before.size()) == 0);
        CHECK(std::memcmp(&report_before, &report, sizeof report) == 0);
    }
    SUBCASE("the report inside the workspace") {
        std::vector<unsigned char> work(work_bytes + sizeof(Report));
        std::vector<uint32_t> tris(3 * capacity);
        size_t count = 7;
        Report* inside = reinterpret_cast<Report*>(work.data() + 64);
        CHECK(stratmesh::reconstruct(cloud_of(s), o, work.data(), work.size(), tris.data(), capacity, &count,
                                     inside) == Status::invalid_argument);
        CHECK(count == 7);
    }
}

TEST_CASE("malformed clouds: the documented status, counts that add up, nothing written past the buffers") {
    const Shape& s = reference_cylinder();
    Options along_z = {};
    along_z.axis = Axis::z;
    auto check_refused = [](const Run& run, Status expected) {
        CHECK(run.status == expected);
        CHECK(run.count == 0);
        CHECK(run.workspace_guard_intact);
        CHECK(run.triangle_guard_intact);
        CHECK(counts_add_up(run.report));
        CHECK(run.report.detail != nullptr);
    };
    SUBCASE("a null cloud with a non-zero count: invalid_argument") {
        check_refused(reconstruct_guarded(Cloud{nullptr, 100, 0, Scalar::float64}, along_z), Status::invalid_argument);
    }
    SUBCASE("a count beyond 32-bit indices: too_many_points, before anything is read") {
        double three[9] = {1, 0, 0, 0, 1, 0, -1, 0, 1};
        std::vector<unsigned char> work(256);
        uint32_t tris[3];
        size_t count = 5;
        Report report = {};
        CHECK(stratmesh::reconstruct(Cloud{three, size_t{0xFFFFFFFEu}, 0, Scalar::float64}, along_z, work.data(),
                                     work.size(), tris, 1, &count, &report) == Status::too_many_points);
        CHECK(count == 0);
        CHECK(report.points.in_count == size_t{0xFFFFFFFEu});
        CHECK(counts_add_up(report));
    }
    SUBCASE("one point repeated: too_few_points, the repeats counted as duplicates") {
        std::vector<double> xyz;
        for (int i = 0; i < 5; ++i) xyz.insert(xyz.end(), {1.0, 2.0, 3.0});
        Run run = reconstruct_guarded(Cloud{xyz.data(), 5, 0, Scalar::float64}, along_z);
        check_refused(run, Status::too_few_points);
        CHECK(run.report.points.duplicate_count + run.report.points.unused_count == 5);
    }
    SUBCASE("two positions repeated among skipped NaNs: too_few_points until a third comes") {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        const double a[3] = {1, 2, 3}, b[3] = {1, 2, 4}, c[3] = {2, 2, 3.5};
        std::vector<double> xyz;
        for (const double* p : {a, b, a, b, a}) {
            xyz.insert(xyz.end(), {nan, nan, nan});
            xyz.insert(xyz.end(), p, p + 3);
        }
        Options skipping = along_z;
        skipping.flags = stratmesh::skip_invalid_points;
        const char* few = "fewer than 3 distinct valid points";
        Run two = reconstruct_guarded(Cloud{xyz.data(), 10, 0, Scalar::float64}, skipping);
        check_refused(two, Status::too_few_points);
        CHECK(two.report.points.rejected_count == 5);
        REQUIRE(two.report.detail != nullptr);
        CHECK(std::string(two.report.detail) == few);
        // A third position as the very last point passes that check (what follows refuses
        // three points for its own reason, or meshes them).
        xyz.insert(xyz.end(), c, c + 3);
        Run three = reconstruct_guarded(Cloud{xyz.data(), 11, 0, Scalar::float64}, skipping);
        CHECK(three.report.points.rejected_count == 5);
        CHECK(counts_add_up(three.report));
        CHECK((three.report.detail == nullptr || std::string(three.report.detail) != few));
    }
    SUBCASE("all points on one line beside the axis, or across it: degenerate") {
        // Small integers times powers of two: exactly on their lines whatever the compiler
        // contracts (a fused multiply-add would move 0.01 * i - 1 off the line).
        std::vector<double> beside, across;
        for (int i = 0; i < 200; ++i) {
            const double k = i, centred = i - 100;
            beside.insert(beside.end(), {1.0, 0.5, k * 0x1p-6});
            across.insert(across.end(), {centred * 0x1p-7, centred * 0x1p-6, k * 0x1p-8});
        }
        for (const std::vector<double>* line : {&beside, &across}) {
            Run run = reconstruct_guarded(Cloud{line->data(), 200, 0, Scalar::float64}, along_z);
            CHECK(run.status == Status::degenerate);
            check_refused(run, run.status);
            CHECK(run.report.points.unused_count == 200);
        }
    }
    SUBCASE("all points in one layer: cuts all outside the cloud") {
        double cuts[3] = {-100, 100, 1e300};
        Options o = axis_options(s);
        o.cuts = cuts;
        o.cut_count = 3;
        Run run = reconstruct_guarded(cloud_of(s), o);
        CHECK(run.report.layers.used_count == 1);
        check_annulus_through_every_point(s, run);
    }
    SUBCASE("an empty layer: two cuts inside a gap of the cloud") {
        // The cylinder without the points of the middle fifth of its height.
        std::vector<double> xyz;
        const double low = s.z_min + 0.4 * (s.z_max - s.z_min), high = s.z_min + 0.6 * (s.z_max - s.z_min);
        for (size_t i = 0; i < s.size(); ++i) {
            const double z = s.point(i)[2];
            if (z < low || z > high) xyz.insert(xyz.end(), s.point(i), s.point(i) + 3);
        }
        Shape gap = with_points(s, xyz, ", with a gap");
        double cuts[2] = {low + 0.25 * (high - low), low + 0.75 * (high - low)};
        Options o = axis_options(gap);
        o.cuts = cuts;
        o.cut_count = 2;
        Run run = reconstruct_guarded(cloud_of(gap), o);
        CHECK(run.report.layers.used_count >= 2);
        for (const LayerInfo& layer : run.layers) CHECK(layer.point_count > 0);
        check_annulus_through_every_point(gap, run);
    }
    SUBCASE("thousands of layers, by count and by cuts: tiny layers merge") {
        Options by_count = axis_options(s);
        by_count.layer_count = 5000;
        Run counted = reconstruct_guarded(cloud_of(s), by_count);
        check_annulus_through_every_point(s, counted);
        CHECK(counted.report.layers.used_count <= s.size() / 16);
        CHECK(stratmesh::reconstruct_workspace_size(s.size(), by_count) ==
              stratmesh::reconstruct_workspace_size(s.size(), [&] {
                  Options o = by_count;
                  o.layer_count = static_cast<uint32_t>(s.size());
                  return o;
              }()));

        std::vector<double> cuts(100000);
        for (size_t i = 0; i < cuts.size(); ++i)  // descending, every value twice
            cuts[i] = s.along_axis(s.z_max - (s.z_max - s.z_min) * static_cast<double>(i / 2) / 50000.0);
        Options by_cuts = axis_options(s);
        by_cuts.cuts = cuts.data();
        by_cuts.cut_count = cuts.size();
        Run cut = reconstruct_guarded(cloud_of(s), by_cuts);
        check_annulus_through_every_point(s, cut);
        CHECK(cut.report.layers.used_count <= s.size() / 16);
    }
    SUBCASE("a layer height far below the point spacing: layers merge until they hold enough points") {
        Options o = axis_options(s);
        o.layer_height = 1e-12;
        Run run = reconstruct_guarded(cloud_of(s), o);
        check_annulus_through_every_point(s, run);
    }
}

TEST_CASE("extreme magnitudes: scaling by a power of two gives the same triangles, and 1e30, 1e-30 and 1e7 offsets work") {
    const double origin[3] = {0, 0, 0};
    const Shape unit = moved_cylinder(1, origin);
    Options o = axis_options(unit);
    o.layer_count = 4;
    Run reference = reconstruct_guarded(cloud_of(unit), o);
    check_annulus_through_every_point(unit, reference);
    // doctest runs the test case once per subcase: every check sits in one, so none runs
    // twice.
    SUBCASE("powers of two from 2^-600 to 2^600: the same triangles") {
        for (double scale : {0x1p-600, 0x1p-100, 0x1p100, 0x1p600}) {
            CAPTURE(scale);
            const Shape scaled = moved_cylinder(scale, origin);
            Run run = reconstruct_guarded(cloud_of(scaled), o);
            check_annulus_through_every_point(scaled, run);
            CHECK(run.triangles == reference.triangles);
        }
    }
    SUBCASE("a cloud spanning more than the largest double: the same triangles as at unit size") {
        // Centred on the origin and scaled by 2^1022, heights run from -3 2^1022 to
        // 3 2^1022: their range, and the sum of the points, overflow a double.
        const double centring[3] = {-0.25, 0.5, -2};
        const Shape centred = moved_cylinder(1, centring), vast = moved_cylinder(0x1p1022, origin, centred);
        Run small = reconstruct_guarded(cloud_of(centred), o);
        Run run = reconstruct_guarded(cloud_of(vast), o);
        check_annulus_through_every_point(centred, small);
        REQUIRE(run.status == Status::ok);
        CHECK(run.triangles == small.triangles);
        CHECK(run.report.points.unused_count == 0);
    }
    SUBCASE("1e-30 and 1e30: a manifold annulus through every point") {
        for (double scale : {1e-30, 1e30}) {
            CAPTURE(scale);
            const Shape scaled = moved_cylinder(scale, origin);
            Run run = reconstruct_guarded(cloud_of(scaled), o);
            check_annulus_through_every_point(scaled, run);
        }
    }
    SUBCASE("a georeferenced scan: a 50 mm pipe 1e7 m from the origin, millimetre spacing kept") {
        const double far[3] = {6.5e6, 1.0e7, 350.0};
        const Shape pipe = moved_cylinder(0.05, far);
        Options p = axis_options(pipe);
        p.layer_count = 4;
        Run run = reconstruct_guarded(cloud_of(pipe), p);
        check_annulus_through_every_point(pipe, run);
        mesh_check::Result m = check_mesh(pipe, run.triangles.data(), run.count, true);
        CHECK(m.inward == 0);
        CHECK(m.intersecting_pairs == 0);
        // The coordinates carry about 2e-9 m of rounding at 1e7: the mesh must meet the
        // surface as well as the same pipe at the origin does, to a micrometre.
        const Shape near = moved_cylinder(0.05, origin);
        Run at_origin = reconstruct_guarded(cloud_of(near), p);
        REQUIRE(at_origin.status == Status::ok);
        mesh_check::Result n = check_mesh(near, at_origin.triangles.data(), at_origin.count, false);
        MESSAGE("pipe deviation at 1e7: " << m.max_deviation() << " m, at the origin: " << n.max_deviation()
                                          << " m, spacing " << pipe.spacing << " m");
        CHECK(m.max_deviation() < n.max_deviation() + 1e-6);
    }
    SUBCASE("subnormal coordinates: refused with a status, or a manifold annulus") {
        const Shape tiny = moved_cylinder(0x1p-1060, origin);
        Run run = reconstruct_guarded(cloud_of(tiny), o);
        MESSAGE("subnormal cylinder: " << std::string(stratmesh::status_string(run.status)));
        CHECK(counts_add_up(run.report));
        CHECK(run.workspace_guard_intact);
        CHECK(run.triangle_guard_intact);
        if (run.status == Status::ok) {
            mesh_check::Result m = check_mesh(tiny, run.triangles.data(), run.count, false);
            CHECK(m.manifold());
        } else {
            CHECK(run.report.detail != nullptr);
        }
    }
}

// ===========================================================================================
// Automatic layers (the paper's layering rule, see >>layers in the header): as few layers as
// keep every layer well unrolled, more only where the centre line drifts or a layer would
// be too tall for its radius.

namespace {

// A unit-radius tube along Z over z in [-6, 6] whose centre line bends sideways:
// x = amplitude * sin(pi z / 12). With amplitude 2 the two ends are four radii apart, so
// no straight line runs inside the whole tube.
struct BentTube {
    double amplitude;
    std::vector<double> xyz;
    double centre_x(double z) const { return amplitude * std::sin(shapes::kPi * z / 12); }
};

BentTube bent_tube(size_t n, double amplitude) {
    BentTube tube{amplitude, {}};
    shapes::Rng rng(23);
    for (size_t i = 0; i < n; ++i) {
        double z = rng.uniform(-6, 6), t = rng.uniform(0, 2 * shapes::kPi);
        tube.xyz.insert(tube.xyz.end(), {tube.centre_x(z) + std::cos(t), std::sin(t), z});
    }
    return tube;
}

mesh_check::Result check_bent_mesh(const BentTube& tube, const Run& run) {
    mesh_check::Input in;
    in.points = tube.xyz.data();
    in.point_count = tube.xyz.size() / 3;
    in.triangles = run.triangles.data();
    in.triangle_count = run.count;
    in.axis_point[0] = in.axis_point[1] = in.axis_point[2] = 0;
    in.axis_direction[0] = in.axis_direction[1] = 0;
    in.axis_direction[2] = 1;  // the straight axis: orientation counts are not meaningful
    in.surface = [&tube](const double* p) { return std::hypot(p[0] - tube.centre_x(p[2]), p[1]) - 1; };
    in.self_intersections = true;
    return mesh_check::check(in);
}

}  // namespace

TEST_CASE("automatic layers: one layer where one unrolls well, with no fold") {
    for (Pose pose : {Pose::z, Pose::tilted}) {
        for (const Shape& s : {shapes::vase(kSmall, pose), shapes::head(kLarge, pose), shapes::ct_slices(kSmall, pose),
                               shapes::bumpy_tube(kSmall, pose)}) {
            CAPTURE(s.name);
            CAPTURE(shapes::pose_name(pose));
            Run run = reconstruct_guarded(cloud_of(s), axis_options(s));
            check_annulus_through_every_point(s, run);
            CHECK(run.report.layers.used_count == 1);
            CHECK(run.report.diagnostics.fold_count == 0);
            mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, true);
            CHECK(m.inward == 0);
            CHECK(m.intersecting_pairs == 0);
        }
    }
    SUBCASE("no folds where the paper's anatomical cuts give none, with fewer layers") {
        Case anatomical = head_case(Pose::z, kLarge);
        Shape s = shapes::head(kLarge, Pose::z);
        Run automatic = reconstruct_guarded(cloud_of(s), axis_options(s));
        REQUIRE(automatic.status == Status::ok);
        CHECK(automatic.report.diagnostics.fold_count <= anatomical.run.report.diagnostics.fold_count);
        CHECK(automatic.report.layers.used_count < anatomical.run.report.layers.used_count);
    }
}

TEST_CASE("automatic layers: a bent tube is cut where its centre line drifts, and folds vanish") {
    for (double amplitude : {1.0, 2.0}) {
        CAPTURE(amplitude);
        const BentTube tube = bent_tube(8000, amplitude);
        const Cloud cloud = {tube.xyz.data(), tube.xyz.size() / 3, 0, Scalar::float64};
        Options automatic = {};
        automatic.axis = Axis::z;
        Options single = automatic;
        single.layer_count = 1;
        Run split = reconstruct_guarded(cloud, automatic);
        Run whole = reconstruct_guarded(cloud, single);
        REQUIRE(split.status == Status::ok);
        REQUIRE(whole.status == Status::ok);
        mesh_check::Result s = check_bent_mesh(tube, split), w = check_bent_mesh(tube, whole);
        MESSAGE("bent tube, amplitude " << amplitude << ": automatic " << split.report.layers.used_count << " layers, "
                                        << split.report.diagnostics.fold_count << " folds, " << s.intersecting_pairs
                                        << " intersecting pairs; one layer " << whole.report.diagnostics.fold_count << " folds, "
                                        << w.intersecting_pairs << " intersecting pairs");
        CHECK(split.report.layers.used_count >= 2);
        CHECK(s.manifold());
        CHECK(s.boundary_loops == 2);
        CHECK(split.report.points.unused_count == 0);
        CHECK(split.report.diagnostics.fold_count < whole.report.diagnostics.fold_count);
        CHECK(s.intersecting_pairs < w.intersecting_pairs);
        CHECK(s.max_deviation() < w.max_deviation());
        // The layers tile the height range: each one starts where the one below ends.
        for (size_t k = 1; k < split.layers.size(); ++k) CHECK(split.layers[k].bottom == split.layers[k - 1].top);
    }
}

TEST_CASE("automatic layers: a tall thin tube is cut into layers at most 24 radii tall") {
    const double radius = 0.05;  // 120 radii tall
    Shape s = shapes::thin_tube(kLarge, Pose::z, radius);
    Run run = reconstruct_guarded(cloud_of(s), axis_options(s));
    check_annulus_through_every_point(s, run);
    CHECK(run.report.layers.used_count >= 5);
    for (const LayerInfo& layer : run.layers) {
        CHECK(layer.top - layer.bottom <= 24 * layer.radius * 1.05);
        CHECK(layer.radius == doctest::Approx(radius).epsilon(0.05));
    }
}

// ===========================================================================================
// add_caps: caps over the boundary loops make the tube a closed surface.

namespace {

// Six times the signed volume the triangles enclose: positive when they face outward.
double six_times_volume(const Shape& s, const uint32_t* triangles, size_t count) {
    double sum = 0;
    for (size_t t = 0; t < count; ++t) {
        const double* a = s.point(triangles[3 * t]);
        const double* b = s.point(triangles[3 * t + 1]);
        const double* c = s.point(triangles[3 * t + 2]);
        sum += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return sum;
}

// The caps (the cap triangles above the middle of the shape along its axis, and those
// below) whose triangles, summed, face towards the middle: a bottom cap facing up or a top
// cap facing down. Summed, because the triangles that close a loop's ragged pockets along
// the wall (see "pockets closed before a cap" in the header) stand across the axis, either
// way.
size_t caps_facing_inward(const Shape& s, const uint32_t* triangles, size_t first, size_t count) {
    double axis[3], origin[3];
    s.axis_direction(axis);
    s.axis_point(origin);
    const double middle = (s.z_min + s.z_max) / 2;
    double facing_top = 0, facing_bottom = 0;
    for (size_t t = first; t < count; ++t) {
        const double* p[3] = {s.point(triangles[3 * t]), s.point(triangles[3 * t + 1]),
                              s.point(triangles[3 * t + 2])};
        double u[3], v[3], height = 0, facing = 0;
        for (int k = 0; k < 3; ++k) u[k] = p[1][k] - p[0][k], v[k] = p[2][k] - p[0][k];
        const double normal[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                                  u[0] * v[1] - u[1] * v[0]};
        for (int k = 0; k < 3; ++k) {
            height += ((p[0][k] + p[1][k] + p[2][k]) / 3 - origin[k]) * axis[k];
            facing += normal[k] * axis[k];
        }
        (height > middle ? facing_top : facing_bottom) += facing;
    }
    return size_t{facing_top < 0} + size_t{facing_bottom > 0};
}

// Cap diagonals that a flip would lower (on a bottom cap, facing -axis) or raise (on a top
// cap): the other diagonal of the two cap triangles beside it lies below (above) it by more
// than rounding, in a quadrilateral convex across the axis, and is no edge of the surface.
// Caps are meant to be as low (high) as their loops allow, so that a wall leaning over
// the cap near a ragged loop stays above (below) it.
// A point in the frame (e1, e2, axis), in place.
void frame_point(double* p, const double* e1, const double* e2, const double* axis) {
    const double q[3] = {p[0], p[1], p[2]};
    p[0] = q[0] * e1[0] + q[1] * e1[1] + q[2] * e1[2];
    p[1] = q[0] * e2[0] + q[1] * e2[1] + q[2] * e2[2];
    p[2] = q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2];
}

// The angle a triangle (in the frame) spans around the axis through `centre`: the largest
// angle between two of its corners seen from the axis.
double angular_span(const double p[3][3], const double* centre) {
    double widest = 0;
    for (int i = 0; i < 3; ++i) {
        const double ax = p[i][0] - centre[0], ay = p[i][1] - centre[1];
        const double bx = p[(i + 1) % 3][0] - centre[0], by = p[(i + 1) % 3][1] - centre[1];
        widest = std::max(widest, std::fabs(std::atan2(ax * by - ay * bx, ax * bx + ay * by)));
    }
    return widest;
}

size_t improvable_cap_diagonals(const Shape& s, const uint32_t* triangles, size_t first,
                                size_t count) {
    double axis[3], e1[3], e2[3];
    s.axis_direction(axis);
    const double length = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (double& a : axis) a /= length;
    const double seed[3] = {std::fabs(axis[0]) < 0.9 ? 1.0 : 0.0, std::fabs(axis[0]) < 0.9 ? 0.0 : 1.0, 0};
    e1[0] = seed[1] * axis[2] - seed[2] * axis[1];
    e1[1] = seed[2] * axis[0] - seed[0] * axis[2];
    e1[2] = seed[0] * axis[1] - seed[1] * axis[0];
    const double e1_length = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (double& a : e1) a /= e1_length;
    e2[0] = axis[1] * e1[2] - axis[2] * e1[1];
    e2[1] = axis[2] * e1[0] - axis[0] * e1[2];
    e2[2] = axis[0] * e1[1] - axis[1] * e1[0];
    // (x, y) across the axis and h along it, in a right-handed frame.
    auto frame = [&](uint32_t v, double* out) {
        const double* p = s.point(v);
        out[0] = p[0] * e1[0] + p[1] * e1[1] + p[2] * e1[2];
        out[1] = p[0] * e2[0] + p[1] * e2[1] + p[2] * e2[2];
        out[2] = p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
    };
    auto orient = [](const double* a, const double* b, const double* c) {
        return (a[0] - c[0]) * (b[1] - c[1]) - (a[1] - c[1]) * (b[0] - c[0]);
    };
    std::set<std::pair<uint32_t, uint32_t>> surface_edges;
    for (size_t t = 0; t < first; ++t)
        for (size_t k = 0; k < 3; ++k) {
            uint32_t a = triangles[3 * t + k], b = triangles[3 * t + (k + 1) % 3];
            surface_edges.insert({std::min(a, b), std::max(a, b)});
        }
    double centre[3];
    s.axis_point(centre);
    frame_point(centre, e1, e2, axis);
    // Directed cap edge -> third vertex, over the triangles that lie across the axis (within
    // 60 degrees of it) and span more than a pocket around it (pi / 8): those standing
    // along the wall or within a pocket close a ragged loop's pockets before the cap (see
    // "pockets closed before a cap" in the header), whose chords are kept on purpose.
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> beyond;
    for (size_t t = first; t < count; ++t) {
        double p[3][3];
        for (size_t k = 0; k < 3; ++k) frame(triangles[3 * t + k], p[k]);
        if (angular_span(p, centre) < shapes::kPi / 8) continue;
        double u[3], v[3];
        for (int k = 0; k < 3; ++k) u[k] = p[1][k] - p[0][k], v[k] = p[2][k] - p[0][k];
        const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        if (!(std::fabs(n[2]) >= 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]))) continue;
        for (size_t k = 0; k < 3; ++k)
            beyond[{triangles[3 * t + k], triangles[3 * t + (k + 1) % 3]}] = triangles[3 * t + (k + 2) % 3];
    }
    size_t improvable = 0;
    for (const auto& edge : beyond) {
        const uint32_t a = edge.first.first, b = edge.first.second, c = edge.second;
        auto other = beyond.find({b, a});
        if (a > b || other == beyond.end()) continue;  // each diagonal once
        const uint32_t d = other->second;
        if (surface_edges.count({std::min(c, d), std::max(c, d)})) continue;
        double pa[3], pb[3], pc[3], pd[3];
        frame(a, pa), frame(b, pb), frame(c, pc), frame(d, pd);
        const bool bottom = orient(pa, pb, pc) < 0;  // clockwise seen from +axis: faces -axis
        if (bottom) std::swap(pa, pb);               // abc counter-clockwise from here on
        // Strictly convex across the axis: both new triangles turn the same way.
        if (!(orient(pa, pd, pc) > 0 && orient(pd, pb, pc) > 0)) continue;
        // The plane through a, b, c at d's place, against d's height.
        const double area = orient(pa, pb, pc);
        const double wa = orient(pb, pc, pd) / area, wb = orient(pc, pa, pd) / area,
                     wc = orient(pa, pb, pd) / area;
        const double plane = wa * pa[2] + wb * pb[2] + wc * pc[2];
        const double tolerance = 1e-9 * (std::fabs(pa[2]) + std::fabs(pb[2]) + std::fabs(pc[2]) + 1);
        if (bottom ? pd[2] < plane - tolerance : pd[2] > plane + tolerance) ++improvable;
    }
    return improvable;
}

}  // namespace

// STRATMESH_SMALL_CODE leaves out the lowering and raising of caps (see the header's Config).
#if defined(STRATMESH_SMALL_CODE)
const bool kLiftedCaps = false;
#else
const bool kLiftedCaps = true;
#endif

TEST_CASE("add_caps: cylinder, vase, bumpy tube, head and CT slices become closed, outward surfaces, the tube unchanged") {
    // Measured (g++ 12 -O2): every run below closes both loops, 29 to 196 cap triangles at
    // 2000 points (the CT stack's end contours hold 100 points each), no intersection.
    const size_t kinds[] = {0, 4, 2, 8, 6};
    const Layering layerings[] = {Layering::single, Layering::equal, Layering::automatic};
    for (size_t kind : kinds) {
        for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
            for (size_t points : {size_t{200}, kSmall}) {
                Shape s = shapes::kinds()[kind].make(points, pose);
                for (Layering layering : layerings) {
                    std::vector<double> cuts;
                    Options open = layered_options(s, layering, cuts);
                    Options closed = open;
                    closed.flags |= stratmesh::add_caps;
                    Run tube = reconstruct_guarded(cloud_of(s), open);
                    Run run = reconstruct_guarded(cloud_of(s), closed);
                    mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, true);
                    INFO(s.name << ", " << points << " points, " << layering_name(layering) << ": "
                                << run.report.caps.triangle_count << " cap triangles; " << m.summary());
                    REQUIRE(tube.status == Status::ok);
                    REQUIRE(run.status == Status::ok);
                    CHECK(run.workspace_guard_intact);
                    CHECK(run.triangle_guard_intact);
                    // Without the flag: no caps reported, and the same tube comes first with it.
                    CHECK(tube.report.caps.closed_count == 0);
                    CHECK(tube.report.caps.triangle_count == 0);
                    REQUIRE(run.count == tube.count + run.report.caps.triangle_count);
                    CHECK(std::equal(tube.triangles.begin(), tube.triangles.end(), run.triangles.begin()));
                    CHECK(run.report.caps.wall_flip_count == 0);
                    CHECK(run.report.caps.closed_count == 2);
                    CHECK(run.report.caps.open_count == 0);
                    CHECK(run.report.triangle_count == run.count);
                    CHECK(run.report.detail == nullptr);
                    CHECK(run.count <= run.max_triangles);
                    // A closed surface through V vertices: 2V - 4 triangles.
                    CHECK(run.count == 2 * run.report.points.used_count - 4);
                    CHECK(m.bad_indices == 0);
                    CHECK(m.degenerate == 0);
                    CHECK(m.zero_area == 0);
                    CHECK(m.manifold());
                    CHECK(m.boundary_edges == 0);
                    CHECK(m.boundary_loops == 0);
                    CHECK(m.components == 1);
                    CHECK(m.euler == 2);
                    CHECK(m.vertices_used == s.size());
                    CHECK(m.unused_expected == 0);
                    CHECK(m.intersecting_pairs == 0);
                    CHECK(m.vertex_overlaps == 0);
                    CHECK(six_times_volume(s, run.triangles.data(), run.count) > 0);
                    CHECK(caps_facing_inward(s, run.triangles.data(), tube.count, run.count) == 0);
                    if (kLiftedCaps)
                        CHECK(improvable_cap_diagonals(s, run.triangles.data(), tube.count, run.count) == 0);
                }
            }
        }
    }
}

#if !defined(STRATMESH_SMALL_CODE)
TEST_CASE("add_caps on a noisy tube: caps as low (bottom) and high (top) as their ragged loops allow stay clear of the wall") {
    // With Delaunay caps (before they were lowered and raised: see the header's >>caps) a
    // cap crossed the wall of the 2000-point tube along Z, with each of these layerings.
    const Layering layerings[] = {Layering::single, Layering::equal, Layering::automatic};
    for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
        for (size_t points : {size_t{200}, kSmall}) {
            Shape s = shapes::noisy_tube(points, pose);
            for (Layering layering : layerings) {
                std::vector<double> cuts;
                Options o = layered_options(s, layering, cuts);
                o.flags |= stratmesh::add_caps;
                Run run = reconstruct_guarded(cloud_of(s), o);
                REQUIRE(run.status == Status::ok);
                mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, true);
                const size_t first = run.count - run.report.caps.triangle_count;
                INFO(s.name << ", " << points << " points, " << layering_name(layering) << ": "
                            << m.summary());
                CHECK(run.report.caps.closed_count == 2);
                CHECK(m.manifold());
                CHECK(m.boundary_edges == 0);
                CHECK(m.euler == 2);
                CHECK(m.intersecting_pairs == 0);
                CHECK(m.vertex_overlaps == 0);
                CHECK(caps_facing_inward(s, run.triangles.data(), first, run.count) == 0);
                CHECK(improvable_cap_diagonals(s, run.triangles.data(), first, run.count) == 0);
            }
        }
    }
}
#endif

#if !defined(STRATMESH_SMALL_CODE)
TEST_CASE("add_caps on a tilted tube that flares toward its ends: the caps stay clear of the wall") {
    // Where the wall widens toward an end, a ragged loop's lower points lie inside it seen
    // along the axis, and a cap over the whole loop dips with them through the wall's top
    // row; the pockets under the loop's upper hull are closed along the wall first (see
    // "pockets closed before a cap" in the header). The defaults: the automatic axis.
    auto flared = [](double theta, double z) {
        return (1.2 + 0.5 * std::sin(0.9 * z)) * (1 + 0.15 * std::sin(4 * theta));
    };
    struct Size { size_t points; double height; uint64_t seed; };
    for (Size size : {Size{20000, 10, 4}, Size{30000, 5, 6}, Size{60000, 7, 3}}) {
        Shape s = shapes::radial_random("flared tube", Pose::tilted, flared, 0, size.height,
                                        size.points, size.seed);
        Options o = {};
        o.flags = stratmesh::add_caps;
        Run run = reconstruct_guarded(cloud_of(s), o);
        REQUIRE(run.status == Status::ok);
        mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, true);
        const size_t first = run.count - run.report.caps.triangle_count;
        INFO(size.points << " points, height " << size.height << ": " << m.summary());
        CHECK(run.report.caps.closed_count == 2);
        CHECK(m.manifold());
        CHECK(m.boundary_edges == 0);
        CHECK(m.euler == 2);
        CHECK(m.vertices_used == s.size());
        CHECK(m.intersecting_pairs == 0);
        CHECK(m.vertex_overlaps == 0);
        CHECK(six_times_volume(s, run.triangles.data(), run.count) > 0);
        CHECK(caps_facing_inward(s, run.triangles.data(), first, run.count) == 0);
    }
}
#endif

TEST_CASE("add_caps at 20000 points: closed, oriented, the bound on triangles holds") {
    for (size_t kind : {size_t{2}, size_t{6}}) {
        Shape s = shapes::kinds()[kind].make(kLarge, Pose::tilted);
        Options o = axis_options(s);
        o.flags = stratmesh::add_caps;
        Run run = reconstruct_guarded(cloud_of(s), o);
        REQUIRE(run.status == Status::ok);
        mesh_check::Result m = check_mesh(s, run.triangles.data(), run.count, kind == 2);
        INFO(s.name << ": " << m.summary());
        CHECK(run.report.caps.closed_count == 2);
        CHECK(m.manifold());
        CHECK(m.boundary_edges == 0);
        CHECK(m.components == 1);
        CHECK(m.euler == 2);
        CHECK(m.vertices_used == s.size());
        CHECK(m.intersecting_pairs == 0);
        CHECK(m.vertex_overlaps == 0);
        CHECK(run.count == 2 * s.size() - 4);
        CHECK(six_times_volume(s, run.triangles.data(), run.count) > 0);
    }
}

TEST_CASE("add_caps: a triangle array too small for the caps gives triangle_capacity with the needed count") {
    const Shape& s = reference_cylinder();
    Options o = axis_options(s);
    o.flags = stratmesh::add_caps;
    Run reference = reconstruct_guarded(cloud_of(s), o);
    REQUIRE(reference.status == Status::ok);
    std::vector<unsigned char> work(stratmesh::reconstruct_workspace_size(s.size(), o));
    for (size_t capacity : {reference.count - reference.report.caps.triangle_count, reference.count - 1,
                            reference.count}) {
        CAPTURE(capacity);
        std::vector<uint32_t> tris(3 * (capacity + kGuardTriangles), kSentinel);
        size_t count = 0;
        Report report{};
        Status status = stratmesh::reconstruct(cloud_of(s), o, work.data(), work.size(), tris.data(),
                                               capacity, &count, &report);
        bool guard = true;
        for (size_t i = 3 * capacity; i < tris.size(); ++i) guard = guard && tris[i] == kSentinel;
        CHECK(guard);
        CHECK(counts_add_up(report));
        if (capacity == reference.count) {
            CHECK(status == Status::ok);
            tris.resize(3 * count);
            CHECK(tris == reference.triangles);
        } else {
            CHECK(status == Status::triangle_capacity);
            CHECK(count == reference.count);
        }
    }
}

// surface_flips re-triangulates each layer by the empty-circle rule in 3D. It must keep
// everything the plain run guarantees (one manifold annulus through every point, outward,
// no more folds) and add no crossing pair of triangles, also where the flips turn
// triangles to face the axis. On the bumpy tube, whose bumps turn the surface
// steeply around the axis so that the unrolling squeezes them, it must bring the surface
// nearer the truth (measured: 43% at 1 layer, 42% at 6; the cone 49% and 46%, the head 19%
// and 15%, the vase 4% and 3%); the grid and the CT slices have nothing to flip.
TEST_CASE("surface_flips: the same guarantees, the bumpy tube nearer the true surface, no shape farther") {
    const std::vector<Shape> list = {
        shapes::bumpy_tube(kLarge, Pose::tilted), shapes::head(kLarge, Pose::x),
        shapes::vase(kLarge, Pose::z),            shapes::cone(kLarge, Pose::tilted),
        shapes::noisy_tube(kLarge, Pose::z),      shapes::ct_slices(kLarge, Pose::x),
        shapes::scan_grid(kLarge, Pose::tilted),  shapes::capsule(kLarge, Pose::z)};
    for (const Shape& s : list)
        for (uint32_t layers : {1u, 6u}) {
            INFO(s.name << " (" << shapes::pose_name(s.pose) << "), " << layers << " layers");
            Options o = axis_options(s);
            o.layer_count = layers;
            const Run plain = reconstruct_guarded(cloud_of(s), o);
            o.flags |= stratmesh::surface_flips;
            const Run flipped = reconstruct_guarded(cloud_of(s), o);
            REQUIRE(plain.status == Status::ok);
            REQUIRE(flipped.status == Status::ok);
            CHECK(flipped.report.layers.used_count == plain.report.layers.used_count);
            CHECK(flipped.report.points.used_count == plain.report.points.used_count);
            CHECK(flipped.report.diagnostics.fold_count <= plain.report.diagnostics.fold_count);
            CHECK(flipped.workspace_guard_intact);
            CHECK(flipped.triangle_guard_intact);
            CHECK(counts_add_up(flipped.report));
            const mesh_check::Result m = check_mesh(s, flipped.triangles.data(), flipped.count, true);
            INFO(m.summary());
            CHECK(m.bad_indices == 0);
            CHECK(m.manifold());
            CHECK(m.components == 1);
            CHECK(m.boundary_loops == 2);
            CHECK(m.vertices_used ==
                  check_mesh(s, plain.triangles.data(), plain.count, false).vertices_used);
            const mesh_check::Result unflipped =
                check_mesh(s, plain.triangles.data(), plain.count, true);
            CHECK(m.intersecting_pairs <= unflipped.intersecting_pairs);
            CHECK(m.vertex_overlaps <= unflipped.vertex_overlaps);
            if (plain.report.diagnostics.fold_count == 0) CHECK(m.intersecting_pairs == 0);
            const double before = mean_centroid_deviation(s, plain.triangles);
            const double after = mean_centroid_deviation(s, flipped.triangles);
            const size_t wide_before = triangles_wider_than(s, plain.triangles, 150);
            const size_t wide_after = triangles_wider_than(s, flipped.triangles, 150);
            MESSAGE(s.name << ", " << layers << " layers: mean distance " << before << " -> " << after
                           << ", triangles wider than 150 degrees " << wide_before << " -> "
                           << wide_after);
            // With the empty-circle rule alone the vase came out 9% and the cone 7% farther.
            CHECK(after <= before);
            CHECK(wide_after <= wide_before);
            // These two curve much less along one direction than across it, which the bend
            // finds: 10% closer with the empty-circle rule alone, 35 to 50% with both.
            if (s.name.rfind("bumpy tube", 0) == 0 || s.name.rfind("cone", 0) == 0) {
                CHECK(flipped.triangles != plain.triangles);
                CHECK(after <= 0.75 * before);
            }
        }
}

// A cut costs distance: a layer's flips on the surface run before its band exists and
// never move a loop's edge. With surface_flips each chunk's seam (the band and the layer's
// triangles at its bottom loop) is flipped too (header, "flips across the seam"). Mean
// centroid distance over one layer's, 4 and 16 layers, without the seam's flips and with
// them: bumpy tube 1.043 and 1.223 -> 1.018 and 1.104, cone 1.112 and 1.503 -> 1.077 and
// 1.301, vase 1.021 and 1.056 -> 1.017 and 1.043, head 1.030 and 1.237 -> 1.028 and 1.109.
TEST_CASE("surface_flips: many layers come nearly as close as one, across the seams too") {
    const std::vector<Shape> list = {shapes::bumpy_tube(kLarge, Pose::tilted),
                                     shapes::cone(kLarge, Pose::z),
                                     shapes::vase(kLarge, Pose::x),
                                     shapes::head(kLarge, Pose::z)};
    for (const Shape& s : list) {
        Options o = axis_options(s);
        o.flags |= stratmesh::surface_flips;
        o.layer_count = 1;
        const Run one = reconstruct_guarded(cloud_of(s), o);
        REQUIRE(one.status == Status::ok);
        const double single = mean_centroid_deviation(s, one.triangles);
        for (uint32_t layers : {4u, 16u}) {
            INFO(s.name << " (" << shapes::pose_name(s.pose) << "), " << layers << " layers");
            o.layer_count = layers;
            const Run many = reconstruct_guarded(cloud_of(s), o);
            REQUIRE(many.status == Status::ok);
            CHECK(many.workspace_guard_intact);
            CHECK(many.triangle_guard_intact);
            CHECK(counts_add_up(many.report));
            const mesh_check::Result m = check_mesh(s, many.triangles.data(), many.count, true);
            INFO(m.summary());
            CHECK(m.manifold());
            CHECK(m.components == 1);
            CHECK(m.boundary_loops == 2);
            if (many.report.diagnostics.fold_count == 0) CHECK(m.intersecting_pairs == 0);
            const double mean = mean_centroid_deviation(s, many.triangles);
            MESSAGE(s.name << ", " << layers << " layers: mean distance " << mean << ", one layer "
                           << single << ", ratio " << mean / single);
#if !defined(STRATMESH_SMALL_CODE)  // which ignores surface_flips (the header's Config)
            const bool cone = s.name.rfind("cone", 0) == 0;
            CHECK(mean <= (layers == 4 ? 1.10 : cone ? 1.35 : 1.15) * single);
#endif
        }
    }
}
