// fuzz_cloud_reader: the command-line tool's from-memory cloud reader
// (examples/cli/cloud_io.h, read_cloud_from_memory) with every format hint.
//
// Checked: no crash or sanitizer report; on success the coordinates come in threes and the
// point count is consistent with the input size (every point needs at least 3 bytes:
// three one-byte binary properties or three one-digit numbers), on failure the message is
// not empty; detect_cloud_format agrees with what the automatic read reports; a second
// read gives the same result. Allocations proportional to a lying header are caught by
// libFuzzer's -malloc_limit_mb / -rss_limit_mb (see .ci/fuzz.sh).
#include "fuzz_common.h"

#include "cloud_io.h"

#include <cstring>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // A copy of exactly `size` bytes, never null, without a terminating zero: a reader
    // that relies on one trips AddressSanitizer.
    std::vector<char> bytes(data, data + size);
    const char* p = bytes.empty() ? "" : bytes.data();
    using stratmesh_cli::CloudFormat;
    const CloudFormat formats[] = {CloudFormat::automatic, CloudFormat::ply, CloudFormat::xyz,
                                   CloudFormat::off, CloudFormat::obj};
    const CloudFormat detected = stratmesh_cli::detect_cloud_format(p, size);
    for (CloudFormat format : formats) {
        std::vector<double> xyz;
        std::string error;
        stratmesh_cli::CloudInfo info;
        bool ok = stratmesh_cli::read_cloud_from_memory(p, size, format, xyz, error, &info);
        if (ok) {
            STRATMESH_FUZZ_CHECK(xyz.size() % 3 == 0, "coordinates not in threes");
            STRATMESH_FUZZ_CHECK(xyz.size() / 3 <= size / 3, "more points than the input can hold");
            if (format == CloudFormat::automatic)
                STRATMESH_FUZZ_CHECK(info.format == detected, "automatic read disagrees with detection");
            else
                STRATMESH_FUZZ_CHECK(info.format == format, "the forced format was not the one read");
        } else {
            STRATMESH_FUZZ_CHECK(!error.empty(), "failure without a message");
        }
        std::vector<double> xyz2;
        std::string error2;
        bool ok2 = stratmesh_cli::read_cloud_from_memory(p, size, format, xyz2, error2, nullptr);
        STRATMESH_FUZZ_CHECK(ok2 == ok, "second read: different outcome");
        if (ok)
            STRATMESH_FUZZ_CHECK(xyz2.size() == xyz.size() &&
                                     (xyz.empty() || std::memcmp(xyz.data(), xyz2.data(), xyz.size() * sizeof(double)) == 0),
                                 "second read: different points");
        else
            STRATMESH_FUZZ_CHECK(error2 == error, "second read: different error");
    }
    return 0;
}
