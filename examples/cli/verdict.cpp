#include "verdict.h"

#include "stratmesh.h"

#include <cmath>
#include <cstdio>

namespace stratmesh_cli {
namespace {

std::string number(double value, int digits = 6) {
    char text[32];
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    return text;
}

std::string box_text(const double* low, const double* high) {
    const char* names[] = {"x", "y", "z"};
    std::string box;
    for (int k = 0; k < 3; ++k)
        box += std::string(k ? " " : "") + names[k] + " [" + number(low[k]) + ", " +
               number(high[k]) + "]";
    return box;
}

// "z" or "-x" along a coordinate axis, else the direction as --axis takes it.
std::string axis_name(const double* axis) {
    const char* names[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k)
        if (std::fabs(axis[k]) == 1) return std::string(axis[k] < 0 ? "-" : "") + names[k];
    return number(axis[0], 4) + "," + number(axis[1], 4) + "," + number(axis[2], 4);
}

std::string percent(double fraction) {
    char text[32];
    std::snprintf(text, sizeof text, fraction < 0.1 ? "%.1f%%" : "%.0f%%", 100 * fraction);
    return text;
}

} // namespace

const char* verdict_name(Verdict::Class judged) {
    switch (judged) {
    case Verdict::good: return "good";
    case Verdict::poor: return "poor";
    default: return "not measured";
    }
}

Verdict judge_mesh(const RunRecord& r) {
    Verdict v;
    v.axis = axis_name(r.report.axis);
    const stratmesh::Diagnostics& d = r.report.diagnostics;
    if (r.status != stratmesh::Status::ok) {
        v.what = "no mesh";
        return v;
    }
    if (r.stream) {
        v.what = "--stream holds a window of the points, never the whole surface";
        return v;
    }
    if (d.fit_sample_count == 0) {
        v.what = "no triangle to measure";
        return v;
    }
    const bool misfit = d.misfit_area_fraction > stratmesh::kPoorMisfitFraction;
    if (!misfit && d.crossing_pair_count == 0) {
        v.judged = Verdict::good;
        const std::string crossings =
            d.crossing_check_complete ? "no crossing triangles"
            : r.report.triangle_count > stratmesh::kCrossingCheckLimit
                ? "crossings not checked (over " + std::to_string(stratmesh::kCrossingCheckLimit) +
                      " triangles)"
                : "no crossing triangles among those checked";
        v.what = "the surface follows the cloud, " + percent(d.misfit_area_fraction) +
                 " of its area off it, " + crossings;
        return v;
    }
    v.judged = Verdict::poor;
    if (misfit)
        v.what = percent(d.misfit_area_fraction) +
                 " of the surface does not follow the cloud (it folds across it or spans gaps), within " +
                 box_text(d.misfit_box_min, d.misfit_box_max);
    if (d.crossing_pair_count > 0)
        v.what += std::string(misfit ? "; " : "") + std::to_string(d.crossing_pair_count) +
                  (d.crossing_pair_count == 1 ? " pair" : " pairs") +
                  " of triangles cross, within " + box_text(d.crossing_box_min, d.crossing_box_max);
    // An axis the user chose may be the wrong one; the automatic axis already tried the
    // candidates, and then the object is no column for this method.
    if (r.axis != "automatic")
        v.action = "try --axis auto, which picks the direction along which the cloud is most "
                   "like a column";
    else if (r.report.layers.skeleton_node_count > 0)
        v.action = "its skeleton straightens it badly there (a wide end, a tight turn): try "
                   "--parts one-tube, or a method for general surfaces";
    else
        v.action = "the object is not one column along any axis (it bends, branches or folds "
                   "back), which this method cannot follow: mesh its parts apart or use a "
                   "method for general surfaces";
    return v;
}

std::string verdict_text(const Verdict& v, const RunRecord& r) {
    const size_t nodes = r.report.layers.skeleton_node_count;
    const std::string along = nodes > 0 ? "along its bent skeleton (" + std::to_string(nodes) + " nodes)"
                                        : "axis " + v.axis;
    const std::string used = along + ", " + std::to_string(r.report.layers.used_count) +
                             (r.report.layers.used_count == 1 ? " layer" : " layers");
    std::string text = std::string(verdict_name(v.judged)) + ": " + v.what + "; " + used;
    if (v.judged == Verdict::poor) text += ": " + v.action;
    return text;
}

} // namespace stratmesh_cli
