// PLY reader: ascii, binary_little_endian and binary_big_endian. The vertex element's x, y
// and z are the points; its other scalar properties (normals, colours, intensities) are
// kept as raw bytes when asked (PointAttributes), else stepped over, as are its list
// properties and every other element (faces, before or after the vertices). Stepped over
// is still checked: the whole body must match the header (docs/formats.md), an ascii
// record being one line of exactly its properties' values, each within its type.
#include "big_buffer.h"
#include "cloud_readers.h"
#include "file_window.h"
#include "text_scan.h"

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace stratmesh_cli {

namespace {

enum class PlyType : uint8_t { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

struct TypeName {
    const char* name;
    PlyType type;
};

const TypeName kTypeNames[] = {
    {"char", PlyType::int8},      {"int8", PlyType::int8},       {"uchar", PlyType::uint8},
    {"uint8", PlyType::uint8},    {"short", PlyType::int16},     {"int16", PlyType::int16},
    {"ushort", PlyType::uint16},  {"uint16", PlyType::uint16},   {"int", PlyType::int32},
    {"int32", PlyType::int32},    {"uint", PlyType::uint32},     {"uint32", PlyType::uint32},
    {"float", PlyType::float32},  {"float32", PlyType::float32}, {"double", PlyType::float64},
    {"float64", PlyType::float64}};

bool type_from_name(std::string_view name, PlyType& type) {
    for (const TypeName& t : kTypeNames) {
        if (name == t.name) {
            type = t.type;
            return true;
        }
    }
    return false;
}

size_t type_size(PlyType type) {
    switch (type) {
    case PlyType::int8:
    case PlyType::uint8: return 1;
    case PlyType::int16:
    case PlyType::uint16: return 2;
    case PlyType::int32:
    case PlyType::uint32:
    case PlyType::float32: return 4;
    case PlyType::float64: return 8;
    }
    return 8;
}

bool is_integral(PlyType type) { return type != PlyType::float32 && type != PlyType::float64; }

// The type's name as the PLY specification spells it.
const char* type_name(PlyType type) {
    for (const TypeName& t : kTypeNames)
        if (t.type == type) return t.name;
    return "?";
}

// Whether a value read from text is one the type can hold: integers (whole, as
// scan_integer reads them) within their range; floats within float's range (NaN and
// infinities too, for the library to judge); doubles anything (a literal beyond their
// range is already refused).
bool type_holds(PlyType type, double v) {
    double lowest = 0, highest = 0;
    switch (type) {
    case PlyType::int8: lowest = -128, highest = 127; break;
    case PlyType::uint8: highest = 255; break;
    case PlyType::int16: lowest = -32768, highest = 32767; break;
    case PlyType::uint16: highest = 65535; break;
    case PlyType::int32: lowest = -2147483648.0, highest = 2147483647.0; break;
    case PlyType::uint32: highest = 4294967295.0; break;
    case PlyType::float32: return !std::isfinite(v) || std::fabs(v) <= static_cast<double>(FLT_MAX);
    case PlyType::float64: return true;
    }
    return v >= lowest && v <= highest;
}

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::float32;     // the item type for a list
    PlyType count_type = PlyType::uint8; // lists only
    bool is_list = false;
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> properties;
    size_t line = 0; // of its 'element' line
};

enum class PlyEncoding { none, ascii, little_endian, big_endian };

struct PlyHeader {
    PlyEncoding encoding = PlyEncoding::none;
    std::vector<PlyElement> elements;
    size_t data_offset = 0; // first byte after "end_header\n"
    size_t data_line = 0;   // the line number there, for ascii messages
};

// Where x, y, z are: the vertex element's index and, per property, which coordinate it
// holds (-1 for none).
struct VertexLayout {
    size_t element = 0;
    std::vector<int> coordinate_of;
};

const char* encoding_name(PlyEncoding encoding) {
    switch (encoding) {
    case PlyEncoding::ascii: return "ascii";
    case PlyEncoding::little_endian: return "binary_little_endian";
    case PlyEncoding::big_endian: return "binary_big_endian";
    case PlyEncoding::none: break;
    }
    return "none";
}

std::string at_line(size_t line) { return "line " + std::to_string(line) + ": "; }
std::string at_byte(size_t offset) { return "byte " + std::to_string(offset) + ": "; }

// ---- header ------------------------------------------------------------------------------

// A header line's words; only the first kMaxWords are kept, but all are counted.
struct Words {
    static const size_t kMaxWords = 8;
    std::string_view word[kMaxWords];
    size_t count = 0;
};

Words split_words(std::string_view line) {
    Words words;
    std::string_view field;
    while (next_field(line, field, false)) {
        if (words.count < Words::kMaxWords) words.word[words.count] = field;
        ++words.count;
    }
    return words;
}

std::string unknown_type_message(std::string_view name) {
    return "unknown property type " + quote(name) +
           " (expected char, uchar, short, ushort, int, uint, float, double or int8, uint8, "
           "int16, uint16, int32, uint32, float32, float64)";
}

bool parse_format_line(const Words& words, PlyHeader& header, std::string& error) {
    if (header.encoding != PlyEncoding::none) {
        error = "a second 'format' line";
        return false;
    }
    if (words.count != 3) {
        error = "expected 'format <encoding> 1.0'";
        return false;
    }
    if (words.word[2] != "1.0") {
        error = "PLY version " + quote(words.word[2]) + " is not read (only 1.0)";
        return false;
    }
    std::string_view name = words.word[1];
    if (name == "ascii") header.encoding = PlyEncoding::ascii;
    if (name == "binary_little_endian") header.encoding = PlyEncoding::little_endian;
    if (name == "binary_big_endian") header.encoding = PlyEncoding::big_endian;
    if (header.encoding == PlyEncoding::none) {
        error = "unknown encoding " + quote(name);
        return false;
    }
    return true;
}

bool parse_element_line(const Words& words, PlyHeader& header, std::string& error) {
    if (words.count != 3) {
        error = "expected 'element <name> <count>'";
        return false;
    }
    PlyElement element;
    element.name = std::string(words.word[1]);
    for (const PlyElement& before : header.elements) {
        if (before.name == element.name) {
            error = "a second element " + quote(element.name) + " (the first is on line " +
                    std::to_string(before.line) + ")";
            return false;
        }
    }
    CountParse parsed = parse_count(words.word[2], element.count);
    if (parsed != CountParse::ok) {
        error = "the count of element " + quote(element.name) + ", " + quote(words.word[2]) + ", " +
                count_problem(parsed);
        return false;
    }
    header.elements.push_back(std::move(element));
    return true;
}

bool parse_list_property(const Words& words, PlyProperty& property, std::string& error) {
    if (words.count != 5) {
        error = "expected 'property list <count type> <item type> <name>'";
        return false;
    }
    property.is_list = true;
    property.name = std::string(words.word[4]);
    if (!type_from_name(words.word[2], property.count_type)) {
        error = unknown_type_message(words.word[2]);
        return false;
    }
    if (!is_integral(property.count_type)) {
        error = "the count type of list " + quote(property.name) + " must be an integer type";
        return false;
    }
    if (!type_from_name(words.word[3], property.type)) {
        error = unknown_type_message(words.word[3]);
        return false;
    }
    return true;
}

bool parse_property_line(const Words& words, PlyHeader& header, std::string& error) {
    if (header.elements.empty()) {
        error = "a 'property' line before any 'element' line";
        return false;
    }
    PlyProperty property;
    if (words.count >= 2 && words.word[1] == "list") {
        if (!parse_list_property(words, property, error)) return false;
    } else {
        if (words.count != 3) {
            error = "expected 'property <type> <name>'";
            return false;
        }
        if (!type_from_name(words.word[1], property.type)) {
            error = unknown_type_message(words.word[1]);
            return false;
        }
        property.name = std::string(words.word[2]);
    }
    std::vector<PlyProperty>& properties = header.elements.back().properties;
    for (const PlyProperty& before : properties) {
        if (before.name == property.name) {
            error = "a second property " + quote(property.name) + " in element " +
                    quote(header.elements.back().name);
            return false;
        }
    }
    properties.push_back(std::move(property));
    return true;
}

bool parse_header_line(const Words& words, size_t line, PlyHeader& header, std::string& error) {
    std::string_view keyword = words.word[0];
    if (keyword == "comment" || keyword == "obj_info") return true;
    if (keyword == "format") return parse_format_line(words, header, error);
    if (keyword == "element") {
        if (!parse_element_line(words, header, error)) return false;
        header.elements.back().line = line;
        return true;
    }
    if (keyword == "property") return parse_property_line(words, header, error);
    error = "unknown header keyword " + quote(keyword);
    return false;
}

// `data` from the file's first byte, a byte-order mark included.
bool parse_header(std::string_view data, PlyHeader& header, std::string& error) {
    const size_t start = data.size() - skip_byte_order_mark(data).size();
    LineCursor lines(data.substr(start));
    std::string_view line;
    const bool first = lines.next(line);
    if (first && !check_line_ends(line, 1, error)) return false;
    if (!first || line != "ply") {
        error = "line 1: not a PLY file (the first line is not 'ply')";
        return false;
    }
    while (lines.next(line)) {
        if (!check_line_ends(line, lines.line_number(), error)) return false;
        Words words = split_words(line);
        if (words.count == 0) continue;
        if (words.word[0] == "end_header") {
            header.data_offset = start + lines.offset();
            header.data_line = lines.line_number() + 1;
            if (header.encoding != PlyEncoding::none) return true;
            error = at_line(lines.line_number()) + "the header has no 'format' line";
            return false;
        }
        if (!parse_header_line(words, lines.line_number(), header, error)) {
            error = at_line(lines.line_number()) + error;
            return false;
        }
    }
    error = at_line(lines.line_number()) + "the header never ends (no 'end_header' line)";
    return false;
}

bool find_vertex_layout(const PlyHeader& header, VertexLayout& layout, std::string& error) {
    size_t e = 0;
    while (e < header.elements.size() && header.elements[e].name != "vertex") ++e;
    if (e == header.elements.size()) {
        error = "the header declares no 'vertex' element";
        return false;
    }
    const std::vector<PlyProperty>& properties = header.elements[e].properties;
    layout.element = e;
    layout.coordinate_of.assign(properties.size(), -1);
    const char* const names[3] = {"x", "y", "z"};
    for (int c = 0; c < 3; ++c) {
        size_t p = 0;
        while (p < properties.size() && properties[p].name != names[c]) ++p;
        if (p == properties.size()) {
            error = std::string("the vertex element has no '") + names[c] + "' property";
            return false;
        }
        if (properties[p].is_list) {
            error = std::string("the vertex property '") + names[c] + "' is a list";
            return false;
        }
        layout.coordinate_of[p] = c;
    }
    return true;
}

// ---- binary body -------------------------------------------------------------------------

bool host_is_little_endian() {
    const uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    return first == 1;
}

template <class T> T load_as(const unsigned char* bytes) {
    T value;
    std::memcpy(&value, bytes, sizeof value);
    return value;
}

// Reads the binary body from a start offset; never reads past the end.
class ByteReader {
public:
    ByteReader(std::string_view data, size_t start, bool big_endian)
        : data_(reinterpret_cast<const unsigned char*>(data.data())), size_(data.size()),
          pos_(start), swap_(big_endian == host_is_little_endian()), big_endian_(big_endian) {}

    size_t offset() const { return pos_; }
    uint64_t remaining() const { return size_ - pos_; }
    const unsigned char* here() const { return data_ + pos_; }

    bool skip(uint64_t bytes) {
        if (bytes > remaining()) return false;
        pos_ += static_cast<size_t>(bytes);
        return true;
    }

    bool scalar(PlyType type, double& value) {
        unsigned char bytes[8];
        if (!take(type_size(type), bytes)) return false;
        value = decode(type, bytes);
        return true;
    }

    // The next `n` bytes, one value, into `out` in little-endian order.
    bool little_endian(size_t n, unsigned char* out) {
        if (n > remaining()) return false;
        for (size_t i = 0; i < n; ++i) out[i] = data_[pos_ + (big_endian_ ? n - 1 - i : i)];
        pos_ += n;
        return true;
    }

private:
    bool take(size_t n, unsigned char* out) {
        if (n > remaining()) return false;
        for (size_t i = 0; i < n; ++i) out[i] = data_[pos_ + (swap_ ? n - 1 - i : i)];
        pos_ += n;
        return true;
    }

    static double decode(PlyType type, const unsigned char* bytes) {
        switch (type) {
        case PlyType::int8: return load_as<int8_t>(bytes);
        case PlyType::uint8: return load_as<uint8_t>(bytes);
        case PlyType::int16: return load_as<int16_t>(bytes);
        case PlyType::uint16: return load_as<uint16_t>(bytes);
        case PlyType::int32: return load_as<int32_t>(bytes);
        case PlyType::uint32: return load_as<uint32_t>(bytes);
        case PlyType::float32: return static_cast<double>(load_as<float>(bytes));
        case PlyType::float64: return load_as<double>(bytes);
        }
        return 0;
    }

    const unsigned char* data_;
    size_t size_;
    size_t pos_;
    bool swap_;
    bool big_endian_;
};

std::string record_place(const PlyElement& element, uint64_t record) {
    return "element " + quote(element.name) + " record " + std::to_string(record) + " of " +
           std::to_string(element.count);
}

std::string truncated_in(const ByteReader& in, const PlyElement& element, uint64_t record) {
    return at_byte(in.offset()) + "the file ends inside " + record_place(element, record);
}

bool skip_binary_list(ByteReader& in, const PlyElement& element, const PlyProperty& property,
                      uint64_t record, std::string& error) {
    size_t at = in.offset();
    double length = 0;
    if (!in.scalar(property.count_type, length)) {
        error = truncated_in(in, element, record);
        return false;
    }
    if (length < 0) {
        error = at_byte(at) + "list " + quote(property.name) + " has a negative length (" +
                record_place(element, record) + ")";
        return false;
    }
    // The count type is an integer of at most 32 bits: the product cannot overflow.
    if (in.skip(static_cast<uint64_t>(length) * type_size(property.type))) return true;
    error = truncated_in(in, element, record);
    return false;
}

// Reads one record; scalars whose coordinate_of entry is 0..2 land in xyz[that], the other
// scalars, if `kept` is given, one after another there as little-endian bytes.
bool read_binary_record(ByteReader& in, const PlyElement& element,
                        const std::vector<int>& coordinate_of, double* xyz, uint64_t record,
                        std::string& error, unsigned char* kept = nullptr) {
    for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (property.is_list) {
            if (!skip_binary_list(in, element, property, record, error)) return false;
            continue;
        }
        const size_t size = type_size(property.type);
        bool ok = true;
        if (coordinate_of[p] >= 0) {
            ok = in.scalar(property.type, xyz[coordinate_of[p]]);
        } else if (kept) {
            ok = in.little_endian(size, kept);
            kept += size;
        } else {
            ok = in.skip(size);
        }
        if (!ok) {
            error = truncated_in(in, element, record);
            return false;
        }
    }
    return true;
}

// The size of one record if the element has no list property; 0 otherwise.
uint64_t fixed_record_size(const PlyElement& element) {
    uint64_t size = 0;
    for (const PlyProperty& property : element.properties) {
        if (property.is_list) return 0;
        size += type_size(property.type);
    }
    return size;
}

// For fixed-size records: are all the claimed bytes really there?
bool check_claimed_size(const ByteReader& in, const PlyElement& element, std::string& error) {
    uint64_t size = fixed_record_size(element);
    if (size == 0 || element.count <= in.remaining() / size) return true;
    error = at_byte(in.offset()) + "element " + quote(element.name) + " declares " +
            std::to_string(element.count) + " records of " + std::to_string(size) +
            " bytes, but only " + std::to_string(in.remaining()) + " bytes follow";
    return false;
}

bool skip_binary_element(ByteReader& in, const PlyElement& element, std::string& error) {
    if (element.properties.empty()) return true;
    if (!check_claimed_size(in, element, error)) return false;
    uint64_t size = fixed_record_size(element);
    if (size > 0) return in.skip(element.count * size);
    std::vector<int> none(element.properties.size(), -1);
    double unused[3];
    for (uint64_t r = 0; r < element.count; ++r)
        if (!read_binary_record(in, element, none, unused, r, error)) return false;
    return true;
}

// ---- binary fast path: vertex records of one fixed size ---------------------------------
// Each coordinate is a column of the record array: a loop per coordinate type and byte
// order converts a batch of records into a small staging block, which is appended to the
// points whole. That is several times faster than read_binary_record's dispatch on every
// property of every record, which remains for records holding lists.

template <size_t Size> struct BitsOf;
template <> struct BitsOf<1> { using type = uint8_t; };
template <> struct BitsOf<2> { using type = uint16_t; };
template <> struct BitsOf<4> { using type = uint32_t; };
template <> struct BitsOf<8> { using type = uint64_t; };

// The compiler turns the shifts into one byte-swap instruction.
inline uint8_t reverse_bytes(uint8_t v) { return v; }
inline uint16_t reverse_bytes(uint16_t v) { return static_cast<uint16_t>((v >> 8) | (v << 8)); }
inline uint32_t reverse_bytes(uint32_t v) {
    return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}
inline uint64_t reverse_bytes(uint64_t v) {
    return (uint64_t{reverse_bytes(static_cast<uint32_t>(v))} << 32) |
           reverse_bytes(static_cast<uint32_t>(v >> 32));
}

// Reads `count` values of type T, `stride` bytes apart from `first`, into every third
// double of `out`.
template <class T, bool Swap>
void convert_column(const unsigned char* first, size_t stride, size_t count, double* out) {
    using Bits = typename BitsOf<sizeof(T)>::type;
    for (size_t i = 0; i < count; ++i) {
        Bits bits;
        std::memcpy(&bits, first + i * stride, sizeof bits);
        if (Swap) bits = reverse_bytes(bits);
        T value;
        std::memcpy(&value, &bits, sizeof value);
        out[3 * i] = static_cast<double>(value);
    }
}

using ColumnConverter = void (*)(const unsigned char*, size_t, size_t, double*);

template <bool Swap> ColumnConverter column_converter(PlyType type) {
    switch (type) {
    case PlyType::int8: return convert_column<int8_t, Swap>;
    case PlyType::uint8: return convert_column<uint8_t, Swap>;
    case PlyType::int16: return convert_column<int16_t, Swap>;
    case PlyType::uint16: return convert_column<uint16_t, Swap>;
    case PlyType::int32: return convert_column<int32_t, Swap>;
    case PlyType::uint32: return convert_column<uint32_t, Swap>;
    case PlyType::float32: return convert_column<float, Swap>;
    case PlyType::float64: break;
    }
    return convert_column<double, Swap>;
}

// Copies the kept properties of `count` records, `record_size` bytes each from `records`,
// to the end of attributes.bytes, each value little-endian.
void keep_fixed_attributes(const unsigned char* records, size_t count, size_t record_size,
                           const PlyElement& element, const VertexLayout& layout,
                           bool big_endian, PointAttributes& attributes) {
    struct Field {
        size_t from, size;
    };
    std::vector<Field> fields;
    size_t at = 0;
    for (size_t p = 0; p < element.properties.size(); ++p) {
        const size_t size = type_size(element.properties[p].type);
        if (layout.coordinate_of[p] < 0) fields.push_back({at, size});
        at += size;
    }
    const size_t start = attributes.bytes.size();
    attributes.bytes.resize(start + count * attributes.record_bytes);
    unsigned char* out = attributes.bytes.data() + start;
    for (size_t r = 0; r < count; ++r) {
        const unsigned char* record = records + r * record_size;
        for (const Field& field : fields) {
            for (size_t i = 0; i < field.size; ++i)
                *out++ = record[field.from + (big_endian ? field.size - 1 - i : i)];
        }
    }
}

// The vertex element's records, all present (check_claimed_size) and of `record_size`
// bytes each, appended to `xyz`.
void read_fixed_vertices(ByteReader& in, const PlyElement& element, const VertexLayout& layout,
                         size_t record_size, bool swap, std::vector<double>& xyz) {
    ColumnConverter convert[3] = {};
    size_t offset[3] = {};
    size_t at = 0;
    for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyType type = element.properties[p].type;
        if (const int c = layout.coordinate_of[p]; c >= 0) {
            convert[c] = swap ? column_converter<true>(type) : column_converter<false>(type);
            offset[c] = at;
        }
        at += type_size(type);
    }
    const size_t count = static_cast<size_t>(element.count);
    xyz.reserve(xyz.size() + 3 * count);
    prefault_pages(xyz.data() + xyz.size(), 3 * count * sizeof(double));
    // A batch's records and points stay in the first-level caches.
    constexpr size_t kBatch = 1024;
    double staged[3 * kBatch];
    const unsigned char* records = in.here();
    for (size_t done = 0; done < count; done += kBatch) {
        const size_t n = count - done < kBatch ? count - done : kBatch;
        const unsigned char* first = records + done * record_size;
        for (int c = 0; c < 3; ++c) convert[c](first + offset[c], record_size, n, staged + c);
        xyz.insert(xyz.end(), staged, staged + 3 * n);
    }
    in.skip(element.count * record_size);
}

