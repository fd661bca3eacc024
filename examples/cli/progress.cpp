#include "progress.h"

#include <limits>

namespace stratmesh_cli {

namespace {

double seconds_between(std::chrono::steady_clock::time_point a,
                       std::chrono::steady_clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
}

} // namespace

void ProgressMonitor::callback(void* user, stratmesh::Phase phase, double fraction) {
    static_cast<ProgressMonitor*>(user)->on_progress(phase, fraction);
}

void ProgressMonitor::begin() {
    begin_ = phase_start_ = Clock::now();
    current_ = kNoPhase;
}

void ProgressMonitor::end() {
    end_ = Clock::now();
    close_phase(end_);
    for (size_t p = 0; p < kTimedPhases; ++p)
        if (!seen_[p]) seconds_[p] = std::numeric_limits<double>::quiet_NaN();
    if (drawn_) std::fprintf(terminal_, "\r%60s\r", "");
}

double ProgressMonitor::total_seconds() const { return seconds_between(begin_, end_); }

void ProgressMonitor::close_phase(Clock::time_point now) {
    if (current_ < kTimedPhases) seconds_[current_] += seconds_between(phase_start_, now);
    current_ = kNoPhase;
}

void ProgressMonitor::on_progress(stratmesh::Phase phase, double fraction) {
    Clock::time_point now = Clock::now();
    size_t p = static_cast<size_t>(phase);
    bool new_phase = p != current_;
    if (new_phase) {
        close_phase(now);
        current_ = p; // phases this tool does not know are not timed
        if (p < kTimedPhases) seen_[p] = true;
        phase_start_ = now;
    }
    const double kRedrawSeconds = 0.1;
    if (show_ && (new_phase || seconds_between(last_draw_, now) >= kRedrawSeconds))
        draw(phase, fraction, now);
}

void ProgressMonitor::draw(stratmesh::Phase phase, double fraction, Clock::time_point now) {
    const char* name = phase_name(phase);
    double percent = fraction >= 0 && fraction <= 1 ? 100 * fraction : 0;
    std::fprintf(terminal_, "\rstratmesh: %-12s %3.0f%%  ", name ? name : "working", percent);
    std::fflush(terminal_);
    drawn_ = true;
    last_draw_ = now;
}

} // namespace stratmesh_cli
