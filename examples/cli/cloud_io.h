// Reading point clouds for the stratmesh tool.
//
// Formats: PLY (ascii, binary_little_endian, binary_big_endian), XYZ/PTS/TXT numeric
// columns, OFF and OBJ (their vertices are the cloud; faces are counted and skipped).
// Points come out as doubles, x y z packed, in file order. Float data converts to double
// exactly. A UTF-8 byte-order mark at the start of any of them is skipped.
//
// The readers are strict: a body that disagrees with its header (records more or fewer
// than declared, tokens more or fewer than a record's properties, an element or a
// property declared twice, a value outside its declared type, a number beyond the range
// of a double) is an error, never a guess. docs/formats.md lists what each reader accepts.
//
// Every reader parses from a memory buffer and trusts nothing in it: counts are checked
// against the bytes actually present before anything is reserved, vectors otherwise grow
// only as data arrives, and every failure is an error message, never a crash. The message
// says where: "line N" in text, "byte N" (offset from the start) in binary data.
#ifndef STRATMESH_CLI_CLOUD_IO_H
#define STRATMESH_CLI_CLOUD_IO_H

#include "big_buffer.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace stratmesh_cli {

enum class CloudFormat { automatic, ply, xyz, off, obj };

// "PLY", "XYZ", "OFF", "OBJ" ("automatic" for automatic).
const char* cloud_format_name(CloudFormat format);

// From the file name's extension, case-insensitively: .ply; .xyz .pts .txt .csv .asc;
// .off; .obj. Anything else: automatic.
CloudFormat cloud_format_from_extension(const std::string& path);

// From the content: "ply" magic line, an OFF header keyword, OBJ "v" lines; anything
// else is taken for numeric columns (XYZ).
CloudFormat detect_cloud_format(const char* data, size_t size);

// The input's per-point data besides x, y, z: a PLY vertex element's other scalar
// properties (normals, colours, intensity, any scalar), kept as their raw bytes so that the
// writers carry them over unchanged. List properties are not kept.
struct PointAttributes {
    struct Property {
        std::string name;
        std::string type;   // the PLY type name ("uchar", "float", ...)
        size_t size = 0;    // bytes
        size_t offset = 0;  // within a record
        bool integral = false, is_signed = false;
    };
    std::vector<Property> properties;
    size_t record_bytes = 0;          // the properties' sizes added up
    std::vector<unsigned char> bytes; // a record per point, in point order, little-endian
    uint64_t lists_dropped = 0;       // list properties of the vertex element, not kept

    bool empty() const { return properties.empty(); }
    // The property's index, or -1.
    int find(const std::string& name) const;
    // The value of property `property` of point `point`, as a double (exact for every type).
    double value(size_t point, size_t property) const;
};

struct CloudInfo {
    CloudFormat format = CloudFormat::automatic; // the format actually read
    std::string encoding; // PLY: "ascii", "binary_little_endian", "binary_big_endian"
    // open_point_reader: the most points the file can hold (a PLY header's vertex count; a
    // text file's size over the shortest line a point can take); UINT64_MAX if unknown (a
    // pipe).
    uint64_t point_limit = UINT64_MAX;
    // Faces in the file (OFF, OBJ, a PLY 'face' element), which the cloud leaves out.
    uint64_t faces_ignored = 0;
    // Set by the caller: keep the per-point data in `attributes` (whole-file PLY only).
    bool keep_attributes = false;
    PointAttributes attributes;
};

// Parses a whole file image. `format` automatic detects it from the content; any other
// value forces that reader. On success `xyz` holds 3 * point_count doubles; on failure
// `error` says what and where, and `xyz` is unspecified.
bool read_cloud_from_memory(const char* data, size_t size, CloudFormat format,
                            std::vector<double>& xyz, std::string& error,
                            CloudInfo* info = nullptr);

// Reads a whole file ("-": standard input) into `bytes` (its pages faulted in at once,
// big_buffer.h), its length into `size`: one request for a regular file whose size does
// not change, a buffer doubling as the bytes arrive otherwise.
bool read_file_bytes(const std::string& path, BigBuffer& bytes, size_t& size, std::string& error);

// How messages name an input: "standard input" for "-", else the path.
std::string display_name(const std::string& path);

// read_file_bytes + read_cloud_from_memory with the format detected from the content (the
// content wins over a misleading extension). Errors start with the path.
bool read_cloud_file(const std::string& path, std::vector<double>& xyz, std::string& error,
                     CloudInfo* info = nullptr);

// Reads a cloud file point by point with a window of about a megabyte (--stream), so the
// memory does not grow with the file. PLY (ascii, or binary whose vertex records have no
// list property, with no list element before the vertices), XYZ-style columns and OBJ;
// OFF is refused.
class PointReader {
public:
    virtual ~PointReader() = default;
    // The next point; false at the end of the points (`error` left empty) or on an error
    // (`error` says what and where, like the whole-file readers).
    virtual bool next(double xyz[3], std::string& error) = 0;
    // The faces the file holds, which the reader skips: all of them once next() has
    // returned false without an error (a PLY header's count from the start).
    virtual uint64_t faces_ignored() const { return 0; }
};

// Opens `path` ("-": standard input) for reading point by point, with the format detected
// from its first block; null with `error` (starting with the path) if it cannot.
std::unique_ptr<PointReader> open_point_reader(const std::string& path, CloudInfo& info,
                                               std::string& error);

} // namespace stratmesh_cli

#endif
