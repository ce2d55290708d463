#pragma once
// The multi-frame DAG laid out in P2's 32-bit format (§2.2, §4), as the builder
// MultiFrameDag::lay_out (accel/temporal/multi_frame_dag.hpp) gives it: per node a word
// with the 8-bit child mask, then one word address per non-empty child. Level 0 holds
// one root node per non-empty frame in time order (repeated frames repeat their root),
// so frame f is rendered by starting at root(f); everything below is shared across
// space and time. The single leaf node (mask 0) is the last word.
#include <cstdint>
#include <span>
#include <vector>
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/util/math.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

class LaidOutMultiFrameDag {
public:
    static constexpr uint32_t kEmptyFrame = 0xffffffffu;

    LaidOutMultiFrameDag() = default;
    // `roots` holds one word address per frame, kEmptyFrame for a frame with no voxels.
    LaidOutMultiFrameDag(const VoxelGrid& grid, std::vector<uint32_t> words, std::vector<uint64_t> level_begin,
                         std::vector<uint64_t> level_counts, std::vector<uint32_t> roots, uint64_t pointer_count);

    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    size_t frame_count() const { return roots_.size(); }
    std::span<const uint32_t> words() const { return words_; }
    uint32_t root(size_t frame) const;  // kEmptyFrame for an empty frame

    uint8_t mask(uint32_t node) const { return static_cast<uint8_t>(words_[node] & 0xffu); }
    uint32_t child(uint32_t node, int slot) const;  // address, or 0xffffffff for an empty slot

    std::vector<uint64_t> decode(size_t frame) const;  // Morton codes, ascending
    bool contains_voxel(size_t frame, const UVec3& voxel) const;
    size_t reachable_node_count(size_t frame) const;   // nodes below root(f), root and leaf included

    size_t node_count() const;                          // N_n: one root per non-empty frame + shared nodes
    double nodes_per_frame() const;                     // N_p = N_n / F
    size_t pointer_count() const { return pointer_count_; }
    // 32-bit pointers: 4 B per node word and per pointer. The roots need no table since
    // level 0 holds them in time order.
    size_t bytes() const { return words_.size() * sizeof(uint32_t); }
    const std::vector<uint64_t>& level_node_counts() const { return level_counts_; }  // depth+1 entries
    const std::vector<uint64_t>& level_begin() const { return level_begin_; }         // depth+2 entries
    // frames, nodes, nodes_per_frame, pointers, bytes, nodes_level_<k>.
    Stats stats() const;

private:
    VoxelGrid grid_;
    int depth_ = 0;
    std::vector<uint32_t> words_;
    std::vector<uint64_t> level_begin_;
    std::vector<uint64_t> level_counts_;
    std::vector<uint32_t> roots_;
    uint64_t pointer_count_ = 0;
};

// Frame `frame` as a DAG in the 32-bit word format, for cast_dag_ray
// (accel/dag/dag_ray_caster.hpp) and trace_voxel_ray. Throws Error for a frame outside
// the animation.
DagWordsView dag_view(const LaidOutMultiFrameDag& dag, size_t frame);
// Through the root of `frame` (an empty frame is never hit). Throws Error for a frame
// outside the animation.
VoxelRayHit trace_voxel_ray(const LaidOutMultiFrameDag& dag, size_t frame, const Ray& ray);

}  // namespace gilab
