// >>layer plan ===========================================================================
// Cuts along the axis: explicit, equal, by height or automatic; points grouped by layer.
//
// Layers are height ranges along the axis; the points are grouped by layer, in input order
// within a layer.

namespace stratmesh {
namespace detail {

// Layer boundaries: bounds[0] = lowest height, bounds[count] = highest, layer i holds the
// heights in [bounds[i] - tolerance, bounds[i+1] - tolerance) (the last layer includes its
// top). The tolerance (2^-40 of the height range) puts a point that lies on a cut up to
// rounding into the layer above, as one exactly on it: with a tilted axis the heights of
// a planar contour (a CT slice, a scan row) differ in their last bits, and a cut on that
// plane would otherwise split the contour between two layers.
struct LayerPlan {
    double* bounds;
    uint32_t count;
    double tolerance;
};

const size_t kMaxAutomaticLayers = 256;

// Heights are divided by at least layer height / kMaxTurns when unrolled, so exp() stays
// far from overflow and the annulus from extreme ratios in very tall, thin layers; a layer
// up to kMaxTurns radii tall unrolls undistorted (see >>unroll).
const double kMaxTurns = 24.0;

// Whether a layer holds kMinLayerRows rows of points (see Options::cuts). With n points
// over height h around radius r (the layer's own), the spacing is about sqrt(2 pi r h / n),
// so the rows number sqrt(h n / (2 pi r)). A stack of planar contours one per layer, as far
// apart as a few point spacings along the contour, passes.
static inline bool thick_enough(size_t points, double height, double radius) {
    const double two_pi = 6.28318530717958647693;
    return static_cast<double>(points) * height >= kMinLayerRows * kMinLayerRows * two_pi * radius;
}

// The number of layers a request can ask for, before empty layers are dropped.
static inline size_t planned_layer_limit(size_t point_count, const LayerRequest& layers) {
    if (layers.cuts && layers.cut_count > 0) return layers.cut_count + 1;
    if (layers.count > 0)
        return layers.count < point_count ? layers.count : (point_count > 0 ? point_count : 1);
    // A target height: never more layers than points.
    if (layers.height > 0) return point_count > 0 ? point_count : 1;
    return kMaxAutomaticLayers;
}

static inline Status validate_layer_options(const Options& options) {
    if (options.cuts && options.cut_count > 0) {
        if (options.cut_count > kMaxPoints) return Status::invalid_layers;
        for (size_t i = 0; i < options.cut_count; ++i)
            if (!is_finite(options.cuts[i])) return Status::invalid_layers;
    } else if (options.cut_count > 0) {
        return Status::invalid_argument;
    }
    if (!is_finite(options.layer_height) || options.layer_height < 0)
        return Status::invalid_layers;
    return Status::ok;
}

static inline bool automatic_layers(const LayerRequest& layers) {
    return !(layers.cuts && layers.cut_count > 0) && layers.count == 0 && layers.height == 0;
}

// Fills plan.bounds (room for planned_layer_limit + 1 entries) for heights [lo, hi] from
// the layers asked for (not automatic_layers): the cuts are coordinates along the axis
// (Frame::user_height of frame heights), the height a length in the cloud's units.
static inline void plan_layers(const LayerRequest& layers, double lo, double hi, size_t point_count,
                        const Frame& frame, LayerPlan& plan) {
    const double cut_offset = dot(frame.origin, frame.axis);
    double* b = plan.bounds;
    uint32_t n = 0;
    b[n++] = lo;
    if (layers.cuts && layers.cut_count > 0) {
        // The cuts inside (lo, hi], sorted, repeats dropped.
        size_t inside = 0;
        for (size_t i = 0; i < layers.cut_count; ++i) {
            double c = (layers.cuts[i] - cut_offset) * frame.scale;
            if (c > lo && c <= hi) b[1 + inside++] = c;
        }
        heap_sort(b + 1, inside);
        for (size_t i = 0; i < inside; ++i)
            if (b[1 + i] > b[n - 1]) b[n++] = b[1 + i];
    } else {
        double height = hi - lo;
        double planned = 1;
        if (layers.count > 0) {
            planned = layers.count;
        } else if (layers.height > 0) {
            planned = std::ceil(height / (layers.height * frame.scale));
        }
        double limit = static_cast<double>(point_count);
        if (!(planned >= 1)) planned = 1;
        if (planned > limit) planned = limit;
        uint32_t count = static_cast<uint32_t>(planned);
        for (uint32_t i = 1; i < count; ++i) {
            double c = lo + height * (static_cast<double>(i) / static_cast<double>(count));
            if (c > b[n - 1] && c < hi) b[n++] = c;
        }
    }
    b[n] = hi;
    plan.count = n;
}

// ---- automatic layers ----------------------------------------------------------------------
//
// The paper's layering rule, made mechanical. The cloud's height range is cut into equal
// bins (about 256 points each, at most kMaxAutomaticLayers); each bin gets its centroid
// across the axis, its mean radius around that centroid and its inner radius (the smallest
// of kProfileSectors sector-mean radii: the cross-section holds a disc about that wide
// around its centroid when it is star-shaped). Then, starting from one layer over
// everything:
//   - a layer is well unrolled when one centre line serves all its cross-sections (every
//     bin's centroid lies within kCentreDrift inner radii of the layer's centre, the
//     count-weighted mean of its bins' centroids, give or take three standard errors of
//     the bin's centroid, so sampling noise alone never cuts) and it is at most kMaxTurns
//     mean radii
//     tall (taller layers unroll with distorted aspect), and it holds at most an eighth of
//     the points (kLayerPointsShare), or kFewestLayerPoints if that is more, so that a
//     large cloud comes in layers that a job runner can triangulate side by side, the same
//     layers whatever the runner;
//   - a layer that is not is cut in two at the bin boundary where the surface changes
//     least: the smallest sum of centroid drift and radius change between the two bins
//     (relative to the radius), plus a penalty where the bins are denser than average, so
//     dense detailed parts (a face, a joint) stay inside one layer. Only boundaries that
//     leave each side a quarter of the layer's bins are candidates, so the splitting
//     depth stays logarithmic.
// The result is the fewest layers that pass, cut where the shape is calm; O(n) passes over
// the points plus O(bins^2) on the profile, deterministic.

const uint32_t kProfileSectors = 8;

const double kCentreDrift = 0.75;

const size_t kLayerPointsShare = 8;

const size_t kFewestLayerPoints = size_t{1} << 16;

const size_t kPointsPerProfileBin = 256;

const double kDensityWeight = 0.5;

struct ProfileBin {
    uint32_t count;
    uint32_t sectors_seen;                  // direction sectors holding a point
    double cx, cy;                          // centroid across the axis
    double mean_radius, inner_radius;       // around the centroid (inner: occupied sectors)
    double square_sum;                      // sum of squared distances from the centroid
    double sector_sum[kProfileSectors];     // sum of distances per direction sector
    uint32_t sector_count[kProfileSectors];
};

// A range of bins [first, end) waiting to be judged.
struct BinRange {
    uint32_t first, end;
};

static inline uint32_t profile_bin_count(size_t valid_points) {
    size_t bins = valid_points / kPointsPerProfileBin;
    if (bins > kMaxAutomaticLayers) bins = kMaxAutomaticLayers;
    return bins < 1 ? 1u : static_cast<uint32_t>(bins);
}

// The scratch the automatic planner takes (released before the layers are built).
static inline void allocate_profile(Arena& arena, uint32_t bins, ProfileBin** profile,
                                    BinRange** ranges, double** cuts) {
    *profile = arena.alloc<ProfileBin>(bins);
    *ranges = arena.alloc<BinRange>(bins);
    *cuts = arena.alloc<double>(bins);
}

static inline uint32_t sector_of(double dx, double dy) {
    uint32_t s = (dx < 0 ? 4u : 0u) + (dy < 0 ? 2u : 0u);
    return s + (abs_value(dx) < abs_value(dy) ? 1u : 0u);
}

static inline void build_profile(const CloudReader& cloud, size_t count, const Frame& frame,
                                 double lo, double hi, ProfileBin* profile, uint32_t bins) {
    std::memset(static_cast<void*>(profile), 0, sizeof(ProfileBin) * bins);
    const double per_height = static_cast<double>(bins) / (hi - lo);
    auto bin_of = [&](double h) {
        double b = (h - lo) * per_height;
        return b >= static_cast<double>(bins - 1) ? bins - 1 : (b > 0 ? static_cast<uint32_t>(b) : 0u);
    };
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        Local p = frame.local(cloud.point(i));
        ProfileBin& bin = profile[bin_of(p.h)];
        ++bin.count;
        bin.cx += p.x;
        bin.cy += p.y;
    }
    for (uint32_t b = 0; b < bins; ++b) {
        if (profile[b].count == 0) continue;
        profile[b].cx /= profile[b].count;
        profile[b].cy /= profile[b].count;
    }
    for (size_t i = 0; i < count; ++i) {
        if (!cloud.valid(i)) continue;
        Local p = frame.local(cloud.point(i));
        ProfileBin& bin = profile[bin_of(p.h)];
        double dx = p.x - bin.cx, dy = p.y - bin.cy;
        uint32_t s = sector_of(dx, dy);
        bin.sector_sum[s] += std::sqrt(dx * dx + dy * dy);
        bin.square_sum += dx * dx + dy * dy;
        ++bin.sector_count[s];
    }
    for (uint32_t b = 0; b < bins; ++b) {
        ProfileBin& bin = profile[b];
        double total = 0, inner = DBL_MAX;
        for (uint32_t s = 0; s < kProfileSectors; ++s) {
            total += bin.sector_sum[s];
            if (bin.sector_count[s] == 0) continue;
            ++bin.sectors_seen;
            double mean = bin.sector_sum[s] / bin.sector_count[s];
            if (mean < inner) inner = mean;
        }
        bin.mean_radius = bin.count ? total / bin.count : 0.0;
        bin.inner_radius = bin.count ? inner : 0.0;
    }
}

static inline bool well_unrolled(const ProfileBin* profile, BinRange range, double bin_height,
                                 size_t most_points) {
    double cx = 0, cy = 0, radius = 0;
    size_t points = 0;
    for (uint32_t b = range.first; b < range.end; ++b) {
        cx += profile[b].cx * profile[b].count;
        cy += profile[b].cy * profile[b].count;
        radius += profile[b].mean_radius * profile[b].count;
        points += profile[b].count;
    }
    if (points == 0) return true;
    cx /= static_cast<double>(points);
    cy /= static_cast<double>(points);
    radius /= static_cast<double>(points);
    if (bin_height * (range.end - range.first) > kMaxTurns * radius) return false;
    if (points > most_points) return false;
    for (uint32_t b = range.first; b < range.end; ++b) {
        // Too few points to say, or an arc rather than a ring (the slanted end of a scan):
        // such a bin's centroid says nothing about where the centre line must run.
        if (profile[b].count < kPointsPerProfileBin / 4 || profile[b].sectors_seen < kProfileSectors)
            continue;
        double dx = profile[b].cx - cx, dy = profile[b].cy - cy;
        double standard_error = std::sqrt(profile[b].square_sum / (2.0 * profile[b].count * profile[b].count));
        double limit = kCentreDrift * profile[b].inner_radius + 3 * standard_error;
        if (dx * dx + dy * dy > limit * limit) return false;
    }
    return true;
}

// How much the surface changes between bins b - 1 and b, plus the density penalty.
static inline double cut_cost(const ProfileBin* profile, uint32_t b, double mean_count) {
    const ProfileBin& below = profile[b - 1];
    const ProfileBin& above = profile[b];
    double radius = below.mean_radius > above.mean_radius ? below.mean_radius : above.mean_radius;
    if (!(radius > 0)) return 0;  // an empty stretch: the calmest place of all
    double dx = above.cx - below.cx, dy = above.cy - below.cy;
    double change = (std::sqrt(dx * dx + dy * dy) + abs_value(above.mean_radius - below.mean_radius)) / radius;
    double density = (below.count + above.count) / (2 * mean_count) - 1;
    return change + (density > 0 ? kDensityWeight * density : 0.0);
}

// Fills plan.bounds for heights [lo, hi] by the rule above; profile, ranges and cuts hold
// `bins` entries each.
static inline void plan_automatic_layers(const CloudReader& cloud, size_t count, size_t valid,
                                         const Frame& frame, double lo, double hi,
                                         ProfileBin* profile, BinRange* ranges, double* cuts,
                                         uint32_t bins, LayerPlan& plan) {
    build_profile(cloud, count, frame, lo, hi, profile, bins);
    const double bin_height = (hi - lo) / bins;
    const double mean_count = static_cast<double>(valid) / bins;
    const size_t share = valid / kLayerPointsShare;
    const size_t most_points = share > kFewestLayerPoints ? share : kFewestLayerPoints;
    size_t pending = 0, cut_count = 0;
    ranges[pending++] = {0, bins};
    while (pending > 0) {
        BinRange r = ranges[--pending];
        uint32_t width = r.end - r.first;
        if (width < 2 || well_unrolled(profile, r, bin_height, most_points)) continue;
        uint32_t margin = width / 4 > 0 ? width / 4 : 1;
        uint32_t best = r.first + margin;
        double best_cost = DBL_MAX;
        for (uint32_t b = r.first + margin; b <= r.end - margin; ++b) {
            double cost = cut_cost(profile, b, mean_count);
            if (cost < best_cost) {
                best_cost = cost;
                best = b;
            }
        }
        cuts[cut_count++] = lo + bin_height * best;
        // Each split turns one range into two, so at most `bins` are ever pending.
        ranges[pending++] = {r.first, best};
        ranges[pending++] = {best, r.end};
    }
    heap_sort(cuts, cut_count);
    double* bounds = plan.bounds;
    uint32_t n = 0;
    bounds[n++] = lo;
    for (size_t i = 0; i < cut_count; ++i)
        if (cuts[i] > bounds[n - 1] && cuts[i] < hi) bounds[n++] = cuts[i];
    bounds[n] = hi;
    plan.count = n;
}

// The layer of height h: the last k with h >= bounds[k] - tolerance, or 0. `per_height` is
// count / (bounds[count] - bounds[0]). With kFastLoops, the layer h would be in if the
// layers were equal, which they are unless cuts or the automatic plan set them, is tried
// first, with one branch that a million points in no order still predict (a binary
// search's would not); the search is for the rest.
static inline uint32_t layer_of(const LayerPlan& plan, double h, double per_height) {
    const double* bounds = plan.bounds;
    const double tolerance = plan.tolerance;
    const uint32_t last = plan.count - 1;
    const double guess = (h - bounds[0]) * per_height;
    const uint32_t k = guess > 0 ? (guess < last ? static_cast<uint32_t>(guess) : last) : 0;
    if (kFastLoops && ((k == 0) | (h >= bounds[k] - tolerance)) &
                          ((k == last) | (h < bounds[k + 1] - tolerance)))
        return k;
    uint32_t lo = 0, hi = plan.count;  // answer in [lo, hi)
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (h >= plan.bounds[mid] - plan.tolerance)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

// Groups the valid points by layer (input order within a layer): a counting sort, with each
// point's layer kept in `layer` (count entries of scratch) between its two passes. With
// `staged` (optional, as many entries as valid points), the points in frame coordinates
// go there in the same order.
static inline void group_by_layer(const CloudReader& cloud, size_t count, const Frame& frame,
                                  const LayerPlan& plan, uint32_t* layer, Local* staged,
                                  uint32_t* layer_start, uint32_t* order) {
    std::memset(layer_start, 0, sizeof(uint32_t) * (plan.count + 2));
    const double per_height =
        kFastLoops ? plan.count / (plan.bounds[plan.count] - plan.bounds[0]) : 0;
    for (size_t i = 0; i < count; ++i) {
        layer[i] = cloud.valid(i) ? layer_of(plan, frame.height(cloud.point(i)), per_height)
                                  : kNoIndex;
        if (layer[i] != kNoIndex) ++layer_start[layer[i] + 2];
    }
    for (uint32_t k = 0; k < plan.count; ++k) layer_start[k + 2] += layer_start[k + 1];
    for (size_t i = 0; i < count; ++i) {
        if (layer[i] == kNoIndex) continue;
        const uint32_t position = layer_start[layer[i] + 1]++;
        order[position] = static_cast<uint32_t>(i);
        if (staged) staged[position] = frame.local(cloud.point(i));
    }
}

// group_by_layer's counting sort, run by run: first each point's layer and each run's count
// per layer, then (once `first` holds each run's first position per layer) the scatter. The
// positions come out as in group_by_layer.
struct GroupingPass {
    const CloudReader* cloud;
    const Frame* frame;
    const LayerPlan* plan;
    double per_height;
    size_t count;
    uint32_t* layer;
    uint32_t* order;
    uint32_t* counts;    // per run, per layer: its points there
    uint32_t* first;     // per run, per layer: its first position there
    uint32_t* next;      // per run, per layer: the scatter's next position
    bool scatter;

    void run(uint32_t k) {
        const size_t layers = plan->count, begin = run_start(count, k), end = run_start(count, k + 1);
        if (!scatter) {
            uint32_t* c = counts + k * layers;
            std::memset(c, 0, layers * sizeof(uint32_t));
            for (size_t i = begin; i < end; ++i) {
                layer[i] = cloud->valid(i) ? layer_of(*plan, frame->height(cloud->point(i)), per_height)
                                           : kNoIndex;
                if (layer[i] != kNoIndex) ++c[layer[i]];
            }
            return;
        }
        uint32_t* n = next + k * layers;
        std::memcpy(n, first + k * layers, layers * sizeof(uint32_t));
        for (size_t i = begin; i < end; ++i)
            if (layer[i] != kNoIndex) order[n[layer[i]]++] = static_cast<uint32_t>(i);
    }
};

// group_by_layer without staging, as jobs; false (nothing done) where its three tables of a
// count per run and layer would take more than one count per point, or do not fit.
static inline bool group_by_layer_in_jobs(const Options& options, const CloudReader& cloud,
                                          size_t count, const Frame& frame, const LayerPlan& plan,
                                          uint32_t* layer, uint32_t* layer_start, uint32_t* order,
                                          Arena& arena) {
    const size_t table = kPassRuns * static_cast<size_t>(plan.count);
    if (!has_runner(options) || 3 * table > count) return false;
    const size_t mark = arena.mark();
    GroupingPass pass = {&cloud, &frame, &plan, 0, count, layer, order,
                         arena.alloc<uint32_t>(table), arena.alloc<uint32_t>(table),
                         arena.alloc<uint32_t>(table), false};
    if (arena.failed) {
        arena.failed = false;
        arena.rewind(mark);
        return false;
    }
    pass.per_height = kFastLoops ? plan.count / (plan.bounds[plan.count] - plan.bounds[0]) : 0;
    run_pass(options, pass);
    // Layer by layer, run by run: the positions of a counting sort in input order.
    uint32_t position = 0;
    for (uint32_t l = 0; l < plan.count; ++l) {
        layer_start[l] = position;
        for (uint32_t k = 0; k < kPassRuns; ++k) {
            pass.first[k * plan.count + l] = position;
            position += pass.counts[k * plan.count + l];
        }
    }
    layer_start[plan.count] = position;
    pass.scatter = true;
    run_pass(options, pass);
    arena.rewind(mark);
    return true;
}

}  // namespace detail
}  // namespace stratmesh
