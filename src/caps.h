// >>caps =================================================================================
// Closing a boundary loop: pockets, lowered caps, fins.
//
// With the add_caps flag, each boundary loop of the final surface is closed by a cap
// made of triangles over the loop's own vertices. The loop is triangulated in its
// projection across the axis: first checked to be a simple polygon (a sweep over its edges
// sorted by x, exact orient2d), then ear clipping (see the polygon section), then flips of
// the cap's diagonals. A triangulation of a simple polygon lifts to a surface that is a
// graph over it, so the cap's triangles cannot cross one another; but they can cross the
// wall where it leans over the cap near a ragged loop (a bust's shoulders, the noisy end
// of a scan). So the flips make the bottom cap as low as the loop allows and the top cap
// as high: a diagonal is flipped when the other one, with every vertex at its height along
// the axis, lies more than kCapHeightTie below it (above, on the top cap): the lower or
// upper envelope of the loop, where the quadrilaterals allow. On ties (a planar loop, a CT
// contour) the Delaunay criterion decides, so planar caps are the constrained Delaunay
// triangulation (ear clipping alone leaves slivers). Delaunay caps alone cross a wall
// leaning over a ragged loop several times as often. The flips are bounded
// (kCapFlipsPerCorner per loop vertex): any triangulation of the polygon is valid, so
// stopping early only leaves a cap less low. STRATMESH_SMALL_CODE leaves the heights out:
// Delaunay caps.
//
// Each cap triangle runs the loop's edges against the surface's direction, so the closed
// surface stays consistently oriented (the bottom cap faces -axis, the top one +axis). A
// diagonal that is already an edge of the surface would join three triangles: ears and
// flips that would make one are skipped. Where the wall has fins (triangles with two edges
// on the loop: a scan rounded to a grid makes them), the fin's middle corner has no way
// into the cap but a diagonal to a corner it sees across the loop, which ear clipping
// never makes; so a loop that no clipping closes, of at most kCapSearchCorners corners, is
// searched exhaustively (search_cap). Where fins leave no cap at all, the wall's edges under
// them may be flipped (see "fins flipped out of the way" below). A loop whose projection
// is not simple, or that none of these closes, stays open.
//
// The loops of a star-shaped layer run monotonically in angle around its centre (see the
// unroll section), so their projections are simple but for rounding or the safety net's
// removals.

namespace stratmesh {
namespace detail {

// Heights closer than this to a plane count as on it (frame units: the frame scales the
// cloud to an extent of about 1). A planar loop turned into the frame by a tilted axis gets
// heights that differ by rounding: those are ties, for the Delaunay criterion.
const double kCapHeightTie = 0x1p-40;

// How far d lies below the plane through a, b and w (counter-clockwise across the axis),
// each at its height (heights: a's, b's, w's, d's): the plane's height at d's place, the
// heights weighted by the triangles d makes with the opposite edges, less d's own.
static inline double depth_below_plane(const double* a, const double* b, const double* w,
                                const double* d, const double* heights) {
    auto orient = [d](const double* p, const double* q) {
        return (p[0] - d[0]) * (q[1] - d[1]) - (p[1] - d[1]) * (q[0] - d[0]);
    };
    double oa = orient(b, w), ob = orient(w, a), ow = orient(a, b);
    return ((heights[0] - heights[3]) * oa + (heights[1] - heights[3]) * ob +
            (heights[2] - heights[3]) * ow) /
           (oa + ob + ow);
}

const uint32_t kCapFlipsPerCorner = 64;

// A cap triangle's flag while flipping: on the stack of those to check.
const unsigned char kQueued = 4;

// Ear clipping is greedy: where the surface holds some of a loop's diagonals (its
// triangles with three corners on the loop), the ears taken first can leave a remainder
// whose every ear would repeat one, where another order would not (the bundled bust's
// neck loop, whose single layer's loops are peeled: 6 corners left of 249). So a failed
// clipping starts again from other corners, kCapEarStarts spread around the loop in all
// (see the configuration; 1 with STRATMESH_SMALL_CODE).

// Triangulates one loop, already checked simple and counter-clockwise. ids: the loop's
// vertices, whose diagonals must not be edges of the surface; lower: the cap is a bottom
// one (it faces -axis), to be made as low as the loop allows (a top one as high). Returns
// false if no ear is left (every one would repeat an edge of the surface).
class CapTriangulation final : public EarRules {
public:
    CapTriangulation(CapLoop& c, const uint32_t* ids, uint32_t length, const CapGraph& g,
                     bool lower)
        : c_(c), ids_(ids), length_(length), g_(g), lower_(lower) {}

