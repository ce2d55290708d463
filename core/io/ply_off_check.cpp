#include "core/io/ply_off_check.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string_view>
#include <vector>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/util/memory_budget.hpp"

namespace gilab {

namespace {

// Memory per item once loaded: CGAL's Point_3<double> and our float position; CGAL's
// per-face std::vector with its heap block; per corner CGAL's size_t plus our share of
// the face's triangles and material ids.
constexpr uint64_t kVertexMemory = 24 + 12;
constexpr uint64_t kFaceMemory = 24 + 16;
constexpr uint64_t kCornerMemory = 8 + 16;

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

std::vector<std::string_view> split(std::string_view line) {
    std::vector<std::string_view> tokens;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_blank(line[i])) ++i;
        const size_t b = i;
        while (i < line.size() && !is_blank(line[i])) ++i;
        if (i > b) tokens.push_back(line.substr(b, i - b));
    }
    return tokens;
}

// An index or count read as a double, printed as an integer when it is one and as
// read otherwise.
std::string number_text(double v) {
    if (v == std::floor(v) && std::abs(v) < 1e18) return std::to_string(int64_t(v));
    return number_as_given(v);
}

std::string quote(std::string_view t) {
    return "'" + std::string(t.substr(0, 40)) + (t.size() > 40 ? "...'" : "'");
}

std::optional<int64_t> parse_int(std::string_view t) {
    if (!t.empty() && t.front() == '+') t.remove_prefix(1);
    int64_t v = 0;
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || p != t.data() + t.size()) return std::nullopt;
    return v;
}

std::optional<uint64_t> parse_count(std::string_view t) {
    uint64_t v = 0;
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || p != t.data() + t.size()) return std::nullopt;
    return v;
}

std::optional<double> parse_real(std::string_view t) {
    if (!t.empty() && t.front() == '+') t.remove_prefix(1);
    double v = 0;
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (p != t.data() + t.size() || (ec != std::errc() && ec != std::errc::result_out_of_range)) return std::nullopt;
    if (ec == std::errc::result_out_of_range) return std::abs(v) < 1 ? 0.0 : std::copysign(INFINITY, v);
    return v;
}

// ---------------------------------------------------------------- PLY

enum class Kind { Signed, Unsigned, Real };
struct ScalarType {
    int size = 0;
    Kind kind = Kind::Signed;
};

std::optional<ScalarType> scalar_type(std::string_view name) {
    struct Entry {
        const char* a;
        const char* b;
        ScalarType t;
    };
    static const Entry table[] = {
        {"char", "int8", {1, Kind::Signed}},     {"uchar", "uint8", {1, Kind::Unsigned}},
        {"short", "int16", {2, Kind::Signed}},   {"ushort", "uint16", {2, Kind::Unsigned}},
        {"int", "int32", {4, Kind::Signed}},     {"uint", "uint32", {4, Kind::Unsigned}},
        {"float", "float32", {4, Kind::Real}},   {"double", "float64", {8, Kind::Real}},
    };
    for (const Entry& e : table)
        if (name == e.a || name == e.b) return e.t;
    return std::nullopt;
}

struct Property {
    std::string name;
    ScalarType type;
    bool list = false;
    ScalarType count_type;
};

struct Element {
    std::string name;
    uint64_t count = 0;
    std::vector<Property> properties;
};

enum class Format { Ascii, LittleEndian, BigEndian };

// CGAL reads both spellings of the two elements.
bool is_vertex_element(const Element& e) { return e.name == "vertex" || e.name == "vertices"; }
bool is_face_element(const Element& e) { return e.name == "face" || e.name == "faces"; }

bool is_face_list(const Element& e, const Property& p) {
    return is_face_element(e) && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
}
bool is_coordinate(const Element& e, const Property& p) {
    return is_vertex_element(e) && !p.list && (p.name == "x" || p.name == "y" || p.name == "z");
}
bool is_colour(const Property& p) {
    return p.name == "red" || p.name == "green" || p.name == "blue" || p.name == "r" || p.name == "g" || p.name == "b";
}
bool is_uchar(const Property& p) { return !p.list && p.type.size == 1 && p.type.kind == Kind::Unsigned; }

