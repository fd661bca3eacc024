// Exact reference predicates for the tests, written independently of stratmesh.
//
// Every finite double is an integer times a power of two. Scaling the coordinates of a
// predicate's points by a common power of two turns them all into integers without
// changing the sign of the determinant (a polynomial with positive scale factor), and the
// integers are evaluated with a small arbitrary-precision signed integer. Nothing here is
// fast; it is meant to be obviously right. The filtered_* variants answer from plain double
// arithmetic only when a deliberately loose error bound proves the sign, and fall back to the
// exact evaluation otherwise.

#ifndef STRATMESH_TESTS_SUPPORT_EXACT_H
#define STRATMESH_TESTS_SUPPORT_EXACT_H

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace exact_ref {

// A broken precondition of the reference itself (not of the library under test): stop
// loudly. Works without exceptions, so the suite also builds with -fno-exceptions.
[[noreturn]] inline void fail(const char* why) {
    std::fprintf(stderr, "exact reference: %s\n", why);
    std::abort();
}

// ==== BigInt ================================================================================

// A signed integer: sign and magnitude, the magnitude in 32-bit limbs, least significant
// first, without leading zero limbs (zero has no limbs and is never negative). The limbs live
// in a fixed array, large enough for any predicate on doubles: a coordinate scaled to the
// smallest exponent is below 2^2100 (66 limbs) and the in-circle determinant is a product of
// four differences, below 2^8410 (263 limbs). No heap allocation: the exact predicates are
// called often enough for malloc to dominate, especially under AddressSanitizer.
class BigInt {
public:
    static constexpr size_t kMaxLimbs = 280;

    BigInt() = default;
    // Copies only the limbs in use.
    BigInt(const BigInt& other) : negative_(other.negative_), size_(other.size_) {
        std::copy(other.limbs_, other.limbs_ + size_, limbs_);
    }
    BigInt& operator=(const BigInt& other) {
        negative_ = other.negative_;
        size_ = other.size_;
        std::copy(other.limbs_, other.limbs_ + size_, limbs_);
        return *this;
    }

    static BigInt from_int64(int64_t value) {
        bool negative = value < 0;
        uint64_t magnitude = negative ? ~static_cast<uint64_t>(value) + 1u : static_cast<uint64_t>(value);
        return from_scaled(magnitude, negative, 0);
    }

    // (negative ? -1 : 1) * magnitude * 2^shift.
    static BigInt from_scaled(uint64_t magnitude, bool negative, unsigned shift) {
        BigInt r;
        if (magnitude == 0) return r;
        size_t limb_shift = shift / 32u;
        unsigned bit_shift = shift % 32u;
        r.resize(limb_shift + 3);
        for (size_t i = 0; i < limb_shift; ++i) r.limbs_[i] = 0;
        uint64_t low = magnitude << bit_shift;
        uint32_t high = bit_shift == 0 ? 0u : static_cast<uint32_t>(magnitude >> (64u - bit_shift));
        r.limbs_[limb_shift] = static_cast<uint32_t>(low);
        r.limbs_[limb_shift + 1] = static_cast<uint32_t>(low >> 32);
        r.limbs_[limb_shift + 2] = high;
        r.trim();
        r.negative_ = negative;
        return r;
    }

    int sign() const { return size_ == 0 ? 0 : (negative_ ? -1 : 1); }

    BigInt operator-() const {
        BigInt r = *this;
        if (r.size_ != 0) r.negative_ = !r.negative_;
        return r;
    }

    friend BigInt operator+(const BigInt& a, const BigInt& b) {
        BigInt r;
        if (a.negative_ == b.negative_) {
            add_magnitudes(a, b, r);
            r.negative_ = a.negative_;
        } else {
            int c = compare_magnitudes(a, b);
            if (c == 0) return r;
            if (c > 0) {
                subtract_magnitudes(a, b, r);
                r.negative_ = a.negative_;
            } else {
                subtract_magnitudes(b, a, r);
                r.negative_ = b.negative_;
            }
        }
        if (r.size_ == 0) r.negative_ = false;
        return r;
    }

    friend BigInt operator-(const BigInt& a, const BigInt& b) { return a + (-b); }

    friend BigInt operator*(const BigInt& a, const BigInt& b) {
        BigInt r;
        if (a.size_ == 0 || b.size_ == 0) return r;
        multiply_magnitudes(a, b, r);
        r.negative_ = a.negative_ != b.negative_;
        return r;
    }

    // -1, 0 or 1 as a < b, a == b, a > b.
    friend int compare(const BigInt& a, const BigInt& b) { return (a - b).sign(); }
    friend bool operator==(const BigInt& a, const BigInt& b) { return compare(a, b) == 0; }

    // Hexadecimal, e.g. "-0x1f"; "0x0" for zero.
    std::string to_hex() const {
        static const char digits[] = "0123456789abcdef";
        if (size_ == 0) return "0x0";
        std::string out;
        for (size_t i = size_; i-- > 0;) {
            for (int nibble = 7; nibble >= 0; --nibble) {
                unsigned d = (limbs_[i] >> (4 * nibble)) & 0xFu;
                if (out.empty() && d == 0) continue;
                out.push_back(digits[d]);
            }
        }
        return (negative_ ? "-0x" : "0x") + out;
    }

private:
    void resize(size_t n) {
        if (n > kMaxLimbs) fail("BigInt: more limbs than any predicate needs");
        size_ = n;
    }
    void trim() {
        while (size_ > 0 && limbs_[size_ - 1] == 0) --size_;
    }

    static int compare_magnitudes(const BigInt& a, const BigInt& b) {
        if (a.size_ != b.size_) return a.size_ < b.size_ ? -1 : 1;
        for (size_t i = a.size_; i-- > 0;) {
            if (a.limbs_[i] != b.limbs_[i]) return a.limbs_[i] < b.limbs_[i] ? -1 : 1;
        }
        return 0;
    }

    static void add_magnitudes(const BigInt& a, const BigInt& b, BigInt& r) {
        const BigInt& longer = a.size_ >= b.size_ ? a : b;
        const BigInt& shorter = a.size_ >= b.size_ ? b : a;
        r.resize(longer.size_ + 1);
        uint64_t carry = 0;
        for (size_t i = 0; i < longer.size_; ++i) {
            uint64_t s = carry + longer.limbs_[i] + (i < shorter.size_ ? shorter.limbs_[i] : 0u);
            r.limbs_[i] = static_cast<uint32_t>(s);
            carry = s >> 32;
        }
        r.limbs_[longer.size_] = static_cast<uint32_t>(carry);
        r.trim();
    }

    // |a| - |b| for |a| >= |b|.
    static void subtract_magnitudes(const BigInt& a, const BigInt& b, BigInt& r) {
        r.resize(a.size_);
        uint64_t borrow = 0;
        for (size_t i = 0; i < a.size_; ++i) {
            uint64_t subtrahend = borrow + (i < b.size_ ? b.limbs_[i] : 0u);
            uint64_t minuend = a.limbs_[i];
            if (minuend >= subtrahend) {
                r.limbs_[i] = static_cast<uint32_t>(minuend - subtrahend);
                borrow = 0;
            } else {
                r.limbs_[i] = static_cast<uint32_t>((minuend + (uint64_t{1} << 32)) - subtrahend);
                borrow = 1;
            }
        }
        if (borrow != 0) fail("BigInt: subtracting a larger magnitude");
        r.trim();
    }

    static void multiply_magnitudes(const BigInt& a, const BigInt& b, BigInt& r) {
        r.resize(a.size_ + b.size_);
        for (size_t k = 0; k < r.size_; ++k) r.limbs_[k] = 0;
        for (size_t i = 0; i < a.size_; ++i) {
            uint64_t carry = 0;
            for (size_t j = 0; j < b.size_; ++j) {
                // At most (2^32-1)^2 + 2 (2^32-1) = 2^64 - 1: no overflow.
                uint64_t t = static_cast<uint64_t>(a.limbs_[i]) * b.limbs_[j] + r.limbs_[i + j] + carry;
                r.limbs_[i + j] = static_cast<uint32_t>(t);
                carry = t >> 32;
            }
            // Row i's last carry goes to limb i + |b|, which no earlier row has reached.
            r.limbs_[i + b.size_] = static_cast<uint32_t>(carry);
        }
        r.trim();
    }

    bool negative_ = false;
    size_t size_ = 0;
    uint32_t limbs_[kMaxLimbs];
};

// ==== Doubles as integers ===================================================================

// value == mantissa * 2^exponent exactly, |mantissa| < 2^53.
struct Dyadic {
    int64_t mantissa;
    int exponent;
};

inline Dyadic to_dyadic(double value) {
    if (!std::isfinite(value)) fail("exact_ref: non-finite coordinate");
    if (value == 0) return Dyadic{0, 0};
    int e = 0;
    double m = std::frexp(value, &e);  // value = m * 2^e, 0.5 <= |m| < 1, exact
    // m has at most 53 significant bits, so m * 2^53 is an integer below 2^53 in magnitude.
    double scaled = std::ldexp(m, DBL_MANT_DIG);
    return Dyadic{static_cast<int64_t>(scaled), e - DBL_MANT_DIG};
}

// Converts the `count` (at most 8) values to integers that all carry the same factor 2^e (e
// the smallest exponent among them): out[i] * 2^e == values[i] exactly.
inline void to_common_scale(const double* values, size_t count, BigInt* out) {
    if (count > 8) fail("exact_ref: at most 8 values");
    Dyadic d[8];
    bool any = false;
    int emin = 0;
    for (size_t i = 0; i < count; ++i) {
        d[i] = to_dyadic(values[i]);
        if (d[i].mantissa == 0) continue;
        if (!any || d[i].exponent < emin) emin = d[i].exponent;
        any = true;
    }
    for (size_t i = 0; i < count; ++i) {
        bool negative = d[i].mantissa < 0;
        uint64_t magnitude = static_cast<uint64_t>(negative ? -d[i].mantissa : d[i].mantissa);
        unsigned shift = d[i].mantissa == 0 ? 0u : static_cast<unsigned>(d[i].exponent - emin);
        out[i] = BigInt::from_scaled(magnitude, negative, shift);
    }
}

// ==== Exact predicates ======================================================================

// Sign of (b - a) x (c - a): 1 if a, b, c turn counter-clockwise, -1 if clockwise, 0 if
// collinear. Points are double[2].
inline int exact_orient2d_sign(const double* a, const double* b, const double* c) {
    const double v[6] = {a[0], a[1], b[0], b[1], c[0], c[1]};
    BigInt z[6];
    to_common_scale(v, 6, z);
    BigInt bax = z[2] - z[0], bay = z[3] - z[1];
    BigInt cax = z[4] - z[0], cay = z[5] - z[1];
    return (bax * cay - bay * cax).sign();
}

// Sign of the in-circle determinant: 1 if d lies inside the circle through a, b, c when
// a, b, c are counter-clockwise (reversed when they are clockwise), 0 if cocircular. It is
// the determinant of the rows (p - d, |p - d|^2) for p = a, b, c.
inline int exact_incircle_sign(const double* a, const double* b, const double* c, const double* d) {
    const double v[8] = {a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1]};
    BigInt z[8];
    to_common_scale(v, 8, z);
    BigInt adx = z[0] - z[6], ady = z[1] - z[7];
    BigInt bdx = z[2] - z[6], bdy = z[3] - z[7];
    BigInt cdx = z[4] - z[6], cdy = z[5] - z[7];
    BigInt alift = adx * adx + ady * ady;
    BigInt blift = bdx * bdx + bdy * bdy;
    BigInt clift = cdx * cdx + cdy * cdy;
    BigInt det = alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) +
                 clift * (adx * bdy - bdx * ady);
    return det.sign();
}

