// Deterministic point clouds of columnar shapes with their analytic surfaces, for the
// reconstruction tests. Written for the tests, independently of stratmesh.
//
// Every shape is defined in a local frame whose axis is Z: a radial surface
// rho = radius(theta, z) for z in [z_min, z_max] (rho, theta the polar coordinates of
// (x, y)). A pose then places it in the world: a rotation plus an offset, so that the axis
// is along world Z, along world X, or tilted through an arbitrary point. The Z and X poses
// are exact: world coordinates are a permutation of the local ones plus an offset (every
// product by 0 or 1 is exact), so points generated on one local plane z = c keep exactly
// the same world coordinate along the axis, which the tests need to place layer cuts
// exactly on contour planes.
//
// Randomness comes from a private splitmix64 generator with fixed seeds, so the random
// numbers are the same everywhere. The coordinates also go through sin, cos, log and
// sqrt, which compilers may fold at compile time or route to different C library entry
// points: they are the same bits run after run of one build, but not necessarily across
// compilers (measured: the noisy tube differs in the last bits between g++ 12 and clang++
// 14 builds; the cylinder does not). Point and triangle indices quoted in the tests are
// from a g++ build.

#ifndef STRATMESH_TESTS_SUPPORT_SHAPES_H
#define STRATMESH_TESTS_SUPPORT_SHAPES_H

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace shapes {

constexpr double kPi = 3.14159265358979323846;

// splitmix64 (Steele, Lea, Flood 2014): tiny, fast, and good enough for sampling.
class Rng {
public:
    explicit Rng(uint64_t seed) : state_(seed) {}
    uint64_t next() {
        uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    // Uniform in [0, 1), 53 random bits.
    double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    // Standard normal (Box-Muller; one of the pair is dropped to stay stateless).
    double normal() {
        double u1 = 1.0 - uniform();  // (0, 1]
        double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
    }

private:
    uint64_t state_;
};

enum class Pose { z, x, tilted };

inline const char* pose_name(Pose pose) {
    switch (pose) {
    case Pose::z: return "axis Z";
    case Pose::x: return "axis X";
    case Pose::tilted: return "tilted";
    }
    return "?";
}

// world = m * local + t.
struct Transform {
    double m[3][3];
    double t[3];

    void apply(const double local[3], double world[3]) const {
        for (int r = 0; r < 3; ++r)
            world[r] = m[r][0] * local[0] + m[r][1] * local[1] + m[r][2] * local[2] + t[r];
    }
    void unapply(const double world[3], double local[3]) const {
        double d[3] = {world[0] - t[0], world[1] - t[1], world[2] - t[2]};
        for (int c = 0; c < 3; ++c) local[c] = m[0][c] * d[0] + m[1][c] * d[1] + m[2][c] * d[2];
    }
};

inline Transform transform_for(Pose pose) {
    Transform tr = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0.25, -0.5, 2.0}};
    if (pose == Pose::x) {
        // local z -> world x, local x -> world y, local y -> world z (a rotation).
        tr = {{{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {-3.0, 0.75, 0.5}};
    } else if (pose == Pose::tilted) {
        // Rotation by 0.9 rad about the unit vector along (1, 2, 3) (Rodrigues), then an
        // offset well away from the origin.
        double k[3] = {1, 2, 3};
        double len = std::sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]);
        for (double& v : k) v /= len;
        double a = 0.9, c = std::cos(a), s = std::sin(a), C = 1 - c;
        double m[3][3] = {{c + k[0] * k[0] * C, k[0] * k[1] * C - k[2] * s, k[0] * k[2] * C + k[1] * s},
                          {k[1] * k[0] * C + k[2] * s, c + k[1] * k[1] * C, k[1] * k[2] * C - k[0] * s},
                          {k[2] * k[0] * C - k[1] * s, k[2] * k[1] * C + k[0] * s, c + k[2] * k[2] * C}};
        for (int r = 0; r < 3; ++r)
            for (int col = 0; col < 3; ++col) tr.m[r][col] = m[r][col];
        tr.t[0] = 12.5;
        tr.t[1] = -7.25;
        tr.t[2] = 30.0;
    }
    return tr;
}

using RadiusFunction = std::function<double(double theta, double z)>;

struct Shape {
    std::string name;
    Pose pose = Pose::z;
    Transform transform = transform_for(Pose::z);
    RadiusFunction radius;       // the analytic surface, in the local frame
    double z_min = 0, z_max = 0; // its height range, local
    double spacing = 0;          // typical distance between neighbouring points
    double noise = 0;            // standard deviation of the Gaussian noise, 0 if exact
    std::vector<double> xyz;     // world coordinates, packed
    std::vector<double> planes;  // local heights of the contour planes or grid rows, if any
    // For a closed surface (ends included), its signed distance at a local point (positive
    // outside); deviation() then uses it instead of the radial one.
    std::function<double(const double* local)> closed_distance;

    size_t size() const { return xyz.size() / 3; }
    const double* point(size_t i) const { return xyz.data() + 3 * i; }

    // The world axis: a point on it and its unit direction (the local +Z).
    void axis_point(double out[3]) const { out[0] = transform.t[0], out[1] = transform.t[1], out[2] = transform.t[2]; }
    void axis_direction(double out[3]) const {
        for (int r = 0; r < 3; ++r) out[r] = transform.m[r][2];
    }
    // The world coordinate along the axis, dot(P, axis), of the plane at local height z,
    // computed from the world point on the axis at that height. For the Z and X poses it
    // equals, bit for bit, dot(p, axis) of every point generated on that plane.
    double along_axis(double z) const {
        double local[3] = {0, 0, z}, world[3], a[3];
        transform.apply(local, world);
        axis_direction(a);
        return world[0] * a[0] + world[1] * a[1] + world[2] * a[2];
    }
    // Signed radial deviation of a world point from the surface: rho - radius(theta, z) in
    // the local frame (positive outside). For the slopes used here it is within a factor
    // of about 1.5 of the Euclidean distance.
    double deviation(const double* p) const {
        double local[3];
        transform.unapply(p, local);
        if (closed_distance) return closed_distance(local);
        double rho = std::sqrt(local[0] * local[0] + local[1] * local[1]);
        return rho - radius(std::atan2(local[1], local[0]), local[2]);
    }
    // Appends the world point at local (theta, z, rho).
    void add_local(double theta, double z, double rho) {
        double local[3] = {rho * std::cos(theta), rho * std::sin(theta), z}, world[3];
        transform.apply(local, world);
        xyz.insert(xyz.end(), world, world + 3);
    }
};

