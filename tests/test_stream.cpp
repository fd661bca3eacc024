// The streaming reconstruction: pushed layer by layer, it gives reconstruct()'s triangles
// on the same layers, in bounded memory, and refuses malformed pushes without changing.
#include "stratmesh.h"
#include "support/library_options.h"
#include "support/mesh_check.h"
#include "support/shapes.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

using library_options::axis_options;
using stratmesh::Cloud;
using stratmesh::LayerInfo;
using stratmesh::Options;
using stratmesh::Report;
using stratmesh::Scalar;
using stratmesh::Status;
using shapes::Pose;
using shapes::Shape;

// A cloud cut into layers: the points reordered layer after layer (input order within a
// layer) and the cuts between them, each half-way across a gap between the points'
// heights, so that which side a point lies on does not depend on rounding.
struct Layered {
    std::vector<double> xyz;
    std::vector<double> cuts;   // one fewer than the layers
    std::vector<size_t> start;  // first point of each layer, then the end
    double top = 0;             // above every point: the last push's top
    size_t size() const { return xyz.size() / 3; }
};

double height_of(const double* p, const double axis[3]) {
    return p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
}

// Layers at the given fractions of the height range (each moved to the middle of the
// nearest gap between point heights).
Layered layer_cloud(const std::vector<double>& xyz, const double axis[3],
                    const std::vector<double>& fractions) {
    const size_t n = xyz.size() / 3;
    std::vector<double> heights(n);
    for (size_t i = 0; i < n; ++i) heights[i] = height_of(&xyz[3 * i], axis);
    std::vector<double> sorted = heights;
    std::sort(sorted.begin(), sorted.end());
    Layered out;
    for (double f : fractions) {
        size_t k = static_cast<size_t>(f * static_cast<double>(n - 1));
        while (k + 1 < n && sorted[k + 1] - sorted[k] < 1e-9 * (1 + std::fabs(sorted[k]))) ++k;
        if (k + 1 >= n) continue;
        double cut = (sorted[k] + sorted[k + 1]) / 2;
        if (out.cuts.empty() || cut > out.cuts.back()) out.cuts.push_back(cut);
    }
    out.top = sorted.back() + 1;
    out.start.push_back(0);
    for (size_t layer = 0; layer <= out.cuts.size(); ++layer) {
        double lo = layer == 0 ? -std::numeric_limits<double>::infinity() : out.cuts[layer - 1];
        double hi = layer == out.cuts.size() ? std::numeric_limits<double>::infinity() : out.cuts[layer];
        for (size_t i = 0; i < n; ++i)
            if (heights[i] >= lo && heights[i] < hi) out.xyz.insert(out.xyz.end(), &xyz[3 * i], &xyz[3 * i] + 3);
        out.start.push_back(out.xyz.size() / 3);
    }
    return out;
}

std::vector<double> equal_fractions(size_t layers) {
    std::vector<double> f;
    for (size_t k = 1; k < layers; ++k) f.push_back(static_cast<double>(k) / static_cast<double>(layers));
    return f;
}

struct Output {
    Status status = Status::internal_error;
    std::vector<uint32_t> triangles;
    Report report{};
    std::vector<LayerInfo> layers;
};

void collect(void* user, const uint32_t* triangles, size_t count) {
    std::vector<uint32_t>* out = static_cast<std::vector<uint32_t>*>(user);
    out->insert(out->end(), triangles, triangles + 3 * count);
}

Output run_batch(const Layered& l, Options o) {
    Output out;
    o.cuts = l.cuts.data();
    o.cut_count = l.cuts.size();
    const Cloud cloud = {l.xyz.data(), l.size(), 0, Scalar::float64};
    std::vector<unsigned char> work(stratmesh::reconstruct_workspace_size(cloud.count, o));
    out.triangles.resize(3 * stratmesh::reconstruct_max_triangles(cloud.count, o));
    out.layers.resize(512);
    out.report.layers.info = out.layers.data();
    out.report.layers.info_capacity = out.layers.size();
    size_t count = 0;
    out.status = stratmesh::reconstruct(cloud, o, work.data(), work.size(), out.triangles.data(),
                                        out.triangles.size() / 3, &count, &out.report);
    out.triangles.resize(3 * count);
    return out;
}

