// orient2d and incircle against an exact big-integer reference (support/exact.h), which is
// itself checked first on cases with signs known by hand and on inputs where plain double
// arithmetic is provably exact.
#include "stratmesh.h"
#include "support/exact.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <random>
#include <vector>

namespace {

using Point = std::array<double, 2>;
using exact_ref::BigInt;

int sign_of(double v) { return (v > 0) - (v < 0); }

int lib_orient(const Point& a, const Point& b, const Point& c) {
    return sign_of(stratmesh::orient2d(a.data(), b.data(), c.data()));
}
int lib_incircle(const Point& a, const Point& b, const Point& c, const Point& d) {
    return sign_of(stratmesh::incircle(a.data(), b.data(), c.data(), d.data()));
}
int ref_orient(const Point& a, const Point& b, const Point& c) {
    return exact_ref::exact_orient2d_sign(a.data(), b.data(), c.data());
}
int ref_incircle(const Point& a, const Point& b, const Point& c, const Point& d) {
    return exact_ref::exact_incircle_sign(a.data(), b.data(), c.data(), d.data());
}

// Plain double evaluations, each product rounded on its own (volatile keeps the compiler
// from fusing a multiply and an add).
int naive_orient(const Point& a, const Point& b, const Point& c) {
    volatile double left = (b[0] - a[0]) * (c[1] - a[1]);
    volatile double right = (b[1] - a[1]) * (c[0] - a[0]);
    return sign_of(left - right);
}
int naive_incircle(const Point& a, const Point& b, const Point& c, const Point& d) {
    double adx = a[0] - d[0], ady = a[1] - d[1];
    double bdx = b[0] - d[0], bdy = b[1] - d[1];
    double cdx = c[0] - d[0], cdy = c[1] - d[1];
    volatile double alift = adx * adx + ady * ady;
    volatile double blift = bdx * bdx + bdy * bdy;
    volatile double clift = cdx * cdx + cdy * cdy;
    volatile double p1 = bdx * cdy, q1 = cdx * bdy;
    volatile double p2 = cdx * ady, q2 = adx * cdy;
    volatile double p3 = adx * bdy, q3 = bdx * ady;
    volatile double t1 = alift * (p1 - q1), t2 = blift * (p2 - q2), t3 = clift * (p3 - q3);
    return sign_of(t1 + t2 + t3);
}

class Random {
public:
    explicit Random(uint64_t seed) : engine_(seed) {}
    // Uniform in [0, 1) with 53 random bits.
    double unit() { return static_cast<double>(engine_() >> 11) * 0x1p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
    uint64_t bits() { return engine_(); }
    int integer(int lo, int hi) {  // inclusive
        return lo + static_cast<int>(engine_() % static_cast<uint64_t>(hi - lo + 1));
    }
    // A random mantissa in [1, 2) times 10^decimal_exponent, random sign.
    double with_magnitude(int decimal_exponent) {
        double v = uniform(1, 2) * std::pow(10.0, decimal_exponent);
        return (engine_() & 1u) ? -v : v;
    }

private:
    std::mt19937_64 engine_;
};

Point scaled(const Point& p, int power_of_two) {
    return Point{std::ldexp(p[0], power_of_two), std::ldexp(p[1], power_of_two)};
}

// Sign of a permutation given as indices 0..k-1.
int permutation_parity(const int* perm, int k) {
    int inversions = 0;
    for (int i = 0; i < k; ++i)
        for (int j = i + 1; j < k; ++j) inversions += perm[i] > perm[j];
    return inversions % 2 == 0 ? 1 : -1;
}

// Both predicates agree with the reference under every permutation, with the permutation's
// parity applied: the determinants are alternating in their points.
void check_permutations(const Point& a, const Point& b, const Point& c, const Point& d) {
    const Point pts[4] = {a, b, c, d};
    int base_orient = ref_orient(a, b, c);
    int p3[3] = {0, 1, 2};
    do {
        int got = lib_orient(pts[p3[0]], pts[p3[1]], pts[p3[2]]);
        CHECK(got == permutation_parity(p3, 3) * base_orient);
    } while (std::next_permutation(p3, p3 + 3));
    int base_incircle = ref_incircle(a, b, c, d);
    int p4[4] = {0, 1, 2, 3};
    do {
        int got = lib_incircle(pts[p4[0]], pts[p4[1]], pts[p4[2]], pts[p4[3]]);
        CHECK(got == permutation_parity(p4, 4) * base_incircle);
    } while (std::next_permutation(p4, p4 + 4));
}

// Kettner et al.'s "classroom example": p on a 256 x 256 grid of ulp steps from (0.5, 0.5),
// against the line through q and r. Counts cells where each evaluation differs from exact.
struct GridResult {
    int naive_wrong = 0;
    int library_wrong = 0;
    int zero_cells = 0;
    int positive_cells = 0;
    int negative_cells = 0;
};

GridResult orient_classroom_grid(const Point& base, const Point& q, const Point& r, int power_of_two) {
    GridResult g;
    const double ulp = 0x1p-53;  // the spacing of doubles in [0.5, 1)
    for (int i = 0; i < 256; ++i) {
        for (int j = 0; j < 256; ++j) {
            Point p0{base[0] + i * ulp, base[1] + j * ulp};
            Point p = scaled(p0, power_of_two), qs = scaled(q, power_of_two), rs = scaled(r, power_of_two);
            int exact = ref_orient(p, qs, rs);
            g.zero_cells += exact == 0;
            g.positive_cells += exact > 0;
            g.negative_cells += exact < 0;
            g.naive_wrong += naive_orient(p, qs, rs) != exact;
            g.library_wrong += lib_orient(p, qs, rs) != exact;
        }
    }
    return g;
}

// The incircle analogue: d on a grid of ulp steps across the circle through a, b, c.
GridResult incircle_classroom_grid(int power_of_two, int size) {
    GridResult g;
    // Centre (12, 12), radius 5: (17, 12), (12, 17), (7, 12) are on it, counter-clockwise.
    const Point a{17, 12}, b{12, 17}, c{7, 12};
    const double ulp = 0x1p-49;  // the spacing of doubles in [8, 16)
    const double start = 12 + 5 / std::sqrt(2.0) - (size / 2) * ulp;
    Point as = scaled(a, power_of_two), bs = scaled(b, power_of_two), cs = scaled(c, power_of_two);
    for (int i = 0; i < size; ++i) {
        for (int j = 0; j < size; ++j) {
            Point d = scaled(Point{start + i * ulp, start + j * ulp}, power_of_two);
            int exact = ref_incircle(as, bs, cs, d);
            g.zero_cells += exact == 0;
            g.positive_cells += exact > 0;
            g.negative_cells += exact < 0;
            g.naive_wrong += naive_incircle(as, bs, cs, d) != exact;
            g.library_wrong += lib_incircle(as, bs, cs, d) != exact;
        }
    }
    return g;
}

}  // namespace

// ==== The reference itself =================================================================

TEST_CASE("exact reference: big integer arithmetic on known values") {
    BigInt two64 = BigInt::from_scaled(1, false, 64);
    BigInt one = BigInt::from_int64(1);
    CHECK(two64.to_hex() == "0x10000000000000000");
    CHECK(((two64 + one) * (two64 - one)).to_hex() == "0xffffffffffffffffffffffffffffffff");
    CHECK((BigInt::from_int64(0xFFFFFFFFll) + one).to_hex() == "0x100000000");
    CHECK((two64 - one).to_hex() == "0xffffffffffffffff");
    CHECK((one - two64).to_hex() == "-0xffffffffffffffff");
    CHECK((BigInt::from_int64(-5) * BigInt::from_int64(3)).to_hex() == "-0xf");
    CHECK((BigInt::from_int64(-5) * BigInt::from_int64(-3)).to_hex() == "0xf");
    CHECK((BigInt::from_int64(7) - BigInt::from_int64(7)).sign() == 0);
    CHECK((BigInt::from_int64(7) - BigInt::from_int64(7)).to_hex() == "0x0");
    CHECK((BigInt::from_int64(-7) + BigInt::from_int64(7)).sign() == 0);
    CHECK(BigInt::from_int64(INT64_MIN).to_hex() == "-0x8000000000000000");
    CHECK(BigInt::from_scaled(0x1234, true, 36).to_hex() == "-0x1234000000000");  // 36 bits: 9 hex zeros
    CHECK(BigInt::from_scaled(0, true, 100).sign() == 0);
    CHECK(compare(BigInt::from_int64(-3), BigInt::from_int64(2)) == -1);
    CHECK(compare(two64, two64 - one) == 1);
    CHECK(compare(-two64, -two64) == 0);
    // 2^200 - 2^100 squared, in hex: 2^400 - 2^301 + 2^200.
    BigInt x = BigInt::from_scaled(1, false, 200) - BigInt::from_scaled(1, false, 100);
    BigInt expected = BigInt::from_scaled(1, false, 400) - BigInt::from_scaled(1, false, 301) +
                      BigInt::from_scaled(1, false, 200);
    CHECK(x * x == expected);
}

TEST_CASE("exact reference: big integers agree with int64 and with ring identities") {
    Random rng(1);
    for (int trial = 0; trial < 2000; ++trial) {
        int64_t a = static_cast<int64_t>(rng.bits() % 4000000000ull) - 2000000000;
        int64_t b = static_cast<int64_t>(rng.bits() % 4000000000ull) - 2000000000;
        BigInt A = BigInt::from_int64(a), B = BigInt::from_int64(b);
        CHECK(A * B == BigInt::from_int64(a * b));
        CHECK(A + B == BigInt::from_int64(a + b));
        CHECK(A - B == BigInt::from_int64(a - b));
        CHECK(compare(A, B) == (a > b) - (a < b));
    }
    // Many-limb values with carries in every position.
    for (int trial = 0; trial < 300; ++trial) {
        auto big = [&]() {
            BigInt v;
            int parts = rng.integer(1, 8);
            for (int k = 0; k < parts; ++k) {
                v = v + BigInt::from_scaled(rng.bits(), (rng.bits() & 1u) != 0,
                                            static_cast<unsigned>(rng.integer(0, 400)));
            }
            return v;
        };
        BigInt a = big(), b = big(), c = big();
        CHECK((a + b) * (a + b) == a * a + BigInt::from_int64(2) * a * b + b * b);
        CHECK((a - b) * (a + b) == a * a - b * b);
        CHECK(a * (b + c) == a * b + a * c);
        CHECK((a - b) + b == a);
        CHECK((a * b).sign() == a.sign() * b.sign());
    }
}

TEST_CASE("exact reference: doubles decompose exactly into mantissa and exponent") {
    Random rng(2);
    std::vector<double> values = {0.5, 1.0, -3.75, 0.1, 1e300, -1e-300, DBL_MAX, DBL_MIN,
                                  std::numeric_limits<double>::denorm_min(), -DBL_TRUE_MIN * 3};
    for (int k = 0; k < 1000; ++k) values.push_back(std::ldexp(rng.uniform(-1, 1), rng.integer(-1074, 1023)));
    for (double v : values) {
        exact_ref::Dyadic d = exact_ref::to_dyadic(v);
        CHECK(std::llabs(d.mantissa) < (1ll << 53));
        CHECK(std::ldexp(static_cast<double>(d.mantissa), d.exponent) == v);
    }
    CHECK(exact_ref::to_dyadic(0.0).mantissa == 0);
    CHECK(exact_ref::to_dyadic(-0.0).mantissa == 0);
    // 0.1 is 3602879701896397 / 2^55; its full 53-bit mantissa is twice that, over 2^56.
    CHECK(exact_ref::to_dyadic(0.1).mantissa == 7205759403792794ll);
    CHECK(exact_ref::to_dyadic(0.1).exponent == -56);
    CHECK(exact_ref::to_dyadic(-0.75).mantissa == -(3ll << 51));
    CHECK(exact_ref::to_dyadic(-0.75).exponent == -53);
}

TEST_CASE("exact reference: predicates on cases with signs known by hand") {
    using P = Point;
    CHECK(ref_orient(P{0, 0}, P{1, 0}, P{0, 1}) == 1);
    CHECK(ref_orient(P{0, 0}, P{0, 1}, P{1, 0}) == -1);
    CHECK(ref_orient(P{0, 0}, P{1, 1}, P{2, 2}) == 0);
    CHECK(ref_orient(P{1, 1}, P{1, 1}, P{5, -3}) == 0);
    CHECK(ref_orient(P{-2, 3}, P{4, -1}, P{1, 1}) == 0);   // on the segment
    CHECK(ref_orient(P{-2, 3}, P{4, -1}, P{1, 1.5}) == 1);  // above it
    // Extreme exponents: the triangle with legs 2^-1074 and 2^1000 still has positive area.
    CHECK(ref_orient(P{0, 0}, P{DBL_TRUE_MIN, 0}, P{0, 0x1p1000}) == 1);
    CHECK(ref_orient(P{0, 0}, P{0, 0x1p1000}, P{DBL_TRUE_MIN, 0}) == -1);
    // orient((0, 0), (1, 3), (x, y)) = y - 3x. As doubles, 0.1 = 3602879701896397 / 2^55,
    // so 3 x 0.1 = 10808639105689191 / 2^55 exactly,
    // while 0.3 = 10808639105689190 / 2^55 (one unit less) and the rounded product 3 * 0.1 =
    // 10808639105689192 / 2^55 (one unit more).
    CHECK(ref_orient(P{0, 0}, P{1, 3}, P{0.1, 0.3}) == -1);
    CHECK(ref_orient(P{0, 0}, P{1, 3}, P{0.1, 3 * 0.1}) == 1);

    // The unit circle through (1, 0), (0, 1), (-1, 0), counter-clockwise.
    const P a{1, 0}, b{0, 1}, c{-1, 0};
    CHECK(ref_incircle(a, b, c, P{0, 0}) == 1);
    CHECK(ref_incircle(a, b, c, P{0, -1}) == 0);
    CHECK(ref_incircle(a, b, c, P{2, 0}) == -1);
    CHECK(ref_incircle(a, b, c, P{0, -1 - DBL_EPSILON}) == -1);
    CHECK(ref_incircle(a, b, c, P{0, -1 + DBL_EPSILON / 2}) == 1);
    CHECK(ref_incircle(b, a, c, P{0, 0}) == -1);  // clockwise: reversed
    // Pythagorean: (3, 4), (-4, 3), (-5, 0) and (0, -5) lie on the circle of radius 5.
    CHECK(ref_incircle(P{3, 4}, P{-4, 3}, P{-5, 0}, P{0, -5}) == 0);
    CHECK(ref_incircle(P{3, 4}, P{-4, 3}, P{-5, 0}, P{4, -3}) == 0);
    CHECK(ref_incircle(P{3, 4}, P{-4, 3}, P{-5, 0}, P{4, -2}) == 1);
    CHECK(ref_incircle(P{3, 4}, P{-4, 3}, P{-5, 0}, P{4, -4}) == -1);
}

TEST_CASE("exact reference: matches double arithmetic where doubles are exact or clearly right") {
    Random rng(3);
    // Integers in [-512, 512]: every intermediate of the double evaluation is an integer
    // below 2^45, so the double results are exact.
    auto small = [&]() { return Point{static_cast<double>(rng.integer(-512, 512)), static_cast<double>(rng.integer(-512, 512))}; };
    int zeros = 0;
    for (int trial = 0; trial < 5000; ++trial) {
        Point a = small(), b = small(), c = small(), d = small();
        if (trial % 4 == 0) c = Point{2 * b[0] - a[0], 2 * b[1] - a[1]};  // often collinear cases
        CHECK(ref_orient(a, b, c) == naive_orient(a, b, c));
        CHECK(ref_incircle(a, b, c, d) == naive_incircle(a, b, c, d));
        zeros += ref_orient(a, b, c) == 0;
    }
    CHECK(zeros > 1000);
    // Real inputs whose determinant exceeds 1e-6 of its permanent: far beyond any rounding.
    int decided = 0;
    for (int trial = 0; trial < 5000; ++trial) {
        Point a{rng.uniform(-1, 1), rng.uniform(-1, 1)}, b{rng.uniform(-1, 1), rng.uniform(-1, 1)};
        Point c{rng.uniform(-1, 1), rng.uniform(-1, 1)}, d{rng.uniform(-1, 1), rng.uniform(-1, 1)};
        double l = (b[0] - a[0]) * (c[1] - a[1]), r = (b[1] - a[1]) * (c[0] - a[0]);
        if (std::fabs(l - r) > 1e-6 * (std::fabs(l) + std::fabs(r))) {
            CHECK(ref_orient(a, b, c) == sign_of(l - r));
            ++decided;
        }
        double adx = a[0] - d[0], ady = a[1] - d[1], bdx = b[0] - d[0], bdy = b[1] - d[1];
        double cdx = c[0] - d[0], cdy = c[1] - d[1];
        double al = adx * adx + ady * ady, bl = bdx * bdx + bdy * bdy, cl = cdx * cdx + cdy * cdy;
        double det = al * (bdx * cdy - cdx * bdy) + bl * (cdx * ady - adx * cdy) + cl * (adx * bdy - bdx * ady);
        double permanent = al * (std::fabs(bdx * cdy) + std::fabs(cdx * bdy)) +
                           bl * (std::fabs(cdx * ady) + std::fabs(adx * cdy)) +
                           cl * (std::fabs(adx * bdy) + std::fabs(bdx * ady));
        if (std::fabs(det) > 1e-6 * permanent) {
            CHECK(ref_incircle(a, b, c, d) == sign_of(det));
            ++decided;
        }
    }
    CHECK(decided > 9800);
}

TEST_CASE("exact reference: the filtered predicates agree with the pure big-integer ones") {
    Random rng(4);
    const Point a{17, 12}, b{12, 17}, c{7, 12};
    const double ulp = 0x1p-49;
    const double start = 12 + 5 / std::sqrt(2.0) - 16 * ulp;
    for (int i = 0; i < 32; ++i) {
        for (int j = 0; j < 32; ++j) {
            Point d{start + i * ulp, start + j * ulp};
            CHECK(exact_ref::filtered_incircle_sign(a.data(), b.data(), c.data(), d.data()) == ref_incircle(a, b, c, d));
            CHECK(exact_ref::filtered_orient2d_sign(a.data(), d.data(), b.data()) == ref_orient(a, d, b));
        }
    }
    for (int trial = 0; trial < 3000; ++trial) {
        Point p[4];
        for (Point& q : p) q = Point{rng.uniform(-1, 1), rng.uniform(-1, 1)};
        if (trial % 2) p[2] = Point{p[0][0] + 0.5 * (p[1][0] - p[0][0]), p[0][1] + 0.5 * (p[1][1] - p[0][1])};
        CHECK(exact_ref::filtered_orient2d_sign(p[0].data(), p[1].data(), p[2].data()) == ref_orient(p[0], p[1], p[2]));
        CHECK(exact_ref::filtered_incircle_sign(p[0].data(), p[1].data(), p[2].data(), p[3].data()) ==
              ref_incircle(p[0], p[1], p[2], p[3]));
    }
}

// ==== The library's predicates =============================================================

TEST_CASE("orient2d and incircle signs are exact on uniform random inputs") {
    Random rng(10);
    for (int trial = 0; trial < 20000; ++trial) {
        Point p[4];
        for (Point& q : p) q = Point{rng.uniform(-10, 10), rng.uniform(-10, 10)};
        CHECK(lib_orient(p[0], p[1], p[2]) == ref_orient(p[0], p[1], p[2]));
        CHECK(lib_incircle(p[0], p[1], p[2], p[3]) == ref_incircle(p[0], p[1], p[2], p[3]));
    }
}

TEST_CASE("orient2d is exact on the classroom grid where naive evaluation fails") {
    struct Line {
        Point base, q, r;
    };
    const Line lines[] = {
        {{0.5, 0.5}, {12, 12}, {24, 24}},
        {{0.5, 0.5}, {8.8000000000000007, 8.8000000000000007}, {12.1, 12.1}},
        // Slope 1/2 through (0.5, 0.5): exactly zero where j = i / 2.
        {{0.5, 0.5}, {8.5, 4.5}, {16.5, 8.5}},
    };
    int naive_wrong_total = 0;
    for (const Line& line : lines) {
        GridResult g = orient_classroom_grid(line.base, line.q, line.r, 0);
        CAPTURE(line.q[0]);
        INFO("classroom grid q = " << line.q[0] << ": " << g.positive_cells << " positive, " << g.negative_cells
                << " negative, " << g.zero_cells << " zero cells; naive wrong in " << g.naive_wrong);
        CHECK(g.library_wrong == 0);
        naive_wrong_total += g.naive_wrong;
        // Each line passes exactly through (0.5, 0.5) and crosses the grid.
        CHECK(g.positive_cells > 0);
        CHECK(g.negative_cells > 0);
        CHECK(g.zero_cells == (line.q[1] == line.q[0] ? 256 : 128));
    }
    CHECK(naive_wrong_total > 0);
}

TEST_CASE("incircle is exact on a grid of ulp steps across a circle where naive evaluation fails") {
    GridResult g = incircle_classroom_grid(0, 128);
    CHECK(g.library_wrong == 0);
    CHECK(g.positive_cells > 0);
    CHECK(g.negative_cells > 0);
    CHECK(g.naive_wrong > 0);
}

TEST_CASE("orient2d and incircle are exact at huge and tiny magnitudes") {
    // The classroom grids scaled by powers of two (exact), from about 1e-59 to 1e70 (the
    // top of the documented safe range; the bottom end fails, see the regression below).
    for (int power : {-196, -150, -100, 100, 150, 196, 228}) {
        CAPTURE(power);
        GridResult o = orient_classroom_grid(Point{0.5, 0.5}, Point{12, 12}, Point{24, 24}, power);
        CHECK(o.library_wrong == 0);
        CHECK(o.zero_cells == 256);
        GridResult c = incircle_classroom_grid(power, 48);
        CHECK(c.library_wrong == 0);
        CHECK(c.positive_cells > 0);
        CHECK(c.negative_cells > 0);
    }
    // Random points at magnitudes 1e30..1e60 and 1e-30..1e-60, nearly degenerate: a point
    // moved a few ulps off an exactly collinear triple, or off an axis-aligned rectangle
    // (whose corners are exactly cocircular).
    Random rng(11);
    for (int trial = 0; trial < 3000; ++trial) {
        int e = rng.integer(30, 60) * (trial % 2 ? 1 : -1);
        double t1 = rng.with_magnitude(e), t2 = rng.with_magnitude(e), t3 = rng.with_magnitude(e);
        // (t, 2t) is on the line y = 2x exactly.
        Point a{t1, 2 * t1}, b{t2, 2 * t2}, c{t3, 2 * t3};
        CHECK(lib_orient(a, b, c) == 0);
        CHECK(ref_orient(a, b, c) == 0);
        int steps = rng.integer(1, 4);
        for (int s = 0; s < steps; ++s) c[1] = std::nextafter(c[1], (trial / 2) % 2 ? HUGE_VAL : -HUGE_VAL);
        CHECK(lib_orient(a, b, c) == ref_orient(a, b, c));
        CHECK(ref_orient(a, b, c) != 0);

        double x1 = rng.with_magnitude(e), x2 = rng.with_magnitude(e);
        double y1 = rng.with_magnitude(e), y2 = rng.with_magnitude(e);
        Point r1{x1, y1}, r2{x2, y1}, r3{x2, y2}, r4{x1, y2};
        CHECK(lib_incircle(r1, r2, r3, r4) == 0);
        CHECK(ref_incircle(r1, r2, r3, r4) == 0);
        for (int s = 0; s < steps; ++s) r4[static_cast<size_t>(s % 2)] = std::nextafter(r4[static_cast<size_t>(s % 2)], (trial / 4) % 2 ? HUGE_VAL : -HUGE_VAL);
        CHECK(lib_incircle(r1, r2, r3, r4) == ref_incircle(r1, r2, r3, r4));
    }
}

TEST_CASE("orient2d and incircle are exact with mixed magnitudes") {
    Random rng(12);
    for (int trial = 0; trial < 4000; ++trial) {
        Point p[4];
        for (Point& q : p) q = Point{rng.with_magnitude(rng.integer(-60, 60)), rng.with_magnitude(rng.integer(-60, 60))};
        CHECK(lib_orient(p[0], p[1], p[2]) == ref_orient(p[0], p[1], p[2]));
        CHECK(lib_incircle(p[0], p[1], p[2], p[3]) == ref_incircle(p[0], p[1], p[2], p[3]));
        // Nearly degenerate with mixed magnitudes: exactly collinear on y = 2x, then nudged.
        Point a{p[0][0], 2 * p[0][0]}, b{p[1][0], 2 * p[1][0]}, c{p[2][0], 2 * p[2][0]};
        CHECK(lib_orient(a, b, c) == 0);
        c[0] = std::nextafter(c[0], trial % 2 ? HUGE_VAL : -HUGE_VAL);
        CHECK(lib_orient(a, b, c) == ref_orient(a, b, c));
        // A rectangle with corners of mixed magnitudes, then nudged.
        Point r1{p[0][0], p[0][1]}, r2{p[1][0], p[0][1]}, r3{p[1][0], p[1][1]}, r4{p[0][0], p[1][1]};
        CHECK(lib_incircle(r1, r2, r3, r4) == 0);
        r4[static_cast<size_t>(trial % 2)] = std::nextafter(r4[static_cast<size_t>(trial % 2)], trial % 3 ? HUGE_VAL : -HUGE_VAL);
        CHECK(lib_incircle(r1, r2, r3, r4) == ref_incircle(r1, r2, r3, r4));
    }
}

// The integer stages take orient2d and incircle when the differences are exact and span at
// most 62 bits; wider spans take the expansions. Points are d plus integers of a chosen
// width times a power of two, so the span is set directly, on both sides of the limit and
// at magnitudes that scale the integers up (tiny points) or down (huge ones).
TEST_CASE("orient2d and incircle are exact when the differences are integers spanning up to 62 bits and beyond") {
    Random rng(15);
    int collinear = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        int width = rng.integer(1, 66);
        int power = rng.integer(-1000, 900);
        CAPTURE(width);
        CAPTURE(power);
        auto offset = [&](int bits) {
            // A random integer below 2^bits, at most 53 significant bits, random sign.
            if (bits == 0) return 0.0;
            int significant = std::min(bits, 53);
            double v = std::ldexp(static_cast<double>(rng.bits() >> (64 - significant)), bits - significant);
            return (rng.bits() & 1u) ? -v : v;
        };
        Point d{std::ldexp(static_cast<double>(rng.integer(-3, 3)), power + width), std::ldexp(0.5, power)};
        Point q[3];
        for (Point& p : q) {
            p = Point{d[0] + std::ldexp(offset(width), power), d[1] + std::ldexp(offset(rng.integer(0, width)), power)};
            if (rng.integer(0, 7) == 0) p[static_cast<size_t>(rng.integer(0, 1))] = d[static_cast<size_t>(rng.integer(0, 1))];
        }
        CHECK(lib_incircle(q[0], q[1], q[2], d) == ref_incircle(q[0], q[1], q[2], d));
        CHECK(lib_orient(q[0], q[1], d) == ref_orient(q[0], q[1], d));
        // Collinear when the arithmetic below is exact (the reference tells); then nudged
        // by an ulp.
        Point u{q[0][0] - d[0], q[0][1] - d[1]};
        Point e{d[0] - 2 * u[0], d[1] - 2 * u[1]};
        if (ref_orient(q[0], e, d) == 0) {
            ++collinear;
            CHECK(lib_orient(q[0], e, d) == 0);
            // Not a zero coordinate: its neighbour, 2^-1074, is outside the contract.
            size_t axis = e[0] != 0 && (trial % 2 || e[1] == 0) ? 0 : 1;
            e[axis] = std::nextafter(e[axis], trial % 3 ? HUGE_VAL : -HUGE_VAL);
            CHECK(lib_orient(q[0], e, d) == ref_orient(q[0], e, d));
        }
        // Exactly cocircular: the reflections of (x, y) in the axes through d, and a
        // rectangle; then one point moved by an ulp.
        double x = std::ldexp(offset(width), power), y = std::ldexp(offset(rng.integer(1, width)), power);
        Point centre{std::ldexp(1.0, power + width), std::ldexp(3.0, power + width)};
        Point r[4] = {{centre[0] + x, centre[1] + y}, {centre[0] - x, centre[1] + y},
                      {centre[0] - x, centre[1] - y}, {centre[0] + x, centre[1] - y}};
        if (x != 0 && y != 0 && r[0][0] - centre[0] == x && r[0][1] - centre[1] == y &&
            r[2][0] - centre[0] == -x && r[2][1] - centre[1] == -y) {
            CHECK(ref_incircle(r[0], r[1], r[2], r[3]) == 0);
            CHECK(lib_incircle(r[0], r[1], r[2], r[3]) == 0);
            Point s{centre[0] + y, centre[1] + x};
            CHECK(lib_incircle(r[0], r[1], r[2], s) == ref_incircle(r[0], r[1], r[2], s));
            size_t axis = static_cast<size_t>(trial % 2);
            r[3][axis] = std::nextafter(r[3][axis], trial % 3 ? HUGE_VAL : -HUGE_VAL);
            CHECK(lib_incircle(r[0], r[1], r[2], r[3]) == ref_incircle(r[0], r[1], r[2], r[3]));
        }
    }
    CHECK(collinear > 5000);
}

