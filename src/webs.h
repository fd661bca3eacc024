// >>webs =================================================================================
// How much of a finished surface spans gaps (Diagnostics).
//
// How much of a finished surface is web (Diagnostics): triangles far longer than the
// spacing of the points they join, as where one tube wraps limbs and spans the gaps between
// them. A vertex's local spacing is the median length of its edges, each counted once: the
// edge that leaves it in each of its triangles (a boundary vertex misses one of its two
// boundary edges). The median, not the shortest: a CT stack's edges across its slices are
// far longer than those along a slice, and a vertex at a web's border has a few long edges
// among its own. A triangle is web when its longest edge exceeds kWebSpacings times the
// largest spacing of its corners: the largest, so that a triangle between a densely and a
// sparsely sampled region is measured by the sparse one's. With 6, single columns (tubes,
// heads, cones, capsules, CT slices, scan grids, noisy tubes, the bundled bust) show no web
// triangle or a few, under 0.3% of their area, while objects with limbs meshed as one tube
// show 2 to 12% of theirs. Far more of such a mesh is folded surface whose vertices have
// only long edges (a fan of slivers from a foot to the body): the measure counts the
// spans, which is enough to tell. The caps are left out: a cap spans its loop by design.
//
// The pass runs once the surface is final, when the layers' scratch is free: 72 bytes a
// point (with 2 triangles a point), within reconstruct_workspace_size()'s bound. Lengths
// are measured in the cloud's coordinates times a power of two that brings its extent near
// 1 (exact), so that no square overflows or underflows.

