// A stratmesh::JobRunner on std::thread, for Options::run_jobs (the tool's --threads and
// the benchmark's threaded cases). Header-only so the benchmark can use it without the
// tool's library.
#ifndef STRATMESH_CLI_THREAD_JOBS_H
#define STRATMESH_CLI_THREAD_JOBS_H

#include "stratmesh.h"

#include <atomic>
#include <cstdint>
#include <system_error>
#include <thread>
#include <vector>

namespace stratmesh_cli {

// Runs each batch on up to `threads` threads: the caller's thread plus min(threads, count)
// - 1 started for the batch, each taking the next index from a shared counter until none
// is left. Starting threads per batch costs tens of microseconds; a batch is whole layers.
struct ThreadJobs {
    uint32_t threads = 1;

    static void run(void* user, uint32_t count, stratmesh::JobFunction job, void* context) {
        const ThreadJobs& self = *static_cast<const ThreadJobs*>(user);
        std::atomic<uint32_t> next{0};
        auto work = [&] {
            for (uint32_t i = next++; i < count; i = next++) job(context, i);
        };
        uint32_t helpers = (self.threads < count ? self.threads : count);
        std::vector<std::thread> started;
        started.reserve(helpers);
        for (uint32_t t = 1; t < helpers; ++t) {
            // A thread the system cannot start (out of memory or of threads) leaves its
            // share to the others; the caller's thread alone does them all.
            try {
                started.emplace_back(work);
            } catch (const std::system_error&) {
                break;
            }
        }
        work();
        for (std::thread& thread : started) thread.join();
    }

    // Sets options.run_jobs to this runner when it has more than one thread; one thread
    // leaves the library's own in-order loop.
    void attach(stratmesh::Options& options) {
        if (threads <= 1) return;
        options.run_jobs = &ThreadJobs::run;
        options.jobs_user = this;
    }
};

} // namespace stratmesh_cli

#endif
