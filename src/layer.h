// >>layer ================================================================================
// One layer on its annulus: its loops and their peeling, closed ends, the centre search.

namespace stratmesh {
namespace detail {

struct LayerLoops {
    uint32_t* bottom;  // layer-local indices, counter-clockwise on the annulus
    uint32_t bottom_count;
    uint32_t* top;
    uint32_t top_count;
    // Per loop vertex, set by triangulate_layer: the pass that peeled it onto the loop
    // (kPassBit up; 0 on the centre's link or the hull); the bits below are the seam's
    // (SurfaceChain::top_unused).
    unsigned char* bottom_flags;
    unsigned char* top_flags;
    // From triangulate_layer: where in the sink its triangles at the bottom loop begin (they
    // come last), and how many of its points have a triangle but are off the bottom loop.
    size_t border_start;
    size_t interior_used;
};

// A layer's points that fell on a vertex already there: duplicates (merged into it) and
// collisions (not vertices).
struct CoincidentPoints {
    size_t duplicates;   // same 3D coordinates as an earlier point
    size_t collisions;   // distinct in 3D, same place on the annulus
};

// Classifies the points the layer's triangulation found on an existing vertex.
struct LayerDuplicates {
    const CloudReader* cloud;
    const uint32_t* ids;    // layer-local index -> reader index
    const uint32_t* order;  // vertex - 1 -> layer-local index (vertex 0 is the centre)
    CoincidentPoints* counts;

