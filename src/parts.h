// >>parts ================================================================================
// reconstruct()'s default: trunk and branches, meshed and joined.
//
// reconstruct()'s default where the cloud parts into branches (PartCounts). One tube wraps
// branches and the gaps between them, so where find_parting() finds a cut, the trunk (the
// points labelled kInTrunk) is meshed along the cloud's axis, each branch as a tube of its
// own around its own automatic axis, and join_branches() zips them into one surface (caps
// last, with close_ends, once joined). That is kept only when it is whole: every part
// meshed, every side joined, every point in a part; otherwise, unless keep_parts, the cloud
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
inline size_t most_layers(size_t count) { return count / kMinLayerPoints + 2; }

struct PartsMemory {
    uint8_t* labels;          // find_parting's branch_of for the whole cloud
    unsigned char* mask;      // the points left out of the part being meshed
    LayerInfo* layers;        // the trunk's
    double* cuts;             // the trunk's, merged at its ends (see cuts_for_tall_ends)
    size_t layer_capacity;
};

inline bool allocate_parts(PartsMemory& m, size_t count, Arena& arena) {
    m.labels = arena.alloc<uint8_t>(count);
    m.mask = arena.alloc<unsigned char>(count / 8 + 1);
    m.layer_capacity = most_layers(count);
    m.layers = arena.alloc<LayerInfo>(m.layer_capacity);
    m.cuts = arena.alloc<double>(m.layer_capacity);
    return !arena.failed;
}

// The reader of the part labelled `label`: every other point left out with the outliers.
inline TubeInput part_input(const TubeInput& whole, const PartsMemory& m, uint8_t label) {
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

inline void adopt_stray_points(const TubeInput& whole, double gap, uint8_t* labels) {
    const double reach = kAdoptionGaps * gap;
    uint64_t checks_left = kMostStrayChecks;
    // Passes until none is adopted: a point can be adopted through one adopted before it
    // (the sparse tip of a horn, point after point).
    for (bool adopted = true; adopted;) {
        adopted = false;
        uint64_t strays = 0;
        for (size_t i = 0; i < whole.count; ++i)
            strays += labels[i] == kBeyondBranches && whole.reader.valid(i);
        if (strays == 0 || strays > checks_left / whole.count) return;
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
            labels[i] = label;
        }
    }
}

