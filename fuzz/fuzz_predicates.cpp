// fuzz_predicates: the sign of stratmesh::orient2d and stratmesh::incircle against the exact
// big-integer reference of tests/support/exact.h.
//
// Input: a mode byte, then data for 8 doubles (a, b, c, d as x, y):
//   mode 0: raw bit patterns;
//   mode 1: structured degenerate configurations (collinear points, cocircular points on
//           an integer circle, a repeated point), scaled by a power of two and translated,
//           then each coordinate moved by a few ulps.
// Non-finite inputs are skipped, and so is each call outside the documented robustness
// contract: coordinates and coordinate differences spanning more than 2^800 for orient2d,
// 2^320 for incircle (stratmesh.h, Robustness contract).
#include "fuzz_common.h"
#include "known_bugs.h"

#include "stratmesh.h"
#include "support/exact.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace {

using stratmesh_fuzz::Bytes;

int sign_of(double v) { return v > 0 ? 1 : v < 0 ? -1 : 0; }

double nudge(double v, int ulps) {
    for (int k = 0; k < ulps; ++k) v = std::nextafter(v, HUGE_VAL);
    for (int k = 0; k > ulps; --k) v = std::nextafter(v, -HUGE_VAL);
    return v;
}

void structured(Bytes& in, double p[8]) {
    // Integer points on the circle of radius 25 (and its centre), so that four of them
    // are exactly cocircular and three of the ones on a line exactly collinear.
    static const int ring[][2] = {{25, 0},  {24, 7},   {20, 15},  {15, 20},  {7, 24},
                                  {0, 25},  {-7, 24},  {-15, 20}, {-20, 15}, {-24, 7},
                                  {-25, 0}, {-24, -7}, {-20, -15}, {-15, -20}, {-7, -24},
                                  {0, -25}, {7, -24},  {15, -20}, {20, -15}, {24, -7}};
    const uint32_t ring_size = sizeof ring / sizeof ring[0];
    uint8_t shape = in.u8();
    for (int k = 0; k < 4; ++k) {
        double x = 0, y = 0;
        switch (shape % 4) {
        case 0: {  // cocircular
            const int* q = ring[in.below(ring_size)];
            x = q[0];
            y = q[1];
            break;
        }
        case 1: {  // collinear: t * (dx, dy)
            double t = in.centered(1000);
            x = t * 3;
            y = t * 7;
            break;
        }
        case 2: {  // small grid: many repeats and collinear triples
            x = in.centered(2);
            y = in.centered(2);
            break;
        }
        default: {  // a line through irrational-looking values
            double t = in.centered(64) / 64.0;
            x = 0.1 + t * 0.3;
            y = 0.7 - t * 0.11;
            break;
        }
        }
        p[2 * k] = x;
        p[2 * k + 1] = y;
    }
    int scale = in.centered(600);
    double tx = in.centered(1000);
    tx = std::ldexp(tx, in.centered(600));
    double ty = in.centered(1000);
    ty = std::ldexp(ty, in.centered(600));
    for (int k = 0; k < 8; ++k) {
        p[k] = std::ldexp(p[k], scale) + (k % 2 ? ty : tx);
        p[k] = nudge(p[k], in.centered(4));
    }
}

bool all_finite(const double p[8]) {
    for (int k = 0; k < 8; ++k)
        if (!std::isfinite(p[k])) return false;
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Bytes in(data, size);
    double p[8];
    if (in.u8() % 2 == 0) {
        for (double& v : p) v = in.raw_double();
    } else {
        structured(in, p);
    }
    if (!all_finite(p)) return 0;
    if (std::getenv("STRATMESH_FUZZ_VERBOSE"))
        for (int k = 0; k < 8; ++k) std::fprintf(stderr, "p[%d] = %a (%.17g)\n", k, p[k], p[k]);
    const double* a = p;
    const double* b = p + 2;
    const double* c = p + 4;
    const double* d = p + 6;
    // All four triples, so that each point of a collinear or cocircular set gets its turn.
    const double* triples[4][3] = {{a, b, c}, {b, c, d}, {a, c, d}, {a, b, d}};
    const bool strict = stratmesh_fuzz::strict();
    for (const auto& t : triples) {
        if (stratmesh_fuzz::orient2d_spread(t[0], t[1], t[2]) > 800) continue;
        int got = sign_of(stratmesh::orient2d(t[0], t[1], t[2]));
        int want = exact_ref::exact_orient2d_sign(t[0], t[1], t[2]);
        STRATMESH_FUZZ_CHECK(got == want, "orient2d sign differs from the exact reference");
    }
    if (!strict && stratmesh_fuzz::bug_b_incircle(a, b, c, d)) return 0;
    int got = sign_of(stratmesh::incircle(a, b, c, d));
    int want = exact_ref::exact_incircle_sign(a, b, c, d);
    STRATMESH_FUZZ_CHECK(got == want, "incircle sign differs from the exact reference");
    if (!strict && stratmesh_fuzz::bug_b_incircle(b, a, d, c)) return 0;
    got = sign_of(stratmesh::incircle(b, a, d, c));
    want = exact_ref::exact_incircle_sign(b, a, d, c);
    STRATMESH_FUZZ_CHECK(got == want, "incircle sign differs from the exact reference (permuted)");
    return 0;
}
