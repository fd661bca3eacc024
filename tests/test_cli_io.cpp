// Tests of the stratmesh tool's file handling: cloud readers (round trips, malformed
// input, format detection), mesh writers (read back with independent mini readers), the
// JSON report and the command line.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include "args.h"
#include "big_buffer.h"
#include "cloud_io.h"
#include "mesh_ends.h"
#include "mesh_io.h"
#include "report_json.h"
#include "safe_output.h"
#include "text_scan.h"

#include "cli/mini_json.h"
#include "cli/mini_mesh.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#ifndef _WIN32
#include <sys/stat.h>
#endif

using namespace stratmesh_cli;

namespace {

// ---- helpers -----------------------------------------------------------------------------

// A fresh directory for the test's files, removed afterwards.
struct TempDir {
    std::filesystem::path path;

    TempDir() {
        auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
        path = std::filesystem::temp_directory_path() /
               ("stratmesh_cli_io_" + std::to_string(std::random_device{}()) + "_" +
                std::to_string(stamp));
        std::filesystem::create_directories(path);
    }
    ~TempDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
    }
    std::string file(const std::string& name) const { return (path / name).string(); }
};

void save(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Points with awkward values: fractions no float holds, large and tiny magnitudes.
std::vector<double> test_points(size_t count) {
    std::vector<double> xyz;
    for (size_t i = 0; i < count; ++i) {
        double t = static_cast<double>(i);
        xyz.push_back(0.1 * t - 3.7);
        xyz.push_back(std::sqrt(t + 2.0) * 1234.5678);
        xyz.push_back(-1e-7 * t * t + 1e5 / (t + 3));
    }
    return xyz;
}

std::vector<double> rounded_to_float(const std::vector<double>& xyz) {
    std::vector<double> out;
    for (double v : xyz) out.push_back(static_cast<double>(static_cast<float>(v)));
    return out;
}

std::string exact_text(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

// Binary encoder for test files, in either byte order.
struct Bytes {
    bool big_endian;
    std::string data;

    template <class T> Bytes& put(T value) {
        unsigned char raw[sizeof(T)];
        std::memcpy(raw, &value, sizeof value);
        uint16_t probe = 1;
        unsigned char first;
        std::memcpy(&first, &probe, 1);
        bool host_little = first == 1;
        for (size_t i = 0; i < sizeof(T); ++i)
            data += static_cast<char>(raw[host_little == !big_endian ? i : sizeof(T) - 1 - i]);
        return *this;
    }
};

struct ReadResult {
    bool ok;
    std::vector<double> xyz;
    std::string error;
    CloudInfo info;
};

ReadResult read_text(const std::string& bytes, CloudFormat format = CloudFormat::automatic) {
    ReadResult r;
    r.ok = read_cloud_from_memory(bytes.data(), bytes.size(), format, r.xyz, r.error, &r.info);
    return r;
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

const char* kXyz = "property float x\nproperty float y\nproperty float z\n";

// The file is refused with a message holding every part.
void check_fails(const std::string& bytes, const std::vector<std::string>& parts) {
    ReadResult r = read_text(bytes);
    CHECK_FALSE(r.ok);
    for (const std::string& part : parts) CHECK_MESSAGE(contains(r.error, part), r.error);
}

// ---- PLY files built by the tests --------------------------------------------------------

// Binary PLY with a face element before the vertices and an edge element after, and
// vertices interleaving x, y, z with normals, colours and an intensity.
std::string busy_binary_ply(const std::vector<double>& xyz, bool big_endian) {
    size_t n = xyz.size() / 3;
    std::string header = std::string("ply\nformat ") +
                         (big_endian ? "binary_big_endian" : "binary_little_endian") +
                         " 1.0\ncomment busy\nelement face 2\n"
                         "property list uchar int vertex_indices\nproperty uchar flags\n"
                         "element vertex " +
                         std::to_string(n) +
                         "\n"
                         "property float nx\nproperty float x\nproperty uchar red\n"
                         "property float32 y\nproperty ushort label\nproperty float z\n"
                         "property float intensity\nelement edge 1\n"
                         "property int v1\nproperty int v2\nend_header\n";
    Bytes b{big_endian, header};
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2).put<uint8_t>(7);
    b.put<uint8_t>(4).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2).put<int32_t>(3).put<uint8_t>(
        9);
    for (size_t i = 0; i < n; ++i) {
        b.put<float>(0.5f).put(static_cast<float>(xyz[3 * i])).put<uint8_t>(200);
        b.put(static_cast<float>(xyz[3 * i + 1])).put<uint16_t>(65535);
        b.put(static_cast<float>(xyz[3 * i + 2])).put<float>(0.25f);
    }
    b.put<int32_t>(0).put<int32_t>(1);
    return b.data;
}

// Binary PLY of doubles with a list property inside the vertex element.
std::string double_binary_ply(const std::vector<double>& xyz, bool big_endian) {
    size_t n = xyz.size() / 3;
    std::string header = std::string("ply\nformat ") +
                         (big_endian ? "binary_big_endian" : "binary_little_endian") +
                         " 1.0\nelement vertex " + std::to_string(n) +
                         "\nproperty double x\nproperty list ushort short extra\n"
                         "property float64 y\nproperty double z\nend_header\n";
    Bytes b{big_endian, header};
    for (size_t i = 0; i < n; ++i) {
        b.put(xyz[3 * i]).put<uint16_t>(static_cast<uint16_t>(i % 3));
        for (size_t k = 0; k < i % 3; ++k) b.put<int16_t>(-5);
        b.put(xyz[3 * i + 1]).put(xyz[3 * i + 2]);
    }
    return b.data;
}

std::string ascii_ply(const std::vector<double>& xyz, const char* newline) {
    size_t n = xyz.size() / 3;
    std::string nl = newline;
    std::string text = "ply" + nl + "format ascii 1.0" + nl + "comment hello" + nl +
                       "obj_info made by a test" + nl + "element face 1" + nl +
                       "property list uchar uint vertex_indices" + nl + "element vertex " +
                       std::to_string(n) + nl + "property double x" + nl + "property uchar r" + nl +
                       "property double y" + nl + "property double z" + nl + "end_header" + nl +
                       "3 0 1 2" + nl;
    for (size_t i = 0; i < n; ++i)
        text += exact_text(xyz[3 * i]) + " 17 " + exact_text(xyz[3 * i + 1]) + " " +
                exact_text(xyz[3 * i + 2]) + nl;
    return text;
}

std::string little_ply_header(const std::string& elements) {
    return "ply\nformat binary_little_endian 1.0\n" + elements + "end_header\n";
}

} // namespace

// ==== cloud readers: round trips ==========================================================

TEST_CASE("binary PLY, float, other properties and elements skipped, both byte orders") {
    std::vector<double> xyz = test_points(40);
    for (bool big : {false, true}) {
        ReadResult r = read_text(busy_binary_ply(xyz, big));
        REQUIRE_MESSAGE(r.ok, r.error);
        CHECK(r.info.format == CloudFormat::ply);
        CHECK(r.info.encoding == (big ? "binary_big_endian" : "binary_little_endian"));
        CHECK(r.xyz == rounded_to_float(xyz));
    }
}

TEST_CASE("binary PLY, double, with a list inside the vertex element, both byte orders") {
    std::vector<double> xyz = test_points(25);
    for (bool big : {false, true}) {
        ReadResult r = read_text(double_binary_ply(xyz, big));
        REQUIRE_MESSAGE(r.ok, r.error);
        CHECK(r.xyz == xyz);
    }
}

TEST_CASE("binary PLY with integer coordinates") {
    Bytes b{false, little_ply_header("element vertex 2\nproperty short x\nproperty int y\n"
                                     "property uchar z\n")};
    b.put<int16_t>(-300).put<int32_t>(70000).put<uint8_t>(255);
    b.put<int16_t>(5).put<int32_t>(-1).put<uint8_t>(0);
    ReadResult r = read_text(b.data);
    REQUIRE_MESSAGE(r.ok, r.error);
    CHECK(r.xyz == std::vector<double>{-300, 70000, 255, 5, -1, 0});
}

