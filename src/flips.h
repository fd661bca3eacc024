// >>flips ================================================================================
// Flips on the surface: within a layer, and across the seam between layers.

namespace stratmesh {
namespace detail {

// ---- flips on the surface ----
//
// With the surface_flips flag. The unrolling squeezes whatever lies almost across the axis:
// the underside of an ear, the crease where it meets the head, a chin. There the annulus's
// Delaunay triangles, good in the plane, are long and thin on the surface and run across
// the crease: on a synthetic bust with ears (bench/horned_bust.py --no-horns) the ears had
// 14% of the area and 57% of the distance to the true surface, 2.7 times the distance of
// CGAL's advancing front there, as close as it elsewhere. So once a layer is triangulated
// and its loops are settled, its surface edges are flipped on the surface itself, by two
// rules. An edge ab between triangles abp and baq is flipped to pq
//  - by the empty-circle rule, where the angles at p and q, measured in 3D, sum to more
//    than 180 degrees (in a plane: q inside the circle through a, b, p), unless pq bends
//    the surface more than kBendVeto times what ab did;
//  - for the bend alone, where pq bends it kBendGain times less than ab.
// The bend of an edge ab is |(b - a) . (n_b - n_a)| with n the vertex normals (the mean of
// the unit normals of the triangles around): 8 times the sag at the middle of a curve
// through a and b normal to n_a and n_b. An edge along the direction in which the surface
// curves least bends least, and triangles along it lie nearest the surface: on a cone,
// along its generatrices. The empty-circle rule alone, which wants fat triangles, turned
// the annulus's triangles across that direction on smooth surfaces of revolution (one
// layer, mean distance to the analytic surface: vase 13% and cone 27% farther than
// without flips); with both rules the vase is 3% and the cone 47% closer, the bumpy tube
// 44% (10% with the empty-circle rule alone), the bust with ears 25% (18%). Since
// kBendVeto <= kBendGain, the two rules never flip one quad back and forth with the same
// normals; the normals are estimated anew at the start of each of the first
// kNormalSweeps sweeps and then kept, so that the flips settle (the clouds measured: at
// most 2 flips in the last sweep).
// A flip is kept only if neither new triangle is degenerate, the new triangles' widest
// angle is at most 150 degrees (kWidestAngle) or less wide than the old ones' (the bend
// alone makes needles: without that limit 17% of the bust's triangles had an angle under
// 5 degrees, with it 2%, as without flips), pq is not already an edge nor a chord of a
// loop (where add_caps puts its cap), and neither new triangle meets another surface
// triangle of the layer. A new triangle may face the axis: where the surface does (a
// crown, the underside of a chin) the annulus squeezes it, and forbidding that kept a
// third of the flips that mend its slivers (5th percentile of the smallest angle, with
// and without: femur 6.2 and 8.0 degrees, mannequin head 4.7 and 5.8, lion head 3.5 and
// 5.4). The layer's fold count stays the unrolling's. Near a fold (a corner of a triangle
// facing the axis, from the unrolling or a flip), where the lifted annulus may lie over
// itself, the new triangles are tested against every surface triangle of the layer that
// could reach them (see "the crossing test"); elsewhere the layer is its annulus lifted
// and a flip covers about the place the old pair covered: a gentle one (both new normals
// within 26 degrees of the old pair's, kGentleFlip) is not tested, another against the
// triangles around the quad's corners. Loop edges are never flipped, so the loops, the
// bands and the peeled triangles that add_group may put back are the same as without the
// flips (the band and the triangles at its loops are flipped later, see "flips across the
// seam"). The first sweep visits every edge; later sweeps only the triangles the sweep
// before changed. The sweeps are bounded (kSurfaceFlipSweeps).
const uint32_t kSurfaceFlipSweeps = 8;

const uint32_t kNormalSweeps = 4;  // the sweeps that start with the normals estimated anew

const uint32_t kFanLimit = 64;  // a vertex with more neighbours keeps its edges

const double kFlipMargin = 1e-9;

const double kGentleFlip = 0.9;  // cosine of the largest angle between a new and the mean normal

const double kShrink = 1e-6;

const double kGrow = 1e-9;

const double kBendVeto = 3;  // a flip by the empty-circle rule may bend at most 3 times more

const double kBendGain = 3;  // a flip for the bend alone must bend 3 times less

const double kWidestAngle = -0.86602540378443865;  // cosine of 150 degrees

static inline Vec3 vec_of(const Local& p) { return Vec3{p.x, p.y, p.h}; }

struct Box3 {
    Vec3 low, high;
    bool meets(const Box3& o) const {
        return low.x <= o.high.x && o.low.x <= high.x && low.y <= o.high.y &&
               o.low.y <= high.y && low.z <= o.high.z && o.low.z <= high.z;
    }
};

static inline Box3 box_of(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    Box3 box = {a, a};
    const Vec3 rest[3] = {b, c, d};
    for (const Vec3& p : rest) {
        box.low = Vec3{p.x < box.low.x ? p.x : box.low.x, p.y < box.low.y ? p.y : box.low.y,
                       p.z < box.low.z ? p.z : box.low.z};
        box.high = Vec3{p.x > box.high.x ? p.x : box.high.x, p.y > box.high.y ? p.y : box.high.y,
                        p.z > box.high.z ? p.z : box.high.z};
    }
    return box;
}

// Whether the angles at p and q facing the segment ab sum to more than 180 degrees: then
// sin(angle_p + angle_q), a sum of sine-cosine products, is negative. Two acute angles
// (most edges) are settled by two dot products.
static inline bool flip_helps(Vec3 a, Vec3 b, Vec3 p, Vec3 q) {
    const Vec3 pa = a - p, pb = b - p, qa = a - q, qb = b - q;
    const double cos_p = dot(pa, pb), cos_q = dot(qa, qb);
    if (cos_p >= 0 && cos_q >= 0) return false;
    const Vec3 np = cross(pa, pb), nq = cross(qa, qb);
    const double sin_p = std::sqrt(dot(np, np)), sin_q = std::sqrt(dot(nq, nq));
    const double lengths = std::sqrt(dot(pa, pa) * dot(pb, pb) * dot(qa, qa) * dot(qb, qb));
    return sin_p * cos_q + cos_p * sin_q < -kFlipMargin * lengths;
}

// Whether triangles u and v, each scaled by `scale` about its centroid, overlap along every
// axis that could separate them: their normals, the cross products of their edges, and
// each normal crossed with the triangle's own edges (for coplanar triangles). Triangles
// with a shared corner are shrunk (kShrink) so that it does not count; others are grown
// (kGrow), so that a touch counts too.
static inline bool triangles_meet(const Vec3* u, const Vec3* v, double scale) {
    Vec3 s[3], t[3];
    const Vec3 cu = scaled(Vec3{u[0].x + u[1].x + u[2].x, u[0].y + u[1].y + u[2].y,
                                u[0].z + u[1].z + u[2].z}, 1.0 / 3);
    const Vec3 cv = scaled(Vec3{v[0].x + v[1].x + v[2].x, v[0].y + v[1].y + v[2].y,
                                v[0].z + v[1].z + v[2].z}, 1.0 / 3);
    for (int k = 0; k < 3; ++k) {
        const Vec3 du = u[k] - cu, dv = v[k] - cv;
        s[k] = Vec3{cu.x + du.x * scale, cu.y + du.y * scale, cu.z + du.z * scale};
        t[k] = Vec3{cv.x + dv.x * scale, cv.y + dv.y * scale, cv.z + dv.z * scale};
    }
    Vec3 es[3], et[3];
    for (int k = 0; k < 3; ++k) {
        es[k] = s[(k + 1) % 3] - s[k];
        et[k] = t[(k + 1) % 3] - t[k];
    }
    const Vec3 ns = cross(es[0], es[1]), nt = cross(et[0], et[1]);
    auto separates = [&s, &t](Vec3 axis) {
        double s_lo = dot(s[0], axis), s_hi = s_lo, t_lo = dot(t[0], axis), t_hi = t_lo;
        for (int k = 1; k < 3; ++k) {
            const double ds = dot(s[k], axis), dt = dot(t[k], axis);
            s_lo = ds < s_lo ? ds : s_lo;
            s_hi = ds > s_hi ? ds : s_hi;
            t_lo = dt < t_lo ? dt : t_lo;
            t_hi = dt > t_hi ? dt : t_hi;
        }
        return s_hi < t_lo || t_hi < s_lo;
    };
    if (separates(ns) || separates(nt)) return false;
    for (int i = 0; i < 3; ++i) {
        if (separates(cross(ns, es[i])) || separates(cross(nt, et[i]))) return false;
        for (int j = 0; j < 3; ++j)
            if (separates(cross(es[i], et[j]))) return false;
    }
    return true;
}

// Calls visit(g) for each half-edge g leaving the start of half-edge `from`, counter-clockwise
// around it, until visit returns false. False if a visit did, or the vertex has more than
// kFanLimit neighbours.
template <class Visit>
static inline bool around_vertex(const Triangulation& tr, uint32_t from, Visit visit) {
    uint32_t e = from;
    for (uint32_t steps = 0; steps < kFanLimit; ++steps) {
        if (!visit(e)) return false;
        e = tr.twin[prev_edge(e)];
        if (e == from) return true;
    }
    return false;
}

// The crossing test. A flip is made only if neither new triangle meets a surface triangle
// of the layer but the two it replaces (shared corners aside), in floating point: those
// with a shared corner shrunk by kShrink about their centroids, the others grown by kGrow,
// so that a touch counts. A triangle lies within the ball about any of its corners c
// through c's farther neighbour in it, so a triangle that meets a region has every corner
// within that corner's longest surface edge of it. The layer's vertices (the centre,
// vertex 0, aside) are kept in levels by that edge: level l holds those whose edges are at
// most bound(l) = base * 2^l long, base half the mean surface edge (the last level holds
// the rest, its bound the longest edge), sorted within a level by the cell of a grid whose
// cells are at least as wide as its bound and two mean edges: the vertices of a level
// within its bound of a flip's quad are in a few cells. Each vertex has a half-edge leaving
// it, so that its triangles are at hand. A flip that would give p or q an edge longer than
// its level's bound is not made, so the levels stay as sorted.
const uint32_t kLevels = 16;

const uint32_t kGridCells = 1024;  // cells along a side of a level's grid, at most

const uint32_t kGridColumns = 1024;  // a flip whose region spans more columns is not made

// A flip with more vertices near it is not made (their list is on the stack, 4 KB; the
// scans measured never reach it).
const uint32_t kMostVisited = 1024;

// Per vertex, one word: its level above kSpanBits, and below its longest edge as a share of
// the level's bound, rounded up.
const uint32_t kSpanBits = 27;

const double kSpanScale = 134217728;  // 2^kSpanBits

struct GridLevel {
    uint32_t first, count;  // its vertices: ids[first, first + count)
    double bound, inverse_side;
    uint32_t cells[3];

