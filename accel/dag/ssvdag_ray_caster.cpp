#include "accel/dag/ssvdag_ray_caster.hpp"

#include "accel/dag/child_mask.hpp"
#include "accel/dag/dag_ray_walk.hpp"
#include "accel/dag/ssvdag.hpp"

namespace gilab {
namespace {

// The SSVDAG's words: interior nodes as the SVDAG's with mirrored pointers, the voxels'
// parents as bytes, four to a word, named by index.
struct MirroredNodes {
    const uint32_t* words;
    uint32_t leaf_begin;
    DagWalkNode root_node;
    DagWalkNode root() const { return root_node; }
    uint32_t mask(DagWalkNode node, bool voxel_parent) const {
        if (voxel_parent) return (words[leaf_begin + (node.address >> 2)] >> (8 * (node.address & 3u))) & 0xffu;
        return words[node.address] & 0xffu;
    }
    DagWalkNode child(DagWalkNode node, uint32_t mask, uint32_t slot) const {
        const SsvdagPointer p = decode_ssvdag_pointer(words[node.address + 1 + child_rank(mask, int(slot))]);
        return {p.address, p.mirror};
    }
};

}  // namespace

VoxelRayHit cast_ssvdag_ray(const Ssvdag& dag, const Ray& ray) {
    if (dag.empty()) return {};
    const MirroredNodes nodes{dag.words().data(), dag.leaf_begin(), {dag.root().address, dag.root().mirror}};
    return walk_dag_ray(nodes, dag.grid(), dag.depth(), ray);
}

}  // namespace gilab
