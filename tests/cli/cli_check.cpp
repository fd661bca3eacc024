// stratmesh_cli_check: helper for the tool's end-to-end tests (no Python needed).
//
//   stratmesh_cli_check make-inputs DIR
//       writes small good and bad input files into DIR (see make_inputs below)
//   stratmesh_cli_check json FILE [ASSERTION...]
//       FILE must be valid JSON; each ASSERTION must hold:
//         a.b=c.d+e+12   sums of numbers at dotted paths (keys, or indices into arrays:
//                        layers.0.top) and number literals are equal
//         #a.b           (as a term) the length of the array at a.b
//         a.b:text       the string at a.b is `text` (or true, false, null)
//   stratmesh_cli_check same-mesh FILE FILE
//       the two meshes read back with the same vertices and the same triangles, in order
//   stratmesh_cli_check attributes INPUT.ply OUTPUT
//       OUTPUT's vertices carry INPUT's per-point data, point by point: a PLY output all of
//       its scalar properties (names, types, values), an OBJ output its normals and colours
//   stratmesh_cli_check no-attributes FILE
//       the mesh's vertices carry their coordinates only
//   stratmesh_cli_check svg FILE REPORT.json
//       FILE is well-formed XML, an <svg> with a polygon per triangle and a line per
//       boundary edge of the report, in each of its two views
//   stratmesh_cli_check mesh FILE VERTICES [REPORT.json]
//       the mesh (.ply .obj .off .stl) reads back, has VERTICES vertices (not checked for
//       STL), at least one triangle, indices in range, and as many triangles as the
//       report says
#include "mini_json.h"
#include "mini_mesh.h"
#include "../support/shapes.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace {

const double kPi = 3.14159265358979323846;

bool write_file(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return static_cast<bool>(out);
}

std::string number_text(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.9g", v);
    return text;
}

// A wavy cylinder, radius about 20, height 100, points on a golden-angle spiral.
std::vector<double> cylinder_points(size_t count) {
    std::vector<double> xyz;
    const double golden = kPi * (3 - std::sqrt(5.0));
    for (size_t i = 0; i < count; ++i) {
        double t = static_cast<double>(i);
        double angle = golden * t;
        double z = 100 * (t + 0.5) / static_cast<double>(count);
        double r = 20 + 2 * std::sin(z / 9) + 0.8 * std::cos(3 * angle);
        xyz.insert(xyz.end(), {r * std::cos(angle), r * std::sin(angle), z});
    }
    return xyz;
}

// Points 0.01 i, 0.02 i, 0.03 i: on one line but for rounding.
std::vector<double> line_points(size_t count) {
    std::vector<double> xyz;
    for (size_t i = 0; i < count; ++i) {
        const double t = static_cast<double>(i);
        xyz.insert(xyz.end(), {0.01 * t, 0.02 * t, 0.03 * t});
    }
    return xyz;
}

// The cloud with one more point at z = 1e30, which sets its extent on its own.
std::vector<double> with_far_point(std::vector<double> xyz) {
    xyz.insert(xyz.end(), {0, 0, 1e30});
    return xyz;
}

// Two parallel cylinders of radius 10, 50 apart, height 100: one tube around both folds
// wherever it is centred.
std::vector<double> twin_tube_points(size_t count) {
    std::vector<double> xyz = cylinder_points(count);
    for (size_t i = 0; i < count; ++i) {
        const double r = std::hypot(xyz[3 * i], xyz[3 * i + 1]);
        const double side = i % 2 ? 25 : -25;
        xyz[3 * i] = side + 10 * xyz[3 * i] / r;
        xyz[3 * i + 1] = 10 * xyz[3 * i + 1] / r;
    }
    return xyz;
}

// A fork: a trunk of radius 10 for z in [0, 60] and two prongs of radius 3 around
// x = -7 and 7 for z in [60, 100], touching the trunk's wall at its top; golden-angle
// spirals with about 1.1 points per unit of area.
std::vector<double> forked_points() {
    std::vector<double> xyz;
    const double golden = kPi * (3 - std::sqrt(5.0));
    auto spiral = [&](size_t count, double cx, double radius, double z0, double z1) {
        for (size_t i = 0; i < count; ++i) {
            const double t = static_cast<double>(i), angle = golden * t;
            const double z = z0 + (z1 - z0) * (t + 0.5) / static_cast<double>(count);
            xyz.insert(xyz.end(), {cx + radius * std::cos(angle), radius * std::sin(angle), z});
        }
    };
    spiral(4200, 0, 10, 0, 60);
    spiral(850, -7, 3, 60, 100);
    spiral(850, 7, 3, 60, 100);
    return xyz;
}