    uint32_t cell_along(double x, double low_x, uint32_t n) const {
        const double c = (x - low_x) * inverse_side;
        if (!(c > 0)) return 0;
        return c >= n - 1 ? n - 1 : static_cast<uint32_t>(c);
    }
    uint32_t key(uint32_t ix, uint32_t iy, uint32_t iz) const {
        return (ix * cells[1] + iy) * cells[2] + iz;
    }
};

struct LayerGrid {
    const Local* points;
    uint32_t* ids;    // the vertices by level, then cell
    uint32_t* edge;   // per vertex, a half-edge leaving it
    uint32_t* spans;  // per vertex: its level and longest edge (see kSpanBits)
    uint32_t count;
    bool sorted;  // ids and spans are filled only once a flip near a fold needs them
    Vec3 low;
    GridLevel levels[kLevels];

    uint32_t level_of(uint32_t v) const { return spans[v] >> kSpanBits; }
    // At least the longest surface edge at v.
    double span(uint32_t v) const {
        const double share = static_cast<double>((spans[v] & ((1u << kSpanBits) - 1)) + 1);
        return levels[level_of(v)].bound * share / kSpanScale;
    }
    // The word of a vertex at level l whose longest edge is `length`.
    uint32_t span_word(uint32_t l, double length) const {
        const double share = levels[l].bound > 0 ? length / levels[l].bound * kSpanScale : 0;
        const uint32_t most = (1u << kSpanBits) - 1;
        return (l << kSpanBits) | (share >= most ? most : static_cast<uint32_t>(share));
    }
    uint32_t key_of(uint32_t v) const {
        const GridLevel& l = levels[level_of(v)];
        const Local& p = points[v - 1];
        return l.key(l.cell_along(p.x, low.x, l.cells[0]), l.cell_along(p.y, low.y, l.cells[1]),
                     l.cell_along(p.h, low.z, l.cells[2]));
    }
    bool before(uint32_t v, uint32_t w) const {
        if (level_of(v) != level_of(w)) return level_of(v) < level_of(w);
        const uint32_t kv = key_of(v), kw = key_of(w);
        return kv < kw || (kv == kw && v < w);
    }
    // The first position of level l whose vertex's key is at least k.
    uint32_t first_at(const GridLevel& l, uint32_t k) const {
        uint32_t lo = l.first, hi = l.first + l.count;
        while (lo < hi) {
            const uint32_t mid = lo + (hi - lo) / 2;
            if (key_of(ids[mid]) < k)
                lo = mid + 1;
            else
                hi = mid;
        }
        return lo;
    }
    // Whether vertex v may have an edge of `length`.
    bool admits(uint32_t v, double length) const {
        return !sorted || length <= levels[level_of(v)].bound;
    }
    // Vertex v has an edge of `length` (admitted).
    void stretch(uint32_t v, double length) {
        if (!sorted) return;
        const uint32_t word = span_word(level_of(v), length);
        spans[v] = word > spans[v] ? word : spans[v];
    }
};

// The length of edge k of surface triangle t.
static inline double edge_length(const Triangulation& tr, const Local* points, uint32_t t,
                                 uint32_t k) {
    const uint32_t* v = tr.vertex + 3 * t;
    const Vec3 d = vec_of(points[v[(k + 1) % 3] - 1]) - vec_of(points[v[k] - 1]);
    return std::sqrt(dot(d, d));
}

// Sets up the grid of a layer's `vertices` in `ids`, `edge` and `spans`, each with room for
// every vertex: the half-edges now, the rest once a flip needs it (sort_layer_grid).
static inline void link_layer_grid(const Triangulation& tr, const Local* points, size_t vertices,
                                   uint32_t* ids, uint32_t* edge, uint32_t* spans,
                                   LayerGrid& grid) {
    grid.points = points;
    grid.ids = ids;
    grid.edge = edge;
    grid.spans = spans;
    grid.count = static_cast<uint32_t>(vertices - 1);
    grid.sorted = false;
    for (size_t v = 0; v < vertices; ++v) edge[v] = kNoIndex;  // duplicates have none
    for (uint32_t h = 0; h < 3 * tr.triangle_count; ++h)
        if (tr.vertex[h] != kGhost) edge[tr.vertex[h]] = h;
}

// Sorts the grid's vertices by level and cell (see above), once a flip needs it.
static inline void sort_layer_grid(const Triangulation& tr, LayerGrid& grid) {
    const Local* points = grid.points;
    uint32_t* ids = grid.ids;
    uint32_t* spans = grid.spans;
    const size_t vertices = size_t{grid.count} + 1;
    grid.sorted = true;
    for (size_t v = 0; v < vertices; ++v) spans[v] = 0;
    double length_sum = 0, longest = 0;
    size_t edges = 0;
    for (uint32_t t = 0; t < tr.triangle_count; ++t)
        for (uint32_t k = 0; on_surface(tr, t) && k < 3; ++k) {
            const double length = edge_length(tr, points, t, k);
            length_sum += length;
            longest = length > longest ? length : longest;
            ++edges;
        }
    const double mean = edges > 0 ? length_sum / static_cast<double>(edges) : 0;
    Vec3 low = vec_of(points[0]), high = low;
    for (size_t v = 1; v < vertices; ++v) {
        const Vec3 p = vec_of(points[v - 1]);
        low = Vec3{std::fmin(low.x, p.x), std::fmin(low.y, p.y), std::fmin(low.z, p.z)};
        high = Vec3{std::fmax(high.x, p.x), std::fmax(high.y, p.y), std::fmax(high.z, p.z)};
        ids[v - 1] = static_cast<uint32_t>(v);
    }
    grid.low = low;
    const double extent[3] = {high.x - low.x, high.y - low.y, high.z - low.z};
    for (uint32_t l = 0; l < kLevels; ++l) {
        GridLevel& g = grid.levels[l];
        g.bound = std::ldexp(mean / 2, static_cast<int>(l));
        if (l + 1 == kLevels) g.bound = std::fmax(g.bound, longest);
        double side = std::fmax(g.bound, 2 * mean);
        for (double e : extent) side = std::fmax(side, e / kGridCells);
        g.inverse_side = side > 0 ? 1 / side : 0;
        for (int d = 0; d < 3; ++d) {
            const double n = extent[d] * g.inverse_side + 1;
            g.cells[d] = n >= kGridCells ? kGridCells : static_cast<uint32_t>(n);
        }
        g.first = g.count = 0;
    }
    for (uint32_t t = 0; t < tr.triangle_count; ++t)
        for (uint32_t k = 0; on_surface(tr, t) && k < 3; ++k) {
            const double length = edge_length(tr, points, t, k);
            uint32_t l = 0;
            while (l + 1 < kLevels && length > grid.levels[l].bound) ++l;
            const uint32_t word = grid.span_word(l, length);
            const uint32_t a = tr.vertex[3 * t + k], b = tr.vertex[3 * t + (k + 1) % 3];
            spans[a] = word > spans[a] ? word : spans[a];
            spans[b] = word > spans[b] ? word : spans[b];
        }
    heap_sort(ids, grid.count, [&grid](uint32_t v, uint32_t w) { return grid.before(v, w); });
    for (uint32_t i = 0; i < grid.count; ++i) {
        GridLevel& g = grid.levels[grid.level_of(ids[i])];
        if (g.count++ == 0) g.first = i;
    }
}

// Whether clear(g) holds for every half-edge g leaving a vertex within its level's bound of
// `box` (each triangle tested from the first of its corners visited: kVisited marks them);
// false too if a level's region spans more than kGridColumns columns, more than
// kMostVisited vertices are near, or one has more than kFanLimit neighbours.
template <class Clear>
static inline bool region_clear(const Triangulation& tr, const LayerGrid& grid, const Box3& box,
                                uint32_t* flags, Clear clear) {
    uint32_t visited[kMostVisited];
    uint32_t visits = 0;
    auto unmark = [&]() {
        for (uint32_t k = 0; k < visits; ++k) flags[visited[k]] &= ~kVisited;
    };
    auto clear_once = [&](uint32_t g) {
        const uint32_t* c = tr.vertex + 3 * (g / 3);
        return c[0] == kGhost || c[1] == kGhost || c[2] == kGhost ||
               ((flags[c[0]] | flags[c[1]] | flags[c[2]]) & kVisited) || clear(g);
    };
    for (const GridLevel& l : grid.levels) {
        if (l.count == 0) continue;
        const double r = l.bound;
        const uint32_t x0 = l.cell_along(box.low.x - r, grid.low.x, l.cells[0]);
        const uint32_t x1 = l.cell_along(box.high.x + r, grid.low.x, l.cells[0]);
        const uint32_t y0 = l.cell_along(box.low.y - r, grid.low.y, l.cells[1]);
        const uint32_t y1 = l.cell_along(box.high.y + r, grid.low.y, l.cells[1]);
        const uint32_t z0 = l.cell_along(box.low.z - r, grid.low.z, l.cells[2]);
        const uint32_t z1 = l.cell_along(box.high.z + r, grid.low.z, l.cells[2]);
        if (size_t{x1 - x0 + 1} * (y1 - y0 + 1) > kGridColumns) {
            unmark();
            return false;
        }
        for (uint32_t ix = x0; ix <= x1; ++ix)
            for (uint32_t iy = y0; iy <= y1; ++iy) {
                const uint32_t last = l.key(ix, iy, z1), end = l.first + l.count;
                for (uint32_t i = grid.first_at(l, l.key(ix, iy, z0));
                     i < end && grid.key_of(grid.ids[i]) <= last; ++i) {
                    const uint32_t v = grid.ids[i];
                    const Vec3 p = vec_of(grid.points[v - 1]);
                    const Vec3 off = {
                        p.x < box.low.x ? box.low.x - p.x : p.x > box.high.x ? p.x - box.high.x : 0,
                        p.y < box.low.y ? box.low.y - p.y : p.y > box.high.y ? p.y - box.high.y : 0,
                        p.z < box.low.z ? box.low.z - p.z : p.z > box.high.z ? p.z - box.high.z : 0};
                    const double near = grid.span(v) * (1 + kGrow);
                    if (dot(off, off) > near * near || grid.edge[v] == kNoIndex) continue;
                    if (visits == kMostVisited || !around_vertex(tr, grid.edge[v], clear_once)) {
                        unmark();
                        return false;
                    }
                    flags[v] |= kVisited;
                    visited[visits++] = v;
                }
            }
    }
    unmark();
    return true;
}

// The vertex normals, kept in the room of the annulus coordinates (free once the loops are
// settled) as two 16-bit integers a vertex, a unit vector's octahedral encoding (its
// coordinates over their absolute sum, the lower half folded out, to 1/32767): the sum of
// the unit normals of the surface triangles around the vertex, made unit.
struct VertexNormals {
    int16_t* room;
    static constexpr int16_t kNone = INT16_MIN;  // no normal
    static constexpr double kScale = 32767, kUnit = 1 / kScale;

