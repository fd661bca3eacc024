#include "report_json.h"

#include "args.h"
#include "safe_output.h"
#include "summary.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace stratmesh_cli {

namespace {

// Length of the valid UTF-8 sequence starting at s (n bytes available), 0 if invalid.
size_t utf8_length(const unsigned char* s, size_t n) {
    unsigned char c = s[0];
    size_t length = 0;
    unsigned char low = 0x80, high = 0xbf; // allowed range of the second byte
    if (c < 0x80) return 1;
    if (c >= 0xc2 && c <= 0xdf) length = 2;
    if (c >= 0xe0 && c <= 0xef) length = 3;
    if (c >= 0xf0 && c <= 0xf4) length = 4;
    if (c == 0xe0) low = 0xa0;
    if (c == 0xed) high = 0x9f;
    if (c == 0xf0) low = 0x90;
    if (c == 0xf4) high = 0x8f;
    if (length == 0 || length > n) return 0;
    if (s[1] < low || s[1] > high) return 0;
    for (size_t i = 2; i < length; ++i)
        if (s[i] < 0x80 || s[i] > 0xbf) return 0;
    return length;
}

void append_escaped_control(std::string& out, unsigned char c) {
    const char* hex = "0123456789abcdef";
    switch (c) {
    case '\n': out += "\\n"; return;
    case '\r': out += "\\r"; return;
    case '\t': out += "\\t"; return;
    case '\b': out += "\\b"; return;
    case '\f': out += "\\f"; return;
    default: break;
    }
    out += "\\u00";
    out += hex[c >> 4];
    out += hex[c & 15];
}

// A pretty-printing JSON builder: it places commas, newlines and indentation.
class JsonWriter {
public:
    void begin_object() { open('{'); }
    void end_object() { close('}'); }
    void begin_array() { open('['); }
    void end_array() { close(']'); }

    void key(std::string_view name) {
        before_value();
        out_ += json_string(name);
        out_ += ": ";
        after_key_ = true;
    }

    void number(double value) {
        before_value();
        append_number(value);
    }

    void integer(uint64_t value) { literal(std::to_string(value)); }
    void boolean(bool value) { literal(value ? "true" : "false"); }
    void null() { literal("null"); }
    void string(std::string_view text) { literal(json_string(text)); }

    // A short array of numbers, on one line.
    void numbers(const double* values, size_t count) {
        before_value();
        out_ += '[';
        for (size_t i = 0; i < count; ++i) {
            if (i > 0) out_ += ", ";
            append_number(values[i]);
        }
        out_ += ']';
    }

    // key + value in one call.
    void text_field(std::string_view name, std::string_view value) {
        key(name);
        string(value);
    }
    void number_field(std::string_view name, double value) {
        key(name);
        number(value);
    }
    void count_field(std::string_view name, uint64_t value) {
        key(name);
        integer(value);
    }
    void flag_field(std::string_view name, bool value) {
        key(name);
        boolean(value);
    }
    void numbers_field(std::string_view name, const double* values, size_t count) {
        key(name);
        numbers(values, count);
    }

    const std::string& text() const { return out_; }

private:
    // Shortest text that reads back as the same double; null for NaN and infinities.
    void append_number(double value) {
        if (!std::isfinite(value)) {
            out_ += "null";
            return;
        }
        char text[64];
        std::to_chars_result r = std::to_chars(text, text + sizeof text, value);
        out_.append(text, r.ptr);
    }

    void literal(const std::string& text) {
        before_value();
        out_ += text;
    }

    void before_value() {
        if (after_key_) {
            after_key_ = false;
            return;
        }
        if (!has_items_.empty()) {
            if (has_items_.back()) out_ += ',';
            has_items_.back() = true;
            newline();
        }
    }

    void open(char bracket) {
        before_value();
        out_ += bracket;
        has_items_.push_back(false);
    }

    void close(char bracket) {
        bool had_items = has_items_.back();
        has_items_.pop_back();
        if (had_items) newline();
        out_ += bracket;
        if (has_items_.empty()) out_ += '\n';
    }

    void newline() {
        out_ += '\n';
        out_.append(2 * has_items_.size(), ' ');
    }

