#pragma once
// Time-correlated difference tree (Ma & Shen 2000), the baseline P2 §5.3 compares with:
// a path-copying octree over frames. Frame 0 is the whole SVO; in frame f a node is
// stored again only if the voxels below it differ from frame f-1's below the same
// place (a node absent before counts as different). Unchanged subtrees are pointers
// into earlier frames. There is no merging within a frame, which is the weakness the
// multi-frame DAG removes.
//
// Nodes are stored like SVDAG nodes (children need not be contiguous): a mask word and
// one 32-bit pointer per child; leaf voxels are nodes too, as in the SVO counts. That
// costs 8 B per changed voxel (its word and its parent's pointer to it). The SVDAG and
// the time-correlated DAG keep the voxel level in their parents' masks instead; the
// *_leaves_in_masks figures count the tree stored that way, so the baseline is priced
// like the structures it is compared with. Which nodes a frame adds does not change:
// a bottom node whose mask is unchanged has exactly the same voxels.
#include <cstdint>
#include <span>
#include <vector>
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

class DifferenceTree {
public:
    explicit DifferenceTree(const VoxelGrid& grid);

    // Appends a frame (ascending Morton codes); returns the nodes it added (changed_f).
    uint64_t append_frame(std::span<const uint64_t> codes);
    std::vector<uint64_t> decode(size_t frame) const;  // ascending Morton codes

    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    size_t frame_count() const { return roots_.size(); }
    uint64_t node_count() const;                   // N_n: every stored node
    double nodes_per_frame() const;                // N_p = N_n / F
    uint64_t nodes_added(size_t frame) const { return added_.at(frame); }
    const std::vector<uint64_t>& level_node_counts() const { return level_counts_; }  // depth+1 entries
    // 4 B mask word + 4 B per child pointer per stored node + 4 B root per frame.
    size_t bytes() const;
    // The same tree with the voxel level held in the masks of the level above it: no
    // voxel nodes and no pointers to them.
    uint64_t node_count_leaves_in_masks() const;
    size_t bytes_leaves_in_masks() const;

    static constexpr uint32_t kEmptyFrame = 0xffffffffu;

private:
    struct Level {
        std::vector<uint32_t> offsets;   // record of each node id
        std::vector<uint32_t> records;   // mask, then the child ids on the level below
    };
    // Node (level, id): its mask and children.
    uint32_t mask(int level, uint32_t id) const { return levels_[level].records[levels_[level].offsets[id]]; }
    const uint32_t* children(int level, uint32_t id) const {
        return levels_[level].records.data() + levels_[level].offsets[id] + 1;
    }
    uint32_t store(int level, uint32_t mask, const uint32_t* children, uint32_t count);

    VoxelGrid grid_;
    int depth_ = 0;
    std::vector<Level> levels_;
    std::vector<uint64_t> level_counts_;
    std::vector<uint64_t> level_pointers_;  // child pointers stored by the nodes of each level
    std::vector<uint32_t> roots_;
    std::vector<uint64_t> added_;
    // The previous frame's nodes per level: ascending codes and their ids.
    std::vector<std::vector<uint64_t>> previous_codes_;
    std::vector<std::vector<uint32_t>> previous_ids_;
};

}  // namespace gilab
