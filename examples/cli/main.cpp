// stratmesh: the command-line tool. Reads a point cloud, reconstructs a mesh with
// stratmesh::reconstruct and writes it; see usage_text() in args.cpp for the options.
//
// The output's vertices are the input points as read, all of them, in input order (unused
// points are kept), so the library's triangle indices, which index the input, are written
// unchanged. See mesh_io.h.
#include "args.h"
#include "cloud_io.h"
#include "mesh_ends.h"
#include "mesh_io.h"
#include "peak_memory.h"
#include "preview.h"
#include "progress.h"
#include "report_json.h"
#include "safe_output.h"
#include "stratmesh.h"
#include "stream_run.h"
#include "summary.h"
#include "thread_jobs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#ifdef _WIN32
#include <io.h>
#define STRATMESH_CLI_STDERR_IS_TERMINAL() (_isatty(_fileno(stderr)) != 0)
#else
#include <unistd.h>
#define STRATMESH_CLI_STDERR_IS_TERMINAL() (isatty(fileno(stderr)) != 0)
#endif

namespace {

using namespace stratmesh_cli;

const int kExitOk = 0;
const int kExitRefused = 1;
const int kExitUsage = 2;
const int kExitFile = 3;
const int kExitUnsorted = 4;
const int kExitPoor = 5; // --strict: the mesh is written, and judged poor

// Progress is drawn for inputs this large, when stderr is a terminal.
const size_t kProgressPoints = 200000;
// Per-layer details are kept for at most this many layers unless the options say more.
const size_t kDefaultLayerCapacity = 65536;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

struct FreeDeleter {
    void operator()(void* p) const { std::free(p); }
};

// Uninitialised memory (no zero-filling of a large workspace), or null.
template <class T> std::unique_ptr<T, FreeDeleter> allocate(size_t count) {
    if (count > SIZE_MAX / sizeof(T)) return nullptr;
    size_t bytes = count * sizeof(T);
    return std::unique_ptr<T, FreeDeleter>(static_cast<T*>(std::malloc(bytes ? bytes : 1)));
}

void record_command_line(const CommandLine& line, RunRecord& record) {
    MeshFormat format = line.output_format;
    record.input_path = line.input;
    record.output_path = line.output;
    record.output_format = mesh_format_name(format);
    record.output_ascii = line.ascii && (format == MeshFormat::ply || format == MeshFormat::stl);
    record.axis = axis_name(line.axis);
    for (size_t k = 0; k < 3; ++k) record.direction[k] = line.direction[k];
    record.cuts = line.cuts;
    record.layer_count = line.layer_count;
    record.layer_height = line.layer_height;
    record.skip_invalid = line.skip_invalid;
    record.cap = line.cap;
    record.drop_outliers = line.drop_outliers;
    record.surface_flips = line.surface_flips;
    record.ends_are_cuts = line.ends_are_cuts;
    record.find_branches = line.find_branches;
    record.parts_option = line.parts;
    record.threads = line.threads;
    record.origin_given = line.origin_given || line.stream;
    for (size_t k = 0; k < 3; ++k) record.origin[k] = line.origin[k];
}

stratmesh::Options make_options(const CommandLine& line, ProgressMonitor& monitor,
                                ThreadJobs& jobs) {
    stratmesh::Options options = {};
    options.axis = line.axis;
    for (size_t k = 0; k < 3; ++k) options.direction[k] = line.direction[k];
    options.cuts = line.cuts.empty() ? nullptr : line.cuts.data();
    options.cut_count = line.cuts.size();
    options.layer_count = line.layer_count;
    options.layer_height = line.layer_height;
    options.flags = (line.skip_invalid ? stratmesh::skip_invalid_points : 0u) |
                    (line.cap ? stratmesh::add_caps : 0u) |
                    (line.drop_outliers ? stratmesh::drop_outliers : 0u) |
                    (line.surface_flips ? stratmesh::surface_flips : 0u) |
                    (line.ends_are_cuts ? stratmesh::ends_are_cuts : 0u);
    options.parts = line.find_branches ? stratmesh::Parts::one_tube : line.parts;
    options.progress = &ProgressMonitor::callback;
    options.progress_user = &monitor;
    if (line.origin_given) {
        options.flags |= stratmesh::origin_given;
        for (size_t k = 0; k < 3; ++k) options.origin[k] = line.origin[k];
    }
    jobs.threads = line.threads;
    jobs.attach(options);
    return options;
}

// Room for the per-layer details: layers hold at least 3 points each.
size_t layer_capacity(const CommandLine& line, size_t points) {
    size_t most = points / 3 + 1;
    size_t asked = kDefaultLayerCapacity;
    if (!line.cuts.empty()) asked = line.cuts.size() + 1;
    if (line.layer_count > 0) asked = line.layer_count;
    return asked < most ? asked : most;
}

// Reads the points and, unless --no-attributes or the output carries none, their other
// data into `attributes`.
bool read_input(const CommandLine& line, std::vector<double>& xyz, PointAttributes& attributes,
                RunRecord& record) {
    Clock::time_point start = Clock::now();
    CloudInfo info;
    info.keep_attributes = !line.no_attributes && (line.output_format == MeshFormat::ply ||
                                                   line.output_format == MeshFormat::obj);
    std::string error;
    if (!read_cloud_file(line.input, xyz, error, &info)) {
        std::fprintf(stderr, "stratmesh: %s\n", error.c_str());
        return false;
    }
    record.read_seconds = seconds_since(start);
    record.input_format = cloud_format_name(info.format);
    record.input_encoding = info.encoding;
    record.input_faces_ignored = info.faces_ignored;
    attributes = std::move(info.attributes);
    record.point_properties = attributes.properties.size();
    record.point_properties_carried = carried_attributes(&attributes, line.output_format);
    CloudFormat named = cloud_format_from_extension(line.input);
    if (!line.quiet && named != CloudFormat::automatic && named != info.format)
        std::fprintf(stderr, "stratmesh: note: %s holds %s, not %s; read as %s\n",
                     line.input.c_str(), cloud_format_name(info.format), cloud_format_name(named),
                     cloud_format_name(info.format));
    return true;
}

// What reconstruct() produced: triangles indexing the input points.
struct Reconstruction {
    std::unique_ptr<uint32_t, FreeDeleter> triangles;
    size_t triangle_count = 0;
};

bool allocate_buffers(size_t workspace_bytes, size_t max_triangles,
                      std::unique_ptr<unsigned char, FreeDeleter>& workspace,
                      Reconstruction& result) {
    workspace = allocate<unsigned char>(workspace_bytes);
    result.triangles =
        allocate<uint32_t>(max_triangles <= SIZE_MAX / 3 ? 3 * max_triangles : SIZE_MAX);
    if (workspace && result.triangles) return true;
    std::fprintf(stderr, "stratmesh: cannot allocate %zu bytes of workspace and %zu triangles\n",
                 workspace_bytes, max_triangles);
    return false;
}

// Moves the library's report, the filled layer details and the phase times into the record.
void record_outcome(stratmesh::Report report, std::vector<stratmesh::LayerInfo>& layers,
                    const ProgressMonitor& monitor, RunRecord& record) {
    record.reconstructed = true;
    record.reconstruct_seconds = monitor.total_seconds();
    for (size_t p = 0; p < kTimedPhases; ++p) record.phase_seconds[p] = monitor.phase_seconds(p);
    record.take_report(report, layers);
}

// One call of reconstruct() on packed points, with its buffers: the workspace and
// triangle buffer sizes go to *workspace_bytes and *triangle_buffer_bytes. False if the
// buffers cannot be allocated.
bool run_reconstruct(const std::vector<double>& xyz, const stratmesh::Options& options,
                     std::vector<stratmesh::LayerInfo>& layers,
                     std::vector<stratmesh::PartInfo>& parts, Reconstruction& result,
                     stratmesh::Status& status, stratmesh::Report& report,
                     size_t* workspace_bytes, size_t* triangle_buffer_bytes) {
    const size_t count = xyz.size() / 3;
    *workspace_bytes = stratmesh::reconstruct_workspace_size(count, options);
    const size_t max_triangles = stratmesh::reconstruct_max_triangles(count, options);
    *triangle_buffer_bytes = max_triangles <= SIZE_MAX / 12 ? 12 * max_triangles : SIZE_MAX;
    std::unique_ptr<unsigned char, FreeDeleter> workspace;
    if (!allocate_buffers(*workspace_bytes, max_triangles, workspace, result)) return false;
    report = {};
    report.layers.info = layers.data();
    report.layers.info_capacity = layers.size();
    report.parts.info = parts.data();
    report.parts.info_capacity = parts.size();
    const stratmesh::Cloud cloud = {xyz.data(), count, 0, stratmesh::Scalar::float64};
    status = stratmesh::reconstruct(cloud, options, workspace.get(), *workspace_bytes,
                                    result.triangles.get(), max_triangles,
                                    &result.triangle_count, &report);
    return true;
}

// Runs reconstruct() and records its outcome; false if the buffers cannot be allocated.
bool reconstruct_points(const std::vector<double>& xyz, const CommandLine& line,
                        Reconstruction& result, RunRecord& record) {
    size_t count = xyz.size() / 3;
    bool show = !line.quiet && count >= kProgressPoints && STRATMESH_CLI_STDERR_IS_TERMINAL();
    ProgressMonitor monitor(show, stderr);
    ThreadJobs jobs;
    stratmesh::Options options = make_options(line, monitor, jobs);
    std::vector<stratmesh::LayerInfo> layers(layer_capacity(line, count));
    std::vector<stratmesh::PartInfo> parts(1 + 2 * stratmesh::kMaxBranches);
    stratmesh::Report report;
    monitor.begin();
    if (!run_reconstruct(xyz, options, layers, parts, result, record.status, report,
                         &record.workspace_bytes, &record.triangle_buffer_bytes))
        return false;
    monitor.end();
    record_outcome(report, layers, monitor, record);
    record.take_parts(report.parts, parts);
    return true;
}

// With --branches: where the cloud parts, into the record (the mesh is then one tube).
// False if the buffer cannot be allocated.
bool find_branches(const std::vector<double>& xyz, const CommandLine& line, RunRecord& record) {
    ProgressMonitor silent(false, stderr);
    ThreadJobs jobs;
    const stratmesh::Options options = make_options(line, silent, jobs);
    const size_t count = xyz.size() / 3;
    const size_t bytes = stratmesh::find_parting_workspace_size(count, options);
    std::unique_ptr<unsigned char, FreeDeleter> workspace = allocate<unsigned char>(bytes);
    if (!workspace) {
        std::fprintf(stderr, "stratmesh: cannot allocate %zu bytes to find the branches\n", bytes);
        return false;
    }
    const stratmesh::Cloud cloud = {xyz.data(), count, 0, stratmesh::Scalar::float64};
    Clock::time_point start = Clock::now();
    record.parting_status =
        stratmesh::find_parting(cloud, options, workspace.get(), bytes, &record.parting, nullptr);
    record.branches_seconds = seconds_since(start);
    record.parting_run = true;
    return true;
}

// `advice`, if any, is the tool's own account of the refusal (the stream's memory, which
// its options size), said in place of the library's.
void explain_refusal(const CommandLine& line, const RunRecord& record, const std::string& advice) {
    const std::string name = display_name(line.input);
    if (!advice.empty()) {
        std::fprintf(stderr, "stratmesh: cannot reconstruct %s: out_of_memory: %s\n", name.c_str(),
                     advice.c_str());
        return;
    }
    if (record.status == stratmesh::Status::invalid_origin) {
        std::fprintf(stderr, "stratmesh: --origin %.6g,%.6g,%.6g: %s\n", line.origin[0],
                     line.origin[1], line.origin[2],
                     in_tool_words(record.report.detail ? record.report.detail
                                                        : stratmesh::status_string(record.status)).c_str());
        return;
    }
    std::fprintf(stderr, "stratmesh: cannot reconstruct %s: %s\n", name.c_str(),
                 stratmesh::status_string(record.status));
    // Where the tool gives its own advice (--skip-invalid), the library's, in the library's
    // terms, is left out.
    if (record.status == stratmesh::Status::invalid_point)
        std::fprintf(stderr,
                     "stratmesh: point %zu (counting from 0) has a NaN or infinite coordinate; "
                     "--skip-invalid skips such points\n",
                     record.report.points.first_invalid_index);
    else if (record.report.detail)
        std::fprintf(stderr, "stratmesh: %s\n", in_tool_words(record.report.detail).c_str());
}

// The valid points' range along the axis used, the cuts given outside it, and with layers
// from the options, how many of the layers planned as the library plans them (Options:
// the cuts inside the range, or equal heights) hold fewer than stratmesh::kMinLayerPoints points.
// Counted over the valid points as given: duplicates and outliers, which the library
// leaves out first, count too.
void measure_along_axis(const std::vector<double>& xyz, RunRecord& record) {
    const bool layers_asked = !record.cuts.empty() || record.layer_count > 0 ||
                              record.layer_height > 0;
    if (!layers_asked) return;
    const double* axis = record.report.axis;
    std::vector<double> heights;
    heights.reserve(xyz.size() / 3);
    for (size_t i = 0; i + 2 < xyz.size(); i += 3) {
        const double h = xyz[i] * axis[0] + xyz[i + 1] * axis[1] + xyz[i + 2] * axis[2];
        if (std::isfinite(h)) heights.push_back(h);
    }
    if (heights.empty()) return;
    std::sort(heights.begin(), heights.end());
    const double low = heights.front(), high = heights.back();
    record.range_known = true;
    record.range_low = low;
    record.range_high = high;
    std::vector<double> bounds = {low};
    if (!record.cuts.empty()) {
        std::vector<double> cuts = record.cuts;
        std::sort(cuts.begin(), cuts.end());
        for (double cut : cuts) {
            if (cut < low || cut > high) record.cuts_outside.push_back(cut);
            else if (cut > bounds.back() && cut < high) bounds.push_back(cut);
        }
    } else {
        double count = record.layer_count > 0 ? record.layer_count
                                              : std::ceil((high - low) / record.layer_height);
        count = std::max(1.0, std::min(count, static_cast<double>(heights.size())));
        const size_t layers = static_cast<size_t>(count);
        for (size_t k = 1; k < layers; ++k)
            bounds.push_back(low + (high - low) * (static_cast<double>(k) / count));
    }
    bounds.push_back(high);
    for (size_t k = 0; k + 1 < bounds.size(); ++k) {
        const auto first = std::lower_bound(heights.begin(), heights.end(), bounds[k]);
        const auto stop = k + 2 == bounds.size()
                              ? heights.end()
                              : std::lower_bound(heights.begin(), heights.end(), bounds[k + 1]);
        if (stop - first < static_cast<std::ptrdiff_t>(stratmesh::kMinLayerPoints))
            ++record.sparse_planned_layers;
    }
}

// The files a run writes: opened before the input is read, so that a destination that
// cannot be created fails before any work, each completed as it is written, and published
// together at the end (commit_files, safe_output.h), or not at all.
struct Outputs {
    AtomicFile mesh, preview, report;

