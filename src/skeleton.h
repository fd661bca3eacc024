// >>skeleton =============================================================================
// Objects that bend: layers across a skeleton of geodesic rings, not one straight axis.
//
// find_skeleton(): on a sample of about kSkeletonSample kept points (by a hash of their
// coordinates), a graph joining each point to its kMostNeighbours nearest within
// kReachDeciles nearest-neighbour deciles (found in a grid of that side), its largest
// connected piece, and the distance along the graph from one end of the object (Dijkstra
// from the point farthest along the graph from an extreme point; its heap an array). Bands
// of that distance, each at least two reaches wide, fall into connected pieces: the
// object's rings around its centre line (Verroust and Lazarus, "Extracting skeletal curves
// from 3D scattered data", 2000). Where every band holds one ring, the centres of circles
// fitted to the rings, smoothed by Taubin's filter (which does not pull a bend inward), are
// the skeleton: a polyline with a frame carried along it without twist.
// The object counts as bent where that polyline is kLongRadii ring radii long or more,
// strays kStrayRadii from its chord, and turns nowhere more tightly than kTightestTurn
// radii (tighter, the straightened coordinates below would fold). Then mesh_if_bent()
// meshes it as one tube in straightened coordinates: each point across its nearest
// skeleton segment (two coordinates in the frame there) and along it (arc length), so the
// layers are the skeleton's cross-sections wherever the object goes, and the triangles
// index the cloud as ever. A band with two rings is a branch (or a handle): such an object
// goes on to the parts (>>parts), as does a straight one.

