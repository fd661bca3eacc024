// >>parallel layers ======================================================================
// Layers triangulated ahead as jobs on the caller's runner.

namespace stratmesh {
namespace detail {

// ---- parallel layers -----------------------------------------------------------------------
//
// With Options::run_jobs, every planned layer that could stand as a group on its own (at
// least kMinLayerPoints points, or the last one) is loaded and, if group_stands, triangulated
// ahead by a job, into its own part of the workspace; the job also keeps the triangles at
// its bottom loop and turns the rest to reader indices (keep_border). Then the groups are
// formed in order as always; a group that is one planned layer takes the job's result
// (add_group), stitches it and, when the safety net has nothing to do there, finishes the
// chunk reading only the band and that border (replay_chunk); any other group (merged
// layers, a chunk the net must repair) is triangulated then. So the result is the
// sequential one whatever the jobs' order and threads, and what runs in order is a small
// part of each layer's work. Jobs are contiguous runs of such layers with about equal point
// counts, each with the scratch of its largest layer.

#if !defined(STRATMESH_NO_PARALLEL_LAYERS)

struct ParallelLayers {
    bool ready;                  // the jobs ran
    const CloudReader* reader;
    const Frame* frame;
    const LayerQueue* queue;
    uint32_t slots;              // layers done ahead
    LayerAhead* ahead;           // per slot
    uint32_t* layer_of_slot;
    uint32_t* slot_of_layer;     // kNoIndex: not done ahead
    uint32_t job_count;
    uint32_t first_slot[kMaxJobs + 1];
    unsigned char* scratch[kMaxJobs];
    size_t scratch_bytes[kMaxJobs];

