// >>spatial sort =========================================================================
// The insertion order of the Delaunay triangulation.
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

namespace stratmesh {
namespace detail {

const uint32_t kHilbertBits = 13;  // per axis; 5 bits of the 32-bit key are left for rounds

// The curve as a state machine. At each level the remaining sub-square is the unit
// square under one of four transforms (complemented or not, x and y swapped or not; the
// two commute): the quadrant's bits, seen through the transform, give the curve digit
// (3 rx) ^ ry, and a quadrant with ry = 0 swaps the transform (and complements it if
// rx = 1). The table runs two levels a step: entry (state << 4 | x bits << 2 | y bits)
// holds the two digits in its low 4 bits and the next state above them. Built at compile
// time from that rule, so it is a constant, not state.
struct HilbertTable {
    unsigned char entry[64];
    constexpr HilbertTable() : entry() {
        for (uint32_t i = 0; i < 64; ++i) {
            uint32_t complement = (i >> 4) & 1u, swapped = i >> 5, digits = 0;
            for (uint32_t level = 2; level-- > 0;) {
                uint32_t bx = (i >> (2 + level)) & 1u, by = (i >> level) & 1u;
                uint32_t rx = (swapped ? by : bx) ^ complement;
                uint32_t ry = (swapped ? bx : by) ^ complement;
                digits = (digits << 2) | ((3u * rx) ^ ry);
                complement ^= rx & (ry ^ 1u);
                swapped ^= ry ^ 1u;
            }
            entry[i] = static_cast<unsigned char>(digits | (complement << 4) | (swapped << 5));
        }
    }
};

constexpr HilbertTable kHilbertTable{};

static inline uint32_t hilbert_index(uint32_t x, uint32_t y) {
    // kHilbertBits is odd: a zero level is put on top, entered with x and y swapped so
    // that it leaves the identity transform (its digit is 0), and the 14 levels run in
    // seven steps.
    static_assert(kHilbertBits % 2 == 1, "the levels are paired under one zero level");
    uint32_t state = 2, d = 0;
    for (uint32_t shift = kHilbertBits + 1; shift >= 2;) {
        shift -= 2;
        uint32_t bx = (x >> shift) & 3u, by = (y >> shift) & 3u;
        uint32_t e = kHilbertTable.entry[(state << 4) | (bx << 2) | by];
        d = (d << 4) | (e & 15u);
        state = e >> 4;
    }
    return d;
}

static inline uint32_t quantize(double v, double lo, double scale) {
    const double top = static_cast<double>((1u << kHilbertBits) - 1);
    double q = (v - lo) * scale;
    if (!(q > 0)) return 0;
    if (q >= top) return (1u << kHilbertBits) - 1;
    return static_cast<uint32_t>(q);
}

static inline uint32_t mix32(uint32_t h) {
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return h;
}

// A hash of the point's coordinates (-0 and +0 hash alike).
static inline uint32_t coordinate_hash(double x, double y) {
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
static inline void radix_sort(uint32_t* keys, uint32_t* order, uint32_t* keys_tmp,
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

// The number of trailing zero bits of h, at most `limit` (< 32). The loop over the bits,
// whose length is random, mispredicts its exit on about every other point; GCC and Clang
// count them in an instruction or two (2.5% of delaunay_2d's time on 1e6 points).
static inline uint32_t trailing_zeros(uint32_t h, uint32_t limit) {
#if defined(__GNUC__) || defined(__clang__)
    const uint32_t zeros = h ? static_cast<uint32_t>(__builtin_ctz(h)) : 32;
    return zeros < limit ? zeros : limit;
#else
    uint32_t zeros = 0;
    while (zeros < limit && (h & (1u << zeros)) == 0) ++zeros;
    return zeros;
#endif
}

// Fills order[0..count) with the indices of the points (x, y doubles, stride bytes apart)
// in BRIO order over `box`; scratch from the arena.
static inline bool spatial_order(const unsigned char* xy, size_t stride, size_t count,
                          const BoundingBox2d& box, uint32_t* order, Arena& arena) {
    size_t mark = arena.mark();
    uint32_t* keys = arena.alloc<uint32_t>(count);
    uint32_t* keys_tmp = arena.alloc<uint32_t>(count);
    uint32_t* order_tmp = arena.alloc<uint32_t>(count);
    if (arena.failed) return false;
    // One scale for both axes, the longer side's: square cells keep the curve local in the
    // plane's own metric, and a long strip is ordered along its length. (Separate scales
    // made a layer's unrolled strip, six times longer than high, a grid of cells six times
    // wider than high: a walk crossed 5.8 triangles on the bumpy tube instead of 4.1.)
    double width = box.max[0] - box.min[0], height = box.max[1] - box.min[1];
    double range = width > height ? width : height;
    double scale = (range > 0 && is_finite(range)) ? ((1u << kHilbertBits) - 1) / range : 0.0;
    if (!is_finite(scale)) scale = 0.0;
    // Rounds: the last holds about half the points, the first about 64.
    uint32_t rounds = 0;
    while (rounds < 24 && (count >> (rounds + 7)) > 0) ++rounds;
    const uint32_t curve_mask = (1u << (2 * kHilbertBits)) - 1;
    for (size_t i = 0; i < count; ++i) {
        const unsigned char* p = xy + i * stride;
        double x = read_double(p), y = read_double(p + sizeof(double));
        uint32_t h = coordinate_hash(x, y);
        const uint32_t zeros = trailing_zeros(h, rounds);
        uint32_t round = rounds - zeros;
        uint32_t curve = hilbert_index(quantize(x, box.min[0], scale),
                                       quantize(y, box.min[1], scale));
        // Odd rounds run the curve backwards, so each round starts where the last ended.
        if (round % 2 == 1) curve = curve_mask - curve;
        keys[i] = (round << (2 * kHilbertBits)) | curve;
        order[i] = static_cast<uint32_t>(i);
    }
    radix_sort(keys, order, keys_tmp, order_tmp, count);
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh
