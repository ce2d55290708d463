#pragma once
// Symmetry-aware sparse voxel DAGs: the SVDAG with subtrees that are equal up to a node
// symmetry (node_symmetry.hpp) merged as well, each child pointer naming a stored node and
// the symmetry t it is seen through. A symmetry moves the child of slot k to slot
// slot_map(t, k) and applies itself to that child's subtree about the child's centre, so
// the child in slot j of a node seen through t is the stored child of slot
// source_slot(t, j), seen through compose(t, its pointer's own transform).
//
// Two groups are stored:
// - Ssvdag (Villanueva, Marton & Gobbetti, I3D 2016): the 8 reflections along the grid
//   axes, a 3-bit mirror per pointer (bit a: reflected along axis a; composing is XOR).
//   Implemented from the paper: merging under the reflections, the mirror in each pointer,
//   variable-size pointers (16 bits to the nodes that most pointers reach, 32 bits to the
//   rest) and ray casting with the mirror applied to the child order. Not implemented:
//   4³-voxel leaves as 64-bit masks and the paper's out-of-core build (gilab streams the
//   SVDAG instead, svdag.hpp).
// - CubeSymmetricDag: all 48 symmetries of the cube (the 6 axis permutations, each with
//   the 8 reflections), a 6-bit transform per pointer (permutation × 8 + mirror): the
//   transform-aware DAG of Molenaar & Eisemann (I3D 2025) without its translations, in the
//   SSVDAG's pointer layout.
//
// Built from an Svdag by merging its subtrees under the group (symmetric_merge.hpp): the
// unique minimal DAG under the group, the same for every build and thread count.
//
// Storage, 16-bit units; addresses count units. B is the group's transform bits (3 or 6):
// - levels 0..depth-2, laid out top-down from address 0. Within a level the nodes are
//   ordered by pointers reaching them per unit they take, most first (ties by id), so
//   that the most reached ones sit within a short pointer's reach of the level's start.
//   Per node a header unit, child mask | long-pointer mask << 8 (bit k: the pointer of
//   slot k is long), then per non-empty child in slot order its pointer:
//     short, one unit: transform << (16 − B) | the child's offset from its level's first unit;
//     long, two units (low first): transform << (32 − B) | the child's address;
//   a pointer is short exactly when the offset is below 2^(16 − B);
// - level depth-1 (nodes whose children are voxels): their 8-bit masks, two to a unit,
//   after the last interior level, ordered by pointers reaching them; pointers to them
//   hold the mask's index (which is also its offset);
// - level depth (the voxel) is not stored.
// The root's pointer (address 0, or mask index 0 when depth is 1, and its transform) is
// kept beside the units.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>
#include "accel/dag/child_mask.hpp"
#include "accel/dag/node_symmetry.hpp"
#include "accel/dag/svdag.hpp"
#include "core/util/math.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

// A reference to a stored node: its address (unit address, or mask index on level
// depth-1) and the symmetry under which it is seen.
struct SymmetricDagPointer {
    uint32_t address = 0;
    uint32_t transform = 0;
    bool operator==(const SymmetricDagPointer&) const = default;
};

// The child mask of a node reflected by `mirror`: bit k moves to bit k ^ mirror.
inline uint8_t reflect_mask(uint32_t mask, uint32_t mirror) {
    return ReflectionGroup::transform_mask(mirror, mask);
}

struct SymmetricDagBuildStats {
    double total_ms = 0;       // the whole conversion from the SVDAG
    double dedup_ms = 0;       // keying nodes under the symmetries and looking them up
    uint64_t input_nodes = 0;  // SVDAG nodes read
    size_t table_bytes = 0;    // merge tables at the end of the build
};

template <class Group>
class SymmetricDagBuilder;

template <class Group>
class SymmetricDag {
public:
    static constexpr int kTransformBits = Group::kBits;
    // Long pointers: a (32 − B)-bit address below the B-bit transform.
    static constexpr int kLongTransformShift = 32 - kTransformBits;
    static constexpr uint32_t kAddressLimit = 1u << kLongTransformShift;  // addresses below this
    static constexpr uint32_t kAddressMask = kAddressLimit - 1;
    // Short pointers: a (16 − B)-bit offset from the child level's start below the transform.
    static constexpr int kShortTransformShift = 16 - kTransformBits;
    static constexpr uint32_t kShortOffsetLimit = 1u << kShortTransformShift;  // offsets below this
    static constexpr uint32_t kShortOffsetMask = kShortOffsetLimit - 1;

    // A long pointer's 32 bits. Throws Error when the address or the transform does not
    // fit its bits.
    static uint32_t encode_long_pointer(uint64_t address, uint32_t transform);
    static SymmetricDagPointer decode_long_pointer(uint32_t word) {
        return {word & kAddressMask, word >> kLongTransformShift};
    }

    using SymmetryGroup = Group;

    SymmetricDag() = default;

