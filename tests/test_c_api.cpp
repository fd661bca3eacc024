// The C interface against the C++ one it wraps: the same triangles, the same report
// (field by field, the layer array byte for byte), the callbacks passed through (progress,
// a jobs runner, the stream's triangles), for the same input.
#include "stratmesh.h"
#include "support/library_options.h"
#include "support/shapes.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace {

using library_options::axis_options;
using library_options::cloud_of;
using stratmesh::Options;
using stratmesh::Report;
using stratmesh::Status;
using shapes::Pose;
using shapes::Shape;

stratmesh_options to_c(const Options& o) {
    stratmesh_options c;
    std::memset(&c, 0, sizeof c);
    c.axis = static_cast<uint32_t>(o.axis);
    for (int k = 0; k < 3; ++k) {
        c.direction[k] = o.direction[k];
        c.origin[k] = o.origin[k];
    }
    c.cuts = o.cuts;
    c.cut_count = o.cut_count;
    c.layer_count = o.layer_count;
    c.layer_height = o.layer_height;
    c.flags = o.flags;
    c.parts = static_cast<uint32_t>(o.parts);
    return c;
}

stratmesh_cloud to_c(const stratmesh::Cloud& cloud) {
    return stratmesh_cloud{cloud.xyz, cloud.count, cloud.stride_bytes,
                           static_cast<uint32_t>(cloud.scalar)};
}

// The stream's C report counts its workspace from the start of the caller's buffer, the
// C handle included: compared apart (see the stream's test).
void check_same_report(const Report& r, const stratmesh_report& c, bool same_workspace = true) {
    CHECK(c.triangle_count == r.triangle_count);
    for (int k = 0; k < 3; ++k) {
        CHECK(c.axis[k] == r.axis[k]);
        CHECK(c.axis_origin[k] == r.axis_origin[k]);
    }
    CHECK(c.points.in_count == r.points.in_count);
    CHECK(c.points.used_count == r.points.used_count);
    CHECK(c.points.duplicate_count == r.points.duplicate_count);
    CHECK(c.points.rejected_count == r.points.rejected_count);
    CHECK(c.points.outlier_count == r.points.outlier_count);
    CHECK(c.points.unused_count == r.points.unused_count);
    CHECK(c.points.first_invalid_index == r.points.first_invalid_index);
    CHECK(c.points.held_count == r.points.held_count);
    CHECK(c.layers.planned_count == r.layers.planned_count);
    CHECK(c.layers.used_count == r.layers.used_count);
    CHECK(c.layers.parallel_count == r.layers.parallel_count);
    CHECK(c.layers.skeleton_node_count == r.layers.skeleton_node_count);
    CHECK(c.caps.closed_count == r.caps.closed_count);
    CHECK(c.caps.open_count == r.caps.open_count);
    CHECK(c.caps.triangle_count == r.caps.triangle_count);
    CHECK(c.caps.wall_flip_count == r.caps.wall_flip_count);
    CHECK(c.parts.outcome == static_cast<uint32_t>(r.parts.outcome));
    CHECK(c.parts.part_count == r.parts.part_count);
    CHECK(c.parts.gap == r.parts.parting.gap);
    CHECK(c.parts.above_branch_count == r.parts.parting.above_branch_count);
    CHECK(c.parts.below_branch_count == r.parts.parting.below_branch_count);
    CHECK(c.diagnostics.fold_count == r.diagnostics.fold_count);
    CHECK(c.diagnostics.illegal_removed_count == r.diagnostics.illegal_removed_count);
    CHECK(c.diagnostics.diagonal_swap_count == r.diagnostics.diagonal_swap_count);
    CHECK(c.diagnostics.point_spacing == r.diagnostics.point_spacing);
    CHECK(c.diagnostics.area_per_point == r.diagnostics.area_per_point);
    CHECK(c.diagnostics.fit_sample_count == r.diagnostics.fit_sample_count);
    CHECK(c.diagnostics.misfit_area_fraction == r.diagnostics.misfit_area_fraction);
    CHECK(c.diagnostics.misfit_area == r.diagnostics.misfit_area);
    CHECK(c.diagnostics.crossing_pair_count == r.diagnostics.crossing_pair_count);
    CHECK((c.diagnostics.crossing_check_complete != 0) == r.diagnostics.crossing_check_complete);
    for (int k = 0; k < 3; ++k) {
        CHECK(c.diagnostics.misfit_box_min[k] == r.diagnostics.misfit_box_min[k]);
        CHECK(c.diagnostics.misfit_box_max[k] == r.diagnostics.misfit_box_max[k]);
        CHECK(c.diagnostics.crossing_box_min[k] == r.diagnostics.crossing_box_min[k]);
        CHECK(c.diagnostics.crossing_box_max[k] == r.diagnostics.crossing_box_max[k]);
    }
    CHECK(c.detail == r.detail);
    if (same_workspace) CHECK(c.workspace_used_bytes == r.workspace_used_bytes);
}