// Where branches stand on a closed end of the trunk (its end layer at a side that parts
// is closed, as a skull's crown under horns), the cuts that merge that end layer with the
// layers next to it until it is kPoleLayerRadii times the largest of their radii tall;
// false where no end needs it. *merged counts the layers merged away.
inline bool cuts_for_tall_ends(const PartsMemory& m, size_t n, const Parting& parting,
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

// A part's counts into the whole's report.
inline void add_part_counts(const Report& part, Report& rep) {
    rep.points.used_count += part.points.used_count;
    rep.points.duplicate_count += part.points.duplicate_count;
    rep.diagnostics.fold_count += part.diagnostics.fold_count;
    rep.diagnostics.illegal_removed_count += part.diagnostics.illegal_removed_count;
    rep.diagnostics.diagonal_swap_count += part.diagnostics.diagonal_swap_count;
}

inline void record_part(Report& rep, uint8_t label, Status status, const TubeInput& in,
                        const Report& part, size_t triangles, size_t merged) {
    PartCounts& p = rep.parts;
    if (p.part_count < p.info_capacity)
        p.info[p.part_count] = {label, status, in.sums.valid, part.layers.used_count,
                                status == Status::ok ? triangles : 0,
                                part.diagnostics.fold_count, merged};
    ++p.part_count;
}

// Finds where the cloud parts, on a sample first when it is large (see above); the labels
// are filled where it parts. False if the workspace is too small.
inline bool search_parting(const Cloud& cloud, const TubeInput& whole, const Options& along,
                           const PartsMemory& m, Arena& arena, Parting& parting) {
    Options search = along;
    search.flags &= skip_invalid_points | drop_outliers;
    if (whole.sums.valid > kPartingSample) {
        const size_t mark = arena.mark();
        size_t taken = 0;
        const double* sample = sample_points(whole, kPartingSample, arena, &taken);
        if (!sample) return false;
        Options on_sample = search;
        on_sample.flags &= ~static_cast<uint32_t>(skip_invalid_points | drop_outliers);
        const size_t bytes = find_parting_workspace_size(taken, on_sample);
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
    const size_t bytes = find_parting_workspace_size(cloud.count, search);
    void* work = arena.alloc<unsigned char>(bytes);
    if (!work) return false;
    const Status status = find_parting(cloud, search, work, bytes, &parting, m.labels);
    arena.rewind(mark);
    if (status != Status::ok) parting.above_branch_count = parting.below_branch_count = 0;
    return true;
}

// A fork scanned askew is cut obliquely, lower under one branch than under another, and a
// graft needs the cut square to the fork (see join_branches()). Where the trunk's own axis
// leans from the parting's by more than kSquareCutLeast (and less than kSquareCutMost:
// beyond, the trunk runs another way than its branches, as a body whose legs hang under
// it), the parting is searched again along the mean of the two axes, up to kSquareCutRounds
// times: an oblique cut leaves more of one branch in the trunk, which leans the trunk's
// axis the other way, so the mean comes closer each round. A round is kept only if it
// finds as many branches on each side; `along` then takes its axis. Not where the caller
// gave cuts, which are positions along the axis. False if the workspace is too small.
const double kSquareCutLeast = 0.99996;  // cos 0.5 degree

const double kSquareCutMost = 0.866;     // cos 30 degrees

const int kSquareCutRounds = 4;

inline bool square_cut_to_trunk(const Cloud& cloud, const TubeInput& whole, const PartsMemory& m,
                                Arena& arena, Options& along, Parting& parting) {
    for (int round = 0; round < kSquareCutRounds && along.cut_count == 0; ++round) {
        Options automatic = along, own;
        automatic.axis = Axis::automatic;
        Report ignored = {};
        const size_t mark = arena.mark();
        const Status status = resolve_axis(part_input(whole, m, kInTrunk), automatic, arena,
                                           own, ignored);
        arena.rewind(mark);
        if (status != Status::ok || own.axis != Axis::direction) break;
        const Vec3 cut = {parting.axis[0], parting.axis[1], parting.axis[2]};
        Vec3 trunk = {own.direction[0], own.direction[1], own.direction[2]};
        if (!normalize(trunk)) break;
        const double lean = dot(trunk, cut);
        if (!(std::fabs(lean) < kSquareCutLeast && std::fabs(lean) > kSquareCutMost)) break;
        const Vec3 toward = scaled(trunk, lean < 0 ? -1 : 1);  // the parting's way
        Options squared = along;
        squared.axis = Axis::direction;
        squared.direction[0] = cut.x + toward.x;
        squared.direction[1] = cut.y + toward.y;
        squared.direction[2] = cut.z + toward.z;
        Parting again = {};
        if (!search_parting(cloud, whole, squared, m, arena, again)) return false;
        if (again.above_branch_count != parting.above_branch_count ||
            again.below_branch_count != parting.below_branch_count) {
            if (!search_parting(cloud, whole, along, m, arena, parting)) return false;
            break;  // the last round's labels are back
        }
        along = squared;
        parting = again;
    }
    return true;
}

// The trunk along the cloud's axis, its end layers under branches merged where they stand
// on a closed end; its triangles start the output.
inline Status mesh_trunk(const TubeInput& trunk, const Options& along, const Parting& parting,
                         const PartsMemory& m, Arena& arena, uint32_t* triangles,
                         size_t capacity, size_t* count, Report& part, size_t* merged) {
    Options o = along;
    o.flags &= ~static_cast<uint32_t>(close_ends);
    part.layers.info = m.layers;
    part.layers.info_capacity = m.layer_capacity;
    const size_t mark = arena.mark();
    Status status = mesh_tube(trunk, o, arena, triangles, capacity, count, part);
    arena.rewind(mark);
    size_t cut_count = 0;
    *merged = 0;
    if (status != Status::ok || part.layers.used_count > m.layer_capacity ||
        !cuts_for_tall_ends(m, part.layers.used_count, parting, &cut_count, merged))
        return status;
    // Again along the same axis, through the layers' own cuts but those merged.
    o.axis = Axis::direction;
    for (int k = 0; k < 3; ++k) o.direction[k] = part.axis[k];
    o.cuts = m.cuts;
    o.cut_count = cut_count;
    o.layer_count = cut_count == 0 ? 1 : 0;
    o.layer_height = 0;
    part = Report{};
    part.layers.info = m.layers;
    part.layers.info_capacity = m.layer_capacity;
    status = mesh_tube(trunk, o, arena, triangles, capacity, count, part);
    arena.rewind(mark);
    return status;
}

// Meshes the parts into the output and joins them (then caps them, with close_ends).
// Returns ok with rep.parts.outcome joined or kept_apart, or ok with outcome undone (the
// output is then to be made again as one tube); other statuses are errors.
inline Status mesh_parts(const Cloud& cloud, const TubeInput& whole, const Options& along,
                         const PartsMemory& m, Arena& arena, uint32_t* triangles,
                         size_t capacity, size_t* triangle_count, Report& rep) {
    const Parting& parting = rep.parts.parting;
    bool whole_split = true;
    Report trunk_report = {};
    const TubeInput trunk = part_input(whole, m, kInTrunk);
    size_t count = 0, merged = 0;
    Options trunk_options = along;
    Status status = Status::ok;
    // The trunk around its own axis, as the branches (a body whose legs hang under it is
    // meshed along the body), unless the caller laid out the layers.
    if (along.cut_count == 0 && along.layer_count == 0 && !(along.layer_height > 0)) {
        Options automatic = along;
        automatic.axis = Axis::automatic;
        const size_t mark = arena.mark();
        status = resolve_axis(trunk, automatic, arena, trunk_options, trunk_report);
        arena.rewind(mark);
        // Pointing the parting's way, so that the trunk's top is on the side above.
        const double* d = trunk_options.direction;
        if (trunk_options.axis == Axis::direction &&
            d[0] * parting.axis[0] + d[1] * parting.axis[1] + d[2] * parting.axis[2] < 0)
            for (int k = 0; k < 3; ++k) trunk_options.direction[k] = -d[k];
    }
    if (status == Status::ok)
        status = mesh_trunk(trunk, trunk_options, parting, m, arena, triangles, capacity, &count,
                            trunk_report, &merged);
    record_part(rep, kInTrunk, status, trunk, trunk_report, count, merged);
    if (status != Status::ok) {
        rep.parts.outcome = PartsOutcome::undone;
        return status == Status::out_of_memory ? status : Status::ok;
    }
    add_part_counts(trunk_report, rep);
    for (int k = 0; k < 3; ++k) {
        rep.axis[k] = trunk_report.axis[k];
        rep.axis_origin[k] = trunk_report.axis_origin[k];
    }
    rep.layers.used_count = trunk_report.layers.used_count;
    rep.layers.planned_count = trunk_report.layers.planned_count;
    rep.layers.parallel_count = trunk_report.layers.parallel_count;
    for (size_t k = 0; k < rep.layers.used_count && k < rep.layers.info_capacity &&
                       k < m.layer_capacity; ++k)
        rep.layers.info[k] = m.layers[k];
    Options branch_options = along;
    branch_options.axis = Axis::automatic;
    branch_options.cuts = nullptr;
    branch_options.cut_count = 0;
    branch_options.layer_count = 0;
    branch_options.layer_height = 0;
    branch_options.progress = nullptr;
    branch_options.flags &= ~static_cast<uint32_t>(origin_given | close_ends);
    const uint32_t branches = parting.above_branch_count + parting.below_branch_count;
    for (uint32_t b = 0; b < branches; ++b) {
        const bool above = b < parting.above_branch_count;
        const uint8_t label = static_cast<uint8_t>(
            above ? kFirstAboveBranch + b : kFirstBelowBranch + (b - parting.above_branch_count));
        const TubeInput branch = part_input(whole, m, label);
        if (branch.sums.valid == 0) continue;  // the side above took its points
        Report part = {};
        Options own;
        size_t added = 0;
        const size_t mark = arena.mark();
        status = resolve_axis(branch, branch_options, arena, own, part);
        // The branch's end at the cut is a cut, not a closed end: its low end along its own
        // axis if that runs away from the trunk.
        const Vec3 trunk_axis = {parting.axis[0], parting.axis[1], parting.axis[2]};
        const Vec3 own_axis = {own.direction[0], own.direction[1], own.direction[2]};
        const bool away = (dot(own_axis, trunk_axis) > 0) == above;
        TubeInput cut = branch;
        cut.cut_ends = away ? kLowPole : kHighPole;
        if (status == Status::ok)
            status = mesh_tube(cut, own, arena, triangles + 3 * count, capacity - count,
                               &added, part);
        arena.rewind(mark);
        record_part(rep, label, status, branch, part, added, 0);
        if (status == Status::out_of_memory) return status;
        if (status != Status::ok) {  // its points stay unused
            whole_split = false;
            if (!rep.detail) rep.detail = part.detail;
            continue;
        }
        add_part_counts(part, rep);
        count += added;
    }
    for (size_t i = 0; i < whole.count && whole_split; ++i)
        whole_split = m.labels[i] != kBeyondBranches;
    if (!whole_split && !rep.detail)
        rep.detail = "points beyond a cut belong to no branch (a piece more than two gaps "
                     "from every part)";
    // The junctions.
    JoinReport join = {};
    const size_t join_bytes = join_branches_workspace_size(cloud.count, count);
    const size_t mark = arena.mark();
    void* work = arena.alloc<unsigned char>(join_bytes);
    if (!work) return Status::out_of_memory;
    Options joining = {};
    joining.flags = along.flags & skip_invalid_points;
    size_t joined = count;
    status = join_branches(cloud, joining, parting, m.labels, work, join_bytes, triangles,
                           capacity, &joined, &join);
    arena.rewind(mark);
    if (status == Status::ok) count = joined;
    rep.parts.joined_side_count = join.joined_side_count;
    rep.parts.apart_side_count = join.apart_side_count;
    rep.parts.grafted_branch_count = join.grafted_branch_count;
    rep.parts.junction_triangle_count = join.added_triangle_count;
    rep.parts.removed_triangle_count = join.removed_triangle_count;
    if (!rep.detail) rep.detail = join.detail;
    whole_split = whole_split && status == Status::ok && join.apart_side_count == 0;
    if (!whole_split && !(along.flags & keep_parts)) {
        rep.parts.outcome = PartsOutcome::undone;
        return Status::ok;
    }
    rep.parts.outcome = whole_split ? PartsOutcome::joined : PartsOutcome::kept_apart;
    if (along.flags & close_ends) {
        const size_t cap_bytes = cap_ends_workspace_size(cloud.count, count);
        void* capping = arena.alloc<unsigned char>(cap_bytes);
        if (!capping) return Status::out_of_memory;
        Options capped = along;
        capped.flags &= skip_invalid_points | origin_given;
        Report caps = {};
        status = cap_ends(cloud, capped, capping, cap_bytes, triangles, capacity, &count, &caps);
        arena.rewind(mark);
        if (status != Status::ok) return status;
        rep.caps = caps.caps;
    }
    *triangle_count = count;
    rep.triangle_count = count;
    return Status::ok;
}

// The area of a surface whose triangles index the cloud.
inline double surface_area(const CloudReader& reader, const uint32_t* triangles, size_t count) {
    double area = 0;
    for (size_t t = 0; t < count; ++t) {
        const Vec3 a = reader.point(triangles[3 * t]);
        const Vec3 n = cross(reader.point(triangles[3 * t + 1]) - a,
                             reader.point(triangles[3 * t + 2]) - a);
        area += std::sqrt(dot(n, n)) / 2;
    }
    return area;
}

// reconstruct() with the search for branches: `in` is read and `along` has its axis. Where
// the cloud parts, the parts joined are kept only if their surface is smaller than the one
// tube's (unless keep_parts): a tube that wraps branches bridges the gaps between them
// with webs, which add area, and so does a join that folds where the parting misread the
// cloud (a neck's torn rim taken for two branches). The tube is meshed first for its area,
// and again if it wins.
inline Status reconstruct_default(const Cloud& cloud, const TubeInput& in, const Options& along,
                                  Arena& arena, uint32_t* triangles, size_t capacity,
                                  size_t* triangle_count, Report& rep) {
    if (in.sums.distinct >= 3) {
        const size_t mark = arena.mark();
        PartsMemory m;
        if (!allocate_parts(m, cloud.count, arena)) return Status::out_of_memory;
        if (!search_parting(cloud, in, along, m, arena, rep.parts.parting))
            return Status::out_of_memory;
        const Parting& p = rep.parts.parting;
        // A trunk of fewer points than a branch is no trunk: the cloud is apart all along
        // (separate objects), and is meshed as one tube.
        size_t trunk_points = 0;
        if (p.above_branch_count + p.below_branch_count > 0)
            for (size_t i = 0; i < cloud.count; ++i) trunk_points += m.labels[i] == kInTrunk;
        if (trunk_points >= kSmallestBranch) {
            Options cut_along = along;
            if (!square_cut_to_trunk(cloud, in, m, arena, cut_along, rep.parts.parting))
                return Status::out_of_memory;
            adopt_stray_points(in, p.gap, m.labels);
            const Report before = rep;
            double tube_area = DBL_MAX;
            if (!(along.flags & keep_parts)) {
                Report tube = before;
                size_t count = 0;
                const size_t tube_mark = arena.mark();
                const Status status =
                    mesh_tube(in, along, arena, triangles, capacity, &count, tube);
                arena.rewind(tube_mark);
                if (status == Status::out_of_memory) return status;
                if (status == Status::ok) tube_area = surface_area(in.reader, triangles, count);
            }
            const Status status = mesh_parts(cloud, in, cut_along, m, arena, triangles,
                                             capacity, triangle_count, rep);
            if (status != Status::ok) return status;
            if (rep.parts.outcome != PartsOutcome::undone &&
                (rep.parts.outcome == PartsOutcome::kept_apart ||
                 surface_area(in.reader, triangles, *triangle_count) < tube_area))
                return status;
            // Not kept: the counts start again, the parts' record stays.
            PartCounts parts = rep.parts;
            if (parts.outcome != PartsOutcome::undone) {
                parts.outcome = PartsOutcome::undone;
                rep.detail = "the branches joined made a larger surface than one tube";
            }
            const char* detail = rep.detail;
            rep = before;
            rep.parts = parts;
            rep.detail = detail;
        }
        arena.rewind(mark);
    }
    return mesh_tube(in, along, arena, triangles, capacity, triangle_count, rep);
}

// The workspace reconstruct_default() takes on top of read_cloud()'s.
inline size_t parts_workspace_size(size_t count, const Options& options) {
    Arena arena = Arena::measuring();
    PartsMemory m;
    allocate_parts(m, count, arena);
    Options plain = options;  // a part's points are read through the mask
    plain.flags &= ~static_cast<uint32_t>(drop_outliers | close_ends);
    Options search = options;
    search.flags &= skip_invalid_points | drop_outliers;
    Options tube = options;  // the one tube meshed for its area while the parts' memory is held
    tube.flags &= ~static_cast<uint32_t>(drop_outliers);
    const size_t triangles = reconstruct_max_triangles(count, options);
    const size_t sample = count > kPartingSample
                              ? saturating_product(3 * sizeof(double), kPartingSample) + Arena::kAlign +
                                    find_parting_workspace_size(kPartingSample, plain)
                              : 0;
    Options branch = plain;  // its own automatic axis and layers
    branch.cuts = nullptr;
    branch.cut_count = 0;
    branch.layer_count = 0;
    branch.layer_height = 0;
    const size_t steps[] = {sample, find_parting_workspace_size(count, search),
                            tube_workspace_size(count, plain), tube_workspace_size(count, tube),
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
