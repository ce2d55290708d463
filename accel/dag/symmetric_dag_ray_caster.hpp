#pragma once
// First-hit ray casting through a symmetry-aware DAG (SSVDAG or CubeSymmetricDag): the
// Laine–Karras walk of cast_dag_ray (accel/dag/dag_ray_caster.hpp) with each node's
// transform applied to its child order. The walk moves through the octree's cells as they
// are; a node reached through the composed transform t holds the child of cell slot k in
// its stored slot source_slot(t, k) (for a mirror m, k ^ m). The DAG encodes the same
// octree as the SVDAG it was built from, so the answer (voxel, entry distance, nodes
// entered) is the one cast_dag_ray gives on that SVDAG.
#include "accel/dag/symmetric_dag.hpp"
#include "accel/dag/voxel_ray_traversal.hpp"

namespace gilab {

// Nearest voxel along the ray between ray.tmin and ray.tmax (an empty DAG is never hit).
template <class Group>
VoxelRayHit cast_symmetric_dag_ray(const SymmetricDag<Group>& dag, const Ray& ray);

extern template VoxelRayHit cast_symmetric_dag_ray(const Ssvdag&, const Ray&);
extern template VoxelRayHit cast_symmetric_dag_ray(const CubeSymmetricDag&, const Ray&);

}  // namespace gilab