struct Run {
    Status status = Status::ok;
    std::vector<uint32_t> tris;
    size_t count = 0;
};

const size_t kInfo = 64;

// A workspace at a 64-byte boundary: the peak a run reports counts from the buffer's start,
// alignment padding included, so two runs compare only at the same alignment (malloc gives
// 16 bytes on 64-bit targets, 8 on 32-bit ones).
unsigned char* aligned_workspace(std::vector<unsigned char>& storage, size_t bytes) {
    storage.assign(bytes + 64, 0);
    const size_t skip = (64 - reinterpret_cast<uintptr_t>(storage.data()) % 64) % 64;
    return storage.data() + skip;
}

Run run_cpp(const Shape& s, const Options& o, Report& rep, std::vector<stratmesh::LayerInfo>& info) {
    Run run;
    std::vector<unsigned char> storage;
    const size_t bytes = stratmesh::reconstruct_workspace_size(s.size(), o);
    unsigned char* work = aligned_workspace(storage, bytes);
    run.tris.resize(3 * stratmesh::reconstruct_max_triangles(s.size(), o));
    info.assign(kInfo, stratmesh::LayerInfo{});
    rep = Report{};
    rep.layers.info = info.data();
    rep.layers.info_capacity = info.size();
    run.status = stratmesh::reconstruct(cloud_of(s), o, work, bytes, run.tris.data(),
                                        run.tris.size() / 3, &run.count, &rep);
    run.tris.resize(3 * run.count);
    return run;
}

Run run_c(const Shape& s, const stratmesh_options& o, stratmesh_report& rep,
          std::vector<stratmesh_layer_info>& info) {
    Run run;
    std::vector<unsigned char> storage;
    const size_t bytes = stratmesh_reconstruct_workspace_size(s.size(), &o);
    unsigned char* work = aligned_workspace(storage, bytes);
    run.tris.resize(3 * stratmesh_reconstruct_max_triangles(s.size(), &o));
    info.assign(kInfo, stratmesh_layer_info{});
    std::memset(&rep, 0, sizeof rep);
    rep.layers.info = info.data();
    rep.layers.info_capacity = info.size();
    const stratmesh_cloud cloud = to_c(cloud_of(s));
    run.status = static_cast<Status>(stratmesh_reconstruct(&cloud, &o, work, bytes,
                                                           run.tris.data(), run.tris.size() / 3,
                                                           &run.count, &rep));
    run.tris.resize(3 * run.count);
    return run;
}