    std::string out_;
    std::vector<bool> has_items_; // per open container: has it a member yet?
    bool after_key_ = false;
};

// ---- sections ----------------------------------------------------------------------------

void write_files(JsonWriter& j, const RunRecord& r) {
    j.key("input");
    j.begin_object();
    j.text_field("path", r.input_path);
    j.text_field("format", r.input_format);
    j.text_field("encoding", r.input_encoding);
    j.count_field("faces_ignored", r.input_faces_ignored);
    j.count_field("point_properties", r.point_properties);
    j.end_object();
    j.key("output");
    j.begin_object();
    j.text_field("path", r.output_path);
    j.text_field("format", r.output_format);
    j.flag_field("ascii", r.output_ascii);
    j.flag_field("written", r.output_written);
    j.count_field("point_properties", r.point_properties_carried);
    j.end_object();
}

void write_options(JsonWriter& j, const RunRecord& r) {
    j.key("options");
    j.begin_object();
    j.text_field("axis", r.axis);
    j.key("direction");
    if (r.axis == "direction")
        j.numbers(r.direction, 3);
    else
        j.null();
    j.key("cuts");
    j.numbers(r.cuts.data(), r.cuts.size());
    j.key("layers");
    if (r.layer_count > 0)
        j.integer(r.layer_count);
    else
        j.null();
    j.key("layer_height");
    j.number(r.layer_height > 0 ? r.layer_height : std::numeric_limits<double>::quiet_NaN());
    j.flag_field("skip_invalid", r.skip_invalid);
    j.flag_field("cap", r.cap);
    j.flag_field("drop_outliers", r.drop_outliers);
    j.flag_field("surface_flips", r.surface_flips);
    j.flag_field("ends_are_cuts", r.ends_are_cuts);
    j.flag_field("branches", r.find_branches);
    j.text_field("parts", parts_name(r.parts_option));
    j.count_field("threads", r.threads);
    j.flag_field("stream", r.stream);
    j.key("stream_points");
    if (r.stream)
        j.integer(r.stream_points);
    else
        j.null();
    j.key("origin");
    if (r.origin_given)
        j.numbers(r.origin, 3);
    else
        j.null();
    j.end_object();
}

// The status's name: its message up to the colon.
std::string_view status_name(stratmesh::Status status) {
    const char* message = stratmesh::status_string(status);
    const char* colon = std::strchr(message, ':');
    return colon ? std::string_view(message, size_t(colon - message)) : message;
}

void write_status(JsonWriter& j, const RunRecord& r) {
    j.text_field("status", status_name(r.status));
    j.text_field("status_message", stratmesh::status_string(r.status));
    j.key("detail");
    if (r.report.detail)
        j.string(r.report.detail);
    else
        j.null();
}

// The fit of the surface to the cloud (Report::diagnostics) and the tool's verdict on it:
// the fit null with --stream, which does not measure it; a box null when empty.
void write_box(JsonWriter& j, const char* name, bool any, const double* low, const double* high) {
    j.key(name);
    if (!any) return j.null();
    j.begin_object();
    j.numbers_field("min", low, 3);
    j.numbers_field("max", high, 3);
    j.end_object();
}

void write_fit(JsonWriter& j, const RunRecord& r) {
    const stratmesh::Diagnostics& d = r.report.diagnostics;
    j.key("fit");
    if (r.stream) {
        j.null();
    } else {
        j.begin_object();
        j.number_field("point_spacing", d.point_spacing);
        j.number_field("area_per_point", d.area_per_point);
        j.count_field("samples", d.fit_sample_count);
        j.number_field("misfit_area_fraction", d.misfit_area_fraction);
        j.number_field("misfit_area", d.misfit_area);
        write_box(j, "misfit_box", d.misfit_area > 0, d.misfit_box_min, d.misfit_box_max);
        j.count_field("crossing_pairs", d.crossing_pair_count);
        j.flag_field("crossing_check_complete", d.crossing_check_complete);
        write_box(j, "crossing_box", d.crossing_pair_count > 0, d.crossing_box_min,
                  d.crossing_box_max);
        j.end_object();
    }
    const Verdict v = judge_mesh(r);
    j.key("verdict");
    j.begin_object();
    j.text_field("class", verdict_name(v.judged));
    j.text_field("what", v.what);
    j.key("action");
    if (v.action.empty())
        j.null();
    else
        j.string(v.action);
    j.text_field("axis", v.axis);
    j.end_object();
}

void write_counts(JsonWriter& j, const RunRecord& r) {
    const stratmesh::Report& rep = r.report;
    const stratmesh::Status status = r.status;
    j.key("points");
    j.begin_object();
    j.count_field("in", rep.points.in_count);
    j.count_field("used", rep.points.used_count);
    j.count_field("duplicates", rep.points.duplicate_count);
    j.count_field("rejected", rep.points.rejected_count);
    j.count_field("outliers", rep.points.outlier_count);
    j.count_field("unused", rep.points.unused_count);
    j.key("first_invalid");
    if (status == stratmesh::Status::invalid_point)
        j.integer(rep.points.first_invalid_index);
    else
        j.null();
    j.end_object();
    j.count_field("triangles", rep.triangle_count);
    j.count_field("illegal_removed", rep.diagnostics.illegal_removed_count);
    j.count_field("folds", rep.diagnostics.fold_count);
    write_fit(j, r);
    j.key("caps");
    j.begin_object();
    j.count_field("closed", rep.caps.closed_count);
    j.count_field("left_open", rep.caps.open_count);
    j.count_field("triangles", rep.caps.triangle_count);
    j.count_field("wall_flips", rep.caps.wall_flip_count);
    j.end_object();
    j.key("axis");
    j.begin_object();
    j.numbers_field("direction", rep.axis, 3);
    j.numbers_field("origin", rep.axis_origin, 3);
    j.end_object();
    j.count_field("layer_count", rep.layers.used_count);
    j.count_field("parallel_layers", rep.layers.parallel_count);
    j.count_field("skeleton_nodes", rep.layers.skeleton_node_count);
    j.count_field("points_held", rep.points.held_count);
}

// One side of the parting: its cut and its branches' point counts, or null.
void write_parting_side(JsonWriter& j, const char* name, double cut, const uint32_t* points,
                        uint32_t branches) {
    j.key(name);
    if (branches == 0) return j.null();
    j.begin_object();
    j.number_field("cut", cut);
    j.key("points");
    j.begin_array();
    for (uint32_t k = 0; k < branches; ++k) j.integer(points[k]);
    j.end_array();
    j.end_object();
}

void write_branches(JsonWriter& j, const RunRecord& r) {
    j.key("branches");
    if (!r.parting_run) return j.null();
    const stratmesh::Parting& p = r.parting;
    j.begin_object();
    j.text_field("status", status_name(r.parting_status));
    j.number_field("gap", p.gap);
    j.numbers_field("axis", p.axis, 3);  // the cuts' axis
    write_parting_side(j, "above", p.above, p.above_point_counts, p.above_branch_count);
    write_parting_side(j, "below", p.below, p.below_point_counts, p.below_branch_count);
    j.end_object();
}

void write_split(JsonWriter& j, const RunRecord& r) {
    j.key("split");
    if (r.split.empty()) return j.null();
    j.begin_array();
    for (const RunRecord::SplitPart& part : r.split) {
        j.begin_object();
        j.text_field("part", part.name);
        j.count_field("points", part.points);
        j.text_field("status", status_name(part.status));
        j.count_field("layers", part.layers);
        j.count_field("triangles", part.triangles);
        j.count_field("folds", part.folds);
        j.count_field("end_layers_merged", part.end_layers_merged);
        j.end_object();
    }
    j.end_array();
}

void write_junction(JsonWriter& j, const RunRecord& r) {
    j.key("junction");
    if (!r.junction_run) return j.null();
    j.begin_object();
    j.text_field("status", status_name(r.junction_status));
    j.count_field("sides_joined", r.junction.joined_side_count);
    j.count_field("sides_left_apart", r.junction.apart_side_count);
    j.count_field("branches_grafted", r.junction.grafted_branch_count);
    j.count_field("triangles", r.junction.junction_triangle_count);
    j.count_field("triangles_removed", r.junction.removed_triangle_count);
    j.key("detail");
    if (r.junction.detail)
        j.string(r.junction.detail);
    else
        j.null();
    j.end_object();
}

void write_stream(JsonWriter& j, const RunRecord& r) {
    j.key("stream");
    if (!r.stream) return j.null();
    j.begin_object();
    j.count_field("pushes", r.stream_pushes);
    j.numbers_field("batch_cuts", r.batch_cuts.data(), r.batch_cuts.size());
    j.end_object();
}

void write_layer(JsonWriter& j, const stratmesh::LayerInfo& layer) {
    j.begin_object();
    j.number_field("bottom", layer.bottom);
    j.number_field("top", layer.top);
    j.numbers_field("centre", layer.centre, 3);
    j.number_field("radius", layer.radius);
    j.count_field("points", layer.point_count);
    j.count_field("triangles", layer.triangle_count);
    j.count_field("folds", layer.fold_count);
    j.flag_field("closed_bottom", layer.closed_ends & stratmesh::closed_bottom);
    j.flag_field("closed_top", layer.closed_ends & stratmesh::closed_top);
    j.end_object();
}

void write_layers(JsonWriter& j, const RunRecord& r) {
    j.key("layers");
    j.begin_array();
    for (const stratmesh::LayerInfo& layer : r.layers) write_layer(j, layer);
    j.end_array();
    j.flag_field("layers_complete", r.layers.size() == r.report.layers.used_count);
}

// The surface's ends: each one's boundary loops (their edge counts; none where it is
// closed) and whether its one loop is the small one left around a pole; null when the
// triangles were not kept (the stream without --cap).
void write_ends(JsonWriter& j, const RunRecord& r) {
    j.key("ends");
    if (!r.ends.known) {
        j.null();
        return;
    }
    j.begin_object();
    for (const auto& [name, end] : {std::pair<const char*, const SurfaceEnd*>{"bottom", &r.ends.bottom},
                                    std::pair<const char*, const SurfaceEnd*>{"top", &r.ends.top}}) {
        j.key(name);
        j.begin_object();
        j.key("loop_edges");
        j.begin_array();
        for (size_t edges : end->loop_edges) j.integer(edges);
        j.end_array();
        j.flag_field("closed", end->loop_edges.empty());
        j.flag_field("pole_loop", end->pole_loop);
        j.end_object();
    }
    j.end_object();
}

void write_costs(JsonWriter& j, const RunRecord& r) {
    j.key("seconds");
    j.begin_object();
    j.number_field("read", r.read_seconds);
    j.number_field("reconstruct", r.reconstruct_seconds);
    j.number_field("write", r.write_seconds);
    j.number_field("branches", r.branches_seconds);
    j.key("phases");
    j.begin_object();
    for (size_t p = 0; p < kTimedPhases; ++p)
        j.number_field(phase_name(static_cast<stratmesh::Phase>(p)), r.phase_seconds[p]);
    j.end_object();
    j.end_object();
    double points = static_cast<double>(r.report.points.in_count);
    j.key("memory");
    j.begin_object();
    j.count_field("workspace_bytes", r.workspace_bytes);
    j.key("workspace_bytes_per_point");
    j.number(static_cast<double>(r.workspace_bytes) / points);
    j.count_field("triangle_buffer_bytes", r.triangle_buffer_bytes);
    j.key("peak_rss_bytes");
    if (r.peak_rss_bytes > 0)
        j.integer(r.peak_rss_bytes);
    else
        j.null();
    j.end_object();
}

} // namespace

