// stratmesh.h - stratified surface reconstruction of columnar point clouds, in fixed memory.
// Version 0.1.0. MIT licence (text at the end of this file).
//
// stratmesh turns a 3D point cloud of a roughly columnar object (a head, a limb, a bone,
// a pipe, a tree stem) into a triangle mesh that interpolates the points. It slices the
// cloud into layers across an axis, unrolls each layer from a cylinder onto a plane,
// triangulates it with its own exact 2D Delaunay triangulation and stitches the layers
// into one manifold surface. No heap, no exceptions, no globals: all working memory is a
// buffer the caller sizes in advance.
//
// ==== Quick start ==========================================================================
//
//     #define STRATMESH_IMPLEMENTATION    // in exactly one .cpp file
//     #include "stratmesh.h"
//
//     // 2D Delaunay triangulation of n points stored as x0,y0,x1,y1,...
//     std::vector<unsigned char> work(stratmesh::delaunay_2d_workspace_size(n));
//     std::vector<uint32_t> tris(3 * stratmesh::delaunay_2d_max_triangles(n));
//     stratmesh::Delaunay2dInfo info;
//     stratmesh::Status s = stratmesh::delaunay_2d(xy, n, 2 * sizeof(double),
//                                                  work.data(), work.size(),
//                                                  tris.data(), tris.size() / 3, &info,
//                                                  nullptr);
//     if (s != stratmesh::Status::ok) puts(stratmesh::status_string(s));
//     // tris[0 .. 3 * info.triangle_count) are counter-clockwise index triples.
//
// ==== Integration ==========================================================================
//
// Either define STRATMESH_IMPLEMENTATION before including this header in one source file
// (every other file includes it plainly), or compile stratmesh.cpp, which does exactly
// that, and link it (CMake: target stratmesh::stratmesh). Including the header several
// times, with or without the macro, is safe.
//
// Only freestanding-friendly C++17 headers are used: <cstddef>, <cstdint>, <cstring>,
// <cfloat>, <climits>. Builds with -fno-exceptions -fno-rtti.
//
// ==== Configuration macros =================================================================
//
//   STRATMESH_ASSERT(cond)   default: nothing (assertions compiled out).
//                            Define it (e.g. to assert(cond)) to check internal
//                            invariants in debug builds. Bad *data* never reaches an
//                            assert: it returns a Status.
//
// ==== Memory ===============================================================================
//
// Every function that needs working memory takes (void* workspace, size_t workspace_bytes)
// and has a *_workspace_size() companion that returns a size that is always sufficient.
// The workspace needs no particular alignment. A smaller workspace returns
// Status::out_of_memory; the library never writes outside the workspace and the output
// arrays it is given, whatever the input.
//
// delaunay_2d needs 72 bytes per point plus about 10 KiB; its output is at most
// 2n - 5 triangles (24 bytes per point).
//
// ==== Errors ===============================================================================
//
// Every public function returns a Status; status_string() names it. Status values are
// grouped by what detects them: argument checks, the data, memory, and internal_error,
// which means an invariant failed (a bug: please report it with the input). Nothing is
// thrown and nothing aborts.
//
// ==== Threading ============================================================================
//
// No global or static mutable state. Functions are reentrant: threads may run them at
// once with separate workspaces.
//
// ==== Robustness contract ==================================================================
//
// - orient2d and incircle return values whose sign is exact for every finite double input
//   whose intermediate products neither overflow nor underflow (coordinates with
//   magnitudes between about 1e-70 and 1e70 are always safe). A fast floating-point
//   filter with a proven error bound decides almost every call; expansion arithmetic
//   decides the rest. The implementation pins floating-point contraction off (no fused
//   multiply-add), whatever the compiler's flags.
// - delaunay_2d produces the Delaunay triangulation of the distinct input points. Where
//   four or more points are cocircular, the triangulation is made unique by a symbolic
//   perturbation (each point is lifted off the paraboloid by an infinitesimal amount that
//   grows with its lexicographic (x, y) rank), so the set of triangles depends only on
//   the coordinates: not on the input order, not on the architecture. Exact duplicates
//   are not triangulated twice: each is mapped to the lowest index with the same
//   coordinates. Every other point is a vertex of the output.
// - NaN or infinite coordinates are refused (Status::invalid_point, with the index).

#ifndef STRATMESH_H
#define STRATMESH_H

#include <cstddef>
#include <cstdint>

#define STRATMESH_VERSION_MAJOR 0
#define STRATMESH_VERSION_MINOR 1
#define STRATMESH_VERSION_PATCH 0
#define STRATMESH_VERSION_STRING "0.1.0"