    // Ear clipping from kCapEarStarts corners, then the search; false if neither closes.
    bool triangulate() {
        for (uint32_t k = 0; k < kCapEarStarts; ++k)
            if (clip_ears(static_cast<uint32_t>(uint64_t{k} * length_ / kCapEarStarts))) return true;
        return kCapSearchCorners > 0 && search_cap();
    }

    // From now on the chords of the fins marked in `fins` (per position, kFinWaived) are
    // allowed as diagonals: the wall's edge there is to be flipped away (see flip_used_fins).
    void waive(const unsigned char* fins) { waived_ = fins; }

    // The fin whose chord is a - b (positions): the position between them, if it is a
    // waived fin; else kNoIndex.
    uint32_t waived_fin(uint32_t a, uint32_t b) const {
        if (!kCapFinFlips || waived_ == nullptr) return kNoIndex;
        const uint32_t after_a = a + 1 == length_ ? 0 : a + 1, after_b = b + 1 == length_ ? 0 : b + 1;
        const uint32_t mid = (after_a + 1 == length_ ? 0 : after_a + 1) == b ? after_a
                           : (after_b + 1 == length_ ? 0 : after_b + 1) == a ? after_b
                                                                             : kNoIndex;
        return mid != kNoIndex && (waived_[mid] & kFinWaived) ? mid : kNoIndex;
    }

    bool clip_ears(uint32_t start) {
        std::memset(c_.owner, 0xFF, sizeof(uint32_t) * length_);  // all kNoIndex
        triangles_ = 0;
        EarClipper clipper(c_.xy, length_, {c_.prev, c_.next, c_.reflex, c_.flags});
        return clipper.clip(start, EarWalk::from_previous, *this);
    }

    // Flips until no diagonal would be lower (higher, on a top cap) flipped, nor, where the
    // heights cannot tell, more Delaunay (or the flip would repeat an edge of the surface),
    // or until the budget of flips is spent.
    void settle_diagonals() {
        uint32_t depth = 0;
        // No overflow: a loop takes more than 64 bytes of workspace per vertex.
        size_t budget = static_cast<size_t>(kCapFlipsPerCorner) * length_;
        for (uint32_t t = 0; t < triangles_; ++t) c_.flags[t] = 0;
        for (uint32_t t = 0; t < triangles_; ++t) queue(t, depth);
        while (depth > 0 && budget > 0) {
            uint32_t t = c_.stack[--depth];
            c_.flags[t] = 0;
            for (uint32_t k = 0; k < 3; ++k) {
                uint32_t u = flip_if_better(t, k);
                if (u == kNoIndex) continue;
                --budget;
                queue(t, depth);
                queue(u, depth);
                break;
            }
        }
    }

    // Triangulates the loop by searching all its triangulations for one whose diagonals
    // are no edges of the surface (dynamic programming over the pairs of corners: the
    // polygon i, i + 1, ..., j closed by diagonal i - j has one if some corner k between
    // makes a triangle i, k, j with both sides closable): what ear clipping misses where
    // fins of the wall leave a corner nothing to join but a corner across the loop. For
    // loops of at most kCapSearchCorners corners (cubic time: about 0.1 s for 256);
    // false if there are more, or none is found.
    bool search_cap() {
        const uint32_t m = length_;
        if (m > kCapSearchCorners || m < 3) return false;
        // choice(i, j): the corner k, stored as k - i, of a triangle i, k, j from which the
        // polygon i .. j closes; 0 if it does not (i - j no diagonal, or no such k).
        auto choice = [this](uint32_t i, uint32_t j) -> uint8_t& {
            return c_.search[static_cast<size_t>(j) * (j - 1) / 2 + i];
        };
        auto closes = [&choice](uint32_t i, uint32_t j) { return j == i + 1 || choice(i, j) != 0; };
        for (uint32_t span = 2; span < m; ++span)
            for (uint32_t i = 0; i + span < m; ++i) {
                const uint32_t j = i + span;
                uint8_t& best = choice(i, j);
                best = 0;
                // i - j must be a diagonal (the loop edge m - 1 -> 0 closes the whole).
                if ((j != m - 1 || i != 0) &&
                    (joined(i, j) || !diagonal_inside(c_.xy, m, i, j)))
                    continue;
                for (uint32_t k = i + 1; k < j && best == 0; ++k)
                    if (closes(i, k) && closes(k, j)) best = static_cast<uint8_t>(k - i);
            }
        if (choice(0, m - 1) == 0) return false;
        // The triangles, from the outermost in: each job is a pair (i, j) and the edge of
        // the triangle already made beyond its side j -> i (kNoIndex for the loop edge).
        triangles_ = 0;
        uint32_t depth = 0;
        auto push = [this, &depth](uint32_t i, uint32_t j, uint32_t beyond) {
            c_.prev[depth] = i;
            c_.next[depth] = j;
            c_.owner[depth++] = beyond;
        };
        push(0, m - 1, kNoIndex);
        while (depth > 0) {
            --depth;
            const uint32_t i = c_.prev[depth], j = c_.next[depth], beyond = c_.owner[depth];
            const uint32_t k = i + choice(i, j);
            const uint32_t t = triangles_++;
            uint32_t* corner = c_.corners + 3 * static_cast<size_t>(t);
            corner[0] = i;
            corner[1] = k;
            corner[2] = j;
            for (uint32_t e = 0; e < 3; ++e) c_.across[3 * static_cast<size_t>(t) + e] = kNoIndex;
            link(3 * t + 2, beyond);
            if (k > i + 1) push(i, k, 3 * t);
            if (j > k + 1) push(k, j, 3 * t + 1);
        }
        return true;
    }

