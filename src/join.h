// >>join branches ========================================================================
// join_branches(): zips and grafts.
//
// join_branches(): the boundary loops of the caller's surface are traced as the caps trace
// them (build_cap_graph, trace_boundary_loops: each loop in cap order, the boundary
// reversed), each side that parts is planned (its loops chosen, the trunk's loop split at
// the gaps), the triangles counted, then written. A side is seen turned half a turn about
// e1 when it is the side below, so that on both its branches lie above its cut and the
// trunk's loop in cap order runs the way the branches' boundary runs: each band is then
// the same zipper, whose triangles (a, a', b) and (a, b', b) run the trunk's loop in cap
// order and the branch's loop against its boundary.

#if !defined(STRATMESH_SMALL_CODE)
namespace stratmesh {
namespace detail {

// The most trunk triangles a graft looks at under one branch's loop (see plan_graft): its
// arrays are sized for them, not for the whole surface.
const size_t kGraftMaxTriangles = size_t{1} << 16;

// The small gaps in the trunk's end a graft may close (see plan_graft): at most
// kMostGapCorners vertices each, within kGapReach times the branch loop's reach of its
// centre, at most one a graft, so at most kMostGapTriangles triangles in all.
const double kGapReach = 1.5;

// A directed edge of a triangle under a branch's loop, and which of them it belongs to.
struct GraftEdge {
    uint32_t from, to, slot;
    bool operator<(const GraftEdge& o) const { return from != o.from ? from < o.from : to < o.to; }
    bool operator>(const GraftEdge& o) const { return o < *this; }
};

struct JoinMemory {
    CapLoop loops;  // only ids and starts
    uint32_t* gap_joins;  // per entry of loops.ids on a loop of at most kMostGapCorners: bit j
                          // set where its vertex and the loop's j-th are joined by an edge of
                          // the caller's surface (the diagonals a gap fill may not make)
    CapGraph graph;  // until the loops are traced; the grafts' arrays then take its memory
    uint32_t* hole_next;     // per point: its successor on a planned hole, kNoIndex if free,
                             // kHeldVertex where no hole may pass (the trunk's boundary)
    uint32_t* holes;         // the planned holes' loops, one after another
    unsigned char* removed;  // per triangle, the caller's then the filled: 1 where a
                             // planned hole takes it out
    uint32_t* filled;        // the triangles that closed gaps in the trunk's end, 3 each
    size_t filled_count;
    uint32_t* under;         // the triangles under the branch's loop being grafted
    GraftEdge* edges;        // 3 per triangle of `under`, sorted
    uint64_t* queue;         // hole edges to grow across, (from << 32) | to
    size_t under_capacity;
    size_t room;  // the arena's mark after the loops
};

const uint32_t kHeldVertex = kNoIndex - 1;

// The arena sequence of the call, shared with join_branches_workspace_size(): the loops,
// then the graph after them, then (allocate_grafts) once the loops are traced and the gaps'
// joins noted, the grafts' arrays in the graph's room.
static inline bool allocate_join(JoinMemory& m, size_t point_count, size_t triangle_count, Arena& arena) {
    m.loops.ids = arena.alloc<uint32_t>(point_count);  // every point on a loop at most
    m.loops.starts = arena.alloc<unsigned char>(point_count);
    m.gap_joins = arena.alloc<uint32_t>(point_count);
    m.room = arena.mark();
    allocate_cap_graph(m.graph, point_count, triangle_count, arena);
    return !arena.failed;
}

static inline bool allocate_grafts(JoinMemory& m, size_t point_count, size_t triangle_count, Arena& arena) {
    arena.rewind(m.room);
    m.under_capacity = triangle_count < kGraftMaxTriangles ? triangle_count : kGraftMaxTriangles;
    m.hole_next = arena.alloc<uint32_t>(point_count);
    m.holes = arena.alloc<uint32_t>(point_count);
    m.removed = arena.alloc<unsigned char>(triangle_count + kMostGapTriangles);
    m.filled = arena.alloc<uint32_t>(3 * kMostGapTriangles);
    m.filled_count = 0;
    m.under = arena.alloc<uint32_t>(m.under_capacity);
    m.edges = arena.alloc<GraftEdge>(3 * m.under_capacity);
    m.queue = arena.alloc<uint64_t>(2 * m.under_capacity + 3);
    return !arena.failed;
}

// A traced loop: its entries in CapLoop::ids, in cap order.
struct TracedLoop {
    const uint32_t* ids;
    uint32_t length;
};

// One side's junction: the trunk's loop, the branches' loops in their order around the
// trunk's centre, where each branch's loop opens (a position in cap order) and the trunk's
// vertex at the gap after each branch (a position on the trunk's loop).
struct SideJunction {
    TracedLoop trunk;
    uint32_t branches;
    TracedLoop branch[kMaxBranches];
    uint32_t opening[kMaxBranches];
    uint32_t gap[kMaxBranches];
    double centre[kMaxBranches][2];  // of each branch's loop, across the axis
    double sense;                    // +1 where the trunk's loop turns counter-clockwise

    size_t triangles() const {
        size_t total = trunk.length + 2 * static_cast<size_t>(branches) - 2;
        for (uint32_t i = 0; i < branches; ++i) total += branch[i].length;
        return total;
    }
};

// Frame coordinates of one side: the side below turned half a turn about e1.
struct SideView {
    const CloudReader& reader;
    const Frame& frame;
    double sign;  // +1 above, -1 below

