// Output that never destroys data: no output may be the input or another output, and the
// outputs are written to temporaries beside their destinations and renamed onto them
// together, only once every one of them is complete, so a failure or an interrupt leaves
// every old file (or none) behind, never a partial or clobbered one.
#ifndef STRATMESH_CLI_SAFE_OUTPUT_H
#define STRATMESH_CLI_SAFE_OUTPUT_H

#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

namespace stratmesh_cli {

// The name that stands for standard input (as the input) or standard output (as -o).
inline const char kStandardStream[] = "-";

// A file the tool reads or writes, with how the command line names it ("the input", "-o",
// "--report"). "-" is standard input for the input, standard output for an output.
struct NamedFile {
    std::string option;
    std::string path;
    bool input = false;
};

// False, with a message naming both options, if two of `files` are the same file: the same
// device and inode (through symlinks and hard links; for "-", those of the standard stream
// it stands for, so that `- -o in.xyz < in.xyz` is caught) for files that exist, the same
// directory and name for files that do not exist yet. The input may share a character
// device (a terminal, /dev/null) with an output: a device holds no data to destroy.
bool check_distinct_files(const std::vector<NamedFile>& files, std::string& error);

// A file written whole or not at all. open() creates a temporary in the destination's
// directory (the directory of a symlink's target), ".NAME.stratmesh-XXXXXX", or
// ".stratmesh-XXXXXX" where NAME is too long for that; complete() flushes it to the disk and
// closes it; commit_files() renames it onto the destination, keeping the permissions of a
// file it replaces. A destination that exists and is no regular file (a device such as
// /dev/null, a pipe) is written directly: renaming onto it would replace the device, and so
// is "-", which stands for standard output (left open). Destroyed uncommitted, it removes
// its temporary.
class AtomicFile {
public:
    AtomicFile() = default;
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    // False with "PATH: cannot create: ..." if the temporary cannot be created.
    bool open(const std::string& path, std::string& error);
    std::FILE* file() const { return file_; }
    // The destination as given ("-" for standard output).
    const std::string& path() const { return path_; }
    // Whether the data goes straight to the destination (standard output, a device, a
    // pipe): what is written there cannot be taken back.
    bool direct() const { return temporary_.empty(); }
    // Ends the writing: flushes what is written and, for a temporary, syncs it to the disk
    // and closes it, so that only the rename is left. `failure` is the errno of a write
    // that already failed (0 if none). False with write_error()'s message (the temporary
    // removed) if anything failed.
    bool complete(int failure, std::string& error);
    // "PATH: cannot write: ...", or for standard output whose reader has gone (EPIPE),
    // "standard output closed early (broken pipe): ...".
    std::string write_error(int failure) const;
    // Removes the temporary (nothing if committed or never opened): the destination stays
    // as it was.
    void discard();
    // Starts writing what the temporary holds so far to the disk, without waiting for it,
    // so that complete()'s flush waits only for the rest: the disk works while the rest is
    // formatted. Only a hint (Linux); the one flush in complete() is what makes the file
    // safe.
    void start_writeback();

private:
    friend bool commit_files(std::initializer_list<AtomicFile*> files, std::string& error);
    bool rename_into_place(std::string& error);

    std::FILE* file_ = nullptr;
    std::string path_;      // as given, for messages
    std::string target_;    // the file to replace: `path_` or its symlink's target
    std::string temporary_; // empty when writing directly
    int slot_ = -1;         // in the table the signal handler cleans
    bool standard_output_ = false; // `file_` is stdout, flushed but never closed
    bool completed_ = false;       // complete() succeeded: only the rename is left
    bool failed_ = false;          // complete() failed: the set is not to be published
};

// Publishes the outputs of one run together, all or none. If every file of `files` that is
// open was completed, renames the temporaries onto their destinations, in the order given,
// with SIGINT, SIGTERM and SIGHUP held off until the last rename. If one failed or is still
// being written, replaces nothing. Either way removes every temporary left. Direct outputs
// have nothing left to do then: their data went out as they were written and complete()
// flushed it; so completing every file, direct ones included, before committing any makes
// a failure anywhere leave every destination as it was. False with a message if nothing
// was replaced, or if a rename failed (only if the directory changes under the tool): the
// message then names the files renamed before it. Files discarded or never opened are
// skipped.
bool commit_files(std::initializer_list<AtomicFile*> files, std::string& error);

// A scratch file in the directory of `path`, already unlinked on systems that allow it (it
// disappears when closed, whatever happens to the process); null with a message if it
// cannot be created.
std::FILE* scratch_file_beside(const std::string& path, std::string& error);

// For the tool's main(): SIGINT, SIGTERM and SIGHUP remove the open temporaries before the
// tool dies of the signal; SIGXFSZ is ignored, so a write beyond a file size limit
// (ulimit -f) fails as a write error (EFBIG) instead of killing the tool mid-file, and so
// is SIGPIPE, so that a reader that closes the pipe early (| head) makes the write fail
// (EPIPE), which the tool reports, instead of killing it without a word.
void install_output_signal_handlers();

} // namespace stratmesh_cli

#endif
