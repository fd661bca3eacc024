// No heap, no shared mutable state, bounded stack.
//
// 1. delaunay_2d and reconstruct allocate nothing: every input and buffer is prepared
//    first, then each call runs with every global allocation function counting (see
//    alloc_counter.cpp), on success and on every error status the data and memory can
//    produce; a control shows an allocation made during the call is seen.
// 2. Two threads reconstructing (and triangulating) different inputs with separate
//    workspaces give byte-identical results to the same calls made one after the other.
// 3. Stack high-water mark: each call runs in a thread whose stack is a buffer we own,
//    painted with a pattern; the deepest byte no longer holding the pattern, measured from
//    the frame that makes the call, is the call's stack use. Asserted below 16 KiB (not
//    under a sanitizer, whose instrumentation inflates frames). POSIX only.
#include "stratmesh.h"
#include "support/shapes.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <string>
#include <thread>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#define NO_HEAP_STACK_TEST 1
#include <pthread.h>
#endif

// The counter, defined in alloc_counter.cpp (which says how each allocation is caught).
namespace alloc_counter {

// Allocations (any successful or attempted allocation call) and releases of non-null
// pointers since the program started, over all threads.
std::size_t allocations();
std::size_t releases();
// Which mechanism is in force: "malloc+new", "sanitizer hooks" or "operator new only".
const char* mechanism();

// Allocations made while running f().
template <class F>
std::size_t allocations_during(F&& f) {
    std::size_t before = allocations();
    f();
    return allocations() - before;
}

}  // namespace alloc_counter

// ==== the prepared calls ===============================================================

namespace no_heap {

// One prepared reconstruct() call: the cloud, options and every buffer, sized before.
struct ReconstructCase {
    std::string name;
    std::vector<double> xyz;
    std::vector<float> xyz32;      // used when float32 is true
    bool float32 = false;
    std::vector<double> cuts;
    stratmesh::Options options = {};
    std::vector<unsigned char> work;
    std::vector<uint32_t> tris;
    std::vector<stratmesh::LayerInfo> layers;
    stratmesh::Report report = {};
    size_t count = 0;
    stratmesh::Status expected = stratmesh::Status::ok;

    stratmesh::Cloud cloud() const {
        if (float32) return {xyz32.data(), xyz32.size() / 3, 0, stratmesh::Scalar::float32};
        return {xyz.data(), xyz.size() / 3, 0, stratmesh::Scalar::float64};
    }
    // Sizes the buffers; `work_bytes` / `tri_capacity` override the bounds if non-zero
    // (to provoke out_of_memory / triangle_capacity).
    void prepare(size_t work_bytes = 0, size_t tri_capacity = SIZE_MAX) {
        if (float32) xyz32.assign(xyz.begin(), xyz.end());
        if (!cuts.empty()) {
            options.cuts = cuts.data();
            options.cut_count = cuts.size();
        }
        size_t n = cloud().count;
        work.assign(work_bytes ? work_bytes : stratmesh::reconstruct_workspace_size(n, options), 0);
        size_t cap = tri_capacity != SIZE_MAX ? tri_capacity : stratmesh::reconstruct_max_triangles(n, options);
        tris.assign(3 * cap + 3, 0);  // never empty, so data() is non-null
        layers.assign(64, stratmesh::LayerInfo{});
    }
    stratmesh::Status run() {
        report = {};
        report.layers.info = layers.data();
        report.layers.info_capacity = layers.size();
        count = 0;
        return stratmesh::reconstruct(cloud(), options, work.data(), work.size(), tris.data(),
                                      (tris.size() - 3) / 3, &count, &report);
    }
};

// One prepared delaunay_2d() call.
struct DelaunayCase {
    std::string name;
    std::vector<double> xy;
    std::vector<unsigned char> work;
    std::vector<uint32_t> tris;
    std::vector<uint32_t> duplicate_of;
    stratmesh::Delaunay2dInfo info = {};
    stratmesh::Status expected = stratmesh::Status::ok;