namespace stratmesh {
namespace detail {

// Points the skeleton is found on: enough for rings of tens of points on a coil of two
// turns, few enough to cost a few milliseconds.
const size_t kSkeletonSample = 4096;
// Points the nearest-neighbour decile is measured on: a decile needs no more.
const size_t kSpacingSample = 2048;
// Neighbours are joined within this many nearest-neighbour deciles: on a uniformly random
// sample of a surface, about 20 points, and a graph in one piece.
const double kReachDeciles = 3.0;
// The most bands (so skeleton nodes): the smallest band is two reaches wide, or this share
// of the object's geodesic length.
const uint32_t kMostBands = 256;
// A piece of a band counts as a ring from this share of the band's points (and at least
// kMinRingPoints): smaller pieces are specks the graph did not join. Small enough that an
// animal's leg beside its body counts.
const uint32_t kRingShare = 32;
const uint32_t kMinRingPoints = 8;
// Bent: at least this long and straying this far from the chord, in ring radii.
const double kLongRadii = 8.0;
const double kStrayRadii = 2.0;
// The tightest turn the straightening follows, as the skeleton's radius of curvature over
// the rings' radius.
const double kTightestTurn = 1.5;
const double kUnreached = DBL_MAX;
// Taubin's smoothing of the skeleton: passes, and the weights in and back out.
const int kSmoothingPasses = 10;
const double kSmoothIn = 0.5;
const double kSmoothOut = -0.53;

// The skeleton: nodes along the object's centre line with a frame each (tangent and a
// normal carried along without twist) and their arc length from the first.
struct Skeleton {
    Vec3* centre;
    Vec3* tangent;
    Vec3* normal;
    double* arc;
    uint32_t count;
};

// The neighbours a point keeps: its nearest within reach. Where the density varies, the
// reach that joins the sparse parts holds hundreds of points in the dense ones.
const uint32_t kMostNeighbours = 16;

// The sample's neighbourhood graph: the points in grid order (cells of side `reach`), and
// each one's neighbours, neighbour[first[j] .. first[j + 1]).
struct SkeletonGraph {
    CellScratch grid;
    size_t count;
    double reach;
    uint32_t* first;
    uint32_t* neighbour;
};

// The nearest points within reach of one point, kept in a max-heap by squared distance
// (ties by index) as the candidates go by.
struct NearestKept {
    double square[kMostNeighbours];
    uint32_t index[kMostNeighbours];
    uint32_t count;
    bool after(uint32_t a, uint32_t b) const {
        return square[a] > square[b] || (square[a] == square[b] && index[a] > index[b]);
    }
    void swap(uint32_t a, uint32_t b) {
        const double s = square[a];
        const uint32_t i = index[a];
        square[a] = square[b], index[a] = index[b];
        square[b] = s, index[b] = i;
    }
    void offer(double q, uint32_t k) {
        uint32_t at;
        if (count < kMostNeighbours) {
            at = count++;
            square[at] = q, index[at] = k;
            while (at > 0 && after(at, (at - 1) / 2)) swap(at, (at - 1) / 2), at = (at - 1) / 2;
            return;
        }
        if (q > square[0] || (q == square[0] && k > index[0])) return;
        square[0] = q, index[0] = k, at = 0;
        for (;;) {
            uint32_t child = 2 * at + 1;
            if (child >= count) break;
            if (child + 1 < count && after(child + 1, child)) ++child;
            if (!after(child, at)) break;
            swap(at, child);
            at = child;
        }
    }
};

// The neighbours of every point: its nearest within reach in the block of cells around its
// cell, the block found once a cell (the cells come in key order, so `fingers` help).
static inline void link_neighbours(SkeletonGraph& g) {
    const double reach2 = g.reach * g.reach;
    size_t fingers[18] = {};
    uint32_t edges = 0;
    for (size_t cell = 0; cell < g.count;) {
        size_t end = cell;
        while (end < g.count && g.grid.items[end].cell == g.grid.items[cell].cell) ++end;
        const CellBlock block = block_around(g.grid.items, g.count, cell, fingers);
        for (size_t j = cell; j < end; ++j) {
            g.first[j] = edges;
            const Vec3 p = g.grid.sorted[j];
            NearestKept nearest;
            nearest.count = 0;
            for (uint32_t b = 0; b < block.count; ++b)
                for (size_t k = block.begin[b]; k < block.end[b]; ++k) {
                    const Vec3 d = g.grid.sorted[k] - p;
                    if (k != j && dot(d, d) <= reach2) nearest.offer(dot(d, d), static_cast<uint32_t>(k));
                }
            for (uint32_t e = 0; e < nearest.count; ++e) g.neighbour[edges + e] = nearest.index[e];
            edges += nearest.count;
        }
        cell = end;
    }
    g.first[g.count] = edges;
}

// Calls visit(k) for every neighbour k of point j.
template <class Visit> void for_each_neighbour(const SkeletonGraph& g, size_t j, Visit visit) {
    for (uint32_t e = g.first[j]; e < g.first[j + 1]; ++e) visit(size_t{g.neighbour[e]});
}

// Union-find (find_root): the lower root index wins.
static inline void join_roots(uint32_t* parent, uint32_t a, uint32_t b) {
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a != b) parent[a > b ? a : b] = a < b ? a : b;  // the lower index: the same on every run
}

// Dijkstra's heap: point indices ordered by distance (then index), with each point's slot.
struct DistanceHeap {
    uint32_t* heap;
    uint32_t* slot;
    const double* distance;
    uint32_t size;
    bool before(uint32_t a, uint32_t b) const {
        return distance[a] < distance[b] || (distance[a] == distance[b] && a < b);
    }
    void place(uint32_t at, uint32_t point) {
        heap[at] = point;
        slot[point] = at;
    }
    void rise(uint32_t at) {
        const uint32_t point = heap[at];
        while (at > 0 && before(point, heap[(at - 1) / 2])) {
            place(at, heap[(at - 1) / 2]);
            at = (at - 1) / 2;
        }
        place(at, point);
    }
    uint32_t pop() {
        const uint32_t top = heap[0], last = heap[--size];
        uint32_t at = 0;
        for (;;) {
            uint32_t child = 2 * at + 1;
            if (child >= size) break;
            if (child + 1 < size && before(heap[child + 1], heap[child])) ++child;
            if (!before(heap[child], last)) break;
            place(at, heap[child]);
            at = child;
        }
        if (size > 0) place(at, last);
        return top;
    }
};

// A ring's circle, fitted in the plane across the centre line (Kasa's algebraic fit: the
// least squares of x^2 + y^2 - 2ax - 2by - c over the ring's points, a linear system):
// the centroid of a ring on a bend lies outward of its centre, where the surface has
// more area.
struct RingFit {
    Vec3 u, v;  // the plane's axes, through the centroid
    double x, y, xx, yy, xy, z, xz, yz;  // sums, z = x^2 + y^2
    bool plane;
    void add(Vec3 d) {
        const double px = dot(d, u), py = dot(d, v), pz = px * px + py * py;
        x += px, y += py, xx += px * px, yy += py * py, xy += px * py;
        z += pz, xz += px * pz, yz += py * pz;
    }
    // The circle's centre in the plane, by Cramer's rule; false where the ring is too
    // flat for it (a determinant lost in rounding) or the centre leaves the ring.
    bool centre(double n, double radius, double& a, double& b) const {
        const double m[3][3] = {{xx, xy, x}, {xy, yy, y}, {x, y, n}};
        const double r[3] = {xz, yz, z};
        const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        const double scale = xx * yy * n;
        if (!(abs_value(det) > 1e-9 * scale)) return false;
        const double det_a = r[0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                             m[0][1] * (r[1] * m[2][2] - m[1][2] * r[2]) +
                             m[0][2] * (r[1] * m[2][1] - m[1][1] * r[2]);
        const double det_b = m[0][0] * (r[1] * m[2][2] - m[1][2] * r[2]) -
                             r[0] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                             m[0][2] * (m[1][0] * r[2] - r[1] * m[2][0]);
        a = det_a / det / 2;
        b = det_b / det / 2;
        return a * a + b * b < radius * radius;
    }
};

struct SkeletonMemory {
    SkeletonGraph graph;
    Vec3* sample;      // the sampled points, in input order
    double* distance;  // geodesic, kUnreached off the largest piece
    uint32_t* heap;
    uint32_t* slot;
    uint32_t* parent;
    uint32_t* size;
    // Per band: points, rings, the sum of their points (then the ring's centre), the mean
    // distance to it, and the sums of the circle fit across the band.
    uint32_t* band_points;
    uint32_t* band_rings;
    Vec3* band_centre;
    double* band_radius;
    RingFit* band_fit;
};

// Room for the sample: a hash picks about one point in sample_step(), so twice that.
static inline size_t skeleton_sample_count(size_t valid) {
    return valid < 2 * kSkeletonSample ? valid : 2 * kSkeletonSample;
}

// One allocation sequence for the call and for the workspace bound: the skeleton that
// stays, then the scratch.
static inline void allocate_skeleton(Skeleton& sk, Arena& arena) {
    sk.centre = arena.alloc<Vec3>(kMostBands + 1);
    sk.tangent = arena.alloc<Vec3>(kMostBands + 1);
    sk.normal = arena.alloc<Vec3>(kMostBands + 1);
    sk.arc = arena.alloc<double>(kMostBands + 1);
    sk.count = 0;
}

static inline void allocate_skeleton_scratch(SkeletonMemory& m, size_t samples, Arena& arena) {
    m.graph.grid = allocate_cell_scratch(arena, samples);
    m.graph.first = arena.alloc<uint32_t>(samples + 1);
    m.graph.neighbour = arena.alloc<uint32_t>(samples * kMostNeighbours);
    m.sample = arena.alloc<Vec3>(samples);
    m.distance = arena.alloc<double>(samples);
    m.heap = arena.alloc<uint32_t>(samples);
    m.slot = arena.alloc<uint32_t>(samples);
    m.parent = arena.alloc<uint32_t>(samples);
    m.size = arena.alloc<uint32_t>(samples);
    m.band_points = arena.alloc<uint32_t>(kMostBands + 1);
    m.band_rings = arena.alloc<uint32_t>(kMostBands + 1);
    m.band_centre = arena.alloc<Vec3>(kMostBands + 1);
    m.band_radius = arena.alloc<double>(kMostBands + 1);
    m.band_fit = arena.alloc<RingFit>(kMostBands + 1);
}

// The geodesic distance over the graph from `source` into m.distance (kUnreached where
// the graph does not reach); returns the point farthest from it (the lowest index of ties).
static inline uint32_t geodesic_distance(SkeletonMemory& m, uint32_t source) {
    const SkeletonGraph& g = m.graph;
    for (size_t j = 0; j < g.count; ++j) m.distance[j] = kUnreached;
    DistanceHeap heap = {m.heap, m.slot, m.distance, 0};
    m.distance[source] = 0;
    heap.place(heap.size++, source);
    uint32_t farthest = source;
    while (heap.size > 0) {
        const uint32_t j = heap.pop();
        m.slot[j] = UINT32_MAX;  // settled
        const double dj = m.distance[j];
        if (dj > m.distance[farthest] || (dj == m.distance[farthest] && j < farthest)) farthest = j;
        for_each_neighbour(g, j, [&](size_t k) {
            const Vec3 d = g.grid.sorted[k] - g.grid.sorted[j];
            const double through = dj + std::sqrt(dot(d, d));
            if (!(through < m.distance[k])) return;
            const bool queued = m.distance[k] != kUnreached;
            m.distance[k] = through;
            if (!queued) heap.place(heap.size++, static_cast<uint32_t>(k));
            heap.rise(m.slot[k]);
        });
    }
    return farthest;
}

// The band of a geodesic distance.
static inline uint32_t band_of(double distance, double width, uint32_t bands) {
    const double b = std::floor(distance / width);
    return b < static_cast<double>(bands - 1) ? static_cast<uint32_t>(b) : bands - 1;
}

// The radius of the circle through three nodes (DBL_MAX where they lie on a line).
static inline double turn_radius(Vec3 a, Vec3 b, Vec3 c) {
    const Vec3 ab = b - a, bc = c - b, ca = a - c;
    const Vec3 n = cross(ab, c - a);
    const double twice_area = std::sqrt(dot(n, n));
    if (!(twice_area > 0)) return DBL_MAX;
    return std::sqrt(dot(ab, ab) * dot(bc, bc) * dot(ca, ca)) / (2 * twice_area);
}

// Moves each band's centre from its points' centroid to the centre of the circle fitted
// across the centre line there (RingFit), the line's direction taken from the centroids
// of the bands on either side.
static inline void fit_ring_circles(SkeletonMemory& m, uint32_t bands, double width) {
    const SkeletonGraph& g = m.graph;
    for (uint32_t b = 0; b < bands; ++b) {
        RingFit& f = m.band_fit[b];
        f = RingFit{};
        if (m.band_points[b] == 0) continue;
        uint32_t lo = b, hi = b;
        while (lo > 0 && (lo == b || m.band_points[lo] == 0)) --lo;
        while (hi + 1 < bands && (hi == b || m.band_points[hi] == 0)) ++hi;
        Vec3 along = m.band_centre[hi] - m.band_centre[lo];
        if (m.band_points[lo] == 0 || m.band_points[hi] == 0 || !normalize(along)) continue;
        f.u = cross(axis_least_along(along), along);
        f.plane = normalize(f.u);
        f.v = cross(along, f.u);
    }
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached) continue;
        const uint32_t b = band_of(m.distance[j], width, bands);
        if (m.band_fit[b].plane) m.band_fit[b].add(g.grid.sorted[j] - m.band_centre[b]);
    }
    for (uint32_t b = 0; b < bands; ++b) {
        const RingFit& f = m.band_fit[b];
        double a = 0, c = 0;
        if (f.plane && f.centre(m.band_points[b], m.band_radius[b], a, c))
            m.band_centre[b] = m.band_centre[b] + scaled(f.u, a) + scaled(f.v, c);
    }
}