namespace detail {

// |dP/dtheta x dP/dz| for P = (r cos t, r sin t, z): sqrt(r^2 + r_t^2 + r^2 r_z^2).
inline double area_element(const RadiusFunction& radius, double theta, double z) {
    const double h = 1e-5;
    double r = radius(theta, z);
    double rt = (radius(theta + h, z) - radius(theta - h, z)) / (2 * h);
    double rz = (radius(theta, z + h) - radius(theta, z - h)) / (2 * h);
    return std::sqrt(r * r + rt * rt + r * r * rz * rz);
}

// Surface area and the largest area element, on a fine grid.
inline std::pair<double, double> surface_area(const RadiusFunction& radius, double z0, double z1) {
    const int nt = 128, nz = 128;
    double area = 0, peak = 0;
    double dt = 2 * kPi / nt, dz = (z1 - z0) / nz;
    for (int i = 0; i < nt; ++i)
        for (int j = 0; j < nz; ++j) {
            double e = area_element(radius, (i + 0.5) * dt, z0 + (j + 0.5) * dz);
            area += e * dt * dz;
            if (e > peak) peak = e;
        }
    return {area, peak};
}

inline Shape start(const char* name, Pose pose, RadiusFunction radius, double z0, double z1) {
    Shape s;
    s.name = std::string(name) + " (" + pose_name(pose) + ")";
    s.pose = pose;
    s.transform = transform_for(pose);
    s.radius = std::move(radius);
    s.z_min = z0;
    s.z_max = z1;
    return s;
}

// The angle difference a - b wrapped to (-pi, pi].
inline double angle_between(double a, double b) {
    double d = std::fmod(a - b, 2 * kPi);
    if (d > kPi) d -= 2 * kPi;
    if (d <= -kPi) d += 2 * kPi;
    return d;
}

inline double smoothstep(double t) {
    if (t <= 0) return 0;
    if (t >= 1) return 1;
    return t * t * (3 - 2 * t);
}

}  // namespace detail

// n points uniformly distributed over the area of a radial surface (rejection sampling),
// with theta in [theta0, theta1) and optional isotropic Gaussian noise of standard
// deviation `noise`.
inline Shape radial_random(const char* name, Pose pose, RadiusFunction radius, double z0,
                           double z1, size_t n, uint64_t seed, double noise = 0,
                           double theta0 = 0, double theta1 = 2 * kPi) {
    Shape s = detail::start(name, pose, std::move(radius), z0, z1);
    std::pair<double, double> area = detail::surface_area(s.radius, z0, z1);
    double fraction = (theta1 - theta0) / (2 * kPi);
    s.spacing = std::sqrt(area.first * fraction / static_cast<double>(n));
    s.noise = noise;
    double bound = 1.05 * area.second;
    Rng rng(seed);
    s.xyz.reserve(3 * n);
    while (s.size() < n) {
        double theta = rng.uniform(theta0, theta1);
        double z = rng.uniform(z0, z1);
        if (rng.uniform() * bound > detail::area_element(s.radius, theta, z)) continue;
        double rho = s.radius(theta, z);
        s.add_local(theta, z, rho);
        if (noise > 0) {
            double* p = &s.xyz[s.xyz.size() - 3];
            for (int k = 0; k < 3; ++k) p[k] += noise * rng.normal();
        }
    }
    return s;
}

// Radius functions of the shapes (local frame).
inline double cylinder_radius(double, double) { return 1.0; }
inline double ellipse_radius(double theta, double) {
    const double a = 1.5, b = 0.8;
    double c = std::cos(theta), s = std::sin(theta);
    return a * b / std::sqrt(b * b * c * c + a * a * s * s);
}
inline double bumpy_radius(double theta, double z) { return 1 + 0.25 * std::sin(5 * theta) * std::cos(z); }
inline double cone_radius(double, double z) { return 1.5 - 0.2 * z; }
inline double vase_radius(double, double z) { return 1 + 0.5 * std::sin(1.5 * z); }

// A head-like column over z in [0, 2.4]: a neck (radius 0.45), a wider skull (about 0.9),
// slightly longer front to back, narrowing a little at the crown (left open), and a nose
// bump facing local +x between about z = 1.35 and 1.75.
inline double head_radius(double theta, double z) {
    double base = 0.45 + 0.45 * detail::smoothstep((z - 0.6) / 0.7) -
                  0.12 * detail::smoothstep((z - 2.0) / 0.4);
    double shape = 1 + 0.08 * std::cos(2 * theta);
    double dt = detail::angle_between(theta, 0) / 0.22, dz = (z - 1.55) / 0.13;
    double nose = 0.2 * std::exp(-dt * dt - dz * dz);
    return base * shape + nose;
}