// ==== Filtered (still exact) predicates =====================================================
//
// A double evaluation decides when |det| exceeds a bound several times larger than the
// worst-case rounding error. The bounds assume no overflow or underflow, so every
// coordinate difference must be zero or between 2^-240 and 2^240 in magnitude (products of
// four such values stay normal); anything else goes to the exact code.

namespace detail {
constexpr double kUnitRoundoff = DBL_EPSILON / 2;

inline bool filter_safe(double v) {
    double m = std::fabs(v);
    return m == 0 || (m >= 0x1p-240 && m <= 0x1p240);
}
}  // namespace detail

inline int filtered_orient2d_sign(const double* a, const double* b, const double* c) {
    double bax = b[0] - a[0], bay = b[1] - a[1];
    double cax = c[0] - a[0], cay = c[1] - a[1];
    if (detail::filter_safe(bax) && detail::filter_safe(bay) && detail::filter_safe(cax) &&
        detail::filter_safe(cay)) {
        double left = bax * cay;
        double right = bay * cax;
        double det = left - right;
        // The rounding error is below about 4 u (|left| + |right|).
        double bound = 8 * detail::kUnitRoundoff * (std::fabs(left) + std::fabs(right));
        if (det > bound) return 1;
        if (det < -bound) return -1;
    }
    return exact_orient2d_sign(a, b, c);
}