    Local at(uint32_t id) const {
        const Local l = frame.local(reader.point(id));
        return {l.x, sign * l.y, sign * l.h};
    }
};

static inline double loop_mean_height(const TracedLoop& loop, const SideView& view) {
    double sum = 0;
    for (uint32_t i = 0; i < loop.length; ++i) sum += view.at(loop.ids[i]).h;
    return sum / loop.length;
}

// The label every point of the loop has, or kBeyondBranches where they differ.
static inline uint8_t loop_label(const TracedLoop& loop, const uint8_t* branch_of) {
    const uint8_t label = branch_of[loop.ids[0]];
    for (uint32_t i = 1; i < loop.length; ++i)
        if (branch_of[loop.ids[i]] != label) return kBeyondBranches;
    return label;
}

const double kJoinReach = 4;

// The loops a side's junction starts from: the trunk's highest (its points all kInTrunk;
// not `taken`, the trunk loop the other side joined) and each branch's lowest (ids null
// where a branch has none), with their mean heights in the view.
struct SideLoops {
    TracedLoop trunk;
    double trunk_height;
    TracedLoop branch[kMaxBranches];
    double branch_height[kMaxBranches];
};

static inline void find_side_loops(const CapLoop& loops, size_t entries, const uint8_t* branch_of,
                            uint8_t first_label, uint32_t branches, const SideView& view,
                            const uint32_t* taken, SideLoops& side) {
    side.trunk = {nullptr, 0};
    side.trunk_height = -DBL_MAX;
    for (uint32_t b = 0; b < branches; ++b) side.branch[b] = {nullptr, 0};
    for (size_t start = 0; start < entries;) {
        size_t end = start + 1;
        while (end < entries && loops.starts[end] == 0) ++end;
        const TracedLoop loop = {loops.ids + start, static_cast<uint32_t>(end - start)};
        const bool closed = loops.starts[start] == kLoopStart;
        start = end;
        if (!closed || loop.ids == taken) continue;
        const uint8_t label = loop_label(loop, branch_of);
        const double height = loop_mean_height(loop, view);
        if (label == kInTrunk) {
            if (height > side.trunk_height) {
                side.trunk_height = height;
                side.trunk = loop;
            }
        } else if (label >= first_label && label - first_label < static_cast<int>(branches)) {
            const uint32_t b = static_cast<uint32_t>(label - first_label);
            if (!side.branch[b].ids || height < side.branch_height[b]) {
                side.branch[b] = loop;
                side.branch_height[b] = height;
            }
        }
    }
}

// The trunk's loop seen across the axis: its centre, its mean radius, and the sense it
// turns in (+1 counter-clockwise).
struct TrunkCentre {
    double cx, cy, radius, sense;

    double angle(double x, double y) const { return std::atan2(sense * (y - cy), x - cx); }
};

static inline TrunkCentre trunk_centre(const TracedLoop& trunk, const SideView& view) {
    double cx = 0, cy = 0, area = 0;
    for (uint32_t i = 0; i < trunk.length; ++i) {
        const Local p = view.at(trunk.ids[i]);
        const Local q = view.at(trunk.ids[(i + 1) % trunk.length]);
        cx += p.x;
        cy += p.y;
        area += p.x * q.y - q.x * p.y;
    }
    cx /= trunk.length;
    cy /= trunk.length;
    double radius = 0;
    for (uint32_t i = 0; i < trunk.length; ++i) {
        const Local p = view.at(trunk.ids[i]);
        radius += std::sqrt((p.x - cx) * (p.x - cx) + (p.y - cy) * (p.y - cy));
    }
    radius /= trunk.length;
    return {cx, cy, radius, area < 0 ? -1.0 : 1.0};
}

// Adds the branch's loop to the side's, in the order of their angles around the trunk's
// centre (kept in branch_angle): its centre, and where it opens, its vertex nearest the
// trunk's centre. False (detail set) where its centre is not within the trunk's loop.
static inline bool add_rim_branch(const TracedLoop& loop, const SideView& view,
                           const TrunkCentre& trunk, SideJunction& side, double* branch_angle,
                           const char*& detail) {
    double bx = 0, by = 0, nearest = DBL_MAX;
    uint32_t opening = 0;
    for (uint32_t i = 0; i < loop.length; ++i) {
        const Local p = view.at(loop.ids[i]);
        bx += p.x;
        by += p.y;
        const double d = (p.x - trunk.cx) * (p.x - trunk.cx) + (p.y - trunk.cy) * (p.y - trunk.cy);
        if (d < nearest) {
            nearest = d;
            opening = i;
        }
    }
    bx /= loop.length;
    by /= loop.length;
    if ((bx - trunk.cx) * (bx - trunk.cx) + (by - trunk.cy) * (by - trunk.cy) >=
        trunk.radius * trunk.radius) {
        detail = "a branch's loop is not within the trunk's loop nearest it, across the axis "
                 "(a branch standing on a closed end, not on a rim around the branches)";
        return false;
    }
    const double a = trunk.angle(bx, by);
    uint32_t k = side.branches++;
    for (; k > 0 && branch_angle[k - 1] > a; --k) {
        branch_angle[k] = branch_angle[k - 1];
        side.branch[k] = side.branch[k - 1];
        side.opening[k] = side.opening[k - 1];
        side.centre[k][0] = side.centre[k - 1][0];
        side.centre[k][1] = side.centre[k - 1][1];
    }
    branch_angle[k] = a;
    side.branch[k] = loop;
    side.opening[k] = opening;
    side.centre[k][0] = bx;
    side.centre[k][1] = by;
    return true;
}

// The gap after each branch i: the trunk's vertex nearest in angle to the middle between
// branch i and the next one. False (detail set) where the gaps do not follow one another
// along the trunk's loop as the branches do.
static inline bool place_rim_gaps(const SideView& view, const TrunkCentre& centre,
                           const double* branch_angle, SideJunction& side, const char*& detail) {
    const TracedLoop& trunk = side.trunk;
    const double two_pi = 6.28318530717958647693;
    for (uint32_t i = 0; i < side.branches; ++i) {
        const uint32_t next = (i + 1) % side.branches;
        double span = branch_angle[next] - branch_angle[i];
        if (span <= 0) span += two_pi;
        const double middle = branch_angle[i] + span / 2;
        double nearest = DBL_MAX;
        for (uint32_t j = 0; j < trunk.length; ++j) {
            const Local p = view.at(trunk.ids[j]);
            const double off = std::fabs(std::remainder(centre.angle(p.x, p.y) - middle, two_pi));
            if (off < nearest) {
                nearest = off;
                side.gap[i] = j;
            }
        }
    }
    const uint32_t last = side.gap[side.branches - 1];
    uint32_t before = 0;
    for (uint32_t i = 0; i + 1 < side.branches; ++i) {
        const uint32_t along = (side.gap[i] + trunk.length - last) % trunk.length;
        if (along <= before) {
            detail = "the trunk's loop does not go around a side's branches in their order";
            return false;
        }
        before = along;
    }
    return true;
}

// Plans the rim junction of a side with `branches` branches, from its loops, with its cut
// and gap as heights of the view: false (detail set) if it cannot be joined so.
static inline bool plan_junction(const SideLoops& loops, uint32_t branches, double cut, double gap,
                          const SideView& view, SideJunction& side, const char*& detail) {
    side.trunk = loops.trunk;
    // Loops farther than kJoinReach gaps from the cut are not the junction's: a trunk
    // closed at the cut keeps only its far loop, a branch closed there only its tip's.
    auto near_cut = [&](double height) { return std::fabs(height - cut) <= kJoinReach * gap; };
    if (!side.trunk.ids || !near_cut(loops.trunk_height)) {
        detail = "the trunk has no boundary loop near the cut to join a side's branches to "
                 "(a trunk closed there: the branches stand on a closed end)";
        return false;
    }
    const TrunkCentre centre = trunk_centre(side.trunk, view);
    side.sense = centre.sense;
    double branch_angle[kMaxBranches];
    side.branches = 0;
    for (uint32_t b = 0; b < branches; ++b) {
        if (!loops.branch[b].ids || !near_cut(loops.branch_height[b])) continue;
        if (!add_rim_branch(loops.branch[b], view, centre, side, branch_angle, detail))
            return false;
    }
    if (side.branches < 2) {
        detail = "fewer than two of a side's branches have a boundary loop of their own";
        return false;
    }
    return place_rim_gaps(view, centre, branch_angle, side, detail);
}

// Angles around a centre across the axis, from the direction of a reference point, in
// [0, 2 pi), counter-clockwise where sense is +1.
struct AngleAround {
    const SideView& view;
    double cx, cy;
    Local reference;
    double sense;