    size_t count() const { return xy.size() / 2; }
    void prepare(size_t work_bytes = 0, size_t tri_capacity = SIZE_MAX) {
        work.assign(work_bytes ? work_bytes : stratmesh::delaunay_2d_workspace_size(count()), 0);
        size_t cap = tri_capacity != SIZE_MAX ? tri_capacity : stratmesh::delaunay_2d_max_triangles(count());
        tris.assign(3 * cap + 3, 0);
        duplicate_of.assign(count() + 1, 0);
    }
    stratmesh::Status run() {
        info = {};
        return stratmesh::delaunay_2d(xy.data(), count(), 2 * sizeof(double), work.data(),
                                      work.size(), tris.data(), (tris.size() - 3) / 3, &info,
                                      duplicate_of.data());
    }
};

inline stratmesh::Options z_axis() {
    stratmesh::Options o = {};
    o.axis = stratmesh::Axis::z;
    return o;
}

inline void progress_sink(void* user, stratmesh::Phase, double) {
    ++*static_cast<size_t*>(user);
}

inline void run_jobs_in_order(void*, uint32_t count, stratmesh::JobFunction job, void* context) {
    for (uint32_t i = 0; i < count; ++i) job(context, i);
}

// reconstruct() inputs: ordinary shapes, layer options, float input, degenerate data and
// every error status the data and memory can produce.
inline std::vector<ReconstructCase> reconstruct_cases() {
    using shapes::Pose;
    using stratmesh::Status;
    std::vector<ReconstructCase> v;
    auto add = [&](const char* name, const shapes::Shape& s, stratmesh::Options o,
                   Status expected) -> ReconstructCase& {
        ReconstructCase c;
        c.name = name;
        c.xyz = s.xyz;
        c.options = o;
        c.expected = expected;
        v.push_back(std::move(c));
        return v.back();
    };
    stratmesh::Options o = z_axis();
    add("cylinder, automatic layers", shapes::cylinder(1500, Pose::z), o, Status::ok).prepare();
    stratmesh::Options six = z_axis();
    six.layer_count = 6;
    add("bumpy tube, 6 layers", shapes::bumpy_tube(2000, Pose::z), six, Status::ok).prepare();
    stratmesh::Options jobs = six;
    jobs.run_jobs = run_jobs_in_order;
    add("bumpy tube, 6 layers, triangulated ahead by jobs", shapes::bumpy_tube(2000, Pose::z), jobs,
        Status::ok).prepare();
    stratmesh::Options automatic = {};
    add("vase tilted, automatic axis", shapes::vase(1200, Pose::tilted), automatic, Status::ok).prepare();
    stratmesh::Options height = z_axis();
    height.layer_height = 0.7;
    add("scan grid (cocircular), layer height", shapes::scan_grid(900, Pose::z), height, Status::ok).prepare();
    {
        ReconstructCase& c = add("CT slices, cuts", shapes::ct_slices(1000, Pose::z), z_axis(), Status::ok);
        c.cuts = {-1.5, 0.25, 1.75, 9.0, -1.5};
        c.prepare();
    }
    {
        stratmesh::Options d = {};
        d.axis = stratmesh::Axis::direction;
        d.direction[0] = 1;
        d.layer_count = 3;
        ReconstructCase& c = add("cylinder along x, float32, direction", shapes::cylinder(800, Pose::x), d, Status::ok);
        c.float32 = true;
        c.prepare();
    }
    {
        // Duplicates and NaN points skipped.
        shapes::Shape s = shapes::noisy_tube(700, Pose::z);
        for (size_t i = 0; i < 60; ++i) s.xyz.insert(s.xyz.end(), s.point(i * 5), s.point(i * 5) + 3);
        s.xyz[3 * 10 + 1] = std::numeric_limits<double>::quiet_NaN();
        s.xyz[3 * 20 + 2] = std::numeric_limits<double>::infinity();
        stratmesh::Options k = z_axis();
        k.flags = stratmesh::skip_invalid_points;
        k.layer_count = 4;
        add("noisy tube, duplicates, skipped NaN/Inf", s, k, Status::ok).prepare();
        add("noisy tube, NaN refused", s, z_axis(), Status::invalid_point).prepare();
    }
    {
        stratmesh::Options p = z_axis();
        p.layer_count = 2;
        ReconstructCase& c = add("head, progress callback", shapes::head(1000, Pose::z), p, Status::ok);
        c.prepare();
    }
    add("half cylinder (closed across the open side)", shapes::half_cylinder(600, Pose::z), z_axis(), Status::ok).prepare();
    {
        // A plane through the axis surrounds no centre.
        shapes::Shape s = shapes::cylinder(3, Pose::z);
        s.xyz.clear();
        shapes::Rng rng(9);
        for (size_t i = 0; i < 1000; ++i) s.xyz.insert(s.xyz.end(), {rng.uniform(-1, 1), 0.0, rng.uniform(-3, 3)});
        stratmesh::Options l = z_axis();
        l.layer_count = 6;
        add("plane through the axis: not columnar", s, l, Status::not_columnar).prepare();
    }
    {
        shapes::Shape s = shapes::cylinder(300, Pose::z);
        for (size_t i = 0; i < s.size(); ++i) s.xyz[3 * i + 2] = 1.0;
        add("flat cloud", s, z_axis(), Status::flat_cloud).prepare();
    }
    {
        shapes::Shape s = shapes::cylinder(2, Pose::z);
        add("two points", s, z_axis(), Status::too_few_points).prepare();
    }
    {
        stratmesh::Options bad = {};
        bad.axis = stratmesh::Axis::direction;  // zero direction
        add("zero axis direction", shapes::cylinder(300, Pose::z), bad, Status::invalid_axis).prepare();
    }
    {
        stratmesh::Options bad = z_axis();
        bad.layer_height = -1;
        add("negative layer height", shapes::cylinder(300, Pose::z), bad, Status::invalid_layers).prepare();
    }
    add("workspace too small", shapes::cylinder(1000, Pose::z), z_axis(), Status::out_of_memory).prepare(4096);
    add("triangle array too small", shapes::cylinder(1000, Pose::z), z_axis(), Status::triangle_capacity).prepare(0, 10);
    return v;
}

inline std::vector<DelaunayCase> delaunay_cases() {
    using stratmesh::Status;
    std::vector<DelaunayCase> v;
    auto add = [&](const char* name, std::vector<double> xy, Status expected) -> DelaunayCase& {
        DelaunayCase c;
        c.name = name;
        c.xy = std::move(xy);
        c.expected = expected;
        v.push_back(std::move(c));
        return v.back();
    };
    shapes::Rng rng(7);
    std::vector<double> random;
    for (int i = 0; i < 3000; ++i) random.push_back(rng.uniform(-1, 1));
    add("1500 random points", random, Status::ok).prepare();
    std::vector<double> grid;
    for (int j = 0; j < 30; ++j)
        for (int i = 0; i < 30; ++i) grid.insert(grid.end(), {double(i), double(j)});
    add("30x30 grid (cocircular)", grid, Status::ok).prepare();
    std::vector<double> circle;
    for (int i = 0; i < 64; ++i) {
        double t = 2 * shapes::kPi * i / 64;
        circle.insert(circle.end(), {std::cos(t), std::sin(t)});
    }
    add("64 points on a circle", circle, Status::ok).prepare();
    std::vector<double> dup = random;
    dup.resize(400);
    dup.insert(dup.end(), random.begin(), random.begin() + 200);
    add("duplicates", dup, Status::ok).prepare();
    std::vector<double> line;
    for (int i = 0; i < 50; ++i) line.insert(line.end(), {double(i), 2.0 * i});
    add("collinear", line, Status::collinear).prepare();
    add("two distinct points", {0, 0, 1, 1, 0, 0, 1, 1}, Status::too_few_points).prepare();
    std::vector<double> nan = random;
    nan[101] = std::numeric_limits<double>::quiet_NaN();
    add("NaN", nan, Status::invalid_point).prepare();
    add("workspace too small", random, Status::out_of_memory).prepare(512);
    add("triangle array too small", random, Status::triangle_capacity).prepare(0, 5);
    return v;
}

}  // namespace no_heap

