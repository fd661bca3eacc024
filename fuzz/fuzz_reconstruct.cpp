// fuzz_reconstruct: stratmesh::reconstruct on clouds built from the fuzzer's bytes.
//
// The cloud: float32 or float64, a stride with padding (or 0: packed), up to 255 points,
// each either raw bit patterns (NaN, Inf, denormals) or snapped to a coarse grid (degenerate
// layers), optionally repeating an earlier point (fuzz_cloud.h). Its buffer ends exactly
// after the last point's z, the workspace is exactly reconstruct_workspace_size() and the
// triangle array ends where its allocation ends, so any overrun trips AddressSanitizer.
// Options: every axis (direction with zero/NaN components too), cuts with NaN, unsorted and
// repeated values, layer_count, layer_height, skip_invalid_points, add_caps (caps),
// drop_outliers, surface_flips, ends_are_cuts, layer and part arrays to fill. Under libFuzzer a
// structure-aware mutator (fuzz_cloud_mutator.h) makes the clouds that sensors make.
//
// How much of the pipeline runs, by a hash of the input's bytes (a given input always runs
// the same way; libFuzzer's mutations of it spread over all three):
//  - one input in kWholeShare: the whole pipeline as a caller gets it: every point, the
//    automatic axis where the options ask for it, the search for branches;
//  - one in kAxisShare of the others: the first kQuickPoints points as one tube
//    (Parts::one_tube), the automatic axis where the options ask for it;
//  - the rest: the same, along z where the options ask for the automatic axis.
// Choosing the axis meshes up to six samples and the branch search meshes a cloud that parts
// twice; with both on every input of up to 512 points the harness ran tens of inputs a
// second (docs/benchmarks.md), too few to explore. Each costly part still runs hundreds of
// times a minute.
//
// Checked after each run: the status is a documented one; the report's counts add up on
// every status; on ok, every index < n, no repeated index in a triangle, at most
// reconstruct_max_triangles triangles, the mesh an oriented edge- and vertex-manifold
// (tests/support/mesh_check.h), vertices only distinct valid points and points_used equal
// to the vertices used. On an eighth of the inputs (by other bits of the hash; all of them
// with STRATMESH_FUZZ_STRICT) two more: a second run on a differently-filled workspace,
// with the layers triangulated ahead by jobs (Options::run_jobs, run in reverse order),
// gives the same bits (triangles, report, layers, parts); and find_parting(), in a
// workspace of exactly find_parting_workspace_size(), returns a documented status, and on
// ok branches that a side of the cloud can hold (sizes from kSmallestBranch, largest first,
// adding up to at most n), each point labelled (the branches above exactly as large as
// reported, those below at most: the side above keeps the points of both).
#include "fuzz_cloud.h"
#include "fuzz_cloud_mutator.h"
#include "fuzz_common.h"
#include "known_bugs.h"

#include "stratmesh.h"
#include "support/mesh_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

const uint32_t kMaxPoints = stratmesh_fuzz::kReconstructMaxPoints;
const size_t kQuickPoints = stratmesh_fuzz::kReconstructQuickPoints;
// One input in kWholeShare runs the whole pipeline, one in kAxisShare of the others the
// automatic axis (see above).
const uint64_t kWholeShare = 64;
const uint64_t kAxisShare = 16;

using stratmesh_fuzz::Bytes;

struct Run {
    stratmesh::Status status;
    size_t count;
    stratmesh::Report report;
    std::vector<uint32_t> triangles;
    std::vector<stratmesh::LayerInfo> layers;
    std::vector<stratmesh::PartInfo> parts;
};

Run run(const stratmesh::Cloud& cloud, const stratmesh::Options& options, size_t capacity,
        size_t info_capacity, unsigned char fill) {
    Run r;
    const size_t work_bytes = stratmesh::reconstruct_workspace_size(cloud.count, options);
    std::vector<unsigned char> work(work_bytes, fill);
    r.triangles.assign(3 * capacity, 0xDEADBEEFu);
    r.layers.resize(info_capacity);
    r.parts.resize(info_capacity);
    std::memset(static_cast<void*>(&r.report), fill, sizeof r.report);
    r.report.layers.info = info_capacity ? r.layers.data() : nullptr;
    r.report.layers.info_capacity = info_capacity;
    r.report.parts.info = info_capacity ? r.parts.data() : nullptr;
    r.report.parts.info_capacity = info_capacity;
    r.count = 12345;
    r.status = stratmesh::reconstruct(cloud, options, work.empty() ? nullptr : work.data(),
                                      work_bytes, capacity ? r.triangles.data() : nullptr,
                                      capacity, &r.count, &r.report);
    return r;
}

