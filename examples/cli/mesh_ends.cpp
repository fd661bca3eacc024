#include "mesh_ends.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <unordered_map>

namespace stratmesh_cli {

namespace {

double height(const double* p, const double axis[3]) {
    return p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
}

// splitmix64's finaliser: vertex indices spread over 64 bits.
uint64_t mix(uint32_t v) {
    uint64_t x = v + 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

} // namespace

std::vector<uint64_t> boundary_edges(const uint32_t* triangles, size_t count) {
    // On an oriented surface an inner edge runs a -> b in one triangle and b -> a in the
    // other, so around an inner vertex the neighbours its edges leave for and those they
    // arrive from are the same: their hashes, added and taken away, cancel. Only edges
    // between two vertices where they do not (the boundary's, and a few more) are counted.
    uint32_t vertices = 0;
    for (size_t i = 0; i < 3 * count; ++i) vertices = std::max(vertices, triangles[i] + 1);
    std::vector<uint64_t> balance(vertices, 0);
    for (size_t t = 0; t < count; ++t)
        for (size_t k = 0; k < 3; ++k) {
            const uint32_t a = triangles[3 * t + k], b = triangles[3 * t + (k + 1) % 3];
            balance[a] += mix(b);
            balance[b] -= mix(a);
        }
    std::vector<uint64_t> edges;
    for (size_t t = 0; t < count; ++t)
        for (size_t k = 0; k < 3; ++k) {
            const uint32_t a = triangles[3 * t + k], b = triangles[3 * t + (k + 1) % 3];
            if (balance[a] != 0 && balance[b] != 0)
                edges.push_back(uint64_t{std::min(a, b)} << 32 | std::max(a, b));
        }
    std::sort(edges.begin(), edges.end());
    size_t kept = 0;
    for (size_t i = 0; i < edges.size();) {
        size_t j = i + 1;
        while (j < edges.size() && edges[j] == edges[i]) ++j;
        if (j - i == 1) edges[kept++] = edges[i];
        i = j;
    }
    edges.resize(kept);
    return edges;
}

namespace {

// The boundary edges chained into loops (the vertices of each, in order). The surface is
// vertex-manifold, so a boundary vertex has two boundary edges; a chain that does not
// close (never on the library's output) still counts as one loop.
std::vector<std::vector<uint32_t>> chain_loops(const std::vector<uint64_t>& edges) {
    std::unordered_map<uint32_t, std::vector<uint32_t>> next;
    for (uint64_t e : edges) {
        const uint32_t a = static_cast<uint32_t>(e >> 32), b = static_cast<uint32_t>(e);
        next[a].push_back(b);
        next[b].push_back(a);
    }
    std::vector<std::vector<uint32_t>> loops;
    std::unordered_map<uint32_t, bool> visited;
    for (const auto& start : next) {
        if (visited[start.first]) continue;
        std::vector<uint32_t> loop;
        uint32_t previous = start.first, at = start.first;
        for (;;) {
            visited[at] = true;
            loop.push_back(at);
            uint32_t step = at;
            for (uint32_t n : next[at])
                if (!visited[n] && n != previous) step = n;
            if (step == at) break;
            previous = at;
            at = step;
        }
        loops.push_back(std::move(loop));
    }
    return loops;
}

// The loop's largest distance across the axis from the end layer's centre line.
double distance_from_centre_line(const double* xyz, const std::vector<uint32_t>& loop,
                                 const double axis[3], const stratmesh::LayerInfo& layer) {
    double largest = 0;
    for (uint32_t v : loop) {
        double d[3];
        for (size_t k = 0; k < 3; ++k) d[k] = xyz[3 * size_t{v} + k] - layer.centre[k];
        const double along = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2];
        double across = 0;
        for (size_t k = 0; k < 3; ++k) across += (d[k] - along * axis[k]) * (d[k] - along * axis[k]);
        largest = std::max(largest, std::sqrt(across));
    }
    return largest;
}

// The corners whose median height splits the ends: enough for any shape.
const size_t kSampledCorners = 1 << 16;

// A pole loop lies within this share of the end layer's unrolling radius from its centre
// line; a rim lies about one radius out.
const double kPoleShare = 0.5;

void name_pole_loop(SurfaceEnd& end, const std::vector<uint32_t>* only_loop, const double* xyz,
                    const double axis[3], const stratmesh::LayerInfo* layer, uint32_t closed_bit) {
    end.pole_loop = only_loop && layer && (layer->closed_ends & closed_bit) &&
                    distance_from_centre_line(xyz, *only_loop, axis, *layer) <
                        kPoleShare * layer->radius;
}

// The unit direction from a to b; false where they coincide.
bool direction(const double* a, const double* b, double out[3]) {
    double length = 0;
    for (size_t k = 0; k < 3; ++k) {
        out[k] = b[k] - a[k];
        length += out[k] * out[k];
    }
    length = std::sqrt(length);
    if (!(length > 0)) return false;
    for (size_t k = 0; k < 3; ++k) out[k] /= length;
    return true;
}

// Along a bent skeleton (Report::layers.skeleton_node_count) the bottom end is where the
// skeleton starts (Report::axis_origin, Report::axis its direction there), wherever the top
// end lies: a loop within kStartRadii of the first layer's radius of the start is at the
// bottom, any other at the top. The top's centre line runs from the last layer but one to
// the last (a single layer names no pole loop at the top).
const double kStartRadii = 3.0;

bool skeleton_ends(const double* xyz, const std::vector<std::vector<uint32_t>>& loops,
                   const double axis[3], const double origin[3],
                   const std::vector<stratmesh::LayerInfo>& layers, SurfaceEnds& ends) {
    if (layers.empty()) return false;
    const std::vector<uint32_t>* bottom_loop = nullptr;
    const std::vector<uint32_t>* top_loop = nullptr;
    for (const std::vector<uint32_t>& loop : loops) {
        double from_start = 0;
        for (uint32_t v : loop) {
            double square = 0;
            for (size_t k = 0; k < 3; ++k)
                square += (xyz[3 * size_t{v} + k] - origin[k]) * (xyz[3 * size_t{v} + k] - origin[k]);
            from_start += std::sqrt(square);
        }
        const bool bottom =
            from_start / static_cast<double>(loop.size()) < kStartRadii * layers.front().radius;
        (bottom ? ends.bottom : ends.top).loop_edges.push_back(loop.size());
        (bottom ? bottom_loop : top_loop) = &loop;
    }
    stratmesh::LayerInfo start = layers.front();
    for (size_t k = 0; k < 3; ++k) start.centre[k] = origin[k];
    name_pole_loop(ends.bottom, ends.bottom.loop_edges.size() == 1 ? bottom_loop : nullptr, xyz,
                   axis, &start, stratmesh::closed_bottom);
    const size_t n = layers.size();
    double top_axis[3];
    if (n >= 2 && direction(layers[n - 2].centre, layers[n - 1].centre, top_axis))
        name_pole_loop(ends.top, ends.top.loop_edges.size() == 1 ? top_loop : nullptr, xyz,
                       top_axis, &layers.back(), stratmesh::closed_top);
    return true;
}

} // namespace

SurfaceEnds find_surface_ends(const double* xyz, const uint32_t* triangles,
                              size_t triangle_count, const double axis[3],
                              const std::vector<stratmesh::LayerInfo>& layers,
                              bool along_skeleton, const double* origin) {
    SurfaceEnds ends;
    ends.known = true;
    if (triangle_count == 0) return ends;
    if (along_skeleton && skeleton_ends(xyz, chain_loops(boundary_edges(triangles, triangle_count)),
                                        axis, origin, layers, ends))
        return ends;
    // The median corner (of an even sample of at most kSampledCorners): a stray vertex far
    // along the axis does not move it.
    const size_t corners = 3 * triangle_count;
    const size_t step = corners > kSampledCorners ? corners / kSampledCorners : 1;
    std::vector<double> heights;
    for (size_t i = 0; i < corners; i += step)
        heights.push_back(height(xyz + 3 * size_t{triangles[i]}, axis));
    const auto half = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
    std::nth_element(heights.begin(), half, heights.end());
    const double middle = *half;
    heights = {};
    const std::vector<std::vector<uint32_t>> loops =
        chain_loops(boundary_edges(triangles, triangle_count));
    const std::vector<uint32_t>* bottom_loop = nullptr;
    const std::vector<uint32_t>* top_loop = nullptr;
    for (const std::vector<uint32_t>& loop : loops) {
        double sum = 0;
        for (uint32_t v : loop) sum += height(xyz + 3 * size_t{v}, axis);
        const bool bottom = sum / static_cast<double>(loop.size()) < middle;
        (bottom ? ends.bottom : ends.top).loop_edges.push_back(loop.size());
        (bottom ? bottom_loop : top_loop) = &loop;
    }
    const bool lone_bottom = ends.bottom.loop_edges.size() == 1;
    const bool lone_top = ends.top.loop_edges.size() == 1;
    name_pole_loop(ends.bottom, lone_bottom ? bottom_loop : nullptr, xyz, axis,
                   layers.empty() ? nullptr : &layers.front(), stratmesh::closed_bottom);
    name_pole_loop(ends.top, lone_top ? top_loop : nullptr, xyz, axis,
                   layers.empty() ? nullptr : &layers.back(), stratmesh::closed_top);
    return ends;
}

} // namespace stratmesh_cli