// The rings' centres of the bands [first, last] as skeleton nodes, with their
// arc lengths and frames; false where they make no polyline (fewer than four nodes, a
// frame that cannot be carried on).
static inline bool chain_nodes(const SkeletonMemory& m, uint32_t first, uint32_t last, Skeleton& sk) {
    sk.count = 0;
    for (uint32_t b = first; b <= last; ++b)
        if (m.band_points[b] > 0)
            sk.centre[sk.count++] = m.band_centre[b];
    if (sk.count < 4) return false;
    // Taubin's smoothing (a pass of the (1/4, 1/2, 1/4) filter, then one back out by a bit
    // more): it rounds a sharp corner and a ring's noise, where the plain filter would also
    // pull every bend's nodes inward.
    for (int pass = 0; pass < 2 * kSmoothingPasses; ++pass) {
        const double weight = pass % 2 == 0 ? kSmoothIn : kSmoothOut;
        Vec3 before = sk.centre[0];
        for (uint32_t i = 1; i + 1 < sk.count; ++i) {
            const Vec3 here = sk.centre[i];
            const Vec3 pull = scaled(before + sk.centre[i + 1], 0.5) - here;
            sk.centre[i] = here + scaled(pull, weight);
            before = here;
        }
    }
    sk.arc[0] = 0;
    for (uint32_t i = 1; i < sk.count; ++i) {
        const Vec3 d = sk.centre[i] - sk.centre[i - 1];
        sk.arc[i] = sk.arc[i - 1] + std::sqrt(dot(d, d));
        if (!(sk.arc[i] > sk.arc[i - 1])) return false;
    }
    for (uint32_t i = 0; i < sk.count; ++i) {
        const uint32_t lo = i > 0 ? i - 1 : 0, hi = i + 1 < sk.count ? i + 1 : i;
        sk.tangent[i] = sk.centre[hi] - sk.centre[lo];
        if (!normalize(sk.tangent[i])) return false;
    }
    // The first normal: across the tangent, from the coordinate axis least along it.
    sk.normal[0] = cross(axis_least_along(sk.tangent[0]), sk.tangent[0]);
    if (!normalize(sk.normal[0])) return false;
    for (uint32_t i = 1; i < sk.count; ++i) {
        const Vec3 n = sk.normal[i - 1], ti = sk.tangent[i];
        sk.normal[i] = n - scaled(ti, dot(n, ti));
        if (!normalize(sk.normal[i])) return false;
    }
    return true;
}

