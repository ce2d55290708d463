#pragma once
// Fast first-hit ray casting through a DAG in P2's 32-bit word format (Svdag, one frame
// of a TemporalSvdag): the octree walk of Laine & Karras 2010 (ESVO, appendix), in
// single precision in the [1,2]³ cube with the ray mirrored so that it runs towards −x,
// −y, −z. Children are entered front to back with no sorting, a step to a neighbour is
// one comparison per axis, and a pop finds the ancestor to resume from the highest
// differing bit of the position, so no per-child box test is made.
//
// It answers the same question as trace_voxel_ray (accel/dag/voxel_ray_traversal.hpp), the
// double-precision reference it is tested against: the nearest occupied voxel, where the
// ray enters it, and how many nodes the ray entered. Entry distances agree to single
// precision; where a ray passes exactly through an edge shared by occupied voxels, the
// two may pick different voxels at the same distance.
#include <cstdint>
#include <span>
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

// One DAG to cast into: its words, the word address of the root, and its grid.
struct DagWordsView {
    std::span<const uint32_t> words;
    uint32_t root = 0;
    int depth = 0;  // levels below the root; the voxels are at level `depth`
    VoxelGrid grid;
    bool empty = true;
};

DagWordsView dag_view(const Svdag& dag);
// Throws Error for a frame outside the animation.
DagWordsView dag_view(const TemporalSvdag& dag, size_t frame);

// Nearest voxel along the ray between ray.tmin and ray.tmax.
VoxelRayHit cast_dag_ray(const DagWordsView& dag, const Ray& ray);

}  // namespace gilab
