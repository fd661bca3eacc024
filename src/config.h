// >>config ==================================================================================
// Build switches: what STRATMESH_SMALL_CODE leaves out; the floating-point environment.

#include <cfloat>
#include <climits>
#include <cmath>
#include <cstring>

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

#if defined(STRATMESH_SMALL_CODE) && !defined(STRATMESH_NO_PARALLEL_LAYERS)
#define STRATMESH_NO_PARALLEL_LAYERS
#endif
#if defined(STRATMESH_NO_PARALLEL_LAYERS)
const bool kParallelLayers = false;
#else
const bool kParallelLayers = true;  // lets the compiler drop what only jobs' results reach
#endif
#if defined(STRATMESH_SMALL_CODE)
const bool kNetShortcut = false;
const bool kStagePoints = false;
const bool kFastExactStages = false;
const bool kLiftedCaps = false;
const bool kCrescentLayers = false;
const bool kClosedEnds = false;
const uint32_t kCapEarStarts = 1;
const uint32_t kCapSearchCorners = 0;
const bool kCapFinFlips = false;
const bool kDropOutliers = false;
const bool kSurfaceFlips = false;
const bool kFindParts = false;
const bool kAxisTrials = false;
const bool kDegenerateCheck = false;
const bool kLocalUnpeel = false;
const bool kPeelFoldedEnds = false;
const bool kFoldMerge = false;
const uint32_t kFoldMergeReach = 0;
const bool kFastLoops = false;
const bool kMeasureFit = false;
#else
const bool kNetShortcut = true;  // a chunk whose loop fans are whole skips the net
const bool kStagePoints = true;  // reconstruct() keeps the grouped points in spare workspace
// The predicates settle near-ties in integers, then from exact differences, before the
// general exact stage.
const bool kFastExactStages = true;
// Caps are lowered (bottom) and raised (top) along the axis before the Delaunay criterion
// settles their diagonals (see >>caps); without it, Delaunay caps only.
const bool kLiftedCaps = true;
// A crescent layer (the slanted end of a tube) joins its neighbour (see kRingGap).
const bool kCrescentLayers = true;
// A closed end of the surface is unrolled around a pole (see "closed ends" in >>unroll).
const bool kClosedEnds = true;
// A cap whose ear clipping gets stuck is clipped again from other corners (see >>caps).
const uint32_t kCapEarStarts = 8;
// A loop of at most this many corners that no clipping closes is searched exhaustively for
// a cap (see >>caps; its table takes a byte per pair of corners: 32 KiB).
const uint32_t kCapSearchCorners = 256;
// A loop that no cap closes as the wall stands may have the wall's edges under its fins
// flipped, where its cap needs their chords (see >>caps).
const bool kCapFinFlips = true;
// The drop_outliers flag (see "outliers" in >>layers); without it, the flag is refused.
const bool kDropOutliers = true;
// Layers are flipped on the surface (see "flips on the surface" in >>layer triangulation).
const bool kSurfaceFlips = true;
const bool kFindParts = true;
const bool kAxisTrials = true;
const bool kDegenerateCheck = true;
// A band that folds between peeled loops gets back only the peeled triangles around its
// folds (see add_group); without it, all of them.
const bool kLocalUnpeel = true;
// The surface's end loops are peeled in layers that fold too (see "peeling" in >>layer
// triangulation).
const bool kPeelFoldedEnds = true;
// A layer that folds is tried again with the next one joined (see "folding layers" at
// add_group).
const bool kFoldMerge = true;
// The most planned layers joined to a folding one (see kFoldMerge).
const uint32_t kFoldMergeReach = 2;
// Per-point loops in forms that cost code for speed, the same bits either way: the equal-
// layer guess in layer_of, pseudo_angle without branches, floor by truncation in
// exp_portable, the height range from choose_frame's extremes, count_folds' prefetching.
const bool kFastLoops = true;
// reconstruct() measures the fit of its output to the cloud (Diagnostics; see >>fit).
const bool kMeasureFit = true;
#endif
static const size_t kMaxPoints = 0xFFFFFFFEu;

// Kept out of line: STRATMESH_NOINLINE always, the predicates' exact stages, so that the
// filtered call, which settles nearly all, keeps its registers (inlined, the exact stage
// made it spill: 125 instructions a filtered incircle instead of about 70);
// STRATMESH_FAST_NOINLINE in the full build, for the same reason (the small build inlines
// it into its one caller, where a call costs more code); STRATMESH_SMALL_NOINLINE in the
// small build: inlined at each caller, these few functions grow the Cortex-M7 code past
// its 32 KiB (examples/firmware/build.sh).
#if defined(__GNUC__) || defined(__clang__)
#define STRATMESH_NOINLINE __attribute__((noinline))
#elif defined(_MSC_VER)
#define STRATMESH_NOINLINE __declspec(noinline)
#else
#define STRATMESH_NOINLINE
#endif
#if defined(STRATMESH_SMALL_CODE)
#define STRATMESH_SMALL_NOINLINE STRATMESH_NOINLINE
#if defined(__GNUC__) || defined(__clang__)
#define STRATMESH_FAST_NOINLINE __attribute__((always_inline))
#else
#define STRATMESH_FAST_NOINLINE
#endif
#else
#define STRATMESH_SMALL_NOINLINE
#define STRATMESH_FAST_NOINLINE STRATMESH_NOINLINE
#endif

#if defined(__GNUC__) || defined(__clang__)
static inline double abs_value(double x) { return __builtin_fabs(x); }
#else
static inline double abs_value(double x) { return x < 0 ? -x : x; }
#endif
static inline bool is_finite(double x) { return x - x == 0; }

// Sorts in place so that no element comes before one it is `before`: heapsort, O(n log n)
// on any input (a million cuts, a huge fan) with no recursion and no memory.
template <class T, class Before> void sift_down(T* v, size_t root, size_t count, Before before) {
    for (;;) {
        size_t child = 2 * root + 1;
        if (child >= count) return;
        if (child + 1 < count && before(v[child], v[child + 1])) ++child;
        if (!before(v[root], v[child])) return;
        T t = v[root];
        v[root] = v[child];
        v[child] = t;
        root = child;
    }
}

// A union-find's root of i, halving the path on the way (no recursion); parent[i] == i at
// a root.
static inline uint32_t find_root(uint32_t* parent, uint32_t i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

template <class T, class Before> void heap_sort(T* v, size_t count, Before before) {
    for (size_t i = count / 2; i-- > 0;) sift_down(v, i, count, before);
    for (size_t end = count; end-- > 1;) {
        T t = v[0];
        v[0] = v[end];
        v[end] = t;
        sift_down(v, 0, end, before);
    }
}

// Sorts ascending.
template <class T> void heap_sort(T* v, size_t count) {
    heap_sort(v, count, [](const T& a, const T& b) { return a < b; });
}

static inline double read_double(const unsigned char* p) {
    double v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

}  // namespace detail
}  // namespace stratmesh