    // Throws Error when the result would need addresses beyond a long pointer's reach
    // (checked before the units are allocated).
    static SymmetricDag from_svdag(const Svdag& dag);

    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    bool empty() const { return empty_; }
    std::span<const uint16_t> units() const { return units_; }
    // The root as stored: address 0 (mask index 0 when depth is 1) and its transform.
    SymmetricDagPointer root() const { return root_; }
    uint32_t leaf_begin() const { return leaf_begin_; }  // unit where the level depth-1 masks start
    // Where level `level` < depth-1 starts; level depth-1 is addressed by mask index.
    uint32_t level_begin(int level) const { return uint32_t(level_begin_[size_t(level)]); }

    // Stored mask of a node on level < depth (untransformed).
    uint8_t stored_mask(uint32_t address, int level) const {
        return level == depth_ - 1 ? leaf_mask(address) : static_cast<uint8_t>(units_[address] & 0xffu);
    }
    uint8_t leaf_mask(uint32_t index) const {
        return static_cast<uint8_t>(units_[leaf_begin_ + (index >> 1)] >> (8 * (index & 1u)));
    }
    // The pointer in stored slot `stored_slot` (non-empty) of the node at `address` on
    // interior level `level` < depth-1, as stored (its own transform, not composed).
    SymmetricDagPointer stored_child(uint32_t address, int level, uint32_t stored_slot) const {
        const uint32_t header = units_[address];
        const uint32_t before = (1u << stored_slot) - 1u;
        const uint32_t at = address + 1 + child_count(header & before) + child_count((header >> 8) & before);
        if ((header >> (8 + stored_slot)) & 1u)
            return decode_long_pointer(uint32_t(units_[at]) | uint32_t(units_[at + 1]) << 16);
        const uint32_t unit = units_[at];
        return {(unit & kShortOffsetMask) + child_level_begin_[size_t(level)], unit >> kShortTransformShift};
    }
    // Child mask of a node as seen through its pointer's transform.
    uint8_t mask(const SymmetricDagPointer& node, int level) const {
        return Group::transform_mask(node.transform, stored_mask(node.address, level));
    }
    // The child in `slot` of a node seen through node.transform, with the transforms along
    // the way composed; nullopt for an empty slot. `level` < depth is the node's level.
    std::optional<SymmetricDagPointer> child(const SymmetricDagPointer& node, int level, int slot) const;
    // Addresses (mask indices on level depth-1) of one level's stored nodes, in storage order.
    std::vector<uint32_t> level_nodes(int level) const;

    size_t node_count() const;  // stored nodes plus the implicit voxel node
    size_t pointer_count() const { return pointer_count_; }
    size_t transformed_pointer_count() const { return transformed_pointer_count_; }  // not the identity
    size_t permuting_pointer_count() const { return permuting_pointer_count_; }      // permuting axes
    size_t long_pointer_count() const { return long_pointer_count_; }                // pointers of 32 bits
    size_t bytes() const { return units_.size() * sizeof(uint16_t); }
    // Bytes of the same nodes with every header and pointer a 32-bit word and the masks
    // of level depth-1 four to a word: what merging under the group alone gives.
    size_t word_bytes() const { return word_bytes_; }
    // Stored nodes per level, depth+1 entries; level `depth` counts the one voxel node
    // (not stored), as Svdag counts its one leaf.
    const std::vector<uint64_t>& level_node_counts() const { return level_counts_; }
    uint64_t voxel_count() const;  // counted over the DAG

    bool contains_voxel(const UVec3& voxel) const;
    bool occupied(const Vec3& world_point) const;
    std::vector<uint64_t> decode() const;  // Morton codes of all voxels, ascending

    const SymmetricDagBuildStats& build_stats() const { return stats_; }
    // nodes, pointers, transformed_pointers, permuting_pointers, long_pointers, bytes,
    // word_bytes, convert_ms, dedup_ms, input_nodes, table_bytes, nodes_level_<k>.
    Stats stats() const;

private:
    friend class SymmetricDagBuilder<Group>;
    VoxelGrid grid_;
    int depth_ = 0;
    bool empty_ = true;
    std::vector<uint16_t> units_;
    SymmetricDagPointer root_;
    uint32_t leaf_begin_ = 0;
    std::vector<uint64_t> level_counts_;
    std::vector<uint64_t> level_begin_;        // unit where each interior level starts, then leaf_begin_
    std::vector<uint32_t> child_level_begin_;  // per interior level: where the level below starts (0 above the masks)
    size_t pointer_count_ = 0;
    size_t transformed_pointer_count_ = 0;
    size_t permuting_pointer_count_ = 0;
    size_t long_pointer_count_ = 0;
    size_t word_bytes_ = 0;
    SymmetricDagBuildStats stats_;
};

extern template class SymmetricDag<ReflectionGroup>;
extern template class SymmetricDag<CubeSymmetryGroup>;

using Ssvdag = SymmetricDag<ReflectionGroup>;
using CubeSymmetricDag = SymmetricDag<CubeSymmetryGroup>;

}  // namespace gilab
