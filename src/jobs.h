// >>jobs =================================================================================
// The caller's callbacks: progress, and passes split into jobs for the runner.

namespace stratmesh {
namespace detail {

inline void notify(const Options& options, Phase phase, double fraction) {
    if (options.progress) options.progress(options.progress_user, phase, fraction);
}

// ---- passes over all points as jobs ----
//
// With Options::run_jobs, a pass over all points that gives the same bits in any order
// (grouping the points by layer) is cut into kPassRuns runs of consecutive points, run as
// jobs. As for the layers' jobs (see JobRunner), a run the runner skips is done in order
// afterwards, and a run done again changes nothing.
const uint32_t kPassRuns = 16;

// The first point of run k of `count` points.
inline size_t run_start(size_t count, uint32_t k) {
    return static_cast<size_t>(static_cast<uint64_t>(count) * k / kPassRuns);
}

template <class Pass> struct PassJobs {
    Pass* pass;
    bool done[kPassRuns];
};

template <class Pass> inline void run_pass_job(void* context, uint32_t index) {
    PassJobs<Pass>& jobs = *static_cast<PassJobs<Pass>*>(context);
    if (index >= kPassRuns) return;  // a runner's mistake: no run of ours
    jobs.pass->run(index);
    jobs.done[index] = true;
}

template <class Pass> inline void run_pass(const Options& options, Pass& pass) {
    PassJobs<Pass> jobs = {&pass, {}};
    options.run_jobs(options.jobs_user, kPassRuns, run_pass_job<Pass>, &jobs);
    for (uint32_t k = 0; k < kPassRuns; ++k)
        if (!jobs.done[k]) pass.run(k);
}

}  // namespace detail
}  // namespace stratmesh