// ==== no allocation ===================================================================

TEST_CASE("the allocation counter sees malloc and every operator new") {
    MESSAGE("counting mechanism: " << std::string(alloc_counter::mechanism()));
    // Explicit calls of each overload (new-expressions may be elided by the optimiser).
    size_t n = alloc_counter::allocations_during([] {
        void* volatile p = ::operator new(8);
        ::operator delete(p);
        p = ::operator new[](8);
        ::operator delete[](p);
        p = ::operator new(64, std::align_val_t(64));
        ::operator delete(p, std::align_val_t(64));
        p = ::operator new[](64, std::align_val_t(64), std::nothrow);
        ::operator delete[](p, std::align_val_t(64), std::nothrow);
        p = ::operator new(8, std::nothrow);
        ::operator delete(p, std::nothrow);
        std::vector<double> v(100);
        p = v.data();
    });
    CHECK(n == 6);
    size_t m = alloc_counter::allocations_during([] {
        void* volatile p = std::malloc(16);
        std::free(p);
    });
    if (std::string(alloc_counter::mechanism()) != "operator new only") {
        CHECK(m == 1);
    }
}

TEST_CASE("reconstruct allocates nothing, on success and on every error status") {
    std::vector<no_heap::ReconstructCase> cases = no_heap::reconstruct_cases();
    size_t total = 0;
    for (no_heap::ReconstructCase& c : cases) {
        size_t progress_calls = 0;
        if (c.name.find("progress") != std::string::npos) {
            c.options.progress = no_heap::progress_sink;
            c.options.progress_user = &progress_calls;
        }
        stratmesh::Status s = stratmesh::Status::internal_error;
        size_t n = alloc_counter::allocations_during([&] { s = c.run(); });
        INFO(c.name << ": " << std::string(stratmesh::status_string(s)));
        CHECK(s == c.expected);
        CHECK(n == 0);
        if (c.options.progress) CHECK(progress_calls > 0);
        if (s == stratmesh::Status::ok) CHECK(c.count > 0);
        total += n;
    }
    MESSAGE("reconstruct: " << cases.size() << " calls, " << total << " allocations");
}

