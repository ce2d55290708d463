#pragma once
// Mesh checks done with CGAL: whether a triangle mesh is closed (watertight 2-manifold).
#include <cstdint>
#include <vector>
#include "core/scene/mesh.hpp"

namespace gilab {

struct MeshTopology {
    bool closed = false;          // every edge shared by exactly two faces, consistently
    size_t boundary_edges = 0;
    size_t connected_components = 0;
    // Components closed on their own (a model of many closed parts, like a building of
    // separate walls and towers, is open as a whole while each part is closed).
    size_t closed_components = 0;
    // Per input triangle: the index of its edge-connected component when that component
    // is closed, else -1 (an open component, a triangle collapsed by welding, or a soup
    // CGAL cannot turn into a mesh).
    std::vector<int32_t> closed_component;
    // Per input triangle: +1 if its winding agrees with the consistent orientation CGAL
    // gave its component, −1 if CGAL had to reverse it (0 where closed_component is −1).
    // Inside a closed component, triangles with the same sign wind the same way round.
    std::vector<int8_t> winding;
};

MeshTopology analyze_topology(const Mesh& mesh);

}  // namespace gilab
