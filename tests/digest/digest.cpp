// Cross-architecture determinism check: reconstructs a fixed set of generated clouds (with
// reconstruct() and with the stream), triangulates a few 2D point sets, and prints one
// FNV-1a 64-bit digest of every status, triangle count and triangle array. The same digest
// must come out of every platform (.ci/arm.sh compares x86-64, aarch64 and 32-bit ARM,
// the last built with STRATMESH_SMALL_CODE).
//
// A second digest, "full", covers what STRATMESH_SMALL_CODE leaves out or meshes
// differently (closed ends, the crescent rule, caps, drop_outliers, cap_ends, the
// surface_flips flag, bands that fold between peeled loops, the fit measure): it is
// printed by builds without the macro (x86-64 and aarch64 in .ci/arm.sh), which must agree.
//
// The clouds come from tests/support/shapes.h, whose coordinates go through sin, cos and
// log: C libraries may differ there in the last bit. To test the library and not the C
// library, every coordinate is rounded to a multiple of 2^-20 (exact, with nearbyint),
// which absorbs last-bit differences; the digest of the inputs is printed separately
// ("input"), so a mismatch says which side differs.
//
// Build: c++ -std=c++17 -O2 -I. -Itests tests/digest/digest.cpp stratmesh.cpp
#include "stratmesh.h"
#include "support/shapes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <vector>