bool same_double(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// One side of a parting: no branch, or 2 to kMaxBranches of them, largest first, each of
// kSmallestBranch points or more, together at most n, at a finite cut.
void check_parting_side(uint32_t branches, const uint32_t* points, double cut, size_t n) {
    if (branches == 0) return;
    STRATMESH_FUZZ_CHECK(branches >= 2 && branches <= stratmesh::kMaxBranches, "parting: branch count");
    STRATMESH_FUZZ_CHECK(std::isfinite(cut), "parting: a cut that is not finite");
    size_t total = 0;
    for (uint32_t k = 0; k < branches; ++k) {
        STRATMESH_FUZZ_CHECK(points[k] >= stratmesh::kSmallestBranch, "parting: a branch too small");
        STRATMESH_FUZZ_CHECK(k == 0 || points[k] <= points[k - 1], "parting: branches out of order");
        total += points[k];
    }
    STRATMESH_FUZZ_CHECK(total <= n, "parting: more points in branches than in the cloud");
}

void check_parting(const stratmesh::Cloud& cloud, const stratmesh::Options& options) {
    const size_t bytes = stratmesh::find_parting_workspace_size(cloud.count, options);
    std::vector<unsigned char> work(bytes, 0xC3);
    stratmesh::Parting p;
    std::vector<uint8_t> label(cloud.count, 0xA5);
    const stratmesh::Status status =
        stratmesh::find_parting(cloud, options, work.empty() ? nullptr : work.data(), bytes, &p,
                                label.empty() ? nullptr : label.data());
    using stratmesh::Status;
    if (status != Status::ok && status != Status::invalid_point && status != Status::too_few_points &&
        status != Status::invalid_axis && status != Status::flat_cloud)
        stratmesh_fuzz::fail("find_parting returned an unexpected status", stratmesh::status_string(status));
    STRATMESH_FUZZ_CHECK(p.workspace_used_bytes <= bytes, "find_parting: more workspace than its size");
    if (status != Status::ok) return;
    STRATMESH_FUZZ_CHECK(std::isfinite(p.gap) && p.gap >= 0, "parting: a gap that is not finite");
    check_parting_side(p.above_branch_count, p.above_point_counts, p.above, cloud.count);
    check_parting_side(p.below_branch_count, p.below_point_counts, p.below, cloud.count);
    std::vector<uint32_t> in_label(256, 0);
    for (uint8_t l : label) ++in_label[l];
    for (uint32_t l = 0; l < 256; ++l) {
        const bool above = l >= stratmesh::kFirstAboveBranch && l < stratmesh::kFirstAboveBranch + p.above_branch_count;
        const bool below = l >= stratmesh::kFirstBelowBranch && l < stratmesh::kFirstBelowBranch + p.below_branch_count;
        if (above)
            STRATMESH_FUZZ_CHECK(in_label[l] == p.above_point_counts[l - stratmesh::kFirstAboveBranch],
                                 "parting: a branch above labelled with another size");
        else if (below)
            STRATMESH_FUZZ_CHECK(in_label[l] <= p.below_point_counts[l - stratmesh::kFirstBelowBranch],
                                 "parting: a branch below labelled with more points");
        else if (l != stratmesh::kInTrunk && l != stratmesh::kBeyondBranches)
            STRATMESH_FUZZ_CHECK(in_label[l] == 0, "parting: a label that names no branch");
    }
}

void run_jobs_in_reverse(void*, uint32_t count, stratmesh::JobFunction job, void* context) {
    for (uint32_t i = count; i-- > 0;) job(context, i);
}

bool verbose() { return std::getenv("STRATMESH_FUZZ_VERBOSE") != nullptr; }

// The options as the input's bytes give them, the capacities still to be sized.
struct Setup {
    stratmesh::Options options = {};
    std::vector<double> cuts;
    bool small_capacity = false;
    uint32_t capacity_wanted = 0;  // with small_capacity
    size_t info_capacity = 0;  // of the report's layer and part arrays
};

void read_layers(Bytes& in, const stratmesh_fuzz::FuzzCloud& fc, uint8_t how, Setup& s) {
    stratmesh::Options& options = s.options;
    switch (how) {
    case 0: break;  // automatic layers
    case 1: {
        size_t cut_count = in.below(20);
        for (size_t k = 0; k < cut_count; ++k) {
            uint8_t m = in.u8() % 8;
            if (m == 0)
                s.cuts.push_back(in.raw_double());
            else if (m == 1 && !s.cuts.empty())
                s.cuts.push_back(s.cuts[in.below(static_cast<uint32_t>(s.cuts.size()))]);
            else
                s.cuts.push_back(in.centered(4 * fc.grid_range + 2) * fc.grid);
        }
        options.cuts = s.cuts.empty() ? nullptr : s.cuts.data();
        options.cut_count = s.cuts.size();
        break;
    }
    case 2: options.layer_count = in.below(40); break;
    default: {
        uint8_t m = in.u8() % 4;
        options.layer_height = m == 0 ? in.raw_double() : (1 + in.below(64)) * fc.grid / 4;
        break;
    }
    }
}

void read_options(Bytes& in, const stratmesh_fuzz::FuzzCloud& fc, Setup& s) {
    stratmesh::Options& options = s.options;
    const uint8_t ocfg = in.u8();
    options.axis = static_cast<stratmesh::Axis>(ocfg % 5);
    if (options.axis == stratmesh::Axis::direction) {
        for (double& d : options.direction) {
            uint8_t m = in.u8() % 8;
            d = m == 0 ? 0.0 : m == 1 ? in.raw_double() : static_cast<double>(in.centered(3));
        }
    }
    read_layers(in, fc, static_cast<uint8_t>((ocfg >> 3) % 4), s);
    if (ocfg & 0x20) options.flags |= stratmesh::skip_invalid_points;
    if (ocfg & 0x80) options.flags |= stratmesh::add_caps;
    s.small_capacity = (ocfg & 0x40) != 0;
    if (s.small_capacity) s.capacity_wanted = in.below(64);
    s.info_capacity = in.below(8);
    // Read last, so that the corpus's older inputs keep their meaning.
    const uint8_t last = in.u8();
    if (last & 1) options.flags |= stratmesh::drop_outliers;
    if (last & 2) options.flags |= stratmesh::surface_flips;
    if (last & 4) options.flags |= stratmesh::ends_are_cuts;
}

// The status is a documented one and the report's counts add up; a NaN/Inf point is
// refused unless skipped.
void check_status(const Run& first, const Setup& s, const stratmesh_fuzz::FuzzCloud& fc,
                  const std::vector<char>& valid) {
    using stratmesh::Status;
    const stratmesh::Report& rep = first.report;
    switch (first.status) {
    case Status::ok:
    case Status::invalid_point:
    case Status::too_few_points:
    case Status::collinear:
    case Status::invalid_axis:
    case Status::invalid_layers:
    case Status::flat_cloud:
    case Status::not_columnar:
    case Status::degenerate:
    case Status::separate_clusters:
    case Status::triangle_capacity:
        break;
    default:
        stratmesh_fuzz::fail("reconstruct returned an unexpected status", stratmesh::status_string(first.status));
    }
    if (first.status == Status::triangle_capacity)
        STRATMESH_FUZZ_CHECK(s.small_capacity, "triangle_capacity with reconstruct_max_triangles");
    STRATMESH_FUZZ_CHECK(rep.points.in_count == fc.n, "report.points.in_count != n");
    STRATMESH_FUZZ_CHECK(rep.points.in_count == rep.points.used_count + rep.points.duplicate_count + rep.points.rejected_count + rep.points.unused_count,
                         "report counts do not add up");
    const size_t first_invalid = static_cast<size_t>(std::find(valid.begin(), valid.end(), 0) - valid.begin());
    if (first_invalid < fc.n && !(s.options.flags & stratmesh::skip_invalid_points) &&
        first.status != Status::invalid_axis && first.status != Status::invalid_layers) {
        STRATMESH_FUZZ_CHECK(first.status == Status::invalid_point, "a NaN/Inf point was not refused");
    }
    if (first.status == Status::invalid_point)
        STRATMESH_FUZZ_CHECK(rep.points.first_invalid_index == first_invalid, "wrong first_invalid_index");
}

// On ok: the triangles' indices, and the counts of rejected points and outliers.
void check_triangles(const Run& first, const Setup& s, size_t max_tris, size_t capacity,
                     const std::vector<char>& valid) {
    const stratmesh::Report& rep = first.report;
    const size_t n = valid.size(), count = first.count;
    const size_t invalid = static_cast<size_t>(std::count(valid.begin(), valid.end(), 0));
    STRATMESH_FUZZ_CHECK(count <= max_tris, "more triangles than reconstruct_max_triangles");
    STRATMESH_FUZZ_CHECK(count <= capacity, "more triangles than the capacity");
    STRATMESH_FUZZ_CHECK(rep.triangle_count == count, "report.triangle_count != triangle count");
    STRATMESH_FUZZ_CHECK(rep.points.rejected_count == invalid + rep.points.outlier_count, "report.points.rejected_count != NaN/Inf points + outliers");
    STRATMESH_FUZZ_CHECK((s.options.flags & stratmesh::drop_outliers) || rep.points.outlier_count == 0, "outliers without drop_outliers");
    const uint32_t* t = first.triangles.data();
    for (size_t k = 0; k < count; ++k) {
        uint32_t a = t[3 * k], b = t[3 * k + 1], c = t[3 * k + 2];
        STRATMESH_FUZZ_CHECK(a < n && b < n && c < n, "triangle index out of range");
        STRATMESH_FUZZ_CHECK(a != b && b != c && a != c, "degenerate triangle (repeated index)");
        STRATMESH_FUZZ_CHECK(valid[a] && valid[b] && valid[c], "a NaN/Inf point is a vertex");
    }
    // (Entries past 3 * count may have been written: the safety net removes triangles after
    // they were emitted, and the documentation promises nothing about the rest of the array.)
}

// Duplicates: a vertex never repeats a lower-indexed point's coordinates. A repeat counts
// as a duplicate when its lowest twin is a vertex, as unused otherwise (Report::unused).
void check_duplicates(const Run& first, const Setup& s, const std::vector<double>& xyz,
                      const std::vector<char>& valid) {
    const stratmesh::Report& rep = first.report;
    const size_t n = valid.size();
    const uint32_t* t = first.triangles.data();
    std::vector<size_t> order;
    for (size_t i = 0; i < n; ++i)
        if (valid[i]) order.push_back(i);
    std::sort(order.begin(), order.end(), [&](size_t i, size_t j) {
        for (size_t k = 0; k < 3; ++k)
            if (xyz[3 * i + k] != xyz[3 * j + k]) return xyz[3 * i + k] < xyz[3 * j + k];
        return i < j;
    });
    std::vector<char> is_vertex(n, 0), first_of(n, 1);
    for (size_t k = 0; k < 3 * first.count; ++k) is_vertex[t[k]] = 1;
    size_t dups = 0, dups_of_vertices = 0;
    size_t lowest = order.empty() ? 0 : order[0];
    for (size_t k = 1; k < order.size(); ++k) {
        size_t i = order[k - 1], j = order[k];
        if (xyz[3 * i] == xyz[3 * j] && xyz[3 * i + 1] == xyz[3 * j + 1] && xyz[3 * i + 2] == xyz[3 * j + 2]) {
            first_of[j] = 0;
            ++dups;
            if (is_vertex[lowest]) ++dups_of_vertices;
            if (verbose())
                std::fprintf(stderr, "duplicate: %zu of %zu: %a %a %a / %a %a %a\n", j, i, xyz[3 * j],
                             xyz[3 * j + 1], xyz[3 * j + 2], xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
        } else {
            lowest = j;
        }
    }
    if (s.options.flags & stratmesh::drop_outliers)  // repeats of an outlier are outliers
        STRATMESH_FUZZ_CHECK(rep.points.duplicate_count <= dups && rep.points.duplicate_count + rep.points.unused_count + rep.points.outlier_count >= dups,
                             "report.points.duplicate_count inconsistent with repeated points and outliers");
    else  // every repeat of a vertex is a duplicate, exactly
        STRATMESH_FUZZ_CHECK(rep.points.duplicate_count == dups_of_vertices,
                             "report.points.duplicate_count != repeats of vertices");
    for (size_t k = 0; k < 3 * first.count; ++k)
        STRATMESH_FUZZ_CHECK(first_of[t[k]], "a duplicate (not the lowest index) is a vertex");
}

// The mesh is an oriented edge- and vertex-manifold whose vertices the report counts.
void check_manifold(const Run& first, const std::vector<double>& xyz) {
    const stratmesh::Report& rep = first.report;
    const size_t n = xyz.size() / 3;
    std::vector<double> finite_xyz(xyz);
    for (double& v : finite_xyz)
        if (!std::isfinite(v)) v = 0;
    mesh_check::Input mi;
    mi.points = finite_xyz.data();
    mi.point_count = n;
    mi.triangles = first.triangles.data();
    mi.triangle_count = first.count;
    for (size_t k = 0; k < 3; ++k) {
        mi.axis_point[k] = rep.axis_origin[k];
        mi.axis_direction[k] = rep.axis[k];
    }
    std::vector<char> no_expectation(n, 0);
    mi.expected_used = &no_expectation;
    mi.self_intersections = false;  // not guaranteed (see the robustness contract)
    mesh_check::Result mr = mesh_check::check(mi);
    if (!mr.manifold() || mr.bad_indices || mr.degenerate)
        stratmesh_fuzz::fail("the mesh is not an oriented manifold", mr.summary().c_str());
    STRATMESH_FUZZ_CHECK(mr.vertices_used == rep.points.used_count, "report.points.used_count != vertices used");
}

// The same bits from a second run on a differently-filled workspace, with the layers
// triangulated ahead by jobs run in reverse order.
void check_second_run(const Run& first, const stratmesh::Cloud& cloud, const Setup& s, size_t capacity) {
    stratmesh::Options with_jobs = s.options;
    with_jobs.run_jobs = run_jobs_in_reverse;
    Run second = run(cloud, with_jobs, capacity, s.info_capacity, 0x5A);
    const stratmesh::Report& rep = first.report;
    STRATMESH_FUZZ_CHECK(second.status == first.status, "second run: different status");
    STRATMESH_FUZZ_CHECK(second.count == first.count, "second run: different count");
    STRATMESH_FUZZ_CHECK(second.triangles == first.triangles, "second run: different triangles");
    const stratmesh::Report& r2 = second.report;
    STRATMESH_FUZZ_CHECK(r2.points.used_count == rep.points.used_count && r2.points.duplicate_count == rep.points.duplicate_count &&
                             r2.points.rejected_count == rep.points.rejected_count && r2.points.outlier_count == rep.points.outlier_count && r2.points.unused_count == rep.points.unused_count &&
                             r2.diagnostics.illegal_removed_count == rep.diagnostics.illegal_removed_count && r2.diagnostics.fold_count == rep.diagnostics.fold_count &&
                             r2.layers.used_count == rep.layers.used_count,
                         "second run: different report");
    for (size_t k = 0; k < 3; ++k)
        STRATMESH_FUZZ_CHECK(same_double(r2.axis[k], rep.axis[k]) && same_double(r2.axis_origin[k], rep.axis_origin[k]),
                             "second run: different axis");
    size_t filled = std::min(rep.layers.used_count, s.info_capacity);
    for (size_t k = 0; k < filled; ++k) {
        const stratmesh::LayerInfo& a = first.layers[k];
        const stratmesh::LayerInfo& b = second.layers[k];
        bool same = same_double(a.bottom, b.bottom) && same_double(a.top, b.top) &&
                    same_double(a.radius, b.radius) && a.point_count == b.point_count &&
                    a.triangle_count == b.triangle_count && a.fold_count == b.fold_count;
        for (size_t j = 0; j < 3; ++j) same = same && same_double(a.centre[j], b.centre[j]);
        STRATMESH_FUZZ_CHECK(same, "second run: different layers");
    }
    const stratmesh::PartCounts &p1 = rep.parts, &p2 = r2.parts;
    STRATMESH_FUZZ_CHECK(p1.outcome == p2.outcome && p1.part_count == p2.part_count &&
                             p1.joined_side_count == p2.joined_side_count && p1.apart_side_count == p2.apart_side_count &&
                             p1.grafted_branch_count == p2.grafted_branch_count &&
                             p1.junction_triangle_count == p2.junction_triangle_count &&
                             p1.removed_triangle_count == p2.removed_triangle_count,
                         "second run: different parts");
    for (size_t k = 0; k < std::min(p1.part_count, s.info_capacity); ++k) {
        const stratmesh::PartInfo& a = first.parts[k];
        const stratmesh::PartInfo& b = second.parts[k];
        STRATMESH_FUZZ_CHECK(a.label == b.label && a.status == b.status && a.point_count == b.point_count &&
                                 a.layer_count == b.layer_count && a.triangle_count == b.triangle_count &&
                                 a.fold_count == b.fold_count && a.merged_end_layer_count == b.merged_end_layer_count,
                             "second run: different part details");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Bytes in(data, size);
    uint64_t hash = 1469598103934665603ull;
    for (size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * 1099511628211ull;
    const bool strict = stratmesh_fuzz::strict();
    const bool thorough = hash % 8 == 0 || strict;

    const stratmesh_fuzz::FuzzCloud read = stratmesh_fuzz::read_cloud(in, kMaxPoints);
    Setup setup;
    read_options(in, read, setup);
    // Known bug J (known_bugs.h): thin layers of up to a layer a point take quadratic time.
    const bool whole = (hash >> 3) % kWholeShare == 0 &&
                       (strict || !stratmesh_fuzz::bug_j_thin_layers(read.xyz.data(), read.n, setup.options));
    const bool own_axis = whole || (hash >> 9) % kAxisShare == 0;
    const stratmesh_fuzz::FuzzCloud fc = read.first(whole ? read.n : kQuickPoints);
    stratmesh::Options& options = setup.options;
    if (!whole) options.parts = stratmesh::Parts::one_tube;
    if (!own_axis && options.axis == stratmesh::Axis::automatic) options.axis = stratmesh::Axis::z;
    const stratmesh::Cloud cloud = fc.cloud();
    const size_t max_tris = stratmesh::reconstruct_max_triangles(fc.n, options);
    const size_t capacity = setup.small_capacity ? std::min<size_t>(max_tris, setup.capacity_wanted) : max_tris;

    if (thorough) check_parting(cloud, options);
    Run first = run(cloud, options, capacity, setup.info_capacity, 0xA5);
    const stratmesh::Report& rep = first.report;
    if (verbose())
        std::fprintf(stderr, "n %zu%s, %s, %zu triangles, %zu layers, used %zu dup %zu rej %zu unused %zu\n", fc.n,
                     whole ? " (whole pipeline)" : "", stratmesh::status_string(first.status), first.count,
                     rep.layers.used_count, rep.points.used_count, rep.points.duplicate_count,
                     rep.points.rejected_count, rep.points.unused_count);

    // Valid points (as the library converts them: to double).
    std::vector<char> valid(fc.n);
    for (size_t i = 0; i < fc.n; ++i)
        valid[i] = std::isfinite(fc.xyz[3 * i]) && std::isfinite(fc.xyz[3 * i + 1]) && std::isfinite(fc.xyz[3 * i + 2]);
    check_status(first, setup, fc, valid);
    if (first.status != stratmesh::Status::ok) return 0;
    check_triangles(first, setup, max_tris, capacity, valid);
    check_duplicates(first, setup, fc.xyz, valid);
    check_manifold(first, fc.xyz);
    if (thorough) check_second_run(first, cloud, setup, capacity);
    return 0;
}

// ---- the mutator (libFuzzer only: the replay driver runs the corpus as it is) -------------
#if !defined(STRATMESH_FUZZ_REPLAY)

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

// Half the time the cloud's structure (fuzz_cloud_mutator.h), otherwise libFuzzer's own
// changes to the bytes, which also reach the options after the cloud.
extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size, unsigned int seed) {
    stratmesh_fuzz::Random random(seed);
    if (random.below(2) == 0) {
        const size_t written = stratmesh_fuzz::mutate_cloud(data, size, max_size, kMaxPoints, kQuickPoints, random);
        if (written) return written;
    }
    return LLVMFuzzerMutate(data, size, max_size);
}

extern "C" size_t LLVMFuzzerCustomCrossOver(const uint8_t* data1, size_t size1, const uint8_t* data2,
                                            size_t size2, uint8_t* out, size_t max_out_size,
                                            unsigned int seed) {
    stratmesh_fuzz::Random random(seed);
    return stratmesh_fuzz::cross_clouds(data1, size1, data2, size2, out, max_out_size, kMaxPoints,
                                        kQuickPoints, random);
}

#endif