// Pushes the layers one at a time into a stream that may hold `held` points.
Output run_stream(const Layered& l, const Options& o, size_t held) {
    Output out;
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(held, o));
    out.layers.resize(512);
    out.report.layers.info = out.layers.data();
    out.report.layers.info_capacity = out.layers.size();
    stratmesh::Stream* stream = nullptr;
    out.status = stratmesh::stream_open(o, work.data(), work.size(), collect, &out.triangles,
                                        &out.report, &stream);
    if (out.status != Status::ok) return out;
    for (size_t k = 0; k + 1 < l.start.size(); ++k) {
        const Cloud layer = {l.xyz.data() + 3 * l.start[k], l.start[k + 1] - l.start[k], 0,
                             Scalar::float64};
        out.status = stratmesh::stream_push(stream, layer, k < l.cuts.size() ? l.cuts[k] : l.top);
        if (out.status != Status::ok) return out;
    }
    out.status = stratmesh::stream_close(stream);
    return out;
}

// The origin both runs use: the first point (any point will do, as long as it is shared).
Options shared_origin(const Shape& s) {
    Options o = axis_options(s);
    o.flags = stratmesh::origin_given;
    for (int k = 0; k < 3; ++k) o.origin[k] = s.xyz[static_cast<size_t>(k)];
    return o;
}

void check_same(const Output& batch, const Output& stream) {
    REQUIRE(batch.status == Status::ok);
    CHECK(stream.status == batch.status);
    CHECK(stream.triangles.size() == batch.triangles.size());
    CHECK(stream.triangles == batch.triangles);
    CHECK(stream.report.points.in_count == batch.report.points.in_count);
    CHECK(stream.report.points.used_count == batch.report.points.used_count);
    CHECK(stream.report.points.duplicate_count == batch.report.points.duplicate_count);
    CHECK(stream.report.points.unused_count == batch.report.points.unused_count);
    CHECK(std::string(stream.report.detail ? stream.report.detail : "") ==
          std::string(batch.report.detail ? batch.report.detail : ""));
    CHECK(stream.report.triangle_count == batch.report.triangle_count);
    CHECK(stream.report.diagnostics.illegal_removed_count == batch.report.diagnostics.illegal_removed_count);
    CHECK(stream.report.diagnostics.fold_count == batch.report.diagnostics.fold_count);
    CHECK(stream.report.diagnostics.diagonal_swap_count == batch.report.diagnostics.diagonal_swap_count);
    REQUIRE(stream.report.layers.used_count == batch.report.layers.used_count);
    for (size_t k = 0; k < batch.report.layers.used_count && k < batch.layers.size(); ++k) {
        CHECK(stream.layers[k].point_count == batch.layers[k].point_count);
        CHECK(stream.layers[k].triangle_count == batch.layers[k].triangle_count);
        CHECK(stream.layers[k].closed_ends == batch.layers[k].closed_ends);
        CHECK(stream.layers[k].bottom == doctest::Approx(batch.layers[k].bottom));
        CHECK(stream.layers[k].top == doctest::Approx(batch.layers[k].top));
        CHECK(stream.layers[k].radius == doctest::Approx(batch.layers[k].radius));
    }
}

// Runs check(layered cloud, options with a shared origin) on every test shape, the closed
// ones (whose ends the first and the last layer close), the forked tube (whose last layer
// folds, and its end loop is peeled all the same) and the knobbed tube (closed at a bottom
// whose layer is not star-shaped), in 3 poses, at 400 and 3000 points, cut by each plan of
// layer fractions.
template <class Check>
void for_every_shape(const std::vector<std::vector<double>>& plans, const Check& check) {
    std::vector<shapes::Kind> kinds = shapes::kinds();
    kinds.push_back({"closed cylinder", [](size_t n, Pose p) { return shapes::closed_cylinder(n, p); }});
    kinds.push_back({"capsule", [](size_t n, Pose p) { return shapes::capsule(n, p); }});
    kinds.push_back({"forked tube", [](size_t n, Pose p) { return shapes::forked_tube(n, p); }});
    kinds.push_back({"knobbed tube", [](size_t n, Pose p) { return shapes::knobbed_tube(n, p); }});
    for (const shapes::Kind& kind : kinds) {
        for (Pose pose : {Pose::z, Pose::x, Pose::tilted}) {
            for (size_t n : {size_t(400), size_t(3000)}) {
                const Shape s = kind.make(n, pose);
                double axis[3];
                s.axis_direction(axis);
                for (size_t plan = 0; plan < plans.size(); ++plan) {
                    INFO(kind.name << " (" << shapes::pose_name(pose) << "), " << n
                                   << " points, plan " << plan);
                    check(layer_cloud(s.xyz, axis, plans[plan]), shared_origin(s));
                }
            }
        }
    }
}

}  // namespace

TEST_CASE("stream: the same triangles as reconstruct() on the same layers, every test shape") {
    // Equal layers; many thin pushes that must merge; uneven pushes with a thin last one.
    const std::vector<std::vector<double>> plans = {
        equal_fractions(6), equal_fractions(40), {0.03, 0.06, 0.85, 0.97}, {}};
    for_every_shape(plans, [](const Layered& l, const Options& o) {
        const Output batch = run_batch(l, o);
        // Room for the whole cloud: the stream's grouping is tested, not its memory.
        const Output stream = run_stream(l, o, l.size());
        check_same(batch, stream);
    });
}