    double operator()(uint32_t id) const {
        const Local q = view.at(id);
        const double rx = reference.x - cx, ry = reference.y - cy;
        const double dx = q.x - cx, dy = q.y - cy;
        const double t = std::atan2(sense * (rx * dy - ry * dx), rx * dx + ry * dy);
        return t < 0 ? t + 6.28318530717958647693 : t;
    }
};

// Writes the junction's side.triangles() triangles at out.
static inline void write_junction(const SideJunction& side, const SideView& view, uint32_t* out) {
    const TracedLoop& trunk = side.trunk;
    auto emit = [&out](uint32_t a, uint32_t b, uint32_t c) {
        out[0] = a;
        out[1] = b;
        out[2] = c;
        out += 3;
    };
    auto opening_point = [&](uint32_t i) { return side.branch[i].ids[side.opening[i]]; };
    for (uint32_t i = 0; i < side.branches; ++i) {
        // The trunk's arc from the gap before branch i to the gap after it, in cap order;
        // the branch's loop from its opening round to it again, against its cap order.
        const uint32_t from = side.gap[(i + side.branches - 1) % side.branches];
        const uint32_t steps = (side.gap[i] + trunk.length - from) % trunk.length;
        const TracedLoop& loop = side.branch[i];
        const uint32_t n = loop.length;
        auto a = [&](uint32_t j) { return trunk.ids[(from + j) % trunk.length]; };
        auto b = [&](uint32_t l) { return loop.ids[(side.opening[i] + n - l % n) % n]; };
        // Both chains in the order of their angle around the branch's centre, from the
        // opening on: a zipper by angle lays a band between two curves that go once around
        // a point in triangles that do not overlap, where shortest diagonals can fold.
        const AngleAround turn = {view, side.centre[i][0], side.centre[i][1], view.at(b(0)),
                                  side.sense};
        emit(a(0), b(1), b(0));
        uint32_t j = 0, l = 1;
        while (j < steps || l + 1 < n) {
            const bool along_trunk = l + 1 == n || (j < steps && turn(a(j + 1)) <= turn(b(l + 1)));
            if (along_trunk) {
                emit(a(j), a(j + 1), b(l));
                ++j;
            } else {
                emit(a(j), b(l + 1), b(l));
                ++l;
            }
        }
        emit(a(steps), b(n), b(n - 1));
    }
    // The crotch: a triangle per gap, and a fan over the openings where three or more meet.
    for (uint32_t i = 0; i < side.branches; ++i)
        emit(opening_point(i), trunk.ids[side.gap[i]], opening_point((i + 1) % side.branches));
    for (uint32_t i = 1; i + 1 < side.branches; ++i)
        emit(opening_point(0), opening_point(i), opening_point(i + 1));
}

// ---- grafts ----
//
// A branch standing on a closed end of the trunk (horns on a skull) has no trunk loop
// around it: the trunk's mesh runs over the stump under the branch's loop instead. It is
// grafted: the trunk's triangles under the loop that face the branch are taken out as a
// disc (grown from the one nearest the loop's centre across the edges they share, each
// triangle added bringing a vertex new to the disc, so every vertex keeps a triangle of
// the trunk and the hole's loop is simple), and the hole's loop is zipped to the branch's
// by angle around the branch's centre, as the rim junction zips its arcs. "Under" is seen
// along the axis: the triangle's centroid inside the branch's loop and at most kJoinReach
// gaps below its mean height, its normal within acos(kGraftFacing) of the axis; the hole
// never reaches a vertex of the trunk's boundary nor one of another hole, so the surface
// stays an oriented edge- and vertex-manifold. The trunk's end under a fork is meshed
// across its open top (the pole projection of a closed end), with long triangles and at
// times a small gap; where a gap's vertex is a corner of the triangle under the branch's
// centre, the disc cannot cover the centre. Then the gap is closed (fill_gap) and the
// hole planned again: of 216 axes tilted 0.1 to 15 degrees every way from the trunk of
// the tests' Y, 15 fell back to one tube that way before, none since. Refused (the
// branch left apart) where no such triangle is free, where more than kGraftMaxTriangles
// are under the loop, or where the hole or the branch's loop does not go once around the
// branch's centre in the sense a junction's do.

const double kGraftFacing = 0.25;

struct Graft {
    TracedLoop hole;    // in the direction of the triangles it replaces (in JoinMemory::holes)
    TracedLoop branch;  // in cap order
    double centre[2];
    double side;        // the view's sign: +1 above the cut, -1 below
    size_t removed;     // the trunk's triangles the hole takes out

