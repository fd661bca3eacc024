// Webs (Report::diagnostics): where one tube wraps limbs, the triangles that span the gaps
// between them are counted, their area and where they lie; single columns and caps show
// none. Every count is checked against a plain recomputation from the triangles (edge
// lists sorted by vertex), and the report against runs with a job runner and at other
// magnitudes.
#include "stratmesh.h"
#include "support/reconstructed.h"
#include "support/shapes.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <thread>
#include <utility>
#include <vector>

namespace {

using stratmesh::Cloud;
using stratmesh::Diagnostics;
using stratmesh::Options;
using stratmesh::Report;
using stratmesh::Scalar;
using stratmesh::Status;
using shapes::Pose;
using shapes::Shape;

// Single columns stay under this share of their area as web (the command-line tool warns
// from here); objects with limbs meshed as one tube stay above three times as much.
const double kNoWeb = 0.005;
const double kWebbed = 3 * kNoWeb;

using reconstructed::cloud_of;
using reconstructed::Mesh;
using reconstructed::mesh;

// ---- the measure, recomputed plainly ------------------------------------------------------

struct Webs {
    size_t count = 0;
    double area = 0, total = 0;  // of the web triangles, of all measured
    double low[3] = {0, 0, 0}, high[3] = {0, 0, 0};
};

// The definition in Diagnostics, in the straightforward way: each triangle's edges a -> b,
// b -> c, c -> a give the vertex they leave a length (double, rounded to float); the pairs
// are sorted, each vertex's spacing is the lower median of its lengths, and a triangle
// whose longest edge exceeds kWebSpacings times its corners' largest spacing is web. The
// last `caps` triangles are left out. `point` gives a point's coordinates as doubles.
Webs recompute(const std::function<void(uint32_t, double[3])>& point,
               const std::vector<uint32_t>& tri, size_t caps) {
    const size_t count = tri.size() / 3 - caps;
    auto length = [&](uint32_t a, uint32_t b) {
        double p[3], q[3];
        point(a, p);
        point(b, q);
        const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        return static_cast<float>(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    };
    std::vector<std::pair<uint32_t, float>> edges;
    for (size_t t = 0; t < count; ++t)
        for (size_t j = 0; j < 3; ++j)
            edges.emplace_back(tri[3 * t + j], length(tri[3 * t + j], tri[3 * t + (j + 1) % 3]));
    std::sort(edges.begin(), edges.end());
    std::vector<std::pair<uint32_t, float>> spacing;  // (vertex, lower median), by vertex
    for (size_t first = 0, end; first < edges.size(); first = end) {
        for (end = first; end < edges.size() && edges[end].first == edges[first].first;) ++end;
        spacing.emplace_back(edges[first].first, edges[first + (end - first - 1) / 2].second);
    }
    auto spacing_of = [&](uint32_t v) {
        return std::lower_bound(spacing.begin(), spacing.end(), std::make_pair(v, -1.0f))->second;
    };
    Webs w;
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* c = &tri[3 * t];
        double p[3][3];
        for (size_t j = 0; j < 3; ++j) point(c[j], p[j]);
        double u[3], v[3];
        for (int k = 0; k < 3; ++k) {
            u[k] = p[1][k] - p[0][k];
            v[k] = p[2][k] - p[1][k];
        }
        const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                             u[0] * v[1] - u[1] * v[0]};
        const double area = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 2;
        w.total += area;
        const float longest = std::max({length(c[0], c[1]), length(c[1], c[2]), length(c[2], c[0])});
        const float largest = std::max({spacing_of(c[0]), spacing_of(c[1]), spacing_of(c[2])});
        if (!(static_cast<double>(longest) > stratmesh::kWebSpacings * static_cast<double>(largest)))
            continue;
        for (int k = 0; k < 3; ++k) {
            const double lo = std::min({p[0][k], p[1][k], p[2][k]});
            const double hi = std::max({p[0][k], p[1][k], p[2][k]});
            w.low[k] = w.count == 0 ? lo : std::min(w.low[k], lo);
            w.high[k] = w.count == 0 ? hi : std::max(w.high[k], hi);
        }
        ++w.count;
        w.area += area;
    }
    return w;
}

Webs recompute(const std::vector<double>& xyz, const std::vector<uint32_t>& tri, size_t caps) {
    return recompute([&](uint32_t i, double p[3]) { std::memcpy(p, &xyz[3 * i], 3 * sizeof(double)); },
                     tri, caps);
}

// The report's web fields against the recomputation: the same triangles, box and areas.
void check_report(const Diagnostics& d, const Webs& w) {
    CHECK(d.web_triangle_count == w.count);
    CHECK(d.web_area == doctest::Approx(w.area).epsilon(1e-12));
    CHECK(d.web_area_fraction ==
          doctest::Approx(w.total > 0 ? w.area / w.total : 0).epsilon(1e-12));
    for (int k = 0; k < 3; ++k) {
        CHECK(d.web_box_min[k] == w.low[k]);
        CHECK(d.web_box_max[k] == w.high[k]);
    }
}