TEST_CASE("stream: with surface_flips, the same triangles as reconstruct() with it") {
    for_every_shape({equal_fractions(6), {0.03, 0.06, 0.85, 0.97}}, [](const Layered& l, Options o) {
        o.flags |= stratmesh::surface_flips;
        check_same(run_batch(l, o), run_stream(l, o, l.size()));
    });
}

// ends_are_cuts reaches both paths: the closed shapes' ends stay open in either.
TEST_CASE("stream: with ends_are_cuts, the same triangles as reconstruct() with it, no end closed") {
    for_every_shape({equal_fractions(6), {0.03, 0.06, 0.85, 0.97}}, [](const Layered& l, Options o) {
        o.flags |= stratmesh::ends_are_cuts;
        const Output batch = run_batch(l, o);
        check_same(batch, run_stream(l, o, l.size()));
        for (size_t k = 0; k < batch.report.layers.used_count && k < batch.layers.size(); ++k)
            CHECK(batch.layers[k].closed_ends == 0);
    });
}

TEST_CASE("stream: pushes of one contour each (CT slices) merge into layers as reconstruct() does") {
    for (Pose pose : {Pose::z, Pose::x}) {
        const Shape s = shapes::ct_slices(2000, pose);
        double axis[3];
        s.axis_direction(axis);
        std::vector<double> fractions;  // a cut between every two planes
        for (size_t k = 1; k < s.planes.size(); ++k) fractions.push_back(static_cast<double>(k) / static_cast<double>(s.planes.size()));
        const Layered l = layer_cloud(s.xyz, axis, fractions);
        REQUIRE(l.cuts.size() == s.planes.size() - 1);
        const Options o = shared_origin(s);
        const Output batch = run_batch(l, o);
        const Output stream = run_stream(l, o, l.size());
        check_same(batch, stream);
    }
}

TEST_CASE("stream: 200,000 points in 100 layers run in a workspace sized for 2.5 layers") {
    const Shape s = shapes::bumpy_tube(200000, Pose::z);
    double axis[3];
    s.axis_direction(axis);
    const Layered l = layer_cloud(s.xyz, axis, equal_fractions(100));
    size_t largest = 0;
    for (size_t k = 0; k + 1 < l.start.size(); ++k) largest = std::max(largest, l.start[k + 1] - l.start[k]);
    const Options o = shared_origin(s);
    const size_t held = largest * 5 / 2;
    const Output stream = run_stream(l, o, held);
    const Output batch = run_batch(l, o);
    check_same(batch, stream);
    CHECK(stream.report.points.held_count <= held);
    CHECK(stream.report.points.held_count > largest);
    const size_t stream_bytes = stratmesh::stream_workspace_size(held, o);
    const size_t batch_bytes = stratmesh::reconstruct_workspace_size(l.size(), o);
    CHECK(stream.report.workspace_used_bytes <= stream_bytes);
    CHECK(stream_bytes * 20 < batch_bytes);
    MESSAGE("largest layer " << largest << " points, held at most " << stream.report.points.held_count
                             << "; stream workspace " << stream_bytes << " B, batch " << batch_bytes << " B");
}

TEST_CASE("stream: the output is a manifold tube through every point") {
    const Shape s = shapes::vase(5000, Pose::tilted);
    double axis[3];
    s.axis_direction(axis);
    const Layered l = layer_cloud(s.xyz, axis, equal_fractions(10));
    Options o = axis_options(s);  // no origin given: the first layer's centroid
    const Output out = run_stream(l, o, l.size());
    REQUIRE(out.status == Status::ok);
    Shape reordered = s;
    reordered.xyz = l.xyz;
    mesh_check::Input in;
    in.points = reordered.xyz.data();
    in.point_count = reordered.size();
    in.triangles = out.triangles.data();
    in.triangle_count = out.triangles.size() / 3;
    reordered.axis_point(in.axis_point);
    reordered.axis_direction(in.axis_direction);
    in.surface = [&reordered](const double* p) { return reordered.deviation(p); };
    in.self_intersections = true;
    const mesh_check::Result r = mesh_check::check(in);
    CHECK(r.bad_indices == 0);
    CHECK(r.nonmanifold_edges == 0);
    CHECK(r.nonmanifold_vertices == 0);
    CHECK(r.inconsistent_edges == 0);
    CHECK(r.components == 1);
    CHECK(r.boundary_loops == 2);
    CHECK(r.euler == 0);
    CHECK(r.vertices_used == s.size());
    CHECK(r.inward == 0);
    CHECK(r.intersecting_pairs == 0);
    CHECK(out.report.points.used_count == s.size());
    CHECK(out.report.layers.used_count == 10);
}