// Returns the C++ report (its layer array gone).
Report check_same_reconstruction(const Shape& s, const Options& o) {
    Report rep;
    std::vector<stratmesh::LayerInfo> info;
    const Run cpp = run_cpp(s, o, rep, info);
    const stratmesh_options co = to_c(o);
    CHECK(stratmesh_reconstruct_workspace_size(s.size(), &co) ==
          stratmesh::reconstruct_workspace_size(s.size(), o));
    CHECK(stratmesh_reconstruct_max_triangles(s.size(), &co) ==
          stratmesh::reconstruct_max_triangles(s.size(), o));
    stratmesh_report crep;
    std::vector<stratmesh_layer_info> cinfo;
    const Run c = run_c(s, co, crep, cinfo);
    REQUIRE(cpp.status == Status::ok);
    CHECK(c.status == cpp.status);
    CHECK(c.count == cpp.count);
    CHECK(c.tris == cpp.tris);
    check_same_report(rep, crep);
    CHECK(crep.layers.info == cinfo.data());
    CHECK(std::memcmp(cinfo.data(), info.data(), kInfo * sizeof(stratmesh::LayerInfo)) == 0);
    rep.layers.info = nullptr;
    return rep;
}

TEST_CASE("C interface: reconstruct gives the C++ triangles and report") {
    const Shape tilted = shapes::bumpy_tube(2000, Pose::tilted);
    Options o = axis_options(tilted);
    o.flags = stratmesh::add_caps;
    o.layer_count = 6;
    check_same_reconstruction(tilted, o);

    const Shape upright = shapes::elliptic_tube(1500, Pose::z);
    Options automatic = {};
    automatic.flags = stratmesh::surface_flips | stratmesh::skip_invalid_points;
    check_same_reconstruction(upright, automatic);

    const double cuts[] = {-1.0, 0.5, 2.0};
    Options cut = axis_options(upright);
    cut.cuts = cuts;
    cut.cut_count = 3;
    cut.flags = stratmesh::add_caps;
    check_same_reconstruction(upright, cut);

    // A fork meshed as one tube spans the gap between its prongs: the misfit fields too.
    const Shape fork = shapes::forked_tube(3000, Pose::z);
    Options one = {};
    one.parts = stratmesh::Parts::one_tube;
    CHECK(check_same_reconstruction(fork, one).diagnostics.misfit_area > 0);
}

TEST_CASE("C interface: a refusal gives the C++ status and report") {
    Shape s = shapes::bumpy_tube(500, Pose::z);
    s.xyz[3 * 7 + 2] = std::numeric_limits<double>::infinity();
    Options o = axis_options(s);
    Report rep;
    std::vector<stratmesh::LayerInfo> info;
    const Run cpp = run_cpp(s, o, rep, info);
    CHECK(cpp.status == Status::invalid_point);
    stratmesh_report crep;
    std::vector<stratmesh_layer_info> cinfo;
    const Run c = run_c(s, to_c(o), crep, cinfo);
    CHECK(c.status == Status::invalid_point);
    CHECK(crep.points.first_invalid_index == 7);
    check_same_report(rep, crep);
}

// The C callbacks: the phases as the C++ callback sees them, and jobs that the C runner
// runs (last first) giving the same bytes as no runner.
struct Phases {
    std::vector<uint32_t> seen;
};

TEST_CASE("C interface: progress and a jobs runner pass through") {
    const Shape s = shapes::bumpy_tube(4000, Pose::z);
    Options o = axis_options(s);
    o.layer_count = 8;
    Phases cpp_phases, c_phases;
    o.progress = [](void* user, stratmesh::Phase phase, double) {
        static_cast<Phases*>(user)->seen.push_back(static_cast<uint32_t>(phase));
    };
    o.progress_user = &cpp_phases;
    Report rep;
    std::vector<stratmesh::LayerInfo> info;
    const Run cpp = run_cpp(s, o, rep, info);
    REQUIRE(cpp.status == Status::ok);

    stratmesh_options co = to_c(o);
    co.progress = [](void* user, stratmesh_phase phase, double) {
        static_cast<Phases*>(user)->seen.push_back(static_cast<uint32_t>(phase));
    };
    co.progress_user = &c_phases;
    size_t batches = 0;
    co.run_jobs = [](void* user, uint32_t count, stratmesh_job_function job, void* context) {
        ++*static_cast<size_t*>(user);
        for (uint32_t i = count; i-- > 0;) job(context, i);
    };
    co.jobs_user = &batches;
    stratmesh_report crep;
    std::vector<stratmesh_layer_info> cinfo;
    const Run c = run_c(s, co, crep, cinfo);
    CHECK(c.status == Status::ok);
    CHECK(c.tris == cpp.tris);
    CHECK(batches > 0);
    CHECK(crep.layers.parallel_count > 0);
    CHECK(c_phases.seen == cpp_phases.seen);
    REQUIRE(!c_phases.seen.empty());
    CHECK(c_phases.seen.back() == STRATMESH_PHASE_DONE);
    CHECK(std::is_sorted(c_phases.seen.begin(), c_phases.seen.end()));
}