namespace {

// Keeps the triangles a stream emits, in storage sized before.
struct Emitted {
    size_t count = 0;
    std::vector<uint32_t>* triangles = nullptr;  // capacity reserved: no allocation
    static void take(void* user, const uint32_t* t, size_t count) {
        Emitted& e = *static_cast<Emitted*>(user);
        for (size_t k = 0; k < 3 * count && 3 * e.count + k < e.triangles->size(); ++k)
            (*e.triangles)[3 * e.count + k] = t[k];
        e.count += count;
    }
};

}  // namespace

TEST_CASE("the stream and its caps allocate nothing: open, every push, close, cap_ends") {
    const shapes::Shape s = shapes::bumpy_tube(3000, shapes::Pose::z);
    // Ten pushes of points sorted along the axis.
    std::vector<size_t> order(s.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return s.xyz[3 * a + 2] < s.xyz[3 * b + 2]; });
    std::vector<double> sorted;
    for (size_t i : order) sorted.insert(sorted.end(), &s.xyz[3 * i], &s.xyz[3 * i] + 3);
    stratmesh::Options o = no_heap::z_axis();
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(s.size(), o));
    stratmesh::Report report = {};
    std::vector<uint32_t> triangles(3 * stratmesh::reconstruct_max_triangles(s.size(), o));
    Emitted emitted;
    emitted.triangles = &triangles;
    std::vector<unsigned char> capping(stratmesh::cap_ends_workspace_size(s.size(), s.size() * 2));
    size_t capped = 0;
    std::vector<stratmesh::Status> statuses;
    statuses.reserve(16);
    size_t n = alloc_counter::allocations_during([&] {
        stratmesh::Stream* stream = nullptr;
        statuses.push_back(stratmesh::stream_open(o, work.data(), work.size(), Emitted::take, &emitted,
                                                  &report, &stream));
        const size_t per_push = s.size() / 10;
        for (size_t k = 0; k < 10; ++k) {
            size_t first = k * per_push, last = k == 9 ? s.size() : first + per_push;
            double top = k == 9 ? sorted[3 * (last - 1) + 2] : sorted[3 * last + 2];
            stratmesh::Cloud layer = {sorted.data() + 3 * first, last - first, 0, stratmesh::Scalar::float64};
            statuses.push_back(stratmesh::stream_push(stream, layer, top));
        }
        statuses.push_back(stratmesh::stream_close(stream));
        capped = emitted.count;
        stratmesh::Cloud all = {sorted.data(), s.size(), 0, stratmesh::Scalar::float64};
        statuses.push_back(stratmesh::cap_ends(all, o, capping.data(), capping.size(), triangles.data(),
                                               triangles.size() / 3, &capped, &report));
    });
    CHECK(n == 0);
    for (stratmesh::Status st : statuses) CHECK(st == stratmesh::Status::ok);
    CHECK(emitted.count == report.triangle_count);
    CHECK(report.points.used_count == s.size());
    CHECK(report.caps.closed_count == 2);
    CHECK(capped == emitted.count + report.caps.triangle_count);
}