namespace {

// A PLY type's name and its values: the first few are the type's extremes and oddities,
// the rest random bit patterns (for floats these include NaNs, infinities, subnormals).
struct TypedColumn {
    const char* name;
    size_t size;
    std::vector<std::string> raw;  // each value's bytes, little-endian
    std::vector<double> expected;  // each value as a double
};

template <class T> TypedColumn typed_column(const char* name, size_t count, uint64_t seed) {
    using Limits = std::numeric_limits<T>;
    std::vector<T> values = {Limits::lowest(), Limits::max(), T(0), T(1)};
    if (!Limits::is_integer) {
        values.push_back(-T(0));
        values.push_back(Limits::denorm_min());
        values.push_back(-Limits::infinity());
        values.push_back(Limits::quiet_NaN());
    }
    std::mt19937_64 random(seed);
    while (values.size() < count) {
        const uint64_t bits = random();
        T value;
        std::memcpy(&value, &bits, sizeof value);
        values.push_back(value);
    }
    TypedColumn column{name, sizeof(T), {}, {}};
    for (size_t i = 0; i < count; ++i) {
        Bytes little{false, ""};
        little.put(values[i]);
        column.raw.push_back(little.data);
        column.expected.push_back(static_cast<double>(values[i]));
    }
    return column;
}

std::vector<TypedColumn> every_typed_column(size_t count) {
    return {typed_column<int8_t>("char", count, 1),     typed_column<uint8_t>("uint8", count, 2),
            typed_column<int16_t>("short", count, 3),   typed_column<uint16_t>("ushort", count, 4),
            typed_column<int32_t>("int32", count, 5),   typed_column<uint32_t>("uint", count, 6),
            typed_column<float>("float", count, 7),     typed_column<double>("float64", count, 8)};
}

// Binary PLY whose vertices hold x, y, z from three columns (`count` points: values i,
// count + i, 2 count + i of each), between other properties; with `list`, also a list
// property, which makes the records variable in size (the per-record path).
std::string typed_binary_ply(const TypedColumn* xyz[3], size_t count, bool big_endian,
                             bool list) {
    std::string header = std::string("ply\nformat ") +
                         (big_endian ? "binary_big_endian" : "binary_little_endian") +
                         " 1.0\nelement face 2\nproperty uchar flags\nproperty double area\n"
                         "element vertex " + std::to_string(count) + "\nproperty uchar red\n" +
                         "property " + xyz[0]->name + " x\nproperty short label\n" +
                         (list ? "property list uchar int extra\n" : "") +
                         "property " + xyz[1]->name + " y\nproperty " + xyz[2]->name +
                         " z\nproperty double w\nend_header\n";
    Bytes b{big_endian, header};
    for (int f = 0; f < 2; ++f) b.put<uint8_t>(7).put<double>(0.5);
    auto raw = [&](const TypedColumn& column, size_t i) {
        std::string bytes = column.raw[i];
        if (big_endian) bytes.assign(bytes.rbegin(), bytes.rend());
        b.data += bytes;
    };
    for (size_t i = 0; i < count; ++i) {
        b.put<uint8_t>(200);
        raw(*xyz[0], i);
        b.put<int16_t>(-3);
        if (list) {
            b.put<uint8_t>(static_cast<uint8_t>(i % 3));
            for (size_t k = 0; k < i % 3; ++k) b.put<int32_t>(-1);
        }
        raw(*xyz[1], count + i);
        raw(*xyz[2], 2 * count + i);
        b.put<double>(1.25);
    }
    return b.data;
}

std::vector<double> typed_expected(const TypedColumn* xyz[3], size_t count) {
    std::vector<double> out;
    for (size_t i = 0; i < count; ++i)
        for (size_t k = 0; k < 3; ++k) out.push_back(xyz[k]->expected[k * count + i]);
    return out;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

} // namespace

TEST_CASE("binary PLY: fixed-size records of every scalar type and byte order read as written") {
    // More points than one conversion batch holds, and a last batch that is partial.
    const size_t n = 2500;
    const std::vector<TypedColumn> columns = every_typed_column(3 * n);
    std::vector<std::vector<const TypedColumn*>> layouts;
    for (const TypedColumn& c : columns) layouts.push_back({&c, &c, &c});
    layouts.push_back({&columns[0], &columns[7], &columns[3]}); // char, double, ushort
    layouts.push_back({&columns[6], &columns[5], &columns[2]}); // float, uint, short
    for (const auto& layout : layouts) {
        const TypedColumn* xyz[3] = {layout[0], layout[1], layout[2]};
        const std::vector<double> expected = typed_expected(xyz, n);
        for (bool big : {false, true}) {
            CAPTURE(xyz[0]->name);
            CAPTURE(xyz[1]->name);
            CAPTURE(xyz[2]->name);
            CAPTURE(big);
            ReadResult fixed = read_text(typed_binary_ply(xyz, n, big, false));
            ReadResult listed = read_text(typed_binary_ply(xyz, n, big, true));
            REQUIRE_MESSAGE(fixed.ok, fixed.error);
            REQUIRE_MESSAGE(listed.ok, listed.error);
            CHECK(same_bits(fixed.xyz, expected));
            CHECK(same_bits(listed.xyz, expected));
        }
    }
}

TEST_CASE("binary PLY: fixed-size records cut short fail at the vertices' first byte") {
    const size_t n = 40;
    const std::vector<TypedColumn> columns = every_typed_column(3 * n);
    for (const TypedColumn& c : columns) {
        const TypedColumn* xyz[3] = {&c, &c, &c};
        for (bool big : {false, true}) {
            CAPTURE(c.name);
            CAPTURE(big);
            const std::string whole = typed_binary_ply(xyz, n, big, false);
            // The header, then two face records of 9 bytes before the vertices.
            const size_t vertices_at = whole.find("end_header\n") + 11 + 2 * 9;
            const size_t record = 1 + 2 + 8 + 3 * c.size;
            REQUIRE(whole.size() == vertices_at + n * record);
            for (size_t cut : {size_t{1}, record - 1, record + 1, n * record - 1}) {
                CAPTURE(cut);
                ReadResult r = read_text(whole.substr(0, whole.size() - cut));
                CHECK_FALSE(r.ok);
                CHECK_MESSAGE(contains(r.error, "byte " + std::to_string(vertices_at) +
                                                    ": element 'vertex' declares " +
                                                    std::to_string(n) + " records of " +
                                                    std::to_string(record) + " bytes, but only " +
                                                    std::to_string(n * record - cut) +
                                                    " bytes follow"),
                              r.error);
            }
        }
    }
}

TEST_CASE("big buffers: any size, writable to the last byte, reallocated keeping the start") {
    for (size_t bytes : {size_t{0}, size_t{1}, size_t{4096}, (size_t{3} << 20) + 5}) {
        CAPTURE(bytes);
        auto* memory = static_cast<unsigned char*>(allocate_big(bytes));
        REQUIRE(memory != nullptr);
        const size_t usable = bytes > 0 ? bytes : 1;
        for (size_t i = 0; i < usable; i += 4093) memory[i] = static_cast<unsigned char>(i);
        memory[usable - 1] = 0xab;
        CHECK(memory[usable - 1] == 0xab);
        free_big(memory, bytes);
    }
    BigBuffer buffer;
    REQUIRE(buffer.reallocate(100, 0));
    std::memcpy(buffer.data(), "stratmesh", 9);
    REQUIRE(buffer.reallocate(5u << 20, 9));
    CHECK(std::string(buffer.data(), 9) == "stratmesh");
    REQUIRE(buffer.reallocate(4, 9));
    CHECK(std::string(buffer.data(), 4) == "stra");
    for (Pages pages : {Pages::huge, Pages::prefaulted}) {
        const size_t bytes = (size_t{5} << 20) + 3;
        auto* memory = static_cast<unsigned char*>(allocate_big(bytes, pages));
        REQUIRE(memory != nullptr);
        std::memset(memory, 0x5a, bytes);
        CHECK(memory[bytes - 1] == 0x5a);
        free_big(memory, bytes);
    }
    // Faulting in a vector's pages keeps what it holds.
    std::vector<double> values(1u << 20);
    for (size_t i = 0; i < values.size(); ++i) values[i] = static_cast<double>(i);
    prefault_pages(values.data() + 3, (values.size() - 3) * sizeof(double));
    size_t changed = 0;
    for (size_t i = 0; i < values.size(); ++i) changed += values[i] != static_cast<double>(i);
    CHECK(changed == 0);
}

TEST_CASE("a file is read whole: in one read, or growing through a pipe") {
    TempDir dir;
    std::string bytes(3u << 20, '\0');
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7 + i / 4096);
    save(dir.file("big.bin"), bytes);
    BigBuffer read;
    size_t size = 0;
    std::string error;
    REQUIRE_MESSAGE(read_file_bytes(dir.file("big.bin"), read, size, error), error);
    CHECK(size == bytes.size());
    CHECK(std::string(read.data(), size) == bytes);
    save(dir.file("empty.bin"), "");
    REQUIRE_MESSAGE(read_file_bytes(dir.file("empty.bin"), read, size, error), error);
    CHECK(size == 0);
    CHECK_FALSE(read_file_bytes(dir.file("missing.bin"), read, size, error));
    CHECK(contains(error, "cannot open"));
#ifndef _WIN32
    // A pipe announces no size: the buffer doubles from its first guess as bytes arrive.
    const std::string fifo = dir.file("pipe");
    REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
    std::thread writer([&] { save(fifo, bytes); });
    const bool ok = read_file_bytes(fifo, read, size, error);
    writer.join();
    REQUIRE_MESSAGE(ok, error);
    CHECK(size == bytes.size());
    CHECK(std::string(read.data(), size) == bytes);
#endif
}

TEST_CASE("ascii PLY, LF and CRLF line ends") {
    std::vector<double> xyz = test_points(30);
    for (const char* newline : {"\n", "\r\n"}) {
        ReadResult r = read_text(ascii_ply(xyz, newline));
        REQUIRE_MESSAGE(r.ok, r.error);
        CHECK(r.info.encoding == "ascii");
        CHECK(r.xyz == xyz);
    }
}

TEST_CASE("PLY with zero vertices is an empty cloud, not an error") {
    ReadResult r = read_text(little_ply_header(std::string("element vertex 0\n") + kXyz));
    REQUIRE_MESSAGE(r.ok, r.error);
    CHECK(r.xyz.empty());
}

namespace {

// The points as columns parted by `separator`, with a decimal comma if `comma`, extra
// columns if `extra`, after a comment and a line of column names; comments, blank lines and
// CRLF line ends here and there.
std::string columns_text(const std::vector<double>& xyz, const std::string& separator,
                         bool comma, bool extra) {
    auto number = [&](double v) {
        std::string text = exact_text(v);
        if (comma) std::replace(text.begin(), text.end(), '.', ',');
        return text;
    };
    std::string text = "# scanner export\nX" + separator + "Y" + separator + "Z" +
                       (extra ? separator + "R" + separator + "G" + separator + "B" : "") +
                       "\n\n";
    for (size_t i = 0; i < xyz.size() / 3; ++i) {
        text += number(xyz[3 * i]) + separator + number(xyz[3 * i + 1]) + separator +
                number(xyz[3 * i + 2]);
        text += extra ? separator + "255" + separator + "0" + separator + "12" : "";
        text += i % 3 == 0 ? "  // a comment\r\n" : "\n";
        if (i == 7) text += "   \n// a line comment\n# another\n";
    }
    return text;
}

} // namespace

TEST_CASE("XYZ columns: each file parted by blanks, commas or semicolons, a point or a comma as its decimal mark") {
    const std::vector<double> xyz = test_points(20);
    const struct {
        const char* separator;
        bool comma;
    } dialects[] = {{" ", false},  {"  ", false}, {"\t", false}, {" \t", false}, {",", false},
                    {", ", false}, {" , ", false}, {";", false}, {"; ", false},  {";", true},
                    {" ; ", true}, {" ", true},    {"\t", true}};
    for (const auto& dialect : dialects) {
        for (bool extra : {false, true}) {
            CAPTURE(dialect.separator);
            CAPTURE(dialect.comma);
            CAPTURE(extra);
            ReadResult r = read_text(columns_text(xyz, dialect.separator, dialect.comma, extra));
            REQUIRE_MESSAGE(r.ok, r.error);
            CHECK(r.info.format == CloudFormat::xyz);
            CHECK(r.xyz == xyz);
        }
    }
}

TEST_CASE("a semicolon-separated file with decimal commas, as European software writes it") {
    ReadResult r = read_text("x;y;z\n0,0675;0,8916;2,1769\n-1,5;2;1e3\n,5;-,25;3,\n");
    REQUIRE_MESSAGE(r.ok, r.error);
    CHECK(r.xyz == std::vector<double>{0.0675, 0.8916, 2.1769, -1.5, 2, 1000, 0.5, -0.25, 3});
}