// The points sorted by height and cut into `pushes` runs at gaps between heights.
struct Pushes {
    std::vector<double> xyz;
    std::vector<size_t> start;   // each push's first point, then the end
    std::vector<double> tops;
};

Pushes cut_into(const Shape& s, size_t pushes) {
    std::vector<size_t> order(s.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return s.xyz[3 * a + 2] < s.xyz[3 * b + 2]; });
    Pushes p;
    for (size_t i : order) p.xyz.insert(p.xyz.end(), &s.xyz[3 * i], &s.xyz[3 * i] + 3);
    p.start.push_back(0);
    for (size_t k = 1; k < pushes; ++k) {
        size_t at = k * order.size() / pushes;
        p.start.push_back(at);
        p.tops.push_back((p.xyz[3 * (at - 1) + 2] + p.xyz[3 * at + 2]) / 2);
    }
    p.start.push_back(order.size());
    p.tops.push_back(p.xyz.back() + 1);
    return p;
}

struct Collected {
    std::vector<uint32_t> tris;
};

void collect(void* user, const uint32_t* tris, size_t count) {
    Collected& c = *static_cast<Collected*>(user);
    c.tris.insert(c.tris.end(), tris, tris + 3 * count);
}

TEST_CASE("C interface: the C stream gives the C++ stream's triangles and report") {
    const Shape s = shapes::bumpy_tube(3000, Pose::z);
    const Pushes p = cut_into(s, 6);
    Options o = axis_options(s);
    o.flags = stratmesh::origin_given;
    for (int k = 0; k < 3; ++k) o.origin[k] = p.xyz[static_cast<size_t>(k)];
    const size_t held = 3 * (p.start[1] - p.start[0]) + 16;

    Collected cpp_tris, c_tris;
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(held, o));
    Report rep = {};
    stratmesh::Stream* stream = nullptr;
    REQUIRE(stratmesh::stream_open(o, work.data(), work.size(), collect, &cpp_tris, &rep,
                                   &stream) == Status::ok);

    const stratmesh_options co = to_c(o);
    const size_t c_bytes = stratmesh_stream_workspace_size(held, &co);
    CHECK(c_bytes > work.size());
    std::vector<unsigned char> c_work(c_bytes + 3);
    stratmesh_report crep;
    std::memset(&crep, 0, sizeof crep);
    stratmesh_stream* c_stream = nullptr;
    // An odd address: the handle is placed at the next aligned one.
    REQUIRE(stratmesh_stream_open(&co, c_work.data() + 3, c_bytes, collect, &c_tris, &crep,
                                  &c_stream) == STRATMESH_STATUS_OK);
    for (size_t k = 0; k + 1 < p.start.size(); ++k) {
        const stratmesh::Cloud push{&p.xyz[3 * p.start[k]], p.start[k + 1] - p.start[k], 0,
                                    stratmesh::Scalar::float64};
        const stratmesh_cloud c_push = to_c(push);
        const Status status = stratmesh::stream_push(stream, push, p.tops[k]);
        CHECK(status == Status::ok);
        CHECK(static_cast<Status>(stratmesh_stream_push(c_stream, &c_push, p.tops[k])) == status);
        CHECK(c_tris.tris == cpp_tris.tris);
        check_same_report(rep, crep, false);
    }
    // A refused push: the same status and reason.
    const stratmesh::Cloud low{p.xyz.data(), 4, 0, stratmesh::Scalar::float64};
    const stratmesh_cloud c_low = to_c(low);
    CHECK(stratmesh::stream_push(stream, low, p.tops.back() + 1) == Status::out_of_order);
    CHECK(stratmesh_stream_push(c_stream, &c_low, p.tops.back() + 1) == STRATMESH_STATUS_OUT_OF_ORDER);
    check_same_report(rep, crep, false);
    CHECK(stratmesh::stream_close(stream) == Status::ok);
    CHECK(stratmesh_stream_close(c_stream) == STRATMESH_STATUS_OK);
    CHECK(c_tris.tris == cpp_tris.tris);
    CHECK(!c_tris.tris.empty());
    check_same_report(rep, crep, false);
    CHECK(crep.points.used_count == s.size());
    // The C handle comes first in the caller's buffer: it adds its size and alignment.
    CHECK(crep.workspace_used_bytes > rep.workspace_used_bytes);
    CHECK(crep.workspace_used_bytes <= rep.workspace_used_bytes + (c_bytes - work.size()) + 16);
    CHECK(crep.workspace_used_bytes <= c_bytes);
}

