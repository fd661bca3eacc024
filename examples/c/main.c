/* stratmesh from C: a tube of points, its buffers sized by the bound functions, one
 * reconstruction with caps, and what the report says. Build stratmesh.cpp with a C++
 * compiler and link it (CMake: target stratmesh::stratmesh). */
#include "stratmesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(void) {
    enum { rings = 16, per_ring = 24, count = rings * per_ring };
    const double pi = 3.14159265358979323846;
    float* xyz = (float*)malloc(3 * count * sizeof(float));
    stratmesh_cloud cloud;
    stratmesh_options options;
    stratmesh_report report;
    stratmesh_layer_info layers[8];
    unsigned char* workspace;
    uint32_t* triangles;
    size_t workspace_bytes, max_triangles, triangle_count = 0;
    stratmesh_status status;
    int ring, k;

    if (!xyz) return 1;
    /* Rings along z, every other one turned by half a step, the radius swelling a little. */
    for (ring = 0; ring < rings; ++ring) {
        for (k = 0; k < per_ring; ++k) {
            double angle = 2 * pi * (k + 0.5 * (ring % 2)) / per_ring;
            double radius = 1.0 + 0.1 * sin(0.4 * ring);
            float* p = xyz + 3 * (ring * per_ring + k);
            p[0] = (float)(radius * cos(angle));
            p[1] = (float)(radius * sin(angle));
            p[2] = (float)(0.25 * ring);
        }
    }

    memset(&options, 0, sizeof options); /* all zero: the defaults */
    options.axis = STRATMESH_AXIS_Z;
    options.layer_count = 4;
    options.flags = STRATMESH_FLAG_ADD_CAPS;
    cloud.xyz = xyz;
    cloud.count = count;
    cloud.stride_bytes = 0; /* packed x, y, z */
    cloud.scalar = STRATMESH_SCALAR_FLOAT32;

    /* The bounds size the buffers before the call; the library allocates nothing. */
    workspace_bytes = stratmesh_reconstruct_workspace_size(count, &options);
    max_triangles = stratmesh_reconstruct_max_triangles(count, &options);
    workspace = (unsigned char*)malloc(workspace_bytes);
    triangles = (uint32_t*)malloc(3 * max_triangles * sizeof(uint32_t));
    if (!workspace || !triangles) return 1;

    memset(&report, 0, sizeof report);
    report.layers.info = layers;
    report.layers.info_capacity = sizeof layers / sizeof layers[0];
    status = stratmesh_reconstruct(&cloud, &options, workspace, workspace_bytes, triangles,
                                   max_triangles, &triangle_count, &report);
    printf("%s\n", stratmesh_status_string(status));
    if (status == STRATMESH_STATUS_OK) {
        size_t layer;
        printf("%zu points, %zu triangles (at most %zu), %zu caps\n", report.points.in_count,
               triangle_count, max_triangles, report.caps.closed_count);
        printf("workspace: %zu bytes used of %zu\n", report.workspace_used_bytes,
               workspace_bytes);
        for (layer = 0; layer < report.layers.used_count && layer < 8; ++layer)
            printf("layer %zu: z %.2f to %.2f, %u points, radius %.3f\n", layer,
                   layers[layer].bottom, layers[layer].top, layers[layer].point_count,
                   layers[layer].radius);
        printf("first triangle: %u %u %u\n", triangles[0], triangles[1], triangles[2]);
    }
    free(triangles);
    free(workspace);
    free(xyz);
    return status == STRATMESH_STATUS_OK ? 0 : 1;
}
