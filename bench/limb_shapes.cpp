// limb_shapes.cpp - the analytic shapes with limbs of the tests, as clouds and as a check.
//
//   stratmesh_limb_shapes write DIR [POINTS]     one DIR/NAME.ply per shape (default 20,000
//                                                points), binary little-endian, double x y z
//   stratmesh_limb_shapes check NAME MESH.off    one JSON line on MESH (ascii OFF whose
//                                                vertices are the cloud's, in order)
//
// NAME is one of y, branched, hand, animal, tee, twice, elbow, u_bend, coil, torus
// (tests/support/shapes.h: a Y of tubes, a trunk with three side branches, a hand, a
// four-legged body with a neck and head, a tee of pipes, a Y whose arm parts again, an
// elbow of pipe, a U bend, a coil of two turns, a torus). The check measures against the
// shape's analytic surface: "mean" is the area-weighted mean distance from the mesh to the
// surface (four points a triangle) over the bounding box's diagonal, "area" the mesh's
// area over the surface's (estimated from the sampling), then the tests' mesh checker's
// counts (components, boundary loops, non-manifold edges and vertices, crossing pairs of
// triangles sharing no vertex, points that are no vertex). Exit 0, or 2 on a usage or file
// error. bench/limbs.sh runs it on the tool's and the advancing-front peer's meshes.

#include "support/mesh_check.h"
#include "support/shapes.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace {

const char* const kNames[] = {"y", "branched", "hand", "animal", "tee", "twice",
                              "elbow", "u_bend", "coil", "torus"};

bool make(const std::string& name, size_t n, shapes::Shape& s) {
    const shapes::Pose z = shapes::Pose::z;
    if (name == "y") s = shapes::y_of_tubes(n, z);
    else if (name == "branched") s = shapes::branched_trunk(n, z);
    else if (name == "hand") s = shapes::hand(n, z);
    else if (name == "animal") s = shapes::four_legged(n, z);
    else if (name == "tee") s = shapes::tee(n, z);
    else if (name == "twice") s = shapes::twice_forked(n, z);
    else if (name == "elbow") s = shapes::elbow(n, z);
    else if (name == "u_bend") s = shapes::u_bend(n, z);
    else if (name == "coil") s = shapes::coil(n, z);
    else if (name == "torus") s = shapes::torus(n, z);
    else return false;
    return true;
}

bool write_ply(const std::string& path, const shapes::Shape& s) {
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex " << s.size()
        << "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
    out.write(reinterpret_cast<const char*>(s.xyz.data()),
              static_cast<std::streamsize>(s.xyz.size() * sizeof(double)));
    return static_cast<bool>(out);
}

// The faces of an ascii OFF mesh (triangles only, comments allowed); false if it is not one.
bool read_off(const std::string& path, size_t vertices, std::vector<uint32_t>& triangles) {
    std::ifstream file(path);
    std::string line, text;
    while (std::getline(file, line)) text += line.substr(0, line.find('#')) + "\n";  // comments
    std::istringstream in(text);
    std::string word;
    size_t v = 0, f = 0, e = 0;
    if (!(in >> word) || word != "OFF" || !(in >> v >> f >> e) || v != vertices) return false;
    double x;
    for (size_t k = 0; k < 3 * v; ++k)
        if (!(in >> x)) return false;
    for (size_t k = 0; k < f; ++k) {
        size_t corners = 0;
        uint32_t a, b, c;
        if (!(in >> corners >> a >> b >> c) || corners != 3) return false;
        triangles.insert(triangles.end(), {a, b, c});
    }
    return true;
}

int check(const std::string& name, const std::string& mesh) {
    shapes::Shape s;
    const size_t n = static_cast<size_t>(std::atol(std::getenv("LIMB_POINTS") ? std::getenv("LIMB_POINTS") : "20000"));
    if (!make(name, n, s)) return 2;
    std::vector<uint32_t> t;
    if (!read_off(mesh, s.size(), t)) {
        std::fprintf(stderr, "limb_shapes: %s is not an ascii OFF triangle mesh of %zu vertices\n",
                     mesh.c_str(), s.size());
        return 2;
    }
    const double far = std::numeric_limits<double>::infinity();
    double lo[3] = {far, far, far}, hi[3] = {-far, -far, -far};
    for (size_t i = 0; i < s.size(); ++i)
        for (size_t k = 0; k < 3; ++k) {
            lo[k] = std::fmin(lo[k], s.xyz[3 * i + k]);
            hi[k] = std::fmax(hi[k], s.xyz[3 * i + k]);
        }
    const double diagonal = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    const double weights[4][3] = {{1 / 3.0, 1 / 3.0, 1 / 3.0}, {2 / 3.0, 1 / 6.0, 1 / 6.0},
                                  {1 / 6.0, 2 / 3.0, 1 / 6.0}, {1 / 6.0, 1 / 6.0, 2 / 3.0}};
    double area = 0, weighted = 0;
    for (size_t f = 0; f < t.size(); f += 3) {
        const double* p[3] = {s.point(t[f]), s.point(t[f + 1]), s.point(t[f + 2])};
        const double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
        const double v[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
        const double a = std::hypot(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                                    u[0] * v[1] - u[1] * v[0]) / 2;
        double d = 0;
        for (const auto& w : weights) {
            double g[3];
            for (size_t k = 0; k < 3; ++k) g[k] = w[0] * p[0][k] + w[1] * p[1][k] + w[2] * p[2][k];
            d += std::fabs(s.deviation(g)) / 4;
        }
        area += a;
        weighted += a * d;
    }
    mesh_check::Input in;
    in.points = s.xyz.data();
    in.point_count = s.size();
    in.triangles = t.data();
    in.triangle_count = t.size() / 3;
    const mesh_check::Result r = mesh_check::check(in);
    std::printf("{\"shape\": \"%s\", \"points\": %zu, \"triangles\": %zu, \"mean\": %.6f, "
                "\"area\": %.4f, \"components\": %zu, \"boundary_loops\": %zu, "
                "\"nonmanifold_edges\": %zu, \"nonmanifold_vertices\": %zu, "
                "\"crossing_pairs\": %zu, \"unused\": %zu}\n",
                name.c_str(), s.size(), t.size() / 3, area > 0 ? weighted / area / diagonal : 0.0,
                area / (s.spacing * s.spacing * static_cast<double>(s.size())), r.components,
                r.boundary_loops, r.nonmanifold_edges, r.nonmanifold_vertices,
                r.intersecting_pairs, r.unused_expected);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc >= 3 && std::strcmp(argv[1], "write") == 0) {
        const size_t n = argc > 3 ? static_cast<size_t>(std::atol(argv[3])) : 20000;
        for (const char* name : kNames) {
            shapes::Shape s;
            make(name, n, s);
            if (!write_ply(std::string(argv[2]) + "/" + name + ".ply", s)) return 2;
        }
        return 0;
    }
    if (argc == 4 && std::strcmp(argv[1], "check") == 0) return check(argv[2], argv[3]);
    std::fprintf(stderr, "usage: stratmesh_limb_shapes write DIR [POINTS] | check NAME MESH.off\n");
    return 2;
}
