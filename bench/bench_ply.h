// bench_ply.h - the benchmark's PLY point reader (--cloud FILE.ply).
//
// Reads the vertex positions of an ascii or binary little-endian PLY file:
// - the vertex element must be the first element (faces and others may follow it, and
//   are ignored; an element before it is refused with a clear error);
// - x, y and z must be float or double properties (float32 and float64 are accepted as
//   names), each exactly once, in any order;
// - every other vertex property may be of any scalar type and is skipped; list
//   properties in the vertex element are refused;
// - binary_big_endian is refused.
// A header that breaks these rules, or a body shorter than the header promises, is an
// error with a message naming the problem.

#ifndef STRATMESH_BENCH_PLY_H
#define STRATMESH_BENCH_PLY_H

#include "stratmesh.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace bench {

// The vertex points of a PLY file, ready for stratmesh::reconstruct. `cloud` points into
// `raw` or `xyz` of this object: a copy's cloud still points into the original.
struct PlyCloud {
    std::string format;              // "ascii" or "binary_little_endian"
    size_t vertex_count = 0;
    size_t record_bytes = 0;         // binary: the size of one vertex record
    std::vector<unsigned char> raw;  // binary, read in place: the vertex records
    std::vector<double> xyz;         // otherwise: packed x y z doubles
    stratmesh::Cloud cloud = {nullptr, 0, 0, stratmesh::Scalar::float64};
};

// Checks the header, and for a binary file that it holds every vertex record; cheap (it
// reads the header only). False and `error` set if the file cannot be used; otherwise
// `vertex_count` is the header's.
bool check_ply_file(const std::string& path, size_t& vertex_count, std::string& error);

// Reads the vertices. When the file is binary little-endian on a little-endian host and
// x, y, z are adjacent and of one type, the cloud points into the records as they are
// (stride = the record size, the file's scalar type), which is how a scanner's buffer is
// handed to stratmesh; otherwise the positions are converted to packed doubles.
bool read_ply_file(const std::string& path, PlyCloud& ply, std::string& error);

}  // namespace bench

#endif  // STRATMESH_BENCH_PLY_H
