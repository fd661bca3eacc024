// stratmesh_bench - times stratmesh's public entry points on fixed, reproducible inputs.
//
// Prints one JSON object per line per case on stdout; notes and errors go to stderr.
// Built with -DSTRATMESH_BENCH_WITH_CGAL it also times CGAL's 2D Delaunay triangulation
// on the same points in the same process, as a peer. stratmesh::reconstruct is timed on
// generated 3D clouds (bench_clouds.h) and on PLY files (bench_ply.h), each beside
// delaunay_2d on as many uniform 2D points, the cost it is measured against. Run with
// --help for the options.
//
// Adding a case: write a generator (a function that fills a coordinate array from a size
// and a seed) and add a row to kCases below. A new kind of measurement gets a Kind value,
// a measure_* function and a line in run_job(); the table, the selection and the output
// format stay as they are.

#include "stratmesh.h"

#include "bench_clouds.h"
#include "bench_json.h"
#include "bench_mesh.h"
#include "bench_ply.h"
#include "bench_random.h"
#include "thread_jobs.h"  // the tool's std::thread job runner (examples/cli)

#include <algorithm>
#include <array>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>  // mallopt, malloc_trim: see keep_heap_warm()
#endif

#ifdef STRATMESH_BENCH_WITH_CGAL
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/version.h>
#endif

namespace {

using bench::Random;

// ==== Generators ===========================================================================
//
// Each fills `coords` with the case's points, x0 y0 x1 y1 ... for 2D cases, x0 y0 z0 x1 ...
// for 3D cases (those are in bench_clouds.h). `n` is the table's size; a generator whose
// shape fixes the count documents how it reads n.

// n points uniformly distributed in the unit square.
void generate_uniform(size_t n, uint64_t seed, std::vector<double>& coords) {
    Random random(seed);
    coords.resize(2 * n);
    for (size_t i = 0; i < 2 * n; ++i) coords[i] = random.uniform();
}

// A square grid of side sqrt(n) with spacing 1e-3, row by row. x depends on the column
// only and y on the row only, so every cell is an exact rectangle: its four corners are
// exactly cocircular, the degenerate case for a Delaunay triangulation.
void generate_grid(size_t n, uint64_t, std::vector<double>& coords) {
    size_t side = static_cast<size_t>(std::llround(std::sqrt(static_cast<double>(n))));
    coords.resize(2 * side * side);
    size_t k = 0;
    for (size_t row = 0; row < side; ++row) {
        for (size_t column = 0; column < side; ++column) {
            coords[k++] = static_cast<double>(column) * 1e-3;
            coords[k++] = static_cast<double>(row) * 1e-3;
        }
    }
}

// sqrt(n) concentric rings around the origin, ring i of radius 1 + i * 1e-3, each with
// sqrt(n) points at equal angular steps (the same angles on every ring). Every ring is
// cocircular up to rounding, and the points at one angle are collinear with the centre
// up to rounding: nearly every predicate on this input is close to zero.
void generate_rings(size_t n, uint64_t, std::vector<double>& coords) {
    const double two_pi = 6.283185307179586476925286766559;
    size_t side = static_cast<size_t>(std::llround(std::sqrt(static_cast<double>(n))));
    coords.resize(2 * side * side);
    size_t k = 0;
    for (size_t ring = 0; ring < side; ++ring) {
        double radius = 1.0 + static_cast<double>(ring) * 1e-3;
        for (size_t step = 0; step < side; ++step) {
            double angle = two_pi * static_cast<double>(step) / static_cast<double>(side);
            coords[k++] = radius * std::cos(angle);
            coords[k++] = radius * std::sin(angle);
        }
    }
}

// n points in 100 Gaussian blobs: centres uniform in [0.1, 0.9]^2, standard deviations
// uniform in [0.001, 0.03], each point in a blob chosen uniformly. Densities differ by
// about three orders of magnitude between the tightest and the widest blobs.
void generate_clustered(size_t n, uint64_t seed, std::vector<double>& coords) {
    const size_t blob_count = 100;
    Random random(seed);
    std::vector<double> centre(2 * blob_count), sigma(blob_count);
    for (size_t b = 0; b < blob_count; ++b) {
        centre[2 * b] = random.uniform(0.1, 0.9);
        centre[2 * b + 1] = random.uniform(0.1, 0.9);
        sigma[b] = random.uniform(0.001, 0.03);
    }
    coords.resize(2 * n);
    for (size_t i = 0; i < n; ++i) {
        size_t b = random.below(blob_count);
        double dx = 0.0, dy = 0.0;
        random.normal_pair(dx, dy);
        coords[2 * i] = centre[2 * b] + sigma[b] * dx;
        coords[2 * i + 1] = centre[2 * b + 1] + sigma[b] * dy;
    }
}

// ==== The case table =======================================================================

enum class Kind {
    delaunay_2d,  // stratmesh::delaunay_2d on 2D points (peer: CGAL Delaunay_triangulation_2)
    reconstruct,  // stratmesh::reconstruct on a 3D cloud, beside delaunay_2d on as many
                  // uniform 2D points (its reference cost)
    layered,      // the same, plus one line per layer of the result (the paper's cases)
    threads,      // reconstruct without a job runner against a 2-thread runner, and
                  // two independent serial calls at once (the machine's ceiling)
    stream,       // the stream, pushed layer by layer, against reconstruct on the same layers
};

// How a 3D case is cut into layers (see stratmesh::Options); unused by 2D cases.
struct Layering {
    stratmesh::Axis axis;
    uint32_t layer_count;  // 0 and no cuts: the library's automatic layers
    const double* cuts;    // coordinates along the axis
    size_t cut_count;
    uint32_t flags = 0;    // stratmesh::Options::flags
    stratmesh::Parts parts = stratmesh::Parts::automatic;
};

constexpr Layering kNoLayering = {stratmesh::Axis::automatic, 0, nullptr, 0};

// Eight equal layers along z; one layer; automatic layers.
constexpr Layering kTubeLayers = {stratmesh::Axis::z, 8, nullptr, 0};
constexpr Layering kTubeLayersFlipped = {stratmesh::Axis::z, 8, nullptr, 0, stratmesh::surface_flips};
constexpr Layering kOneLayerAlongZ = {stratmesh::Axis::z, 1, nullptr, 0};
constexpr Layering kAutomaticAlongZ = {stratmesh::Axis::z, 0, nullptr, 0};
// The library's defaults (Options all zero), and the same without the search for branches
// or with the flips on the surface: what each costs on top.
constexpr Layering kDefaults = {stratmesh::Axis::automatic, 0, nullptr, 0};
constexpr Layering kDefaultsOneTube = {stratmesh::Axis::automatic, 0, nullptr, 0, 0,
                                       stratmesh::Parts::one_tube};
constexpr Layering kDefaultsFlipped = {stratmesh::Axis::automatic, 0, nullptr, 0, stratmesh::surface_flips};
// A hundred equal layers along z (the stream case cuts them itself, between the extremes).
constexpr Layering kHundredLayers = {stratmesh::Axis::z, 100, nullptr, 0};

// The paper's cuts along z (section 2).
template <size_t N> constexpr Layering cuts_along_z(const double (&cuts)[N]) {
    return Layering{stratmesh::Axis::z, 0, cuts, N};
}

struct CaseSpec {
    const char* name;    // unique; what --case selects and what the output calls it
    const char* family;  // --case FAMILY selects every case of the family
    Kind kind;
    size_t n;            // size handed to the generator
    uint64_t seed;       // handed to the generator (ignored by regular shapes)
    int default_runs;    // timed repetitions; the median is reported
    void (*generate)(size_t n, uint64_t seed, std::vector<double>& coords);
    Layering layering;   // 3D cases
};

const CaseSpec kCases[] = {
    {"uniform-1e5", "uniform", Kind::delaunay_2d, 100000, 0x5EED0001u, 5, generate_uniform,
     kNoLayering},
    {"uniform-1e6", "uniform", Kind::delaunay_2d, 1000000, 0x5EED0002u, 5, generate_uniform,
     kNoLayering},
    {"uniform-4e6", "uniform", Kind::delaunay_2d, 4000000, 0x5EED0003u, 3, generate_uniform,
     kNoLayering},
    {"grid", "grid", Kind::delaunay_2d, 1000 * 1000, 0, 5, generate_grid, kNoLayering},
    {"rings", "rings", Kind::delaunay_2d, 1000 * 1000, 0, 5, generate_rings, kNoLayering},
    {"clustered", "clustered", Kind::delaunay_2d, 1000000, 0x5EED0004u, 5, generate_clustered,
     kNoLayering},
    {"tube-1e5", "tube", Kind::reconstruct, 100000, 0x5EED0101u, 5, bench::generate_tube,
     kTubeLayers},
    {"tube-1e6", "tube", Kind::reconstruct, 1000000, 0x5EED0102u, 5, bench::generate_tube,
     kTubeLayers},
    {"tube-4e6", "tube", Kind::reconstruct, 4000000, 0x5EED0103u, 3, bench::generate_tube,
     kTubeLayers},
    // The cloud of tube-1e6 (same seed) with the surface_flips flag.
    {"tube-1e6-flips", "tube", Kind::reconstruct, 1000000, 0x5EED0102u, 5,
     bench::generate_tube, kTubeLayersFlipped},
    // The cloud of tube-1e6 (same seed) in a single layer.
    {"tube-1e6-1layer", "tube", Kind::reconstruct, 1000000, 0x5EED0102u, 5,
     bench::generate_tube, kOneLayerAlongZ},
    // The cloud of tube-1e6 (same seed) with the library's default options; without the
    // search for branches; with the flips on the surface.
    {"default-1e5", "default", Kind::reconstruct, 100000, 0x5EED0101u, 5, bench::generate_tube,
     kDefaults},
    {"default-1e6", "default", Kind::reconstruct, 1000000, 0x5EED0102u, 5, bench::generate_tube,
     kDefaults},
    {"default-1e6-one-tube", "default", Kind::reconstruct, 1000000, 0x5EED0102u, 5,
     bench::generate_tube, kDefaultsOneTube},
    {"default-1e6-flips", "default", Kind::reconstruct, 1000000, 0x5EED0102u, 5,
     bench::generate_tube, kDefaultsFlipped},
    {"threads-default-1e6", "threads", Kind::threads, 1000000, 0x5EED0102u, 3,
     bench::generate_tube, kDefaults},
    // The clouds of tube-1e6 and tube-4e6 (same seeds): no runner against two threads.
    {"threads-tube-1e6", "threads", Kind::threads, 1000000, 0x5EED0102u, 3,
     bench::generate_tube, kTubeLayers},
    {"threads-tube-4e6", "threads", Kind::threads, 4000000, 0x5EED0103u, 3,
     bench::generate_tube, kTubeLayers},
    // The cloud of tube-4e6 streamed in 100 layers, against reconstruct on the same layers.
    {"stream-tube-4e6", "stream", Kind::stream, 4000000, 0x5EED0103u, 3, bench::generate_tube,
     kHundredLayers},
    // Automatic layers against one layer and against cuts chosen by hand.
    {"layering-head-auto", "layering", Kind::reconstruct, bench::kHeadPoints, 0x5EED0201u, 5,
     bench::generate_paper_head, kAutomaticAlongZ},
    {"layering-head-1layer", "layering", Kind::reconstruct, bench::kHeadPoints, 0x5EED0201u, 5,
     bench::generate_paper_head, kOneLayerAlongZ},
    {"layering-head-cuts", "layering", Kind::reconstruct, bench::kHeadPoints, 0x5EED0201u, 5,
     bench::generate_paper_head, cuts_along_z(bench::kHeadCuts)},
    {"layering-vase-auto", "layering", Kind::reconstruct, 20000, 0x5EED0301u, 5,
     bench::generate_vase, kAutomaticAlongZ},
    {"layering-vase-1layer", "layering", Kind::reconstruct, 20000, 0x5EED0301u, 5,
     bench::generate_vase, kOneLayerAlongZ},
    {"layering-vase-cuts", "layering", Kind::reconstruct, 20000, 0x5EED0301u, 5,
     bench::generate_vase, cuts_along_z(bench::kVaseCuts)},
    {"layering-bent-auto", "layering", Kind::reconstruct, 20000, 0x5EED0302u, 5,
     bench::generate_bent_tube, kAutomaticAlongZ},
    {"layering-bent-1layer", "layering", Kind::reconstruct, 20000, 0x5EED0302u, 5,
     bench::generate_bent_tube, kOneLayerAlongZ},
    {"layering-bent-cuts", "layering", Kind::reconstruct, 20000, 0x5EED0302u, 5,
     bench::generate_bent_tube, cuts_along_z(bench::kBentTubeCuts)},
    {"paper-head", "paper", Kind::layered, bench::kHeadPoints, 0x5EED0201u, 11,
     bench::generate_paper_head, cuts_along_z(bench::kHeadCuts)},
    {"paper-ventricle", "paper", Kind::layered, bench::kVentriclePoints, 0x5EED0202u, 11,
     bench::generate_paper_ventricle, cuts_along_z(bench::kVentricleCuts)},
    {"paper-skull", "paper", Kind::layered, bench::kSkullPoints, 0x5EED0203u, 11,
     bench::generate_paper_skull, cuts_along_z(bench::kSkullCuts)},
};

// Growth lines: the time ratio between two cases of one shape, against n log n.
struct Growth {
    const char* from;
    const char* to;
};

const Growth kGrowths[] = {{"tube-1e6", "tube-4e6"}};

// Where a job's points come from.
enum class Input { table, xy_file, ply_file };

// One thing to measure: a table row, or a user's file.
struct Job {
    std::string name;
    Kind kind;
    int runs;
    const CaseSpec* spec;  // null for a file
    std::string path;      // the file, when spec is null
    Input input;
    Layering layering;     // 3D jobs
};

// What a job measured, for the exit status and the growth lines.
enum class Outcome { ok, failed, bad_input };

struct Result {
    Outcome outcome;
    size_t n;
    double seconds;           // median
    double delaunay_seconds;  // median of the reference delaunay_2d (3D jobs)
    double min_seconds;       // fastest run (3D jobs; NaN for the others)
    double delaunay_min_seconds;
};

// ==== Timing ===============================================================================

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    size_t m = values.size() / 2;
    if (values.size() % 2 == 1) return values[m];
    return 0.5 * (values[m - 1] + values[m]);
}