    uint32_t triangles() const { return triangles_; }

private:
    const double* point(uint32_t i) const { return c_.xy + 2 * static_cast<size_t>(i); }

    // Whether positions a and b are joined by an edge of the surface that stays there.
    bool joined(uint32_t a, uint32_t b) const {
        return g_.has_edge(ids_[a], ids_[b]) && waived_fin(a, b) == kNoIndex;
    }

    // The clipping's rules: no diagonal that is an edge of the surface staying there; each
    // ear a cap triangle, its edges p -> v and v -> n linked to the triangles beyond. Its
    // edge n -> p is the polygon's new edge p -> n, with t beyond it, but for the last ear,
    // whose n -> p is an edge of the polygon already.
    bool forbidden(uint32_t a, uint32_t b) const override { return joined(a, b); }

    void take(uint32_t p, uint32_t v, uint32_t n) override {
        const uint32_t t = triangles_++;
        uint32_t* corner = c_.corners + 3 * static_cast<size_t>(t);
        corner[0] = p;
        corner[1] = v;
        corner[2] = n;
        link(3 * t, c_.owner[p]);
        link(3 * t + 1, c_.owner[v]);
        link(3 * t + 2, t + 3 == length_ ? c_.owner[n] : kNoIndex);
        c_.owner[p] = 3 * t + 2;
    }

    void queue(uint32_t t, uint32_t& depth) {
        if (c_.flags[t] & kQueued) return;
        c_.flags[t] = kQueued;
        c_.stack[depth++] = t;
    }

    void link(uint32_t edge, uint32_t other) {
        c_.across[edge] = other;
        if (other != kNoIndex) c_.across[other] = edge;
    }

    // Flips the diagonal on edge k of t if the other diagonal lies lower (higher on a top
    // cap), or on a tie if the vertex beyond lies in t's circumcircle; only where the
    // quadrilateral is strictly convex and the new diagonal is no edge of the surface.
    // Returns the other triangle, or kNoIndex if nothing was flipped.
    uint32_t flip_if_better(uint32_t t, uint32_t k) {
        uint32_t beyond = c_.across[3 * t + k];
        if (beyond == kNoIndex) return kNoIndex;
        uint32_t u = beyond / 3, j = beyond % 3;
        uint32_t* ct = c_.corners + 3 * static_cast<size_t>(t);
        uint32_t* cu = c_.corners + 3 * static_cast<size_t>(u);
        uint32_t a = ct[k], b = ct[(k + 1) % 3], w = ct[(k + 2) % 3], d = cu[(j + 2) % 3];
        const double heights[4] = {c_.height[a], c_.height[b], c_.height[w], c_.height[d]};
        // How much lower (higher, on a top cap) the other diagonal lies: flip if clearly
        // so; on a tie, by the Delaunay criterion. A NaN (a sliver abw) flips nothing.
        double gain =
            kLiftedCaps ? depth_below_plane(point(a), point(b), point(w), point(d), heights) : 0;
        if (!lower_) gain = -gain;
        if (!(gain > kCapHeightTie ||
              (gain >= -kCapHeightTie &&
               incircle_perturbed(point(a), point(b), point(w), point(d), c_.scratch) > 0)))
            return kNoIndex;
        if (orient2d_robust(point(a), point(d), point(w)) <= 0 ||
            orient2d_robust(point(d), point(b), point(w)) <= 0 || joined(w, d))
            return kNoIndex;
        uint32_t beyond_bw = c_.across[3 * t + (k + 1) % 3], beyond_wa = c_.across[3 * t + (k + 2) % 3];
        uint32_t beyond_ad = c_.across[3 * u + (j + 1) % 3], beyond_db = c_.across[3 * u + (j + 2) % 3];
        // t becomes a -> d -> w (d -> w the new diagonal), u becomes d -> b -> w.
        ct[0] = a;
        ct[1] = d;
        ct[2] = w;
        cu[0] = d;
        cu[1] = b;
        cu[2] = w;
        link(3 * t, beyond_ad);
        link(3 * t + 2, beyond_wa);
        link(3 * u, beyond_db);
        link(3 * u + 1, beyond_bw);
        link(3 * t + 1, 3 * u + 2);
        return u;
    }