TEST_CASE("find_parting allocates nothing: a fork found and labelled, no parting, refusals") {
    using shapes::Pose;
    const shapes::Shape fork = shapes::forked_tube(20000, Pose::z);
    const shapes::Shape tube = shapes::bumpy_tube(2000, Pose::x);
    std::vector<double> nan_cloud = tube.xyz;
    nan_cloud[7] = std::numeric_limits<double>::quiet_NaN();
    const stratmesh::Options z = no_heap::z_axis();
    stratmesh::Options x = {};
    x.axis = stratmesh::Axis::x;
    std::vector<unsigned char> work(stratmesh::find_parting_workspace_size(fork.size(), z));
    std::vector<uint8_t> labels(fork.size());
    stratmesh::Parting found = {}, none = {}, refused = {}, short_of = {};
    stratmesh::Status statuses[4] = {};
    const size_t n = alloc_counter::allocations_during([&] {
        statuses[0] = stratmesh::find_parting({fork.xyz.data(), fork.size(), 0, stratmesh::Scalar::float64},
                                              z, work.data(), work.size(), &found, labels.data());
        statuses[1] = stratmesh::find_parting({tube.xyz.data(), tube.size(), 0, stratmesh::Scalar::float64},
                                              x, work.data(), work.size(), &none, nullptr);
        statuses[2] = stratmesh::find_parting({nan_cloud.data(), tube.size(), 0, stratmesh::Scalar::float64},
                                              x, work.data(), work.size(), &refused, nullptr);
        statuses[3] = stratmesh::find_parting({fork.xyz.data(), fork.size(), 0, stratmesh::Scalar::float64},
                                              z, work.data(), 1000, &short_of, nullptr);
    });
    CHECK(n == 0);
    CHECK(statuses[0] == stratmesh::Status::ok);
    CHECK(found.above_branch_count == 2);
    CHECK(statuses[1] == stratmesh::Status::ok);
    CHECK(none.above_branch_count + none.below_branch_count == 0);
    CHECK(statuses[2] == stratmesh::Status::invalid_point);
    CHECK(statuses[3] == stratmesh::Status::out_of_memory);
}