// Allocates a buffer and writes every byte once, so that page faults happen now and not
// inside a timed call.
std::unique_ptr<unsigned char[]> allocate_touched(size_t bytes) {
    std::unique_ptr<unsigned char[]> buffer(new unsigned char[bytes == 0 ? 1 : bytes]);
    std::memset(buffer.get(), 0xA5, bytes == 0 ? 1 : bytes);
    return buffer;
}

// stratmesh's workspace is allocated and touched before its clock starts, so its timings
// contain no page faults. CGAL allocates inside the call; to hold it to the same rule its
// memory must come back warm on the next run. glibc would instead hand big blocks back to
// the kernel (mmap for large allocations, trimming of the heap top) and fault them in
// again on every run, a third or more of CGAL's time on uniform points. So: no mmap, no
// trimming. Other C libraries keep their default behaviour.
void keep_heap_warm() {
#if defined(__GLIBC__)
    mallopt(M_MMAP_MAX, 0);
    mallopt(M_TRIM_THRESHOLD, INT_MAX);
#endif
}

// ==== Output ===============================================================================

// Builds one JSON object on one line.
class JsonLine {
public:
    void add(const char* key, const std::string& value) {
        start(key);
        text_ += bench::json_quoted(value);
    }
    void add(const char* key, const char* value) { add(key, std::string(value)); }
    void add(const char* key, size_t value) {
        start(key);
        text_ += std::to_string(value);
    }
    void add(const char* key, int value) {
        start(key);
        text_ += std::to_string(value);
    }
    void add(const char* key, bool value) {
        start(key);
        text_ += value ? "true" : "false";
    }
    void add(const char* key, double value) {
        start(key);
        if (!std::isfinite(value)) {
            text_ += "null";  // JSON has no NaN or infinity
            return;
        }
        char number[32];
        std::snprintf(number, sizeof number, "%.6g", value);
        text_ += number;
    }
    // Adds the other line's fields after this one's.
    void append(const JsonLine& other) {
        if (other.text_.empty()) return;
        if (!text_.empty()) text_ += ", ";
        text_ += other.text_;
    }
    void print() const {
        std::printf("{%s}\n", text_.c_str());
        std::fflush(stdout);
    }

private:
    void start(const char* key) {
        if (!text_.empty()) text_ += ", ";
        text_ += '"';
        text_ += key;
        text_ += "\": ";
    }
    std::string text_;
};

// "ok" from "ok: success".
std::string status_name(stratmesh::Status status) {
    std::string text = stratmesh::status_string(status);
    size_t colon = text.find(':');
    return colon == std::string::npos ? text : text.substr(0, colon);
}

// ==== The CGAL peer ========================================================================

#ifdef STRATMESH_BENCH_WITH_CGAL

// Gives the heap's free memory back to the kernel, so that the next allocations fault
// their pages in again, as in a fresh process (glibc only; elsewhere nothing happens).
void release_free_heap() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

using CgalKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalDelaunay = CGAL::Delaunay_triangulation_2<CgalKernel>;

struct CgalResult {
    double seconds;       // median of the timed runs
    double min_seconds;   // fastest timed run
    double cold_seconds;  // the untimed warm-up run, on a heap emptied first
    size_t faces;     // finite faces
    size_t vertices;  // finite vertices (duplicates merged)
};

