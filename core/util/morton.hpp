#pragma once
// 64-bit Morton (Z-order) codes of 3D integer coordinates, up to 2^21 per axis.
// Bit 3i holds bit i of x, bit 3i+1 of y, bit 3i+2 of z, so the three lowest bits of a
// code are the octree child slot (x | y<<1 | z<<2) of a voxel inside its parent.
#include <cstdint>
#include "core/util/math.hpp"

namespace gilab {

inline constexpr uint32_t kMortonMaxCoordinate = (1u << 21) - 1;

// Spreads the low 21 bits of v so that bit i lands on bit 3i.
constexpr uint64_t morton_spread3(uint64_t v) {
    v &= 0x1fffff;
    v = (v | (v << 32)) & 0x1f00000000ffffull;
    v = (v | (v << 16)) & 0x1f0000ff0000ffull;
    v = (v | (v << 8)) & 0x100f00f00f00f00full;
    v = (v | (v << 4)) & 0x10c30c30c30c30c3ull;
    v = (v | (v << 2)) & 0x1249249249249249ull;
    return v;
}

// Inverse of morton_spread3: gathers bits 0, 3, 6, ... into the low 21 bits.
constexpr uint32_t morton_compact3(uint64_t v) {
    v &= 0x1249249249249249ull;
    v = (v | (v >> 2)) & 0x10c30c30c30c30c3ull;
    v = (v | (v >> 4)) & 0x100f00f00f00f00full;
    v = (v | (v >> 8)) & 0x1f0000ff0000ffull;
    v = (v | (v >> 16)) & 0x1f00000000ffffull;
    v = (v | (v >> 32)) & 0x1fffffull;
    return static_cast<uint32_t>(v);
}

constexpr uint64_t morton_encode(uint32_t x, uint32_t y, uint32_t z) {
    return morton_spread3(x) | (morton_spread3(y) << 1) | (morton_spread3(z) << 2);
}
inline uint64_t morton_encode(const UVec3& p) { return morton_encode(p.x, p.y, p.z); }

inline UVec3 morton_decode(uint64_t code) {
    return {morton_compact3(code), morton_compact3(code >> 1), morton_compact3(code >> 2)};
}

// Child slot (0..7) as used in every octree here: x | y<<1 | z<<2.
constexpr int octree_child_slot(uint32_t x_bit, uint32_t y_bit, uint32_t z_bit) {
    return static_cast<int>((x_bit & 1u) | ((y_bit & 1u) << 1) | ((z_bit & 1u) << 2));
}

}  // namespace gilab
