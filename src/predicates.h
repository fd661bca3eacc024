// >>predicates ===========================================================================
// orient2d and incircle: filter, integer and expansion stages.
//
// This work is based on:
//   J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
//   Predicates", Discrete & Computational Geometry 18:305-363, 1997.
//   O. Devillers, M. Teillaud, "Perturbations for Delaunay and weighted Delaunay 3D
//   triangulations", Computational Geometry 44(3), 2011 (the symbolic perturbation).
//
// An expansion is an array of doubles, sorted by increasing magnitude, nonoverlapping,
// whose exact sum is the represented value; its sign is the sign of its last component.
// Error bounds use eps = 2^-53 (half an ulp of 1) and are derived in Shewchuk's paper:
// for a determinant evaluated in floating point, |computed - exact| <= bound * permanent,
// where the permanent is the same expression with absolute values everywhere.

namespace stratmesh {
namespace detail {

constexpr double kEps = DBL_EPSILON / 2;

constexpr double kSplitter = 134217729.0; // 2^27 + 1: splits a double into two 26-bit halves

constexpr double kOrientBoundA = (3.0 + 16.0 * kEps) * kEps;

constexpr double kIncircleBoundA = (10.0 + 96.0 * kEps) * kEps;

// a + b = x + y exactly, with x = fl(a + b).
static inline void two_sum(double a, double b, double& x, double& y) {
    x = a + b;
    double bv = x - a;
    double av = x - bv;
    y = (a - av) + (b - bv);
}

// a - b = x + y exactly, with x = fl(a - b).
static inline void two_diff(double a, double b, double& x, double& y) {
    x = a - b;
    double bv = a - x;
    double av = x + bv;
    y = (a - av) + (bv - b);
}

static inline void split(double a, double& hi, double& lo) {
    double c = kSplitter * a;
    double big = c - a;
    hi = c - big;
    lo = a - hi;
}

// a * b = x + y exactly, with x = fl(a * b) (Dekker's product, Veltkamp's split).
static inline void two_product(double a, double b, double& x, double& y) {
    x = a * b;
    double ahi, alo, bhi, blo;
    split(a, ahi, alo);
    split(b, bhi, blo);
    double err1 = x - ahi * bhi;
    double err2 = err1 - alo * bhi;
    double err3 = err2 - ahi * blo;
    y = alo * blo - err3;
}

// (a1 + a0) - (b1 + b0) as a four-component expansion out[0..3], least significant first.
static inline void two_two_diff(double a1, double a0, double b1, double b0, double* out) {
    double i, j, z;
    two_diff(a0, b0, i, out[0]);
    two_sum(a1, i, j, z);
    two_diff(z, b1, i, out[1]);
    two_sum(j, i, out[3], out[2]);
}

// ax*by - ay*bx as a four-component expansion.
static inline void cross_exact(double ax, double ay, double bx, double by, double* out) {
    double p1, p0, q1, q0;
    two_product(ax, by, p1, p0);
    two_product(ay, bx, q1, q0);
    two_two_diff(p1, p0, q1, q0, out);
}

// h = e + f; returns the length of h with zero components removed (at least 1). h needs
// room for elen + flen components and must not alias e or f.
static inline int expansion_sum(int elen, const double* e, int flen, const double* f, double* h) {
    int ei = 0, fi = 0, hi = 0;
    double q = 0, hh = 0;
    bool first = true;
    while (ei < elen || fi < flen) {
        double next;
        if (fi >= flen || (ei < elen && abs_value(e[ei]) < abs_value(f[fi]))) {
            next = e[ei++];
        } else {
            next = f[fi++];
        }
        if (first) {
            q = next;
            first = false;
            continue;
        }
        double s;
        two_sum(q, next, s, hh);
        q = s;
        if (hh != 0) h[hi++] = hh;
    }
    if (q != 0 || hi == 0) h[hi++] = q;
    return hi;
}

// Removes the zero components of e in place; returns the new length (at least 1).
static inline int compress_zeros(int len, double* e) {
    int kept = 0;
    for (int i = 0; i < len; ++i)
        if (e[i] != 0) e[kept++] = e[i];
    if (kept == 0) e[kept++] = 0;
    return kept;
}

// h = b * e; returns the length of h (at most 2 * elen) with zeros removed. h must not
// alias e.
static inline int expansion_scale(int elen, const double* e, double b, double* h) {
    if (b == 0 || (elen == 1 && e[0] == 0)) {
        h[0] = 0;
        return 1;
    }
    double q, hh;
    two_product(e[0], b, q, hh);
    int hi = 0;
    if (hh != 0) h[hi++] = hh;
    for (int i = 1; i < elen; ++i) {
        double p1, p0, sum;
        two_product(e[i], b, p1, p0);
        two_sum(q, p0, sum, hh);
        if (hh != 0) h[hi++] = hh;
        two_sum(p1, sum, q, hh);
        if (hh != 0) h[hi++] = hh;
    }
    if (q != 0 || hi == 0) h[hi++] = q;
    return hi;
}

// h = e * f; h and tmp each need room for 2 * elen * flen components, scaled for 2 * elen.
static inline int expansion_product(int elen, const double* e, int flen, const double* f, double* h,
                             double* tmp, double* scaled) {
    int len = expansion_scale(elen, e, f[0], h);
    for (int j = 1; j < flen; ++j) {
        int slen = expansion_scale(elen, e, f[j], scaled);
        len = expansion_sum(len, h, slen, scaled, tmp);
        std::memcpy(h, tmp, sizeof(double) * static_cast<size_t>(len));
    }
    return len;
}

static inline void expansion_negate(int len, double* e) {
    for (int i = 0; i < len; ++i) e[i] = -e[i];
}

// The most significant non-zero component (0 if the expansion is zero).
static inline double expansion_top(int len, const double* e) {
    for (int i = len - 1; i >= 0; --i)
        if (e[i] != 0) return e[i];
    return 0;
}

// orient2d from the raw coordinates: a x b + b x c + c x a, exactly.
static inline double orient2d_exact(const double* a, const double* b, const double* c) {
    double ab[4], bc[4], ca[4], s[8], t[12];
    cross_exact(a[0], a[1], b[0], b[1], ab);
    cross_exact(b[0], b[1], c[0], c[1], bc);
    cross_exact(c[0], c[1], a[0], a[1], ca);
    int slen = expansion_sum(4, ab, 4, bc, s);
    int tlen = expansion_sum(slen, s, 4, ca, t);
    return expansion_top(tlen, t);
}

// The exact stages are exact only if no product underflows or overflows. Their terms are
// products of 2 (orient) or 4 (incircle) coordinates or differences, so when points are a
// few ulps apart near 1e-70, or very large, they are first scaled by a power of two that
// centres the magnitudes in play: exact, and the determinant's sign does not change.
// `values` are the coordinates and differences involved; `limit` the largest safe binary
// exponent for the degree. Returns the factor, or 0 when no scaling is needed (or none
// can help: magnitudes spread over more than the double range allows).
static inline double rescaling_factor(const double* values, int count, int limit) {
    double largest = 0, smallest = DBL_MAX;
    for (int i = 0; i < count; ++i) {
        double v = abs_value(values[i]);
        if (v == 0 || !is_finite(v)) continue;
        if (v > largest) largest = v;
        if (v < smallest) smallest = v;
    }
    if (largest == 0) return 0;
    int high = 0, low = 0;
    std::frexp(largest, &high);
    std::frexp(smallest, &low);
    if (high <= limit && low >= -limit) return 0;
    if (high - low > 2 * limit) return 0;
    // Centre the magnitudes, but never by a power of two that is itself out of range
    // (points that are all subnormal would ask for about 2^1070).
    int shift = -(high + low) / 2;
    if (shift > 1000) shift = 1000;
    if (shift < -1000) shift = -1000;
    return std::ldexp(1.0, shift);
}

// The filters' error bounds ignore underflow, which adds an absolute error of at most a
// few 2^-1075: a result is only trusted beyond this.
constexpr double kUnderflowGuard = 0x1p-1000;

// Points the first `count` entries of `points` at scaled copies in `storage`, unless
// factor is 0 (no scaling needed).
static inline void rescale_points(double factor, const double** points, double (*storage)[2],
                           int count) {
    if (factor == 0) return;
    for (int k = 0; k < count; ++k) {
        storage[k][0] = points[k][0] * factor;
        storage[k][1] = points[k][1] * factor;
        points[k] = storage[k];
    }
}

// Integer stages. Exact zeros are the common case on grids: every rectangle of grid points
// is cocircular and grid lines make collinear triples, and proving those zeros with
// expansion products costs several times more than this. Every double is an integer times
// a power of two, so when the differences a predicate uses span at most 62 bits, from the
// highest set bit of any to the lowest set bit of any, scaling them all by one power of
// two makes them integers below 2^62, and the determinant (of degree 2 or 4 in them) an
// integer below 2^125 or 2^252. Fixed-width integer arithmetic gets it exactly, whatever
// the magnitudes and without underflow, so these stages need no rescaling.

// floor(log2(|v|)) for a finite non-zero double.
static inline int top_bit_exponent(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    int biased = static_cast<int>((bits >> 52) & 0x7FF);
    if (biased != 0) return biased - 1023;
    // Subnormal: the conversion of the mantissa (below 2^52) to double is exact, and its
    // exponent field tells where the top bit is.
    double mantissa = static_cast<double>(bits & ((uint64_t(1) << 52) - 1));
    std::memcpy(&bits, &mantissa, sizeof bits);
    return static_cast<int>((bits >> 52) & 0x7FF) - 1023 - 1074;
}

// 2^e for -1022 <= e <= 1023.
static inline double power_of_two(int e) {
    uint64_t bits = static_cast<uint64_t>(e + 1023) << 52;
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
}

// Unsigned integers as little-endian arrays of 64-bit words.
struct Uint128 {
    uint64_t word[2];
};

struct Uint256 {
    uint64_t word[4];
};

// a * b exactly. Where the compiler has a 128-bit type this is one instruction on 64-bit
// targets; elsewhere it is built from 32-bit halves. Both are exact, so results agree.
static inline Uint128 multiply_wide(uint64_t a, uint64_t b) {
    Uint128 r;
#if defined(__SIZEOF_INT128__)
    __extension__ typedef unsigned __int128 uint128_type;
    uint128_type p = static_cast<uint128_type>(a) * b;
    r.word[0] = static_cast<uint64_t>(p);
    r.word[1] = static_cast<uint64_t>(p >> 64);
#else
    const uint64_t mask = 0xFFFFFFFFu;
    uint64_t a0 = a & mask, a1 = a >> 32, b0 = b & mask, b1 = b >> 32;
    uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    uint64_t middle = (p00 >> 32) + (p01 & mask) + (p10 & mask);
    r.word[0] = (middle << 32) | (p00 & mask);
    r.word[1] = p11 + (p01 >> 32) + (p10 >> 32) + (middle >> 32);
#endif
    return r;
}

// a + b + carry; carry becomes the carry out (the carry in is 0 or 1).
static inline uint64_t add_with_carry(uint64_t a, uint64_t b, uint64_t& carry) {
    uint64_t s = a + b;
    uint64_t out = s < a;
    uint64_t t = s + carry;
    carry = out | (t < s);
    return t;
}

// sum += term or sum -= term, two's complement modulo 2^(64 N); term is zero-extended.
template <size_t N, size_t M>
static inline void words_accumulate(uint64_t (&sum)[N], const uint64_t (&term)[M], bool subtract) {
    uint64_t flip = subtract ? ~uint64_t(0) : 0;
    uint64_t carry = subtract ? 1 : 0;
    for (size_t k = 0; k < N; ++k)
        sum[k] = add_with_carry(sum[k], (k < M ? term[k] : 0) ^ flip, carry);
}

// Makes a two's complement number its magnitude; returns whether it was negative.
template <size_t N>
static inline bool words_to_magnitude(uint64_t (&value)[N]) {
    if ((value[N - 1] >> 63) == 0) return false;
    uint64_t carry = 1;
    for (size_t k = 0; k < N; ++k) {
        value[k] = ~value[k] + carry;
        carry = carry & (value[k] == 0);
    }
    return true;
}

// a * b for a, b < 2^127 (the top word cannot overflow).
static inline Uint256 multiply_wide(const Uint128& a, const Uint128& b) {
    Uint128 p00 = multiply_wide(a.word[0], b.word[0]);
    Uint128 p01 = multiply_wide(a.word[0], b.word[1]);
    Uint128 p10 = multiply_wide(a.word[1], b.word[0]);
    Uint128 p11 = multiply_wide(a.word[1], b.word[1]);
    Uint256 r;
    uint64_t carry = 0, carry2 = 0;
    r.word[0] = p00.word[0];
    r.word[1] = add_with_carry(p00.word[1], p01.word[0], carry);
    r.word[1] = add_with_carry(r.word[1], p10.word[0], carry2);
    carry += carry2;
    carry2 = 0;
    r.word[2] = add_with_carry(p01.word[1], p10.word[1], carry);
    r.word[2] = add_with_carry(r.word[2], p11.word[0], carry2);
    r.word[3] = p11.word[1] + carry + carry2;
    return r;
}

// Up to six differences as integers below 2^62: value[i] * 2^shift is
// (-1)^negative[i] * magnitude[i].
struct ScaledIntegers {
    uint64_t magnitude[6];
    bool negative[6];
    int shift;
};

// Scales `count` (at most 6) exact, hence finite, differences into integers; false when
// they span more than 62 bits, or all lie below 2^-962 (the factor would leave the double
// range; rare enough to leave to the expansions).
static inline bool to_integers(const double* values, int count, ScaledIntegers& out) {
    double largest = 0;
    for (int i = 0; i < count; ++i)
        if (abs_value(values[i]) > largest) largest = abs_value(values[i]);
    out.shift = largest == 0 ? 0 : 61 - top_bit_exponent(largest);
    if (out.shift > 1023) return false;
    double scale = power_of_two(out.shift);
    for (int i = 0; i < count; ++i) {
        // Exact unless it underflows (only when scaling down), which the test below
        // catches: what underflowed is not a non-zero integer.
        double scaled = values[i] * scale;
        int64_t n = static_cast<int64_t>(scaled);
        if (static_cast<double>(n) != scaled || (n == 0 && values[i] != 0)) return false;
        out.negative[i] = n < 0;
        out.magnitude[i] = n < 0 ? 0 - static_cast<uint64_t>(n) : static_cast<uint64_t>(n);
    }
    return true;
}

// u0 v1 - u1 v0 for four of the integers, given by index: its magnitude (below 2^125)
// and whether it is negative.
static inline Uint128 integer_cross(const ScaledIntegers& z, int u0, int u1, int v0, int v1,
                             bool* negative) {
    Uint128 cross = {{0, 0}};
    Uint128 left = multiply_wide(z.magnitude[u0], z.magnitude[v1]);
    Uint128 right = multiply_wide(z.magnitude[u1], z.magnitude[v0]);
    words_accumulate(cross.word, left.word, z.negative[u0] != z.negative[v1]);
    words_accumulate(cross.word, right.word, z.negative[u1] == z.negative[v0]);
    *negative = words_to_magnitude(cross.word);
    return cross;
}

// (-1)^negative * magnitude * 2^exponent as a double. Only the sign is exact: a non-zero
// value is kept from rounding to zero or infinity.
template <size_t N>
static inline double to_signed_double(const uint64_t (&magnitude)[N], bool negative, int exponent) {
    double value = 0;
    for (size_t k = N; k-- > 0;) value = value * 0x1p64 + static_cast<double>(magnitude[k]);
    if (value == 0) return 0;
    value = std::ldexp(value, exponent);
    if (value == 0) value = DBL_TRUE_MIN;
    if (!is_finite(value)) value = DBL_MAX;
    return negative ? -value : value;
}

// orient2d from exact differences u = a - c, v = b - c: u x v, or false when the integer
// stage does not apply.
static inline bool orient2d_from_integer_differences(const double differences[4], double* det) {
    ScaledIntegers z;
    if (!to_integers(differences, 4, z)) return false;
    bool negative = false;
    Uint128 cross = integer_cross(z, 0, 1, 2, 3, &negative);
    *det = to_signed_double(cross.word, negative, -2 * z.shift);
    return true;
}

// incircle from exact differences to d, rows (dx, dy): the 3x3 determinant of rows
// (dx, dy, dx^2 + dy^2) expanded along the lifts, or false when the integer stage does
// not apply.
static inline bool incircle_from_integer_differences(const double rows[3][2], double* det) {
    ScaledIntegers z;
    if (!to_integers(&rows[0][0], 6, z)) return false;
    uint64_t sum[4] = {0, 0, 0, 0};
    for (int i = 0; i < 3; ++i) {
        // The lift of row i times the minor of the other two rows u, v: u x v.
        Uint128 lift = multiply_wide(z.magnitude[2 * i], z.magnitude[2 * i]);
        Uint128 square = multiply_wide(z.magnitude[2 * i + 1], z.magnitude[2 * i + 1]);
        words_accumulate(lift.word, square.word, false);
        int u = 2 * ((i + 1) % 3), v = 2 * ((i + 2) % 3);
        bool minor_negative = false;
        Uint128 minor = integer_cross(z, u, u + 1, v, v + 1, &minor_negative);
        words_accumulate(sum, multiply_wide(lift, minor).word, minor_negative);
    }
    bool negative = words_to_magnitude(sum);
    *det = to_signed_double(sum, negative, -4 * z.shift);
    return true;
}

// orient2d once the filter has failed: the differences are tried for exactness (in the
// integer stage, then with rescaling in expansions), then the raw coordinates are used
// (with STRATMESH_SMALL_CODE at once, after the rescaling: kFastExactStages). Kept apart
// from the filter so that the common, filtered call stays small.
STRATMESH_NOINLINE static inline double orient2d_beyond_filter(const double* a, const double* b,
                                                         const double* c) {
    double differences[4], tails[4], det = 0;
    two_diff(a[0], c[0], differences[0], tails[0]);
    two_diff(a[1], c[1], differences[1], tails[1]);
    two_diff(b[0], c[0], differences[2], tails[2]);
    two_diff(b[1], c[1], differences[3], tails[3]);
    bool exact = tails[0] == 0 && tails[1] == 0 && tails[2] == 0 && tails[3] == 0;
    if (kFastExactStages && exact && orient2d_from_integer_differences(differences, &det))
        return det;
    const double magnitudes[10] = {differences[0], differences[2], differences[1],
                                   differences[3], a[0], a[1], b[0], b[1], c[0], c[1]};
    double factor = rescaling_factor(magnitudes, 10, 400);
    const double* points[3] = {a, b, c};
    double scaled[3][2];
    rescale_points(factor, points, scaled, 3);
    a = points[0];
    b = points[1];
    c = points[2];
    double acx, acy, bcx, bcy, t0, t1, t2, t3;
    two_diff(a[0], c[0], acx, t0);
    two_diff(b[0], c[0], bcx, t1);
    two_diff(a[1], c[1], acy, t2);
    two_diff(b[1], c[1], bcy, t3);
    if (kFastExactStages && t0 == 0 && t1 == 0 && t2 == 0 && t3 == 0) {
        double d[4];
        cross_exact(acx, acy, bcx, bcy, d);
        return expansion_top(4, d);
    }
    return orient2d_exact(a, b, c);
}

// Sign-exact orient2d: the filter decides unless |det| is within the rounding error.
static inline double orient2d_robust(const double* a, const double* b, const double* c) {
    double acx = a[0] - c[0], bcx = b[0] - c[0];
    double acy = a[1] - c[1], bcy = b[1] - c[1];
    double left = acx * bcy;
    double right = acy * bcx;
    double det = left - right;
    double bound = kOrientBoundA * (abs_value(left) + abs_value(right)) + kUnderflowGuard;
    if (det > bound || -det > bound) return det;
    return orient2d_beyond_filter(a, b, c);
}

// Scratch, in doubles, for the exact incircle below.
const int kIncircleScratch = 1024;

// incircle from the raw coordinates: the 4x4 determinant with rows (x, y, x^2 + y^2, 1),
// expanded along the lift column. Needs kIncircleScratch doubles of scratch.
static inline double incircle_exact(const double* a, const double* b, const double* c,
                             const double* d, double* scratch) {
    const double* p[4] = {a, b, c, d};
    double* acc = scratch;         // 384
    double* acc2 = scratch + 384;  // 384
    double* term = scratch + 768;  // 96
    double* tmp = scratch + 864;   // 96
    double* scaled = scratch + 960; // 24
    double* orient = scratch + 984; // 12
    double* cross = scratch + 996;  // 8
    double lift[4], lp[2], lq[2];
    int acc_len = 0;
    for (int skip = 0; skip < 4; ++skip) {
        // orient2d of the other three points, in their order.
        const double* q[3];
        for (int k = 0, m = 0; k < 4; ++k)
            if (k != skip) q[m++] = p[k];
        double ab[4], bc[4], ca[4];
        cross_exact(q[0][0], q[0][1], q[1][0], q[1][1], ab);
        cross_exact(q[1][0], q[1][1], q[2][0], q[2][1], bc);
        cross_exact(q[2][0], q[2][1], q[0][0], q[0][1], ca);
        int clen = expansion_sum(4, ab, 4, bc, cross);
        int olen = expansion_sum(clen, cross, 4, ca, orient);
        two_product(p[skip][0], p[skip][0], lp[1], lp[0]);
        two_product(p[skip][1], p[skip][1], lq[1], lq[0]);
        int llen = expansion_sum(2, lp, 2, lq, lift);
        int tlen = expansion_product(olen, orient, llen, lift, term, tmp, scaled);
        // Cofactor signs of the lift column: +, -, +, -.
        if (skip % 2 == 1) expansion_negate(tlen, term);
        if (acc_len == 0) {
            std::memcpy(acc, term, sizeof(double) * static_cast<size_t>(tlen));
            acc_len = tlen;
        } else {
            acc_len = expansion_sum(acc_len, acc, tlen, term, acc2);
            std::memcpy(acc, acc2, sizeof(double) * static_cast<size_t>(acc_len));
        }
    }
    return expansion_top(acc_len, acc);
}

// An expansion rounded to a double-double hi + lo, |lo| <= eps |hi|: the components are
// summed smallest first with error-free sums, so the result is off by a few eps^2 of the
// value. (Taking the expansion's two largest components instead is not enough: a
// nonoverlapping expansion may hold a lone high bit followed by a component nearly as
// large.)
static inline void to_double_double(const double* e, int len, double* hi, double* lo) {
    double h = 0, l = 0;
    for (int k = 0; k < len; ++k) {
        double s, err;
        two_sum(h, e[k], s, err);
        h = s;
        l += err;
    }
    two_sum(h, l, *hi, *lo);
}

// incircle when the six coordinate differences are exact doubles but span too many bits
// for the integer stage: the 3x3 determinant of rows (dx, dy, L = dx^2 + dy^2), expanded
// along L. Each lift L and minor M = u x v is formed exactly (cheap). First the three
// products L M are summed in double-double arithmetic from the lifts and minors rounded
// to double-doubles (each off by a few eps^2): each product is then off by about
// 12 eps^2 |L M| and the sum adds about 6 eps^2 per term, so a result beyond
// 64 eps^2 sum |L M| has the right sign. That settles near-cocircular points whose
// determinant is not zero; exact zeros take the exact products. Needs 264 doubles of
// scratch.
static inline double incircle_from_differences(const double rows[3][2], double* scratch) {
    double lift[3][4], minor[3][4];
    int lift_len[3], minor_len[3];
    double hi = 0, lo = 0, magnitude = 0;
    for (int i = 0; i < 3; ++i) {
        const double* u = rows[(i + 1) % 3];
        const double* v = rows[(i + 2) % 3];
        cross_exact(u[0], u[1], v[0], v[1], minor[i]);
        minor_len[i] = compress_zeros(4, minor[i]);
        double sx[2], sy[2];
        two_product(rows[i][0], rows[i][0], sx[1], sx[0]);
        two_product(rows[i][1], rows[i][1], sy[1], sy[0]);
        lift_len[i] = expansion_sum(2, sx, 2, sy, lift[i]);
        double l1, l0, m1, m0, t1, t0, s, e;
        to_double_double(lift[i], lift_len[i], &l1, &l0);
        to_double_double(minor[i], minor_len[i], &m1, &m0);
        two_product(l1, m1, t1, t0);
        double cross = l1 * m0 + l0 * m1 + t0;
        two_sum(hi, t1, s, e);
        hi = s;
        lo += e + cross;
        magnitude += abs_value(l1) * abs_value(m1);
    }
    double approximate = hi + lo;
    double bound = 64 * kEps * kEps * magnitude + kUnderflowGuard;
    if (approximate > bound || -approximate > bound) return approximate;
    double* det = scratch;            // 96
    double* det2 = scratch + 96;      // 96
    double* product = scratch + 192;  // 32
    double* tmp = scratch + 224;      // 32
    double* scaled = scratch + 256;   // 8
    int det_len = 0;
    for (int i = 0; i < 3; ++i) {
        int len = expansion_product(minor_len[i], minor[i], lift_len[i], lift[i], product, tmp,
                                    scaled);
        if (det_len == 0) {
            std::memcpy(det, product, sizeof(double) * static_cast<size_t>(len));
            det_len = len;
        } else {
            det_len = expansion_sum(det_len, det, len, product, det2);
            std::memcpy(det, det2, sizeof(double) * static_cast<size_t>(det_len));
        }
    }
    return expansion_top(det_len, det);
}

// The differences of a, b, c to d, as rows; whether all six are exact.
static inline bool differences_to(const double* a, const double* b, const double* c, const double* d,
                           double rows[3][2]) {
    const double* p[3] = {a, b, c};
    bool exact = true;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 2; ++k) {
            double tail;
            two_diff(p[i][k], d[k], rows[i][k], tail);
            exact = exact && tail == 0;
        }
    return exact;
}

// incircle once the filter has failed. The integer stage goes first: the differences of
// nearby points are nearly always exact and narrow enough, and it needs no rescaling
// (there is no underflow to avoid); then the differences after rescaling; then the raw
// coordinates (with STRATMESH_SMALL_CODE only these: kFastExactStages). Kept apart from
// the filter so that the common, filtered call stays small.
STRATMESH_NOINLINE static inline double incircle_beyond_filter(const double* a, const double* b,
                                                         const double* c, const double* d,
                                                         double* scratch) {
    double rows[3][2], det = 0;
    const bool exact = differences_to(a, b, c, d, rows);
    if (kFastExactStages && exact && incircle_from_integer_differences(rows, &det))
        return det;
    const double magnitudes[14] = {rows[0][0], rows[1][0], rows[2][0], rows[0][1],
                                   rows[1][1], rows[2][1], a[0], a[1], b[0], b[1],
                                   c[0], c[1], d[0], d[1]};
    double factor = rescaling_factor(magnitudes, 14, 160);
    const double* points[4] = {a, b, c, d};
    double scaled[4][2];
    rescale_points(factor, points, scaled, 4);
    a = points[0];
    b = points[1];
    c = points[2];
    d = points[3];
    if (kFastExactStages && differences_to(a, b, c, d, rows))
        return incircle_from_differences(rows, scratch);
    return incircle_exact(a, b, c, d, scratch);
}

// Sign-exact incircle using `scratch` (kIncircleScratch doubles) when the filter fails.
static inline double incircle_robust(const double* a, const double* b, const double* c,
                              const double* d, double* scratch) {
    double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
    double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
    double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
    double alift = adx * adx + ady * ady;
    double cdxady = cdx * ady, adxcdy = adx * cdy;
    double blift = bdx * bdx + bdy * bdy;
    double adxbdy = adx * bdy, bdxady = bdx * ady;
    double clift = cdx * cdx + cdy * cdy;
    double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) +
                 clift * (adxbdy - bdxady);
    double permanent = (abs_value(bdxcdy) + abs_value(cdxbdy)) * alift +
                       (abs_value(cdxady) + abs_value(adxcdy)) * blift +
                       (abs_value(adxbdy) + abs_value(bdxady)) * clift;
    double bound = kIncircleBoundA * permanent + kUnderflowGuard;
    if (det > bound || -det > bound) return det;
    return incircle_beyond_filter(a, b, c, d, scratch);
}

