// Text readers: numeric columns (XYZ, PTS, TXT, CSV), OFF and OBJ. All are line based,
// keep the first three numbers of each point line and name the line of any error.
#include "cloud_readers.h"
#include "file_window.h"
#include "text_scan.h"

#include <cstdint>

namespace stratmesh_cli {

namespace {

std::string at_line(size_t line) { return "line " + std::to_string(line) + ": "; }

bool is_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }

// The fields of a line that one `separator` parts, blanks around each dropped; any of them
// may be empty, the last too ("1;2;" has three fields).
class SeparatedFields {
public:
    SeparatedFields(std::string_view line, char separator) : rest_(line), separator_(separator) {}

    bool next(std::string_view& field) {
        if (done_) return false;
        const size_t at = rest_.find(separator_);
        done_ = at == std::string_view::npos;
        field = trim_blanks(rest_.substr(0, at));
        rest_.remove_prefix(done_ ? rest_.size() : at + 1);
        return true;
    }

private:
    std::string_view rest_;
    char separator_;
    bool done_ = false;
};

// The fields of one line, all expected to be numbers.
struct NumberRow {
    size_t fields = 0; // fields seen
    double first[3] = {0, 0, 0};
    size_t empty = 0;     // the first empty field, counting from 1; 0 if none
    std::string_view bad; // the first field that is not a number, if any
    NumberParse bad_as = NumberParse::ok; // and why
};

// The numbers of a line whose fields `separator` parts: ' ' for runs of blanks, else ','
// or ';'. `mark` is the file's decimal mark (kEitherMark until a number has one).
NumberRow scan_numbers(std::string_view content, char separator, char& mark) {
    NumberRow row;
    SeparatedFields separated(content, separator);
    std::string_view field;
    double value = 0;
    NumberParse parsed = NumberParse::ok;
    for (;;) {
        const bool more = separator == ' ' ? next_number(content, field, value, parsed, mark)
                                           : separated.next(field);
        if (!more) break;
        ++row.fields;
        if (field.empty()) {
            if (row.empty == 0) row.empty = row.fields;
            continue;
        }
        if (separator != ' ') parsed = scan_number(field, mark, value);
        if (parsed != NumberParse::ok && row.bad.empty()) {
            row.bad = field;
            row.bad_as = parsed;
        }
        if (parsed == NumberParse::ok && row.fields <= 3) row.first[row.fields - 1] = value;
    }
    return row;
}

// What keeps a row from being a point (every field a number, at least three of them), as a
// clause of a message; empty if nothing does.
std::string point_problem(const NumberRow& row, char mark, size_t mark_line) {
    if (row.empty > 0) return "field " + std::to_string(row.empty) + " is empty";
    if (!row.bad.empty()) return number_problem(row.bad, row.bad_as, mark, mark_line);
    if (row.fields < 3)
        return "found " + std::to_string(row.fields) +
               (row.fields == 1 ? " number" : " numbers") + " where a point needs at least 3 (x y z)";
    return std::string();
}

// A point row of an OFF or OBJ file, blanks parting numbers with a decimal point, appended
// to `xyz`; false with a message if the row is no point.
bool take_point(std::string_view content, size_t line, std::vector<double>& xyz,
                std::string& error) {
    char point = '.';
    const NumberRow row = scan_numbers(content, ' ', point);
    const std::string problem = point_problem(row, point, 0);
    if (!problem.empty()) {
        error = at_line(line) + problem;
        return false;
    }
    xyz.insert(xyz.end(), row.first, row.first + 3);
    return true;
}

// A line of column names: no field a number, each beginning with a letter ("X Y Z",
// "x;y;z").
bool is_column_names(std::string_view content) {
    std::string_view field;
    while (next_field(content, field, true)) {
        char mark = kEitherMark;
        double value = 0;
        if (!is_letter(field[0]) || scan_number(field, mark, value) == NumberParse::ok)
            return false;
    }
    return true;
}

// The separator of a column file, from its first point line: ';' if the line has one;
// ',' where commas part the line (it has fewer than three blank-parted fields, or a comma
// beside a blank or at an end); else blanks, a comma then being a decimal comma.
char column_separator(std::string_view content) {
    if (content.find(';') != std::string_view::npos) return ';';
    if (content.find(',') == std::string_view::npos) return ' ';
    std::string_view field;
    size_t fields = 0;
    bool comma_at_edge = false;
    while (next_field(content, field, false)) {
        ++fields;
        comma_at_edge = comma_at_edge || field.front() == ',' || field.back() == ',';
    }
    return fields < 3 || comma_at_edge ? ',' : ' ';
}

const char* separator_name(char separator) {
    return separator == ',' ? "','" : separator == ';' ? "';'" : "blanks";
}

// A PTS count line: a single whole number.
bool is_count_line(std::string_view content, uint64_t& count) {
    std::string_view field, rest = content;
    if (!next_field(rest, field, false)) return false;
    std::string_view extra;
    return !next_field(rest, extra, false) && parse_count(field, count) == CountParse::ok;
}

// Advances to the next line with something other than blanks and '#' comments.
bool next_content_line(LineCursor& lines, std::string_view& content) {
    std::string_view line, field;
    while (lines.next(line)) {
        content = strip_comment(line, false);
        std::string_view probe = content;
        if (next_field(probe, field, false)) return true;
    }
    return false;
}

bool read_off_vertices(LineCursor& lines, uint64_t count, std::vector<double>& xyz,
                       std::string& error) {
    std::string_view content;
    for (uint64_t v = 0; v < count; ++v) {
        if (!next_content_line(lines, content)) {
            error = at_line(lines.line_number()) + "the file ends after " + std::to_string(v) +
                    " of the " + std::to_string(count) + " vertices the header announces";
            return false;
        }
        if (!take_point(content, lines.line_number(), xyz, error)) return false;
    }
    return true;
}

// The face lines after an OFF file's vertices: each a vertex count k and k whole numbers,
// indices of the `vertices` (colours may follow); nothing but blank and comment lines
// after the last.
bool read_off_faces(LineCursor& lines, uint64_t count, uint64_t vertices, std::string& error) {
    std::string_view content, field;
    for (uint64_t f = 0; f < count; ++f) {
        if (!next_content_line(lines, content)) {
            error = at_line(lines.line_number()) + "the file ends after " + std::to_string(f) +
                    " of the " + std::to_string(count) + " faces the header announces";
            return false;
        }
        uint64_t corners = 0, index = 0;
        bool in_range = true;
        next_field(content, field, false);
        CountParse parsed = parse_count(field, corners);
        for (uint64_t k = 0; parsed == CountParse::ok && in_range && k < corners; ++k) {
            parsed = next_field(content, field, false) ? parse_count(field, index)
                                                       : CountParse::not_a_number;
            in_range = index < vertices;
        }
        if (parsed != CountParse::ok) {
            error = at_line(lines.line_number()) + "face " + std::to_string(f) +
                    " is not a corner count followed by that many vertex indices";
            return false;
        }
        if (!in_range) {
            error = at_line(lines.line_number()) + "face " + std::to_string(f) + " names vertex " +
                    std::to_string(index) + ", but the file has " + std::to_string(vertices) +
                    " vertices (numbered from 0)";
            return false;
        }
    }
    if (!next_content_line(lines, content)) return true;
    error = at_line(lines.line_number()) + "more lines than the header's vertices and " +
            std::to_string(count) + " faces";
    return false;
}

// The keyword line of an OFF file, and the vertex count (on that line or the next).
bool read_off_header(LineCursor& lines, uint64_t& vertex_count, uint64_t& face_count,
                     std::string& error) {
    std::string_view rest, keyword, count;
    if (!next_content_line(lines, rest) || !next_field(rest, keyword, false) ||
        !is_off_keyword(keyword)) {
        error = at_line(lines.line_number()) + "not an OFF file (no OFF keyword)";
        return false;
    }
    if (keyword.find_first_of("4n") != std::string_view::npos) {
        error = at_line(lines.line_number()) + quote(keyword) + " files are not supported";
        return false;
    }
    std::string_view probe = rest;
    if (!next_field(probe, count, false) && !next_content_line(lines, rest)) {
        error = at_line(lines.line_number()) + "the vertex count is missing";
        return false;
    }
    next_field(rest, count, false);
    if (count == "BINARY") {
        error = at_line(lines.line_number()) + "binary OFF files are not supported";
        return false;
    }
    CountParse parsed = parse_count(count, vertex_count);
    if (parsed != CountParse::ok) {
        error = at_line(lines.line_number()) + "the vertex count " + quote(count) + " " +
                count_problem(parsed);
        return false;
    }
    std::string_view faces;
    parsed = next_field(rest, faces, false) ? parse_count(faces, face_count)
                                            : CountParse::not_a_number;
    if (parsed == CountParse::ok) return true;
    error = at_line(lines.line_number()) + "the face count " + quote(faces) + " " +
            count_problem(parsed) + " (the counts line is 'vertices faces edges')";
    return false;
}

// The lines of a column file (XYZ, PTS, TXT, CSV): a point per line, except blank and
// comment lines and a first line of column names. A file whose first line with a number
// is a single whole number is PTS: each such count line announces the points up to the
// next one (scans joined one after another), and each must count them exactly.
// The first point line decides how the file's lines split: at which separator
// (column_separator) and into how many fields, the same on every point line. The first
// number with a decimal mark decides the mark of the others.
class ColumnRows {
public:
    // Appends the line's point, if it has one; false with a message on a bad line.
    bool take(std::string_view line, size_t line_number, std::vector<double>& xyz,
              std::string& error) {
        std::string_view content = strip_comment(line, true), probe = content, field;
        if (!next_field(probe, field, false)) return true;
        const bool first_content = first_content_;
        first_content_ = false;
        if (first_content && is_column_names(content)) return true;
        const bool first = first_number_;
        first_number_ = false;
        uint64_t count = 0;
        if ((first || counted_) && is_count_line(content, count)) {
            if (!finish(error)) return false;
            counted_ = true;
            count_ = count;
            count_line_ = line_number;
            points_ = 0;
            return true;
        }
        if (separator_ == 0) {
            separator_ = column_separator(content);
            if (separator_ == ',') mark_ = '.';
        }
        return take_point_line(content, line_number, xyz, error);
    }

