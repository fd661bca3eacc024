#include "safe_output.h"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>

#ifndef _WIN32
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#endif
#ifdef __linux__
#include <fcntl.h>
#endif

namespace stratmesh_cli {

namespace fs = std::filesystem;

namespace {

// ---- the temporaries a signal handler removes --------------------------------------------
// Plain arrays: the handler may only touch memory that is complete whenever it runs.

constexpr int kSlots = 8;
constexpr size_t kPathBytes = 4096;
char g_temporary[kSlots][kPathBytes];
volatile std::sig_atomic_t g_in_use[kSlots];

int remember_temporary(const std::string& path) {
    if (path.size() >= kPathBytes) return -1;
    for (int s = 0; s < kSlots; ++s) {
        if (g_in_use[s]) continue;
        std::memcpy(g_temporary[s], path.c_str(), path.size() + 1);
        g_in_use[s] = 1;
        return s;
    }
    return -1;
}

void forget_temporary(int& slot) {
    if (slot >= 0) g_in_use[slot] = 0;
    slot = -1;
}

extern "C" void remove_temporaries_and_die(int signal_number) {
    for (int s = 0; s < kSlots; ++s)
#ifndef _WIN32
        if (g_in_use[s]) unlink(g_temporary[s]);
#else
        if (g_in_use[s]) std::remove(g_temporary[s]);
#endif
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
}

// Holds off the signals that end the tool while it lives, so that what it guards runs
// whole; a signal that came meanwhile is delivered when it ends.
class SignalsHeld {
public:
#ifndef _WIN32
    SignalsHeld() {
        sigset_t ending;
        sigemptyset(&ending);
        for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&ending, signal_number);
        sigprocmask(SIG_BLOCK, &ending, &before_);
    }
    ~SignalsHeld() { sigprocmask(SIG_SETMASK, &before_, nullptr); }

private:
    sigset_t before_;
#endif
};

// ---- names -------------------------------------------------------------------------------

// The temporaries' name where the target's own is too long to be part of it.
const char kShortPrefix[] = ".stratmesh-";

// Six letters that differ between calls and between processes; a clash only costs a retry
// (the temporary is created exclusively).
std::string unique_suffix() {
    static uint64_t counter = 0;
    uint64_t x = static_cast<uint64_t>(
                     std::chrono::steady_clock::now().time_since_epoch().count()) ^
                 (++counter * 0x9E3779B97F4A7C15ull) ^
                 static_cast<uint64_t>(reinterpret_cast<uintptr_t>(&counter));
#ifndef _WIN32
    x ^= static_cast<uint64_t>(getpid()) << 32;
#endif
    std::string suffix;
    for (int k = 0; k < 6; ++k) {
        x ^= x >> 29;
        x *= 0xBF58476D1CE4E5B9ull;
        x ^= x >> 32;
        suffix += "abcdefghijklmnopqrstuvwxyz0123456789"[x % 36];
    }
    return suffix;
}

// Creates a new file, exclusively, in the directory of `target`: a hidden name that no
// reader takes for the finished file, ".NAME.stratmesh-XXXXXX" after the target's NAME, or
// ".stratmesh-XXXXXX" where that is too long for the file system (NAME is then longer than
// it), so that a temporary fits wherever the target does. The name goes into `temporary`
// and into the signal handler's table (`slot`) before the file exists.
std::FILE* create_beside(const std::string& target, const char* mode, std::string& temporary,
                         int& slot) {
    const fs::path where(target);
    fs::path directory = where.parent_path();
    if (directory.empty()) directory = ".";
    std::string prefix = "." + where.filename().string() + ".stratmesh-";
    for (int attempt = 0; attempt < 100; ++attempt) {
        temporary = (directory / (prefix + unique_suffix())).string();
        slot = remember_temporary(temporary);
        std::FILE* file = std::fopen(temporary.c_str(), mode);
        if (file) return file;
        const int failure = errno;
        forget_temporary(slot);
        if (failure == ENAMETOOLONG && prefix != kShortPrefix) {
            prefix = kShortPrefix;
            continue;
        }
        if (failure != EEXIST) {
            errno = failure;
            return nullptr;
        }
    }
    errno = EEXIST;
    return nullptr;
}

#ifndef _WIN32
// The file behind a name, through symlinks; for "-", the standard stream it stands for.
// False if there is none.
bool identify(const NamedFile& file, struct stat& status) {
    if (file.path != kStandardStream) return stat(file.path.c_str(), &status) == 0;
    return fstat(file.input ? STDIN_FILENO : STDOUT_FILENO, &status) == 0;
}
#endif

// Whether two of the tool's names stand for one file, or would once created.
bool same_file(const NamedFile& a, const NamedFile& b) {
#ifndef _WIN32
    struct stat sa, sb;
    const bool a_exists = identify(a, sa), b_exists = identify(b, sb);
    // A character device (a terminal, /dev/null) holds no data: the input may come from
    // the one an output goes to.
    if (a_exists && b_exists)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino &&
               !(a.input != b.input && S_ISCHR(sa.st_mode));
#else
    std::error_code ea, eb, e;
    const bool a_exists = a.path != kStandardStream && fs::exists(a.path, ea);
    const bool b_exists = b.path != kStandardStream && fs::exists(b.path, eb);
    if (a_exists && b_exists) return fs::equivalent(a.path, b.path, e) && !e;
#endif
    if (a_exists || b_exists || a.path == kStandardStream || b.path == kStandardStream)
        return false;
    const fs::path pa(a.path), pb(b.path);
    if (pa.filename() != pb.filename()) return false;
    fs::path da = pa.parent_path(), db = pb.parent_path();
    if (da.empty()) da = ".";
    if (db.empty()) db = ".";
    std::error_code same;
    return fs::equivalent(da, db, same) && !same;
}

// "-o 'm.ply'", "the input (standard input)".
std::string describe(const NamedFile& file) {
    if (file.path != kStandardStream) return file.option + " '" + file.path + "'";
    return file.option + (file.input ? " (standard input)" : " (standard output)");
}

} // namespace

