#include "accel/dag/ssvdag_ray_caster.hpp"

#include "accel/dag/child_mask.hpp"
#include "accel/dag/dag_ray_walk.hpp"
#include "accel/dag/ssvdag.hpp"

namespace gilab {
namespace {

// The SSVDAG's units: interior nodes as a header and short or long mirrored pointers, the
// voxels' parents as bytes, two to a unit, named by index.
struct MirroredNodes {
    const Ssvdag& dag;
    DagWalkNode root() const { return {dag.root().address, dag.root().mirror}; }
    uint32_t mask(DagWalkNode node, bool voxel_parent) const {
        return voxel_parent ? dag.leaf_mask(node.address) : uint32_t(dag.units()[node.address] & 0xffu);
    }
    DagWalkNode child(DagWalkNode node, uint32_t, uint32_t slot, int level) const {
        const SsvdagPointer p = dag.stored_child(node.address, level, slot);
        return {p.address, p.mirror};
    }
};

}  // namespace

VoxelRayHit cast_ssvdag_ray(const Ssvdag& dag, const Ray& ray) {
    if (dag.empty()) return {};
    const MirroredNodes nodes{dag};
    return walk_dag_ray(nodes, dag.grid(), dag.depth(), ray);
}

}  // namespace gilab
