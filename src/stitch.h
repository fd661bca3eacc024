// >>stitch ===============================================================================
// The band between two layers' loops.
//
// Two neighbouring layers meet at a cut: the top loop A of the lower layer and the bottom
// loop B of the upper one are closed loops around the axis. Both are unrolled onto one
// strip (u, v) = (R theta, h - cut) around the average of the two cylinders: A below the
// cut, B above it. (Where the band settled on that strip folds, it is settled again around
// each layer's own centre and the band with the least area is kept: once the centre
// search has moved a centre, the midpoint may lie outside what both loops are star-shaped
// around.) A zipper merges the loops by angle: each step adds a triangle on the
// next edge of A or of B, so the band is a manifold annulus by construction. Then the
// paper's diagonal swap: a rung shared by an A-triangle and a B-triangle is swapped when
// the opposite vertex lies in the circumcircle (Lawson flips, which terminate in one fixed
// plane), or when the zipper folded a sliver that the swap unfolds. A swap only ever
// exchanges adjacent A and B steps, so the band stays a band; a clockwise step the swaps
// cannot reach is then untangled across its run (see untangle_runs). The strip is
// periodic: a vertex reached again after a full turn is shifted by the circumference. The
// rung that closes the loop (first A vertex to first B vertex) is kept by both, so the band
// restarts half-way round for a second pass of each. The strip, not the annulus, is used
// here because band triangles are long and flat: on the annulus the circle's curvature would
// flip their orientation relative to the surface. The loops come peeled (see "peeling" in
// >>layer triangulation): they hug the cut, so the band's triangles join points about one
// spacing apart; where a band between peeled loops still folds, add_group stitches it again
// from the loops as they were, with the peeled triangles put back.

namespace stratmesh {
namespace detail {

// Rotates loop[0..n) and its strip coordinates so that entry `first` comes first; the
// entries moved to the end are shifted by `turn` (one period of the strip), so angles
// keep increasing along the loop.
static inline void rotate_loop(uint32_t* loop, double* uv, uint32_t n, uint32_t first,
                               double turn) {
    for (uint32_t i = 0; i < first; ++i) uv[2 * i] += turn;
    // Three reversals rotate in place.
    auto reverse = [&](uint32_t lo, uint32_t hi) {  // the range [lo, hi)
        for (; hi > lo + 1; ++lo) {
            --hi;
            uint32_t t = loop[lo];
            loop[lo] = loop[hi];
            loop[hi] = t;
            for (uint32_t k = 0; k < 2; ++k) {
                double c = uv[2 * lo + k];
                uv[2 * lo + k] = uv[2 * hi + k];
                uv[2 * hi + k] = c;
            }
        }
    };
    reverse(0, first);
    reverse(first, n);
    reverse(0, n);
}

// Rotates loop[0..n) so its smallest angle comes first (angles in [0, turn)).
static inline void rotate_to_first_angle(uint32_t* loop, double* uv, uint32_t n) {
    uint32_t first = 0;
    for (uint32_t i = 1; i < n; ++i)
        if (uv[2 * i] < uv[2 * first]) first = i;
    rotate_loop(loop, uv, n, first, 0);
}

struct Band {
    uint32_t* a;        // loop A, band indices (see stitch_layers)
    double* xa;         // its strip coordinates, angles increasing from the smallest
    uint32_t p;
    uint32_t* b;
    double* xb;
    uint32_t q;
    double turn;        // the strip's period, 2 pi R
    unsigned char* steps;  // p + q: 0 = advance A, 1 = advance B
    double* scratch;       // incircle scratch
    double corner[4][2];   // the current quad, unwrapped

    // Strip coordinates of the i-th vertex of A counted from the start, i <= p.
    const double* pa(uint32_t i, int slot) {
        corner[slot][0] = xa[2 * (i % p)] + (i >= p ? turn : 0);
        corner[slot][1] = xa[2 * (i % p) + 1];
        return corner[slot];
    }
    const double* pb(uint32_t j, int slot) {
        corner[slot][0] = xb[2 * (j % q)] + (j >= q ? turn : 0);
        corner[slot][1] = xb[2 * (j % q) + 1];
        return corner[slot];
    }