// Whether the skeleton is bent (see above) for rings of radius `radius`.
static inline bool bent_enough(const Skeleton& sk, double radius) {
    const uint32_t last = sk.count - 1;
    if (!(sk.arc[last] >= kLongRadii * radius)) return false;
    Vec3 chord = sk.centre[last] - sk.centre[0];
    const bool has_chord = normalize(chord);
    double stray = 0;
    for (uint32_t i = 1; i < last; ++i) {
        Vec3 d = sk.centre[i] - sk.centre[0];
        if (has_chord) d = d - scaled(chord, dot(d, chord));
        const double off = std::sqrt(dot(d, d));
        stray = off > stray ? off : stray;
        if (turn_radius(sk.centre[i - 1], sk.centre[i], sk.centre[i + 1]) < kTightestTurn * radius)
            return false;
    }
    return stray >= kStrayRadii * radius;
}

// The skeleton of the kept points of `in` (see above), in `sk`; false where the object is
// not one bent chain of rings. *unbranched: every band held one ring (bent or not).
static inline bool find_skeleton(const TubeInput& in, Arena& arena, Skeleton& sk,
                                 bool* unbranched) {
    *unbranched = false;
    SkeletonMemory m;
    const size_t samples = skeleton_sample_count(in.sums.valid);
    allocate_skeleton_scratch(m, samples, arena);
    if (arena.failed || samples < 4 * kMinRingPoints) return false;
    // By a hash of the coordinates (sampled_point): every k-th point in input order could
    // fall in step with a scanner's rows.
    const uint32_t step = sample_step(in.sums.valid, kSkeletonSample);
    size_t n = 0;
    for (size_t i = 0; i < in.count && n < samples; ++i)
        if (in.reader.valid(i) && sampled_point(in.reader.point(i), step)) m.sample[n++] = in.reader.point(i);
    const CloudReader sample = {reinterpret_cast<const unsigned char*>(m.sample), sizeof(Vec3), false,
                                nullptr};
    const CloudBox box = box_of(sample, n);
    const double decile = nearest_spacing(sample, n, box, m.graph.grid, kSpacingSample);
    SkeletonGraph& g = m.graph;
    g.reach = kReachDeciles * decile;
    if (!(g.reach > 0) || !is_finite(g.reach)) return false;
    g.count = sort_into_cells(sample, n, box.low, g.reach, g.grid);
    for (size_t j = 0; j < g.count; ++j) g.grid.sorted[j] = m.sample[g.grid.items[j].index];
    link_neighbours(g);

    // The largest connected piece, and in it the point farthest from the sample's centre.
    for (size_t j = 0; j < g.count; ++j) m.parent[j] = static_cast<uint32_t>(j), m.size[j] = 0;
    for (size_t j = 0; j < g.count; ++j)
        for_each_neighbour(g, j, [&](size_t k) {
            join_roots(m.parent, static_cast<uint32_t>(j), static_cast<uint32_t>(k));
        });
    uint32_t main = 0;
    for (size_t j = 0; j < g.count; ++j) {
        const uint32_t r = find_root(m.parent, static_cast<uint32_t>(j));
        if (++m.size[r] > m.size[main] || (m.size[r] == m.size[main] && r < main)) main = r;
    }
    const Vec3 middle = scaled(box.low + box.high, 0.5);
    uint32_t extreme = main;
    double farthest = -1;
    for (size_t j = 0; j < g.count; ++j) {
        if (find_root(m.parent, static_cast<uint32_t>(j)) != main) continue;
        const Vec3 d = g.grid.sorted[j] - middle;
        if (dot(d, d) > farthest) farthest = dot(d, d), extreme = static_cast<uint32_t>(j);
    }
    // An end of the object, then the distance from it.
    const uint32_t end = geodesic_distance(m, extreme);
    const uint32_t other_end = geodesic_distance(m, end);
    const double length = m.distance[other_end];
    const double width = length / kMostBands > 2 * g.reach ? length / kMostBands : 2 * g.reach;
    const uint32_t bands = band_of(length, width, kMostBands + 1) + 1;
    if (bands < 4) return false;

    // Rings: the band's pieces joined within the band.
    for (size_t j = 0; j < g.count; ++j) m.parent[j] = static_cast<uint32_t>(j), m.size[j] = 0;
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached) continue;
        const uint32_t bj = band_of(m.distance[j], width, bands);
        for_each_neighbour(g, j, [&](size_t k) {
            if (band_of(m.distance[k], width, bands) == bj)
                join_roots(m.parent, static_cast<uint32_t>(j), static_cast<uint32_t>(k));
        });
    }
    for (uint32_t b = 0; b < bands; ++b)
        m.band_points[b] = 0, m.band_rings[b] = 0, m.band_centre[b] = {0, 0, 0}, m.band_radius[b] = 0;
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached) continue;
        const uint32_t b = band_of(m.distance[j], width, bands);
        ++m.size[find_root(m.parent, static_cast<uint32_t>(j))];
        ++m.band_points[b];
        m.band_centre[b] = m.band_centre[b] + g.grid.sorted[j];
    }
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached || m.parent[j] != j) continue;
        const uint32_t b = band_of(m.distance[j], width, bands);
        if (m.size[j] >= kMinRingPoints && kRingShare * m.size[j] >= m.band_points[b]) ++m.band_rings[b];
        if (m.band_rings[b] > 1) return false;  // a branch, or a handle
    }
    for (uint32_t b = 0; b < bands; ++b)
        if (m.band_points[b] > 0) m.band_centre[b] = scaled(m.band_centre[b], 1.0 / m.band_points[b]);
    for (size_t j = 0; j < g.count; ++j) {
        if (m.distance[j] == kUnreached) continue;
        const uint32_t b = band_of(m.distance[j], width, bands);
        const Vec3 d = g.grid.sorted[j] - m.band_centre[b];
        m.band_radius[b] += std::sqrt(dot(d, d)) / m.band_points[b];
    }
    fit_ring_circles(m, bands, width);
    // The rings' median radius, and the bands within one radius of either end left out:
    // a ring there may be part of the end's rim, its centre off the centre line.
    uint32_t with_points = 0;
    for (uint32_t b = 0; b < bands; ++b)
        if (m.band_points[b] > 0) m.distance[with_points++] = m.band_radius[b];
    heap_sort(m.distance, with_points);
    const double radius = m.distance[with_points / 2];
    const double end_bands = std::ceil(radius / width);
    if (!(end_bands < bands / 2.0 - 2)) return false;
    const uint32_t skip = static_cast<uint32_t>(end_bands);
    if (!chain_nodes(m, skip, bands - 1 - skip, sk)) return false;
    *unbranched = true;
    return bent_enough(sk, radius);
}

