// stratmesh_library_default INPUT MESH: reads INPUT as the command-line tool does, meshes it
// with the library's defaults (reconstruct() with all-zero Options, no runner) and checks
// that MESH, the tool's output with no options, has exactly those triangles in that order.
// So the tool adds nothing to the pipeline a library user gets from one call.
#include "cloud_io.h"
#include "mini_mesh.h"
#include "stratmesh.h"

#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: stratmesh_library_default INPUT MESH\n");
        return 2;
    }
    std::vector<double> xyz;
    std::string error;
    if (!stratmesh_cli::read_cloud_file(argv[1], xyz, error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return 2;
    }
    const stratmesh::Cloud cloud = {xyz.data(), xyz.size() / 3, 0, stratmesh::Scalar::float64};
    const stratmesh::Options options = {};
    std::vector<unsigned char> work(stratmesh::reconstruct_workspace_size(cloud.count, options));
    std::vector<uint32_t> tris(3 * stratmesh::reconstruct_max_triangles(cloud.count, options));
    size_t count = 0;
    stratmesh::Report report = {};
    const stratmesh::Status status = stratmesh::reconstruct(
        cloud, options, work.data(), work.size(), tris.data(), tris.size() / 3, &count, &report);
    if (status != stratmesh::Status::ok) {
        std::fprintf(stderr, "reconstruct: %s\n", stratmesh::status_string(status));
        return 1;
    }
    tris.resize(3 * count);
    mini_mesh::Mesh tool;
    if (!mini_mesh::read(argv[2], tool)) {
        std::fprintf(stderr, "cannot read the mesh %s\n", argv[2]);
        return 2;
    }
    if (count == 0 || tool.tris != tris) {
        std::fprintf(stderr, "the library's defaults give %zu triangles, the tool %zu: not the same\n",
                     count, tool.tris.size() / 3);
        return 1;
    }
    std::printf("the tool's mesh is the library default's: %zu triangles, parts %zu\n", count,
                report.parts.part_count);
    return 0;
}
