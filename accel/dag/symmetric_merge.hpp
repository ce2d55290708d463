#pragma once
// An SVDAG's subtrees that are equal up to a node symmetry (node_symmetry.hpp) merged
// into one, level by level from the voxels' parents up. SymmetricDag (symmetric_dag.hpp)
// stores the result: the SSVDAG for the 8 reflections, the cube-symmetric DAG for all 48
// symmetries of the cube.
//
// Each node is keyed as (mask, then (child id, child transform) per non-empty slot in
// slot order) under every symmetry t of the group; the smallest key is kept, and the node
// is referred to by that key's id plus the smallest transform that turns the kept node
// back into it. Child transforms are reduced by the child's own symmetries before keying,
// so a symmetric subtree has one key: the result is the unique minimal DAG under the
// group, the same for every build and thread count.
#include <cstdint>
#include <vector>
#include "accel/dag/dag_level_table.hpp"
#include "accel/dag/node_symmetry.hpp"
#include "accel/dag/svdag.hpp"

namespace gilab {

template <class Group>
class SymmetricMerge {
public:
    // A child while merging: its id on its level and the transform it is seen through,
    // id << kBits | transform, so comparing references compares (id, transform).
    static uint32_t ref(uint32_t id, uint32_t transform) { return id << Group::kBits | transform; }
    static uint32_t ref_id(uint32_t r) { return r >> Group::kBits; }
    static uint32_t ref_transform(uint32_t r) { return r & ((1u << Group::kBits) - 1u); }
    static constexpr uint64_t kIdLimit = uint64_t(1) << (32 - Group::kBits);  // ids per level below this

    // Merges `dag` (nothing for an empty DAG or depth 0). Throws Error when a level would
    // hold kIdLimit nodes or more.
    explicit SymmetricMerge(const Svdag& dag);

    bool merged() const { return merged_; }
    int depth() const { return depth_; }
    // Levels 0..depth-2: the kept nodes, children as references to the level below.
    const std::vector<DagLevelTable>& tables() const { return tables_; }
    // Level depth-1 (children are voxels, alike under every symmetry): the kept masks by id.
    const std::vector<uint8_t>& leaf_masks() const { return leaf_masks_; }
    uint32_t root_ref() const { return root_ref_; }
    double dedup_ms() const { return dedup_ms_; }  // keying and looking up
    size_t table_bytes() const;

private:
    struct ConvertedLevel;
    ConvertedLevel convert_leaf_parents();
    ConvertedLevel convert_level(int level, const ConvertedLevel& below);

    const Svdag& dag_;
    int depth_;
    bool merged_ = false;
    std::vector<DagLevelTable> tables_;
    std::vector<uint8_t> leaf_masks_;
    uint32_t root_ref_ = 0;
    double dedup_ms_ = 0;
};

extern template class SymmetricMerge<ReflectionGroup>;
extern template class SymmetricMerge<CubeSymmetryGroup>;

// Sizes of the DAG merged under a group, counted as the SSVDAG counts its own.
struct SymmetricDagCounts {
    std::vector<uint64_t> level_nodes;   // depth+1 entries; level depth is the one voxel node
    uint64_t nodes = 0;                  // all levels
    uint64_t pointers = 0;               // child pointers of levels 0..depth-2
    uint64_t transformed_pointers = 0;   // with a transform other than the identity
    uint64_t permuting_pointers = 0;     // with a transform that permutes axes (not a reflection alone)
    // Every header and pointer a 32-bit word, the voxels' parents' masks four to a word
    // (Ssvdag::word_bytes for the reflections).
    uint64_t word_bytes = 0;
};

template <class Group>
SymmetricDagCounts count_symmetric_dag(const Svdag& dag);

}  // namespace gilab