// Times construction plus insert(begin, end), which spatially sorts the points first (its
// fastest path). The points are converted to CGAL's type beforehand and the triangulation
// is destroyed after the clock stops. CGAL's memory allocation is inside the timing,
// because that is how it builds a triangulation; its page faults are not, as they are not
// for stratmesh: an untimed first run warms the heap (see keep_heap_warm). That run starts
// from an emptied heap, so its time, reported as cold_seconds, includes the faults.
CgalResult measure_cgal_2d(const std::vector<double>& xy, int runs) {
    size_t n = xy.size() / 2;
    std::vector<CgalKernel::Point_2> points;
    points.reserve(n);
    for (size_t i = 0; i < n; ++i) points.emplace_back(xy[2 * i], xy[2 * i + 1]);

    CgalResult result = {0.0, 0.0, 0.0, 0, 0};
    std::vector<double> times;
    release_free_heap();
    for (int run = -1; run < runs; ++run) {
        Clock::time_point start = Clock::now();
        std::unique_ptr<CgalDelaunay> dt(new CgalDelaunay());
        dt->insert(points.begin(), points.end());
        Clock::time_point stop = Clock::now();
        if (run < 0)
            result.cold_seconds = seconds_between(start, stop);
        else
            times.push_back(seconds_between(start, stop));
        result.faces = dt->number_of_faces();
        result.vertices = dt->number_of_vertices();
    }
    result.seconds = median(times);
    result.min_seconds = *std::min_element(times.begin(), times.end());
    return result;
}

#endif

// ==== Measurements =========================================================================

struct Options {
    bool cgal = true;          // time the peer when it is compiled in
    bool layer_lines = false;  // one line per layer for every reconstruction, not only
                               // the layered cases
};

// Times stratmesh::delaunay_2d on interleaved x, y and prints the case's line. Returns
// false if the call failed or disagreed with the peer.
bool measure_delaunay_2d(const std::string& name, const std::vector<double>& xy, int runs,
                         const Options& options) {
    size_t n = xy.size() / 2;
    size_t workspace_bytes = stratmesh::delaunay_2d_workspace_size(n);
    size_t max_triangles = stratmesh::delaunay_2d_max_triangles(n);
    size_t triangle_bytes = 3 * sizeof(uint32_t) * max_triangles;
    std::unique_ptr<unsigned char[]> workspace = allocate_touched(workspace_bytes);
    std::unique_ptr<uint32_t[]> triangles(new uint32_t[3 * max_triangles + 1]);
    std::memset(triangles.get(), 0xA5, triangle_bytes + sizeof(uint32_t));

    stratmesh::Status status = stratmesh::Status::ok;
    stratmesh::Delaunay2dInfo info = {};
    std::vector<double> times;
    for (int run = 0; run < runs; ++run) {
        Clock::time_point start = Clock::now();
        stratmesh::Status s = stratmesh::delaunay_2d(xy.data(), n, 2 * sizeof(double),
                                                     workspace.get(), workspace_bytes,
                                                     triangles.get(), max_triangles, &info,
                                                     nullptr);
        Clock::time_point stop = Clock::now();
        times.push_back(seconds_between(start, stop));
        if (s != stratmesh::Status::ok) status = s;
    }
    double seconds = median(times);
    double per_point = n > 0 ? 1.0 / static_cast<double>(n) : 0.0;
    bool ok = status == stratmesh::Status::ok;

    JsonLine line;
    line.add("name", name);
    line.add("n", n);
    line.add("runs", runs);
    line.add("seconds", seconds);
    line.add("min_seconds", *std::min_element(times.begin(), times.end()));
    line.add("mpts_per_s", static_cast<double>(n) / seconds * 1e-6);
    line.add("workspace_bytes_per_point", static_cast<double>(workspace_bytes) * per_point);
    line.add("total_bytes_per_point",
             static_cast<double>(workspace_bytes + triangle_bytes) * per_point);
    line.add("status", status_name(status));
    line.add("triangles", info.triangle_count);
    line.add("hull_vertices", info.hull_vertex_count);
    line.add("duplicates", info.duplicate_count);

#ifdef STRATMESH_BENCH_WITH_CGAL
    // Points CGAL cannot take (NaN, infinity) or calls refused before any work are not
    // handed to it; every other outcome, failures included, is compared.
    bool peer = options.cgal && status != stratmesh::Status::invalid_point &&
                status != stratmesh::Status::invalid_argument &&
                status != stratmesh::Status::too_many_points;
    if (peer) {
        CgalResult cgal = measure_cgal_2d(xy, runs);
        // Equal counts of triangles and of distinct vertices. A stratmesh failure counts
        // as zero triangles, which only agrees when CGAL made no face either.
        size_t triangles_made = ok ? info.triangle_count : 0;
        size_t vertices_made = n - info.duplicate_count;
        bool agree = triangles_made == cgal.faces &&
                     (!ok || vertices_made == cgal.vertices);
        line.add("cgal_seconds", cgal.seconds);
        line.add("cgal_min_seconds", cgal.min_seconds);
        line.add("cgal_faces", cgal.faces);
        line.add("ratio", cgal.seconds / seconds);
        line.add("cgal_cold_seconds", cgal.cold_seconds);
        line.add("agree", agree);
        ok = ok && agree;
    }
#else
    (void)options;
#endif
    line.print();
    return ok;
}

// ==== Reconstruction =======================================================================
//
// stratmesh::reconstruct is timed beside delaunay_2d on as many uniform 2D points, call for
// call, alternately, so that both see the same machine load and the same cache state.
// Their ratio is what the layers, the unrolling, the stitching and the safety net cost on
// top of one plain triangulation of the same size.

const size_t kPhaseCount = static_cast<size_t>(stratmesh::Phase::done) + 1;
const char* const kPhaseKeys[kPhaseCount] = {
    "validate_seconds", "layers_seconds",   "triangulate_seconds",
    "stitch_seconds",   "manifold_seconds", "done_seconds"};

// When each phase was first announced during one call.
struct PhaseClock {
    Clock::time_point start[kPhaseCount];
    bool seen[kPhaseCount];
};

// Options::progress: notes when a phase starts; the later calls of a phase (its progress
// fractions) change nothing.
void note_phase(void* user, stratmesh::Phase phase, double) {
    PhaseClock* clock = static_cast<PhaseClock*>(user);
    size_t p = static_cast<size_t>(phase);
    if (p >= kPhaseCount || clock->seen[p]) return;
    clock->seen[p] = true;
    clock->start[p] = Clock::now();
}

// Each phase's duration in one call: from its start to the next phase's start, or to the
// call's end for the last one. NaN for a phase that never started (a failed call).
void phase_durations(const PhaseClock& clock, Clock::time_point stop, double* seconds) {
    for (size_t p = 0; p < kPhaseCount; ++p) {
        seconds[p] = std::nan("");
        if (!clock.seen[p]) continue;
        Clock::time_point end = stop;
        for (size_t q = p + 1; q < kPhaseCount; ++q) {
            if (clock.seen[q]) {
                end = clock.start[q];
                break;
            }
        }
        seconds[p] = seconds_between(clock.start[p], end);
    }
}

// The median of the values that are not NaN; NaN if there are none.
double median_of_numbers(const std::vector<double>& values) {
    std::vector<double> numbers;
    for (double v : values)
        if (!std::isnan(v)) numbers.push_back(v);
    return numbers.empty() ? std::nan("") : median(numbers);
}

// delaunay_2d on n uniform points in the unit square, its buffers allocated and touched
// up front, like every timed call's.
class DelaunayReference {
public:
    DelaunayReference(size_t n, uint64_t seed)
        : n_(n),
          workspace_bytes_(stratmesh::delaunay_2d_workspace_size(n)),
          max_triangles_(stratmesh::delaunay_2d_max_triangles(n)),
          workspace_(allocate_touched(workspace_bytes_)),
          triangles_(new uint32_t[3 * max_triangles_ + 1]) {
        generate_uniform(n, seed, xy_);
        std::memset(triangles_.get(), 0xA5, sizeof(uint32_t) * (3 * max_triangles_ + 1));
    }

    // One timed call; returns its seconds.
    double run() {
        stratmesh::Delaunay2dInfo info = {};
        Clock::time_point start = Clock::now();
        stratmesh::Status s = stratmesh::delaunay_2d(xy_.data(), n_, 2 * sizeof(double),
                                                     workspace_.get(), workspace_bytes_,
                                                     triangles_.get(), max_triangles_, &info,
                                                     nullptr);
        Clock::time_point stop = Clock::now();
        if (s != stratmesh::Status::ok) status_ = s;
        return seconds_between(start, stop);
    }

    stratmesh::Status status() const { return status_; }

private:
    size_t n_;
    size_t workspace_bytes_;
    size_t max_triangles_;
    std::unique_ptr<unsigned char[]> workspace_;
    std::unique_ptr<uint32_t[]> triangles_;
    std::vector<double> xy_;
    stratmesh::Status status_ = stratmesh::Status::ok;
};

// One reconstruction to time.
struct ReconstructCase {
    std::string name;
    stratmesh::Cloud cloud;
    Layering layering;
    int runs;
    bool layer_lines;         // print one line per layer before the summary line
    uint64_t reference_seed;  // the reference's uniform 2D points
    JsonLine extra;           // fields appended to the summary line
};