bool check_distinct_files(const std::vector<NamedFile>& files, std::string& error) {
    for (size_t j = 1; j < files.size(); ++j) {
        for (size_t i = 0; i < j; ++i) {
            if (files[i].path.empty() || files[j].path.empty() || !same_file(files[i], files[j]))
                continue;
            error = describe(files[j]) + " is the same file as " + describe(files[i]) +
                    ": give " + files[j].option + " another path";
            return false;
        }
    }
    return true;
}

AtomicFile::~AtomicFile() { discard(); }

bool AtomicFile::open(const std::string& path, std::string& error) {
    discard();
    standard_output_ = false;
    path_ = target_ = path;
    std::error_code e;
    const fs::file_status status = fs::status(path, e);
    int failure = 0;
    if (path == kStandardStream) {
        file_ = stdout;
        standard_output_ = true;
    } else if (fs::is_directory(status)) {
        failure = EISDIR;
    } else if (fs::exists(status) && !fs::is_regular_file(status)) {
        file_ = std::fopen(path.c_str(), "wb");
        if (!file_) failure = errno;
    } else {
        if (fs::exists(status)) {
            const fs::path resolved = fs::canonical(path, e);
            if (!e) target_ = resolved.string();
#ifndef _WIN32
            // Renaming would replace a file that may not be written.
            if (access(target_.c_str(), W_OK) != 0) failure = errno;
#endif
        }
        if (failure == 0) file_ = create_beside(target_, "wbx", temporary_, slot_);
        if (!file_ && failure == 0) failure = errno;
    }
    if (file_) return true;
    error = path + ": cannot create: " + std::strerror(failure);
    temporary_.clear();
    return false;
}