TEST_CASE("a column file whose lines split differently, or with an empty field, is refused with the line") {
    const std::pair<const char*, std::vector<std::string>> cases[] = {
        {"1;2;3\n4,5,6\n", {"line 2: splits into 1 field at ';', where line 1 splits into 3"}},
        {"1;2;3\n4;5\n", {"line 2: splits into 2 fields at ';', where line 1 splits into 3"}},
        {"1,2,3\n4;5;6\n", {"line 2: splits into 1 field at ',', where line 1 splits into 3"}},
        {"1 2 3\n4,5,6\n", {"line 2: splits into 1 field at blanks, where line 1 splits into 3"}},
        {"1 2 3 4\n5 6 7\n", {"line 2: splits into 3 fields at blanks, where line 1 splits into 4"}},
        {"x,y,z\n1,2,3\n4,5,6,7\n", {"line 3: splits into 4 fields at ','"}},
        {"a,b,c\n1,,2,3\n", {"line 2: read as XYZ text (x y z columns), but field 2 is empty"}},
        {"1,2,3\n4,,5,6\n", {"line 2: field 2 is empty"}},
        {"1;2;3\n4;5;6;\n", {"line 2: field 4 is empty"}},
        {";1;2;3\n", {"line 1:", "field 1 is empty"}},
        {"1;2; ;3\n", {"line 1:", "field 3 is empty"}},
        {"1, 2,\t,3\n", {"line 1:", "field 3 is empty"}}};
    for (const auto& c : cases) {
        const std::string file = c.first;
        CAPTURE(file);
        ReadResult r = read_text(file);
        CHECK_FALSE(r.ok);
        for (const std::string& part : c.second) CHECK_MESSAGE(contains(r.error, part), r.error);
    }
}

TEST_CASE("thousands separators and a second decimal mark are refused with the line") {
    const std::pair<const char*, std::vector<std::string>> cases[] = {
        {"67.55 891.56 2,176.92\n", {"line 1:", "'2,176.92' has a thousands separator (',')"}},
        {"1 2 3\n67.55 891.56 2,176.92\n", {"line 2: '2,176.92' has a thousands separator (',')"}},
        {"1.5 2 3\n2,176 1 1\n", {"line 2: '2,176' has a thousands separator (',')"}},
        {"1,234,567 2 3\n", {"line 1:", "'1,234,567' has a thousands separator (',')"}},
        {"1.234,5;2;3\n", {"line 1:", "'1.234,5' has a thousands separator ('.')"}},
        {"1,5;2;3\n1.234;2;3\n", {"line 2: '1.234' has a thousands separator ('.')"}},
        {"-1,234.5e3 2 3\n", {"line 1:", "'-1,234.5e3' has a thousands separator (',')"}},
        {"1.5 2 3\n1,5 2 3\n",
         {"line 2: '1,5' has a decimal comma, where the file's decimal mark is a point (as line 1 writes it)"}},
        {"1;2,5;3\n1;2;3.5\n",
         {"line 2: '3.5' has a decimal point, where the file's decimal mark is a comma (as line 1 writes it)"}},
        {"1,5 2 3\n1.5 2 3\n", {"line 2: '1.5' has a decimal point"}},
        {"1.2.3 4 5\n", {"line 1:", "'1.2.3' is not a number"}},
        {"1,2,3\n4,5.5.5,6\n", {"line 2: '5.5.5' is not a number"}}};
    for (const auto& c : cases) {
        const std::string file = c.first;
        CAPTURE(file);
        ReadResult r = read_text(file);
        CHECK_FALSE(r.ok);
        for (const std::string& part : c.second) CHECK_MESSAGE(contains(r.error, part), r.error);
    }
    // In PLY, OFF and OBJ the decimal mark is a point.
    check_fails("ply\nformat ascii 1.0\nelement vertex 1\n" + std::string(kXyz) +
                    "end_header\n1,5 2 3\n",
                {"line 8: '1,5' has a decimal comma, where the file's decimal mark is a point"});
    check_fails("OFF\n1 0 0\n1 2 2,176.5\n", {"line 3: '2,176.5' has a thousands separator"});
    check_fails("v 1 2 3\nv 1,5 2 3\n", {"line 2: '1,5' has a decimal comma"});
}

TEST_CASE("fields part at blanks, and at commas and semicolons when asked, no other byte") {
    for (int byte = 0; byte < 256; ++byte) {
        const char c = static_cast<char>(byte);
        CAPTURE(byte);
        const bool blank = c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
        for (bool commas : {false, true}) {
            const bool separates = blank || (commas && (c == ',' || c == ';'));
            const std::string line = std::string("12") + c + "34";
            std::string_view rest = line;
            std::string_view field;
            std::vector<std::string> fields;
            while (next_field(rest, field, commas)) fields.emplace_back(field);
            if (separates)
                CHECK(fields == std::vector<std::string>{"12", "34"});
            else
                CHECK(fields == std::vector<std::string>{line});
        }
    }
}

TEST_CASE("numbers read in one pass are the fields and numbers of the two-step scan") {
    const char* pieces[] = {"1",    "-2.5e3", "+4",    ".5",    "-.5",     "1e400",  "-1e-400",
                            "nan",  "-inf",   "inf",   "1e",    "1.5x",    "0x10",   "abc",
                            "5+3",  "+",      "-",     "1,2",   "3;4",     "1e5",    "7.25E-2",
                            "00012", "1..2",  "\xff",  "1,5",   "2,176.92", "1.#INF", "-1.#IND00",
                            "+nan", "1.",     ",5",    "1.#J",  "nan(ind)", "1 ,2"};
    const size_t kPieces = sizeof pieces / sizeof pieces[0];
    const char* separators[] = {" ", "\t", "  ", " \t", "\r", "\v", "\f", ""};
    std::mt19937 random(99);
    for (int round = 0; round < 5000; ++round) {
        std::string line;
        const int count = static_cast<int>(random() % 6);
        for (int k = 0; k < count; ++k) {
            line += separators[random() % 8];
            line += pieces[random() % kPieces];
        }
        line += separators[random() % 8];
        CAPTURE(line);
        for (char start_mark : {kEitherMark, '.', ','}) {
            std::string_view two = line, one = line, field_two, field_one;
            char mark_two = start_mark, mark_one = start_mark;
            for (;;) {
                double value_two = -7, value_one = -7;
                NumberParse parsed_one = NumberParse::ok;
                const bool more_two = next_field(two, field_two, false);
                const bool more_one = next_number(one, field_one, value_one, parsed_one, mark_one);
                REQUIRE(more_two == more_one);
                if (!more_two) break;
                const NumberParse parsed_two = scan_number(field_two, mark_two, value_two);
                CHECK(field_one == field_two);
                CHECK(parsed_one == parsed_two);
                CHECK(mark_one == mark_two);
                if (parsed_two == NumberParse::ok)
                    CHECK(std::memcmp(&value_one, &value_two, sizeof(double)) == 0);
                CHECK(one.data() == two.data());
            }
        }
    }
}

TEST_CASE("every NaN and infinity spelling in use is read as not finite, by every reader") {
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const std::pair<const char*, double> spellings[] = {
        {"nan", nan},          {"NaN", nan},          {"NAN", nan},         {"-nan", nan},
        {"+nan", nan},         {"nan(ind)", nan},     {"-nan(ind)", nan},   {"nan(snan)", nan},
        {"NaNQ", nan},         {"NaNS", nan},         {"-NaNQ", nan},       {"1.#IND", nan},
        {"-1.#IND", nan},      {"1.#QNAN", nan},      {"-1.#QNAN", nan},    {"1.#SNAN", nan},
        {"1.#IND00", nan},     {"-1.#IND000000", nan}, {"1.#QNAN0", nan},   {"1.#ind", nan},
        {"1,#IND", nan},       {"-1.#IND00e+000", nan}, {"inf", inf},       {"INF", inf},
        {"Inf", inf},          {"+inf", inf},         {"-inf", -inf},       {"infinity", inf},
        {"Infinity", inf},     {"-Infinity", -inf},   {"+INFINITY", inf},   {"1.#INF", inf},
        {"-1.#INF", -inf},     {"1.#INF00", inf},     {"-1.#INF000000", -inf},
        {"1.#INF00e+000", inf}, {"1,#INF", inf}};
    for (const auto& spelling : spellings) {
        const std::string token = spelling.first;
        CAPTURE(token);
        const std::string files[] = {
            "1 2 3\n0.5 0.5 " + token + "\n",
            "1;2;3\n0,5;0,5;" + token + "\n",
            "1,2,3\n0.5,0.5," + token + "\n",
            "ply\nformat ascii 1.0\nelement vertex 2\n" + std::string(kXyz) +
                "end_header\n1 2 3\n0.5 0.5 " + token + "\n",
            "OFF\n2 0 0\n1 2 3\n0.5 0.5 " + token + "\n",
            "v 1 2 3\nv 0.5 0.5 " + token + "\n"};
        for (const std::string& file : files) {
            CAPTURE(file);
            // A comma-separated file cannot hold MSVC's spellings with a decimal comma.
            if (file[1] == ',' && token.find(',') != std::string::npos) continue;
            ReadResult r = read_text(file);
            REQUIRE_MESSAGE(r.ok, r.error);
            REQUIRE(r.xyz.size() == 6);
            CHECK(r.xyz[3] == 0.5);
            CHECK(r.xyz[4] == 0.5);
            if (std::isnan(spelling.second))
                CHECK(std::isnan(r.xyz[5]));
            else
                CHECK(r.xyz[5] == spelling.second);
        }
    }
}

