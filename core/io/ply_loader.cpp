// PLY and OFF polygon soups read with CGAL, triangulated into one mesh. CGAL trusts the
// counts a file declares (and only says yes or no), so the file is first checked
// structurally (core/io/ply_off_check.hpp): counts against the file's size and the memory
// budget, numbers, indices; CGAL then reads the same bytes.
#include <CGAL/IO/OFF.h>
#include <CGAL/IO/PLY.h>
#include <CGAL/Simple_cartesian.h>

#include <sstream>
#include "core/util/error.hpp"
#include "core/util/input_file.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/io/ply_off_check.hpp"
#include "core/io/polygon_triangulation.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;

std::string lower_extension(const fs::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace

Scene load_ply_or_off(const fs::path& path) {
    const std::string file = path.string();
    const std::string ext = lower_extension(path);
    if (ext != ".ply" && ext != ".off") throw Error(file, "not a .ply or .off file");
    const std::string format = ext == ".ply" ? "PLY" : "OFF";
    const std::string bytes = read_input_file(path);
    // Binary OFF is refused by check_off with its own message, before its NULs look like UTF-16.
    if (ext == ".off" && bytes.substr(0, std::min<size_t>(bytes.find('\n'), 64)).find("BINARY") == std::string::npos)
        check_text_encoding(bytes, file, "OFF");
    else if (bytes.size() >= 2 && (bytes.compare(0, 2, "\xFF\xFE") == 0 || bytes.compare(0, 2, "\xFE\xFF") == 0))
        check_text_encoding(bytes, file, "PLY header");
    const PolygonFileCounts declared = ext == ".ply" ? check_ply(bytes, file) : check_off(bytes, file);
    if (declared.vertices > UINT32_MAX)
        throw Error(file, "vertex count " + std::to_string(declared.vertices) + " exceeds 4294967295, the most a mesh can index");

    std::vector<Point> points;
    std::vector<std::vector<size_t>> polygons;
    points.reserve(size_t(declared.vertices));
    polygons.reserve(size_t(declared.faces));
    // gilab reads positions and faces only. CGAL's readers of OFF colours and texture
    // coordinates index past the numbers a line holds when lines disagree with each
    // other or with the header (found by fuzzing), so CGAL is given the keyword "OFF":
    // it then reads the first three numbers of each vertex line and ignores the rest.
    std::string plain_off;
    if (declared.off_keyword_length > 3)
        plain_off = std::string(bytes).replace(declared.off_keyword_offset, declared.off_keyword_length, "OFF");
    std::istringstream in(plain_off.empty() ? bytes : plain_off, std::ios::in | std::ios::binary);
    const bool ok = ext == ".ply" ? CGAL::IO::read_PLY(in, points, polygons, CGAL::parameters::verbose(false))
                                  : CGAL::IO::read_OFF(in, points, polygons, CGAL::parameters::verbose(false));
    if (points.size() < declared.vertices || polygons.size() < declared.faces)
        throw Error(file, "truncated " + format + ": the header declares " + std::to_string(declared.vertices) +
                              " vertices and " + std::to_string(declared.faces) + " faces, but only " +
                              std::to_string(points.size()) + " vertices and " + std::to_string(polygons.size()) +
                              " faces could be read");
    if (!ok) throw Error(file, "malformed " + format + " (could not be parsed)");

    Mesh mesh;
    mesh.name = path.stem().string();
    mesh.positions.reserve(points.size());
    for (const Point& p : points) mesh.positions.emplace_back(float(p.x()), float(p.y()), float(p.z()));
    TriangulationTally tally;
    std::vector<Vec3> corners;
    for (size_t f = 0; f < polygons.size(); ++f) {
        const auto& poly = polygons[f];
        if (poly.size() < 3)
            throw Error(file, "face " + std::to_string(f) + " has " + std::to_string(poly.size()) +
                                  " vertices, expected at least 3");
        corners.clear();
        for (size_t v : poly) {
            if (v >= points.size())
                throw Error(file, "face " + std::to_string(f) + " references vertex " + std::to_string(v) +
                                      " but the file has " + std::to_string(points.size()) +
                                      " vertices (index out of range)");
            corners.push_back(mesh.positions[v]);
        }
        const PolygonTriangulation t = triangulate_polygon(corners);
        tally.count(t);
        for (const auto& tri : t.triangles)
            mesh.triangles.emplace_back(uint32_t(poly[tri[0]]), uint32_t(poly[tri[1]]), uint32_t(poly[tri[2]]));
    }
    if (mesh.triangles.empty()) throw Error(file, "no faces in " + format + " file");
    mesh.material_ids.assign(mesh.triangles.size(), 0);

    Scene scene;
    scene.name = mesh.name;
    scene.source = file;
    scene.materials.push_back(Material{});
    scene.warnings = declared.warnings;
    tally.add_notes(file, scene.warnings);
    scene.degenerate_triangles_dropped = validate_and_clean(mesh, 1, file).degenerate_triangles_dropped;
    scene.add_mesh_instance(std::move(mesh));
    return scene;
}

}  // namespace gilab