TEST_CASE("orient2d is exactly zero on collinear points and incircle on cocircular points") {
    Random rng(13);
    // Integer grid lines: a + k d for small integer directions.
    for (int trial = 0; trial < 2000; ++trial) {
        Point a{static_cast<double>(rng.integer(-1000, 1000)), static_cast<double>(rng.integer(-1000, 1000))};
        double dx = rng.integer(-7, 7), dy = rng.integer(-7, 7);
        double k1 = rng.integer(-50, 50), k2 = rng.integer(-50, 50);
        Point b{a[0] + k1 * dx, a[1] + k1 * dy}, c{a[0] + k2 * dx, a[1] + k2 * dy};
        CHECK(stratmesh::orient2d(a.data(), b.data(), c.data()) == 0.0);
        CHECK(ref_orient(a, b, c) == 0);
    }
    // Non-representable decimals on axis-parallel lines and on the diagonal y = x.
    for (int i = 1; i < 60; ++i) {
        for (int j = i + 1; j < 60; j += 7) {
            Point a{0.1 * i, 0.7}, b{0.1 * j, 0.7}, c{0.1 * (i + j), 0.7};
            CHECK(stratmesh::orient2d(a.data(), b.data(), c.data()) == 0.0);
            Point d{0.3, 0.1 * i}, e{0.3, 0.1 * j}, f{0.3, 0.01 * j};
            CHECK(stratmesh::orient2d(d.data(), e.data(), f.data()) == 0.0);
            Point g{0.1 * i, 0.1 * i}, h{0.1 * j, 0.1 * j}, k{0.01 * i, 0.01 * i};
            CHECK(stratmesh::orient2d(g.data(), h.data(), k.data()) == 0.0);
            CHECK(ref_orient(g, h, k) == 0);
        }
    }
    // Lattice points on x^2 + y^2 = 1105^2 (1105 = 5 * 13 * 17 has many), around integer
    // centres and scaled by powers of two.
    std::vector<Point> circle;
    for (int x = -1105; x <= 1105; ++x) {
        int64_t y2 = 1105ll * 1105ll - static_cast<int64_t>(x) * x;
        int64_t y = static_cast<int64_t>(std::llround(std::sqrt(static_cast<double>(y2))));
        if (y * y != y2) continue;
        circle.push_back(Point{static_cast<double>(x), static_cast<double>(y)});
        if (y != 0) circle.push_back(Point{static_cast<double>(x), static_cast<double>(-y)});
    }
    CHECK(circle.size() == 108);
    for (int trial = 0; trial < 1500; ++trial) {
        Point centre{static_cast<double>(rng.integer(-100000, 100000)), static_cast<double>(rng.integer(-100000, 100000))};
        int power = rng.integer(-150, 150);
        Point q[4];
        for (Point& p : q) {
            const Point& on = circle[static_cast<size_t>(rng.integer(0, static_cast<int>(circle.size()) - 1))];
            p = scaled(Point{centre[0] + on[0], centre[1] + on[1]}, power);
        }
        CHECK(stratmesh::incircle(q[0].data(), q[1].data(), q[2].data(), q[3].data()) == 0.0);
        CHECK(ref_incircle(q[0], q[1], q[2], q[3]) == 0);
        Point inside = scaled(centre, power);
        if (ref_orient(q[0], q[1], q[2]) != 0) {
            CHECK(lib_incircle(q[0], q[1], q[2], inside) == ref_orient(q[0], q[1], q[2]));
        }
    }
    // Axis-aligned rectangles with coordinates like 0.1 i are exactly cocircular.
    for (int i = 0; i < 40; ++i) {
        for (int j = i + 1; j < 40; j += 3) {
            double x1 = 0.1 * i, x2 = 0.1 * j, y1 = 0.3 * i + 0.7, y2 = 0.1 * (i + j) + 5;
            Point a{x1, y1}, b{x2, y1}, c{x2, y2}, d{x1, y2};
            CHECK(stratmesh::incircle(a.data(), b.data(), c.data(), d.data()) == 0.0);
            CHECK(stratmesh::incircle(b.data(), d.data(), a.data(), c.data()) == 0.0);
            CHECK(ref_incircle(a, b, c, d) == 0);
        }
    }
}