TEST_CASE("stream: malformed pushes are refused with their status and change nothing") {
    const Shape s = shapes::cylinder(2000, Pose::z);
    double axis[3];
    s.axis_direction(axis);
    const Layered l = layer_cloud(s.xyz, axis, equal_fractions(4));
    REQUIRE(l.cuts.size() == 3);
    const Options o = shared_origin(s);
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(l.size(), o));
    std::vector<uint32_t> triangles;
    Report report{};
    stratmesh::Stream* stream = nullptr;
    REQUIRE(stratmesh::stream_open(o, work.data(), work.size(), collect, &triangles, &report,
                                   &stream) == Status::ok);
    auto layer = [&l](size_t k) {
        return Cloud{l.xyz.data() + 3 * l.start[k], l.start[k + 1] - l.start[k], 0, Scalar::float64};
    };
    const Cloud none = {nullptr, 0, 0, Scalar::float64};
    // Each refusal says why in the report, in its own words: not those of the refusal before
    // when its status differs.
    Status last_status = Status::ok;
    const char* last_detail = nullptr;
    auto refused = [&](const Cloud& c, double top, Status expected) {
        const size_t in = report.points.in_count, emitted = triangles.size();
        CHECK(stratmesh::stream_push(stream, c, top) == expected);
        CHECK(report.points.in_count == in);
        CHECK(triangles.size() == emitted);
        CHECK(report.detail != nullptr);
        if (expected != last_status) CHECK(report.detail != last_detail);
        last_status = expected;
        last_detail = report.detail;
    };
    // Before the first point a push without points has a top all the same: what follows
    // keeps to it (layer 0 lies below the first cut).
    REQUIRE(stratmesh::stream_push(stream, none, l.cuts[0]) == Status::ok);
    refused(none, l.cuts[0] - 1, Status::out_of_order);
    refused(layer(0), l.cuts[0], Status::out_of_order);
    REQUIRE(stratmesh::stream_push(stream, layer(1), l.cuts[1]) == Status::ok);
    refused(layer(0), l.cuts[1], Status::out_of_order);     // below the previous top
    refused(layer(2), l.cuts[0], Status::out_of_order);     // a top below the previous one
    refused(layer(3), l.cuts[2], Status::out_of_order);     // above its own top
    refused(layer(2), std::nan(""), Status::invalid_layers);
    const Cloud third = layer(2);
    refused(Cloud{third.xyz, third.count, 2 * sizeof(double), Scalar::float64}, l.cuts[2],
            Status::invalid_argument);  // a stride smaller than one point
    refused(layer(2), std::numeric_limits<double>::infinity(), Status::invalid_layers);
    refused(Cloud{third.xyz, third.count, 0, static_cast<Scalar>(7)}, l.cuts[2],
            Status::invalid_argument);  // an unknown scalar type
    refused(Cloud{nullptr, 5, 0, Scalar::float64}, l.cuts[2], Status::invalid_argument);
    refused(Cloud{work.data() + 64, 10, 0, Scalar::float32}, l.cuts[2],
            Status::invalid_argument);  // points in the stream's workspace
    std::vector<double> with_nan(l.xyz.begin() + 3 * static_cast<std::ptrdiff_t>(l.start[2]),
                                 l.xyz.begin() + 3 * static_cast<std::ptrdiff_t>(l.start[3]));
    with_nan[3 * 5 + 1] = std::nan("");
    const size_t before = report.points.in_count;
    refused(Cloud{with_nan.data(), with_nan.size() / 3, 0, Scalar::float64}, l.cuts[2],
            Status::invalid_point);
    CHECK(report.points.first_invalid_index == before + 5);
    REQUIRE(stratmesh::stream_push(stream, layer(2), l.cuts[2]) == Status::ok);
    REQUIRE(stratmesh::stream_push(stream, layer(3), l.top) == Status::ok);
    REQUIRE(stratmesh::stream_close(stream) == Status::ok);
    const size_t accepted = l.size() - (l.start[1] - l.start[0]);
    CHECK(report.points.in_count == accepted);
    CHECK(report.points.used_count == accepted);
    // The accepted points' global indices: layers 1 to 3 in push order.
    REQUIRE(!triangles.empty());
    CHECK(*std::max_element(triangles.begin(), triangles.end()) < accepted);
}

