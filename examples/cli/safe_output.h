// Output that never destroys data: no two of the tool's files may be the same file, and
// every file is written to a temporary beside its destination and renamed onto it only
// once it is complete, so a failure or an interrupt leaves the old file (or none) behind,
// never a partial or clobbered one.
#ifndef STRATMESH_CLI_SAFE_OUTPUT_H
#define STRATMESH_CLI_SAFE_OUTPUT_H

#include <cstdio>
#include <string>
#include <vector>

namespace stratmesh_cli {

// The name that stands for standard input (as the input) or standard output (as -o).
inline const char kStandardStream[] = "-";

// A file the tool reads or writes, with how the command line names it ("the input", "-o",
// "--report").
struct NamedFile {
    std::string option;
    std::string path;
};

// False, with a message naming both options, if two of `files` are the same file: the same
// device and inode (through symlinks and hard links) for files that exist, the same
// directory and name for files that do not exist yet.
bool check_distinct_files(const std::vector<NamedFile>& files, std::string& error);

// A file written whole or not at all. open() creates a temporary in the destination's
// directory (the directory of a symlink's target), commit() flushes it to the disk and
// renames it onto the destination, keeping the permissions of a file it replaces. A
// destination that exists and is no regular file (a device such as /dev/null, a pipe) is
// written directly: renaming onto it would replace the device, and so is "-", which
// stands for standard output (left open). Destroyed uncommitted, it removes its temporary.
class AtomicFile {
public:
    AtomicFile() = default;
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    // False with "PATH: cannot create: ..." if the temporary cannot be created.
    bool open(const std::string& path, std::string& error);
    std::FILE* file() const { return file_; }
    // Completes the file. `failure` is the errno of a write that already failed (0 if
    // none). False with "PATH: cannot write: ..." (the temporary removed) if anything
    // failed.
    bool commit(int failure, std::string& error);
    // Removes the temporary (nothing if committed or never opened).
    void discard();
    // Starts writing what the temporary holds so far to the disk, without waiting for it,
    // so that commit()'s flush waits only for the rest: the disk works while the rest is
    // formatted. Only a hint (Linux); the one flush in commit() is what makes the file safe.
    void start_writeback();

private:
    std::FILE* file_ = nullptr;
    std::string path_;      // as given, for messages
    std::string target_;    // the file to replace: `path_` or its symlink's target
    std::string temporary_; // empty when writing directly
    int slot_ = -1;         // in the table the signal handler cleans
    bool standard_output_ = false; // `file_` is stdout, flushed but never closed
};

// A scratch file in the directory of `path`, already unlinked on systems that allow it (it
// disappears when closed, whatever happens to the process); null with a message if it
// cannot be created.
std::FILE* scratch_file_beside(const std::string& path, std::string& error);

// For the tool's main(): SIGINT, SIGTERM and SIGHUP remove the open temporaries before the
// tool dies of the signal, and SIGXFSZ is ignored, so a write beyond a file size limit
// (ulimit -f) fails as a write error (EFBIG) instead of killing the tool mid-file.
void install_output_signal_handlers();

} // namespace stratmesh_cli

#endif
