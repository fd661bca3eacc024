#include "text_scan.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>

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

bool is_blank(char c) { return is_field_separator(c, kBlank); }

bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool is_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }

// `word` is `lower` in any case.
bool same_letters(std::string_view word, std::string_view lower) {
    if (word.size() != lower.size()) return false;
    for (size_t i = 0; i < word.size(); ++i)
        if ((word[i] | 0x20) != lower[i]) return false;
    return true;
}

// The offset of the first `marker` that starts a field, or npos.
size_t comment_start(std::string_view line, std::string_view marker) {
    for (size_t at = line.find(marker); at != std::string_view::npos; at = line.find(marker, at + 1))
        if (at == 0 || is_blank(line[at - 1])) return at;
    return std::string_view::npos;
}

// An exponent and nothing after it: 'e' or 'E', an optional sign, digits.
bool is_exponent(std::string_view text) {
    if (text.empty() || (text[0] != 'e' && text[0] != 'E')) return false;
    text.remove_prefix(1);
    if (!text.empty() && (text[0] == '+' || text[0] == '-')) text.remove_prefix(1);
    return !text.empty() && std::all_of(text.begin(), text.end(), is_digit);
}

double not_finite(bool infinite, bool negative) {
    const double value = infinite ? std::numeric_limits<double>::infinity()
                                  : std::numeric_limits<double>::quiet_NaN();
    return negative ? -value : value;
}

// The NaNs that from_chars does not know: AIX's "NaNQ" and "NaNS"; MSVC's "1.#INF",
// "1.#IND", "1.#QNAN", "1.#SNAN" with either decimal mark, padded with zeros to the
// precision printed ("1.#INF00") and, in e-form, an exponent ("1.#INF00e+000"). `body`
// may start with '-'.
bool scan_other_spelling(std::string_view body, double& value) {
    const bool negative = !body.empty() && body[0] == '-';
    if (negative) body.remove_prefix(1);
    if (same_letters(body, "nanq") || same_letters(body, "nans")) {
        value = not_finite(false, negative);
        return true;
    }
    if (body.size() < 6 || body[0] != '1' || (body[1] != '.' && body[1] != ',') || body[2] != '#')
        return false;
    body.remove_prefix(3);
    size_t letters = 0;
    while (letters < body.size() && is_letter(body[letters])) ++letters;
    const std::string_view word = body.substr(0, letters);
    const bool infinite = same_letters(word, "inf");
    if (!infinite && !same_letters(word, "ind") && !same_letters(word, "qnan") &&
        !same_letters(word, "snan"))
        return false;
    body.remove_prefix(letters);
    while (!body.empty() && body[0] == '0') body.remove_prefix(1);
    if (!body.empty() && !is_exponent(body)) return false;
    value = not_finite(infinite, negative);
    return true;
}

// `body` (no leading '+') with a decimal point, as from_chars reads it.
NumberParse scan_with_point(std::string_view body, double& value) {
    if (body.empty()) return NumberParse::not_a_number;
    const char* first = body.data();
    const char* last = first + body.size();
    std::from_chars_result r = std::from_chars(first, last, value);
    if (r.ptr != last) return NumberParse::not_a_number;
    if (r.ec == std::errc()) return NumberParse::ok;
    if (r.ec != std::errc::result_out_of_range) return NumberParse::not_a_number;
    // from_chars leaves `value` alone out of range; strtod rounds to infinity on overflow
    // and to zero or a subnormal on underflow. The tool never changes the C locale.
    std::string copy(body);
    value = std::strtod(copy.c_str(), nullptr);
    return std::isinf(value) ? NumberParse::out_of_range : NumberParse::ok;
}

// `body` with its one decimal comma read as a point.
NumberParse scan_with_comma(std::string_view body, double& value) {
    std::string copy(body);
    std::replace(copy.begin(), copy.end(), ',', '.');
    return scan_with_point(copy, value);
}

// `digits` (no sign) grouped in threes by `thousands` ("1,234,567"), then optionally
// `decimal` and digits, then optionally an exponent.
bool is_grouped(std::string_view digits, char thousands, char decimal) {
    size_t at = 0;
    while (at < digits.size() && is_digit(digits[at])) ++at;
    if (at == 0 || at > 3) return false;
    size_t groups = 0;
    while (at < digits.size() && digits[at] == thousands) {
        size_t end = at + 1;
        while (end < digits.size() && is_digit(digits[end])) ++end;
        if (end - at != 4) return false;
        at = end;
        ++groups;
    }
    if (groups == 0) return false;
    if (at < digits.size() && digits[at] == decimal) {
        ++at;
        while (at < digits.size() && is_digit(digits[at])) ++at;
    }
    return at == digits.size() || is_exponent(digits.substr(at));
}

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
    size_t cut = comment_start(line, "#");
    if (slashes) cut = std::min(cut, comment_start(line, "//"));
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

