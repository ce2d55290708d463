#pragma once
// The 3-state shadow octree of one aligned cell of the light-space grid (P2 §3.1): each
// interior node has a 16-bit child mask (2 bits of ShadowState per child) and the index
// of its first Boundary child on the next level; only Boundary children are subdivided.
// Nodes are stored breadth-first, level by level, in Morton order within a level, as
// the plain SVO is. The subdivision stops at 4×4×4 leaves, each a 64-bit mask whose bit
// (x + 4y + 16z) is set when that voxel is in shadow.
//
// Undefined space that survives the rules (an undefined child of a Boundary node, an
// undefined voxel of a mixed leaf) may be stored as lit or as shadow: the paper leaves
// the choice to whichever gives the simpler DAG. It is a build option, `undefined_as`.
//
// The states follow the paper's bottom-up rules (combine_child_states). The build gets
// them top-down from the depth pyramids, which gives the same states: a cell's rule
// result depends only on whether it holds a lit voxel and whether it holds a shadow
// voxel, and the pyramids answer both for any aligned cell (see cell_state).
#include <cstdint>
#include <vector>
#include "accel/shadow/light_depth_maps.hpp"
#include "accel/shadow/shadow_state.hpp"
#include "core/util/math.hpp"

namespace gilab {

inline constexpr int kShadowLeafLevels = 2;  // a leaf spans 2 octree levels: 4³ voxels

class ShadowSvo {
public:
    // The octree of the cell at `cell_level` whose minimum voxel is `cell_first`, in a
    // grid of octree depth `grid_depth` (≥ 3). The cell's columns must lie in `tile`.
    static ShadowSvo build(const LightDepthTile& tile, const UVec3& cell_first, int cell_level, int grid_depth,
                           ShadowState undefined_as = ShadowState::Shadow);

    ShadowState root_state() const { return root_state_; }  // Boundary: the tree below exists
    int cell_level() const { return cell_level_; }
    int grid_depth() const { return grid_depth_; }
    int leaf_level() const { return grid_depth_ - kShadowLeafLevels; }
    // Interior levels cell_level .. leaf_level-1, indexed from 0 at the cell's level.
    size_t interior_levels() const { return masks_.size(); }
    const std::vector<uint16_t>& masks(size_t i) const { return masks_[i]; }
    const std::vector<uint32_t>& first_child(size_t i) const { return first_child_[i]; }
    const std::vector<uint64_t>& leaves() const { return leaves_; }
    size_t node_count() const;  // interior nodes plus leaves

    // Assembles a tree from its parts (used to expand a DAG back into an SVO).
    static ShadowSvo from_parts(ShadowState root_state, int cell_level, int grid_depth,
                                std::vector<std::vector<uint16_t>> masks,
                                std::vector<std::vector<uint32_t>> first_child, std::vector<uint64_t> leaves);
    bool operator==(const ShadowSvo&) const = default;

private:
    ShadowState root_state_ = ShadowState::Lit;
    int cell_level_ = 0;
    int grid_depth_ = 0;
    std::vector<std::vector<uint16_t>> masks_;
    std::vector<std::vector<uint32_t>> first_child_;
    std::vector<uint64_t> leaves_;
};

// Shadow bits of the 4³ leaf whose minimum voxel is `first`.
uint64_t shadow_leaf_bits(const LightDepthTile& tile, const UVec3& first, ShadowState undefined_as);

}  // namespace gilab