TEST_CASE("a '#' inside a field is no comment: spellings cut short are not numbers") {
    for (const char* token : {"1.#J", "-1.#J", "1.$", "1.#IO", "1.#R", "1.#INFx", "1.#INF0x",
                              "1#", "3#c", "1.#IND00e", "2.#INF", "1.#NAN", "nanx",
                              "++1", "+-1", "NA", "1.#INFe+0x"}) {
        const std::string quoted = "'" + std::string(token) + "' is not a number";
        CAPTURE(quoted);
        check_fails("1 2 3\n0.5 0.5 " + std::string(token) + "\n", {"line 2: " + quoted});
        check_fails("ply\nformat ascii 1.0\nelement vertex 1\n" + std::string(kXyz) +
                        "end_header\n0.5 0.5 " + token + "\n",
                    {"line 8: " + quoted});
        check_fails("OFF\n1 0 0\n0.5 0.5 " + std::string(token) + "\n", {"line 3: " + quoted});
        check_fails("v 1 2 3\nv 0.5 0.5 " + std::string(token) + "\n", {"line 2: " + quoted});
    }
    // A comment starts a field: at the line's start or after a blank.
    ReadResult r = read_text("#c\n1 2 3 #c\n4 5 6\t// c\n  # c\n7 8 9//c\n");
    CHECK_FALSE(r.ok);
    CHECK_MESSAGE(contains(r.error, "line 5: '9//c' is not a number"), r.error);
    r = read_text("#c\n1 2 3 #c\n4 5 6\t// c\n  # c\n7 8 9 //c\n");
    REQUIRE_MESSAGE(r.ok, r.error);
    CHECK(r.xyz == std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9});
}

TEST_CASE("PTS with a count line, and a leading plus sign") {
    ReadResult r = read_text("3\n1 2 3 -50 255 255 255\n+4 5e0 6 10 1 2 3\n.5 -0 7 0 0 0 0\n");
    REQUIRE_MESSAGE(r.ok, r.error);
    CHECK(r.xyz == std::vector<double>{1, 2, 3, 4, 5, 6, 0.5, 0, 7});
}

TEST_CASE("XYZ keeps NaN and infinite coordinates for the library to judge") {
    ReadResult r = read_text("1 2 3\nnan nan nan\n4 inf -inf\n");
    REQUIRE_MESSAGE(r.ok, r.error);
    REQUIRE(r.xyz.size() == 9);
    CHECK(std::isnan(r.xyz[3]));
    CHECK(r.xyz[7] == std::numeric_limits<double>::infinity());
}

TEST_CASE("OFF: comments, counts on the keyword line or the next, extra vertex columns") {
    std::vector<double> xyz = test_points(12);
    std::string body;
    for (size_t i = 0; i < 12; ++i)
        body += exact_text(xyz[3 * i]) + " " + exact_text(xyz[3 * i + 1]) + " " +
                exact_text(xyz[3 * i + 2]) + (i % 2 ? " 0 0 1\n" : "\n");
    body += "3 0 1 2\n3 2 3 4\n";
    for (const std::string& head :
         {std::string("OFF\n# comment\n\n12 2 0\n"), std::string("NOFF 12 2 0\n"),
          std::string("# leading comment\nCOFF\r\n12 2 0\r\n")}) {
        ReadResult r = read_text(head + body);
        REQUIRE_MESSAGE(r.ok, r.error);
        CHECK(r.info.format == CloudFormat::off);
        CHECK(r.xyz == xyz);
    }
}

TEST_CASE("OBJ: v lines only, with vn, vt, f, groups and comments ignored") {
    std::vector<double> xyz = test_points(10);
    std::string text = "# exported\nmtllib a.mtl\no thing\n";
    for (size_t i = 0; i < 10; ++i) {
        text += "v " + exact_text(xyz[3 * i]) + " " + exact_text(xyz[3 * i + 1]) + " " +
                exact_text(xyz[3 * i + 2]) + (i % 2 ? " 1.0\n" : "\n");
        text += "vn 0 0 1\nvt 0.5 0.5\n";
    }
    text += "g side\nf 1/1/1 2/2/2 3/3/3\nf 1//1 3//3 4//4\n";
    ReadResult r = read_text(text);
    REQUIRE_MESSAGE(r.ok, r.error);
    CHECK(r.info.format == CloudFormat::obj);
    CHECK(r.xyz == xyz);
}

// ==== cloud readers: malformed input ======================================================

TEST_CASE("truncated binary PLY") {
    std::string whole = busy_binary_ply(test_points(10), false);
    check_fails(whole.substr(0, whole.size() - 20), {"byte", "vertex"});
    std::string header = little_ply_header(std::string("element vertex 10\n") + kXyz);
    check_fails(header + std::string(12 * 5, '\0'), {"byte", "declares 10 records of 12 bytes"});
}

TEST_CASE("a list running past the end of the file") {
    Bytes b{false, little_ply_header("element face 1\nproperty list uint int v\n"
                                     "element vertex 1\n" +
                                     std::string(kXyz))};
    b.put<uint32_t>(4000000000u).put<int32_t>(1);
    check_fails(b.data, {"byte", "ends inside element 'face' record 0"});
}

TEST_CASE("a negative list length in a signed count type") {
    Bytes b{false, little_ply_header("element face 1\nproperty list char int v\n"
                                     "element vertex 1\n" +
                                     std::string(kXyz))};
    b.put<int8_t>(-1);
    check_fails(b.data, {"byte", "negative length"});
}

TEST_CASE("a vertex count of 4000000000 is caught before any allocation") {
    std::string lie = std::string("element vertex 4000000000\n") + kXyz;
    check_fails(little_ply_header(lie) + std::string(36, '\0'), {"declares 4000000000"});
    check_fails("ply\nformat ascii 1.0\n" + lie + "end_header\n1 2 3\n",
                {"line 8", "ends before element 'vertex' record 1 of 4000000000"});
}

TEST_CASE("element counts that overflow") {
    std::string fixed = "element face 18446744073709551615\nproperty uchar a\nproperty double b\n";
    check_fails(little_ply_header(fixed + "element vertex 1\n" + kXyz) + std::string(64, '\0'),
                {"declares 18446744073709551615"});
    std::string lists = "element face 18446744073709551615\nproperty list uchar int v\n";
    check_fails(little_ply_header(lists + "element vertex 1\n" + kXyz) + std::string(64, '\0'),
                {"ends inside element 'face'"});
    check_fails(little_ply_header("element vertex 99999999999999999999\n"), {"is too large"});
}

TEST_CASE("bad counts and types in a PLY header") {
    check_fails(little_ply_header("element vertex -5\n"), {"line 3", "is negative"});
    check_fails(little_ply_header("element vertex lots\n"), {"line 3", "not a whole number"});
    check_fails(little_ply_header("element vertex 1\nproperty float128 x\n"),
                {"line 4", "unknown property type 'float128'"});
    check_fails(little_ply_header("element face 1\nproperty list float int v\n"),
                {"line 4", "must be an integer type"});
    check_fails(little_ply_header("property float x\n"), {"before any 'element'"});
    check_fails(little_ply_header("elephant vertex 1\n"), {"unknown header keyword"});
    check_fails("ply\nformat binary_middle_endian 1.0\nend_header\n", {"unknown encoding"});
    check_fails("ply\nelement vertex 0\nend_header\n", {"no 'format' line"});
    check_fails("ply\nformat ascii 1.0\nelement vertex 1\n", {"no 'end_header'"});
}

TEST_CASE("missing or unusable x, y, z") {
    check_fails(little_ply_header("element vertex 1\nproperty float x\nproperty float y\n"),
                {"no 'z' property"});
    check_fails(little_ply_header("element vertex 1\nproperty float x\nproperty float y\n"
                                  "property list uchar float z\n"),
                {"'z' is a list"});
    check_fails(little_ply_header("element face 0\n"), {"no 'vertex' element"});
}

TEST_CASE("a file that is only a header") {
    check_fails(little_ply_header(std::string("element vertex 3\n") + kXyz),
                {"byte", "declares 3 records"});
    check_fails("ply\nformat ascii 1.0\nelement vertex 3\n" + std::string(kXyz) + "end_header\n",
                {"line 7", "ends before element 'vertex' record 0 of 3"});
}

TEST_CASE("garbage in text files names the line") {
    check_fails("1 2 3\n4 5 6\n7 x 9\n", {"line 3", "'x' is not a number"});
    check_fails("1 2\n", {"line 1: read as XYZ text (x y z columns), but found 2 numbers where "
                           "a point needs at least 3 (x y z)"});
    check_fails("1 2 3\n4 5\n", {"line 2: splits into 2 fields at blanks, where line 1 splits into 3"});
    check_fails("1 2 3 4 5 6 7\n4 5 6 7 8 9 oops\n", {"line 2: 'oops' is not a number"});
    check_fails("ply\nformat ascii 1.0\nelement vertex 2\n" + std::string(kXyz) +
                    "end_header\n1 2 3\n4 five 6\n",
                {"line 9", "'five' is not a number"});
    check_fails("OFF\n2 0 0\n1 2 3\n1 2\n", {"line 4: found 2 numbers where a point needs at least 3"});
    check_fails("v 1 2 3\nv 1 2\n", {"line 2: found 2 numbers where a point needs at least 3"});
    check_fails(std::string("1 2 3\n\x01\x02\xff 5 6\n", 14), {"line 2", "\\x01\\x02\\xff"});
}

TEST_CASE("a text file that is no cloud says how it was read and what was expected") {
    check_fails("stratmesh 0.1.0 report\n",
                {"line 1: read as XYZ text (x y z columns), but 'stratmesh' is not a number"});
    check_fails("Hello\nworld\n",
                {"line 2: read as XYZ text (x y z columns), but 'world' is not a number"});
    check_fails("title\n", {"no points found: read as XYZ text (x y z columns), no line holds a point"});
    // Once a point is read, a bad line is a bad point line.
    check_fails("1 2 3\nstratmesh 2 3\n", {"line 2: 'stratmesh' is not a number"});
}

TEST_CASE("PLY: only version 1.0 of the format is read") {
    for (const std::string version : {"2.0", "1.1", "1", "1.00", "0.9"}) {
        CAPTURE(version);
        check_fails("ply\nformat ascii " + version + "\nelement vertex 1\n" + kXyz +
                        "end_header\n1 2 3\n",
                    {"line 2: PLY version '" + version + "' is not read (only 1.0)"});
        check_fails("ply\nformat binary_little_endian " + version +
                        "\nelement vertex 0\n" + kXyz + "end_header\n",
                    {"line 2: PLY version"});
    }
}