inline Shape cylinder(size_t n, Pose pose, uint64_t seed = 11) {
    return radial_random("cylinder", pose, cylinder_radius, -3, 3, n, seed);
}
inline Shape elliptic_tube(size_t n, Pose pose, uint64_t seed = 12) {
    return radial_random("elliptic tube", pose, ellipse_radius, -3, 3, n, seed);
}
inline Shape bumpy_tube(size_t n, Pose pose, uint64_t seed = 13) {
    return radial_random("bumpy tube", pose, bumpy_radius, -3, 3, n, seed);
}
inline Shape cone(size_t n, Pose pose, uint64_t seed = 14) {
    return radial_random("cone", pose, cone_radius, -3, 3, n, seed);
}
inline Shape vase(size_t n, Pose pose, uint64_t seed = 15) {
    return radial_random("vase", pose, vase_radius, -3, 3, n, seed);
}
// Uniform sampling of the bumpy tube with isotropic Gaussian noise of standard deviation
// `relative_noise` times the point spacing.
inline Shape noisy_tube(size_t n, Pose pose, double relative_noise = 0.05, uint64_t seed = 16) {
    double spacing = std::sqrt(detail::surface_area(bumpy_radius, -3, 3).first / static_cast<double>(n));
    return radial_random("noisy bumpy tube", pose, bumpy_radius, -3, 3, n, seed,
                         relative_noise * spacing);
}
// A cylinder of small radius over z in [-3, 3]: very tall for its width.
inline Shape thin_tube(size_t n, Pose pose, double radius, uint64_t seed = 21) {
    return radial_random("thin tube", pose, [radius](double, double) { return radius; }, -3, 3, n, seed);
}
inline Shape head(size_t n, Pose pose, uint64_t seed = 17) {
    return radial_random("head", pose, head_radius, 0, 2.4, n, seed);
}
// A head on a neck, longer from front to back (x) than tall (z): a neck of radius 0.35 up
// to z = 0.5, then a head about 2.6 long, 1.2 wide and 1.5 tall. Its largest variance is
// front to back; the method needs z.
inline double long_head_radius(double theta, double z) {
    const double head = 0.35 + 0.55 * detail::smoothstep((z - 0.5) / 0.4) -
                        0.35 * detail::smoothstep((z - 1.6) / 0.4);
    const double neck = 1 - detail::smoothstep((z - 0.5) / 0.4);
    return head * (1 + (1 - neck) * 0.45 * std::cos(2 * theta));
}
inline Shape long_head(size_t n, Pose pose, uint64_t seed = 24) {
    return radial_random("long head", pose, long_head_radius, 0, 2.0, n, seed);
}
// A cylinder with theta in [0, pi] only: it does not surround its axis.
inline Shape half_cylinder(size_t n, Pose pose, uint64_t seed = 18) {
    return radial_random("half cylinder", pose, cylinder_radius, -3, 3, n, seed, 0, 0, kPi);
}
// A cylinder with a slit: theta in [0, 2 pi - gap).
inline Shape slit_cylinder(size_t n, Pose pose, double gap, uint64_t seed = 19) {
    return radial_random("slit cylinder", pose, cylinder_radius, -3, 3, n, seed, 0, 0,
                         2 * kPi - gap);
}

// The unit cylinder cut at both ends by planes leaning 35 degrees from the cross-section
// (a limb or a pipe scanned with slanted ends): z in [-3, 3] + tan(35 deg) cos(theta), so
// a layer thinner than 1.4 near either end holds a crescent, not a ring.
inline Shape slanted_tube(size_t n, Pose pose, uint64_t seed = 22) {
    const double slant = std::tan(35 * kPi / 180);
    Shape s = detail::start("slanted tube", pose, cylinder_radius, -3 - slant, 3 + slant);
    s.spacing = std::sqrt(2 * kPi * 6 / static_cast<double>(n));
    Rng rng(seed);
    s.xyz.reserve(3 * n);
    for (size_t i = 0; i < n; ++i) {
        double theta = rng.uniform(0, 2 * kPi);
        s.add_local(theta, rng.uniform(-3, 3) + slant * std::cos(theta), 1.0);
    }
    return s;
}

// Closed objects, scanned all round: ends included, n points spread evenly over the area.
// The unit cylinder over z in [-3, 3] closed by two flat discs (a bust's base, a cut
// bone), and a capsule: the unit cylinder over z in [-2, 2] closed by two half spheres (a
// bone's ends, a crown). deviation() is their signed distance.
inline Shape closed_cylinder(size_t n, Pose pose, uint64_t seed = 23) {
    Shape s = detail::start("closed cylinder", pose, cylinder_radius, -3, 3);
    s.closed_distance = [](const double* p) {
        double rho = std::hypot(p[0], p[1]), dz = std::fabs(p[2]) - 3;
        if (rho <= 1 && dz <= 0) return -std::min(1 - rho, -dz);
        return std::hypot(std::max(rho - 1, 0.0), std::max(dz, 0.0));
    };
    const double wall = 2 * kPi * 6, disc = kPi;
    s.spacing = std::sqrt((wall + 2 * disc) / static_cast<double>(n));
    Rng rng(seed);
    while (s.size() < n) {
        double theta = rng.uniform(0, 2 * kPi), u = rng.uniform(0, wall + 2 * disc);
        if (u < wall)
            s.add_local(theta, rng.uniform(-3, 3), 1.0);
        else
            s.add_local(theta, u < wall + disc ? -3 : 3, std::sqrt(rng.uniform()));
    }
    return s;
}
inline Shape capsule(size_t n, Pose pose, uint64_t seed = 24) {
    Shape s = detail::start("capsule", pose, cylinder_radius, -3, 3);
    s.closed_distance = [](const double* p) {
        return std::hypot(std::hypot(p[0], p[1]), p[2] - std::max(-2.0, std::min(2.0, p[2]))) - 1;
    };
    const double wall = 2 * kPi * 4, sphere = 4 * kPi;
    s.spacing = std::sqrt((wall + sphere) / static_cast<double>(n));
    Rng rng(seed);
    while (s.size() < n) {
        double theta = rng.uniform(0, 2 * kPi), u = rng.uniform(0, wall + sphere);
        if (u < wall) {
            s.add_local(theta, rng.uniform(-2, 2), 1.0);
        } else {  // a sphere's height is uniform over its area (Archimedes)
            double z = rng.uniform(-1, 1);
            s.add_local(theta, z + (z < 0 ? -2 : 2), std::sqrt(1 - z * z));
        }
    }
    return s;
}

struct RoundCone {  // a segment a -> b with radius ra at a and rb at b, rounded ends
    double a[3], b[3], ra, rb;
    double distance(const double* p) const {
        double ab[3], ap[3], dot = 0, len2 = 0;
        for (int k = 0; k < 3; ++k) {
            ab[k] = b[k] - a[k];
            ap[k] = p[k] - a[k];
            dot += ab[k] * ap[k];
            len2 += ab[k] * ab[k];
        }
        const double t = std::max(0.0, std::min(1.0, dot / len2));
        return std::hypot(ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]) -
               (ra + t * (rb - ra));
    }
};