bool read_binary_vertices(ByteReader& in, const PlyElement& element, const VertexLayout& layout,
                          bool big_endian, std::vector<double>& xyz, PointAttributes* attributes,
                          std::string& error) {
    if (!check_claimed_size(in, element, error)) return false;
    if (const uint64_t size = fixed_record_size(element); size > 0) {
        if (attributes)
            keep_fixed_attributes(in.here(), static_cast<size_t>(element.count),
                                  static_cast<size_t>(size), element, layout, big_endian,
                                  *attributes);
        read_fixed_vertices(in, element, layout, static_cast<size_t>(size),
                            big_endian == host_is_little_endian(), xyz);
        return true;
    }
    std::vector<unsigned char> kept(attributes ? attributes->record_bytes : 0);
    for (uint64_t r = 0; r < element.count; ++r) {
        double point[3] = {0, 0, 0};
        if (!read_binary_record(in, element, layout.coordinate_of, point, r, error,
                                attributes ? kept.data() : nullptr))
            return false;
        xyz.insert(xyz.end(), point, point + 3);
        if (attributes) attributes->bytes.insert(attributes->bytes.end(), kept.begin(), kept.end());
    }
    return true;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// After a binary body: nothing, or line ends and spaces (some writers end the file with a
// newline). Anything else means the header does not describe the file.
std::string trailing_bytes_message(uint64_t offset, uint64_t count, const PlyHeader& header) {
    return at_byte(static_cast<size_t>(offset)) + std::to_string(count) +
           " bytes follow the last element (" + quote(header.elements.back().name) +
           "): the header does not describe the whole file";
}

bool read_binary_body(std::string_view data, const PlyHeader& header, const VertexLayout& layout,
                      std::vector<double>& xyz, PointAttributes* attributes, std::string& error) {
    ByteReader in(data, header.data_offset, header.encoding == PlyEncoding::big_endian);
    for (size_t e = 0; e < header.elements.size(); ++e) {
        bool ok = e == layout.element
                      ? read_binary_vertices(in, header.elements[e], layout,
                                             header.encoding == PlyEncoding::big_endian, xyz,
                                             attributes, error)
                      : skip_binary_element(in, header.elements[e], error);
        if (!ok) return false;
    }
    for (size_t at = in.offset(); at < data.size(); ++at) {
        if (is_space(data[at])) continue;
        error = trailing_bytes_message(in.offset(), in.remaining(), header);
        return false;
    }
    return true;
}

// ---- ascii body --------------------------------------------------------------------------
// A record is one line holding exactly its properties' values (a list: its length, then
// that many items). The readers take any line source: BodyLines over the whole file, or
// WindowLines over a window of it (--stream).

// The lines of an ascii body held in memory, numbered as in the file.
class BodyLines {
public:
    BodyLines(std::string_view body, size_t first_line) : lines_(body), first_(first_line) {}
    bool next(std::string_view& line) { return lines_.next(line); }
    size_t line_number() const { return first_ + lines_.line_number() - 1; }

private:
    LineCursor lines_;
    size_t first_;
};

std::string property_place(const PlyElement& element, const PlyProperty& property,
                           uint64_t record) {
    return "property " + quote(property.name) + " of " + record_place(element, record);
}

// `token` as a value of the integer type `type`; why it is none, if it is none.
std::string integer_problem(std::string_view token, PlyType type, double& value) {
    bool negative = false;
    uint64_t magnitude = 0;
    const IntegerParse parsed = scan_integer(token, negative, magnitude);
    if (parsed == IntegerParse::not_an_integer) {
        char point = '.';
        const NumberParse as_number = scan_number(token, point, value);
        if (as_number != NumberParse::ok) return number_problem(token, as_number, '.');
        return quote(token) + " is not an integer (digits with an optional sign), as " +
               type_name(type) + " requires";
    }
    value = negative ? -static_cast<double>(magnitude) : static_cast<double>(magnitude);
    if (parsed == IntegerParse::ok && type_holds(type, value)) return std::string();
    return quote(token) + " is out of the range of " + type_name(type);
}

// The next value of a record's line, checked against `type`.
bool next_ascii_value(std::string_view& rest, size_t line, const PlyElement& element,
                      const PlyProperty& property, PlyType type, uint64_t record,
                      double& value, std::string& error) {
    std::string_view token;
    NumberParse parsed = NumberParse::ok;
    char point = '.';
    const bool more = is_integral(type) ? next_field(rest, token, false)
                                        : next_number(rest, token, value, parsed, point);
    if (!more) {
        error = at_line(line) + "the line ends before " + property_place(element, property, record);
        return false;
    }
    std::string problem;
    if (is_integral(type))
        problem = integer_problem(token, type, value);
    else if (parsed != NumberParse::ok)
        problem = number_problem(token, parsed, '.');
    else if (!type_holds(type, value))
        problem = quote(token) + " is out of the range of " + type_name(type);
    if (problem.empty()) return true;
    error = at_line(line) + problem + " (" + property_place(element, property, record) + ")";
    return false;
}

// A value read from text as its type's little-endian bytes (it is within the type's range:
// next_ascii_value checked).
unsigned char* put_little_endian(PlyType type, double value, unsigned char* out) {
    uint64_t bits = 0;
    if (type == PlyType::float32) {
        const float narrow = static_cast<float>(value);
        uint32_t narrow_bits = 0;
        std::memcpy(&narrow_bits, &narrow, sizeof narrow);
        bits = narrow_bits;
    } else if (type == PlyType::float64) {
        std::memcpy(&bits, &value, sizeof bits);
    } else {
        bits = static_cast<uint64_t>(static_cast<int64_t>(value)); // two's complement
    }
    for (size_t i = 0; i < type_size(type); ++i) *out++ = static_cast<unsigned char>(bits >> (8 * i));
    return out;
}

// Reads one record's line; as read_binary_record, the other scalars go to `kept`.
template <class Lines>
bool read_ascii_record(Lines& in, const PlyElement& element,
                       const std::vector<int>& coordinate_of, double* xyz, uint64_t record,
                       std::string& error, unsigned char* kept = nullptr) {
    std::string_view line;
    if (!in.next(line)) {
        error = at_line(in.line_number()) + "the file ends before " + record_place(element, record);
        return false;
    }
    const size_t number = in.line_number();
    std::string_view rest = line, probe = line, token;
    if (!next_field(probe, token, false)) {
        error = at_line(number) + "an empty line where " + record_place(element, record) +
                " should be";
        return false;
    }
    size_t values = 0;
    for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        double value = 0;
        if (!property.is_list) {
            if (!next_ascii_value(rest, number, element, property, property.type, record, value,
                                  error))
                return false;
            if (coordinate_of[p] >= 0)
                xyz[coordinate_of[p]] = value;
            else if (kept)
                kept = put_little_endian(property.type, value, kept);
            ++values;
            continue;
        }
        if (!next_ascii_value(rest, number, element, property, property.count_type, record,
                              value, error))
            return false;
        if (value < 0) {
            error = at_line(number) + "list " + quote(property.name) + " has a negative length (" +
                    record_place(element, record) + ")";
            return false;
        }
        const uint64_t length = static_cast<uint64_t>(value);
        for (uint64_t i = 0; i < length; ++i)
            if (!next_ascii_value(rest, number, element, property, property.type, record, value,
                                  error))
                return false;
        values += 1 + length;
    }
    size_t extra = 0;
    while (next_field(rest, token, false)) ++extra;
    if (extra == 0) return true;
    error = at_line(number) + std::to_string(values + extra) + " values where " +
            record_place(element, record) + " has " + std::to_string(values) +
            ": the header does not describe the line";
    return false;
}

