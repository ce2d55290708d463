#pragma once
// An indexed triangle mesh in its own (local) space.
#include <cstdint>
#include <string>
#include <vector>
#include "core/math.hpp"
#include "core/skin.hpp"

namespace gilab {

struct Mesh {
    std::string name;
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;        // per vertex, optional (empty = flat shading)
    std::vector<Vec2> uvs;            // per vertex, optional
    std::vector<UVec3> triangles;     // vertex indices
    std::vector<uint32_t> material_ids;  // one per triangle, index into Scene::materials
    std::vector<VertexInfluences> influences;  // per vertex, for skinning (empty = rigid)

    size_t triangle_count() const { return triangles.size(); }
    Bounds3 bounds() const;
};

struct MeshCleanupReport {
    size_t degenerate_triangles_dropped = 0;
};

// Checks a freshly loaded mesh: NaN/Inf positions and out-of-range indices are errors
// (thrown, naming `source`); zero-area triangles are dropped and counted.
MeshCleanupReport validate_and_clean(Mesh& mesh, size_t material_count, const std::string& source);

}  // namespace gilab