namespace detail {

// n points spread evenly over the boundary of the union of round cones (the parts of each
// piece outside the others), cut to heights [z0, z1] (open there); deviation() is the
// union's signed distance (a piece's is measured across its centre line, within 1% of the
// true distance for a taper like a horn's).
inline Shape union_of_round_cones(const char* name, Pose pose, std::vector<RoundCone> parts,
                                  double z0, double z1, size_t n, uint64_t seed) {
    Shape s = start(name, pose, cylinder_radius, z0, z1);
    s.closed_distance = [parts](const double* p) {
        double d = parts[0].distance(p);
        for (const RoundCone& q : parts) d = std::min(d, q.distance(p));
        return d;
    };
    // Each piece: its side (area about pi (ra + rb) times its length) and its two end caps
    // (half spheres of radius ra and rb).
    const size_t count = parts.size();
    std::vector<double> side(count), area(count);
    double total = 0;
    for (size_t c = 0; c < count; ++c) {
        const RoundCone& q = parts[c];
        side[c] = kPi * (q.ra + q.rb) * std::hypot(q.b[0] - q.a[0], q.b[1] - q.a[1], q.b[2] - q.a[2]);
        area[c] = side[c] + 2 * kPi * (q.ra * q.ra + q.rb * q.rb);
        total += area[c];
    }
    Rng rng(seed);
    size_t tries = 0;
    while (s.size() < n) {
        ++tries;
        double u = rng.uniform(0, total);
        size_t c = 0;
        while (c + 1 < count && u >= area[c]) u -= area[c++];
        const RoundCone& q = parts[c];
        double axis[3] = {q.b[0] - q.a[0], q.b[1] - q.a[1], q.b[2] - q.a[2]};
        const double length = std::hypot(axis[0], axis[1], axis[2]);
        for (double& x : axis) x /= length;
        // Two unit vectors across the segment: (z, 0, -x) normalised, or x for a piece
        // along y.
        double e1[3] = {axis[2], 0, -axis[0]};
        const double l1 = std::hypot(e1[0], e1[1], e1[2]);
        if (l1 < 1e-9) {
            e1[0] = 1, e1[2] = 0;
        } else {
            for (double& x : e1) x /= l1;
        }
        const double e2[3] = {axis[1] * e1[2] - axis[2] * e1[1], axis[2] * e1[0] - axis[0] * e1[2],
                              axis[0] * e1[1] - axis[1] * e1[0]};
        double p[3];
        if (u < side[c]) {  // t drawn with density proportional to the radius
            const double t = rng.uniform(), phi = rng.uniform(0, 2 * kPi);
            const double r = q.ra + t * (q.rb - q.ra);
            if (rng.uniform() * std::max(q.ra, q.rb) > r) continue;
            for (int k = 0; k < 3; ++k)
                p[k] = q.a[k] + t * length * axis[k] + r * (std::cos(phi) * e1[k] + std::sin(phi) * e2[k]);
        } else {  // a half sphere at one end, chosen by its area
            const bool at_b = rng.uniform() * (q.ra * q.ra + q.rb * q.rb) < q.rb * q.rb;
            const double r = at_b ? q.rb : q.ra;
            const double h = rng.uniform(0, 1) * (at_b ? 1 : -1), phi = rng.uniform(0, 2 * kPi);
            const double w = std::sqrt(1 - h * h);
            const double* end = at_b ? q.b : q.a;
            for (int k = 0; k < 3; ++k)
                p[k] = end[k] + r * (h * axis[k] + w * (std::cos(phi) * e1[k] + std::sin(phi) * e2[k]));
        }
        if (p[2] < z0 || p[2] > z1) continue;  // the open ends
        bool inside = false;
        for (size_t o = 0; o < count; ++o)
            if (o != c && parts[o].distance(p) < 0) inside = true;
        if (inside) continue;
        s.add_local(std::atan2(p[1], p[0]), p[2], std::hypot(p[0], p[1]));
    }
    // The boundary's area is about the share of samples kept.
    s.spacing = std::sqrt(total / static_cast<double>(tries));
    return s;
}

}  // namespace detail

// A tube that forks at its top end into two horns, as on a bust with horns: a trunk of
// radius 1 around the axis from z = -3 (open there) up to the pole of its dome at z = 1.5,
// and two horns rising outward from inside the dome, (+-0.45, 0, 0.6), to tips at
// (+-1.1, 0, 3.5), their radius tapering from 0.3 to 0.03. Above the dome the cross-section
// is two separate discs.
inline Shape forked_tube(size_t n, Pose pose, uint64_t seed = 25) {
    return detail::union_of_round_cones("forked tube", pose,
                                        {{{0, 0, -4}, {0, 0, 0.5}, 1.0, 1.0},
                                         {{0.45, 0, 0.6}, {1.1, 0, 3.5}, 0.3, 0.03},
                                         {{-0.45, 0, 0.6}, {-1.1, 0, 3.5}, 0.3, 0.03}},
                                        -3, 3.53, n, seed);
}

// A tube closed at its bottom by two knobs side by side, as a femur by its condyles: a
// trunk of radius 1 around the axis, open at z = 3, its dome's pole at z = -1, and two
// knobs of radius 0.5 along (+-0.65, 0, z) for z from -1.2 to -0.2, wider together than
// the trunk, their lowest points at z = -1.7. Below the trunk's pole the cross-section is
// two discs 0.3 apart, and the notch between them rises to the pole.
inline Shape knobbed_tube(size_t n, Pose pose, uint64_t seed = 26) {
    return detail::union_of_round_cones("knobbed tube", pose,
                                        {{{0, 0, 0}, {0, 0, 4}, 1.0, 1.0},
                                         {{0.65, 0, -1.2}, {0.65, 0, -0.2}, 0.5, 0.5},
                                         {{-0.65, 0, -1.2}, {-0.65, 0, -0.2}, 0.5, 0.5}},
                                        -1.7, 3, n, seed);
}

// Objects with limbs: unions of round cones, closed where a limb ends and open where the
// cut at z0 crosses the trunk. Sizes in units of the trunk's radius.

