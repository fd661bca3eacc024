// fuzz_join: stratmesh::join_branches on surfaces and partings built from the fuzzer's
// bytes, two ways (the first byte):
//  - raw: a cloud of fuzz_cloud.h, triangles with any indices (some past the cloud), labels
//    and a Parting (branch counts past kMaxBranches, any axis, cuts and gap) from the bytes;
//  - forked: a trunk with two to four prongs on its rim (radii, offsets, heights and point
//    counts from the bytes), meshed apart by find_parting's labels as the tool's
//    --parts apart does, then joined.
// Buffers are exact: the workspace is join_branches_workspace_size(), the triangle array
// ends where its allocation ends, so any overrun trips AddressSanitizer.
//
// Checked after each call: the status is a documented one; on every status but ok the
// triangles are unchanged (on triangle_capacity the count needed is above the capacity);
// on ok the given triangles are kept in their order but removed_triangle_count of them, the
// count is the kept ones and junction_triangle_count (at most
// join_branches_max_triangles()), nothing is written past them, every new index names a
// valid point, no new triangle repeats one, the sides joined and left apart are at most the
// sides that part, and where
// the given surface was an oriented edge- and vertex-manifold (tests/support/mesh_check.h),
// the joined one still is.
#include "fuzz_cloud.h"
#include "fuzz_common.h"

#include "stratmesh.h"
#include "support/mesh_check.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <vector>

