#include "cloud_io.h"

#include "cloud_readers.h"
#include "path_util.h"
#include "safe_output.h"
#include "text_scan.h"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string_view>

namespace stratmesh_cli {

namespace {

bool starts_with(std::string_view text, std::string_view prefix) {
    return text.substr(0, prefix.size()) == prefix;
}

// OBJ statements other than "v" that may come before the first vertex.
bool is_obj_keyword(std::string_view word) {
    for (const char* k : {"vn", "vt", "vp", "f", "l", "p", "o", "g", "s", "mtllib", "usemtl"})
        if (word == k) return true;
    return false;
}

// Looks at the first lines only: enough for any header, cheap for a huge file.
CloudFormat detect_text_format(std::string_view text) {
    const size_t kLinesToLook = 200;
    LineCursor lines(text);
    std::string_view line, word;
    bool first_content = true;
    while (lines.next(line) && lines.line_number() <= kLinesToLook) {
        std::string_view rest = strip_comment(line, false);
        if (!next_field(rest, word, false)) continue;
        if (first_content && is_off_keyword(word)) return CloudFormat::off;
        first_content = false;
        if (word == "v") return CloudFormat::obj;
        double number = 0;
        if (!is_obj_keyword(word) && parse_number(word, number)) return CloudFormat::xyz;
    }
    return CloudFormat::xyz;
}

bool dispatch(std::string_view data, CloudFormat format, std::vector<double>& xyz,
              std::string& error, std::string& encoding, uint64_t& faces,
              PointAttributes* attributes) {
    encoding = "text";
    faces = 0;
    const std::string_view text = skip_byte_order_mark(data);
    switch (format) {
    case CloudFormat::ply: return read_ply(data, xyz, error, encoding, faces, attributes);
    case CloudFormat::off: return read_off(text, xyz, error, faces);
    case CloudFormat::obj: return read_obj(text, xyz, error, faces);
    case CloudFormat::xyz:
    case CloudFormat::automatic: break;
    }
    return read_xyz(text, xyz, error);
}

// The file's size as the file system reports it, to allocate the buffer once; 0 if
// unknown. Only a hint: reading stops at the real end whatever it says.
size_t size_hint(const std::string& path) {
    if (path == kStandardStream) return 0;
    std::error_code error;
    uintmax_t size = std::filesystem::file_size(path, error);
    return error || size > SIZE_MAX / 2 ? 0 : static_cast<size_t>(size);
}

} // namespace

int PointAttributes::find(const std::string& name) const {
    for (size_t k = 0; k < properties.size(); ++k)
        if (properties[k].name == name) return static_cast<int>(k);
    return -1;
}

double PointAttributes::value(size_t point, size_t property) const {
    const Property& p = properties[property];
    const unsigned char* at = bytes.data() + point * record_bytes + p.offset;
    uint64_t bits = 0;
    for (size_t i = 0; i < p.size; ++i) bits |= uint64_t{at[i]} << (8 * i);
    if (!p.integral) {
        if (p.size == 4) {
            const uint32_t narrow = static_cast<uint32_t>(bits);
            float f = 0;
            std::memcpy(&f, &narrow, sizeof f);
            return static_cast<double>(f);
        }
        double d = 0;
        std::memcpy(&d, &bits, sizeof d);
        return d;
    }
    const unsigned shift = static_cast<unsigned>(64 - 8 * p.size);
    if (p.is_signed) // sign-extended from its top bit
        return static_cast<double>(static_cast<int64_t>(bits << shift) >> shift);
    return static_cast<double>(bits);
}

const char* cloud_format_name(CloudFormat format) {
    switch (format) {
    case CloudFormat::ply: return "PLY";
    case CloudFormat::xyz: return "XYZ";
    case CloudFormat::off: return "OFF";
    case CloudFormat::obj: return "OBJ";
    case CloudFormat::automatic: break;
    }
    return "automatic";
}

CloudFormat cloud_format_from_extension(const std::string& path) {
    std::string ext = lowercase_extension(path);
    if (ext == "ply") return CloudFormat::ply;
    if (ext == "off") return CloudFormat::off;
    if (ext == "obj") return CloudFormat::obj;
    for (const char* text : {"xyz", "pts", "txt", "csv", "asc"})
        if (ext == text) return CloudFormat::xyz;
    return CloudFormat::automatic;
}

CloudFormat detect_cloud_format(const char* data, size_t size) {
    std::string_view text = skip_byte_order_mark(std::string_view(data, data ? size : 0));
    // "ply\r" alone too: the PLY reader refuses CR-only line ends with a message that says so.
    if (starts_with(text, "ply\n") || starts_with(text, "ply\r")) return CloudFormat::ply;
    return detect_text_format(text);
}

bool read_cloud_from_memory(const char* data, size_t size, CloudFormat format,
                            std::vector<double>& xyz, std::string& error, CloudInfo* info) {
    if (!data || size == 0) {
        error = "the file is empty";
        return false;
    }
    if (format == CloudFormat::automatic) format = detect_cloud_format(data, size);
    std::string encoding;
    uint64_t faces = 0;
    PointAttributes* attributes = info && info->keep_attributes ? &info->attributes : nullptr;
    bool ok = dispatch(std::string_view(data, size), format, xyz, error, encoding, faces,
                       attributes);
    if (info) {
        info->format = format;
        info->encoding = encoding;
        info->faces_ignored = faces;
    }
    return ok;
}

bool read_file_bytes(const std::string& path, BigBuffer& bytes, size_t& size, std::string& error) {
    size = 0;
    const bool standard_input = path == kStandardStream;
    std::FILE* file = standard_input ? stdin : std::fopen(path.c_str(), "rb");
    if (!file) {
        error = "cannot open: " + std::string(std::strerror(errno));
        return false;
    }
    // A byte more than the size announced: a read that fills it means the file grew.
    const size_t kFirstGuess = size_t{1} << 16;
    size_t capacity = size_hint(path);
    capacity = capacity > 0 ? capacity + 1 : kFirstGuess;
    bool failed = !bytes.reallocate(capacity, 0);
    while (!failed) {
        // A request this large bypasses stdio's buffer: the system reads into ours.
        size += std::fread(bytes.data() + size, 1, bytes.size() - size, file);
        if (size < bytes.size()) break;
        failed = bytes.size() > SIZE_MAX / 2 || !bytes.reallocate(2 * bytes.size(), size);
        if (failed) errno = ENOMEM;
    }
    failed = failed || std::ferror(file) != 0;
    const int failure = errno;
    if (!standard_input) std::fclose(file);
    if (!failed) return true;
    error = "cannot read: " + std::string(std::strerror(failure));
    return false;
}

bool read_cloud_file(const std::string& path, std::vector<double>& xyz, std::string& error,
                     CloudInfo* info) {
    BigBuffer bytes;
    size_t size = 0;
    bool ok = read_file_bytes(path, bytes, size, error) &&
              read_cloud_from_memory(bytes.data(), size, CloudFormat::automatic, xyz, error,
                                     info);
    if (!ok) error = display_name(path) + ": " + error;
    return ok;
}

std::string display_name(const std::string& path) {
    return path == kStandardStream ? "standard input" : path;
}

std::unique_ptr<PointReader> open_point_reader(const std::string& path, CloudInfo& info,
                                               std::string& error) {
    // Enough to detect any format (detect_cloud_format looks at 200 lines at most).
    const size_t kDetectBytes = 1 << 16;
    std::FILE* opened = path == kStandardStream ? stdin : std::fopen(path.c_str(), "rb");
    if (!opened) {
        error = path + ": cannot open: " + std::strerror(errno);
        return nullptr;
    }
    auto file = std::make_unique<FileWindow>(opened);
    std::string_view start = file->peek(kDetectBytes);
    info.format = detect_cloud_format(start.data(), start.size());
    info.encoding = "text";
    std::unique_ptr<PointReader> reader;
    if (start.empty())
        error = file->failure().empty() ? "the file is empty" : file->failure();
    else if (info.format == CloudFormat::off)
        error = "OFF files cannot be read point by point (--stream): convert the file to PLY "
                "or XYZ";
    else if (info.format == CloudFormat::ply)
        reader = open_ply_points(std::move(file), error, info.encoding, info.point_limit,
                                 info.faces_ignored);
    else {
        // A point takes a line of at least three one-character numbers and two separators
        // ("1 2 3"), an OBJ vertex two characters more ("v 1 2 3"), and a line end but on
        // the last line.
        std::error_code failed;
        const bool regular =
            path != kStandardStream && std::filesystem::is_regular_file(path, failed);
        const uintmax_t bytes = regular ? std::filesystem::file_size(path, failed) : 0;
        if (regular && !failed)
            info.point_limit = bytes / (info.format == CloudFormat::obj ? 8 : 6) + 1;
        if (start.substr(0, kByteOrderMark.size()) == kByteOrderMark)
            file->skip(kByteOrderMark.size());
        // Refused here, before the window would grow to hold a file of CR-only lines whole.
        if (check_line_ends(start, 1, error))
            reader = open_text_points(std::move(file), info.format == CloudFormat::obj);
    }
    if (!reader) error = display_name(path) + ": " + error;
    return reader;
}

} // namespace stratmesh_cli
