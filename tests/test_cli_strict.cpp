// Tests of the tool's guarantees about files: output that never destroys data
// (safe_output.h), readers that refuse a body disagreeing with its header and say where
// (cloud_io.h), and a round trip through every input format and encoding the tool reads.
#include <doctest/doctest.h>

#include "args.h"
#include "cloud_io.h"
#include "safe_output.h"

#include <cerrno>
#include <cstdint>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#ifndef _WIN32
#include <fcntl.h>
#include <unistd.h>
#endif

using namespace stratmesh_cli;
namespace fs = std::filesystem;

namespace {

struct ScratchDir {
    fs::path path;
    ScratchDir() {
        path = fs::temp_directory_path() /
               ("stratmesh_cli_strict_" + std::to_string(std::random_device{}()) + "_" +
                std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
        fs::create_directories(path);
    }
    ~ScratchDir() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
    std::string file(const std::string& name) const { return (path / name).string(); }
    size_t entries() const {
        return static_cast<size_t>(
            std::distance(fs::directory_iterator(path), fs::directory_iterator()));
    }
};

void save(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
}

std::string load(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

} // namespace

// ==== output that never destroys data =====================================================

TEST_CASE("two names of one file are refused, through symlinks and hard links") {
    ScratchDir dir;
    save(dir.file("scan.ply"), "points");
    fs::create_symlink("scan.ply", dir.file("link.ply"));
    fs::create_hard_link(dir.file("scan.ply"), dir.file("hard.ply"));
    fs::create_directory(dir.file("sub"));
    const std::string scan = dir.file("scan.ply");
    const std::string around = dir.file("sub/../scan.ply");
    const struct {
        std::vector<NamedFile> files;
        const char* message; // empty: distinct
    } cases[] = {
        {{{"the input", scan}, {"-o", scan}}, "-o '"},
        {{{"the input", scan}, {"-o", dir.file("link.ply")}}, "-o '"},
        {{{"the input", scan}, {"-o", dir.file("hard.ply")}}, "-o '"},
        {{{"the input", scan}, {"-o", around}}, "-o '"},
        {{{"the input", scan}, {"-o", dir.file("m.ply")}, {"--report", scan}}, "--report '"},
        {{{"the input", scan}, {"-o", dir.file("m.ply")}, {"--report", dir.file("m.ply")}},
         "is the same file as -o"},
        // Neither exists yet: the same directory and name.
        {{{"the input", scan}, {"-o", dir.file("new.ply")}, {"--report", dir.file("sub/../new.ply")}},
         "is the same file as -o"},
        {{{"the input", scan}, {"-o", dir.file("m.ply")}, {"--report", dir.file("r.json")}}, ""},
        {{{"the input", scan}, {"-o", dir.file("m.ply")}, {"--report", ""}}, ""},
        {{{"the input", scan}, {"-o", dir.file("sub/scan.ply")}}, ""},
    };
    for (const auto& c : cases) {
        std::string error;
        const bool distinct = check_distinct_files(c.files, error);
        CAPTURE(error);
        CHECK(distinct == (c.message[0] == 0));
        if (!distinct) {
            CHECK(contains(error, c.message));
            CHECK(contains(error, "another path"));
        }
    }
}

TEST_CASE("the command line's files are the input, -o, --report and --preview") {
    CommandLine line;
    std::string error;
    const char* argv[] = {"stratmesh", "in.ply", "-o",         "out.ply",
                          "--report",  "r.json", "--preview", "p.svg"};
    REQUIRE(parse_command_line(8, argv, line, error) == CommandAction::run);
    std::vector<NamedFile> files = named_files(line);
    REQUIRE(files.size() == 4);
    CHECK(files[0].path == "in.ply");
    CHECK(files[1].option == "-o");
    CHECK(files[2].path == "r.json");
    CHECK(files[3].option == "--preview");
    // The standard streams are named too, the input's as the input; options not given
    // name nothing.
    CommandLine streams;
    const char* dashes[] = {"stratmesh", "-", "-o", "-", "--format", "off"};
    REQUIRE(parse_command_line(6, dashes, streams, error) == CommandAction::run);
    CHECK(streams.output_format == MeshFormat::off);
    files = named_files(streams);
    REQUIRE(files.size() == 2);
    CHECK((files[0].path == "-" && files[0].input));
    CHECK((files[1].path == "-" && !files[1].input));
}

TEST_CASE("at most one output goes to standard output") {
    const char* cases[][8] = {
        {"stratmesh", "in.ply", "-o", "-", "--format", "obj", "--report", "-"},
        {"stratmesh", "in.ply", "-o", "-", "--format", "obj", "--preview", "-"},
        {"stratmesh", "in.ply", "-o", "m.ply", "--report", "-", "--preview", "-"}};
    for (const auto& argv : cases) {
        CommandLine line;
        std::string error;
        CHECK(parse_command_line(8, argv, line, error) == CommandAction::usage_error);
        CHECK(contains(error, "at most one of -o, --report and --preview may be -"));
    }
}

#ifndef _WIN32
TEST_CASE("standard input is compared as the file it is") {
    ScratchDir dir;
    const std::string scan = dir.file("scan.ply");
    save(scan, "points");
    fs::create_symlink("scan.ply", dir.file("link.ply"));
    // Standard input, for the length of the test, is scan.ply.
    const int saved = dup(STDIN_FILENO);
    const int opened = open(scan.c_str(), O_RDONLY);
    REQUIRE(saved >= 0);
    REQUIRE(opened >= 0);
    REQUIRE(dup2(opened, STDIN_FILENO) == STDIN_FILENO);
    close(opened);
    std::string error;
    const NamedFile input = {"the input", "-", true};
    const bool over_it = check_distinct_files({input, {"-o", scan}}, error);
    const std::string over_it_error = error;
    const bool through_link =
        check_distinct_files({input, {"--report", dir.file("link.ply")}}, error);
    const bool elsewhere = check_distinct_files({input, {"-o", dir.file("m.ply")}}, error);
    dup2(saved, STDIN_FILENO);
    close(saved);
    CHECK_FALSE(over_it);
    CHECK(contains(over_it_error,
                   "-o '" + scan + "' is the same file as the input (standard input)"));
    CHECK_FALSE(through_link);
    CHECK(elsewhere);
}
#endif

TEST_CASE("an atomic file appears only when committed, keeping the old one until then") {
    ScratchDir dir;
    const std::string path = dir.file("m.ply");
    save(path, "old");
    fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
    {
        AtomicFile file;
        std::string error;
        REQUIRE(file.open(path, error));
        std::fputs("new", file.file());
        std::fflush(file.file());
        CHECK(load(path) == "old");
        CHECK(dir.entries() == 2);
        REQUIRE(file.complete(0, error));
        CHECK(load(path) == "old"); // complete, not yet committed
        REQUIRE(commit_files({&file}, error));
    }
    CHECK(load(path) == "new");
    CHECK(dir.entries() == 1);
    CHECK((fs::status(path).permissions() & fs::perms::all) ==
          (fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read));
}

TEST_CASE("starting the writeback early is only a hint: the file still appears whole at commit") {
    ScratchDir dir;
    const std::string path = dir.file("m.ply");
    save(path, "old");
    std::string expected;
    for (int i = 0; expected.size() < (3u << 20); ++i) expected += std::to_string(i) + "\n";
    AtomicFile file;
    std::string error;
    REQUIRE(file.open(path, error));
    const size_t half = expected.size() / 2;
    REQUIRE(std::fwrite(expected.data(), 1, half, file.file()) == half);
    file.start_writeback();
    REQUIRE(std::fwrite(expected.data() + half, 1, expected.size() - half, file.file()) ==
            expected.size() - half);
    file.start_writeback();
    CHECK(load(path) == "old");
    REQUIRE_MESSAGE(file.complete(0, error), error);
    REQUIRE_MESSAGE(commit_files({&file}, error), error);
    CHECK(load(path) == expected);
    CHECK(dir.entries() == 1);
#ifndef _WIN32
    // A device is written directly: nothing to start, and its failure still counts.
    if (fs::exists("/dev/full")) {
        AtomicFile full;
        REQUIRE(full.open("/dev/full", error));
        std::fputs("anything", full.file());
        full.start_writeback();
        CHECK_FALSE(full.complete(0, error));
        CHECK(contains(error, "/dev/full: cannot write"));
    }
#endif
}

TEST_CASE("a failed write leaves the old file and no temporary") {
    ScratchDir dir;
    const std::string path = dir.file("m.ply");
    save(path, "old");
    SUBCASE("a write that failed (the disk full)") {
        AtomicFile file;
        std::string error;
        REQUIRE(file.open(path, error));
        std::fputs("partial", file.file());
        CHECK_FALSE(file.complete(ENOSPC, error));
        CHECK(error == path + ": cannot write: " + std::strerror(ENOSPC));
        CHECK_FALSE(commit_files({&file}, error));
    }
    SUBCASE("abandoned (an error elsewhere)") {
        AtomicFile file;
        std::string error;
        REQUIRE(file.open(path, error));
        std::fputs("partial", file.file());
    }
    CHECK(load(path) == "old");
    CHECK(dir.entries() == 1);
}

TEST_CASE("outputs are committed all or none") {
    ScratchDir dir;
    save(dir.file("m.ply"), "old mesh");
    AtomicFile mesh, report;
    std::string error;
    REQUIRE(mesh.open(dir.file("m.ply"), error));
    REQUIRE(report.open(dir.file("r.json"), error));
    std::fputs("new mesh", mesh.file());
    std::fputs("new report", report.file());
    REQUIRE(mesh.complete(0, error));
    SUBCASE("one failed") {
        CHECK_FALSE(report.complete(ENOSPC, error));
        CHECK_FALSE(commit_files({&mesh, &report}, error));
        CHECK(contains(error, "no output is replaced"));
        CHECK(load(dir.file("m.ply")) == "old mesh");
        CHECK(dir.entries() == 1);
    }
    SUBCASE("one still being written") {
        CHECK_FALSE(commit_files({&mesh, &report}, error));
        CHECK(contains(error, "r.json: not written whole"));
        CHECK(load(dir.file("m.ply")) == "old mesh");
        CHECK(dir.entries() == 1);
    }
    SUBCASE("one discarded (a refused run writes only its report)") {
        mesh.discard();
        REQUIRE(report.complete(0, error));
        REQUIRE(commit_files({&mesh, &report}, error));
        CHECK(load(dir.file("m.ply")) == "old mesh");
        CHECK(load(dir.file("r.json")) == "new report");
        CHECK(dir.entries() == 2);
    }
    SUBCASE("both complete") {
        REQUIRE(report.complete(0, error));
        REQUIRE(commit_files({&mesh, &report}, error));
        CHECK(load(dir.file("m.ply")) == "new mesh");
        CHECK(load(dir.file("r.json")) == "new report");
        CHECK(dir.entries() == 2);
    }
}

TEST_CASE("a symlinked destination is replaced at its target, and a device is written directly") {
    ScratchDir dir;
    save(dir.file("real.ply"), "old");
    fs::create_symlink("real.ply", dir.file("link.ply"));
    AtomicFile file;
    std::string error;
    REQUIRE(file.open(dir.file("link.ply"), error));
    std::fputs("new", file.file());
    REQUIRE(file.complete(0, error));
    REQUIRE(commit_files({&file}, error));
    CHECK(fs::is_symlink(dir.file("link.ply")));
    CHECK(load(dir.file("real.ply")) == "new");
    CHECK(dir.entries() == 2);
#ifndef _WIN32
    if (fs::exists("/dev/full")) {
        AtomicFile full;
        REQUIRE(full.open("/dev/full", error));
        CHECK(full.direct());
        std::fputs("anything", full.file());
        CHECK_FALSE(full.complete(0, error));
        CHECK(contains(error, "/dev/full: cannot write"));
        CHECK(fs::is_character_file("/dev/full"));
    }
#endif
}

TEST_CASE("a temporary fits wherever its destination does: a long name gets a short one") {
    ScratchDir dir;
    for (size_t length : {size_t{200}, size_t{239}, size_t{250}, size_t{255}}) {
        CAPTURE(length);
        const std::string path = dir.file(std::string(length - 4, 'n') + ".ply");
        AtomicFile file;
        std::string error;
        const bool opened = file.open(path, error);
        CHECK_MESSAGE(opened, error);
        if (!opened) continue;
        std::string temporary;
        for (const auto& entry : fs::directory_iterator(dir.path))
            temporary = entry.path().filename().string();
        CHECK(temporary.rfind(length + 18 <= 255 ? ".nnn" : ".stratmesh-", 0) == 0);
        std::FILE* scratch = scratch_file_beside(path, error);
        CHECK_MESSAGE(scratch, error);
        if (scratch) std::fclose(scratch);
        std::fputs("mesh", file.file());
        REQUIRE_MESSAGE(file.complete(0, error), error);
        REQUIRE_MESSAGE(commit_files({&file}, error), error);
        CHECK(load(path) == "mesh");
        fs::remove(path);
        CHECK(dir.entries() == 0);
    }
}

TEST_CASE("a destination that cannot be created says so") {
    ScratchDir dir;
    AtomicFile file;
    std::string error;
    CHECK_FALSE(file.open(dir.file("no/such/dir/m.ply"), error));
    CHECK(contains(error, "no/such/dir/m.ply: cannot create"));
    CHECK_FALSE(file.open(dir.path.string(), error));
    CHECK(contains(error, "cannot create"));
    CHECK(dir.entries() == 0);
}

TEST_CASE("a scratch file beside the destination leaves no name behind") {
    ScratchDir dir;
    std::string error;
    std::FILE* scratch = scratch_file_beside(dir.file("m.ply"), error);
    REQUIRE(scratch);
    CHECK(std::fputs("body", scratch) >= 0);
    std::rewind(scratch);
    char back[5] = {};
    CHECK(std::fread(back, 1, 4, scratch) == 4);
    CHECK(std::string(back) == "body");
#ifndef _WIN32
    CHECK(dir.entries() == 0);
#endif
    std::fclose(scratch);
    CHECK(dir.entries() == 0);
}

// ==== round trip through every format and encoding ========================================

namespace {

// Coordinates every format holds exactly: small integers for the integer types, floats for
// float, any double for double and for text written with %.17g.
enum class Kind { int8, int16, int32, float32, float64 };

std::vector<double> round_trip_points(Kind kind, size_t count) {
    std::mt19937_64 random(20240611 + static_cast<unsigned>(kind));
    std::vector<double> xyz;
    for (size_t i = 0; i < 3 * count; ++i) {
        const double u = std::ldexp(static_cast<double>(random() >> 11), -53) * 2 - 1;
        switch (kind) {
        case Kind::int8: xyz.push_back(std::floor(u * 127)); break;
        case Kind::int16: xyz.push_back(std::floor(u * 32767)); break;
        case Kind::int32: xyz.push_back(std::floor(u * 2147483647.0)); break;
        case Kind::float32: xyz.push_back(static_cast<double>(static_cast<float>(std::ldexp(u, static_cast<int>(i % 40) - 20)))); break;
        case Kind::float64: xyz.push_back(std::ldexp(u, static_cast<int>(i % 600) - 300)); break;
        }
    }
    return xyz;
}

std::string text_number(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

void append_bytes(std::string& out, const void* p, size_t n, bool big_endian) {
    const unsigned char* b = static_cast<const unsigned char*>(p);
    const uint16_t probe = 1;
    const bool host_little = *reinterpret_cast<const unsigned char*>(&probe) == 1;
    for (size_t i = 0; i < n; ++i) out += static_cast<char>(b[host_little == big_endian ? n - 1 - i : i]);
}

void append_binary(std::string& out, double v, Kind kind, bool big_endian) {
    switch (kind) {
    case Kind::int8: { const int8_t x = static_cast<int8_t>(v); append_bytes(out, &x, 1, big_endian); break; }
    case Kind::int16: { const int16_t x = static_cast<int16_t>(v); append_bytes(out, &x, 2, big_endian); break; }
    case Kind::int32: { const int32_t x = static_cast<int32_t>(v); append_bytes(out, &x, 4, big_endian); break; }
    case Kind::float32: { const float x = static_cast<float>(v); append_bytes(out, &x, 4, big_endian); break; }
    case Kind::float64: append_bytes(out, &v, 8, big_endian); break;
    }
}

const char* ply_type(Kind kind) {
    const char* names[] = {"char", "short", "int", "float", "double"};
    return names[static_cast<int>(kind)];
}

// The cloud as a PLY file with a face element after the vertices (checked, left out).
std::string as_ply(const std::vector<double>& xyz, Kind kind, const char* encoding) {
    const size_t n = xyz.size() / 3;
    std::string out = std::string("ply\nformat ") + encoding + " 1.0\nelement vertex " +
                      std::to_string(n) + "\n";
    for (const char* axis : {"x", "y", "z"}) out += std::string("property ") + ply_type(kind) + " " + axis + "\n";
    out += "property uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const bool ascii = std::string(encoding) == "ascii";
    const bool big = std::string(encoding) == "binary_big_endian";
    for (size_t i = 0; i < n; ++i) {
        for (size_t k = 0; k < 3; ++k) {
            if (ascii) out += (k ? " " : "") + text_number(xyz[3 * i + k]);
            else append_binary(out, xyz[3 * i + k], kind, big);
        }
        if (ascii) out += " 200\n";
        else out += static_cast<char>(200);
    }
    if (ascii) return out + "3 0 1 2\n";
    out += static_cast<char>(3);
    for (int32_t corner : {0, 1, 2}) append_bytes(out, &corner, 4, big);
    return out;
}

std::string as_text(const std::vector<double>& xyz, const std::string& head, const char* prefix,
                    const char* separator, const std::string& tail) {
    std::string out = head;
    for (size_t i = 0; i < xyz.size() / 3; ++i) {
        out += prefix;
        for (size_t k = 0; k < 3; ++k) out += (k ? separator : "") + text_number(xyz[3 * i + k]);
        out += "\n";
    }
    return out + tail;
}

} // namespace

TEST_CASE("every format and encoding reads back the points written, bit for bit") {
    const size_t n = 50;
    const Kind kinds[] = {Kind::int8, Kind::int16, Kind::int32, Kind::float32, Kind::float64};
    std::vector<std::pair<std::string, std::string>> files; // name, bytes
    std::vector<std::vector<double>> expected;
    for (Kind kind : kinds) {
        const std::vector<double> xyz = round_trip_points(kind, n);
        for (const char* encoding : {"ascii", "binary_little_endian", "binary_big_endian"}) {
            files.push_back({std::string("PLY ") + encoding + " " + ply_type(kind), as_ply(xyz, kind, encoding)});
            expected.push_back(xyz);
        }
    }
    const std::vector<double> xyz = round_trip_points(Kind::float64, n);
    const std::string count = std::to_string(n);
    const std::pair<std::string, std::string> text_files[] = {
        {"XYZ", as_text(xyz, "", "", " ", "")},
        {"CSV", as_text(xyz, "x,y,z\n", "", ",", "")},
        {"PTS", as_text(xyz, count + "\n", "", " ", "")},
        {"OFF", as_text(xyz, "OFF\n" + count + " 1 0\n", "", " ", "3 0 1 2\n")},
        {"OBJ", as_text(xyz, "o cloud\n", "v ", " ", "f 1 2 3\n")}};
    for (const auto& f : text_files) {
        files.push_back(f);
        expected.push_back(xyz);
    }
    ScratchDir dir;
    for (size_t i = 0; i < files.size(); ++i) {
        CAPTURE(files[i].first);
        for (bool streamed : {false, true}) {
            CAPTURE(streamed);
            if (streamed && files[i].first == "OFF") continue; // not readable point by point
            std::vector<double> got;
            std::string error;
            CloudInfo info;
            bool ok = false;
            uint64_t faces_seen = 0;
            if (!streamed) {
                ok = read_cloud_from_memory(files[i].second.data(), files[i].second.size(),
                                            CloudFormat::automatic, got, error, &info);
                faces_seen = info.faces_ignored;
            } else {
                const std::string path = dir.file("cloud_" + std::to_string(i));
                save(path, files[i].second);
                std::unique_ptr<PointReader> reader = open_point_reader(path, info, error);
                REQUIRE_MESSAGE(reader, error);
                double p[3];
                while (reader->next(p, error)) got.insert(got.end(), p, p + 3);
                ok = error.empty();
                faces_seen = reader->faces_ignored();
            }
            REQUIRE_MESSAGE(ok, error);
            REQUIRE(got.size() == expected[i].size());
            CHECK(std::memcmp(got.data(), expected[i].data(), got.size() * sizeof(double)) == 0);
            const bool faces = files[i].first.rfind("PLY", 0) == 0 || files[i].first == "OFF" ||
                               files[i].first == "OBJ";
            CHECK(faces_seen == (faces ? 1u : 0u));
        }
    }
}