    // Whether the steps at t, t+1 (state i, j before t) should be swapped. Counter-clockwise
    // on the strip, an A step makes (a0, a1, b0) and a B step (a0, b1, b0). A swap is
    // taken when the swapped pair is proper and either the current pair is not (the
    // zipper made a folded sliver: untangle it) or the empty-circle test asks for it.
    bool should_swap(uint32_t t, uint32_t i, uint32_t j) {
        const double *a0 = pa(i, 0), *a1 = pa(i + 1, 1), *b0 = pb(j, 2), *b1 = pb(j + 1, 3);
        bool a_then_b = steps[t] == 0;
        // A then B: (a0 a1 b0), (a1 b1 b0). B then A: (a0 b1 b0), (a0 a1 b1).
        bool proper_ab = orient2d_robust(a0, a1, b0) > 0 && orient2d_robust(a1, b1, b0) > 0;
        bool proper_ba = orient2d_robust(a0, b1, b0) > 0 && orient2d_robust(a0, a1, b1) > 0;
        if (a_then_b ? !proper_ba : !proper_ab) return false;
        if (a_then_b ? !proper_ab : !proper_ba) return true;
        if (a_then_b) return incircle_perturbed(a0, a1, b0, b1, scratch) > 0;
        return incircle_perturbed(a0, b1, b0, a1, scratch) > 0;
    }

