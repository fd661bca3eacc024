// Parallel layers: with Options::run_jobs, reconstruct() gives the same bytes (triangles and
// report) as without, whatever order and threads the runner uses, in the workspace its
// bound promises.
#include "stratmesh.h"
#include "support/library_options.h"
#include "support/shapes.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

namespace {

using library_options::axis_options;
using library_options::cloud_of;
using stratmesh::JobFunction;
using stratmesh::LayerInfo;
using stratmesh::Options;
using stratmesh::Report;
using stratmesh::Status;
using shapes::Pose;
using shapes::Shape;

// Runners: in order, in reverse order, and on threads taking indices from a counter.
void run_in_order(void*, uint32_t count, JobFunction job, void* context) {
    for (uint32_t i = 0; i < count; ++i) job(context, i);
}

void run_in_reverse(void*, uint32_t count, JobFunction job, void* context) {
    for (uint32_t i = count; i-- > 0;) job(context, i);
}

void run_on_threads(void* user, uint32_t count, JobFunction job, void* context) {
    const unsigned threads = *static_cast<const unsigned*>(user);
    std::atomic<uint32_t> next{0};
    auto work = [&]() {
        for (uint32_t i = next++; i < count; i = next++) job(context, i);
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads && t < count; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
}

struct Result {
    Status status = Status::internal_error;
    std::vector<uint32_t> triangles;
    Report report{};
    std::vector<LayerInfo> layers;
    size_t bound = 0;
};

Result run(const Shape& s, const Options& o) {
    Result r;
    const stratmesh::Cloud cloud = cloud_of(s);
    r.bound = stratmesh::reconstruct_workspace_size(cloud.count, o);
    std::vector<unsigned char> work(r.bound);
    r.triangles.resize(3 * stratmesh::reconstruct_max_triangles(cloud.count, o));
    r.layers.resize(300);
    r.report.layers.info = r.layers.data();
    r.report.layers.info_capacity = r.layers.size();
    size_t count = 0;
    r.status = stratmesh::reconstruct(cloud, o, work.data(), work.size(), r.triangles.data(),
                                      r.triangles.size() / 3, &count, &r.report);
    r.triangles.resize(3 * count);
    r.layers.resize(std::min<size_t>(r.report.layers.used_count, r.layers.size()));
    return r;
}

void check_same(const Result& sequential, const Result& parallel) {
    REQUIRE(parallel.status == sequential.status);
    CHECK(parallel.triangles == sequential.triangles);
    CHECK(parallel.report.points.used_count == sequential.report.points.used_count);
    CHECK(parallel.report.points.duplicate_count == sequential.report.points.duplicate_count);
    CHECK(parallel.report.diagnostics.fold_count == sequential.report.diagnostics.fold_count);
    CHECK(parallel.report.diagnostics.diagonal_swap_count == sequential.report.diagnostics.diagonal_swap_count);
    CHECK(parallel.report.diagnostics.illegal_removed_count == sequential.report.diagnostics.illegal_removed_count);
    // The webs too, bit for bit (the forked and knobbed tubes have some).
    CHECK(std::memcmp(&parallel.report.diagnostics, &sequential.report.diagnostics,
                      sizeof(stratmesh::Diagnostics)) == 0);
    REQUIRE(parallel.layers.size() == sequential.layers.size());
    for (size_t k = 0; k < parallel.layers.size(); ++k)
        CHECK(std::memcmp(&parallel.layers[k], &sequential.layers[k], sizeof(LayerInfo)) == 0);
    CHECK(parallel.report.workspace_used_bytes <= parallel.bound);
}

struct Layout {
    const char* name;
    void (*apply)(Options&, std::vector<double>&, const Shape&);
};

const Layout kLayouts[] = {
    {"6 equal layers", [](Options& o, std::vector<double>&, const Shape&) { o.layer_count = 6; }},
    {"40 equal layers (thin ones merge)", [](Options& o, std::vector<double>&, const Shape&) { o.layer_count = 40; }},
    {"automatic", [](Options&, std::vector<double>&, const Shape&) {}},
    {"uneven cuts", [](Options& o, std::vector<double>& cuts, const Shape& s) {
         for (double f : {0.03, 0.06, 0.85}) cuts.push_back(s.along_axis(s.z_min + f * (s.z_max - s.z_min)));
         o.cuts = cuts.data();
         o.cut_count = cuts.size();
     }},
};

}  // namespace

TEST_CASE("parallel layers: the same bytes as in order, whatever the runner, on every test shape") {
    const std::vector<Shape> shapes_list = {
        shapes::cylinder(3000, Pose::z),    shapes::bumpy_tube(3000, Pose::tilted),
        shapes::cone(3000, Pose::x),        shapes::vase(3000, Pose::z),
        shapes::scan_grid(3000, Pose::z),   shapes::ct_slices(3000, Pose::tilted),
        shapes::noisy_tube(3000, Pose::z),  shapes::head(3000, Pose::tilted),
        shapes::elliptic_tube(3000, Pose::x), shapes::slanted_tube(3000, Pose::tilted),
        shapes::closed_cylinder(3000, Pose::x), shapes::capsule(3000, Pose::tilted),
        shapes::forked_tube(3000, Pose::z),     shapes::knobbed_tube(3000, Pose::x)};
    unsigned two = 2, eight = 8;
    for (const Shape& s : shapes_list) {
        for (const Layout& layout : kLayouts)
        for (uint32_t flags : {0u, uint32_t(stratmesh::surface_flips)}) {
            INFO(s.name << " (" << shapes::pose_name(s.pose) << "), " << layout.name
                        << (flags ? ", surface_flips" : ""));
            std::vector<double> cuts;
            Options o = axis_options(s);
            o.flags |= flags;
            layout.apply(o, cuts, s);
            const Result sequential = run(s, o);
            REQUIRE(sequential.status == Status::ok);
            CHECK(sequential.report.layers.parallel_count == 0);
            struct Runner {
                stratmesh::JobRunner run;
                void* user;
            };
            for (Runner runner : {Runner{run_in_order, nullptr}, Runner{run_in_reverse, nullptr},
                                  Runner{run_on_threads, &two}, Runner{run_on_threads, &eight}}) {
                Options p = o;
                p.run_jobs = runner.run;
                p.jobs_user = runner.user;
                const Result parallel = run(s, p);
                check_same(sequential, parallel);
                if (sequential.report.layers.used_count > 1) CHECK(parallel.report.layers.parallel_count > 0);
            }
        }
    }
}

TEST_CASE("parallel layers: chunks the safety net repairs come out the same") {
    // Thin layers where the net removes a triangle; their jobs' results go through the
    // safety net in order instead of being replayed (see replay_chunk).
    struct Repaired {
        Shape shape;
        uint32_t layers;
    };
    const Repaired cases[] = {{shapes::cylinder(2000, Pose::z), 30},
                              {shapes::elliptic_tube(1000, Pose::x), 30},
                              {shapes::vase(600, Pose::tilted), 30}};
    unsigned two = 2;
    for (const Repaired& r : cases) {
        INFO(r.shape.name << ", " << r.layers << " layers");
        Options o = axis_options(r.shape);
        o.layer_count = r.layers;
        const Result sequential = run(r.shape, o);
        REQUIRE(sequential.status == Status::ok);
        CHECK(sequential.report.diagnostics.illegal_removed_count > 0);
        Options p = o;
        p.run_jobs = run_on_threads;
        p.jobs_user = &two;
        const Result parallel = run(r.shape, p);
        check_same(sequential, parallel);
        CHECK(parallel.report.layers.parallel_count > 0);
    }
}

TEST_CASE("parallel layers: a folding layer tried again with the next one joined comes out the same") {
    // A job's layer that folds is triangulated again, joined, before its chunk is named: the
    // try that is not kept must leave nothing behind (points counted as used, triangles).
    unsigned two = 2;
    struct Folding {
        Shape shape;
        uint32_t layers;
    };
    // Two parallel tubes, every other point shifted to one side: each layer holds both and
    // folds, yet its chunk is sound: a job's result is replayed (its points named) there.
    Shape twin = shapes::cylinder(3000, Pose::z);
    twin.name = "twin tubes";
    for (size_t i = 0; i < twin.size(); ++i) twin.xyz[3 * i] += i % 2 ? 2.5 : -2.5;
    const Folding cases[] = {{twin, 2},
                             {twin, 5},
                             {shapes::knobbed_tube(10000, Pose::z), 16},
                             {shapes::knobbed_tube(10000, Pose::tilted), 16}};
    for (const Folding& f : cases) {
        INFO(f.shape.name << ", " << f.layers << " layers");
        Options o = axis_options(f.shape);
        o.layer_count = f.layers;
        const Result sequential = run(f.shape, o);
        REQUIRE(sequential.status == Status::ok);
        for (stratmesh::JobRunner runner : {run_in_order, run_on_threads}) {
            Options p = o;
            p.run_jobs = runner;
            p.jobs_user = &two;
            const Result parallel = run(f.shape, p);
            check_same(sequential, parallel);
            CHECK(parallel.report.layers.parallel_count > 0);
        }
    }
}

TEST_CASE("parallel layers: a workspace too small for the jobs falls back to working in order") {
    const Shape s = shapes::bumpy_tube(4000, Pose::z);
    Options o = axis_options(s);
    o.layer_count = 8;
    o.parts = stratmesh::Parts::one_tube;  // the search for branches would take more room
    const Result sequential = run(s, o);
    Options p = o;
    p.run_jobs = run_in_order;
    const stratmesh::Cloud cloud = cloud_of(s);
    // What the sequential run used at its peak (and room to align the buffer elsewhere):
    // enough for the groups, not for the layers done ahead.
    std::vector<unsigned char> work(sequential.report.workspace_used_bytes + 64);
    REQUIRE(work.size() < stratmesh::reconstruct_workspace_size(cloud.count, p));
    std::vector<uint32_t> tris(3 * stratmesh::reconstruct_max_triangles(cloud.count, p));
    Report report = {};
    size_t count = 0;
    REQUIRE(stratmesh::reconstruct(cloud, p, work.data(), work.size(), tris.data(), tris.size() / 3,
                                   &count, &report) == Status::ok);
    tris.resize(3 * count);
    CHECK(tris == sequential.triangles);
    CHECK(report.layers.parallel_count == 0);
}

TEST_CASE("parallel layers: any workspace below the bound gives out_of_memory or the same triangles") {
    // The jobs take their room in steps (the layers done ahead, then each group, its band,
    // the flips across its seam, the safety net, the caps): a workspace that runs out at any
    // of them must end in out_of_memory with nothing counted, or, where the runner falls
    // back to working in order, in the triangles of the sequential run, never in others;
    // and nothing is written past the workspace or the triangle capacity.
    struct Case {
        Shape shape;
        uint32_t layers;
        uint32_t flags;
    };
    const Case cases[] = {
        {shapes::bumpy_tube(2000, Pose::tilted), 6, 0},
        {shapes::bumpy_tube(2000, Pose::tilted), 6, uint32_t(stratmesh::surface_flips)},
        {shapes::capsule(2000, Pose::x), 5, uint32_t(stratmesh::add_caps)},
        {shapes::cylinder(2000, Pose::z), 30, 0},  // thin layers: the safety net repairs
    };
    unsigned two = 2;
    for (const Case& c : cases) {
        INFO(c.shape.name << ", " << c.layers << " layers, flags " << c.flags);
        Options o = axis_options(c.shape);
        o.layer_count = c.layers;
        o.flags |= c.flags;
        const Result sequential = run(c.shape, o);
        REQUIRE(sequential.status == Status::ok);
        Options p = o;
        p.run_jobs = run_on_threads;
        p.jobs_user = &two;
        const stratmesh::Cloud cloud = cloud_of(c.shape);
        const size_t bound = stratmesh::reconstruct_workspace_size(cloud.count, p);
        const size_t capacity = stratmesh::reconstruct_max_triangles(cloud.count, p);
        size_t failures = 0, successes = 0, smallest_success = bound;
        auto attempt = [&](size_t bytes) {
            CAPTURE(bytes);
            std::vector<unsigned char> work(bytes + 64, 0xA5);
            std::vector<uint32_t> tris(3 * capacity + 1, 0xFEFEFEFEu);
            Report report = {};
            size_t count = 12345;
            const Status status = stratmesh::reconstruct(cloud, p, work.data(), bytes, tris.data(),
                                                         capacity, &count, &report);
            CHECK(tris.back() == 0xFEFEFEFEu);
            CHECK(std::all_of(work.end() - 64, work.end(), [](unsigned char b) { return b == 0xA5; }));
            if (status == Status::ok) {
                ++successes;
                smallest_success = std::min(smallest_success, bytes);
                tris.resize(3 * count);
                CHECK(tris == sequential.triangles);
                CHECK(report.points.used_count == sequential.report.points.used_count);
            } else {
                ++failures;
                CHECK(status == Status::out_of_memory);
                CHECK(count == 0);
            }
        };
        // A coarse ladder up to the bound, then a fine one across the coarse step where the
        // sizes began to work: there the room runs out late in the run.
        for (size_t bytes : {size_t{0}, size_t{1}, size_t{100}, size_t{4096}, bound - 1}) attempt(bytes);
        for (size_t k = 1; k < 64; ++k) attempt(bound * k / 64);
        const size_t coarse = smallest_success;
        for (size_t k = 1; k < 64; ++k) attempt(coarse - bound / 64 * k / 64);
        MESSAGE(c.shape.name << ": " << failures << " sizes out_of_memory, " << successes
                             << " the same triangles; smallest that worked " << smallest_success
                             << " of a bound of " << bound);
        CHECK(failures >= 4);
        CHECK(successes >= 1);
    }
}

namespace {

// Runners that break the contract in the ways JobRunner allows for.
void run_even_only(void*, uint32_t count, JobFunction job, void* context) {
    for (uint32_t i = 0; i < count; i += 2) job(context, i);
}

void run_twice(void*, uint32_t count, JobFunction job, void* context) {
    for (uint32_t round = 0; round < 2; ++round)
        for (uint32_t i = 0; i < count; ++i) job(context, i);
}

void run_with_strangers(void*, uint32_t count, JobFunction job, void* context) {
    job(context, count);
    job(context, 0xFFFFFFFFu);
    for (uint32_t i = 0; i < count; ++i) job(context, i);
    job(context, count + 1);
}

void run_none(void*, uint32_t, JobFunction, void*) {}

}  // namespace

TEST_CASE("parallel layers: a runner that skips jobs, repeats them or names others gives the same bytes") {
    const Shape s = shapes::bumpy_tube(4000, Pose::tilted);
    Options o = axis_options(s);
    o.layer_count = 8;
    const Result sequential = run(s, o);
    REQUIRE(sequential.status == Status::ok);
    Options all = o;
    all.run_jobs = run_in_order;
    const size_t every_layer = run(s, all).report.layers.parallel_count;
    REQUIRE(every_layer > 2);
    struct Runner {
        const char* name;
        stratmesh::JobRunner run;
    };
    for (Runner runner : {Runner{"every other job", run_even_only}, Runner{"every job twice", run_twice},
                          Runner{"indices past the count", run_with_strangers}, Runner{"no job", run_none}}) {
        INFO(runner.name);
        Options p = o;
        p.run_jobs = runner.run;
        const Result parallel = run(s, p);
        check_same(sequential, parallel);
        if (runner.run == run_even_only) {
            CHECK(parallel.report.layers.parallel_count > 0);
            CHECK(parallel.report.layers.parallel_count < every_layer);
        } else if (runner.run == run_none) {
            CHECK(parallel.report.layers.parallel_count == 0);
        } else {
            CHECK(parallel.report.layers.parallel_count == every_layer);
        }
    }
}
