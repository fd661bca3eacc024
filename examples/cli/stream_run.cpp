#include "stream_run.h"

#include "cloud_io.h"
#include "mesh_ends.h"
#include "mesh_io.h"
#include "safe_output.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <vector>

namespace stratmesh_cli {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// Per-layer details kept for the report (the stream's own memory does not depend on it).
const size_t kLayerCapacity = 65536;

// The unit axis the library measures heights along, for a non-automatic axis.
void unit_axis(const stratmesh::Options& options, double axis[3]) {
    for (size_t k = 0; k < 3; ++k) axis[k] = options.direction[k];
    if (options.axis != stratmesh::Axis::direction) {
        axis[0] = axis[1] = axis[2] = 0;
        axis[static_cast<size_t>(options.axis) - static_cast<size_t>(stratmesh::Axis::x)] = 1;
    }
    double length = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (size_t k = 0; k < 3; ++k) axis[k] /= length;
}

// Whether `bytes` can be allocated now. The byte written (volatile) keeps the compiler from
// taking the allocation for unused and leaving it out.
bool can_allocate(size_t bytes) {
    if (bytes == 0) return false;
    std::unique_ptr<unsigned char[]> block(new (std::nothrow) unsigned char[bytes]);
    if (!block) return false;
    *static_cast<volatile unsigned char*>(block.get()) = 0;
    return true;
}

// Where the layers end: after the first point, the top of the layer a height falls in.
class LayerTops {
public:
    explicit LayerTops(const CommandLine& line) : cuts_(line.cuts), height_(line.layer_height) {
        std::sort(cuts_.begin(), cuts_.end());
    }

    void start(double first_height) { base_ = first_height; }

    // The least top above `height` (a point on a cut belongs to the layer above it), or
    // infinity for the last layer.
    double top_above(double height) {
        if (height_ > 0) {
            double top = base_ + height_ * (std::floor((height - base_) / height_) + 1);
            return top > height ? top : top + height_;
        }
        while (next_cut_ < cuts_.size() && cuts_[next_cut_] <= height) ++next_cut_;
        return next_cut_ < cuts_.size() ? cuts_[next_cut_] : kInfinity;
    }

    static constexpr double kInfinity = std::numeric_limits<double>::infinity();

private:
    std::vector<double> cuts_;
    double height_;
    double base_ = 0;
    size_t next_cut_ = 0;
};

class StreamRunner {
public:
    StreamRunner(const CommandLine& line, stratmesh::Options options, RunRecord& record,
                 AtomicFile& mesh)
        : line_(line), options_(options), record_(record), mesh_(mesh), tops_(line),
          layers_(kLayerCapacity) {
        // The stream refuses add_caps: --cap runs cap_ends() once it is closed.
        options_.flags &= ~static_cast<uint32_t>(stratmesh::add_caps);
        unit_axis(options_, axis_);
        report_.layers.info = layers_.data();
        report_.layers.info_capacity = layers_.size();
    }

    StreamOutcome run(std::string& error) {
        Clock::time_point start = Clock::now();
        CloudInfo info;
        std::unique_ptr<PointReader> reader = open_point_reader(line_.input, info, error);
        if (!reader) return StreamOutcome::file_error;
        // The stream never holds more points than the file has: a small file gets a small
        // workspace, whatever --stream-points allows (the library needs room for 16).
        const uint64_t most = std::max<uint64_t>(info.point_limit, 16);
        if (record_.stream_points > most) record_.stream_points = most;
        record_.input_format = cloud_format_name(info.format);
        record_.input_encoding = info.encoding;
        if (!writer_.open(mesh_, line_.output_format, line_.ascii, error))
            return StreamOutcome::file_error;
        StreamOutcome outcome = read_and_push(*reader, error);
        if (outcome == StreamOutcome::done) outcome = close(error);
        if (outcome == StreamOutcome::refused) {
            count_refused_push();
            error = advice_;
        }
        record_.take_report(report_, layers_);
        // With --cap every triangle is kept: the ends can be read off them.
        if (outcome == StreamOutcome::done && line_.cap)
            record_.ends = find_surface_ends(all_points_.data(), kept_.data(),
                                             record_.report.triangle_count, axis_,
                                             record_.layers);
        record_.read_seconds = seconds_since(start) - stream_seconds_ - write_seconds_;
        return outcome;
    }

private:
    StreamOutcome read_and_push(PointReader& reader, std::string& error) {
        double point[3];
        while (reader.next(point, error)) {
            bool valid =
                std::isfinite(point[0]) && std::isfinite(point[1]) && std::isfinite(point[2]);
            if (valid && !stream_ && !open_stream(point)) return StreamOutcome::refused;
            double height = point[0] * axis_[0] + point[1] * axis_[1] + point[2] * axis_[2];
            // Invalid points have no place in the order: they stay in the layer being read.
            if (valid) {
                if (height < highest_) {
                    error = backwards_message(height);
                    return StreamOutcome::unsorted;
                }
                if (height >= top_ && !push(top_)) return StreamOutcome::refused;
                if (height >= top_ || !std::isfinite(highest_)) top_ = tops_.top_above(height);
                highest_ = height;
            }
            layer_.insert(layer_.end(), point, point + 3);
            ++points_read_;
        }
        record_.input_faces_ignored = reader.faces_ignored();
        if (error.empty()) return StreamOutcome::done;
        error = display_name(line_.input) + ": " + error;
        return StreamOutcome::file_error;
    }