// The fork and a speck of 12 points 0.5 apart 20 above its prongs: beyond the cut but in
// no branch (find_parting's kBeyondBranches).
std::vector<double> forked_speck_points() {
    std::vector<double> xyz = forked_points();
    for (int i = 0; i < 12; ++i)
        xyz.insert(xyz.end(), {0.5 * (i % 3), 0.5 * (i / 3 % 2), 120 + 0.5 * (i / 6)});
    return xyz;
}

// The cylinder and 9 stray points: 6 single ones 3 to 10 heights away, and a speck of 3
// points 0.1 apart above it.
std::vector<double> with_strays(std::vector<double> xyz) {
    xyz.insert(xyz.end(), {500, 0, 50, -400, 300, 200, 0, -700, -300, 350, 350, 900,
                           -1000, 0, 40, 0, 20, -500, 0, 0, 600, 0.1, 0, 600, 0, 0.1, 600});
    return xyz;
}

std::string as_xyz(const std::vector<double>& xyz, size_t nan_every,
                   const char* title = "a wavy cylinder") {
    std::string text = std::string("# ") + title + "\n";
    for (size_t i = 0; i < xyz.size() / 3; ++i) {
        if (nan_every && i % nan_every == nan_every / 2) text += "nan nan nan\n";
        text += number_text(xyz[3 * i]) + " " + number_text(xyz[3 * i + 1]) + " " +
                number_text(xyz[3 * i + 2]) + "\n";
    }
    return text;
}

std::string as_obj(const std::vector<double>& xyz) {
    std::string text = "# a wavy cylinder\no cylinder\n";
    for (size_t i = 0; i < xyz.size() / 3; ++i)
        text += "v " + number_text(xyz[3 * i]) + " " + number_text(xyz[3 * i + 1]) + " " +
                number_text(xyz[3 * i + 2]) + "\n";
    return text;
}

// The cylinder sorted along z, as its text reads back, after a first point (20, 0, 0) below
// the others: a known --origin for the batch run equivalent to --stream.
std::vector<double> sorted_cylinder(const std::vector<double>& cylinder) {
    std::vector<double> xyz = {20, 0, 0};
    for (double v : cylinder) xyz.push_back(std::strtod(number_text(v).c_str(), nullptr));
    return xyz;
}

// Binary little-endian PLY of doubles.
std::string as_binary_ply(const std::vector<double>& xyz) {
    std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                        std::to_string(xyz.size() / 3) +
                        "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
    for (double v : xyz) {
        uint64_t bits = 0;
        std::memcpy(&bits, &v, sizeof bits);
        for (int i = 0; i < 8; ++i) bytes += static_cast<char>((bits >> (8 * i)) & 0xffu);
    }
    return bytes;
}

// The cylinder with per-point data of every kind: normals before the coordinates, colours,
// an intensity, a quality and a signed label; ascii, binary little-endian, or binary
// big-endian with a list property among them (which the tool does not carry).
enum class PlyEncoding { ascii, little, big_with_list };

void append_bytes(std::string& bytes, uint64_t bits, size_t size, bool big) {
    for (size_t i = 0; i < size; ++i)
        bytes += static_cast<char>((bits >> (8 * (big ? size - 1 - i : i))) & 0xffu);
}

std::string as_attribute_ply(const std::vector<double>& xyz, PlyEncoding encoding) {
    const bool list = encoding == PlyEncoding::big_with_list;
    std::string bytes = std::string("ply\nformat ") +
                        (encoding == PlyEncoding::ascii    ? "ascii"
                         : encoding == PlyEncoding::little ? "binary_little_endian"
                                                           : "binary_big_endian") +
                        " 1.0\nelement vertex " + std::to_string(xyz.size() / 3) +
                        "\nproperty float nx\nproperty float ny\nproperty float nz\n"
                        "property float x\nproperty float y\nproperty float z\n"
                        "property uchar red\nproperty uchar green\nproperty uchar blue\n" +
                        (list ? "property list uchar int neighbours\n" : "") +
                        "property ushort intensity\nproperty double quality\nproperty int label\n"
                        "end_header\n";
    for (size_t i = 0; i < xyz.size() / 3; ++i) {
        const double* p = &xyz[3 * i];
        const double r = std::sqrt(p[0] * p[0] + p[1] * p[1]);
        const float floats[6] = {static_cast<float>(p[0] / r), static_cast<float>(p[1] / r), 0.0f,
                                 static_cast<float>(p[0]), static_cast<float>(p[1]),
                                 static_cast<float>(p[2])};
        const unsigned colour[3] = {unsigned(i % 256), unsigned(i * 7 % 256), unsigned(255 - i % 256)};
        const unsigned intensity = unsigned(i * 37 % 65536);
        const double quality = p[2] / 3;
        const int label = static_cast<int>(i) - 1500;
        if (encoding == PlyEncoding::ascii) {
            for (float f : floats) bytes += number_text(static_cast<double>(f)) + " ";
            for (unsigned c : colour) bytes += std::to_string(c) + " ";
            char text[64];
            std::snprintf(text, sizeof text, "%u %.17g %d\n", intensity, quality, label);
            bytes += text;
            continue;
        }
        const bool big = encoding == PlyEncoding::big_with_list;
        for (float f : floats) {
            uint32_t bits = 0;
            std::memcpy(&bits, &f, sizeof bits);
            append_bytes(bytes, bits, 4, big);
        }
        for (unsigned c : colour) append_bytes(bytes, c, 1, big);
        if (list) { // a list of i % 2 neighbours
            append_bytes(bytes, i % 2, 1, big);
            if (i % 2) append_bytes(bytes, static_cast<uint32_t>(i + 1), 4, big);
        }
        append_bytes(bytes, intensity, 2, big);
        uint64_t bits = 0;
        std::memcpy(&bits, &quality, sizeof bits);
        append_bytes(bytes, bits, 8, big);
        append_bytes(bytes, static_cast<uint32_t>(label), 4, big);
    }
    return bytes;
}

