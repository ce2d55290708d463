#pragma once
// An indexed triangle mesh in its own (local) space.
#include <cstdint>
#include <string>
#include <vector>
#include "core/util/math.hpp"
#include "core/scene/skin.hpp"

namespace gilab {

struct Mesh {
    std::string name;
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;        // per vertex, optional (empty = flat shading)
    std::vector<Vec2> uvs;            // per vertex, optional (glTF TEXCOORD_0, OBJ vt)
    std::vector<Vec2> uvs1;           // per vertex, optional second set (glTF TEXCOORD_1)
    std::vector<UVec3> triangles;     // vertex indices
    std::vector<uint32_t> material_ids;  // one per triangle, index into Scene::materials
    std::vector<VertexInfluences> influences;  // per vertex, for skinning (empty = rigid)

    size_t triangle_count() const { return triangles.size(); }
    Bounds3 bounds() const;
};

// Largest coordinate magnitude geometry may reach, in a mesh's own space and in the
// world: Embree's range for vertex positions. Far below float overflow, so extents,
// edge cross products and ray offsets stay finite.
inline constexpr float kMaxCoordinate = 1e18f;

struct MeshCleanupReport {
    size_t degenerate_triangles_dropped = 0;
};

// Checks a freshly loaded mesh: NaN/Inf positions, coordinates beyond kMaxCoordinate and
// out-of-range indices are errors (thrown, naming `source`); zero-area triangles are
// dropped and counted.
// "mesh 'name'" (or "mesh" when unnamed), for error messages.
std::string mesh_label(const Mesh& mesh);

MeshCleanupReport validate_and_clean(Mesh& mesh, size_t material_count, const std::string& source);

}  // namespace gilab
