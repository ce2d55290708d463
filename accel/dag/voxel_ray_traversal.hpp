#pragma once
// First occupied voxel along a ray in an SVO, ESVO, SVDAG or one frame of a multi-frame
// DAG: a stack-based octree walk that visits children front to back (slot order XOR the
// ray's direction signs), so the first leaf reached is the nearest. All of them give the
// same voxel, entry distance and visit count for the same voxel set, since they encode
// the same tree.
#include <cstddef>
#include <cstdint>
#include <span>
#include "core/util/math.hpp"
#include "core/util/ray.hpp"
#include "core/voxel/voxel_grid.hpp"

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

// One DAG in P2's 32-bit word format (an Svdag, or one frame of a laid-out multi-frame
// DAG, accel/temporal/laid_out_multi_frame_dag.hpp): its words, the word address of the
// root, and its grid.
struct DagWordsView {
    std::span<const uint32_t> words;
    uint32_t root = 0;
    int depth = 0;  // levels below the root; the voxels are at level `depth`
    VoxelGrid grid;
    bool empty = true;
};
// Through the view's root (an empty view is never hit).
VoxelRayHit trace_voxel_ray(const DagWordsView& dag, const Ray& ray);

}  // namespace gilab