stratmesh::Options reconstruct_options(const Layering& layering, PhaseClock* clock) {
    stratmesh::Options options = {};
    options.axis = layering.axis;
    options.cuts = layering.cuts;
    options.cut_count = layering.cut_count;
    options.layer_count = layering.layer_count;
    options.flags = layering.flags;
    options.parts = layering.parts;
    options.progress = note_phase;
    options.progress_user = clock;
    return options;
}

// Room for every layer the options can produce; automatic layering is capped (the
// summary's `layers` still counts them all).
size_t layer_capacity(const Layering& layering, size_t n) {
    if (layering.cuts && layering.cut_count > 0) return layering.cut_count + 1;
    if (layering.layer_count > 0) return layering.layer_count;
    return std::max<size_t>(1, std::min<size_t>(n, 4096));
}

// The extent of the cloud's finite points along a unit axis, as dot(point, axis).
void extent_along(const stratmesh::Cloud& cloud, const double axis[3], double& lo,
                  double& hi) {
    lo = HUGE_VAL;
    hi = -HUGE_VAL;
    for (size_t i = 0; i < cloud.count; ++i) {
        double p[3];
        bench::cloud_point(cloud, i, p);
        double h = p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
        if (!std::isfinite(h)) continue;
        lo = std::min(lo, h);
        hi = std::max(hi, h);
    }
}

std::string axis_text(const double axis[3]) {
    char text[96];
    std::snprintf(text, sizeof text, "%.4g %.4g %.4g", axis[0], axis[1], axis[2]);
    return text;
}

void print_layer_lines(const std::string& name, const stratmesh::Report& report) {
    size_t shown = std::min(report.layers.used_count, report.layers.info_capacity);
    for (size_t i = 0; i < shown; ++i) {
        const stratmesh::LayerInfo& layer = report.layers.info[i];
        JsonLine line;
        line.add("name", name);
        line.add("layer", i + 1);
        line.add("bottom", layer.bottom);
        line.add("top", layer.top);
        line.add("point_count", static_cast<size_t>(layer.point_count));
        line.add("triangle_count", static_cast<size_t>(layer.triangle_count));
        line.add("fold_count", static_cast<size_t>(layer.fold_count));
        line.add("radius", layer.radius);
        line.print();
    }
    if (shown < report.layers.used_count)
        std::fprintf(stderr, "stratmesh_bench: %s: %zu layers, the first %zu shown\n",
                     name.c_str(), report.layers.used_count, shown);
}

// Times stratmesh::reconstruct and the reference delaunay_2d, alternately, and prints the
// layer lines (if asked) and the summary line.
Result measure_reconstruct(const ReconstructCase& job) {
    const stratmesh::Cloud& cloud = job.cloud;
    const size_t n = cloud.count;
    PhaseClock clock = PhaseClock();
    const stratmesh::Options options = reconstruct_options(job.layering, &clock);
    size_t workspace_bytes = stratmesh::reconstruct_workspace_size(n, options);
    size_t max_triangles = stratmesh::reconstruct_max_triangles(n, options);
    size_t triangle_bytes = 3 * sizeof(uint32_t) * max_triangles;
    std::unique_ptr<unsigned char[]> workspace = allocate_touched(workspace_bytes);
    std::unique_ptr<uint32_t[]> triangles(new uint32_t[3 * max_triangles + 1]);
    std::memset(triangles.get(), 0xA5, triangle_bytes + sizeof(uint32_t));
    std::vector<stratmesh::LayerInfo> layers(layer_capacity(job.layering, n));
    DelaunayReference reference(n, job.reference_seed);

    stratmesh::Status status = stratmesh::Status::ok;
    stratmesh::Report report = stratmesh::Report();
    size_t triangle_count = 0;
    std::vector<double> times, reference_times, phase_times[kPhaseCount];
    for (int run = 0; run < job.runs; ++run) {
        clock = PhaseClock();
        report = stratmesh::Report();
        report.layers.info = layers.data();
        report.layers.info_capacity = layers.size();
        Clock::time_point start = Clock::now();
        stratmesh::Status s = stratmesh::reconstruct(cloud, options, workspace.get(),
                                                     workspace_bytes, triangles.get(),
                                                     max_triangles, &triangle_count, &report);
        Clock::time_point stop = Clock::now();
        times.push_back(seconds_between(start, stop));
        double phases[kPhaseCount];
        phase_durations(clock, stop, phases);
        for (size_t p = 0; p < kPhaseCount; ++p) phase_times[p].push_back(phases[p]);
        if (s != stratmesh::Status::ok) status = s;
        reference_times.push_back(reference.run());
    }

    double min_seconds = *std::min_element(times.begin(), times.end());
    double reference_min = *std::min_element(reference_times.begin(), reference_times.end());
    Result result = {Outcome::ok, n, median(times), median(reference_times), min_seconds,
                     reference_min};
    double per_point = n > 0 ? 1.0 / static_cast<double>(n) : 0.0;
    if (status != stratmesh::Status::ok || reference.status() != stratmesh::Status::ok)
        result.outcome = Outcome::failed;

    if (job.layer_lines) print_layer_lines(job.name, report);
    JsonLine line;
    line.add("name", job.name);
    line.add("n", n);
    line.add("runs", job.runs);
    line.add("seconds", result.seconds);
    line.add("min_seconds", min_seconds);
    line.add("mpts_per_s", static_cast<double>(n) / result.seconds * 1e-6);
    line.add("workspace_bytes_per_point", static_cast<double>(workspace_bytes) * per_point);
    line.add("total_bytes_per_point",
             static_cast<double>(workspace_bytes + triangle_bytes) * per_point);
    line.add("status", status_name(status));
    line.add("triangles", triangle_count);
    line.add("layers", report.layers.used_count);
    line.add("folds", report.diagnostics.fold_count);
    line.add("illegal_removed", report.diagnostics.illegal_removed_count);
    line.add("unused", report.points.unused_count);
    line.add("points_used", report.points.used_count);
    line.add("duplicates", report.points.duplicate_count);
    line.add("rejected", report.points.rejected_count);
    line.add("delaunay_seconds", result.delaunay_seconds);
    line.add("delaunay_min_seconds", reference_min);
    line.add("ratio_to_delaunay", result.seconds / result.delaunay_seconds);
    line.add("min_ratio_to_delaunay", min_seconds / reference_min);
    if (reference.status() != stratmesh::Status::ok)
        line.add("delaunay_status", status_name(reference.status()));
    for (size_t p = 0; p < kPhaseCount; ++p)
        line.add(kPhaseKeys[p], median_of_numbers(phase_times[p]));
    double lo = 0, hi = 0;
    extent_along(cloud, report.axis, lo, hi);
    line.add("axis", axis_text(report.axis));
    line.add("height_min", lo);
    line.add("height_max", hi);
    if (report.detail) line.add("detail", report.detail);
    if (status == stratmesh::Status::ok) {
        bench::Boundary boundary = bench::find_boundary(triangles.get(), triangle_count, cloud,
                                                        report.axis, report.axis_origin);
        line.add("boundary_edges", boundary.edges);
        line.add("boundary_loops", boundary.loops);
        line.add("nonmanifold_edges", boundary.nonmanifold_edges);
        line.add("top_loop_vertices", boundary.top_loop_vertices);
        line.add("top_loop_height_min", boundary.top_loop_height_min);
        line.add("top_loop_height_max", boundary.top_loop_height_max);
        line.add("top_loop_radius", boundary.top_loop_radius);
        bench::AngleStats angles = bench::smallest_angles(triangles.get(), triangle_count, cloud);
        line.add("min_angle_p05", angles.p05);
        line.add("min_angle_median", angles.median);
        line.add("frac_min_angle_lt10", angles.below_10);
    }
    line.append(job.extra);
    line.print();
    return result;
}

// ==== Threads and stream ===================================================================

// The triangles of one reconstruct() call, and what it reported.
struct Reconstructed {
    stratmesh::Status status = stratmesh::Status::ok;
    stratmesh::Report report = stratmesh::Report();
    std::vector<uint32_t> triangles;  // 3 per triangle
    Clock::time_point start, stop;    // around the call only, not the triangle array's setup
    double seconds = 0;
};

// Runs reconstruct() once into `out` with a workspace of at least the options' bound.
void run_reconstruct(const stratmesh::Cloud& cloud, const stratmesh::Options& options,
                     unsigned char* workspace, size_t workspace_bytes, Reconstructed& out) {
    size_t max_triangles = stratmesh::reconstruct_max_triangles(cloud.count, options);
    out.triangles.resize(3 * max_triangles);
    out.report = stratmesh::Report();
    size_t count = 0;
    out.start = Clock::now();
    out.status = stratmesh::reconstruct(cloud, options, workspace, workspace_bytes,
                                        out.triangles.data(), max_triangles, &count, &out.report);
    out.stop = Clock::now();
    out.seconds = seconds_between(out.start, out.stop);
    out.triangles.resize(3 * count);
}