// The frame across the skeleton at segment j, parameter t clamped to [0, 1] (the frame
// interpolated between the segment's nodes).
static inline void skeleton_frame(const Skeleton& sk, uint32_t j, double t, Vec3& tangent,
                                  Vec3& normal, Vec3& binormal) {
    const double u = t < 0 ? 0 : t > 1 ? 1 : t;
    tangent = scaled(sk.tangent[j], 1 - u) + scaled(sk.tangent[j + 1], u);
    normal = scaled(sk.normal[j], 1 - u) + scaled(sk.normal[j + 1], u);
    if (!normalize(tangent)) tangent = sk.tangent[j];
    normal = normal - scaled(tangent, dot(normal, tangent));
    if (!normalize(normal)) normal = sk.normal[j];
    binormal = cross(tangent, normal);
}

// Point p in straightened coordinates: across its nearest segment of the skeleton (the
// ends' segments reach on beyond their ends) and along it.
static inline Vec3 straightened(const Skeleton& sk, Vec3 p) {
    const uint32_t last = sk.count - 2;  // the last segment
    uint32_t best = 0;
    double best_t = 0, best_d2 = DBL_MAX;
    for (uint32_t j = 0; j <= last; ++j) {
        const Vec3 e = sk.centre[j + 1] - sk.centre[j];
        double t = dot(p - sk.centre[j], e) / dot(e, e);
        if (t < 0 && j > 0) t = 0;
        if (t > 1 && j < last) t = 1;
        const Vec3 d = p - (sk.centre[j] + scaled(e, t));
        if (dot(d, d) < best_d2) best_d2 = dot(d, d), best = j, best_t = t;
    }
    Vec3 tangent, normal, binormal;
    skeleton_frame(sk, best, best_t, tangent, normal, binormal);
    const Vec3 e = sk.centre[best + 1] - sk.centre[best];
    const Vec3 d = p - (sk.centre[best] + scaled(e, best_t));
    const double along = sk.arc[best] + best_t * (sk.arc[best + 1] - sk.arc[best]);
    return {dot(d, normal), dot(d, binormal), along + dot(d, tangent)};
}