    static void report(void* context, uint32_t point, uint32_t vertex) {
        LayerDuplicates* d = static_cast<LayerDuplicates*>(context);
        Vec3 p = d->cloud->point(d->ids[d->order[point - 1]]);
        Vec3 v = d->cloud->point(d->ids[d->order[vertex - 1]]);
        if (p.x == v.x && p.y == v.y && p.z == v.z)
            ++d->counts->duplicates;
        else
            ++d->counts->collisions;
    }
};

// Per vertex of a layer's triangulation, in triangulate_layer (the flip stack's room).
const uint32_t kOnBottomLoop = 1, kEmitted = 2, kOnTopLoop = 4;

// See flip_layer_on_surface.
const uint32_t kFlippedBefore = 8, kFlippedNow = 16, kVisited = 32, kNearFold = 64;

const uint32_t kPassShift = 8;  // above it: the peeling pass that put a vertex on its loop

const uint32_t kPassBit = 3;    // where LayerLoops::bottom_flags and top_flags keep that pass

const unsigned char kPassBits = static_cast<unsigned char>(0xF << kPassBit);

// The last pass those 4 bits hold. Only an end loop of a layer that folds peels further,
// and no band puts its peeled triangles back: its later passes are kept as this one.
const uint32_t kLastPass = 0xF;

const unsigned char kUnpeeled = 0x80;  // in those flags: the band puts the peeled triangle back

// Collects the link of the centre (vertex 0) counter-clockwise into loop, one entry per link
// edge u -> w: the half-edge w -> u of the triangle beyond it. Flags its vertices
// kOnBottomLoop. False if the centre touches the hull: the layer does not surround its axis.
static inline bool centre_link(const Triangulation& tr, uint32_t* loop, uint32_t* count,
                        uint32_t* flags) {
    uint32_t start = kNoIndex;
    for (uint32_t e = 0; e < 3 * tr.triangle_count; ++e)
        if (tr.vertex[e] == 0) {
            start = e;
            break;
        }
    if (start == kNoIndex) return false;
    uint32_t n = 0, e = start;
    do {
        uint32_t u = tr.vertex[next_edge(e)];
        if (u == kGhost || tr.vertex[prev_edge(e)] == kGhost || n > tr.triangle_count)
            return false;
        loop[n++] = tr.twin[next_edge(e)];
        flags[u] = kOnBottomLoop;
        e = tr.twin[prev_edge(e)];  // the next triangle counter-clockwise around the centre
    } while (e != start);
    *count = n;
    return true;
}

// Collects the convex hull counter-clockwise into loop, one entry per hull edge a -> b: that
// half-edge, in the triangle inside. Flags its vertices kOnTopLoop. A ghost (a, b, G) holds
// G -> a, then a -> b; the twin of G -> a is a -> G in the ghost (z, a, G), whose next
// half-edge is G -> z: the next ghost along the hull.
static inline void hull_loop(const Triangulation& tr, uint32_t* loop, uint32_t* count, uint32_t* flags) {
    uint32_t start = 0;
    while (tr.vertex[start] != kGhost) ++start;
    uint32_t n = 0, e = start;
    do {
        loop[n++] = tr.twin[next_edge(e)];
        flags[tr.vertex[next_edge(e)]] |= kOnTopLoop;
        e = next_edge(tr.twin[e]);
    } while (e != start && n <= tr.triangle_count);
    *count = n;
}

// Peeling. Both loops are convex hulls, each in its own picture: the top loop on the
// annulus, the bottom loop on the annulus turned inside out (z -> 1/z maps the centre's
// link to the hull). A hull's edges are chords over the points just inside it, several
// spacings long, and the band to the next layer spanned them with long triangles that cut
// through the surface: with 24 layers on a star-shaped tube the bands held 11% of the
// area, at 5 times the mean distance from the true surface. The next layer's points lie
// beyond the chord, so in one triangulation of both layers the chord's sliver would not
// be there. Hence a loop triangle is peeled off the layer when its angle at the inner
// vertex x is obtuse on the surface (in 3D), and x joins the loop, where the band's
// empty-circle swaps settle it with the other layer's points. Only when x is on no loop
// (the loops stay simple and apart), lies between the edge's ends in angle around the
// centre (the loop still turns monotonically), and the two new loop edges rise at most
// kPeelSlope (45 degrees) on the surface's ends (the first layer's bottom loop, the last
// one's top loop: steeper loops made the caps fail on ragged ends), kInnerPeelSlope (63
// degrees) between layers, where the gentler limit left chords several spacings long (a
// steeper limit brings the layers' seams no closer to the surface and crosses more). And
// only in
// a layer without folds: where the layer is not star-shaped around its centre the loops
// are not monotone around the band's centre either, and longer loops gave the bands more
// self-intersections. Except the surface's end loops, which meet no band (kPeelFoldedEnds):
// a layer folds where the object branches, and at the end the branches' tips stand apart
// (the horns of bench/horned_bust.py): the hull runs from tip to tip and the triangles
// under it are a web across the gap, down to where the branches meet. There an end loop
// peels at any slope short of vertical, up to kFoldedEndPeelPasses passes, and most of the
// web goes (on a bust with horns, half the mean distance to the true surface). A cap
// (add_caps) over such a loop, which dips to where the branches meet, can cross them.
// The passes are bounded:
// each peels every loop edge at most once.
// Each loop keeps, per vertex, the pass that put it there (LayerLoops::bottom_flags,
// top_flags), so that the band can put the peeled triangles back: where a band between
// peeled loops folds (a peeled loop can dip where the other cannot follow), add_group
// stitches it again with the peeled triangles around the folds put back
// (put_back_peeled), and if it still folds, between the loops as they were, with all the
// triangles peeled off both put back: the seam as without peeling.
const uint32_t kPeelPasses = 8;

// Stitches of a band (see add_group): the first between the peeled loops; where it folds,
// with kLocalUnpeel, up to two more with the peel groups around the folds put back, then
// one with all; without kLocalUnpeel, one with all.
const uint32_t kUnpeelRounds = kLocalUnpeel ? 4 : 2;

const double kPeelSlope = 1.0;

const double kInnerPeelSlope = 2.0;

const uint32_t kFoldedEndPeelPasses = 64;

const double kFoldedEndPeelSlope = 1e6;

// Whether the triangle of loop entry g (see centre_link and hull_loop) is peeled.
static inline bool peels(const Triangulation& tr, const Local* points, const uint32_t* flags,
                  uint32_t g, bool top, double slope) {
    if (!on_surface(tr, g / 3)) return false;
    uint32_t from = tr.vertex[g], to = tr.vertex[next_edge(g)], x = tr.vertex[prev_edge(g)];
    if (flags[x] & (kOnBottomLoop | kOnTopLoop)) return false;
    if (!top) {  // the bottom loop runs against its entries' half-edges
        uint32_t t = from;
        from = to;
        to = t;
    }
    const Local &a = points[from - 1], &b = points[to - 1], &p = points[x - 1];
    auto gentle = [&p, slope](const Local& q) {
        double dh = q.h - p.h, dx = q.x - p.x, dy = q.y - p.y;
        return dh * dh <= slope * slope * (dx * dx + dy * dy);
    };
    double dot = (a.x - p.x) * (b.x - p.x) + (a.y - p.y) * (b.y - p.y) + (a.h - p.h) * (b.h - p.h);
    return dot < 0 && gentle(a) && gentle(b) &&
           orient2d_robust(tr.xy, tr.xy + 2 * from, tr.xy + 2 * x) > 0 &&
           orient2d_robust(tr.xy, tr.xy + 2 * x, tr.xy + 2 * to) > 0;
}

// Peels the loop's entries loop[0..n) (capacity: the layer's points, which no loop exceeds)
// and returns its new length. A peeled triangle loses its first vertex to the centre, so
// that it is no longer emitted. The pass reads the loop from the array's end, where it never
// meets what it writes: both loops together hold each vertex at most once.
static inline uint32_t peel_loop(Triangulation& tr, const Local* points, uint32_t* flags, uint32_t* loop,
                          uint32_t n, uint32_t capacity, bool top, double slope,
                          uint32_t passes) {
    for (uint32_t pass = 0; pass < passes; ++pass) {
        std::memmove(loop + (capacity - n), loop, n * sizeof(uint32_t));
        const uint32_t* entries = loop + (capacity - n);
        uint32_t m = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t g = entries[i];
            if (m + 2 > capacity - n + i + 1 || !peels(tr, points, flags, g, top, slope)) {
                loop[m++] = g;
                continue;
            }
            const uint32_t kept = kPeelFoldedEnds && pass >= kLastPass ? kLastPass : pass + 1;
            flags[tr.vertex[prev_edge(g)]] |= (top ? kOnTopLoop : kOnBottomLoop) |
                                              kept << kPassShift;
            const uint32_t before = tr.twin[prev_edge(g)], after = tr.twin[next_edge(g)];
            loop[m++] = top ? before : after;
            loop[m++] = top ? after : before;
            tr.vertex[g - g % 3] = 0;
        }
        if (m == n) break;
        n = m;
    }
    return n;
}

// Turns loop entries into the layer-local indices of the loop's vertices, in loop order, and
// sets each vertex's peeling pass in passes (0: on the centre's link or the hull).
static inline void name_loop(const Triangulation& tr, const uint32_t* order, const uint32_t* flags,
                      uint32_t* loop, uint32_t n, unsigned char* passes, bool top) {
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t v = tr.vertex[top ? loop[i] : next_edge(loop[i])];
        passes[i] = static_cast<unsigned char>(flags[v] >> kPassShift << kPassBit);
        loop[i] = order[v - 1];
    }
}

