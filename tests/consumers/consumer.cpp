// A user's program: triangulates a unit square with its centre and checks the result.
#include "stratmesh.h"

#include <cstdio>

int main() {
    const double xy[] = {0, 0, 1, 0, 1, 1, 0, 1, 0.5, 0.5};
    unsigned char workspace[16384];
    if (stratmesh::delaunay_2d_workspace_size(5) > sizeof workspace) return 2;
    uint32_t triangles[3 * 5];
    stratmesh::Delaunay2dInfo info;
    stratmesh::Status status = stratmesh::delaunay_2d(xy, 5, 2 * sizeof(double), workspace,
                                                      sizeof workspace, triangles, 5, &info,
                                                      nullptr);
    std::printf("%s, %zu triangles\n", stratmesh::status_string(status), info.triangle_count);
    // The centre splits the square into 4 triangles, each with the centre as a vertex.
    if (status != stratmesh::Status::ok || info.triangle_count != 4) return 1;
    for (size_t t = 0; t < 4; ++t) {
        const uint32_t* tri = triangles + 3 * t;
        if (tri[0] != 4 && tri[1] != 4 && tri[2] != 4) return 1;
    }
    return 0;
}
