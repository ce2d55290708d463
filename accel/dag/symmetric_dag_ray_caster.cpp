#include "accel/dag/symmetric_dag_ray_caster.hpp"

#include "accel/dag/child_mask.hpp"
#include "accel/dag/dag_ray_walk.hpp"

namespace gilab {
namespace {

// The DAG's units: interior nodes as a header and short or long transformed pointers, the
// voxels' parents as bytes, two to a unit, named by index.
template <class Group>
struct TransformedNodes {
    const SymmetricDag<Group>& dag;
    DagWalkNode root() const { return {dag.root().address, dag.root().transform}; }
    uint32_t mask(DagWalkNode node, bool voxel_parent) const {
        return voxel_parent ? dag.leaf_mask(node.address) : uint32_t(dag.units()[node.address] & 0xffu);
    }
    DagWalkNode child(DagWalkNode node, uint32_t, uint32_t slot, int level) const {
        const SymmetricDagPointer p = dag.stored_child(node.address, level, slot);
        return {p.address, p.transform};
    }
    // The group's rules (for the reflections, XOR).
    static uint32_t compose(uint32_t a, uint32_t b) { return Group::compose(a, b); }
    static uint32_t source_slot(uint32_t t, uint32_t slot) { return Group::source_slot(t, slot); }
};

}  // namespace

template <class Group>
VoxelRayHit cast_symmetric_dag_ray(const SymmetricDag<Group>& dag, const Ray& ray) {
    if (dag.empty()) return {};
    return walk_dag_ray(TransformedNodes<Group>{dag}, dag.grid(), dag.depth(), ray);
}

template VoxelRayHit cast_symmetric_dag_ray(const Ssvdag&, const Ray&);
template VoxelRayHit cast_symmetric_dag_ray(const CubeSymmetricDag&, const Ray&);

}  // namespace gilab