// A layer's points in frame coordinates, read from the cloud once so that the fit, the
// unrolling and the fold test read a compact array instead of the cloud at random, and the
// cylinder fitted to them. Triangles and loops name the points by their position in `ids`
// (layer-local indices).
struct LoadedLayer {
    const uint32_t* ids;  // layer-local index -> reader index
    size_t count;
    Local* points;        // ids' points, until triangulate_layer puts them in its own order
    Cylinder cyl;
    bool surface_flips;   // Frame::surface_flips
    uint32_t ends;        // kLowPole, kHighPole: the surface's ends (see find_closed_ends)
    uint32_t cut_ends;    // Frame::cut_ends
};

// `staged` (optional): the same points in frame coordinates, in the arena's end room
// (LayerQueue::staged), read in sequence instead of the cloud at random while intact.
static inline bool load_layer(const CloudReader& cloud, const Frame& frame, const uint32_t* ids,
                       const Local* staged, size_t count, double h0, double h1, Arena& arena,
                       LoadedLayer& layer) {
    const bool intact = kStagePoints && staged && arena.untouched(staged);
    layer.ids = ids;
    layer.ends = 0;
    layer.count = count;
    if (kSurfaceFlips) layer.surface_flips = frame.surface_flips;
    layer.cut_ends = frame.cut_ends;
    layer.points = arena.alloc<Local>(count);
    if (arena.failed) return false;
    if (intact)
        std::memmove(layer.points, staged, count * sizeof(Local));  // they may overlap
    else
        for (size_t i = 0; i < count; ++i) layer.points[i] = frame.local(cloud.point(ids[i]));
    const Local* points = layer.points;
    layer.cyl =
        fit_cylinder([points](size_t i) -> const Local& { return points[i]; }, count, h0, h1);
    return true;
}