    CapLoop& c_;
    const uint32_t* ids_;
    uint32_t length_;
    const CapGraph& g_;
    bool lower_;
    uint32_t triangles_ = 0;
    const unsigned char* waived_ = nullptr;
};

// What capping a surface's loops did: loops closed and left open, the caps' triangles and
// the wall edges flipped under fins (Report::caps).
struct CapTally {
    size_t closed, left_open, triangles, wall_flips;
};

// Report::detail for the caps, from reconstruct() and cap_ends() alike.
const char* const kCapsTooLargeDetail =
    "the triangle array is too small for the caps; triangle_count says how many are needed";

const char* const kLoopLeftOpenDetail =
    "a boundary loop's projection across the axis is not a simple polygon (or every cap "
    "found for it would repeat an edge of the surface): it is left open";

// ---- fins flipped out of the way
//
// A loop with fins can have no cap at all: each fin's middle corner needs a diagonal to a
// corner it sees across the loop, and with fins close together those diagonals cross or
// see nothing (a fin under every other edge: most loops the search leaves open on
// sparsely sampled ends). Then the wall gives way: the fin (u, v, m)
// and the wall triangle beyond its chord, (v, u, x), become (u, x, m) and (x, v, m) (m,
// the fin's middle corner, has no other triangle, so m - x is a new edge and the surface
// stays a manifold), and the chord u - v is free for the cap. Only fins whose x is on no
// loop (no new chord) and whose two new triangles face the way the old pair does are
// offered, and only those whose chord the cap then takes are flipped: a loop that closed
// before closes as before, and one that stays open leaves the wall as it was.

// The per point key of a loop's fin chords: at the chord's first corner (position i - 1),
// the fin's position i, for the fins with a flag in `wanted`. `key` is all kNoIndex outside
// these calls: clear_fin_chords puts it back.
static inline void key_fin_chords(uint32_t* key, const uint32_t* ids, uint32_t length,
                           const unsigned char* fins, unsigned char wanted) {
    for (uint32_t i = 0; i < length; ++i)
        if (fins[i] & wanted) key[ids[i == 0 ? length - 1 : i - 1]] = i;
}

static inline void clear_fin_chords(uint32_t* key, const uint32_t* ids, uint32_t length) {
    for (uint32_t i = 0; i < length; ++i) key[ids[i]] = kNoIndex;
}

// The fin position whose chord is a - b (either way round), or kNoIndex.
static inline uint32_t keyed_fin(const uint32_t* key, const uint32_t* ids, uint32_t length,
                          uint32_t a, uint32_t b) {
    for (int side = 0; side < 2; ++side) {
        const uint32_t i = key[side == 0 ? a : b];
        if (i != kNoIndex && ids[i + 1 == length ? 0 : i + 1] == (side == 0 ? b : a)) return i;
    }
    return kNoIndex;
}

// Whether (u, x, m) and (x, v, m) face the way (u, v, m) and (v, u, x) do together.
static inline bool fin_flip_keeps_facing(const CloudReader& cloud, const Frame& frame, uint32_t u,
                                  uint32_t v, uint32_t m, uint32_t x) {
    const Vec3 pu = frame.offset(cloud.point(u)), pv = frame.offset(cloud.point(v));
    const Vec3 pm = frame.offset(cloud.point(m)), px = frame.offset(cloud.point(x));
    const Vec3 fin = cross(pv - pu, pm - pu), beyond = cross(pu - pv, px - pv);
    const Vec3 first = cross(px - pu, pm - pu), second = cross(pv - px, pm - px);
    return dot(first, fin) + dot(first, beyond) > 0 && dot(second, fin) + dot(second, beyond) > 0;
}

// Marks kFinWaived the fins of the loop ids[0 .. length) that may be flipped (above),
// scanning the wall tri[0 .. 3 wall); returns how many.
static inline uint32_t mark_flippable_fins(const uint32_t* tri, size_t wall, const CloudReader& cloud,
                                    const Frame& frame, const CapGraph& g, uint32_t* key,
                                    const uint32_t* ids, uint32_t length, unsigned char* fins) {
    if (length <= 4) return 0;  // a chord two corners apart either way: no single fin
    for (uint32_t i = 0; i < length; ++i)
        fins[i] = g.has_edge(ids[i == 0 ? length - 1 : i - 1], ids[i + 1 == length ? 0 : i + 1])
                      ? kFinSeen | kFinFlippable : 0;
    key_fin_chords(key, ids, length, fins, kFinSeen);
    for (uint32_t i = 0; i < length; ++i) fins[i] = 0;
    for (size_t t = 0; t < wall; ++t) {
        const uint32_t* c = tri + 3 * t;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t a = c[k], b = c[(k + 1) % 3], o = c[(k + 2) % 3];
            const uint32_t i = keyed_fin(key, ids, length, a, b);
            if (i == kNoIndex) continue;
            if (o == ids[i]) {
                fins[i] |= kFinSeen;
            } else if (g.offsets[o + 1] == g.offsets[o] &&  // o is on no loop
                       fin_flip_keeps_facing(cloud, frame, b, a, ids[i], o)) {
                fins[i] |= kFinFlippable;  // beyond a -> b: the fin runs b -> a -> ids[i]
            }
        }
    }
    clear_fin_chords(key, ids, length);
    uint32_t marked = 0;
    for (uint32_t i = 0; i < length; ++i) {
        const bool both = fins[i] == (kFinSeen | kFinFlippable);
        fins[i] = both ? kFinWaived : 0;
        marked += both;
    }
    return marked;
}

// Flips the wall's edge under each fin marked kFinUsed; returns how many it flipped. slots:
// two size_t per position (in the memory of the loop's projection, free once its cap is made).
static inline size_t flip_used_fins(uint32_t* tri, size_t wall, uint32_t* key, const uint32_t* ids,
                             uint32_t length, const unsigned char* fins, double* slots) {
    auto slot = [slots](uint32_t i, uint32_t which) { return slots + 2 * static_cast<size_t>(i) + which; };
    static_assert(sizeof(size_t) <= sizeof(double), "a slot holds a triangle index");
    const size_t unset = ~size_t{0};
    for (uint32_t i = 0; i < length; ++i) {
        std::memcpy(slot(i, 0), &unset, sizeof unset);
        std::memcpy(slot(i, 1), &unset, sizeof unset);
    }
    key_fin_chords(key, ids, length, fins, kFinUsed);
    size_t flipped_count = 0;
    for (size_t t = 0; t < wall; ++t) {
        const uint32_t* c = tri + 3 * t;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t i = keyed_fin(key, ids, length, c[k], c[(k + 1) % 3]);
            if (i != kNoIndex) std::memcpy(slot(i, c[(k + 2) % 3] == ids[i] ? 0 : 1), &t, sizeof t);
        }
    }
    for (uint32_t i = 0; i < length; ++i) {
        if (!(fins[i] & kFinUsed)) continue;
        size_t fin = 0, beyond = 0;
        std::memcpy(&fin, slot(i, 0), sizeof fin);
        std::memcpy(&beyond, slot(i, 1), sizeof beyond);
        if (fin == unset || beyond == unset) continue;  // a soup given to cap_ends() only
        uint32_t* f = tri + 3 * fin;
        uint32_t* w = tri + 3 * beyond;
        uint32_t k = 0;  // w's edge k -> k + 1 is the chord, v -> u
        while (k < 2 && keyed_fin(key, ids, length, w[k], w[(k + 1) % 3]) != i) ++k;
        const uint32_t v = w[k], u = w[(k + 1) % 3], x = w[(k + 2) % 3], m = ids[i];
        const uint32_t flipped[6] = {u, x, m, x, v, m};
        std::memcpy(f, flipped, 3 * sizeof(uint32_t));
        std::memcpy(w, flipped + 3, 3 * sizeof(uint32_t));
        ++flipped_count;
    }
    clear_fin_chords(key, ids, length);
    return flipped_count;
}

