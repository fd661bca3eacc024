#include "summary.h"

#include <cmath>
#include <string>

namespace stratmesh_cli {

namespace {

std::string seconds_text(double seconds) {
    if (!std::isfinite(seconds)) return "-";
    char text[32];
    std::snprintf(text, sizeof text, "%.3f s", seconds);
    return text;
}

// A coordinate in 6 significant digits.
std::string number_text(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", value);
    return text;
}

std::string bytes_text(size_t bytes) {
    const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    double value = static_cast<double>(bytes);
    size_t unit = 0;
    while (value >= 1024 && unit + 1 < sizeof units / sizeof units[0]) {
        value /= 1024;
        ++unit;
    }
    char text[32];
    if (unit == 0)
        std::snprintf(text, sizeof text, "%zu bytes", bytes);
    else
        std::snprintf(text, sizeof text, "%.1f %s", value, units[unit]);
    return text;
}

std::string phase_times_text(const RunRecord& r) {
    std::string text;
    for (size_t p = 0; p < kTimedPhases; ++p) {
        if (!std::isfinite(r.phase_seconds[p])) continue;
        char item[64];
        std::snprintf(item, sizeof item, "%s%s %.3f", text.empty() ? "" : ", ",
                      phase_name(static_cast<stratmesh::Phase>(p)), r.phase_seconds[p]);
        text += item;
    }
    return text.empty() ? text : " (" + text + ")";
}

// The surface's ends: a closed end (a crown, a base) is meshed across to a small loop at
// its pole; an open one is the rim of the tube. Known only when every layer was recorded.
void print_ends(std::FILE* out, const RunRecord& r) {
    if (r.layers.empty() || r.layers.size() != r.report.layers.used_count) return;
    const bool bottom = r.layers.front().closed_ends & stratmesh::closed_bottom;
    const bool top = r.layers.back().closed_ends & stratmesh::closed_top;
    std::fprintf(out, "  ends       bottom %s, top %s\n", bottom ? "closed" : "open",
                 top ? "closed" : "open");
}

// Where the surface folds (triangles facing the axis): the layers, bottom up from 1, with
// their fold counts, so that a user can move the cuts or the axis there. Known only when
// every layer was recorded.
void print_folds(std::FILE* out, const RunRecord& r) {
    if (r.report.diagnostics.fold_count == 0 || r.layers.empty() || r.layers.size() != r.report.layers.used_count)
        return;
    const size_t kListed = 6;
    std::string list;
    size_t listed = 0, folding = 0;
    for (size_t k = 0; k < r.layers.size(); ++k) {
        if (r.layers[k].fold_count == 0) continue;
        ++folding;
        if (listed == kListed) continue;
        ++listed;
        const uint32_t folds = r.layers[k].fold_count;
        list += (list.empty() ? "" : ", ") + std::to_string(k + 1) + " (" +
                std::to_string(folds) + (folds == 1 ? " fold)" : " folds)");
    }
    if (folding > listed) list += ", ...";
    std::fprintf(out, "  folds      in layer%s %s of %zu, bottom up:\n"
                      "             not star-shaped around any centre tried (a branch, an "
                      "overhang):\n             the surface may bridge gaps or cross itself "
                      "there\n",
                 folding > 1 ? "s" : "", list.c_str(), r.layers.size());
}

void print_counts(std::FILE* out, const RunRecord& r) {
    const stratmesh::Report& rep = r.report;
    std::fprintf(out, "  points     %zu read: %zu used, %zu duplicates, %zu rejected%s, %zu unused\n",
                 rep.points.in_count, rep.points.used_count, rep.points.duplicate_count, rep.points.rejected_count,
                 rep.points.outlier_count ? (" (" + std::to_string(rep.points.outlier_count) + " outliers)").c_str() : "",
                 rep.points.unused_count);
    std::fprintf(out, "  layers     %zu (%zu triangulated in parallel)\n", rep.layers.used_count,
                 rep.layers.parallel_count);
    print_ends(out, r);
    std::fprintf(out, "  triangles  %zu (%zu illegal removed, %zu folds)\n", rep.triangle_count,
                 rep.diagnostics.illegal_removed_count, rep.diagnostics.fold_count);
    print_folds(out, r);
    if (rep.caps.closed_count + rep.caps.open_count > 0)
        std::fprintf(out, "  caps       %zu closed (%zu triangles), %zu left open%s\n",
                     rep.caps.closed_count, rep.caps.triangle_count, rep.caps.open_count,
                     rep.caps.wall_flip_count ? (", " + std::to_string(rep.caps.wall_flip_count) +
                                           " wall edges flipped under fins").c_str()
                                        : "");
}

// With --branches: where the cloud parts, each side's cut along the axis (as --cuts takes
// it) and its branches' point counts.
// ", 2 branches grafted (41 triangles of the trunk taken out)", or nothing.
std::string grafted_note(const stratmesh::JoinReport& j) {
    if (j.grafted_branch_count == 0) return "";
    return ", " + std::to_string(j.grafted_branch_count) + " branch" +
           (j.grafted_branch_count == 1 ? "" : "es") + " grafted (" +
           std::to_string(j.removed_triangle_count) + " triangles of the trunk taken out)";
}

void print_branches(std::FILE* out, const RunRecord& r) {
    if (!r.parting_run) return;
    const stratmesh::Parting& p = r.parting;
    if (r.parting_status != stratmesh::Status::ok) {
        std::fprintf(out, "  branches   not found: %s\n", stratmesh::status_string(r.parting_status));
        return;
    }
    auto side = [&](const char* name, double cut, const uint32_t* points, uint32_t branches) {
        if (branches == 0) return std::string(name) + ": none";
        std::string text = std::string(name) + " " + number_text(cut) + ": " +
                           std::to_string(branches) + " (";
        for (uint32_t k = 0; k < branches; ++k)
            text += (k ? ", " : "") + std::to_string(points[k]);
        return text + " points)";
    };
    std::fprintf(out, "  branches   %s; %s (gap %s)\n",
                 side("above", p.above, p.above_point_counts, p.above_branch_count).c_str(),
                 side("below", p.below, p.below_point_counts, p.below_branch_count).c_str(),
                 number_text(p.gap).c_str());
    if (p.above_branch_count + p.below_branch_count > 0 && r.split.empty())
        std::fprintf(out, "             one tube wraps branches and the gaps between them: mesh "
                          "each side apart\n             (README, \"Where the cloud parts\")\n");
}

// Where the cloud parts and the parts are meshed: each tube meshed apart.
void print_split(std::FILE* out, const RunRecord& r) {
    if (r.split.empty()) return;
    for (size_t k = 0; k < r.split.size(); ++k) {
        const RunRecord::SplitPart& part = r.split[k];
        const bool ok = part.status == stratmesh::Status::ok;
        const std::string merged =
            part.end_layers_merged == 0
                ? ""
                : " (" + std::to_string(part.end_layers_merged) + " merged into its closed end " +
                      "under the branches)";
        std::fprintf(out, "  %s %s, %zu points: %s%zu layer%s%s, %zu triangles, %zu folds\n",
                     k == 0 ? "split     " : "          ", part.name.c_str(), part.points,
                     ok ? "" : (std::string(stratmesh::status_string(part.status)) +
                                " (its points unused); ").c_str(),
                     part.layers, part.layers == 1 ? "" : "s", merged.c_str(), part.triangles,
                     part.folds);
    }
    if (!r.junction_run) return;
    const stratmesh::JoinReport& j = r.junction;
    if (r.junction_status != stratmesh::Status::ok)
        std::fprintf(out, "             not joined: %s\n", stratmesh::status_string(r.junction_status));
    else if (j.joined_side_count > 0 || j.grafted_branch_count > 0)
        std::fprintf(out, "             joined at %u side%s by %zu triangles%s%s\n", j.joined_side_count,
                     j.joined_side_count == 1 ? "" : "s", j.added_triangle_count,
                     j.apart_side_count ? " (a side left apart)" : "",
                     grafted_note(j).c_str());
    if (j.detail)
        std::fprintf(out, "             %s%s\n", j.joined_side_count ? "" : "left apart: ", j.detail);
    if (r.split_undone)
        std::fprintf(out, "             not kept: meshed as one tube instead (--split-branches "
                          "keeps the parts)\n");
}

void print_costs(std::FILE* out, const RunRecord& r) {
    if (!r.stream) // the stream triangulates in order, whatever --threads says
        std::fprintf(out, "  threads    %u\n", static_cast<unsigned>(r.threads));
    std::fprintf(out, "  time       read %s, reconstruct %s%s, %swrite %s\n",
                 seconds_text(r.read_seconds).c_str(), seconds_text(r.reconstruct_seconds).c_str(),
                 phase_times_text(r).c_str(),
                 r.parting_run ? ("branches " + seconds_text(r.branches_seconds) + ", ").c_str() : "",
                 seconds_text(r.write_seconds).c_str());
    double per_point = r.report.points.in_count ? static_cast<double>(r.workspace_bytes) /
                                                static_cast<double>(r.report.points.in_count)
                                          : 0.0;
    std::fprintf(out, "  memory     workspace %s (%zu bytes, %.0f bytes/point), triangles %s%s\n",
                 bytes_text(r.workspace_bytes).c_str(), r.workspace_bytes, per_point,
                 bytes_text(r.triangle_buffer_bytes).c_str(),
                 r.peak_rss_bytes ? (", peak resident " + bytes_text(r.peak_rss_bytes)).c_str()
                                  : "");
    if (r.stream)
        std::fprintf(out, "  stream     %zu layers pushed, at most %zu points held (of %llu)\n",
                     r.stream_pushes, r.report.points.held_count,
                     static_cast<unsigned long long>(r.stream_points));
}

} // namespace

void print_summary(std::FILE* out, const RunRecord& record) {
    std::fprintf(out, "stratmesh: %s (%s %s) -> %s (%s%s)\n", record.input_path.c_str(),
                 record.input_format.c_str(), record.input_encoding.c_str(),
                 record.output_path.c_str(), record.output_format.c_str(),
                 record.output_ascii ? " text" : "");
    print_counts(out, record);
    print_branches(out, record);
    print_split(out, record);
    print_costs(out, record);
}

} // namespace stratmesh_cli
