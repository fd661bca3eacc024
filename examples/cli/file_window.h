// Reading a file front to back through a buffer of a few blocks, for --stream: the
// readers see the file one window at a time, never all of it.
#ifndef STRATMESH_CLI_FILE_WINDOW_H
#define STRATMESH_CLI_FILE_WINDOW_H

#include "text_scan.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace stratmesh_cli {

class FileWindow {
public:
    // Takes ownership of `file` (closed by the destructor).
    explicit FileWindow(std::FILE* file) : file_(file) {}
    ~FileWindow();
    FileWindow(const FileWindow&) = delete;
    FileWindow& operator=(const FileWindow&) = delete;

    // Up to `bytes` bytes from the current position, fewer only at the end of the file;
    // not consumed. Valid until the next call.
    std::string_view peek(size_t bytes);
    // Consumes `bytes` bytes (at most what the last peek returned).
    void skip(size_t bytes) { pos_ += bytes; }
    // Consumes `bytes` bytes however many there are; false if the file ends first.
    bool discard(uint64_t bytes);
    // The next whole lines (up to and including a '\n'; at the end of the file, the rest),
    // about a block's worth; false when nothing is left. Valid until the next call.
    bool next_lines(std::string_view& lines);
    // The number of the first line next_lines() returned last (counting from first_line).
    size_t lines_first_line() const { return lines_first_line_; }
    void set_first_line(size_t line) { next_line_ = line; }
    // Offset from the start of the file of the next byte not consumed.
    uint64_t offset() const { return consumed_ + pos_; }
    // The read error, if reading failed (an empty string otherwise).
    std::string failure() const;

private:
    // Moves the unconsumed bytes to the front and reads one more block after them; false
    // at the end of the file or on a read error.
    bool fill();

    static constexpr size_t kBlock = 1 << 20;
    std::FILE* file_;
    std::vector<char> buffer_;
    size_t pos_ = 0, end_ = 0;
    uint64_t consumed_ = 0; // bytes before buffer_[0]
    size_t next_line_ = 1, lines_first_line_ = 1;
    int failure_ = 0;
};

// The lines of a file read through a FileWindow, numbered as in the file: a LineCursor over
// each run of whole lines. A run with a carriage return that ends no CRLF pair
// (check_line_ends) ends them, and failure() says so.
class WindowLines {
public:
    explicit WindowLines(FileWindow& file) : file_(file), cursor_(std::string_view()) {}

    // The next line, without its terminator; false at the end of the file or on a failure.
    bool next(std::string_view& line);
    // The number of the line last returned (or, before any, of the first line to come).
    size_t line_number() const {
        return cursor_.line_number() == 0 ? file_.lines_first_line()
                                          : file_.lines_first_line() + cursor_.line_number() - 1;
    }
    // Why next() returned false before the end of the file: a read error or a lone carriage
    // return (empty otherwise).
    std::string failure() const { return failure_.empty() ? file_.failure() : failure_; }

private:
    FileWindow& file_;
    LineCursor cursor_;
    std::string failure_;
};

} // namespace stratmesh_cli

#endif
