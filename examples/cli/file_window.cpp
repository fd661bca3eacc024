#include "file_window.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace stratmesh_cli {

FileWindow::~FileWindow() { std::fclose(file_); }

bool FileWindow::fill() {
    if (failure_ != 0) return false;
    std::copy(buffer_.begin() + static_cast<std::ptrdiff_t>(pos_),
              buffer_.begin() + static_cast<std::ptrdiff_t>(end_), buffer_.begin());
    consumed_ += pos_;
    end_ -= pos_;
    pos_ = 0;
    if (buffer_.size() < end_ + kBlock) buffer_.resize(end_ + kBlock);
    size_t got = std::fread(buffer_.data() + end_, 1, kBlock, file_);
    end_ += got;
    if (got == 0 && std::ferror(file_)) failure_ = errno != 0 ? errno : EIO;
    return got > 0;
}

std::string_view FileWindow::peek(size_t bytes) {
    while (end_ - pos_ < bytes && fill()) {
    }
    return std::string_view(buffer_.data() + pos_, std::min(bytes, end_ - pos_));
}

bool FileWindow::discard(uint64_t bytes) {
    while (bytes > 0) {
        size_t step = static_cast<size_t>(std::min<uint64_t>(bytes, kBlock));
        size_t got = peek(step).size();
        skip(got);
        bytes -= got;
        if (got < step) return false;
    }
    return true;
}

bool FileWindow::next_lines(std::string_view& lines) {
    size_t last = std::string_view::npos;
    for (;;) {
        lines = std::string_view(buffer_.data() + pos_, end_ - pos_);
        last = lines.rfind('\n');
        if (last != std::string_view::npos || !fill()) break;
    }
    if (last == std::string_view::npos)
        lines = std::string_view(buffer_.data() + pos_, end_ - pos_);
    if (lines.empty()) return false;
    if (last != std::string_view::npos) lines = lines.substr(0, last + 1);
    pos_ += lines.size();
    lines_first_line_ = next_line_;
    next_line_ += static_cast<size_t>(std::count(lines.begin(), lines.end(), '\n'));
    return true;
}

bool WindowLines::next(std::string_view& line) {
    std::string_view block;
    while (!cursor_.next(line)) {
        if (!failure_.empty() || !file_.next_lines(block)) return false;
        if (!check_line_ends(block, file_.lines_first_line(), failure_)) return false;
        cursor_ = LineCursor(block);
    }
    return true;
}

std::string FileWindow::failure() const {
    return failure_ != 0 ? "cannot read: " + std::string(std::strerror(failure_)) : "";
}

} // namespace stratmesh_cli
