// File-name helpers shared by the readers and writers.
#ifndef STRATMESH_CLI_PATH_UTIL_H
#define STRATMESH_CLI_PATH_UTIL_H

#include <string>

namespace stratmesh_cli {

// The text after the last '.' of the file name (not of a directory), in lower case;
// empty if there is none.
inline std::string lowercase_extension(const std::string& path) {
    size_t dot = path.find_last_of('.');
    size_t slash = path.find_last_of("/\\");
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot + 1);
    for (char& c : ext)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return ext;
}

} // namespace stratmesh_cli

#endif
