#pragma once
// 8-bit child masks of octree/DAG nodes: how many children, and the rank of a slot
// (children stored before it). A table, since the build has no popcount instruction.
#include <array>
#include <cstdint>

namespace gilab {

namespace detail {
constexpr std::array<uint8_t, 256> make_popcount8() {
    std::array<uint8_t, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = uint8_t((i & 1) + ((i >> 1) & 1) + ((i >> 2) & 1) + ((i >> 3) & 1) +
                                                 ((i >> 4) & 1) + ((i >> 5) & 1) + ((i >> 6) & 1) + ((i >> 7) & 1));
    return t;
}
inline constexpr std::array<uint8_t, 256> kPopcount8 = make_popcount8();
}  // namespace detail

inline uint32_t child_count(uint32_t mask) { return detail::kPopcount8[mask & 0xffu]; }
// Children in slots below `slot`.
inline uint32_t child_rank(uint32_t mask, int slot) { return detail::kPopcount8[mask & ((1u << slot) - 1u)]; }

}  // namespace gilab
