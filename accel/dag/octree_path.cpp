#include "accel/dag/octree_path.hpp"
#include <cmath>
#include "core/util/error.hpp"
#include "core/util/morton.hpp"

namespace gilab {

OctreePath OctreePath::child(int slot) const {
    OctreePath p = *this;
    p.slots.push_back(static_cast<uint8_t>(slot));
    return p;
}

OctreeCell path_to_cell(const OctreePath& path, int depth) {
    if (path.level() > depth)
        throw Error("octree path", "path of " + std::to_string(path.level()) + " steps is deeper than the octree (" +
                                       std::to_string(depth) + " levels)");
    OctreeCell cell;
    for (uint8_t s : path.slots) {
        if (s > 7) throw Error("octree path", "child slot " + std::to_string(s) + " is not in 0..7");
        cell.first = cell.first * 2u + UVec3(s & 1u, (s >> 1) & 1u, (s >> 2) & 1u);
    }
    cell.level = path.level();
    int shift = depth - cell.level;
    cell.first <<= UVec3(uint32_t(shift));
    cell.size = 1u << shift;
    return cell;
}

OctreePath voxel_path(const UVec3& voxel, int level, int depth) {
    OctreePath p;
    p.slots.resize(level);
    for (int l = 0; l < level; ++l) {
        int shift = depth - 1 - l;
        p.slots[l] = static_cast<uint8_t>(octree_child_slot(voxel.x >> shift, voxel.y >> shift, voxel.z >> shift));
    }
    return p;
}

OctreePath morton_path(uint64_t cell_code, int level) {
    OctreePath p;
    p.slots.resize(level);
    for (int l = 0; l < level; ++l) p.slots[l] = static_cast<uint8_t>((cell_code >> (3 * (level - 1 - l))) & 7);
    return p;
}

uint64_t path_morton(const OctreePath& path) {
    uint64_t code = 0;
    for (uint8_t s : path.slots) code = code << 3 | s;
    return code;
}

Bounds3 path_to_box(const VoxelGrid& grid, const OctreePath& path) {
    OctreeCell c = path_to_cell(path, grid.depth());
    return grid.cell_bounds(c.first, c.size);
}

std::optional<OctreePath> box_to_path(const VoxelGrid& grid, const Bounds3& box, int max_level) {
    const int depth = grid.depth();
    if (max_level < 0 || max_level > depth) max_level = depth;
    if (box.empty()) return std::nullopt;
    // Shrink the box by a small fraction of a voxel so an exact cell box, whose faces
    // lie on cell boundaries, is not taken as touching its neighbours.
    const double eps = 1e-4;
    DVec3 lo = grid.to_voxel_space(box.min) + eps, hi = grid.to_voxel_space(box.max) - eps;
    hi = glm::max(lo, hi);
    const double octree = double(grid.octree_size());
    for (int k = 0; k < 3; ++k)
        if (lo[k] < 0 || hi[k] >= octree) return std::nullopt;
    UVec3 a(glm::floor(lo)), b(glm::floor(hi));
    OctreePath p;
    for (int l = 0; l < max_level; ++l) {
        int shift = depth - 1 - l;
        UVec3 sa = a >> UVec3(uint32_t(shift)), sb = b >> UVec3(uint32_t(shift));
        if (sa != sb) break;
        p.slots.push_back(static_cast<uint8_t>(octree_child_slot(sa.x, sa.y, sa.z)));
    }
    return p;
}

std::optional<OctreePath> point_to_path(const VoxelGrid& grid, const Vec3& point) {
    auto v = grid.voxel_of(point);
    if (!v) return std::nullopt;
    return voxel_path(*v, grid.depth(), grid.depth());
}

}  // namespace gilab
