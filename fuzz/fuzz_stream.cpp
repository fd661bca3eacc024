// fuzz_stream: the streaming reconstruction on clouds built from the fuzzer's bytes (see
// fuzz_cloud.h), pushed in pieces: sorted along the axis and cut at the fuzzer's chosen
// places, or in input order with arbitrary tops (out-of-order pushes), with NaN and
// infinite tops, empty pushes, a workspace the fuzzer sizes (exactly
// stream_workspace_size() of its choice: too small ones must refuse pushes, not overrun).
//
// Checked: every status is a documented one; a refused push changes nothing (the next
// accepted push's indices continue from the accepted ones); the report's counts add up;
// emitted indices are below the points accepted; on a successful close the emitted mesh is
// an oriented edge- and vertex-manifold whose vertices are distinct valid points, with
// points_used of them; and, when the pushes were sorted, all accepted, no point lies near a
// cut and the origin was given, the output equals reconstruct() of the accepted points
// with cuts at the pushes' tops, triangle for triangle (the documented equivalence).
// Then cap_ends() on the emitted mesh: an oriented manifold still, its loops closed or
// counted open, and with the equivalence, reconstruct()'s add_caps triangles (the caps
// and any edges under fins it flipped); on a soup
// made of the mesh by moving corners, a documented status and no write past its buffers.
#include "fuzz_cloud.h"
#include "fuzz_common.h"

#include "stratmesh.h"
#include "support/mesh_check.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace {

using stratmesh::Status;
using stratmesh_fuzz::Bytes;

struct Emitted {
    std::vector<uint32_t> triangles;
    const size_t* accepted = nullptr;  // points accepted when the callback runs
    static void take(void* user, const uint32_t* t, size_t count) {
        Emitted& e = *static_cast<Emitted*>(user);
        for (size_t k = 0; k < 3 * count; ++k)
            STRATMESH_FUZZ_CHECK(t[k] < *e.accepted, "an emitted index beyond the points pushed");
        e.triangles.insert(e.triangles.end(), t, t + 3 * count);
    }
};

