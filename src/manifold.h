// >>manifold =============================================================================
// The safety net that keeps the surface a manifold.
//
// The paper's step 5, as a safety net: by construction the layers and bands already form a
// manifold, so on sound input this removes nothing. Around every vertex v, each triangle
// (v, b, c) leaves along v->b and arrives along c->v. The surface is an oriented manifold
// at v when no directed edge repeats (at most two triangles per edge, consistently
// oriented) and the triangles form one fan: one chain or one cycle of triangles, each
// arriving where the next leaves. Triangles on a repeated directed edge go (the later
// one), then every fan but the largest; repeated until nothing changes, since a removal
// can split a neighbour's fan.
//
// It runs on each chunk of the surface (a layer's triangles and the band joining it to the
// layer below) as soon as the chunk is built, so that chunks are final when they leave
// (the stream hands them out at once) and the net's memory follows the largest layer, not
// the cloud. Chunks meet only along the layers' top loops, where each side gives a loop
// vertex one chain of triangles ending on the loop's edges by construction; where the net
// removed triangles, seal_seam makes sure the two sides still share an edge at every loop
// vertex (else the upper side's triangles there go), so they never meet in a vertex alone.
//
// Within a chunk, only the vertices the band joins can break the manifold: a layer's
// triangles are its planar triangulation (exact predicates) without the centre's star and
// the outside of the hull. Around a vertex off the centre's link (the bottom loop) that
// leaves its star minus the two ghost triangles at most: one fan. Off the hull, a
// bottom-loop vertex loses the two triangles on its edge to the centre: one fan too. A
// vertex on both loops can be left with two, and every band vertex is on a loop. So only
// the fans of the loop vertices are checked (fans_are_one_piece), and the net runs over
// the chunk only when one of them fails; on sound input it never does, and the net's
// relabelling and sorting, most of its cost, is skipped. A layer emits its triangles at
// the bottom loop last, so those fans are read from one stretch of the chunk, its border
// and band (chunk_is_sound); the rest of the chunk is only renamed.

namespace stratmesh {
namespace detail {

// In-place sort of packed (key, value) pairs: insertion sort for the small fans of almost
// every vertex, heap sort (O(n log n), no recursion) for large ones.
static inline void sort_pairs(uint64_t* items, size_t count) {
    if (count <= 16) {
        for (size_t i = 1; i < count; ++i) {
            uint64_t item = items[i];
            size_t j = i;
            for (; j > 0 && items[j - 1] > item; --j) items[j] = items[j - 1];
            items[j] = item;
        }
        return;
    }
    heap_sort(items, count);
}

struct Fan {
    uint64_t* key;       // (leaving neighbour << 32 | entry), sorted by leaving neighbour
    uint32_t* arrive;    // per entry: the arriving neighbour
    uint32_t* triangle;  // per entry: its triangle
    uint32_t* label;     // per sorted position: fan piece
    uint32_t* sizes;     // entries per piece
    size_t size;

