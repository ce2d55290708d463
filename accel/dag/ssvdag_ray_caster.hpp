#pragma once
// First-hit ray casting through an SSVDAG: the Laine–Karras walk of cast_dag_ray
// (accel/dag/dag_ray_caster.hpp) with each node's mirror applied to its child order. The
// walk moves through the octree's cells as they are; a node reached through the composed
// mirror m (the XOR of the pointers' mirrors from the root) holds the child of cell slot k
// in its stored slot k ^ m. The SSVDAG encodes the same octree as the SVDAG it was built
// from, so the answer (voxel, entry distance, nodes entered) is the one cast_dag_ray gives
// on that SVDAG.
#include "accel/dag/voxel_ray_traversal.hpp"

namespace gilab {

class Ssvdag;

// Nearest voxel along the ray between ray.tmin and ray.tmax (an empty SSVDAG is never hit).
VoxelRayHit cast_ssvdag_ray(const Ssvdag& dag, const Ray& ray);

}  // namespace gilab