namespace stratmesh {

// ==== Status ===============================================================================

// One list generates the enum and its messages, so they cannot drift apart.
#define STRATMESH_STATUS_LIST(X)                                                           \
    /* success */                                                                         \
    X(ok, "success")                                                                      \
    /* argument checks: a caller error, detected before any work */                      \
    X(invalid_argument, "a null pointer with a non-zero count, or a stride too small")    \
    X(too_many_points, "more points than 32-bit indices can address")                    \
    /* the data */                                                                        \
    X(invalid_point, "a coordinate is NaN or infinite")                                   \
    X(too_few_points, "fewer than 3 distinct points")                                     \
    X(collinear, "all points lie on one line")                                            \
    /* memory */                                                                          \
    X(out_of_memory, "the workspace is smaller than its *_workspace_size() bound")         \
    X(triangle_capacity, "the triangle array is too small for the result")               \
    /* bugs */                                                                            \
    X(internal_error, "an internal invariant failed (a bug: please report the input)")

enum class Status : uint32_t {
#define STRATMESH_STATUS_ENUM(name, message) name,
    STRATMESH_STATUS_LIST(STRATMESH_STATUS_ENUM)
#undef STRATMESH_STATUS_ENUM
};

// The status's name followed by a one-line explanation; never null.
const char* status_string(Status status);

// ==== Predicates ===========================================================================
//
// Points are double[2] (x, y). The returned value's sign is exact (see the robustness
// contract above); its magnitude is an approximation of the determinant.

// Twice the signed area of triangle abc: positive if a, b, c turn counter-clockwise,
// negative if clockwise, zero if collinear.
double orient2d(const double a[2], const double b[2], const double c[2]);

// Positive if d lies inside the circle through a, b, c (which must be counter-clockwise),
// negative if outside, zero if the four points are cocircular. If a, b, c are clockwise
// the sign is reversed.
double incircle(const double a[2], const double b[2], const double c[2], const double d[2]);

// ==== 2D Delaunay triangulation ============================================================

struct Delaunay2dInfo {
    size_t triangle_count;      // triangles written (or needed, on triangle_capacity)
    size_t duplicate_count;     // points that repeat an earlier point's coordinates
    size_t hull_vertex_count;   // points on the convex hull boundary, collinear ones too
    size_t first_invalid_point; // index of the first NaN/Inf point, on invalid_point
};

// A size in bytes that is always enough workspace for delaunay_2d of point_count points.
size_t delaunay_2d_workspace_size(size_t point_count);

// The most triangles delaunay_2d can produce for point_count points: 2n - 5 for n >= 3.
size_t delaunay_2d_max_triangles(size_t point_count);

// Delaunay triangulation of 2D points.
//
// xy              first point's x; y follows it; the next point starts stride_bytes later.
//                 Needs no alignment.
// point_count     number of points, at most 2^32 - 2.
// stride_bytes    distance between consecutive points, at least 2 * sizeof(double).
// workspace       at least delaunay_2d_workspace_size(point_count) bytes.
// triangles       receives 3 * triangle_count indices into the input, each triangle
//                 counter-clockwise. Triangles appear in an unspecified but deterministic
//                 order; the set of triangles depends only on the coordinates.
// triangle_capacity  how many triangles fit in `triangles`; delaunay_2d_max_triangles()
//                 always suffices. When too small: Status::triangle_capacity, nothing
//                 written, info->triangle_count says how many are needed.
// info            optional; receives counts (see Delaunay2dInfo).
// duplicate_of    optional array of point_count entries: receives, for each point, the
//                 index of the lowest-indexed point with the same coordinates (itself if
//                 it has no lower twin). Written on ok.
//
// Returns ok; invalid_argument; too_many_points; invalid_point; too_few_points (fewer
// than 3 distinct points); collinear (no triangle exists); out_of_memory;
// triangle_capacity. On every status but ok, triangle_count is 0 (except
// triangle_capacity) and no triangle is written.
Status delaunay_2d(const double* xy, size_t point_count, size_t stride_bytes,
                   void* workspace, size_t workspace_bytes,
                   uint32_t* triangles, size_t triangle_capacity,
                   Delaunay2dInfo* info, uint32_t* duplicate_of);

} // namespace stratmesh

#endif // STRATMESH_H

// ===========================================================================================
// ==== Implementation =======================================================================
// ===========================================================================================

#if defined(STRATMESH_IMPLEMENTATION) && !defined(STRATMESH_IMPLEMENTATION_DONE)
#define STRATMESH_IMPLEMENTATION_DONE

#include <cfloat>
#include <climits>
#include <cstring>

// >>config ==================================================================================

#ifndef STRATMESH_ASSERT
#define STRATMESH_ASSERT(cond) ((void)0)
#endif

static_assert(sizeof(double) == 8 && DBL_MANT_DIG == 53 && FLT_RADIX == 2,
              "stratmesh needs IEEE-754 binary64 doubles");
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0
#error "stratmesh needs FLT_EVAL_METHOD == 0 (x87 extended precision breaks the predicates; use SSE2)"
#endif

// The error-free transformations below are only exact if every product is rounded on its
// own. A fused multiply-add contracted from a*b - c changes the rounding and silently
// breaks them, so contraction is switched off for the whole implementation, whatever
// flags the user compiles with (GCC contracts by default outside strict ISO mode, clang
// within expressions).
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")
#elif defined(_MSC_VER)
#pragma fp_contract(off)
#endif