// A Y of tubes: a trunk up to z = 0, open at z = -3, and two arms of radius 0.6 rising
// outward to (+-2.2, 0, 3.5).
inline Shape y_of_tubes(size_t n, Pose pose, uint64_t seed = 31) {
    return detail::union_of_round_cones("Y of tubes", pose,
                                        {{{0, 0, -4}, {0, 0, 0}, 1.0, 1.0},
                                         {{0, 0, 0}, {2.2, 0, 3.5}, 0.6, 0.6},
                                         {{0, 0, 0}, {-2.2, 0, 3.5}, 0.6, 0.6}},
                                        -3, 1e9, n, seed);
}

// A trunk open at z = 0 with three branches leaving its side at heights 2, 4.5 and 7 in
// three directions, its top a dome.
inline Shape branched_trunk(size_t n, Pose pose, uint64_t seed = 32) {
    return detail::union_of_round_cones("branched trunk", pose,
                                        {{{0, 0, -1}, {0, 0, 9}, 1.0, 1.0},
                                         {{0, 0, 2}, {3.2, 0, 4}, 0.45, 0.4},
                                         {{0, 0, 4.5}, {-2, 2.2, 6.5}, 0.45, 0.4},
                                         {{0, 0, 7}, {0.6, -3, 8.5}, 0.4, 0.35}},
                                        0, 1e9, n, seed);
}

// A hand: a forearm open at z = -2, a flat palm (two round cones side by side), four
// fingers spreading from its top and a thumb standing out sideways.
inline Shape hand(size_t n, Pose pose, uint64_t seed = 33) {
    return detail::union_of_round_cones("hand", pose,
                                        {{{0, 0, -3}, {0, 0, 0}, 0.8, 0.8},
                                         {{-0.45, 0, 0.2}, {-0.5, 0, 1.9}, 0.6, 0.55},
                                         {{0.45, 0, 0.2}, {0.5, 0, 1.9}, 0.6, 0.55},
                                         {{-0.8, 0, 1.9}, {-1.5, 0, 3.9}, 0.22, 0.2},
                                         {{-0.27, 0, 2.0}, {-0.45, 0, 4.4}, 0.22, 0.2},
                                         {{0.27, 0, 2.0}, {0.45, 0, 4.4}, 0.22, 0.2},
                                         {{0.8, 0, 1.9}, {1.5, 0, 3.9}, 0.22, 0.2},
                                         {{0.9, 0, 0.7}, {2.6, 0, 1.5}, 0.26, 0.22}},
                                        -2, 1e9, n, seed);
}

// A four-legged body: a horizontal body along x, four vertical legs under it, a neck and
// a head in front. Closed all over.
inline Shape four_legged(size_t n, Pose pose, uint64_t seed = 34) {
    return detail::union_of_round_cones("four-legged body", pose,
                                        {{{-3, 0, 0}, {3, 0, 0}, 1.0, 1.0},
                                         {{2, 0.55, -0.3}, {2, 0.55, -3.5}, 0.3, 0.27},
                                         {{2, -0.55, -0.3}, {2, -0.55, -3.5}, 0.3, 0.27},
                                         {{-2, 0.55, -0.3}, {-2, 0.55, -3.5}, 0.3, 0.27},
                                         {{-2, -0.55, -0.3}, {-2, -0.55, -3.5}, 0.3, 0.27},
                                         {{2.8, 0, 0.3}, {3.8, 0, 1.9}, 0.45, 0.4},
                                         {{3.7, 0, 2}, {4.9, 0, 1.8}, 0.6, 0.45}},
                                        -1e9, 1e9, n, seed);
}

// A tee of pipes: a pipe along x and a narrower one rising from its middle along z, their
// ends rounded.
inline Shape tee(size_t n, Pose pose, uint64_t seed = 35) {
    return detail::union_of_round_cones("tee", pose,
                                        {{{-4, 0, 0}, {4, 0, 0}, 1.0, 1.0},
                                         {{0, 0, 0}, {0, 0, 4}, 0.7, 0.7}},
                                        -1e9, 1e9, n, seed);
}

// A Y whose right arm parts again into two twigs.
inline Shape twice_forked(size_t n, Pose pose, uint64_t seed = 36) {
    return detail::union_of_round_cones("twice forked", pose,
                                        {{{0, 0, -4}, {0, 0, 0}, 1.0, 1.0},
                                         {{0, 0, 0}, {-2, 0, 3.2}, 0.55, 0.5},
                                         {{0, 0, 0}, {1.6, 0, 2.5}, 0.6, 0.55},
                                         {{1.6, 0, 2.5}, {3.3, 0, 4.8}, 0.35, 0.3},
                                         {{1.6, 0, 2.5}, {1.2, 0, 5.2}, 0.35, 0.3}},
                                        -3, 1e9, n, seed);
}

// A U of pipe: two upright legs of radius 0.5 at x = -2 and 2, open at z = 4, joined at the
// bottom by a pipe along x. Along z its sections are two discs, then one long one.
inline Shape u_tube(size_t n, Pose pose, uint64_t seed = 37) {
    return detail::union_of_round_cones("U of pipe", pose,
                                        {{{-2, 0, 0}, {-2, 0, 5}, 0.5, 0.5},
                                         {{2, 0, 0}, {2, 0, 5}, 0.5, 0.5},
                                         {{-2, 0, 0}, {2, 0, 0}, 0.5, 0.5}},
                                        -1e9, 4, n, seed);
}

namespace detail {

// A pipe's centre line: a polyline, with a bounding sphere for each run of kRun segments so
// that queries skip the runs too far away to matter (a coil's other turn, a U's other leg).
class CentreLine {
public:
    static constexpr size_t kNone = static_cast<size_t>(-1);

    explicit CentreLine(std::vector<std::array<double, 3>> vertices) : v_(std::move(vertices)) {
        for (size_t first = 0; first + 1 < v_.size(); first += kRun) {
            Run run;
            run.first = first;
            run.last = std::min(first + kRun, v_.size() - 1);
            double lo[3], hi[3];
            for (size_t k = 0; k < 3; ++k) lo[k] = hi[k] = v_[first][k];
            for (size_t j = first; j <= run.last; ++j)
                for (size_t k = 0; k < 3; ++k) {
                    lo[k] = std::min(lo[k], v_[j][k]);
                    hi[k] = std::max(hi[k], v_[j][k]);
                }
            for (size_t k = 0; k < 3; ++k) run.centre[k] = (lo[k] + hi[k]) / 2;
            run.radius = 0;
            for (size_t j = first; j <= run.last; ++j)
                run.radius = std::max(run.radius, std::sqrt(distance2(v_[j].data(), run.centre)));
            runs_.push_back(run);
        }
    }

