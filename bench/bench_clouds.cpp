// bench_clouds.cpp - the benchmark's 3D point clouds (see bench_clouds.h).

#include "bench_clouds.h"

#include "bench_random.h"

#include <algorithm>
#include <cmath>

namespace bench {

const double kHeadCuts[5] = {68, 74, 135, 210, 270};
const double kVentricleCuts[2] = {15, 30};
const double kSkullCuts[3] = {-3, 1, 4};

namespace {

const double kPi = 3.14159265358979323846;
const double kTwoPi = 6.28318530717958647692;

// 0 below a, 1 above b, a smooth cubic between.
double smoothstep(double a, double b, double x) {
    double t = (x - a) / (b - a);
    if (t <= 0) return 0;
    if (t >= 1) return 1;
    return t * t * (3 - 2 * t);
}

// A Gaussian bump of width s, 1 at d = 0.
double bump(double d, double s) { return std::exp(-0.5 * (d / s) * (d / s)); }

// The signed angle from b to a, in [-pi, pi].
double angle_offset(double a, double b) {
    double d = std::fmod(a - b, kTwoPi);
    if (d > kPi) d -= kTwoPi;
    if (d < -kPi) d += kTwoPi;
    return d;
}

// The angle to the nearer of the two sides (theta = 0 and theta = pi).
double side_offset(double theta) {
    return std::min(std::fabs(angle_offset(theta, 0)), std::fabs(angle_offset(theta, kPi)));
}

// The radius of an ellipse with semi-axes a (along x) and b (along y) at angle theta.
double ellipse_radius(double theta, double a, double b) {
    double c = std::cos(theta) / a, s = std::sin(theta) / b;
    return 1 / std::sqrt(c * c + s * s);
}

// ==== Sampling a surface ==================================================================
//
// A surface around a vertical axis, parametrised by the angle theta in [0, 2 pi) and t in
// [0, 1] from bottom to top, with a relative sampling density. Points are drawn by
// rejection: a uniform (theta, t) is kept with probability proportional to the area of the
// surface element there times the density, so the points are spread by area, denser
// where the density says.

struct Surface {
    void (*point)(double theta, double t, double p[3]);
    double (*density)(double theta, double t);
};

// The surface area per unit of (theta, t) at (theta, t), times the density there.
double sample_weight(const Surface& surface, double theta, double t) {
    const double h = 1e-6;
    double t0 = std::max(0.0, t - h), t1 = std::min(1.0, t + h);
    double a[3], b[3], c[3], d[3];
    surface.point(theta - h, t, a);
    surface.point(theta + h, t, b);
    surface.point(theta, t0, c);
    surface.point(theta, t1, d);
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) {
        u[k] = (b[k] - a[k]) / (2 * h);
        v[k] = (d[k] - c[k]) / (t1 - t0);
    }
    double n0 = u[1] * v[2] - u[2] * v[1];
    double n1 = u[2] * v[0] - u[0] * v[2];
    double n2 = u[0] * v[1] - u[1] * v[0];
    return std::sqrt(n0 * n0 + n1 * n1 + n2 * n2) * surface.density(theta, t);
}

void sample_surface(const Surface& surface, size_t n, uint64_t seed, std::vector<double>& xyz) {
    // The acceptance bound: the largest weight on a fine grid, with a margin.
    const int steps = 512;
    double most = 0;
    for (int i = 0; i < steps; ++i) {
        double theta = kTwoPi * (i + 0.5) / steps;
        for (int j = 0; j <= steps; ++j) {
            double t = static_cast<double>(j) / steps;
            most = std::max(most, sample_weight(surface, theta, t));
        }
    }
    most *= 1.25;
    Random random(seed);
    xyz.resize(3 * n);
    size_t k = 0;
    while (k < n) {
        double theta = kTwoPi * random.uniform();
        double t = random.uniform();
        if (random.uniform() * most >= sample_weight(surface, theta, t)) continue;
        surface.point(theta, t, &xyz[3 * k]);
        ++k;
    }
}

// ==== The head (experiment 1) =============================================================

const double kHeadBottom = 21.88, kHeadTop = 305.35;
const double kHeadFront = kPi / 2;  // the face looks along +y

double head_height(double t) { return kHeadBottom + (kHeadTop - kHeadBottom) * t; }

double head_radius(double theta, double z) {
    // Neck, jaw, face, skull, then the crown narrowing towards the open top.
    double r = 52 + 20 * smoothstep(60, 98, z) + 8 * smoothstep(98, 140, z) +
               5 * smoothstep(140, 215, z) - 27 * smoothstep(245, kHeadTop, z);
    r *= ellipse_radius(theta, 0.9, 1.1);  // deeper front to back than side to side
    double f = angle_offset(theta, kHeadFront);
    r += 10 * bump(f, 0.45) * bump(z - 88, 8);                               // chin
    r += 7 * bump(f, 0.35) * bump(z - 112, 5);                               // lips
    r += 22 * bump(f, 0.15) * bump(z - 160, 13);                             // nose
    r -= 6 * (bump(f - 0.42, 0.13) + bump(f + 0.42, 0.13)) * bump(z - 183, 6);  // eyes
    r += 5 * bump(f, 0.6) * bump(z - 194, 4);                                // brow
    r += 13 * bump(side_offset(theta), 0.12) * bump(z - 172, 13);            // ears
    return r;
}

void head_point(double theta, double t, double p[3]) {
    double z = head_height(t);
    double r = head_radius(theta, z);
    double neck_back = -12 * (1 - smoothstep(60, 110, z));  // the neck sits behind the face
    p[0] = 88.93 + r * std::cos(theta);
    p[1] = -97.0 + neck_back + r * std::sin(theta);
    p[2] = z;
}

double head_density(double theta, double t) {
    double z = head_height(t);
    double f = angle_offset(theta, kHeadFront);
    return 1 + 3 * bump(f, 0.45) * bump(z - 110, 11)                          // mouth, chin
           + 3 * bump(f, 0.2) * bump(z - 160, 14)                             // nose
           + 2 * (bump(f - 0.42, 0.16) + bump(f + 0.42, 0.16)) * bump(z - 183, 7)  // eyes
           + 2 * bump(side_offset(theta), 0.2) * bump(z - 172, 15);           // ears
}

// ==== The skull (experiment 3) ============================================================

const double kSkullBottom = -10.6, kSkullTop = 7.5;
const double kSkullCrown = 0.5;    // the dome starts here
const double kSkullSplit = 0.6;    // ... at this t
const double kSkullFront = -kPi / 2;  // the face looks along -y

// The height of the section at t, and its size relative to the widest section.
void skull_level(double t, double& z, double& scale) {
    if (t <= kSkullSplit) {
        z = kSkullBottom + (kSkullCrown - kSkullBottom) * t / kSkullSplit;
        scale = 0.62 + 0.33 * smoothstep(kSkullBottom, -3, z) +
                0.05 * smoothstep(-3, kSkullCrown, z);
    } else {
        double phi = (t - kSkullSplit) / (1 - kSkullSplit) * (kPi / 2);
        z = kSkullCrown + (kSkullTop - kSkullCrown) * std::sin(phi);
        scale = std::cos(phi);  // 0 at the top: the dome is closed
    }
}

void skull_point(double theta, double t, double p[3]) {
    double z = 0, scale = 0;
    skull_level(t, z, scale);
    double r = ellipse_radius(theta, 7.45, 9.85);
    double f = angle_offset(theta, kSkullFront);
    r -= 1.6 * (bump(f - 0.5, 0.16) + bump(f + 0.5, 0.16)) * bump(z + 1.0, 1.1);  // eyes
    r += 0.9 * (bump(f - 1.0, 0.2) + bump(f + 1.0, 0.2)) * bump(z + 2.6, 0.9);    // cheekbones
    r -= 1.1 * bump(f, 0.14) * bump(z + 4.2, 1.0);                                // nose
    r += 0.8 * bump(side_offset(theta), 0.15) * bump(z + 1.8, 1.2);               // ears
    r *= scale;
    p[0] = 2.05 + r * std::cos(theta);
    p[1] = -1.35 + r * std::sin(theta);
    p[2] = z;
}

double skull_density(double theta, double t) {
    double z = 0, scale = 0;
    skull_level(t, z, scale);
    double f = angle_offset(theta, kSkullFront);
    double eyes = (bump(f - 0.5, 0.25) + bump(f + 0.5, 0.25)) * bump(z + 1.0, 1.3);
    double cheekbones = (bump(f - 1.0, 0.3) + bump(f + 1.0, 0.3)) * bump(z + 2.2, 1.0);
    double ears = bump(side_offset(theta), 0.25) * bump(z + 1.8, 1.3);
    return 1 + 2 * eyes + 2 * cheekbones + 2 * ears;
}

// ==== The right ventricle (experiment 2) ==================================================

const int kVentricleContours = 89;    // z = 0, 0.5, ..., 44
const double kVentricleSpacing = 0.5;
const double kVentricleSeptum = 0.3 * kPi;  // where the septum pushes the wall in

double ventricle_radius(double theta, double z) {
    double size = 8 + 37 * std::pow(z / 44, 0.6);  // from the apex to the base
    return size * (1 + 0.08 * std::cos(2 * theta) -
                   0.3 * bump(angle_offset(theta, kVentricleSeptum), 0.55));
}

double ventricle_perimeter(double z) {
    const int steps = 720;
    double length = 0, px = ventricle_radius(0, z), py = 0;
    for (int i = 1; i <= steps; ++i) {
        double theta = kTwoPi * i / steps;
        double r = ventricle_radius(theta, z);
        double x = r * std::cos(theta), y = r * std::sin(theta);
        length += std::hypot(x - px, y - py);
        px = x;
        py = y;
    }
    return length;
}

// Splits n into shares proportional to `weights`, summing to n exactly (largest remainder).
std::vector<size_t> proportional_shares(size_t n, const std::vector<double>& weights) {
    double total = 0;
    for (double w : weights) total += w;
    std::vector<size_t> shares(weights.size());
    std::vector<std::pair<double, size_t>> remainders;
    size_t given = 0;
    for (size_t i = 0; i < weights.size(); ++i) {
        double ideal = static_cast<double>(n) * weights[i] / total;
        shares[i] = static_cast<size_t>(std::floor(ideal));
        given += shares[i];
        remainders.emplace_back(ideal - std::floor(ideal), i);
    }
    std::sort(remainders.begin(), remainders.end(),
              [](const std::pair<double, size_t>& a, const std::pair<double, size_t>& b) {
                  return a.first != b.first ? a.first > b.first : a.second < b.second;
              });
    for (size_t k = 0; given < n; ++k, ++given)
        ++shares[remainders[k % remainders.size()].second];
    return shares;
}

}  // namespace