    bool open(const CommandLine& line) {
        const std::pair<AtomicFile*, const std::string*> named[] = {
            {&mesh, &line.output}, {&preview, &line.preview}, {&report, &line.report}};
        for (const auto& [file, path] : named) {
            std::string error;
            if (path->empty() || file->open(*path, error)) continue;
            std::fprintf(stderr, "stratmesh: %s\n", error.c_str());
            return false;
        }
        return true;
    }

    // Publishes the outputs written; false with the message printed.
    bool commit() {
        std::string error;
        if (commit_files({&mesh, &preview, &report}, error)) return true;
        std::fprintf(stderr, "stratmesh: %s\n", error.c_str());
        return false;
    }
};

// With --preview: the picture of the mesh.
bool write_preview(const CommandLine& line, const std::vector<double>& xyz,
                   const Reconstruction& result, const RunRecord& record, AtomicFile& file) {
    if (line.preview.empty()) return true;
    const MeshView mesh = {xyz.data(), xyz.size() / 3, result.triangles.get(),
                           result.triangle_count};
    std::string error;
    if (write_preview_svg(file, mesh, record.report.axis, record.layers, error)) return true;
    std::fprintf(stderr, "stratmesh: %s\n", error.c_str());
    return false;
}

bool write_report(const CommandLine& line, const RunRecord& record, AtomicFile& file) {
    if (line.report.empty()) return true;
    std::string error;
    if (write_text_file(file, run_record_json(record), error)) return true;
    std::fprintf(stderr, "stratmesh: %s\n", error.c_str());
    return false;
}

bool write_output(const CommandLine& line, const std::vector<double>& xyz,
                  const PointAttributes& attributes, const Reconstruction& result,
                  RunRecord& record, AtomicFile& file) {
    Clock::time_point start = Clock::now();
    MeshView mesh = {xyz.data(), xyz.size() / 3, result.triangles.get(), result.triangle_count,
                     &attributes};
    std::string error;
    if (!write_mesh_file(file, line.output_format, mesh, line.ascii, error)) {
        std::fprintf(stderr, "stratmesh: %s\n", error.c_str());
        return false;
    }
    record.write_seconds = seconds_since(start);
    record.output_written = true;
    return true;
}

// Writes the report of a run whose mesh is written, publishes the outputs, then prints the
// summary (not with --quiet) and the warnings (always; a poor verdict among them with
// --quiet). --strict fails exactly on a poor verdict.
int finish_run(const CommandLine& line, RunRecord& record, Outputs& outputs) {
    record.peak_rss_bytes = peak_resident_bytes();
    if (!write_report(line, record, outputs.report) || !outputs.commit()) return kExitFile;
    const Verdict verdict = judge_mesh(record);
    std::vector<std::string> warnings = run_warnings(record);
    if (!line.quiet) print_summary(stderr, record, verdict, warnings.size(), line.verbose);
    if (line.quiet && verdict.judged == Verdict::poor)
        warnings.push_back("mesh " + verdict_text(verdict, record));
    print_warnings(stderr, warnings);
    return line.strict && verdict.judged == Verdict::poor ? kExitPoor : kExitOk;
}

// Explains the refusal (with the tool's `advice`, if any) and writes the report alone.
int refuse(const CommandLine& line, RunRecord& record,
           const std::string& advice, Outputs& outputs) {
    const std::string faces = faces_warning(record);
    if (!faces.empty()) print_warnings(stderr, {faces});
    explain_refusal(line, record, advice);
    record.peak_rss_bytes = peak_resident_bytes();
    outputs.mesh.discard();
    outputs.preview.discard();
    if (write_report(line, record, outputs.report)) outputs.commit();
    // An origin the frame cannot use is the command line's fault, not the cloud's.
    return record.status == stratmesh::Status::invalid_origin ? kExitUsage : kExitRefused;
}

int run_streamed(const CommandLine& line, RunRecord& record, Outputs& outputs) {
    ProgressMonitor silent(false, stderr);
    ThreadJobs jobs;
    std::string error;
    StreamOutcome outcome =
        run_stream(line, make_options(line, silent, jobs), record, outputs.mesh, error);
    switch (outcome) {
    case StreamOutcome::done: return finish_run(line, record, outputs);
    case StreamOutcome::refused: return refuse(line, record, error, outputs);
    case StreamOutcome::file_error: break;
    case StreamOutcome::usage:
        std::fprintf(stderr, "stratmesh: %s\n", error.c_str());
        return kExitUsage;
    case StreamOutcome::unsorted:
        std::fprintf(stderr, "stratmesh: %s: %s\n", display_name(line.input).c_str(), error.c_str());
        return kExitUnsorted;
    }
    std::fprintf(stderr, "stratmesh: %s\n", error.c_str());
    return kExitFile;
}

int run(const CommandLine& line) {
    std::string clash;
    if (!check_distinct_files(named_files(line), clash)) {
        std::fprintf(stderr, "stratmesh: %s\n", clash.c_str());
        return kExitUsage;
    }
    Outputs outputs;
    if (!outputs.open(line)) return kExitFile;
    RunRecord record;
    record_command_line(line, record);
    if (line.stream) return run_streamed(line, record, outputs);
    std::vector<double> xyz;
    PointAttributes attributes;
    Reconstruction result;
    if (!read_input(line, xyz, attributes, record)) return kExitFile;
    if (line.find_branches && !find_branches(xyz, line, record)) return kExitRefused;
    if (!reconstruct_points(xyz, line, result, record)) return kExitRefused;
    if (record.status != stratmesh::Status::ok) return refuse(line, record, "", outputs);
    measure_along_axis(xyz, record);
    record.ends = find_surface_ends(xyz.data(), result.triangles.get(), result.triangle_count,
                                    record.report.axis, record.layers,
                                    record.report.layers.skeleton_node_count > 0,
                                    record.report.axis_origin);
    if (!write_output(line, xyz, attributes, result, record, outputs.mesh) ||
        !write_preview(line, xyz, result, record, outputs.preview))
        return kExitFile;
    return finish_run(line, record, outputs);
}

// What to do when the memory ran out outside the workspaces the tool sizes and checks.
const char* memory_advice(const CommandLine& line) {
    if (!line.stream)
        return "--stream reads and meshes a cloud sorted along its axis in bounded memory";
    if (line.cap)
        return "--cap keeps every point and triangle until the end: without it the stream "
               "holds only its layers";
    return "thinner layers (closer --cuts, a smaller --layer-height) or a lower "
           "--stream-points leave more room";
}

} // namespace

int main(int argc, char** argv) {
    install_output_signal_handlers();
    CommandLine line;
    std::string error;
    switch (parse_command_line(argc, argv, line, error)) {
    case CommandAction::help: std::fputs(usage_text(), stdout); return kExitOk;
    case CommandAction::version:
        std::printf("stratmesh %s\n", STRATMESH_VERSION_STRING);
        return kExitOk;
    case CommandAction::usage_error:
        std::fprintf(stderr, "stratmesh: %s\nTry 'stratmesh --help'.\n", error.c_str());
        return kExitUsage;
    case CommandAction::run: break;
    }
    try {
        return run(line);
    } catch (const std::bad_alloc&) {
        // Unwound: the outputs' temporaries are gone, every destination is as it was.
        std::fprintf(stderr, "stratmesh: out of memory, no file replaced: %s\n",
                     memory_advice(line));
        return kExitRefused;
    }
}
