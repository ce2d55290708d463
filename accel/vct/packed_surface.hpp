#pragma once
// The G-buffer of a voxel at its smallest type: what the light injection reads besides
// the radiance. The voxelizer's faces +k and −k see the same fragments with the same
// weight and differ only in the normal's sign (fragment_voxelizer.cpp), so one record per
// axis serves both, oriented towards +k. A record is 12 bytes, as GPU cone tracers keep
// their G-buffers in 8-bit textures:
//  - opacity: 8-bit unsigned normalized (P3 counts a byte per face), never 0 when the
//    face has any coverage;
//  - albedo: 8-bit sRGB-encoded per channel, as an RGBA8_SRGB texture;
//  - normal: octahedral, two 8-bit signed normalized values (error < 1°);
//  - position: the mean fragment position relative to the voxel's centre, in voxel
//    sizes, three 16-bit signed normalized values over [−1, 1] (1/32767 of a voxel, far
//    below the shadow rays' offset of 1/1000 of a voxel, so a lit face never shadows
//    itself).
// The cascades and the dense texture's voxel list store voxels this way alike.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include "accel/vct/anisotropic_voxel.hpp"
#include "accel/vct/fragment_voxelizer.hpp"
#include "core/util/math.hpp"

namespace gilab {

struct PackedSurface {
    uint8_t opacity = 0;
    uint8_t albedo[3] = {0, 0, 0};
    int8_t normal[2] = {0, 0};
    int16_t offset[3] = {0, 0, 0};
    bool operator==(const PackedSurface&) const = default;
};
static_assert(sizeof(PackedSurface) == 12);

// One voxel: axis k serves faces +k (2k) and −k (2k + 1); opacity 0 where neither sees
// anything.
struct PackedVoxel {
    std::array<PackedSurface, 3> axis{};
    bool empty() const { return !axis[0].opacity && !axis[1].opacity && !axis[2].opacity; }
    bool operator==(const PackedVoxel&) const = default;
};

// The centre of voxel v of a lattice, as every structure computes it.
inline Vec3 voxel_center(const VoxelLattice& lattice, const IVec3& v) {
    return Vec3(lattice.anchor + (DVec3(v) + DVec3(0.5)) * lattice.voxel_size);
}

inline int16_t to_snorm16(float x) { return int16_t(std::lround(std::clamp(x, -1.0f, 1.0f) * 32767.0f)); }
inline float from_snorm16(int16_t x) { return std::max(float(x) / 32767.0f, -1.0f); }
inline int8_t to_snorm8(float x) { return int8_t(std::lround(std::clamp(x, -1.0f, 1.0f) * 127.0f)); }
inline float from_snorm8(int8_t x) { return std::max(float(x) / 127.0f, -1.0f); }
uint8_t to_srgb8(float linear);   // clamped to [0, 1], rounded to nearest
float from_srgb8(uint8_t encoded);

// `face` is the axis's +k face as the voxelizer wrote it (normal oriented towards +k).
PackedSurface pack_surface(const VoxelFaceData& face, const Vec3& center, float voxel_size);
// The record of each axis from whichever of its two faces is covered.
PackedVoxel pack_voxel(const AnisotropicVoxel& voxel, const VoxelLattice& lattice);

inline float unpack_opacity(const PackedSurface& p) { return float(p.opacity) * (1.0f / 255.0f); }
inline Vec3 unpack_albedo(const PackedSurface& p) {
    return {from_srgb8(p.albedo[0]), from_srgb8(p.albedo[1]), from_srgb8(p.albedo[2])};
}
// Oriented towards +k; face −k's normal is its negation.
Vec3 unpack_normal(const PackedSurface& p);
inline Vec3 unpack_position(const PackedSurface& p, const Vec3& center, float voxel_size) {
    return center + voxel_size * Vec3(from_snorm16(p.offset[0]), from_snorm16(p.offset[1]), from_snorm16(p.offset[2]));
}

// One occupied voxel of the dense texture's sparse G-buffer list.
struct PackedVoxelAt {
    IVec3 coord{0};
    PackedVoxel voxel;
};

}  // namespace gilab
