#pragma once
// A cubic voxel grid: a box in world space (min corner + side length) cut into
// resolution³ voxels. Any resolution 1..2^21 is allowed, not only powers of two; the
// octrees built over a grid have depth ceil(log2 resolution), and voxel coordinates
// beyond resolution−1 are simply never occupied.
#include <cstdint>
#include <optional>
#include <string>
#include "core/util/math.hpp"

namespace gilab {

inline constexpr uint32_t kMaxVoxelResolution = 1u << 21;  // 64-bit Morton codes

// A box of voxel coordinates, [begin, end) per axis.
struct VoxelRegion {
    UVec3 begin{0};
    UVec3 end{0};

    bool empty() const { return end.x <= begin.x || end.y <= begin.y || end.z <= begin.z; }
    uint64_t volume() const;  // voxels inside; 0 if empty
    bool contains(const UVec3& v) const {
        return v.x >= begin.x && v.y >= begin.y && v.z >= begin.z && v.x < end.x && v.y < end.y &&
               v.z < end.z;
    }
    VoxelRegion intersect(const VoxelRegion& other) const;
};

struct VoxelGrid {
    Vec3 origin{0};          // minimum corner
    float extent = 1.0f;     // side length of the cube
    uint32_t resolution = 1; // voxels per axis

    // The smallest cube that holds `bounds`, grown by `margin` (a fraction of its side)
    // so surfaces on the bounding box still fall strictly inside. Throws Error for an
    // empty or non-finite box and for a bad resolution.
    static VoxelGrid enclosing(const Bounds3& bounds, uint32_t resolution, double margin = 1e-3);

    // Throws Error (prefixed by `where`) for resolution 0, above 2^21, or a
    // non-positive / non-finite box.
    void validate(const std::string& where = "voxel grid") const;

    double voxel_size() const { return static_cast<double>(extent) / resolution; }
    int depth() const;                                   // ceil(log2 resolution)
    uint32_t octree_size() const { return 1u << depth(); }  // voxels per axis of the octree
    VoxelRegion full_region() const { return {UVec3(0), UVec3(resolution)}; }
    Bounds3 bounds() const;
    // World box of an aligned cell of `size` voxels per axis whose minimum voxel is `first`.
    Bounds3 cell_bounds(const UVec3& first, uint32_t size = 1) const;
    // World point → continuous voxel coordinates (voxel v spans [v, v+1) per axis).
    DVec3 to_voxel_space(const Vec3& p) const;
    // The voxel holding p, or nullopt outside the grid. Upper faces belong to the next
    // voxel, so the grid's own upper faces are outside.
    std::optional<UVec3> voxel_of(const Vec3& p) const;
};

}  // namespace gilab
