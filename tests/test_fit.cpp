// The fit measure (Report::diagnostics): single columns follow their cloud, objects with
// limbs meshed as one tube do not; the crossing pairs and the misfit share are checked
// against plain recomputations (every pair of triangles; every point's distance), and the
// report against runs with a job runner, at other magnitudes and from the stream.
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
#include <thread>
#include <vector>

namespace {

using stratmesh::Diagnostics;
using stratmesh::Options;
using stratmesh::Report;
using stratmesh::Status;
using shapes::Pose;
using shapes::Shape;
using reconstructed::cloud_of;
using reconstructed::Mesh;
using reconstructed::mesh;

struct P {
    double x, y, z;
};
P operator-(P a, P b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
P cross(P a, P b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot(P a, P b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
P point(const std::vector<double>& xyz, uint32_t i) { return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}; }

double length(P v) { return std::sqrt(dot(v, v)); }

// Where segment pq meets the plane of abc, strictly between p and q, and whether that point
// lies strictly inside abc (barycentric coordinates from areas); p and q within rounding of
// the plane (a relative 1e-12, as the library takes it) do not pierce it.
bool pierces(P p, P q, P a, P b, P c) {
    const P n = cross(b - a, c - a);
    const double dp = dot(n, p - a), dq = dot(n, q - a);
    const double flat = 1e-12 * length(b - a) * length(c - a);
    if (!((dp > flat * length(p - a) && dq < -flat * length(q - a)) ||
          (dp < -flat * length(p - a) && dq > flat * length(q - a))))
        return false;
    const double t = dp / (dp - dq);
    const P x = {p.x + t * (q.x - p.x), p.y + t * (q.y - p.y), p.z + t * (q.z - p.z)};
    const double u = dot(cross(b - x, c - x), n), v = dot(cross(c - x, a - x), n),
                 w = dot(cross(a - x, b - x), n);
    return u > 0 && v > 0 && w > 0;
}

// Every pair of triangles sharing no corner, one's edge through the other's inside (pairs
// whose bounding boxes are apart skipped).
size_t crossing_pairs(const std::vector<double>& xyz, const std::vector<uint32_t>& tri) {
    const size_t n = tri.size() / 3;
    std::vector<double> box(6 * n);
    for (size_t t = 0; t < n; ++t)
        for (size_t k = 0; k < 3; ++k) {
            const double a = xyz[3 * tri[3 * t] + k], b = xyz[3 * tri[3 * t + 1] + k],
                         c = xyz[3 * tri[3 * t + 2] + k];
            box[6 * t + k] = std::min({a, b, c});
            box[6 * t + 3 + k] = std::max({a, b, c});
        }
    size_t pairs = 0;
    for (size_t s = 0; s < n; ++s)
        for (size_t t = s + 1; t < n; ++t) {
            bool apart = false;
            for (size_t k = 0; k < 3; ++k)
                apart = apart || box[6 * s + k] > box[6 * t + 3 + k] || box[6 * t + k] > box[6 * s + 3 + k];
            if (apart) continue;
            const uint32_t* u = &tri[3 * s];
            const uint32_t* v = &tri[3 * t];
            bool shared = false;
            for (int i = 0; i < 3; ++i)
                shared = shared || u[i] == v[0] || u[i] == v[1] || u[i] == v[2];
            if (shared) continue;
            const P a[3] = {point(xyz, u[0]), point(xyz, u[1]), point(xyz, u[2])};
            const P b[3] = {point(xyz, v[0]), point(xyz, v[1]), point(xyz, v[2])};
            bool cross_found = false;
            for (int k = 0; k < 3 && !cross_found; ++k)
                cross_found = pierces(a[k], a[(k + 1) % 3], b[0], b[1], b[2]) ||
                              pierces(b[k], b[(k + 1) % 3], a[0], a[1], a[2]);
            pairs += cross_found;
        }
    return pairs;
}

// The share of the walls' area whose centroid lies farther than kMisfitSpacings point
// spacings from every point (the gaps a web spans), by every point's distance.
double far_share(const std::vector<double>& xyz, const std::vector<uint32_t>& tri, size_t walls,
                 double spacing) {
    double far = 0, total = 0;
    const double reach = stratmesh::kMisfitSpacings * spacing;
    for (size_t t = 0; t < walls; ++t) {
        const P a = point(xyz, tri[3 * t]), b = point(xyz, tri[3 * t + 1]), c = point(xyz, tri[3 * t + 2]);
        const P n = cross(b - a, c - a);
        const double area = std::sqrt(dot(n, n)) / 2;
        const P m = {(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, (a.z + b.z + c.z) / 3};
        double nearest = 1e300;
        for (uint32_t i = 0; i < xyz.size() / 3; ++i) {
            const P d = point(xyz, i) - m;
            nearest = std::min(nearest, dot(d, d));
        }
        total += area;
        if (nearest > reach * reach) far += area;
    }
    return total > 0 ? far / total : 0;
}

// The ninth decile of the points' nearest-neighbour distances.
double ninth_decile_spacing(const std::vector<double>& xyz) {
    const size_t n = xyz.size() / 3;
    std::vector<double> nearest(n, 1e300);
    for (uint32_t i = 0; i < n; ++i)
        for (uint32_t j = 0; j < n; ++j)
            if (i != j) {
                const P d = point(xyz, i) - point(xyz, j);
                nearest[i] = std::min(nearest[i], dot(d, d));
            }
    std::sort(nearest.begin(), nearest.end());
    return std::sqrt(nearest[n * 9 / 10]);
}

bool poor(const Diagnostics& d) {
    return d.crossing_pair_count > 0 || d.misfit_area_fraction > stratmesh::kPoorMisfitFraction;
}

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

}  // namespace

TEST_CASE("fit: single columns follow their cloud, with or without caps, whatever the pose") {
    for (const shapes::Kind& kind : shapes::kinds())
        for (Pose pose : {Pose::z, Pose::tilted}) {
            const Shape s = kind.make(2000, pose);
            for (uint32_t flags : {0u, uint32_t(stratmesh::add_caps)}) {
                INFO(s.name << (flags ? ", add_caps" : ""));
                Options o = {};
                o.flags = flags;
                const Mesh m = mesh(s.xyz, o);
                REQUIRE(m.status == Status::ok);
                const Diagnostics& d = m.report.diagnostics;
                CHECK(d.fit_sample_count == m.triangles.size() / 3 - m.report.caps.triangle_count);
                CHECK(d.misfit_area_fraction < stratmesh::kPoorMisfitFraction);
                CHECK(d.crossing_check_complete);
                CHECK(d.crossing_pair_count == crossing_pairs(s.xyz, m.triangles));
                // Near one where the points are even; a CT stack's rows lie farther apart
                // than its points along them.
                CHECK(d.area_per_point > 0.2);
                CHECK(d.area_per_point < 3);
                CHECK(m.report.workspace_used_bytes <= m.bound);
            }
        }
}

TEST_CASE("fit: the measured spacing, misfit and crossings are the plain recomputations'") {
    for (const Shape& s : {shapes::y_of_tubes(3000, Pose::z), shapes::four_legged(3000, Pose::tilted),
                           shapes::vase(3000, Pose::z)}) {
        INFO(s.name);
        Options o = {};
        o.parts = stratmesh::Parts::one_tube;
        const Mesh m = mesh(s.xyz, o);
        REQUIRE(m.status == Status::ok);
        const Diagnostics& d = m.report.diagnostics;
        // The library samples a share of the points for the spacing.
        CHECK(d.point_spacing == doctest::Approx(ninth_decile_spacing(s.xyz)).epsilon(0.15));
        REQUIRE(d.crossing_check_complete);
        CHECK(d.crossing_pair_count == crossing_pairs(s.xyz, m.triangles));
        // Every far triangle misfits; the normals add more.
        const size_t walls = m.triangles.size() / 3 - m.report.caps.triangle_count;
        CHECK(d.misfit_area_fraction >= far_share(s.xyz, m.triangles, walls, d.point_spacing) - 1e-12);
        if (d.misfit_area > 0)
            for (int k = 0; k < 3; ++k) CHECK(d.misfit_box_min[k] <= d.misfit_box_max[k]);
    }
}

// The mean distance of the triangles' centroids to the true surface, weighted by area,
// over the bounding box's diagonal.
double distance_to_truth(const Shape& s, const std::vector<uint32_t>& tri) {
    double low[3] = {1e300, 1e300, 1e300}, high[3] = {-1e300, -1e300, -1e300};
    for (size_t i = 0; i < s.xyz.size(); ++i) {
        low[i % 3] = std::min(low[i % 3], s.xyz[i]);
        high[i % 3] = std::max(high[i % 3], s.xyz[i]);
    }
    double sum = 0, area = 0;
    for (size_t t = 0; t < tri.size() / 3; ++t) {
        const P a = point(s.xyz, tri[3 * t]), b = point(s.xyz, tri[3 * t + 1]), c = point(s.xyz, tri[3 * t + 2]);
        const double w = length(cross(b - a, c - a)) / 2;
        const double m[3] = {(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, (a.z + b.z + c.z) / 3};
        sum += w * std::fabs(s.deviation(m));
        area += w;
    }
    return sum / area / std::hypot(high[0] - low[0], high[1] - low[1], high[2] - low[2]);
}

TEST_CASE("fit: poor where the surface leaves the object, as the distance to the true surface says") {
    // A web across a body's legs, a fan of spikes beside fingers, and a machined part given
    // as its CAD vertices (rings, nothing inside its flat faces): each far from its true
    // surface (over 0.2% of the diagonal).
    const std::vector<Shape> poor_shapes = {
        shapes::four_legged(10000, Pose::z), shapes::hand(5000, Pose::z),
        shapes::cad_spool(48, Pose::z), shapes::cad_spool(48, Pose::tilted),
        shapes::y_of_tubes(10000, Pose::z), shapes::branched_trunk(5000, Pose::z),
        shapes::twice_forked(5000, Pose::z)};
    for (const Shape& s : poor_shapes) {
        INFO(s.name << ", " << s.size() << " points");
        const Mesh m = mesh(s.xyz, Options{});
        REQUIRE(m.status == Status::ok);
        CHECK(distance_to_truth(s, m.triangles) > 0.002);
        CHECK(poor(m.report.diagnostics));
        CHECK(m.report.workspace_used_bytes <= m.bound);
    }
    // Single columns close to theirs (under 0.1% of the diagonal) are good.
    // So is a U of three straight pipes, meshed across its skeleton.
    for (const Shape& s : {shapes::bumpy_tube(20000, Pose::tilted), shapes::head(20000, Pose::z),
                           shapes::capsule(20000, Pose::x), shapes::noisy_tube(20000, Pose::z),
                           shapes::u_tube(6000, Pose::z)}) {
        INFO(s.name);
        const Mesh m = mesh(s.xyz, Options{});
        REQUIRE(m.status == Status::ok);
        CHECK(distance_to_truth(s, m.triangles) < 0.001);
        CHECK_FALSE(poor(m.report.diagnostics));
    }
    // The body is a tube along x at z in [-1, 1], its legs under it down to z = -3.77: the
    // misfit reaches down among the legs.
    const Shape& body = poor_shapes[0];
    const Mesh m = mesh(body.xyz, Options{});
    double low[3];
    body.transform.unapply(m.report.diagnostics.misfit_box_min, low);
    CHECK(low[2] < -3);
}

TEST_CASE("fit: the same report with a job runner, and at every magnitude") {
    const Shape fork = shapes::twice_forked(5000, Pose::z);
    const Mesh plain = mesh(fork.xyz, Options{});
    REQUIRE(plain.status == Status::ok);
    REQUIRE(plain.report.diagnostics.fit_sample_count > 0);
    for (stratmesh::JobRunner runner : {run_in_reverse, run_on_two_threads}) {
        Options o = {};
        o.run_jobs = runner;
        const Mesh jobs = mesh(fork.xyz, o);
        REQUIRE(jobs.status == Status::ok);
        CHECK(jobs.triangles == plain.triangles);
        CHECK(std::memcmp(&jobs.report.diagnostics, &plain.report.diagnostics,
                          sizeof(Diagnostics)) == 0);
    }
    // Scaled by a power of two: the same triangles, counts and shares; lengths scaled.
    Options along = {};
    along.axis = stratmesh::Axis::z;
    along.parts = stratmesh::Parts::one_tube;
    const Mesh unit = mesh(fork.xyz, along);
    REQUIRE(unit.status == Status::ok);
    REQUIRE(unit.report.diagnostics.misfit_area > 0);
    for (int exponent : {-300, 300}) {
        INFO("scaled by 2^" << exponent);
        const double scale = std::ldexp(1.0, exponent);
        std::vector<double> xyz = fork.xyz;
        for (double& v : xyz) v *= scale;
        const Mesh scaled = mesh(xyz, along);
        REQUIRE(scaled.status == Status::ok);
        CHECK(scaled.triangles == unit.triangles);
        const Diagnostics &d = scaled.report.diagnostics, &p = unit.report.diagnostics;
        CHECK(d.crossing_pair_count == p.crossing_pair_count);
        CHECK(d.misfit_area_fraction == p.misfit_area_fraction);
        CHECK(d.area_per_point == p.area_per_point);
        CHECK(d.point_spacing == p.point_spacing * scale);
        CHECK(d.misfit_area == p.misfit_area * scale * scale);
        for (int k = 0; k < 3; ++k) CHECK(d.misfit_box_max[k] == p.misfit_box_max[k] * scale);
    }
}

TEST_CASE("fit: the stream does not measure it, reconstruct() of the same tube does") {
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
    CHECK(report.diagnostics.fit_sample_count == 0);
    CHECK(report.diagnostics.point_spacing == 0);
    CHECK(report.diagnostics.misfit_area == 0);
    o.parts = stratmesh::Parts::one_tube;
    o.layer_count = 1;
    const Mesh batch = mesh(fork.xyz, o);
    REQUIRE(batch.status == Status::ok);
    CHECK(batch.triangles == triangles);
    CHECK(poor(batch.report.diagnostics));
}