    // The unit normal at vertex v; zero if it has no surface triangle of nonzero area.
    Vec3 at(uint32_t v) const {
        if (room[2 * size_t{v}] == kNone) return Vec3{0, 0, 0};
        const double u = room[2 * size_t{v}] * kUnit, w = room[2 * size_t{v} + 1] * kUnit;
        const double z = 1 - std::fabs(u) - std::fabs(w);
        Vec3 n = z >= 0 ? Vec3{u, w, z}
                        : Vec3{std::copysign(1 - std::fabs(w), u),
                               std::copysign(1 - std::fabs(u), w), z};
        return scaled(n, 1 / std::sqrt(dot(n, n)));
    }
    void put(uint32_t v, Vec3 sum) {
        int16_t* slot = room + 2 * size_t{v};
        const double l1 = std::fabs(sum.x) + std::fabs(sum.y) + std::fabs(sum.z);
        if (!(l1 > 0)) {
            slot[0] = slot[1] = kNone;
            return;
        }
        double u = sum.x / l1, w = sum.y / l1;
        if (sum.z < 0) {
            const double fu = std::copysign(1 - std::fabs(w), u);
            w = std::copysign(1 - std::fabs(u), w);
            u = fu;
        }
        slot[0] = static_cast<int16_t>(std::lround(u * kScale));
        slot[1] = static_cast<int16_t>(std::lround(w * kScale));
    }
    // The normal from the triangles around it (a vertex with more than kFanLimit
    // neighbours has none) of every vertex, or with `changed` of those flagged with it (the
    // corners of the quads flipped since: no other vertex's triangles changed).
    void estimate(const Triangulation& tr, const Local* points, const LayerGrid& grid,
                  const uint32_t* flags, uint32_t changed) {
        put(0, Vec3{0, 0, 0});
        for (uint32_t v = 1; v <= grid.count; ++v) {
            if (changed && !(flags[v] & changed)) continue;
            Vec3 sum = {0, 0, 0};
            const bool fan = grid.edge[v] != kNoIndex && around_vertex(tr, grid.edge[v], [&](uint32_t g) {
                const uint32_t s = g / 3;
                if (!on_surface(tr, s)) return true;
                const uint32_t* c = tr.vertex + 3 * s;
                const Vec3 n = normal_of(points[c[0] - 1], points[c[1] - 1], points[c[2] - 1]);
                const double length = std::sqrt(dot(n, n));
                if (length > 0) sum = sum + scaled(n, 1 / length);
                return true;
            });
            put(v, fan ? sum : Vec3{0, 0, 0});
        }
    }
};

// How much the surface bends along edge ab, with unit normals na and nb at its ends (see
// above).
static inline double bend_along(Vec3 a, Vec3 b, Vec3 na, Vec3 nb) {
    return std::fabs(dot(b - a, nb - na));
}

// The cosine of the widest angle of triangle abc.
static inline double widest_angle_cosine(Vec3 a, Vec3 b, Vec3 c) {
    const Vec3 corner[3] = {a, b, c};
    double widest = 1;
    for (int k = 0; k < 3; ++k) {
        const Vec3 u = corner[(k + 1) % 3] - corner[k], v = corner[(k + 2) % 3] - corner[k];
        const double lengths = std::sqrt(dot(u, u) * dot(v, v));
        const double cosine = lengths > 0 ? dot(u, v) / lengths : -1;
        widest = cosine < widest ? cosine : widest;
    }
    return widest;
}

// Whether the surface wants ab of triangles abp and baq turned into pq, by the two rules
// (see above; na .. nq the corners' unit normals, none zero) without an angle wider than
// kWidestAngle (unless the old pair had a wider one).
static inline bool flip_wanted(const Local& la, const Local& lb, const Local& lp, const Local& lq,
                               Vec3 na, Vec3 nb, Vec3 np, Vec3 nq) {
    if (dot(na, na) == 0 || dot(nb, nb) == 0 || dot(np, np) == 0 || dot(nq, nq) == 0)
        return false;
    const double bend_before = bend_along(vec_of(la), vec_of(lb), na, nb);
    const double bend_after = bend_along(vec_of(lp), vec_of(lq), np, nq);
    if (flip_helps(vec_of(la), vec_of(lb), vec_of(lp), vec_of(lq))
            ? bend_after > kBendVeto * bend_before
            : !(kBendGain * bend_after < bend_before))
        return false;
    const double widest_after =
        std::fmin(widest_angle_cosine(vec_of(lp), vec_of(la), vec_of(lq)),
                  widest_angle_cosine(vec_of(lq), vec_of(lb), vec_of(lp)));
    return !(widest_after < kWidestAngle &&
             widest_after < std::fmin(widest_angle_cosine(vec_of(la), vec_of(lb), vec_of(lp)),
                                      widest_angle_cosine(vec_of(lb), vec_of(la), vec_of(lq))));
}

// Whether both new triangles (p, a, q) and (q, b, p) of that flip have normals within
// kGentleFlip of the old pair's mean.
static inline bool gentle_flip(const Local& la, const Local& lb, const Local& lp, const Local& lq) {
    Vec3 mean = normal_of(la, lb, lp);
    const Vec3 other_normal = normal_of(lb, la, lq);
    mean = Vec3{mean.x + other_normal.x, mean.y + other_normal.y, mean.z + other_normal.z};
    const Vec3 n1 = normal_of(lp, la, lq), n2 = normal_of(lq, lb, lp);
    return dot(n1, mean) > kGentleFlip * std::sqrt(dot(n1, n1) * dot(mean, mean)) &&
           dot(n2, mean) > kGentleFlip * std::sqrt(dot(n2, n2) * dot(mean, mean));
}

// Whether a new triangle of that flip faces away from the old pair's mean normal: turned
// over, a pleat in the surface.
static inline bool turns_over(const Local& la, const Local& lb, const Local& lp, const Local& lq) {
    const Vec3 mean = normal_of(la, lb, lp) + normal_of(lb, la, lq);
    return !(dot(normal_of(lp, la, lq), mean) > 0) || !(dot(normal_of(lq, lb, lp), mean) > 0);
}

// Flips half-edge e of a layer's triangulation on the surface if that helps (see above).
static inline bool flip_on_surface(Triangulation& tr, const Local* points, uint32_t* flags,
                                   VertexNormals& normals, LayerGrid& grid, const Cylinder& cyl,
                                   uint32_t e) {
    const uint32_t f = tr.twin[e];
    const uint32_t t = e / 3, u = f / 3;
    if (!on_surface(tr, u)) return false;
    const uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)], p = tr.vertex[prev_edge(e)];
    const uint32_t q = tr.vertex[prev_edge(f)];
    // A chord of a loop would stand where add_caps puts its cap.
    if (p == q || (flags[p] & flags[q] & (kOnBottomLoop | kOnTopLoop))) return false;
    const Local &la = points[a - 1], &lb = points[b - 1], &lp = points[p - 1], &lq = points[q - 1];
    if (!flip_wanted(la, lb, lp, lq, normals.at(a), normals.at(b), normals.at(p), normals.at(q)))
        return false;
    // The new triangles (p, a, q) and (q, b, p), counter-clockwise on the annulus.
    if (doubled_area(lp, la, lq) == 0 || doubled_area(lq, lb, lp) == 0 ||
        turns_over(la, lb, lp, lq))
        return false;
    if (!around_vertex(tr, prev_edge(e), [&tr, q](uint32_t g) {
            return tr.vertex[next_edge(g)] != q;
        }))
        return false;
    const Vec3 first[3] = {vec_of(lp), vec_of(la), vec_of(lq)};
    const Vec3 second[3] = {vec_of(lq), vec_of(lb), vec_of(lp)};
    const Box3 quad = box_of(first[0], first[1], first[2], second[1]);
    auto clear_of = [&](uint32_t g) {
        const uint32_t s = g / 3;
        if (s == t || s == u || !on_surface(tr, s)) return true;
        const uint32_t* v = tr.vertex + 3 * s;
        const Vec3 other[3] = {vec_of(points[v[0] - 1]), vec_of(points[v[1] - 1]),
                               vec_of(points[v[2] - 1])};
        if (!quad.meets(box_of(other[0], other[1], other[2], other[2]))) return true;
        const auto has = [v](uint32_t x) { return v[0] == x || v[1] == x || v[2] == x; };
        const bool shares_pq = has(p) || has(q);
        return !triangles_meet(first, other, shares_pq || has(a) ? 1 - kShrink : 1 + kGrow) &&
               !triangles_meet(second, other, shares_pq || has(b) ? 1 - kShrink : 1 + kGrow);
    };
    const Vec3 pq = first[2] - first[0];
    const double pq_length = std::sqrt(dot(pq, pq));
    const bool new_fold = faces_axis(lq, la, lp, cyl) || faces_axis(lp, lb, lq, cyl);
    const bool near_fold = new_fold || ((flags[a] | flags[b] | flags[p] | flags[q]) & kNearFold);
    if (near_fold && !grid.sorted) sort_layer_grid(tr, grid);
    if (!grid.admits(p, pq_length) || !grid.admits(q, pq_length)) return false;
    if (near_fold) {
        if (!region_clear(tr, grid, quad, flags, clear_of)) return false;
    } else if (!gentle_flip(la, lb, lp, lq)) {
        // Away from folds the layer is its annulus lifted: a gentle flip covers about the
        // same place as before, another is checked against the triangles around the quad.
        const uint32_t corners[4] = {e, f, prev_edge(e), prev_edge(f)};
        for (uint32_t corner : corners)
            if (!around_vertex(tr, corner, clear_of)) return false;
    }
    flip_edge<false>(tr, e, nullptr);
    // t is (p, a, q) now and u (q, b, p); their corners leave by these half-edges.
    grid.edge[p] = 3 * t;
    grid.edge[a] = 3 * t + 1;
    grid.edge[q] = 3 * u;
    grid.edge[b] = 3 * u + 1;
    grid.stretch(p, pq_length);
    grid.stretch(q, pq_length);
    if (new_fold) {
        flags[a] |= kNearFold;
        flags[b] |= kNearFold;
        flags[p] |= kNearFold;
        flags[q] |= kNearFold;
    }
    return true;
}