TEST_CASE("join_branches allocates nothing: a fork's parts traced and planned, refusals") {
    // The fork's prongs stand on its dome: each is grafted onto a hole cut in it.
    const shapes::Shape fork = shapes::forked_tube(20000, shapes::Pose::z);
    const stratmesh::Options z = no_heap::z_axis();
    const stratmesh::Cloud cloud = {fork.xyz.data(), fork.size(), 0, stratmesh::Scalar::float64};
    std::vector<unsigned char> work(stratmesh::find_parting_workspace_size(fork.size(), z));
    std::vector<uint8_t> labels(fork.size());
    stratmesh::Parting parting = {};
    REQUIRE(stratmesh::find_parting(cloud, z, work.data(), work.size(), &parting, labels.data()) ==
            stratmesh::Status::ok);
    REQUIRE(parting.above_branch_count == 2);
    std::vector<uint32_t> triangles;
    for (uint8_t label : {stratmesh::kInTrunk, stratmesh::kFirstAboveBranch,
                          static_cast<uint8_t>(stratmesh::kFirstAboveBranch + 1)}) {
        std::vector<double> part;
        std::vector<uint32_t> index;
        for (size_t i = 0; i < fork.size(); ++i)
            if (labels[i] == label) {
                index.push_back(static_cast<uint32_t>(i));
                part.insert(part.end(), fork.point(i), fork.point(i) + 3);
            }
        stratmesh::Options o = z;
        if (label != stratmesh::kInTrunk) o.axis = stratmesh::Axis::automatic;
        std::vector<unsigned char> space(stratmesh::reconstruct_workspace_size(index.size(), o));
        std::vector<uint32_t> t(3 * stratmesh::reconstruct_max_triangles(index.size(), o));
        size_t count = 0;
        REQUIRE(stratmesh::reconstruct({part.data(), index.size(), 0, stratmesh::Scalar::float64}, o,
                                       space.data(), space.size(), t.data(), t.size() / 3, &count,
                                       nullptr) == stratmesh::Status::ok);
        for (size_t k = 0; k < 3 * count; ++k) triangles.push_back(index[t[k]]);
    }
    const size_t given = triangles.size() / 3;
    triangles.resize(3 * (given + stratmesh::join_branches_max_triangles(fork.size())));
    std::vector<unsigned char> joining(stratmesh::join_branches_workspace_size(fork.size(), given));
    stratmesh::JoinReport planned = {}, short_of = {};
    size_t count = given, refused_count = given;
    stratmesh::Status statuses[2] = {};
    const size_t n = alloc_counter::allocations_during([&] {
        statuses[0] = stratmesh::join_branches(cloud, z, parting, labels.data(), joining.data(),
                                               joining.size(), triangles.data(), triangles.size() / 3,
                                               &count, &planned);
        statuses[1] = stratmesh::join_branches(cloud, z, parting, labels.data(), joining.data(), 1000,
                                               triangles.data(), triangles.size() / 3, &refused_count,
                                               &short_of);
    });
    CHECK(n == 0);
    CHECK(statuses[0] == stratmesh::Status::ok);
    CHECK(planned.grafted_branch_count == 2);  // the fork stands on a dome: grafted, holes and all
    CHECK(statuses[1] == stratmesh::Status::out_of_memory);
}

TEST_CASE("delaunay_2d allocates nothing, on success and on every error status") {
    std::vector<no_heap::DelaunayCase> cases = no_heap::delaunay_cases();
    size_t total = 0;
    for (no_heap::DelaunayCase& c : cases) {
        stratmesh::Status s = stratmesh::Status::internal_error;
        size_t n = alloc_counter::allocations_during([&] { s = c.run(); });
        INFO(c.name << ": " << std::string(stratmesh::status_string(s)));
        CHECK(s == c.expected);
        CHECK(n == 0);
        if (s == stratmesh::Status::ok) CHECK(c.info.triangle_count > 0);
        total += n;
    }
    MESSAGE("delaunay_2d: " << cases.size() << " calls, " << total << " allocations");
}

TEST_CASE("the sizing functions, predicates and status strings allocate nothing") {
    stratmesh::Options o = no_heap::z_axis();
    double a[2] = {0, 0}, b[2] = {1, 0}, c[2] = {0, 1}, d[2] = {0.5, 0.5};
    volatile size_t sink = 0;
    size_t n = alloc_counter::allocations_during([&] {
        sink = sink + stratmesh::reconstruct_workspace_size(100000, o);
        sink = sink + stratmesh::reconstruct_max_triangles(100000, o);
        sink = sink + stratmesh::delaunay_2d_workspace_size(100000);
        sink = sink + stratmesh::delaunay_2d_max_triangles(100000);
        sink = sink + stratmesh::cap_ends_workspace_size(100000, 200000);
        sink = sink + stratmesh::find_parting_workspace_size(100000, o);
        sink = sink + stratmesh::join_branches_workspace_size(100000, 200000);
        sink = sink + stratmesh::join_branches_max_triangles(100000);
        sink = sink + (stratmesh::orient2d(a, b, c) > 0) + (stratmesh::incircle(a, b, c, d) > 0);
        sink = sink + (stratmesh::status_string(stratmesh::Status::collinear)[0] != 0);
    });
    CHECK(n == 0);
}

namespace {
void allocating_progress(void* user, stratmesh::Phase, double) {
    void* volatile p = std::malloc(32);
    std::free(p);
    int* volatile q = new int(1);
    delete q;
    ++*static_cast<size_t*>(user);
}
}  // namespace