// sectors_held by a loaded layer around its fitted centre (before the centre search moves
// it).
static inline uint32_t layer_sectors(const LoadedLayer& layer) {
    const Local* points = layer.points;
    return sectors_held([points](size_t i) -> const Local& { return points[i]; }, layer.count,
                        layer.cyl.cx, layer.cyl.cy);
}

// ---- closed ends ----
//
// Whether the layer, an end of the surface (`ends`: kLowPole for the first layer, kHighPole
// for the last), holds a closed end there (see "closed ends" in >>unroll): among the points
// within kEndSlab radii of that end (at most a third of the layer), a twentieth or more
// (and at least 3) lie within kAcrossEnd times their mean distance from the axis, and
// either (by share) that share is more than twice the share among the points between the
// two ends' slabs, or (by outline) a twentieth or more (and at least 3) are also within
// kAcrossEnd times the outline of the slab beyond (as thick, next to it) in their sector,
// and that slab surrounds the axis (no octant empty). An open end has none there; a
// section that is not star-shaped around the centre (two lobes) has as many all along the
// layer, and they lie on the outline, not inside it, so it is left as it was (its folds
// are the centre search's). Sets layer.cyl's poles, kPoleDepth radii in from the ends: at
// most half-way when the layer holds both ends, else at most three quarters of the way, so
// the layer's far quarter keeps the cylinder's picture and its loop there still hugs the
// cut (with the pole beyond the layer, one run of the femur's 16 crossed itself in 4
// pairs). Measured over the 16 layerings of bench/layer_sweep.sh: the femur's mean
// distance 4% smaller and 103 self-intersecting pairs (111 before), the hand and the bust
// within 1%, open star-shaped tubes unchanged; poles on every end layer instead made open
// tubes 19% farther from their surface. Thin end layers: a slab of a quarter of the layer
// (at most) missed the dome of the test suite's capsule cut in 12 layers (2 points across
// of 34), and poles at most half-way left a flat end in a thin layer twice as far from its
// surface as in a thick one; a third and three quarters bring a flat-ended cylinder 5%
// closer over 1 to 24 layers (10% with 24), and leave the real clouds within 0.4%.
// By outline finds the ends that split into knobs (a femur's condyles, the test suite's
// knobbed tube), which by share missed: the notch between the knobs rises into the layer
// and gives it as many points near the axis as the end has. Then the knobbed tube with 4
// and 8 layers had 9 to 25 folds and now none; the same 16 layerings of the femur come
// 2.9% closer (geometric mean) with 93 self-intersecting pairs (108 before; 6 layers along
// z: 15 to 0), the hand, the kitten, the busts and the analytic tubes unchanged. By outline
// alone left the femur's top open (a flat cut, few points across), and without the
// octants' rule a bent tube's open ends, which pass beside the axis, were taken for closed.
const double kPoleDepth = 1.0;

const double kEndSlab = 0.5;

const double kAcrossEnd = 0.5;