    const LayerAhead* ahead_of(uint32_t layer) const {
        uint32_t slot = slot_of_layer[layer];
        return slot == kNoIndex ? nullptr : ahead + slot;
    }
};

// Room for the results of `slots` layers holding `points` points in all, out of `layers`
// planned layers.
static inline bool allocate_ahead(ParallelLayers& p, uint32_t slots, size_t points, size_t layers,
                                  Arena& arena, uint32_t** triangles, uint32_t** loops,
                                  unsigned char** loop_flags, uint32_t** borders) {
    p.ahead = arena.alloc<LayerAhead>(slots);
    p.layer_of_slot = arena.alloc<uint32_t>(slots);
    p.slot_of_layer = arena.alloc<uint32_t>(layers);
    *triangles = arena.alloc<uint32_t>(3 * 2 * points);
    *loops = arena.alloc<uint32_t>(2 * points);
    *loop_flags = arena.alloc<unsigned char>(2 * points);
    *borders = arena.alloc<uint32_t>(3 * (points / 4 + 4 * static_cast<size_t>(slots)));
    return !arena.failed;
}

// The border a layer of n points may keep for replay_chunk: its bottom loop holds a few
// times the square root of n points in a sound layer, with two or three triangles each.
// A thin layer's border can be most of its triangles: it is finished in order instead.
static inline size_t border_capacity(size_t n) { return n / 4 + 4; }

static inline bool may_stand_alone(const LayerQueue& q, uint32_t k) {
    size_t n = q.start[k + 1] - q.start[k];
    return n >= kMinLayerPoints || (k + 1 == q.planned && n >= 3);
}

// The job scratch bound: a run of layers needs the scratch of its largest, and scratch grows
// linearly with rounding, so jobs over n points in all need at most this.
static inline size_t job_scratch_bound(size_t points) {
    size_t whole = reconstruct_scratch_size(points, false), one = reconstruct_scratch_size(0, false);
    const size_t slack = 1024;  // the rounding of every allocation, with room to spare
    if (whole == 0 || one > (SIZE_MAX - whole) / kMaxJobs - slack) return 0;
    return whole + kMaxJobs * (one + slack);
}

// What replay_chunk needs of a job's layer (see LayerAhead), then, if it can replay them,
// its triangles in reader indices (`ids`).
static inline void keep_border(LayerAhead& a, const uint32_t* ids, size_t n, Arena& arena) {
    const unsigned char on_bottom = 1, has_triangle = 2;
    unsigned char* flags = arena.alloc<unsigned char>(n);
    a.replayable = flags != nullptr;
    a.border_count = a.interior_used = 0;
    if (!flags) return;
    std::memset(flags, 0, n);
    for (uint32_t i = 0; i < a.bottom_count; ++i) flags[a.bottom[i]] = on_bottom;
    for (size_t t = 0; t < a.triangle_count; ++t) {
        uint32_t* v = a.triangles + 3 * t;
        if ((flags[v[0]] | flags[v[1]] | flags[v[2]]) & on_bottom) {
            if (a.border_count < a.border_capacity)
                std::memcpy(a.border + 3 * a.border_count, v, 3 * sizeof(uint32_t));
            ++a.border_count;
        }
        for (size_t k = 0; k < 3; ++k) flags[v[k]] |= has_triangle;
    }
    for (size_t v = 0; v < n; ++v) a.interior_used += flags[v] == has_triangle;
    for (uint32_t i = 0; i < a.top_count; ++i) a.replayable = a.replayable && flags[a.top[i]] != 0;
    a.replayable = a.replayable && a.border_count <= a.border_capacity;
    if (!a.replayable) return;
    for (size_t k = 0; k < 3 * a.triangle_count; ++k) a.triangles[k] = ids[a.triangles[k]];
}

// Job `job`: triangulates the layers of slots first_slot[job] .. first_slot[job + 1] - 1 in
// the job's own scratch.
static inline void triangulate_job(const ParallelLayers& p, uint32_t job) {
    const LayerQueue& q = *p.queue;
    Arena arena = Arena::over(p.scratch[job], p.scratch_bytes[job]);
    for (uint32_t slot = p.first_slot[job]; slot < p.first_slot[job + 1]; ++slot) {
        LayerAhead& a = p.ahead[slot];
        const uint32_t k = p.layer_of_slot[slot];
        const size_t n = q.start[k + 1] - q.start[k];
        arena.rewind(0);
        LoadedLayer layer;
        if (!load_layer(*p.reader, *p.frame, q.ids + q.start[k], nullptr, n, q.bounds[k],
                        q.bounds[k + 1], arena, layer) ||
            !group_stands(n, q.bounds[k + 1] - q.bounds[k], layer.cyl.radius, k + 1 == q.planned))
            continue;
        a.fitted = layer.cyl;
        a.sectors = kCrescentLayers ? layer_sectors(layer) : 0;
        // The ends as add_group will see them if this layer is a group of its own.
        a.ends = (k == 0 ? kLowPole : 0) | (k + 1 == q.planned ? kHighPole : 0);
        find_closed_ends(layer, a.ends);
        TriangleSink sink = {a.triangles, 2 * n, 0, 0};
        LayerLoops loops = {a.bottom, 0, a.top, 0, a.bottom_flags, a.top_flags, 0, 0};
        a.status = triangulate_layer(*p.reader, layer, arena, sink, loops, a.counts);
        // An annulus through n points has at most 2n triangles; anything else is redone in order.
        if ((a.status != Status::ok && a.status != Status::not_columnar) || sink.count > sink.capacity)
            continue;
        a.cylinder = layer.cyl;
        a.triangle_count = sink.count;
        a.folds = sink.folds;
        a.bottom_count = loops.bottom_count;
        a.top_count = loops.top_count;
        if (a.status == Status::ok) keep_border(a, q.ids + q.start[k], n, arena);
        a.done = true;
    }
}

// Gives each layer that may stand alone a slot: its part of the results carved from the
// arena (false if they do not fit). `points` are the slots' points in all.
static inline bool assign_slots(ParallelLayers& p, uint32_t slots, size_t points, Arena& arena) {
    const LayerQueue& q = *p.queue;
    uint32_t* triangles = nullptr;
    uint32_t* loops = nullptr;
    unsigned char* loop_flags = nullptr;
    uint32_t* borders = nullptr;
    if (!allocate_ahead(p, slots, points, q.planned, arena, &triangles, &loops, &loop_flags,
                        &borders))
        return false;
    p.slots = slots;
    uint32_t slot = 0;
    size_t at = 0, border_at = 0;
    for (uint32_t k = 0; k < q.planned; ++k) {
        p.slot_of_layer[k] = kNoIndex;
        if (!may_stand_alone(q, k)) continue;
        const size_t n = q.start[k + 1] - q.start[k];
        LayerAhead& a = p.ahead[slot];
        a.done = false;
        a.triangles = triangles + 6 * at;
        a.bottom = loops + 2 * at;
        a.top = loops + 2 * at + n;
        a.bottom_flags = loop_flags + 2 * at;
        a.top_flags = loop_flags + 2 * at + n;
        a.border = borders + 3 * border_at;
        a.border_capacity = border_capacity(n);
        border_at += a.border_capacity;
        at += n;
        p.layer_of_slot[slot] = k;
        p.slot_of_layer[k] = slot++;
    }
    return true;
}

// Cuts the slots into jobs: runs of slots with about equal point counts. A slot goes to the
// share of the points its middle falls in, so equal layers get a job each (a threshold on
// a running count would put a layer slightly under the mean together with the next).
static inline void divide_jobs(ParallelLayers& p, size_t points) {
    const LayerQueue& q = *p.queue;
    const uint32_t most = p.slots < kMaxJobs ? p.slots : kMaxJobs;
    uint32_t job = 0;
    uint64_t share_of_job = 0, before = 0;
    p.first_slot[0] = 0;
    for (uint32_t s = 0; s < p.slots; ++s) {
        const uint32_t k = p.layer_of_slot[s];
        const uint64_t n = q.start[k + 1] - q.start[k];
        const uint64_t share = (before + n / 2) * most / points;
        if (s > 0 && share > share_of_job) {
            p.first_slot[++job] = s;
            share_of_job = share;
        }
        before += n;
    }
    p.job_count = job + 1;
    p.first_slot[p.job_count] = p.slots;
}

// Each job's scratch: that of its largest layer. False if they do not fit.
static inline bool allocate_job_scratch(ParallelLayers& p, Arena& arena) {
    const LayerQueue& q = *p.queue;
    for (uint32_t j = 0; j < p.job_count; ++j) {
        size_t largest = 0;
        for (uint32_t s = p.first_slot[j]; s < p.first_slot[j + 1]; ++s) {
            uint32_t k = p.layer_of_slot[s];
            size_t n = q.start[k + 1] - q.start[k];
            if (n > largest) largest = n;
        }
        p.scratch_bytes[j] = reconstruct_scratch_size(largest, false) + Arena::kAlign;
        p.scratch[j] = arena.alloc<unsigned char>(p.scratch_bytes[j]);
    }
    return !arena.failed;
}

// Plans the jobs over the queue, carves their results and scratch from the arena and runs
// them. Returns with p.ready false (and the arena as it was) when there is nothing to gain or
// no room: the groups are then triangulated in order. The results stay in the arena; the
// jobs' scratch is released.
static inline void triangulate_ahead(const Options& options, ParallelLayers& p, Arena& arena) {
    p.ready = false;
    const LayerQueue& q = *p.queue;
    uint32_t slots = 0;
    size_t points = 0;
    for (uint32_t k = 0; k < q.planned; ++k)
        if (may_stand_alone(q, k)) {
            ++slots;
            points += q.start[k + 1] - q.start[k];
        }
    if (slots < 2) return;
    const size_t mark = arena.mark();
    auto give_up = [&]() {
        arena.failed = false;
        arena.rewind(mark);
    };
    if (!assign_slots(p, slots, points, arena)) return give_up();
    const size_t results = arena.mark();
    divide_jobs(p, points);
    if (!allocate_job_scratch(p, arena)) return give_up();
    // A job the runner skips leaves its layers to their groups.
    run_jobs(options, p.job_count, false, [&p](uint32_t job) { triangulate_job(p, job); });
    arena.rewind(results);
    p.ready = true;
}

// Starts the jobs for reconstruct(); returns the layers they triangulated.
static inline size_t start_parallel_layers(const Options& options, const CloudReader& reader,
                                           const Frame& frame, const LayerQueue& queue,
                                           Arena& arena, ParallelLayers& parallel) {
    parallel.ready = false;
    if (!has_runner(options)) return 0;
    parallel.reader = &reader;
    parallel.frame = &frame;
    parallel.queue = &queue;
    triangulate_ahead(options, parallel, arena);
    size_t done = 0;
    for (uint32_t slot = 0; parallel.ready && slot < parallel.slots; ++slot)
        done += parallel.ahead[slot].done;
    return done;
}

// What the layers done ahead add to the workspace bound: their results, which stay, in
// `arena`; the jobs' scratch, which comes and goes before the groups' own, in *scratch.
static inline bool plan_parallel_workspace(size_t point_count, size_t layer_limit, Arena& arena,
                                           size_t* scratch) {
    ParallelLayers p;
    uint32_t* triangles = nullptr;
    uint32_t* loops = nullptr;
    unsigned char* loop_flags = nullptr;
    uint32_t* borders = nullptr;
    size_t slots = point_count / kMinLayerPoints + 1;
    allocate_ahead(p, static_cast<uint32_t>(slots), point_count, layer_limit, arena, &triangles,
                   &loops, &loop_flags, &borders);
    size_t jobs = job_scratch_bound(point_count);
    if (jobs > *scratch) *scratch = jobs;
    return jobs != 0;
}

#else  // STRATMESH_NO_PARALLEL_LAYERS: Options::run_jobs is ignored.

struct ParallelLayers {
    bool ready;
    const LayerAhead* ahead_of(uint32_t) const { return nullptr; }
};

static inline size_t start_parallel_layers(const Options&, const CloudReader&, const Frame&,
                                           const LayerQueue&, Arena&, ParallelLayers& parallel) {
    parallel.ready = false;
    return 0;
}

static inline bool plan_parallel_workspace(size_t, size_t, Arena&, size_t*) { return true; }

#endif  // STRATMESH_NO_PARALLEL_LAYERS

}  // namespace detail
}  // namespace stratmesh