    // Whether step t (state i, j before it) is counter-clockwise on the strip: an A step
    // makes (a0 a1 b0), a B step (a0 b1 b0).
    bool proper(uint32_t t, uint32_t i, uint32_t j) {
        const double* a0 = pa(i, 0);
        const double* b0 = pb(j, 2);
        return orient2d_robust(a0, steps[t] == 0 ? pa(i + 1, 1) : pb(j + 1, 1), b0) > 0;
    }
};

// A step sequence is a band only if no rung repeats: walking all of A while B stands
// still (or all of B) would return to the rung it started from. That happens exactly when
// the cyclic sequence has a single run of A steps, so a band needs at least two.
static inline bool starts_a_run(const unsigned char* steps, uint32_t length, uint32_t k) {
    return steps[k % length] == 0 && steps[(k + length - 1) % length] == 1;
}

static inline uint32_t count_a_runs(const unsigned char* steps, uint32_t length) {
    uint32_t runs = 0;
    for (uint32_t k = 0; k < length; ++k) runs += starts_a_run(steps, length, k);
    return runs;
}

// Whether swapping steps t and t + 1 keeps at least two runs of A (only the run starts at
// t, t + 1 and t + 2 can change).
static inline bool swap_keeps_band(unsigned char* steps, uint32_t length, uint32_t t,
                                   uint32_t runs) {
    uint32_t before = 0, after = 0;
    for (uint32_t k = t; k < t + 3; ++k) before += starts_a_run(steps, length, k);
    unsigned char s = steps[t];
    steps[t] = steps[t + 1];
    steps[t + 1] = s;
    for (uint32_t k = t; k < t + 3; ++k) after += starts_a_run(steps, length, k);
    steps[t + 1] = steps[t];
    steps[t] = s;
    return runs - before + after >= 2;
}

// Merges the loops by angle; if that walks one loop in a single run (tiny or skewed
// loops), one boundary step is swapped so the band is a band.
static inline void zip_by_angle(Band& band) {
    const uint32_t length = band.p + band.q;
    uint32_t i = 0, j = 0, t = 0;
    while (i < band.p || j < band.q) {
        bool take_a;
        if (i == band.p) take_a = false;
        else if (j == band.q) take_a = true;
        else take_a = band.pa(i + 1, 0)[0] <= band.pb(j + 1, 1)[0];
        band.steps[t++] = take_a ? 0 : 1;
        if (take_a) ++i; else ++j;
    }
    if (count_a_runs(band.steps, length) >= 2) return;
    for (t = 0; t + 1 < length; ++t) {
        if (band.steps[t] == band.steps[t + 1]) continue;
        unsigned char s = band.steps[t];
        band.steps[t] = band.steps[t + 1];
        band.steps[t + 1] = s;
        return;
    }
}

// Lawson flips over the step sequence; returns the number of swaps.
static inline size_t swap_diagonals(Band& band) {
    const uint32_t length = band.p + band.q;
    const size_t limit = 16 * static_cast<size_t>(length) + 64;
    uint32_t runs = count_a_runs(band.steps, length);
    size_t swaps = 0;
    uint32_t t = 0, i = 0, j = 0;
    while (t + 1 < length) {
        if (band.steps[t] != band.steps[t + 1] && swaps < limit && band.should_swap(t, i, j) &&
            swap_keeps_band(band.steps, length, t, runs)) {
            uint32_t before = 0, after = 0;
            for (uint32_t k = t; k < t + 3; ++k) before += starts_a_run(band.steps, length, k);
            unsigned char s = band.steps[t];
            band.steps[t] = band.steps[t + 1];
            band.steps[t + 1] = s;
            for (uint32_t k = t; k < t + 3; ++k) after += starts_a_run(band.steps, length, k);
            runs = runs - before + after;
            ++swaps;
            if (t > 0) {
                --t;
                if (band.steps[t] == 0) --i; else --j;
            }
            continue;
        }
        if (band.steps[t] == 0) ++i; else ++j;
        ++t;
    }
    return swaps;
}

// The swaps only exchange neighbouring A and B steps, so a clockwise step inside a run of
// one loop stays (as does one whose swapped pair is clockwise too). Both loops hug the
// cut, so band triangles are flat, and an A step (a0 a1 b0) turns clockwise, a sliver
// facing the axis, when b0 lies below the line through a0 and a1: behind a0 with a1
// dipping, or past a1 with a1 rising (a B step likewise). Moving the other loop's next
// step back to it, or its previous step forward, across the run hangs the edge from the
// other loop's next (or previous) vertex; only the triangles of that stretch change, and
// the move is kept when they all turn counter-clockwise and the band keeps two runs of A.
// Returns the adjacent exchanges made.
static inline size_t untangle_runs(Band& band) {
    // Longer runs (a fan from one vertex over many of the other loop) are left as they
    // are: this bounds the work at kLongestUntangledRun steps per step of the band.
    const uint32_t kLongestUntangledRun = 64;
    const uint32_t length = band.p + band.q;
    unsigned char* steps = band.steps;
    uint32_t runs = count_a_runs(steps, length);
    // Run starts at lo .. hi + 1: the only ones a change of steps [lo, hi] can move.
    auto starts_near = [&](uint32_t lo, uint32_t hi) {
        uint32_t starts = 0;
        for (uint32_t k = lo; k <= hi + 1; ++k) starts += starts_a_run(steps, length, k);
        return starts;
    };
    size_t moves = 0;
    uint32_t i = 0, j = 0;
    for (uint32_t t = 0; t < length; ++t) {
        const unsigned char kind = steps[t];
        unsigned char taken = kind;  // what step t adds to the state
        if (!band.proper(t, i, j)) {
            uint32_t next = t + 1, previous = t;
            const uint32_t most = kLongestUntangledRun;
            while (next < length && steps[next] == kind && next - t <= most) ++next;
            while (previous > 0 && steps[previous - 1] == kind && t - previous <= most) --previous;
            const uint32_t run = t - previous;  // steps of the run before t
            const bool short_run = next - previous <= most;
            for (int backward = 0; short_run && backward < 2; ++backward) {
                // Steps [lo, hi] change: the other loop's step goes from `from` to t.
                const uint32_t lo = backward ? previous - 1 : t, hi = backward ? t : next;
                const uint32_t from = backward ? lo : hi;
                if (backward ? previous == 0 : next == length) continue;
                const unsigned char other = steps[from];
                const uint32_t starts_before = starts_near(lo, hi);
                for (uint32_t k = lo; k <= hi; ++k) steps[k] = kind;
                steps[t] = other;
                const uint32_t runs_after = runs - starts_before + starts_near(lo, hi);
                bool ok = runs_after >= 2;
                // The state before lo: for a backward move, the run and that step undone.
                uint32_t ik = backward ? i - (kind == 0 ? run : 1) : i;
                uint32_t jk = backward ? j - (kind == 0 ? 1 : run) : j;
                for (uint32_t k = lo; ok && k <= hi; ++k) {
                    ok = band.proper(k, ik, jk);
                    if (steps[k] == 0) ++ik; else ++jk;
                }
                if (ok) {
                    runs = runs_after;
                    moves += hi - lo;
                    taken = backward ? kind : other;  // backward: the same steps up to t
                    break;
                }
                for (uint32_t k = lo; k <= hi; ++k) steps[k] = kind;
                steps[from] = other;
            }
        }
        if (taken == 0) ++i; else ++j;
    }
    return moves;
}

// Rotates the band (its loops and steps) to start half-way round. False if the half-way
// point does not fall between the ends of both loops (the band stays as it is).
static inline bool restart_half_way(Band& band) {
    const uint32_t length = band.p + band.q, half = length / 2;
    uint32_t i_half = 0, j_half = 0;
    for (uint32_t t = 0; t < half; ++t) (band.steps[t] == 0 ? i_half : j_half) += 1;
    if (!(i_half > 0 && i_half < band.p && j_half > 0 && j_half < band.q)) return false;
    rotate_loop(band.a, band.xa, band.p, i_half, band.turn);
    rotate_loop(band.b, band.xb, band.q, j_half, band.turn);
    unsigned char* steps = band.steps;
    auto reverse = [steps](uint32_t lo, uint32_t hi) {  // the range [lo, hi)
        for (; hi > lo + 1; ++lo) {
            --hi;
            unsigned char c = steps[lo];
            steps[lo] = steps[hi];
            steps[hi] = c;
        }
    };
    reverse(0, half);
    reverse(half, length);
    reverse(0, length);
    return true;
}

// Whether every step of the band is counter-clockwise on the strip.
static inline bool band_is_proper(Band& band) {
    uint32_t i = 0, j = 0;
    for (uint32_t t = 0; t < band.p + band.q; ++t) {
        if (!band.proper(t, i, j)) return false;
        if (band.steps[t] == 0) ++i; else ++j;
    }
    return true;
}

// Zips the loops and settles the band: the empty-circle swaps, and the untangling of
// clockwise steps. The closing rung is held fixed by both: the band restarts half-way round
// and swaps again, so the quads around it get their test too, and where a clockwise step is
// left next to it, untangles once more from there.
static inline void settle_band(Band& band, size_t* swaps) {
    zip_by_angle(band);
    *swaps += swap_diagonals(band);
    if (restart_half_way(band)) *swaps += swap_diagonals(band);
    *swaps += untangle_runs(band);
    if (!band_is_proper(band) && restart_half_way(band)) *swaps += untangle_runs(band);
}

// Marks kUnpeeled the peeled entries of a loop's flags[0..n) in the peel groups around entry
// k: the entries between the nearest ones before and after k that were on the loop before
// peeling (pass 0; entry 0 is one). A peeled vertex came off an edge between entries of
// earlier passes in its group, so the group put back whole leaves the loop as it was
// there, and the other groups' peeling as it is.
static inline void unpeel_around(unsigned char* flags, uint32_t n, uint32_t k) {
    auto unpeel = [flags](uint32_t i) {
        if (!(flags[i] & kPassBits)) return false;
        flags[i] |= kUnpeeled;
        return true;
    };
    unpeel(k);
    for (uint32_t i = k; i > 0 && unpeel(i - 1); --i) {}
    for (uint32_t i = (k + 1) % n; i != k && unpeel(i); i = (i + 1) % n) {}
}

// Marks every peeled entry of flags[0..n) kUnpeeled or, with !on, none.
static inline void mark_unpeeled(unsigned char* flags, uint32_t n, bool on) {
    for (uint32_t i = 0; i < n; ++i)
        flags[i] = static_cast<unsigned char>(on && (flags[i] & kPassBits) ? flags[i] | kUnpeeled
                                                                           : flags[i] & ~kUnpeeled);
}

static inline size_t count_unpeeled(const unsigned char* flags, uint32_t n) {
    size_t marked = 0;
    for (uint32_t i = 0; i < n; ++i) marked += (flags[i] & kUnpeeled) != 0;
    return marked;
}

// A band being stitched (see stitch_layers): its loops in band indices, where their points
// come from, and the strip they are unrolled on.
struct Stitch {
    const CloudReader* cloud;
    const Frame* frame;
    const LoadedLayer* layer;
    const LayerLoops* loops;
    unsigned char* a_flags;  // loop A's, every entry (a_length)
    uint32_t a_length;
    uint32_t below;          // the band index of A's entry 0: layer.count
    Local* a_points;         // A's points, every entry
    Cylinder shared;         // the strip's cylinder; its centre is set per trial
    double unrolled_radius;
    Band band;