    uint32_t entry(size_t position) const { return static_cast<uint32_t>(key[position]); }
    uint32_t leaving(size_t position) const { return static_cast<uint32_t>(key[position] >> 32); }
};

// The sorted position of the entry leaving towards `neighbour`, or SIZE_MAX.
static inline size_t position_leaving_to(const Fan& fan, uint32_t neighbour) {
    size_t lo = 0, hi = fan.size;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (fan.leaving(mid) < neighbour) lo = mid + 1; else hi = mid;
    }
    return lo < fan.size && fan.leaving(lo) == neighbour ? lo : SIZE_MAX;
}

// Collects v's live triangles, sorted by leaving edge; marks dead those repeating one.
static inline size_t collect_fan(const uint32_t* tri, const uint32_t* incident, size_t begin,
                          size_t end, uint32_t v, unsigned char* dead, Fan& fan) {
    fan.size = 0;
    for (size_t k = begin; k < end; ++k) {
        uint32_t t = incident[k];
        if (dead[t]) continue;
        const uint32_t* c = tri + 3 * static_cast<size_t>(t);
        uint32_t corner = c[0] == v ? 0u : c[1] == v ? 1u : 2u;
        uint32_t e = static_cast<uint32_t>(fan.size++);
        fan.arrive[e] = c[(corner + 2) % 3];
        fan.triangle[e] = t;
        fan.key[e] = (static_cast<uint64_t>(c[(corner + 1) % 3]) << 32) | e;
    }
    sort_pairs(fan.key, fan.size);
    size_t kept = 0, removed = 0;
    for (size_t k = 0; k < fan.size; ++k) {
        if (kept > 0 && fan.leaving(kept - 1) == fan.leaving(k)) {
            dead[fan.triangle[fan.entry(k)]] = 1;
            ++removed;
            continue;
        }
        fan.key[kept++] = fan.key[k];
    }
    fan.size = kept;
    return removed;
}

// Labels the connected pieces of the fan (each triangle linked to the one leaving where
// it arrives) and returns how many there are.
static inline uint32_t label_fan(Fan& fan) {
    const uint32_t unlabeled = kNoIndex;
    for (size_t k = 0; k < fan.size; ++k) fan.label[k] = unlabeled;
    uint32_t pieces = 0;
    for (size_t k = 0; k < fan.size; ++k) {
        if (fan.label[k] != unlabeled) continue;
        size_t at = k, walked = 0;
        while (at != SIZE_MAX && fan.label[at] == unlabeled) {
            fan.label[at] = pieces;
            ++walked;
            at = position_leaving_to(fan, fan.arrive[fan.entry(at)]);
        }
        uint32_t joined = (at != SIZE_MAX) ? fan.label[at] : pieces;
        if (joined != pieces) {
            // This walk ran into an earlier piece: it belongs to it.
            for (size_t w = k; w != at; w = position_leaving_to(fan, fan.arrive[fan.entry(w)]))
                fan.label[w] = joined;
            fan.sizes[joined] += static_cast<uint32_t>(walked);
        } else {
            fan.sizes[pieces++] = static_cast<uint32_t>(walked);
        }
    }
    return pieces;
}

// Makes v's fan a single oriented piece; returns the number of triangles marked dead.
static inline size_t repair_fan(const uint32_t* tri, const uint32_t* incident, size_t begin,
                         size_t end, uint32_t v, unsigned char* dead, Fan& fan) {
    size_t removed = collect_fan(tri, incident, begin, end, v, dead, fan);
    uint32_t pieces = label_fan(fan);
    if (pieces <= 1) return removed;
    uint32_t best = 0;
    for (uint32_t c = 1; c < pieces; ++c)
        if (fan.sizes[c] > fan.sizes[best]) best = c;
    for (size_t k = 0; k < fan.size; ++k) {
        if (fan.label[k] == best) continue;
        dead[fan.triangle[fan.entry(k)]] = 1;
        ++removed;
    }
    return removed;
}

// Whether a vertex's corners, packed (leaving << 32 | arriving) neighbours, form one chain
// or one cycle with no leaving edge repeated: then the safety net has nothing to do there.
// False sends the vertex to repair_fan, which then decides as if this had not run. The
// corners sit together in memory, where the triangles they come from are scattered, and are
// sorted in place by leaving neighbour; each corner's successor (the corner leaving where it
// arrives) is then found by binary search and kept in place of its arriving neighbour. One
// piece: every corner has one and a walk from any corner comes back after all of them (a
// cycle), or all but one have one and a walk from the corner nobody arrives at takes in all
// of them (a chain).
static inline bool fan_is_one_piece(uint64_t* corners, size_t size) {
    if (size == 0) return true;
    sort_pairs(corners, size);
    auto leaving = [&](size_t i) { return static_cast<uint32_t>(corners[i] >> 32); };
    // The chain's first corner leaves along the one leaving neighbour no corner arrives at:
    // the sum of the leaving neighbours less the arriving ones that some corner leaves along.
    // Each corner's arriving neighbour is replaced by its successor's position (size: none).
    uint64_t first_leaving = 0;
    size_t linked = 0;
    for (size_t i = 0; i < size; ++i) {
        if (i > 0 && leaving(i) == leaving(i - 1)) return false;
        const uint32_t arrive = static_cast<uint32_t>(corners[i]);
        size_t lo = 0, hi = size;
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (leaving(mid) < arrive) lo = mid + 1;
            else hi = mid;
        }
        const size_t next = lo < size && leaving(lo) == arrive ? lo : size;
        first_leaving += leaving(i);
        if (next < size) {
            ++linked;
            first_leaving -= arrive;
        }
        corners[i] = (corners[i] >> 32 << 32) | next;
    }
    auto successor = [&](size_t i) { return static_cast<size_t>(corners[i] & 0xFFFFFFFFu); };
    size_t start = 0;
    if (linked + 1 == size) {
        while (start < size && leaving(start) != first_leaving) ++start;
        if (start == size) return false;
    } else if (linked != size) {
        return false;
    }
    size_t walked = 1;
    for (size_t at = successor(start); at != size && at != start && walked <= size;
         at = successor(at))
        ++walked;
    return walked == size;
}

// Whether every vertex v with checked[v] != 0 passes fan_is_one_piece in tri[0 .. 3 count)
// (indices below point_count): then the safety net would remove nothing at those vertices.
// Lets finish_chunk skip the net where nothing can fail; the arena's failure answers false.
static inline bool fans_are_one_piece(const uint32_t* tri, size_t count, size_t point_count,
                               const unsigned char* checked, Arena& arena) {
    size_t mark = arena.mark();
    uint32_t* offsets = arena.alloc<uint32_t>(point_count + 1);
    if (arena.failed) return false;
    std::memset(offsets, 0, sizeof(uint32_t) * (point_count + 1));
    for (size_t k = 0; k < 3 * count; ++k)
        if (checked[tri[k]]) ++offsets[tri[k] + 1];
    for (size_t v = 0; v < point_count; ++v) offsets[v + 1] += offsets[v];
    uint64_t* corners = arena.alloc<uint64_t>(offsets[point_count]);
    if (arena.failed) return false;
    for (size_t k = 0; k < 3 * count; ++k) {
        if (!checked[tri[k]]) continue;
        const uint32_t* c = tri + (k - k % 3);
        corners[offsets[tri[k]]++] = (static_cast<uint64_t>(c[(k + 1) % 3]) << 32) | c[(k + 2) % 3];
    }
    // Each cursor now sits at the next vertex's start.
    bool one_piece = true;
    for (size_t v = 0, begin = 0; v < point_count && one_piece; begin = offsets[v++])
        one_piece = fan_is_one_piece(corners + begin, offsets[v] - begin);
    arena.rewind(mark);
    return one_piece;
}