TEST_CASE("stream: a NaN origin, or one beyond 2^32 times the first layer's size, is invalid_origin") {
    const Shape s = shapes::cylinder(2000, Pose::z);
    double axis[3];
    s.axis_direction(axis);
    const Layered l = layer_cloud(s.xyz, axis, equal_fractions(2));
    Options o = shared_origin(s);
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(l.size(), o));
    std::vector<uint32_t> triangles;
    stratmesh::Stream* stream = nullptr;
    o.origin[0] = std::nan("");
    CHECK(stratmesh::stream_open(o, work.data(), work.size(), collect, &triangles, nullptr, &stream) ==
          Status::invalid_origin);
    o.origin[0] = 1e13;  // the cylinder is a few units across
    Report report{};
    REQUIRE(stratmesh::stream_open(o, work.data(), work.size(), collect, &triangles, &report, &stream) ==
            Status::ok);
    const Cloud first = {l.xyz.data(), l.start[1], 0, Scalar::float64};
    CHECK(stratmesh::stream_push(stream, first, l.cuts[0]) == Status::invalid_origin);
    CHECK(report.points.in_count == 0);
    REQUIRE(report.detail != nullptr);
    CHECK(std::string(report.detail).find("2^32") != std::string::npos);
    o.origin[0] = 1e6;
    REQUIRE(stratmesh::stream_open(o, work.data(), work.size(), collect, &triangles, &report, &stream) ==
            Status::ok);
    CHECK(stratmesh::stream_push(stream, first, l.cuts[0]) == Status::ok);
}

#if !defined(STRATMESH_SMALL_CODE)  // cap_ends() is left out there (see the header's Config)
namespace {

struct Capped {
    Status status = Status::internal_error;
    std::vector<uint32_t> triangles;
    Report report{};
    size_t count = 0;
};

// cap_ends() on `surface` over the layered cloud's points, with room for 2n triangles.
Capped cap_surface(const Layered& l, const Options& o, const std::vector<uint32_t>& surface) {
    Capped out;
    const Cloud cloud = {l.xyz.data(), l.size(), 0, Scalar::float64};
    out.triangles = surface;
    out.triangles.resize(3 * stratmesh::reconstruct_max_triangles(cloud.count, o));
    std::vector<unsigned char> work(stratmesh::cap_ends_workspace_size(cloud.count, surface.size() / 3));
    out.count = surface.size() / 3;
    out.status = stratmesh::cap_ends(cloud, o, work.data(), work.size(), out.triangles.data(),
                                     out.triangles.size() / 3, &out.count, &out.report);
    if (out.status == Status::ok) out.triangles.resize(3 * out.count);
    CHECK(out.report.workspace_used_bytes <= work.size());
    return out;
}

}  // namespace

TEST_CASE("cap_ends: the stream's surface capped is reconstruct()'s with add_caps, triangle for triangle") {
    const std::vector<std::vector<double>> plans = {equal_fractions(6), {0.03, 0.06, 0.85, 0.97}, {}};
    size_t compared = 0, closed = 0;
    for_every_shape(plans, [&](const Layered& l, const Options& o) {
        Options closing = o;
        closing.flags |= stratmesh::add_caps;
        const Output batch = run_batch(l, closing);
        const Output stream = run_stream(l, o, l.size());
        REQUIRE(stream.status == batch.status);
        if (batch.status != Status::ok) return;
        const Capped capped = cap_surface(l, o, stream.triangles);
        REQUIRE(capped.status == Status::ok);
        CHECK(capped.triangles == batch.triangles);
        CHECK(capped.report.caps.closed_count == batch.report.caps.closed_count);
        CHECK(capped.report.caps.open_count == batch.report.caps.open_count);
        CHECK(capped.report.caps.triangle_count == batch.report.caps.triangle_count);
        CHECK(capped.report.caps.wall_flip_count == batch.report.caps.wall_flip_count);
        // Only the cap fields are set: the stream's counts stay.
        CHECK(capped.report.points.in_count == 0);
        ++compared;
        closed += batch.report.caps.closed_count;
    });
    // The comparison means something only if most runs had caps to make (measured: 162
    // runs, 318 caps).
    CHECK(compared >= 150);
    CHECK(closed >= 3 * compared / 2);
}

