// >>parts ================================================================================
// reconstruct()'s default: trunk and branches, meshed and joined.
//
// reconstruct()'s default where the cloud parts into branches (PartCounts). One tube wraps
// branches and the gaps between them, so where find_parting() finds a cut, the trunk (the
// points labelled kInTrunk) is meshed along the cloud's axis, each branch as a tube of its
// own around its own automatic axis, and join_branches() zips them into one surface (caps
// last, with add_caps, once joined). That is kept only when it is whole: every part
// meshed, every side joined, every point in a part; otherwise, unless Parts::apart, the cloud
// is meshed as one tube after all (PartsOutcome::undone). A part is meshed in place: the
// points of the other parts join the outliers in the reader's bitmap, so its triangles
// index the cloud directly and its frame is the one a copy of its points would get.
//
// The search costs about the reconstruction's time again on a cloud that does not part,
// so a cloud of more than kPartingSample points is searched on a sample first (every k-th
// kept point) and in full only where the sample parts: a branch of fewer than about
// kSmallestBranch * n / kPartingSample points can go unseen.

#if !defined(STRATMESH_SMALL_CODE)
namespace stratmesh {
namespace detail {

const size_t kPartingSample = 4096;

// On the sample a branch counts from this share of kSmallestBranch points: fewer than on
// the whole cloud, so that a branch the whole cloud would count is seen in the sample too
// (a horn of one point in a hundred); the search in full then decides.
const uint32_t kSampleBranchShare = 4;

// The trunk's end layer under branches standing on its closed end is merged with the
// layers next to it until it is this many of their largest radius tall: a closed end
// projects from a pole one radius in from the end, but at most three quarters of the way
// into its layer (kPoleDepth), and a thinner end layer puts the pole so near the end that
// the branches' stumps fold over the crown and their grafts cross the trunk beside them.
const double kPoleLayerRadii = 4.0 / 3.0;

// The trunk's layers, as many as a tube of `count` points can have (each holds at least
// kMinLayerPoints but the last).
static inline size_t most_layers(size_t count) { return count / kMinLayerPoints + 2; }

struct PartsMemory {
    uint8_t* labels;          // find_parting's branch_of for the whole cloud
    unsigned char* mask;      // the points left out of the part being meshed
    LayerInfo* layers;        // the trunk's
    double* cuts;             // the trunk's, merged at its ends (see cuts_for_tall_ends)
    size_t layer_capacity;
};

static inline bool allocate_parts(PartsMemory& m, size_t count, Arena& arena) {
    m.labels = arena.alloc<uint8_t>(count);
    m.mask = arena.alloc<unsigned char>(count / 8 + 1);
    m.layer_capacity = most_layers(count);
    m.layers = arena.alloc<LayerInfo>(m.layer_capacity);
    m.cuts = arena.alloc<double>(m.layer_capacity);
    return !arena.failed;
}

// The reader of the part labelled `label`: every other point left out with the outliers.
static inline TubeInput part_input(const TubeInput& whole, const PartsMemory& m, uint8_t label) {
    const size_t bytes = whole.count / 8 + 1;
    std::memset(m.mask, 0, bytes);
    for (size_t i = 0; i < whole.count; ++i)
        if (m.labels[i] != label) m.mask[i >> 3] |= static_cast<unsigned char>(1u << (i & 7));
    if (whole.reader.dropped)
        for (size_t b = 0; b < bytes; ++b) m.mask[b] |= whole.reader.dropped[b];
    TubeInput in = whole;
    in.reader.dropped = m.mask;
    in.sums = sum_cloud(in.reader, in.count);
    return in;
}

// A point beyond a cut in no branch is most often a sparse point of a branch whose nearest
// neighbour lies more than a gap away (uniform sampling leaves a few in every ten thousand;
// the thin tip of a horn more): within kAdoptionGaps gaps of a part's point, it goes to
// the part of the nearest one, so that the split is kept and the point is a vertex. Farther
// away it is a piece of its own (a speck, a patch a hole cut off), and the split is undone.
// Sought among all points, so at most kMostStrayChecks distance checks in all.
const double kAdoptionGaps = 2.0;

const uint64_t kMostStrayChecks = uint64_t{1} << 26;

// True if the trunk took a point.
static inline bool adopt_stray_points(const TubeInput& whole, double gap, uint8_t* labels) {
    const double reach = kAdoptionGaps * gap;
    uint64_t checks_left = kMostStrayChecks;
    bool trunk_grew = false;
    // Passes until none is adopted: a point can be adopted through one adopted before it
    // (the sparse tip of a horn, point after point).
    for (bool adopted = true; adopted;) {
        adopted = false;
        uint64_t strays = 0;
        for (size_t i = 0; i < whole.count; ++i)
            strays += labels[i] == kBeyondBranches && whole.reader.valid(i);
        if (strays == 0 || strays > checks_left / whole.count) return trunk_grew;
        checks_left -= strays * whole.count;
        for (size_t i = 0; i < whole.count; ++i) {
            if (labels[i] != kBeyondBranches || !whole.reader.valid(i)) continue;
            const Vec3 p = whole.reader.point(i);
            double nearest = reach * reach;
            uint8_t label = kBeyondBranches;
            for (size_t j = 0; j < whole.count; ++j) {
                if (labels[j] == kBeyondBranches || !whole.reader.valid(j)) continue;
                const Vec3 d = whole.reader.point(j) - p;
                const double d2 = dot(d, d);
                if (d2 <= nearest) {
                    nearest = d2;
                    label = labels[j];
                }
            }
            adopted = adopted || label != kBeyondBranches;
            trunk_grew = trunk_grew || label == kInTrunk;
            labels[i] = label;
        }
    }
    return trunk_grew;
}

// Whether every point is in a part (none is left beyond a cut in no branch).
static inline bool every_point_in_a_part(size_t count, const uint8_t* labels) {
    for (size_t i = 0; i < count; ++i)
        if (labels[i] == kBeyondBranches) return false;
    return true;
}

// Where branches stand on a closed end of the trunk (its end layer at a side that parts
// is closed, as a skull's crown under horns), the cuts that merge that end layer with the
// layers next to it until it is kPoleLayerRadii times the largest of their radii tall;
// false where no end needs it. *merged counts the layers merged away.
static inline bool cuts_for_tall_ends(const PartsMemory& m, size_t n, const Parting& parting,
                               size_t* cut_count, size_t* merged) {
    if (n < 2) return false;
    const LayerInfo* layers = m.layers;
    size_t first = 0, last = n - 1;  // the layers kept whole: [first, last]
    if (parting.above_branch_count > 0 && (layers[n - 1].closed_ends & closed_top)) {
        double radius = layers[last].radius;
        while (last > 0 && layers[n - 1].top - layers[last].bottom < kPoleLayerRadii * radius) {
            --last;
            radius = radius > layers[last].radius ? radius : layers[last].radius;
        }
    }
    if (parting.below_branch_count > 0 && (layers[0].closed_ends & closed_bottom)) {
        double radius = layers[first].radius;
        while (first < last && layers[first].top - layers[0].bottom < kPoleLayerRadii * radius) {
            ++first;
            radius = radius > layers[first].radius ? radius : layers[first].radius;
        }
    }
    if (first == 0 && last == n - 1) return false;
    *cut_count = 0;
    for (size_t k = first; k < last; ++k) m.cuts[(*cut_count)++] = layers[k].top;
    *merged = n - 1 - *cut_count;
    return true;
}

// A part meshed into the record of the parts, and where meshed, its counts into the whole's.
static inline void record_part(Report& rep, uint8_t label, Status status, const TubeInput& in,
                        const Report& part, size_t triangles, size_t merged) {
    PartCounts& p = rep.parts;
    if (p.part_count < p.info_capacity)
        p.info[p.part_count] = {label, status, in.sums.valid, part.layers.used_count,
                                status == Status::ok ? triangles : 0,
                                part.diagnostics.fold_count, merged};
    ++p.part_count;
    if (status != Status::ok) return;
    rep.points.used_count += part.points.used_count;
    rep.points.duplicate_count += part.points.duplicate_count;
    rep.diagnostics.fold_count += part.diagnostics.fold_count;
    rep.diagnostics.illegal_removed_count += part.diagnostics.illegal_removed_count;
    rep.diagnostics.diagonal_swap_count += part.diagnostics.diagonal_swap_count;
}

// ---- the steps ---------------------------------------------------------------------------
//
// reconstruct_default() reads top to bottom: search where the cloud parts, square the cut
// to the trunk, adopt the stray points, mesh the one tube for its area, mesh the parts,
// join them, then keep them or undo them. Each step asks for its tubes with a TubeRequest
// of its own, made from the caller's (see >>request).

// What the steps share: the memory, the request the parts are cut along (the caller's,
// along the axis the cut is squared to), and the trunk's own axis once chosen for the
// labels as they stand (`trunk_known`).
struct PartsWork {
    PartsMemory m;
    TubeRequest cut;
    bool trunk_known;
    Status trunk_status;
    TubeRequest trunk;
};

// Finds where the cloud parts along the request's axis (the frame's origin the centroid),
// on a sample first when it is large (see above); the labels are filled where it parts.
// False if the workspace is too small.
static inline bool search_parting(const Cloud& cloud, const TubeInput& whole, const TubeRequest& along,
                           const PartsMemory& m, Arena& arena, Parting& parting) {
    TubeRequest search = along;
    search.origin = nullptr;
    if (whole.sums.valid > kPartingSample) {
        const size_t mark = arena.mark();
        size_t taken = 0;
        const double* sample = sample_points(whole, kPartingSample, arena, &taken);
        if (!sample) return false;
        TubeRequest on_sample = search;  // the sample holds the kept points only
        on_sample.drop_outliers = false;
        const size_t bytes = parting_workspace_size(taken, on_sample);
        void* work = arena.alloc<unsigned char>(bytes);
        if (!work) return false;
        const Status status =
            find_parting_with({sample, taken, 0, Scalar::float64}, on_sample, work, bytes,
                              &parting, nullptr, kSmallestBranch / kSampleBranchShare);
        arena.rewind(mark);
        if (status != Status::ok || parting.above_branch_count + parting.below_branch_count == 0)
            return true;
    }
    const size_t mark = arena.mark();
    const size_t bytes = parting_workspace_size(cloud.count, search);
    void* work = arena.alloc<unsigned char>(bytes);
    if (!work) return false;
    const Status status = find_parting_with(cloud, search, work, bytes, &parting, m.labels,
                                            kSmallestBranch);
    arena.rewind(mark);
    if (status != Status::ok) parting.above_branch_count = parting.below_branch_count = 0;
    return true;
}

// Whether the cloud parts around a trunk: a trunk of fewer points than a branch is no
// trunk, the cloud is apart all along (separate objects) and is meshed as one tube.
static inline bool parts_around_trunk(size_t count, const Parting& parting, const uint8_t* labels) {
    if (parting.above_branch_count + parting.below_branch_count == 0) return false;
    size_t trunk_points = 0;
    for (size_t i = 0; i < count; ++i) trunk_points += labels[i] == kInTrunk;
    return trunk_points >= kSmallestBranch;
}

// The trunk's own automatic axis, chosen once for the labels as they stand: squaring the
// cut asks for it, and the trunk is meshed around it unless a label changed since.
static inline Status trunk_axis(const TubeInput& whole, PartsWork& w, Arena& arena) {
    if (w.trunk_known) return w.trunk_status;
    w.trunk = w.cut;
    w.trunk.axis = Axis::automatic;
    const char* ignored = nullptr;
    const size_t mark = arena.mark();
    w.trunk_status = resolve_axis(part_input(whole, w.m, kInTrunk), arena, w.trunk, &ignored);
    arena.rewind(mark);
    w.trunk_known = true;
    return w.trunk_status;
}

// A fork scanned askew is cut obliquely, lower under one branch than under another, and a
// graft needs the cut square to the fork (see join_branches()). Where the trunk's own axis
// leans from the parting's by more than kSquareCutLeast (and less than kSquareCutMost:
// beyond, the trunk runs another way than its branches, as a body whose legs hang under
// it), the parting is searched again along the mean of the two axes, up to kSquareCutRounds
// times: an oblique cut leaves more of one branch in the trunk, which leans the trunk's
// axis the other way, so the mean comes closer each round. A round is kept only if it
// finds as many branches on each side; the parts are then cut along its axis. Not where
// the caller gave cuts, which are positions along the axis. False if the workspace is too
// small.
const double kSquareCutLeast = 0.99996;  // cos 0.5 degree

const double kSquareCutMost = 0.866;     // cos 30 degrees

const int kSquareCutRounds = 4;

static inline bool square_cut_to_trunk(const Cloud& cloud, const TubeInput& whole, PartsWork& w,
                                Arena& arena, Parting& parting) {
    for (int round = 0; round < kSquareCutRounds && w.cut.layers.cut_count == 0; ++round) {
        if (trunk_axis(whole, w, arena) != Status::ok || w.trunk.axis != Axis::direction) break;
        const Vec3 cut = {parting.axis[0], parting.axis[1], parting.axis[2]};
        Vec3 trunk = {w.trunk.direction[0], w.trunk.direction[1], w.trunk.direction[2]};
        if (!normalize(trunk)) break;
        const double lean = dot(trunk, cut);
        if (!(std::fabs(lean) < kSquareCutLeast && std::fabs(lean) > kSquareCutMost)) break;
        const Vec3 toward = scaled(trunk, lean < 0 ? -1 : 1);  // the parting's way
        const double mean[3] = {cut.x + toward.x, cut.y + toward.y, cut.z + toward.z};
        TubeRequest squared = w.cut;
        set_direction(squared, mean);
        Parting again = {};
        if (!search_parting(cloud, whole, squared, w.m, arena, again)) return false;
        if (again.above_branch_count != parting.above_branch_count ||
            again.below_branch_count != parting.below_branch_count) {
            // The last round's labels back, and with them the trunk's axis chosen on them.
            return search_parting(cloud, whole, w.cut, w.m, arena, parting);
        }
        w.cut = squared;
        w.trunk_known = false;
        parting = again;
    }
    return true;
}

// The area of a surface whose triangles index the cloud.
static inline double surface_area(const CloudReader& reader, const uint32_t* triangles, size_t count) {
    double area = 0;
    for (size_t t = 0; t < count; ++t) {
        const Vec3 a = reader.point(triangles[3 * t]);
        const Vec3 n = cross(reader.point(triangles[3 * t + 1]) - a,
                             reader.point(triangles[3 * t + 2]) - a);
        area += std::sqrt(dot(n, n)) / 2;
    }
    return area;
}

// The one tube's area, to weigh the parts against (DBL_MAX where it has none), where it
// can decide: not where the parts are kept whatever their area, nor where a point in no
// part undoes them whatever it. Its triangles are overwritten by the parts'.
static inline Status one_tube_area(const TubeInput& in, const TubeRequest& request, bool all_in_parts,
                            Arena& arena, uint32_t* triangles, size_t capacity,
                            const Report& before, double* area) {
    *area = DBL_MAX;
    if (request.parts == Parts::apart || !all_in_parts) return Status::ok;
    Report tube = before;
    size_t count = 0;
    const size_t mark = arena.mark();
    const Status status = mesh_tube(in, request, arena, triangles, capacity, &count, tube);
    arena.rewind(mark);
    if (status == Status::ok) *area = surface_area(in.reader, triangles, count);
    return status == Status::out_of_memory ? status : Status::ok;
}

// The trunk along `along`, its end layers under branches merged where they stand on a
// closed end; its triangles start the output.
static inline Status mesh_trunk(const TubeInput& trunk, const TubeRequest& along, const Parting& parting,
                         const PartsMemory& m, Arena& arena, uint32_t* triangles,
                         size_t capacity, size_t* count, Report& part, size_t* merged) {
    part.layers.info = m.layers;
    part.layers.info_capacity = m.layer_capacity;
    const size_t mark = arena.mark();
    Status status = mesh_tube(trunk, along, arena, triangles, capacity, count, part);
    arena.rewind(mark);
    size_t cut_count = 0;
    *merged = 0;
    if (status != Status::ok || part.layers.used_count > m.layer_capacity ||
        !cuts_for_tall_ends(m, part.layers.used_count, parting, &cut_count, merged))
        return status;
    // Again along the same axis, through the layers' own cuts but those merged.
    TubeRequest again = along;
    set_direction(again, part.axis);
    again.layers = {m.cuts, cut_count, cut_count == 0 ? 1u : 0u, 0};
    part = Report{};
    part.layers.info = m.layers;
    part.layers.info_capacity = m.layer_capacity;
    status = mesh_tube(trunk, again, arena, triangles, capacity, count, part);
    arena.rewind(mark);
    return status;
}

// The trunk into the output, around its own axis as the branches (a body whose legs hang
// under it is meshed along the body) unless the caller laid out the layers; its frame and
// layers are the whole's in the report. Where it fails, the outcome is undone.
static inline Status mesh_trunk_part(const TubeInput& whole, PartsWork& w, Arena& arena,
                              uint32_t* triangles, size_t capacity, size_t* count, Report& rep) {
    const Parting& parting = rep.parts.parting;
    const TubeInput trunk = part_input(whole, w.m, kInTrunk);
    const bool own_axis = automatic_layers(w.cut.layers);
    Status status = own_axis ? trunk_axis(whole, w, arena) : Status::ok;
    TubeRequest along = own_axis ? w.trunk : w.cut;
    along.caps = false;  // the caps come once the parts are joined
    // Pointing the parting's way, so that the trunk's top is on the side above.
    const double* d = along.direction;
    if (own_axis && along.axis == Axis::direction &&
        d[0] * parting.axis[0] + d[1] * parting.axis[1] + d[2] * parting.axis[2] < 0)
        for (int k = 0; k < 3; ++k) along.direction[k] = -d[k];
    Report part = {};
    size_t merged = 0;
    if (status == Status::ok)
        status = mesh_trunk(trunk, along, parting, w.m, arena, triangles, capacity, count, part,
                            &merged);
    record_part(rep, kInTrunk, status, trunk, part, *count, merged);
    if (status != Status::ok) {
        rep.parts.outcome = PartsOutcome::undone;
        return status == Status::out_of_memory ? status : Status::ok;
    }
    for (int k = 0; k < 3; ++k) {
        rep.axis[k] = part.axis[k];
        rep.axis_origin[k] = part.axis_origin[k];
    }
    rep.layers.used_count = part.layers.used_count;
    rep.layers.planned_count = part.layers.planned_count;
    rep.layers.parallel_count = part.layers.parallel_count;
    size_t kept = rep.layers.used_count < w.m.layer_capacity ? rep.layers.used_count
                                                              : w.m.layer_capacity;
    kept = kept < rep.layers.info_capacity ? kept : rep.layers.info_capacity;
    if (kept > 0) std::memcpy(rep.layers.info, w.m.layers, kept * sizeof(LayerInfo));
    return Status::ok;
}

// A branch's request: around its own automatic axis and layers, its frame's origin its own
// centroid, no caps (they come once the parts are joined) and no progress (the caller's
// would run backwards from part to part).
static inline TubeRequest branch_request(TubeRequest r) {
    r.axis = Axis::automatic;
    r.layers = LayerRequest{};
    r.origin = nullptr;
    r.caps = false;
    r.progress = nullptr;
    return r;
}

// Each branch into the output after the trunk's `*count` triangles, its end at the cut a
// cut, not a closed end: its low end along its own axis if that runs away from the trunk.
// *all_meshed is cleared where a branch fails (its points stay unused).
static inline Status mesh_branches(const TubeInput& whole, const PartsWork& w, Arena& arena,
                            uint32_t* triangles, size_t capacity, size_t* count, bool* all_meshed,
                            Report& rep) {
    const Parting& parting = rep.parts.parting;
    const TubeRequest branches = branch_request(w.cut);
    const Vec3 parting_axis = {parting.axis[0], parting.axis[1], parting.axis[2]};
    const uint32_t total = parting.above_branch_count + parting.below_branch_count;
    for (uint32_t b = 0; b < total; ++b) {
        const bool above = b < parting.above_branch_count;
        const uint8_t label = static_cast<uint8_t>(
            above ? kFirstAboveBranch + b : kFirstBelowBranch + (b - parting.above_branch_count));
        const TubeInput branch = part_input(whole, w.m, label);
        if (branch.sums.valid == 0) continue;  // the side above took its points
        Report part = {};
        TubeRequest own = branches;
        size_t added = 0;
        const size_t mark = arena.mark();
        Status status = resolve_axis(branch, arena, own, &part.detail);
        const Vec3 own_axis = {own.direction[0], own.direction[1], own.direction[2]};
        own.cut_ends |= (dot(own_axis, parting_axis) > 0) == above ? kLowPole : kHighPole;
        if (status == Status::ok)
            status = mesh_tube(branch, own, arena, triangles + 3 * *count, capacity - *count,
                               &added, part);
        arena.rewind(mark);
        record_part(rep, label, status, branch, part, added, 0);
        if (status == Status::out_of_memory) return status;
        if (status != Status::ok) {
            *all_meshed = false;
            if (!rep.detail) rep.detail = part.detail;
            continue;
        }
        *count += added;
    }
    return Status::ok;
}

// Joins the parts meshed into the output (then caps them, as asked); `whole` tells whether
// every part was meshed and every point is in one. Sets rep.parts.outcome: joined,
// kept_apart, or undone (the output is then to be made again as one tube).
static inline Status join_parts(const Cloud& cloud, const PartsWork& w, bool whole, Arena& arena,
                         uint32_t* triangles, size_t capacity, size_t count,
                         size_t* triangle_count, Report& rep) {
    JoinReport join = {};
    const size_t bytes = join_branches_workspace_size(cloud.count, count);
    const size_t mark = arena.mark();
    void* work = arena.alloc<unsigned char>(bytes);
    if (!work) return Status::out_of_memory;
    size_t joined = count;
    Status status = join_branches(cloud, *w.cut.caller, rep.parts.parting, w.m.labels, work,
                                  bytes, triangles, capacity, &joined, &join);
    arena.rewind(mark);
    if (status == Status::ok) count = joined;
    rep.parts.joined_side_count = join.joined_side_count;
    rep.parts.apart_side_count = join.apart_side_count;
    rep.parts.grafted_branch_count = join.grafted_branch_count;
    rep.parts.junction_triangle_count = join.junction_triangle_count;
    rep.parts.removed_triangle_count = join.removed_triangle_count;
    if (!rep.detail) rep.detail = join.detail;
    whole = whole && status == Status::ok && join.apart_side_count == 0;
    if (!whole && w.cut.parts != Parts::apart) {
        rep.parts.outcome = PartsOutcome::undone;
        return Status::ok;
    }
    rep.parts.outcome = whole ? PartsOutcome::joined : PartsOutcome::kept_apart;
    if (w.cut.caps) {
        // Around the axis the cut was made along, in the frame of the whole cloud.
        const CloudReader reader = reader_of(cloud);
        const TubeInput all = {reader, cloud.count, sum_cloud(reader, cloud.count)};
        CapTally caps = {0, 0, 0, 0};
        size_t needed = 0;
        status = cap_surface(all, w.cut, arena, triangles, capacity, count, caps, &needed);
        arena.rewind(mark);
        if (status != Status::ok) return status;
        rep.caps.closed_count = caps.closed;
        rep.caps.open_count = caps.left_open;
        rep.caps.triangle_count = caps.triangles;
        rep.caps.wall_flip_count = caps.wall_flips;
    }
    *triangle_count = count;
    rep.triangle_count = count;
    return Status::ok;
}

// Whether the parts are kept: joined and smaller than the one tube (a tube that wraps
// branches bridges the gaps between them with webs, which add area, and so does a join
// that folds where the parting misread the cloud, as a neck's torn rim taken for two
// branches), or kept apart as asked. Otherwise the counts start again from `before`, the
// parts' record stays.
static inline bool keep_or_undo(const TubeInput& in, const uint32_t* triangles, size_t count,
                         double tube_area, const Report& before, Report& rep) {
    const PartsOutcome outcome = rep.parts.outcome;
    if (outcome == PartsOutcome::kept_apart ||
        (outcome == PartsOutcome::joined && surface_area(in.reader, triangles, count) < tube_area))
        return true;
    PartCounts parts = rep.parts;
    if (outcome != PartsOutcome::undone) {
        parts.outcome = PartsOutcome::undone;
        rep.detail = "the branches joined made a larger surface than one tube";
    }
    const char* detail = rep.detail;
    rep = before;
    rep.parts = parts;
    rep.detail = detail;
    return false;
}

// The steps where the cloud may part (see above); *kept tells whether the parts are the
// output, else the one tube is to be meshed.
static inline Status mesh_apart(const Cloud& cloud, const TubeInput& in, const TubeRequest& request,
                         Arena& arena, uint32_t* triangles, size_t capacity,
                         size_t* triangle_count, Report& rep, bool* kept) {
    PartsWork w = {};
    w.cut = request;
    Parting& parting = rep.parts.parting;
    if (!allocate_parts(w.m, cloud.count, arena) ||
        !search_parting(cloud, in, w.cut, w.m, arena, parting))
        return Status::out_of_memory;
    if (!parts_around_trunk(cloud.count, parting, w.m.labels)) return Status::ok;
    if (!square_cut_to_trunk(cloud, in, w, arena, parting)) return Status::out_of_memory;
    if (adopt_stray_points(in, parting.gap, w.m.labels)) w.trunk_known = false;
    bool whole = every_point_in_a_part(in.count, w.m.labels);
    const Report before = rep;
    double tube_area = DBL_MAX;
    Status status = one_tube_area(in, request, whole, arena, triangles, capacity, before,
                                  &tube_area);
    size_t count = 0;
    if (status == Status::ok)
        status = mesh_trunk_part(in, w, arena, triangles, capacity, &count, rep);
    if (status != Status::ok) return status;
    if (rep.parts.outcome != PartsOutcome::undone) {
        status = mesh_branches(in, w, arena, triangles, capacity, &count, &whole, rep);
        if (status != Status::ok) return status;
        if (!whole && !rep.detail)
            rep.detail = "points beyond a cut belong to no branch (a piece more than two gaps "
                         "from every part)";
        status = join_parts(cloud, w, whole, arena, triangles, capacity, count, triangle_count,
                            rep);
        if (status != Status::ok) return status;
    }
    *kept = keep_or_undo(in, triangles, *triangle_count, tube_area, before, rep);
    return Status::ok;
}

// reconstruct() with the search for branches: `in` is read and the request's axis is
// resolved. Where the cloud parts, the parts joined are kept only where whole and smaller
// than the one tube's (see keep_or_undo()), else the one tube is.
static inline Status reconstruct_default(const Cloud& cloud, const TubeInput& in,
                                  const TubeRequest& request, Arena& arena,
                                  uint32_t* triangles, size_t capacity, size_t* triangle_count,
                                  Report& rep) {
    if (in.sums.distinct >= 3) {
        const size_t mark = arena.mark();
        bool kept = false;
        const Status status = mesh_apart(cloud, in, request, arena, triangles, capacity,
                                         triangle_count, rep, &kept);
        if (status != Status::ok || kept) return status;
        arena.rewind(mark);
    }
    return mesh_tube(in, request, arena, triangles, capacity, triangle_count, rep);
}

// The workspace reconstruct_default() takes on top of read_cloud()'s.
static inline size_t parts_workspace_size(size_t count, const TubeRequest& request) {
    Arena arena = Arena::measuring();
    PartsMemory m;
    allocate_parts(m, count, arena);
    // The one tube meshed for its area while the parts' memory is held, and the parts (their
    // points read through the mask): the trunk's tube, without caps, takes no more.
    TubeRequest tube = request;
    tube.drop_outliers = false;
    TubeRequest part = tube;
    part.caps = false;
    const size_t triangles = reconstruct_max_triangles(count, *request.caller);
    const size_t sample = count > kPartingSample
                              ? saturating_product(3 * sizeof(double), kPartingSample) + Arena::kAlign +
                                    parting_workspace_size(kPartingSample, part)
                              : 0;
    const TubeRequest branch = branch_request(part);
    const size_t steps[] = {sample, parting_workspace_size(count, request),
                            tube_workspace_size(count, tube),
                            axis_workspace_size(count, branch),
                            tube_workspace_size(count, branch),
                            join_branches_workspace_size(count, triangles),
                            cap_ends_workspace_size(count, triangles)};
    size_t most = sample;
    for (size_t k = 1; k < sizeof steps / sizeof steps[0]; ++k) {
        if (steps[k] == 0) return 0;  // beyond what this platform can address
        most = steps[k] > most ? steps[k] : most;
    }
    if (arena.failed || most > SIZE_MAX - arena.required_bytes() - Arena::kAlign) return 0;
    return arena.required_bytes() + Arena::kAlign + most;
}

}  // namespace detail
}  // namespace stratmesh

#endif  // STRATMESH_SMALL_CODE