    size_t triangles() const { return static_cast<size_t>(hole.length) + branch.length; }
};

// How many times the loop winds around (x, y) across the axis, counter-clockwise positive.
static inline long loop_winding(const TracedLoop& loop, const SideView& view, double x, double y) {
    const double p[2] = {x, y};
    auto corner = [&](uint32_t i) {
        const Local q = view.at(loop.ids[i]);
        return Point2{{q.x, q.y}};
    };
    return winding_number(corner, loop.length, p);
}

// The trunk's triangles a graft reads: the caller's, `count` of them, then those that
// closed small gaps in the trunk's end (m.filled, see fill_gap).
static inline const uint32_t* trunk_corners(const uint32_t* tri, size_t count, const JoinMemory& m,
                                     size_t t) {
    return t < count ? tri + 3 * t : m.filled + 3 * (t - count);
}

// The first of the sorted edges m.edges[0 .. 3 * found) not below key.
static inline size_t first_edge_from(const JoinMemory& m, size_t found, const GraftEdge& key) {
    size_t lo = 0, hi = 3 * found;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (m.edges[mid] < key) lo = mid + 1; else hi = mid;
    }
    return lo;
}

// Grows a hole from its edges queued in m.queue[0 .. queued) (from << 32 | to, with
// m.hole_next[from] == to) across the triangles m.under[0 .. found) (their edges sorted in
// m.edges): a triangle (x, y, z) beyond the hole's edge y -> x joins when z is free, and the
// loop then runs y -> z -> x, so every vertex stays on the loop and keeps a triangle of the
// trunk. Returns the triangles taken (marked in m.removed).
static inline size_t grow_hole(const uint32_t* tri, size_t count, JoinMemory& m, size_t found,
                        size_t queued) {
    uint32_t* next = m.hole_next;
    size_t taken = 0;
    for (size_t head = 0; head < queued; ++head) {
        const uint32_t y = static_cast<uint32_t>(m.queue[head] >> 32);
        const uint32_t x = static_cast<uint32_t>(m.queue[head]);
        if (next[y] != x) continue;
        for (size_t lo = first_edge_from(m, found, {x, y, 0}); lo < 3 * found && m.edges[lo].from == x && m.edges[lo].to == y; ++lo) {
            const uint32_t t = m.under[m.edges[lo].slot];
            const uint32_t* c = trunk_corners(tri, count, m, t);
            const uint32_t z = c[0] ^ c[1] ^ c[2] ^ x ^ y;
            if (m.removed[t] || next[z] != kNoIndex) continue;
            next[y] = z;
            next[z] = x;
            m.removed[t] = 1;
            ++taken;
            m.queue[queued++] = (uint64_t{y} << 32) | z;
            m.queue[queued++] = (uint64_t{z} << 32) | x;
            break;
        }
    }
    return taken;
}

// Whether vertex v is a corner of one of m.under[0 .. found), whose edges m.edges holds sorted.
static inline bool corner_under(const JoinMemory& m, size_t found, uint32_t v) {
    const size_t lo = first_edge_from(m, found, {v, 0, 0});
    return lo < 3 * found && m.edges[lo].from == v;
}

// A small gap in the trunk's end beside a branch's stump: a closed boundary loop of the
// trunk of at most kMostGapCorners vertices, each held by no hole, within `reach` of (cx, cy)
// across the axis and within [low, high] along it, one of them a corner of a triangle
// under the branch; the one nearest (cx, cy), {nullptr, 0} if none.
static inline TracedLoop gap_beside(const JoinMemory& m, size_t entries, size_t found,
                             const uint8_t* branch_of, const SideView& view, double cx,
                             double cy, double reach, double low, double high) {
    TracedLoop best = {nullptr, 0};
    double nearest = DBL_MAX;
    for (size_t start = 0; start < entries;) {
        size_t end = start + 1;
        while (end < entries && m.loops.starts[end] == 0) ++end;
        const TracedLoop loop = {m.loops.ids + start, static_cast<uint32_t>(end - start)};
        const bool closed = m.loops.starts[start] == kLoopStart;
        start = end;
        if (!closed || loop.length < 3 || loop.length > kMostGapCorners) continue;
        bool near = true, touches = false;
        double x = 0, y = 0;
        for (uint32_t i = 0; i < loop.length && near; ++i) {
            const uint32_t v = loop.ids[i];
            const Local p = view.at(v);
            near = branch_of[v] == kInTrunk && m.hole_next[v] == kHeldVertex && p.h >= low &&
                   p.h <= high && (p.x - cx) * (p.x - cx) + (p.y - cy) * (p.y - cy) <= reach * reach;
            touches = touches || corner_under(m, found, v);
            x += p.x / loop.length;
            y += p.y / loop.length;
        }
        const double d = (x - cx) * (x - cx) + (y - cy) * (y - cy);
        if (near && touches && d < nearest) {
            nearest = d;
            best = loop;
        }
    }
    return best;
}

static_assert(kMostGapCorners <= 32, "a gap's joins are bits of 32");

// Notes in m.gap_joins, from the graph, which vertices of each loop small enough to be a
// gap are joined by an edge of the caller's surface: the graph keeps the edges between
// boundary vertices, and its memory goes to the grafts.
static inline void note_gap_joins(JoinMemory& m, size_t entries) {
    for (size_t start = 0; start < entries;) {
        size_t end = start + 1;
        while (end < entries && m.loops.starts[end] == 0) ++end;
        const uint32_t* ids = m.loops.ids + start;
        for (size_t i = 0; end - start <= kMostGapCorners && i < end - start; ++i) {
            uint32_t joins = 0;
            for (size_t j = 0; j < end - start; ++j)
                if (m.graph.has_edge(ids[i], ids[j])) joins |= uint32_t{1} << j;
            m.gap_joins[start + i] = joins;
        }
        start = end;
    }
}

// A gap's ears: no diagonal that is an edge of the caller's surface (see note_gap_joins);
// each ear a triangle of m.filled.
class GapEars final : public EarRules {
public:
    GapEars(const uint32_t* ids, const uint32_t* joins, JoinMemory& m)
        : ids_(ids), joins_(joins), m_(m) {}

private:
    bool forbidden(uint32_t a, uint32_t b) const override { return ((joins_[a] >> b) & 1) != 0; }