    // At the end of the file: false with a message if a count line was wrong.
    bool finish(std::string& error) const {
        if (!counted_ || points_ == count_) return true;
        error = at_line(count_line_) + "the count line announces " + std::to_string(count_) +
                " points, " + std::to_string(points_) + " follow";
        return false;
    }

private:
    bool take_point_line(std::string_view content, size_t line, std::vector<double>& xyz,
                         std::string& error) {
        const char mark_before = mark_;
        const NumberRow row = scan_numbers(content, separator_, mark_);
        if (mark_before == kEitherMark && mark_ != kEitherMark) mark_line_ = line;
        std::string problem;
        if (row.empty == 0 && fields_ > 0 && row.fields != fields_)
            problem = "splits into " + std::to_string(row.fields) +
                      (row.fields == 1 ? " field at " : " fields at ") +
                      separator_name(separator_) + ", where line " + std::to_string(fields_line_) +
                      " splits into " + std::to_string(fields_);
        else
            problem = point_problem(row, mark_, mark_line_);
        if (!problem.empty()) {
            error = at_line(line) + (fields_ == 0 ? "read as XYZ text (x y z columns), but " : "") +
                    problem;
            return false;
        }
        if (fields_ == 0) {
            fields_ = row.fields;
            fields_line_ = line;
        }
        ++points_;
        xyz.insert(xyz.end(), row.first, row.first + 3);
        return true;
    }

