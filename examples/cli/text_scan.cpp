#include "text_scan.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>

namespace stratmesh_cli {

namespace {

// Separator classes by byte, so that scanning a field is one lookup per byte.
constexpr unsigned char kBlank = 1, kComma = 2;

struct SeparatorTable {
    unsigned char kind[256] = {};
    constexpr SeparatorTable() {
        for (char c : {' ', '\t', '\r', '\v', '\f'}) kind[static_cast<unsigned char>(c)] = kBlank;
        kind[static_cast<unsigned char>(',')] = kComma;
        kind[static_cast<unsigned char>(';')] = kComma;
    }
};

constexpr SeparatorTable kSeparators;

bool is_field_separator(char c, unsigned char classes) {
    return (kSeparators.kind[static_cast<unsigned char>(c)] & classes) != 0;
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

} // namespace

bool LineCursor::next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    size_t end = text_.find('\n', pos_);
    size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++line_number_;
    return true;
}

bool check_line_ends(std::string_view text, size_t first_line, std::string& error) {
    for (size_t at = text.find('\r'); at != std::string_view::npos; at = text.find('\r', at + 1)) {
        if (at + 1 == text.size() || text[at + 1] == '\n') continue;
        const auto before = text.substr(0, at);
        const size_t line = first_line + static_cast<size_t>(std::count(before.begin(), before.end(), '\n'));
        error = "line " + std::to_string(line) +
                ": a carriage return (CR) without a line feed: lines ended by CR alone, as "
                "classic Mac OS wrote them, are not read; convert the line ends to LF or CRLF";
        return false;
    }
    return true;
}

std::string_view strip_comment(std::string_view line, bool slashes) {
    size_t cut = line.find('#');
    if (slashes) {
        size_t slash = line.find("//");
        if (slash < cut) cut = slash;
    }
    return cut == std::string_view::npos ? line : line.substr(0, cut);
}

bool next_field(std::string_view& rest, std::string_view& field, bool commas) {
    const unsigned char classes = commas ? kBlank | kComma : kBlank;
    size_t start = 0;
    while (start < rest.size() && is_field_separator(rest[start], classes)) ++start;
    if (start == rest.size()) {
        rest = std::string_view();
        return false;
    }
    size_t stop = start;
    while (stop < rest.size() && !is_field_separator(rest[stop], classes)) ++stop;
    field = rest.substr(start, stop - start);
    rest.remove_prefix(stop);
    return true;
}

NumberParse scan_number(std::string_view token, double& value) {
    // from_chars takes no leading '+'; allow one before a digit or a point.
    if (token.size() > 1 && token[0] == '+' && (is_digit(token[1]) || token[1] == '.'))
        token.remove_prefix(1);
    if (token.empty()) return NumberParse::not_a_number;
    const char* first = token.data();
    const char* last = first + token.size();
    std::from_chars_result r = std::from_chars(first, last, value);
    if (r.ptr != last) return NumberParse::not_a_number;
    if (r.ec == std::errc()) return NumberParse::ok;
    if (r.ec != std::errc::result_out_of_range) return NumberParse::not_a_number;
    // from_chars leaves `value` alone out of range; strtod rounds to infinity on overflow
    // and to zero or a subnormal on underflow. The tool never changes the C locale.
    std::string copy(token);
    value = std::strtod(copy.c_str(), nullptr);
    return std::isinf(value) ? NumberParse::out_of_range : NumberParse::ok;
}

bool parse_number(std::string_view token, double& value) {
    return scan_number(token, value) == NumberParse::ok;
}

bool next_number(std::string_view& rest, std::string_view& field, double& value,
                 NumberParse& parsed, bool commas) {
    const unsigned char classes = commas ? kBlank | kComma : kBlank;
    size_t start = 0;
    while (start < rest.size() && is_field_separator(rest[start], classes)) ++start;
    const char* first = rest.data() + start;
    const char* last = rest.data() + rest.size();
    std::from_chars_result r = std::from_chars(first, last, value);
    if (r.ec == std::errc() && r.ptr > first &&
        (r.ptr == last || is_field_separator(*r.ptr, classes))) {
        field = std::string_view(first, static_cast<size_t>(r.ptr - first));
        rest.remove_prefix(static_cast<size_t>(r.ptr - rest.data()));
        parsed = NumberParse::ok;
        return true;
    }
    // Anything else (a sign, a range error, no number, text after it) as the two calls do.
    if (!next_field(rest, field, commas)) return false;
    parsed = scan_number(field, value);
    return true;
}

std::string_view skip_byte_order_mark(std::string_view text) {
    if (text.substr(0, kByteOrderMark.size()) == kByteOrderMark)
        text.remove_prefix(kByteOrderMark.size());
    return text;
}

CountParse parse_count(std::string_view token, uint64_t& value) {
    if (token.empty()) return CountParse::not_a_number;
    if (token[0] == '-') {
        bool numeric = token.size() > 1;
        for (size_t i = 1; i < token.size(); ++i) numeric = numeric && is_digit(token[i]);
        return numeric ? CountParse::negative : CountParse::not_a_number;
    }
    if (token[0] == '+') token.remove_prefix(1);
    if (token.empty()) return CountParse::not_a_number;
    uint64_t v = 0;
    for (char c : token) {
        if (!is_digit(c)) return CountParse::not_a_number;
        uint64_t digit = static_cast<uint64_t>(c - '0');
        if (v > (UINT64_MAX - digit) / 10) return CountParse::too_large;
        v = v * 10 + digit;
    }
    value = v;
    return CountParse::ok;
}

const char* count_problem(CountParse result) {
    switch (result) {
    case CountParse::ok: return "is fine";
    case CountParse::negative: return "is negative";
    case CountParse::not_a_number: return "is not a whole number";
    case CountParse::too_large: return "is too large";
    }
    return "is invalid";
}

std::string quote(std::string_view token) {
    const size_t kShown = 32;
    std::string out = "'";
    for (size_t i = 0; i < token.size() && i < kShown; ++i) {
        unsigned char c = static_cast<unsigned char>(token[i]);
        if (c >= 0x20 && c < 0x7f) {
            out += static_cast<char>(c);
        } else {
            const char* hex = "0123456789abcdef";
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
        }
    }
    if (token.size() > kShown) out += "...";
    out += "'";
    return out;
}

} // namespace stratmesh_cli