// ---- pockets closed before a cap ----
//
// A loop is ragged along the axis: its points dip a little below its highest ones, and
// where the wall flares out toward the end (its lower points inside the loop, seen along
// the axis), a cap over the loop dips with them and crosses the wall's top row (a tilted
// tube widening at its top: 24 to 65 crossing pairs with 60,000 points). So the cap spans
// the loop's upper hull in the loop's own unrolled picture (the angle around its centroid,
// and the height; the lower hull for a bottom loop), which lies above the wall, and each
// pocket between a hull chord and the points dipping under it is first closed by
// triangles of its own, along the wall. Only for a loop that runs once around its
// centroid, monotonically; a pocket whose chord or diagonal would repeat an edge of the
// surface is left for the cap as it is. The pockets and the cap together triangulate the
// loop, so the caps' triangle count is the same.

// The widest pocket closed, in angle around the loop's centroid: a loop's ragged dips span
// a few of its points; wider ones (the low side of a slanted end) are the cap's.
const double kPocketTurn = 3.14159265358979323846 / 8;

// The loop (positions in cap order, the first its highest: see fill_pockets) in its
// annulus picture, as the layers unroll (see >>unroll): around its centroid across the
// axis, at a radius exp((h - h_first) / r) for the height h (-h for a bottom loop) and the
// loop's mean radius r, mirrored so that the loop turns clockwise. False if it does not
// run once around its centroid monotonically.
static inline bool unroll_loop(const CloudReader& cloud, const Frame& frame, const uint32_t* ids,
                        uint32_t length, bool lower, double* xy) {
    double cx = 0, cy = 0, radius = 0;
    for (uint32_t i = 0; i < length; ++i) {
        const Local p = frame.local(cloud.point(ids[i]));
        cx += p.x;
        cy += p.y;
    }
    cx /= length;
    cy /= length;
    const double pi = 3.14159265358979323846;
    double turned = 0, previous = 0;
    for (uint32_t i = 0; i <= length; ++i) {
        const Local p = frame.local(cloud.point(ids[i % length]));
        const double dx = p.x - cx, dy = p.y - cy, angle = std::atan2(dy, dx);
        double step = i == 0 ? 0 : angle - previous;
        step = step > pi ? step - 2 * pi : step < -pi ? step + 2 * pi : step;
        if (i > 0 && !(step * (turned == 0 ? step : turned) > 0)) return false;
        turned += step;
        previous = angle;
        if (i < length) {
            radius += std::sqrt(dx * dx + dy * dy);
            xy[2 * i] = dx;
            xy[2 * i + 1] = lower ? -p.h : p.h;
        }
    }
    if (!(abs_value(abs_value(turned) - 2 * pi) < 1e-9) || !(radius > 0)) return false;
    radius /= length;
    const double first = xy[1];
    for (uint32_t i = 0; i < length; ++i) {
        const Local p = frame.local(cloud.point(ids[i]));
        const double dx = p.x - cx, dy = p.y - cy, d = std::sqrt(dx * dx + dy * dy);
        const double rho = exp_portable((xy[2 * i + 1] - first) / radius);
        const double u = d > 0 ? dx / d : 1, v = d > 0 ? dy / d : 0;
        // Clockwise: mirrored where the loop turns counter-clockwise.
        xy[2 * i] = (turned > 0 ? -u : u) * rho;
        xy[2 * i + 1] = v * rho;
    }
    return true;
}