namespace {

using stratmesh_fuzz::Bytes;

struct Surface {
    std::vector<double> xyz;  // packed float64, as the library reads the cloud
    stratmesh::Cloud cloud;
    std::vector<uint32_t> triangles;
    std::vector<uint8_t> label;
    stratmesh::Parting parting{};
    stratmesh::Options options{};
};

bool manifold(const Surface& s, const std::vector<uint32_t>& t) {
    for (uint32_t i : t)
        if (i >= s.cloud.count) return false;
    std::vector<double> finite(s.xyz);
    for (double& v : finite)
        if (!std::isfinite(v)) v = 0;
    mesh_check::Input in;
    in.points = finite.data();
    in.point_count = s.cloud.count;
    in.triangles = t.data();
    in.triangle_count = t.size() / 3;
    in.self_intersections = false;
    const mesh_check::Result r = mesh_check::check(in);
    return r.manifold() && r.degenerate == 0;
}

void raw_surface(Bytes& in, Surface& s, stratmesh_fuzz::FuzzCloud& fc) {
    fc = stratmesh_fuzz::read_cloud(in, 400);
    s.xyz = fc.xyz;
    s.cloud = fc.cloud();
    const uint32_t n = static_cast<uint32_t>(fc.n);
    const uint32_t triangles = in.below(800);
    for (uint32_t k = 0; k < 3 * triangles; ++k) s.triangles.push_back(in.below(n + 2));
    const uint8_t labels[4] = {stratmesh::kInTrunk, stratmesh::kFirstAboveBranch,
                               static_cast<uint8_t>(stratmesh::kFirstAboveBranch + 1),
                               stratmesh::kFirstBelowBranch};
    for (uint32_t i = 0; i < n; ++i) {
        const uint8_t b = in.u8();
        s.label.push_back(b < 240 ? labels[b % 4] : b);
    }
    s.parting.above_branch_count = in.below(stratmesh::kMaxBranches + 4);
    s.parting.below_branch_count = in.below(4);
    const uint8_t axis = in.u8();
    if (axis < 200) {
        s.parting.axis[axis % 3] = 1;
    } else {
        for (double& a : s.parting.axis) a = in.raw_double();
    }
    s.parting.above = in.centered(64) * fc.grid;
    s.parting.below = in.centered(64) * fc.grid;
    s.parting.gap = in.u8() < 200 ? (1 + in.below(16)) * fc.grid : in.raw_double();
    s.options.flags = in.u8() & 1 ? stratmesh::skip_invalid_points : 0u;
}

// A trunk of radius R around the z axis for z in [0, H] and prongs of radius r on circles
// inside its rim for z in [H, 2H], golden-angle spirals.
void forked_surface(Bytes& in, Surface& s) {
    const double R = 5 + in.below(11), H = 20 + in.below(41);
    const uint32_t prongs = 2 + in.below(3);
    const double r = 1.5 + 0.25 * in.below(7);
    const double golden = 3.14159265358979323846 * (3 - std::sqrt(5.0));
    auto spiral = [&](uint32_t count, double cx, double cy, double radius, double z0, double z1) {
        for (uint32_t i = 0; i < count; ++i) {
            const double t = i, angle = golden * t;
            s.xyz.insert(s.xyz.end(), {cx + radius * std::cos(angle), cy + radius * std::sin(angle),
                                       z0 + (z1 - z0) * (t + 0.5) / count});
        }
    };
    const double density = 0.6 + 0.1 * in.below(8);  // points per unit of area
    spiral(static_cast<uint32_t>(density * 2 * 3.14159265358979323846 * R * H), 0, 0, R, 0, H);
    for (uint32_t k = 0; k < prongs; ++k) {
        const double angle = 2 * 3.14159265358979323846 * (k + 0.1 * in.below(4)) / prongs;
        const double at = R - r - 0.1 * in.below(10);
        spiral(static_cast<uint32_t>(density * 2 * 3.14159265358979323846 * r * H), at * std::cos(angle),
               at * std::sin(angle), r, H, 2 * H);
    }
    s.cloud = {s.xyz.data(), s.xyz.size() / 3, 0, stratmesh::Scalar::float64};
    s.options.axis = stratmesh::Axis::z;
    s.label.assign(s.cloud.count, 0);
    std::vector<unsigned char> work(stratmesh::find_parting_workspace_size(s.cloud.count, s.options));
    if (stratmesh::find_parting(s.cloud, s.options, work.data(), work.size(), &s.parting,
                                s.label.data()) != stratmesh::Status::ok)
        return;
    for (unsigned label = 0; label < 256; ++label) {
        std::vector<double> part;
        std::vector<uint32_t> index;
        for (size_t i = 0; i < s.cloud.count; ++i)
            if (s.label[i] == label) {
                index.push_back(static_cast<uint32_t>(i));
                part.insert(part.end(), &s.xyz[3 * i], &s.xyz[3 * i] + 3);
            }
        if (index.empty()) continue;
        stratmesh::Options o = s.options;
        if (label != stratmesh::kInTrunk) o.axis = stratmesh::Axis::automatic;
        const stratmesh::Cloud c = {part.data(), index.size(), 0, stratmesh::Scalar::float64};
        std::vector<unsigned char> space(stratmesh::reconstruct_workspace_size(c.count, o));
        std::vector<uint32_t> t(3 * stratmesh::reconstruct_max_triangles(c.count, o));
        size_t count = 0;
        if (stratmesh::reconstruct(c, o, space.data(), space.size(), t.data(), t.size() / 3, &count,
                                   nullptr) != stratmesh::Status::ok)
            continue;
        for (size_t k = 0; k < 3 * count; ++k) s.triangles.push_back(index[t[k]]);
    }
}

bool finite_point(const Surface& s, uint32_t i) {
    return std::isfinite(s.xyz[3 * i]) && std::isfinite(s.xyz[3 * i + 1]) &&
           std::isfinite(s.xyz[3 * i + 2]);
}

bool documented(stratmesh::Status s) {
    using stratmesh::Status;
    return s == Status::ok || s == Status::invalid_argument || s == Status::too_many_points ||
           s == Status::invalid_point || s == Status::invalid_axis || s == Status::out_of_memory ||
           s == Status::triangle_capacity;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Bytes in(data, size);
    Surface s;
    stratmesh_fuzz::FuzzCloud fc;
    const bool raw = in.u8() & 1;
    if (raw)
        raw_surface(in, s, fc);
    else
        forked_surface(in, s);
    const size_t n = s.cloud.count, given = s.triangles.size() / 3;
    const bool was_manifold = manifold(s, s.triangles);
    const size_t room = in.u8() < 200 ? stratmesh::join_branches_max_triangles(n) : in.below(64);
    const size_t capacity = given + room;
    const size_t bytes = stratmesh::join_branches_workspace_size(n, given);
    const size_t short_by = in.u8() < 240 ? 0 : 1 + in.below(4096);
    std::vector<unsigned char> work(bytes > short_by ? bytes - short_by : 1, 0xA5);
    std::vector<uint32_t> t(s.triangles);
    t.resize(3 * capacity, 0xDEADBEEFu);
    const std::vector<uint32_t> before = t;
    size_t count = given;
    stratmesh::JoinReport report;
    const stratmesh::Status status = stratmesh::join_branches(
        s.cloud, s.options, s.parting, n ? s.label.data() : nullptr, work.data(),
        bytes > short_by ? bytes - short_by : 0, t.empty() ? nullptr : t.data(), capacity, &count,
        &report);
    STRATMESH_FUZZ_CHECK(documented(status), "an undocumented status");
    STRATMESH_FUZZ_CHECK(report.workspace_used_bytes <= (bytes > short_by ? bytes - short_by : 0),
                         "workspace_used_bytes beyond the workspace");
    if (status != stratmesh::Status::ok) {
        STRATMESH_FUZZ_CHECK(t == before, "triangles changed on a failure");
        if (status == stratmesh::Status::triangle_capacity)
            STRATMESH_FUZZ_CHECK(count > capacity, "triangle_capacity but the count fits");
        return 0;
    }
    STRATMESH_FUZZ_CHECK(report.removed_triangle_count <= given, "more triangles removed than given");
    const size_t kept = given - report.removed_triangle_count;
    STRATMESH_FUZZ_CHECK(count == kept + report.junction_triangle_count, "count != kept + added");
    STRATMESH_FUZZ_CHECK(report.junction_triangle_count <= stratmesh::join_branches_max_triangles(n),
                         "more triangles than join_branches_max_triangles()");
    size_t matched = 0;
    for (size_t g = 0; g < given && matched < kept; ++g)
        if (std::equal(&before[3 * g], &before[3 * g] + 3, &t[3 * matched])) ++matched;
    STRATMESH_FUZZ_CHECK(matched == kept, "the triangles kept are not the given ones in order");
    const auto added_end = static_cast<std::ptrdiff_t>(3 * count);
    STRATMESH_FUZZ_CHECK(std::equal(before.begin() + added_end, before.end(), t.begin() + added_end),
                         "a write past the triangles added");
    const uint32_t sides = static_cast<uint32_t>(s.parting.above_branch_count > 0) +
                           static_cast<uint32_t>(s.parting.below_branch_count > 0);
    STRATMESH_FUZZ_CHECK(report.joined_side_count + report.apart_side_count <= sides,
                         "more sides than part");
    for (size_t k = 3 * kept; k < 3 * count; k += 3) {
        for (size_t j = 0; j < 3; ++j)
            STRATMESH_FUZZ_CHECK(t[k + j] < n && finite_point(s, t[k + j]),
                                 "a new triangle names no valid point");
        STRATMESH_FUZZ_CHECK(t[k] != t[k + 1] && t[k + 1] != t[k + 2] && t[k] != t[k + 2],
                             "a new triangle repeats a vertex");
    }
    if (was_manifold) {
        t.resize(3 * count);
        STRATMESH_FUZZ_CHECK(manifold(s, t), "a manifold surface joined is no longer one");
    }
    return 0;
}