std::string truncated_ply() {
    std::string text = "ply\nformat binary_little_endian 1.0\nelement vertex 100\n"
                       "property float x\nproperty float y\nproperty float z\nend_header\n";
    return text + std::string(10 * 12, '\x01');
}

// Hostile inputs too large to keep as files in tests/cli/hostile: an ascii PLY whose header
// says 10 vertices over a body of 600, a coordinate of 100,000 digits, and the sorted
// cylinder with its point 1500 NaN (for --stream's counts after a refusal).
std::string ply_more_records_than_declared(const std::vector<double>& xyz) {
    std::string text = "ply\nformat ascii 1.0\nelement vertex 10\nproperty double x\n"
                       "property double y\nproperty double z\nend_header\n";
    for (size_t i = 0; i < 600; ++i)
        text += number_text(xyz[3 * i]) + " " + number_text(xyz[3 * i + 1]) + " " +
                number_text(xyz[3 * i + 2]) + "\n";
    return text;
}

std::string xyz_with_huge_integer() {
    return "1 2 3\n4 5 6\n7 1" + std::string(100000, '0') + " 9\n";
}

std::string sorted_with_nan_at(std::vector<double> sorted, size_t index) {
    for (size_t k = 0; k < 3; ++k) sorted[3 * index + k] = std::nan("");
    return as_xyz(sorted, 0);
}

// ---- text as people write it: the text readers' cases -------------------------------------
// The cylinder as columns: `head` first, then a line per point, its numbers parted by
// `separator` and written with a decimal comma if `comma`. Line `odd_line` (counting from 1,
// 0 for none) is `odd` instead; every line ends with `end`.
struct Columns {
    Columns(std::string head_line, std::string parting, bool decimal_comma = false,
            size_t replaced_line = 0, std::string replacement = "", std::string line_end = "\n")
        : head(std::move(head_line)), separator(std::move(parting)), comma(decimal_comma),
          odd_line(replaced_line), odd(std::move(replacement)), end(std::move(line_end)) {}
    std::string head, separator;
    bool comma;
    size_t odd_line;
    std::string odd, end;
};

std::string as_columns(const std::vector<double>& xyz, const Columns& c) {
    auto number = [&](double v) {
        std::string text = number_text(v);
        if (c.comma) std::replace(text.begin(), text.end(), '.', ',');
        return text;
    };
    std::string text;
    size_t line = 0;
    auto add = [&](const std::string& content) {
        ++line;
        text += (line == c.odd_line ? c.odd : content) + c.end;
    };
    if (!c.head.empty()) add(c.head);
    for (size_t i = 0; i < xyz.size() / 3; ++i)
        add(number(xyz[3 * i]) + c.separator + number(xyz[3 * i + 1]) + c.separator +
            number(xyz[3 * i + 2]));
    return text;
}

// The cylinder with a point of NaN or infinite coordinates every 500 points, each in
// another spelling in use (MSVC's among them).
std::string with_nan_spellings(const std::vector<double>& xyz) {
    const char* spellings[] = {"-1.#IND 0.5 0.5", "0.5 0.5 1.#INF", "1.#QNAN 1.#SNAN -1.#INF00",
                               "nan(ind) -nan(ind) 0", "NaN -Infinity 1", "0.5 0.5 NaNQ"};
    std::string text;
    for (size_t i = 0; i < xyz.size() / 3; ++i) {
        if (i % 500 == 250) text += std::string(spellings[i / 500 % 6]) + "\n";
        text += number_text(xyz[3 * i]) + " " + number_text(xyz[3 * i + 1]) + " " +
                number_text(xyz[3 * i + 2]) + "\n";
    }
    return text;
}

// An ascii PLY of the cylinder's first 10 points with a label; `format` is its format
// line, `label` the first point's label.
std::string small_ply(const std::vector<double>& xyz, const std::string& format,
                      const std::string& label, const std::string& end) {
    std::string text = "ply" + end + format + end + "element vertex 10" + end +
                       "property double x" + end + "property double y" + end +
                       "property double z" + end + "property int label" + end + "end_header" + end;
    for (size_t i = 0; i < 10; ++i)
        text += number_text(xyz[3 * i]) + " " + number_text(xyz[3 * i + 1]) + " " +
                number_text(xyz[3 * i + 2]) + " " + (i == 0 ? label : "7") + end;
    return text;
}

// An OFF mesh of the cylinder's first 1500 points, its faces fans; the last face names
// vertex `last`.
std::string off_mesh(const std::vector<double>& xyz, size_t last) {
    std::string text = "OFF\n1500 3 0\n";
    for (size_t i = 0; i < 1500; ++i)
        text += number_text(xyz[3 * i]) + " " + number_text(xyz[3 * i + 1]) + " " +
                number_text(xyz[3 * i + 2]) + "\n";
    return text + "3 0 1 2\n3 0 2 3\n3 0 3 " + std::to_string(last) + "\n";
}

bool make_reader_inputs(const std::string& dir, const std::vector<double>& cylinder) {
    const std::string thousands = "67.55 891.56 2,176.92";
    return write_file(dir + "/european.csv", as_columns(cylinder, {"X;Y;Z", ";", true})) &&
           write_file(dir + "/decimal_comma.txt", as_columns(cylinder, {"", "\t", true})) &&
           write_file(dir + "/comma_separated.csv", as_columns(cylinder, {"x, y, z", ", "})) &&
           write_file(dir + "/thousands.xyz", as_columns(cylinder, {"", " ", false, 7, thousands})) &&
           write_file(dir + "/empty_field.csv",
                      as_columns(cylinder, {"x,y,z", ",", false, 12, "1.5,,2.5,3.5"})) &&
           write_file(dir + "/split_differently.csv",
                      as_columns(cylinder, {"x;y;z", ";", true, 30, "1,5,2,5,3,5"})) &&
           write_file(dir + "/mixed_marks.csv",
                      as_columns(cylinder, {"x;y;z", ";", true, 40, "1.5;2;3"})) &&
           write_file(dir + "/not_a_cloud.txt", "stratmesh 0.1.0 report\npoints: 3000\n") &&
           write_file(dir + "/cr_only.xyz", as_columns(cylinder, {"# CR only", " ", false, 0, "", "\r"})) &&
           write_file(dir + "/cr_only.ply", small_ply(cylinder, "format ascii 1.0", "7", "\r")) &&
           write_file(dir + "/ply_version_2.ply", small_ply(cylinder, "format ascii 2.0", "7", "\n")) &&
           write_file(dir + "/ply_int_exponent.ply",
                      small_ply(cylinder, "format ascii 1.0", "1e2", "\n")) &&
           write_file(dir + "/off_face_beyond.off", off_mesh(cylinder, 5000)) &&
           write_file(dir + "/nan_spellings.xyz", with_nan_spellings(cylinder)) &&
           write_file(dir + "/nan_cut_short.xyz",
                      as_columns(cylinder, {"", " ", false, 20, "0.5 0.5 -1.#J"}));
}

