// bench_mesh.h - what the benchmark checks on a reconstruction's output (untimed).

#ifndef STRATMESH_BENCH_MESH_H
#define STRATMESH_BENCH_MESH_H

#include "stratmesh.h"

#include <cstddef>
#include <cstdint>

namespace bench {

// Point i of the cloud, as doubles.
void cloud_point(const stratmesh::Cloud& cloud, size_t i, double p[3]);

// The boundary of a triangle mesh: its edges with one triangle, and the loops they make.
// A reconstructed tube has two loops, its bottom and its top; a closed top adds none.
struct Boundary {
    size_t edges = 0;              // edges of exactly one triangle
    size_t nonmanifold_edges = 0;  // edges of three or more triangles (expected: 0)
    size_t loops = 0;              // closed loops of boundary edges
    // The highest loop (largest mean height along the axis): its vertex count, its
    // extent along the axis and the mean distance of its vertices from the axis. For a
    // cloud whose top is closed, this is the hole the mesh leaves there. NaN, and 0
    // vertices, without a loop.
    size_t top_loop_vertices = 0;
    double top_loop_height_min = 0;
    double top_loop_height_max = 0;
    double top_loop_radius = 0;
};

// The boundary of `triangle_count` triangles (index triples into `cloud`); heights and
// radii are measured along the line through `origin` in the unit direction `axis`.
Boundary find_boundary(const uint32_t* triangles, size_t triangle_count,
                       const stratmesh::Cloud& cloud, const double axis[3],
                       const double origin[3]);

// The distribution of the triangles' smallest angles, in degrees (a measure of shape:
// 60 for an equilateral triangle, 0 for a sliver).
struct AngleStats {
    double p05 = 0, median = 0;   // 5th percentile and median of the smallest angles
    double below_10 = 0;          // fraction of triangles whose smallest angle is under 10
};

AngleStats smallest_angles(const uint32_t* triangles, size_t triangle_count,
                           const stratmesh::Cloud& cloud);

}  // namespace bench

#endif  // STRATMESH_BENCH_MESH_H
