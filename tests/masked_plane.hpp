#pragma once
// A textured, alpha-masked plane for the voxelizer tests: one triangle of the plane
// y = height covering x, z in [0, 8] whole (no seam through the voxels of a unit grid),
// with u = x / 8, v = z / 8, and a 32² texture of 8 × 8 blocks of 4² texels, one per unit
// voxel: block (bx, by) is opaque where (bx + by) % 3 != 0, red where bx is even, blue
// where odd.
#include <memory>
#include "core/scene/scene.hpp"

namespace gilab::test {

inline bool masked_block_opaque(int bx, int by) { return (bx + by) % 3 != 0; }

inline SceneFrame masked_block_plane(float height, const Vec3& albedo) {
    Rgba8Image img{32, 32, {}};
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            const bool red = (x / 4) % 2 == 0;
            img.texels.insert(img.texels.end(), {uint8_t(red ? 255 : 0), 0, uint8_t(red ? 0 : 255),
                                                 uint8_t(masked_block_opaque(x / 4, y / 4) ? 255 : 0)});
        }
    auto image = std::make_shared<const MipMap>(img, ColorEncoding::Srgb, "blocks");
    Material m;
    m.albedo = albedo;
    m.albedo_texture.image = image;
    m.alpha_mode = AlphaMode::Mask;
    m.alpha_texture.image = image;
    SceneFrame frame;
    frame.materials = {m};
    WorldMesh mesh;
    mesh.positions = {Vec3(0, height, 0), Vec3(16, height, 0), Vec3(0, height, 16)};
    mesh.uvs = {Vec2(0, 0), Vec2(2, 0), Vec2(0, 2)};
    mesh.triangles = {UVec3(0, 1, 2)};
    mesh.material_ids = {0};
    frame.meshes.push_back(mesh);
    frame.bounds.extend(Vec3(0));
    frame.bounds.extend(Vec3(8, height + 0.5f, 8));
    return frame;
}

}  // namespace gilab::test
