// fuzz_cloud_reader: the command-line tool's from-memory cloud reader
// (examples/cli/cloud_io.h, read_cloud_from_memory) with every format hint.
//
// Checked: no crash or sanitizer report; on success the coordinates come in threes and the
// point count is consistent with the input size (every point needs at least 3 bytes:
// three one-byte binary properties or three one-digit numbers), and a PLY file gives
// exactly the vertex count its header declares; no text read succeeds over a carriage
// return that ends no CRLF pair (CR-only line ends are refused, never read as one line); on
// failure the message names the line or the byte where the file went wrong (but for an
// empty file or a text file without a single point); detect_cloud_format agrees with what
// the automatic read reports; a second read gives the same result. Allocations proportional to a lying header are caught by
// libFuzzer's -malloc_limit_mb / -rss_limit_mb (see .ci/fuzz.sh).
//
// The custom mutator knows the formats: it rewrites PLY element counts, property types
// and names, duplicates header lines, adds and removes tokens and lines of the body, turns
// numbers into extreme values and NaN spellings, writes a line as European software does
// (semicolons, decimal commas) or with a thousands separator or an empty field, adds a
// byte-order mark, and switches line ends (LF, CRLF, CR alone); otherwise it leaves the
// bytes to libFuzzer's own mutations.
#include "fuzz_common.h"

#include "cloud_io.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

namespace {

using stratmesh_cli::CloudFormat;

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Whitespace-separated tokens of a line, as offsets and lengths.
std::vector<std::pair<size_t, size_t>> tokens_of(std::string_view line) {
    std::vector<std::pair<size_t, size_t>> tokens;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_blank(line[i])) ++i;
        size_t start = i;
        while (i < line.size() && !is_blank(line[i])) ++i;
        if (i > start) tokens.push_back({start, i - start});
    }
    return tokens;
}

// The first "element vertex N" of a PLY header (a byte-order mark skipped); false if the
// header has none or N is not a plain decimal count that fits in 64 bits.
bool declared_vertices(std::string_view text, uint64_t& count) {
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    size_t at = 0;
    while (at < text.size()) {
        size_t end = text.find('\n', at);
        std::string_view line = text.substr(at, end == std::string_view::npos ? end : end - at);
        std::vector<std::pair<size_t, size_t>> t = tokens_of(line);
        auto word = [&](size_t k) { return line.substr(t[k].first, t[k].second); };
        if (!t.empty() && word(0) == "end_header") return false;
        if (t.size() == 3 && word(0) == "element" && word(1) == "vertex") {
            std::string_view digits = word(2);
            if (digits[0] == '+') digits.remove_prefix(1);
            if (digits.empty()) return false;
            // Any number of digits, as long as the value fits: "00000000000000000000" is 0.
            count = 0;
            for (char c : digits) {
                if (c < '0' || c > '9') return false;
                const uint64_t digit = static_cast<uint64_t>(c - '0');
                if (count > (UINT64_MAX - digit) / 10) return false;
                count = count * 10 + digit;
            }
            return true;
        }
        if (end == std::string_view::npos) break;
        at = end + 1;
    }
    return false;
}

// A carriage return that is neither followed by a line feed nor the last byte.
bool has_lone_carriage_return(std::string_view text) {
    for (size_t at = text.find('\r'); at != std::string_view::npos; at = text.find('\r', at + 1))
        if (at + 1 < text.size() && text[at + 1] != '\n') return true;
    return false;
}

// "line N" or "byte N" somewhere in the message.
bool names_a_place(const std::string& error) {
    for (const char* word : {"line ", "byte "}) {
        for (size_t at = error.find(word); at != std::string::npos; at = error.find(word, at + 1)) {
            const size_t digit = at + std::strlen(word);
            if (digit < error.size() && error[digit] >= '0' && error[digit] <= '9') return true;
        }
    }
    return false;
}

// Messages about the whole file, which has no place to name.
bool is_whole_file_message(const std::string& error) {
    return error == "the file is empty" || error.rfind("no points found", 0) == 0 ||
           error.rfind("no vertices found", 0) == 0;
}

} // namespace

// ---- the mutator (libFuzzer only: the replay driver runs the corpus as it is) -------------
#if !defined(STRATMESH_FUZZ_REPLAY)

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

using stratmesh_fuzz::Random;

std::vector<std::string> split_lines(const std::string& text) {
    std::vector<std::string> lines;
    size_t at = 0;
    while (at <= text.size()) {
        size_t end = text.find('\n', at);
        if (end == std::string::npos) {
            lines.push_back(text.substr(at));
            break;
        }
        lines.push_back(text.substr(at, end - at));
        at = end + 1;
    }
    return lines;
}