// CGAL looks the properties it reads up by name and casts them to the type it expects
// without checking (a null pointer when the file disagrees, found by fuzzing): x, y, z
// must be float or double, the face indices a list of integers, and when one colour
// property is uchar (which makes CGAL read colours) all of them must be.
void check_properties_cgal_reads(const Element& e, const std::string& where) {
    if (!is_vertex_element(e) && !is_face_element(e)) return;
    bool uchar_colour = false;
    for (size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        for (size_t j = 0; j < i; ++j)
            if (e.properties[j].name == p.name)
                throw Error(where, "element '" + e.name + "' declares property '" + p.name + "' twice");
        uchar_colour = uchar_colour || (is_colour(p) && is_uchar(p));
    }
    for (const Property& p : e.properties) {
        const bool coordinate_name = is_vertex_element(e) && (p.name == "x" || p.name == "y" || p.name == "z");
        if (coordinate_name && (p.list || p.type.kind != Kind::Real))
            throw Error(where, "vertex property '" + p.name + "' must be a float or double number (gilab reads "
                               "real-valued coordinates only)");
        const bool index_name = is_face_element(e) && (p.name == "vertex_indices" || p.name == "vertex_index");
        if (index_name && (!p.list || p.type.kind == Kind::Real))
            throw Error(where, "face property '" + p.name + "' must be a list of integers");
        if (uchar_colour && is_colour(p) && !is_uchar(p))
            throw Error(where, "element '" + e.name + "' mixes uchar and other colour properties ('" + p.name +
                                   "' is not uchar); use one type for red, green and blue");
    }
}

class PlyChecker {
public:
    PlyChecker(const std::string& bytes, const std::string& file) : bytes_(bytes), file_(file) {}

    PolygonFileCounts run() {
        read_header();
        check_declared_counts();
        if (format_ == Format::Ascii) walk_ascii();
        else walk_binary();
        MemoryBudget::check(MemoryBudget::times(counts_.vertices, kVertexMemory) +
                                MemoryBudget::times(counts_.faces, kFaceMemory) +
                                MemoryBudget::times(counts_.corners, kCornerMemory),
                            "loading " + std::to_string(counts_.vertices) + " vertices and " +
                                std::to_string(counts_.faces) + " faces (" + std::to_string(counts_.corners) + " corners)",
                            file_);
        return counts_;
    }

private:
    const std::string& bytes_;
    const std::string& file_;
    Format format_ = Format::Ascii;
    std::vector<Element> elements_;
    size_t data_ = 0;  // first byte after the header
    PolygonFileCounts counts_;
    size_t free_text_lines_ = 0;

    std::string at_line(size_t line) const { return file_ + ":" + std::to_string(line); }
    std::string at_byte(size_t offset) const { return file_ + " (byte " + std::to_string(offset) + ")"; }

    [[noreturn]] void truncated(const Element& e, uint64_t record) const {
        throw Error(file_, "truncated PLY: the file ends in element '" + e.name + "' at record " + std::to_string(record) +
                               " of " + std::to_string(e.count));
    }

