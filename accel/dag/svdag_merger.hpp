#pragma once
// Bottom-up merging of Morton-sorted voxels into per-level unique-node tables that the
// caller owns (P2 §2.2). One merger serves a single SVDAG build or many frames sharing
// one set of tables (the multi-frame DAG), because a node's identity is only its mask
// and its children's ids on the level below.
//
// Level `depth` holds the one leaf node (id 0); level depth-1 holds nodes whose
// children are all that leaf, so their mask is their whole key.
#include <array>
#include <cstdint>
#include <span>
#include <vector>
#include "accel/dag/dag_level_table.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

// Throws Error (prefixed by `where`) unless `codes` are strictly ascending Morton codes
// inside the grid.
void check_voxel_codes(const VoxelGrid& grid, std::span<const uint64_t> codes, const char* where);

class SvdagMerger {
public:
    // `tables` must hold depth+1 levels and outlive the merger.
    SvdagMerger(std::vector<DagLevelTable>& tables, int depth);

    int depth() const { return depth_; }
    uint32_t leaf_id();
    // Id on level depth-1 of the node whose (leaf) children are given by `mask`.
    uint32_t bottom_id(uint8_t mask);

    // Merges one subtree given by its ascending voxel codes up to level `top` and
    // returns its id there (the codes must all lie in one level-`top` cell).
    uint32_t add_subtree(std::span<const uint64_t> codes, int top);
    // The same from the subtree's voxels as ascending 4³ blocks and their masks
    // (core/voxel/voxelizer.hpp, VoxelBlocks): a mask's bytes are the lowest nodes' masks.
    uint32_t add_subtree(std::span<const uint64_t> blocks, std::span<const uint64_t> masks, int top);
    // Nodes given on `level` (ascending codes, ids) merged up to the root; returns the
    // root's id on level 0 (kNoNode when there are none).
    uint32_t finish_top(int level, std::vector<uint64_t> codes, std::vector<uint32_t> ids);

    // Nodes on `level` (ascending codes with ids) → their parents on level-1.
    void merge_up(int level, const std::vector<uint64_t>& codes, const std::vector<uint32_t>& ids,
                  std::vector<uint64_t>& out_codes, std::vector<uint32_t>& out_ids);

    // Ids cached from the tables become stale when the tables are rebuilt.
    void forget_cache() { mask_ids_.fill(kNoNode); }

    // Time spent finding identical nodes (hashing keys and looking them up in the level
    // tables), the paper's t_B; grouping children under their parents is not counted.
    double lookup_ms() const { return lookup_ms_; }

    static constexpr uint32_t kNoNode = 0xffffffffu;

private:
    void merge_leaves(std::span<const uint64_t> codes, std::vector<uint64_t>& out_codes, std::vector<uint32_t>& out_ids);
    void merge_leaf_blocks(std::span<const uint64_t> blocks, std::span<const uint64_t> masks,
                           std::vector<uint64_t>& out_codes, std::vector<uint32_t>& out_ids);
    // Levels depth-1 .. top+1 of codes_a_/ids_a_ merged up to `top`.
    uint32_t merge_to(int top);
    void look_up_bottom(std::vector<uint32_t>& out_ids);

    std::vector<DagLevelTable>& tables_;
    int depth_;
    std::array<uint32_t, 256> mask_ids_;
    std::vector<uint64_t> codes_a_, codes_b_;
    std::vector<uint32_t> ids_a_, ids_b_;
    // One level's parents, grouped before they are looked up: masks and children.
    std::vector<uint8_t> masks_;
    std::vector<uint32_t> kids_;
    double lookup_ms_ = 0;
};

}  // namespace gilab