// Flips the surface edges of a layer's triangulation, sweep after sweep, until a sweep
// flips none or kSurfaceFlipSweeps have run; after the first sweep, only edges between
// two corners of quads flipped in the sweep before (the edges whose triangles changed).
// `flags` holds a word per vertex (see triangulate_layer); the bits kFlippedBefore,
// kFlippedNow, kVisited and kNearFold are used here and cleared. `room` is the annulus
// coordinates, two doubles a vertex, overwritten by four words a vertex: the normals, the
// grid's order, each vertex's half-edge and its span. Returns the number of flips.
static inline size_t flip_layer_on_surface(Triangulation& tr, const Local* points,
                                           const Cylinder& cyl, uint32_t* flags, double* room,
                                           size_t vertices) {
    // Four words a vertex: the normal, the grid's order, the half-edges and the spans.
    int16_t* normal_room = reinterpret_cast<int16_t*>(room);
    uint32_t* grid_room = reinterpret_cast<uint32_t*>(room) + vertices;
    LayerGrid grid;
    link_layer_grid(tr, points, vertices, grid_room, grid_room + vertices,
                    grid_room + 2 * vertices, grid);
    for (uint32_t t = 0; t < tr.triangle_count; ++t) {
        const uint32_t* v = tr.vertex + 3 * t;
        // Counter-clockwise on the annulus: faces_axis takes the corners the other way.
        if (on_surface(tr, t) && faces_axis(points[v[2] - 1], points[v[1] - 1], points[v[0] - 1], cyl)) {
            flags[v[0]] |= kNearFold;
            flags[v[1]] |= kNearFold;
            flags[v[2]] |= kNearFold;
        }
    }
    VertexNormals normals = {normal_room};
    size_t flips = 0;
    for (uint32_t sweep = 0; sweep < kSurfaceFlipSweeps; ++sweep) {
        if (sweep < kNormalSweeps)
            normals.estimate(tr, points, grid, flags, sweep == 0 ? 0 : kFlippedBefore);
        size_t flipped = 0;
        for (uint32_t t = 0; t < tr.triangle_count; ++t) {
            if (!on_surface(tr, t)) continue;
            const uint32_t* v = tr.vertex + 3 * t;
            // After the first sweep: at least two corners flipped before.
            if (sweep > 0 && ((flags[v[0]] & kFlippedBefore) + (flags[v[1]] & kFlippedBefore) +
                              (flags[v[2]] & kFlippedBefore)) < 2 * kFlippedBefore)
                continue;
            for (uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
                // Each edge once a sweep, from the side of its larger half-edge.
                const uint32_t a = tr.vertex[e], b = tr.vertex[next_edge(e)];
                if (tr.twin[e] > e || (sweep > 0 && !(flags[a] & flags[b] & kFlippedBefore)) ||
                    !flip_on_surface(tr, points, flags, normals, grid, cyl, e))
                    continue;
                ++flipped;
                // t is (p, a, q) after the flip, and the twin's triangle (q, b, p).
                flags[tr.vertex[3 * t]] |= kFlippedNow;
                flags[tr.vertex[3 * t + 1]] |= kFlippedNow;
                flags[tr.vertex[3 * t + 2]] |= kFlippedNow;
                flags[b] |= kFlippedNow;
                break;
            }
        }
        for (size_t v = 0; v < vertices; ++v)
            flags[v] = (flags[v] & ~(kFlippedBefore | kFlippedNow)) |
                       ((flags[v] & kFlippedNow) ? kFlippedBefore : 0);
        flips += flipped;
        if (flipped == 0) break;
    }
    for (size_t v = 0; v < vertices; ++v) flags[v] &= ~(kFlippedBefore | kNearFold);
    return flips;
}