// Runs the steps one after the other, in order, `runs` times each, so all see the same
// load; each returns its time. The result holds each step's times, in the steps' order.
template <class... Steps>
std::array<std::vector<double>, sizeof...(Steps)> alternate(int runs, Steps... steps) {
    std::array<std::vector<double>, sizeof...(Steps)> times;
    for (int run = 0; run < runs; ++run) {
        size_t k = 0;
        (times[k++].push_back(steps()), ...);  // a comma fold runs left to right
    }
    return times;
}

// The fields every case line starts with.
JsonLine case_line(const std::string& name, size_t n, int runs) {
    JsonLine line;
    line.add("name", name);
    line.add("n", n);
    line.add("runs", runs);
    return line;
}

// Times reconstruct() with no job runner and with a 2-thread runner on one workspace
// (sized for the runner, the larger bound), and compares their triangles. Alternating with
// them, it times two serial calls at once, on the calling thread and one std::thread, each
// with its own workspace and triangles: the throughput two cores give on two independent
// copies of the same work. That is the ceiling for the runner's speedup on this machine,
// below 2 where the work is bound by memory bandwidth rather than arithmetic.
Result measure_threads(const std::string& name, const stratmesh::Cloud& cloud,
                       const Layering& layering, int runs) {
    stratmesh::Options serial = reconstruct_options(layering, nullptr);
    serial.progress = nullptr;
    stratmesh::Options threaded = serial;
    stratmesh_cli::ThreadJobs jobs;
    jobs.threads = 2;
    jobs.attach(threaded);
    size_t workspace_bytes = stratmesh::reconstruct_workspace_size(cloud.count, threaded);
    size_t serial_bytes = stratmesh::reconstruct_workspace_size(cloud.count, serial);
    std::unique_ptr<unsigned char[]> workspace = allocate_touched(workspace_bytes);
    // The pair's second call gets this one; the first reuses `workspace`, as the serial
    // call does, so only one more serial workspace is held.
    std::unique_ptr<unsigned char[]> other_workspace = allocate_touched(serial_bytes);
    Reconstructed one, two, pair[2];
    auto [one_times, two_times, pair_times] = alternate(
        runs,
        [&] {
            run_reconstruct(cloud, serial, workspace.get(), workspace_bytes, one);
            return one.seconds;
        },
        [&] {
            run_reconstruct(cloud, threaded, workspace.get(), workspace_bytes, two);
            return two.seconds;
        },
        [&] {
            std::thread other([&] {
                run_reconstruct(cloud, serial, other_workspace.get(), serial_bytes, pair[1]);
            });
            run_reconstruct(cloud, serial, workspace.get(), workspace_bytes, pair[0]);
            other.join();
            // From the first call's start to the last one's end; each triangle array's
            // setup is outside its own call's clock.
            return seconds_between(std::min(pair[0].start, pair[1].start),
                                   std::max(pair[0].stop, pair[1].stop));
        });
    stratmesh::Status pair_status =
        pair[0].status != stratmesh::Status::ok ? pair[0].status : pair[1].status;
    bool ok = one.status == stratmesh::Status::ok && two.status == stratmesh::Status::ok &&
              pair_status == stratmesh::Status::ok;
    double seconds_no_runner = median(one_times);
    double seconds_2_threads = median(two_times);
    double seconds_2_independent = median(pair_times);
    double speedup = seconds_no_runner / seconds_2_threads;
    double speedup_ceiling = 2 * seconds_no_runner / seconds_2_independent;
    Result result = {ok ? Outcome::ok : Outcome::failed, cloud.count, seconds_2_threads,
                     std::nan(""), std::nan(""), std::nan("")};
    JsonLine line = case_line(name, cloud.count, runs);
    line.add("layers", one.report.layers.used_count);
    line.add("seconds_no_runner", seconds_no_runner);
    line.add("seconds_2_threads", seconds_2_threads);
    line.add("speedup", speedup);
    line.add("seconds_2_independent", seconds_2_independent);
    line.add("speedup_ceiling", speedup_ceiling);
    line.add("share_of_ceiling", speedup / speedup_ceiling);
    line.add("parallel_layers", two.report.layers.parallel_count);
    line.add("identical", one.triangles == two.triangles);
    line.add("independent_identical",
             one.triangles == pair[0].triangles && one.triangles == pair[1].triangles);
    line.add("triangles", one.triangles.size() / 3);
    line.add("workspace_bytes_no_runner", serial_bytes);
    line.add("workspace_bytes_2_threads", workspace_bytes);
    line.add("status", status_name(one.status));
    line.add("status_2_threads", status_name(two.status));
    line.add("status_2_independent", status_name(pair_status));
    line.print();
    return result;
}

// A cloud regrouped into equal layers along z: the points of each layer in input order,
// layer after layer, and the cuts between the layers.
struct LayeredCloud {
    std::vector<double> xyz;
    std::vector<double> cuts;
    std::vector<size_t> start;  // the first point of each layer, then the end
    double top = 0;             // the highest point's height: the last push's top
};

LayeredCloud layer_along_z(const std::vector<double>& coords, uint32_t layers) {
    LayeredCloud out;
    const size_t n = coords.size() / 3;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (size_t i = 0; i < n; ++i) {
        lo = std::min(lo, coords[3 * i + 2]);
        hi = std::max(hi, coords[3 * i + 2]);
    }
    for (uint32_t k = 1; k < layers; ++k)
        out.cuts.push_back(lo + (hi - lo) * static_cast<double>(k) / static_cast<double>(layers));
    out.top = hi;
    std::vector<std::vector<size_t>> members(layers);
    for (size_t i = 0; i < n; ++i) {
        auto above = std::upper_bound(out.cuts.begin(), out.cuts.end(), coords[3 * i + 2]);
        members[static_cast<size_t>(above - out.cuts.begin())].push_back(i);
    }
    out.xyz.reserve(coords.size());
    for (const std::vector<size_t>& layer : members) {
        out.start.push_back(out.xyz.size() / 3);
        for (size_t i : layer) out.xyz.insert(out.xyz.end(), &coords[3 * i], &coords[3 * i] + 3);
    }
    out.start.push_back(n);
    return out;
}

void collect_triangles(void* user, const uint32_t* triangles, size_t count) {
    auto& all = *static_cast<std::vector<uint32_t>*>(user);
    all.insert(all.end(), triangles, triangles + 3 * count);
}

// Pushes every layer through a stream in `workspace`; the triangles land in out.triangles.
void run_stream(const LayeredCloud& cloud, const stratmesh::Options& options,
                unsigned char* workspace, size_t workspace_bytes, Reconstructed& out) {
    out.triangles.clear();
    out.report = stratmesh::Report();
    Clock::time_point start = Clock::now();
    stratmesh::Stream* stream = nullptr;
    out.status = stratmesh::stream_open(options, workspace, workspace_bytes, collect_triangles,
                                        &out.triangles, &out.report, &stream);
    for (size_t k = 0; k + 1 < cloud.start.size() && out.status == stratmesh::Status::ok; ++k) {
        stratmesh::Cloud layer = {&cloud.xyz[3 * cloud.start[k]],
                                  cloud.start[k + 1] - cloud.start[k], 0,
                                  stratmesh::Scalar::float64};
        double top = k < cloud.cuts.size() ? cloud.cuts[k] : cloud.top;
        out.status = stratmesh::stream_push(stream, layer, top);
    }
    if (out.status == stratmesh::Status::ok) out.status = stratmesh::stream_close(stream);
    out.seconds = seconds_between(start, Clock::now());
}

