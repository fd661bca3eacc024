#include "mesh_io.h"

#include "path_util.h"
#include "safe_output.h"
#include "stratmesh.h"

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>
#include <vector>

namespace stratmesh_cli {

// Collects output in a buffer of a megabyte (it stays in the caches while it is filled)
// and hands each full one to the file in one write. The formatters write straight into
// it: room() makes space for a bounded record, advance() takes what they wrote.
class BlockWriter {
public:
    // `output`, if given, is the AtomicFile that `file` belongs to: its writeback to the
    // disk is started as the blocks go out, so that complete() waits for little.
    explicit BlockWriter(std::FILE* file, AtomicFile* output = nullptr)
        : file_(file), output_(output), buffer_(new char[kBlockBytes]) {}

    std::FILE* file() const { return file_; }
    bool failed() const { return failure_ != 0; }

    // Room for `bytes` bytes (at most a block) at the returned cursor.
    char* room(size_t bytes) {
        if (kBlockBytes - used_ < bytes) flush();
        return buffer_.get() + used_;
    }
    // How many records of at most `bytes` bytes fit without a flush (at least one).
    size_t records_that_fit(size_t bytes) {
        if (kBlockBytes - used_ < bytes) flush();
        return (kBlockBytes - used_) / bytes;
    }
    // The cursor after what was written at room()'s.
    void advance(char* end) { used_ = static_cast<size_t>(end - buffer_.get()); }

    void append(std::string_view text) {
        while (!text.empty()) {
            const size_t step = std::min(text.size(), kBlockBytes);
            char* out = room(step);
            std::memcpy(out, text.data(), step);
            advance(out + step);
            text.remove_prefix(step);
        }
    }

    void flush() {
        if (used_ > 0 && std::fwrite(buffer_.get(), 1, used_, file_) != used_)
            remember_failure();
        unsynced_ += used_;
        used_ = 0;
        if (output_ && unsynced_ >= kWritebackBytes && failure_ == 0) {
            output_->start_writeback();
            unsynced_ = 0;
        }
    }

    // Writes out the buffer; the errno of the first write that failed, 0 if none.
    int drain() {
        flush();
        return failure_;
    }

    // Flushes and closes; false (with errno's text in `error`) if anything failed.
    bool close(std::string& error) {
        flush();
        if (std::fclose(file_) != 0) remember_failure();
        if (failure_ != 0) error = std::strerror(failure_);
        return failure_ == 0;
    }

private:
    void remember_failure() {
        if (failure_ == 0) failure_ = errno != 0 ? errno : EIO;
    }

