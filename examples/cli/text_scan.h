// Small helpers for scanning text point files: lines, fields, numbers, error quoting.
// Everything works on string_views into the caller's buffer; nothing here allocates
// except the quoting of a token for an error message.
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

// Cuts `line` at the first comment marker: '#' always, "//" when `slashes` is set.
std::string_view strip_comment(std::string_view line, bool slashes);

// Pops the next field off `rest`. Fields are separated by runs of spaces, tabs, '\r',
// '\v', '\f', and also of ',' and ';' when `commas` is set. False when none is left.
bool next_field(std::string_view& rest, std::string_view& field, bool commas);

enum class NumberParse { ok, not_a_number, out_of_range };

// The whole token as a double (decimal or scientific, optional sign, "nan", "inf").
// Locale-independent. A finite literal beyond the largest double ("1e400", a number of
// 400 digits) is out_of_range, never infinity; one below the smallest rounds to the
// nearest double (a subnormal or zero), as any decimal rounds.
NumberParse scan_number(std::string_view token, double& value);

// scan_number() == ok.
bool parse_number(std::string_view token, double& value);

// next_field(), then scan_number() of that field, in one pass over the bytes when the field
// is a plain number: it is read where the field starts, and ends where the number does if
// a separator (or the end) follows. The results are those of the two calls.
bool next_number(std::string_view& rest, std::string_view& field, double& value,
                 NumberParse& parsed, bool commas);

// The three bytes of a UTF-8 byte-order mark, which some editors write at the start of a
// text file.
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

// `text` without a leading byte-order mark.
std::string_view skip_byte_order_mark(std::string_view text);

enum class CountParse { ok, negative, not_a_number, too_large };

// A non-negative decimal integer that fits in 64 bits.
CountParse parse_count(std::string_view token, uint64_t& value);

// An error-message phrase for a bad count, e.g. "is negative".
const char* count_problem(CountParse result);

// The token in single quotes for a message: at most 32 characters, control and
// non-ASCII bytes shown as \xHH.
std::string quote(std::string_view token);

} // namespace stratmesh_cli

#endif
