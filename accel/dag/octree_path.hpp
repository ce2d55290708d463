#pragma once
// Where an octree (or DAG) node is in space (P2 §2.3). A DAG node stands for every
// region whose traversal path leads to it, so a position is a path: the child slot
// (x | y<<1 | z<<2, Morton order) taken at each level from the root. These functions
// map a path to its cell and world box and back.
#include <cstdint>
#include <optional>
#include <vector>
#include "core/util/math.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

struct OctreePath {
    std::vector<uint8_t> slots;  // slots[k] is taken at level k (root = level 0)

    int level() const { return static_cast<int>(slots.size()); }  // of the node reached
    OctreePath child(int slot) const;
    bool operator==(const OctreePath&) const = default;
};

// A cell of the octree over a grid, in voxel units: `size` voxels per axis from `first`.
struct OctreeCell {
    UVec3 first{0};
    uint32_t size = 1;
    int level = 0;
};

// Throws Error if the path is longer than `depth` or holds a slot above 7.
OctreeCell path_to_cell(const OctreePath& path, int depth);
// Path of the level-`level` cell holding `voxel` in an octree of `depth` levels.
OctreePath voxel_path(const UVec3& voxel, int level, int depth);
// Path from a Morton code of the cell coordinates on `level` (code of voxel >> (depth-level)).
OctreePath morton_path(uint64_t cell_code, int level);
uint64_t path_morton(const OctreePath& path);

// World box of the node reached by `path` in the octree over `grid`.
Bounds3 path_to_box(const VoxelGrid& grid, const OctreePath& path);
// Path of the deepest cell (at most `max_level`, default the leaf level) that contains
// the whole box; nullopt if the box leaves the octree. An exact cell box maps back to
// its own path.
std::optional<OctreePath> box_to_path(const VoxelGrid& grid, const Bounds3& box, int max_level = -1);
// Path of the leaf voxel (level = grid depth) holding a world point; nullopt outside.
std::optional<OctreePath> point_to_path(const VoxelGrid& grid, const Vec3& point);

// Morton codes of every leaf below `root`, ascending: a depth-first descent that takes
// child slots in Morton order. child(node, slot) returns a child or `none`;
// is_leaf(node, level) ends a path. Shared by the pointer-based trees (ESVO, SVDAG).
template <typename Child, typename IsLeaf>
std::vector<uint64_t> collect_leaf_codes(uint32_t root, uint32_t none, Child&& child, IsLeaf&& is_leaf) {
    struct Item {
        uint32_t node;
        int level;
        uint64_t code;
    };
    std::vector<uint64_t> codes;
    std::vector<Item> stack{{root, 0, 0}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        if (is_leaf(it.node, it.level)) {
            codes.push_back(it.code);
            continue;
        }
        for (int s = 7; s >= 0; --s) {  // reversed so slot 0 pops first: Morton order
            const uint32_t c = child(it.node, s);
            if (c != none) stack.push_back({c, it.level + 1, it.code << 3 | uint64_t(s)});
        }
    }
    return codes;
}

}  // namespace gilab