std::string_view trim_blanks(std::string_view field) {
    while (!field.empty() && is_blank(field.front())) field.remove_prefix(1);
    while (!field.empty() && is_blank(field.back())) field.remove_suffix(1);
    return field;
}

NumberParse scan_number(std::string_view token, char& mark, double& value) {
    // from_chars takes no leading '+'; allow one before anything but another sign.
    if (token.size() > 1 && token[0] == '+' && token[1] != '+' && token[1] != '-')
        token.remove_prefix(1);
    const auto points = std::count(token.begin(), token.end(), '.');
    const auto commas = std::count(token.begin(), token.end(), ',');
    if (scan_other_spelling(token, value)) return NumberParse::ok;
    if (points + commas == 0) return scan_with_point(token, value);
    const char used = points > 0 ? '.' : ',';
    if (points + commas == 1 && (mark == kEitherMark || mark == used)) {
        NumberParse parsed = used == '.' ? scan_with_point(token, value) : scan_with_comma(token, value);
        if (parsed == NumberParse::ok && mark == kEitherMark) mark = used;
        return parsed;
    }
    const std::string_view digits = token.substr(!token.empty() && token[0] == '-' ? 1 : 0);
    if (is_grouped(digits, ',', '.') || is_grouped(digits, '.', ','))
        return NumberParse::grouped;
    return points + commas == 1 ? NumberParse::other_mark : NumberParse::not_a_number;
}

bool parse_number(std::string_view token, double& value) {
    char point = '.';
    return scan_number(token, point, value) == NumberParse::ok;
}

bool next_number(std::string_view& rest, std::string_view& field, double& value,
                 NumberParse& parsed, char& mark) {
    size_t start = 0;
    while (start < rest.size() && is_blank(rest[start])) ++start;
    const char* first = rest.data() + start;
    const char* last = rest.data() + rest.size();
    if (mark != ',') {
        std::from_chars_result r = std::from_chars(first, last, value);
        if (r.ec == std::errc() && r.ptr > first && (r.ptr == last || is_blank(*r.ptr))) {
            field = std::string_view(first, static_cast<size_t>(r.ptr - first));
            if (mark == kEitherMark && field.find('.') != std::string_view::npos) mark = '.';
            rest.remove_prefix(static_cast<size_t>(r.ptr - rest.data()));
            parsed = NumberParse::ok;
            return true;
        }
    }
    // Anything else (a sign, a range error, no number, text after it) as the two calls do.
    if (!next_field(rest, field, false)) return false;
    parsed = scan_number(field, mark, value);
    return true;
}

std::string number_problem(std::string_view token, NumberParse parsed, char mark,
                           size_t mark_line) {
    const std::string quoted = quote(token);
    switch (parsed) {
    case NumberParse::out_of_range: return quoted + " is beyond the range of a double";
    case NumberParse::grouped: {
        const char thousands = token[token.find_first_of(".,")];
        return quoted + " has a thousands separator ('" + thousands +
               "'): write numbers without digit grouping";
    }
    case NumberParse::other_mark: {
        std::string text = quoted + " has a decimal " + (mark == '.' ? "comma" : "point") +
                           ", where the file's decimal mark is a " +
                           (mark == '.' ? "point" : "comma");
        if (mark_line > 0) text += " (as line " + std::to_string(mark_line) + " writes it)";
        return text;
    }
    case NumberParse::ok:
    case NumberParse::not_a_number: break;
    }
    return quoted + " is not a number";
}

std::string_view skip_byte_order_mark(std::string_view text) {
    if (text.substr(0, kByteOrderMark.size()) == kByteOrderMark)
        text.remove_prefix(kByteOrderMark.size());
    return text;
}

IntegerParse scan_integer(std::string_view token, bool& negative, uint64_t& magnitude) {
    negative = !token.empty() && token[0] == '-';
    if (!token.empty() && (token[0] == '-' || token[0] == '+')) token.remove_prefix(1);
    if (token.empty()) return IntegerParse::not_an_integer;
    uint64_t v = 0;
    bool too_large = false;
    for (char c : token) {
        if (!is_digit(c)) return IntegerParse::not_an_integer;
        const uint64_t digit = static_cast<uint64_t>(c - '0');
        too_large = too_large || v > (UINT64_MAX - digit) / 10;
        v = v * 10 + digit;
    }
    magnitude = v;
    return too_large ? IntegerParse::too_large : IntegerParse::ok;
}

CountParse parse_count(std::string_view token, uint64_t& value) {
    bool negative = false;
    uint64_t magnitude = 0;
    const IntegerParse parsed = scan_integer(token, negative, magnitude);
    if (parsed == IntegerParse::not_an_integer) return CountParse::not_a_number;
    if (negative) return CountParse::negative;
    if (parsed == IntegerParse::too_large) return CountParse::too_large;
    value = magnitude;
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
