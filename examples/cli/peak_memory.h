// The process's peak resident memory, for the report.
#ifndef STRATMESH_CLI_PEAK_MEMORY_H
#define STRATMESH_CLI_PEAK_MEMORY_H

#include <cstddef>

namespace stratmesh_cli {

// VmHWM from /proc/self/status on Linux, in bytes; 0 elsewhere or if it cannot be read.
size_t peak_resident_bytes();

} // namespace stratmesh_cli

#endif
