// Times the library's phases from its progress callback and, when asked to, shows the
// progress on a terminal line (throttled).
#ifndef STRATMESH_CLI_PROGRESS_H
#define STRATMESH_CLI_PROGRESS_H

#include "report_json.h"
#include "stratmesh.h"

#include <chrono>
#include <cstdint>
#include <cstdio>

namespace stratmesh_cli {

class ProgressMonitor {
public:
    // `show`: draw a progress line on `terminal` (a tty; the caller decides).
    ProgressMonitor(bool show, std::FILE* terminal) : show_(show), terminal_(terminal) {}

    // For Options::progress, with this monitor as the user pointer.
    static void callback(void* user, stratmesh::Phase phase, double fraction);

    void begin(); // just before reconstruct()
    void end();   // just after: closes the last phase and erases the progress line

    // Seconds spent in phase p (p < kTimedPhases), NaN if the library never reported it.
    double phase_seconds(size_t p) const { return seconds_[p]; }
    // Seconds between begin() and end().
    double total_seconds() const;

private:
    using Clock = std::chrono::steady_clock;

    void on_progress(stratmesh::Phase phase, double fraction);
    void close_phase(Clock::time_point now);
    void draw(stratmesh::Phase phase, double fraction, Clock::time_point now);

    bool show_;
    std::FILE* terminal_;
    bool drawn_ = false;
    Clock::time_point begin_, end_, phase_start_, last_draw_;
    static constexpr size_t kNoPhase = SIZE_MAX;
    size_t current_ = kNoPhase; // the phase running
    double seconds_[kTimedPhases] = {};
    bool seen_[kTimedPhases] = {};
};

} // namespace stratmesh_cli

#endif
