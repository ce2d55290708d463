#pragma once
// What the scale experiments check and time on a symmetry-aware DAG beside the SVDAG it
// came from: the paired walk that proves both hold one octree, and the same camera rays
// cast through each DAG in turn.
#include <cstdint>
#include <functional>
#include <vector>
#include "accel/dag/svdag.hpp"
#include "accel/dag/symmetric_dag.hpp"
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/util/ray.hpp"
#include "experiments/p2_dag/dag_models.hpp"

namespace gilab::p2 {

// Whether `dag` holds the SVDAG's octree: both walked from the root together, the child
// masks compared at every pair of nodes met (equal masks everywhere = equal voxels). Each
// SVDAG node is walked once per distinct pointer it meets, so the walk costs the size of
// the DAGs, not the voxel count: it checks rows far too large to decode.
template <class Group>
bool same_octree(const Svdag& svdag, const SymmetricDag<Group>& dag);

// One ray per pixel centre of a size² image from the model's scene camera.
std::vector<Ray> camera_rays(const Model& model, int size);

// The rays cast through one DAG: each ray's hit and the rates of the repetitions.
struct RayRun {
    std::vector<VoxelRayHit> hits;
    std::vector<double> rays_per_s;
    double median_rays_per_s() const;
    double hit_fraction() const;
};
using RayCast = std::function<VoxelRayHit(const Ray&)>;

// Every ray through each caster on all threads, `reps` rounds, the casters in turn within
// a round so that a change in the machine's load hits all alike.
std::vector<RayRun> cast_in_turn(const std::vector<Ray>& rays, int reps, const std::vector<RayCast>& casts);

// Rays whose hit, or hit voxel, differs between two runs.
uint64_t disagreeing_rays(const RayRun& a, const RayRun& b);

extern template bool same_octree(const Svdag&, const Ssvdag&);
extern template bool same_octree(const Svdag&, const CubeSymmetricDag&);

}  // namespace gilab::p2
