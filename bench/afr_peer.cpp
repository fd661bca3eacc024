// afr_peer.cpp - CGAL's advancing-front surface reconstruction as a quality peer.
//
//   stratmesh_afr_peer INPUT.ply [-o OUTPUT.ply|OUTPUT.off]
//
// Reads the vertex positions of a PLY cloud (bench_ply.h's reader and rules), runs
// CGAL::advancing_front_surface_reconstruction with its default parameters
// (radius_ratio_bound 5, beta 0.52), writes the mesh and prints one JSON line:
//
//   {"tool": "cgal_afr", "cgal_version": ..., "input": ..., "output": ..., "points": N,
//    "triangles": T, "seconds": S, "radius_ratio_bound": 5, "beta": 0.52,
//    "status": "ok"}
//
// `seconds` is the library call only (CGAL's 3D Delaunay triangulation of the points and
// the advancing front over it); reading, the conversion to CGAL points and writing are
// outside it. Single-threaded, like stratmesh's library call with --threads 1.
//
// The output keeps every input point as a vertex, in input order, as stratmesh's tool
// does, so triangle indices are input indices (exact duplicates: CGAL keeps one of them,
// the other is an unused vertex). By the output's extension: .off is ascii OFF with
// round-trip precision; anything else is binary little-endian PLY with double x, y, z.
// Exit status: 0 success, 1 CGAL failed (the JSON line has "status": "error" and
// "error"), 2 usage error, 3 file error.
//
// A benchmark tool only: CGAL never reaches the library.

#include "bench_json.h"
#include "bench_mesh.h"
#include "bench_ply.h"

#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/version.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Facet = std::array<std::size_t, 3>;

bool ends_with(const std::string& s, const char* suffix) {
    const size_t n = std::strlen(suffix);
    if (s.size() < n) return false;
    for (size_t i = 0; i < n; ++i) {
        char c = s[s.size() - n + i];
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
        if (c != suffix[i]) return false;
    }
    return true;
}

bool write_off(const std::string& path, const std::vector<Point>& points,
               const std::vector<Facet>& facets) {
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return false;
    std::fprintf(f, "OFF\n%zu %zu 0\n", points.size(), facets.size());
    for (const Point& p : points)
        std::fprintf(f, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
    for (const Facet& t : facets) std::fprintf(f, "3 %zu %zu %zu\n", t[0], t[1], t[2]);
    return std::fclose(f) == 0;
}

// Binary little-endian PLY; the host is assumed little-endian (x86-64, ARM as used here).
bool write_ply(const std::string& path, const std::vector<Point>& points,
               const std::vector<Facet>& facets) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    std::fprintf(f,
                 "ply\nformat binary_little_endian 1.0\ncomment stratmesh_afr_peer: "
                 "CGAL advancing front, default parameters\nelement vertex %zu\n"
                 "property double x\nproperty double y\nproperty double z\n"
                 "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
                 points.size(), facets.size());
    bool ok = true;
    for (const Point& p : points) {
        const double v[3] = {p.x(), p.y(), p.z()};
        ok = ok && std::fwrite(v, sizeof v, 1, f) == 1;
    }
    for (const Facet& t : facets) {
        unsigned char record[1 + 3 * sizeof(uint32_t)];
        record[0] = 3;
        for (int k = 0; k < 3; ++k) {
            const uint32_t index = static_cast<uint32_t>(t[static_cast<size_t>(k)]);
            std::memcpy(record + 1 + static_cast<size_t>(k) * sizeof index, &index, sizeof index);
        }
        ok = ok && std::fwrite(record, sizeof record, 1, f) == 1;
    }
    return std::fclose(f) == 0 && ok;
}

int usage() {
    std::fprintf(stderr, "usage: stratmesh_afr_peer INPUT.ply [-o OUTPUT.ply|OUTPUT.off]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::string input, output;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if ((arg == "-o" || arg == "--output") && i + 1 < argc) {
            output = argv[++i];
        } else if (arg == "-h" || arg == "--help") {
            usage();
            return 0;
        } else if (!arg.empty() && arg[0] != '-' && input.empty()) {
            input = arg;
        } else {
            return usage();
        }
    }
    if (input.empty()) return usage();

    bench::PlyCloud ply;
    std::string error;
    if (!bench::read_ply_file(input, ply, error)) {
        std::fprintf(stderr, "stratmesh_afr_peer: %s\n", error.c_str());
        return 3;
    }
    // Checked here, before a large input goes through CGAL: the PLY writer stores 32-bit
    // indices.
    if (ply.cloud.count > UINT32_MAX) {
        std::fprintf(stderr, "stratmesh_afr_peer: %s: more points than 32-bit indices hold\n",
                     input.c_str());
        return 3;
    }
    std::vector<Point> points;
    points.reserve(ply.cloud.count);
    for (size_t i = 0; i < ply.cloud.count; ++i) {
        double p[3];
        bench::cloud_point(ply.cloud, i, p);
        points.emplace_back(p[0], p[1], p[2]);
    }

    const double radius_ratio_bound = 5;  // CGAL's defaults, given explicitly to print them
    const double beta = 0.52;
    std::vector<Facet> facets;
    std::string failure;
    const auto start = std::chrono::steady_clock::now();
    try {
        CGAL::advancing_front_surface_reconstruction(points.begin(), points.end(),
                                                     std::back_inserter(facets),
                                                     radius_ratio_bound, beta);
    } catch (const std::exception& e) {
        failure = e.what();
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    if (failure.empty() && !output.empty()) {
        const bool written = ends_with(output, ".off") ? write_off(output, points, facets)
                                                       : write_ply(output, points, facets);
        if (!written) {
            std::fprintf(stderr, "stratmesh_afr_peer: cannot write %s\n", output.c_str());
            return 3;
        }
    }

    std::printf("{\"tool\": \"cgal_afr\", \"cgal_version\": \"%s\", \"input\": %s, \"output\": %s, "
                "\"points\": %zu, \"triangles\": %zu, \"seconds\": %.9g, "
                "\"radius_ratio_bound\": %g, \"beta\": %g, \"status\": %s",
                CGAL_VERSION_STR, bench::json_quoted(input).c_str(),
                output.empty() ? "null" : bench::json_quoted(output).c_str(), points.size(),
                facets.size(), seconds, radius_ratio_bound, beta,
                failure.empty() ? "\"ok\"" : "\"error\"");
    if (!failure.empty()) std::printf(", \"error\": %s", bench::json_quoted(failure).c_str());
    std::printf("}\n");
    return failure.empty() ? 0 : 1;
}
