// >>delaunay =============================================================================
// The incremental 2D Delaunay triangulation (delaunay_2d).
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

namespace stratmesh {
namespace detail {

static const uint32_t kGhost = kNoIndex;

static inline uint32_t next_edge(uint32_t e) { return e % 3 == 2 ? e - 2 : e + 1; }

static inline uint32_t prev_edge(uint32_t e) { return e % 3 == 0 ? e + 2 : e - 1; }

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
static inline bool allocate_triangulation(Triangulation& tr, size_t count, Arena& arena) {
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
static inline void start_triangulation(Triangulation& tr, uint32_t a, uint32_t b, uint32_t c) {
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
static inline Location locate(const Triangulation& tr, const double* p, uint32_t& edge) {
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

static inline bool push_edge(Triangulation& tr, uint32_t& top, uint32_t e) {
    STRATMESH_ASSERT(top < tr.stack_capacity);
    if (top >= tr.stack_capacity) return false;
    tr.stack[top++] = e;
    return true;
}

// Splits the triangle of half-edge e = (a, b, c) into (a, b, p), (b, c, p), (c, a, p).
static inline void split_triangle(Triangulation& tr, uint32_t t, uint32_t p, uint32_t& top) {
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
static inline void split_edge(Triangulation& tr, uint32_t e, uint32_t p, uint32_t& top) {
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
static inline bool must_flip(const Triangulation& tr, uint32_t e) {
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

// Flips e = a->b of (a, b, p) with its twin in (b, a, q) into (p, a, q) and (q, b, p) (the
// new triangles keep e's two triangle slots), and with kQueue queues the two edges that may
// now fail the Delaunay test.
template <bool kQueue> static inline void flip_edge(Triangulation& tr, uint32_t e, uint32_t* top) {
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
    if (!kQueue) return;
    push_edge(tr, *top, 3 * t + 1);
    push_edge(tr, *top, 3 * u);
}

// Inserts vertex p. Returns the vertex it duplicates, p itself if it was inserted, or
// kNoIndex if an invariant failed.
static inline uint32_t insert_vertex(Triangulation& tr, uint32_t p) {
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
        flip_edge<true>(tr, e, &top);
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
static inline Status triangulate_points(Triangulation& tr, uint32_t count, DuplicateSink sink,
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
    STRATMESH_ASSERT(tr.triangle_count == 2 * n_inserted - 2);
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

static inline bool plan_delaunay_2d(Delaunay2dMemory& m, size_t count, Arena& arena,
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
}  // namespace stratmesh

namespace stratmesh {

size_t delaunay_2d_workspace_size(size_t point_count) {
    if (point_count > detail::kMaxPoints) return 0;
    detail::Arena arena = detail::Arena::measuring();
    detail::Delaunay2dMemory m;
    detail::plan_delaunay_2d(m, point_count, arena, nullptr, 0, nullptr);
    return arena.failed ? 0 : arena.required_bytes();
}

size_t delaunay_2d_max_triangles(size_t point_count) {
    if (point_count > SIZE_MAX / 2) return 0;
    return point_count >= 3 ? 2 * point_count - 5 : 0;
}

}  // namespace stratmesh

namespace stratmesh {
namespace detail {

// True if any two of the caller's buffers share a byte: checked before anything is
// written. A count beyond the limit is refused as too_many_points instead, whatever its
// span would cover.
static inline bool delaunay_buffers_overlap(const double* xy, size_t point_count, size_t stride_bytes,
                                     void* workspace, size_t workspace_bytes,
                                     uint32_t* triangles, size_t triangle_capacity,
                                     Delaunay2dInfo* info, uint32_t* duplicate_of) {
    if (point_count > kMaxPoints) return false;
    const ByteRange buffers[] = {
        strided_range(xy, point_count, stride_bytes, 2 * sizeof(double)),
        byte_range(workspace, workspace_bytes),
        byte_range(triangles, saturating_product(triangle_capacity, 3 * sizeof(uint32_t))),
        byte_range(duplicate_of, saturating_product(point_count, sizeof(uint32_t))),
        byte_range(info, sizeof(Delaunay2dInfo))};
    return any_overlap(buffers, 5);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

Status delaunay_2d(const double* xy, size_t point_count, size_t stride_bytes,
                   void* workspace, size_t workspace_bytes,
                   uint32_t* triangles, size_t triangle_capacity,
                   Delaunay2dInfo* info, uint32_t* duplicate_of) {
    if (detail::delaunay_buffers_overlap(xy, point_count, stride_bytes, workspace,
                                         workspace_bytes, triangles, triangle_capacity, info,
                                         duplicate_of))
        return Status::invalid_argument;
    Delaunay2dInfo local = {0, 0, 0, 0, 0};
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
                out.first_invalid_index = i;
                return Status::invalid_point;
            }
            if (v < box.min[k]) box.min[k] = v;
            if (v > box.max[k]) box.max[k] = v;
        }
    }

    detail::Arena arena = detail::Arena::over(workspace, workspace_bytes);
    detail::Delaunay2dMemory m;
    if (!detail::plan_delaunay_2d(m, point_count, arena, base, stride_bytes, &box))
        {
        out.workspace_used_bytes = arena.peak_from_buffer();
        return Status::out_of_memory;
    }
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
    out.workspace_used_bytes = arena.peak_from_buffer();
    if (status != Status::ok) return status;

    size_t ghosts = 0;
    for (uint32_t t = 0; t < m.tr.triangle_count; ++t) ghosts += m.tr.is_ghost(t);
    // A triangulation's hull has 3 edges or more; fewer means contradictory predicate
    // signs (coordinates beyond the exact range), and then 2n - 5 would not bound `real`.
    if (ghosts < 3) return Status::internal_error;
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
