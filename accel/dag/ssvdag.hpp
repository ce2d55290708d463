#pragma once
// Symmetry-aware sparse voxel DAG (Villanueva, Marton & Gobbetti, I3D 2016): the SVDAG
// with subtrees that are equal up to a reflection merged as well. A child pointer names a
// stored node and a 3-bit mirror m; bit a of m set means the child's subtree is the
// stored one reflected along axis a about the child's centre plane. Reflecting a node by
// m moves the child of slot k to slot k ^ m and reflects each child subtree by m too, so
// a child (node, c) of a node seen through mirror m is (node, c ^ m).
//
// Built from an Svdag bottom-up, level by level from the voxels' parents: each node is
// keyed as (mask, then (child id, child mirror) per non-empty slot in slot order) under
// all 8 reflections; the smallest key is stored and the node is referred to as that key
// plus the smallest mirror that gives it. Child mirrors are reduced by the child's own
// symmetries before keying, so a symmetric subtree has one key and the result is the
// unique minimal SSVDAG over reflections: the same for every build and thread count.
//
// Implemented from the paper: merging under the 8 reflections along the grid axes, the
// mirror carried in each pointer, and ray casting with the mirror applied to the child
// order (ssvdag_ray_caster.hpp). Not implemented: the variable-bit-rate pointers (16-bit
// pointers to the most referenced nodes), 4³-voxel leaves as 64-bit masks and the
// out-of-core build.
//
// Storage, all 32-bit words; addresses count words:
// - levels 0..depth-2, laid out top-down from address 0: per node a header word (its
//   8-bit child mask) and then, per non-empty child in slot order, a pointer word
//   mirror << 29 | address (29-bit address, so at most 2^29 words);
// - level depth-1 (nodes whose children are voxels): their 8-bit masks, four to a word,
//   after the last interior level; pointers to them hold the mask's index;
// - level depth (the voxel) is not stored.
// The root's pointer (address 0, or mask index 0 when depth is 1, and its mirror) is
// kept beside the words.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>
#include "accel/dag/svdag.hpp"
#include "core/util/math.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

inline constexpr int kSsvdagMirrorShift = 29;
inline constexpr uint32_t kSsvdagAddressLimit = 1u << kSsvdagMirrorShift;  // addresses below this
inline constexpr uint32_t kSsvdagAddressMask = kSsvdagAddressLimit - 1;

// A reference to a stored node: its address (word address, or mask index on level
// depth-1) and the reflection under which it is seen.
struct SsvdagPointer {
    uint32_t address = 0;
    uint32_t mirror = 0;
    bool operator==(const SsvdagPointer&) const = default;
};

// Throws Error when the address needs more than 29 bits or the mirror more than 3.
uint32_t encode_ssvdag_pointer(uint64_t address, uint32_t mirror);
inline SsvdagPointer decode_ssvdag_pointer(uint32_t word) {
    return {word & kSsvdagAddressMask, word >> kSsvdagMirrorShift};
}

namespace detail {
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
}  // namespace detail

// The child mask of a node reflected by `mirror`: bit k moves to bit k ^ mirror.
inline uint8_t reflect_mask(uint32_t mask, uint32_t mirror) {
    return detail::kReflectedMasks[mirror & 7u][mask & 0xffu];
}

struct SsvdagBuildStats {
    double total_ms = 0;       // the whole conversion from the SVDAG
    double dedup_ms = 0;       // keying nodes under the reflections and looking them up
    uint64_t input_nodes = 0;  // SVDAG nodes read
    size_t table_bytes = 0;    // merge tables at the end of the build
};

class Ssvdag {
public:
    Ssvdag() = default;

    // Throws Error when the result would need addresses of 2^29 words or more (checked
    // before the words are allocated).
    static Ssvdag from_svdag(const Svdag& dag);

    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    bool empty() const { return empty_; }
    std::span<const uint32_t> words() const { return words_; }
    // The root as stored: address 0 (mask index 0 when depth is 1) and its mirror.
    SsvdagPointer root() const { return root_; }
    uint32_t leaf_begin() const { return leaf_begin_; }  // word where the level depth-1 masks start

    // Stored mask of a node on level < depth (unreflected).
    uint8_t stored_mask(uint32_t address, int level) const {
        return level == depth_ - 1 ? leaf_mask(address) : static_cast<uint8_t>(words_[address] & 0xffu);
    }
    uint8_t leaf_mask(uint32_t index) const {
        return static_cast<uint8_t>(words_[leaf_begin_ + (index >> 2)] >> (8 * (index & 3u)));
    }
    // Child mask of a node as seen through its pointer's mirror.
    uint8_t mask(const SsvdagPointer& node, int level) const {
        return reflect_mask(stored_mask(node.address, level), node.mirror);
    }
    // The child in `slot` of a node seen through node.mirror, with the mirrors along the
    // way composed; nullopt for an empty slot. `level` < depth is the node's level.
    std::optional<SsvdagPointer> child(const SsvdagPointer& node, int level, int slot) const;
    // Addresses (mask indices on level depth-1) of one level's stored nodes, in storage order.
    std::vector<uint32_t> level_nodes(int level) const;

    size_t node_count() const;  // stored nodes plus the implicit voxel node
    size_t pointer_count() const { return pointer_count_; }
    size_t mirrored_pointer_count() const { return mirrored_pointer_count_; }  // pointers with a mirror
    size_t bytes() const { return words_.size() * sizeof(uint32_t); }
    // Stored nodes per level, depth+1 entries; level `depth` counts the one voxel node
    // (not stored), as Svdag counts its one leaf.
    const std::vector<uint64_t>& level_node_counts() const { return level_counts_; }
    uint64_t voxel_count() const;  // counted over the DAG

    bool contains_voxel(const UVec3& voxel) const;
    bool occupied(const Vec3& world_point) const;
    std::vector<uint64_t> decode() const;  // Morton codes of all voxels, ascending

    const SsvdagBuildStats& build_stats() const { return stats_; }
    // nodes, pointers, mirrored_pointers, bytes, convert_ms, dedup_ms, input_nodes,
    // table_bytes, nodes_level_<k>.
    Stats stats() const;

private:
    friend class SsvdagBuilder;
    VoxelGrid grid_;
    int depth_ = 0;
    bool empty_ = true;
    std::vector<uint32_t> words_;
    SsvdagPointer root_;
    uint32_t leaf_begin_ = 0;
    std::vector<uint64_t> level_counts_;
    std::vector<uint64_t> level_begin_;  // word address where each interior level starts; depth entries
    size_t pointer_count_ = 0;
    size_t mirrored_pointer_count_ = 0;
    SsvdagBuildStats stats_;
};

}  // namespace gilab
