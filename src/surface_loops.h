// >>surface loops ========================================================================
// The boundary loops of a surface, traced from its triangles.

namespace stratmesh {
namespace detail {

// The surface's directed edges between boundary vertices, grouped by first vertex, each
// group sorted; and per vertex the far end of its boundary edge. The output is
// vertex-manifold, so a vertex has at most one boundary edge leaving it.
struct CapGraph {
    size_t* offsets;          // point_count + 1: each vertex's range in `targets`
    uint32_t* targets;        // at most 3 per triangle
    uint32_t* boundary_next;  // per vertex, or kNoIndex

    bool leads_to(uint32_t a, uint32_t b) const {
        size_t lo = offsets[a], hi = offsets[a + 1];
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (targets[mid] < b) lo = mid + 1; else hi = mid;
        }
        return lo < offsets[a + 1] && targets[lo] == b;
    }
    // For boundary vertices a and b only.
    bool has_edge(uint32_t a, uint32_t b) const { return leads_to(a, b) || leads_to(b, a); }
};

// The simplicity sweep keys a loop edge by its smaller x and its index, packed in 64 bits:
// the high 32 bits of an unsigned integer that orders as x does (finite, -0 as +0), then
// the index. Coarser than x, the key still never orders an edge before one whose smaller x
// is below its own, so the sweep meets every pair whose x ranges overlap (and a few more,
// which the exact test settles).
static inline uint32_t sweep_key(double x) {
    x += 0.0;
    uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    bits = (bits >> 63) ? ~bits : bits | (uint64_t{1} << 63);
    return static_cast<uint32_t>(bits >> 32);
}

// The arrays of one loop, sized for all boundary vertices together (every loop fits).
// Positions are the loop's vertices in cap order, 0 .. length - 1.
struct CapLoop {
    uint32_t* ids;            // all loops one after another, each in cap order
    unsigned char* starts;    // per entry of `ids`: kLoopStart, kLoopBroken or 0
    double* xy;               // per position: the projection, mirrored to turn counter-clockwise
    double* height;           // per position, for the flips: the height along the axis (in
                              // the clipping arrays' memory)
    unsigned char* flags;     // per position while clipping, per cap triangle while flipping
    double* scratch;          // for incircle
    uint64_t* sweep;          // per edge (sweep_key); shares its memory with the arrays below
    uint32_t* prev;           // per position: the neighbours in the polygon left to clip
    uint32_t* next;
    uint32_t* reflex;         // positions that were not strictly convex when last checked
    uint32_t* owner;          // per position p: the cap triangle edge (3 t + k) beyond the
                              // polygon edge p -> next[p], or kNoIndex on the loop itself
    uint32_t* corners;        // per cap triangle: 3 positions, counter-clockwise
    uint32_t* across;         // per cap triangle edge k (corner k to k + 1): the edge beyond
    uint32_t* stack;          // cap triangles whose edges are to be checked (before the
                              // cap, the positions on its pockets' hull)
    uint8_t* search;          // per pair of positions i < j: the cap search's choice, k - i
                              // (allocated, and read, only where kCapSearchCorners > 0)
};

const unsigned char kLoopStart = 1, kLoopBroken = 2;

const unsigned char kFinSeen = 1, kFinFlippable = 2, kFinWaived = 4, kFinUsed = 8;

// The allocation sequences of the cap phase: the call runs them with its real sizes,
// reconstruct_workspace_size with the largest possible ones, so the two cannot disagree.
static inline bool allocate_cap_graph(CapGraph& g, size_t point_count, size_t triangle_count,
                               Arena& arena) {
    g.offsets = arena.alloc<size_t>(point_count + 1);
    g.targets = arena.alloc<uint32_t>(3 * triangle_count);
    g.boundary_next = arena.alloc<uint32_t>(point_count);
    return !arena.failed;
}

static inline bool allocate_cap_loop(CapLoop& c, size_t length, Arena& arena) {
    c.ids = arena.alloc<uint32_t>(length);
    c.starts = arena.alloc<unsigned char>(length);
    c.xy = arena.alloc<double>(2 * length);
    c.flags = arena.alloc<unsigned char>(length);
    c.scratch = arena.alloc<double>(kIncircleScratch);
    // The sweep is over before clipping starts: the clipping arrays reuse its memory; and
    // the heights, filled once the clipping is over, reuse the clipping arrays'.
    size_t mark = arena.mark();
    c.sweep = arena.alloc<uint64_t>(length);
    arena.rewind(mark);
    c.height = arena.alloc<double>(length);
    arena.rewind(mark);
    c.prev = arena.alloc<uint32_t>(length);
    c.next = arena.alloc<uint32_t>(length);
    c.reflex = arena.alloc<uint32_t>(length);
    c.owner = arena.alloc<uint32_t>(length);
    c.corners = arena.alloc<uint32_t>(3 * length);
    c.across = arena.alloc<uint32_t>(3 * length);
    c.stack = arena.alloc<uint32_t>(length);
    if (kCapSearchCorners > 0) {
        const size_t searched = length < kCapSearchCorners ? length : kCapSearchCorners;
        c.search = arena.alloc<uint8_t>(searched * (searched - 1) / 2);
    }
    return !arena.failed;
}

// Fills the graph from the triangles; returns the number of boundary vertices. Only edges
// between boundary vertices are kept (the diagonals of a cap join boundary vertices), so
// on a tube the graph is small and built in three streaming passes.
static inline size_t build_cap_graph(const uint32_t* tri, size_t count, size_t point_count,
                              CapGraph& g) {
    // Around an inner vertex the triangles leave towards the same vertices they arrive
    // from; around a boundary vertex (one fan, a chain) the two sets differ by the far
    // ends of its two boundary edges. So the xor of all of them is 0 exactly at inner
    // vertices: the ends differ, since a loop has at least 3 vertices.
    uint32_t* side = g.boundary_next;
    std::memset(side, 0, sizeof(uint32_t) * point_count);
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* c = tri + 3 * t;
        side[c[0]] ^= c[1] ^ c[2];
        side[c[1]] ^= c[2] ^ c[0];
        side[c[2]] ^= c[0] ^ c[1];
    }
    auto kept = [&](uint32_t a, uint32_t b) { return side[a] != 0 && side[b] != 0; };
    std::memset(g.offsets, 0, sizeof(size_t) * (point_count + 1));
    for (size_t k = 0; k < 3 * count; ++k) {
        uint32_t to = tri[k - k % 3 + (k + 1) % 3];
        if (kept(tri[k], to)) ++g.offsets[tri[k] + 1];
    }
    for (size_t v = 0; v < point_count; ++v) g.offsets[v + 1] += g.offsets[v];
    size_t total = g.offsets[point_count];
    // Filled from the end of each range, so offsets[v + 1] ends as the start of v's.
    for (size_t k = 3 * count; k-- > 0;) {
        uint32_t to = tri[k - k % 3 + (k + 1) % 3];
        if (kept(tri[k], to)) g.targets[--g.offsets[tri[k] + 1]] = to;
    }
    for (size_t v = 0; v < point_count; ++v) g.offsets[v] = g.offsets[v + 1];
    g.offsets[point_count] = total;
    size_t boundary = 0;
    for (size_t v = 0; v < point_count; ++v) {
        uint32_t* group = g.targets + g.offsets[v];
        size_t size = g.offsets[v + 1] - g.offsets[v];
        if (size <= 16) {
            for (size_t i = 1; i < size; ++i)
                for (size_t j = i; j > 0 && group[j - 1] > group[j]; --j) {
                    uint32_t s = group[j];
                    group[j] = group[j - 1];
                    group[j - 1] = s;
                }
        } else {
            heap_sort(group, size);
        }
    }
    // Every group is sorted: now the boundary edge leaving each boundary vertex, the one
    // no triangle runs backwards. `side` is read for v just before it is overwritten.
    for (size_t v = 0; v < point_count; ++v) {
        uint32_t a = static_cast<uint32_t>(v);
        uint32_t next = kNoIndex;
        if (side[v] != 0)
            for (size_t k = g.offsets[v]; k < g.offsets[v + 1]; ++k)
                if (!g.leads_to(g.targets[k], a)) next = g.targets[k];
        g.boundary_next[v] = next;
        boundary += next != kNoIndex;
    }
    return boundary;
}

