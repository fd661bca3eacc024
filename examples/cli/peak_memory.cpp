#include "peak_memory.h"

#include <cstdio>
#include <cstring>

namespace stratmesh_cli {

size_t peak_resident_bytes() {
    size_t kib = 0;
#ifdef __linux__
    std::FILE* status = std::fopen("/proc/self/status", "r");
    if (!status) return 0;
    char line[256];
    while (std::fgets(line, sizeof line, status)) {
        unsigned long long value = 0;
        if (std::strncmp(line, "VmHWM:", 6) == 0 && std::sscanf(line + 6, "%llu", &value) == 1)
            kib = static_cast<size_t>(value);
    }
    std::fclose(status);
#endif
    return kib * 1024;
}

} // namespace stratmesh_cli