// ---- flips across the seam ----
//
// With the surface_flips flag. A layer's flips on the surface (see "flips on the surface")
// run before its band is stitched and never move a loop's edge, so the band and the layer's
// triangles at its bottom loop keep the unrolled Delaunay's choice, and every cut would
// cost closeness to the surface (twice as much as with the seam's flips). Once a chunk is
// final, its seam (the triangles with a corner on the loop below or on the layer's bottom
// loop) is flipped by the same rules, with three limits that keep everything outside the
// seam as it is:
//  - only edges between two seam triangles, so the loop below's edges, the edges to the
//    rest of the chunk and the chunk before (which the stream has handed out) stay;
//  - only flips where p or q is a loop point: a loop point's triangles in the chunk are all
//    in the seam, so whether pq is an edge already is read from its fan (the loop below's
//    other side, in the chunk before, has no point of this layer), and a chord between two
//    points of one loop (the loop below, the layer's bottom or top loop) is refused, as it
//    would stand where the next band or a cap goes; both new triangles keep that corner,
//    so they stay in the seam;
//  - only gentle flips (kGentleFlip), which need no crossing test, none that makes or
//    unmakes a fold (the layer's cylinder), so Report::diagnostics.fold_count keeps its
//    count, and none with a corner on a triangle facing the axis (kSeamNearFold), where the
//    layer's flips may have laid the lifted annulus over itself (without that, seam flips
//    made 3 crossing pairs on a lion head scan).
// Vertex normals come from every triangle of the chunk. The seam's memory, at most about
// 72 bytes per vertex of the chunk and 4 per point read, fits in the safety net's room
// (reconstruct_scratch_size: 91 per point) because a seam of more triangles than three
// quarters of the chunk's vertices is left as it is: a thin layer, mostly loop.

