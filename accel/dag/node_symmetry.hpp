#pragma once
// Symmetries of an octree node about its centre, as groups acting on the 8 child slots
// (slot = x | y << 1 | z << 2). A symmetry moves the child in slot k to slot
// slot_map(t, k) and applies itself to that child's subtree about the child's own
// centre, so subtrees equal up to a symmetry can be stored once (symmetric_merge.hpp).
//
// ReflectionGroup: the 8 reflections along the grid axes (SSVDAG, Villanueva et al.
//   2016); t is a mirror, bit a set = reflected along axis a, so t maps k to k ^ t.
// CubeSymmetryGroup: all 48 symmetries of the cube, axis permutations with reflections
//   (the transform-aware DAG of Molenaar & Eisemann 2025 without translations);
//   t = permutation × 8 + mirror, with t < 8 the reflections, numbered as above.
// Both give: compose(a, b) (b first, then a), inverse, the transformed child mask, the
// slot a transformed node's child comes from, and reduce(t, s): the smallest member of
// t's coset t ∘ s for a set s of symmetries of the child (bit g: g leaves it unchanged).
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>

namespace gilab {

namespace detail {

// Permutation p: coordinate a of the moved corner is coordinate kAxisOf[p][a] of the corner.
inline constexpr uint8_t kAxisOf[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

constexpr uint32_t cube_slot_map(uint32_t t, uint32_t k) {
    const uint32_t p = t >> 3, mirror = t & 7u;
    uint32_t moved = 0;
    for (uint32_t a = 0; a < 3; ++a) moved |= ((k >> kAxisOf[p][a]) & 1u) << a;
    return moved ^ mirror;
}

struct CubeTables {
    std::array<std::array<uint8_t, 8>, 48> slot_map{};
    std::array<std::array<uint8_t, 8>, 48> source_slot{};  // inverse slot maps
    std::array<std::array<uint8_t, 48>, 48> compose{};
    std::array<uint8_t, 48> inverse{};
    std::array<std::array<uint8_t, 256>, 48> mask{};
};

constexpr CubeTables make_cube_tables() {
    CubeTables c{};
    for (uint32_t t = 0; t < 48; ++t)
        for (uint32_t k = 0; k < 8; ++k) {
            c.slot_map[t][k] = uint8_t(cube_slot_map(t, k));
            c.source_slot[t][cube_slot_map(t, k)] = uint8_t(k);
        }
    // A symmetry is linear on the corners, so the images of corners 0, 1, 2 and 4 name it.
    std::array<uint8_t, 4096> named{};
    auto name = [](uint32_t c0, uint32_t c1, uint32_t c2, uint32_t c4) { return c0 | c1 << 3 | c2 << 6 | c4 << 9; };
    for (uint32_t t = 0; t < 48; ++t)
        named[name(c.slot_map[t][0], c.slot_map[t][1], c.slot_map[t][2], c.slot_map[t][4])] = uint8_t(t);
    for (uint32_t a = 0; a < 48; ++a)
        for (uint32_t b = 0; b < 48; ++b) {
            const auto& ma = c.slot_map[a];
            const auto& mb = c.slot_map[b];
            c.compose[a][b] = named[name(ma[mb[0]], ma[mb[1]], ma[mb[2]], ma[mb[4]])];
        }
    for (uint32_t a = 0; a < 48; ++a)
        for (uint32_t b = 0; b < 48; ++b)
            if (c.compose[a][b] == 0) c.inverse[a] = uint8_t(b);
    for (uint32_t t = 0; t < 48; ++t)
        for (uint32_t m = 0; m < 256; ++m) {
            uint32_t moved = 0;
            for (uint32_t k = 0; k < 8; ++k)
                if (m & (1u << k)) moved |= 1u << c.slot_map[t][k];
            c.mask[t][m] = uint8_t(moved);
        }
    return c;
}
inline constexpr CubeTables kCubeTables = make_cube_tables();

constexpr std::array<std::array<uint8_t, 256>, 8> make_reflected_masks() {
    std::array<std::array<uint8_t, 256>, 8> t{};
    for (uint32_t m = 0; m < 8; ++m)
        for (uint32_t mask = 0; mask < 256; ++mask) {
            uint32_t r = 0;
            for (uint32_t k = 0; k < 8; ++k)
                if (mask & (1u << k)) r |= 1u << (k ^ m);
            t[m][mask] = uint8_t(r);
        }
    return t;
}
inline constexpr std::array<std::array<uint8_t, 256>, 8> kReflectedMasks = make_reflected_masks();

// reduce() of the reflections for every set of symmetries: x ^ r, r in the set, smallest.
constexpr std::array<std::array<uint8_t, 8>, 256> make_reduced_mirrors() {
    std::array<std::array<uint8_t, 8>, 256> t{};
    for (uint32_t symmetries = 0; symmetries < 256; ++symmetries)
        for (uint32_t x = 0; x < 8; ++x) {
            uint32_t best = x;
            for (uint32_t r = 0; r < 8; ++r)
                if (symmetries & (1u << r)) best = std::min(best, x ^ r);
            t[symmetries][x] = uint8_t(best);
        }
    return t;
}
inline constexpr std::array<std::array<uint8_t, 8>, 256> kReducedMirrors = make_reduced_mirrors();

}  // namespace detail

struct ReflectionGroup {
    static constexpr uint32_t kSize = 8;
    static constexpr int kBits = 3;  // bits of a transform in a child reference
    using Set = uint8_t;             // bit t: symmetry t
    static constexpr const char* kName = "reflections";

    static uint32_t compose(uint32_t a, uint32_t b) { return a ^ b; }
    static uint32_t inverse(uint32_t t) { return t; }
    static uint8_t transform_mask(uint32_t t, uint32_t mask) { return detail::kReflectedMasks[t & 7u][mask & 0xffu]; }
    static uint32_t source_slot(uint32_t t, uint32_t slot) { return slot ^ t; }
    static uint32_t reduce(uint32_t t, Set symmetries) { return detail::kReducedMirrors[symmetries][t]; }
};

struct CubeSymmetryGroup {
    static constexpr uint32_t kSize = 48;
    static constexpr int kBits = 6;
    using Set = uint64_t;
    static constexpr const char* kName = "cube symmetries";

    static uint32_t compose(uint32_t a, uint32_t b) { return detail::kCubeTables.compose[a][b]; }
    static uint32_t inverse(uint32_t t) { return detail::kCubeTables.inverse[t]; }
    static uint8_t transform_mask(uint32_t t, uint32_t mask) { return detail::kCubeTables.mask[t][mask & 0xffu]; }
    static uint32_t source_slot(uint32_t t, uint32_t slot) { return detail::kCubeTables.source_slot[t][slot]; }
    static uint32_t reduce(uint32_t t, Set symmetries) {
        uint32_t best = t;
        for (Set s = symmetries & ~Set(1); s; s &= s - 1)  // bit 0, the identity, keeps t
            best = std::min(best, compose(t, uint32_t(std::countr_zero(s))));
        return best;
    }
};

}  // namespace gilab
