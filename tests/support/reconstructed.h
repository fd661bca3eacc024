// One reconstruct() call with buffers of the sizes the library's bounds give: its status,
// report, triangles and the workspace bound, for suites that check a mesh's properties.
#pragma once

#include "stratmesh.h"

#include <cstdint>
#include <vector>

namespace reconstructed {

struct Mesh {
    stratmesh::Status status = stratmesh::Status::internal_error;
    std::vector<uint32_t> triangles;
    stratmesh::Report report{};
    size_t bound = 0;  // reconstruct_workspace_size(), the workspace given
};

inline Mesh mesh(const stratmesh::Cloud& cloud, const stratmesh::Options& o) {
    Mesh m;
    m.bound = stratmesh::reconstruct_workspace_size(cloud.count, o);
    std::vector<unsigned char> work(m.bound);
    m.triangles.resize(3 * stratmesh::reconstruct_max_triangles(cloud.count, o));
    size_t count = 0;
    m.status = stratmesh::reconstruct(cloud, o, work.data(), work.size(), m.triangles.data(),
                                      m.triangles.size() / 3, &count, &m.report);
    m.triangles.resize(3 * count);
    return m;
}

// Packed doubles as a cloud.
inline stratmesh::Cloud cloud_of(const std::vector<double>& xyz) {
    return stratmesh::Cloud{xyz.data(), xyz.size() / 3, 0, stratmesh::Scalar::float64};
}

inline Mesh mesh(const std::vector<double>& xyz, const stratmesh::Options& o) {
    return mesh(cloud_of(xyz), o);
}

}  // namespace reconstructed
