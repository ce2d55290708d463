#pragma once
// First occupied voxel along a ray in an SVO, ESVO or SVDAG: a stack-based octree walk
// that visits children front to back (slot order XOR the ray's direction signs), so the
// first leaf reached is the nearest. All three structures give the same voxel, entry
// distance and visit count, since they encode the same tree.
#include <cstdint>
#include "core/math.hpp"
#include "core/ray.hpp"

namespace gilab {

class Svo;
class Esvo;
class Svdag;

struct VoxelRayHit {
    bool hit = false;
    UVec3 voxel{0};            // voxel coordinates in the grid
    float t = kInfinity;       // where the ray enters the voxel (clamped to ray.tmin), units of |direction|
    uint32_t nodes_visited = 0;  // nodes whose box the ray entered, root and leaf included
};

VoxelRayHit trace_voxel_ray(const Svo& svo, const Ray& ray);
VoxelRayHit trace_voxel_ray(const Esvo& esvo, const Ray& ray);
VoxelRayHit trace_voxel_ray(const Svdag& dag, const Ray& ray);

}  // namespace gilab
