// The reconstruction harness's structure-aware mutator. It reads an input's cloud as
// read_cloud() does, reshapes it as sensors and their pipelines shape clouds, and writes it
// back with write_cloud(), the bytes after the cloud (the harness's options) kept as they
// were: the result is an ordinary input, which the replay driver runs without the mutator.
//
// New clouds: rings (a scanner's rows around a column, the radius varying along it, each
// ring's first point turned a little further, the column along x, y, z or tilted) and forks
// (a trunk of rings under two arms of more than kSmallestBranch points each, which the
// branch search parts). Changes to a cloud: exact duplicates; coordinates snapped to a
// coarse grid, some then nudged by an ulp (near-coplanar and near-collinear sets); a ring
// of points exactly on a circle (the integer points of x^2 + y^2 = r^2), some nudged by an
// ulp; points in layers (the axis coordinate snapped to a few rows); extreme scales (the
// cloud or a run of its points times 2^-1000 to 2^1000, 1e-300 or 1e300); NaN and
// infinite coordinates; a few far outliers; a copy of a run of points far away (clusters
// apart); a collinear run; points removed or reordered; noise; a large offset; float32 or
// float64 and the stride's padding. The cross-over puts a run of one input's points into
// the other's cloud, in place or far away. New points go among the first `front` points,
// the ones that every run of the harness meshes (most mesh only those), and new clouds
// are often no larger.
#ifndef STRATMESH_FUZZ_CLOUD_MUTATOR_H
#define STRATMESH_FUZZ_CLOUD_MUTATOR_H

#include "fuzz_cloud.h"
#include "fuzz_common.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <vector>