const char* phase_name(stratmesh::Phase phase) {
    // A table rather than a switch: a phase added to the library is simply unnamed here.
    const struct {
        stratmesh::Phase phase;
        const char* name;
    } names[] = {
        {stratmesh::Phase::validate, "validate"},       {stratmesh::Phase::layers, "layers"},
        {stratmesh::Phase::triangulate, "triangulate"}, {stratmesh::Phase::stitch, "stitch"},
        {stratmesh::Phase::manifold, "manifold"},       {stratmesh::Phase::done, "done"}};
    for (const auto& n : names)
        if (n.phase == phase) return n.name;
    return nullptr;
}

RunRecord::RunRecord() {
    const double unknown = std::numeric_limits<double>::quiet_NaN();
    read_seconds = reconstruct_seconds = write_seconds = branches_seconds = unknown;
    for (double& s : phase_seconds) s = unknown;
}

void RunRecord::take_parts(const stratmesh::PartCounts& parts,
                           const std::vector<stratmesh::PartInfo>& filled) {
    if (parts_option != stratmesh::Parts::one_tube && !find_branches) {
        parting_run = true;
        parting = parts.parting;
    }
    split_undone = parts.outcome == stratmesh::PartsOutcome::undone;
    const size_t count = std::min(parts.part_count, filled.size());
    for (size_t k = 0; k < count; ++k) {
        const stratmesh::PartInfo& info = filled[k];
        std::string name = "trunk";
        if (info.label >= stratmesh::kFirstBelowBranch)
            name = "branch below " + std::to_string(info.label - stratmesh::kFirstBelowBranch + 1);
        else if (info.label >= stratmesh::kFirstAboveBranch)
            name = "branch above " + std::to_string(info.label - stratmesh::kFirstAboveBranch + 1);
        split.push_back({name, info.point_count, info.status, info.layer_count,
                         info.triangle_count, info.fold_count, info.merged_end_layer_count});
    }
    // The junctions were made once the trunk was meshed.
    junction_run = count > 0 && filled[0].status == stratmesh::Status::ok;
    junction.joined_side_count = parts.joined_side_count;
    junction.apart_side_count = parts.apart_side_count;
    junction.grafted_branch_count = parts.grafted_branch_count;
    junction.junction_triangle_count = parts.junction_triangle_count;
    junction.removed_triangle_count = parts.removed_triangle_count;
}