// Times the stream (workspace for 4 times the largest layer, as the header documents) and
// reconstruct() with the same cuts and origin on the regrouped cloud, alternately, and
// compares their triangles.
Result measure_stream(const std::string& name, const std::vector<double>& coords,
                      const Layering& layering, int runs) {
    LayeredCloud layered = layer_along_z(coords, layering.layer_count);
    size_t largest = 0;
    for (size_t k = 0; k + 1 < layered.start.size(); ++k)
        largest = std::max(largest, layered.start[k + 1] - layered.start[k]);
    stratmesh::Options options = {};
    options.axis = stratmesh::Axis::z;
    options.flags = stratmesh::origin_given;
    for (size_t k = 0; k < 3; ++k) options.origin[k] = layered.xyz[k];
    size_t stream_bytes = stratmesh::stream_workspace_size(largest * 4, options);
    stratmesh::Options batch = options;
    batch.cuts = layered.cuts.data();
    batch.cut_count = layered.cuts.size();
    stratmesh::Cloud cloud = {layered.xyz.data(), layered.xyz.size() / 3, 0,
                              stratmesh::Scalar::float64};
    size_t batch_bytes = stratmesh::reconstruct_workspace_size(cloud.count, batch);
    std::unique_ptr<unsigned char[]> stream_workspace = allocate_touched(stream_bytes);
    std::unique_ptr<unsigned char[]> batch_workspace = allocate_touched(batch_bytes);
    Reconstructed streamed, whole;
    streamed.triangles.reserve(3 * stratmesh::reconstruct_max_triangles(cloud.count, batch));
    auto [stream_times, batch_times] = alternate(
        runs,
        [&] {
            run_stream(layered, options, stream_workspace.get(), stream_bytes, streamed);
            return streamed.seconds;
        },
        [&] {
            run_reconstruct(cloud, batch, batch_workspace.get(), batch_bytes, whole);
            return whole.seconds;
        });
    // The stream's surface closed afterwards by cap_ends(), against reconstruct() with
    // add_caps on the same cuts (once each: they run after the timed alternation).
    const size_t surface = streamed.triangles.size() / 3;
    const size_t cap_bytes = stratmesh::cap_ends_workspace_size(cloud.count, surface);
    std::unique_ptr<unsigned char[]> cap_workspace = allocate_touched(cap_bytes);
    std::vector<uint32_t> capped = streamed.triangles;
    capped.resize(3 * stratmesh::reconstruct_max_triangles(cloud.count, batch));
    size_t capped_count = surface;
    stratmesh::Report cap_report = stratmesh::Report();
    Clock::time_point cap_start = Clock::now();
    const stratmesh::Status cap_status =
        stratmesh::cap_ends(cloud, options, cap_workspace.get(), cap_bytes, capped.data(),
                            capped.size() / 3, &capped_count, &cap_report);
    const double cap_seconds = seconds_between(cap_start, Clock::now());
    capped.resize(3 * capped_count);
    stratmesh::Options closing = batch;
    closing.flags |= stratmesh::add_caps;
    const size_t closing_bytes = stratmesh::reconstruct_workspace_size(cloud.count, closing);
    batch_workspace.reset();
    std::unique_ptr<unsigned char[]> closing_workspace = allocate_touched(closing_bytes);
    Reconstructed closed;
    run_reconstruct(cloud, closing, closing_workspace.get(), closing_bytes, closed);

    bool ok = streamed.status == stratmesh::Status::ok && whole.status == stratmesh::Status::ok &&
              cap_status == stratmesh::Status::ok && closed.status == stratmesh::Status::ok;
    Result result = {ok ? Outcome::ok : Outcome::failed, cloud.count, median(stream_times),
                     std::nan(""), std::nan(""), std::nan("")};
    JsonLine line = case_line(name, cloud.count, runs);
    line.add("pushes", layered.start.size() - 1);
    line.add("largest_push", largest);
    line.add("stream_seconds", median(stream_times));
    line.add("reconstruct_seconds", median(batch_times));
    line.add("stream_workspace_bytes", stream_bytes);
    line.add("reconstruct_workspace_bytes", batch_bytes);
    line.add("workspace_ratio",
             static_cast<double>(batch_bytes) / static_cast<double>(stream_bytes));
    line.add("stream_workspace_used", streamed.report.workspace_used_bytes);
    line.add("reconstruct_workspace_used", whole.report.workspace_used_bytes);
    line.add("workspace_used_ratio", static_cast<double>(whole.report.workspace_used_bytes) /
                                         static_cast<double>(streamed.report.workspace_used_bytes));
    line.add("points_held", streamed.report.points.held_count);
    line.add("layers", whole.report.layers.used_count);
    line.add("stream_layers", streamed.report.layers.used_count);
    line.add("identical", streamed.triangles == whole.triangles);
    line.add("triangles", whole.triangles.size() / 3);
    line.add("stream_triangles", streamed.triangles.size() / 3);
    line.add("status", status_name(whole.status));
    line.add("stream_status", status_name(streamed.status));
    if (streamed.report.detail) line.add("stream_detail", streamed.report.detail);
    line.add("cap_ends_seconds", cap_seconds);
    line.add("cap_ends_workspace_bytes", cap_bytes);
    line.add("cap_ends_bytes_per_point",
             static_cast<double>(cap_bytes) / static_cast<double>(cloud.count));
    line.add("cap_ends_status", status_name(cap_status));
    line.add("caps_closed", cap_report.caps.closed_count);
    line.add("add_caps_seconds", closed.seconds);
    line.add("stream_and_cap_ends_over_add_caps",
             (median(stream_times) + cap_seconds) / closed.seconds);
    line.add("capped_identical", capped == closed.triangles);
    line.print();
    return result;
}

// ==== Inputs ===============================================================================

// The size of a raw x, y float64 file, checked: true and `bytes` set if it is a non-empty
// multiple of 16 bytes, otherwise false and `error` says why.
bool check_xy_file(const std::string& path, uint64_t& bytes, std::string& error) {
    std::ifstream file(path, std::ios::binary | std::ios::ate);
    if (!file) {
        error = "cannot open '" + path + "'";
        return false;
    }
    std::streamoff end = file.tellg();
    if (end < 0) {
        error = "cannot determine the size of '" + path + "'";
        return false;
    }
    bytes = static_cast<uint64_t>(end);
    if (bytes == 0 || bytes % 16 != 0) {
        error = "'" + path + "' has " + std::to_string(bytes) +
                " bytes, which is not a non-zero multiple of 16 (one point is two "
                "little-endian float64 values, x then y)";
        return false;
    }
    return true;
}

// Reads little-endian float64 pairs; decodes byte by byte, so the host's byte order does
// not matter.
bool read_xy_file(const std::string& path, std::vector<double>& coords, std::string& error) {
    uint64_t bytes = 0;
    if (!check_xy_file(path, bytes, error)) return false;
    std::ifstream file(path, std::ios::binary);
    std::vector<unsigned char> raw(static_cast<size_t>(bytes));
    if (!file.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(bytes))) {
        error = "cannot read '" + path + "'";
        return false;
    }
    coords.resize(static_cast<size_t>(bytes / 8));
    for (size_t i = 0; i < coords.size(); ++i) {
        uint64_t bits = 0;
        for (size_t b = 0; b < 8; ++b)
            bits |= static_cast<uint64_t>(raw[8 * i + b]) << (8 * b);
        std::memcpy(&coords[i], &bits, sizeof bits);
    }
    return true;
}

