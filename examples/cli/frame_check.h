// Checks of the unrolling frame the command line asks for, made by the tool so that a
// frame the library cannot use is a usage error (exit 2) with one piece of advice, not a
// refusal of the cloud.
#ifndef STRATMESH_CLI_FRAME_CHECK_H
#define STRATMESH_CLI_FRAME_CHECK_H

#include <cstddef>
#include <string>

namespace stratmesh_cli {

// The farthest an --origin may lie from the cloud's bounding box, in multiples of the
// box's largest side (2^32). Seen from farther, the whole cloud lies within 2^-32 radians
// of one direction and its offsets from the origin keep fewer than 21 of their 53 bits
// for the cloud's own shape: no unrolling around such an origin means anything, and far
// enough out (1e300) the frame's coordinates overflow.
constexpr double kOriginReach = 4294967296.0;

// Scales `v` to unit length without overflow or underflow: first by the power of two that
// brings its largest component into [1, 2), then by its length. False if `v` is zero or
// not finite.
bool normalise_direction(double v[3]);

// The bounding box of the finite points seen so far.
class CloudBox {
public:
    void add(const double* xyz, size_t count);
    bool empty() const { return !any_; }
    // False with a message naming --origin if `origin` lies farther than kOriginReach
    // times the box's largest side from the box. An empty box passes.
    bool origin_in_reach(const double origin[3], std::string& error) const;

private:
    double lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};
    bool any_ = false;
};

} // namespace stratmesh_cli

#endif
