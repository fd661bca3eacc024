// What one run of the tool did, and its machine-readable form (--report FILE.json).
#ifndef STRATMESH_CLI_REPORT_JSON_H
#define STRATMESH_CLI_REPORT_JSON_H

#include "mesh_ends.h"
#include "stratmesh.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace stratmesh_cli {

// The library phases that are timed; later ones (if the library gains any) are not.
const size_t kTimedPhases = 5; // validate, layers, triangulate, stitch, manifold

// The phase's name ("validate", ...), or nullptr for a value this tool does not know.
const char* phase_name(stratmesh::Phase phase);

struct RunRecord {
    // Input and output.
    std::string input_path, input_format, input_encoding;
    uint64_t input_faces_ignored = 0; // faces in the input, left out of the cloud
    // The input's per-point properties besides x, y, z that were read (PLY, unless
    // --no-attributes or the output carries none), and how many the output carries.
    size_t point_properties = 0, point_properties_carried = 0;
    std::string output_path, output_format;
    bool output_ascii = false;
    bool output_written = false;
    // The options given.
    std::string axis = "automatic"; // "automatic", "x", "y", "z" or "direction"
    double direction[3] = {0, 0, 0};
    std::vector<double> cuts;
    uint32_t layer_count = 0; // --layers, 0 if not given
    double layer_height = 0;  // --layer-height, 0 if not given
    bool skip_invalid = false;
    bool cap = false;
    bool drop_outliers = false;
    bool surface_flips = false;
    bool ends_are_cuts = false;
    bool find_branches = false;
    stratmesh::Parts parts_option = stratmesh::Parts::automatic;  // --parts
    uint32_t threads = 1;
    bool origin_given = false;
    double origin[3] = {0, 0, 0};
    bool stream = false;
    uint64_t stream_points = 0; // --stream-points, with --stream
    // With --stream: the layers pushed, and their tops but the last's (the --cuts of the
    // equivalent run without --stream).
    size_t stream_pushes = 0;
    std::vector<double> batch_cuts;
    // The outcome. report.layers.info is not used: the filled entries are copied to `layers`.
    bool reconstructed = false; // reconstruct() ran (the input could be read)
    stratmesh::Status status = stratmesh::Status::ok;
    stratmesh::Report report = {};
    std::vector<stratmesh::LayerInfo> layers;
    // The surface's boundary loops at each end (mesh_ends.h).
    SurfaceEnds ends;
    // The valid points' range along the axis used, dot(point, Report::axis) (known when
    // `range_known`), and the cuts given outside it.
    bool range_known = false;
    double range_low = 0, range_high = 0;
    std::vector<double> cuts_outside;
    // With --layers, --cuts or --layer-height and `range_known`: the planned layers that
    // held fewer than the library's 16 points, which it merges into the next.
    size_t sparse_planned_layers = 0;
    // The cost; seconds are NaN when unknown (written as null).
    double read_seconds, reconstruct_seconds, write_seconds, branches_seconds;
    double phase_seconds[kTimedPhases];
    size_t workspace_bytes = 0;
    size_t triangle_buffer_bytes = 0;
    size_t peak_rss_bytes = 0; // the process's peak resident memory; 0 if unknown
    // With --branches, once the reconstruction succeeded: find_parting's status and result.
    bool parting_run = false;
    stratmesh::Status parting_status = stratmesh::Status::ok;
    stratmesh::Parting parting = {};
    // Where the cloud parts and the parts are meshed: each tube meshed apart, the trunk first
    // (whose report, with the whole cloud's counts, is `report`).
    struct SplitPart {
        std::string name;       // "trunk", "branch above 1", "branch below 2", ...
        size_t points = 0;
        stratmesh::Status status = stratmesh::Status::ok;
        size_t layers = 0, triangles = 0, folds = 0;
        size_t end_layers_merged = 0;  // the trunk's: merged into an end under branches
    };
    std::vector<SplitPart> split;
    // By default where the cloud parts: the parts were meshed but not kept (a side left
    // apart, a part not meshed, points in no part), the cloud meshed as one tube instead.
    bool split_undone = false;
    // Where the cloud parts and the parts were meshed: join_branches()'s status and report.
    bool junction_run = false;
    stratmesh::Status junction_status = stratmesh::Status::ok;
    stratmesh::JoinReport junction = {};

    RunRecord();

    // Records the library's report; the first `outcome.layers.used_count` (at most) entries
    // of `filled`, which outcome.layers.info pointed at, move into `layers`.
    void take_report(stratmesh::Report outcome, std::vector<stratmesh::LayerInfo>& filled);
    // Records where the cloud parted and how its parts were meshed and joined, from the
    // library's report and the part details it filled.
    void take_parts(const stratmesh::PartCounts& parts,
                    const std::vector<stratmesh::PartInfo>& filled);
};

// The record as a JSON document (UTF-8, numbers round-trip exactly, NaN/Inf as null).
std::string run_record_json(const RunRecord& record);

// `text` as a JSON string literal, quotes included. Bytes that are not valid UTF-8 become
// U+FFFD, so the result is always valid JSON.
std::string json_string(std::string_view text);

class AtomicFile;

// Writes `text` into `file` (opened, safe_output.h) and completes it; false with a message
// naming the file on failure.
bool write_text_file(AtomicFile& file, const std::string& text, std::string& error);

} // namespace stratmesh_cli

#endif