    void read_header() {
        const std::string malformed = "malformed PLY: no 'ply' magic line or no 'end_header'";
        size_t pos = 0, line_no = 0;
        auto next_line = [&](std::string_view& line) {
            if (pos >= bytes_.size()) return false;
            size_t end = bytes_.find('\n', pos);
            if (end == std::string::npos) end = bytes_.size();
            line = std::string_view(bytes_).substr(pos, end - pos);
            if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
            pos = std::min(end + 1, bytes_.size());
            ++line_no;
            return true;
        };
        std::string_view line;
        if (!next_line(line) || line != "ply") throw Error(file_, malformed);
        bool has_format = false;
        while (next_line(line)) {
            const auto t = split(line);
            if (t.empty()) continue;
            const std::string where = at_line(line_no);
            if (t[0] == "end_header") {
                if (!has_format) throw Error(where, "malformed PLY: no 'format' line before 'end_header'");
                data_ = pos;
                for (const Element& e : elements_) {
                    check_properties_cgal_reads(e, file_);
                    if (is_vertex_element(e)) counts_.vertices = e.count;
                    if (is_face_element(e)) counts_.faces = e.count;
                }
                return;
            }
            if (t[0] == "comment" || t[0] == "obj_info") continue;
            if (t[0] == "format") {
                if (t.size() < 2) throw Error(where, "malformed PLY: 'format' without a format");
                if (t[1] == "ascii") format_ = Format::Ascii;
                else if (t[1] == "binary_little_endian") format_ = Format::LittleEndian;
                else if (t[1] == "binary_big_endian") format_ = Format::BigEndian;
                else throw Error(where, "unknown PLY format " + quote(t[1]) + " (expected ascii, binary_little_endian or binary_big_endian)");
                if (t.size() >= 3 && t[2] != "1.0")
                    throw Error(where, "PLY version " + quote(t[2]) + " is not supported (only 1.0)");
                has_format = true;
            } else if (t[0] == "element") {
                if (t.size() != 3) throw Error(where, "malformed PLY: 'element' needs a name and a count");
                auto count = parse_count(t[2]);
                if (!count)
                    throw Error(where, "element '" + std::string(t[1]) + "' count " + quote(t[2]) +
                                           " is not a non-negative integer");
                elements_.push_back({std::string(t[1]), *count, {}});
            } else if (t[0] == "property") {
                if (elements_.empty()) throw Error(where, "malformed PLY: 'property' before any 'element'");
                Property p;
                if (t.size() >= 2 && t[1] == "list") {
                    if (t.size() != 5) throw Error(where, "malformed PLY: 'property list' needs a count type, an item type and a name");
                    auto ct = scalar_type(t[2]);
                    auto it = scalar_type(t[3]);
                    if (!ct || ct->kind == Kind::Real)
                        throw Error(where, "property '" + std::string(t[4]) + "': list count type " + quote(t[2]) + " is not an integer type");
                    if (!it) throw Error(where, "property '" + std::string(t[4]) + "': unknown item type " + quote(t[3]));
                    p = {std::string(t[4]), *it, true, *ct};
                } else {
                    if (t.size() != 3) throw Error(where, "malformed PLY: 'property' needs a type and a name");
                    auto type = scalar_type(t[1]);
                    if (!type) throw Error(where, "property '" + std::string(t[2]) + "': unknown type " + quote(t[1]));
                    p = {std::string(t[2]), *type, false, {}};
                }
                elements_.back().properties.push_back(p);
            } else {
                note_free_text(where, t[0]);
            }
        }
        throw Error(file_, malformed);
    }

    // Free text in the header: one note per line for the first few, then a count (a
    // header of a million such lines must not make a million warnings).
    void note_free_text(const std::string& where, std::string_view first_word) {
        constexpr size_t kNotedLines = 5;
        ++free_text_lines_;
        if (free_text_lines_ <= kNotedLines)
            counts_.warnings.push_back(where + ": header line starting with " + quote(first_word) +
                                       " is not a PLY keyword; ignored");
        else if (free_text_lines_ == kNotedLines + 1)
            counts_.warnings.push_back(file_ + ": further header lines that are no PLY keyword ignored");
    }

    // Each element's count against the bytes after the header and the budget, before
    // any record is read.
    void check_declared_counts() const {
        const uint64_t left = bytes_.size() - data_;
        uint64_t used = 0;
        for (const Element& e : elements_) {
            uint64_t record = 0;
            for (const Property& p : e.properties)
                record += format_ == Format::Ascii ? 2 : uint64_t(p.list ? p.count_type.size : p.type.size);
            const uint64_t memory = e.name == "vertex" ? kVertexMemory : e.name == "face" ? kFaceMemory : 0;
            // A text record's last token needs no separator at the very end of the file; a
            // record of no properties still cannot be counted beyond the file's size.
            MemoryBudget::check_count(e.count, std::max<uint64_t>(record, 1), left - std::min(used, left) + (format_ == Format::Ascii ? 1 : 0),
                                      memory, "element '" + e.name + "' count", file_);
            used += e.count * record;  // cannot overflow: bounded by the file size just checked
        }
    }