bool AtomicFile::complete(int failure, std::string& error) {
    if (!file_) {
        error = path_ + ": cannot write: the file is not open";
        return false;
    }
    if (std::fflush(file_) != 0 && failure == 0) failure = errno;
#ifndef _WIN32
    // On the disk before the rename: after a power cut the name holds the old file or the
    // new one, never an empty one (some file systems commit a rename before the data).
    if (!temporary_.empty() && failure == 0 && fsync(fileno(file_)) != 0) failure = errno;
#endif
    if (!standard_output_ && std::fclose(file_) != 0 && failure == 0) failure = errno;
    file_ = nullptr;
    if (failure == 0 && !temporary_.empty()) {
        std::error_code e;
        const fs::file_status old = fs::status(target_, e);
        if (fs::is_regular_file(old)) fs::permissions(temporary_, old.permissions(), e);
    }
    completed_ = failure == 0;
    if (completed_) return true;
    error = write_error(failure);
    discard();
    failed_ = true;
    return false;
}

std::string AtomicFile::write_error(int failure) const {
    if (standard_output_ && failure == EPIPE)
        return "standard output closed early (broken pipe): its reader stopped before the "
               "end, and what it read is incomplete";
    return path_ + ": cannot write: " + std::strerror(failure);
}

bool AtomicFile::rename_into_place(std::string& error) {
    std::error_code e;
    fs::rename(temporary_, target_, e);
    if (e) {
        error = write_error(e.value());
        return false;
    }
    temporary_.clear();
    forget_temporary(slot_);
    return true;
}

bool commit_files(std::initializer_list<AtomicFile*> files, std::string& error) {
    bool ok = true;
    for (const AtomicFile* file : files) {
        if (ok && (file->failed_ || file->file_)) {
            error = file->path_ + ": not written whole: no output is replaced";
            ok = false;
        }
    }
    std::string replaced; // the destinations renamed onto so far
    {
        // Only renames are left: an interrupt between two would replace some destinations
        // and not the others.
        SignalsHeld held;
        for (AtomicFile* file : files) {
            if (!ok || !file->completed_ || file->direct()) continue;
            ok = file->rename_into_place(error);
            if (ok) replaced += (replaced.empty() ? "" : ", ") + file->path_;
            else if (!replaced.empty()) error += " (" + replaced + " already replaced)";
        }
    }
    for (AtomicFile* file : files) file->discard();
    return ok;
}

void AtomicFile::discard() {
    if (file_ && !standard_output_) std::fclose(file_);
    file_ = nullptr;
    completed_ = failed_ = false;
    if (!temporary_.empty()) std::remove(temporary_.c_str());
    temporary_.clear();
    forget_temporary(slot_);
}

void AtomicFile::start_writeback() {
#ifdef __linux__
    // What stdio still buffers goes out later (its errors are complete()'s to report). The
    // whole file's range: pages already written or on their way to the disk are skipped.
    if (file_ && !temporary_.empty()) sync_file_range(fileno(file_), 0, 0, SYNC_FILE_RANGE_WRITE);
#endif
}

std::FILE* scratch_file_beside(const std::string& path, std::string& error) {
    std::error_code e;
    const fs::file_status status = fs::status(path, e);
    std::FILE* file = nullptr;
#ifndef _WIN32
    if (path != kStandardStream && (!fs::exists(status) || fs::is_regular_file(status))) {
        // Beside the destination: on its file system, not on a /tmp that may be smaller.
        std::string temporary;
        int slot = -1;
        const fs::path resolved = fs::exists(status) ? fs::canonical(path, e) : fs::path(path);
        file = create_beside(e ? path : resolved.string(), "wb+x", temporary, slot);
        if (file) unlink(temporary.c_str());
        forget_temporary(slot);
    } else
#endif
    {
        // A device, a pipe or standard output has no directory of its own to write in.
        file = std::tmpfile();
    }
    if (!file) error = path + ": cannot create a temporary file beside it: " + std::strerror(errno);
    return file;
}

void install_output_signal_handlers() {
    for (int signal_number : {SIGINT, SIGTERM})
        std::signal(signal_number, remove_temporaries_and_die);
#ifndef _WIN32
    std::signal(SIGHUP, remove_temporaries_and_die);
    std::signal(SIGXFSZ, SIG_IGN);
    std::signal(SIGPIPE, SIG_IGN);
#endif
}

} // namespace stratmesh_cli
