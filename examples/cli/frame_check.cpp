#include "frame_check.h"

#include <cmath>
#include <cstdio>

namespace stratmesh_cli {

bool normalise_direction(double v[3]) {
    double largest = 0;
    for (size_t k = 0; k < 3; ++k) {
        if (!std::isfinite(v[k])) return false;
        largest = std::fmax(largest, std::fabs(v[k]));
    }
    if (largest == 0) return false;
    // Exact: a power of two only moves exponents (a component that falls below the
    // smallest subnormal is negligible beside the largest one, which becomes 1 to 2).
    const int exponent = std::ilogb(largest);
    for (size_t k = 0; k < 3; ++k) v[k] = std::ldexp(v[k], -exponent);
    const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (size_t k = 0; k < 3; ++k) v[k] /= length;
    return true;
}

void CloudBox::add(const double* xyz, size_t count) {
    for (size_t i = 0; i < count; ++i) {
        const double* p = xyz + 3 * i;
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
        for (size_t k = 0; k < 3; ++k) {
            lo_[k] = any_ ? std::fmin(lo_[k], p[k]) : p[k];
            hi_[k] = any_ ? std::fmax(hi_[k], p[k]) : p[k];
        }
        any_ = true;
    }
}

bool CloudBox::origin_in_reach(const double origin[3], std::string& error) const {
    if (!any_) return true;
    // Sides and distances along each axis, compared as ratios so nothing overflows: a side
    // of infinity (a box wider than the largest double) accepts any origin.
    double side = 0, distance = 0;
    for (size_t k = 0; k < 3; ++k) {
        side = std::fmax(side, hi_[k] - lo_[k]);
        distance = std::fmax(distance, std::fmax(lo_[k] - origin[k], origin[k] - hi_[k]));
    }
    if (distance <= kOriginReach * side) return true;
    char text[400];
    std::snprintf(text, sizeof text,
                  "--origin %.6g,%.6g,%.6g lies %.3g from the cloud, which spans %.3g: "
                  "give an origin within 2^32 times the cloud's size of it (or none: the "
                  "default is the cloud's centroid)",
                  origin[0], origin[1], origin[2], distance, side);
    error = text;
    return false;
}

} // namespace stratmesh_cli
