// --stream: reads the input point by point, pushes it to a stratmesh stream layer by
// layer and writes the mesh as the triangles come, so the memory follows the layers, not
// the file.
#ifndef STRATMESH_CLI_STREAM_RUN_H
#define STRATMESH_CLI_STREAM_RUN_H

#include "args.h"
#include "report_json.h"
#include "stratmesh.h"

#include <string>

namespace stratmesh_cli {

enum class StreamOutcome {
    done,       // the mesh is written
    refused,    // the library refused the input: record.status says why, and where the
                // stream ran out of memory, `error` what to do about it
    file_error, // reading or writing failed: `error` says what and where
    unsorted,   // a point lies below the one before it along the axis: `error` says which
    usage       // the command line asks for what the cloud cannot give: `error` says what
};

// Runs the stream with `options` (axis, flags; the origin, unless given, is the first
// valid point read) and the layers of `line` (--cuts or --layer-height), writing the mesh
// into `mesh` (opened; completed when done, for commit_files() to publish). Fills `record`.
StreamOutcome run_stream(const CommandLine& line, stratmesh::Options options, RunRecord& record,
                         AtomicFile& mesh, std::string& error);

} // namespace stratmesh_cli

#endif