// Chains the boundary edges into loops, stored one after another in cap order (the
// boundary reversed); a chain that does not come back to its start is marked broken.
// Returns the cap triangles all the unbroken loops would need.
static inline size_t trace_boundary_loops(CapGraph& g, size_t point_count, CapLoop& c,
                                   size_t* loop_entries) {
    size_t filled = 0, triangles = 0;
    for (size_t v = 0; v < point_count; ++v) {
        if (g.boundary_next[v] == kNoIndex) continue;
        size_t start = filled;
        uint32_t at = static_cast<uint32_t>(v);
        while (g.boundary_next[at] != kNoIndex) {  // each boundary vertex is taken once
            c.ids[filled] = at;
            c.starts[filled++] = 0;
            uint32_t to = g.boundary_next[at];
            g.boundary_next[at] = kNoIndex;
            at = to;
        }
        size_t length = filled - start;
        bool closed = at == v && length >= 3;
        c.starts[start] = closed ? kLoopStart : kLoopBroken;
        for (size_t i = start, j = filled - 1; i < j; ++i, --j) {
            uint32_t t = c.ids[i];
            c.ids[i] = c.ids[j];
            c.ids[j] = t;
        }
        if (closed) triangles += length - 2;
    }
    *loop_entries = filled;
    return triangles;
}

}  // namespace detail
}  // namespace stratmesh