TEST_CASE("PLY: an integer property takes an integer, written as one") {
    auto ply = [](const std::string& value) {
        return "ply\nformat ascii 1.0\nelement vertex 1\n" + std::string(kXyz) +
               "property int label\nproperty uchar red\nelement face 1\n"
               "property list uchar int vertex_indices\nend_header\n1 2 3 " +
               value + " 7\n3 0 0 0\n";
    };
    for (const auto& good : {std::pair<const char*, double>{"100", 100}, {"+100", 100},
                             {"-5", -5}, {"0", 0}, {"-0", 0}, {"-2147483648", -2147483648.0},
                             {"0002147483647", 2147483647.0}}) {
        const std::string value = good.first;
        CAPTURE(value);
        ReadResult r;
        r.info.keep_attributes = true;
        const std::string bytes = ply(good.first);
        r.ok = read_cloud_from_memory(bytes.data(), bytes.size(), CloudFormat::automatic, r.xyz,
                                      r.error, &r.info);
        REQUIRE_MESSAGE(r.ok, r.error);
        CHECK(r.xyz == std::vector<double>{1, 2, 3});
        REQUIRE(r.info.attributes.find("label") == 0);
        CHECK(r.info.attributes.value(0, 0) == good.second);
    }
    const std::pair<const char*, const char*> bad[] = {
        {"1e2", "'1e2' is not an integer (digits with an optional sign), as int requires"},
        {"100.0", "'100.0' is not an integer (digits with an optional sign), as int requires"},
        {"0.66", "'0.66' is not an integer"},
        {"nan", "'nan' is not an integer"},
        {"-1.#IND", "'-1.#IND' is not an integer"},
        {"2147483648", "'2147483648' is out of the range of int"},
        {"99999999999999999999999", "'99999999999999999999999' is out of the range of int"},
        {"1,000", "'1,000' has a thousands separator (',')"},
        {"x", "'x' is not a number"}};
    for (const auto& c : bad) {
        const std::string value = c.first;
        CAPTURE(value);
        check_fails(ply(value), {"line 12: " + std::string(c.second),
                                 "(property 'label' of element 'vertex' record 0 of 1)"});
    }
    // A list's length too.
    const std::string list = "ply\nformat ascii 1.0\nelement vertex 1\n" + std::string(kXyz) +
                             "element face 1\nproperty list uchar int vertex_indices\n"
                             "end_header\n1 2 3\n";
    check_fails(list + "3e0 0 0 0\n", {"line 11: '3e0' is not an integer", "property 'vertex_indices'"});
    check_fails(list + "3 0 1e0 0\n", {"line 11: '1e0' is not an integer"});
}

TEST_CASE("OFF: a face naming a vertex beyond the file's is refused with the line") {
    const std::string head = "OFF\n# a comment\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n";
    ReadResult r = read_text(head + "3 1 2 3 0.5 0.5 0.5\n");
    REQUIRE_MESSAGE(r.ok, r.error);
    CHECK(r.info.faces_ignored == 2);
    check_fails(head + "3 1 2 4\n",
                {"line 9: face 1 names vertex 4, but the file has 4 vertices (numbered from 0)"});
    check_fails(head + "3 5000 1 2\n", {"line 9: face 1 names vertex 5000"});
    check_fails("OFF\n0 1 0\n3 0 0 0\n", {"line 3: face 0 names vertex 0, but the file has 0 vertices"});
}

TEST_CASE("CR-only line ends are refused, saying so, and CRLF and LF are read") {
    const std::string cr_message = "a carriage return (CR) without a line feed: lines ended by CR "
                                   "alone, as classic Mac OS wrote them, are not read";
    auto with_ends = [](std::string text, const std::string& end) {
        std::string out;
        for (char c : text) out += c == '\n' ? end : std::string(1, c);
        return out;
    };
    const std::string files[] = {
        "ply\nformat ascii 1.0\nelement vertex 3\n" + std::string(kXyz) +
            "end_header\n1 2 3\n4 5 6\n7 8 9\n",
        "# points\n1 2 3\n4 5 6\n7 8 9\n", "x;y;z\n1;2;3\n4;5;6\n7;8;9\n",
        "OFF\n3 0 0\n1 2 3\n4 5 6\n7 8 9\n", "# obj\nv 1 2 3\nv 4 5 6\nv 7 8 9\n"};
    for (const std::string& file : files) {
        CAPTURE(file);
        for (const char* end : {"\n", "\r\n"}) {
            ReadResult r = read_text(with_ends(file, end));
            REQUIRE_MESSAGE(r.ok, r.error);
            CHECK(r.xyz == std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9});
        }
        check_fails(with_ends(file, "\r"), {"line 1: " + cr_message});
    }
    // A binary PLY header with CR-only line ends.
    check_fails("ply\rformat binary_little_endian 1.0\relement vertex 0\rend_header\r",
                {"line 1: " + cr_message});
    // A lone CR anywhere, even in a comment, where it would hide the points after it.
    check_fails("1 2 3\n# note\r4 5 6\n7 8 9\n", {"line 2: " + cr_message});
    check_fails("1 2 3\n4 5 6\r\r\n7 8 9\n", {"line 2: " + cr_message});
    check_fails("ply\nformat ascii 1.0\nelement vertex 2\n" + std::string(kXyz) +
                    "end_header\n1 2 3\n4 5\r6\n",
                {"line 9: " + cr_message});
    check_fails("ply\nformat ascii 1.0\nelement vertex 0\ncomment a\rb\nend_header\n",
                {"line 4: " + cr_message});
    // A CR as the very last byte ends the last line (CRLF cut short).
    ReadResult r = read_text("1 2 3\n4 5 6\n7 8 9\r");
    REQUIRE_MESSAGE(r.ok, r.error);
    CHECK(r.xyz.size() == 9);
}

TEST_CASE("empty and pointless files") {
    check_fails("", {"empty"});
    check_fails("# nothing here\n\n", {"no points"});
    check_fails("OFF\n4000000000 0 0\n1 2 3\n", {"line 3", "after 1 of the 4000000000 vertices"});
    check_fails("OFF\n-4 0 0\n", {"line 2", "is negative"});
    check_fails("OFF BINARY\n", {"binary OFF"});
    check_fails("4OFF\n1 0 0\n1 2 3 4\n", {"'4OFF' files are not supported"});
    check_fails("OFF\n", {"vertex count is missing"});
    ReadResult mark_only = read_text(std::string(kByteOrderMark), CloudFormat::ply);
    CHECK_FALSE(mark_only.ok);
    CHECK(contains(mark_only.error, "line 1: not a PLY file"));
    ReadResult forced = read_text("1 2 3\n", CloudFormat::obj);
    CHECK_FALSE(forced.ok);
    CHECK(contains(forced.error, "no 'v' line"));
}

// The number after "byte " in a message, or SIZE_MAX if there is none.
size_t byte_named(const std::string& error) {
    size_t at = error.find("byte ");
    return at == std::string::npos ? SIZE_MAX : std::stoul(error.substr(at + 5));
}

bool names_line(const std::string& error) {
    size_t at = error.find("line ");
    return at != std::string::npos && at + 5 < error.size() && std::isdigit(error[at + 5]);
}

TEST_CASE("every truncation and many corruptions of valid files fail cleanly") {
    // Under the sanitizers this is a small deterministic fuzz run of all the readers.
    std::vector<double> xyz = test_points(6);
    struct File {
        std::string bytes;
        size_t points;  // what the whole file holds
        bool binary;    // a PLY binary body: any truncation is an error at a byte offset
        bool counted;   // a header counts the points: a truncation never gives fewer
    };
    const File files[] = {
        {busy_binary_ply(xyz, false), 6, true, true},
        {double_binary_ply(xyz, true), 6, true, true},
        {ascii_ply(xyz, "\n"), 6, false, true},
        {"OFF\n3 1 0\n1 2 3\n4 5 6\n7 8 9\n3 0 1 2\n", 3, false, true},
        {"v 1 2 3\nv 4 5 6\nf 1 2 3\n", 2, false, false},
        {"3\n1 2 3\n4 5 6\n7 8 9\n", 3, false, true}};
    std::mt19937 random(12345);
    for (const File& f : files) {
        const std::string& file = f.bytes;
        for (size_t length = 0; length < file.size(); ++length) {
            CAPTURE(length);
            ReadResult r = read_text(file.substr(0, length));
            if (f.binary) {
                // Ends before the body's last byte: an error, at a byte within what is
                // there (or at a line of the header).
                REQUIRE_FALSE(r.ok);
                // (The first bytes, "ply" without its line end, are no PLY file yet.)
                CHECK((byte_named(r.error) <= length || names_line(r.error) || length == 0 ||
                       contains(r.error, "no points found")));
            } else if (r.ok) {
                CHECK(r.xyz.size() / 3 <= f.points);
                if (f.counted) CHECK(r.xyz.size() / 3 == f.points);
            } else {
                CHECK((names_line(r.error) || length == 0 ||
                       contains(r.error, "no points found") || contains(r.error, "no vertices found")));
            }
        }
        ReadResult whole = read_text(file);
        REQUIRE_MESSAGE(whole.ok, whole.error);
        CHECK(whole.xyz.size() / 3 == f.points);
        for (int round = 0; round < 300; ++round) {
            std::string bent = file;
            bent[random() % bent.size()] = static_cast<char>(random() & 0xff);
            ReadResult r = read_text(bent);
            CHECK((r.ok || !r.error.empty()));
        }
    }
}

// ==== format detection ====================================================================

TEST_CASE("the content decides the format") {
    auto detect = [](const std::string& s) { return detect_cloud_format(s.data(), s.size()); };
    CHECK(detect("ply\nformat ascii 1.0\n") == CloudFormat::ply);
    CHECK(detect("ply\r\nformat ascii 1.0\r\n") == CloudFormat::ply);
    CHECK(detect("ply\rformat ascii 1.0\r") == CloudFormat::ply);
    CHECK(detect("OFF\n3 1 0\n") == CloudFormat::off);
    CHECK(detect("# c\nSTCNOFF\n") == CloudFormat::off);
    CHECK(detect("# obj\nmtllib x.mtl\no a\nv 1 2 3\n") == CloudFormat::obj);
    CHECK(detect("1 2 3\n") == CloudFormat::xyz);
    CHECK(detect("x,y,z\n1,2,3\n") == CloudFormat::xyz);
    CHECK(detect("plywood 1 2\n") == CloudFormat::xyz);
    CHECK(detect("") == CloudFormat::xyz);
}