    void check_index(double value, const Element& e, uint64_t record, const std::string& where) {
        if (!(value >= 0) || value >= double(counts_.vertices) || value != std::floor(value))
            throw Error(where, e.name + " " + std::to_string(record) + " references vertex " + number_text(value) +
                                   " but the file has " + std::to_string(counts_.vertices) + " vertices (index out of range)");
    }

    // ---- binary
    double read_binary(size_t at, ScalarType t) const {
        unsigned char raw[8];
        std::memcpy(raw, bytes_.data() + at, size_t(t.size));
        const bool swap = format_ == Format::BigEndian;
        if (swap) std::reverse(raw, raw + t.size);
        switch (t.size) {
            case 1: return t.kind == Kind::Signed ? double(int8_t(raw[0])) : double(raw[0]);
            case 2: {
                uint16_t u;
                std::memcpy(&u, raw, 2);
                return t.kind == Kind::Signed ? double(int16_t(u)) : double(u);
            }
            case 4: {
                if (t.kind == Kind::Real) {
                    float f;
                    std::memcpy(&f, raw, 4);
                    return double(f);
                }
                uint32_t u;
                std::memcpy(&u, raw, 4);
                return t.kind == Kind::Signed ? double(int32_t(u)) : double(u);
            }
            default: {
                double d;
                std::memcpy(&d, raw, 8);
                return d;
            }
        }
    }

    void walk_binary() {
        size_t at = data_;
        for (const Element& e : elements_) {
            for (uint64_t r = 0; r < e.count; ++r) {
                for (const Property& p : e.properties) {
                    if (!p.list) {
                        if (uint64_t(p.type.size) > bytes_.size() - at) truncated(e, r);
                        if (is_coordinate(e, p)) {
                            const double x = read_binary(at, p.type);
                            if (!std::isfinite(x))
                                throw Error(at_byte(at), "vertex " + std::to_string(r) + " has a non-finite coordinate " +
                                                             p.name + " = " + number_text(x));
                        }
                        at += size_t(p.type.size);
                        continue;
                    }
                    if (uint64_t(p.count_type.size) > bytes_.size() - at) truncated(e, r);
                    const double n = read_binary(at, p.count_type);
                    const std::string where = at_byte(at);
                    at += size_t(p.count_type.size);
                    const std::string field = e.name + " " + std::to_string(r) + " list '" + p.name + "' length";
                    if (n < 0) throw Error(where, field + " is " + number_text(n) + " (negative)");
                    const bool face = is_face_list(e, p);
                    MemoryBudget::check_count(uint64_t(n), uint64_t(p.type.size), bytes_.size() - at,
                                              face ? kCornerMemory : 0, field, where);
                    if (face) {
                        for (uint64_t k = 0; k < uint64_t(n); ++k, at += size_t(p.type.size))
                            check_index(read_binary(at, p.type), e, r, at_byte(at));
                        counts_.corners += uint64_t(n);
                    } else {
                        at += size_t(n) * size_t(p.type.size);
                    }
                }
            }
        }
    }

    // ---- ASCII: whitespace-separated tokens, records need not follow lines
    void walk_ascii() {
        size_t pos = data_, line = 1 + size_t(std::count(bytes_.begin(), bytes_.begin() + long(data_), '\n'));
        size_t token_line = line;
        auto next = [&]() -> std::string_view {
            while (pos < bytes_.size() && is_blank(bytes_[pos])) line += bytes_[pos++] == '\n';
            token_line = line;
            const size_t b = pos;
            while (pos < bytes_.size() && !is_blank(bytes_[pos])) ++pos;
            return std::string_view(bytes_).substr(b, pos - b);
        };
        for (const Element& e : elements_) {
            for (uint64_t r = 0; r < e.count; ++r) {
                for (const Property& p : e.properties) {
                    std::string_view tok = next();
                    if (tok.empty()) truncated(e, r);
                    const std::string where = at_line(token_line);
                    const std::string label = e.name + " " + std::to_string(r);
                    if (!p.list) {
                        auto value = parse_real(tok);
                        if (!value || (p.type.kind != Kind::Real && !parse_int(tok)))
                            throw Error(where, label + " property '" + p.name + "' value " + quote(tok) + " is not a " +
                                                   (p.type.kind == Kind::Real ? "number" : "integer"));
                        if (is_coordinate(e, p) && !std::isfinite(*value))
                            throw Error(where, "vertex " + std::to_string(r) + " has a non-finite coordinate " + p.name +
                                                   " = " + std::string(tok));
                        continue;
                    }
                    const std::string field = label + " list '" + p.name + "' length";
                    auto n = parse_int(tok);
                    if (!n || *n < 0) throw Error(where, field + " " + quote(tok) + " is not a non-negative integer");
                    const bool face = is_face_list(e, p);
                    MemoryBudget::check_count(uint64_t(*n), 2, bytes_.size() - pos + 1, face ? kCornerMemory : 0, field, where);
                    for (int64_t k = 0; k < *n; ++k) {
                        std::string_view item = next();
                        if (item.empty()) truncated(e, r);
                        auto value = parse_real(item);
                        if (!value || (p.type.kind != Kind::Real && !parse_int(item)))
                            throw Error(at_line(token_line), label + " list '" + p.name + "' item " + quote(item) + " is not a number");
                        if (face) check_index(*value, e, r, at_line(token_line));
                    }
                    if (face) counts_.corners += uint64_t(*n);
                }
            }
        }
    }
};

