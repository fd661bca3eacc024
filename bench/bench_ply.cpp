// bench_ply.cpp - the benchmark's PLY point reader (see bench_ply.h).

#include "bench_ply.h"

#include <cstdlib>
#include <cstring>
#include <fstream>

namespace bench {
namespace {

enum class PlyType { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

struct TypeName {
    const char* name;
    PlyType type;
    size_t bytes;
};

// The PLY 1.0 scalar type names, and the sized names many writers use.
const TypeName kTypes[] = {
    {"char", PlyType::int8, 1},      {"int8", PlyType::int8, 1},
    {"uchar", PlyType::uint8, 1},    {"uint8", PlyType::uint8, 1},
    {"short", PlyType::int16, 2},    {"int16", PlyType::int16, 2},
    {"ushort", PlyType::uint16, 2},  {"uint16", PlyType::uint16, 2},
    {"int", PlyType::int32, 4},      {"int32", PlyType::int32, 4},
    {"uint", PlyType::uint32, 4},    {"uint32", PlyType::uint32, 4},
    {"float", PlyType::float32, 4},  {"float32", PlyType::float32, 4},
    {"double", PlyType::float64, 8}, {"float64", PlyType::float64, 8},
};

const TypeName* find_type(const std::string& name) {
    for (const TypeName& t : kTypes)
        if (name == t.name) return &t;
    return nullptr;
}

struct Property {
    std::string name;
    const TypeName* type;
    size_t offset;  // in a binary record
};

struct Header {
    bool ascii = false;
    uint64_t file_bytes = 0;
    size_t header_bytes = 0;  // through the end_header line
    size_t vertex_count = 0;
    std::vector<Property> properties;  // the vertex element's
    size_t record_bytes = 0;
    size_t position[3] = {0, 0, 0};  // the indices of x, y, z in `properties`
};

// Sets `message`; returns false, for `return refuse(...)`.
bool refuse(std::string& message, const std::string& text) {
    message = text;
    return false;
}

// Sets `error` to the file's name and the message; returns false, for `return fail(...)`.
bool fail(std::string& error, const std::string& path, const std::string& message) {
    error = "'" + path + "': " + message;
    return false;
}

std::vector<std::string> words_of(const std::string& line) {
    std::vector<std::string> words;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) words.push_back(line.substr(start, i - start));
    }
    return words;
}

// A decimal count: digits only, no sign, no overflow.
bool parse_count(const std::string& text, uint64_t& value) {
    if (text.empty() || text.size() > 19) return false;
    value = 0;
    for (char c : text) {
        if (c < '0' || c > '9') return false;
        value = value * 10 + static_cast<uint64_t>(c - '0');
    }
    return true;
}

// What the parser knows between header lines.
struct HeaderState {
    bool have_format = false;
    bool seen_vertex = false;
    bool in_vertex = false;
    bool ended = false;
};

// Handles one header line after the first; false and `message` set on a bad line.
bool parse_header_line(const std::vector<std::string>& w, HeaderState& state, Header& header,
                       std::string& message) {
    const std::string& key = w[0];
    if (key == "comment" || key == "obj_info") return true;
    if (key == "format") {
        if (state.have_format) return refuse(message, "a second format line");
        if (w.size() != 3)
            return refuse(message, "the format line needs a format and a version");
        if (w[1] == "binary_big_endian")
            return refuse(message, "binary_big_endian is not supported by the bench "
                             "(convert the file to binary_little_endian or ascii)");
        if (w[1] != "ascii" && w[1] != "binary_little_endian")
            return refuse(message, "unknown format '" + w[1] + "'");
        if (w[2] != "1.0") return refuse(message, "unknown PLY version '" + w[2] + "'");
        header.ascii = w[1] == "ascii";
        state.have_format = true;
        return true;
    }
    if (key == "element") {
        uint64_t count = 0;
        if (!state.have_format) return refuse(message, "an element before the format line");
        if (w.size() != 3 || !parse_count(w[2], count))
            return refuse(message, "an element line needs a name and a count");
        if (w[1] == "vertex") {
            if (state.seen_vertex) return refuse(message, "a second vertex element");
            if (count > 0xFFFFFFFDull)
                return refuse(message, "more vertices than stratmesh can address");
            header.vertex_count = static_cast<size_t>(count);
            state.seen_vertex = state.in_vertex = true;
        } else {
            if (!state.seen_vertex)
                return refuse(message,
                              "element '" + w[1] + "' comes before the vertex element; the "
                              "bench only reads files whose first element is vertex");
            state.in_vertex = false;
        }
        return true;
    }
    if (key == "property") {
        if (!state.seen_vertex) return refuse(message, "a property before any element");
        if (w.size() >= 2 && w[1] == "list") {
            if (w.size() != 5 || !find_type(w[2]) || !find_type(w[3]))
                return refuse(message,
                              "a list property needs a count type, an item type and a name");
            if (state.in_vertex)
                return refuse(message, "list property '" + w[4] +
                                           "' in the vertex element is not supported by "
                                           "the bench");
            return true;
        }
        if (w.size() != 3) return refuse(message, "a property line needs a type and a name");
        const TypeName* type = find_type(w[1]);
        if (!type) return refuse(message, "unknown property type '" + w[1] + "'");
        if (state.in_vertex) {
            for (const Property& p : header.properties)
                if (p.name == w[2])
                    return refuse(message, "vertex property '" + w[2] + "' twice");
            header.properties.push_back(Property{w[2], type, header.record_bytes});
            header.record_bytes += type->bytes;
        }
        return true;
    }
    if (key == "end_header") {
        if (w.size() != 1) return refuse(message, "words after end_header");
        state.ended = true;
        return true;
    }
    return refuse(message, "unexpected header line starting with '" + key + "'");
}

// Finds x, y and z, and checks they are float or double.
bool find_positions(Header& header, std::string& message) {
    const char* names[3] = {"x", "y", "z"};
    for (size_t k = 0; k < 3; ++k) {
        size_t i = 0;
        while (i < header.properties.size() && header.properties[i].name != names[k]) ++i;
        if (i == header.properties.size())
            return refuse(message, std::string("the vertex element has no '") + names[k] +
                             "' property");
        PlyType type = header.properties[i].type->type;
        if (type != PlyType::float32 && type != PlyType::float64)
            return refuse(message, std::string("vertex property '") + names[k] + "' is " +
                             header.properties[i].type->name +
                             "; the bench reads float or double positions only");
        header.position[k] = i;
    }
    return true;
}

bool read_header(const std::string& path, Header& header, std::string& error) {
    std::ifstream file(path, std::ios::binary | std::ios::ate);
    if (!file) return fail(error, path, "cannot open the file");
    std::streamoff end = file.tellg();
    if (end < 0) return fail(error, path, "cannot determine the file's size");
    header.file_bytes = static_cast<uint64_t>(end);
    const uint64_t limit = 1u << 20;  // no sane header is longer
    std::string head(static_cast<size_t>(header.file_bytes < limit ? header.file_bytes : limit),
                     '\0');
    file.seekg(0);
    if (!file.read(&head[0], static_cast<std::streamsize>(head.size())))
        return fail(error, path, "cannot read the header");

    HeaderState state;
    size_t pos = 0, line_number = 0;
    std::string message;
    while (!state.ended) {
        size_t newline = head.find('\n', pos);
        if (newline == std::string::npos)
            return fail(error, path, line_number == 0 ? "not a PLY file (no 'ply' line)"
                                                      : "the header has no end_header line");
        std::string line = head.substr(pos, newline - pos);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        pos = newline + 1;
        ++line_number;
        if (line_number == 1) {
            if (line != "ply") return fail(error, path, "not a PLY file (no 'ply' line)");
            continue;
        }
        std::vector<std::string> words = words_of(line);
        if (words.empty()) continue;
        if (!parse_header_line(words, state, header, message))
            return fail(error, path, "header line " + std::to_string(line_number) + ": " +
                                         message);
    }
    header.header_bytes = pos;
    if (!state.have_format) return fail(error, path, "the header has no format line");
    if (!state.seen_vertex) return fail(error, path, "the header has no vertex element");
    if (header.vertex_count == 0) return fail(error, path, "the vertex element is empty");
    if (!find_positions(header, message)) return fail(error, path, message);
    if (!header.ascii) {
        uint64_t body = header.file_bytes - header.header_bytes;
        uint64_t needed = static_cast<uint64_t>(header.vertex_count) * header.record_bytes;
        if (body < needed)
            return fail(error, path,
                        "truncated: the header promises " +
                            std::to_string(header.vertex_count) + " vertices of " +
                            std::to_string(header.record_bytes) + " bytes (" +
                            std::to_string(needed) + " bytes), the file has " +
                            std::to_string(body) + " bytes after the header");
    }
    return true;
}

bool host_is_little_endian() {
    const uint16_t one = 1;
    unsigned char first = 0;
    std::memcpy(&first, &one, 1);
    return first == 1;
}

// A little-endian float or double, decoded byte by byte.
double decode_position(const unsigned char* p, PlyType type) {
    if (type == PlyType::float32) {
        uint32_t bits = 0;
        for (size_t b = 0; b < 4; ++b) bits |= static_cast<uint32_t>(p[b]) << (8 * b);
        float value = 0;
        std::memcpy(&value, &bits, sizeof value);
        return static_cast<double>(value);
    }
    uint64_t bits = 0;
    for (size_t b = 0; b < 8; ++b) bits |= static_cast<uint64_t>(p[b]) << (8 * b);
    double value = 0;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

bool read_binary_body(const std::string& path, const Header& header, PlyCloud& ply,
                      std::string& error) {
    std::ifstream file(path, std::ios::binary);
    file.seekg(static_cast<std::streamoff>(header.header_bytes));
    ply.raw.resize(header.vertex_count * header.record_bytes);
    if (!file || !file.read(reinterpret_cast<char*>(ply.raw.data()),
                            static_cast<std::streamsize>(ply.raw.size())))
        return fail(error, path, "truncated: the vertex records end early");

    const Property& x = header.properties[header.position[0]];
    const Property& y = header.properties[header.position[1]];
    const Property& z = header.properties[header.position[2]];
    size_t size = x.type->bytes;
    bool in_place = host_is_little_endian() && y.type == x.type && z.type == x.type &&
                    y.offset == x.offset + size && z.offset == y.offset + size;
    if (in_place) {
        ply.cloud.xyz = ply.raw.data() + x.offset;
        ply.cloud.stride_bytes = header.record_bytes;
        ply.cloud.scalar = x.type->type == PlyType::float32 ? stratmesh::Scalar::float32
                                                             : stratmesh::Scalar::float64;
        return true;
    }
    ply.xyz.resize(3 * header.vertex_count);
    for (size_t i = 0; i < header.vertex_count; ++i) {
        const unsigned char* record = ply.raw.data() + i * header.record_bytes;
        for (size_t k = 0; k < 3; ++k) {
            const Property& p = header.properties[header.position[k]];
            ply.xyz[3 * i + k] = decode_position(record + p.offset, p.type->type);
        }
    }
    ply.raw.clear();
    ply.raw.shrink_to_fit();
    ply.cloud.xyz = ply.xyz.data();
    ply.cloud.stride_bytes = 3 * sizeof(double);
    ply.cloud.scalar = stratmesh::Scalar::float64;
    return true;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// Whitespace-separated numbers, one per vertex property, vertex after vertex.
bool read_ascii_body(const std::string& path, const Header& header, PlyCloud& ply,
                     std::string& error) {
    std::ifstream file(path, std::ios::binary);
    file.seekg(static_cast<std::streamoff>(header.header_bytes));
    std::string body(static_cast<size_t>(header.file_bytes - header.header_bytes), '\0');
    bool read = file && (body.empty() ||
                         file.read(&body[0], static_cast<std::streamsize>(body.size())));
    if (!read)
        return fail(error, path, "cannot read the vertex data");

    ply.xyz.resize(3 * header.vertex_count);
    const char* p = body.c_str();
    const char* body_end = p + body.size();
    for (size_t i = 0; i < header.vertex_count; ++i) {
        for (size_t k = 0; k < header.properties.size(); ++k) {
            while (p < body_end && is_space(*p)) ++p;
            if (p == body_end)
                return fail(error, path, "truncated: the data ends after " + std::to_string(i) +
                                             " of " + std::to_string(header.vertex_count) +
                                             " vertices");
            char* stop = nullptr;
            double value = std::strtod(p, &stop);
            if (stop == p || (stop < body_end && !is_space(*stop))) {
                const char* word_end = p;
                while (word_end < body_end && !is_space(*word_end) && word_end - p < 40)
                    ++word_end;
                return fail(error, path, "vertex " + std::to_string(i) + ", property '" +
                                             header.properties[k].name + "': '" +
                                             std::string(p, word_end) + "' is not a number");
            }
            p = stop;
            for (size_t axis = 0; axis < 3; ++axis) {
                if (header.position[axis] != k) continue;
                // A float property holds what a float reader would get.
                if (header.properties[k].type->type == PlyType::float32)
                    value = static_cast<double>(static_cast<float>(value));
                ply.xyz[3 * i + axis] = value;
            }
        }
    }
    ply.cloud.xyz = ply.xyz.data();
    ply.cloud.stride_bytes = 3 * sizeof(double);
    ply.cloud.scalar = stratmesh::Scalar::float64;
    return true;
}

}  // namespace

bool check_ply_file(const std::string& path, size_t& vertex_count, std::string& error) {
    Header header;
    if (!read_header(path, header, error)) return false;
    vertex_count = header.vertex_count;
    return true;
}

bool read_ply_file(const std::string& path, PlyCloud& ply, std::string& error) {
    Header header;
    if (!read_header(path, header, error)) return false;
    ply = PlyCloud();
    ply.format = header.ascii ? "ascii" : "binary_little_endian";
    ply.vertex_count = header.vertex_count;
    ply.record_bytes = header.ascii ? 0 : header.record_bytes;
    bool ok = header.ascii ? read_ascii_body(path, header, ply, error)
                           : read_binary_body(path, header, ply, error);
    if (!ok) return false;
    ply.cloud.count = header.vertex_count;
    return true;
}

}  // namespace bench