namespace stratmesh {
namespace detail {

// The vertices are numbered in the order the triangles first name them, their points
// copied in that order, and the triangles renumbered in place (then restored): the passes
// over the triangles then read nearby memory, whatever the cloud's order. The passes over
// the vertices alone (copying their points, the medians) run as jobs where the caller gave
// a runner; those over the triangles stay in order, as the areas are summed in it.
struct WebMemory {
    Vec3* points;      // a vertex's point (halved where the cloud spans more than a double)
    size_t* ends;      // a vertex's count of edges, then where its lengths end once sorted
    float* spacings;   // a vertex's local spacing
    uint32_t* index;   // a vertex's index in the cloud
    float* longest;    // a triangle's longest edge
    // While the vertices are numbered, a point's number (or kNoIndex); then, in the same
    // memory, the lengths of the edges leaving each vertex, vertex after vertex.
    uint32_t* id;
    float* lengths;
};

static inline bool allocate_webs(WebMemory& m, size_t point_count, size_t triangle_count,
                                 Arena& arena) {
    m.points = arena.alloc<Vec3>(point_count);
    m.ends = arena.alloc<size_t>(point_count);
    m.spacings = arena.alloc<float>(point_count);
    m.index = arena.alloc<uint32_t>(point_count);
    m.longest = arena.alloc<float>(triangle_count);
    const size_t lengths = saturating_product(3, triangle_count);
    void* shared = arena.take(lengths > point_count ? lengths : point_count, sizeof(float));
    m.id = static_cast<uint32_t*>(shared);
    m.lengths = static_cast<float*>(shared);
    return !arena.failed;
}

// The workspace measure_webs() takes.
static inline size_t webs_workspace_size(size_t point_count, size_t triangle_count) {
    Arena arena = Arena::measuring();
    WebMemory m;
    return allocate_webs(m, point_count, triangle_count, arena) ? arena.required_bytes() : 0;
}

// Edges in the cloud's coordinates times a power of two that brings the cloud's extent
// near 1 (exact): no square overflows or underflows. Where the cloud spans more than the
// largest double, the points are halved first, so that no difference overflows.
struct WebFrame {
    double scale;
    bool halved;
    Vec3 point(const CloudReader& reader, uint32_t i) const {
        return halved ? scaled(reader.point(i), 0.5) : reader.point(i);
    }
    // ab, bc and ca of the triangle whose corners are numbered c.
    void edges(const Vec3* points, const uint32_t* c, Vec3 e[3]) const {
        const double s = halved ? 2 * scale : scale;
        const Vec3 a = points[c[0]], b = points[c[1]], d = points[c[2]];
        e[0] = scaled(b - a, s);
        e[1] = scaled(d - b, s);
        e[2] = scaled(a - d, s);
    }
};

static inline WebFrame web_frame(const CloudSums& s) {
    const Vec3 low = {s.lowest[0], s.lowest[1], s.lowest[2]};
    const Vec3 high = {s.highest[0], s.highest[1], s.highest[2]};
    const Vec3 size = high - low, half = scaled(high, 0.5) - scaled(low, 0.5);
    double extent = half.x > half.y ? half.x : half.y;
    if (half.z > extent) extent = half.z;
    return {scale_for_extent(extent), !(is_finite(size.x) && is_finite(size.y) && is_finite(size.z))};
}

// a, b in order (as min and max, which compile without a branch).
static inline void order(float& a, float& b) {
    const float low = b < a ? b : a, high = a < b ? b : a;
    a = low;
    b = high;
}

// The lower median of v[0 .. count), count > 0: by a sorting network for a vertex's few
// edges (no branch to mispredict), by heapsort for a large fan.
static inline float lower_median(float* v, size_t count) {
    if (count > 8) {
        heap_sort(v, count);
        return v[(count - 1) / 2];
    }
    float s[8];
    for (size_t i = 0; i < 8; ++i) s[i] = i < count ? v[i] : FLT_MAX;
    order(s[0], s[2]), order(s[1], s[3]), order(s[4], s[6]), order(s[5], s[7]);
    order(s[0], s[4]), order(s[1], s[5]), order(s[2], s[6]), order(s[3], s[7]);
    order(s[0], s[1]), order(s[2], s[3]), order(s[4], s[5]), order(s[6], s[7]);
    order(s[2], s[4]), order(s[3], s[5]);
    order(s[1], s[4]), order(s[3], s[6]);
    order(s[1], s[2]), order(s[3], s[4]), order(s[5], s[6]);
    return s[(count - 1) / 2];
}

// Corners this far ahead are prefetched while the vertices are numbered, and points while
// they are copied: the triangles name them in no order of the cloud's.
const size_t kWebAhead = 16;

// Numbers the vertices, renumbers the triangles' corners and counts the edges leaving each
// vertex, then turns the counts into starts; returns how many vertices there are.
static inline uint32_t number_vertices(uint32_t* tri, size_t count, size_t point_count,
                                       const WebMemory& m) {
    for (size_t v = 0; v < point_count; ++v) m.id[v] = kNoIndex;
    uint32_t vertices = 0;
    for (size_t k = 0; k < 3 * count; ++k) {
        if (kFastLoops && k + kWebAhead < 3 * count) prefetch(m.id + tri[k + kWebAhead]);
        uint32_t& id = m.id[tri[k]];
        if (id == kNoIndex) {
            id = vertices++;
            m.index[id] = tri[k];
            m.ends[id] = 0;
        }
        ++m.ends[id];
        tri[k] = id;
    }
    size_t start = 0;
    for (uint32_t v = 0; v < vertices; ++v) {
        const size_t edges = m.ends[v];
        m.ends[v] = start;
        start += edges;
    }
    return vertices;
}

// The passes over the vertices, by runs of them (see run_pass).
struct WebVertexPass {
    const CloudReader* reader;
    const WebFrame* frame;
    const WebMemory* m;
    uint32_t vertices;
    bool medians;  // else the points