    void take(uint32_t p, uint32_t v, uint32_t n) override {
        uint32_t* out = m_.filled + 3 * m_.filled_count++;
        out[0] = ids_[p];
        out[1] = ids_[v];
        out[2] = ids_[n];
    }

    const uint32_t* ids_;
    const uint32_t* joins_;
    JoinMemory& m_;
};

// Closes the gap `loop` (in cap order) with triangles in m.filled, by ears clipped in the
// view, each from the first corner left, and frees its vertices for the holes; false
// (nothing added) where the loop is no simple polygon turning counter-clockwise in the view
// (the way the triangles facing a branch turn) or no ear is left whose diagonal is not an
// edge of the surface. count: the caller's triangles, which m.removed numbers first.
static inline bool fill_gap(size_t count, const TracedLoop& loop, const SideView& view, JoinMemory& m) {
    const uint32_t n = loop.length;
    if (m.filled_count + (n - 2) > kMostGapTriangles) return false;
    double xy[2 * kMostGapCorners] = {};
    for (uint32_t i = 0; i < n; ++i) {
        const Local p = view.at(loop.ids[i]);
        xy[2 * i] = p.x;
        xy[2 * i + 1] = p.y;
    }
    uint64_t sweep[kMostGapCorners];
    if (!polygon_is_simple(xy, n, sweep) || !(simple_polygon_turn(xy, n) > 0)) return false;
    uint32_t prev[kMostGapCorners], next[kMostGapCorners], reflex[kMostGapCorners];
    unsigned char flags[kMostGapCorners];
    const size_t first = m.filled_count;
    GapEars ears(loop.ids, m.gap_joins + (loop.ids - m.loops.ids), m);
    EarClipper clipper(xy, n, {prev, next, reflex, flags});
    if (!clipper.clip(0, EarWalk::from_first, ears)) {
        m.filled_count = first;
        return false;
    }
    for (size_t f = first; f < m.filled_count; ++f) m.removed[count + f] = 0;
    for (uint32_t i = 0; i < n; ++i) m.hole_next[loop.ids[i]] = kNoIndex;
    return true;
}

// Where a branch's loop stands in the view: its centre across the axis, the square of its
// reach from there, and the heights a trunk triangle's centroid under it may have.
struct GraftSite {
    double cx, cy, reach, low, high;
};

// The site of the branch's loop, within kJoinReach gaps below its mean height and one gap
// above; false (detail set) where the loop does not go once around its centre.
static inline bool graft_site(const TracedLoop& loop, double gap, const SideView& view,
                       GraftSite& site, const char*& detail) {
    double cx = 0, cy = 0, height = 0;
    for (uint32_t i = 0; i < loop.length; ++i) {
        const Local p = view.at(loop.ids[i]);
        cx += p.x;
        cy += p.y;
        height += p.h;
    }
    cx /= loop.length;
    cy /= loop.length;
    height /= loop.length;
    // In cap order a branch's loop turns clockwise seen from the branch (its cap would face
    // away from it), once around its centre.
    if (loop_winding(loop, view, cx, cy) != -1) {
        detail = "a branch's loop does not go once around its centre, seen along the axis";
        return false;
    }
    double reach = 0;
    for (uint32_t i = 0; i < loop.length; ++i) {
        const Local p = view.at(loop.ids[i]);
        const double d = (p.x - cx) * (p.x - cx) + (p.y - cy) * (p.y - cy);
        if (d > reach) reach = d;
    }
    site = {cx, cy, reach, height - kJoinReach * gap, height + gap};
    return true;
}

// Collects in m.under[0 .. found) the trunk's triangles under the branch's loop that face
// it (see "grafts" above) and no planned hole takes; false (detail set) if there are more
// than m.under holds.
static inline bool find_under(const uint32_t* tri, size_t count, const uint8_t* branch_of,
                       const TracedLoop& loop, const SideView& view, const GraftSite& site,
                       JoinMemory& m, size_t& found, const char*& detail) {
    found = 0;
    for (size_t t = 0; t < count + m.filled_count; ++t) {
        const uint32_t* c = trunk_corners(tri, count, m, t);
        if (m.removed[t] || c[0] == c[1] || c[1] == c[2] || c[2] == c[0]) continue;
        if (branch_of[c[0]] != kInTrunk || branch_of[c[1]] != kInTrunk ||
            branch_of[c[2]] != kInTrunk)
            continue;
        const Local a = view.at(c[0]), b = view.at(c[1]), d = view.at(c[2]);
        const double gx = (a.x + b.x + d.x) / 3, gy = (a.y + b.y + d.y) / 3;
        const double gh = (a.h + b.h + d.h) / 3;
        if (gh < site.low || gh > site.high) continue;
        if ((gx - site.cx) * (gx - site.cx) + (gy - site.cy) * (gy - site.cy) > site.reach) continue;
        const Vec3 normal = cross({b.x - a.x, b.y - a.y, b.h - a.h}, {d.x - a.x, d.y - a.y, d.h - a.h});
        if (!(normal.z > kGraftFacing * std::sqrt(dot(normal, normal)))) continue;
        // Odd: inside by the even-odd rule.
        if (loop_winding(loop, view, gx, gy) % 2 == 0) continue;
        if (found == m.under_capacity) {
            detail = "more of the trunk's triangles lie under a branch's loop than a graft "
                     "takes (kGraftMaxTriangles)";
            return false;
        }
        m.under[found++] = static_cast<uint32_t>(t);
    }
    return true;
}

// The position in m.under[0 .. found) of the triangle nearest the site's centre whose
// corners no hole holds; found if there is none.
static inline size_t hole_seed(const uint32_t* tri, size_t count, const JoinMemory& m, size_t found,
                        const SideView& view, const GraftSite& site) {
    size_t seed = found;
    double nearest = DBL_MAX;
    for (size_t k = 0; k < found; ++k) {
        const uint32_t* c = trunk_corners(tri, count, m, m.under[k]);
        if (m.hole_next[c[0]] != kNoIndex || m.hole_next[c[1]] != kNoIndex ||
            m.hole_next[c[2]] != kNoIndex)
            continue;
        const Local a = view.at(c[0]), b = view.at(c[1]), d = view.at(c[2]);
        const double gx = (a.x + b.x + d.x) / 3 - site.cx, gy = (a.y + b.y + d.y) / 3 - site.cy;
        if (gx * gx + gy * gy < nearest) {
            nearest = gx * gx + gy * gy;
            seed = k;
        }
    }
    return seed;
}

enum class HolePlan { cut, refused, missed_centre };

// Plans the hole under the branch's loop: the disc grown from the seed across the
// triangles under it, its loop written at `hole` and kept in graft.hole, its triangles in
// graft.removed. Refused (detail set, nothing taken) where no triangle is there to take;
// missed_centre where the disc does not go once around the site's centre. found: the
// triangles under the loop, for gap_beside.
static inline HolePlan plan_hole(const uint32_t* tri, size_t count, const uint8_t* branch_of,
                          const TracedLoop& loop, const SideView& view, const GraftSite& site,
                          JoinMemory& m, uint32_t* hole, size_t& found, Graft& graft,
                          const char*& detail) {
    if (!find_under(tri, count, branch_of, loop, view, site, m, found, detail))
        return HolePlan::refused;
    const size_t seed = hole_seed(tri, count, m, found, view, site);
    if (seed == found) {
        detail = "no triangle of the trunk under a branch's loop faces it (and is free to take)";
        return HolePlan::refused;
    }
    for (size_t k = 0; k < found; ++k)
        for (size_t e = 0; e < 3; ++e) {
            const uint32_t* c = trunk_corners(tri, count, m, m.under[k]);
            m.edges[3 * k + e] = {c[e], c[(e + 1) % 3], static_cast<uint32_t>(k)};
        }
    heap_sort(m.edges, 3 * found);
    uint32_t* next = m.hole_next;
    const uint32_t* first = trunk_corners(tri, count, m, m.under[seed]);
    for (size_t e = 0; e < 3; ++e) {
        next[first[e]] = first[(e + 1) % 3];
        m.queue[e] = (uint64_t{first[e]} << 32) | first[(e + 1) % 3];
    }
    m.removed[m.under[seed]] = 1;
    graft.removed = 1 + grow_hole(tri, count, m, found, 3);
    const uint32_t length = static_cast<uint32_t>(graft.removed + 2);
    hole[0] = first[0];
    for (uint32_t i = 1; i < length; ++i) hole[i] = next[hole[i - 1]];
    graft.hole = {hole, length};
    if (loop_winding(graft.hole, view, site.cx, site.cy) == 1) return HolePlan::cut;
    for (uint32_t i = 0; i < length; ++i) next[hole[i]] = kNoIndex;
    for (size_t k = 0; k < found; ++k) m.removed[m.under[k]] = 0;
    detail = "the hole under a branch's loop does not go once around the branch's centre";
    return HolePlan::missed_centre;
}

// Plans the graft of the branch whose loop (nearest the cut) is `loop`, taking the hole's
// triangles out in m.removed and its vertices in m.hole_next, its loop appended to m.holes
// at holes_used; false (nothing taken, detail set) if it cannot be grafted. tri: the
// caller's `count` triangles; entries: the count of m.loops' ids.
static inline bool plan_graft(const uint32_t* tri, size_t count, const uint8_t* branch_of,
                       const TracedLoop& loop, double gap, const SideView& view, JoinMemory& m,
                       size_t entries, size_t& holes_used, Graft& graft, const char*& detail) {
    GraftSite site;
    if (!graft_site(loop, gap, view, site, detail)) return false;
    uint32_t* hole = m.holes + holes_used;
    size_t found = 0;
    HolePlan plan = plan_hole(tri, count, branch_of, loop, view, site, m, hole, found, graft, detail);
    // A disc with no vertex inside never takes a triangle with a corner it may not take.
    // Where such a corner is on a small gap in the trunk's end beside the stump (an end
    // meshed across a fork's open top keeps some among its long triangles) and that
    // triangle covers the branch's centre, the hole misses the centre: the gap is closed
    // and the hole planned again, free to take that triangle now.
    if (plan == HolePlan::missed_centre) {
        const TracedLoop beside =
            gap_beside(m, entries, found, branch_of, view, site.cx, site.cy,
                       kGapReach * std::sqrt(site.reach), site.low, site.high);
        const size_t filled_before = m.filled_count;
        if (beside.ids && fill_gap(count, beside, view, m)) {
            plan = plan_hole(tri, count, branch_of, loop, view, site, m, hole, found, graft, detail);
            if (plan != HolePlan::cut) {
                m.filled_count = filled_before;
                for (uint32_t i = 0; i < beside.length; ++i) m.hole_next[beside.ids[i]] = kHeldVertex;
            }
        }
    }
    if (plan != HolePlan::cut) return false;
    holes_used += graft.hole.length;
    graft.branch = loop;
    graft.centre[0] = site.cx;
    graft.centre[1] = site.cy;
    graft.side = view.sign;
    return true;
}

// Writes the graft's graft.triangles() triangles at out: the hole's loop, counter-clockwise
// from its vertex first in angle after the branch loop's first vertex, and the branch's loop
// against its cap order, merged by angle around the branch's centre.
static inline void write_graft(const Graft& graft, const SideView& view, uint32_t* out) {
    const uint32_t m = graft.hole.length, n = graft.branch.length;
    const uint32_t* branch = graft.branch.ids;
    const AngleAround turn = {view, graft.centre[0], graft.centre[1], view.at(branch[0]), 1.0};
    uint32_t start = 0;
    for (uint32_t i = 1; i < m; ++i)
        if (turn(graft.hole.ids[i]) < turn(graft.hole.ids[start])) start = i;
    auto a = [&](uint32_t j) { return graft.hole.ids[(start + j) % m]; };
    auto b = [&](uint32_t l) { return branch[(n - l % n) % n]; };
    const double two_pi = 6.28318530717958647693;
    auto hole_turn = [&](uint32_t j) { return j == m ? two_pi + turn(a(0)) : turn(a(j)); };
    auto branch_turn = [&](uint32_t l) { return l == n ? two_pi : turn(b(l)); };
    auto emit = [&out](uint32_t p, uint32_t q, uint32_t r) {
        out[0] = p;
        out[1] = q;
        out[2] = r;
        out += 3;
    };
    for (uint32_t j = 0, l = 0; j < m || l < n;) {
        if (l == n || (j < m && hole_turn(j + 1) <= branch_turn(l + 1))) {
            emit(a(j), a(j + 1), b(l));
            ++j;
        } else {
            emit(a(j), b(l + 1), b(l));
            ++l;
        }
    }
}

// The caller's input as join_branches() plans from it: the surface's triangles in the
// cloud's indices, the labels, the frame along the parting's axis, the traced loops'
// entries (in JoinMemory::loops).
struct JoinInput {
    const CloudReader& reader;
    const Frame& frame;
    const Parting& parting;
    const uint32_t* triangles;
    size_t given;
    const uint8_t* branch_of;
    size_t entries;
};

// What join_branches() plans before it writes: each side's rim junction, or the grafts of
// its branches; the triangles they need in all.
struct JoinPlan {
    SideJunction junction[2];
    bool rim[2] = {false, false};
    Graft grafts[2 * kMaxBranches];
    uint32_t graft_count = 0;
    size_t holes_used = 0, removed = 0, needed = 0;
    const uint32_t* taken = nullptr;  // the trunk loop a side's rim joined: not the other's
};

// Plans side k (0 above the cut, 1 below) with `branches` branches: its rim junction where
// a trunk loop goes around them, else a graft for each branch where it stands; counts the
// side into r.
static inline void plan_side(int k, uint32_t branches, const JoinInput& in, JoinMemory& m,
                      JoinPlan& plan, JoinReport& r) {
    const SideView view = {in.reader, in.frame, k == 0 ? 1.0 : -1.0};
    const uint8_t first = static_cast<uint8_t>(k == 0 ? kFirstAboveBranch : kFirstBelowBranch);
    const double cut = (k == 0 ? in.parting.above : in.parting.below) -
                       dot(in.frame.origin, in.frame.axis);
    const double gap = in.parting.gap * in.frame.scale;
    SideLoops loops;
    find_side_loops(m.loops, in.entries, in.branch_of, first, branches, view, plan.taken, loops);
    const char* rim_why = nullptr;  // superseded by the grafts' reasons
    plan.rim[k] = plan_junction(loops, branches, view.sign * cut * in.frame.scale, gap, view,
                                plan.junction[k], rim_why);
    if (plan.rim[k]) {
        plan.taken = plan.junction[k].trunk.ids;
        plan.needed += plan.junction[k].triangles();
        ++r.joined_side_count;
        return;
    }
    // No rim goes around the branches: each is grafted where it stands on the trunk.
    uint32_t grafted = 0;
    for (uint32_t b = 0; b < branches; ++b) {
        const char* graft_why = nullptr;
        Graft& graft = plan.grafts[plan.graft_count];
        if (!loops.branch[b].ids) {
            graft_why = "a branch has no boundary loop of its own to join";
        } else if (plan_graft(in.triangles, in.given, in.branch_of, loops.branch[b], gap, view,
                              m, in.entries, plan.holes_used, graft, graft_why)) {
            plan.needed += graft.triangles();
            plan.removed += graft.removed;
            ++plan.graft_count;
            ++grafted;
            continue;
        }
        if (!r.detail) r.detail = graft_why;
    }
    r.grafted_branch_count += grafted;
    if (grafted == branches)
        ++r.joined_side_count;
    else
        ++r.apart_side_count;
}

// Writes the plan over the caller's triangles: those the holes take out gone, then the
// gaps' triangles, the rims' and the grafts'; counts into r; returns the triangles in all.
static inline size_t write_join(const JoinInput& in, const JoinMemory& m, const JoinPlan& plan,
                         uint32_t* triangles, JoinReport& r) {
    size_t kept = 0;
    for (size_t t = 0; t < in.given; ++t) {
        if (m.removed[t]) continue;
        if (kept != t)
            for (size_t e = 0; e < 3; ++e) triangles[3 * kept + e] = triangles[3 * t + e];
        ++kept;
    }
    r.removed_triangle_count = in.given - kept;
    uint32_t* out = triangles + 3 * kept;
    for (size_t f = 0; f < m.filled_count; ++f) {
        if (m.removed[in.given + f]) continue;
        for (size_t e = 0; e < 3; ++e) out[e] = m.filled[3 * f + e];
        out += 3;
        ++r.junction_triangle_count;
    }
    for (int k = 0; k < 2; ++k) {
        if (!plan.rim[k]) continue;
        const SideView view = {in.reader, in.frame, k == 0 ? 1.0 : -1.0};
        write_junction(plan.junction[k], view, out);
        out += 3 * plan.junction[k].triangles();
        r.junction_triangle_count += plan.junction[k].triangles();
    }
    for (uint32_t g = 0; g < plan.graft_count; ++g) {
        const SideView view = {in.reader, in.frame, plan.grafts[g].side};
        write_graft(plan.grafts[g], view, out);
        out += 3 * plan.grafts[g].triangles();
        r.junction_triangle_count += plan.grafts[g].triangles();
    }
    return kept + r.junction_triangle_count;
}

// join_branches()'s checks of the points and the triangles: ok, or a status with
// checks.detail set.
static inline Status check_join_input(const CloudReader& reader, size_t point_count,
                               const CloudSums& sums, const Options& options,
                               const uint32_t* triangles, size_t given, Report& checks) {
    const Status status = reject_invalid_points(reader, point_count, sums, options, checks);
    if (status != Status::ok) return status;
    for (size_t k = 0; k < 3 * given; ++k)
        if (triangles[k] >= point_count || !reader.valid(triangles[k])) {
            checks.detail = "a triangle names a point outside the cloud, or an invalid one";
            return Status::invalid_argument;
        }
    return Status::ok;
}

// The frame join_branches() sees the sides in: along the parting's axis.
static inline Status join_frame(const CloudSums& sums, const Options& options, const Parting& parting,
                         Frame& frame) {
    Options along = options;
    along.axis = Axis::direction;
    along.flags &= ~static_cast<uint32_t>(origin_given);
    for (int k = 0; k < 3; ++k) along.direction[k] = parting.axis[k];
    return choose_frame(sums, along, frame);
}

}  // namespace detail
}  // namespace stratmesh