static inline void find_closed_ends(LoadedLayer& layer, uint32_t ends) {
    layer.ends = ends;
    Cylinder& c = layer.cyl;
    const Local* points = layer.points;
    const size_t n = layer.count;
    ends &= ~layer.cut_ends;
    if (!kClosedEnds || !ends || n == 0) return;
    double lo = points[0].h, hi = lo;
    for (size_t i = 1; i < n; ++i) {
        lo = points[i].h < lo ? points[i].h : lo;
        hi = points[i].h > hi ? points[i].h : hi;
    }
    const double reach = 1 / c.scale, mid = lo + (hi - lo) / 2;
    const double slab = kEndSlab * reach < (hi - lo) / 3 ? kEndSlab * reach : (hi - lo) / 3;
    auto end_of = [&](const Local& p) { return p.h < lo + slab ? 0 : p.h > hi - slab ? 1 : -1; };
    auto distance = [&](const Local& p) {
        const double dx = p.x - c.cx, dy = p.y - c.cy;
        return std::sqrt(dx * dx + dy * dy);
    };
    // Each end in turn. "Across" is measured against the slab's own width, so the narrow
    // open end of a widening layer (a vase) is not taken for a closed one.
    double outline[kSectors];  // per sector: the farthest point beyond the slab
    for (int end = 0; end < 2; ++end) {
        if (!(ends & (1u << end))) continue;
        auto beyond = [&](const Local& p) {
            return end == 0 ? p.h >= lo + slab && p.h < lo + 2 * slab
                            : p.h <= hi - slab && p.h > hi - 2 * slab;
        };
        auto sector = [&](const Local& p) { return sector_around(p.x - c.cx, p.y - c.cy); };
        double in_slab = 0, slab_radius = 0;
        for (double& o : outline) o = 0;
        for (size_t i = 0; i < n; ++i) {
            const double d = distance(points[i]);
            if (end_of(points[i]) == end) {
                in_slab += 1;
                slab_radius += d;
            } else if (beyond(points[i])) {
                double& o = outline[sector(points[i])];
                o = d > o ? d : o;
            }
        }
        if (in_slab == 0) continue;
        const double limit = kAcrossEnd * slab_radius / in_slab;
        double across = 0, inside = 0, across_rest = 0, in_rest = 0;
        for (size_t i = 0; i < n; ++i) {
            const double d = distance(points[i]);
            const int at = end_of(points[i]);
            across += at == end && d < limit;
            inside += at == end && d < limit && d < kAcrossEnd * outline[sector(points[i])];
            across_rest += at < 0 && d < limit;
            in_rest += at < 0;
        }
        // Two ways to be closed. More of the slab across than of the layer between the
        // slabs: a section that is not star-shaped around the centre (two lobes) has as
        // many all along. Or, where that fails, well inside the outline of the slab beyond,
        // sector by sector, which a lobed section's waist (a peanut, a trefoil) is not, but
        // a knobbed end's is (a femur's condyles: the notch between them rises into the
        // layer and brings its points near the axis); that slab must surround the axis (a
        // point in every octant, as sparse layers leave a few sectors empty), which the end
        // of a tube passing beside the axis (a bent tube's) does not.
        bool surrounded = true;
        for (uint32_t octant = 0; octant < 8; ++octant) {
            bool held = false;
            for (uint32_t k = octant * (kSectors / 8); k < (octant + 1) * (kSectors / 8); ++k)
                held = held || outline[k] > 0;
            surrounded = surrounded && held;
        }
        const bool from_rest = across * in_rest > 2 * across_rest * in_slab;
        const bool from_outline = surrounded && inside >= 3 && 20 * inside >= in_slab;
        const bool enough = across >= 3 && 20 * across >= in_slab;
        if (enough && (from_rest || from_outline)) c.poles |= 1u << end;
    }
    const double low_limit = (c.poles & kHighPole) ? mid : hi - (hi - lo) / 4;
    const double high_limit = (c.poles & kLowPole) ? mid : lo + (hi - lo) / 4;
    c.pole_low = lo + kPoleDepth * reach < low_limit ? lo + kPoleDepth * reach : low_limit;
    c.pole_high = hi - kPoleDepth * reach > high_limit ? hi - kPoleDepth * reach : high_limit;
}