void RunRecord::take_report(stratmesh::Report outcome,
                            std::vector<stratmesh::LayerInfo>& filled) {
    if (outcome.layers.used_count < filled.size()) filled.resize(outcome.layers.used_count);
    layers = std::move(filled);
    outcome.layers.info = nullptr; // it pointed into `filled`
    outcome.layers.info_capacity = 0;
    report = outcome;
}

std::string json_string(std::string_view text) {
    std::string out = "\"";
    const unsigned char* s = reinterpret_cast<const unsigned char*>(text.data());
    for (size_t i = 0; i < text.size();) {
        size_t length = utf8_length(s + i, text.size() - i);
        if (length == 0) {
            out += "\\ufffd";
            i += 1;
        } else if (s[i] < 0x20) {
            append_escaped_control(out, s[i++]);
        } else if (s[i] == '"' || s[i] == '\\') {
            out += '\\';
            out += static_cast<char>(s[i++]);
        } else {
            out.append(text.data() + i, length);
            i += length;
        }
    }
    return out + "\"";
}

std::string run_record_json(const RunRecord& record) {
    JsonWriter j;
    j.begin_object();
    j.text_field("tool", "stratmesh");
    j.text_field("version", STRATMESH_VERSION_STRING);
    write_files(j, record);
    write_options(j, record);
    j.flag_field("reconstructed", record.reconstructed);
    write_status(j, record);
    write_counts(j, record);
    write_layers(j, record);
    write_ends(j, record);
    // The warnings printed: a refused run's only warning is the input's faces.
    const bool meshed = record.reconstructed && record.status == stratmesh::Status::ok;
    j.key("warnings");
    j.begin_array();
    for (const std::string& warning :
         meshed ? run_warnings(record) : std::vector<std::string>{faces_warning(record)})
        if (!warning.empty()) j.string(warning);
    j.end_array();
    write_stream(j, record);
    write_branches(j, record);
    write_split(j, record);
    j.flag_field("split_undone", record.split_undone);
    write_junction(j, record);
    write_costs(j, record);
    j.end_object();
    return j.text();
}

bool write_text_file(AtomicFile& file, const std::string& text, std::string& error) {
    const bool written = std::fwrite(text.data(), 1, text.size(), file.file()) == text.size();
    return file.complete(written ? 0 : (errno != 0 ? errno : EIO), error);
}

} // namespace stratmesh_cli