    static constexpr size_t kBlockBytes = size_t{1} << 20;
    static constexpr size_t kWritebackBytes = size_t{8} << 20;
    std::FILE* file_;
    AtomicFile* output_;
    std::unique_ptr<char[]> buffer_;
    size_t used_ = 0;
    size_t unsynced_ = 0;
    int failure_ = 0;
};

namespace {

// Writes `count` records of at most `most` bytes each: put(cursor, i) writes record i and
// returns the cursor after it. The loop over a block's records has no other test.
template <class Put> void put_records(BlockWriter& w, size_t count, size_t most, Put put) {
    for (size_t i = 0; i < count;) {
        const size_t stop = i + std::min(w.records_that_fit(most), count - i);
        char* out = w.room(most);
        for (; i < stop; ++i) out = put(out, i);
        w.advance(out);
    }
}

// ---- encoding ----------------------------------------------------------------------------

bool host_is_little_endian() {
    const uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    return first == 1;
}

const bool kLittleHost = host_is_little_endian();

template <class Bits> char* put_le(char* out, Bits bits) {
    if (kLittleHost) {
        std::memcpy(out, &bits, sizeof bits);
    } else {
        for (size_t i = 0; i < sizeof bits; ++i)
            out[i] = static_cast<char>((bits >> (8 * i)) & 0xffu);
    }
    return out + sizeof bits;
}

char* put_le_u32(char* out, uint32_t value) { return put_le(out, value); }

char* put_le_float(char* out, float value) {
    uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    return put_le(out, bits);
}

char* put_le_double(char* out, double value) {
    uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    return put_le(out, bits);
}

const double kFloatMax = static_cast<double>(FLT_MAX);

bool fits_float(double v) { return std::isnan(v) || std::isinf(v) || std::fabs(v) <= kFloatMax; }

// Finite doubles beyond float's range clamp to its largest value rather than overflow.
float to_float(double v) {
    if (fits_float(v)) return static_cast<float>(v);
    return v < 0 ? -FLT_MAX : FLT_MAX;
}

// The longest shortest form of a double ("-2.2250738585072014e-308") and of an index.
constexpr size_t kNumberBytes = 24;
constexpr size_t kIndexBytes = 20;

// The shortest text that reads back as the same double. A float stored in a double also
// reads back exactly as that float.
char* put_number(char* out, double value) {
    return std::to_chars(out, out + kNumberBytes, value).ptr;
}

char* put_point(char* out, const double* p) {
    out = put_number(out, p[0]);
    *out++ = ' ';
    out = put_number(out, p[1]);
    *out++ = ' ';
    return put_number(out, p[2]);
}

char* put_index(char* out, uint64_t index) {
    return std::to_chars(out, out + kIndexBytes, index).ptr;
}

char* put_text(char* out, std::string_view text) {
    std::memcpy(out, text.data(), text.size());
    return out + text.size();
}

const char* generator_comment() {
    return "stratmesh " STRATMESH_VERSION_STRING
           ": vertex i is input point i (all points kept, in input order)";
}

// ---- formats -----------------------------------------------------------------------------

std::string ply_header(size_t vertex_count, size_t triangle_count, bool ascii, bool single,
                       const PointAttributes* attributes = nullptr) {
    const char* type = single ? "float" : "double";
    std::string out = "ply\nformat ";
    out += ascii ? "ascii" : "binary_little_endian";
    out += " 1.0\ncomment ";
    out += generator_comment();
    out += "\nelement vertex " + std::to_string(vertex_count) + "\n";
    for (const char* axis : {"x", "y", "z"})
        out += std::string("property ") + type + " " + axis + "\n";
    if (attributes)
        for (const PointAttributes::Property& p : attributes->properties)
            out += "property " + p.type + " " + p.name + "\n";
    out += "element face " + std::to_string(triangle_count) + "\n";
    out += "property list uchar uint vertex_indices\nend_header\n";
    return out;
}

// The point's coordinates, then its attribute record as it was read (little-endian).
void put_binary_vertices_with(BlockWriter& w, const double* xyz, size_t count, bool single,
                              const PointAttributes& attributes) {
    const size_t record = attributes.record_bytes;
    const unsigned char* bytes = attributes.bytes.data();
    put_records(w, count, 24 + record, [=](char* out, size_t i) {
        for (size_t k = 0; k < 3; ++k)
            out = single ? put_le_float(out, static_cast<float>(xyz[3 * i + k]))
                         : put_le_double(out, xyz[3 * i + k]);
        std::memcpy(out, bytes + i * record, record);
        return out + record;
    });
}

void put_binary_vertices(BlockWriter& w, const double* xyz, size_t count, bool single) {
    if (single) {
        // Every coordinate is a float (all_coordinates_are_floats): converted as it is.
        put_records(w, count, 12, [xyz](char* out, size_t i) {
            for (size_t k = 0; k < 3; ++k)
                out = put_le_float(out, static_cast<float>(xyz[3 * i + k]));
            return out;
        });
    } else {
        put_records(w, count, 24, [xyz](char* out, size_t i) {
            for (size_t k = 0; k < 3; ++k) out = put_le_double(out, xyz[3 * i + k]);
            return out;
        });
    }
}

void put_binary_faces(BlockWriter& w, const uint32_t* triangles, size_t count) {
    put_records(w, count, 13, [triangles](char* out, size_t t) {
        *out++ = static_cast<char>(3);
        for (size_t k = 0; k < 3; ++k) out = put_le_u32(out, triangles[3 * t + k]);
        return out;
    });
}

// Text PLY, OBJ and OFF share their shape: a vertex line per point, a face line per
// triangle.
struct TextStyle {
    std::string_view vertex_prefix; // "v " or ""
    std::string_view face_prefix;   // "f" or "3"
    uint32_t index_base;            // 1 or 0
};

const TextStyle kObjStyle = {"v ", "f", 1};
const TextStyle kOffStyle = {"", "3", 0}; // text PLY's too

void put_vertex_lines(BlockWriter& w, const double* xyz, size_t count, const TextStyle& style) {
    const size_t most = style.vertex_prefix.size() + 3 * kNumberBytes + 3;
    put_records(w, count, most, [xyz, &style](char* out, size_t i) {
        out = put_point(put_text(out, style.vertex_prefix), xyz + 3 * i);
        *out++ = '\n';
        return out;
    });
}

void put_face_lines(BlockWriter& w, const uint32_t* triangles, size_t count,
                    const TextStyle& style) {
    const size_t most = style.face_prefix.size() + 3 * (1 + kIndexBytes) + 1;
    put_records(w, count, most, [triangles, &style](char* out, size_t t) {
        out = put_text(out, style.face_prefix);
        for (size_t k = 0; k < 3; ++k) {
            *out++ = ' ';
            out = put_index(out, uint64_t{triangles[3 * t + k]} + style.index_base);
        }
        *out++ = '\n';
        return out;
    });
}

// An attribute's value as text: integers whole, floats in the shortest digits that read
// back as the same float, doubles as the same double.
char* put_attribute(char* out, const PointAttributes& attributes, size_t point, size_t property) {
    const PointAttributes::Property& p = attributes.properties[property];
    const double value = attributes.value(point, property);
    if (p.integral) return std::to_chars(out, out + kNumberBytes, static_cast<int64_t>(value)).ptr;
    if (p.size == 4) return std::to_chars(out, out + kNumberBytes, static_cast<float>(value)).ptr;
    return put_number(out, value);
}

// Text PLY vertex lines with the attributes after the coordinates.
void put_ply_vertex_lines_with(BlockWriter& w, const double* xyz, size_t count,
                               const PointAttributes& attributes) {
    const size_t values = attributes.properties.size();
    const size_t most = (3 + values) * (kNumberBytes + 1) + 1;
    put_records(w, count, most, [&](char* out, size_t i) {
        out = put_point(out, xyz + 3 * i);
        for (size_t k = 0; k < values; ++k) {
            *out++ = ' ';
            out = put_attribute(out, attributes, i, k);
        }
        *out++ = '\n';
        return out;
    });
}

void write_ply(BlockWriter& w, const MeshView& mesh, bool ascii) {
    // Float coordinates are declared float, in binary and in text alike; text gives each
    // coordinate the digits that read back as the same double, which a float reader
    // rounds to that float.
    const bool single = all_coordinates_are_floats(mesh.xyz, mesh.vertex_count);
    const PointAttributes* attributes =
        mesh.attributes && !mesh.attributes->empty() ? mesh.attributes : nullptr;
    w.append(ply_header(mesh.vertex_count, mesh.triangle_count, ascii, single, attributes));
    if (ascii) {
        if (attributes)
            put_ply_vertex_lines_with(w, mesh.xyz, mesh.vertex_count, *attributes);
        else
            put_vertex_lines(w, mesh.xyz, mesh.vertex_count, kOffStyle);
        put_face_lines(w, mesh.triangles, mesh.triangle_count, kOffStyle);
    } else {
        if (attributes)
            put_binary_vertices_with(w, mesh.xyz, mesh.vertex_count, single, *attributes);
        else
            put_binary_vertices(w, mesh.xyz, mesh.vertex_count, single);
        put_binary_faces(w, mesh.triangles, mesh.triangle_count);
    }
}

// ---- OBJ with normals and colours -----------------------------------------------------------

// A colour channel's scale to OBJ's 0 to 1: integers over their type's largest value.
double channel_scale(const PointAttributes::Property& p) {
    if (!p.integral) return 1;
    return static_cast<double>((uint64_t{1} << (8 * p.size - (p.is_signed ? 1 : 0))) - 1);
}

void write_obj_with(BlockWriter& w, const MeshView& mesh, const ObjAttributes& obj) {
    const PointAttributes& a = *mesh.attributes;
    const bool colours = obj.colour[0] >= 0;
    const bool normals = obj.normal[0] >= 0;
    double scale[3] = {1, 1, 1};
    if (colours)
        for (size_t k = 0; k < 3; ++k)
            scale[k] = channel_scale(a.properties[static_cast<size_t>(obj.colour[k])]);
    put_records(w, mesh.vertex_count, 2 + 6 * (kNumberBytes + 1) + 1, [&](char* out, size_t i) {
        out = put_point(put_text(out, "v "), mesh.xyz + 3 * i);
        for (size_t k = 0; colours && k < 3; ++k) {
            *out++ = ' ';
            out = put_number(out, a.value(i, static_cast<size_t>(obj.colour[k])) / scale[k]);
        }
        *out++ = '\n';
        return out;
    });
    if (normals) {
        put_records(w, mesh.vertex_count, 3 + 3 * (kNumberBytes + 1) + 1, [&](char* out, size_t i) {
            out = put_text(out, "vn");
            for (size_t k = 0; k < 3; ++k) {
                *out++ = ' ';
                out = put_number(out, a.value(i, static_cast<size_t>(obj.normal[k])));
            }
            *out++ = '\n';
            return out;
        });
    }
    // With normals each corner names its normal, the vertex's own: "f 1//1 2//2 3//3".
    put_records(w, mesh.triangle_count, 1 + 3 * (2 * kIndexBytes + 3) + 1,
                [&](char* out, size_t t) {
                    *out++ = 'f';
                    for (size_t k = 0; k < 3; ++k) {
                        const uint64_t index = uint64_t{mesh.triangles[3 * t + k]} + 1;
                        *out++ = ' ';
                        out = put_index(out, index);
                        if (!normals) continue;
                        out = put_text(out, "//");
                        out = put_index(out, index);
                    }
                    *out++ = '\n';
                    return out;
                });
}

std::string obj_header() { return std::string("# ") + generator_comment() + "\n"; }

std::string off_header(size_t vertex_count, size_t triangle_count) {
    return std::string("OFF\n# ") + generator_comment() + "\n" + std::to_string(vertex_count) +
           " " + std::to_string(triangle_count) + " 0\n";
}

void write_text_mesh(BlockWriter& w, const MeshView& mesh, const TextStyle& style) {
    put_vertex_lines(w, mesh.xyz, mesh.vertex_count, style);
    put_face_lines(w, mesh.triangles, mesh.triangle_count, style);
}

// The unit normal of triangle t (zero if degenerate), from the right-hand rule.
void triangle_normal(const MeshView& mesh, size_t t, double n[3]) {
    const double* a = mesh.xyz + 3 * size_t{mesh.triangles[3 * t]};
    const double* b = mesh.xyz + 3 * size_t{mesh.triangles[3 * t + 1]};
    const double* c = mesh.xyz + 3 * size_t{mesh.triangles[3 * t + 2]};
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; ++k) n[k] = length > 0 && std::isfinite(length) ? n[k] / length : 0.0;
}

const double* corner(const MeshView& mesh, size_t t, size_t k) {
    return mesh.xyz + 3 * size_t{mesh.triangles[3 * t + k]};
}

void write_stl_binary(BlockWriter& w, const MeshView& mesh) {
    std::string title = "stratmesh " STRATMESH_VERSION_STRING " binary STL";
    title.resize(80, ' ');
    w.append(title);
    char* count = w.room(4);
    w.advance(put_le_u32(count, static_cast<uint32_t>(mesh.triangle_count)));
    put_records(w, mesh.triangle_count, 50, [&mesh](char* out, size_t t) {
        double n[3];
        triangle_normal(mesh, t, n);
        for (double c : n) out = put_le_float(out, to_float(c));
        for (size_t k = 0; k < 3; ++k)
            for (size_t j = 0; j < 3; ++j) out = put_le_float(out, to_float(corner(mesh, t, k)[j]));
        *out++ = '\0'; // the attribute byte count
        *out++ = '\0';
        return out;
    });
}

void write_stl_ascii(BlockWriter& w, const MeshView& mesh) {
    w.append("solid stratmesh\n");
    const size_t most = 4 * (3 * kNumberBytes + 16) + 32;
    put_records(w, mesh.triangle_count, most, [&mesh](char* out, size_t t) {
        double n[3];
        triangle_normal(mesh, t, n);
        out = put_point(put_text(out, "facet normal "), n);
        out = put_text(out, "\n outer loop\n");
        for (size_t k = 0; k < 3; ++k) {
            out = put_point(put_text(out, "  vertex "), corner(mesh, t, k));
            *out++ = '\n';
        }
        return put_text(out, " endloop\nendfacet\n");
    });
    w.append("endsolid stratmesh\n");
}

// Everything a file format cannot express, found before the file is created.
bool check_mesh(const MeshView& mesh, MeshFormat format, std::string& error) {
    // The largest index first, in a loop the compiler vectorises; the culprit only then.
    const size_t indices = 3 * mesh.triangle_count;
    uint32_t largest = 0;
    for (size_t i = 0; i < indices; ++i) largest = std::max(largest, mesh.triangles[i]);
    for (size_t i = 0; indices > 0 && largest >= mesh.vertex_count; ++i) {
        if (mesh.triangles[i] >= mesh.vertex_count) {
            error = "triangle " + std::to_string(i / 3) + " refers to vertex " +
                    std::to_string(mesh.triangles[i]) + " of " + std::to_string(mesh.vertex_count);
            return false;
        }
    }
    if (format == MeshFormat::stl && mesh.triangle_count > UINT32_MAX) {
        error = "too many triangles for binary STL";
        return false;
    }
    return true;
}

void write_body(BlockWriter& w, MeshFormat format, const MeshView& mesh, bool ascii) {
    switch (format) {
    case MeshFormat::ply: write_ply(w, mesh, ascii); break;
    case MeshFormat::obj:
        w.append(obj_header());
        if (const ObjAttributes obj = obj_attributes(mesh.attributes); obj.carried() > 0)
            write_obj_with(w, mesh, obj);
        else
            write_text_mesh(w, mesh, kObjStyle);
        break;
    case MeshFormat::off:
        w.append(off_header(mesh.vertex_count, mesh.triangle_count));
        write_text_mesh(w, mesh, kOffStyle);
        break;
    case MeshFormat::stl:
        if (ascii)
            write_stl_ascii(w, mesh);
        else
            write_stl_binary(w, mesh);
        break;
    case MeshFormat::unknown: break;
    }
}

} // namespace

