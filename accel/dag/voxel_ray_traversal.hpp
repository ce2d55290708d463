#pragma once
// First occupied voxel along a ray in an SVO, ESVO, SVDAG or one frame of a multi-frame
// DAG: a stack-based octree walk that visits children front to back (slot order XOR the
// ray's direction signs), so the first leaf reached is the nearest. All of them give the
// same voxel, entry distance and visit count for the same voxel set, since they encode
// the same tree.
#include <cstddef>
#include <cstdint>
#include "core/util/math.hpp"
#include "core/util/ray.hpp"

namespace gilab {

class Svo;
class Esvo;
class Svdag;
class TemporalSvdag;

struct VoxelRayHit {
    bool hit = false;
    UVec3 voxel{0};            // voxel coordinates in the grid
    float t = kInfinity;       // where the ray enters the voxel (clamped to ray.tmin), units of |direction|
    uint32_t nodes_visited = 0;  // nodes whose box the ray entered, root and leaf included
};

VoxelRayHit trace_voxel_ray(const Svo& svo, const Ray& ray);
VoxelRayHit trace_voxel_ray(const Esvo& esvo, const Ray& ray);
VoxelRayHit trace_voxel_ray(const Svdag& dag, const Ray& ray);
// Through the root of `frame` (an empty frame is never hit). Throws Error for a frame
// outside the animation.
VoxelRayHit trace_voxel_ray(const TemporalSvdag& dag, size_t frame, const Ray& ray);

}  // namespace gilab