// A pocket's ears: its corners are the loop's positions from `from` on (mod length); no
// diagonal that is an edge of the surface; each ear appended at tri[3 added] as the cap
// writes its own triangles (in loop order).
class PocketEars final : public EarRules {
public:
    PocketEars(uint32_t* tri, size_t count, const CapGraph& g, const uint32_t* ids,
               uint32_t length, uint32_t from)
        : added(count), tri_(tri), g_(g), ids_(ids), length_(length), from_(from) {}

    size_t added;

private:
    uint32_t id(uint32_t corner) const { return ids_[(from_ + corner) % length_]; }

    bool forbidden(uint32_t a, uint32_t b) const override { return g_.has_edge(id(a), id(b)); }

    void take(uint32_t p, uint32_t v, uint32_t n) override {
        tri_[3 * added] = id(p);
        tri_[3 * added + 1] = id(v);
        tri_[3 * added + 2] = id(n);
        ++added;
    }

    uint32_t* tri_;
    const CapGraph& g_;
    const uint32_t* ids_;
    uint32_t length_, from_;
};

// Closes the pocket of the `corners` positions from `from` on (the last may be the first
// position again), whose points in the annulus picture are run[0 .. 2 corners), by ear
// clipping from its second corner on (it turns counter-clockwise there); appends its
// triangles at tri[3 * count]. False, with count unchanged, where no ear is left whose
// diagonal is not already an edge of the surface.
static inline bool close_pocket(uint32_t* tri, size_t& count, const CapGraph& g, const uint32_t* ids,
                         uint32_t length, const double* run, uint32_t from, uint32_t corners,
                         const EarRing& ring) {
    PocketEars ears(tri, count, g, ids, length, from);
    EarClipper clipper(run, corners, ring);
    if (!clipper.clip(1, EarWalk::from_previous, ears)) return false;
    count = ears.added;
    return true;
}