ObjAttributes obj_attributes(const PointAttributes* attributes) {
    ObjAttributes obj;
    if (!attributes) return obj;
    const char* const normals[3] = {"nx", "ny", "nz"};
    const char* const colours[3] = {"red", "green", "blue"};
    int normal[3], colour[3];
    for (size_t k = 0; k < 3; ++k) {
        normal[k] = attributes->find(normals[k]);
        colour[k] = attributes->find(colours[k]);
    }
    if (normal[0] >= 0 && normal[1] >= 0 && normal[2] >= 0)
        for (size_t k = 0; k < 3; ++k) obj.normal[k] = normal[k];
    if (colour[0] >= 0 && colour[1] >= 0 && colour[2] >= 0)
        for (size_t k = 0; k < 3; ++k) obj.colour[k] = colour[k];
    return obj;
}

size_t carried_attributes(const PointAttributes* attributes, MeshFormat format) {
    if (!attributes) return 0;
    if (format == MeshFormat::ply) return attributes->properties.size();
    if (format == MeshFormat::obj) return obj_attributes(attributes).carried();
    return 0;
}

const char* mesh_format_name(MeshFormat format) {
    switch (format) {
    case MeshFormat::ply: return "PLY";
    case MeshFormat::obj: return "OBJ";
    case MeshFormat::off: return "OFF";
    case MeshFormat::stl: return "STL";
    case MeshFormat::unknown: break;
    }
    return "unknown";
}