std::string join_lines(const std::vector<std::string>& lines) {
    std::string text;
    for (size_t i = 0; i < lines.size(); ++i) {
        if (i > 0) text += '\n';
        text += lines[i];
    }
    return text;
}

const char* const kExtremes[] = {"1e400",   "-1e400", "1e-400", "nan",        "inf",  "-0",
                                 "366",     "-1",     "0.66",   "4294967296", "256",  "65536",
                                 "2147483648", "3.5e38", "0x10", "1e308",     "",     "+",
                                 "18446744073709551616", "1.#INF", "-1.#IND", "1.#QNAN00",
                                 "nan(ind)", "-Infinity", "NaNQ", "1.#J", "1e2", "2,176.92",
                                 "1,5", "1.234,5", "#", "1#", "+inf"};
const char* const kTypes[] = {"char",  "uchar", "short", "ushort", "int",   "uint",  "float",
                              "double", "int8", "uint32", "float64", "list", "float128"};
const char* const kCounts[] = {"0", "1", "2", "3", "10", "4000000000", "18446744073709551615",
                               "-1", "99999999999999999999"};

// One structural change; false if it did not apply to this input.
bool mutate_structure(std::string& text, Random& random) {
    std::vector<std::string> lines = split_lines(text);
    if (lines.empty()) return false;
    size_t end_header = lines.size();
    for (size_t i = 0; i < lines.size(); ++i)
        if (lines[i].rfind("end_header", 0) == 0) {
            end_header = i;
            break;
        }
    const bool ply = end_header < lines.size();
    std::string& line = lines[random.below(lines.size())];
    std::vector<std::pair<size_t, size_t>> tokens = tokens_of(line);
    switch (random.below(13)) {
    case 0: { // an element's count
        if (!ply) return false;
        std::string& header_line = lines[random.below(end_header)];
        if (header_line.rfind("element ", 0) != 0) return false;
        std::vector<std::pair<size_t, size_t>> t = tokens_of(header_line);
        if (t.size() < 3) return false;
        header_line.replace(t[2].first, t[2].second, kCounts[random.below(std::size(kCounts))]);
        break;
    }
    case 1: { // a property's type or name
        if (!ply) return false;
        std::string& header_line = lines[random.below(end_header)];
        if (header_line.rfind("property ", 0) != 0) return false;
        std::vector<std::pair<size_t, size_t>> t = tokens_of(header_line);
        if (t.size() < 2) return false;  // "property" alone: nothing to replace
        size_t k = 1 + random.below(t.size() - 1);
        const char* names[] = {"x", "y", "z", "red"};
        const std::string replacement = k + 1 == t.size() && random.below(2)
                                            ? names[random.below(4)]
                                            : kTypes[random.below(std::size(kTypes))];
        header_line.replace(t[k].first, t[k].second, replacement);
        break;
    }
    case 2: { // a header line twice
        if (!ply || end_header < 2) return false;
        const size_t k = 1 + random.below(end_header - 1);
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(k), lines[k]);
        break;
    }
    case 3: // a token more
        line += random.below(2) ? " 7" : " 1e400";
        break;
    case 4: // a token less
        if (tokens.empty()) return false;
        line.erase(tokens.back().first, tokens.back().second);
        break;
    case 5: { // a number made extreme
        if (tokens.empty()) return false;
        const auto& t = tokens[random.below(tokens.size())];
        line.replace(t.first, t.second, kExtremes[random.below(std::size(kExtremes))]);
        break;
    }
    case 6: { // a digit string of a hundred digits
        if (tokens.empty()) return false;
        const auto& t = tokens[random.below(tokens.size())];
        line.replace(t.first, t.second, "1" + std::string(100, '0'));
        break;
    }
    case 7: { // a line twice or gone
        const size_t k = random.below(lines.size());
        if (random.below(2))
            lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(k), lines[k]);
        else
            lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(k));
        break;
    }
    case 8: // a blank line
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(random.below(lines.size() + 1)),
                     std::string(random.below(3), ' '));
        break;
    case 9: { // a line written as European software does: semicolons, decimal commas
        std::string european;
        for (char c : line) european += c == '.' ? ',' : c == ' ' ? ';' : c;
        line = european;
        break;
    }
    case 10: { // an empty field, or a comma inside a number (a thousands separator)
        if (tokens.empty()) return false;
        const auto& t = tokens[random.below(tokens.size())];
        line.insert(t.first + random.below(t.second + 1), random.below(2) ? ",," : ",");
        break;
    }
    case 11: // a byte-order mark, on or off
        if (text.rfind("\xEF\xBB\xBF", 0) == 0) {
            text.erase(0, 3);
        } else {
            text.insert(0, "\xEF\xBB\xBF");
        }
        return true;
    default: { // line ends switched: LF to CRLF, CRLF to CR alone, CR alone to LF
        std::string switched;
        const bool crlf = text.find("\r\n") != std::string::npos;
        const bool cr = !crlf && text.find('\r') != std::string::npos;
        for (size_t i = 0; i < text.size(); ++i) {
            if (!crlf && !cr && text[i] == '\n') switched += '\r';
            if (crlf && text[i] == '\n' && i > 0 && text[i - 1] == '\r') continue;
            switched += cr && text[i] == '\r' ? '\n' : text[i];
        }
        text = switched;
        return true;
    }
    }
    text = join_lines(lines);
    return true;
}

} // namespace

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size,
                                          unsigned int seed) {
    Random random(seed);
    if (size > 0 && random.below(4) != 0) {
        std::string text(reinterpret_cast<const char*>(data), size);
        for (int attempt = 0; attempt < 4; ++attempt) {
            if (!mutate_structure(text, random)) continue;
            if (text.size() > max_size) break;
            std::copy(text.begin(), text.end(), data);
            return text.size();
        }
    }
    return LLVMFuzzerMutate(data, size, max_size);
}

