#pragma once
// The G-buffer of one voxel face at its smallest type: what the light injection reads
// besides the opacity — albedo, normal and position — in 16 bytes instead of 36. The
// cascades and the dense texture's voxel list store faces this way alike.
//  - albedo: three half floats (albedo is never negative; half_rgba.hpp's rounding);
//  - normal: octahedral, two 16-bit signed normalized values (error < 0.01°);
//  - position: the mean fragment position relative to the voxel's centre, in voxel
//    sizes, three 16-bit signed normalized values over [−1, 1] (1/32767 of a voxel).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include "accel/vct/anisotropic_voxel.hpp"
#include "accel/vct/fragment_voxelizer.hpp"
#include "accel/vct/half_rgba.hpp"
#include "core/util/math.hpp"

namespace gilab {

struct PackedSurface {
    uint16_t albedo[3] = {0, 0, 0};
    int16_t normal[2] = {0, 0};
    int16_t offset[3] = {0, 0, 0};
    bool operator==(const PackedSurface&) const = default;
};

// The centre of voxel v of a lattice, as every structure computes it.
inline Vec3 voxel_center(const VoxelLattice& lattice, const IVec3& v) {
    return Vec3(lattice.anchor + (DVec3(v) + DVec3(0.5)) * lattice.voxel_size);
}

inline int16_t to_snorm16(float x) {
    return int16_t(std::lround(std::clamp(x, -1.0f, 1.0f) * 32767.0f));
}
inline float from_snorm16(int16_t x) { return std::max(float(x) / 32767.0f, -1.0f); }

inline PackedSurface pack_surface(const VoxelFaceData& face, const Vec3& center, float voxel_size) {
    PackedSurface p;
    for (int k = 0; k < 3; ++k) p.albedo[k] = to_half(face.albedo[k]);
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
        p.normal[0] = to_snorm16(u);
        p.normal[1] = to_snorm16(v);
    }
    const Vec3 offset = (face.position - center) / voxel_size;
    for (int k = 0; k < 3; ++k) p.offset[k] = to_snorm16(offset[k]);
    return p;
}

inline Vec3 unpack_albedo(const PackedSurface& p) {
    return {from_half(p.albedo[0]), from_half(p.albedo[1]), from_half(p.albedo[2])};
}

inline Vec3 unpack_normal(const PackedSurface& p) {
    const float u = from_snorm16(p.normal[0]), v = from_snorm16(p.normal[1]);
    Vec3 n(u, v, 1.0f - std::abs(u) - std::abs(v));
    if (n.z < 0) {
        n.x = (1.0f - std::abs(v)) * (u >= 0 ? 1.0f : -1.0f);
        n.y = (1.0f - std::abs(u)) * (v >= 0 ? 1.0f : -1.0f);
    }
    return glm::normalize(n);
}

inline Vec3 unpack_position(const PackedSurface& p, const Vec3& center, float voxel_size) {
    return center + voxel_size * Vec3(from_snorm16(p.offset[0]), from_snorm16(p.offset[1]), from_snorm16(p.offset[2]));
}

// One occupied voxel of the dense texture's sparse G-buffer.
struct PackedVoxel {
    IVec3 coord{0};
    std::array<float, kFaceCount> opacity{};
    std::array<PackedSurface, kFaceCount> surface{};
};

inline PackedVoxel pack_voxel(const AnisotropicVoxel& voxel, const VoxelLattice& lattice) {
    PackedVoxel p;
    p.coord = voxel.coord;
    const Vec3 center = voxel_center(lattice, voxel.coord);
    for (int f = 0; f < kFaceCount; ++f) {
        p.opacity[size_t(f)] = voxel.faces[size_t(f)].opacity;
        p.surface[size_t(f)] = pack_surface(voxel.faces[size_t(f)], center, float(lattice.voxel_size));
    }
    return p;
}

}  // namespace gilab