namespace stratmesh {

size_t join_branches_workspace_size(size_t point_count, size_t triangle_count) {
    if (point_count > detail::kMaxPoints - 1) return 0;
    detail::Arena arena = detail::Arena::measuring();
    detail::JoinMemory m;
    detail::allocate_join(m, point_count, triangle_count, arena);
    detail::allocate_grafts(m, point_count, triangle_count, arena);
    return arena.failed ? 0 : arena.required_bytes();
}

size_t join_branches_max_triangles(size_t point_count) {
    return point_count + 4 * static_cast<size_t>(kMaxBranches) + kMostGapTriangles;
}

Status join_branches(const Cloud& cloud, const Options& options, const Parting& parting,
                     const uint8_t* branch_of, void* workspace, size_t workspace_bytes,
                     uint32_t* triangles, size_t triangle_capacity, size_t* triangle_count,
                     JoinReport* report) {
    using namespace detail;
    const bool countable = cloud.count <= kMaxPoints - 1;
    const ByteRange buffers[] = {
        countable ? cloud_bytes(cloud) : ByteRange{0, 0},
        byte_range(workspace, workspace_bytes),
        byte_range(triangles, saturating_product(triangle_capacity, 3 * sizeof(uint32_t))),
        byte_range(triangle_count, sizeof(size_t)),
        byte_range(report, sizeof(JoinReport)),
        byte_range(branch_of, countable ? cloud.count : 0)};
    if (any_overlap(buffers, 6)) return Status::invalid_argument;
    JoinReport r = {0, 0, 0, 0, 0, 0, nullptr};
    Report checks = {};
    Arena arena = Arena::over(workspace, workspace_bytes);
    const size_t given = triangle_count ? *triangle_count : 0;
    size_t needed = given;
    auto finish = [&](Status status) {
        r.workspace_used_bytes = arena.peak_from_buffer();
        if (!r.detail) r.detail = checks.detail;
        if (report) *report = r;
        if (status == Status::triangle_capacity) *triangle_count = needed;
        return status;
    };
    Status status = check_reconstruct_arguments(cloud, triangles, triangle_capacity,
                                                triangle_count, workspace, checks);
    if (status != Status::ok) return finish(status);
    if (const char* refusal = options_refusal(options)) {
        checks.detail = refusal;
        return finish(Status::invalid_argument);
    }
    if (given > triangle_capacity || (cloud.count > 0 && !branch_of)) {
        checks.detail = given > triangle_capacity ? "triangle_count is above triangle_capacity"
                                                  : "branch_of is null";
        return finish(Status::invalid_argument);
    }
    const CloudReader reader = reader_of(cloud);
    const CloudSums sums = sum_cloud(reader, cloud.count);
    status = check_join_input(reader, cloud.count, sums, options, triangles, given, checks);
    if (status != Status::ok) return finish(status);
    Frame frame;
    status = join_frame(sums, options, parting, frame);
    if (status != Status::ok) return finish(status);
    const uint32_t sides[2] = {parting.above_branch_count < kMaxBranches ? parting.above_branch_count : kMaxBranches,
                               parting.below_branch_count < kMaxBranches ? parting.below_branch_count : kMaxBranches};
    if (given == 0 || (sides[0] == 0 && sides[1] == 0)) return finish(Status::ok);
    JoinMemory m;
    if (!allocate_join(m, cloud.count, given, arena)) {
        checks.detail = "the workspace is smaller than join_branches_workspace_size()";
        return finish(Status::out_of_memory);
    }
    build_cap_graph(triangles, given, cloud.count, m.graph);
    size_t entries = 0;
    trace_boundary_loops(m.graph, cloud.count, m.loops, &entries);
    note_gap_joins(m, entries);
    if (!allocate_grafts(m, cloud.count, given, arena)) {
        checks.detail = "the workspace is smaller than join_branches_workspace_size()";
        return finish(Status::out_of_memory);
    }
    std::memset(m.hole_next, 0xFF, sizeof(uint32_t) * cloud.count);
    for (size_t i = 0; i < entries; ++i) m.hole_next[m.loops.ids[i]] = kHeldVertex;
    std::memset(m.removed, 0, given);
    const JoinInput in = {reader, frame, parting, triangles, given, branch_of, entries};
    JoinPlan plan;
    plan.needed = given;
    for (int k = 0; k < 2; ++k)
        if (sides[k] != 0) plan_side(k, sides[k], in, m, plan, r);
    needed = plan.needed + m.filled_count - plan.removed;
    if (needed > triangle_capacity) return finish(Status::triangle_capacity);
    *triangle_count = write_join(in, m, plan, triangles, r);
    return finish(Status::ok);
}

}  // namespace stratmesh

#endif  // STRATMESH_SMALL_CODE