// The file's name without its directories.
std::string base_name(const std::string& path) {
    size_t slash = path.find_last_of("/\\");
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

const char* scalar_name(stratmesh::Scalar scalar) {
    return scalar == stratmesh::Scalar::float32 ? "float32" : "float64";
}

// Times the reconstruction of a PLY file's points.
Result measure_ply_file(const Job& job, const Options& options) {
    const double none = std::nan("");
    Result result = {Outcome::bad_input, 0, none, none, none, none};
    bench::PlyCloud ply;
    std::string error;
    if (!bench::read_ply_file(job.path, ply, error)) {
        std::fprintf(stderr, "stratmesh_bench: %s\n", error.c_str());
        return result;
    }
    ReconstructCase c = {job.name, ply.cloud, job.layering, job.runs, options.layer_lines,
                         0x5EED0F11Eu, JsonLine()};
    c.extra.add("path", job.path);
    c.extra.add("format", ply.format);
    c.extra.add("scalar", scalar_name(ply.cloud.scalar));
    c.extra.add("stride_bytes", ply.cloud.stride_bytes);
    c.extra.add("in_place", !ply.raw.empty());
    return measure_reconstruct(c);
}

// Generates or loads the job's input and measures it.
Result run_job(const Job& job, const Options& options) {
    if (job.input == Input::ply_file) return measure_ply_file(job, options);
    const double none = std::nan("");
    Result result = {Outcome::bad_input, 0, none, none, none, none};
    std::vector<double> coords;
    if (job.input == Input::table) {
        job.spec->generate(job.spec->n, job.spec->seed, coords);
    } else {
        std::string error;
        if (!read_xy_file(job.path, coords, error)) {
            std::fprintf(stderr, "stratmesh_bench: %s\n", error.c_str());
            return result;
        }
    }
    switch (job.kind) {
    case Kind::delaunay_2d:
        result.n = coords.size() / 2;
        result.outcome = measure_delaunay_2d(job.name, coords, job.runs, options)
                             ? Outcome::ok
                             : Outcome::failed;
        return result;
    case Kind::threads: {
        stratmesh::Cloud cloud = {coords.data(), coords.size() / 3, 0,
                                  stratmesh::Scalar::float64};
        return measure_threads(job.name, cloud, job.layering, job.runs);
    }
    case Kind::stream: return measure_stream(job.name, coords, job.layering, job.runs);
    case Kind::reconstruct:
    case Kind::layered: {
        stratmesh::Cloud cloud = {coords.data(), coords.size() / 3, 0,
                                  stratmesh::Scalar::float64};
        ReconstructCase c = {job.name, cloud, job.layering, job.runs,
                             job.kind == Kind::layered || options.layer_lines,
                             job.spec->seed ^ 0xD2D2D2D2u, JsonLine()};
        return measure_reconstruct(c);
    }
    }
    result.outcome = Outcome::failed;
    return result;
}

// Prints a line comparing the growth of the time from one case to another with n log n.
void print_growth(const Growth& growth, const Result& from, const Result& to) {
    double n_ratio = static_cast<double>(to.n) / static_cast<double>(from.n);
    JsonLine line;
    line.add("name", std::string(growth.from) + "-to-" + growth.to);
    line.add("n_from", from.n);
    line.add("n_to", to.n);
    line.add("seconds_ratio", to.seconds / from.seconds);
    line.add("nlogn_prediction", n_ratio * std::log(static_cast<double>(to.n)) /
                                     std::log(static_cast<double>(from.n)));
    line.add("linear_prediction", n_ratio);
    line.add("delaunay_seconds_ratio", to.delaunay_seconds / from.delaunay_seconds);
    line.add("min_seconds_ratio", to.min_seconds / from.min_seconds);
    line.add("delaunay_min_seconds_ratio", to.delaunay_min_seconds / from.delaunay_min_seconds);
    line.print();
}

// ==== Command line =========================================================================

void print_help(std::FILE* out) {
    std::fputs(
        "usage: stratmesh_bench [--case NAME]... [--xy FILE]... [--cloud FILE.ply]...\n"
        "                       [--axis x|y|z|auto] [--layers N] [--layer-lines]\n"
        "                       [--runs N] [--no-cgal] [--list] [--write-cloud CASE FILE]\n"
        "                       [--help]\n"
        "\n"
        "Times stratmesh on fixed inputs and prints one JSON object per line per case.\n"
        "\n"
        "delaunay_2d (cases uniform, grid, rings, clustered; --xy files):\n"
        "  name, n, runs             the case, its point count, timed repetitions\n"
        "  seconds, min_seconds      median and fastest run of the library call\n"
        "  mpts_per_s                million input points per second (from the median)\n"
        "  workspace_bytes_per_point delaunay_2d_workspace_size(n) / n\n"
        "  total_bytes_per_point     workspace plus the triangle array at its maximum\n"
        "                            size, over n\n"
        "  status, triangles, hull_vertices, duplicates   what the call reported\n",
        out);
#ifdef STRATMESH_BENCH_WITH_CGAL
    std::fputs(
        "and from the CGAL peer (Delaunay_triangulation_2, Epick, insert(begin, end)):\n"
        "  cgal_seconds, cgal_min_seconds   median and fastest run, heap already warm\n"
        "  cgal_faces                finite faces\n"
        "  ratio                     cgal_seconds / seconds: above 1, stratmesh is faster\n"
        "  cgal_cold_seconds         CGAL's untimed first run, page faults included\n"
        "  agree                     same triangle count and distinct vertex count\n",
        out);
#else
    std::fputs("(this build has no CGAL peer: configure with -DSTRATMESH_BENCH_CGAL=ON)\n",
               out);
#endif
    std::fputs(
        "\n"
        "reconstruct (cases tube, paper; --cloud files):\n"
        "  name, n, runs, seconds, min_seconds, mpts_per_s   as above\n"
        "  workspace_bytes_per_point reconstruct_workspace_size(n, options) / n\n"
        "  total_bytes_per_point     workspace plus the triangle array at its maximum\n"
        "                            size, over n\n"
        "  status, triangles, layers, folds, illegal_removed, unused, points_used,\n"
        "  duplicates, rejected      what the call reported\n"
        "  delaunay_seconds, delaunay_min_seconds   delaunay_2d on n uniform 2D points,\n"
        "                            timed in the same run, alternating with reconstruct\n"
        "  ratio_to_delaunay         seconds / delaunay_seconds (min_ratio_to_delaunay:\n"
        "                            the same from the fastest runs)\n"
        "  validate_seconds, layers_seconds, triangulate_seconds, stitch_seconds,\n"
        "  manifold_seconds, done_seconds   median time from the start of each phase\n"
        "                            (Options::progress) to the start of the next\n"
        "  axis, height_min, height_max   the axis used, the cloud's extent along it\n"
        "  detail                    the report's explanation, when it gives one\n"
        "  path, format, scalar, stride_bytes, in_place   --cloud files only\n"
        "The paper cases (and every reconstruction with --layer-lines) print one line\n"
        "per layer first: name, layer, bottom, top, point_count, triangle_count,\n"
        "fold_count, radius. After tube-1e6 and tube-4e6, a growth line compares\n"
        "their seconds_ratio (of medians; min_seconds_ratio of the fastest runs, steadier\n"
        "on a shared machine; delaunay_* the same for the reference) with\n"
        "nlogn_prediction = 4 log(4e6) / log(1e6).\n"
        "\n"
        "threads (cases threads-tube-1e6, threads-tube-4e6: 8 layers):\n"
        "  seconds_no_runner, seconds_2_threads   medians of reconstruct without a job\n"
        "                            runner and with a 2-thread std::thread runner\n"
        "  speedup                   seconds_no_runner / seconds_2_threads\n"
        "  seconds_2_independent     median wall time of two serial reconstructs at once\n"
        "                            on two threads, each with its own workspace\n"
        "  speedup_ceiling           2 x seconds_no_runner / seconds_2_independent: what\n"
        "                            two cores give on two independent copies of the work\n"
        "  share_of_ceiling          speedup / speedup_ceiling\n"
        "  parallel_layers           Report::layers.parallel_count of the threaded run\n"
        "  identical                 the serial and threaded arrays are the same bytes\n"
        "  independent_identical     both independent calls gave the serial call's bytes\n"
        "  workspace_bytes_no_runner, workspace_bytes_2_threads   the two bounds\n"
        "  status, status_2_threads, status_2_independent   what the calls returned\n"
        "stream (case stream-tube-4e6: 100 equal layers along z):\n"
        "  stream_seconds, reconstruct_seconds   medians of the stream pushed layer by\n"
        "                            layer and of reconstruct with the same cuts and origin\n"
        "  stream_workspace_bytes    stream_workspace_size(4 x largest_push)\n"
        "  reconstruct_workspace_bytes, workspace_ratio (reconstruct / stream)\n"
        "  stream_workspace_used, reconstruct_workspace_used, workspace_used_ratio\n"
        "                            Report::workspace_used_bytes of each\n"
        "  points_held, identical    the stream's Report::points.held_count; same triangles\n"
        "  cap_ends_seconds, cap_ends_workspace_bytes, cap_ends_bytes_per_point,\n"
        "  cap_ends_status, caps_closed   cap_ends() on the stream's triangles, once\n"
        "  add_caps_seconds          reconstruct with add_caps on the same cuts, once\n"
        "  stream_and_cap_ends_over_add_caps   (stream_seconds + cap_ends_seconds) /\n"
        "                            add_caps_seconds\n"
        "  capped_identical          cap_ends' output equals reconstruct's with add_caps\n"
        "\n"
        "  --case NAME   run only this case or family (repeatable, or a comma list);\n"
        "                see --list. Without --case, --xy or --cloud, every case runs.\n"
        "  --xy FILE     also time delaunay_2d on the points in FILE: raw little-endian\n"
        "                float64 pairs x0 y0 x1 y1 ... (repeatable); the case is named\n"
        "                after the file.\n"
        "  --cloud FILE  also time reconstruct on the vertices of a PLY file: ascii or\n"
        "                binary_little_endian, float or double x, y, z, other vertex\n"
        "                properties skipped, vertex the first element (repeatable).\n"
        "  --axis A      x, y, z or auto (default): the axis for --cloud files.\n"
        "  --layers N    N equal layers for --cloud files (default 0: the library's\n"
        "                automatic layers).\n"
        "  --layer-lines one line per layer for every reconstruction.\n"
        "  --runs N      timed repetitions per case (default: see --list; for files 11\n"
        "                up to 1e5 points, 5 up to 1e6, 3 above).\n"
        "  --no-cgal     do not time the CGAL peer even if it is compiled in.\n"
        "  --list        print the case names and families, then exit.\n"
        "  --write-cloud CASE FILE  write a 3D case's cloud as binary PLY (float64 x, y,\n"
        "                z), then exit: the cloud bench/end_to_end.sh times.\n"
        "  --help        print this help, then exit.\n"
        "\n",
        out);
    std::fprintf(out,
                 "Exit status: 0 if every case succeeded%s, 1 otherwise,\n"
                 "2 on a usage error or an input file that cannot be used.\n",
#ifdef STRATMESH_BENCH_WITH_CGAL
                 " (and agreed with CGAL)"
#else
                 ""
#endif
    );
}

int usage_error(const std::string& message) {
    std::fprintf(stderr, "stratmesh_bench: %s\n(stratmesh_bench --help for the options)\n",
                 message.c_str());
    return 2;
}

// An input file that cannot be used: its problem, and the exit status 2.
int input_error(const std::string& message) {
    std::fprintf(stderr, "stratmesh_bench: %s\n", message.c_str());
    return 2;
}

// Appends the cases NAME selects (a case name or a family) to `selected`; false if none.
bool select_cases(const std::string& name, std::vector<const CaseSpec*>& selected) {
    bool found = false;
    for (const CaseSpec& spec : kCases) {
        if (name == spec.name || name == spec.family) {
            found = true;
            if (std::find(selected.begin(), selected.end(), &spec) == selected.end())
                selected.push_back(&spec);
        }
    }
    return found;
}

bool parse_runs(const char* text, int& runs) {
    char* end = nullptr;
    long value = std::strtol(text, &end, 10);
    if (end == text || *end != '\0' || value < 1 || value > 100000) return false;
    runs = static_cast<int>(value);
    return true;
}

std::string case_names() {
    std::string names;
    for (const CaseSpec& spec : kCases) {
        if (!names.empty()) names += ", ";
        names += spec.name;
    }
    return names;
}

bool parse_axis(const std::string& text, stratmesh::Axis& axis) {
    if (text == "x") axis = stratmesh::Axis::x;
    else if (text == "y") axis = stratmesh::Axis::y;
    else if (text == "z") axis = stratmesh::Axis::z;
    else if (text == "auto") axis = stratmesh::Axis::automatic;
    else return false;
    return true;
}

bool parse_layers(const char* text, uint32_t& layers) {
    char* end = nullptr;
    long value = std::strtol(text, &end, 10);
    if (end == text || *end != '\0' || value < 0 || value > 1000000) return false;
    layers = static_cast<uint32_t>(value);
    return true;
}

// A file named on the command line, and its point count.
struct InputFile {
    Input input;
    std::string path;
    size_t n;
};

// The default repetitions for a file: as for the generated cases of its size, more for
// small files, whose runs are short and noisy.
int default_file_runs(size_t n) { return n <= 100000 ? 11 : n <= 1000000 ? 5 : 3; }

struct CommandLine {
    std::vector<const CaseSpec*> selected;
    std::vector<InputFile> files;  // in the order given
    int runs_override = 0;
    Options options;
    Layering file_layering = {stratmesh::Axis::automatic, 0, nullptr, 0};
    bool file_options = false;  // --axis or --layers given
    // --write-cloud CASE FILE: the case's cloud written as binary PLY (float64), then exit.
    const CaseSpec* cloud_case = nullptr;
    std::string cloud_path;
};

// A 3D case's generated cloud as a binary little-endian PLY of float64 x, y, z, for tools
// to read the very cloud a case times (bench/end_to_end.sh). False on a write error.
bool write_case_cloud(const CaseSpec& spec, const std::string& path) {
    std::vector<double> xyz;
    spec.generate(spec.n, spec.seed, xyz);
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    const size_t n = xyz.size() / 3;
    std::fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex %zu\n"
                    "property double x\nproperty double y\nproperty double z\nend_header\n", n);
    bool ok = true;
    for (double v : xyz) {  // byte by byte: the file is little-endian on any machine
        uint64_t bits;
        std::memcpy(&bits, &v, sizeof bits);
        unsigned char bytes[8];
        for (int k = 0; k < 8; ++k) bytes[k] = static_cast<unsigned char>(bits >> (8 * k));
        ok = ok && std::fwrite(bytes, 1, 8, f) == 8;
    }
    return std::fclose(f) == 0 && ok;
}

