// The surface's ends as its triangles make them: the boundary loops (edges of one
// triangle only), each put at the bottom or the top end along the axis. An end is closed
// only where no loop is left.
#ifndef STRATMESH_CLI_MESH_ENDS_H
#define STRATMESH_CLI_MESH_ENDS_H

#include "stratmesh.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace stratmesh_cli {

struct SurfaceEnd {
    std::vector<size_t> loop_edges; // each boundary loop at this end: its edge count
    // One loop, well inside the end layer's radius, where the library meshed the end
    // across (LayerInfo::closed_ends): the small loop left around the pole.
    bool pole_loop = false;
};

struct SurfaceEnds {
    bool known = false; // false: the triangles were not kept (the stream without --cap)
    SurfaceEnd bottom, top;
};

// The edges used by exactly one triangle, each as (smaller index << 32 | larger index),
// sorted.
std::vector<uint64_t> boundary_edges(const uint32_t* triangles, size_t count);

// The boundary loops of a mesh whose vertices are `xyz` (3 doubles each): a loop is put at
// the bottom end when its vertices' mean height, dot(point, axis), lies below the median
// height of the triangles' corners. `layers` (bottom up, possibly empty) names pole loops.
// Where the layers follow a bent skeleton starting at `origin` (Report::axis_origin), a
// loop near the start is at the bottom, any other at the top.
SurfaceEnds find_surface_ends(const double* xyz, const uint32_t* triangles,
                              size_t triangle_count, const double axis[3],
                              const std::vector<stratmesh::LayerInfo>& layers,
                              bool along_skeleton = false, const double* origin = nullptr);

} // namespace stratmesh_cli

#endif