template <class Lines>
bool read_ascii_element(Lines& in, const PlyElement& element,
                        const std::vector<int>& coordinate_of, std::vector<double>* xyz,
                        std::string& error, PointAttributes* attributes = nullptr) {
    if (element.properties.empty()) return true;
    std::vector<unsigned char> kept(attributes ? attributes->record_bytes : 0);
    for (uint64_t r = 0; r < element.count; ++r) {
        double point[3] = {0, 0, 0};
        if (!read_ascii_record(in, element, coordinate_of, point, r, error,
                               attributes ? kept.data() : nullptr))
            return false;
        if (xyz) xyz->insert(xyz->end(), point, point + 3);
        if (attributes) attributes->bytes.insert(attributes->bytes.end(), kept.begin(), kept.end());
    }
    return true;
}

// After the last record: only blank lines.
template <class Lines>
bool check_ascii_end(Lines& in, const PlyHeader& header, std::string& error) {
    std::string_view line, token;
    while (in.next(line)) {
        if (!next_field(line, token, false)) continue;
        uint64_t records = 0;
        for (const PlyElement& element : header.elements) records += element.count;
        error = at_line(in.line_number()) + "data after the last record (the header declares " +
                std::to_string(records) + " records in " + std::to_string(header.elements.size()) +
                (header.elements.size() == 1 ? " element" : " elements") + ")";
        return false;
    }
    return true;
}

