// Tiny mesh readers for the tests, independent of the tool's code: just enough to read
// back what the tool writes (PLY ascii/binary, x y z float or double and any other scalar
// vertex properties, a uchar/uint face list; OBJ with normals and colours; OFF; STL binary
// and ascii) and check it.
// Header-only; everything is inline.
#ifndef STRATMESH_TESTS_MINI_MESH_H
#define STRATMESH_TESTS_MINI_MESH_H

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace mini_mesh {

struct Mesh {
    std::vector<double> xyz;    // 3 per vertex (STL: 3 corners per triangle)
    std::vector<uint32_t> tris; // 3 per triangle
    std::vector<float> normals; // STL only: 3 per triangle
    // PLY: the vertex properties besides x, y, z, in order, and their values, one row of
    // them per vertex.
    struct Property {
        std::string type, name;
    };
    std::vector<Property> properties;
    std::vector<double> values;
    // OBJ: "vn" lines (3 numbers each) and the colours after a "v" line's coordinates.
    std::vector<double> obj_normals, obj_colours;
};

inline bool load(const std::string& path, std::string& bytes) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

// The value of type T stored at `at`, in little-endian (or big-endian) byte order.
template <class T> T value_at(const std::string& bytes, size_t at, bool big_endian = false) {
    unsigned char raw[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) raw[i] = static_cast<unsigned char>(bytes[at + i]);
    uint16_t probe = 1;
    unsigned char first;
    std::memcpy(&first, &probe, 1);
    if ((first == 1) == big_endian)
        for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    T value;
    std::memcpy(&value, raw, sizeof value);
    return value;
}

template <class T> T little_endian_at(const std::string& bytes, size_t at) {
    return value_at<T>(bytes, at, false);
}

// A PLY scalar type's size in bytes, 0 if unknown.
inline size_t ply_type_size(const std::string& type) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32" ||
        type == "float" || type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

inline double ply_binary_value(const std::string& bytes, size_t at, const std::string& type,
                               bool big) {
    if (type == "char" || type == "int8") return value_at<int8_t>(bytes, at, big);
    if (type == "uchar" || type == "uint8") return value_at<uint8_t>(bytes, at, big);
    if (type == "short" || type == "int16") return value_at<int16_t>(bytes, at, big);
    if (type == "ushort" || type == "uint16") return value_at<uint16_t>(bytes, at, big);
    if (type == "int" || type == "int32") return value_at<int32_t>(bytes, at, big);
    if (type == "uint" || type == "uint32") return value_at<uint32_t>(bytes, at, big);
    if (type == "float" || type == "float32")
        return static_cast<double>(value_at<float>(bytes, at, big));
    return value_at<double>(bytes, at, big);
}

// The vertex element holds scalars only (x, y, z among them); the face element a uchar
// count and uint indices, or nothing at all.
struct PlyLayout {
    bool ascii = false, big_endian = false;
    size_t vertices = 0, faces = 0, body = 0;
    std::vector<Mesh::Property> vertex; // every vertex property, x y z included
};

inline bool ply_header(const std::string& bytes, PlyLayout& layout) {
    size_t end = bytes.find("end_header\n");
    if (bytes.compare(0, 4, "ply\n") != 0 || end == std::string::npos) return false;
    layout.body = end + 11;
    std::istringstream header(bytes.substr(0, end));
    std::string line, element;
    while (std::getline(header, line)) {
        std::istringstream words(line);
        std::string a, b, c;
        words >> a >> b >> c;
        if (a == "format") {
            layout.ascii = b == "ascii";
            layout.big_endian = b == "binary_big_endian";
        }
        if (a == "element") element = b;
        if (a == "element" && b == "vertex") layout.vertices = std::stoul(c);
        if (a == "element" && b == "face") layout.faces = std::stoul(c);
        if (a == "property" && element == "vertex") {
            if (ply_type_size(b) == 0) return false;
            layout.vertex.push_back({b, c});
        }
    }
    return true;
}

// Puts a vertex's values: x, y, z into xyz, the others into the property rows.
inline void put_vertex(const PlyLayout& l, const std::vector<double>& row, Mesh& mesh) {
    double point[3] = {0, 0, 0};
    for (size_t p = 0; p < l.vertex.size(); ++p) {
        const std::string& name = l.vertex[p].name;
        if (name == "x" || name == "y" || name == "z")
            point[name[0] - 'x'] = row[p];
        else
            mesh.values.push_back(row[p]);
    }
    mesh.xyz.insert(mesh.xyz.end(), point, point + 3);
}

inline bool ply_binary_body(const std::string& bytes, const PlyLayout& l, Mesh& mesh) {
    size_t record = 0;
    for (const Mesh::Property& p : l.vertex) record += ply_type_size(p.type);
    size_t need = l.body + record * l.vertices + 13 * l.faces;
    if (bytes.size() != need) return false;
    size_t at = l.body;
    std::vector<double> row(l.vertex.size());
    for (size_t i = 0; i < l.vertices; ++i) {
        for (size_t p = 0; p < l.vertex.size(); ++p) {
            row[p] = ply_binary_value(bytes, at, l.vertex[p].type, l.big_endian);
            at += ply_type_size(l.vertex[p].type);
        }
        put_vertex(l, row, mesh);
    }
    for (size_t f = 0; f < l.faces; ++f, at += 13) {
        if (bytes[at] != 3) return false;
        for (size_t k = 0; k < 3; ++k)
            mesh.tris.push_back(value_at<uint32_t>(bytes, at + 1 + 4 * k, l.big_endian));
    }
    return true;
}

inline bool ply_ascii_body(const std::string& bytes, const PlyLayout& l, Mesh& mesh) {
    std::istringstream in(bytes.substr(l.body));
    std::vector<double> row(l.vertex.size());
    for (size_t i = 0; i < l.vertices; ++i) {
        for (size_t p = 0; p < row.size(); ++p) {
            std::string token;
            if (!(in >> token)) return false;
            row[p] = std::stod(token);
            // A float property holds the float nearest its text (the coordinates, which
            // the tool keeps as read, excepted).
            const Mesh::Property& property = l.vertex[p];
            const bool coordinate = property.name == "x" || property.name == "y" || property.name == "z";
            if (!coordinate && (property.type == "float" || property.type == "float32"))
                row[p] = static_cast<double>(static_cast<float>(row[p]));
        }
        put_vertex(l, row, mesh);
    }
    for (size_t f = 0; f < l.faces; ++f) {
        uint32_t n = 0, a = 0, b = 0, c = 0;
        if (!(in >> n >> a >> b >> c) || n != 3) return false;
        mesh.tris.insert(mesh.tris.end(), {a, b, c});
    }
    std::string rest;
    return !(in >> rest);
}

inline bool parse_ply(const std::string& bytes, Mesh& mesh) {
    PlyLayout layout;
    if (!ply_header(bytes, layout)) return false;
    for (const Mesh::Property& p : layout.vertex)
        if (p.name != "x" && p.name != "y" && p.name != "z") mesh.properties.push_back(p);
    return layout.ascii ? ply_ascii_body(bytes, layout, mesh)
                        : ply_binary_body(bytes, layout, mesh);
}

// Reads "v x y z [r g b]", "vn x y z" and "f a b c" (each corner "a", "a/t", "a//n" or
// "a/t/n": the vertex index is the first number).
inline bool parse_obj(const std::string& bytes, Mesh& mesh) {
    std::istringstream in(bytes);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream words(line);
        std::string kind;
        words >> kind;
        std::vector<std::string> fields;
        for (std::string field; words >> field;) fields.push_back(field);
        if (kind == "v" && (fields.size() == 3 || fields.size() == 6)) {
            for (size_t k = 0; k < 3; ++k) mesh.xyz.push_back(std::stod(fields[k]));
            for (size_t k = 3; k < fields.size(); ++k) mesh.obj_colours.push_back(std::stod(fields[k]));
        } else if (kind == "vn" && fields.size() == 3) {
            for (const std::string& field : fields) mesh.obj_normals.push_back(std::stod(field));
        } else if (kind == "f" && fields.size() == 3) {
            for (const std::string& field : fields)
                mesh.tris.push_back(static_cast<uint32_t>(std::stoul(field)) - 1);
        } else if (kind == "v" || kind == "vn" || kind == "f") {
            return false;
        }
    }
    return true;
}

