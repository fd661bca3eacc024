// The tool's command line.
#ifndef STRATMESH_CLI_ARGS_H
#define STRATMESH_CLI_ARGS_H

#include "mesh_io.h"
#include "safe_output.h"
#include "stratmesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace stratmesh_cli {

struct CommandLine {
    std::string input;  // "-": standard input
    std::string output; // "-": standard output
    // From --format, else from the output's extension (--format is required with -o -).
    MeshFormat output_format = MeshFormat::unknown;
    std::string report; // --report, empty if not given
    std::string preview; // --preview FILE.svg, empty if not given
    stratmesh::Axis axis = stratmesh::Axis::automatic;
    double direction[3] = {0, 0, 0}; // with Axis::direction
    std::vector<double> cuts;        // --cuts
    uint32_t layer_count = 0;        // --layers, 0 if not given
    double layer_height = 0;         // --layer-height, 0 if not given
    bool ascii = false;
    bool no_attributes = false;    // --no-attributes: write the points' coordinates only
    bool skip_invalid = false;
    bool cap = false;              // --cap: close the ends (stratmesh::add_caps)
    bool drop_outliers = false;    // --drop-outliers (stratmesh::drop_outliers)
    bool surface_flips = false;    // --surface-flips (stratmesh::surface_flips)
    bool ends_are_cuts = false;    // --ends-are-cuts (stratmesh::ends_are_cuts)
    // Where the cloud parts into branches (stratmesh::find_parting). By default the tool
    // looks, meshes the parts apart and joins them, and keeps that only if every part was
    // meshed and joined (else one tube, see main.cpp).
    bool find_branches = false;    // --branches: only find and report where it parts
    // --parts automatic|one-tube|apart (stratmesh::Options::parts)
    stratmesh::Parts parts = stratmesh::Parts::automatic;
    bool parts_given = false;
    bool quiet = false;             // no summary (warnings and errors still)
    bool verbose = false;           // --verbose: timings, memory and details in the summary
    bool strict = false;            // --strict: warnings give an exit status of their own
    uint32_t threads = 1;           // --threads (default: the hardware's threads, at least 1)
    bool stream = false;            // --stream: read and reconstruct layer by layer
    uint64_t stream_points = 3000000; // --stream-points: the most points the stream holds
    bool origin_given = false;      // --origin
    double origin[3] = {0, 0, 0};
};

enum class CommandAction { run, help, version, usage_error };

// Parses argv. --help and --version win over any error; otherwise an error (unknown
// option, missing value or -o, bad number, unknown output extension...) gives
// usage_error with the message in `error`.
CommandAction parse_command_line(int argc, const char* const* argv, CommandLine& line,
                                 std::string& error);

// The files the command line names ("-" for the standard streams), the input first, each
// with how the command line names it: what check_distinct_files (safe_output.h) compares.
std::vector<NamedFile> named_files(const CommandLine& line);

// The --help text.
const char* usage_text();

// "automatic", "x", "y", "z" or "direction".
const char* axis_name(stratmesh::Axis axis);

// --parts' spelling: "automatic", "one-tube" or "apart".
const char* parts_name(stratmesh::Parts parts);

} // namespace stratmesh_cli

#endif