bool read_ascii_body(std::string_view data, const PlyHeader& header, const VertexLayout& layout,
                     std::vector<double>& xyz, PointAttributes* attributes, std::string& error) {
    if (!check_line_ends(data.substr(header.data_offset), header.data_line, error)) return false;
    BodyLines in(data.substr(header.data_offset), header.data_line);
    for (size_t e = 0; e < header.elements.size(); ++e) {
        const PlyElement& element = header.elements[e];
        bool ok = true;
        if (e == layout.element) {
            ok = read_ascii_element(in, element, layout.coordinate_of, &xyz, error, attributes);
        } else {
            std::vector<int> none(element.properties.size(), -1);
            ok = read_ascii_element(in, element, none, nullptr, error);
        }
        if (!ok) return false;
    }
    return check_ascii_end(in, header, error);
}

// The vertex element's properties that PointAttributes keeps: its scalars but x, y, z.
void describe_attributes(const PlyElement& vertex, const VertexLayout& layout,
                         PointAttributes& attributes) {
    attributes = PointAttributes();
    for (size_t p = 0; p < vertex.properties.size(); ++p) {
        const PlyProperty& property = vertex.properties[p];
        if (property.is_list) {
            ++attributes.lists_dropped;
            continue;
        }
        if (layout.coordinate_of[p] >= 0) continue;
        PointAttributes::Property kept;
        kept.name = property.name;
        kept.type = type_name(property.type);
        kept.size = type_size(property.type);
        kept.offset = attributes.record_bytes;
        kept.integral = is_integral(property.type);
        kept.is_signed = property.type == PlyType::int8 || property.type == PlyType::int16 ||
                         property.type == PlyType::int32;
        attributes.record_bytes += kept.size;
        attributes.properties.push_back(kept);
    }
}