namespace stratmesh {

const char* status_string(Status status) {
    switch (status) {
#define STRATMESH_STATUS_CASE(name, message) \
    case Status::name: return #name ": " message;
        STRATMESH_STATUS_LIST(STRATMESH_STATUS_CASE)
#undef STRATMESH_STATUS_CASE
    }
    return "unknown status";
}

namespace detail {

static const uint32_t kNoIndex = 0xFFFFFFFFu;
static const size_t kMaxPoints = 0xFFFFFFFEu;

#if defined(__GNUC__) || defined(__clang__)
inline double abs_value(double x) { return __builtin_fabs(x); }
#else
inline double abs_value(double x) { return x < 0 ? -x : x; }
#endif
inline bool is_finite(double x) { return x - x == 0; }

inline double read_double(const unsigned char* p) {
    double v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

// >>arena ===================================================================================
//
// A bump allocator over the caller's buffer. A "measuring" arena (null base) only adds up
// sizes, so *_workspace_size() runs the very allocation sequence the real call runs and
// the two cannot disagree.

struct Arena {
    static const size_t kAlign = 16;

    unsigned char* base;
    size_t capacity;
    size_t used;
    size_t high_water;
    bool failed;

    static Arena over(void* buffer, size_t bytes) {
        Arena a = {nullptr, 0, 0, 0, false};
        if (!buffer) return a;
        uintptr_t start = reinterpret_cast<uintptr_t>(buffer);
        size_t pad = (kAlign - start % kAlign) % kAlign;
        if (bytes < pad) {
            a.base = static_cast<unsigned char*>(buffer);
            return a;
        }
        a.base = static_cast<unsigned char*>(buffer) + pad;
        a.capacity = bytes - pad;
        return a;
    }
    static Arena measuring() { return Arena{nullptr, SIZE_MAX, 0, 0, false}; }

    bool is_measuring() const { return base == nullptr && capacity == SIZE_MAX; }

    // The bytes to ask the caller for: what was used, plus the worst alignment padding.
    size_t required_bytes() const { return high_water + kAlign - 1; }

    template <class T> T* alloc(size_t count) {
        if (failed) return nullptr;
        if (count > (SIZE_MAX - kAlign) / sizeof(T)) {
            failed = true;
            return nullptr;
        }
        size_t bytes = (count * sizeof(T) + kAlign - 1) / kAlign * kAlign;
        if (bytes > capacity - used) {
            failed = true;
            return nullptr;
        }
        size_t offset = used;
        used += bytes;
        if (used > high_water) high_water = used;
        if (is_measuring()) return reinterpret_cast<T*>(kAlign); // never dereferenced
        return reinterpret_cast<T*>(base + offset);
    }

    size_t mark() const { return used; }
    void rewind(size_t m) { used = m; }
};

// >>predicates ==============================================================================
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

constexpr double kEps = DBL_EPSILON / 2;
constexpr double kSplitter = 134217729.0; // 2^27 + 1: splits a double into two 26-bit halves
constexpr double kOrientBoundA = (3.0 + 16.0 * kEps) * kEps;
constexpr double kIncircleBoundA = (10.0 + 96.0 * kEps) * kEps;

// a + b = x + y exactly, with x = fl(a + b).
inline void two_sum(double a, double b, double& x, double& y) {
    x = a + b;
    double bv = x - a;
    double av = x - bv;
    y = (a - av) + (b - bv);
}

// a - b = x + y exactly, with x = fl(a - b).
inline void two_diff(double a, double b, double& x, double& y) {
    x = a - b;
    double bv = a - x;
    double av = x + bv;
    y = (a - av) + (bv - b);
}

inline void split(double a, double& hi, double& lo) {
    double c = kSplitter * a;
    double big = c - a;
    hi = c - big;
    lo = a - hi;
}

// a * b = x + y exactly, with x = fl(a * b) (Dekker's product, Veltkamp's split).
inline void two_product(double a, double b, double& x, double& y) {
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
inline void two_two_diff(double a1, double a0, double b1, double b0, double* out) {
    double i, j, z;
    two_diff(a0, b0, i, out[0]);
    two_sum(a1, i, j, z);
    two_diff(z, b1, i, out[1]);
    two_sum(j, i, out[3], out[2]);
}

// ax*by - ay*bx as a four-component expansion.
inline void cross_exact(double ax, double ay, double bx, double by, double* out) {
    double p1, p0, q1, q0;
    two_product(ax, by, p1, p0);
    two_product(ay, bx, q1, q0);
    two_two_diff(p1, p0, q1, q0, out);
}

// h = e + f; returns the length of h with zero components removed (at least 1). h needs
// room for elen + flen components and must not alias e or f.
inline int expansion_sum(int elen, const double* e, int flen, const double* f, double* h) {
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
inline int compress_zeros(int len, double* e) {
    int kept = 0;
    for (int i = 0; i < len; ++i)
        if (e[i] != 0) e[kept++] = e[i];
    if (kept == 0) e[kept++] = 0;
    return kept;
}

// h = b * e; returns the length of h (at most 2 * elen) with zeros removed. h must not
// alias e.
inline int expansion_scale(int elen, const double* e, double b, double* h) {
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
inline int expansion_product(int elen, const double* e, int flen, const double* f, double* h,
                             double* tmp, double* scaled) {
    int len = expansion_scale(elen, e, f[0], h);
    for (int j = 1; j < flen; ++j) {
        int slen = expansion_scale(elen, e, f[j], scaled);
        len = expansion_sum(len, h, slen, scaled, tmp);
        std::memcpy(h, tmp, sizeof(double) * static_cast<size_t>(len));
    }
    return len;
}

inline void expansion_negate(int len, double* e) {
    for (int i = 0; i < len; ++i) e[i] = -e[i];
}

// The most significant non-zero component (0 if the expansion is zero).
inline double expansion_top(int len, const double* e) {
    for (int i = len - 1; i >= 0; --i)
        if (e[i] != 0) return e[i];
    return 0;
}

// orient2d from the raw coordinates: a x b + b x c + c x a, exactly.
inline double orient2d_exact(const double* a, const double* b, const double* c) {
    double ab[4], bc[4], ca[4], s[8], t[12];
    cross_exact(a[0], a[1], b[0], b[1], ab);
    cross_exact(b[0], b[1], c[0], c[1], bc);
    cross_exact(c[0], c[1], a[0], a[1], ca);
    int slen = expansion_sum(4, ab, 4, bc, s);
    int tlen = expansion_sum(slen, s, 4, ca, t);
    return expansion_top(tlen, t);
}

// Sign-exact orient2d: the filter decides unless |det| is within the rounding error, then
// the differences are tried for exactness, then the raw coordinates are used.
inline double orient2d_robust(const double* a, const double* b, const double* c) {
    double acx = a[0] - c[0], bcx = b[0] - c[0];
    double acy = a[1] - c[1], bcy = b[1] - c[1];
    double left = acx * bcy;
    double right = acy * bcx;
    double det = left - right;
    double bound = kOrientBoundA * (abs_value(left) + abs_value(right));
    if (det > bound || -det > bound) return det;
    double t0, t1, t2, t3;
    two_diff(a[0], c[0], acx, t0);
    two_diff(b[0], c[0], bcx, t1);
    two_diff(a[1], c[1], acy, t2);
    two_diff(b[1], c[1], bcy, t3);
    if (t0 == 0 && t1 == 0 && t2 == 0 && t3 == 0) {
        double d[4];
        cross_exact(acx, acy, bcx, bcy, d);
        return expansion_top(4, d);
    }
    return orient2d_exact(a, b, c);
}

// Scratch, in doubles, for the exact incircle below.
const int kIncircleScratch = 1024;

// incircle from the raw coordinates: the 4x4 determinant with rows (x, y, x^2 + y^2, 1),
// expanded along the lift column. Needs kIncircleScratch doubles of scratch.
inline double incircle_exact(const double* a, const double* b, const double* c,
                             const double* d, double* scratch) {
    const double* p[4] = {a, b, c, d};
    double* acc = scratch;         // 384
    double* acc2 = scratch + 384;  // 384
    double* term = scratch + 768;  // 96
    double* tmp = scratch + 864;   // 96
    double* scaled = scratch + 960; // 24
    double* orient = scratch + 984; // 12
    double* cross = scratch + 996;  // 8
    double lift[4], lp[2], lq[2], pair[8];
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
    (void)pair;
    return expansion_top(acc_len, acc);
}

// incircle when the six coordinate differences are exact doubles: the 3x3 determinant of
// (dx, dy, dx^2 + dy^2) rows, exactly. Needs 256 doubles of scratch.
inline double incircle_exact_differences(double adx, double ady, double bdx, double bdy,
                                         double cdx, double cdy, double* scratch) {
    const double rows[3][2] = {{adx, ady}, {bdx, bdy}, {cdx, cdy}};
    double* det = scratch;          // 96
    double* det2 = scratch + 96;    // 96
    double* x1 = scratch + 192;     // 8
    double* x2 = scratch + 200;     // 16
    double* y1 = scratch + 216;     // 8
    double* y2 = scratch + 224;     // 16
    double* sum = scratch + 240;    // 32 (ends at 272)
    int det_len = 0;
    for (int i = 0; i < 3; ++i) {
        const double* u = rows[(i + 1) % 3];
        const double* v = rows[(i + 2) % 3];
        double minor[4];
        cross_exact(u[0], u[1], v[0], v[1], minor);
        int mlen = compress_zeros(4, minor);
        int l1 = expansion_scale(mlen, minor, rows[i][0], x1);
        int l2 = expansion_scale(l1, x1, rows[i][0], x2);
        int l3 = expansion_scale(mlen, minor, rows[i][1], y1);
        int l4 = expansion_scale(l3, y1, rows[i][1], y2);
        int slen = expansion_sum(l2, x2, l4, y2, sum);
        if (det_len == 0) {
            std::memcpy(det, sum, sizeof(double) * static_cast<size_t>(slen));
            det_len = slen;
        } else {
            det_len = expansion_sum(det_len, det, slen, sum, det2);
            std::memcpy(det, det2, sizeof(double) * static_cast<size_t>(det_len));
        }
    }
    return expansion_top(det_len, det);
}

// Sign-exact incircle using `scratch` (kIncircleScratch doubles) when the filter fails.
inline double incircle_robust(const double* a, const double* b, const double* c,
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
    double bound = kIncircleBoundA * permanent;
    if (det > bound || -det > bound) return det;
    double t[6];
    two_diff(a[0], d[0], adx, t[0]);
    two_diff(b[0], d[0], bdx, t[1]);
    two_diff(c[0], d[0], cdx, t[2]);
    two_diff(a[1], d[1], ady, t[3]);
    two_diff(b[1], d[1], bdy, t[4]);
    two_diff(c[1], d[1], cdy, t[5]);
    if (t[0] == 0 && t[1] == 0 && t[2] == 0 && t[3] == 0 && t[4] == 0 && t[5] == 0)
        return incircle_exact_differences(adx, ady, bdx, bdy, cdx, cdy, scratch);
    return incircle_exact(a, b, c, d, scratch);
}

// Lexicographic order on (x, y): the rank that sets each point's perturbation.
inline bool lex_less(const double* p, const double* q) {
    return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
}

// The sign of incircle(a, b, c, d) for counter-clockwise abc, with ties broken by the
// symbolic perturbation: point i is lifted by eps^(4 - rank(i)), the lexicographically
// largest point the most. A tie is settled by the largest point whose cofactor (the
// orientation of the other three) is non-zero; d's cofactor is -orient(a, b, c) < 0, so
// the loop always ends. Never returns 0 for four distinct points.
inline int incircle_perturbed(const double* a, const double* b, const double* c,
                              const double* d, double* scratch) {
    double det = incircle_robust(a, b, c, d, scratch);
    if (det > 0) return 1;
    if (det < 0) return -1;
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

}  // namespace detail

double orient2d(const double a[2], const double b[2], const double c[2]) {
    return detail::orient2d_robust(a, b, c);
}

double incircle(const double a[2], const double b[2], const double c[2], const double d[2]) {
    double scratch[detail::kIncircleScratch];
    return detail::incircle_robust(a, b, c, d, scratch);
}

namespace detail {

// >>spatial sort ============================================================================
//
// This work is based on:
//   N. Amenta, S. Choi, G. Rote, "Incremental constructions con BRIO", SoCG 2003.
//
// Points are inserted in a biased randomized insertion order: rounds of doubling size,
// each round ordered along a Hilbert curve. The curve keeps every walk short; the rounds
// spread the early points over the whole domain so that later points land in
// well-shaped triangles (a pure curve order makes long slivers at the growing front and
// costs about 40% more flips). The "random" round of a point is a hash of its
// coordinates, so exact duplicates share a round and a curve cell, and the stable sort
// keeps them in input order: the first inserted is the lowest index.

const uint32_t kHilbertBits = 13;  // per axis; 5 bits of the 32-bit key are left for rounds

inline uint32_t hilbert_index(uint32_t x, uint32_t y) {
    const uint32_t full = (1u << kHilbertBits) - 1;
    uint32_t d = 0;
    for (uint32_t s = 1u << (kHilbertBits - 1); s > 0; s >>= 1) {
        uint32_t rx = (x & s) ? 1u : 0u;
        uint32_t ry = (y & s) ? 1u : 0u;
        d += s * s * ((3u * rx) ^ ry);
        // Rotate the quadrant, without branches (their outcome is random).
        uint32_t reflect = full & (0u - (rx & (ry ^ 1u)));
        x ^= reflect;
        y ^= reflect;
        uint32_t swap = (x ^ y) & (0u - (ry ^ 1u));
        x ^= swap;
        y ^= swap;
    }
    return d;
}

inline uint32_t quantize(double v, double lo, double scale) {
    const double top = static_cast<double>((1u << kHilbertBits) - 1);
    double q = (v - lo) * scale;
    if (!(q > 0)) return 0;
    if (q >= top) return (1u << kHilbertBits) - 1;
    return static_cast<uint32_t>(q);
}

inline uint32_t mix32(uint32_t h) {
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return h;
}

// A hash of the point's coordinates (-0 and +0 hash alike).
inline uint32_t coordinate_hash(double x, double y) {
    uint64_t bx, by;
    x += 0.0;
    y += 0.0;
    std::memcpy(&bx, &x, sizeof bx);
    std::memcpy(&by, &y, sizeof by);
    uint32_t h = mix32(static_cast<uint32_t>(bx) ^ 0x9E3779B9u);
    h = mix32(h ^ static_cast<uint32_t>(bx >> 32));
    h = mix32(h ^ static_cast<uint32_t>(by));
    return mix32(h ^ static_cast<uint32_t>(by >> 32));
}

// Stable LSD radix sort of `order` by `keys` (both count long), 8 bits a pass.
inline void radix_sort(uint32_t* keys, uint32_t* order, uint32_t* keys_tmp,
                       uint32_t* order_tmp, size_t count) {
    for (uint32_t shift = 0; shift < 32; shift += 8) {
        size_t histogram[256];
        std::memset(histogram, 0, sizeof histogram);
        for (size_t i = 0; i < count; ++i) ++histogram[(keys[i] >> shift) & 0xFFu];
        size_t total = 0;
        for (size_t& h : histogram) {
            size_t c = h;
            h = total;
            total += c;
        }
        for (size_t i = 0; i < count; ++i) {
            size_t slot = histogram[(keys[i] >> shift) & 0xFFu]++;
            keys_tmp[slot] = keys[i];
            order_tmp[slot] = order[i];
        }
        uint32_t* t = keys; keys = keys_tmp; keys_tmp = t;
        t = order; order = order_tmp; order_tmp = t;
    }
    // An even number of passes: the sorted data is back in the caller's arrays.
}

struct BoundingBox2d {
    double min[2], max[2];
};

// Fills order[0..count) with the indices of the points (x, y doubles, stride bytes apart)
// in BRIO order over `box`; scratch from the arena.
inline bool spatial_order(const unsigned char* xy, size_t stride, size_t count,
                          const BoundingBox2d& box, uint32_t* order, Arena& arena) {
    size_t mark = arena.mark();
    uint32_t* keys = arena.alloc<uint32_t>(count);
    uint32_t* keys_tmp = arena.alloc<uint32_t>(count);
    uint32_t* order_tmp = arena.alloc<uint32_t>(count);
    if (arena.failed) return false;
    double scale[2];
    for (int k = 0; k < 2; ++k) {
        double range = box.max[k] - box.min[k];
        scale[k] = (range > 0 && is_finite(range)) ? ((1u << kHilbertBits) - 1) / range : 0.0;
        if (!is_finite(scale[k])) scale[k] = 0.0;
    }
    // Rounds: the last holds about half the points, the first about 64.
    uint32_t rounds = 0;
    while (rounds < 24 && (count >> (rounds + 7)) > 0) ++rounds;
    const uint32_t curve_mask = (1u << (2 * kHilbertBits)) - 1;
    for (size_t i = 0; i < count; ++i) {
        const unsigned char* p = xy + i * stride;
        double x = read_double(p), y = read_double(p + sizeof(double));
        uint32_t h = coordinate_hash(x, y);
        uint32_t zeros = 0;
        while (zeros < rounds && (h & (1u << zeros)) == 0) ++zeros;
        uint32_t round = rounds - zeros;
        uint32_t curve = hilbert_index(quantize(x, box.min[0], scale[0]),
                                       quantize(y, box.min[1], scale[1]));
        // Odd rounds run the curve backwards, so each round starts where the last ended.
        if (round % 2 == 1) curve = curve_mask - curve;
        keys[i] = (round << (2 * kHilbertBits)) | curve;
        order[i] = static_cast<uint32_t>(i);
    }
    radix_sort(keys, order, keys_tmp, order_tmp, count);
    arena.rewind(mark);
    return true;
}

// >>delaunay ================================================================================
//
// This work is based on:
//   C. L. Lawson, "Software for C1 surface interpolation", 1977 (edge flips).
//   P. J. Green, R. Sibson, "Computing Dirichlet tessellations in the plane", 1978.
//   O. Devillers, S. Pion, M. Teillaud, "Walking in a triangulation", 2002.
//
// Incremental insertion with Lawson flips on compact arrays. Triangle t owns half-edges
// 3t, 3t+1, 3t+2; half-edge e runs from vertex[e] to vertex[next(e)] and twin[e] is the
// opposite half-edge. Real triangles are counter-clockwise. The outside of the convex
// hull is covered by "ghost" triangles (a, b, kGhost), one per hull edge a->b (seen with
// the outside on its left), so every half-edge has a twin and points outside the hull are
// inserted like any other: a ghost (a, b, G) "contains" p when orient(a, b, p) > 0, and
// an edge to G is flipped when p sees the next hull edge. With m points there are always
// 2m - 2 triangles, ghosts included.

static const uint32_t kGhost = kNoIndex;

inline uint32_t next_edge(uint32_t e) { return e % 3 == 2 ? e - 2 : e + 1; }
inline uint32_t prev_edge(uint32_t e) { return e % 3 == 0 ? e + 2 : e - 1; }

struct Triangulation {
    const double* xy;     // 2 per vertex, vertices in insertion order
    uint32_t* vertex;     // 3 per triangle
    uint32_t* twin;       // 3 per triangle
    uint32_t triangle_count;
    uint32_t triangle_capacity;
    uint32_t* stack;      // half-edges waiting for the flip test
    uint32_t stack_capacity;
    double* scratch;      // for exact incircle
    uint32_t hint;        // triangle to start the next walk from

    const double* point(uint32_t v) const { return xy + 2 * static_cast<size_t>(v); }

    bool is_ghost(uint32_t t) const {
        return vertex[3 * t] == kGhost || vertex[3 * t + 1] == kGhost ||
               vertex[3 * t + 2] == kGhost;
    }

    void link(uint32_t e, uint32_t f) {
        twin[e] = f;
        twin[f] = e;
    }

    void set_triangle(uint32_t t, uint32_t a, uint32_t b, uint32_t c) {
        vertex[3 * t] = a;
        vertex[3 * t + 1] = b;
        vertex[3 * t + 2] = c;
    }
};

// Memory for a triangulation of up to `count` points (the points themselves excluded).
inline bool allocate_triangulation(Triangulation& tr, size_t count, Arena& arena) {
    size_t triangles = count >= 3 ? 2 * count - 2 : 4;
    tr.vertex = arena.alloc<uint32_t>(3 * triangles);
    tr.twin = arena.alloc<uint32_t>(3 * triangles);
    tr.stack = arena.alloc<uint32_t>(count + 4);
    tr.scratch = arena.alloc<double>(kIncircleScratch);
    tr.triangle_count = 0;
    tr.triangle_capacity = static_cast<uint32_t>(triangles);
    tr.stack_capacity = static_cast<uint32_t>(count + 4);
    tr.hint = 0;
    return !arena.failed;
}

// The first triangle (a, b, c), counter-clockwise, and its three ghosts.
inline void start_triangulation(Triangulation& tr, uint32_t a, uint32_t b, uint32_t c) {
    tr.set_triangle(0, a, b, c);
    tr.set_triangle(1, b, a, kGhost);
    tr.set_triangle(2, c, b, kGhost);
    tr.set_triangle(3, a, c, kGhost);
    tr.link(0, 3);  // a->b with b->a
    tr.link(1, 6);  // b->c with c->b
    tr.link(2, 9);  // c->a with a->c
    tr.link(4, 11); // a->G with G->a
    tr.link(7, 5);  // b->G with G->b
    tr.link(10, 8); // c->G with G->c
    tr.triangle_count = 4;
    tr.hint = 0;
}

enum class Location { inside, on_edge, on_vertex, outside, failed };

// Walks from the hint to the triangle containing p. On return `edge` is: for inside, any
// half-edge of the triangle; for on_edge, the half-edge p lies on; for on_vertex, a
// half-edge starting at the vertex p coincides with; for outside, the hull half-edge of
// the ghost triangle p is in (p strictly on its outer side).
inline Location locate(const Triangulation& tr, const double* p, uint32_t& edge) {
    uint32_t t = tr.hint;
    if (tr.is_ghost(t)) {
        for (uint32_t k = 0; k < 3; ++k) {
            uint32_t e = 3 * t + k;
            if (tr.vertex[e] != kGhost && tr.vertex[next_edge(e)] != kGhost) {
                t = tr.twin[e] / 3;
                break;
            }
        }
    }
    uint32_t came_from = kNoIndex;
    for (uint32_t steps = 0; steps <= tr.triangle_count; ++steps) {
        double o[3];
        bool moved = false;
        for (uint32_t k = 0; k < 3; ++k) {
            uint32_t e = 3 * t + (k + steps) % 3;
            if (e == came_from) {
                o[e % 3] = 1;
                continue;
            }
            o[e % 3] = orient2d_robust(tr.point(tr.vertex[e]), tr.point(tr.vertex[next_edge(e)]), p);
            if (o[e % 3] < 0) {
                uint32_t f = tr.twin[e];
                uint32_t u = f / 3;
                if (tr.is_ghost(u)) {
                    edge = f;
                    return Location::outside;
                }
                came_from = f;
                t = u;
                moved = true;
                break;
            }
        }
        if (moved) continue;
        int zeros = (o[0] == 0) + (o[1] == 0) + (o[2] == 0);
        if (zeros == 0) {
            edge = 3 * t;
            return Location::inside;
        }
        if (zeros == 1) {
            edge = 3 * t + (o[0] == 0 ? 0u : o[1] == 0 ? 1u : 2u);
            return Location::on_edge;
        }
        // Two zero edges meet at the vertex p coincides with: the start of the later one.
        uint32_t k = (o[0] != 0) ? 2u : (o[1] != 0) ? 0u : 1u;
        edge = 3 * t + k;
        return Location::on_vertex;
    }
    return Location::failed;
}

inline bool push_edge(Triangulation& tr, uint32_t& top, uint32_t e) {
    if (top >= tr.stack_capacity) return false;
    tr.stack[top++] = e;
    return true;
}

// Splits the triangle of half-edge e = (a, b, c) into (a, b, p), (b, c, p), (c, a, p).
inline void split_triangle(Triangulation& tr, uint32_t t, uint32_t p, uint32_t& top) {
    uint32_t a = tr.vertex[3 * t], b = tr.vertex[3 * t + 1], c = tr.vertex[3 * t + 2];
    uint32_t o1 = tr.twin[3 * t + 1], o2 = tr.twin[3 * t + 2];
    uint32_t t1 = tr.triangle_count, t2 = tr.triangle_count + 1;
    tr.triangle_count += 2;
    tr.set_triangle(t, a, b, p);
    tr.set_triangle(t1, b, c, p);
    tr.set_triangle(t2, c, a, p);
    tr.link(3 * t1, o1);
    tr.link(3 * t2, o2);
    tr.link(3 * t + 1, 3 * t1 + 2);  // b->p with p->b
    tr.link(3 * t + 2, 3 * t2 + 1);  // p->a with a->p
    tr.link(3 * t1 + 1, 3 * t2 + 2); // c->p with p->c
    push_edge(tr, top, 3 * t);
    push_edge(tr, top, 3 * t1);
    push_edge(tr, top, 3 * t2);
    tr.hint = t;
}

// Splits the edge e = a->b (in triangle (a, b, c), twin in (b, a, d)) at p.
inline void split_edge(Triangulation& tr, uint32_t e, uint32_t p, uint32_t& top) {
    uint32_t f = tr.twin[e];
    uint32_t t = e / 3, u = f / 3;
    uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)], c = tr.vertex[prev_edge(e)];
    uint32_t d = tr.vertex[prev_edge(f)];
    uint32_t x1 = tr.twin[next_edge(e)], x2 = tr.twin[prev_edge(e)];  // b->c, c->a
    uint32_t y1 = tr.twin[next_edge(f)], y2 = tr.twin[prev_edge(f)];  // a->d, d->b
    uint32_t t1 = tr.triangle_count, u1 = tr.triangle_count + 1;
    tr.triangle_count += 2;
    tr.set_triangle(t, c, a, p);
    tr.set_triangle(t1, c, p, b);
    tr.set_triangle(u, d, b, p);
    tr.set_triangle(u1, d, p, a);
    tr.link(3 * t, x2);
    tr.link(3 * t1 + 2, x1);
    tr.link(3 * u, y2);
    tr.link(3 * u1 + 2, y1);
    tr.link(3 * t + 1, 3 * u1 + 1);  // a->p with p->a
    tr.link(3 * t + 2, 3 * t1);      // p->c with c->p
    tr.link(3 * t1 + 1, 3 * u + 1);  // p->b with b->p
    tr.link(3 * u + 2, 3 * u1);      // p->d with d->p
    push_edge(tr, top, 3 * t);
    push_edge(tr, top, 3 * t1 + 2);
    push_edge(tr, top, 3 * u);
    push_edge(tr, top, 3 * u1 + 2);
    tr.hint = t;
}

// Whether edge e, in triangle (a, b, p) with p the point just inserted, must be flipped.
inline bool must_flip(const Triangulation& tr, uint32_t e) {
    uint32_t f = tr.twin[e];
    uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)], p = tr.vertex[prev_edge(e)];
    uint32_t q = tr.vertex[prev_edge(f)];
    if (a != kGhost && b != kGhost) {
        if (q == kGhost) return false;  // a hull edge: nothing beyond it
        return incircle_perturbed(tr.point(a), tr.point(b), tr.point(p), tr.point(q),
                                  tr.scratch) > 0;
    }
    // An edge to the ghost vertex: flip when p strictly sees the neighbouring hull edge.
    if (b == kGhost) return orient2d_robust(tr.point(a), tr.point(q), tr.point(p)) > 0;
    return orient2d_robust(tr.point(q), tr.point(b), tr.point(p)) > 0;
}

// Flips e = a->b of (a, b, p) with its twin in (b, a, q) into (p, a, q) and (q, b, p).
inline void flip_edge(Triangulation& tr, uint32_t e, uint32_t& top) {
    uint32_t f = tr.twin[e];
    uint32_t t = e / 3, u = f / 3;
    uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)], p = tr.vertex[prev_edge(e)];
    uint32_t q = tr.vertex[prev_edge(f)];
    uint32_t xa = tr.twin[next_edge(e)];  // b->p
    uint32_t xb = tr.twin[prev_edge(e)];  // p->a
    uint32_t xc = tr.twin[next_edge(f)];  // a->q
    uint32_t xd = tr.twin[prev_edge(f)];  // q->b
    tr.set_triangle(t, p, a, q);
    tr.set_triangle(u, q, b, p);
    tr.link(3 * t, xb);
    tr.link(3 * t + 1, xc);
    tr.link(3 * u, xd);
    tr.link(3 * u + 1, xa);
    tr.link(3 * t + 2, 3 * u + 2);
    push_edge(tr, top, 3 * t + 1);
    push_edge(tr, top, 3 * u);
}

// Inserts vertex p. Returns the vertex it duplicates, p itself if it was inserted, or
// kNoIndex if an invariant failed.
inline uint32_t insert_vertex(Triangulation& tr, uint32_t p) {
    uint32_t edge = 0;
    Location where = locate(tr, tr.point(p), edge);
    uint32_t top = 0;
    switch (where) {
    case Location::failed: return kNoIndex;
    case Location::on_vertex: return tr.vertex[edge];
    case Location::inside:
    case Location::outside: split_triangle(tr, edge / 3, p, top); break;
    case Location::on_edge: split_edge(tr, edge, p, top); break;
    }
    uint32_t flips = 0;
    while (top > 0) {
        uint32_t e = tr.stack[--top];
        if (!must_flip(tr, e)) continue;
        if (top + 2 > tr.stack_capacity || ++flips > tr.triangle_capacity) return kNoIndex;
        flip_edge(tr, e, top);
    }
    return p;
}

// Receives each point that repeats an earlier vertex: duplicate(point, vertex).
struct DuplicateSink {
    void (*report)(void* context, uint32_t point, uint32_t vertex);
    void* context;
};

// Builds the Delaunay triangulation of xy[0 .. count) (2 doubles per point, already in
// insertion order), reporting duplicates to `sink`. Counts the vertices in *inserted.
inline Status triangulate_points(Triangulation& tr, uint32_t count, DuplicateSink sink,
                                 uint32_t* inserted) {
    *inserted = 0;
    if (count < 3) return Status::too_few_points;
    const double* p0 = tr.point(0);
    uint32_t i1 = 1;
    while (i1 < count && tr.point(i1)[0] == p0[0] && tr.point(i1)[1] == p0[1]) ++i1;
    if (i1 == count) return Status::too_few_points;
    uint32_t i2 = i1 + 1;
    while (i2 < count && orient2d_robust(p0, tr.point(i1), tr.point(i2)) == 0) ++i2;
    if (i2 == count) {
        // All on one line: are there at least three distinct points on it?
        const double* p1 = tr.point(i1);
        for (uint32_t k = i1 + 1; k < count; ++k) {
            const double* q = tr.point(k);
            if ((q[0] != p0[0] || q[1] != p0[1]) && (q[0] != p1[0] || q[1] != p1[1]))
                return Status::collinear;
        }
        return Status::too_few_points;
    }
    if (orient2d_robust(p0, tr.point(i1), tr.point(i2)) > 0)
        start_triangulation(tr, 0, i1, i2);
    else
        start_triangulation(tr, 0, i2, i1);
    uint32_t n_inserted = 3;
    for (uint32_t k = 1; k < count; ++k) {
        if (k == i1 || k == i2) continue;
        uint32_t v = insert_vertex(tr, k);
        if (v == kNoIndex) return Status::internal_error;
        if (v == k)
            ++n_inserted;
        else if (sink.report)
            sink.report(sink.context, k, v);
    }
    *inserted = n_inserted;
    return tr.triangle_count == 2 * n_inserted - 2 ? Status::ok : Status::internal_error;
}

// The memory plan of delaunay_2d, shared by the call and by its size function.
struct Delaunay2dMemory {
    uint32_t* order;      // insertion position -> input index
    double* xy;           // points in insertion order
    Triangulation tr;
};

// Writes duplicates straight into the caller's duplicate_of, in input indices.
struct DuplicateMap {
    const uint32_t* order;
    uint32_t* duplicate_of;
    static void report(void* context, uint32_t point, uint32_t vertex) {
        DuplicateMap* m = static_cast<DuplicateMap*>(context);
        m->duplicate_of[m->order[point]] = m->order[vertex];
    }
};

inline bool plan_delaunay_2d(Delaunay2dMemory& m, size_t count, Arena& arena,
                             const unsigned char* xy, size_t stride,
                             const BoundingBox2d* box) {
    m.order = arena.alloc<uint32_t>(count);
    if (arena.failed) return false;
    if (box) {
        if (!spatial_order(xy, stride, count, *box, m.order, arena)) return false;
    } else {
        // Measuring: the sort's scratch is released before the rest is taken.
        size_t mark = arena.mark();
        arena.alloc<uint32_t>(count);
        arena.alloc<uint32_t>(count);
        arena.alloc<uint32_t>(count);
        arena.rewind(mark);
    }
    m.xy = arena.alloc<double>(2 * count);
    m.tr.xy = m.xy;
    return allocate_triangulation(m.tr, count, arena);
}

}  // namespace detail

