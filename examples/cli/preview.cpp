#include "preview.h"

#include "mesh_ends.h"
#include "safe_output.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <limits>

namespace stratmesh_cli {

namespace {

// Each view's drawing, in pixels, within a margin, under a line for its title.
const double kViewPixels = 480;
const double kMargin = 16;
const double kTitle = 20;
// The light's share that reaches every face, however it is turned.
const double kAmbient = 0.3;
// The layers' tints, alternating bottom up.
const double kTints[2][3] = {{0.45, 0.62, 0.92}, {0.95, 0.68, 0.38}};
const char kBoundaryColour[] = "#d01010";

double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

void cross(const double* a, const double* b, double* out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

void normalise(double* v) {
    const double length = std::sqrt(dot(v, v));
    for (size_t k = 0; k < 3; ++k) v[k] = length > 0 ? v[k] / length : 0.0;
}

// A view: `right` and `up` span the picture, `toward` points at the viewer.
struct View {
    const char* title;
    double right[3], up[3], toward[3];
};

// Front and side: `up` along the axis, `right` across it (the coordinate axis least
// aligned with it, made perpendicular), the side a quarter turn around the axis.
void make_views(const double axis[3], View views[2]) {
    size_t least = 0;
    for (size_t k = 1; k < 3; ++k)
        if (std::fabs(axis[k]) < std::fabs(axis[least])) least = k;
    double right[3] = {0, 0, 0};
    right[least] = 1;
    const double along = dot(right, axis);
    for (size_t k = 0; k < 3; ++k) right[k] -= along * axis[k];
    normalise(right);
    double toward[3];
    cross(right, axis, toward);
    views[0] = {"front", {right[0], right[1], right[2]}, {axis[0], axis[1], axis[2]},
                {toward[0], toward[1], toward[2]}};
    double side_right[3];
    cross(axis, right, side_right);
    views[1] = {"side", {side_right[0], side_right[1], side_right[2]},
                {axis[0], axis[1], axis[2]}, {right[0], right[1], right[2]}};
}

const double* corner(const MeshView& mesh, size_t t, size_t k) {
    return mesh.xyz + 3 * size_t{mesh.triangles[3 * t + k]};
}

// The triangles' corners' extent in a view, for one scale that fits both views.
struct Extent {
    double low_x = std::numeric_limits<double>::infinity(), high_x = -low_x;
    double low_y = low_x, high_y = -low_x;
    void add(double x, double y) {
        low_x = std::min(low_x, x);
        high_x = std::max(high_x, x);
        low_y = std::min(low_y, y);
        high_y = std::max(high_y, y);
    }
};

std::string colour_text(const double rgb[3]) {
    char text[8];
    int channel[3];
    for (size_t k = 0; k < 3; ++k)
        channel[k] = static_cast<int>(std::lround(255 * std::min(1.0, std::max(0.0, rgb[k]))));
    std::snprintf(text, sizeof text, "#%02x%02x%02x", channel[0], channel[1], channel[2]);
    return text;
}

// The layer a height falls in, bottom up from 0 (the last for any height above).
size_t layer_of(const std::vector<stratmesh::LayerInfo>& layers, double height) {
    if (layers.empty()) return 0;
    const auto below = std::partition_point(
        layers.begin(), layers.end() - 1,
        [height](const stratmesh::LayerInfo& layer) { return height >= layer.top; });
    return static_cast<size_t>(below - layers.begin());
}

// The text goes to the file a megabyte at a time, so that a large mesh's picture is never
// held whole.
const size_t kFlushBytes = size_t{1} << 20;

class Painter {
public:
    Painter(const MeshView& mesh, const double axis[3],
            const std::vector<stratmesh::LayerInfo>& layers, std::FILE* file)
        : mesh_(mesh), axis_(axis), layers_(layers), file_(file) {}

    // The errno of the first write that failed, 0 if none.
    int draw() {
        View views[2];
        make_views(axis_, views);
        Extent extents[2];
        for (size_t v = 0; v < 2; ++v)
            for (size_t t = 0; t < mesh_.triangle_count; ++t)
                for (size_t k = 0; k < 3; ++k)
                    extents[v].add(dot(corner(mesh_, t, k), views[v].right),
                                   dot(corner(mesh_, t, k), views[v].up));
        double largest = 0;
        for (const Extent& e : extents)
            largest = std::max({largest, e.high_x - e.low_x, e.high_y - e.low_y});
        scale_ = largest > 0 && std::isfinite(largest) ? kViewPixels / largest : 1.0;
        tint_of_.resize(mesh_.triangle_count);
        for (size_t t = 0; t < mesh_.triangle_count; ++t) {
            double centre = 0;
            for (size_t k = 0; k < 3; ++k) centre += dot(corner(mesh_, t, k), axis_) / 3;
            tint_of_[t] = static_cast<unsigned char>(layer_of(layers_, centre) % 2);
        }
        edges_ = boundary_edges(mesh_.triangles, mesh_.triangle_count);
        const double width = 2 * (kViewPixels + 2 * kMargin);
        const double height = kViewPixels + 2 * kMargin + kTitle;
        char head[320];
        std::snprintf(head, sizeof head,
                      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                      "viewBox=\"0 0 %.0f %.0f\">\n"
                      "<rect width=\"100%%\" height=\"100%%\" fill=\"#ffffff\"/>\n",
                      width, height, width, height);
        out_ = head;
        for (size_t v = 0; v < 2; ++v)
            draw_view(views[v], extents[v], static_cast<double>(v) * (kViewPixels + 2 * kMargin));
        out_ += "</svg>\n";
        flush();
        return failure_;
    }

private:
    void flush() {
        if (!out_.empty() && std::fwrite(out_.data(), 1, out_.size(), file_) != out_.size() &&
            failure_ == 0)
            failure_ = errno != 0 ? errno : EIO;
        out_.clear();
    }

    void point(const View& view, const Extent& extent, double left, const double* p) {
        // Centred across its view; both views share the scale and the top.
        const double centring = (kViewPixels - (extent.high_x - extent.low_x) * scale_) / 2;
        const double x = left + kMargin + centring + (dot(p, view.right) - extent.low_x) * scale_;
        const double y = kTitle + kMargin + (extent.high_y - dot(p, view.up)) * scale_;
        char text[64];
        std::snprintf(text, sizeof text, "%.1f,%.1f", x, y);
        out_ += text;
    }

    double shade(const View& view, size_t t) const {
        const double* a = corner(mesh_, t, 0);
        const double* b = corner(mesh_, t, 1);
        const double* c = corner(mesh_, t, 2);
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double normal[3];
        cross(u, w, normal);
        normalise(normal);
        // From in front of the viewer, a little above and to the left.
        double light[3];
        for (size_t k = 0; k < 3; ++k)
            light[k] = view.toward[k] + 0.5 * view.up[k] - 0.3 * view.right[k];
        normalise(light);
        return kAmbient + (1 - kAmbient) * std::fabs(dot(normal, light));
    }

    void draw_view(const View& view, const Extent& extent, double left) {
        char title[160];
        std::snprintf(title, sizeof title,
                      "<g><text x=\"%.0f\" y=\"%.0f\" font-family=\"sans-serif\" "
                      "font-size=\"14\">%s</text>\n",
                      left + kMargin, kTitle, view.title);
        out_ += title;
        // Far to near: the painter's algorithm, by the depth of each triangle's centre.
        std::vector<std::pair<double, size_t>> order(mesh_.triangle_count);
        for (size_t t = 0; t < mesh_.triangle_count; ++t) {
            double depth = 0;
            for (size_t k = 0; k < 3; ++k) depth += dot(corner(mesh_, t, k), view.toward);
            order[t] = {depth, t};
        }
        std::sort(order.begin(), order.end());
        for (const auto& [depth, t] : order) {
            const double light = shade(view, t);
            double rgb[3];
            for (size_t k = 0; k < 3; ++k) rgb[k] = light * kTints[tint_of_[t]][k];
            const std::string colour = colour_text(rgb);
            out_ += "<polygon points=\"";
            for (size_t k = 0; k < 3; ++k) {
                if (k) out_ += ' ';
                point(view, extent, left, corner(mesh_, t, k));
            }
            // The outline in the fill's colour closes the hairline seams between polygons.
            out_ += "\" fill=\"" + colour + "\" stroke=\"" + colour + "\" stroke-width=\"0.4\"/>\n";
            if (out_.size() >= kFlushBytes) flush();
        }
        for (uint64_t edge : edges_) {
            const double* a = mesh_.xyz + 3 * static_cast<size_t>(edge >> 32);
            const double* b = mesh_.xyz + 3 * static_cast<size_t>(edge & 0xffffffffu);
            out_ += "<polyline points=\"";
            point(view, extent, left, a);
            out_ += ' ';
            point(view, extent, left, b);
            out_ += std::string("\" fill=\"none\" stroke=\"") + kBoundaryColour +
                    "\" stroke-width=\"1.2\"/>\n";
            if (out_.size() >= kFlushBytes) flush();
        }
        out_ += "</g>\n";
    }

    const MeshView& mesh_;
    const double* axis_;
    const std::vector<stratmesh::LayerInfo>& layers_;
    double scale_ = 1;
    std::vector<unsigned char> tint_of_;
    std::vector<uint64_t> edges_;
    std::FILE* file_;
    std::string out_;
    int failure_ = 0;
};

} // namespace

bool write_preview_svg(AtomicFile& file, const MeshView& mesh, const double axis[3],
                       const std::vector<stratmesh::LayerInfo>& layers, std::string& error) {
    return file.complete(Painter(mesh, axis, layers, file.file()).draw(), error);
}

} // namespace stratmesh_cli
