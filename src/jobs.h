// >>jobs =================================================================================
// The caller's callbacks: progress, and batches of jobs for the runner.

namespace stratmesh {
namespace detail {

static inline void notify(const Options& options, Phase phase, double fraction) {
    if (options.progress) options.progress(options.progress_user, phase, fraction);
}

// ---- jobs on the caller's runner ----
//
// Every batch of jobs reaches Options::run_jobs through run_jobs below, which holds the
// runner to its contract (see JobRunner): an index outside the batch is ignored, a job run
// again does nothing, and a job the runner skipped is done afterwards as the batch says.

// Whether work is cut into jobs: a runner given, in a build that has them.
static inline bool has_runner(const Options& options) {
    return kParallelLayers && options.run_jobs != nullptr;
}

template <class Job> struct JobBatch {
    const Job* job;
    uint32_t count;
    bool done[kMaxJobs];
};

template <class Job> static inline void run_batch_job(void* context, uint32_t index) {
    JobBatch<Job>& batch = *static_cast<JobBatch<Job>*>(context);
    if (index >= batch.count || batch.done[index]) return;  // no job of ours, or done already
    (*batch.job)(index);
    batch.done[index] = true;
}

// Runs job(k) for k in [0, count), count <= kMaxJobs, on the caller's runner where there is
// one. With `redo_skipped`, each job the runner skipped, or every job without a runner, is
// then run here in order; else it is left undone (the layers not done ahead are
// triangulated by their groups).
template <class Job>
static inline void run_jobs(const Options& options, uint32_t count, bool redo_skipped,
                            const Job& job) {
    JobBatch<Job> batch = {&job, count, {}};
    if (has_runner(options)) options.run_jobs(options.jobs_user, count, run_batch_job<Job>, &batch);
    for (uint32_t k = 0; redo_skipped && k < count; ++k)
        if (!batch.done[k]) job(k);
}

// ---- passes over all points as jobs ----
//
// With a runner, a pass over all points that gives the same bits in any order (grouping
// the points by layer) is cut into kPassRuns runs of consecutive points, run as jobs.
const uint32_t kPassRuns = 16;
static_assert(kPassRuns <= kMaxJobs, "a pass's runs are one batch of jobs");

// The first point of run k of `count` points.
static inline size_t run_start(size_t count, uint32_t k) {
    return static_cast<size_t>(static_cast<uint64_t>(count) * k / kPassRuns);
}

// Runs pass.run(k) for every run k: as jobs with a runner, else in order.
template <class Pass> static inline void run_pass(const Options& options, Pass& pass) {
    run_jobs(options, kPassRuns, true, [&pass](uint32_t k) { pass.run(k); });
}

}  // namespace detail
}  // namespace stratmesh