// Closes the pockets of the loop ids[0 .. length) (see above), rotating ids so that its
// highest position (its lowest, for a bottom loop) comes first, and keeps in ids, in order,
// the positions left for the cap; returns their number. The cap loop's arrays serve as
// scratch.
static inline uint32_t fill_pockets(uint32_t* tri, size_t& count, const CapGraph& g, CapLoop& c,
                             const CloudReader& cloud, const Frame& frame, uint32_t* ids,
                             uint32_t length, bool lower) {
    uint32_t top = 0;
    for (uint32_t i = 1; i < length; ++i) {
        const double h = frame.height(cloud.point(ids[i])), best = frame.height(cloud.point(ids[top]));
        if (lower ? h < best : h > best) top = i;
    }
    // Rotated by three reversals, in place.
    auto reverse = [ids](uint32_t first, uint32_t end) {
        for (; first + 1 < end; ++first, --end) {
            const uint32_t t = ids[first];
            ids[first] = ids[end - 1];
            ids[end - 1] = t;
        }
    };
    reverse(0, top);
    reverse(top, length);
    reverse(0, length);
    double* xy = c.xy;
    if (!unroll_loop(cloud, frame, ids, length, lower, xy)) return length;
    // The convex hull of the clockwise loop from its first position (on the hull, being the
    // farthest out) round to it again: a Graham scan in the loop's order.
    // The first position closes the hull again: scanned last, but not stored twice.
    uint32_t* hull = c.stack;
    uint32_t hull_count = 0;
    for (uint32_t j = 0; j <= length; ++j) {
        const double* pj = xy + 2 * (j % length);
        while (hull_count >= 2 &&
               orient2d_robust(xy + 2 * hull[hull_count - 2], xy + 2 * hull[hull_count - 1], pj) >= 0)
            --hull_count;  // not a strict right turn: off the hull
        if (j < length) hull[hull_count++] = j;
    }
    if (hull_count < 3) return length;  // the cap needs three corners at least
    // The positions a closed pocket takes leave the cap's loop: ids is compacted as the
    // pockets go, behind them (the last pocket reads position 0 again, which stays).
    const EarRing ring = {c.prev, c.next, c.reflex, c.flags};
    uint32_t kept = 0;
    for (uint32_t k = 0; k < hull_count; ++k) {
        const uint32_t from = hull[k], to = k + 1 < hull_count ? hull[k + 1] : length;
        const double* pa = xy + 2 * from;
        const double* pb = xy + 2 * (to % length);
        const double span = std::atan2(abs_value(pa[0] * pb[1] - pa[1] * pb[0]),
                                       pa[0] * pb[0] + pa[1] * pb[1]);
        bool closed = false;
        if (to - from >= 2 && span < kPocketTurn && !g.has_edge(ids[from], ids[to % length])) {
            // The last pocket runs past the loop's end: its points are moved to the front
            // of xy, which nothing reads again, to be a run as the others are.
            if (to == length) {
                const double first[2] = {xy[0], xy[1]};
                std::memmove(xy, xy + 2 * from, sizeof(double) * 2 * (length - from));
                xy[2 * (length - from)] = first[0];
                xy[2 * (length - from) + 1] = first[1];
            }
            closed = close_pocket(tri, count, g, ids, length, to == length ? xy : xy + 2 * from,
                                  from, to - from + 1, ring);
        }
        ids[kept++] = ids[from];
        for (uint32_t j = from + 1; !closed && j < to; ++j) ids[kept++] = ids[j];
    }
    return kept;
}