// Runners: in reverse order, and on two threads taking indices from a counter.
void run_in_reverse(void*, uint32_t count, stratmesh::JobFunction job, void* context) {
    for (uint32_t i = count; i-- > 0;) job(context, i);
}

void run_on_two_threads(void*, uint32_t count, stratmesh::JobFunction job, void* context) {
    std::atomic<uint32_t> next{0};
    auto work = [&]() {
        for (uint32_t i = next++; i < count; i = next++) job(context, i);
    };
    std::thread other(work);
    work();
    other.join();
}

// The shape's local frame: Pose::z only translates.
void local_of(const Shape& s, const double world[3], double local[3]) {
    s.transform.unapply(world, local);
}

}  // namespace

TEST_CASE("webs: objects with limbs meshed by default show the gaps between their limbs") {
    const std::vector<Shape> limbed = {
        shapes::four_legged(10000, Pose::z), shapes::y_of_tubes(10000, Pose::z),
        shapes::hand(5000, Pose::z), shapes::branched_trunk(5000, Pose::z),
        shapes::twice_forked(5000, Pose::z)};
    for (const Shape& s : limbed) {
        INFO(s.name << ", " << s.size() << " points");
        const Mesh m = mesh(s.xyz, Options{});
        REQUIRE(m.status == Status::ok);
        const Diagnostics& d = m.report.diagnostics;
        CHECK(d.web_area_fraction > kWebbed);
        CHECK(d.web_triangle_count > 10);
        CHECK(m.report.workspace_used_bytes <= m.bound);
        check_report(d, recompute(s.xyz, m.triangles, m.report.caps.triangle_count));
        // The box holds web triangles' corners: points of the cloud.
        for (int k = 0; k < 3; ++k) CHECK(d.web_box_min[k] < d.web_box_max[k]);
    }
    // The body is a tube along x at z in [-1, 1], its legs under it down to z = -3.77:
    // the web spans the gaps between the legs, below the body's axis and down to the feet.
    const Shape& body = limbed[0];
    const Mesh m = mesh(body.xyz, Options{});
    double low[3], high[3];
    local_of(body, m.report.diagnostics.web_box_min, low);
    local_of(body, m.report.diagnostics.web_box_max, high);
    CHECK(high[2] < 0);
    CHECK(low[2] < -3);
}

TEST_CASE("webs: single columns show none, with or without caps, whatever the pose") {
    for (const shapes::Kind& kind : shapes::kinds())
        for (Pose pose : {Pose::z, Pose::tilted}) {
            const Shape s = kind.make(2000, pose);
            for (uint32_t flags : {0u, uint32_t(stratmesh::add_caps)}) {
                INFO(s.name << (flags ? ", add_caps" : ""));
                Options o = {};
                o.flags = flags;
                const Mesh m = mesh(s.xyz, o);
                REQUIRE(m.status == Status::ok);
                CHECK(m.report.diagnostics.web_area_fraction < kNoWeb);
                check_report(m.report.diagnostics,
                             recompute(s.xyz, m.triangles, m.report.caps.triangle_count));
            }
        }
    for (const Shape& s : {shapes::closed_cylinder(20000, Pose::z), shapes::capsule(20000, Pose::x),
                           shapes::noisy_tube(20000, Pose::z)}) {
        INFO(s.name);
        const Mesh m = mesh(s.xyz, Options{});
        REQUIRE(m.status == Status::ok);
        CHECK(m.report.diagnostics.web_area_fraction < kNoWeb);
    }
}

TEST_CASE("webs: caps are left out, and would count as web if they were not") {
    // A CT stack capped: each cap spans a slice's contour, points far closer together
    // along it than across the whole slice.
    const Shape ct = shapes::ct_slices(20000, Pose::z);
    Options o = {};
    o.axis = stratmesh::Axis::z;
    o.flags = stratmesh::add_caps;
    const Mesh capped = mesh(ct.xyz, o);
    REQUIRE(capped.status == Status::ok);
    REQUIRE(capped.report.caps.closed_count == 2);
    CHECK(capped.report.diagnostics.web_triangle_count == 0);
    check_report(capped.report.diagnostics,
                 recompute(ct.xyz, capped.triangles, capped.report.caps.triangle_count));
    CHECK(recompute(ct.xyz, capped.triangles, 0).count > 10);  // the caps, counted
    // The walls are measured as without caps (no wall edge was flipped under a fin).
    o.flags = 0;
    const Mesh open = mesh(ct.xyz, o);
    REQUIRE(capped.report.caps.wall_flip_count == 0);
    CHECK(std::memcmp(&open.report.diagnostics, &capped.report.diagnostics,
                      sizeof(Diagnostics)) == 0);
}