uint64_t face_count(const PlyHeader& header) {
    for (const PlyElement& element : header.elements)
        if (element.name == "face") return element.count;
    return 0;
}

// ---- streaming (--stream) ----------------------------------------------------------------

// The vertex element's points, one record at a time; at their end, the rest of the body
// checked against the header.
class PlyPoints : public PointReader {
public:
    PlyPoints(std::unique_ptr<FileWindow> file, PlyHeader header, VertexLayout layout)
        : file_(std::move(file)), header_(std::move(header)), layout_(std::move(layout)),
          lines_(*file_) {}

    // Steps over the elements before the vertices.
    bool skip_to_vertices(std::string& error) {
        for (size_t e = 0; e < layout_.element; ++e) {
            const PlyElement& element = header_.elements[e];
            if (header_.encoding == PlyEncoding::ascii) {
                std::vector<int> none(element.properties.size(), -1);
                if (!lines_read(read_ascii_element(lines_, element, none, nullptr, error), error))
                    return false;
                continue;
            }
            uint64_t size = fixed_record_size(element);
            if (size == 0 && !element.properties.empty()) {
                error = "element " + quote(element.name) +
                        " comes before the vertices and has list properties: it cannot be "
                        "stepped over without reading it whole";
                return false;
            }
            if (!discard_records(element, size, error)) return false;
        }
        return true;
    }

