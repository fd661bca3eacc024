// Objects that bend, meshed by reconstruct()'s default across their skeleton of geodesic
// rings. Checked by the tests' own mesh checker against the shapes' analytic surfaces (pipes
// swept along a centre line): one oriented manifold through every point, no crossing
// triangles, on the surface and no larger than it; the layers' centres on the centre line.
// Straight, branching and handled objects keep the meshing they had.
#include "stratmesh.h"
#include "support/reconstructed.h"
#include "support/shape_check.h"
#include "support/shapes.h"

#include <doctest/doctest.h>

#include <cmath>
#include <vector>

using stratmesh::Options;
using stratmesh::Status;

namespace {

using reconstructed::mesh;
using Meshed = reconstructed::Mesh;

using shape_check::check;

// The triangles' area and their area-weighted mean distance to the analytic surface.
void area_and_distance(const shapes::Shape& s, const std::vector<uint32_t>& t, double& area,
                       double& mean_distance) {
    area = 0;
    double weighted = 0;
    for (size_t k = 0; k < t.size(); k += 3) {
        const double* a = s.point(t[k]);
        const double* b = s.point(t[k + 1]);
        const double* c = s.point(t[k + 2]);
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double w = std::hypot(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                                    u[0] * v[1] - u[1] * v[0]) / 2;
        const double centroid[3] = {(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3,
                                    (a[2] + b[2] + c[2]) / 3};
        area += w;
        weighted += w * std::fabs(s.deviation(centroid));
    }
    mean_distance = area > 0 ? weighted / area : 0;
}

const double kPipeRadius = 0.5;

std::vector<shapes::Shape> bent_pipes(size_t n, shapes::Pose pose) {
    return {shapes::elbow(n, pose), shapes::u_bend(n, pose), shapes::coil(n, pose)};
}

}  // namespace

TEST_CASE("bends: an elbow, a U bend and a coil of pipe are meshed across their skeleton, on their surface") {
    for (shapes::Pose pose : {shapes::Pose::z, shapes::Pose::tilted}) {
        for (const shapes::Shape& s : bent_pipes(20000, pose)) {
            INFO(s.name << ", pose " << shapes::pose_name(pose));
            std::vector<stratmesh::LayerInfo> layers(64);
            stratmesh::Report report{};
            report.layers.info = layers.data();
            report.layers.info_capacity = layers.size();
            const Options options = {};
            const size_t bound = stratmesh::reconstruct_workspace_size(s.size(), options);
            std::vector<unsigned char> work(bound);
            Meshed m;
            m.triangles.resize(3 * stratmesh::reconstruct_max_triangles(s.size(), options));
            size_t count = 0;
            m.status = stratmesh::reconstruct(reconstructed::cloud_of(s.xyz), options, work.data(),
                                              work.size(), m.triangles.data(),
                                              m.triangles.size() / 3, &count, &report);
            m.triangles.resize(3 * count);
            m.report = report;
            REQUIRE(m.status == Status::ok);
            CHECK(report.layers.skeleton_node_count >= 4);
            CHECK(report.workspace_used_bytes <= bound);
            // Through the points, so inside the surface by at most a chord's sag; a web
            // across a bend would pass a radius away.
            shape_check::check_whole(check(s, m), 0.1 * kPipeRadius);
            double area = 0, distance = 0;
            area_and_distance(s, m.triangles, area, distance);
            const double surface_area = s.spacing * s.spacing * static_cast<double>(s.size());
            CHECK(area < 1.05 * surface_area);
            CHECK(area > 0.95 * surface_area);
            CHECK(distance < 0.1 * s.spacing);
            // Each layer's centre lies near the pipe's centre line (a radius inside its
            // surface): within a third of a radius, as a layer along a whole bend fits one
            // cylinder to its straightened points. The bend itself is a pipe's width across.
            const size_t described = std::min(report.layers.used_count, layers.size());
            for (size_t l = 0; l < described; ++l)
                CHECK(std::fabs(s.deviation(layers[l].centre) + kPipeRadius) < kPipeRadius / 3);
        }
    }
}

TEST_CASE("bends: one tube along one axis wraps the bend, across the skeleton it does not") {
    const shapes::Shape u = shapes::u_bend(6000, shapes::Pose::z);
    Options one_tube = {};
    one_tube.parts = stratmesh::Parts::one_tube;
    const Meshed straight = mesh(u.xyz, one_tube);
    REQUIRE(straight.status == Status::ok);
    CHECK(straight.report.layers.skeleton_node_count == 0);
    CHECK(check(u, straight).max_deviation() > kPipeRadius);
    const Meshed bent = mesh(u.xyz, Options{});
    REQUIRE(bent.status == Status::ok);
    CHECK(bent.report.layers.skeleton_node_count > 0);
    CHECK(check(u, bent).max_deviation() < 0.1 * kPipeRadius);
    // A layout or an axis the caller gives is kept: the layers are stacked along it.
    Options given = {};
    given.layer_count = 4;
    CHECK(mesh(u.xyz, given).report.layers.skeleton_node_count == 0);
    given = {};
    given.axis = stratmesh::Axis::z;
    CHECK(mesh(u.xyz, given).report.layers.skeleton_node_count == 0);
}

TEST_CASE("bends: straight, branching and looped objects are not meshed across a skeleton") {
    // Straight: no bend to follow. Branching: a band of two rings. A torus: two rings
    // around the hole, so one tube along an axis, which the fit names as poor.
    const shapes::Pose z = shapes::Pose::z;
    for (const shapes::Shape& s : {shapes::cylinder(20000, z), shapes::bumpy_tube(20000, shapes::Pose::tilted),
                                   shapes::head(20000, z), shapes::capsule(20000, shapes::Pose::x),
                                   shapes::y_of_tubes(10000, z), shapes::hand(10000, z),
                                   shapes::knobbed_tube(10000, z)}) {
        INFO(s.name);
        const Meshed m = mesh(s.xyz, Options{});
        REQUIRE(m.status == Status::ok);
        CHECK(m.report.layers.skeleton_node_count == 0);
    }
    const Meshed torus = mesh(shapes::torus(10000, z).xyz, Options{});
    REQUIRE(torus.status == Status::ok);
    CHECK(torus.report.layers.skeleton_node_count == 0);
    CHECK(torus.report.diagnostics.misfit_area_fraction > stratmesh::kPoorMisfitFraction);
}

TEST_CASE("bends: the same triangles with a job runner as without") {
    // The skeleton is found before the layers, on every k-th point in input order: the jobs
    // only triangulate the straightened layers, as they do a straight tube's.
    const shapes::Shape s = shapes::coil(20000, shapes::Pose::tilted);
    const Meshed plain = mesh(s.xyz, Options{});
    REQUIRE(plain.status == Status::ok);
    CHECK(plain.report.layers.skeleton_node_count > 0);
    CHECK(plain.report.layers.used_count > 1);
    Options reversed = {};
    reversed.run_jobs = [](void*, uint32_t count, stratmesh::JobFunction job, void* context) {
        for (uint32_t i = count; i-- > 0;) job(context, i);
    };
    const Meshed jobs = mesh(s.xyz, reversed);
    REQUIRE(jobs.status == Status::ok);
    CHECK(jobs.report.layers.parallel_count > 0);
    CHECK(jobs.triangles == plain.triangles);
}