// A straightened point back in the cloud's space (on the skeleton's frame at its arc length).
static inline Vec3 unstraightened(const Skeleton& sk, Vec3 q) {
    uint32_t j = 0;
    while (j + 2 < sk.count && q.z > sk.arc[j + 1]) ++j;
    const double t = (q.z - sk.arc[j]) / (sk.arc[j + 1] - sk.arc[j]);
    Vec3 tangent, normal, binormal;
    skeleton_frame(sk, j, t, tangent, normal, binormal);
    const Vec3 on = sk.centre[j] + scaled(sk.centre[j + 1] - sk.centre[j], t);
    return on + scaled(normal, q.x) + scaled(binormal, q.y);
}

// Whether reconstruct() looks for a bent skeleton: where it chooses the axis and the
// layers itself, and looks for parts (the skeleton also says where there are none).
static inline bool follows_bends(const TubeRequest& request) {
    return kFindParts && request.parts != Parts::one_tube && request.axis == Axis::automatic &&
           !request.origin && request.layers.cut_count == 0 && request.layers.count == 0 &&
           !(request.layers.height > 0);
}

// The straightened cloud: three doubles a point, while the tube is meshed.
static inline double* allocate_straightened(size_t count, Arena& arena) {
    return arena.alloc<double>(count > SIZE_MAX / 3 ? SIZE_MAX : 3 * count);
}