    size_t segments() const { return v_.size() - 1; }
    const double* vertex(size_t j) const { return v_[j].data(); }

    // The distance from p to the polyline, exact: a run is skipped only when its bounding
    // sphere is farther than the nearest segment found so far (first in the nearest run).
    double distance(const double* p) const {
        size_t nearest = 0;
        double gap = std::numeric_limits<double>::infinity();
        for (size_t r = 0; r < runs_.size(); ++r) {
            const double g = std::sqrt(distance2(p, runs_[r].centre)) - runs_[r].radius;
            if (g < gap) gap = g, nearest = r;
        }
        double best2 = std::numeric_limits<double>::infinity();
        for (size_t s = runs_[nearest].first; s < runs_[nearest].last; ++s)
            best2 = std::min(best2, segment_distance2(s, p));
        double best = std::sqrt(best2);
        for (size_t r = 0; r < runs_.size(); ++r) {
            const Run& run = runs_[r];
            const double reach = best + run.radius;
            if (r == nearest || distance2(p, run.centre) >= reach * reach) continue;
            for (size_t s = run.first; s < run.last; ++s) best2 = std::min(best2, segment_distance2(s, p));
            best = std::sqrt(best2);
        }
        return best;
    }

    // Whether p is strictly inside the solid cylinder (flat ends) of radius r of a segment
    // other than own_segment, or the ball of radius r of a vertex other than own_vertex.
    bool inside(const double* p, double r, size_t own_segment, size_t own_vertex) const {
        for (const Run& run : runs_) {
            const double reach = run.radius + r;
            if (distance2(p, run.centre) >= reach * reach) continue;
            for (size_t j = run.first; j <= run.last; ++j) {
                if (j != own_vertex && distance2(p, v_[j].data()) < r * r) return true;
                if (j == run.last || j == own_segment) continue;
                double ab[3], ap[3];
                for (size_t k = 0; k < 3; ++k) ab[k] = v_[j + 1][k] - v_[j][k], ap[k] = p[k] - v_[j][k];
                const double t = (ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2]) /
                                 (ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]);
                if (t <= 0 || t >= 1) continue;
                double d2 = 0;
                for (size_t k = 0; k < 3; ++k) d2 += (ap[k] - t * ab[k]) * (ap[k] - t * ab[k]);
                if (d2 < r * r) return true;
            }
        }
        return false;
    }

private:
    static constexpr size_t kRun = 16;
    struct Run {
        size_t first, last;  // vertices first..last, segments first..last - 1
        double centre[3], radius;
    };

    static double distance2(const double* a, const double* b) {
        return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
    }
    double segment_distance2(size_t s, const double* p) const {
        const double* a = v_[s].data();
        const double* b = v_[s + 1].data();
        double ab[3], ap[3];
        for (size_t k = 0; k < 3; ++k) ab[k] = b[k] - a[k], ap[k] = p[k] - a[k];
        const double t = std::max(0.0, std::min(1.0, (ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2]) /
                                                         (ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2])));
        double d2 = 0;
        for (size_t k = 0; k < 3; ++k) d2 += (ap[k] - t * ab[k]) * (ap[k] - t * ab[k]);
        return d2;
    }

    std::vector<std::array<double, 3>> v_;
    std::vector<Run> runs_;
};