TEST_CASE("cap_ends: the capped stream output is a closed manifold through every point") {
    const Shape s = shapes::vase(5000, Pose::tilted);
    double axis[3];
    s.axis_direction(axis);
    const Layered l = layer_cloud(s.xyz, axis, equal_fractions(10));
    const Options o = axis_options(s);
    const Output out = run_stream(l, o, l.size());
    REQUIRE(out.status == Status::ok);
    const Capped capped = cap_surface(l, o, out.triangles);
    REQUIRE(capped.status == Status::ok);
    CHECK(capped.report.caps.closed_count == 2);
    CHECK(capped.report.caps.open_count == 0);
    CHECK(capped.count == out.triangles.size() / 3 + capped.report.caps.triangle_count);
    // The surface comes first, unchanged.
    CHECK(std::equal(out.triangles.begin(), out.triangles.end(), capped.triangles.begin()));
    Shape reordered = s;
    reordered.xyz = l.xyz;
    mesh_check::Input in;
    in.points = reordered.xyz.data();
    in.point_count = reordered.size();
    in.triangles = capped.triangles.data();
    in.triangle_count = capped.count;
    reordered.axis_point(in.axis_point);
    reordered.axis_direction(in.axis_direction);
    in.self_intersections = true;
    const mesh_check::Result r = mesh_check::check(in);
    INFO(r.summary());
    CHECK(r.bad_indices == 0);
    CHECK(r.nonmanifold_edges == 0);
    CHECK(r.nonmanifold_vertices == 0);
    CHECK(r.inconsistent_edges == 0);
    CHECK(r.components == 1);
    CHECK(r.boundary_loops == 0);
    CHECK(r.euler == 2);
    CHECK(r.vertices_used == s.size());
    CHECK(r.intersecting_pairs == 0);
}

// An open tube of `around` x 4 quads about the z axis; under every `fin_step`-th bottom
// edge a fin: a point below and outside it, with one triangle on that edge. The bottom
// loop then runs through the fins, whose corners poke outwards across the axis: their
// neighbours are reflex, and each fin's ear would join its edge's ends, an edge of the
// wall, so a cap must join each fin to a corner it sees across the loop.
struct FinnedTube {
    std::vector<double> xyz;
    std::vector<uint32_t> wall, capped;  // capped: cap_ends()'s triangles
    size_t count = 0;
    Report report = {};
    Status status = Status::ok;
    std::vector<uint32_t> fins;  // the fins' points
};

FinnedTube cap_finned_tube(uint32_t around, uint32_t fin_step) {
    const uint32_t rows = 4;
    const double pi = 3.14159265358979323846;
    FinnedTube f;
    auto add_point = [&](double r, double angle, double z) {
        f.xyz.push_back(r * std::cos(angle));
        f.xyz.push_back(r * std::sin(angle));
        f.xyz.push_back(z);
        return static_cast<uint32_t>(f.xyz.size() / 3 - 1);
    };
    for (uint32_t row = 0; row < rows; ++row)
        for (uint32_t k = 0; k < around; ++k) add_point(1.0, 2 * pi * k / around, row);
    auto ring = [&](uint32_t row, uint32_t k) { return row * around + k % around; };
    for (uint32_t row = 0; row + 1 < rows; ++row)
        for (uint32_t k = 0; k < around; ++k) {
            const uint32_t a = ring(row, k), b = ring(row, k + 1), c = ring(row + 1, k + 1),
                           d = ring(row + 1, k);
            f.wall.insert(f.wall.end(), {a, b, c, a, c, d});
        }
    for (uint32_t k = 0; k < around; k += fin_step) {
        const uint32_t fin = add_point(1.08, 2 * pi * (k + 0.5) / around, -0.2);
        f.wall.insert(f.wall.end(), {ring(0, k + 1), ring(0, k), fin});
        f.fins.push_back(fin);
    }
    const size_t n = f.xyz.size() / 3, surface = f.wall.size() / 3;
    const Cloud cloud = {f.xyz.data(), n, 0, Scalar::float64};
    Options o = {};
    o.axis = stratmesh::Axis::z;
    f.capped = f.wall;
    f.capped.resize(3 * stratmesh::reconstruct_max_triangles(n, o));
    std::vector<unsigned char> work(stratmesh::cap_ends_workspace_size(n, surface));
    f.count = surface;
    f.status = stratmesh::cap_ends(cloud, o, work.data(), work.size(), f.capped.data(),
                                   f.capped.size() / 3, &f.count, &f.report);
    CHECK(f.report.workspace_used_bytes <= work.size());
    return f;
}

// A closed, consistently oriented manifold through every point.
void check_closed(const FinnedTube& f) {
    mesh_check::Input in;
    in.points = f.xyz.data();
    in.point_count = f.xyz.size() / 3;
    in.triangles = f.capped.data();
    in.triangle_count = f.count;
    in.self_intersections = false;
    const mesh_check::Result r = mesh_check::check(in);
    INFO(r.summary());
    CHECK(r.nonmanifold_edges == 0);
    CHECK(r.nonmanifold_vertices == 0);
    CHECK(r.inconsistent_edges == 0);
    CHECK(r.boundary_loops == 0);
    CHECK(r.components == 1);
    CHECK(r.euler == 2);
    CHECK(r.vertices_used == in.point_count);
}