// The skeleton, then either the scratch that finds it or the straightened cloud and the tube.
static inline size_t bent_workspace_size(size_t point_count, const TubeRequest& request) {
    Arena arena = Arena::measuring();
    Skeleton sk;
    allocate_skeleton(sk, arena);
    const size_t kept = arena.required_bytes();
    SkeletonMemory m;
    allocate_skeleton_scratch(m, skeleton_sample_count(point_count), arena);
    const size_t scratch = arena.required_bytes() - kept;
    Arena straightened = Arena::measuring();
    allocate_straightened(point_count, straightened);
    TubeRequest along = request;
    along.axis = Axis::z;
    const size_t tube = tube_workspace_size(point_count, along);
    const size_t cloud = straightened.required_bytes();
    if (arena.failed || straightened.failed || tube == 0 || tube > SIZE_MAX - cloud ||
        cloud + tube > SIZE_MAX - kept)
        return 0;
    return kept + (cloud + tube > scratch ? cloud + tube : scratch);
}

// Where the object bends (find_skeleton), meshes it as one tube in straightened
// coordinates and sets *bent; otherwise leaves everything as it was, and sets *unbranched
// where every band held one ring: a straight object that does not branch, which needs no
// search for parts. The report's axis is then the skeleton's tangent at its start
// (axis_origin the start), its layers' bottom and top arc lengths along the skeleton, their
// centres in the cloud's space.
static inline Status mesh_if_bent(const TubeInput& in, const TubeRequest& request, Arena& arena,
                                  uint32_t* triangles, size_t triangle_capacity,
                                  size_t* triangle_count, Report& rep, bool* bent,
                                  bool* unbranched) {
    *bent = false;
    const size_t start = arena.mark();
    Skeleton sk;
    allocate_skeleton(sk, arena);
    const size_t scratch = arena.mark();
    const bool found = !arena.failed && find_skeleton(in, arena, sk, unbranched);
    arena.rewind(scratch);
    double* xyz = found ? allocate_straightened(in.count, arena) : nullptr;
    if (arena.failed) {
        rep.detail = "the workspace is smaller than reconstruct_workspace_size()";
        return Status::out_of_memory;
    }
    if (!found) {
        arena.rewind(start);
        return Status::ok;
    }
    *bent = true;
    for (size_t i = 0; i < in.count; ++i) {
        const Vec3 p = in.reader.point(i);  // left as it is where it is not valid
        const Vec3 q = in.reader.valid(i) ? straightened(sk, p) : p;
        xyz[3 * i] = q.x, xyz[3 * i + 1] = q.y, xyz[3 * i + 2] = q.z;
    }
    TubeInput along = {{reinterpret_cast<const unsigned char*>(xyz), 3 * sizeof(double), false,
                        in.reader.dropped},
                       in.count, {}};
    along.sums = sum_cloud(along.reader, in.count);
    TubeRequest straight = request;
    straight.axis = Axis::z;
    const Status status =
        mesh_tube(along, straight, arena, triangles, triangle_capacity, triangle_count, rep);
    rep.layers.skeleton_node_count = sk.count;
    const Vec3 axis = sk.tangent[0], origin = sk.centre[0];
    rep.axis[0] = axis.x, rep.axis[1] = axis.y, rep.axis[2] = axis.z;
    rep.axis_origin[0] = origin.x, rep.axis_origin[1] = origin.y, rep.axis_origin[2] = origin.z;
    const size_t described = rep.layers.info_capacity < rep.layers.used_count
                                  ? rep.layers.info_capacity : rep.layers.used_count;
    for (size_t l = 0; rep.layers.info && l < described; ++l) {
        double* c = rep.layers.info[l].centre;
        const Vec3 back = unstraightened(sk, {c[0], c[1], c[2]});
        c[0] = back.x, c[1] = back.y, c[2] = back.z;
    }
    return status;
}

}  // namespace detail
}  // namespace stratmesh