int make_inputs(const std::string& dir) {
    std::error_code ignored;
    std::filesystem::create_directories(dir, ignored);
    std::vector<double> cylinder = cylinder_points(3000);
    std::vector<double> sorted = sorted_cylinder(cylinder);
    bool ok = write_file(dir + "/garbage.xyz", "1 2 3\n4 5 6\n7 eight 9\n") &&
              write_file(dir + "/truncated.ply", truncated_ply()) &&
              write_file(dir + "/lying.ply",
                         "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
                         "property float y\nproperty float z\nend_header\n1 2 3\n") &&
              write_file(dir + "/empty.xyz", "") &&
              write_file(dir + "/two_points.xyz", "0 0 0\n1 1 1\n") &&
              write_file(dir + "/cylinder.xyz", as_xyz(cylinder, 0)) &&
              write_file(dir + "/twin_tubes.xyz", as_xyz(twin_tube_points(3000), 0, "two cylinders")) &&
              write_file(dir + "/forked.xyz", as_xyz(forked_points(), 0, "a forked tube")) &&
              write_file(dir + "/four_legged.xyz",
                         as_xyz(shapes::four_legged(10000, shapes::Pose::z).xyz, 0,
                                "a four-legged body")) &&
              write_file(dir + "/u_tube.xyz",
                         as_xyz(shapes::u_tube(6000, shapes::Pose::z).xyz, 0, "a U of pipe")) &&
              write_file(dir + "/u_bend.xyz",
                         as_xyz(shapes::u_bend(6000, shapes::Pose::z).xyz, 0, "a U bend of pipe")) &&
              write_file(dir + "/cad_spool.xyz",
                         as_xyz(shapes::cad_spool(48, shapes::Pose::z).xyz, 0,
                                "a spool's CAD vertices")) &&
              write_file(dir + "/forked_speck.xyz",
                         as_xyz(forked_speck_points(), 0, "a forked tube and a speck")) &&
              write_file(dir + "/cylinder_nan.xyz", as_xyz(cylinder, 500)) &&
              write_file(dir + "/cylinder_strays.xyz", as_xyz(with_strays(cylinder), 0)) &&
              write_file(dir + "/cylinder_obj.ply", as_obj(cylinder)) &&
              write_file(dir + "/sorted.xyz", as_xyz(sorted, 0)) &&
              write_file(dir + "/mesh.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 1\n3 0 1 2\n") &&
              write_file(dir + "/sorted.ply", as_binary_ply(sorted)) &&
              write_file(dir + "/attributes.ply", as_attribute_ply(cylinder, PlyEncoding::little)) &&
              write_file(dir + "/attributes_ascii.ply",
                         as_attribute_ply(cylinder, PlyEncoding::ascii)) &&
              write_file(dir + "/attributes_big.ply",
                         as_attribute_ply(cylinder, PlyEncoding::big_with_list)) &&
              write_file(dir + "/more_records.ply", ply_more_records_than_declared(cylinder)) &&
              write_file(dir + "/huge_integer.xyz", xyz_with_huge_integer()) &&
              write_file(dir + "/sorted_nan.xyz", sorted_with_nan_at(sorted, 1500)) &&
              write_file(dir + "/line.xyz", as_xyz(line_points(2000), 0, "on a line up to rounding")) &&
              write_file(dir + "/far_speck.xyz", as_xyz(with_far_point(cylinder), 0, "a point at 1e30")) &&
              make_reader_inputs(dir, cylinder);
    if (!ok) std::fprintf(stderr, "cannot write the inputs into %s\n", dir.c_str());
    return ok ? 0 : 1;
}

// ---- json --------------------------------------------------------------------------------

bool term_value(const mini_json::Value& root, const std::string& term, double& value) {
    bool is_length = !term.empty() && term[0] == '#';
    const mini_json::Value* v = root.at(is_length ? term.substr(1) : term);
    if (is_length) {
        if (v && v->kind == mini_json::Value::array) value = static_cast<double>(v->items.size());
        return v && v->kind == mini_json::Value::array;
    }
    if (v) {
        value = v->num;
        return v->kind == mini_json::Value::number;
    }
    char* end = nullptr;
    value = std::strtod(term.c_str(), &end);
    return !term.empty() && *end == '\0';
}

bool sum_of(const mini_json::Value& root, const std::string& side, double& sum) {
    sum = 0;
    size_t start = 0;
    for (;;) {
        size_t plus = side.find('+', start);
        double value = 0;
        std::string term = side.substr(start, plus == std::string::npos ? plus : plus - start);
        if (!term_value(root, term, value)) {
            std::fprintf(stderr, "  '%s' is not a number in the report\n", term.c_str());
            return false;
        }
        sum += value;
        if (plus == std::string::npos) return true;
        start = plus + 1;
    }
}

// Strings as they are; true, false and null as those words.
std::string text_of(const mini_json::Value& v) {
    if (v.kind == mini_json::Value::string) return v.text;
    if (v.kind == mini_json::Value::boolean) return v.flag ? "true" : "false";
    if (v.kind == mini_json::Value::null) return "null";
    return "(not text)";
}

bool holds(const mini_json::Value& root, const std::string& assertion) {
    size_t colon = assertion.find(':'), equals = assertion.find('=');
    if (colon != std::string::npos && colon < equals) {
        const mini_json::Value* v = root.at(assertion.substr(0, colon));
        return v && text_of(*v) == assertion.substr(colon + 1);
    }
    double left = 0, right = 0;
    if (equals == std::string::npos || !sum_of(root, assertion.substr(0, equals), left) ||
        !sum_of(root, assertion.substr(equals + 1), right))
        return false;
    if (left != right) std::fprintf(stderr, "  %.17g != %.17g\n", left, right);
    return left == right;
}

bool load_json(const std::string& path, mini_json::Value& root) {
    std::string text, error;
    if (!mini_mesh::load(path, text)) {
        std::fprintf(stderr, "cannot read %s\n", path.c_str());
        return false;
    }
    if (mini_json::parse(text, root, error)) return true;
    std::fprintf(stderr, "%s is not valid JSON: %s\n", path.c_str(), error.c_str());
    return false;
}

int check_json(int argc, char** argv) {
    mini_json::Value root;
    if (!load_json(argv[2], root)) return 1;
    int failures = 0;
    for (int i = 3; i < argc; ++i) {
        if (holds(root, argv[i])) continue;
        std::fprintf(stderr, "assertion failed: %s\n", argv[i]);
        ++failures;
    }
    return failures ? 1 : 0;
}

// ---- mesh --------------------------------------------------------------------------------

