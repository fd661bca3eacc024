// Writing the reconstructed mesh.
//
// The vertex rule: the output vertices are the input points as read, all of them, in
// input order, including points the reconstruction did not use (duplicates, rejected
// NaN/Inf points, unused points). So the triangle indices returned by the library, which
// index the input, are written unchanged, and vertex i of the output is point i of the
// input. STL has no shared vertices: it only lists the triangles' corners.
//
// Coordinates are written exactly. Text formats use the shortest digits that read back as
// the same double (which also read back as the same float when the value is one). Binary
// PLY stores float when every coordinate is exactly a float (as after reading float
// data), double otherwise. Binary STL is float by definition.
//
// The input's per-point data (PointAttributes, from a PLY input) goes with its vertex: into
// a PLY output whole (the same names, types and values), into OBJ only the normals (nx, ny,
// nz as vn lines) and colours (red, green, blue after the coordinates, scaled to 0..1);
// OFF and STL carry none.
#ifndef STRATMESH_CLI_MESH_IO_H
#define STRATMESH_CLI_MESH_IO_H

#include "cloud_io.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

namespace stratmesh_cli {

enum class MeshFormat { unknown, ply, obj, off, stl };

// "PLY", "OBJ", "OFF", "STL" ("unknown").
const char* mesh_format_name(MeshFormat format);

// From the extension, case-insensitively: .ply, .obj, .off, .stl; else unknown.
MeshFormat mesh_format_from_extension(const std::string& path);

struct MeshView {
    const double* xyz; // 3 * vertex_count coordinates
    size_t vertex_count;
    const uint32_t* triangles; // 3 * triangle_count indices below vertex_count
    size_t triangle_count;
    const PointAttributes* attributes = nullptr; // per vertex, or null
};

// Which attributes an OBJ output carries: the indices of nx, ny, nz and of red, green,
// blue in PointAttributes (-1 where the input has not all three).
struct ObjAttributes {
    int normal[3] = {-1, -1, -1};
    int colour[3] = {-1, -1, -1};
    size_t carried() const {
        return (normal[0] >= 0 ? size_t{3} : size_t{0}) + (colour[0] >= 0 ? size_t{3} : size_t{0});
    }
};
ObjAttributes obj_attributes(const PointAttributes* attributes);

// How many of the attributes the format carries (all for PLY, the normals and colours for
// OBJ, none for OFF and STL).
size_t carried_attributes(const PointAttributes* attributes, MeshFormat format);

// True if every coordinate converts to float and back unchanged (NaN and infinities too).
bool all_coordinates_are_floats(const double* xyz, size_t count);

class AtomicFile;
class BlockWriter;

// Writes the mesh into `file` (opened, safe_output.h) and completes it; `ascii` selects text
// PLY and text STL (OBJ and OFF are always text). False with a message naming the file if
// the mesh is unfit or a write failed: the caller's commit_files() then leaves the
// destination as it was.
bool write_mesh_file(AtomicFile& file, MeshFormat format, const MeshView& mesh, bool ascii,
                     std::string& error);

// Writes a mesh whose vertices and triangles arrive piece by piece (--stream), in bounded
// memory, with the same vertex rule and the same bytes as write_mesh_file() given the
// whole mesh (OBJ excepted: its vertex and face lines interleave as they arrive). OBJ goes
// straight to the output's temporary; PLY and OFF, whose headers count what follows, and
// OBJ bound for a direct output, collect their bodies in unnamed scratch files beside the
// output and copy them after the header at finish(), so that nothing reaches the output
// before the mesh is complete. STL, which repeats the corners' coordinates in every
// triangle, is not supported.
class MeshStreamWriter {
public:
    MeshStreamWriter();
    ~MeshStreamWriter();

    // Starts the mesh in `file`, which must stay open while the writer lives; false with a
    // message naming the file.
    bool open(AtomicFile& file, MeshFormat format, bool ascii, std::string& error);
    void add_vertices(const double* xyz, size_t count);
    // Triangles must only use vertices already added.
    void add_triangles(const uint32_t* triangles, size_t count);
    // Completes the file (AtomicFile::complete); on failure discards it and says why.
    bool finish(std::string& error);

private:
    BlockWriter& body(bool vertices);
    bool copy_body(BlockWriter& from, bool doubles_to_floats);
    bool close_bodies(std::string& failure);

    AtomicFile* file_ = nullptr;
    MeshFormat format_ = MeshFormat::unknown;
    bool ascii_ = false;
    std::unique_ptr<BlockWriter> out_, vertices_, faces_;
    size_t vertex_count_ = 0, triangle_count_ = 0;
    bool all_floats_ = true;
};

} // namespace stratmesh_cli

#endif
