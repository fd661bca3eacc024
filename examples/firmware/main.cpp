// stratmesh on a microcontroller: reconstructs the cloud in flash (cloud_data.cpp) into
// static buffers. No heap, no exceptions, no RTTI; the library needs nothing but memset,
// memcpy and a few <cmath> functions from the C library.
//
// Built for a Cortex-M7 by build.sh (arm-none-eabi-g++, newlib-nano); the same file also
// builds and runs on a host as a smoke test (.ci/arm.sh does both).
//
// The buffers are sized at compile time. reconstruct_workspace_size() is an ordinary
// function (not constexpr), so the program checks the constants against it at startup and
// stops with a distinct code if they are too small, before touching the data.
#include "stratmesh.h"  // the implementation is compiled from stratmesh.cpp

#include "cloud_data.h"

#include <cstddef>
#include <cstdint>

namespace {

// The documented bound: about 88 bytes per point plus a fixed part; measured for these
// options: 64 799 bytes, on 32- and 64-bit targets alike. 72 KiB leaves margin
// and fits the 512 KiB SRAM of an STM32F7 or i.MX RT.
constexpr size_t kWorkspaceBytes = 72 * 1024;
// reconstruct produces at most 2n triangles.
constexpr size_t kMaxTriangles = 2 * kCloudPoints;
constexpr uint32_t kLayers = 4;

alignas(8) unsigned char g_workspace[kWorkspaceBytes];
uint32_t g_triangles[3 * kMaxTriangles];
stratmesh::LayerInfo g_layers[16];

}  // namespace

// Results, visible to a debugger (and kept by the linker).
volatile uint32_t g_status = 0xFFFFFFFFu;
volatile uint32_t g_triangle_count = 0;
volatile uint32_t g_points_used = 0;

// Exit codes: 0 ok; 1 workspace too small; 2 triangle array too small; 3 + status on a
// failed reconstruction. On the target, returning from main ends in _exit (a loop).
int main() {
    stratmesh::Options options = {};
    options.axis = stratmesh::Axis::z;
    options.layer_count = kLayers;
    // One tube, as the reduced build meshes it: no search for branches, whose room the
    // bounds would otherwise include in a full build.
    options.parts = stratmesh::Parts::one_tube;

    // The startup check: the constants above against the library's own bounds.
    if (stratmesh::reconstruct_workspace_size(kCloudPoints, options) > sizeof g_workspace) return 1;
    if (stratmesh::reconstruct_max_triangles(kCloudPoints, options) > kMaxTriangles) return 2;

    stratmesh::Cloud cloud = {kCloudXyz, kCloudPoints, 0, stratmesh::Scalar::float32};
    stratmesh::Report report = {};
    report.layers.info = g_layers;
    report.layers.info_capacity = sizeof g_layers / sizeof g_layers[0];
    size_t count = 0;
    stratmesh::Status status = stratmesh::reconstruct(cloud, options, g_workspace, sizeof g_workspace,
                                                      g_triangles, kMaxTriangles, &count, &report);
    g_status = static_cast<uint32_t>(status);
    g_triangle_count = static_cast<uint32_t>(count);
    g_points_used = static_cast<uint32_t>(report.points.used_count);
    if (status != stratmesh::Status::ok) return 3 + static_cast<int>(status);
    return 0;
}