// Whether the triangles form an oriented 2-manifold: no directed edge twice (so at most
// two triangles per edge, consistently oriented) and, around every vertex, the triangles
// form a single fan (one chain or one cycle).
bool is_oriented_manifold(const std::vector<uint32_t>& tris, std::string& why) {
    std::unordered_set<uint64_t> directed;
    std::unordered_map<uint32_t, std::vector<std::pair<uint32_t, uint32_t>>> fans;
    for (size_t t = 0; t + 2 < tris.size(); t += 3) {
        for (size_t k = 0; k < 3; ++k) {
            uint32_t a = tris[t + k], b = tris[t + (k + 1) % 3], c = tris[t + (k + 2) % 3];
            if (!directed.insert((static_cast<uint64_t>(a) << 32) | b).second) {
                why = "edge " + std::to_string(a) + "->" + std::to_string(b) + " repeats";
                return false;
            }
            fans[a].push_back({b, c});  // around a: leaves towards b, arrives from c
        }
    }
    for (const auto& entry : fans) {
        const auto& fan = entry.second;
        // Triangle k links to the one leaving towards where k arrives from; a chain starts
        // at a triangle no other arrives into (its leaving edge is a boundary edge).
        std::unordered_map<uint32_t, size_t> leaving;
        std::unordered_set<uint32_t> arriving;
        for (size_t k = 0; k < fan.size(); ++k) {
            leaving[fan[k].first] = k;
            arriving.insert(fan[k].second);
        }
        size_t starts = 0, start = 0;
        for (size_t k = 0; k < fan.size(); ++k)
            if (!arriving.count(fan[k].first)) {
                ++starts;
                start = k;
            }
        size_t walked = 0;
        for (size_t at = start; walked <= fan.size();) {
            ++walked;
            auto next = leaving.find(fan[at].second);
            if (next == leaving.end() || next->second == start) break;
            at = next->second;
        }
        if (starts > 1 || walked != fan.size()) {
            why = "the triangles around vertex " + std::to_string(entry.first) +
                  " form more than one fan";
            return false;
        }
    }
    return true;
}

int check_same_mesh(char** argv) {
    mini_mesh::Mesh a, b;
    if (!mini_mesh::read(argv[2], a) || !mini_mesh::read(argv[3], b)) {
        std::fprintf(stderr, "cannot read %s or %s\n", argv[2], argv[3]);
        return 1;
    }
    if (a.xyz == b.xyz && a.tris == b.tris && !a.tris.empty()) return 0;
    std::fprintf(stderr, "%s: %zu vertices, %zu triangles; %s: %zu vertices, %zu triangles; "
                         "not the same mesh\n",
                 argv[2], a.xyz.size() / 3, a.tris.size() / 3, argv[3], b.xyz.size() / 3,
                 b.tris.size() / 3);
    return 1;
}

int check_mesh(int argc, char** argv) {
    std::string path = argv[2];
    size_t vertices = std::strtoull(argv[3], nullptr, 10);
    mini_mesh::Mesh mesh;
    if (!mini_mesh::read(path, mesh)) {
        std::fprintf(stderr, "cannot read the mesh %s\n", path.c_str());
        return 1;
    }
    bool stl = path.size() > 4 && path.substr(path.size() - 4) == ".stl";
    size_t have = mesh.xyz.size() / 3, triangles = mesh.tris.size() / 3;
    bool ok = triangles > 0 && (stl || have == vertices);
    for (uint32_t index : mesh.tris) ok = ok && index < have;
    mini_json::Value report;
    if (argc > 4 && load_json(argv[4], report)) {
        const mini_json::Value* t = report.at("triangles");
        ok = ok && t && t->num == static_cast<double>(triangles);
        // With a report the mesh must be an oriented manifold through every point the
        // report calls used, and the report must leave no valid point unused.
        std::string why;
        if (!stl && !is_oriented_manifold(mesh.tris, why)) {
            std::fprintf(stderr, "%s: not an oriented manifold: %s\n", path.c_str(), why.c_str());
            ok = false;
        }
        std::unordered_set<uint32_t> used(mesh.tris.begin(), mesh.tris.end());
        const mini_json::Value* reported = report.at("points.used");
        const mini_json::Value* unused = report.at("points.unused");
        if (!stl && (!reported || reported->num != static_cast<double>(used.size()) ||
                     !unused || unused->num != 0)) {
            std::fprintf(stderr, "%s: %zu vertices used; the report disagrees or has unused points\n",
                         path.c_str(), used.size());
            ok = false;
        }
    } else if (argc > 4) {
        ok = false;
    }
    if (!ok)
        std::fprintf(stderr, "%s: %zu vertices (expected %zu), %zu triangles\n", path.c_str(), have,
                     vertices, triangles);
    return ok ? 0 : 1;
}