    bool first_content_ = true;
    bool first_number_ = true;
    bool counted_ = false; // PTS: count lines start the blocks
    uint64_t count_ = 0, points_ = 0;
    size_t count_line_ = 0;
    char separator_ = 0;          // ' ' (blanks), ',' or ';'; 0 until the first point line
    char mark_ = kEitherMark;     // the decimal mark
    size_t mark_line_ = 0;        // the line whose number decided it (0: the separator did)
    size_t fields_ = 0;           // on every point line; 0 until the first
    size_t fields_line_ = 0;      // the first point line
};

// Appends the point of an OBJ "v" line and counts "f" lines; other lines are ignored.
bool take_obj_line(std::string_view line, size_t line_number, std::vector<double>& xyz,
                   uint64_t& faces, std::string& error) {
    std::string_view rest = strip_comment(line, false), keyword;
    if (!next_field(rest, keyword, false)) return true;
    if (keyword == "f") ++faces;
    if (keyword != "v") return true;
    return take_point(rest, line_number, xyz, error);
}

// The points of a column or OBJ file read line by line through a window (--stream).
class TextPoints : public PointReader {
public:
    TextPoints(std::unique_ptr<FileWindow> file, bool obj) : file_(std::move(file)), obj_(obj) {}

    bool next(double xyz[3], std::string& error) override {
        std::string_view line;
        point_.clear();
        while (point_.empty()) {
            if (!lines_.next(line)) {
                error = lines_.failure();
                if (error.empty() && !obj_) columns_.finish(error);
                return false;
            }
            const size_t number = lines_.line_number();
            bool ok = obj_ ? take_obj_line(line, number, point_, faces_, error)
                           : columns_.take(line, number, point_, error);
            if (!ok) return false;
        }
        for (size_t k = 0; k < 3; ++k) xyz[k] = point_[k];
        return true;
    }