    bool next(double xyz[3], std::string& error) override {
        const PlyElement& vertex = header_.elements[layout_.element];
        if (record_ == vertex.count) {
            if (!checked_rest_) {
                checked_rest_ = true;
                if (!check_rest(error)) return false;
            }
            return false;
        }
        xyz[0] = xyz[1] = xyz[2] = 0;
        bool ok = header_.encoding == PlyEncoding::ascii
                      ? read_ascii_record(lines_, vertex, layout_.coordinate_of, xyz, record_,
                                          error)
                      : next_binary(vertex, xyz, error);
        ++record_;
        return lines_read(ok, error);
    }

    uint64_t faces_ignored() const override { return face_count(header_); }

private:
    // `ok`, unless reading the file failed or its lines have a lone carriage return: then
    // false with that failure as the error (a reader seeing no more lines says otherwise).
    bool lines_read(bool ok, std::string& error) const {
        std::string failure = lines_.failure();
        if (failure.empty()) return ok;
        error = failure;
        return false;
    }

    bool discard_records(const PlyElement& element, uint64_t size, std::string& error) {
        if (element.count <= UINT64_MAX / (size ? size : 1) && file_->discard(element.count * size))
            return true;
        error = at_byte(static_cast<size_t>(file_->offset())) + "the file ends inside element " +
                quote(element.name);
        return false;
    }

