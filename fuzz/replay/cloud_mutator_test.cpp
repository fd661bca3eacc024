// The reconstruction harness's cloud mutator (fuzz/fuzz_cloud_mutator.h) writes inputs that
// the plain harness reads as the mutator meant them. For each file named on the command
// line (or found in a directory named there) and a range of seeds: every change, and the
// cross-over, gives an input that fits its room, reads back (read_cloud) as exactly the
// cloud the mutator wrote, points and header, and keeps the bytes after the cloud (the
// harness's options) as far as they fit. And a fork, the new cloud made for the branch
// search, parts into its two arms (find_parting).
#include "fuzz_cloud.h"
#include "fuzz_cloud_mutator.h"
#include "fuzz_common.h"

#include "stratmesh.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

namespace {

const uint32_t kMaxPoints = stratmesh_fuzz::kReconstructMaxPoints;
const size_t kQuickPoints = stratmesh_fuzz::kReconstructQuickPoints;

using stratmesh_fuzz::SplitInput;

int failures = 0;

void expect(bool ok, const char* what, const std::string& where) {
    if (ok) return;
    if (++failures <= 20) std::fprintf(stderr, "%s: %s\n", where.c_str(), what);
}

// `bytes` reads back as `meant`: the same header, the same bits, the rest a prefix of its rest.
void expect_reads_as(const std::vector<uint8_t>& bytes, const SplitInput& meant, const std::string& where) {
    const SplitInput got = stratmesh_fuzz::split_input(bytes.data(), bytes.size(), kMaxPoints);
    expect(got.spec.f32 == meant.spec.f32 && got.spec.pad == meant.spec.pad &&
               got.spec.grid_exponent == meant.spec.grid_exponent && got.spec.grid_range == meant.spec.grid_range,
           "another header", where);
    expect(got.spec.xyz.size() == meant.spec.xyz.size() &&
               std::equal(got.spec.xyz.begin(), got.spec.xyz.end(), meant.spec.xyz.begin(),
                          [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }),
           "other points", where);
    expect(got.rest.size() <= meant.rest.size() && std::equal(got.rest.begin(), got.rest.end(), meant.rest.begin()),
           "the bytes after the cloud changed", where);
}

// Writes `s` into `room` bytes and checks that it fits and reads back as meant.
void check_written(SplitInput& s, size_t room, const std::string& where) {
    std::vector<uint8_t> out(room);
    const size_t written = stratmesh_fuzz::write_input(s, out.data(), out.size(), kMaxPoints);
    expect(written <= room, "more bytes than the room", where);
    expect(s.spec.count() < kMaxPoints, "too many points", where);
    out.resize(written);
    expect_reads_as(out, s, where);
}

// One change with `seed` to `input`, and its cross-over with `other`, read back as meant.
void check_mutations(const std::vector<uint8_t>& input, const std::vector<uint8_t>& other, unsigned seed,
                     size_t room, const std::string& where) {
    stratmesh_fuzz::Random random(seed);
    SplitInput s = stratmesh_fuzz::split_input(input.data(), input.size(), kMaxPoints);
    if (stratmesh_fuzz::cloud_mutator::change(s.spec, random, {kMaxPoints - 1, kQuickPoints}))
        check_written(s, room, where + ", change");
    SplitInput a = stratmesh_fuzz::split_input(input.data(), input.size(), kMaxPoints);
    SplitInput b = stratmesh_fuzz::split_input(other.data(), other.size(), kMaxPoints);
    const size_t before = a.spec.count();
    stratmesh_fuzz::cloud_mutator::cross(a, b, random, kQuickPoints);
    expect(b.spec.count() == 0 || a.spec.count() > before, "cross-over: no points added", where);
    check_written(a, room, where + ", cross-over");
}

std::vector<std::vector<uint8_t>> read_inputs(int argc, char** argv) {
    std::vector<std::filesystem::path> files;
    for (int i = 1; i < argc; ++i) {
        std::error_code ec;
        if (std::filesystem::is_directory(argv[i], ec)) {
            for (const auto& entry : std::filesystem::directory_iterator(argv[i], ec))
                if (entry.is_regular_file(ec)) files.push_back(entry.path());
        } else {
            files.push_back(argv[i]);
        }
    }
    std::sort(files.begin(), files.end());
    std::vector<std::vector<uint8_t>> inputs;
    for (const auto& f : files) {
        std::ifstream file(f, std::ios::binary);
        inputs.emplace_back((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    }
    return inputs;
}

// Forks from 40 seeds: how many find_parting() parts into two branches on one side.
int forks_parted() {
    int parted = 0;
    for (unsigned seed = 0; seed < 40; ++seed) {
        stratmesh_fuzz::Random random(seed);
        const std::vector<double> p = stratmesh_fuzz::cloud_mutator::fork(random, kMaxPoints - 1);
        const stratmesh::Cloud cloud = {p.data(), p.size() / 3, 0, stratmesh::Scalar::float64};
        const stratmesh::Options options = {};
        std::vector<unsigned char> work(stratmesh::find_parting_workspace_size(cloud.count, options));
        stratmesh::Parting parting;
        const stratmesh::Status status =
            stratmesh::find_parting(cloud, options, work.data(), work.size(), &parting, nullptr);
        if (status == stratmesh::Status::ok && (parting.above_branch_count == 2 || parting.below_branch_count == 2))
            ++parted;
    }
    return parted;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::vector<uint8_t>> inputs = read_inputs(argc, argv);
    if (inputs.empty()) {
        std::fprintf(stderr, "no inputs: usage: %s <file or corpus directory>...\n", argv[0]);
        return 1;
    }
    size_t checked = 0;
    for (size_t i = 0; i < inputs.size(); ++i)
        for (unsigned seed = 0; seed < 40; ++seed) {
            const std::string where = "input " + std::to_string(i) + ", seed " + std::to_string(seed);
            const size_t room = seed % 4 == 0 ? 64 + seed * 16 : 65536;  // some too small for the cloud
            check_mutations(inputs[i], inputs[(i + seed) % inputs.size()], seed, room, where);
            ++checked;
        }
    const int parted = forks_parted();
    expect(parted >= 30, "fewer than 30 of 40 forks part into two branches", "forks");
    std::fprintf(stderr, "%zu changes and cross-overs checked; %d of 40 forks part\n", checked, parted);
    if (failures) std::fprintf(stderr, "%d failures\n", failures);
    return failures ? 1 : 0;
}
