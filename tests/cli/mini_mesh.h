// Tiny mesh readers for the tests, independent of the tool's code: just enough to read
// back what the tool writes (PLY ascii/binary little-endian with x y z float or double
// and a uchar/uint face list, OBJ, OFF, STL binary and ascii) and check it.
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
};

inline bool load(const std::string& path, std::string& bytes) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

template <class T> T little_endian_at(const std::string& bytes, size_t at) {
    unsigned char raw[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) raw[i] = static_cast<unsigned char>(bytes[at + i]);
    uint16_t probe = 1;
    unsigned char first;
    std::memcpy(&first, &probe, 1);
    if (first != 1)
        for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    T value;
    std::memcpy(&value, raw, sizeof value);
    return value;
}

struct PlyLayout {
    bool ascii = false, doubles = false;
    size_t vertices = 0, faces = 0, body = 0;
};

inline bool ply_header(const std::string& bytes, PlyLayout& layout) {
    size_t end = bytes.find("end_header\n");
    if (bytes.compare(0, 4, "ply\n") != 0 || end == std::string::npos) return false;
    layout.body = end + 11;
    std::istringstream header(bytes.substr(0, end));
    std::string line;
    while (std::getline(header, line)) {
        std::istringstream words(line);
        std::string a, b, c;
        words >> a >> b >> c;
        if (a == "format") layout.ascii = b == "ascii";
        if (a == "element" && b == "vertex") layout.vertices = std::stoul(c);
        if (a == "element" && b == "face") layout.faces = std::stoul(c);
        if (a == "property" && b == "double") layout.doubles = true;
    }
    return true;
}

inline bool ply_binary_body(const std::string& bytes, const PlyLayout& l, Mesh& mesh) {
    size_t scalar = l.doubles ? 8 : 4;
    size_t need = l.body + 3 * scalar * l.vertices + 13 * l.faces;
    if (bytes.size() != need) return false;
    size_t at = l.body;
    for (size_t i = 0; i < 3 * l.vertices; ++i, at += scalar)
        mesh.xyz.push_back(l.doubles ? little_endian_at<double>(bytes, at)
                                     : static_cast<double>(little_endian_at<float>(bytes, at)));
    for (size_t f = 0; f < l.faces; ++f, at += 13) {
        if (bytes[at] != 3) return false;
        for (size_t k = 0; k < 3; ++k)
            mesh.tris.push_back(little_endian_at<uint32_t>(bytes, at + 1 + 4 * k));
    }
    return true;
}

inline bool ply_ascii_body(const std::string& bytes, const PlyLayout& l, Mesh& mesh) {
    std::istringstream in(bytes.substr(l.body));
    for (size_t i = 0; i < 3 * l.vertices; ++i) {
        std::string token;
        if (!(in >> token)) return false;
        mesh.xyz.push_back(std::stod(token));
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
    return layout.ascii ? ply_ascii_body(bytes, layout, mesh)
                        : ply_binary_body(bytes, layout, mesh);
}

inline bool parse_obj(const std::string& bytes, Mesh& mesh) {
    std::istringstream in(bytes);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream words(line);
        std::string kind, x, y, z;
        words >> kind;
        if (kind == "v" && (words >> x >> y >> z))
            mesh.xyz.insert(mesh.xyz.end(), {std::stod(x), std::stod(y), std::stod(z)});
        uint32_t a = 0, b = 0, c = 0;
        if (kind == "f" && (words >> a >> b >> c))
            mesh.tris.insert(mesh.tris.end(), {a - 1, b - 1, c - 1});
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