// ---------------------------------------------------------------- OFF

class OffChecker {
public:
    OffChecker(const std::string& bytes, const std::string& file) : bytes_(bytes), file_(file) {}

    PolygonFileCounts run() {
        std::vector<std::string_view> t;
        if (!next_line(t)) throw Error(file_, "malformed OFF: the file is empty");
        size_t first = 0;
        const std::string header_at = at_line(line_no_);
        if (t[0].size() >= 3 && t[0].substr(t[0].size() - 3) == "OFF") {
            const std::string_view prefix = t[0].substr(0, t[0].size() - 3);
            if (prefix.find('4') != std::string_view::npos || prefix.find('n') != std::string_view::npos)
                throw Error(header_at, quote(t[0]) + " (homogeneous or n-dimensional OFF) is not supported; only 3D OFF");
            if (t.size() > 1 && t[1] == "BINARY") throw Error(header_at, "binary OFF is not supported; save the file as text OFF or PLY");
            first = 1;
            keyword_offset_ = size_t(t[0].data() - bytes_.data());
            keyword_length_ = t[0].size();
        }
        // The three counts, on the header line or the next ones.
        std::vector<std::string_view> header(t.begin() + long(first), t.end());
        while (header.size() < 3) {
            std::vector<std::string_view> more;
            if (!next_line(more)) throw Error(file_, "malformed OFF: expected vertex, face and edge counts after the header");
            header.insert(header.end(), more.begin(), more.end());
        }
        const std::string where = at_line(line_no_);
        // CGAL reads the counts as numbers and then the rest of their line as the first
        // record, so anything after the third count would become a face (found by fuzzing).
        if (header.size() > 3)
            throw Error(where, "malformed OFF: " + quote(header[3]) +
                                   " follows the vertex, face and edge counts on their line");
        const char* names[] = {"vertex", "face", "edge"};
        uint64_t counts[3];
        for (int k = 0; k < 3; ++k) {
            auto c = parse_count(header[size_t(k)]);
            if (!c)
                throw Error(where, std::string("malformed OFF: ") + names[k] + " count " + quote(header[size_t(k)]) +
                                       " is not a non-negative integer");
            counts[k] = *c;
        }
        // The edge count is not used, but CGAL doubles it in a 32-bit int (found by fuzzing).
        if (counts[2] > uint64_t(INT32_MAX / 2))
            throw Error(where, "malformed OFF: edge count " + std::to_string(counts[2]) + " is larger than " +
                                   std::to_string(INT32_MAX / 2) + ", the most the OFF reader takes");
        vertices_ = counts[0];
        faces_ = counts[1];
        // The header counts need no check against the file's size here: the walk below
        // allocates nothing and stops at the exact record where a lying count runs out.
        for (uint64_t v = 0; v < vertices_; ++v) {
            if (!next_line(t)) truncated("vertex " + std::to_string(v));
            const std::string at = at_line(line_no_);
            if (t.size() < 3) throw Error(at, "vertex " + std::to_string(v) + " has fewer than 3 coordinates");
            for (size_t k = 0; k < 3; ++k) {
                auto x = parse_real(t[k]);
                if (!x) throw Error(at, "vertex " + std::to_string(v) + " coordinate " + quote(t[k]) + " is not a number");
                if (!std::isfinite(*x))
                    throw Error(at, "vertex " + std::to_string(v) + " coordinate " + quote(t[k]) + " is not finite (non-finite vertex)");
            }
        }
        PolygonFileCounts counts_out{vertices_, faces_, 0, keyword_offset_, keyword_length_, {}};
        for (uint64_t f = 0; f < faces_; ++f) {
            if (!next_line(t)) truncated("face " + std::to_string(f));
            const std::string at = at_line(line_no_);
            auto n = parse_int(t[0]);
            if (!n || *n < 0)
                throw Error(at, "face " + std::to_string(f) + " does not start with a corner count (got " + quote(t[0]) + ")");
            MemoryBudget::check_count(uint64_t(*n), 2, bytes_.size() - line_start_ + 1, kCornerMemory,
                                      "face " + std::to_string(f) + " corner count", at);
            // Corners may continue on the next lines; whatever follows them (a colour) is ignored.
            std::vector<std::string_view> corners(t.begin() + 1, t.end());
            while (corners.size() < size_t(*n)) {
                std::vector<std::string_view> more;
                if (!next_line(more))
                    throw Error(at, "truncated OFF: face " + std::to_string(f) + " declares " + std::to_string(*n) +
                                        " corners but the file ends after " + std::to_string(corners.size()));
                corners.insert(corners.end(), more.begin(), more.end());
            }
            for (int64_t k = 0; k < *n; ++k) {
                auto idx = parse_int(corners[size_t(k)]);
                if (!idx || *idx < 0 || uint64_t(*idx) >= vertices_)
                    throw Error(at, "face " + std::to_string(f) + " references vertex " + quote(corners[size_t(k)]) +
                                        " but the file has " + std::to_string(vertices_) + " vertices (index out of range)");
            }
            counts_out.corners += uint64_t(*n);
        }
        MemoryBudget::check(MemoryBudget::times(counts_out.vertices, kVertexMemory) +
                                MemoryBudget::times(counts_out.faces, kFaceMemory) +
                                MemoryBudget::times(counts_out.corners, kCornerMemory),
                            "loading " + std::to_string(counts_out.vertices) + " vertices and " +
                                std::to_string(counts_out.faces) + " faces (" + std::to_string(counts_out.corners) + " corners)",
                            file_);
        return counts_out;
    }

private:
    const std::string& bytes_;
    const std::string& file_;
    size_t pos_ = 0, line_no_ = 0, line_start_ = 0;
    uint64_t vertices_ = 0, faces_ = 0;
    size_t keyword_offset_ = 0, keyword_length_ = 0;