// The output's vertex data against the input's, point by point: in a PLY output, the
// input's properties but its lists, with the same names and types in the same order, and
// the same values; in an OBJ output, the normals as vn lines and the colours over 255.
int check_attributes(char** argv) {
    const std::string input = argv[2], output = argv[3];
    mini_mesh::Mesh in, out;
    if (!mini_mesh::read(input, in) || !mini_mesh::read(output, out)) {
        std::fprintf(stderr, "cannot read %s or %s\n", input.c_str(), output.c_str());
        return 1;
    }
    const size_t vertices = in.xyz.size() / 3;
    if (out.xyz != in.xyz || in.properties.empty()) {
        std::fprintf(stderr, "%s: not the points of %s, or no properties there\n", output.c_str(),
                     input.c_str());
        return 1;
    }
    const bool obj = output.size() > 4 && output.substr(output.size() - 4) == ".obj";
    if (!obj) {
        bool same = out.properties.size() == in.properties.size();
        for (size_t k = 0; same && k < in.properties.size(); ++k)
            same = out.properties[k].name == in.properties[k].name &&
                   out.properties[k].type == in.properties[k].type;
        if (!same || out.values != in.values) {
            std::fprintf(stderr, "%s: the vertex properties differ from %s's\n", output.c_str(),
                         input.c_str());
            return 1;
        }
        return 0;
    }
    auto column = [&](const char* name) {
        for (size_t k = 0; k < in.properties.size(); ++k)
            if (in.properties[k].name == name) return k;
        return in.properties.size();
    };
    const size_t columns = in.properties.size();
    const size_t normal[3] = {column("nx"), column("ny"), column("nz")};
    const size_t colour[3] = {column("red"), column("green"), column("blue")};
    bool ok = out.obj_normals.size() == 3 * vertices && out.obj_colours.size() == 3 * vertices;
    for (size_t i = 0; ok && i < vertices; ++i) {
        for (size_t k = 0; k < 3; ++k) {
            ok = ok && out.obj_normals[3 * i + k] == in.values[i * columns + normal[k]] &&
                 out.obj_colours[3 * i + k] == in.values[i * columns + colour[k]] / 255;
        }
    }
    if (!ok)
        std::fprintf(stderr, "%s: the normals or colours differ from %s's\n", output.c_str(),
                     input.c_str());
    return ok ? 0 : 1;
}

// ---- svg ---------------------------------------------------------------------------------

bool is_name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' || c == '-' ||
           c == '.';
}

// Character data or an attribute value: no '<', every '&' a known entity.
bool valid_text(const std::string& text) {
    if (text.find('<') != std::string::npos) return false;
    for (size_t at = text.find('&'); at != std::string::npos; at = text.find('&', at + 1)) {
        const size_t end = text.find(';', at);
        if (end == std::string::npos) return false;
        const std::string entity = text.substr(at + 1, end - at - 1);
        const bool known = entity == "amp" || entity == "lt" || entity == "gt" ||
                           entity == "quot" || entity == "apos" ||
                           (entity.size() > 1 && entity[0] == '#');
        if (!known) return false;
    }
    return true;
}

// A small XML well-formedness check: a declaration, comments, one root element, tags
// nested and closed in order, attributes name="value" once each, text without '<' or
// stray '&'. Counts the elements by name.
bool check_xml(const std::string& text, std::unordered_map<std::string, size_t>& counts,
               std::string& why) {
    std::vector<std::string> open;
    bool root_seen = false;
    size_t at = 0;
    auto fail = [&](const std::string& what) {
        why = what + " at byte " + std::to_string(at);
        return false;
    };
    while (at < text.size()) {
        if (text[at] != '<') {
            const size_t next = std::min(text.find('<', at), text.size());
            const std::string chars = text.substr(at, next - at);
            if (!valid_text(chars)) return fail("bad character data");
            if (open.empty() && chars.find_first_not_of(" \t\r\n") != std::string::npos)
                return fail("text outside the root element");
            at = next;
            continue;
        }
        if (text.compare(at, 4, "<!--") == 0 || text.compare(at, 2, "<?") == 0) {
            const bool comment = text[at + 1] == '!';
            const size_t end = text.find(comment ? "-->" : "?>", at);
            if (end == std::string::npos) return fail("an unclosed comment or declaration");
            at = end + (comment ? 3 : 2);
            continue;
        }
        const bool closing = text.compare(at, 2, "</") == 0;
        size_t cursor = at + (closing ? 2 : 1);
        const size_t name_start = cursor;
        while (cursor < text.size() && is_name_char(text[cursor])) ++cursor;
        const std::string name = text.substr(name_start, cursor - name_start);
        if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0])))
            return fail("a tag without a name");
        auto skip_space = [&]() {
            while (cursor < text.size() && std::isspace(static_cast<unsigned char>(text[cursor])))
                ++cursor;
        };
        if (closing) {
            skip_space();
            if (cursor >= text.size() || text[cursor] != '>') return fail("a malformed end tag");
            if (open.empty() || open.back() != name) return fail("</" + name + "> closes nothing open");
            open.pop_back();
            at = cursor + 1;
            continue;
        }
        if (open.empty() && root_seen) return fail("a second root element");
        root_seen = true;
        std::unordered_set<std::string> attributes;
        bool empty_element = false;
        for (;;) {
            skip_space();
            if (cursor >= text.size()) return fail("an unclosed tag");
            if (text.compare(cursor, 2, "/>") == 0) {
                empty_element = true;
                cursor += 2;
                break;
            }
            if (text[cursor] == '>') {
                ++cursor;
                break;
            }
            const size_t attribute_start = cursor;
            while (cursor < text.size() && is_name_char(text[cursor])) ++cursor;
            const std::string attribute = text.substr(attribute_start, cursor - attribute_start);
            if (attribute.empty() || !attributes.insert(attribute).second)
                return fail("a missing or repeated attribute in <" + name + ">");
            skip_space();
            if (cursor >= text.size() || text[cursor] != '=') return fail("an attribute without '='");
            ++cursor;
            skip_space();
            const char quote = cursor < text.size() ? text[cursor] : '\0';
            if (quote != '"' && quote != '\'') return fail("an unquoted attribute value");
            const size_t end = text.find(quote, cursor + 1);
            if (end == std::string::npos || !valid_text(text.substr(cursor + 1, end - cursor - 1)))
                return fail("a bad attribute value");
            cursor = end + 1;
        }
        ++counts[name];
        if (!empty_element) open.push_back(name);
        at = cursor;
    }
    if (!open.empty()) return fail("<" + open.back() + "> never closed");
    if (!root_seen) return fail("no root element");
    return true;
}

