// PLY and OFF polygon soups read with CGAL, fan-triangulated into one mesh. CGAL only
// says yes or no, so the element counts the header declares are read here as well to
// tell a truncated file from a malformed one.
#include <CGAL/IO/OFF.h>
#include <CGAL/IO/PLY.h>
#include <CGAL/Simple_cartesian.h>

#include <fstream>
#include <optional>
#include <sstream>
#include "core/error.hpp"
#include "core/mesh_loaders.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;

struct DeclaredCounts {
    size_t vertices = 0;
    size_t faces = 0;
};

// "element vertex N" / "element face M" from a PLY header (ASCII in every PLY variant).
std::optional<DeclaredCounts> ply_header_counts(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    if (!std::getline(in, line) || line.rfind("ply", 0) != 0) return std::nullopt;
    DeclaredCounts counts;
    while (std::getline(in, line)) {
        std::istringstream s(line);
        std::string word, element;
        s >> word;
        if (word == "end_header") return counts;
        if (word != "element") continue;
        size_t n = 0;
        s >> element >> n;
        if (element == "vertex") counts.vertices = n;
        if (element == "face") counts.faces = n;
    }
    return std::nullopt;
}

// "[ST][C][N][4][n]OFF" then vertex, face and edge counts (comments start with '#').
std::optional<DeclaredCounts> off_header_counts(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<std::string> tokens;
    std::string line;
    while (tokens.size() < 4 && std::getline(in, line)) {
        line = line.substr(0, line.find('#'));
        std::istringstream s(line);
        std::string tok;
        while (s >> tok) tokens.push_back(tok);
    }
    if (tokens.empty()) return std::nullopt;
    size_t first = 0;
    if (tokens[0].size() >= 3 && tokens[0].compare(tokens[0].size() - 3, 3, "OFF") == 0) {
        if (tokens[0].find('4') != std::string::npos || tokens[0].find('n') != std::string::npos) return std::nullopt;
        first = 1;
    }
    if (tokens.size() < first + 2) return std::nullopt;
    try {
        return DeclaredCounts{std::stoul(tokens[first]), std::stoul(tokens[first + 1])};
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

// CGAL rejects a bad OFF file without saying why; re-read it line by line to name the
// problem (only called after CGAL failed).
std::string diagnose_off(const fs::path& path, const DeclaredCounts& declared) {
    std::ifstream in(path, std::ios::binary);
    std::vector<std::vector<std::string>> lines;  // non-empty lines, comments removed
    std::string line;
    while (std::getline(in, line)) {
        line = line.substr(0, line.find('#'));
        std::istringstream s(line);
        std::vector<std::string> tokens;
        std::string tok;
        while (s >> tok) tokens.push_back(tok);
        if (!tokens.empty()) lines.push_back(std::move(tokens));
    }
    // Header: "OFF" and the counts, on one line or two.
    size_t at = 0;
    if (!lines.empty() && lines[0][0].find("OFF") != std::string::npos) at = lines[0].size() > 1 ? 1 : 2;
    else at = 1;
    auto truncated = [&](const std::string& what) {
        return "truncated OFF: the header declares " + std::to_string(declared.vertices) + " vertices and " +
               std::to_string(declared.faces) + " faces, but the file ends before " + what;
    };
    for (size_t v = 0; v < declared.vertices; ++v, ++at) {
        if (at >= lines.size()) return truncated("vertex " + std::to_string(v));
        if (lines[at].size() < 3) return "vertex " + std::to_string(v) + " has fewer than 3 coordinates";
        for (size_t k = 0; k < 3; ++k) {
            const std::string& t = lines[at][k];
            char* end = nullptr;
            const double x = std::strtod(t.c_str(), &end);
            if (end == t.c_str() || *end != '\0') return "vertex " + std::to_string(v) + " coordinate '" + t + "' is not a number";
            if (!std::isfinite(x)) return "vertex " + std::to_string(v) + " coordinate '" + t + "' is not finite";
        }
    }
    for (size_t f = 0; f < declared.faces; ++f, ++at) {
        if (at >= lines.size()) return truncated("face " + std::to_string(f));
        const auto& tokens = lines[at];
        size_t n = 0;
        try {
            n = std::stoul(tokens[0]);
        } catch (const std::exception&) {
            return "face " + std::to_string(f) + " does not start with a vertex count";
        }
        if (tokens.size() < 1 + n) return "face " + std::to_string(f) + " lists fewer vertices than it declares (truncated?)";
        for (size_t k = 1; k <= n; ++k) {
            long long idx = -1;
            try {
                idx = std::stoll(tokens[k]);
            } catch (const std::exception&) {
            }
            if (idx < 0 || size_t(idx) >= declared.vertices)
                return "face " + std::to_string(f) + " references vertex " + tokens[k] + " but the file has " +
                       std::to_string(declared.vertices) + " vertices (index out of range)";
        }
    }
    return "malformed OFF (could not be parsed)";
}

std::string lower_extension(const fs::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace

Scene load_ply_or_off(const fs::path& path) {
    const std::string file = path.string();
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw Error(file, "file not found");
    const std::string ext = lower_extension(path);
    if (ext != ".ply" && ext != ".off") throw Error(file, "not a .ply or .off file");
    const std::string format = ext == ".ply" ? "PLY" : "OFF";

    std::vector<Point> points;
    std::vector<std::vector<size_t>> polygons;
    std::optional<DeclaredCounts> declared;
    bool ok = false;
    if (ext == ".ply") {
        declared = ply_header_counts(path);
        if (!declared) throw Error(file, "malformed PLY: no 'ply' magic line or no 'end_header'");
        ok = CGAL::IO::read_PLY(file, points, polygons);
    } else {
        declared = off_header_counts(path);
        std::ifstream in(path);
        ok = CGAL::IO::read_OFF(in, points, polygons);
    }
    if (declared && (points.size() < declared->vertices || polygons.size() < declared->faces))
        throw Error(file, "truncated " + format + ": the header declares " + std::to_string(declared->vertices) +
                              " vertices and " + std::to_string(declared->faces) + " faces, but only " +
                              std::to_string(points.size()) + " vertices and " + std::to_string(polygons.size()) +
                              " faces could be read");
    if (!ok && ext == ".off" && declared) throw Error(file, diagnose_off(path, *declared));
    if (!ok) throw Error(file, "malformed " + format + " (could not be parsed)");

    Mesh mesh;
    mesh.name = path.stem().string();
    mesh.positions.reserve(points.size());
    for (const Point& p : points) mesh.positions.emplace_back(float(p.x()), float(p.y()), float(p.z()));
    for (size_t f = 0; f < polygons.size(); ++f) {
        const auto& poly = polygons[f];
        if (poly.size() < 3)
            throw Error(file, "face " + std::to_string(f) + " has " + std::to_string(poly.size()) +
                                  " vertices, expected at least 3");
        for (size_t v : poly)
            if (v >= points.size())
                throw Error(file, "face " + std::to_string(f) + " references vertex " + std::to_string(v) +
                                      " but the file has " + std::to_string(points.size()) +
                                      " vertices (index out of range)");
        for (size_t k = 2; k < poly.size(); ++k)
            mesh.triangles.emplace_back(uint32_t(poly[0]), uint32_t(poly[k - 1]), uint32_t(poly[k]));
    }
    if (mesh.triangles.empty()) throw Error(file, "no faces in " + format + " file");
    mesh.material_ids.assign(mesh.triangles.size(), 0);

    Scene scene;
    scene.name = mesh.name;
    scene.source = file;
    scene.materials.push_back(Material{});
    scene.degenerate_triangles_dropped = validate_and_clean(mesh, 1, file).degenerate_triangles_dropped;
    scene.add_mesh_instance(std::move(mesh));
    return scene;
}

}  // namespace gilab