TEST_CASE("orient2d and incircle are alternating under permutations of their points") {
    Random rng(14);
    const double ulp = 0x1p-53;
    for (int trial = 0; trial < 300; ++trial) {
        Point a{0.5 + rng.integer(0, 255) * ulp, 0.5 + rng.integer(0, 255) * ulp};
        Point b{12, 12}, c{24, 24};
        const double cu = 0x1p-49;
        Point d{12 + 5 / std::sqrt(2.0) + rng.integer(-20, 20) * cu, 12 + 5 / std::sqrt(2.0) + rng.integer(-20, 20) * cu};
        check_permutations(a, b, c, d);                                  // nearly collinear a, b, c
        check_permutations(Point{17, 12}, Point{12, 17}, Point{7, 12}, d);  // nearly cocircular
        check_permutations(Point{rng.uniform(-1, 1), rng.uniform(-1, 1)}, Point{rng.uniform(-1, 1), rng.uniform(-1, 1)},
                           Point{rng.uniform(-1, 1), rng.uniform(-1, 1)}, Point{rng.uniform(-1, 1), rng.uniform(-1, 1)});
    }
    // Exactly cocircular and collinear: every permutation gives exactly zero.
    check_permutations(Point{0.1, 0.7}, Point{0.3, 0.7}, Point{0.3, 0.9}, Point{0.1, 0.9});
    check_permutations(Point{0.1, 0.1}, Point{0.2, 0.2}, Point{0.7, 0.7}, Point{5, -3});
}