// ---- the centre search ----
//
// A layer that is not star-shaped around its centre (a C-shaped cross-section, a condyle
// beside a shaft) folds: rays from the centre cross its surface twice, and the unrolled
// triangulation bridges the two sheets. Another centre may see more of it. The layer's
// sample (every k-th point, at most kCentreSamplePoints) is triangulated around the fitted
// centre; if it folds, around each of the 24 other centres of a 5 x 5 grid (steps of
// kCentreStep radii, the inner ring first) too, and the layer is unrolled around the
// centre whose sample folds least; among centres with as few folds, the one whose sample
// has the least area (bridges add area), and the fitted centre on ties with it. Radius and
// scale stay the fitted ones, and a centre outside the sample's hull is never taken (the
// layer must surround it). The search needs less workspace than the layer's own
// triangulation. Cost: one triangulation of the sample per layer (little: a tube's layers
// do not fold), 25 for a layer that folds, at most about 25,000 insertions per layer on
// large ones. With the band's centre choice in >>stitch it removes most of the crossing
// triangle pairs of scans whose layers fold; smaller samples lose most of that. A layer
// that bridges a concavity without folding (a membrane over the neck between two lobes)
// is not searched: searching every layer costs a third more time on a large tube and
// gives scans no fewer self-intersections.

const size_t kCentreSamplePoints = 1024;

const int32_t kCentreRings = 2;  // the candidates: a 5 x 5 grid around the fitted centre

const double kCentreStep = 0.3;

// The folds of the sample points[0], points[stride], ... (count of them) rolled around
// cyl's centre and triangulated, with the doubled area of its surface in *area; SIZE_MAX
// where the centre does not lie inside the sample's hull (it does not surround that
// centre). Its scratch is released.
static inline size_t sample_folds(const Local* points, size_t count, size_t stride,
                           const Cylinder& cyl, Arena& arena, double* area) {
    *area = 0;
    size_t mark = arena.mark(), folds = SIZE_MAX;
    double* xy = arena.alloc<double>(2 * (count + 1));
    Triangulation tr;
    tr.xy = xy;
    uint32_t inserted = 0;
    if (allocate_triangulation(tr, count + 1, arena)) {
        xy[0] = xy[1] = 0;
        for (size_t k = 0; k < count; ++k) roll(cyl, points[k * stride], xy + 2 * (k + 1));
        if (triangulate_points(tr, static_cast<uint32_t>(count + 1),
                               DuplicateSink{nullptr, nullptr}, &inserted) == Status::ok)
            folds = 0;
    }
    for (uint32_t t = 0; folds == 0 && t < tr.triangle_count; ++t) {
        const uint32_t* v = tr.vertex + 3 * t;
        if (tr.is_ghost(t) && (v[0] == 0 || v[1] == 0 || v[2] == 0)) folds = SIZE_MAX;
    }
    if (folds == 0) folds = count_folds(tr, points, stride, cyl, area);
    arena.rewind(mark);
    return folds;
}

// Moves layer.cyl's centre where a sample of the layer folds least (see above).
static inline void choose_centre(LoadedLayer& layer, Arena& arena) {
    const size_t stride = layer.count / kCentreSamplePoints + 1;
    const size_t count = (layer.count + stride - 1) / stride;
    const Cylinder fitted = layer.cyl;
    size_t fitted_folds = 0, fewest = 0;
    double least = 0;
    // Ring 0 is the fitted centre; rings 1 and 2 are the borders of the 3 x 3 and 5 x 5 grids.
    for (int32_t ring = 0; ring <= kCentreRings; ++ring)
        for (int32_t dy = -ring; dy <= ring; ++dy)
            for (int32_t dx = -ring; dx <= ring; ++dx) {
                if (dx != ring && dx != -ring && dy != ring && dy != -ring) continue;
                Cylinder candidate = fitted;
                candidate.cx += kCentreStep * fitted.radius * dx;
                candidate.cy += kCentreStep * fitted.radius * dy;
                double area = 0;
                const size_t folds =
                    sample_folds(layer.points, count, stride, candidate, arena, &area);
                if (ring == 0) {
                    if (folds == 0) return;
                    fitted_folds = fewest = folds;
                    least = area;
                } else if (folds < fewest ||
                           (folds == fewest && fewest < fitted_folds && area < least)) {
                    // Fewer folds; as few and less area, once the fitted centre is beaten.
                    fewest = folds;
                    least = area;
                    layer.cyl = candidate;
                }
            }
}

}  // namespace detail
}  // namespace stratmesh
