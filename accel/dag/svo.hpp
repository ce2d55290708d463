#pragma once
// Sparse voxel octree as in P2 §2.1: per node an 8-bit child mask and, for nodes with
// children, only the index of the first child. Children of a node are contiguous;
// nodes are stored breadth-first, level by level, in Morton order within a level, so
// nothing else is needed to recover the tree. The octree has depth ceil(log2 N) for a
// grid of N voxels per axis; occupied voxels are the leaves (mask 0) at the last level.
#include <cstdint>
#include <span>
#include <vector>
#include "core/util/math.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxel_grid.hpp"
#include "core/voxel/voxelizer.hpp"

namespace gilab {

inline constexpr uint32_t kInvalidNode = 0xffffffffu;

class Svo {
public:
    Svo() = default;
    // Built bottom-up in linear time (parents are runs of code >> 3). Throws Error if
    // the codes are not strictly ascending or hold a voxel outside the grid.
    static Svo build(const VoxelGrid& grid, std::span<const uint64_t> morton_codes);
    static Svo build(const VoxelList& voxels) { return build(voxels.grid, voxels.codes); }

    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    bool empty() const { return masks_.empty(); }
    uint32_t root() const { return empty() ? kInvalidNode : 0; }

    size_t node_count() const { return masks_.size(); }
    size_t voxel_count() const;              // leaves
    size_t pointer_count() const { return first_child_.size(); }  // one per node with children
    size_t bytes() const;                    // as stored: 1 B mask per node + 4 B per pointer
    size_t pointerless_bytes() const { return node_count(); }  // 1 B/node (Schnabel & Klein)
    const std::vector<uint64_t>& level_node_counts() const { return level_counts_; }  // depth+1 entries
    uint64_t level_offset(int level) const { return level_offsets_[level]; }

    uint8_t mask(uint32_t node) const { return masks_[node]; }
    uint32_t first_child(uint32_t node) const { return first_child_[node]; }  // nodes with children only
    uint32_t child(uint32_t node, int slot) const;  // kInvalidNode for an empty slot or a leaf
    std::span<const uint8_t> masks() const { return masks_; }
    std::span<const uint32_t> first_children() const { return first_child_; }

    bool contains_voxel(const UVec3& voxel) const;
    bool occupied(const Vec3& world_point) const;
    std::vector<uint64_t> decode() const;    // Morton codes of the leaves, ascending

    double build_ms() const { return build_ms_; }
    // nodes, pointers, bytes, pointerless_bytes, voxels, build_ms, nodes_level_<k>.
    Stats stats() const;

private:
    VoxelGrid grid_;
    int depth_ = 0;
    std::vector<uint8_t> masks_;
    std::vector<uint32_t> first_child_;
    std::vector<uint64_t> level_counts_;
    std::vector<uint64_t> level_offsets_;  // depth+2 entries
    double build_ms_ = 0;
};

}  // namespace gilab