inline bool parse_off(const std::string& bytes, Mesh& mesh) {
    std::istringstream in(bytes);
    std::string line, keyword;
    size_t vertices = 0, faces = 0, edges = 0;
    std::getline(in, keyword);
    while (std::getline(in, line) && (line.empty() || line[0] == '#')) {
    }
    std::istringstream counts(line);
    if (keyword != "OFF" || !(counts >> vertices >> faces >> edges)) return false;
    for (size_t i = 0; i < 3 * vertices; ++i) {
        std::string token;
        if (!(in >> token)) return false;
        mesh.xyz.push_back(std::stod(token));
    }
    for (size_t f = 0; f < faces; ++f) {
        uint32_t n = 0, a = 0, b = 0, c = 0;
        if (!(in >> n >> a >> b >> c) || n != 3) return false;
        mesh.tris.insert(mesh.tris.end(), {a, b, c});
    }
    return true;
}

inline bool parse_stl_ascii(const std::string& bytes, Mesh& mesh) {
    std::istringstream in(bytes);
    std::string word;
    while (in >> word) {
        if (word == "normal") {
            float n[3];
            if (!(in >> n[0] >> n[1] >> n[2])) return false;
            mesh.normals.insert(mesh.normals.end(), n, n + 3);
        } else if (word == "vertex") {
            std::string x, y, z;
            if (!(in >> x >> y >> z)) return false;
            mesh.xyz.insert(mesh.xyz.end(), {std::stod(x), std::stod(y), std::stod(z)});
            mesh.tris.push_back(static_cast<uint32_t>(mesh.tris.size()));
        }
    }
    return true;
}

inline bool parse_stl(const std::string& bytes, Mesh& mesh) {
    if (bytes.compare(0, 6, "solid ") == 0) return parse_stl_ascii(bytes, mesh);
    if (bytes.size() < 84) return false;
    uint32_t count = little_endian_at<uint32_t>(bytes, 80);
    if (bytes.size() != 84 + 50 * size_t{count}) return false;
    for (size_t t = 0; t < count; ++t) {
        size_t at = 84 + 50 * t;
        for (size_t k = 0; k < 3; ++k)
            mesh.normals.push_back(little_endian_at<float>(bytes, at + 4 * k));
        for (size_t k = 0; k < 9; ++k)
            mesh.xyz.push_back(
                static_cast<double>(little_endian_at<float>(bytes, at + 12 + 4 * k)));
        for (uint32_t k = 0; k < 3; ++k) mesh.tris.push_back(static_cast<uint32_t>(3 * t + k));
    }
    return true;
}

// By the file's extension (lower case): .ply, .obj, .off, .stl.
inline bool read(const std::string& path, Mesh& mesh) {
    std::string bytes;
    if (!load(path, bytes)) return false;
    std::string ext = path.substr(path.find_last_of('.') + 1);
    if (ext == "ply") return parse_ply(bytes, mesh);
    if (ext == "obj") return parse_obj(bytes, mesh);
    if (ext == "off") return parse_off(bytes, mesh);
    if (ext == "stl") return parse_stl(bytes, mesh);
    return false;
}

} // namespace mini_mesh

#endif
