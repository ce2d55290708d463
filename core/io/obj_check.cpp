#include "core/io/obj_check.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <string_view>
#include "core/util/error.hpp"
#include "core/util/input_file.hpp"
#include "core/util/memory_budget.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

// Bytes per item while loading: tinyobjloader's arrays (grown by doubling) and ours —
// a split vertex with normal and uv, its corner-map entry, its share of the triangles.
constexpr uint64_t kVertexMemory = 2 * 16 + 12;
constexpr uint64_t kNormalMemory = 2 * 12;
constexpr uint64_t kTexcoordMemory = 2 * 12;
constexpr uint64_t kCornerMemory = 2 * 12 + 32 + 48 + 16;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view next_token(std::string_view& rest) {
    size_t b = 0;
    while (b < rest.size() && is_space(rest[b])) ++b;
    size_t e = b;
    while (e < rest.size() && !is_space(rest[e]) && rest[e] != '#') ++e;
    std::string_view tok = rest.substr(b, e - b);
    rest = (e < rest.size() && rest[e] == '#') ? std::string_view{} : rest.substr(e);
    return tok;
}

std::string quote(std::string_view t) { return "'" + std::string(t.substr(0, 40)) + (t.size() > 40 ? "...'" : "'"); }

bool parse_float(std::string_view tok, float& out) {
    if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
    auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), out);
    if (ec == std::errc::result_out_of_range && ptr == tok.data() + tok.size()) {
        out = INFINITY;  // beyond float range: reported as not finite
        return true;
    }
    return ec == std::errc() && ptr == tok.data() + tok.size();
}

// One face corner "v", "v/vt", "v//vn" or "v/vt/vn". Indices are non-zero integers
// that fit tinyobjloader's int; negative ones count back from the vertices so far.
void check_corner(std::string_view tok, uint64_t vertices_so_far, const std::string& where) {
    const char* names[] = {"vertex", "texture coordinate", "normal"};
    size_t part = 0, start = 0;
    for (;;) {
        const size_t slash = tok.find('/', start);
        const std::string_view p = tok.substr(start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
        if (part > 2) throw Error(where, "face corner " + quote(tok) + " has more than three indices");
        if (!p.empty() || part == 0) {
            int64_t value = 0;
            const std::string_view digits = !p.empty() && p.front() == '-' ? p.substr(1) : p;
            const bool numeric = !digits.empty() && digits.find_first_not_of("0123456789") == std::string_view::npos;
            if (!numeric) throw Error(where, "face corner " + quote(tok) + ": " + names[part] + " index " + quote(p) + " is not an integer");
            auto [ptr, ec] = std::from_chars(p.data(), p.data() + p.size(), value);
            if (ec != std::errc() || value > INT32_MAX || value < -int64_t(INT32_MAX))
                throw Error(where, "face corner " + quote(tok) + ": " + names[part] + " index " + quote(p) +
                                       " is out of range (an index beyond 32 bits cannot be valid)");
            if (value == 0) throw Error(where, "face corner " + quote(tok) + ": index 0 is invalid (OBJ indices start at 1)");
            if (part == 0 && value < 0 && uint64_t(-value) > vertices_so_far)
                throw Error(where, "face corner " + quote(tok) + " references vertex " + std::to_string(value) +
                                       " but only " + std::to_string(vertices_so_far) + " vertices precede it (index out of range)");
        }
        if (slash == std::string_view::npos) return;
        start = slash + 1;
        ++part;
    }
}

}  // namespace