    // A binary record with lists, stepped over one property at a time.
    bool discard_binary_record(const PlyElement& element, uint64_t record, std::string& error) {
        const bool big = header_.encoding == PlyEncoding::big_endian;
        for (const PlyProperty& property : element.properties) {
            const size_t size = type_size(property.is_list ? property.count_type : property.type);
            std::string_view bytes = file_->peek(size);
            if (bytes.size() < size) {
                error = at_byte(static_cast<size_t>(file_->offset() + bytes.size())) +
                        "the file ends inside " + record_place(element, record);
                return false;
            }
            if (!property.is_list) {
                file_->skip(size);
                continue;
            }
            const size_t at = static_cast<size_t>(file_->offset());
            double length = 0;
            ByteReader in(bytes, 0, big);
            in.scalar(property.count_type, length);
            file_->skip(size);
            if (length < 0) {
                error = at_byte(at) + "list " + quote(property.name) + " has a negative length (" +
                        record_place(element, record) + ")";
                return false;
            }
            if (!file_->discard(static_cast<uint64_t>(length) * type_size(property.type))) {
                error = at_byte(static_cast<size_t>(file_->offset())) + "the file ends inside " +
                        record_place(element, record);
                return false;
            }
        }
        return true;
    }

    // The elements after the vertices, then the end of the file.
    bool check_rest(std::string& error) {
        for (size_t e = layout_.element + 1; e < header_.elements.size(); ++e) {
            const PlyElement& element = header_.elements[e];
            if (header_.encoding == PlyEncoding::ascii) {
                std::vector<int> none(element.properties.size(), -1);
                if (!lines_read(read_ascii_element(lines_, element, none, nullptr, error), error))
                    return false;
                continue;
            }
            const uint64_t size = fixed_record_size(element);
            if (size > 0 || element.properties.empty()) {
                if (!discard_records(element, size, error)) return false;
                continue;
            }
            for (uint64_t r = 0; r < element.count; ++r)
                if (!discard_binary_record(element, r, error)) return false;
        }
        if (header_.encoding == PlyEncoding::ascii)
            return lines_read(check_ascii_end(lines_, header_, error), error);
        const uint64_t end = file_->offset();
        uint64_t rest = 0;
        bool clean = true;
        for (std::string_view bytes = file_->peek(1 << 16); !bytes.empty();
             bytes = file_->peek(1 << 16)) {
            for (char c : bytes) clean = clean && is_space(c);
            rest += bytes.size();
            file_->skip(bytes.size());
        }
        if (!file_->failure().empty()) {
            error = file_->failure();
            return false;
        }
        if (clean) return true;
        error = trailing_bytes_message(end, rest, header_);
        return false;
    }