#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // A copy of exactly `size` bytes, never null, without a terminating zero: a reader
    // that relies on one trips AddressSanitizer.
    std::vector<char> bytes(data, data + size);
    const char* p = bytes.empty() ? "" : bytes.data();
    const CloudFormat formats[] = {CloudFormat::automatic, CloudFormat::ply, CloudFormat::xyz,
                                   CloudFormat::off, CloudFormat::obj};
    const CloudFormat detected = stratmesh_cli::detect_cloud_format(p, size);
    uint64_t declared = 0;
    const bool has_count = declared_vertices(std::string_view(p, size), declared);
    for (CloudFormat format : formats) {
        std::vector<double> xyz;
        std::string error;
        stratmesh_cli::CloudInfo info;
        info.keep_attributes = true; // the second read below does not: the same points
        bool ok = stratmesh_cli::read_cloud_from_memory(p, size, format, xyz, error, &info);
        if (ok) {
            STRATMESH_FUZZ_CHECK(xyz.size() % 3 == 0, "coordinates not in threes");
            const stratmesh_cli::PointAttributes& kept = info.attributes;
            STRATMESH_FUZZ_CHECK(kept.bytes.size() == (kept.empty() ? 0 : kept.record_bytes * (xyz.size() / 3)),
                                 "per-point data not one record per point");
            STRATMESH_FUZZ_CHECK(xyz.size() / 3 <= size / 3, "more points than the input can hold");
            if (format == CloudFormat::automatic)
                STRATMESH_FUZZ_CHECK(info.format == detected, "automatic read disagrees with detection");
            else
                STRATMESH_FUZZ_CHECK(info.format == format, "the forced format was not the one read");
            if (info.format == CloudFormat::ply)
                STRATMESH_FUZZ_CHECK(has_count && xyz.size() / 3 == declared,
                                     "a PLY file read with other than its header's vertex count");
            if (info.format != CloudFormat::ply || info.encoding == "ascii")
                STRATMESH_FUZZ_CHECK(!has_lone_carriage_return(std::string_view(p, size)),
                                     "a text file with CR-only line ends read");
        } else {
            STRATMESH_FUZZ_CHECK(!error.empty(), "failure without a message");
            if (!names_a_place(error) && !is_whole_file_message(error))
                stratmesh_fuzz::fail("a failure that names no line or byte", error.c_str());
        }
        std::vector<double> xyz2;
        std::string error2;
        bool ok2 = stratmesh_cli::read_cloud_from_memory(p, size, format, xyz2, error2, nullptr);
        STRATMESH_FUZZ_CHECK(ok2 == ok, "second read: different outcome");
        if (ok)
            STRATMESH_FUZZ_CHECK(xyz2.size() == xyz.size() &&
                                     (xyz.empty() || std::memcmp(xyz.data(), xyz2.data(), xyz.size() * sizeof(double)) == 0),
                                 "second read: different points");
        else
            STRATMESH_FUZZ_CHECK(error2 == error, "second read: different error");
    }
    return 0;
}
