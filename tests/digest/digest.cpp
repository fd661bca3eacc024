// Cross-architecture determinism check: reconstructs a fixed set of generated clouds and
// triangulates a few 2D point sets, and prints one FNV-1a 64-bit digest of every status,
// triangle count and triangle array. The same digest must come out of every platform
// (.ci/arm.sh compares x86-64, aarch64 and 32-bit ARM).
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

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
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

Fnv1a64 g_input, g_output;

void reconstruct_case(const char* name, const std::vector<double>& raw, stratmesh::Options o) {
    std::vector<double> xyz = quantized(raw);
    for (double d : xyz) g_input.f64(d);
    size_t n = xyz.size() / 3;
    std::vector<unsigned char> work(stratmesh::reconstruct_workspace_size(n, o));
    std::vector<uint32_t> tris(3 * stratmesh::reconstruct_max_triangles(n, o) + 3);
    stratmesh::Report report = {};
    size_t count = 0;
    stratmesh::Cloud cloud = {xyz.data(), n, 0, stratmesh::Scalar::float64};
    stratmesh::Status s = stratmesh::reconstruct(cloud, o, work.data(), work.size(), tris.data(),
                                                 tris.size() / 3, &count, &report);
    g_output.u32(static_cast<uint32_t>(s));
    g_output.u64(count);
    g_output.u64(report.layer_count);
    for (size_t i = 0; i < 3 * count; ++i) g_output.u32(tris[i]);
    std::printf("reconstruct %-34s %5zu points: %-12s %5zu triangles, %3zu layers\n", name, n,
                s == stratmesh::Status::ok ? "ok" : "NOT OK", count, report.layer_count);
}

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

int main() {
    using shapes::Pose;
    std::vector<double> cyl = shapes::cylinder(3000, Pose::z).xyz;
    reconstruct_case("cylinder, automatic layers", cyl, axis_z());
    reconstruct_case("cylinder, 1 layer", cyl, axis_z(1));
    reconstruct_case("cylinder, 8 layers", cyl, axis_z(8));
    std::vector<double> bumpy = shapes::bumpy_tube(3000, Pose::z).xyz;
    reconstruct_case("bumpy tube, 4 layers", bumpy, axis_z(4));
    reconstruct_case("bumpy tube, layer height 0.5", bumpy, axis_z(0, 0.5));
    std::vector<double> vase = shapes::vase(2500, Pose::z).xyz;
    reconstruct_case("vase, automatic", vase, axis_z());
    stratmesh::Options cuts = axis_z();
    const double cut_positions[] = {-2.0, -0.5, 0.75, 2.25};
    cuts.cuts = cut_positions;
    cuts.cut_count = 4;
    reconstruct_case("vase, 4 cuts", vase, cuts);
    stratmesh::Options automatic_axis = {};
    automatic_axis.layer_count = 3;
    reconstruct_case("vase tilted, automatic axis", shapes::vase(2000, Pose::tilted).xyz, automatic_axis);
    std::vector<double> grid = shapes::scan_grid(2000, Pose::z).xyz;
    reconstruct_case("scan grid, 1 layer", grid, axis_z(1));
    reconstruct_case("scan grid, 5 layers", grid, axis_z(5));
    // Not star-shaped around the fitted centres: the outline of a disc and a growing lobe
    // (the centre search moves centres, and a band joins a moved and an unmoved one).
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
    reconstruct_case("disc and lobe, 2 layers", lobe, axis_z(2));

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
    return 0;
}