    std::string at_line(size_t line) const { return file_ + ":" + std::to_string(line); }

    [[noreturn]] void truncated(const std::string& what) const {
        throw Error(file_, "truncated OFF: the header declares " + std::to_string(vertices_) + " vertices and " +
                               std::to_string(faces_) + " faces, but the file (" + std::to_string(bytes_.size()) +
                               " bytes) ends before " + what);
    }

    // Tokens of the next line with content ('#' starts a comment).
    bool next_line(std::vector<std::string_view>& tokens) {
        while (pos_ < bytes_.size()) {
            size_t end = bytes_.find('\n', pos_);
            if (end == std::string::npos) end = bytes_.size();
            std::string_view line = std::string_view(bytes_).substr(pos_, end - pos_);
            line_start_ = pos_;
            pos_ = std::min(end + 1, bytes_.size());
            ++line_no_;
            const size_t hash = line.find('#');
            if (hash != std::string_view::npos) line = line.substr(0, hash);
            tokens = split(line);
            if (!tokens.empty()) return true;
        }
        return false;
    }
};

}  // namespace

PolygonFileCounts check_ply(const std::string& bytes, const std::string& file) { return PlyChecker(bytes, file).run(); }

PolygonFileCounts check_off(const std::string& bytes, const std::string& file) { return OffChecker(bytes, file).run(); }

}  // namespace gilab