MeshFormat mesh_format_from_extension(const std::string& path) {
    std::string ext = lowercase_extension(path);
    if (ext == "ply") return MeshFormat::ply;
    if (ext == "obj") return MeshFormat::obj;
    if (ext == "off") return MeshFormat::off;
    if (ext == "stl") return MeshFormat::stl;
    return MeshFormat::unknown;
}

bool all_coordinates_are_floats(const double* xyz, size_t count) {
    // Branch-free within a block: a finite value beyond float's range becomes an infinity
    // (IEEE 754), unequal to it; an infinity stays itself; NaN is let through by name.
    constexpr size_t kBlock = 4096;
    const size_t values = 3 * count;
    for (size_t first = 0; first < values; first += kBlock) {
        const size_t stop = std::min(values, first + kBlock);
        bool all = true;
        for (size_t i = first; i < stop; ++i) {
            const double v = xyz[i];
            all &= (static_cast<double>(static_cast<float>(v)) == v) | (v != v);
        }
        if (!all) return false;
    }
    return true;
}

bool write_mesh_file(AtomicFile& file, MeshFormat format, const MeshView& mesh, bool ascii,
                     std::string& error) {
    if (format == MeshFormat::unknown) {
        error = file.path() + ": unknown mesh format (use .ply, .obj, .off or .stl)";
        return false;
    }
    if (!check_mesh(mesh, format, error)) {
        error = file.path() + ": " + error;
        return false;
    }
    BlockWriter writer(file.file(), &file);
    write_body(writer, format, mesh, ascii);
    return file.complete(writer.drain(), error);
}

MeshStreamWriter::MeshStreamWriter() = default;

// A writer not finished here is abandoned: its scratch bodies go, and the output's
// temporary with its AtomicFile.
MeshStreamWriter::~MeshStreamWriter() {
    std::string ignored;
    close_bodies(ignored);
}

bool MeshStreamWriter::open(AtomicFile& file, MeshFormat format, bool ascii,
                            std::string& error) {
    file_ = &file;
    format_ = format;
    ascii_ = ascii && format == MeshFormat::ply;
    out_ = std::make_unique<BlockWriter>(file.file(), &file);
    // OBJ goes straight into a temporary; into a direct output (standard output, a pipe)
    // it waits in a scratch body like the others, so that a run that fails midway writes
    // nothing there.
    if (format == MeshFormat::obj && !file.direct()) {
        out_->append(obj_header());
        return true;
    }
    std::FILE* vertices = scratch_file_beside(file.path(), error);
    std::FILE* faces = vertices && format != MeshFormat::obj
                           ? scratch_file_beside(file.path(), error)
                           : nullptr;
    if (vertices) vertices_ = std::make_unique<BlockWriter>(vertices);
    if (faces) faces_ = std::make_unique<BlockWriter>(faces);
    return faces_ || (vertices_ && format == MeshFormat::obj);
}