void print_case_list() {
    for (const CaseSpec& spec : kCases)
        std::printf("%-16s family %-10s n %zu, %d runs\n", spec.name, spec.family, spec.n,
                    spec.default_runs);
}

// Reads the arguments into `cl`. Returns -1 to go on, or the exit status to end with.
int parse_arguments(int argc, char** argv, CommandLine& cl) {
    for (int i = 1; i < argc; ++i) {
        std::string arg = argv[i];
        bool has_value = i + 1 < argc;
        std::string error;
        if (arg == "--help" || arg == "-h") {
            print_help(stdout);
            return 0;
        } else if (arg == "--list") {
            print_case_list();
            return 0;
        } else if (arg == "--no-cgal") {
            cl.options.cgal = false;
        } else if (arg == "--layer-lines") {
            cl.options.layer_lines = true;
        } else if (arg == "--case") {
            if (!has_value) return usage_error("--case needs a case name");
            std::string list = argv[++i];
            size_t begin = 0;
            while (begin <= list.size()) {
                size_t comma = list.find(',', begin);
                if (comma == std::string::npos) comma = list.size();
                std::string name = list.substr(begin, comma - begin);
                if (!select_cases(name, cl.selected))
                    return usage_error("unknown case '" + name + "'; the cases are " +
                                       case_names() + " (and their families)");
                begin = comma + 1;
            }
        } else if (arg == "--runs") {
            if (!has_value) return usage_error("--runs needs a number");
            if (!parse_runs(argv[++i], cl.runs_override))
                return usage_error(std::string("--runs needs a whole number from 1, not '") +
                                   argv[i] + "'");
        } else if (arg == "--write-cloud") {
            if (i + 2 >= argc) return usage_error("--write-cloud needs a case and a file name");
            const std::string name = argv[++i];
            for (const CaseSpec& spec : kCases)
                if (name == spec.name && spec.kind != Kind::delaunay_2d) cl.cloud_case = &spec;
            if (!cl.cloud_case) return usage_error("--write-cloud: no 3D case named '" + name + "'");
            cl.cloud_path = argv[++i];
        } else if (arg == "--xy") {
            if (!has_value) return usage_error("--xy needs a file name");
            std::string path = argv[++i];
            uint64_t bytes = 0;
            if (!check_xy_file(path, bytes, error)) return input_error(error);
            size_t points = static_cast<size_t>(bytes / 16);
            cl.files.push_back(InputFile{Input::xy_file, path, points});
        } else if (arg == "--cloud") {
            if (!has_value) return usage_error("--cloud needs a PLY file name");
            std::string path = argv[++i];
            size_t vertices = 0;
            if (!bench::check_ply_file(path, vertices, error)) return input_error(error);
            cl.files.push_back(InputFile{Input::ply_file, path, vertices});
        } else if (arg == "--axis") {
            if (!has_value || !parse_axis(argv[i + 1], cl.file_layering.axis))
                return usage_error("--axis needs x, y, z or auto");
            ++i;
            cl.file_options = true;
        } else if (arg == "--layers") {
            if (!has_value || !parse_layers(argv[i + 1], cl.file_layering.layer_count))
                return usage_error("--layers needs a whole number from 0 (0: automatic)");
            ++i;
            cl.file_options = true;
        } else {
            return usage_error("unknown argument '" + arg + "'");
        }
    }
    bool any_cloud = false;
    for (const InputFile& file : cl.files)
        any_cloud = any_cloud || file.input == Input::ply_file;
    if (cl.file_options && !any_cloud)
        return usage_error("--axis and --layers apply to --cloud files, and there is none");
    return -1;
}

std::vector<Job> make_jobs(CommandLine& cl) {
    std::vector<Job> jobs;
    if (cl.selected.empty() && cl.files.empty()) {
        for (const CaseSpec& spec : kCases) cl.selected.push_back(&spec);
    }
    for (const CaseSpec* spec : cl.selected) {
        int runs = cl.runs_override > 0 ? cl.runs_override : spec->default_runs;
        jobs.push_back(Job{spec->name, spec->kind, runs, spec, std::string(), Input::table,
                           spec->layering});
    }
    for (const InputFile& file : cl.files) {
        int runs = cl.runs_override > 0 ? cl.runs_override : default_file_runs(file.n);
        bool ply = file.input == Input::ply_file;
        jobs.push_back(Job{base_name(file.path), ply ? Kind::reconstruct : Kind::delaunay_2d,
                           runs, nullptr, file.path, file.input,
                           ply ? cl.file_layering : kNoLayering});
    }
    return jobs;
}

}  // namespace

int main(int argc, char** argv) {
    CommandLine cl;
    int exit_status = parse_arguments(argc, argv, cl);
    if (exit_status >= 0) return exit_status;
    if (cl.cloud_case) {
        if (write_case_cloud(*cl.cloud_case, cl.cloud_path)) return 0;
        std::fprintf(stderr, "stratmesh_bench: cannot write %s\n", cl.cloud_path.c_str());
        return 3;
    }
    std::vector<Job> jobs = make_jobs(cl);

#ifdef STRATMESH_BENCH_WITH_CGAL
    std::fprintf(stderr, "stratmesh_bench: stratmesh %s, peer CGAL %s%s\n",
                 STRATMESH_VERSION_STRING, CGAL_VERSION_STR,
                 cl.options.cgal ? "" : " (disabled by --no-cgal)");
#else
    std::fprintf(stderr, "stratmesh_bench: stratmesh %s, no CGAL peer in this build\n",
                 STRATMESH_VERSION_STRING);
#endif
#ifndef NDEBUG
    std::fprintf(stderr, "stratmesh_bench: warning: built without NDEBUG; "
                         "use -DCMAKE_BUILD_TYPE=Release for meaningful numbers\n");
#endif

    keep_heap_warm();
    bool failed = false, bad_input = false;
    std::vector<std::pair<std::string, Result>> results;
    for (const Job& job : jobs) {
        Result result = run_job(job, cl.options);
        failed = failed || result.outcome == Outcome::failed;
        bad_input = bad_input || result.outcome == Outcome::bad_input;
        if (job.input == Input::table) results.emplace_back(job.name, result);
    }
    for (const Growth& growth : kGrowths) {
        const Result* from = nullptr;
        const Result* to = nullptr;
        for (const auto& named : results) {
            if (named.first == growth.from) from = &named.second;
            if (named.first == growth.to) to = &named.second;
        }
        if (from && to && from->outcome == Outcome::ok && to->outcome == Outcome::ok)
            print_growth(growth, *from, *to);
    }
    return bad_input ? 2 : failed ? 1 : 0;
}