void generate_tube(size_t n, uint64_t seed, std::vector<double>& xyz) {
    Random random(seed);
    xyz.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
        double theta = kTwoPi * random.uniform();
        double z = 8 * random.uniform();
        double r = 1 + 0.25 * std::sin(5 * theta) * std::cos(z);
        xyz[3 * i] = r * std::cos(theta);
        xyz[3 * i + 1] = r * std::sin(theta);
        xyz[3 * i + 2] = z;
    }
}

const double kVaseCuts[2] = {-kPi / 3, kPi / 3};
const double kBentTubeCuts[4] = {-3.6, -1.2, 1.2, 3.6};

void generate_vase(size_t n, uint64_t seed, std::vector<double>& xyz) {
    Random random(seed);
    xyz.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
        double theta = kTwoPi * random.uniform();
        double z = -3 + 6 * random.uniform();
        double r = 1 + 0.5 * std::sin(1.5 * z);
        xyz[3 * i] = r * std::cos(theta);
        xyz[3 * i + 1] = r * std::sin(theta);
        xyz[3 * i + 2] = z;
    }
}

void generate_bent_tube(size_t n, uint64_t seed, std::vector<double>& xyz) {
    Random random(seed);
    xyz.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
        double theta = kTwoPi * random.uniform();
        double z = -6 + 12 * random.uniform();
        xyz[3 * i] = 2 * std::sin(kPi * z / 12) + std::cos(theta);
        xyz[3 * i + 1] = std::sin(theta);
        xyz[3 * i + 2] = z;
    }
}