    // Opens the stream, its frame's origin at the first valid point unless --origin says.
    bool open_stream(const double first[3]) {
        if (!(options_.flags & stratmesh::origin_given))
            for (size_t k = 0; k < 3; ++k) options_.origin[k] = first[k];
        options_.flags |= stratmesh::origin_given;
        for (size_t k = 0; k < 3; ++k) record_.origin[k] = options_.origin[k];
        tops_.start(first[0] * axis_[0] + first[1] * axis_[1] + first[2] * axis_[2]);
        record_.workspace_bytes = stratmesh::stream_workspace_size(
            static_cast<size_t>(std::min<uint64_t>(record_.stream_points, SIZE_MAX)), options_);
        workspace_.reset(new (std::nothrow) unsigned char[record_.workspace_bytes]);
        record_.reconstructed = true;
        if (!workspace_ || record_.workspace_bytes == 0) {
            record_.status = stratmesh::Status::out_of_memory;
            advice_ = workspace_advice();
            return false;
        }
        record_.status = stratmesh::stream_open(options_, workspace_.get(), record_.workspace_bytes,
                                                &StreamRunner::take_triangles, this, &report_,
                                                &stream_);
        return record_.status == stratmesh::Status::ok;
    }

    // Writes the triangles as they come; with --cap, keeps them instead, to write them with
    // the caps: cap_ends() may flip the edge under a fin of the surface in place.
    static void take_triangles(void* user, const uint32_t* triangles, size_t count) {
        StreamRunner& runner = *static_cast<StreamRunner*>(user);
        if (runner.line_.cap)
            runner.kept_.insert(runner.kept_.end(), triangles, triangles + 3 * count);
        else
            runner.writer_.add_triangles(triangles, count);
    }

    // The library's counts leave out the push it refused, whose points (the first invalid
    // one among them, on invalid_point) were read all the same: they count as unused, so
    // that the counts add up and first_invalid_index is one of the points counted.
    void count_refused_push() {
        if (pushed_ <= report_.points.in_count) return;
        report_.points.unused_count += pushed_ - report_.points.in_count;
        report_.points.in_count = pushed_;
    }

    // Writes the layer's vertices (before any triangle can use them) and pushes it.
    bool push(double top) {
        if (layer_.empty()) return true;
        Clock::time_point start = Clock::now();
        writer_.add_vertices(layer_.data(), layer_.size() / 3);
        if (line_.cap) all_points_.insert(all_points_.end(), layer_.begin(), layer_.end());
        Clock::time_point pushed = Clock::now();
        write_seconds_ += std::chrono::duration<double>(pushed - start).count();
        stratmesh::Cloud cloud = {layer_.data(), layer_.size() / 3, 0, stratmesh::Scalar::float64};
        pushed_ += cloud.count;
        record_.status = stratmesh::stream_push(stream_, cloud, top);
        stream_seconds_ += seconds_since(pushed);
        if (record_.status == stratmesh::Status::out_of_memory) advice_ = layer_advice();
        ++record_.stream_pushes;
        record_.batch_cuts.push_back(top);
        layer_.clear();
        return record_.status == stratmesh::Status::ok;
    }

    StreamOutcome close(std::string& error) {
        // The last push's top only bounds its points.
        double last_top = std::isfinite(highest_) ? highest_ : 0;
        if (points_read_ > 0 && !push(last_top)) return StreamOutcome::refused;
        if (!record_.batch_cuts.empty()) record_.batch_cuts.pop_back();
        Clock::time_point start = Clock::now();
        record_.status =
            stream_ ? stratmesh::stream_close(stream_) : stratmesh::Status::too_few_points;
        stream_seconds_ += seconds_since(start);
        if (record_.status == stratmesh::Status::ok && line_.cap) record_.status = close_with_caps();
        record_.reconstruct_seconds = stream_seconds_;
        if (record_.status != stratmesh::Status::ok) return StreamOutcome::refused;
        start = Clock::now();
        bool written = writer_.finish(error);
        write_seconds_ += seconds_since(start);
        record_.write_seconds = write_seconds_;
        record_.output_written = written;
        return written ? StreamOutcome::done : StreamOutcome::file_error;
    }