TEST_CASE("webs: the count is the plain recomputation's on float records with a stride and far from the origin") {
    const Shape fork = shapes::twice_forked(5000, Pose::tilted);
    // x, y, z as floats at the start of 7-float records, 1e5 away from the origin.
    std::vector<float> records(7 * fork.size(), -1.0f);
    for (size_t i = 0; i < fork.size(); ++i)
        for (size_t k = 0; k < 3; ++k)
            records[7 * i + k] = static_cast<float>(fork.xyz[3 * i + k] + 1e5);
    const Cloud cloud = {records.data(), fork.size(), 7 * sizeof(float), Scalar::float32};
    const Mesh m = mesh(cloud, Options{});
    REQUIRE(m.status == Status::ok);
    const Webs w = recompute(
        [&](uint32_t i, double p[3]) {
            for (size_t k = 0; k < 3; ++k) p[k] = static_cast<double>(records[7 * i + k]);
        },
        m.triangles, m.report.caps.triangle_count);
    CHECK(w.count > 0);
    check_report(m.report.diagnostics, w);
}

TEST_CASE("webs: the same report with a job runner, and at every magnitude") {
    const Shape fork = shapes::twice_forked(5000, Pose::z);
    const Mesh plain = mesh(fork.xyz, Options{});
    REQUIRE(plain.status == Status::ok);
    REQUIRE(plain.report.diagnostics.web_triangle_count > 0);
    for (stratmesh::JobRunner runner : {run_in_reverse, run_on_two_threads}) {
        Options o = {};
        o.run_jobs = runner;
        const Mesh jobs = mesh(fork.xyz, o);
        REQUIRE(jobs.status == Status::ok);
        CHECK(jobs.report.layers.parallel_count > 0);
        CHECK(jobs.triangles == plain.triangles);
        CHECK(std::memcmp(&jobs.report.diagnostics, &plain.report.diagnostics,
                          sizeof(Diagnostics)) == 0);
        CHECK(jobs.report.workspace_used_bytes <= jobs.bound);
    }
    // Scaled by a power of two: the same triangles, count and share; areas and box scaled.
    // (Along a given axis and as one tube: the same triangles at every magnitude.)
    Options along = {};
    along.axis = stratmesh::Axis::z;
    along.parts = stratmesh::Parts::one_tube;
    const Mesh unit = mesh(fork.xyz, along);
    REQUIRE(unit.status == Status::ok);
    REQUIRE(unit.report.diagnostics.web_triangle_count > 0);
    for (int exponent : {-300, 300}) {
        INFO("scaled by 2^" << exponent);
        const double scale = std::ldexp(1.0, exponent);
        std::vector<double> xyz = fork.xyz;
        for (double& v : xyz) v *= scale;
        const Mesh scaled = mesh(xyz, along);
        const Mesh& plain_one = unit;
        REQUIRE(scaled.status == Status::ok);
        CHECK(scaled.triangles == plain_one.triangles);
        const Diagnostics &d = scaled.report.diagnostics, &p = plain_one.report.diagnostics;
        CHECK(d.web_triangle_count == p.web_triangle_count);
        CHECK(d.web_area_fraction == p.web_area_fraction);
        CHECK(d.web_area == p.web_area * scale * scale);
        for (int k = 0; k < 3; ++k) CHECK(d.web_box_max[k] == p.web_box_max[k] * scale);
    }
}

TEST_CASE("webs: the stream does not measure them, reconstruct() of the same tube does") {
    // One push: one layer, the tube reconstruct() gives with Parts::one_tube and a single layer.
    const Shape fork = shapes::y_of_tubes(3000, Pose::z);
    Options o = {};
    o.axis = stratmesh::Axis::z;
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(fork.size(), o));
    std::vector<uint32_t> triangles;
    Report report = {};
    stratmesh::Stream* stream = nullptr;
    auto collect = [](void* user, const uint32_t* t, size_t count) {
        auto& out = *static_cast<std::vector<uint32_t>*>(user);
        out.insert(out.end(), t, t + 3 * count);
    };
    REQUIRE(stratmesh::stream_open(o, work.data(), work.size(), collect, &triangles, &report,
                                   &stream) == Status::ok);
    double top = -1e300;
    for (size_t i = 0; i < fork.size(); ++i) top = std::max(top, fork.xyz[3 * i + 2]);
    REQUIRE(stratmesh::stream_push(stream, cloud_of(fork.xyz), top) == Status::ok);
    REQUIRE(stratmesh::stream_close(stream) == Status::ok);
    const Diagnostics none = {};
    CHECK(std::memcmp(&report.diagnostics.web_triangle_count, &none.web_triangle_count,
                      sizeof(Diagnostics) - offsetof(Diagnostics, web_triangle_count)) == 0);
    CHECK(recompute(fork.xyz, triangles, 0).count > 0);
    o.parts = stratmesh::Parts::one_tube;
    o.layer_count = 1;
    const Mesh batch = mesh(fork.xyz, o);
    REQUIRE(batch.status == Status::ok);
    CHECK(batch.triangles == triangles);
    CHECK(batch.report.diagnostics.web_triangle_count > 0);
}