    uint64_t faces_ignored() const override { return faces_; }

private:
    std::unique_ptr<FileWindow> file_;
    bool obj_;
    WindowLines lines_{*file_};
    ColumnRows columns_;
    std::vector<double> point_;
    uint64_t faces_ = 0;
};

} // namespace

bool is_off_keyword(std::string_view token) {
    const std::string_view suffix = "OFF";
    if (token.size() < suffix.size() || token.substr(token.size() - suffix.size()) != suffix)
        return false;
    std::string_view prefix = token.substr(0, token.size() - suffix.size());
    if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
    for (char optional : {'C', 'N', '4', 'n'})
        if (!prefix.empty() && prefix[0] == optional) prefix.remove_prefix(1);
    return prefix.empty();
}

bool read_xyz(std::string_view data, std::vector<double>& xyz, std::string& error) {
    LineCursor lines(data);
    std::string_view line;
    ColumnRows rows;
    xyz.clear();
    if (!check_line_ends(data, 1, error)) return false;
    while (lines.next(line))
        if (!rows.take(line, lines.line_number(), xyz, error)) return false;
    if (!rows.finish(error)) return false;
    if (!xyz.empty()) return true;
    error = "no points found: read as XYZ text (x y z columns), no line holds a point";
    return false;
}

bool read_off(std::string_view data, std::vector<double>& xyz, std::string& error,
              uint64_t& faces) {
    LineCursor lines(data);
    uint64_t vertex_count = 0;
    xyz.clear();
    faces = 0;
    return check_line_ends(data, 1, error) && read_off_header(lines, vertex_count, faces, error) &&
           read_off_vertices(lines, vertex_count, xyz, error) &&
           read_off_faces(lines, faces, vertex_count, error);
}

bool read_obj(std::string_view data, std::vector<double>& xyz, std::string& error,
              uint64_t& faces) {
    LineCursor lines(data);
    std::string_view line;
    xyz.clear();
    faces = 0;
    if (!check_line_ends(data, 1, error)) return false;
    while (lines.next(line))
        if (!take_obj_line(line, lines.line_number(), xyz, faces, error)) return false;
    if (!xyz.empty()) return true;
    error = "no vertices found (no 'v' line)";
    return false;
}

std::unique_ptr<PointReader> open_text_points(std::unique_ptr<FileWindow> file, bool obj) {
    return std::make_unique<TextPoints>(std::move(file), obj);
}

} // namespace stratmesh_cli