// The control: the counter does see an allocation made during the call (here by the
// caller's own progress callback), so the zero counts above are not vacuous.
TEST_CASE("the control: an allocation inside reconstruct's call is counted") {
    std::vector<no_heap::ReconstructCase> cases = no_heap::reconstruct_cases();
    no_heap::ReconstructCase& c = cases[0];
    size_t calls = 0;
    c.options.progress = allocating_progress;
    c.options.progress_user = &calls;
    stratmesh::Status s = stratmesh::Status::internal_error;
    size_t n = alloc_counter::allocations_during([&] { s = c.run(); });
    CHECK(s == stratmesh::Status::ok);
    REQUIRE(calls > 0);
    if (std::string(alloc_counter::mechanism()) == "operator new only") {
        CHECK(n == calls);
    } else {
        CHECK(n == 2 * calls);
    }
}

// ==== threads ========================================================================

namespace {

struct Outcome {
    stratmesh::Status status = stratmesh::Status::internal_error;
    size_t count = 0;
    std::vector<uint32_t> tris;
    std::vector<unsigned char> report_bytes;  // the report's numbers, pointers cleared
};

Outcome capture(no_heap::ReconstructCase& c, stratmesh::Status s) {
    Outcome o;
    o.status = s;
    o.count = c.count;
    o.tris.assign(c.tris.begin(), c.tris.begin() + static_cast<std::ptrdiff_t>(3 * c.count));
    stratmesh::Report r = c.report;
    r.layers.info = nullptr;
    r.detail = nullptr;
    o.report_bytes.resize(sizeof r);
    std::memcpy(o.report_bytes.data(), &r, sizeof r);
    return o;
}

// Repeats the call a few times so the two threads overlap for certain.
Outcome run_repeatedly(no_heap::ReconstructCase& c, int times) {
    Outcome last;
    for (int i = 0; i < times; ++i) {
        std::fill(c.work.begin(), c.work.end(), static_cast<unsigned char>(0xA5 + i));
        stratmesh::Status s = c.run();
        last = capture(c, s);
    }
    return last;
}

}  // namespace

TEST_CASE("two threads with separate workspaces give the same bytes as sequential calls") {
    std::vector<no_heap::ReconstructCase> all = no_heap::reconstruct_cases();
    // A pair of different clouds and options, both successful.
    no_heap::ReconstructCase& a = all[1];  // bumpy tube, 6 layers
    no_heap::ReconstructCase& b = all[2];  // vase, tilted, automatic axis
    REQUIRE(a.expected == stratmesh::Status::ok);
    REQUIRE(b.expected == stratmesh::Status::ok);

    Outcome seq_a = run_repeatedly(a, 1);
    Outcome seq_b = run_repeatedly(b, 1);
    REQUIRE(seq_a.status == stratmesh::Status::ok);
    REQUIRE(seq_b.status == stratmesh::Status::ok);

    Outcome par_a, par_b;
    std::thread ta([&] { par_a = run_repeatedly(a, 8); });
    std::thread tb([&] { par_b = run_repeatedly(b, 8); });
    ta.join();
    tb.join();

    CHECK(par_a.status == seq_a.status);
    CHECK(par_b.status == seq_b.status);
    CHECK(par_a.count == seq_a.count);
    CHECK(par_b.count == seq_b.count);
    CHECK(par_a.tris == seq_a.tris);
    CHECK(par_b.tris == seq_b.tris);
    CHECK(par_a.report_bytes == seq_a.report_bytes);
    CHECK(par_b.report_bytes == seq_b.report_bytes);
}

TEST_CASE("two threads triangulating in 2D give the same bytes as sequential calls") {
    std::vector<no_heap::DelaunayCase> all = no_heap::delaunay_cases();
    no_heap::DelaunayCase& a = all[0];
    no_heap::DelaunayCase& b = all[1];
    REQUIRE(a.run() == stratmesh::Status::ok);
    std::vector<uint32_t> seq_a = a.tris;
    REQUIRE(b.run() == stratmesh::Status::ok);
    std::vector<uint32_t> seq_b = b.tris;
    stratmesh::Status sa = stratmesh::Status::internal_error, sb = sa;
    std::thread ta([&] { for (int i = 0; i < 8; ++i) sa = a.run(); });
    std::thread tb([&] { for (int i = 0; i < 8; ++i) sb = b.run(); });
    ta.join();
    tb.join();
    CHECK(sa == stratmesh::Status::ok);
    CHECK(sb == stratmesh::Status::ok);
    CHECK(a.tris == seq_a);
    CHECK(b.tris == seq_b);
}

