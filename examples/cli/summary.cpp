#include "summary.h"

#include "safe_output.h"

#include <cctype>
#include <cmath>
#include <cstring>
#include <string>

namespace stratmesh_cli {

std::string in_tool_words(const char* library_sentence) {
    static const struct {
        const char* library;
        const char* tool;
    } kWords[] = {{"drop_outliers", "--drop-outliers"}, {"skip_invalid_points", "--skip-invalid"},
                  {"add_caps", "--cap"}, {"ends_are_cuts", "--ends-are-cuts"},
                  {"surface_flips", "--surface-flips"}};
    std::string text = library_sentence ? library_sentence : "";
    for (const auto& w : kWords) {
        const std::string from = w.library;
        for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
            const bool word_start = at == 0 || !(std::isalnum(static_cast<unsigned char>(text[at - 1])) || text[at - 1] == '_');
            const size_t end = at + from.size();
            const bool word_end = end == text.size() || !(std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_');
            if (word_start && word_end) {
                text.replace(at, from.size(), w.tool);
                at += std::strlen(w.tool);
            } else {
                at = end;
            }
        }
    }
    return text;
}

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

std::string plural(size_t count, const char* one, const char* many) {
    return std::to_string(count) + " " + (count == 1 ? one : many);
}

std::string file_name(const std::string& path, const char* stream) {
    return path == kStandardStream ? stream : path;
}

// "bottom closed", "top open: a pole loop of 6 edges", from the boundary loops.
std::string end_text(const char* name, const SurfaceEnd& end) {
    const std::vector<size_t>& loops = end.loop_edges;
    std::string text = std::string(name) + " ";
    if (loops.empty()) return text + "closed";
    if (end.pole_loop) return text + "open: a pole loop of " + plural(loops[0], "edge", "edges");
    if (loops.size() == 1) return text + "open (a rim of " + plural(loops[0], "edge", "edges") + ")";
    text += "open: " + std::to_string(loops.size()) + " loops (";
    for (size_t k = 0; k < loops.size(); ++k) text += (k ? ", " : "") + std::to_string(loops[k]);
    return text + " edges)";
}

std::string ends_text(const RunRecord& r) {
    if (!r.ends.known) return "ends not checked (--stream keeps the triangles only with --cap)";
    return "ends: " + end_text("bottom", r.ends.bottom) + ", " + end_text("top", r.ends.top);
}

// Why the library used fewer layers than it planned: the planned layers that held too few
// points, when the tool could count them, and its other rules, in the words of
// LayerCounts::planned_count (Options in stratmesh.h says each).
std::string merge_reason(const RunRecord& r) {
    const std::string fewest = "under " + std::to_string(stratmesh::kMinLayerPoints) + " points";
    if (!r.range_known) return "merged where a layer held " + fewest + ", or was thin, open or folding";
    if (r.sparse_planned_layers == 0)
        return "merged where a layer was thin, open or folding (none held " + fewest + ")";
    return "merged where a layer held " + fewest + " (" + std::to_string(r.sparse_planned_layers) +
           " did), or was thin, open or folding";
}

// "18 of 100000 asked (30000 planned: at most one a point); merged where ...", "4 as
// asked", "4 (about --layer-height 30 high)", "7 (automatic)".
std::string layers_text(const RunRecord& r) {
    const size_t used = r.report.layers.used_count, planned = r.report.layers.planned_count;
    std::string text = std::to_string(used);
    size_t asked = 0;
    std::string why_planned;
    if (r.layer_count > 0) {
        asked = r.layer_count;
        why_planned = "at most one a point";
    } else if (!r.cuts.empty()) {
        asked = r.cuts.size() + 1;
        why_planned = "cuts outside the cloud or repeated are dropped";
    } else if (r.layer_height > 0) {
        // As many as the height takes: the plan is what was asked.
        if (used >= planned) return text + " (about --layer-height " + number_text(r.layer_height) + " high)";
        return text + " of " + std::to_string(planned) + " planned by --layer-height " +
               number_text(r.layer_height) + "; " + merge_reason(r);
    }
    if (asked == 0) {
        if (used >= planned) return text + " (automatic)";
        return text + " (automatic: " + std::to_string(planned) + " planned; " + merge_reason(r) +
               ")";
    }
    if (asked == used) return text + " as asked";
    text += " of " + std::to_string(asked) + " asked";
    if (planned != asked) text += " (" + std::to_string(planned) + " planned: " + why_planned + ")";
    if (used < planned) text += "; " + merge_reason(r);
    return text;
}

std::string caps_text(const stratmesh::Report& rep) {
    if (rep.caps.closed_count + rep.caps.open_count == 0) return "";
    std::string text = ", caps: " + std::to_string(rep.caps.closed_count) + " closed (" +
                       plural(rep.caps.triangle_count, "triangle", "triangles") + "), " +
                       std::to_string(rep.caps.open_count) + " left open";
    if (rep.caps.wall_flip_count)
        text += ", " + std::to_string(rep.caps.wall_flip_count) + " wall edges flipped under fins";
    return text;
}

void print_counts(std::FILE* out, const RunRecord& r) {
    const stratmesh::Report& rep = r.report;
    const std::string outliers =
        rep.points.outlier_count ? " (" + std::to_string(rep.points.outlier_count) + " outliers)"
                                 : "";
    std::fprintf(out, "  points     %zu read: %zu used, %zu duplicates, %zu rejected%s, %zu unused\n",
                 rep.points.in_count, rep.points.used_count, rep.points.duplicate_count,
                 rep.points.rejected_count, outliers.c_str(), rep.points.unused_count);
    std::fprintf(out, "  layers     %s\n", layers_text(r).c_str());
    std::fprintf(out, "  triangles  %zu%s; %s\n", rep.triangle_count, caps_text(rep).c_str(),
                 ends_text(r).c_str());
}

// ---- warnings ----------------------------------------------------------------------------

// Where the surface folds (triangles facing the axis): the layers, bottom up from 1, with
// their fold counts, so that a user can move the cuts or the axis there. The layers are
// named only when every layer was recorded.
std::string folds_warning(const RunRecord& r) {
    const size_t folds = r.report.diagnostics.fold_count;
    if (folds == 0) return "";
    std::string text = plural(folds, "triangle folds", "triangles fold") + " (facing the axis)";
    if (!r.layers.empty() && r.layers.size() == r.report.layers.used_count) {
        const size_t kListed = 6;
        std::string list;
        size_t listed = 0, folding = 0;
        for (size_t k = 0; k < r.layers.size(); ++k) {
            if (r.layers[k].fold_count == 0) continue;
            ++folding;
            if (listed == kListed) continue;
            ++listed;
            list += (list.empty() ? "" : ", ") + std::to_string(k + 1) + " (" +
                    plural(r.layers[k].fold_count, "fold", "folds") + ")";
        }
        if (folding > listed) list += ", ...";
        if (folding > 0)
            text += " in layer" + std::string(folding > 1 ? "s " : " ") + list + " of " +
                    std::to_string(r.layers.size()) + ", bottom up";
    }
    return text + ": not star-shaped around any centre tried (a branch, an overhang)";
}

// "above 12.5: 2 (750, 740 points); below: none (gap 0.8)".
std::string parting_text(const stratmesh::Parting& p) {
    auto side = [](const char* name, double cut, const uint32_t* points, uint32_t branches) {
        if (branches == 0) return std::string(name) + ": none";
        std::string text = std::string(name) + " " + number_text(cut) + ": " +
                           std::to_string(branches) + " (";
        for (uint32_t k = 0; k < branches; ++k)
            text += (k ? ", " : "") + std::to_string(points[k]);
        return text + " points)";
    };
    // The cuts are positions along the parting's axis, which may lean from the run's where
    // the cut was squared to the trunk: given as --axis takes it.
    const std::string along = p.above_branch_count + p.below_branch_count == 0
                                  ? ""
                                  : ", cuts along " + number_text(p.axis[0]) + "," +
                                        number_text(p.axis[1]) + "," + number_text(p.axis[2]);
    return side("above", p.above, p.above_point_counts, p.above_branch_count) + "; " +
           side("below", p.below, p.below_point_counts, p.below_branch_count) + " (gap " +
           number_text(p.gap) + along + ")";
}

bool branches_found(const RunRecord& r) {
    return r.parting_run && r.parting_status == stratmesh::Status::ok &&
           r.parting.above_branch_count + r.parting.below_branch_count > 0;
}

// Branches left apart from the trunk: the surface is in pieces. (One tube around branches
// is judged by the verdict, whose fit measure sees the gaps it spans.)
std::string branches_warning(const RunRecord& r) {
    if (!branches_found(r) || r.split.empty() || r.split_undone) return "";
    const std::string where = parting_text(r.parting);
    if (r.junction.apart_side_count > 0 || r.junction_status != stratmesh::Status::ok)
        return "branches left apart from the trunk, not joined (" + where +
               "): the surface is in pieces (--verbose says why)";
    return "";
}

// Points that are no vertex of the surface, though not merged into a duplicate: rejected
// (NaN or infinite with --skip-invalid, outliers with --drop-outliers) or unused (the
// library's detail says why). They stay in the output, used by no triangle.
std::string left_out_warning(const RunRecord& r) {
    const stratmesh::PointCounts& p = r.report.points;
    const size_t invalid = p.rejected_count - p.outlier_count;
    if (p.rejected_count + p.unused_count == 0) return "";
    std::string parts;
    auto add = [&parts](size_t count, const std::string& what) {
        if (count) parts += (parts.empty() ? "" : ", ") + std::to_string(count) + " " + what;
    };
    add(invalid, "invalid (--skip-invalid)");
    add(p.outlier_count, p.outlier_count == 1 ? "outlier (--drop-outliers)" : "outliers (--drop-outliers)");
    add(p.unused_count, "unused");
    std::string text = plural(p.rejected_count + p.unused_count, "point", "points") +
                       " left out of the mesh (in the output, used by no triangle): " + parts;
    if (p.unused_count && r.report.detail) text += "; " + in_tool_words(r.report.detail);
    return text;
}

std::string caps_warning(const RunRecord& r) {
    if (r.report.caps.open_count == 0) return "";
    return plural(r.report.caps.open_count, "boundary loop", "boundary loops") +
           " could not be capped: the surface is not closed there";
}

std::string cuts_warning(const RunRecord& r) {
    if (r.cuts_outside.empty()) return "";
    std::string list;
    for (double cut : r.cuts_outside) list += (list.empty() ? "" : ",") + number_text(cut);
    return "--cuts " + list + (r.cuts_outside.size() == 1 ? " lies" : " lie") +
           " outside the cloud's range along the axis (" + number_text(r.range_low) + " to " +
           number_text(r.range_high) + "): ignored";
}

// ---- details, with --verbose -------------------------------------------------------------

// ", 2 branches grafted (41 triangles of the trunk taken out)", or nothing.
std::string grafted_note(const stratmesh::JoinReport& j) {
    if (j.grafted_branch_count == 0) return "";
    return ", " + std::to_string(j.grafted_branch_count) + " branch" +
           (j.grafted_branch_count == 1 ? "" : "es") + " grafted (" +
           std::to_string(j.removed_triangle_count) + " triangles of the trunk taken out)";
}

// Where the cloud parts: each side's cut along the axis (as --cuts takes it) and its
// branches' point counts.
void print_branches(std::FILE* out, const RunRecord& r) {
    if (!r.parting_run) return;
    if (r.parting_status != stratmesh::Status::ok)
        std::fprintf(out, "  branches   not found: %s\n", stratmesh::status_string(r.parting_status));
    else
        std::fprintf(out, "  branches   %s\n", parting_text(r.parting).c_str());
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
        std::fprintf(out, "             joined at %zu side%s by %zu triangles%s%s\n", j.joined_side_count,
                     j.joined_side_count == 1 ? "" : "s", j.junction_triangle_count,
                     j.apart_side_count ? " (a side left apart)" : "",
                     grafted_note(j).c_str());
    if (j.detail)
        std::fprintf(out, "             %s%s\n", j.joined_side_count ? "" : "left apart: ", j.detail);
    if (r.split_undone)
        std::fprintf(out, "             not kept%s%s: meshed as one tube instead (--parts apart "
                          "keeps the parts)\n",
                     r.report.detail ? ", " : "", in_tool_words(r.report.detail).c_str());
}

void print_costs(std::FILE* out, const RunRecord& r) {
    // The jobs triangulate planned layers ahead of the chain, which merges some: counted
    // against the planned layers. The stream triangulates in order, whatever --threads says.
    const stratmesh::LayerCounts& layers = r.report.layers;
    if (!r.stream && layers.parallel_count == 0)
        std::fprintf(out, "  threads    %u (the layers triangulated in order)\n",
                     static_cast<unsigned>(r.threads));
    else if (!r.stream)
        std::fprintf(out, "  threads    %u (jobs triangulated %zu of the %zu planned layers)\n",
                     static_cast<unsigned>(r.threads), layers.parallel_count, layers.planned_count);
    std::fprintf(out, "  time       read %s, reconstruct %s%s, %swrite %s\n",
                 seconds_text(r.read_seconds).c_str(), seconds_text(r.reconstruct_seconds).c_str(),
                 phase_times_text(r).c_str(),
                 std::isfinite(r.branches_seconds)
                     ? ("branches " + seconds_text(r.branches_seconds) + ", ").c_str()
                     : "",
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

std::string faces_warning(const RunRecord& record) {
    if (record.input_faces_ignored == 0) return "";
    return plural(static_cast<size_t>(record.input_faces_ignored), "face", "faces") + " in " +
           file_name(record.input_path, "standard input") +
           " ignored: the points alone are meshed";
}

std::vector<std::string> run_warnings(const RunRecord& record) {
    std::vector<std::string> warnings;
    for (const std::string& warning :
         {branches_warning(record), left_out_warning(record), caps_warning(record),
          faces_warning(record), cuts_warning(record)})
        if (!warning.empty()) warnings.push_back(warning);
    return warnings;
}

void print_warnings(std::FILE* out, const std::vector<std::string>& warnings) {
    for (const std::string& warning : warnings)
        std::fprintf(out, "stratmesh: warning: %s\n", warning.c_str());
}

// ", 7 point properties carried" (of those read), or nothing.
std::string properties_text(const RunRecord& r) {
    if (r.point_properties == 0) return "";
    std::string text = ", " + std::to_string(r.point_properties_carried);
    if (r.point_properties_carried != r.point_properties)
        text += " of " + std::to_string(r.point_properties);
    return text + (r.point_properties == 1 ? " point property carried" : " point properties carried");
}

// With --verbose: what the library settled on its way, which the verdict weighs.
void print_settled(std::FILE* out, const RunRecord& r) {
    const std::string folds = folds_warning(r);
    if (!folds.empty()) std::fprintf(out, "  folds      %s\n", folds.c_str());
    if (branches_found(r) && r.split.empty())
        std::fprintf(out, "  one tube   around the branches, %s\n", parting_text(r.parting).c_str());
}

void print_summary(std::FILE* out, const RunRecord& record, const Verdict& verdict,
                   size_t warning_count, bool verbose) {
    std::fprintf(out, "stratmesh: %s (%s %s) -> %s (%s%s%s)\n",
                 file_name(record.input_path, "standard input").c_str(),
                 record.input_format.c_str(), record.input_encoding.c_str(),
                 file_name(record.output_path, "standard output").c_str(),
                 record.output_format.c_str(), record.output_ascii ? " text" : "",
                 properties_text(record).c_str());
    print_counts(out, record);
    if (verbose) {
        print_settled(out, record);
        print_branches(out, record);
        print_split(out, record);
        print_costs(out, record);
    }
    if (warning_count == 0)
        std::fprintf(out, "  warnings   none\n");
    else
        std::fprintf(out, "  warnings   %zu, below\n", warning_count);
    std::fprintf(out, "  verdict    %s\n", verdict_text(verdict, record).c_str());
}

} // namespace stratmesh_cli