BlockWriter& MeshStreamWriter::body(bool vertices) {
    if (format_ == MeshFormat::obj) return vertices_ ? *vertices_ : *out_;
    return vertices ? *vertices_ : *faces_;
}

void MeshStreamWriter::add_vertices(const double* xyz, size_t count) {
    BlockWriter& w = body(true);
    all_floats_ = all_floats_ && all_coordinates_are_floats(xyz, count);
    if (format_ == MeshFormat::ply && !ascii_)
        put_binary_vertices(w, xyz, count, false);
    else
        put_vertex_lines(w, xyz, count, format_ == MeshFormat::obj ? kObjStyle : kOffStyle);
    vertex_count_ += count;
}

void MeshStreamWriter::add_triangles(const uint32_t* triangles, size_t count) {
    BlockWriter& w = body(false);
    if (format_ == MeshFormat::ply && !ascii_)
        put_binary_faces(w, triangles, count);
    else
        put_face_lines(w, triangles, count, format_ == MeshFormat::obj ? kObjStyle : kOffStyle);
    triangle_count_ += count;
}

// Appends a temporary body to the output; binary PLY vertices were kept as doubles and
// become floats when every coordinate is one (as write_mesh_file decides).
bool MeshStreamWriter::copy_body(BlockWriter& from, bool doubles_to_floats) {
    from.flush();
    std::rewind(from.file());
    std::vector<char> chunk(1 << 20); // a whole number of doubles
    while (size_t got = std::fread(chunk.data(), 1, chunk.size(), from.file())) {
        if (!doubles_to_floats) {
            out_->append(std::string_view(chunk.data(), got));
            continue;
        }
        const char* doubles = chunk.data();
        put_records(*out_, got / 8, 4, [doubles](char* out, size_t i) {
            double value = 0;
            std::memcpy(&value, doubles + 8 * i, 8);
            return put_le_float(out, to_float(value));
        });
    }
    return !from.failed() && !std::ferror(from.file());
}

bool MeshStreamWriter::close_bodies(std::string& failure) {
    bool ok = true;
    for (std::unique_ptr<BlockWriter>* w : {&vertices_, &faces_}) {
        if (*w && !(*w)->close(failure)) ok = false;
        w->reset();
    }
    return ok;
}

bool MeshStreamWriter::finish(std::string& error) {
    const bool single = format_ == MeshFormat::ply && all_floats_;
    if (format_ == MeshFormat::ply)
        out_->append(ply_header(vertex_count_, triangle_count_, ascii_, single));
    else if (format_ == MeshFormat::off)
        out_->append(off_header(vertex_count_, triangle_count_));
    else if (vertices_)
        out_->append(obj_header());
    std::string failure;
    bool ok = !vertices_ || copy_body(*vertices_, single && !ascii_);
    ok = ok && (!faces_ || copy_body(*faces_, false));
    if (!ok) failure = "a temporary file cannot be read back";
    ok = close_bodies(failure) && ok;
    const int written = out_->drain();
    out_.reset();
    if (ok) return file_->complete(written, error);
    error = file_->path() + ": cannot write: " + failure;
    file_->discard();
    return false;
}

} // namespace stratmesh_cli