const uint32_t kLoopBelow = 1, kBottomLoopPoint = 2, kTopLoopPoint = 4, kLoopBits = 3;

const unsigned char kSeamNearFold = 8;  // in Seam::loop: a corner of a triangle facing the axis

struct Seam {
    uint32_t* chunk;        // the chunk's triangles, reader indices
    uint32_t* slot;         // seam triangle s is chunk triangle slot[s]
    uint32_t* vertex;       // 3 per seam triangle: its seam points
    uint32_t* twin;         // 3 per seam triangle: the opposite half-edge, or kNoIndex
    uint32_t* degree;       // per seam point: its seam triangles
    uint32_t* ids;          // per seam point: its reader index
    unsigned char* loop;    // per seam point: kLoopBelow, kBottomLoopPoint, kTopLoopPoint
    float* fixed_normal;    // 3 per seam point: the sum over its triangles off the seam
    float* normal;          // 3 per seam point
    // Per reader index of the chunk's points and loops (the rest unset): its loop bits,
    // and above them (seam point + 1) << kLoopBits once it is one.
    uint32_t* tag;
    uint32_t triangles, points;

    // The seam point of reader index id (one of the chunk's), or kNoIndex.
    uint32_t point_of(uint32_t id) const {
        return (tag[id] >> kLoopBits) == 0 ? kNoIndex : (tag[id] >> kLoopBits) - 1;
    }
};

// Tags the chunk's points and the loops' with their loop bits, over reader indices up to
// the largest of theirs; room for `most` seam triangles. False if the arena is too small.
static inline bool tag_seam_points(const SurfaceChain& c, const LoadedLayer& layer,
                                   const LayerLoops& loops, size_t count, size_t most, Arena& arena,
                                   Seam& seam) {
    const uint32_t* chunk = seam.chunk;
    uint32_t largest = 0;
    for (size_t k = 0; k < 3 * count; ++k) largest = chunk[k] > largest ? chunk[k] : largest;
    for (uint32_t i = 0; i < c.top_count; ++i) largest = c.top[i] > largest ? c.top[i] : largest;
    for (uint32_t i = 0; i < layer.count; ++i)
        largest = layer.ids[i] > largest ? layer.ids[i] : largest;
    seam.tag = arena.alloc<uint32_t>(size_t{largest} + 1);
    seam.slot = arena.alloc<uint32_t>(most);
    if (arena.failed) return false;
    for (size_t k = 0; k < 3 * count; ++k) seam.tag[chunk[k]] = 0;
    for (uint32_t i = 0; i < c.top_count; ++i) seam.tag[c.top[i]] = kLoopBelow;
    for (uint32_t i = 0; i < loops.bottom_count; ++i) seam.tag[layer.ids[loops.bottom[i]]] = 0;
    for (uint32_t i = 0; i < loops.top_count; ++i) seam.tag[layer.ids[loops.top[i]]] = 0;
    for (uint32_t i = 0; i < loops.bottom_count; ++i)
        seam.tag[layer.ids[loops.bottom[i]]] |= kBottomLoopPoint;
    for (uint32_t i = 0; i < loops.top_count; ++i)
        seam.tag[layer.ids[loops.top[i]]] |= kTopLoopPoint;
    return true;
}

