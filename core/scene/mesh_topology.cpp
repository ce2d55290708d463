// Closedness with CGAL: the triangle soup (vertices welded by exact position, so a mesh
// split at normal/uv seams still counts as one surface) is oriented consistently, turned
// into a Surface_mesh and asked whether it has border halfedges. orient_polygon_soup
// duplicates points at non-manifold edges and vertices, so a non-manifold soup never
// reaches the mesh builder in a state it would reject; such a soup is reported open.
#include "core/scene/mesh_topology.hpp"

#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <cstring>
#include <numeric>
#include <unordered_map>

namespace gilab {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

struct PositionHash {
    size_t operator()(const std::array<uint32_t, 3>& k) const {
        return (size_t(k[0]) * 73856093u) ^ (size_t(k[1]) * 19349663u) ^ (size_t(k[2]) * 83492791u);
    }
};

std::array<uint32_t, 3> position_key(const Vec3& p) {
    std::array<uint32_t, 3> key;
    for (int i = 0; i < 3; ++i) {
        float v = p[i] + 0.0f;  // -0 and +0 weld together
        std::memcpy(&key[size_t(i)], &v, sizeof(float));
    }
    return key;
}

// Fallback when the oriented soup still is not a valid polygon mesh: count edges used by
// one triangle, and edge-connected components with a union-find.
MeshTopology soup_topology(const std::vector<std::vector<size_t>>& polygons) {
    MeshTopology topo;
    std::vector<size_t> parent(polygons.size());
    std::iota(parent.begin(), parent.end(), size_t(0));
    auto find = [&](size_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    std::unordered_map<uint64_t, std::pair<size_t, size_t>> edges;  // edge → (use count, first face)
    for (size_t f = 0; f < polygons.size(); ++f) {
        const auto& poly = polygons[f];
        for (size_t k = 0; k < poly.size(); ++k) {
            uint64_t a = poly[k], b = poly[(k + 1) % poly.size()];
            if (a > b) std::swap(a, b);
            auto [it, inserted] = edges.try_emplace((a << 32) | b, 0, f);
            ++it->second.first;
            if (!inserted) parent[find(f)] = find(it->second.second);
        }
    }
    for (const auto& e : edges) topo.boundary_edges += e.second.first == 1;
    for (size_t f = 0; f < polygons.size(); ++f) topo.connected_components += find(f) == f;
    topo.closed = false;
    return topo;
}

}  // namespace

MeshTopology analyze_topology(const Mesh& mesh) {
    std::vector<Point> points;
    std::vector<uint32_t> weld(mesh.positions.size());
    std::unordered_map<std::array<uint32_t, 3>, size_t, PositionHash> welded;
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        auto [it, inserted] = welded.try_emplace(position_key(mesh.positions[i]), points.size());
        if (inserted) {
            const Vec3& p = mesh.positions[i];
            points.emplace_back(p.x, p.y, p.z);
        }
        weld[i] = uint32_t(it->second);
    }
    std::vector<std::vector<size_t>> polygons;
    std::vector<size_t> source_triangle;  // polygon → input triangle
    polygons.reserve(mesh.triangles.size());
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        const UVec3& t = mesh.triangles[i];
        if (t.x >= weld.size() || t.y >= weld.size() || t.z >= weld.size()) continue;
        size_t a = weld[t.x], b = weld[t.y], c = weld[t.z];
        if (a == b || b == c || a == c) continue;  // collapsed by welding
        polygons.push_back({a, b, c});
        source_triangle.push_back(i);
    }
    MeshTopology topo;
    topo.closed_component.assign(mesh.triangles.size(), -1);
    topo.winding.assign(mesh.triangles.size(), 0);
    if (polygons.empty()) return topo;

    const std::vector<std::vector<size_t>> original = polygons;
    const bool manifold = PMP::orient_polygon_soup(points, polygons);
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
        MeshTopology soup = soup_topology(polygons);
        soup.closed_component = std::move(topo.closed_component);
        soup.winding = std::move(topo.winding);
        return soup;
    }

    SurfaceMesh sm;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
    for (auto h : sm.halfedges())
        if (sm.is_border(h)) ++topo.boundary_edges;
    auto component = sm.add_property_map<SurfaceMesh::Face_index, size_t>("f:component", 0).first;
    topo.connected_components = PMP::connected_components(sm, component);
    topo.closed = manifold && topo.boundary_edges == 0 && CGAL::is_closed(sm);
    // A component is closed when none of its faces borders a hole. Faces are numbered
    // in polygon order by polygon_soup_to_polygon_mesh.
    std::vector<uint8_t> open(topo.connected_components, 0);
    for (auto h : sm.halfedges())
        if (sm.is_border(h)) open[component[sm.face(sm.opposite(h))]] = 1;
    if (sm.number_of_faces() == polygons.size()) {
        for (auto f : sm.faces()) {
            const size_t c = component[f], k = size_t(f);
            if (open[c]) continue;
            topo.closed_component[source_triangle[k]] = int32_t(c);
            // orient_polygon_soup reverses polygons in place (it may also split a point
            // into copies at a non-manifold vertex, but then the component is open): the
            // polygon kept its cyclic order or was reversed. Compare by the second corner
            // after the first one's position in the original.
            const auto& o = original[k];
            const auto& p = polygons[k];
            size_t at = 0;
            while (at < 3 && points[o[at]] != points[p[0]]) ++at;
            topo.winding[source_triangle[k]] = (at < 3 && points[o[(at + 1) % 3]] == points[p[1]]) ? 1 : -1;
        }
        for (uint8_t o : open) topo.closed_components += o == 0;
    }
    return topo;
}

}  // namespace gilab
