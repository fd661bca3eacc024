// Small helpers for scanning text point files: lines, fields, numbers, error quoting.
// Everything works on string_views into the caller's buffer; nothing here allocates
// except the text of an error message and the copy of a number with a decimal comma.
//
// Every text reader (PLY ascii, OFF, OBJ, XYZ/CSV/PTS) reads its numbers with scan_number
// and its whole numbers with scan_integer, so that they agree on what a number is.
#ifndef STRATMESH_CLI_TEXT_SCAN_H
#define STRATMESH_CLI_TEXT_SCAN_H

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace stratmesh_cli {

// Walks a buffer line by line. Lines end at '\n'; a '\r' before it is dropped, and so is
// one as the buffer's last byte (a CRLF line end cut short by the end of the file).
class LineCursor {
public:
    explicit LineCursor(std::string_view text) : text_(text) {}

    // The next line, without its terminator; false at the end of the buffer.
    bool next(std::string_view& line);
    // 1-based number of the line last returned by next() (0 before the first).
    size_t line_number() const { return line_number_; }
    // Offset of the first byte after the line last returned (its terminator included).
    size_t offset() const { return pos_; }

private:
    std::string_view text_;
    size_t pos_ = 0;
    size_t line_number_ = 0;
};

// False, with a message naming the line, if `text` holds a carriage return that ends no
// CRLF pair: lines ended by CR alone (as classic Mac OS wrote them) are refused, never
// read as one long line. `first_line` is the number of the text's first line. A '\r' as
// the text's last byte passes: `text` is whole lines, or the end of the file.
bool check_line_ends(std::string_view text, size_t first_line, std::string& error);

// Cuts `line` at the first comment marker that starts a field (the line's first byte, or
// one after a blank): '#' always, "//" when `slashes` is set. A '#' inside a field is
// part of it, as in MSVC's "1.#INF".
std::string_view strip_comment(std::string_view line, bool slashes);

// Pops the next field off `rest`. Fields are separated by runs of spaces, tabs, '\r',
// '\v', '\f', and also of ',' and ';' when `commas` is set. False when none is left.
bool next_field(std::string_view& rest, std::string_view& field, bool commas);

// `field` without the blanks (as next_field's) at either end.
std::string_view trim_blanks(std::string_view field);

enum class NumberParse {
    ok,
    not_a_number,
    out_of_range, // a finite literal beyond the largest double
    grouped,      // digits grouped by a thousands separator: "2,176.92", "1.234,5"
    other_mark,   // one decimal mark, not the file's: "1,5" where the file has '.'
};

// A decimal mark not yet known: scan_number takes either and reports the one it met.
constexpr char kEitherMark = 0;

// The whole token as a double: an optional sign, digits with at most one decimal mark,
// an optional exponent; or a NaN or infinity in any spelling in use ("nan", "-nan",
// "nan(ind)", "NaNQ", "inf", "Infinity", MSVC's "1.#INF", "-1.#IND", "1.#QNAN",
// "1.#SNAN", padded "1.#INF00", in e-form "1.#INF00e+000"). Locale-independent.
// `mark` is the file's decimal mark, '.' or ','; kEitherMark takes either, and becomes the
// one the token has, if it has one. A finite literal beyond the largest double ("1e400", a
// number of 400 digits) is out_of_range, never infinity; one below the smallest rounds to
// the nearest double (a subnormal or zero), as any decimal rounds.
NumberParse scan_number(std::string_view token, char& mark, double& value);

// scan_number() with a decimal point == ok.
bool parse_number(std::string_view token, double& value);

// next_field() without commas, then scan_number() of that field, in one pass over the
// bytes when the field is a plain number: it is read where the field starts, and ends
// where the number does if a blank (or the end) follows. The results are those of the
// two calls.
bool next_number(std::string_view& rest, std::string_view& field, double& value,
                 NumberParse& parsed, char& mark);

// Why `token` is not a number, for an error message: "'x' is not a number", "'2,176.92'
// has a thousands separator (',')", ... `mark` is the file's decimal mark; `mark_line`, if
// not 0, the line whose number set it.
std::string number_problem(std::string_view token, NumberParse parsed, char mark,
                           size_t mark_line = 0);

// The three bytes of a UTF-8 byte-order mark, which some editors write at the start of a
// text file.
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

// `text` without a leading byte-order mark.
std::string_view skip_byte_order_mark(std::string_view text);

enum class IntegerParse { ok, not_an_integer, too_large };

// A whole number written as one: an optional sign and decimal digits ("1e2" and "1.0"
// are not), its magnitude within 64 bits.
IntegerParse scan_integer(std::string_view token, bool& negative, uint64_t& magnitude);

enum class CountParse { ok, negative, not_a_number, too_large };

// A non-negative decimal integer that fits in 64 bits (scan_integer's).
CountParse parse_count(std::string_view token, uint64_t& value);

// An error-message phrase for a bad count, e.g. "is negative".
const char* count_problem(CountParse result);

// The token in single quotes for a message: at most 32 characters, control and
// non-ASCII bytes shown as \xHH.
std::string quote(std::string_view token);

} // namespace stratmesh_cli

#endif