// Numbers the seam triangles' points (seam.ids, and in their tags) and names their corners
// by them, with each point's loop bits and seam triangle count. False if the arena is too
// small.
static inline bool number_seam_points(Arena& arena, Seam& seam) {
    const size_t triangles = seam.triangles;
    seam.vertex = arena.alloc<uint32_t>(3 * triangles);
    seam.twin = arena.alloc<uint32_t>(3 * triangles);
    seam.ids = arena.alloc<uint32_t>(3 * triangles);
    if (arena.failed) return false;
    uint32_t points = 0;
    for (size_t s = 0; s < triangles; ++s)
        for (uint32_t j = 0; j < 3; ++j) {
            const uint32_t id = seam.chunk[3 * size_t{seam.slot[s]} + j];
            if ((seam.tag[id] >> kLoopBits) == 0) {
                seam.ids[points] = id;
                seam.tag[id] |= (points + 1) << kLoopBits;
                ++points;
            }
            seam.vertex[3 * s + j] = (seam.tag[id] >> kLoopBits) - 1;
        }
    seam.points = points;
    seam.degree = arena.alloc<uint32_t>(points);
    seam.loop = arena.alloc<unsigned char>(points);
    seam.fixed_normal = arena.alloc<float>(3 * size_t{points});
    seam.normal = arena.alloc<float>(3 * size_t{points});
    if (arena.failed) return false;
    for (uint32_t v = 0; v < points; ++v) {
        seam.loop[v] = static_cast<unsigned char>(seam.tag[seam.ids[v]] & 7u);
        seam.degree[v] = 0;
    }
    for (size_t i = 0; i < 3 * triangles; ++i) ++seam.degree[seam.vertex[i]];
    return true;
}

// Each seam half-edge's twin, found through each point's outgoing half-edges. False if
// the arena is too small.
static inline bool link_seam_twins(Arena& arena, Seam& seam) {
    const uint32_t points = seam.points, triangles = seam.triangles;
    size_t mark = arena.mark();
    uint32_t* first = arena.alloc<uint32_t>(size_t{points} + 1);
    uint32_t* outgoing = arena.alloc<uint32_t>(3 * size_t{triangles});
    if (arena.failed) return false;
    std::memset(first, 0, (size_t{points} + 1) * sizeof(uint32_t));
    for (size_t e = 0; e < 3 * size_t{triangles}; ++e) ++first[seam.vertex[e] + 1];
    for (uint32_t v = 0; v < points; ++v) first[v + 1] += first[v];
    for (uint32_t e = 0; e < 3 * triangles; ++e) outgoing[first[seam.vertex[e]]++] = e;
    for (uint32_t v = points; v > 0; --v) first[v] = first[v - 1];
    first[0] = 0;
    for (uint32_t e = 0; e < 3 * triangles; ++e) {
        const uint32_t a = seam.vertex[e], b = seam.vertex[next_edge(e)];
        seam.twin[e] = kNoIndex;
        for (uint32_t i = first[b]; i < first[b + 1]; ++i)
            if (seam.vertex[next_edge(outgoing[i])] == a) seam.twin[e] = outgoing[i];
    }
    arena.rewind(mark);
    return true;
}

// The seam of a chunk (see above). False with seam.triangles = 0 when it is left as it is;
// false with arena.failed when the arena is too small.
static inline bool find_seam(const SurfaceChain& c, const LoadedLayer& layer,
                             const LayerLoops& loops, uint32_t* chunk, size_t count, Arena& arena,
                             Seam& seam) {
    seam.chunk = chunk;
    seam.triangles = 0;
    const size_t vertices = layer.count + c.top_count;
    // More seam triangles: left as it is (and the tags' seam points fit above the bits).
    size_t most = 3 * vertices / 4;
    if (most > (kNoIndex >> kLoopBits) / 3) most = (kNoIndex >> kLoopBits) / 3;
    if (!tag_seam_points(c, layer, loops, count, most, arena, seam)) return false;
    size_t triangles = 0;
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* v = chunk + 3 * t;
        if (!((seam.tag[v[0]] | seam.tag[v[1]] | seam.tag[v[2]]) & (kLoopBelow | kBottomLoopPoint)))
            continue;
        if (triangles == most) return false;
        seam.slot[triangles++] = static_cast<uint32_t>(t);
    }
    if (triangles == 0) return false;
    seam.triangles = static_cast<uint32_t>(triangles);
    return number_seam_points(arena, seam) && link_seam_twins(arena, seam);
}

// Seam point v's normal.
static inline Vec3 seam_normal(const Seam& seam, uint32_t v) {
    const float* n = seam.normal + 3 * size_t{v};
    return Vec3{static_cast<double>(n[0]), static_cast<double>(n[1]),
                static_cast<double>(n[2])};
}

// Adds triangle v's unit normal to sums[3 k] for each corner k of it that is a seam point.
static inline void add_seam_normal(const SurfaceChain& c, const Seam& seam, const uint32_t* v,
                                   float* sums) {
    const uint32_t at[3] = {seam.point_of(v[0]), seam.point_of(v[1]), seam.point_of(v[2])};
    if (at[0] == kNoIndex && at[1] == kNoIndex && at[2] == kNoIndex) return;
    Vec3 n = normal_of(c.frame.local(c.reader.point(v[0])), c.frame.local(c.reader.point(v[1])),
                       c.frame.local(c.reader.point(v[2])));
    const double length = std::sqrt(dot(n, n));
    if (length == 0) return;
    n = scaled(n, 1 / length);
    for (uint32_t k : at) {
        if (k == kNoIndex) continue;
        float* sum = sums + 3 * size_t{k};
        sum[0] += static_cast<float>(n.x);
        sum[1] += static_cast<float>(n.y);
        sum[2] += static_cast<float>(n.z);
    }
}

// The sums of the unit normals of the chunk's triangles off the seam, at the seam's points.
static inline void sum_fixed_normals(const SurfaceChain& c, const Seam& seam, size_t count) {
    std::memset(seam.fixed_normal, 0, 3 * size_t{seam.points} * sizeof(float));
    uint32_t next = 0;  // seam.slot is increasing
    for (size_t t = 0; t < count; ++t) {
        if (next < seam.triangles && seam.slot[next] == t) {
            ++next;
            continue;
        }
        add_seam_normal(c, seam, seam.chunk + 3 * t, seam.fixed_normal);
    }
}

// The seam's vertex normals over every triangle of the chunk (see VertexNormals): the fixed
// sums and the seam's own triangles, made unit.
static inline void estimate_seam_normals(const SurfaceChain& c, const Seam& seam) {
    std::memcpy(seam.normal, seam.fixed_normal, 3 * size_t{seam.points} * sizeof(float));
    for (uint32_t s = 0; s < seam.triangles; ++s)
        add_seam_normal(c, seam, seam.chunk + 3 * size_t{seam.slot[s]}, seam.normal);
    for (uint32_t k = 0; k < seam.points; ++k) {
        float* sum = seam.normal + 3 * size_t{k};
        const Vec3 n = seam_normal(seam, k);
        const double length = std::sqrt(dot(n, n));
        if (length == 0) continue;
        sum[0] = static_cast<float>(n.x / length);
        sum[1] = static_cast<float>(n.y / length);
        sum[2] = static_cast<float>(n.z / length);
    }
}