namespace stratmesh_fuzz {

// The reconstruction harness's clouds: fewer than kReconstructMaxPoints points (room for a
// fork: two branches of kSmallestBranch points and a trunk), of which most runs mesh only the
// first kReconstructQuickPoints (fuzz_reconstruct.cpp says why).
const uint32_t kReconstructMaxPoints = 256;
const size_t kReconstructQuickPoints = 32;

// An input as the mutator sees it: its cloud and the bytes after it.
struct SplitInput {
    CloudSpec spec;
    std::vector<uint8_t> rest;
};

inline SplitInput split_input(const uint8_t* data, size_t size, uint32_t max_points) {
    Bytes in(data, size);
    SplitInput s;
    s.spec = spec_of(read_cloud(in, max_points));
    s.rest.assign(data + in.position(), data + size);
    return s;
}

// Writes `s` into out[0, max_size), with as many of its points as fit below max_points and
// in max_size, and as much of the rest as fits after them; returns the size written.
inline size_t write_input(SplitInput& s, uint8_t* out, size_t max_size, uint32_t max_points) {
    const size_t point_bytes = 1 + 3 * (s.spec.f32 ? 4 : 8);
    const size_t header_bytes = 8;
    if (max_size < header_bytes) return 0;
    const size_t fit = std::min<size_t>({s.spec.count(), max_points - 1, (max_size - header_bytes) / point_bytes});
    s.spec.xyz.resize(3 * fit);
    settle(s.spec);
    std::vector<uint8_t> bytes;
    write_cloud(s.spec, bytes);
    const size_t rest = std::min(s.rest.size(), max_size - bytes.size());
    bytes.insert(bytes.end(), s.rest.begin(), s.rest.begin() + static_cast<std::ptrdiff_t>(rest));
    std::copy(bytes.begin(), bytes.end(), out);
    return bytes.size();
}

namespace cloud_mutator {

using Points = std::vector<double>;

const double kPi = 3.14159265358979323846;

// The most points a cloud may have, and how many first points every run meshes.
struct Limits {
    size_t room;
    size_t front;
};

inline size_t count(const Points& p) { return p.size() / 3; }

// The middle of the finite coordinates' box and its largest half-width (1 if none).
struct Frame {
    double centre[3] = {0, 0, 0};
    double extent = 1;
};

inline Frame frame_of(const Points& p) {
    Frame f;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (size_t i = 0; i < p.size(); ++i) {
        if (!std::isfinite(p[i])) continue;
        lo[i % 3] = std::min(lo[i % 3], p[i]);
        hi[i % 3] = std::max(hi[i % 3], p[i]);
    }
    double extent = 0;
    for (size_t k = 0; k < 3; ++k) {
        if (lo[k] > hi[k]) continue;
        f.centre[k] = lo[k] / 2 + hi[k] / 2;
        extent = std::max(extent, hi[k] / 2 - lo[k] / 2);
    }
    if (extent > 0 && std::isfinite(extent)) f.extent = extent;
    return f;
}

// A unit vector in a random direction.
inline void direction(Random& r, double d[3]) {
    double length = 0;
    while (!(length > 1e-3)) {
        for (size_t k = 0; k < 3; ++k) d[k] = 2 * r.uniform() - 1;
        length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
    for (size_t k = 0; k < 3; ++k) d[k] /= length;
}

// 2^e for e in [lo, hi].
inline double power_of_two(Random& r, int lo, int hi) {
    return std::ldexp(1.0, static_cast<int>(r.between(lo, hi)));
}

// Turns a column along z onto x or y, or tilts it by a random rotation.
inline void orient(Points& p, Random& r) {
    const size_t how = r.below(4);
    if (how == 0) return;
    if (how < 3) {
        for (double* q = p.data(); q < p.data() + p.size(); q += 3) std::rotate(q, q + how, q + 3);
        return;
    }
    double q[4];  // a random unit quaternion
    double length = 0;
    while (!(length > 1e-3)) {
        for (double& v : q) v = 2 * r.uniform() - 1;
        length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    }
    for (double& v : q) v /= length;
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                         2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    for (size_t i = 0; i < count(p); ++i) {
        const double a[3] = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
        for (size_t k = 0; k < 3; ++k) p[3 * i + k] = m[3 * k] * a[0] + m[3 * k + 1] * a[1] + m[3 * k + 2] * a[2];
    }
}

// One ring of `per_ring` points around (cx, cy) at height z, its first point turned by
// `turn` of a step.
inline void add_ring(Points& p, size_t per_ring, double cx, double cy, double radius, double z, double turn) {
    for (size_t j = 0; j < per_ring; ++j) {
        const double a = 2 * kPi * (static_cast<double>(j) + turn) / static_cast<double>(per_ring);
        p.insert(p.end(), {cx + radius * std::cos(a), cy + radius * std::sin(a), z});
    }
}

// A scanner's rows around a column, at most `budget` points (none if fewer than 6 fit).
inline Points rings(Random& r, size_t budget) {
    size_t per_ring = 3 + r.below(46);
    size_t ring_count = 2 + r.below(30);
    while (ring_count * per_ring > budget && ring_count > 2) --ring_count;
    while (ring_count * per_ring > budget && per_ring > 3) --per_ring;
    Points p;
    if (ring_count * per_ring > budget) return p;
    const double radius = 0.5 + 4 * r.uniform();
    const double spacing = radius * (0.02 + r.uniform());
    const double bulge = r.below(2) ? 0.0 : r.uniform() / 2;   // a vase's profile
    const double taper = r.below(2) ? 0.0 : (r.uniform() - 0.5) / static_cast<double>(ring_count);
    const double stagger = r.uniform();
    const double noise = r.below(3) ? 0.0 : radius * 1e-3 * r.uniform();
    for (size_t k = 0; k < ring_count; ++k) {
        const double along = static_cast<double>(k) / static_cast<double>(ring_count);
        const double rk = radius * (1 + taper * static_cast<double>(k) + bulge * std::sin(kPi * along));
        add_ring(p, per_ring, 0, 0, rk, spacing * static_cast<double>(k), stagger * static_cast<double>(k));
    }
    for (double& v : p) v += noise * (r.uniform() - 0.5);
    orient(p, r);
    return p;
}

// A trunk under two arms of more than kSmallestBranch points each, at most `budget` points
// in all (none if they do not fit), spaced as find_parting() needs to part them: the arms'
// rings (of radius 1) hold their points a chord c apart, so the linking gap is 4 c; the
// arms stand more than 5 c apart, and rise over 16 c (four gaps) in rings under 4 c apart.
inline Points fork(Random& r, size_t budget) {
    const size_t per_ring = 6 + r.below(5);
    const double chord = 2 * kPi / static_cast<double>(per_ring);
    size_t arm_rings = (stratmesh::kSmallestBranch + per_ring - 1) / per_ring + 1 + r.below(3);
    const double spacing = chord * (2.5 + r.uniform());
    const double apart = 1 + chord * (2.6 + r.uniform());  // each arm's axis from the trunk's
    const double lean = r.uniform() / 4;                  // the arms' slope away from each other
    const double trunk_radius = apart + 1;
    const size_t trunk_per_ring = static_cast<size_t>(std::ceil(2 * kPi * trunk_radius / chord));
    const size_t trunk_rings = 1 + r.below(3);
    while (2 * per_ring * arm_rings + trunk_per_ring * trunk_rings > budget &&
           per_ring * (arm_rings - 1) > stratmesh::kSmallestBranch)
        --arm_rings;
    Points p;
    if (2 * per_ring * arm_rings + trunk_per_ring * trunk_rings > budget) return p;
    for (size_t k = trunk_rings; k > 0; --k)
        add_ring(p, trunk_per_ring, 0, 0, trunk_radius, -spacing * static_cast<double>(k), 0.5 * static_cast<double>(k));
    for (double side : {-1.0, 1.0})
        for (size_t k = 0; k < arm_rings; ++k) {
            const double z = spacing * static_cast<double>(k);
            add_ring(p, per_ring, side * (apart + lean * z), 0, 1, z, 0.5 * static_cast<double>(k));
        }
    orient(p, r);
    return p;
}

// ---- changes to a cloud; each returns false where it does not apply

// A random point index among the first `front` (and at most count(p)).
inline size_t in_front(const Points& p, Random& r, size_t front) {
    return r.below(std::min(count(p), front) + 1);
}

// New points put in at a random place among the first `front`.
inline void place(Points& p, const Points& added, Random& r, size_t front) {
    p.insert(p.begin() + static_cast<std::ptrdiff_t>(3 * in_front(p, r, front)), added.begin(), added.end());
}

// Copies of some points, each put at a random place.
inline bool duplicate(Points& p, Random& r, size_t front) {
    if (p.empty()) return false;
    const size_t copies = 1 + r.below(std::max<size_t>(1, std::min(count(p), front) / 4));
    for (size_t c = 0; c < copies; ++c) {
        const size_t from = r.below(count(p));
        place(p, Points(p.begin() + static_cast<std::ptrdiff_t>(3 * from), p.begin() + static_cast<std::ptrdiff_t>(3 * from + 3)), r, front);
    }
    return true;
}

// v moved by an ulp up or down: a double's, or a float's (which a float32 cloud keeps).
inline double nudge(double v, Random& r) {
    const bool up = r.below(2) != 0;
    if (r.below(2)) return std::nextafter(v, up ? HUGE_VAL : -HUGE_VAL);
    const double f = as_float(v);
    if (!std::isfinite(f)) return v;
    return static_cast<double>(std::nextafter(static_cast<float>(f), up ? HUGE_VALF : -HUGE_VALF));
}

// Every finite coordinate snapped to a grid a few times coarser than the cloud's spacing,
// then some nudged by an ulp.
inline bool snap(Points& p, Random& r) {
    if (p.empty()) return false;
    const Frame f = frame_of(p);
    const double step = std::ldexp(1.0, std::ilogb(f.extent) - static_cast<int>(r.between(1, 6)));
    const size_t nudged_in = 1 + r.below(8);  // one coordinate in this many
    for (double& v : p) {
        if (!std::isfinite(v)) continue;
        v = std::nearbyint(v / step) * step;
        if (r.below(nudged_in) == 0) v = nudge(v, r);
    }
    return true;
}

// The integer points of x^2 + y^2 = radius^2.
inline std::vector<int> integer_circle(int radius) {
    std::vector<int> xy;
    for (int x = -radius; x <= radius; ++x)
        for (int y = -radius; y <= radius; ++y)
            if (x * x + y * y == radius * radius) xy.insert(xy.end(), {x, y});
    return xy;
}

// A ring of points exactly on one circle, across one of the axes, at a snapped place in
// the cloud; some nudged by an ulp.
inline bool cocircle(Points& p, Random& r, size_t front) {
    const int radii[] = {5, 25, 65, 85};
    const std::vector<int> xy = integer_circle(radii[r.below(4)]);
    const Frame f = frame_of(p);
    const double unit = std::ldexp(1.0, std::ilogb(f.extent) - static_cast<int>(r.between(3, 8)));
    const size_t axis = r.below(3);
    double at[3];
    for (size_t k = 0; k < 3; ++k) at[k] = std::nearbyint(f.centre[k] / unit) * unit;
    const size_t nudged_in = 2 + r.below(8);
    Points ring;
    for (size_t i = 0; i < xy.size(); i += 2) {
        double q[3];
        q[axis] = at[axis];
        q[(axis + 1) % 3] = at[(axis + 1) % 3] + xy[i] * unit;
        q[(axis + 2) % 3] = at[(axis + 2) % 3] + xy[i + 1] * unit;
        for (double& v : q)
            if (r.below(nudged_in) == 0) v = nudge(v, r);
        ring.insert(ring.end(), q, q + 3);
    }
    place(p, ring, r, front);
    return true;
}

// One coordinate of every point snapped to a few rows: a scanner's layers.
inline bool layer(Points& p, Random& r) {
    if (p.empty()) return false;
    const Frame f = frame_of(p);
    const size_t axis = r.below(3);
    const double rows = static_cast<double>(2 + r.below(12));
    const double step = 2 * f.extent / rows;
    for (size_t i = axis; i < p.size(); i += 3)
        if (std::isfinite(p[i])) p[i] = f.centre[axis] + std::nearbyint((p[i] - f.centre[axis]) / step) * step;
    return true;
}

// The first and last index (exclusive) of a random run of points, starting among the
// first `front`.
inline void run_of(const Points& p, Random& r, size_t front, size_t& first, size_t& last) {
    first = r.below(std::min(count(p), front));
    last = first + 1 + r.below(count(p) - first);
}

// The cloud, or a run of its points, times an extreme factor.
inline bool rescale(Points& p, Random& r, size_t front) {
    if (p.empty()) return false;
    const double decimal[] = {1e-300, 1e300, 1e-150, 1e150, 1e-30, 1e30, 1e-8, 1e8};
    const double factor = r.below(3) ? power_of_two(r, -1000, 1000) : decimal[r.below(8)];
    size_t first = 0, last = count(p);
    if (r.below(2)) run_of(p, r, front, first, last);
    for (size_t i = 3 * first; i < 3 * last; ++i) p[i] *= factor;
    return true;
}

// One to three coordinates made NaN or infinite.
inline bool break_values(Points& p, Random& r, size_t front) {
    if (p.empty()) return false;
    const double values[] = {std::nan(""), -std::nan(""), std::nan("0x5a5a5"), HUGE_VAL, -HUGE_VAL};
    for (size_t k = 1 + r.below(3); k > 0; --k) p[r.below(3 * std::min(count(p), front))] = values[r.below(5)];
    return true;
}

// One to four points 10 to 10^300 times the cloud's size away from it.
inline bool add_outliers(Points& p, Random& r, size_t front) {
    const Frame f = frame_of(p);
    for (size_t k = 1 + r.below(4); k > 0; --k) {
        double d[3];
        direction(r, d);
        const double distance = f.extent * std::pow(10.0, static_cast<double>(r.between(1, 300)));
        place(p, {f.centre[0] + distance * d[0], f.centre[1] + distance * d[1], f.centre[2] + distance * d[2]}, r, front);
    }
    return true;
}

// A copy of a run of points, moved 3 to 10^30 times the cloud's size away.
inline bool far_copy(Points& p, Random& r, size_t front) {
    if (p.empty()) return false;
    const Frame f = frame_of(p);
    size_t first = 0, last = 0;
    run_of(p, r, front, first, last);
    double d[3];
    direction(r, d);
    const double distance = f.extent * (r.below(2) ? 3 + 10 * r.uniform() : std::pow(10.0, static_cast<double>(r.between(2, 30))));
    Points copy(p.begin() + static_cast<std::ptrdiff_t>(3 * first), p.begin() + static_cast<std::ptrdiff_t>(3 * last));
    for (size_t i = 0; i < copy.size(); ++i) copy[i] += distance * d[i % 3];
    place(p, copy, r, front);
    return true;
}

// Points on one line through a point of the cloud, at exact steps along it, some nudged.
inline bool collinear(Points& p, Random& r, size_t front) {
    const Frame f = frame_of(p);
    double start[3] = {f.centre[0], f.centre[1], f.centre[2]};
    if (!p.empty()) {
        const size_t from = r.below(count(p));
        for (size_t k = 0; k < 3; ++k)
            if (std::isfinite(p[3 * from + k])) start[k] = p[3 * from + k];
    }
    const double unit = std::ldexp(1.0, std::ilogb(f.extent) - static_cast<int>(r.between(2, 6)));
    double step[3];
    for (double& s : step) s = static_cast<double>(r.between(-2, 2)) * unit;
    if (step[0] == 0 && step[1] == 0 && step[2] == 0) step[2] = unit;
    const size_t nudged_in = r.below(2) ? 0 : 1 + r.below(6);
    Points line;
    for (size_t m = 3 + r.below(38); m > 0; --m) {
        const double t = static_cast<double>(m);
        for (size_t k = 0; k < 3; ++k) {
            const double v = start[k] + t * step[k];
            line.push_back(nudged_in && r.below(nudged_in) == 0 ? nudge(v, r) : v);
        }
    }
    place(p, line, r, front);
    return true;
}

// A run of points removed.
inline bool remove(Points& p, Random& r, size_t front) {
    if (count(p) < 2) return false;
    size_t first = 0, last = 0;
    run_of(p, r, front, first, last);
    p.erase(p.begin() + static_cast<std::ptrdiff_t>(3 * first), p.begin() + static_cast<std::ptrdiff_t>(3 * last));
    return true;
}

// The points reversed, rotated, or a few pairs swapped.
inline bool reorder(Points& p, Random& r) {
    if (count(p) < 2) return false;
    const size_t how = r.below(3);
    if (how == 0) {
        for (size_t i = 0, j = count(p) - 1; i < j; ++i, --j) std::swap_ranges(p.data() + 3 * i, p.data() + 3 * i + 3, p.data() + 3 * j);
    } else if (how == 1) {
        std::rotate(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(3 * r.below(count(p))), p.end());
    } else {
        for (size_t k = 1 + r.below(8); k > 0; --k) {
            const size_t i = r.below(count(p)), j = r.below(count(p));
            if (i != j) std::swap_ranges(p.data() + 3 * i, p.data() + 3 * i + 3, p.data() + 3 * j);
        }
    }
    return true;
}

// Noise of 10^-15 to a tenth of the cloud's size on every coordinate.
inline bool jitter(Points& p, Random& r) {
    if (p.empty()) return false;
    const double size = frame_of(p).extent * std::pow(10.0, -static_cast<double>(r.between(1, 15)));
    for (double& v : p) v += size * (r.uniform() - 0.5);
    return true;
}

// The whole cloud moved far from the origin, where its detail is a few bits of its coordinates.
inline bool offset(Points& p, Random& r) {
    if (p.empty()) return false;
    double d[3];
    direction(r, d);
    const double distance = frame_of(p).extent * power_of_two(r, 10, 60);
    for (size_t i = 0; i < p.size(); ++i) p[i] += distance * d[i % 3];
    return true;
}

// float32 or float64, or another padding after each point.
inline bool recode(CloudSpec& spec, Random& r) {
    if (r.below(2))
        spec.f32 = !spec.f32;
    else
        spec.pad = static_cast<uint32_t>(r.below(8));
    return true;
}

// A new cloud of rings (most no larger than the front) or a fork; false if none fits.
inline bool replace(Points& p, Random& r, Limits limits) {
    Points made = r.below(4) ? rings(r, r.below(3) ? std::min(limits.front, limits.room) : limits.room)
                             : fork(r, limits.room);
    if (made.empty()) return false;
    p.swap(made);
    return true;
}

// One change to the cloud, or a new cloud.
inline bool change(CloudSpec& spec, Random& r, Limits limits) {
    Points& p = spec.xyz;
    const size_t front = limits.front;
    switch (r.below(15)) {
    case 0: return replace(p, r, limits);
    case 1: return duplicate(p, r, front);
    case 2: return snap(p, r);
    case 3: return cocircle(p, r, front);
    case 4: return layer(p, r);
    case 5: return rescale(p, r, front);
    case 6: return break_values(p, r, front);
    case 7: return add_outliers(p, r, front);
    case 8: return far_copy(p, r, front);
    case 9: return collinear(p, r, front);
    case 10: return remove(p, r, front);
    case 11: return reorder(p, r);
    case 12: return jitter(p, r);
    case 13: return offset(p, r);
    default: return recode(spec, r);
    }
}

// A run of the points of `other` put into s's cloud as they are, moved into its middle,
// or far away; the bytes after the cloud from either input.
inline void cross(SplitInput& s, SplitInput& other, Random& r, size_t front) {
    const Points& q = other.spec.xyz;
    if (q.empty()) return;
    size_t first = 0, last = 0;
    run_of(q, r, count(q), first, last);
    Points run(q.begin() + static_cast<std::ptrdiff_t>(3 * first), q.begin() + static_cast<std::ptrdiff_t>(3 * last));
    const Frame here = frame_of(s.spec.xyz), there = frame_of(q);
    double shift[3] = {0, 0, 0};
    const size_t how = r.below(3);
    if (how == 1)
        for (size_t k = 0; k < 3; ++k) shift[k] = here.centre[k] - there.centre[k];
    if (how == 2) {
        direction(r, shift);
        for (double& v : shift) v *= here.extent * std::pow(10.0, static_cast<double>(r.between(1, 20)));
    }
    for (size_t i = 0; i < run.size(); ++i) run[i] += shift[i % 3];
    place(s.spec.xyz, run, r, front);
    if (r.below(2)) s.rest.swap(other.rest);
}

}  // namespace cloud_mutator

// One to three changes to the cloud of data[0, size), written back in place (at most
// max_size bytes) with fewer than max_points points, new ones among the first `front`;
// returns the new size, or 0 where nothing changed.
inline size_t mutate_cloud(uint8_t* data, size_t size, size_t max_size, uint32_t max_points, size_t front,
                           Random& r) {
    SplitInput s = split_input(data, size, max_points);
    bool changed = false;
    for (size_t k = 1 + r.below(3); k > 0; --k)
        changed = cloud_mutator::change(s.spec, r, {max_points - 1, front}) || changed;
    return changed ? write_input(s, data, max_size, max_points) : 0;
}

// The cross-over: the cloud of `a` with a run of b's points (cloud_mutator::cross()),
// written into out[0, max_size); returns its size, 0 if b has no points.
inline size_t cross_clouds(const uint8_t* a, size_t a_size, const uint8_t* b, size_t b_size, uint8_t* out,
                           size_t max_size, uint32_t max_points, size_t front, Random& r) {
    SplitInput s = split_input(a, a_size, max_points);
    SplitInput other = split_input(b, b_size, max_points);
    if (other.spec.xyz.empty()) return 0;
    cloud_mutator::cross(s, other, r, front);
    return write_input(s, out, max_size, max_points);
}

}  // namespace stratmesh_fuzz

#endif  // STRATMESH_FUZZ_CLOUD_MUTATOR_H