// A unit vector across the unit vector a: (z, 0, -x) normalised, or x for a along y.
inline std::array<double, 3> unit_across(const double* a) {
    std::array<double, 3> e = {a[2], 0, -a[0]};
    const double l = std::hypot(e[0], e[1], e[2]);
    if (l < 1e-9) return {1, 0, 0};
    for (double& x : e) x /= l;
    return e;
}
inline std::array<double, 3> cross(const double* a, const double* b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// n points spread evenly over a pipe of radius r around a centre line given as a dense
// polyline, closed at both ends by half spheres: the boundary of the union of its
// segments' capsules, whose signed distance deviation() is (the distance to the centre
// line less r). That boundary is made of the segments' cylinder sides, less what a
// neighbour's cylinder covers inside a bend, and at each vertex the lune of its ball
// between the two segments' end planes, outside the bend (the rest of the ball is inside a
// neighbouring cylinder or ball); the ends' half spheres are lunes of half a turn. Each
// piece is drawn by its area and a point kept unless another piece holds it strictly
// inside. The pipe must not touch itself.
inline Shape swept_pipe(const char* name, Pose pose, std::vector<std::array<double, 3>> centre_line,
                        double r, size_t n, uint64_t seed) {
    const CentreLine line(std::move(centre_line));
    const size_t segments = line.segments();
    double z0 = line.vertex(0)[2], z1 = z0;
    for (size_t j = 0; j <= segments; ++j) {
        z0 = std::min(z0, line.vertex(j)[2]);
        z1 = std::max(z1, line.vertex(j)[2]);
    }
    Shape s = start(name, pose, cylinder_radius, z0 - r, z1 + r);
    s.closed_distance = [line, r](const double* p) { return line.distance(p) - r; };

    // The pieces, cylinder sides then lunes, by their cumulative area.
    std::vector<double> cumulative;
    double total = 0;
    std::vector<std::array<double, 3>> along(segments), across(segments);
    std::vector<double> length(segments);
    for (size_t c = 0; c < segments; ++c) {
        const double* a = line.vertex(c);
        const double* b = line.vertex(c + 1);
        length[c] = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
        for (size_t k = 0; k < 3; ++k) along[c][k] = (b[k] - a[k]) / length[c];
        across[c] = unit_across(along[c].data());
        total += 2 * kPi * r * length[c];
        cumulative.push_back(total);
    }
    // A lune at a vertex: unit vectors e (the way in), f (across it, towards the way out)
    // and n (normal to the bend); its points are e cos(alpha) + f sin(alpha) turned about
    // n, alpha in [-pi/2, angle - pi/2] (angle: the bend's, or pi at an end).
    struct Lune {
        std::array<double, 3> e, f, n;
        double angle;
    };
    std::vector<Lune> lunes(segments + 1);
    // Area: Pappus's 2 pi r a unit length of centre line (the cylinders cut by the mitre
    // planes, which is what the union is inside a bend), plus the ends' sphere, plus at
    // each bend its lune, 2 r^2 angle, less the mitre's two wedges outside the bend,
    // 2 r^2 tan(angle / 2) each: about -r^2 angle^3 / 6 a bend.
    double area = total + 4 * kPi * r * r;
    for (size_t j = 0; j <= segments; ++j) {
        Lune& l = lunes[j];
        if (j == 0) {
            for (size_t k = 0; k < 3; ++k) l.e[k] = -along[0][k];
        } else {
            l.e = along[j - 1];
        }
        l.angle = kPi;
        l.n = unit_across(l.e.data());
        if (j > 0 && j < segments) {
            const std::array<double, 3> normal = cross(l.e.data(), along[j].data());
            const double sine = std::hypot(normal[0], normal[1], normal[2]);
            const double cosine = l.e[0] * along[j][0] + l.e[1] * along[j][1] + l.e[2] * along[j][2];
            l.angle = std::atan2(sine, cosine);
            if (sine > 1e-300)
                for (size_t k = 0; k < 3; ++k) l.n[k] = normal[k] / sine;
            area += 2 * r * r * (l.angle - 2 * std::tan(l.angle / 2));
        }
        l.f = cross(l.n.data(), l.e.data());
        total += 2 * r * r * l.angle;
        cumulative.push_back(total);
    }
    s.spacing = std::sqrt(area / static_cast<double>(n));

    Rng rng(seed);
    s.xyz.reserve(3 * n);
    while (s.size() < n) {
        const size_t piece = static_cast<size_t>(
            std::upper_bound(cumulative.begin(), cumulative.end(), rng.uniform(0, total)) - cumulative.begin());
        double p[3];
        if (piece < segments) {
            const size_t c = piece;
            const double t = rng.uniform() * length[c], phi = rng.uniform(0, 2 * kPi);
            const std::array<double, 3> e2 = cross(along[c].data(), across[c].data());
            for (size_t k = 0; k < 3; ++k)
                p[k] = line.vertex(c)[k] + t * along[c][k] +
                       r * (std::cos(phi) * across[c][k] + std::sin(phi) * e2[k]);
            if (line.inside(p, r, c, CentreLine::kNone)) continue;
        } else {
            const size_t j = piece - segments;
            const Lune& l = lunes[j];
            // Uniform by area: alpha uniform, and the height along n too (Archimedes).
            const double alpha = l.angle * rng.uniform() - kPi / 2, h = rng.uniform(-1, 1);
            const double w = std::sqrt(1 - h * h);
            for (size_t k = 0; k < 3; ++k)
                p[k] = line.vertex(j)[k] +
                       r * (w * (std::cos(alpha) * l.e[k] + std::sin(alpha) * l.f[k]) + h * l.n[k]);
            if (line.inside(p, r, CentreLine::kNone, j)) continue;
        }
        s.add_local(std::atan2(p[1], p[0]), p[2], std::hypot(p[0], p[1]));
    }
    return s;
}

}  // namespace detail

// Bent pipes of radius 0.5, their ends rounded: the centre lines are polylines of segments
// about 0.01 long on the bends, within 1e-5 of the circle or helix, and the surface and
// deviation() are exactly the polyline's pipe's.

// An elbow: a leg up z from (0, 0, -3) to the origin, a quarter circle of radius 1.5 about
// (1.5, 0, 0) to (1.5, 0, 1.5), then a leg along x to (4.5, 0, 1.5). Along z its sections
// are a disc, then longer and longer ones across the bend, then one long one.
inline Shape elbow(size_t n, Pose pose, uint64_t seed = 38) {
    std::vector<std::array<double, 3>> line = {{0, 0, -3}};
    const size_t arc = 256;
    for (size_t i = 0; i <= arc; ++i) {
        const double a = kPi / 2 * static_cast<double>(i) / static_cast<double>(arc);
        line.push_back({1.5 - 1.5 * std::cos(a), 0, 1.5 * std::sin(a)});
    }
    line.push_back({4.5, 0, 1.5});
    return detail::swept_pipe("elbow", pose, std::move(line), 0.5, n, seed);
}

// A U bend: legs up z at x = -1.5 and 1.5 from z = 0 to 4, joined below by a half circle
// of radius 1.5 about the origin in the xz plane, lowest at (0, 0, -1.5). Unlike u_tube's
// joint, the bend is smooth: along z the sections are one long disc, then two discs.
inline Shape u_bend(size_t n, Pose pose, uint64_t seed = 39) {
    std::vector<std::array<double, 3>> line = {{-1.5, 0, 4}, {-1.5, 0, 0}};
    const size_t arc = 512;  // even: the lowest point is a vertex
    for (size_t i = 1; i < arc; ++i) {
        const double a = kPi * static_cast<double>(i) / static_cast<double>(arc);
        line.push_back({-1.5 * std::cos(a), 0, -1.5 * std::sin(a)});
    }
    line.push_back({1.5, 0, 0});
    line.push_back({1.5, 0, 4});
    return detail::swept_pipe("U bend", pose, std::move(line), 0.5, n, seed);
}

// A coil: two turns of the helix (2 cos t, 2 sin t, 3 t / (2 pi)), t in [0, 4 pi], about
// the axis: turns 3 apart, a gap of 2 between them. Along z each section is one crescent,
// turning about the axis with the height.
inline Shape coil(size_t n, Pose pose, uint64_t seed = 40) {
    std::vector<std::array<double, 3>> line;
    const size_t segments = 2048;
    for (size_t i = 0; i <= segments; ++i) {
        const double f = static_cast<double>(i) / static_cast<double>(segments);
        line.push_back({2 * std::cos(4 * kPi * f), 2 * std::sin(4 * kPi * f), 6 * f});
    }
    return detail::swept_pipe("coil", pose, std::move(line), 0.5, n, seed);
}