    // --cap: closes the kept surface over every point read, as the run without --stream
    // does (the same frame: the cloud's, with the stream's origin), and writes the surface
    // and its caps.
    stratmesh::Status close_with_caps() {
        Clock::time_point start = Clock::now();
        const size_t n = all_points_.size() / 3, surface = kept_.size() / 3;
        const size_t bytes = stratmesh::cap_ends_workspace_size(n, surface);
        std::unique_ptr<unsigned char[]> work(new (std::nothrow) unsigned char[bytes]);
        if (!work || bytes == 0) {
            advice_ = "--cap needs " + std::to_string(bytes) + " bytes more to cap the " +
                      std::to_string(n) +
                      " points kept, which cannot be allocated: run without --cap (the stream "
                      "then holds only its layers)";
            return stratmesh::Status::out_of_memory;
        }
        kept_.resize(3 * stratmesh::reconstruct_max_triangles(n, options_));
        size_t count = surface;
        const stratmesh::Cloud cloud = {all_points_.data(), n, 0, stratmesh::Scalar::float64};
        stratmesh::Report caps = {};  // its workspace_used_bytes is the caps' alone
        const stratmesh::Status status =
            stratmesh::cap_ends(cloud, options_, work.get(), bytes, kept_.data(),
                                kept_.size() / 3, &count, &caps);
        stream_seconds_ += seconds_since(start);
        if (caps.detail) report_.detail = caps.detail;
        if (status != stratmesh::Status::ok) return status;
        writer_.add_triangles(kept_.data(), count);
        report_.caps.closed_count = caps.caps.closed_count;
        report_.caps.open_count = caps.caps.open_count;
        report_.caps.triangle_count = caps.caps.triangle_count;
        report_.caps.wall_flip_count = caps.caps.wall_flip_count;
        report_.triangle_count = count;
        return status;
    }

    // The workspace for --stream-points cannot be allocated: how many points' workspace
    // can, halving until one is (the library needs room for 16).
    std::string workspace_advice() const {
        uint64_t fits = std::min<uint64_t>(record_.stream_points, SIZE_MAX) / 2;
        while (fits >= 16 &&
               !can_allocate(stratmesh::stream_workspace_size(static_cast<size_t>(fits), options_)))
            fits /= 2;
        const std::string bytes = record_.workspace_bytes > 0
                                      ? std::to_string(record_.workspace_bytes) + " bytes"
                                      : "more bytes than the machine addresses";
        const std::string message = "the stream's workspace for --stream-points " +
                                    std::to_string(record_.stream_points) + " (" + bytes +
                                    ") cannot be allocated";
        if (fits < 16) return message + ", nor the one for 16 points: free some memory";
        return message + ": lower --stream-points to " + std::to_string(fits) +
               " or fewer (that many points' workspace can be)";
    }

    // A layer did not fit beside the points the stream holds: it needs at most the most
    // held so far and the layer's valid points.
    std::string layer_advice() const {
        size_t valid = 0;
        for (size_t i = 0; i + 2 < layer_.size(); i += 3)
            valid += std::isfinite(layer_[i]) && std::isfinite(layer_[i + 1]) &&
                     std::isfinite(layer_[i + 2]);
        const uint64_t enough = std::max<uint64_t>(report_.points.held_count + valid,
                                                   record_.stream_points + 1);
        return "--stream-points " + std::to_string(record_.stream_points) +
               " is too few for these layers (one of " + std::to_string(valid) +
               " points did not fit): raise it to at least " + std::to_string(enough);
    }

    std::string backwards_message(double height) const {
        // sort(1) sorts lines: text only, and a text PLY's header would be sorted too.
        const bool columns = record_.input_format == cloud_format_name(CloudFormat::xyz);
        return "point " + std::to_string(points_read_) + " (counting from 0) lies at height " +
               number_text(height) + " along the axis, below the point before it (" +
               number_text(highest_) +
               "): --stream needs the points sorted along the axis, lowest first (" +
               (columns ? "for example sort the columns of an XYZ file with 'sort -g -k3' for "
                          "--axis z"
                        : "write the points in that order, or convert them to XYZ columns and "
                          "sort those") +
               "), or run without --stream";
    }

    static std::string number_text(double value) {
        char text[32];
        std::snprintf(text, sizeof text, "%.17g", value);
        return text;
    }

    const CommandLine& line_;
    stratmesh::Options options_;
    RunRecord& record_;
    AtomicFile& mesh_;
    LayerTops tops_;
    double axis_[3];
    MeshStreamWriter writer_;
    std::unique_ptr<unsigned char[]> workspace_;
    stratmesh::Stream* stream_ = nullptr;
    stratmesh::Report report_ = {};
    std::vector<stratmesh::LayerInfo> layers_;
    std::vector<double> layer_; // the points of the layer being read, x y z packed
    std::vector<double> all_points_; // with --cap: every point pushed, x y z packed
    std::vector<uint32_t> kept_;     // with --cap: every triangle emitted
    double top_ = LayerTops::kInfinity;
    double highest_ = -LayerTops::kInfinity; // the height of the last finite point
    size_t points_read_ = 0;
    size_t pushed_ = 0; // points handed to stream_push, refused ones too
    double stream_seconds_ = 0, write_seconds_ = 0;
    std::string advice_;       // out_of_memory: what to do about the stream's memory
};

} // namespace

StreamOutcome run_stream(const CommandLine& line, stratmesh::Options options, RunRecord& record,
                         AtomicFile& mesh, std::string& error) {
    record.stream = true;
    record.stream_points = line.stream_points;
    return StreamRunner(line, options, record, mesh).run(error);
}

} // namespace stratmesh_cli
