#include "accel/vct/packed_surface.hpp"

#include "core/image/display_planes.hpp"

namespace gilab {

uint8_t to_srgb8(float linear) {
    const float x = std::isnan(linear) ? 0.0f : std::clamp(linear, 0.0f, 1.0f);
    return uint8_t(std::lround(srgb_encode(x) * 255.0f));
}

float from_srgb8(uint8_t encoded) {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = srgb_decode(float(i) / 255.0f);
        return t;
    }();
    return table[encoded];
}

PackedSurface pack_surface(const VoxelFaceData& face, const Vec3& center, float voxel_size) {
    PackedSurface p;
    if (!(face.opacity > 0)) return p;
    p.opacity = uint8_t(std::clamp(std::lround(std::min(face.opacity, 1.0f) * 255.0f), 1L, 255L));
    for (int k = 0; k < 3; ++k) p.albedo[k] = to_srgb8(face.albedo[k]);
    const Vec3& n = face.normal;
    const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
    if (l1 > 0) {
        float u = n.x / l1, v = n.y / l1;
        if (n.z < 0) {
            const float fu = (1.0f - std::abs(v)) * (u >= 0 ? 1.0f : -1.0f);
            const float fv = (1.0f - std::abs(u)) * (v >= 0 ? 1.0f : -1.0f);
            u = fu;
            v = fv;
        }
        p.normal[0] = to_snorm8(u);
        p.normal[1] = to_snorm8(v);
    }
    const Vec3 offset = (face.position - center) / voxel_size;
    for (int k = 0; k < 3; ++k) p.offset[k] = to_snorm16(offset[k]);
    return p;
}

PackedVoxel pack_voxel(const AnisotropicVoxel& voxel, const VoxelLattice& lattice) {
    PackedVoxel p;
    const Vec3 center = voxel_center(lattice, voxel.coord);
    for (int k = 0; k < 3; ++k) {
        VoxelFaceData face = voxel.faces[size_t(2 * k)];
        if (!(face.opacity > 0)) {
            face = voxel.faces[size_t(2 * k + 1)];
            face.normal = -face.normal;
        }
        p.axis[size_t(k)] = pack_surface(face, center, float(lattice.voxel_size));
    }
    return p;
}

Vec3 unpack_normal(const PackedSurface& p) {
    const float u = from_snorm8(p.normal[0]), v = from_snorm8(p.normal[1]);
    Vec3 n(u, v, 1.0f - std::abs(u) - std::abs(v));
    if (n.z < 0) {
        n.x = (1.0f - std::abs(v)) * (u >= 0 ? 1.0f : -1.0f);
        n.y = (1.0f - std::abs(u)) * (v >= 0 ? 1.0f : -1.0f);
    }
    return glm::normalize(n);
}

}  // namespace gilab