    void run(uint32_t k) const {
        const size_t begin = run_start(vertices, k), end = run_start(vertices, k + 1);
        if (!medians) {
            for (size_t v = begin; v < end; ++v) {
                if (kFastLoops && v + kWebAhead < end)
                    prefetch(reader->base + m->index[v + kWebAhead] * reader->stride);
                m->points[v] = frame->point(*reader, m->index[v]);
            }
            return;
        }
        for (size_t v = begin; v < end; ++v) {
            const size_t first = v > 0 ? m->ends[v - 1] : 0;
            m->spacings[v] = lower_median(m->lengths + first, m->ends[v] - first);
        }
    }
};

// The lengths of the edges leaving each vertex, sorted by vertex (a counting sort: each
// start becomes an end), and each triangle's longest edge. Returns the triangles' area.
static inline double edge_lengths(const WebFrame& f, const uint32_t* tri, size_t count,
                                  const WebMemory& m) {
    double area = 0;
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* c = tri + 3 * t;
        Vec3 e[3];
        f.edges(m.points, c, e);
        const Vec3 n = cross(e[0], e[1]);
        area += std::sqrt(dot(n, n)) / 2;
        float longest = 0;
        for (size_t j = 0; j < 3; ++j) {
            const float length = static_cast<float>(std::sqrt(dot(e[j], e[j])));
            m.lengths[m.ends[c[j]]++] = length;
            longest = length > longest ? length : longest;
        }
        m.longest[t] = longest;
    }
    return area;
}

// The web triangles among the renumbered triangles (see Diagnostics), into d, while their
// corners are numbered back; returns their area.
static inline double find_webs(const WebFrame& f, uint32_t* tri, size_t count, const WebMemory& m,
                               Diagnostics& d) {
    double web = 0;
    Vec3 low = {DBL_MAX, DBL_MAX, DBL_MAX}, high = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t t = 0; t < count; ++t) {
        uint32_t* c = tri + 3 * t;
        float spacing = 0;
        for (size_t j = 0; j < 3; ++j)
            spacing = m.spacings[c[j]] > spacing ? m.spacings[c[j]] : spacing;
        if (static_cast<double>(m.longest[t]) > kWebSpacings * static_cast<double>(spacing)) {
            ++d.web_triangle_count;
            Vec3 e[3];
            f.edges(m.points, c, e);
            const Vec3 n = cross(e[0], e[1]);
            web += std::sqrt(dot(n, n)) / 2;
            for (size_t j = 0; j < 3; ++j) {
                const Vec3 p = m.points[c[j]];
                low = {p.x < low.x ? p.x : low.x, p.y < low.y ? p.y : low.y,
                       p.z < low.z ? p.z : low.z};
                high = {p.x > high.x ? p.x : high.x, p.y > high.y ? p.y : high.y,
                        p.z > high.z ? p.z : high.z};
            }
        }
        for (size_t j = 0; j < 3; ++j) c[j] = m.index[c[j]];
    }
    const double unhalve = f.halved ? 2 : 1;  // the copied points are halved then
    const double lows[3] = {low.x, low.y, low.z}, highs[3] = {high.x, high.y, high.z};
    for (int k = 0; d.web_triangle_count > 0 && k < 3; ++k) {
        d.web_box_min[k] = lows[k] * unhalve;
        d.web_box_max[k] = highs[k] * unhalve;
    }
    return web;
}

// Measures the webs of triangles[0 .. count) less the last `caps` into rep.diagnostics;
// the triangles are renumbered meanwhile and come back as they were. False if the
// workspace is too small (nothing is measured).
static inline bool measure_webs(const Options& options, const CloudReader& reader,
                                size_t point_count, const CloudSums& sums, uint32_t* triangles,
                                size_t count, size_t caps, Arena& arena, Report& rep) {
    const size_t walls = caps < count ? count - caps : 0;
    const size_t mark = arena.mark();
    WebMemory m;
    if (!allocate_webs(m, point_count, walls, arena)) return false;
    const WebFrame f = web_frame(sums);
    WebVertexPass pass = {&reader, &f, &m, number_vertices(triangles, walls, point_count, m),
                          false};
    run_pass(options, pass);
    const double area = edge_lengths(f, triangles, walls, m);
    pass.medians = true;
    run_pass(options, pass);
    Diagnostics& d = rep.diagnostics;
    const double web = find_webs(f, triangles, walls, m, d);
    arena.rewind(mark);
    if (d.web_triangle_count == 0) return true;
    d.web_area = web / f.scale / f.scale;
    d.web_area_fraction = area > 0 ? web / area : 0;
    return true;
}

}  // namespace detail
}  // namespace stratmesh
