#pragma once
// Mesh checks done with CGAL: whether a triangle mesh is closed (watertight 2-manifold).
#include "core/mesh.hpp"

namespace gilab {

struct MeshTopology {
    bool closed = false;          // every edge shared by exactly two faces, consistently
    size_t boundary_edges = 0;
    size_t connected_components = 0;
};

MeshTopology analyze_topology(const Mesh& mesh);

}  // namespace gilab