TEST_CASE("a misleading extension does not matter") {
    TempDir dir;
    std::vector<double> xyz = test_points(8);
    save(dir.file("scan.xyz"), busy_binary_ply(xyz, false));
    save(dir.file("scan.ply"), "v 1 2 3\nv 4 5 6\n");
    save(dir.file("scan.off"), "1 2 3\n");
    save(dir.file("scan.obj"), "OFF\n1 0 0\n1 2 3\n");
    const struct {
        const char* name;
        CloudFormat format;
        size_t points;
    } cases[] = {{"scan.xyz", CloudFormat::ply, 8},
                 {"scan.ply", CloudFormat::obj, 2},
                 {"scan.off", CloudFormat::xyz, 1},
                 {"scan.obj", CloudFormat::off, 1}};
    for (const auto& c : cases) {
        std::vector<double> got;
        std::string error;
        CloudInfo info;
        REQUIRE_MESSAGE(read_cloud_file(dir.file(c.name), got, error, &info), error);
        CHECK(info.format == c.format);
        CHECK(got.size() == 3 * c.points);
    }
}

TEST_CASE("file errors name the file") {
    TempDir dir;
    std::vector<double> xyz;
    std::string error;
    CHECK_FALSE(read_cloud_file(dir.file("missing.ply"), xyz, error));
    CHECK(contains(error, dir.file("missing.ply") + ": cannot open"));
    save(dir.file("bad.xyz"), "1 2 3\nfour 5 6\n");
    CHECK_FALSE(read_cloud_file(dir.file("bad.xyz"), xyz, error));
    CHECK(contains(error, dir.file("bad.xyz") + ": line 2"));
    CHECK_FALSE(read_cloud_file(dir.path.string(), xyz, error));
    CHECK(contains(error, "cannot read"));
}

TEST_CASE("extensions") {
    CHECK(cloud_format_from_extension("a/b.PLY") == CloudFormat::ply);
    CHECK(cloud_format_from_extension("scan.pts") == CloudFormat::xyz);
    CHECK(cloud_format_from_extension("x.y/noext") == CloudFormat::automatic);
    CHECK(mesh_format_from_extension("out.Stl") == MeshFormat::stl);
    CHECK(mesh_format_from_extension("out.xyz") == MeshFormat::unknown);
}

// ==== mesh writers ========================================================================

// ==== point-by-point reading (--stream) ===================================================

namespace {

// Every point of a file through open_point_reader; false with the error if it fails.
bool read_streamed(const std::string& path, std::vector<double>& xyz, std::string& error,
                   CloudInfo& info) {
    std::unique_ptr<PointReader> reader = open_point_reader(path, info, error);
    if (!reader) return false;
    xyz.clear();
    double point[3];
    while (reader->next(point, error)) xyz.insert(xyz.end(), point, point + 3);
    return error.empty();
}

// Binary PLY of float records with no list: a fixed-size element before the vertices and
// a face list after them.
std::string fixed_binary_ply(const std::vector<double>& xyz, bool big_endian) {
    size_t n = xyz.size() / 3;
    std::string header = std::string("ply\nformat ") +
                         (big_endian ? "binary_big_endian" : "binary_little_endian") +
                         " 1.0\nelement camera 2\nproperty double view\nproperty uchar id\n"
                         "element vertex " + std::to_string(n) + "\n" + kXyz +
                         "property uchar red\nelement face 1\n"
                         "property list uchar int vertex_indices\nend_header\n";
    Bytes b{big_endian, header};
    b.put<double>(1.5).put<uint8_t>(1).put<double>(-2.5).put<uint8_t>(2);
    for (size_t i = 0; i < n; ++i) {
        for (size_t k = 0; k < 3; ++k) b.put(static_cast<float>(xyz[3 * i + k]));
        b.put<uint8_t>(9);
    }
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
    return b.data;
}

std::string xyz_text(const std::vector<double>& xyz, const char* separator) {
    std::string text = "x y z\n# a comment\n\n";
    for (size_t i = 0; i < xyz.size(); i += 3)
        text += exact_text(xyz[i]) + separator + exact_text(xyz[i + 1]) + separator +
                exact_text(xyz[i + 2]) + "\n";
    return text;
}

} // namespace

TEST_CASE("point by point reading gives the points of the whole-file readers") {
    TempDir dir;
    // 60000 points make every file longer than the reader's 1 MiB window.
    std::vector<double> xyz = test_points(60000);
    std::string obj = "o cloud\n";
    for (size_t i = 0; i < xyz.size(); i += 3)
        obj += "v " + exact_text(xyz[i]) + " " + exact_text(xyz[i + 1]) + " " +
               exact_text(xyz[i + 2]) + "\nvn 0 0 1\n";
    const std::pair<const char*, std::string> files[] = {
        {"little.ply", fixed_binary_ply(xyz, false)}, {"big.ply", fixed_binary_ply(xyz, true)},
        {"lf.ply", ascii_ply(xyz, "\n")},             {"crlf.ply", ascii_ply(xyz, "\r\n")},
        {"spaces.xyz", xyz_text(xyz, " ")},           {"commas.csv", xyz_text(xyz, ",")},
        {"european.csv", columns_text(xyz, ";", true, true)},
        {"decimal_comma.txt", columns_text(xyz, "\t", true, false)},
        {"cloud.obj", obj}};
    for (const auto& file : files) {
        CAPTURE(file.first);
        save(dir.file(file.first), file.second);
        std::vector<double> whole, streamed;
        std::string error;
        CloudInfo whole_info, streamed_info;
        REQUIRE_MESSAGE(read_cloud_file(dir.file(file.first), whole, error, &whole_info), error);
        REQUIRE_MESSAGE(read_streamed(dir.file(file.first), streamed, error, streamed_info), error);
        CHECK(streamed == whole);
        CHECK(streamed.size() == xyz.size());
        CHECK(streamed_info.format == whole_info.format);
        CHECK(streamed_info.encoding == whole_info.encoding);
        // The most points the file can hold (it sizes the stream's workspace): the PLY
        // header's count, or for text at least the points there are.
        if (streamed_info.format == CloudFormat::ply)
            CHECK(streamed_info.point_limit == xyz.size() / 3);
        else
            CHECK(streamed_info.point_limit >= xyz.size() / 3);
        CHECK(streamed_info.point_limit < UINT64_MAX);
    }
}

TEST_CASE("point by point reading: the most points a text file can hold bounds the shortest lines") {
    TempDir dir;
    // The shortest lines a point can take, with and without a line end on the last one.
    const std::pair<const char*, std::string> files[] = {
        {"short.xyz", "1 2 3\n4 5 6\n7 8 9\n"}, {"no_end.xyz", "1 2 3\n4 5 6\n7 8 9"},
        {"short.obj", "v 1 2 3\nv 4 5 6\nv 7 8 9"}};
    for (const auto& file : files) {
        CAPTURE(file.first);
        save(dir.file(file.first), file.second);
        std::vector<double> streamed;
        std::string error;
        CloudInfo info;
        REQUIRE_MESSAGE(read_streamed(dir.file(file.first), streamed, error, info), error);
        CHECK(streamed.size() == 9);
        CHECK(info.point_limit >= 3);
        CHECK(info.point_limit <= 4);
    }
}

TEST_CASE("point by point reading: what it cannot read, and errors that name the place") {
    TempDir dir;
    std::vector<double> xyz = test_points(10);
    std::string whole = fixed_binary_ply(xyz, false), ascii = ascii_ply(xyz, "\n");
    // A lone carriage return on line 50001, well past the reader's first window.
    std::string late_carriage_return, late_carriage_return_ply =
        "ply\nformat ascii 1.0\nelement vertex 60000\n" + std::string(kXyz) + "end_header\n";
    for (int i = 0; i < 60000; ++i) {
        const std::string line = std::to_string(i) + (i == 50000 ? " 1.25\r2\n" : " 1.25 2\n");
        late_carriage_return += line;
        late_carriage_return_ply += line;
    }
    const struct {
        const char* name;
        std::string bytes;
        const char* message;
    } cases[] = {
        {"truncated.ply", whole.substr(0, whole.size() - 40),
         "the file ends inside element 'vertex' record 7 of 10"},
        {"listed.ply", double_binary_ply(xyz, false), "the vertex element has list properties"},
        {"face_first.ply", busy_binary_ply(xyz, false), "element 'face' comes before the vertices"},
        {"mesh.off", "OFF\n3 1 0\n1 2 3\n4 5 6\n7 8 9\n3 0 1 2\n", "OFF files cannot be read"},
        {"bad.xyz", "1 2 3\n4 5 6\n7 eight 9\n", "line 3: 'eight' is not a number"},
        {"ascii_short.ply", ascii.substr(0, ascii.size() - 30),
         "the line ends before property 'z' of element 'vertex' record 9 of 10"},
        {"empty.xyz", "", "the file is empty"},
        {"cr_only.xyz", "1 2 3\r4 5 6\r", "line 1: a carriage return (CR) without a line feed"},
        {"cr_only.ply", "ply\rformat ascii 1.0\r", "line 1: a carriage return (CR) without a line feed"},
        {"late_cr.xyz", late_carriage_return, "line 50001: a carriage return (CR) without a line feed"},
        {"late_cr.ply", late_carriage_return_ply,
         "line 50008: a carriage return (CR) without a line feed"},
        {"split.csv", "1;2;3\n4;5;6\n7,8,9\n", "line 3: splits into 1 field at ';', where line 1 splits into 3"},
        {"thousands.xyz", "1 2 3\n67.55 891.56 2,176.92\n",
         "line 2: '2,176.92' has a thousands separator (',')"}};
    for (const auto& c : cases) {
        std::string name = c.name;
        CAPTURE(name);
        save(dir.file(c.name), c.bytes);
        std::vector<double> got;
        std::string error;
        CloudInfo info;
        CHECK_FALSE(read_streamed(dir.file(c.name), got, error, info));
        CHECK_MESSAGE(contains(error, c.message), error);
    }
}

namespace {

struct WrittenMesh {
    std::vector<double> xyz;
    std::vector<uint32_t> tris;
};

// Six points, four triangles; point 5 is used by none and must still be written.
WrittenMesh small_mesh(bool float_exact) {
    WrittenMesh m;
    m.xyz = test_points(6);
    if (float_exact) m.xyz = rounded_to_float(m.xyz);
    m.tris = {0, 1, 2, 0, 2, 3, 0, 3, 4, 1, 4, 2};
    return m;
}

mini_mesh::Mesh write_and_read(const WrittenMesh& m, const std::string& path, bool ascii) {
    MeshView view = {m.xyz.data(), m.xyz.size() / 3, m.tris.data(), m.tris.size() / 3};
    std::string error;
    AtomicFile file;
    REQUIRE_MESSAGE(file.open(path, error), error);
    REQUIRE_MESSAGE(write_mesh_file(file, mesh_format_from_extension(path), view, ascii, error),
                    error);
    REQUIRE_MESSAGE(commit_files({&file}, error), error);
    mini_mesh::Mesh back;
    REQUIRE(mini_mesh::read(path, back));
    return back;
}

} // namespace

TEST_CASE("PLY, OBJ and OFF output: every vertex in input order, exact, triangles unchanged") {
    TempDir dir;
    for (bool float_exact : {false, true}) {
        WrittenMesh m = small_mesh(float_exact);
        const std::pair<const char*, bool> outputs[] = {
            {"m.ply", false}, {"m.ply", true}, {"m.obj", false}, {"m.off", false}};
        for (const auto& out : outputs) {
            CAPTURE(out.first);
            CAPTURE(out.second);
            mini_mesh::Mesh back = write_and_read(m, dir.file(out.first), out.second);
            CHECK(back.xyz == m.xyz);
            CHECK(back.tris == m.tris);
        }
    }
}

TEST_CASE("the stream writer, fed piece by piece, writes what write_mesh_file writes") {
    TempDir dir;
    for (bool float_exact : {false, true}) {
        WrittenMesh m = small_mesh(float_exact);
        const std::pair<const char*, bool> outputs[] = {
            {"m.ply", false}, {"m.ply", true}, {"m.off", false}, {"m.obj", false}};
        for (const auto& out : outputs) {
            std::string name = out.first;
            CAPTURE(name);
            CAPTURE(out.second);
            mini_mesh::Mesh whole = write_and_read(m, dir.file("whole_" + name), out.second);
            std::string path = dir.file("pieces_" + name), error;
            AtomicFile file;
            REQUIRE_MESSAGE(file.open(path, error), error);
            MeshStreamWriter writer;
            REQUIRE_MESSAGE(writer.open(file, mesh_format_from_extension(path), out.second, error),
                            error);
            // Vertices 0-2, the triangle over them, the other vertices, the rest.
            writer.add_vertices(m.xyz.data(), 3);
            writer.add_triangles(m.tris.data(), 1);
            writer.add_vertices(m.xyz.data() + 9, m.xyz.size() / 3 - 3);
            writer.add_triangles(m.tris.data() + 3, m.tris.size() / 3 - 1);
            REQUIRE_MESSAGE(writer.finish(error), error);
            REQUIRE_MESSAGE(commit_files({&file}, error), error);
            mini_mesh::Mesh pieces;
            REQUIRE(mini_mesh::read(path, pieces));
            CHECK(pieces.xyz == whole.xyz);
            CHECK(pieces.tris == whole.tris);
            std::string whole_bytes, piece_bytes;
            REQUIRE(mini_mesh::load(dir.file("whole_" + name), whole_bytes));
            REQUIRE(mini_mesh::load(path, piece_bytes));
            if (name != "m.obj") CHECK(piece_bytes == whole_bytes); // OBJ interleaves v and f
        }
    }
}

TEST_CASE("the stream writer leaves nothing behind when abandoned") {
    TempDir dir;
    std::string error;
    {
        AtomicFile file;
        REQUIRE(file.open(dir.file("m.ply"), error));
        MeshStreamWriter writer;
        REQUIRE(writer.open(file, MeshFormat::ply, false, error));
        // Only the output's temporary is there: the scratch bodies are unnamed.
        CHECK_FALSE(std::filesystem::exists(dir.file("m.ply")));
        CHECK(std::distance(std::filesystem::directory_iterator(dir.path),
                            std::filesystem::directory_iterator()) == 1);
    }
    CHECK(std::filesystem::is_empty(dir.path));
}

TEST_CASE("binary PLY uses float when every coordinate is a float, double otherwise") {
    TempDir dir;
    std::string bytes;
    write_and_read(small_mesh(true), dir.file("f.ply"), false);
    REQUIRE(mini_mesh::load(dir.file("f.ply"), bytes));
    CHECK(contains(bytes, "property float x\n"));
    write_and_read(small_mesh(false), dir.file("d.ply"), false);
    REQUIRE(mini_mesh::load(dir.file("d.ply"), bytes));
    CHECK(contains(bytes, "property double x\n"));
}

TEST_CASE("STL output: triangle corners to float precision, unit normals facing the winding") {
    TempDir dir;
    WrittenMesh m = small_mesh(false);
    for (bool ascii : {false, true}) {
        mini_mesh::Mesh back = write_and_read(m, dir.file("m.stl"), ascii);
        REQUIRE(back.xyz.size() == 3 * m.tris.size());
        REQUIRE(back.normals.size() == m.tris.size());
        for (size_t c = 0; c < m.tris.size(); ++c)
            for (size_t k = 0; k < 3; ++k)
                CHECK(static_cast<float>(back.xyz[3 * c + k]) ==
                      static_cast<float>(m.xyz[3 * m.tris[c] + k]));
        for (size_t t = 0; t < m.tris.size() / 3; ++t) {
            const double* a = &m.xyz[3 * m.tris[3 * t]];
            const double* b = &m.xyz[3 * m.tris[3 * t + 1]];
            const double* c = &m.xyz[3 * m.tris[3 * t + 2]];
            double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                           u[0] * v[1] - u[1] * v[0]};
            const float* got = &back.normals[3 * t];
            double dot = n[0] * double(got[0]) + n[1] * double(got[1]) + n[2] * double(got[2]);
            double len =
                std::sqrt(double(got[0]) * double(got[0]) + double(got[1]) * double(got[1]) +
                          double(got[2]) * double(got[2]));
            CHECK(len == doctest::Approx(1.0).epsilon(1e-6));
            CHECK(dot > 0);
        }
    }
}

namespace {

// A mesh large enough that every writer fills its block many times: points with awkward
// doubles (or their floats), two triangles per point, every vertex used.
WrittenMesh large_mesh(size_t points, bool float_exact) {
    WrittenMesh m;
    m.xyz = test_points(points);
    m.xyz[0] = -0.0;
    m.xyz[4] = 3e38;
    if (float_exact) m.xyz = rounded_to_float(m.xyz);
    if (!float_exact) m.xyz[8] = 1e300; // beyond float: the binary PLY holds doubles
    for (size_t i = 0; i < 2 * points; ++i) {
        const uint32_t a = static_cast<uint32_t>(i / 2);
        m.tris.insert(m.tris.end(), {a, static_cast<uint32_t>((a + 1 + i % 7) % points),
                                     static_cast<uint32_t>((a + 5 + 3 * (i % 11)) % points)});
    }
    return m;
}

} // namespace

TEST_CASE("large meshes: every format reads back bit for bit, the stream writer's bytes too") {
    TempDir dir;
    for (bool float_exact : {false, true}) {
        const WrittenMesh m = large_mesh(60000, float_exact);
        const std::pair<const char*, bool> outputs[] = {
            {"m.ply", false}, {"m.ply", true}, {"m.obj", false}, {"m.off", false}};
        for (const auto& out : outputs) {
            const std::string name = out.first;
            CAPTURE(name);
            CAPTURE(out.second);
            CAPTURE(float_exact);
            const std::string path = dir.file("whole_" + name);
            const mini_mesh::Mesh back = write_and_read(m, path, out.second);
            CHECK(back.tris == m.tris);
            std::vector<double> xyz;
            std::string error;
            REQUIRE_MESSAGE(read_cloud_file(path, xyz, error), error);
            CHECK(same_bits(xyz, m.xyz));
            if (name == "m.obj") continue; // the stream interleaves OBJ's lines
            const std::string pieces = dir.file("pieces_" + name);
            AtomicFile file;
            REQUIRE_MESSAGE(file.open(pieces, error), error);
            MeshStreamWriter writer;
            REQUIRE_MESSAGE(writer.open(file, mesh_format_from_extension(pieces), out.second,
                                        error),
                            error);
            const size_t half = m.xyz.size() / 6;
            writer.add_vertices(m.xyz.data(), half);
            writer.add_vertices(m.xyz.data() + 3 * half, m.xyz.size() / 3 - half);
            writer.add_triangles(m.tris.data(), m.tris.size() / 3);
            REQUIRE_MESSAGE(writer.finish(error), error);
            REQUIRE_MESSAGE(commit_files({&file}, error), error);
            std::string whole_bytes, piece_bytes;
            REQUIRE(mini_mesh::load(path, whole_bytes));
            REQUIRE(mini_mesh::load(pieces, piece_bytes));
            CHECK(whole_bytes == piece_bytes);
        }
    }
}

TEST_CASE("large meshes: STL corners are the vertices' floats, triangle by triangle") {
    TempDir dir;
    const WrittenMesh m = large_mesh(30000, false);
    // Binary STL clamps a finite double beyond float's range to the largest float; text
    // STL holds the double itself.
    auto as_float = [](double v, bool ascii) {
        const double largest = static_cast<double>(std::numeric_limits<float>::max());
        if (!ascii && std::isfinite(v) && std::fabs(v) > largest) v = v < 0 ? -largest : largest;
        return static_cast<float>(v);
    };
    for (bool ascii : {false, true}) {
        CAPTURE(ascii);
        const mini_mesh::Mesh back = write_and_read(m, dir.file("m.stl"), ascii);
        REQUIRE(back.xyz.size() == 3 * m.tris.size());
        size_t wrong = 0;
        for (size_t c = 0; c < m.tris.size(); ++c)
            for (size_t k = 0; k < 3; ++k)
                wrong += static_cast<float>(back.xyz[3 * c + k]) !=
                         as_float(m.xyz[3 * m.tris[c] + k], ascii);
        CHECK(wrong == 0);
    }
}

TEST_CASE("the tool reads back what it writes, exactly") {
    TempDir dir;
    WrittenMesh m = small_mesh(false);
    for (const char* name : {"r.ply", "r.obj", "r.off"}) {
        write_and_read(m, dir.file(name), false);
        std::vector<double> xyz;
        std::string error;
        REQUIRE_MESSAGE(read_cloud_file(dir.file(name), xyz, error), error);
        CHECK(xyz == m.xyz);
    }
}

TEST_CASE("writer errors: bad indices leave nothing behind") {
    TempDir dir;
    WrittenMesh m = small_mesh(false);
    m.tris[4] = 6;
    MeshView view = {m.xyz.data(), 6, m.tris.data(), 4};
    std::string error;
    {
        AtomicFile file;
        REQUIRE(file.open(dir.file("bad.ply"), error));
        CHECK_FALSE(write_mesh_file(file, MeshFormat::ply, view, false, error));
        CHECK(contains(error, "refers to vertex 6"));
        CHECK_FALSE(commit_files({&file}, error));
    }
    CHECK_FALSE(std::filesystem::exists(dir.file("bad.ply")));
    CHECK(std::filesystem::is_empty(dir.path));
}

