#pragma once
// Efficient sparse voxel octree layout (Laine & Karras 2010). Each node with children is
// a 64-bit child descriptor: 32 bits of (15-bit child pointer | far bit | 8-bit valid
// mask | 8-bit leaf mask), then 32 bits of contour information (unused here: zero).
// Children that are leaves (occupied voxels) have no descriptor of their own; the
// descriptors of a node's other children are contiguous. The child pointer is the
// offset, in 32-bit words, from the descriptor to its children; when that does not fit
// in 15 bits the far bit is set and the field points to a 32-bit far pointer stored
// right after the descriptor's block, which holds the full offset. Blocks are laid out
// depth-first (a block, its far pointers, then each child's subtree in order).
// Page headers and contour data of the original are not built.
#include <cstdint>
#include <span>
#include <vector>
#include "accel/dag/svo.hpp"
#include "core/util/math.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

class Esvo {
public:
    static constexpr uint32_t kLeafChild = 0xfffffffeu;  // child() of a leaf slot

    Esvo() = default;
    static Esvo from_svo(const Svo& svo);

    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    bool empty() const { return voxel_count_ == 0; }
    uint32_t root() const { return 0; }  // a descriptor address unless depth() == 0
    std::span<const uint32_t> words() const { return words_; }

    uint8_t valid_mask(uint32_t descriptor) const { return uint8_t(words_[descriptor] >> 8); }
    uint8_t leaf_mask(uint32_t descriptor) const { return uint8_t(words_[descriptor]); }
    bool far(uint32_t descriptor) const { return (words_[descriptor] >> 16) & 1u; }
    // Word address of the first child descriptor (far pointers resolved).
    uint32_t child_block(uint32_t descriptor) const;
    // Descriptor address of the child in `slot`, kLeafChild for a leaf, kInvalidNode if empty.
    uint32_t child(uint32_t descriptor, int slot) const;

    size_t descriptor_count() const { return descriptors_; }
    size_t node_count() const { return descriptors_; }
    size_t far_pointer_count() const { return far_pointers_; }
    size_t pointer_count() const { return child_pointers_ + far_pointers_; }  // child pointers used + far pointers
    size_t bytes() const { return words_.size() * sizeof(uint32_t); }      // 8 B per descriptor + 4 B per far pointer
    size_t voxel_count() const { return voxel_count_; }
    // Descriptors per level (depth+1 entries; the leaf level has none).
    const std::vector<uint64_t>& level_node_counts() const { return level_counts_; }

    bool contains_voxel(const UVec3& voxel) const;
    bool occupied(const Vec3& world_point) const;
    std::vector<uint64_t> decode() const;

    double build_ms() const { return build_ms_; }
    // nodes, descriptors, pointers, far_pointers, bytes, voxels, build_ms, nodes_level_<k>.
    Stats stats() const;

private:
    VoxelGrid grid_;
    int depth_ = 0;
    std::vector<uint32_t> words_;
    std::vector<uint64_t> level_counts_;
    size_t descriptors_ = 0, far_pointers_ = 0, child_pointers_ = 0, voxel_count_ = 0;
    double build_ms_ = 0;
};

}  // namespace gilab