TEST_CASE("C interface: status strings and the 2D triangulation are the C++ ones") {
    for (uint32_t v = 0; v <= STRATMESH_STATUS_INTERNAL_ERROR + 1; ++v)
        CHECK(std::strcmp(stratmesh_status_string(v),
                          stratmesh::status_string(static_cast<Status>(v))) == 0);
    std::vector<double> xy;
    for (int i = 0; i < 40; ++i) {
        xy.push_back(static_cast<double>((i * 7) % 13));
        xy.push_back(static_cast<double>((i * 11) % 17) + 0.25 * i);
    }
    const size_t n = xy.size() / 2;
    std::vector<unsigned char> work(stratmesh_delaunay_2d_workspace_size(n));
    CHECK(work.size() == stratmesh::delaunay_2d_workspace_size(n));
    std::vector<uint32_t> a(3 * stratmesh_delaunay_2d_max_triangles(n)), b(a.size());
    std::vector<uint32_t> dup_a(n), dup_b(n);
    stratmesh::Delaunay2dInfo info;
    stratmesh_delaunay_2d_info c_info;
    REQUIRE(stratmesh::delaunay_2d(xy.data(), n, 2 * sizeof(double), work.data(), work.size(),
                                   a.data(), a.size() / 3, &info, dup_a.data()) == Status::ok);
    REQUIRE(stratmesh_delaunay_2d(xy.data(), n, 2 * sizeof(double), work.data(), work.size(),
                                  b.data(), b.size() / 3, &c_info, dup_b.data()) ==
            STRATMESH_STATUS_OK);
    CHECK(a == b);
    CHECK(dup_a == dup_b);
    CHECK(c_info.triangle_count == info.triangle_count);
    CHECK(c_info.hull_vertex_count == info.hull_vertex_count);
    CHECK(c_info.duplicate_count == info.duplicate_count);
    CHECK(c_info.workspace_used_bytes == info.workspace_used_bytes);
    // The info inside the workspace: refused before anything is written.
    CHECK(stratmesh_delaunay_2d(xy.data(), n, 2 * sizeof(double), work.data(), work.size(),
                                b.data(), b.size() / 3,
                                reinterpret_cast<stratmesh_delaunay_2d_info*>(work.data() + 8),
                                nullptr) == STRATMESH_STATUS_INVALID_ARGUMENT);
}

}  // namespace