TEST_CASE("cap_ends: a loop whose every ear would repeat an edge of the wall (fins) is still capped") {
    // A fin under every sixth edge: ear clipping is stuck from each of its starting
    // corners (it left this loop open); the search finds a cap, the wall as it was.
    const FinnedTube f = cap_finned_tube(24, 6);
    REQUIRE(f.status == Status::ok);
    CHECK(f.report.caps.open_count == 0);
    CHECK(f.report.caps.closed_count == 2);
    CHECK(f.report.caps.wall_flip_count == 0);
    CHECK(std::equal(f.wall.begin(), f.wall.end(), f.capped.begin()));
    check_closed(f);
}

TEST_CASE("cap_ends: where fins leave no cap, the wall's edges under them are flipped") {
    // A fin under every other edge: the fins' diagonals across the loop would cross, so no
    // cap over the loop's corners avoids the wall's edges (the search left it open). The
    // edge under a fin is flipped where the cap needs its chord.
    const FinnedTube f = cap_finned_tube(24, 2);
    REQUIRE(f.status == Status::ok);
    CHECK(f.report.caps.open_count == 0);
    CHECK(f.report.caps.closed_count == 2);
    check_closed(f);
    // The wall keeps its count and its boundary; what changed are pairs of triangles, each
    // a fin's and the one beyond its chord, now both at the fin's point.
    const size_t surface = f.wall.size() / 3;
    auto sorted_triangles = [](const uint32_t* t, size_t count) {
        std::vector<std::array<uint32_t, 3>> out(count);
        for (size_t i = 0; i < count; ++i) {
            std::array<uint32_t, 3> c = {t[3 * i], t[3 * i + 1], t[3 * i + 2]};
            std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
            out[i] = c;
        }
        std::sort(out.begin(), out.end());
        return out;
    };
    const auto before = sorted_triangles(f.wall.data(), surface);
    const auto after = sorted_triangles(f.capped.data(), surface);
    std::vector<std::array<uint32_t, 3>> gone, made;
    std::set_difference(before.begin(), before.end(), after.begin(), after.end(), std::back_inserter(gone));
    std::set_difference(after.begin(), after.end(), before.begin(), before.end(), std::back_inserter(made));
    CHECK(!made.empty());
    CHECK(made.size() == gone.size());
    CHECK(made.size() % 2 == 0);
    CHECK(f.report.caps.wall_flip_count == made.size() / 2);
    auto has_fin = [&f](const std::array<uint32_t, 3>& t) {
        return std::any_of(t.begin(), t.end(), [&f](uint32_t v) {
            return std::find(f.fins.begin(), f.fins.end(), v) != f.fins.end();
        });
    };
    CHECK(std::all_of(made.begin(), made.end(), has_fin));
    size_t fins_gone = 0;
    for (const auto& t : gone) fins_gone += has_fin(t);
    CHECK(fins_gone == gone.size() / 2);
    auto boundary = [](const uint32_t* t, size_t count) {
        std::set<std::pair<uint32_t, uint32_t>> edges, open;
        for (size_t i = 0; i < count; ++i)
            for (size_t k = 0; k < 3; ++k) edges.insert({t[3 * i + k], t[3 * i + (k + 1) % 3]});
        for (const auto& e : edges)
            if (!edges.count({e.second, e.first})) open.insert(e);
        return open;
    };
    CHECK(boundary(f.wall.data(), surface) == boundary(f.capped.data(), surface));
}