namespace {

struct Fnv1a64 {
    uint64_t h = 0xcbf29ce484222325ull;
    void byte(unsigned char b) {
        h ^= b;
        h *= 0x100000001b3ull;
    }
    // Little-endian, whatever the platform's byte order.
    void u64(uint64_t v) {
        for (int i = 0; i < 8; ++i) byte(static_cast<unsigned char>(v >> (8 * i)));
    }
    void u32(uint32_t v) {
        for (int i = 0; i < 4; ++i) byte(static_cast<unsigned char>(v >> (8 * i)));
    }
    void f64(double d) {
        uint64_t bits;
        std::memcpy(&bits, &d, sizeof bits);
        u64(bits);
    }
};

double quantized(double x) { return std::nearbyint(x * 1048576.0) / 1048576.0; }

std::vector<double> quantized(const std::vector<double>& v) {
    std::vector<double> out(v.size());
    for (size_t i = 0; i < v.size(); ++i) out[i] = quantized(v[i]);
    return out;
}

Fnv1a64 g_input, g_output, g_full_input, g_full;
size_t g_not_ok = 0; // calls whose status was not ok: each fails the run

// Adds one call's outcome to `output` (its status, triangle count, `counts` and triangles)
// and prints a line: what ran, on what, and `shown` with its label.
void record(Fnv1a64& output, const char* call, const char* name, size_t points,
            stratmesh::Status s, const uint32_t* tris, size_t count,
            std::initializer_list<uint64_t> counts, size_t shown, const char* label) {
    output.u32(static_cast<uint32_t>(s));
    output.u64(count);
    for (uint64_t c : counts) output.u64(c);
    for (size_t i = 0; i < 3 * count; ++i) output.u32(tris[i]);
    if (s != stratmesh::Status::ok) ++g_not_ok;
    std::printf("%-11s %-34s %5zu points: %-12s %5zu triangles, %3zu %s\n", call, name, points,
                s == stratmesh::Status::ok ? "ok" : "NOT OK", count, shown, label);
}

void reconstruct_case(const char* name, const std::vector<double>& raw, stratmesh::Options o,
                      Fnv1a64& input = g_input, Fnv1a64& output = g_output) {
    std::vector<double> xyz = quantized(raw);
    for (double d : xyz) input.f64(d);
    size_t n = xyz.size() / 3;
    std::vector<unsigned char> work(stratmesh::reconstruct_workspace_size(n, o));
    std::vector<uint32_t> tris(3 * stratmesh::reconstruct_max_triangles(n, o) + 3);
    stratmesh::Report report = {};
    size_t count = 0;
    stratmesh::Cloud cloud = {xyz.data(), n, 0, stratmesh::Scalar::float64};
    stratmesh::Status s = stratmesh::reconstruct(cloud, o, work.data(), work.size(), tris.data(),
                                                 tris.size() / 3, &count, &report);
    record(output, "reconstruct", name, n, s, tris.data(), count,
           {report.layers.used_count, report.points.rejected_count, report.caps.closed_count}, report.layers.used_count, "layers");
    // The fit, which the small build does not measure: in the full digest only.
    if (&output == &g_full) {
        const stratmesh::Diagnostics& d = report.diagnostics;
        output.u64(d.fit_sample_count);
        output.u64(d.crossing_pair_count);
        for (double v : {d.point_spacing, d.area_per_point, d.misfit_area_fraction,
                         d.misfit_area, d.misfit_box_min[0], d.misfit_box_max[2],
                         d.crossing_box_min[1]})
            output.f64(v);
    }
}

void collect_triangles(void* user, const uint32_t* triangles, size_t count) {
    std::vector<uint32_t>& out = *static_cast<std::vector<uint32_t>*>(user);
    out.insert(out.end(), triangles, triangles + 3 * count);
}

// The cloud pushed to a stream in `pushes` layers of equal height along z (its points are
// generated in no order: each push takes the points of its height range); returns the
// emitted triangles, and the pushed points in push order in `pushed`.
std::vector<uint32_t> stream_case(const char* name, const std::vector<double>& raw, int pushes,
                                  std::vector<double>& pushed) {
    std::vector<double> xyz = quantized(raw);
    for (double d : xyz) g_input.f64(d);
    const size_t n = xyz.size() / 3;
    double low = xyz[2], high = xyz[2];
    for (size_t i = 0; i < n; ++i) {
        low = std::min(low, xyz[3 * i + 2]);
        high = std::max(high, xyz[3 * i + 2]);
    }
    stratmesh::Options o = {};
    o.axis = stratmesh::Axis::z;
    o.flags = stratmesh::origin_given;
    std::vector<unsigned char> work(stratmesh::stream_workspace_size(n, o));
    std::vector<uint32_t> tris;
    stratmesh::Report report = {};
    stratmesh::Stream* stream = nullptr;
    stratmesh::Status s = stratmesh::stream_open(o, work.data(), work.size(), collect_triangles,
                                                 &tris, &report, &stream);
    pushed.clear();
    for (int k = 0; s == stratmesh::Status::ok && k < pushes; ++k) {
        const double bottom = low + (high - low) * k / pushes;
        const double top = k + 1 == pushes ? high : low + (high - low) * (k + 1) / pushes;
        const size_t first = pushed.size() / 3;
        for (size_t i = 0; i < n; ++i) {
            const double z = xyz[3 * i + 2];
            if (z >= bottom && (z < top || k + 1 == pushes))
                pushed.insert(pushed.end(), {xyz[3 * i], xyz[3 * i + 1], z});
        }
        stratmesh::Cloud layer = {pushed.data() + 3 * first, pushed.size() / 3 - first, 0,
                                  stratmesh::Scalar::float64};
        s = stratmesh::stream_push(stream, layer, top);
    }
    if (s == stratmesh::Status::ok) s = stratmesh::stream_close(stream);
    record(g_output, "stream", name, n, s, tris.data(), tris.size() / 3, {report.layers.used_count},
           report.layers.used_count, "layers");
    return tris;
}

#if !defined(STRATMESH_SMALL_CODE)
// cap_ends() over a stream's triangles (see stream_case).
void cap_ends_case(const char* name, const std::vector<double>& pushed, std::vector<uint32_t> tris) {
    const size_t n = pushed.size() / 3;
    stratmesh::Options o = {};
    o.axis = stratmesh::Axis::z;
    std::vector<unsigned char> work(stratmesh::cap_ends_workspace_size(n, tris.size() / 3));
    size_t count = tris.size() / 3;
    tris.resize(3 * stratmesh::reconstruct_max_triangles(n, o));
    stratmesh::Report report = {};
    stratmesh::Cloud cloud = {pushed.data(), n, 0, stratmesh::Scalar::float64};
    stratmesh::Status s = stratmesh::cap_ends(cloud, o, work.data(), work.size(), tris.data(),
                                              tris.size() / 3, &count, &report);
    record(g_full, "cap_ends", name, n, s, tris.data(), count, {report.caps.closed_count},
           report.caps.closed_count, "caps");
}
#endif

void delaunay_case(const char* name, const std::vector<double>& raw) {
    std::vector<double> xy = quantized(raw);
    for (double d : xy) g_input.f64(d);
    size_t n = xy.size() / 2;
    std::vector<unsigned char> work(stratmesh::delaunay_2d_workspace_size(n));
    std::vector<uint32_t> tris(3 * stratmesh::delaunay_2d_max_triangles(n) + 3);
    std::vector<uint32_t> dup(n + 1);
    stratmesh::Delaunay2dInfo info = {};
    stratmesh::Status s = stratmesh::delaunay_2d(xy.data(), n, 2 * sizeof(double), work.data(),
                                                 work.size(), tris.data(), tris.size() / 3,
                                                 &info, dup.data());
    g_output.u32(static_cast<uint32_t>(s));
    g_output.u64(info.triangle_count);
    for (size_t i = 0; i < 3 * info.triangle_count; ++i) g_output.u32(tris[i]);
    for (size_t i = 0; i < n; ++i) g_output.u32(dup[i]);
    std::printf("delaunay_2d %-34s %5zu points: %-12s %5zu triangles\n", name, n,
                s == stratmesh::Status::ok ? "ok" : "NOT OK", info.triangle_count);
}

stratmesh::Options axis_z(uint32_t layers = 0, double height = 0) {
    stratmesh::Options o = {};
    o.axis = stratmesh::Axis::z;
    o.layer_count = layers;
    o.layer_height = height;
    return o;
}

}  // namespace