void generate_paper_head(size_t n, uint64_t seed, std::vector<double>& xyz) {
    sample_surface(Surface{head_point, head_density}, n, seed, xyz);
}

void generate_paper_skull(size_t n, uint64_t seed, std::vector<double>& xyz) {
    sample_surface(Surface{skull_point, skull_density}, n, seed, xyz);
}

void generate_paper_ventricle(size_t n, uint64_t seed, std::vector<double>& xyz) {
    std::vector<double> perimeters(kVentricleContours);
    for (int k = 0; k < kVentricleContours; ++k)
        perimeters[static_cast<size_t>(k)] = ventricle_perimeter(kVentricleSpacing * k);
    std::vector<size_t> shares = proportional_shares(n, perimeters);
    Random random(seed);
    xyz.clear();
    xyz.reserve(3 * n);
    for (int k = 0; k < kVentricleContours; ++k) {
        double z = kVentricleSpacing * k;
        size_t m = shares[static_cast<size_t>(k)];
        double step = kTwoPi / static_cast<double>(m);
        double start = step * random.uniform();
        double cx = 60.8 + 3 * z / 44, cy = 79.3 - 2 * z / 44;  // a slightly tilted axis
        for (size_t j = 0; j < m; ++j) {
            double theta = start + step * static_cast<double>(j);
            double r = ventricle_radius(theta, z);
            xyz.push_back(cx + r * std::cos(theta));
            xyz.push_back(cy + r * std::sin(theta));
            xyz.push_back(z);
        }
    }
}

}  // namespace bench