// ==== stack ==========================================================================

#if defined(NO_HEAP_STACK_TEST)

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define NO_HEAP_STACK_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer) || __has_feature(hwaddress_sanitizer)
#define NO_HEAP_STACK_SANITIZER 1
#endif
#endif

namespace {

constexpr size_t kStackBytes = 1u << 20;
constexpr unsigned char kPaint = 0xC5;

struct Job {
    void (*call)(void*);
    void* arg;
    const unsigned char* stack_lo;  // the painted region's lowest byte
    size_t used;                    // result: bytes below the calling frame touched
};

// Reads below the stack pointer: left out of the sanitizers' instrumentation.
#if defined(__GNUC__)
__attribute__((noinline, no_sanitize("address", "thread")))
#endif
size_t painted_bytes(const unsigned char* lo) {
    size_t first = 0;
    while (first < kStackBytes && lo[first] == kPaint) ++first;
    return first;
}

#if defined(__GNUC__)
__attribute__((noinline))
#endif
void* thread_body(void* p) {
    Job* job = static_cast<Job*>(p);
    volatile char marker = 0;
    uintptr_t entry = reinterpret_cast<uintptr_t>(&marker);
    job->call(job->arg);
    // Measured here, before the thread's own teardown (which runs from an outer frame and
    // may dig deeper than the call did) can touch the painted region.
    uintptr_t deepest = reinterpret_cast<uintptr_t>(job->stack_lo) + painted_bytes(job->stack_lo);
    job->used = entry > deepest ? static_cast<size_t>(entry - deepest) : 0;
    return nullptr;
}

// Bytes of stack below the caller's frame that `call` touched (the stack grows down).
size_t stack_used(void (*call)(void*), void* arg) {
    std::vector<unsigned char> stack(kStackBytes + 4096);
    uintptr_t base = reinterpret_cast<uintptr_t>(stack.data());
    uintptr_t aligned = (base + 4095) & ~static_cast<uintptr_t>(4095);
    unsigned char* lo = reinterpret_cast<unsigned char*>(aligned);
    std::memset(lo, kPaint, kStackBytes);
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setstack(&attr, lo, kStackBytes);
    Job job = {call, arg, lo, 0};
    pthread_t thread;
    int rc = pthread_create(&thread, &attr, thread_body, &job);
    pthread_attr_destroy(&attr);
    REQUIRE(rc == 0);
    pthread_join(thread, nullptr);
    return job.used;
}

void call_nothing(void*) {}
void call_reconstruct(void* p) { (void)static_cast<no_heap::ReconstructCase*>(p)->run(); }
void call_delaunay(void* p) { (void)static_cast<no_heap::DelaunayCase*>(p)->run(); }

}  // namespace

TEST_CASE("stack high-water mark of reconstruct and delaunay_2d stays below 16 KiB") {
    size_t baseline = stack_used(call_nothing, nullptr);
    size_t worst_r = 0, worst_d = 0;
    std::vector<no_heap::ReconstructCase> rc = no_heap::reconstruct_cases();
    for (no_heap::ReconstructCase& c : rc) {
        size_t used = stack_used(call_reconstruct, &c);
        INFO(c.name);
        CHECK(c.report.points.in_count == c.cloud().count);
        if (used > worst_r) worst_r = used;
    }
    std::vector<no_heap::DelaunayCase> dc = no_heap::delaunay_cases();
    for (no_heap::DelaunayCase& c : dc) {
        size_t used = stack_used(call_delaunay, &c);
        if (used > worst_d) worst_d = used;
    }
    MESSAGE("stack used below the calling frame: reconstruct " << worst_r << " bytes, delaunay_2d "
            << worst_d << " bytes (empty call: " << baseline << " bytes)");
#if !defined(NO_HEAP_STACK_SANITIZER)
    CHECK(worst_r < 16 * 1024);
    CHECK(worst_d < 16 * 1024);
    CHECK(worst_r > baseline);  // the measurement sees the calls at all
    CHECK(worst_d > baseline);
#endif
}

#endif  // NO_HEAP_STACK_TEST