TEST_CASE("cap_ends: bad arguments get their status and leave the triangles as they were") {
    const Shape s = shapes::cylinder(600, Pose::z);
    double axis[3];
    s.axis_direction(axis);
    const Layered l = layer_cloud(s.xyz, axis, equal_fractions(3));
    const Options o = axis_options(s);
    const Output out = run_stream(l, o, l.size());
    REQUIRE(out.status == Status::ok);
    const size_t n = l.size(), surface = out.triangles.size() / 3;
    const Cloud cloud = {l.xyz.data(), n, 0, Scalar::float64};
    std::vector<unsigned char> work(stratmesh::cap_ends_workspace_size(n, surface));
    REQUIRE(!work.empty());
    // Runs cap_ends on a copy of the surface with `capacity` triangles of room; checks that
    // a refusal changed no triangle.
    auto attempt = [&](const Cloud& c, const std::vector<uint32_t>& tris, size_t capacity,
                       size_t given, size_t work_bytes, size_t* count_out, size_t* used = nullptr) {
        std::vector<uint32_t> room = tris;
        room.resize(3 * std::max(capacity, tris.size() / 3), 0xABABABABu);
        const std::vector<uint32_t> before = room;
        size_t count = given;
        Report report{};
        report.points.in_count = 77;
        const Status status = stratmesh::cap_ends(c, o, work.data(), work_bytes, room.data(),
                                                  capacity, &count, &report);
        if (status != Status::ok) CHECK(room == before);
        CHECK(report.points.in_count == 77);
        if (status != Status::ok && status != Status::triangle_capacity) CHECK(count == given);
        CHECK((status == Status::ok) == (report.detail == nullptr));
        if (count_out) *count_out = count;
        if (used) *used = report.workspace_used_bytes;
        return status;
    };
    size_t count = 0, used = 0;
    REQUIRE(attempt(cloud, out.triangles, 2 * n, surface, work.size(), &count, &used) == Status::ok);
    CHECK(used <= work.size());
    const size_t closed = count;
    CHECK(closed > surface);
    SUBCASE("too little room for the caps: triangle_capacity and the count needed") {
        CHECK(attempt(cloud, out.triangles, closed - 1, surface, work.size(), &count) ==
              Status::triangle_capacity);
        CHECK(count == closed);
    }
    SUBCASE("a workspace below what the call used: out_of_memory") {
        for (size_t bytes : {size_t(0), size_t(64), used / 2, used - 1})
            CHECK(attempt(cloud, out.triangles, 2 * n, surface, bytes, nullptr) == Status::out_of_memory);
    }
    SUBCASE("an index outside the cloud, or more triangles than the capacity: invalid_argument") {
        std::vector<uint32_t> wrong = out.triangles;
        wrong[7] = static_cast<uint32_t>(n);
        CHECK(attempt(cloud, wrong, 2 * n, surface, work.size(), nullptr) == Status::invalid_argument);
        CHECK(attempt(cloud, out.triangles, surface - 1, surface, work.size(), nullptr) ==
              Status::invalid_argument);
        CHECK(stratmesh::cap_ends(cloud, o, work.data(), work.size(), nullptr, 0, nullptr, nullptr) ==
              Status::invalid_argument);
    }
    SUBCASE("buffers that share bytes: invalid_argument") {
        std::vector<uint32_t> room = out.triangles;
        room.resize(6 * n);
        size_t given = surface;
        CHECK(stratmesh::cap_ends(cloud, o, room.data() + 3 * surface, 4 * (3 * n - 3 * surface),
                                  room.data(), 2 * n, &given, nullptr) == Status::invalid_argument);
        CHECK(given == surface);
    }
    SUBCASE("a NaN point: invalid_point, unless skipped; a triangle naming it: invalid_argument") {
        Layered with_nan = l;
        with_nan.xyz[3 * 5] = std::nan("");
        const Cloud nan_cloud = {with_nan.xyz.data(), n, 0, Scalar::float64};
        CHECK(attempt(nan_cloud, out.triangles, 2 * n, surface, work.size(), nullptr) ==
              Status::invalid_point);
        Options skipping = o;
        skipping.flags |= stratmesh::skip_invalid_points;
        std::vector<uint32_t> room = out.triangles;
        room.resize(6 * n);
        size_t given = surface;
        CHECK(stratmesh::cap_ends(nan_cloud, skipping, work.data(), work.size(), room.data(), 2 * n,
                                  &given, nullptr) == Status::invalid_argument);
        CHECK(given == surface);
    }
}

TEST_CASE("cap_ends: any triangle soup over the cloud stays within the buffers") {
    const Shape s = shapes::bumpy_tube(300, Pose::tilted);
    const Options o = axis_options(s);
    const Cloud cloud = {s.xyz.data(), s.size(), 0, Scalar::float64};
    shapes::Rng rng(11);
    for (size_t trial = 0; trial < 200; ++trial) {
        const size_t soup = 1 + trial % 40;
        const uint32_t spread = 4 + static_cast<uint32_t>(trial % 9) * 37;  // few or many distinct indices
        std::vector<uint32_t> room(3 * 2 * s.size() + 3, 0xCDCDCDCDu);
        for (size_t k = 0; k < 3 * soup; ++k)
            room[k] = static_cast<uint32_t>(rng.uniform(0, spread)) % static_cast<uint32_t>(s.size());
        const std::vector<uint32_t> before = room;
        std::vector<unsigned char> work(stratmesh::cap_ends_workspace_size(s.size(), soup));
        size_t count = soup;
        Report report{};
        const Status status = stratmesh::cap_ends(cloud, o, work.data(), work.size(), room.data(),
                                                  2 * s.size(), &count, &report);
        INFO("trial " << trial);
        REQUIRE(status == Status::ok);
        CHECK(count == soup + report.caps.triangle_count);
        CHECK(std::equal(before.begin(), before.begin() + 3 * static_cast<std::ptrdiff_t>(soup), room.begin()));
        CHECK(room.back() == 0xCDCDCDCDu);  // nothing past the capacity
        for (size_t k = 3 * soup; k < 3 * count; ++k) CHECK(room[k] < s.size());
        CHECK(report.workspace_used_bytes <= work.size());
    }
}
#endif