// With --control-bad-status, a case that cannot succeed is added: the run must then fail,
// which shows that a bad status does fail it (.ci/arm.sh).
int main(int argc, char** argv) {
    using shapes::Pose;
    if (argc > 1 && std::strcmp(argv[1], "--control-bad-status") == 0)
        reconstruct_case("two points (control: too_few_points)", {0, 0, 0, 1, 1, 1}, axis_z());
    std::vector<double> cyl = shapes::cylinder(3000, Pose::z).xyz;
    reconstruct_case("cylinder, automatic layers", cyl, axis_z());
    reconstruct_case("cylinder, 1 layer", cyl, axis_z(1));
    reconstruct_case("cylinder, 8 layers", cyl, axis_z(8));
    std::vector<double> bumpy = shapes::bumpy_tube(3000, Pose::z).xyz;
    reconstruct_case("bumpy tube, 4 layers", bumpy, axis_z(4));
    reconstruct_case("cylinder, layer height 0.5", cyl, axis_z(0, 0.5));
    std::vector<double> vase = shapes::vase(2500, Pose::z).xyz;
    reconstruct_case("vase, automatic", vase, axis_z());
    stratmesh::Options cuts = axis_z();
    const double cut_positions[] = {-2.0, -0.5, 0.75, 2.25};
    cuts.cuts = cut_positions;
    cuts.cut_count = 4;
    reconstruct_case("vase, 4 cuts", vase, cuts);
    std::vector<double> grid = shapes::scan_grid(2000, Pose::z).xyz;
    reconstruct_case("scan grid, 1 layer", grid, axis_z(1));
    reconstruct_case("scan grid, 5 layers", grid, axis_z(5));
    // Not star-shaped around the fitted centres: the outline of a disc and a growing lobe
    // (the centre search moves centres; with 2 layers, in the full digest, a band that folds
    // joins a moved and an unmoved one).
    shapes::Rng lobe_rng(2026);
    std::vector<double> lobe;
    while (lobe.size() < 3 * 3000) {
        const double t = lobe_rng.uniform(0, 2 * shapes::kPi), z = lobe_rng.uniform(0, 2);
        const double radius = 0.4 + 0.2 * z, centre = 0.8 + radius;
        const bool on_lobe = lobe_rng.uniform() < radius / (1 + radius);
        const double x = on_lobe ? centre + radius * std::cos(t) : std::cos(t);
        const double y = (on_lobe ? radius : 1) * std::sin(t);
        if (on_lobe ? std::hypot(x, y) < 1 : std::hypot(x - centre, y) < radius) continue;
        lobe.insert(lobe.end(), {x, y, z});
    }
    reconstruct_case("disc and lobe, 1 layer", lobe, axis_z(1));
    std::vector<double> pushed;
    const std::vector<uint32_t> streamed = stream_case("bumpy tube, 3 pushes", bumpy, 3, pushed);

#if !defined(STRATMESH_SMALL_CODE)
    // The automatic axis: each candidate meshes a sample (the small build asks for an axis).
    stratmesh::Options automatic_axis = {};
    automatic_axis.layer_count = 3;
    reconstruct_case("vase tilted, automatic axis", shapes::vase(2000, Pose::tilted).xyz,
                     automatic_axis, g_full_input, g_full);
    reconstruct_case("capsule (closed ends), automatic", shapes::capsule(3000, Pose::z).xyz,
                     axis_z(), g_full_input, g_full);
    reconstruct_case("slanted tube (crescent), 6 layers", shapes::slanted_tube(3000, Pose::z).xyz,
                     axis_z(6), g_full_input, g_full);
    stratmesh::Options capped = axis_z(4);
    capped.flags = stratmesh::add_caps;
    reconstruct_case("vase, 4 layers, add_caps", vase, capped, g_full_input, g_full);
    // The bumpy tube with 12 far strays and a speck of 5, each a whole multiple of 2^-4
    // away: drop_outliers must leave out the same 17 points everywhere.
    std::vector<double> strays = bumpy;
    for (int i = 0; i < 12; ++i) {
        const double reach = 8 + i;
        strays.insert(strays.end(), {i % 3 == 0 ? reach : 0.0625 * i, i % 3 == 1 ? -reach : 0.5,
                                     i % 3 == 2 ? reach : 1.0});
    }
    for (int i = 0; i < 5; ++i) strays.insert(strays.end(), {20.0 + 0.0625 * i, 20.0, 20.0});
    stratmesh::Options outliers = axis_z(4);
    outliers.flags = stratmesh::drop_outliers;
    reconstruct_case("bumpy tube + strays, drop_outliers", strays, outliers, g_full_input,
                     g_full);
    // A trunk of radius 10 up to z = 60 and two prongs of radius 3 on its wall above it:
    // golden-angle spirals.
    std::vector<double> pronged;
    const double golden = shapes::kPi * (3 - std::sqrt(5.0));
    const struct {
        size_t count;
        double cx, radius, z0, z1;
    } spirals[] = {{4200, 0, 10, 0, 60}, {850, -7, 3, 60, 100}, {850, 7, 3, 60, 100}};
    for (const auto& sp : spirals)
        for (size_t i = 0; i < sp.count; ++i) {
            const double t = static_cast<double>(i);
            pronged.insert(pronged.end(),
                           {sp.cx + sp.radius * std::cos(golden * t), sp.radius * std::sin(golden * t),
                            sp.z0 + (sp.z1 - sp.z0) * (t + 0.5) / static_cast<double>(sp.count)});
        }
    // reconstruct() finds the parting, meshes the trunk and the prongs apart and joins them.
    reconstruct_case("pronged tube, 4 trunk layers, joined", pronged, axis_z(4), g_full_input,
                     g_full);
    cap_ends_case("bumpy tube, 3 pushes, capped", pushed, streamed);
    stratmesh::Options flipped = axis_z(3);
    flipped.flags = stratmesh::surface_flips;
    reconstruct_case("bumpy tube, 3 layers, surface_flips", bumpy, flipped, g_full_input, g_full);
    flipped.layer_count = 2;
    reconstruct_case("head, 2 layers, surface_flips", shapes::head(3000, Pose::z).xyz, flipped,
                     g_full_input, g_full);
    // Bands that fold between peeled loops: the peel groups around the folds put back.
    reconstruct_case("bumpy tube, layer height 0.5", bumpy, axis_z(0, 0.5), g_full_input, g_full);
    reconstruct_case("disc and lobe, 2 layers", lobe, axis_z(2), g_full_input, g_full);
    // A last layer that folds: its end loop peeled all the same, 64 passes at most.
    reconstruct_case("forked tube, 4 layers", shapes::forked_tube(3000, Pose::z).xyz, axis_z(4),
                     g_full_input, g_full);
    // A first layer closed by the outline rule: a knobbed end (find_closed_ends).
    reconstruct_case("knobbed tube, 4 layers", shapes::knobbed_tube(3000, Pose::z).xyz, axis_z(4),
                     g_full_input, g_full);
    // One tube around a Y's two arms: webs across the gap (Report::diagnostics).
    stratmesh::Options one_tube = axis_z();
    one_tube.parts = stratmesh::Parts::one_tube;
    reconstruct_case("Y of tubes, one tube", shapes::y_of_tubes(3000, Pose::z).xyz, one_tube,
                     g_full_input, g_full);
#endif

    shapes::Rng rng(2024);
    std::vector<double> random;
    for (int i = 0; i < 8000; ++i) random.push_back(rng.uniform(-10, 10));
    delaunay_case("4000 random points", random);
    std::vector<double> lattice;
    for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 40; ++i) lattice.insert(lattice.end(), {0.25 * i, 0.25 * j});
    delaunay_case("40x40 lattice (cocircular)", lattice);
    std::vector<double> circle;
    for (int i = 0; i < 256; ++i) {
        double t = 2 * shapes::kPi * i / 256;
        circle.insert(circle.end(), {std::cos(t), std::sin(t)});
    }
    circle.insert(circle.end(), {0.0, 0.0});
    delaunay_case("circle of 256 plus centre", circle);
    std::vector<double> dups(random.begin(), random.begin() + 1000);
    dups.insert(dups.end(), random.begin(), random.begin() + 500);
    delaunay_case("500 random points, 250 repeated", dups);

    std::printf("input  %016llx\n", static_cast<unsigned long long>(g_input.h));
    std::printf("digest %016llx\n", static_cast<unsigned long long>(g_output.h));
#if !defined(STRATMESH_SMALL_CODE)
    std::printf("full   %016llx   (input %016llx)\n", static_cast<unsigned long long>(g_full.h),
                static_cast<unsigned long long>(g_full_input.h));
#else
    std::printf("full   not built (STRATMESH_SMALL_CODE)\n");
#endif
    if (g_not_ok == 0) return 0;
    std::printf("FAIL: %zu calls did not return ok\n", g_not_ok);
    return 1;
}