// Lexicographic order on (x, y): the rank that sets each point's perturbation.
static inline bool lex_less(const double* p, const double* q) {
    return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
}

// The sign of incircle(a, b, c, d) for counter-clockwise abc, with ties broken by the
// symbolic perturbation: point i is lifted by eps^(4 - rank(i)), the lexicographically
// largest point the most. A tie is settled by the largest point whose cofactor (the
// orientation of the other three) is non-zero; d's cofactor is -orient(a, b, c) < 0, so
// the loop always ends. Never returns 0 for four distinct points. The tie is settled out of
// line (STRATMESH_FAST_NOINLINE), so that the filtered test inlines into its callers.
STRATMESH_FAST_NOINLINE static inline int incircle_tie(const double* a, const double* b,
                                                const double* c, const double* d) {
    const double* p[4] = {a, b, c, d};
    // Sort the four points by decreasing lexicographic rank (insertion sort, 4 items).
    int order[4] = {0, 1, 2, 3};
    for (int i = 1; i < 4; ++i)
        for (int j = i; j > 0 && lex_less(p[order[j - 1]], p[order[j]]); --j) {
            int s = order[j];
            order[j] = order[j - 1];
            order[j - 1] = s;
        }
    for (int k = 0; k < 4; ++k) {
        double o = 0;
        switch (order[k]) {
        case 0: o = orient2d_robust(b, c, d); break;
        case 1: o = orient2d_robust(a, d, c); break;
        case 2: o = orient2d_robust(a, b, d); break;
        default: return -1;
        }
        if (o > 0) return 1;
        if (o < 0) return -1;
    }
    return -1;
}

STRATMESH_SMALL_NOINLINE static inline int incircle_perturbed(const double* a, const double* b,
                                                       const double* c, const double* d,
                                                       double* scratch) {
    const double det = incircle_robust(a, b, c, d, scratch);
    if (det > 0) return 1;
    if (det < 0) return -1;
    return incircle_tie(a, b, c, d);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

double orient2d(const double a[2], const double b[2], const double c[2]) {
    return detail::orient2d_robust(a, b, c);
}

double incircle(const double a[2], const double b[2], const double c[2], const double d[2]) {
    double scratch[detail::kIncircleScratch];
    return detail::incircle_robust(a, b, c, d, scratch);
}

}  // namespace stratmesh