// ==== JSON report =========================================================================

TEST_CASE("json_string escapes quotes, controls and broken UTF-8") {
    CHECK(json_string("a\"b\\c") == "\"a\\\"b\\\\c\"");
    CHECK(json_string(std::string("\n\t\x01", 3)) == "\"\\n\\t\\u0001\"");
    CHECK(json_string("caf\xc3\xa9") == "\"caf\xc3\xa9\"");
    CHECK(json_string("bad\xff\xc3") == "\"bad\\ufffd\\ufffd\"");
    CHECK(json_string("\xed\xa0\x80") == "\"\\ufffd\\ufffd\\ufffd\""); // a UTF-16 surrogate
}

TEST_CASE("the report is valid JSON, with null for unknowns and exact numbers") {
    RunRecord r;
    r.input_path = "in \"quoted\"\\dir\n\xff.ply";
    r.output_path = "out.ply";
    r.status = stratmesh::Status::not_columnar;
    r.report.points.in_count = 10;
    r.report.points.used_count = 6;
    r.report.points.duplicate_count = 2;
    r.report.points.rejected_count = 1;
    r.report.points.unused_count = 1;
    r.report.axis[2] = 1;
    r.report.axis_origin[0] = 0.1;
    r.report.detail = "a \"static\" sentence";
    r.report.layers.used_count = 1;
    stratmesh::LayerInfo layer = {};
    layer.top = std::numeric_limits<double>::infinity();
    layer.radius = 1.0 / 3.0;
    r.layers.push_back(layer);
    r.read_seconds = 0.25;
    r.workspace_bytes = 1000;
    mini_json::Value v;
    std::string error;
    REQUIRE_MESSAGE(mini_json::parse(run_record_json(r), v, error), error);
    CHECK(v.at("status")->text == "not_columnar");
    CHECK(v.at("detail")->text == "a \"static\" sentence");
    CHECK(v.at("points.in")->num == 10);
    CHECK(v.at("points.first_invalid")->kind == mini_json::Value::null);
    CHECK(v.at("seconds.read")->num == 0.25);
    CHECK(v.at("seconds.write")->kind == mini_json::Value::null);
    CHECK(v.at("axis.origin")->items[0].num == 0.1);
    CHECK(v.at("memory.workspace_bytes_per_point")->num == 100);
    const mini_json::Value& first = v.at("layers")->items.at(0);
    CHECK(first.member("top")->kind == mini_json::Value::null);
    CHECK(first.member("radius")->num == 1.0 / 3.0);
}

// ==== command line ========================================================================

namespace {

CommandAction parse(std::vector<const char*> args, CommandLine& line, std::string& error) {
    args.insert(args.begin(), "stratmesh");
    return parse_command_line(static_cast<int>(args.size()), args.data(), line, error);
}

std::string usage_error(std::vector<const char*> args) {
    CommandLine line;
    std::string error;
    CHECK(parse(args, line, error) == CommandAction::usage_error);
    return error;
}

} // namespace

TEST_CASE("command line: every option") {
    CommandLine line;
    std::string error;
    REQUIRE(parse({"in.xyz", "-o", "out.stl", "--axis", "1,-2,0.5", "--cuts=3,-1.5,1e2", "--report",
                   "r.json", "--ascii", "--skip-invalid", "-q"},
                  line, error) == CommandAction::run);
    CHECK(line.input == "in.xyz");
    CHECK(line.output == "out.stl");
    CHECK(line.axis == stratmesh::Axis::direction);
    // As given: the library takes a direction of any finite non-zero length.
    CHECK(line.direction[0] == 1);
    CHECK(line.direction[1] == -2);
    CHECK(line.direction[2] == 0.5);
    CHECK(line.cuts == std::vector<double>{3, -1.5, 100});
    CHECK(line.report == "r.json");
    CHECK((line.ascii && line.skip_invalid && line.quiet));
    CommandLine other;
    REQUIRE(parse({"--layers", "12", "--axis=z", "--output=m.obj", "--", "-odd name.ply"}, other,
                  error) == CommandAction::run);
    CHECK(other.layer_count == 12);
    CHECK(other.axis == stratmesh::Axis::z);
    CHECK(other.input == "-odd name.ply");
    CHECK(other.threads >= 1); // the machine's, by default
    CHECK_FALSE(other.stream);
    CommandLine streamed;
    REQUIRE(parse({"in.ply", "-o", "m.ply", "--stream", "--axis", "y", "--layer-height", "2",
                   "--stream-points", "5000", "--threads", "3", "--origin", "1,2,3"},
                  streamed, error) == CommandAction::run);
    CHECK(streamed.stream);
    CHECK(streamed.stream_points == 5000);
    CHECK(streamed.threads == 3);
    CHECK(streamed.origin_given);
    CHECK(streamed.origin[2] == 3);
}

TEST_CASE("command line: help and version win over errors") {
    CommandLine line;
    std::string error;
    CHECK(parse({"--bogus", "--help"}, line, error) == CommandAction::help);
    CHECK(parse({"-h"}, line, error) == CommandAction::help);
    CHECK(parse({"--version", "in.ply"}, line, error) == CommandAction::version);
    CHECK(contains(usage_text(), "Usage: stratmesh INPUT -o OUTPUT"));
}

TEST_CASE("command line: usage errors") {
    CHECK(contains(usage_error({}), "no input file"));
    CHECK(contains(usage_error({"in.ply"}), "no output file"));
    CHECK(contains(usage_error({"in.ply", "-o", "out.xyz"}), "cannot tell the mesh format"));
    CHECK(contains(usage_error({"in.ply", "-o", "m.ply", "--frobnicate"}),
                   "unknown option '--frobnicate'"));
    CHECK(contains(usage_error({"in.ply", "-o"}), "needs a value"));
    CHECK(contains(usage_error({"a.ply", "b.ply", "-o", "m.ply"}), "more than one input"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "-o", "n.ply"}), "more than once"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--layers", "abc"}), "--layers"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--layers", "0"}), "--layers"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--layers", "-3"}), "--layers"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--layers", "4294967296"}), "--layers"));
    CHECK(
        contains(usage_error({"a.ply", "-o", "m.ply", "--layer-height", "-1"}), "--layer-height"));
    CHECK(
        contains(usage_error({"a.ply", "-o", "m.ply", "--layer-height", "nan"}), "--layer-height"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--cuts", "1,,2"}), "--cuts"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--cuts", "1,inf"}), "--cuts"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--axis", "w"}), "--axis"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--axis", "0,0,0"}), "must not be zero"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--axis", "1,2"}), "--axis"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--ascii=yes"}), "takes no value"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--layers", "3", "--cuts", "1"}),
                   "at most one of"));
    for (const char* bad : {"0", "-1", "abc", "2.5", "1025"})
        CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--threads", bad}), "--threads"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--origin", "1,2"}), "--origin"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--stream-points", "15"}),
                   "--stream-points"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--stream", "--cuts", "1"}),
                   "--stream needs --axis"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.ply", "--stream", "--axis", "z"}),
                   "--stream needs --cuts or --layer-height"));
    CHECK(contains(
        usage_error({"a.ply", "-o", "m.ply", "--stream", "--axis", "z", "--layers", "3"}),
        "--stream needs --cuts or --layer-height"));
    CHECK(contains(usage_error({"a.ply", "-o", "m.stl", "--stream", "--axis", "z", "--cuts", "1"}),
                   "--stream cannot write STL"));
}

// A ring of 8 quads (an open tube, 16 triangles, counter-clockwise seen from outside)
// between z = 0 and z = 1, optionally closed by a fan to a pole at each end.
std::vector<uint32_t> tube_triangles(bool close_bottom, bool close_top) {
    std::vector<uint32_t> tris;
    for (uint32_t k = 0; k < 8; ++k) {
        const uint32_t a = k, b = (k + 1) % 8, c = 8 + k, d = 8 + (k + 1) % 8;
        tris.insert(tris.end(), {a, b, d, a, d, c});
        if (close_bottom) tris.insert(tris.end(), {16, b, a});
        if (close_top) tris.insert(tris.end(), {17, c, d});
    }
    return tris;
}

std::vector<double> tube_points() {
    std::vector<double> xyz;
    for (int level = 0; level < 2; ++level)
        for (int k = 0; k < 8; ++k) {
            const double angle = 6.283185307179586 * k / 8;
            xyz.insert(xyz.end(), {std::cos(angle), std::sin(angle), double(level)});
        }
    xyz.insert(xyz.end(), {0, 0, -0.5, 0, 0, 1.5});
    return xyz;
}

TEST_CASE("the surface's ends come from its boundary edges") {
    const std::vector<double> xyz = tube_points();
    const double axis[3] = {0, 0, 1};
    const std::vector<stratmesh::LayerInfo> no_layers;
    std::vector<uint32_t> open = tube_triangles(false, false);
    CHECK(boundary_edges(open.data(), open.size() / 3).size() == 16);
    SurfaceEnds ends = find_surface_ends(xyz.data(), open.data(), open.size() / 3, axis, no_layers);
    CHECK(ends.known);
    CHECK(ends.bottom.loop_edges == std::vector<size_t>{8});
    CHECK(ends.top.loop_edges == std::vector<size_t>{8});
    std::vector<uint32_t> capped_below = tube_triangles(true, false);
    ends = find_surface_ends(xyz.data(), capped_below.data(), capped_below.size() / 3, axis,
                             no_layers);
    CHECK(ends.bottom.loop_edges.empty());
    CHECK(ends.top.loop_edges == std::vector<size_t>{8});
    std::vector<uint32_t> closed = tube_triangles(true, true);
    CHECK(boundary_edges(closed.data(), closed.size() / 3).empty());
    // One triangle taken out of the closed surface leaves a hole of three edges.
    closed.erase(closed.begin(), closed.begin() + 3);
    const std::vector<uint64_t> hole = boundary_edges(closed.data(), closed.size() / 3);
    CHECK(hole == std::vector<uint64_t>{uint64_t{0} << 32 | 1, uint64_t{0} << 32 | 9,
                                        uint64_t{1} << 32 | 9});
}
