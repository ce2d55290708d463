#pragma once
// The face of a voxel through which a ray enters it: the shading normal of a voxel hit
// (voxels carry no surface normal of their own).
#include "core/util/math.hpp"
#include "core/util/ray.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

// Outward unit normal (±X, ±Y or ±Z) of the face of `voxel` where `ray` enters its box:
// the axis whose slab the ray enters last. A ray that starts inside the voxel gets the
// face nearest to its start point.
Vec3 voxel_entry_normal(const VoxelGrid& grid, const UVec3& voxel, const Ray& ray);

}  // namespace gilab
