#include "mesh_io.h"

#include "path_util.h"
#include "safe_output.h"
#include "stratmesh.h"

#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace stratmesh_cli {

// Collects output in memory and hands it to the file in large blocks.
class BlockWriter {
public:
    explicit BlockWriter(std::FILE* file) : file_(file) {}

    std::string& buffer() { return buffer_; }
    std::FILE* file() const { return file_; }
    bool failed() const { return failure_ != 0; }

    void flush_if_large() {
        if (buffer_.size() >= kBlockBytes) flush();
    }

    void flush() {
        if (!buffer_.empty() &&
            std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
            remember_failure();
        buffer_.clear();
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

    static const size_t kBlockBytes = 1 << 20;
    std::FILE* file_;
    std::string buffer_;
    int failure_ = 0;
};

namespace {


// ---- encoding ----------------------------------------------------------------------------

void append_le(std::string& out, uint64_t bits, size_t bytes) {
    for (size_t i = 0; i < bytes; ++i) out += static_cast<char>((bits >> (8 * i)) & 0xffu);
}

void append_le_u32(std::string& out, uint32_t value) { append_le(out, value, 4); }

void append_le_float(std::string& out, float value) {
    uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    append_le(out, bits, 4);
}

void append_le_double(std::string& out, double value) {
    uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    append_le(out, bits, 8);
}

const double kFloatMax = static_cast<double>(FLT_MAX);

bool fits_float(double v) { return std::isnan(v) || std::isinf(v) || std::fabs(v) <= kFloatMax; }

// Finite doubles beyond float's range clamp to its largest value rather than overflow.
float to_float(double v) {
    if (fits_float(v)) return static_cast<float>(v);
    return v < 0 ? -FLT_MAX : FLT_MAX;
}

// The shortest text that reads back as the same double. A float stored in a double also
// reads back exactly as that float.
void append_number(std::string& out, double value) {
    char text[64];
    std::to_chars_result r = std::to_chars(text, text + sizeof text, value);
    out.append(text, r.ptr);
}

void append_point(std::string& out, const double* p) {
    for (int k = 0; k < 3; ++k) {
        if (k > 0) out += ' ';
        append_number(out, p[k]);
    }
}

void append_index(std::string& out, uint64_t index) {
    char text[24];
    std::to_chars_result r = std::to_chars(text, text + sizeof text, index);
    out.append(text, r.ptr);
}

const char* generator_comment() {
    return "stratmesh " STRATMESH_VERSION_STRING
           ": vertex i is input point i (all points kept, in input order)";
}

// ---- formats -----------------------------------------------------------------------------

void write_ply_header(std::string& out, const MeshView& mesh, bool ascii, bool single) {
    const char* type = single ? "float" : "double";
    out += "ply\nformat ";
    out += ascii ? "ascii" : "binary_little_endian";
    out += " 1.0\ncomment ";
    out += generator_comment();
    out += "\nelement vertex " + std::to_string(mesh.vertex_count) + "\n";
    for (const char* axis : {"x", "y", "z"})
        out += std::string("property ") + type + " " + axis + "\n";
    out += "element face " + std::to_string(mesh.triangle_count) + "\n";
    out += "property list uchar uint vertex_indices\nend_header\n";
}

void append_binary_vertex(std::string& out, const double* p, bool single) {
    for (size_t k = 0; k < 3; ++k) {
        if (single)
            append_le_float(out, to_float(p[k]));
        else
            append_le_double(out, p[k]);
    }
}

void append_binary_face(std::string& out, const uint32_t* triangle) {
    out += static_cast<char>(3);
    for (size_t k = 0; k < 3; ++k) append_le_u32(out, triangle[k]);
}

void write_ply_binary_body(BlockWriter& w, const MeshView& mesh, bool single) {
    for (size_t i = 0; i < mesh.vertex_count; ++i) {
        append_binary_vertex(w.buffer(), mesh.xyz + 3 * i, single);
        w.flush_if_large();
    }
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        append_binary_face(w.buffer(), mesh.triangles + 3 * t);
        w.flush_if_large();
    }
}

// Text PLY, OBJ and OFF share their shape: a vertex line per point, a face line per
// triangle.
struct TextStyle {
    const char* vertex_prefix; // "v " or ""
    const char* face_prefix;   // "f" or "3"
    uint32_t index_base;       // 1 or 0
};

const TextStyle kObjStyle = {"v ", "f", 1};
const TextStyle kOffStyle = {"", "3", 0}; // text PLY's too

void append_vertex_line(std::string& out, const double* p, const TextStyle& style) {
    out += style.vertex_prefix;
    append_point(out, p);
    out += '\n';
}

void append_face_line(std::string& out, const uint32_t* triangle, const TextStyle& style) {
    out += style.face_prefix;
    for (size_t k = 0; k < 3; ++k) {
        out += ' ';
        append_index(out, uint64_t{triangle[k]} + style.index_base);
    }
    out += '\n';
}

void write_text_body(BlockWriter& w, const MeshView& mesh, const TextStyle& style) {
    for (size_t i = 0; i < mesh.vertex_count; ++i) {
        append_vertex_line(w.buffer(), mesh.xyz + 3 * i, style);
        w.flush_if_large();
    }
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        append_face_line(w.buffer(), mesh.triangles + 3 * t, style);
        w.flush_if_large();
    }
}

void write_ply(BlockWriter& w, const MeshView& mesh, bool ascii) {
    bool single = !ascii && all_coordinates_are_floats(mesh.xyz, mesh.vertex_count);
    write_ply_header(w.buffer(), mesh, ascii, single);
    if (ascii)
        write_text_body(w, mesh, kOffStyle);
    else
        write_ply_binary_body(w, mesh, single);
}

std::string obj_header() { return std::string("# ") + generator_comment() + "\n"; }

std::string off_header(size_t vertex_count, size_t triangle_count) {
    return std::string("OFF\n# ") + generator_comment() + "\n" + std::to_string(vertex_count) +
           " " + std::to_string(triangle_count) + " 0\n";
}

void write_obj(BlockWriter& w, const MeshView& mesh) {
    w.buffer() += obj_header();
    write_text_body(w, mesh, kObjStyle);
}

void write_off(BlockWriter& w, const MeshView& mesh) {
    w.buffer() += off_header(mesh.vertex_count, mesh.triangle_count);
    write_text_body(w, mesh, kOffStyle);
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
    std::string& out = w.buffer();
    std::string title = "stratmesh " STRATMESH_VERSION_STRING " binary STL";
    title.resize(80, ' ');
    out += title;
    append_le_u32(out, static_cast<uint32_t>(mesh.triangle_count));
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        double n[3];
        triangle_normal(mesh, t, n);
        for (double c : n) append_le_float(out, to_float(c));
        for (size_t k = 0; k < 3; ++k)
            for (size_t j = 0; j < 3; ++j) append_le_float(out, to_float(corner(mesh, t, k)[j]));
        out += std::string(2, '\0'); // attribute byte count
        w.flush_if_large();
    }
}

