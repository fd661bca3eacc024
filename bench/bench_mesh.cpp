// bench_mesh.cpp - what the benchmark checks on a reconstruction's output (see bench_mesh.h).

#include "bench_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

namespace bench {
namespace {

using DirectedEdge = std::pair<uint32_t, uint32_t>;  // from, to

uint64_t undirected_key(uint32_t a, uint32_t b) {
    return a < b ? (static_cast<uint64_t>(a) << 32) | b : (static_cast<uint64_t>(b) << 32) | a;
}

// The undirected keys of the edges with exactly one triangle, sorted; counts the edges
// with three or more.
std::vector<uint64_t> single_edges(const uint32_t* triangles, size_t triangle_count,
                                   size_t& nonmanifold) {
    std::vector<uint64_t> keys(3 * triangle_count);
    for (size_t t = 0; t < triangle_count; ++t)
        for (size_t k = 0; k < 3; ++k)
            keys[3 * t + k] = undirected_key(triangles[3 * t + k],
                                             triangles[3 * t + (k + 1) % 3]);
    std::sort(keys.begin(), keys.end());
    std::vector<uint64_t> single;
    nonmanifold = 0;
    for (size_t i = 0; i < keys.size();) {
        size_t j = i;
        while (j < keys.size() && keys[j] == keys[i]) ++j;
        if (j - i == 1) single.push_back(keys[i]);
        if (j - i > 2) ++nonmanifold;
        i = j;
    }
    return single;
}

// A loop's vertices, measured against the axis.
struct LoopStats {
    size_t vertices = 0;
    double height_min = HUGE_VAL, height_max = -HUGE_VAL, height_sum = 0, radius_sum = 0;
};

void add_vertex(LoopStats& stats, const double p[3], const double axis[3],
                const double origin[3]) {
    double d[3] = {p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]};
    double along = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2];
    double height = p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
    double across = 0;
    for (int k = 0; k < 3; ++k) {
        double c = d[k] - along * axis[k];
        across += c * c;
    }
    ++stats.vertices;
    stats.height_min = std::min(stats.height_min, height);
    stats.height_max = std::max(stats.height_max, height);
    stats.height_sum += height;
    stats.radius_sum += std::sqrt(across);
}

}  // namespace

void cloud_point(const stratmesh::Cloud& cloud, size_t i, double p[3]) {
    bool is_float = cloud.scalar == stratmesh::Scalar::float32;
    size_t stride = cloud.stride_bytes != 0 ? cloud.stride_bytes
                                            : 3 * (is_float ? sizeof(float) : sizeof(double));
    const unsigned char* at = static_cast<const unsigned char*>(cloud.xyz) + i * stride;
    if (is_float) {
        float f[3];
        std::memcpy(f, at, sizeof f);
        for (int k = 0; k < 3; ++k) p[k] = static_cast<double>(f[k]);
    } else {
        std::memcpy(p, at, 3 * sizeof(double));
    }
}

Boundary find_boundary(const uint32_t* triangles, size_t triangle_count,
                       const stratmesh::Cloud& cloud, const double axis[3],
                       const double origin[3]) {
    Boundary result;
    result.top_loop_height_min = result.top_loop_height_max = std::nan("");
    result.top_loop_radius = std::nan("");
    std::vector<uint64_t> single = single_edges(triangles, triangle_count,
                                                result.nonmanifold_edges);
    result.edges = single.size();
    if (single.empty()) return result;

    // The boundary edges in the direction their triangle gives them, by starting vertex.
    std::vector<DirectedEdge> directed;
    for (size_t t = 0; t < triangle_count; ++t) {
        for (size_t k = 0; k < 3; ++k) {
            uint32_t a = triangles[3 * t + k], b = triangles[3 * t + (k + 1) % 3];
            if (std::binary_search(single.begin(), single.end(), undirected_key(a, b)))
                directed.emplace_back(a, b);
        }
    }
    std::sort(directed.begin(), directed.end());

    std::vector<bool> visited(directed.size(), false);
    double top_mean = -HUGE_VAL;
    for (size_t first = 0; first < directed.size(); ++first) {
        if (visited[first]) continue;
        LoopStats stats;
        size_t e = first;
        bool closed = false;
        while (!visited[e]) {
            visited[e] = true;
            double p[3];
            cloud_point(cloud, directed[e].first, p);
            add_vertex(stats, p, axis, origin);
            auto next = std::lower_bound(directed.begin(), directed.end(),
                                         DirectedEdge(directed[e].second, 0));
            if (next == directed.end() || next->first != directed[e].second) break;
            e = static_cast<size_t>(next - directed.begin());
            closed = e == first;
        }
        if (!closed) continue;
        ++result.loops;
        double mean = stats.height_sum / static_cast<double>(stats.vertices);
        if (mean <= top_mean) continue;
        top_mean = mean;
        result.top_loop_vertices = stats.vertices;
        result.top_loop_height_min = stats.height_min;
        result.top_loop_height_max = stats.height_max;
        result.top_loop_radius = stats.radius_sum / static_cast<double>(stats.vertices);
    }
    return result;
}

AngleStats smallest_angles(const uint32_t* triangles, size_t triangle_count,
                           const stratmesh::Cloud& cloud) {
    AngleStats stats;
    if (triangle_count == 0) return stats;
    std::vector<double> smallest(triangle_count);
    size_t below = 0;
    for (size_t t = 0; t < triangle_count; ++t) {
        double p[3][3];
        for (size_t k = 0; k < 3; ++k) cloud_point(cloud, triangles[3 * t + k], p[k]);
        double least = 180;
        for (int k = 0; k < 3; ++k) {
            const double* a = p[k];
            const double* b = p[(k + 1) % 3];
            const double* c = p[(k + 2) % 3];
            double u[3], v[3];
            for (int d = 0; d < 3; ++d) {
                u[d] = b[d] - a[d];
                v[d] = c[d] - a[d];
            }
            double cross[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                               u[0] * v[1] - u[1] * v[0]};
            double sine = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
            double cosine = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
            least = std::min(least, std::atan2(sine, cosine) * 180 / 3.14159265358979323846);
        }
        smallest[t] = least;
        below += least < 10;
    }
    std::sort(smallest.begin(), smallest.end());
    stats.p05 = smallest[triangle_count / 20];
    stats.median = smallest[triangle_count / 2];
    stats.below_10 = static_cast<double>(below) / static_cast<double>(triangle_count);
    return stats;
}

}  // namespace bench
