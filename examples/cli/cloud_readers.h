// The individual cloud readers behind read_cloud_from_memory (internal to the tool).
#ifndef STRATMESH_CLI_CLOUD_READERS_H
#define STRATMESH_CLI_CLOUD_READERS_H

#include "cloud_io.h"
#include "file_window.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace stratmesh_cli {

// `encoding` receives the PLY format line's encoding name; `faces` the count of faces the
// file holds (and the reader skips). read_ply takes the whole file, a byte-order mark
// included (its byte offsets count from the file's start); the text readers take the
// text after any byte-order mark.
// `attributes`, if given, receives the vertex element's other scalar properties.
bool read_ply(std::string_view data, std::vector<double>& xyz, std::string& error,
              std::string& encoding, uint64_t& faces, PointAttributes* attributes);
bool read_xyz(std::string_view data, std::vector<double>& xyz, std::string& error);
bool read_off(std::string_view data, std::vector<double>& xyz, std::string& error,
              uint64_t& faces);
bool read_obj(std::string_view data, std::vector<double>& xyz, std::string& error,
              uint64_t& faces);

// Point-by-point readers over a file window positioned at the start of the file.
// open_ply_points also gives the header's encoding, vertex count and face count; its file
// may start with a byte-order mark, open_text_points' may not.
std::unique_ptr<PointReader> open_ply_points(std::unique_ptr<FileWindow> file, std::string& error,
                                             std::string& encoding, uint64_t& vertex_count,
                                             uint64_t& faces);
std::unique_ptr<PointReader> open_text_points(std::unique_ptr<FileWindow> file, bool obj);

// True for OFF header keywords: OFF with the optional prefixes ST, C, N, 4, n.
bool is_off_keyword(std::string_view token);

} // namespace stratmesh_cli

#endif
