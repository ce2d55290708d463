#pragma once
// Fast first-hit ray casting through a DAG in P2's 32-bit word format (Svdag, one frame
// of a LaidOutMultiFrameDag): the octree walk of Laine & Karras 2010 (dag_ray_walk.hpp),
// so no per-child box test is made.
//
// It answers the same question as trace_voxel_ray (accel/dag/voxel_ray_traversal.hpp), the
// double-precision reference it is tested against: the nearest occupied voxel, where the
// ray enters it, and how many nodes the ray entered. Entry distances agree to single
// precision; where a ray passes exactly through an edge shared by occupied voxels, the
// two may pick different voxels at the same distance.
#include "accel/dag/voxel_ray_traversal.hpp"

namespace gilab {

// The view of an Svdag (one frame of a laid-out multi-frame DAG: its own dag_view,
// accel/temporal/laid_out_multi_frame_dag.hpp). DagWordsView is in voxel_ray_traversal.hpp.
DagWordsView dag_view(const Svdag& dag);

// Nearest voxel along the ray between ray.tmin and ray.tmax.
VoxelRayHit cast_dag_ray(const DagWordsView& dag, const Ray& ray);

}  // namespace gilab