// Removes triangles until the mesh tri[0 .. 3 count), whose indices are below point_count,
// is edge- and vertex-manifold and consistently oriented. Compacts the survivors in place
// (keeping their order); returns the number removed, or SIZE_MAX if the arena is too small.
//
// The work runs on relabelled triangles: vertices numbered in the order the triangles
// first name them (input indices are restored at the end). The triangles come out of the
// layers in spatial order, so relabelled fans and their triangles sit close together in
// memory whatever order the input points had; only the relabelling itself reads the input
// indices at random.
static inline size_t enforce_manifold(uint32_t* tri, size_t& count, size_t point_count, Arena& arena) {
    size_t mark = arena.mark();
    uint32_t* original = arena.alloc<uint32_t>(point_count);  // label -> input index
    unsigned char* dead = arena.alloc<unsigned char>(count);
    size_t relabel_mark = arena.mark();
    uint32_t* label = arena.alloc<uint32_t>(point_count);     // input index -> label
    if (arena.failed) return SIZE_MAX;
    for (size_t v = 0; v < point_count; ++v) label[v] = kNoIndex;
    std::memset(dead, 0, count);
    uint32_t labels = 0;
    for (size_t k = 0; k < 3 * count; ++k) {
        uint32_t& l = label[tri[k]];
        if (l == kNoIndex) {
            original[labels] = tri[k];
            l = labels++;
        }
        tri[k] = l;
    }
    arena.rewind(relabel_mark);
    uint32_t* local = tri;
    auto give_up = [&]() {  // out of workspace: hand back the input indices untouched
        for (size_t k = 0; k < 3 * count; ++k) tri[k] = original[tri[k]];
        return SIZE_MAX;
    };
    uint32_t* offsets = arena.alloc<uint32_t>(static_cast<size_t>(labels) + 1);
    uint32_t* incident = arena.alloc<uint32_t>(3 * count);
    uint64_t* corners = arena.alloc<uint64_t>(3 * count);  // per incidence: (leaving, arriving)
    if (arena.failed) return give_up();
    std::memset(offsets, 0, sizeof(uint32_t) * (static_cast<size_t>(labels) + 1));
    for (size_t k = 0; k < 3 * count; ++k) ++offsets[local[k] + 1];
    size_t max_degree = 0;
    for (uint32_t v = 0; v < labels; ++v) {
        if (offsets[v + 1] > max_degree) max_degree = offsets[v + 1];
        offsets[v + 1] += offsets[v];
    }
    // Incidences in triangle order: a forward pass that bumps each vertex's write cursor,
    // kept in `incident`'s own slots by filling from the end of each range.
    for (size_t k = 3 * count; k-- > 0;) {
        const uint32_t* c = local + (k - k % 3);
        const size_t at = --offsets[local[k] + 1];
        incident[at] = static_cast<uint32_t>(k / 3);
        corners[at] = (static_cast<uint64_t>(c[(k + 1) % 3]) << 32) | c[(k + 2) % 3];
    }
    // Now offsets[v + 1] is the start of v's range; shift back to the usual layout.
    for (uint32_t v = 0; v < labels; ++v) offsets[v] = offsets[v + 1];
    offsets[labels] = static_cast<uint32_t>(3 * count);
    Fan fan;
    fan.key = arena.alloc<uint64_t>(max_degree);
    fan.arrive = arena.alloc<uint32_t>(max_degree);
    fan.triangle = arena.alloc<uint32_t>(max_degree);
    fan.label = arena.alloc<uint32_t>(max_degree);
    fan.sizes = arena.alloc<uint32_t>(max_degree);
    if (arena.failed) return give_up();
    size_t removed = 0;
    for (size_t pass = 0; pass <= count; ++pass) {
        size_t before = removed;
        for (uint32_t v = 0; v < labels; ++v)
            if (removed > 0 || !fan_is_one_piece(corners + offsets[v], offsets[v + 1] - offsets[v]))
                removed += repair_fan(local, incident, offsets[v], offsets[v + 1], v, dead, fan);
        if (removed == before) break;
    }
    size_t alive = 0;
    for (size_t t = 0; t < count; ++t) {
        if (dead[t]) continue;
        for (size_t k = 0; k < 3; ++k) tri[3 * alive + k] = original[tri[3 * t + k]];
        ++alive;
    }
    count = alive;
    arena.rewind(mark);
    return removed;
}

}  // namespace detail
}  // namespace stratmesh
