#include "accel/dag/dag_ray_caster.hpp"

#include "accel/dag/child_mask.hpp"
#include "accel/dag/dag_ray_walk.hpp"
#include "accel/dag/svdag.hpp"

namespace gilab {
namespace {

// P2's words: a node's first word holds its mask, its children's addresses follow.
struct WordNodes {
    const uint32_t* words;
    uint32_t root_address;
    DagWalkNode root() const { return {root_address, 0}; }
    uint32_t mask(DagWalkNode node, bool) const { return words[node.address] & 0xffu; }
    DagWalkNode child(DagWalkNode node, uint32_t mask, uint32_t slot, int) const {
        return {words[node.address + 1 + child_rank(mask, int(slot))], 0};
    }
};

}  // namespace

DagWordsView dag_view(const Svdag& dag) {
    DagWordsView v;
    v.words = dag.words();
    v.depth = dag.depth();
    v.grid = dag.grid();
    v.empty = dag.empty();
    v.root = v.empty ? 0 : dag.root();
    return v;
}

VoxelRayHit cast_dag_ray(const DagWordsView& dag, const Ray& ray) {
    if (dag.empty) return {};
    return walk_dag_ray(WordNodes{dag.words.data(), dag.root}, dag.grid, dag.depth, ray);
}

}  // namespace gilab