    bool next_binary(const PlyElement& vertex, double xyz[3], std::string& error) {
        size_t size = static_cast<size_t>(fixed_record_size(vertex));
        std::string_view bytes = file_->peek(size);
        if (bytes.size() < size) {
            error = at_byte(file_->offset() + bytes.size()) + "the file ends inside " +
                    record_place(vertex, record_);
            return false;
        }
        ByteReader in(bytes, 0, header_.encoding == PlyEncoding::big_endian);
        file_->skip(size);
        return read_binary_record(in, vertex, layout_.coordinate_of, xyz, record_, error);
    }

    std::unique_ptr<FileWindow> file_;
    PlyHeader header_;
    VertexLayout layout_;
    WindowLines lines_;
    uint64_t record_ = 0;
    bool checked_rest_ = false;
};

} // namespace

std::unique_ptr<PointReader> open_ply_points(std::unique_ptr<FileWindow> file, std::string& error,
                                             std::string& encoding, uint64_t& vertex_count,
                                             uint64_t& faces) {
    // The header must lie within the first block: headers are a few hundred bytes.
    const size_t kMaxHeader = 1 << 20;
    PlyHeader header;
    VertexLayout layout;
    if (!parse_header(file->peek(kMaxHeader), header, error)) return nullptr;
    if (!find_vertex_layout(header, layout, error)) {
        error = at_line(header.data_line - 1) + error;
        return nullptr;
    }
    const PlyElement& vertex = header.elements[layout.element];
    if (header.encoding != PlyEncoding::ascii && fixed_record_size(vertex) == 0) {
        error = "the vertex element has list properties: a binary PLY file with them cannot "
                "be read point by point";
        return nullptr;
    }
    encoding = encoding_name(header.encoding);
    vertex_count = vertex.count;
    faces = face_count(header);
    file->skip(header.data_offset);
    file->set_first_line(header.data_line);
    auto points =
        std::make_unique<PlyPoints>(std::move(file), std::move(header), std::move(layout));
    if (!points->skip_to_vertices(error)) return nullptr;
    return points;
}

bool read_ply(std::string_view data, std::vector<double>& xyz, std::string& error,
              std::string& encoding, uint64_t& faces, PointAttributes* attributes) {
    PlyHeader header;
    VertexLayout layout;
    if (!parse_header(data, header, error)) return false;
    if (!find_vertex_layout(header, layout, error)) {
        error = at_line(header.data_line - 1) + error;
        return false;
    }
    encoding = encoding_name(header.encoding);
    faces = face_count(header);
    xyz.clear();
    if (attributes) {
        describe_attributes(header.elements[layout.element], layout, *attributes);
        if (attributes->empty()) attributes = nullptr;
    }
    if (header.encoding == PlyEncoding::ascii)
        return read_ascii_body(data, header, layout, xyz, attributes, error);
    return read_binary_body(data, header, layout, xyz, attributes, error);
}

} // namespace stratmesh_cli