size_t delaunay_2d_workspace_size(size_t point_count) {
    if (point_count > detail::kMaxPoints) return 0;
    detail::Arena arena = detail::Arena::measuring();
    detail::Delaunay2dMemory m;
    detail::plan_delaunay_2d(m, point_count, arena, nullptr, 0, nullptr);
    return arena.required_bytes();
}

size_t delaunay_2d_max_triangles(size_t point_count) {
    return point_count >= 3 ? 2 * point_count - 5 : 0;
}

Status delaunay_2d(const double* xy, size_t point_count, size_t stride_bytes,
                   void* workspace, size_t workspace_bytes,
                   uint32_t* triangles, size_t triangle_capacity,
                   Delaunay2dInfo* info, uint32_t* duplicate_of) {
    Delaunay2dInfo local = {0, 0, 0, 0};
    Delaunay2dInfo& out = info ? *info : local;
    out = local;
    if (point_count > detail::kMaxPoints) return Status::too_many_points;
    if (point_count > 0 && (!xy || !workspace)) return Status::invalid_argument;
    if (stride_bytes < 2 * sizeof(double)) return Status::invalid_argument;
    if (triangle_capacity > 0 && !triangles) return Status::invalid_argument;
    if (point_count < 3) return Status::too_few_points;

    const unsigned char* base = reinterpret_cast<const unsigned char*>(xy);
    detail::BoundingBox2d box = {{DBL_MAX, DBL_MAX}, {-DBL_MAX, -DBL_MAX}};
    for (size_t i = 0; i < point_count; ++i) {
        const unsigned char* p = base + i * stride_bytes;
        for (size_t k = 0; k < 2; ++k) {
            double v = detail::read_double(p + k * sizeof(double));
            if (!detail::is_finite(v)) {
                out.first_invalid_point = i;
                return Status::invalid_point;
            }
            if (v < box.min[k]) box.min[k] = v;
            if (v > box.max[k]) box.max[k] = v;
        }
    }

    detail::Arena arena = detail::Arena::over(workspace, workspace_bytes);
    detail::Delaunay2dMemory m;
    if (!detail::plan_delaunay_2d(m, point_count, arena, base, stride_bytes, &box))
        return Status::out_of_memory;
    for (size_t k = 0; k < point_count; ++k) {
        const unsigned char* p = base + m.order[k] * stride_bytes;
        m.xy[2 * k] = detail::read_double(p);
        m.xy[2 * k + 1] = detail::read_double(p + sizeof(double));
    }
    if (duplicate_of) {
        for (size_t i = 0; i < point_count; ++i) duplicate_of[i] = static_cast<uint32_t>(i);
    }
    detail::DuplicateMap map = {m.order, duplicate_of};
    detail::DuplicateSink sink = {duplicate_of ? detail::DuplicateMap::report : nullptr, &map};
    uint32_t inserted = 0;
    Status status = detail::triangulate_points(m.tr, static_cast<uint32_t>(point_count),
                                               sink, &inserted);
    if (status != Status::ok) return status;

    size_t ghosts = 0;
    for (uint32_t t = 0; t < m.tr.triangle_count; ++t) ghosts += m.tr.is_ghost(t);
    size_t real = m.tr.triangle_count - ghosts;
    out.hull_vertex_count = ghosts;
    out.duplicate_count = point_count - inserted;
    out.triangle_count = real;
    if (real > triangle_capacity) return Status::triangle_capacity;

    uint32_t* dst = triangles;
    for (uint32_t t = 0; t < m.tr.triangle_count; ++t) {
        if (m.tr.is_ghost(t)) continue;
        for (uint32_t k = 0; k < 3; ++k) *dst++ = m.order[m.tr.vertex[3 * t + k]];
    }
    return Status::ok;
}

}  // namespace stratmesh

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#elif defined(__clang__)
#pragma STDC FP_CONTRACT DEFAULT
#endif

#endif // STRATMESH_IMPLEMENTATION

/*
------------------------------------------------------------------------------------------
MIT License

Copyright (c) 2026 the stratmesh authors

Permission is hereby granted, free of charge, to any person obtaining a copy of this
software and associated documentation files (the "Software"), to deal in the Software
without restriction, including without limitation the rights to use, copy, modify, merge,
publish, distribute, sublicense, and/or sell copies of the Software, and to permit persons
to whom the Software is furnished to do so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all copies or
substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR IMPLIED,
INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS FOR A PARTICULAR
PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT HOLDERS BE LIABLE
FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR
OTHERWISE, ARISING FROM, OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER
DEALINGS IN THE SOFTWARE.
------------------------------------------------------------------------------------------
*/