// Caps every boundary loop of the surface tri[0 .. 3 count) over the cloud's points,
// appending the cap triangles (count grows) and counting into caps (zeroed by the caller);
// each loop is projected across the frame's axis. Returns ok; out_of_memory; or
// triangle_capacity with *needed the triangles every cap closing would take, and nothing
// written.
static inline Status cap_boundary_loops(uint32_t* tri, size_t& count, size_t capacity,
                                 const CloudReader& cloud, size_t point_count,
                                 const Frame& frame, Arena& arena, CapTally& caps,
                                 size_t* needed) {
    auto project = [&](uint32_t id, double* xy, double* height) {
        const Local p = frame.local(cloud.point(id));
        xy[0] = p.x;
        xy[1] = p.y;
        *height = p.h;
    };
    const size_t wall = count;
    size_t mark = arena.mark();
    CapGraph g;
    if (!allocate_cap_graph(g, point_count, count, arena)) return Status::out_of_memory;
    size_t boundary = build_cap_graph(tri, count, point_count, g);
    if (boundary == 0) {
        arena.rewind(mark);
        return Status::ok;
    }
    CapLoop c;
    if (!allocate_cap_loop(c, boundary, arena)) return Status::out_of_memory;
    size_t entries = 0;
    size_t cap_triangles = trace_boundary_loops(g, point_count, c, &entries);
    if (cap_triangles > capacity - count) {
        *needed = count + cap_triangles;
        return Status::triangle_capacity;
    }
    for (size_t start = 0; start < entries;) {
        size_t end = start + 1;
        while (end < entries && c.starts[end] == 0) ++end;
        uint32_t* ids = c.ids + start;
        // Cap triangle edges are numbered 3 t + k in 32 bits.
        const bool usable = c.starts[start] == kLoopStart && end - start <= (kNoIndex - 1) / 3;
        uint32_t length = static_cast<uint32_t>(end - start);
        start = end;
        // The loop's projection across the axis, checked to be a simple polygon, and its
        // turning direction (0: not simple); then the same for the positions its pockets
        // leave to the cap.
        double turn = 0;
        for (bool pockets = kLiftedCaps; usable; pockets = false) {
            double height = 0;
            for (uint32_t i = 0; i < length; ++i)
                project(ids[i], c.xy + 2 * static_cast<size_t>(i), &height);
            if (!polygon_is_simple(c.xy, length, c.sweep)) break;
            turn = simple_polygon_turn(c.xy, length);
            if (!pockets || turn == 0) break;
            const size_t before = count;
            length = fill_pockets(tri, count, g, c, cloud, frame, ids, length, turn < 0);
            caps.triangles += count - before;
            turn = 0;
        }
        if (turn == 0) {
            ++caps.left_open;
            continue;
        }
        if (turn < 0)
            for (uint32_t i = 0; i < length; ++i) c.xy[2 * static_cast<size_t>(i)] = -c.xy[2 * static_cast<size_t>(i)];
        // A loop turning clockwise seen from +axis is capped facing -axis: a bottom cap.
        CapTriangulation cap(c, ids, length, g, turn < 0);
        bool clipped = cap.triangulate();
        // The loop's start markers are read no more: its fins' flags take their place.
        unsigned char* fins = c.starts + (ids - c.ids);
        bool waived = false;
        if (kCapFinFlips && !clipped &&
            mark_flippable_fins(tri, wall, cloud, frame, g, g.boundary_next, ids, length, fins) > 0) {
            cap.waive(fins);
            waived = true;
            clipped = cap.triangulate();
        }
        if (!clipped) {
            ++caps.left_open;
            continue;
        }
        double xy[2];  // c.xy holds them, mirrored
        for (uint32_t i = 0; kLiftedCaps && i < length; ++i) project(ids[i], xy, c.height + i);
        cap.settle_diagonals();
        bool flips = false;
        for (size_t k = 0; k < 3 * static_cast<size_t>(cap.triangles()); ++k) {
            tri[3 * count + k] = ids[c.corners[k]];
            const uint32_t fin = waived ? cap.waived_fin(c.corners[k], c.corners[k - k % 3 + (k + 1) % 3]) : kNoIndex;
            if (fin != kNoIndex) {
                fins[fin] |= kFinUsed;
                flips = true;
            }
        }
        if (flips)
            caps.wall_flips += flip_used_fins(tri, wall, g.boundary_next, ids, length, fins, c.xy);
        count += cap.triangles();
        caps.triangles += cap.triangles();
        ++caps.closed;
    }
    arena.rewind(mark);
    return Status::ok;
}

}  // namespace detail
}  // namespace stratmesh