void write_stl_ascii(BlockWriter& w, const MeshView& mesh) {
    std::string& out = w.buffer();
    out += "solid stratmesh\n";
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        double n[3];
        triangle_normal(mesh, t, n);
        out += "facet normal ";
        append_point(out, n);
        out += "\n outer loop\n";
        for (size_t k = 0; k < 3; ++k) {
            out += "  vertex ";
            append_point(out, corner(mesh, t, k));
            out += '\n';
        }
        out += " endloop\nendfacet\n";
        w.flush_if_large();
    }
    out += "endsolid stratmesh\n";
}

// Everything a file format cannot express, found before the file is created.
bool check_mesh(const MeshView& mesh, MeshFormat format, std::string& error) {
    for (size_t i = 0; i < 3 * mesh.triangle_count; ++i) {
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
    case MeshFormat::obj: write_obj(w, mesh); break;
    case MeshFormat::off: write_off(w, mesh); break;
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
    for (size_t i = 0; i < 3 * count; ++i) {
        double v = xyz[i];
        if (!fits_float(v)) return false;
        if (!std::isnan(v) && static_cast<double>(static_cast<float>(v)) != v) return false;
    }
    return true;
}

bool write_mesh_file(const std::string& path, MeshFormat format, const MeshView& mesh, bool ascii,
                     std::string& error) {
    if (format == MeshFormat::unknown) {
        error = path + ": unknown mesh format (use .ply, .obj, .off or .stl)";
        return false;
    }
    if (!check_mesh(mesh, format, error)) {
        error = path + ": " + error;
        return false;
    }
    AtomicFile file;
    if (!file.open(path, error)) return false;
    BlockWriter writer(file.file());
    write_body(writer, format, mesh, ascii);
    return file.commit(writer.drain(), error);
}

MeshStreamWriter::MeshStreamWriter() = default;

// A writer still open here is abandoned: its temporaries are removed, the destination left
// as it was.
MeshStreamWriter::~MeshStreamWriter() {
    std::string ignored;
    if (out_) finish(false, ignored);
}

bool MeshStreamWriter::open(const std::string& path, MeshFormat format, bool ascii,
                            std::string& error) {
    path_ = path;
    format_ = format;
    ascii_ = ascii && format == MeshFormat::ply;
    file_ = std::make_unique<AtomicFile>();
    if (!file_->open(path, error)) return false;
    out_ = std::make_unique<BlockWriter>(file_->file());
    if (format == MeshFormat::obj) {
        out_->buffer() += obj_header();
        return true;
    }
    std::FILE* vertices = scratch_file_beside(path, error);
    std::FILE* faces = vertices ? scratch_file_beside(path, error) : nullptr;
    if (vertices) vertices_ = std::make_unique<BlockWriter>(vertices);
    if (faces) faces_ = std::make_unique<BlockWriter>(faces);
    if (faces) return true;
    std::string ignored;
    finish(false, ignored);
    return false;
}

void MeshStreamWriter::add_vertices(const double* xyz, size_t count) {
    BlockWriter& w = format_ == MeshFormat::obj ? *out_ : *vertices_;
    bool binary = format_ == MeshFormat::ply && !ascii_;
    all_floats_ = all_floats_ && all_coordinates_are_floats(xyz, count);
    for (size_t i = 0; i < count; ++i) {
        if (binary)
            append_binary_vertex(w.buffer(), xyz + 3 * i, false);
        else
            append_vertex_line(w.buffer(), xyz + 3 * i,
                               format_ == MeshFormat::obj ? kObjStyle : kOffStyle);
        w.flush_if_large();
    }
    vertex_count_ += count;
}

void MeshStreamWriter::add_triangles(const uint32_t* triangles, size_t count) {
    BlockWriter& w = format_ == MeshFormat::obj ? *out_ : *faces_;
    bool binary = format_ == MeshFormat::ply && !ascii_;
    for (size_t t = 0; t < count; ++t) {
        if (binary)
            append_binary_face(w.buffer(), triangles + 3 * t);
        else
            append_face_line(w.buffer(), triangles + 3 * t,
                             format_ == MeshFormat::obj ? kObjStyle : kOffStyle);
        w.flush_if_large();
    }
    triangle_count_ += count;
}

// Appends a temporary body to the output; binary PLY vertices were kept as doubles and
// become floats when every coordinate is one (as write_mesh_file decides).
bool MeshStreamWriter::copy_body(BlockWriter& from, bool doubles_to_floats) {
    from.flush();
    std::rewind(from.file());
    std::vector<char> chunk(1 << 20); // a whole number of doubles
    while (size_t got = std::fread(chunk.data(), 1, chunk.size(), from.file())) {
        if (!doubles_to_floats) out_->buffer().append(chunk.data(), got);
        for (size_t at = 0; doubles_to_floats && at + 8 <= got; at += 8) {
            double value = 0;
            std::memcpy(&value, chunk.data() + at, 8);
            append_le_float(out_->buffer(), to_float(value));
        }
        out_->flush_if_large();
    }
    return !from.failed() && !std::ferror(from.file());
}

bool MeshStreamWriter::finish(bool keep, std::string& error) {
    bool single = format_ == MeshFormat::ply && !ascii_ && all_floats_;
    if (keep && format_ != MeshFormat::obj) {
        MeshView counts = {nullptr, vertex_count_, nullptr, triangle_count_};
        if (format_ == MeshFormat::ply)
            write_ply_header(out_->buffer(), counts, ascii_, single);
        else
            out_->buffer() += off_header(vertex_count_, triangle_count_);
    }
    std::string failure;
    bool ok = keep && (format_ == MeshFormat::obj ||
                       (copy_body(*vertices_, single) && copy_body(*faces_, false)));
    if (keep && !ok) failure = "a temporary file cannot be read back";
    for (std::unique_ptr<BlockWriter>* w : {&vertices_, &faces_}) {
        if (*w && !(*w)->close(failure)) ok = false;
        w->reset();
    }
    const int written = out_ ? out_->drain() : 0;
    out_.reset();
    if (ok) return file_->commit(written, error);
    if (file_) file_->discard();
    if (keep) error = path_ + ": cannot write: " + failure;
    return false;
}

} // namespace stratmesh_cli