// Marks kSeamNearFold the seam points at a corner of a chunk triangle facing the axis: the
// layer's flips on the surface may leave such triangles where the surface turns to face the
// axis, and a flip beside them, gentle as it is, could cross them.
static inline void mark_near_folds(const SurfaceChain& c, Seam& seam, const Cylinder& cyl,
                                   size_t count) {
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* v = seam.chunk + 3 * t;
        const uint32_t at[3] = {seam.point_of(v[0]), seam.point_of(v[1]), seam.point_of(v[2])};
        if (at[0] == kNoIndex && at[1] == kNoIndex && at[2] == kNoIndex) continue;
        if (!faces_axis(c.frame.local(c.reader.point(v[0])), c.frame.local(c.reader.point(v[1])),
                        c.frame.local(c.reader.point(v[2])), cyl))
            continue;
        for (uint32_t k : at)
            if (k != kNoIndex) seam.loop[k] |= kSeamNearFold;
    }
}

// Whether seam point x's triangles, walked around it from half-edge `from` (leaving x) both
// ways, are all of its seam triangles and none has an edge to y.
static inline bool fan_misses(const Seam& seam, uint32_t from, uint32_t x, uint32_t y) {
    uint32_t seen = 0;
    auto clear = [&seam, y](uint32_t g) {
        return seam.vertex[next_edge(g)] != y && seam.vertex[prev_edge(g)] != y;
    };
    uint32_t g = from;
    for (uint32_t steps = 0;; ++steps) {
        if (steps == kFanLimit || !clear(g)) return false;
        ++seen;
        const uint32_t h = seam.twin[prev_edge(g)];
        if (h == from) return seen == seam.degree[x];
        if (h == kNoIndex) break;
        g = h;
    }
    g = from;
    for (uint32_t steps = 0;; ++steps) {
        const uint32_t back = seam.twin[g];
        if (back == kNoIndex) break;
        g = next_edge(back);
        if (steps == kFanLimit || !clear(g)) return false;
        ++seen;
    }
    return seen == seam.degree[x];
}

// Flips half-edge e of the seam if that helps (see above and flip_on_surface).
static inline bool flip_seam_edge(const SurfaceChain& c, Seam& seam, const Cylinder& cyl,
                                  uint32_t e) {
    const uint32_t f = seam.twin[e];
    if (f == kNoIndex) return false;
    const uint32_t a = seam.vertex[e], b = seam.vertex[next_edge(e)];
    const uint32_t p = seam.vertex[prev_edge(e)], q = seam.vertex[prev_edge(f)];
    if (p == q || (seam.loop[p] & seam.loop[q] & 7u) ||
        !((seam.loop[p] | seam.loop[q]) & (kLoopBelow | kBottomLoopPoint)) ||
        ((seam.loop[a] | seam.loop[b] | seam.loop[p] | seam.loop[q]) & kSeamNearFold))
        return false;
    const bool p_anchors = (seam.loop[p] & (kLoopBelow | kBottomLoopPoint)) != 0;
    if (p_anchors ? !fan_misses(seam, prev_edge(e), p, q) : !fan_misses(seam, prev_edge(f), q, p))
        return false;
    const Local la = c.frame.local(c.reader.point(seam.ids[a]));
    const Local lb = c.frame.local(c.reader.point(seam.ids[b]));
    const Local lp = c.frame.local(c.reader.point(seam.ids[p]));
    const Local lq = c.frame.local(c.reader.point(seam.ids[q]));
    if (!flip_wanted(la, lb, lp, lq, seam_normal(seam, a), seam_normal(seam, b),
                     seam_normal(seam, p), seam_normal(seam, q)))
        return false;
    // The chunk's triangles face outwards counter-clockwise, as do the new (p, a, q) and
    // (q, b, p).
    if (faces_axis(la, lb, lp, cyl) || faces_axis(lb, la, lq, cyl) ||
        faces_axis(lp, la, lq, cyl) || faces_axis(lq, lb, lp, cyl) ||
        doubled_area(lp, la, lq) == 0 || doubled_area(lq, lb, lp) == 0)
        return false;
    if (!gentle_flip(la, lb, lp, lq)) return false;
    const uint32_t t = e / 3, u = f / 3;
    const uint32_t xa = seam.twin[next_edge(e)], xb = seam.twin[prev_edge(e)];
    const uint32_t xc = seam.twin[next_edge(f)], xd = seam.twin[prev_edge(f)];
    const uint32_t corners[6] = {p, a, q, q, b, p};
    for (uint32_t j = 0; j < 3; ++j) {
        seam.vertex[3 * t + j] = corners[j];
        seam.vertex[3 * u + j] = corners[3 + j];
        seam.chunk[3 * size_t{seam.slot[t]} + j] = seam.ids[corners[j]];
        seam.chunk[3 * size_t{seam.slot[u]} + j] = seam.ids[corners[3 + j]];
    }
    auto link = [&seam](uint32_t g, uint32_t h) {
        seam.twin[g] = h;
        if (h != kNoIndex) seam.twin[h] = g;
    };
    link(3 * t, xb);
    link(3 * t + 1, xc);
    link(3 * u, xd);
    link(3 * u + 1, xa);
    link(3 * t + 2, 3 * u + 2);
    --seam.degree[a];
    --seam.degree[b];
    ++seam.degree[p];
    ++seam.degree[q];
    return true;
}

// Flips a final chunk's seam (reader indices) on the surface, sweep after sweep as
// flip_layer_on_surface does. Returns false if the arena is too small.
static inline bool flip_seam(const SurfaceChain& c, const LoadedLayer& layer,
                             const LayerLoops& loops, uint32_t* chunk, size_t count, Arena& arena) {
    size_t mark = arena.mark();
    Seam seam;
    if (!find_seam(c, layer, loops, chunk, count, arena, seam)) {
        arena.rewind(mark);
        return !arena.failed;
    }
    sum_fixed_normals(c, seam, count);
    mark_near_folds(c, seam, layer.cyl, count);
    for (uint32_t sweep = 0; sweep < kSurfaceFlipSweeps; ++sweep) {
        if (sweep < kNormalSweeps) estimate_seam_normals(c, seam);
        size_t flipped = 0;
        for (uint32_t s = 0; s < seam.triangles; ++s)
            for (uint32_t e = 3 * s; e < 3 * s + 3; ++e) {
                const uint32_t f = seam.twin[e];
                if (f == kNoIndex || f > e || !flip_seam_edge(c, seam, layer.cyl, e)) continue;
                ++flipped;
                break;
            }
        if (flipped == 0) break;
    }
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh
