#pragma once
// The states of a light-space cell in the shadow DAG (P2 §3.1–3.2) and the 16-bit child
// masks that hold them, 2 bits per child slot (slot = x | y<<1 | z<<2, Morton order).
//
// The paper's codes: 0 = wholly inside the shadow volume, 1 = wholly outside it (lit),
// 2 = crossing the shadow volume's boundary (only these children are subdivided and get
// a pointer). The double-depth variant adds a fourth state, 3 = undefined: space inside
// a closed object, where no visible surface point can lie, so any answer is right there.
#include <array>
#include <cstdint>
#include <span>

namespace gilab {

enum class ShadowState : uint8_t { Shadow = 0, Lit = 1, Boundary = 2, Undefined = 3 };

const char* to_string(ShadowState state);

inline ShadowState child_state(uint32_t mask16, int slot) { return ShadowState((mask16 >> (2 * slot)) & 3u); }
inline uint32_t with_child_state(uint32_t mask16, int slot, ShadowState s) {
    return (mask16 & ~(3u << (2 * slot))) | (uint32_t(s) << (2 * slot));
}
// Bit k set ⇔ child slot k is a boundary child (pointer stored).
inline uint32_t boundary_bits(uint32_t mask16) {
    uint32_t b = 0;
    for (int s = 0; s < 8; ++s) b |= uint32_t(child_state(mask16, s) == ShadowState::Boundary) << s;
    return b;
}
inline uint32_t boundary_count(uint32_t mask16) { return uint32_t(__builtin_popcount(boundary_bits(mask16))); }
// Boundary children stored before `slot`: the pointer of slot k is word 1 + rank.
inline uint32_t boundary_rank(uint32_t mask16, int slot) {
    return uint32_t(__builtin_popcount(boundary_bits(mask16) & ((1u << slot) - 1u)));
}

// The paper's bottom-up rules (§3.2 step 5) for a node whose children have these states:
//  * any Boundary child, or both Lit and Shadow children → Boundary (subdivided);
//  * only {Lit, Undefined} (at least one Lit)            → Lit, children dropped;
//  * only {Shadow, Undefined} (at least one Shadow)      → Shadow, children dropped;
//  * only Undefined                                      → Undefined.
// Without closed geometry no child is Undefined and these reduce to the plain 3-state
// rule of §3.1 (uniform children collapse, anything else is a boundary node).
ShadowState combine_child_states(std::span<const ShadowState, 8> children);

// The same rule stated on what a cell holds: whether any voxel in it is lit, whether any
// is in shadow (everything else is undefined). Used by the top-down build, which knows
// these two facts for a whole cell from depth-map pyramids without visiting its voxels.
inline ShadowState cell_state(bool has_lit, bool has_shadow) {
    if (has_lit && has_shadow) return ShadowState::Boundary;
    if (has_lit) return ShadowState::Lit;
    if (has_shadow) return ShadowState::Shadow;
    return ShadowState::Undefined;
}

// A child state as stored in a Boundary node: undefined space becomes `undefined_as`
// (Lit or Shadow), so stored masks hold only the paper's three codes.
inline ShadowState stored_child_state(ShadowState s, ShadowState undefined_as) {
    return s == ShadowState::Undefined ? undefined_as : s;
}

// What a lookup that ends on a state answers; a wholly undefined node answers as the
// build stored the rest of its undefined space (`undefined_as`), so one choice holds
// for every undefined voxel. Undefined space lies inside the closed part the light
// meets first, behind its entry depth D1. A lookup point lands there when the bias
// (1.5 voxels off the surface, 1 toward the light) carries it into a closed part that
// touches the surface looked up: a contact, where that part stands between the surface
// and the light. Answering as a plain depth map does at D1 (behind it: shadow) is then
// right; answering lit leaks light under every contact. Shadow is the default.
inline bool state_is_lit(ShadowState s, ShadowState undefined_as = ShadowState::Shadow) {
    return s == ShadowState::Lit || (s == ShadowState::Undefined && undefined_as == ShadowState::Lit);
}

}  // namespace gilab