ObjScan scan_obj(const fs::path& path, const std::string& text) {
    const std::string file = path.string();
    check_text_encoding(text, file, "OBJ");
    ObjScan scan;
    uint32_t line_no = 0;
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        std::string_view line(text.data() + pos, end - pos);
        pos = end + 1;
        ++line_no;
        size_t b = 0;
        while (b < line.size() && is_space(line[b])) ++b;
        line.remove_prefix(b);
        if (line.size() < 2) continue;
        const std::string where = file + ":" + std::to_string(line_no);
        if (line.rfind("mtllib", 0) == 0 && line.size() > 6 && is_space(line[6])) {
            std::string_view rest = line.substr(7);
            for (std::string_view name = next_token(rest); !name.empty(); name = next_token(rest)) {
                const fs::path candidate = path.parent_path() / std::string(name);
                // tinyobjloader would read a device or FIFO without end: refuse it here.
                const std::string problem = non_regular_file_problem(candidate);
                if (!problem.empty()) throw Error(where, "material library " + quote(name) + " " + problem);
                if (regular_file_exists(candidate)) {
                    scan.material_libraries.push_back(candidate);
                    break;  // tinyobjloader reads the first one it finds
                }
            }
            continue;
        }
        if (line[0] == 'v' && line[1] == 'n' && line.size() > 2 && is_space(line[2])) ++scan.normals;
        if (line[0] == 'v' && line[1] == 't' && line.size() > 2 && is_space(line[2])) ++scan.texcoords;
        if (!is_space(line[1])) continue;
        if (line[0] == 'v') {
            std::string_view rest = line.substr(2);
            for (int k = 0; k < 3; ++k) {
                std::string_view tok = next_token(rest);
                float value = 0;
                if (tok.empty())
                    throw Error(where, "vertex has " + std::to_string(k) +
                                           " coordinates, expected 3 (malformed or truncated file)");
                if (!parse_float(tok, value))
                    throw Error(where, "vertex coordinate '" + std::string(tok) + "' is not a number");
                if (!std::isfinite(value))
                    throw Error(where, "vertex coordinate '" + std::string(tok) + "' is not finite (NaN/Inf vertex)");
            }
            ++scan.vertices;
        } else if (line[0] == 'f') {
            std::string_view rest = line.substr(2);
            int corners = 0;
            for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest)) {
                if (corners < 256) check_corner(tok, scan.vertices, where);
                ++corners;
            }
            if (corners < 3)
                throw Error(where, "face has " + std::to_string(corners) +
                                       " vertices, expected at least 3 (malformed or truncated file)");
            if (corners > 255) throw Error(where, "face has " + std::to_string(corners) + " vertices; at most 255 are supported");
            scan.face_lines.push_back(line_no);
            scan.corners += uint64_t(corners);
        }
    }
    MemoryBudget::check(MemoryBudget::times(scan.vertices, kVertexMemory) + MemoryBudget::times(scan.normals, kNormalMemory) +
                            MemoryBudget::times(scan.texcoords, kTexcoordMemory) +
                            MemoryBudget::times(scan.corners, kCornerMemory),
                        "loading " + std::to_string(scan.vertices) + " vertices and " +
                            std::to_string(scan.face_lines.size()) + " faces",
                        file);
    return scan;
}

void check_mtl(const fs::path& path) {
    const std::string file = path.string();
    const std::string text = read_input_file(path);
    check_text_encoding(text, file, "MTL");
    size_t pos = 0, line_no = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        std::string_view rest(text.data() + pos, end - pos);
        pos = end + 1;
        ++line_no;
        const std::string_view key = next_token(rest);
        const bool colour = key == "Kd" || key == "Ka" || key == "Ks" || key == "Ke" || key == "Tf";
        const bool scalar = key == "Ns" || key == "Ni" || key == "d" || key == "Tr";
        if (!colour && !scalar) continue;
        const std::string where = file + ":" + std::to_string(line_no);
        std::string_view peek = rest;
        const std::string_view first = next_token(peek);
        if (colour && (first == "spectral" || first == "xyz")) continue;  // not read as RGB
        int values = 0;
        for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest)) {
            if (tok.size() > 1 && tok[0] == '-' && std::isalpha(static_cast<unsigned char>(tok[1]))) continue;  // "-halo"
            float x = 0;
            if (!parse_float(tok, x)) throw Error(where, std::string(key) + " value " + quote(tok) + " is not a number");
            if (!std::isfinite(x)) throw Error(where, std::string(key) + " value " + quote(tok) + " is not a finite number");
            ++values;
        }
        if (values == 0) throw Error(where, std::string(key) + " has no value");
        if (values > (colour ? 3 : 1))
            throw Error(where, std::string(key) + " has " + std::to_string(values) + " values, expected " +
                                   (colour ? "1 or 3" : "1"));
    }
}

}  // namespace gilab
