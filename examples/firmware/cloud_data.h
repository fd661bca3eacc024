// The firmware example's point cloud: float32 x, y, z triples in read-only memory.
#ifndef STRATMESH_FIRMWARE_CLOUD_DATA_H
#define STRATMESH_FIRMWARE_CLOUD_DATA_H

#include <cstddef>

constexpr size_t kCloudPoints = 504;
extern const float kCloudXyz[3 * kCloudPoints];

#endif