// ==== Regressions ==========================================================================

// Regression: points a few ulps apart near 1e-66 .. 1e-70. The four-fold products of
// their differences (about ulp^4 < 2^-1074) underflowed, the filter's error bound rounded
// to zero and incircle returned 0, or even a wrong non-zero sign. Fixed by rescaling the
// points by a power of two before the exact stages.
TEST_CASE("incircle of points a few ulps apart at magnitude 1e-66 to 1e-70 has the exact sign") {
    // The smallest case: centre c, three points 5 ulps away on the axes (counter-clockwise)
    // and c itself, which is strictly inside their circle.
    const double cx = 1.2e-70, cy = 1.3e-70;  // same binade [2^-233, 2^-232): ulp 2^-285
    const double u = 0x1p-285;
    REQUIRE(std::nextafter(cx, 1.0) - cx == u);
    REQUIRE(std::nextafter(cy, 1.0) - cy == u);
    const Point a{cx + 5 * u, cy}, b{cx, cy + 5 * u}, c{cx - 5 * u, cy}, centre{cx, cy};
    CHECK(ref_incircle(a, b, c, centre) == 1);
    CHECK(lib_incircle(a, b, c, centre) == 1);

    // A sweep: d on a 7 x 7 ulp grid around the bottom of circles of radius 5, 25 and 1105
    // ulps (many cells exactly on the circle), at several magnitudes.
    for (int decimal : {-66, -68, -70}) {
        CAPTURE(decimal);
        const double x0 = 1.2 * std::pow(10.0, decimal), y0 = 1.3 * std::pow(10.0, decimal);
        const double step = std::nextafter(x0, 1.0) - x0;
        REQUIRE(std::nextafter(y0, 1.0) - y0 == step);
        int wrong = 0, wrong_nonzero_on_circle = 0;
        for (int radius : {5, 25, 1105}) {
            for (int i = -3; i <= 3; ++i) {
                for (int j = -3; j <= 3; ++j) {
                    const Point pa{x0 + radius * step, y0}, pb{x0, y0 + radius * step}, pc{x0 - radius * step, y0};
                    const Point d{x0 + i * step, y0 + (j - radius) * step};
                    int exact = ref_incircle(pa, pb, pc, d);
                    int got = lib_incircle(pa, pb, pc, d);
                    wrong += got != exact;
                    wrong_nonzero_on_circle += exact == 0 && got != 0;
                }
            }
        }
        CHECK(wrong == 0);
        CHECK(wrong_nonzero_on_circle == 0);
    }
}
