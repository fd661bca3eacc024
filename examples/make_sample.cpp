// make_sample: writes the bundled sample cloud, examples/data/bust.ply.
//
// A synthetic head-and-neck bust in millimetres, z up, about 260 mm tall: a neck that
// flares into the shoulders at the bottom, an egg-shaped head with a nose, chin, lips,
// brow, eye sockets and ears, closed by the crown. Points are spread evenly over the
// surface with a little noise along the normal and a few exact duplicates, as a scanner
// would deliver them; each carries a normal (float nx, ny, nz) and an intensity (uchar)
// the reconstruction ignores. Every horizontal section is star-shaped around the z axis
// (the surface is r(z, theta) in cylindrical coordinates), as stratmesh expects.
//
// Deterministic: its own PRNG and a fixed seed. The file is binary little-endian PLY.
//
// Usage: make_sample [OUTPUT.ply] [--points N] [--seed S]
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

const double kPi = 3.14159265358979323846;

// xorshift64* (Marsaglia's xorshift with a multiplicative output scramble).
class Random {
public:
    explicit Random(uint64_t seed) : state_(seed ? seed : 0x9e3779b97f4a7c15ull) {}

    uint64_t next() {
        state_ ^= state_ >> 12;
        state_ ^= state_ << 25;
        state_ ^= state_ >> 27;
        return state_ * 0x2545f4914f6cdd1dull;
    }
    // Uniform in [0, 1).
    double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
    // Roughly normal, mean 0, deviation 1 (sum of twelve uniforms).
    double gaussian() {
        double sum = 0;
        for (int i = 0; i < 12; ++i) sum += uniform();
        return sum - 6.0;
    }

private:
    uint64_t state_;
};

struct Vec {
    double x, y, z;
};

Vec sub(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec cross(Vec a, Vec b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double length(Vec a) { return std::sqrt(dot(a, a)); }

double smoothstep(double edge0, double edge1, double x) {
    double t = (x - edge0) / (edge1 - edge0);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return t * t * (3 - 2 * t);
}

// Distance from the origin, along direction theta, to the ellipse centred at (cx, cy) with
// semi-axes a (along x) and b (along y). The origin must be inside the ellipse.
double ray_to_ellipse(double theta, double cx, double cy, double a, double b) {
    double dx = std::cos(theta) / a, dy = std::sin(theta) / b;
    double ox = -cx / a, oy = -cy / b;
    double qa = dx * dx + dy * dy, qb = 2 * (ox * dx + oy * dy), qc = ox * ox + oy * oy - 1;
    return (-qb + std::sqrt(qb * qb - 4 * qa * qc)) / (2 * qa);
}

// A bump of height `amplitude` centred at (z0, theta0) on the surface.
struct Bump {
    double z0, theta0, amplitude, sigma_z, sigma_theta;

    double at(double z, double theta) const {
        double dt = std::remainder(theta - theta0, 2 * kPi);
        double u = (z - z0) / sigma_z, v = dt / sigma_theta;
        return amplitude * std::exp(-0.5 * (u * u + v * v));
    }
};

const double kFront = kPi / 2; // the face looks along +y
const Bump kFeatures[] = {
    {165, kFront, 19, 13, 0.13},                                 // nose
    {118, kFront, 9, 9, 0.35},                                   // chin
    {139, kFront, 4, 4, 0.25},                                   // lips
    {194, kFront, 3, 5, 0.5},                                    // brow
    {184, kFront - 0.38, -5, 6, 0.12},                           // eye sockets
    {184, kFront + 0.38, -5, 6, 0.12}, {170, 0.0, 11, 16, 0.10}, // ears
    {170, kPi, 11, 16, 0.10},
};

const double kHeadCentre = 175, kHeadHalfHeight = 85, kTop = kHeadCentre + kHeadHalfHeight;

double neck_radius(double z, double theta) {
    double flare = 1 + 0.6 * std::exp(-z / 18); // into the shoulders
    double fade = 1 - smoothstep(120, 200, z);  // hidden inside the head higher up
    return ray_to_ellipse(theta, 0, -14, 47, 44) * flare * fade;
}

double head_radius(double z, double theta) {
    double u = (z - kHeadCentre) / kHeadHalfHeight;
    if (u <= -1 || u >= 1) return 0;
    double jaw = 1 - 0.12 * smoothstep(170, 110, z); // narrower below the cheekbones
    return ray_to_ellipse(theta, 0, 4, 74 * jaw, 94) * std::sqrt(1 - u * u);
}

// The surface radius at height z in direction theta.
double radius(double z, double theta) {
    double n = neck_radius(z, theta), h = head_radius(z, theta);
    double r = std::pow(std::pow(n, 5) + std::pow(h, 5), 1.0 / 5); // a soft maximum
    double fade = 1 - smoothstep(230, kTop, z);                    // no feature reaches the crown
    for (const Bump& b : kFeatures) r += b.at(z, theta) * fade;
    return r;
}

// The surface as a map of (s, theta), s in [0, 1]: straight up the neck, then along the
// head's meridian so that the crown is reached at a finite slope.
double height_of(double s) {
    const double kBend = 0.7;
    if (s <= kBend) return kHeadCentre * s / kBend;
    return kHeadCentre + kHeadHalfHeight * std::sin(0.5 * kPi * (s - kBend) / (1 - kBend));
}

Vec surface(double s, double theta) {
    double z = height_of(s);
    double r = radius(z, theta);
    return {r * std::cos(theta), r * std::sin(theta), z};
}

// The unnormalised outward normal; its length is the area element dA / (ds dtheta).
Vec area_normal(double s, double theta) {
    const double h = 1e-5;
    Vec ds = sub(surface(s + h, theta), surface(s - h, theta));
    Vec dt = sub(surface(s, theta + h), surface(s, theta - h));
    Vec n = cross(dt, ds);
    double scale = 1 / (4 * h * h);
    return {n.x * scale, n.y * scale, n.z * scale};
}

double largest_area_element() {
    double most = 0;
    for (int i = 1; i < 400; ++i)
        for (int j = 0; j < 400; ++j)
            most = std::fmax(most, length(area_normal(i / 400.0, 2 * kPi * j / 400.0)));
    return 1.25 * most;
}

struct Sample {
    float position[3];
    float normal[3];
    unsigned char intensity;
};

// The scanner's brightness: lit from the front and above, with speckle.
unsigned char intensity_of(Vec unit_normal, Random& random) {
    Vec light = {0.0, 0.8, 0.6};
    double shade = 60 + 170 * std::fmax(0.0, dot(unit_normal, light)) + 6 * random.gaussian();
    shade = shade < 0 ? 0 : (shade > 255 ? 255 : shade);
    return static_cast<unsigned char>(shade);
}

Sample make_sample(double s, double theta, Vec n, Random& random) {
    const double kNoise = 0.15; // millimetres along the normal
    Vec unit = {n.x / length(n), n.y / length(n), n.z / length(n)};
    Vec p = surface(s, theta);
    double offset = kNoise * random.gaussian();
    Sample out;
    const double position[3] = {p.x + offset * unit.x, p.y + offset * unit.y,
                                p.z + offset * unit.z};
    const double normal[3] = {unit.x, unit.y, unit.z};
    for (int k = 0; k < 3; ++k) {
        out.position[k] = static_cast<float>(position[k]);
        out.normal[k] = static_cast<float>(normal[k]);
    }
    out.intensity = intensity_of(unit, random);
    return out;
}

// Rejection sampling: uniform in (s, theta), kept in proportion to the area element.
std::vector<Sample> sample_bust(size_t count, uint64_t seed) {
    const size_t kDuplicateEvery = 1000; // scanners repeat the odd point
    Random random(seed);
    double most = largest_area_element();
    std::vector<Sample> samples;
    while (samples.size() < count) {
        double s = random.uniform(), theta = 2 * kPi * random.uniform();
        Vec n = area_normal(s, theta);
        if (random.uniform() * most >= length(n)) continue;
        samples.push_back(make_sample(s, theta, n, random));
        if (samples.size() % kDuplicateEvery == 0 && samples.size() < count)
            samples.push_back(samples.back());
    }
    return samples;
}

void put_float_le(std::string& out, float value) {
    uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    for (int i = 0; i < 4; ++i) out += static_cast<char>((bits >> (8 * i)) & 0xffu);
}

std::string ply_image(const std::vector<Sample>& samples) {
    std::string out =
        "ply\nformat binary_little_endian 1.0\n"
        "comment stratmesh sample: a synthetic head-and-neck bust, millimetres, z up\n"
        "comment made by examples/make_sample.cpp\n"
        "element vertex " +
        std::to_string(samples.size()) +
        "\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "property uchar intensity\nend_header\n";
    for (const Sample& s : samples) {
        for (float v : s.position) put_float_le(out, v);
        for (float v : s.normal) put_float_le(out, v);
        out += static_cast<char>(s.intensity);
    }
    return out;
}

bool parse_arguments(int argc, char** argv, std::string& path, size_t& count, uint64_t& seed) {
    for (int i = 1; i < argc; ++i) {
        std::string arg = argv[i];
        bool has_value = i + 1 < argc;
        if (arg == "--points" && has_value) {
            count = std::strtoull(argv[++i], nullptr, 10);
        } else if (arg == "--seed" && has_value) {
            seed = std::strtoull(argv[++i], nullptr, 10);
        } else if (!arg.empty() && arg[0] != '-') {
            path = arg;
        } else {
            return false;
        }
    }
    return count >= 3;
}

} // namespace

int main(int argc, char** argv) {
    std::string path = "bust.ply";
    size_t count = 30000;
    uint64_t seed = 20240601;
    if (!parse_arguments(argc, argv, path, count, seed)) {
        std::fprintf(stderr, "usage: make_sample [OUTPUT.ply] [--points N (>= 3)] [--seed S]\n");
        return 2;
    }
    std::string image = ply_image(sample_bust(count, seed));
    std::FILE* file = std::fopen(path.c_str(), "wb");
    bool ok = file && std::fwrite(image.data(), 1, image.size(), file) == image.size();
    if (file && std::fclose(file) != 0) ok = false;
    if (!ok) {
        std::fprintf(stderr, "make_sample: cannot write %s\n", path.c_str());
        return 3;
    }
    std::printf("%s: %zu points, %zu bytes\n", path.c_str(), count, image.size());
    return 0;
}
