// The smallest useful program: a 2D Delaunay triangulation of a few points, in a fixed
// buffer on the stack. No heap anywhere.
#include "stratmesh.h"

#include <cstdio>

int main() {
    // A 4 x 4 grid: every cell is cocircular, the worst case for naive triangulators.
    double xy[2 * 16];
    for (int i = 0; i < 16; ++i) {
        xy[2 * i] = i % 4;
        xy[2 * i + 1] = i / 4;
    }
    unsigned char workspace[16384];
    uint32_t triangles[3 * 27];
    stratmesh::Delaunay2dInfo info;
    stratmesh::Status status =
        stratmesh::delaunay_2d(xy, 16, 2 * sizeof(double), workspace, sizeof workspace,
                               triangles, 27, &info, nullptr);
    std::printf("%s\n", stratmesh::status_string(status));
    if (status != stratmesh::Status::ok) return 1;
    std::printf("%zu triangles, %zu hull vertices, workspace %zu bytes\n", info.triangle_count,
                info.hull_vertex_count, stratmesh::delaunay_2d_workspace_size(16));
    for (size_t t = 0; t < info.triangle_count; ++t)
        std::printf("  %u %u %u\n", triangles[3 * t], triangles[3 * t + 1], triangles[3 * t + 2]);
    return 0;
}