// What stream_push may return for a push it refuses (and then must not change anything).
bool is_refusal(Status s) {
    switch (s) {
    case Status::invalid_point:
    case Status::invalid_layers:
    case Status::invalid_origin:
    case Status::out_of_order:
    case Status::out_of_memory:
    case Status::too_many_points:
        return true;
    default:
        return false;
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Bytes in(data, size);
    const stratmesh_fuzz::FuzzCloud fc = stratmesh_fuzz::read_cloud(in, 2500);
    const size_t n = fc.n;

    // ---- options
    stratmesh::Options options = {};
    const uint8_t ocfg = in.u8();
    options.axis = static_cast<stratmesh::Axis>(ocfg % 5);
    if (options.axis == stratmesh::Axis::direction)
        for (double& d : options.direction) d = static_cast<double>(in.centered(3));
    if (ocfg & 0x08) options.flags |= stratmesh::skip_invalid_points;
    if (ocfg & 0x80) options.flags |= stratmesh::ends_are_cuts;
    const bool origin_given = (ocfg & 0x10) != 0;
    if (origin_given) {
        options.flags |= stratmesh::origin_given;
        for (double& o : options.origin) o = in.centered(8) * fc.grid;
    }
    const bool sorted = (ocfg & 0x20) == 0;
    const size_t held = (ocfg & 0x40) ? in.below(static_cast<uint32_t>(n + 40)) : n + 16;

    // The axis as the library will take it, to sort and cut along.
    double axis[3] = {0, 0, 1};
    if (options.axis == stratmesh::Axis::x) axis[0] = 1, axis[2] = 0;
    if (options.axis == stratmesh::Axis::y) axis[1] = 1, axis[2] = 0;
    if (options.axis == stratmesh::Axis::direction) {
        double len = std::sqrt(options.direction[0] * options.direction[0] +
                               options.direction[1] * options.direction[1] +
                               options.direction[2] * options.direction[2]);
        for (int k = 0; k < 3; ++k) axis[k] = len > 0 ? options.direction[k] / len : 0;
    }
    auto height = [&](size_t i) {
        const double* p = &fc.xyz[3 * i];
        return p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
    };
    std::vector<size_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = i;
    if (sorted) {
        // Invalid points first (any push takes them), then by height.
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
            double ha = height(a), hb = height(b);
            bool fa = std::isfinite(ha), fb = std::isfinite(hb);
            if (fa != fb) return !fa;
            return fa && ha < hb;
        });
    }
    // The points in push order, as the library is given them (same scalar type and stride).
    std::vector<unsigned char> pushed(fc.buffer.size());
    const size_t record = fc.f32 ? 12 : 24;
    for (size_t k = 0; k < n; ++k)
        std::memcpy(pushed.data() + k * fc.step, fc.buffer.data() + order[k] * fc.step, record);

    // ---- the stream
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(held, options));
    stratmesh::Report report;
    std::memset(static_cast<void*>(&report), 0xA5, sizeof report);
    std::vector<stratmesh::LayerInfo> layers(in.below(6));
    report.layers.info = layers.empty() ? nullptr : layers.data();
    report.layers.info_capacity = layers.size();
    Emitted emitted;
    size_t accepted = 0;
    emitted.accepted = &accepted;
    stratmesh::Stream* stream = nullptr;
    Status open = stratmesh::stream_open(options, work.empty() ? nullptr : work.data(), work.size(),
                                         Emitted::take, &emitted, &report, &stream);
    if (open != Status::ok) {
        STRATMESH_FUZZ_CHECK(open == Status::invalid_axis || open == Status::out_of_memory ||
                                 open == Status::invalid_argument,
                             "stream_open returned an undocumented status");
        STRATMESH_FUZZ_CHECK(open != Status::invalid_axis || options.axis == stratmesh::Axis::automatic ||
                                 options.axis == stratmesh::Axis::direction,
                             "invalid_axis for a coordinate axis");
        return 0;
    }
    std::vector<unsigned char> accepted_points;  // the accepted pushes, concatenated
    std::vector<double> tops;                    // accepted pushes' tops
    bool all_accepted = true;
    size_t next = 0;
    while (next < n || (in.remaining() > 0 && in.u8() % 8 == 0)) {
        size_t count = n - next;
        if (in.remaining() > 0) count = std::min<size_t>(count, in.below(static_cast<uint32_t>(n / 2 + 8)));
        double top;
        const uint8_t tcfg = in.u8();
        if (tcfg % 16 == 0) {
            top = in.raw_double();
        } else if (!sorted) {
            top = in.centered(8 * fc.grid_range) * fc.grid;
        } else {
            // Half-way to the next push's lowest height, or above the last point.
            double h = -HUGE_VAL, h_next = HUGE_VAL;
            for (size_t k = next; k < next + count; ++k) h = std::max(h, height(order[k]));
            if (next + count < n) h_next = height(order[next + count]);
            top = std::isfinite(h_next) ? (std::isfinite(h) ? (h + h_next) / 2 : h_next) : h + 1;
            if (!std::isfinite(top)) top = 0;
        }
        const stratmesh::Cloud piece = {count ? pushed.data() + next * fc.step : nullptr, count,
                                        fc.stride, fc.f32 ? stratmesh::Scalar::float32 : stratmesh::Scalar::float64};
        const size_t before_in = report.points.in_count, before_triangles = report.triangle_count;
        Status s = stratmesh::stream_push(stream, piece, top);
        if (s == Status::ok) {
            accepted += count;
            accepted_points.resize(accepted * fc.step);
            for (size_t k = 0; k < count; ++k)
                std::memcpy(accepted_points.data() + (accepted - count + k) * fc.step,
                            pushed.data() + (next + k) * fc.step, record);
            tops.push_back(top);
            STRATMESH_FUZZ_CHECK(report.points.in_count == before_in + count, "points_in after an accepted push");
        } else {
            STRATMESH_FUZZ_CHECK(is_refusal(s), stratmesh::status_string(s));
            all_accepted = false;
            STRATMESH_FUZZ_CHECK(report.points.in_count == before_in && report.triangle_count == before_triangles,
                                 "a refused push changed the stream");
        }
        STRATMESH_FUZZ_CHECK(report.points.in_count == report.points.used_count + report.points.duplicate_count + report.points.rejected_count + report.points.unused_count,
                             "report counts do not add up after a push");
        next += count;
        if (count == 0 && next >= n) break;
    }
    // `accepted` counts the pushed points; emitted indices must stay below it.
    const Status closed = stratmesh::stream_close(stream);
    switch (closed) {
    case Status::ok: case Status::too_few_points: case Status::flat_cloud: case Status::not_columnar:
        break;
    default:
        stratmesh_fuzz::fail("stream_close returned an unexpected status", stratmesh::status_string(closed));
    }
    STRATMESH_FUZZ_CHECK(report.points.in_count == accepted, "points_in != points accepted");
    STRATMESH_FUZZ_CHECK(report.points.in_count == report.points.used_count + report.points.duplicate_count + report.points.rejected_count + report.points.unused_count,
                         "report counts do not add up at the close");
    STRATMESH_FUZZ_CHECK(emitted.triangles.size() == 3 * report.triangle_count, "emitted != triangle_count");
    if (closed != Status::ok) return 0;

    // ---- the mesh over the accepted points
    const size_t m = accepted;
    std::vector<double> xyz(3 * m);
    std::vector<char> valid(m);
    for (size_t i = 0; i < m; ++i) {
        const unsigned char* p = accepted_points.data() + i * fc.step;
        for (size_t k = 0; k < 3; ++k) {
            if (fc.f32) {
                float v;
                std::memcpy(&v, p + 4 * k, 4);
                xyz[3 * i + k] = static_cast<double>(v);
            } else {
                std::memcpy(&xyz[3 * i + k], p + 8 * k, 8);
            }
        }
        valid[i] = std::isfinite(xyz[3 * i]) && std::isfinite(xyz[3 * i + 1]) && std::isfinite(xyz[3 * i + 2]);
    }
    const std::vector<uint32_t>& t = emitted.triangles;
    std::vector<char> used(m, 0);
    for (uint32_t v : t) {
        STRATMESH_FUZZ_CHECK(valid[v], "a NaN/Inf point is a vertex");
        used[v] = 1;
    }
    size_t vertices = 0;
    for (char u : used) vertices += u != 0;
    STRATMESH_FUZZ_CHECK(vertices == report.points.used_count, "points_used != vertices used");
    std::vector<double> finite(xyz);
    for (double& v : finite)
        if (!std::isfinite(v)) v = 0;
    mesh_check::Input mi;
    mi.points = finite.data();
    mi.point_count = m;
    mi.triangles = t.data();
    mi.triangle_count = t.size() / 3;
    mi.self_intersections = false;
    const mesh_check::Result r = mesh_check::check(mi);
    STRATMESH_FUZZ_CHECK(r.bad_indices == 0 && r.degenerate == 0, "bad or degenerate triangles");
    STRATMESH_FUZZ_CHECK(r.nonmanifold_edges == 0 && r.inconsistent_edges == 0, "not an oriented edge-manifold");
    STRATMESH_FUZZ_CHECK(r.nonmanifold_vertices == 0, "not vertex-manifold");

    // ---- its caps: cap_ends() keeps it an oriented manifold and closes its loops, or says
    // which stay open; on a soup made of it by moving some corners, it stays in its buffers
    const stratmesh::Cloud whole = {accepted_points.empty() ? nullptr : accepted_points.data(), m, fc.stride,
                                    fc.f32 ? stratmesh::Scalar::float32 : stratmesh::Scalar::float64};
    std::vector<uint32_t> capped(t);
    const bool soup = in.remaining() > 0 && in.u8() % 4 == 0;
    for (size_t k = 0; soup && k < capped.size() && in.remaining() > 0; k += 1 + in.below(16))
        capped[k] = in.below(static_cast<uint32_t>(m));
    const size_t surface = capped.size() / 3;
    const std::vector<uint32_t> given(capped);
    capped.resize(3 * stratmesh::reconstruct_max_triangles(m, options) + 3, 0xFEFEFEFEu);
    std::vector<unsigned char> cap_work(stratmesh::cap_ends_workspace_size(m, surface));
    stratmesh::Report cap_report = {};
    size_t capped_count = surface;
    const Status capping = stratmesh::cap_ends(whole, options, cap_work.data(), cap_work.size(), capped.data(),
                                               capped.size() / 3 - 1, &capped_count, &cap_report);
    if (soup) {
        // A soup's loops can need more cap triangles than stratmesh's own surface ever does.
        STRATMESH_FUZZ_CHECK(capping == Status::ok || capping == Status::invalid_argument ||
                                 capping == Status::triangle_capacity,
                             "cap_ends on a soup: an undocumented status");
        if (capping == Status::triangle_capacity)
            STRATMESH_FUZZ_CHECK(capped_count > capped.size() / 3 - 1,
                                 "cap_ends: triangle_capacity without the count it needs");
    } else {
        STRATMESH_FUZZ_CHECK(capping == Status::ok, "cap_ends fails on the stream's surface");
    }
    STRATMESH_FUZZ_CHECK(capped.back() == 0xFEFEFEFEu, "cap_ends wrote past the capacity");
    if (capping != Status::ok)
        STRATMESH_FUZZ_CHECK(std::equal(given.begin(), given.end(), capped.begin()),
                             "cap_ends changed the triangles on a failure");
    STRATMESH_FUZZ_CHECK(cap_report.workspace_used_bytes <= cap_work.size(), "cap_ends beyond its workspace");
    if (capping == Status::ok) {
        STRATMESH_FUZZ_CHECK(capped_count == surface + cap_report.caps.triangle_count, "cap triangles miscounted");
        for (size_t k = 3 * surface; k < 3 * capped_count; ++k)
            STRATMESH_FUZZ_CHECK(capped[k] < m && valid[capped[k]], "a cap corner outside the valid points");
    }
    if (capping == Status::ok && !soup) {
        mi.triangles = capped.data();
        mi.triangle_count = capped_count;
        const mesh_check::Result c = mesh_check::check(mi);
        STRATMESH_FUZZ_CHECK(c.bad_indices == 0 && c.degenerate == 0, "caps: bad or degenerate triangles");
        STRATMESH_FUZZ_CHECK(c.nonmanifold_edges == 0 && c.inconsistent_edges == 0,
                             "caps: not an oriented edge-manifold");
        STRATMESH_FUZZ_CHECK(c.nonmanifold_vertices == 0, "caps: not vertex-manifold");
        STRATMESH_FUZZ_CHECK(c.boundary_loops == cap_report.caps.open_count, "caps: loops neither closed nor counted");
        // Each flip under a fin rewrites two triangles of the surface, in place.
        size_t rewritten = 0;
        for (size_t k = 0; k < 3 * surface; k += 3)
            rewritten += given[k] != capped[k] || given[k + 1] != capped[k + 1] || given[k + 2] != capped[k + 2];
        STRATMESH_FUZZ_CHECK(rewritten == 2 * cap_report.caps.wall_flip_count, "wall flips miscounted");
    }

    // ---- the same as reconstruct() on the same layers (with add_caps: the caps too)
    if (!(sorted && all_accepted && origin_given && tops.size() >= 1)) return 0;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (size_t i = 0; i < m; ++i)
        if (valid[i]) {
            double h = xyz[3 * i] * axis[0] + xyz[3 * i + 1] * axis[1] + xyz[3 * i + 2] * axis[2];
            lo = std::min(lo, h);
            hi = std::max(hi, h);
        }
    std::vector<double> cuts(tops.begin(), tops.end() - 1);
    const double margin = 1e-9 * (hi - lo + std::fabs(hi) + std::fabs(lo));
    for (double c : cuts) {
        if (!(c > lo + margin && c < hi - margin)) return 0;  // outside the documented equivalence
        for (size_t i = 0; i < m; ++i) {
            if (!valid[i]) continue;
            double h = xyz[3 * i] * axis[0] + xyz[3 * i + 1] * axis[1] + xyz[3 * i + 2] * axis[2];
            if (std::fabs(h - c) <= margin) return 0;
        }
    }
    for (size_t k = 1; k < cuts.size(); ++k)
        if (!(cuts[k] > cuts[k - 1] + margin)) return 0;
    options.cuts = cuts.empty() ? nullptr : cuts.data();
    options.cut_count = cuts.size();
    auto run_batch = [&](uint32_t flags) {
        stratmesh::Options o = options;
        o.flags |= flags;
        o.parts = stratmesh::Parts::one_tube;  // the stream meshes one tube
        std::vector<unsigned char> batch_work(stratmesh::reconstruct_workspace_size(m, o));
        std::vector<uint32_t> batch(3 * stratmesh::reconstruct_max_triangles(m, o) + 3);
        size_t batch_count = 0;
        Status b = stratmesh::reconstruct(whole, o, batch_work.data(), batch_work.size(), batch.data(),
                                          batch.size() / 3, &batch_count, nullptr);
        // A cloud whose surface has no area is refused by reconstruct(), which knows the
        // whole cloud's extent; the stream's triangles have left before it is known.
        if (b == Status::degenerate || b == Status::separate_clusters) return std::vector<uint32_t>();
        STRATMESH_FUZZ_CHECK(b == Status::ok, "reconstruct fails where the stream succeeded");
        batch.resize(3 * batch_count);
        return batch;
    };
    const std::vector<uint32_t> batch = run_batch(0);
    if (batch.empty() && !t.empty()) return 0;  // refused as degenerate (see run_batch)
    STRATMESH_FUZZ_CHECK(batch == t, "the stream's triangles differ from reconstruct()'s on the same layers");
    if (soup) return 0;
    // With add_caps, cap_ends' output whole: the caps, and the wall's edges flipped under fins.
    capped.resize(3 * capped_count);
    STRATMESH_FUZZ_CHECK(run_batch(stratmesh::add_caps) == capped,
                         "cap_ends' caps differ from reconstruct()'s with add_caps");
    return 0;
}