    // The point of band index id. The layer's points are read again (the loaded ones are in
    // triangulate_layer's order, or were never loaded when a job triangulated the layer):
    // only the loop's are read.
    Local point(uint32_t id) const {
        if (id >= below) return a_points[id - below];
        return frame->local(cloud->point(layer->ids[id]));
    }
    void unroll(uint32_t id, double* uv) const {
        const Local l = point(id);
        uv[0] = unrolled_radius * polar_angle(l.x - shared.cx, l.y - shared.cy);
        uv[1] = l.h - shared.h0;
    }
};

// Emits the triangles peeled off loop A (`top`: the lower layer's top loop) or the layer's
// bottom loop (see "peeling" in >>layer triangulation), with kLocalUnpeel those whose
// vertex is marked kUnpeeled, else all: vertex x, peeled in pass k, came off the edge
// between the nearest loop vertices before and after it from earlier passes (entry 0 is on
// the hull or the link).
static inline void put_back_peeled(const Stitch& st, bool top, TriangleSink& sink) {
    const unsigned char* flags = top ? st.a_flags : st.loops->bottom_flags;
    const uint32_t n = top ? st.a_length : st.loops->bottom_count;
    auto pass = [flags](uint32_t i) { return flags[i] & kPassBits; };
    auto id = [&st, top](uint32_t i) { return top ? st.below + i : st.loops->bottom[i]; };
    for (uint32_t x = 0; x < n; ++x) {
        if (!pass(x) || (kLocalUnpeel && !(flags[x] & kUnpeeled))) continue;
        uint32_t before = x - 1, after = (x + 1) % n;
        while (pass(before) >= pass(x)) --before;
        while (pass(after) >= pass(x)) after = (after + 1) % n;
        // Counter-clockwise on the annulus: the top loop's edge ran before -> after, the
        // bottom loop's after -> before.
        uint32_t u = id(top ? before : after), v = id(top ? after : before), w = id(x);
        sink.emit(u, v, w, st.point(u), st.point(v), st.point(w), st.shared);
    }
}

// Carves the band's loops from the arena and fills them with the entries of A (reader
// indices a_ids) and of the layer's bottom loop that are not left out (see stitch_layers),
// A's points copied. False if the arena is too small.
static inline bool gather_band_loops(Stitch& st, const uint32_t* a_ids, bool unpeel, Arena& arena) {
    const LayerLoops& loops = *st.loops;
    Band& band = st.band;
    band.a = arena.alloc<uint32_t>(st.a_length);
    band.b = arena.alloc<uint32_t>(loops.bottom_count);
    st.a_points = arena.alloc<Local>(st.a_length);
    band.xa = arena.alloc<double>(2 * static_cast<size_t>(st.a_length));
    band.xb = arena.alloc<double>(2 * static_cast<size_t>(loops.bottom_count));
    band.steps = arena.alloc<unsigned char>(static_cast<size_t>(st.a_length) + loops.bottom_count);
    band.scratch = arena.alloc<double>(kIncircleScratch);
    if (arena.failed) return false;
    auto left_out = [unpeel](unsigned char f) {
        return (f & kPassBits) && (unpeel || (kLocalUnpeel && (f & kUnpeeled)));
    };
    band.p = 0;
    for (uint32_t i = 0; i < st.a_length; ++i) {
        if (!left_out(st.a_flags[i])) band.a[band.p++] = st.below + i;
        st.a_points[i] = st.frame->local(st.cloud->point(a_ids[i]));
    }
    band.q = 0;
    for (uint32_t j = 0; j < loops.bottom_count; ++j)
        if (!left_out(loops.bottom_flags[j])) band.b[band.q++] = loops.bottom[j];
    return true;
}

// Unrolls both loops around the centre (cx, cy) and settles the band there.
static inline void settle_band_around(Stitch& st, double cx, double cy, size_t* swaps) {
    Band& band = st.band;
    st.shared.cx = cx;
    st.shared.cy = cy;
    for (uint32_t i = 0; i < band.p; ++i) st.unroll(band.a[i], band.xa + 2 * i);
    for (uint32_t j = 0; j < band.q; ++j) st.unroll(band.b[j], band.xb + 2 * j);
    rotate_to_first_angle(band.a, band.xa, band.p);
    rotate_to_first_angle(band.b, band.xb, band.q);
    settle_band(band, swaps);
}

// Walks the settled band: returns its folds, adds its doubled area to *area and, with a
// sink, writes its triangles there and (kLocalUnpeel) marks the peel groups around the
// folds: those around the state's a[i] and b[j], which hold the triangle's third corner
// too unless it is on the loop since before peeling. B's entry of b[j] is found walking
// loops.bottom along (b is in its order, rotated), once around at most.
static inline size_t walk_band(const Stitch& st, TriangleSink* sink, double* area) {
    const Band& band = st.band;
    const LayerLoops& loops = *st.loops;
    const uint32_t p = band.p, q = band.q;
    size_t folds = 0;
    uint32_t i = 0, j = 0, entry = 0;
    for (uint32_t t = 0; t < p + q; ++t) {
        uint32_t x, y, z;  // counter-clockwise on the annulus
        const uint32_t a0 = band.a[i % p], b0 = band.b[j % q];
        if (band.steps[t] == 0) {
            x = band.a[(i + 1) % p], y = a0, z = b0;
            ++i;
        } else {
            x = b0, y = band.b[(j + 1) % q], z = a0;
            ++j;
        }
        const Local px = st.point(x), py = st.point(y), pz = st.point(z);
        const bool folded = faces_axis(px, pz, py, st.shared);
        folds += folded;
        *area += doubled_area(px, py, pz);
        if (sink) sink->write(x, y, z);
        if (!kLocalUnpeel || !sink || !folded) continue;
        for (uint32_t k = 0; k < loops.bottom_count && loops.bottom[entry] != b0; ++k)
            entry = (entry + 1) % loops.bottom_count;
        unpeel_around(st.a_flags, st.a_length, a0 - st.below);
        unpeel_around(loops.bottom_flags, loops.bottom_count, entry);
    }
    return folds;
}

// Settles the band around the strip's centre: the cylinders' midpoint; where the band
// folds around it (the loops turn back around it: after choose_centre moved one of the
// centres, the midpoint may lie outside what both loops are star-shaped around), the one
// of the midpoint and the two layers' centres whose settled band has the least area. Trial
// 3 settles the band again around that one, unless it was the last tried. Returns the
// swaps of the band kept.
static inline size_t settle_least_area(Stitch& st, const Cylinder& ca, const Cylinder& cb) {
    const Cylinder* centres[3] = {nullptr, &ca, &cb};  // 0: the midpoint
    double least = 0;
    uint32_t best = 0;
    size_t best_swaps = 0;
    for (uint32_t trial = 0; trial < 4 && !(trial == 3 && best == 2); ++trial) {
        const uint32_t k = trial < 3 ? trial : best;
        size_t trial_swaps = 0;
        settle_band_around(st, k ? centres[k]->cx : (ca.cx + cb.cx) / 2,
                           k ? centres[k]->cy : (ca.cy + cb.cy) / 2, &trial_swaps);
        if (trial == 3) break;
        double area = 0;
        const size_t folds = walk_band(st, nullptr, &area);
        if (trial == 0 || area < least) {
            least = area;
            best = k;
            best_swaps = trial_swaps;
        }
        if (folds == 0 && trial == 0) break;
    }
    return best_swaps;
}

// Stitches loop A (the lower layer's top loop: reader indices a_ids with their seam flags,
// cylinder ca) to the loaded upper layer's bottom loop (loops.bottom, layer-local indices;
// the layer's cylinder has the cut as h0). With `unpeel`, both loops as they were before
// peeling, and the peeled triangles put back (with kLocalUnpeel the caller marks them all
// kUnpeeled first); else, with kLocalUnpeel, the entries marked kUnpeeled are left out and
// their peeled triangles put back, and each band triangle that faces the axis marks the
// peel groups around its corners kUnpeeled (unpeel_around) for a next attempt. The band's
// triangles name the upper layer's points by layer-local index and the i-th point of A by
// layer.count + i.
static inline bool stitch_layers(const CloudReader& cloud, const Frame& frame, const Cylinder& ca,
                                 const uint32_t* a_ids, unsigned char* a_flags, uint32_t p,
                                 const LoadedLayer& layer, const LayerLoops& loops, bool unpeel,
                                 Arena& arena, TriangleSink& sink, size_t* swaps) {
    const Cylinder& cb = layer.cyl;
    Stitch st;
    st.cloud = &cloud;
    st.frame = &frame;
    st.layer = &layer;
    st.loops = &loops;
    st.a_flags = a_flags;
    st.a_length = p;
    st.below = static_cast<uint32_t>(layer.count);
    const size_t mark = arena.mark();
    if (!gather_band_loops(st, a_ids, unpeel, arena)) return false;
    st.shared.poles = 0;
    st.shared.radius = (ca.radius + cb.radius) / 2;
    st.shared.h0 = cb.h0;
    st.shared.scale = (ca.scale + cb.scale) / 2;
    st.unrolled_radius = 1 / st.shared.scale;
    const double two_pi = 6.28318530717958647693;
    st.band.turn = two_pi * st.unrolled_radius;
    *swaps += settle_least_area(st, ca, cb);
    if (kLocalUnpeel || unpeel) {
        put_back_peeled(st, true, sink);
        put_back_peeled(st, false, sink);
    }
    double area = 0;
    sink.folds += walk_band(st, &sink, &area);
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh
