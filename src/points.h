// >>points ===============================================================================
// The cloud's points as the library reads them, and the vector arithmetic on them.
//
// The cloud is read in place (float or double, any stride): CloudReader turns point i into
// doubles and says whether it is valid (finite, and not left out as an outlier).

namespace stratmesh {
namespace detail {

struct Vec3 {
    double x, y, z;
};

static inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }

static inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

static inline Vec3 scaled(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }

struct CloudReader {
    const unsigned char* base;
    size_t stride;
    bool is_float;
    const unsigned char* dropped;  // optional bitmap: points left out as outliers

    Vec3 point(size_t i) const {
        const unsigned char* p = base + i * stride;
        if (is_float) {
            float v[3];
            std::memcpy(v, p, sizeof v);
            return {static_cast<double>(v[0]), static_cast<double>(v[1]),
                    static_cast<double>(v[2])};
        }
        double v[3];
        std::memcpy(v, p, sizeof v);
        return {v[0], v[1], v[2]};
    }
    bool valid(size_t i) const {
        if (kDropOutliers && dropped && ((dropped[i >> 3] >> (i & 7)) & 1)) return false;
        // One test for three coordinates: a product by zero is zero exactly when the
        // coordinate is finite, and it never overflows.
        Vec3 p = point(i);
        return p.x * 0 + p.y * 0 + p.z * 0 == 0;
    }
};

// The coordinate axis along which d is shortest (x where it ties for that, else z over y):
// crossed with d, it gives a direction well across d.
static inline Vec3 axis_least_along(Vec3 d) {
    if (abs_value(d.x) > abs_value(d.y) || abs_value(d.x) > abs_value(d.z))
        return abs_value(d.y) < abs_value(d.z) ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
    return {1, 0, 0};
}

static inline double largest_of(Vec3 v) {
    const double xy = v.x > v.y ? v.x : v.y;
    return xy > v.z ? xy : v.z;
}

static inline double coordinate(Vec3 p, int k) { return k == 0 ? p.x : k == 1 ? p.y : p.z; }

// False unless v's squared length is a normal double (v's length between about 1.5e-154
// and 1.3e154): a subnormal square has lost the bits that make the result unit.

static inline bool normalize(Vec3& v) {
    const double square = dot(v, v);
    if (!(square >= DBL_MIN) || !is_finite(square)) return false;
    const double len = std::sqrt(square);
    v = scaled(v, 1.0 / len);
    return true;
}

// A direction of any finite non-zero length made unit: first scaled by the power of two
// that brings its largest component into [1, 2) (exact: a component that falls below the
// smallest subnormal is negligible beside it), so that its square neither overflows nor
// underflows. False for zero, NaN or infinite components.
static inline bool unit_direction(Vec3& v) {
    if (!is_finite(v.x) || !is_finite(v.y) || !is_finite(v.z)) return false;
    const double largest = largest_of({abs_value(v.x), abs_value(v.y), abs_value(v.z)});
    if (largest == 0) return false;
    int exponent = 0;
    std::frexp(largest, &exponent);
    v = {std::ldexp(v.x, 1 - exponent), std::ldexp(v.y, 1 - exponent), std::ldexp(v.z, 1 - exponent)};
    return normalize(v);
}

}  // namespace detail
}  // namespace stratmesh