// The picture is well-formed XML whose root is <svg>, with a polygon per triangle in each
// of its two views and a red line per boundary edge in each (the report's triangles and
// its ends' loops).
int check_svg(char** argv) {
    std::string text;
    mini_json::Value report;
    if (!mini_mesh::load(argv[2], text) || !load_json(argv[3], report)) {
        std::fprintf(stderr, "cannot read %s or %s\n", argv[2], argv[3]);
        return 1;
    }
    std::unordered_map<std::string, size_t> counts;
    std::string why;
    if (!check_xml(text, counts, why)) {
        std::fprintf(stderr, "%s: not well-formed XML: %s\n", argv[2], why.c_str());
        return 1;
    }
    const mini_json::Value* triangles = report.at("triangles");
    size_t boundary = 0;
    for (const char* end : {"ends.bottom.loop_edges", "ends.top.loop_edges"})
        if (const mini_json::Value* loops = report.at(end))
            for (const mini_json::Value& edges : loops->items)
                boundary += static_cast<size_t>(edges.num);
    const bool ok = counts["svg"] == 1 && text.find("<svg") < text.find("<g") && triangles &&
                    static_cast<double>(counts["polygon"]) == 2 * triangles->num &&
                    counts["polyline"] == 2 * boundary;
    if (!ok)
        std::fprintf(stderr, "%s: %zu polygons and %zu boundary lines; the report has %g "
                             "triangles and %zu boundary edges, in each of two views\n",
                     argv[2], counts["polygon"], counts["polyline"],
                     triangles ? triangles->num : -1.0, boundary);
    return ok ? 0 : 1;
}

int check_no_attributes(char** argv) {
    mini_mesh::Mesh mesh;
    if (!mini_mesh::read(argv[2], mesh) || mesh.tris.empty()) {
        std::fprintf(stderr, "cannot read the mesh %s\n", argv[2]);
        return 1;
    }
    if (mesh.properties.empty() && mesh.obj_normals.empty() && mesh.obj_colours.empty()) return 0;
    std::fprintf(stderr, "%s: the vertices carry more than their coordinates\n", argv[2]);
    return 1;
}

} // namespace

int main(int argc, char** argv) {
    std::string command = argc > 1 ? argv[1] : "";
    if (command == "make-inputs" && argc == 3) return make_inputs(argv[2]);
    if (command == "json" && argc >= 3) return check_json(argc, argv);
    if (command == "mesh" && (argc == 4 || argc == 5)) return check_mesh(argc, argv);
    if (command == "same-mesh" && argc == 4) return check_same_mesh(argv);
    if (command == "attributes" && argc == 4) return check_attributes(argv);
    if (command == "no-attributes" && argc == 3) return check_no_attributes(argv);
    if (command == "svg" && argc == 4) return check_svg(argv);
    std::fprintf(stderr, "usage: stratmesh_cli_check make-inputs DIR | json FILE [ASSERTION...] |"
                         " mesh FILE VERTICES [REPORT.json] | same-mesh FILE FILE |"
                         " attributes INPUT.ply OUTPUT | no-attributes FILE |"
                         " svg FILE REPORT.json\n");
    return 2;
}