inline int filtered_incircle_sign(const double* a, const double* b, const double* c, const double* d) {
    double adx = a[0] - d[0], ady = a[1] - d[1];
    double bdx = b[0] - d[0], bdy = b[1] - d[1];
    double cdx = c[0] - d[0], cdy = c[1] - d[1];
    if (detail::filter_safe(adx) && detail::filter_safe(ady) && detail::filter_safe(bdx) &&
        detail::filter_safe(bdy) && detail::filter_safe(cdx) && detail::filter_safe(cdy)) {
        double alift = adx * adx + ady * ady;
        double blift = bdx * bdx + bdy * bdy;
        double clift = cdx * cdx + cdy * cdy;
        double p1 = bdx * cdy, q1 = cdx * bdy;
        double p2 = cdx * ady, q2 = adx * cdy;
        double p3 = adx * bdy, q3 = bdx * ady;
        double det = alift * (p1 - q1) + blift * (p2 - q2) + clift * (p3 - q3);
        double permanent = alift * (std::fabs(p1) + std::fabs(q1)) +
                           blift * (std::fabs(p2) + std::fabs(q2)) +
                           clift * (std::fabs(p3) + std::fabs(q3));
        // The rounding error is below about 12 u times the permanent.
        double bound = 32 * detail::kUnitRoundoff * permanent;
        if (det > bound) return 1;
        if (det < -bound) return -1;
    }
    return exact_incircle_sign(a, b, c, d);
}

}  // namespace exact_ref

#endif  // STRATMESH_TESTS_SUPPORT_EXACT_H