// A torus about the axis: major radius 2, minor 0.6. Its sections along z are rings.
inline Shape torus(size_t n, Pose pose, uint64_t seed = 41) {
    const double major = 2, minor = 0.6;
    Shape s = detail::start("torus", pose, cylinder_radius, -minor, minor);
    s.closed_distance = [major, minor](const double* p) {
        return std::hypot(std::hypot(p[0], p[1]) - major, p[2]) - minor;
    };
    s.spacing = std::sqrt(4 * kPi * kPi * major * minor / static_cast<double>(n));
    Rng rng(seed);
    s.xyz.reserve(3 * n);
    while (s.size() < n) {
        const double u = rng.uniform(0, 2 * kPi), v = rng.uniform(0, 2 * kPi);
        // The area element grows with the distance from the axis.
        if (rng.uniform() * (major + minor) > major + minor * std::cos(v)) continue;
        s.add_local(u, minor * std::sin(v), major + minor * std::cos(v));
    }
    return s;
}

// A spool as a CAD model gives it: the vertices of its tessellation, rings of `per_ring`
// points on the circles where its faces meet (a shaft of radius 0.5 from z = -1.6 to 1.6
// between two flanges of radius 2 and thickness 0.4), and none inside its flat faces.
inline Shape cad_spool(size_t per_ring, Pose pose) {
    Shape s = detail::start("CAD spool", pose, cylinder_radius, -2, 2);
    const double rings[][2] = {{-2, 0.5}, {-2, 2}, {-1.6, 2}, {-1.6, 0.5},
                               {1.6, 0.5}, {1.6, 2}, {2, 2}, {2, 0.5}};
    for (const auto& ring : rings)
        for (size_t k = 0; k < per_ring; ++k)
            s.add_local(2 * kPi * static_cast<double>(k) / static_cast<double>(per_ring), ring[0], ring[1]);
    s.closed_distance = [](const double* p) {
        const double r = std::hypot(p[0], p[1]), z = std::fabs(p[2]);
        auto box = [&](double radius, double low, double high) {  // a solid cylinder's distance
            const double dr = r - radius, dz = std::max(low - z, z - high);
            return dr > 0 && dz > 0 ? std::hypot(dr, dz) : std::max(dr, dz);
        };
        return std::min(box(0.5, 0, 2), box(2, 1.6, 2));
    };
    s.spacing = 2 * kPi * 2 / static_cast<double>(per_ring);
    return s;
}

// A cylindrical range scan: a regular (theta, z) grid on the unit cylinder over
// z in [-3, 3], with about n points in rows of equal angular and vertical spacing. Every
// grid cell is a rectangle: four cocircular points, everywhere.
inline Shape scan_grid(size_t n, Pose pose) {
    Shape s = detail::start("cylindrical range scan grid", pose, cylinder_radius, -3, 3);
    const double height = 6, circumference = 2 * kPi;
    // columns * rows ~ n with circumference / columns ~ height / (rows - 1).
    size_t columns = static_cast<size_t>(std::lround(std::sqrt(static_cast<double>(n) * circumference / height)));
    if (columns < 8) columns = 8;
    size_t rows = (n + columns - 1) / columns;
    if (rows < 2) rows = 2;
    s.spacing = std::fmax(circumference / static_cast<double>(columns),
                          height / static_cast<double>(rows - 1));
    for (size_t j = 0; j < rows; ++j) {
        double z = -3 + height * static_cast<double>(j) / static_cast<double>(rows - 1);
        s.planes.push_back(z);
        for (size_t i = 0; i < columns; ++i)
            s.add_local(2 * kPi * static_cast<double>(i) / static_cast<double>(columns), z, 1.0);
    }
    return s;
}

// A stack of planar contours, like CT or MRI slices: `slices` equally spaced planes over
// z in [-3, 3] through the vase, each cut by a contour of about n / slices points at equal
// angles from a random phase. Many points share each height.
inline Shape ct_slices(size_t n, Pose pose, size_t slices = 20, uint64_t seed = 20) {
    Shape s = detail::start("CT slice stack (vase)", pose, vase_radius, -3, 3);
    Rng rng(seed);
    size_t per_slice = n / slices;
    double gap = 6.0 / static_cast<double>(slices - 1);
    s.spacing = std::fmax(gap, 2 * kPi * 1.5 / static_cast<double>(per_slice));
    for (size_t j = 0; j < slices; ++j) {
        double z = -3 + gap * static_cast<double>(j);
        if (j + 1 == slices) z = 3;
        s.planes.push_back(z);
        double phase = rng.uniform();
        for (size_t i = 0; i < per_slice; ++i) {
            double theta = 2 * kPi * (static_cast<double>(i) + phase) / static_cast<double>(per_slice);
            s.add_local(theta, z, vase_radius(theta, z));
        }
    }
    return s;
}

// The test shapes under the short names the suites log. Tests pick shapes by their index
// here, so new shapes go at the end.
struct Kind {
    const char* name;
    Shape (*make)(size_t n, Pose pose);
};

inline const std::vector<Kind>& kinds() {
    static const std::vector<Kind> list = {
        {"cylinder", [](size_t n, Pose p) { return cylinder(n, p); }},
        {"elliptic tube", [](size_t n, Pose p) { return elliptic_tube(n, p); }},
        {"bumpy tube", [](size_t n, Pose p) { return bumpy_tube(n, p); }},
        {"cone", [](size_t n, Pose p) { return cone(n, p); }},
        {"vase", [](size_t n, Pose p) { return vase(n, p); }},
        {"scan grid", [](size_t n, Pose p) { return scan_grid(n, p); }},
        {"CT slices", [](size_t n, Pose p) { return ct_slices(n, p); }},
        {"noisy tube", [](size_t n, Pose p) { return noisy_tube(n, p); }},
        {"head", [](size_t n, Pose p) { return head(n, p); }},
        {"slanted tube", [](size_t n, Pose p) { return slanted_tube(n, p); }},
    };
    return list;
}

}  // namespace shapes

#endif  // STRATMESH_TESTS_SUPPORT_SHAPES_H
