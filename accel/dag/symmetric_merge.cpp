#include "accel/dag/symmetric_merge.hpp"
#include <algorithm>
#include <string>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include "accel/dag/child_mask.hpp"
#include "core/util/error.hpp"
#include "core/util/stats.hpp"

namespace gilab {
namespace {

// A node in canonical form: the smallest of its keys under the group.
template <class Group>
struct CanonicalNode {
    uint8_t mask = 0;                     // of the kept node
    uint8_t transform = 0;                // the smallest symmetry turning the kept node into the given one
    typename Group::Set symmetries = 0;   // bit t: symmetry t leaves the kept node unchanged
    uint8_t count = 0;
    uint32_t children[8] = {};            // references of the kept node's children, in slot order
    uint64_t hash = 0;
};

// Key order: the mask, then the child references in slot order (equal masks, equal counts).
inline int compare_keys(uint8_t mask_a, const uint32_t* a, uint8_t mask_b, const uint32_t* b, uint32_t count) {
    if (mask_a != mask_b) return mask_a < mask_b ? -1 : 1;
    for (uint32_t i = 0; i < count; ++i)
        if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
    return 0;
}

// `slot_refs[k]` is the reference of the child in slot k of the node as given;
// `child_symmetries` the symmetries of the level below, by id. Nodes of level depth-1
// have no children to key (their children are voxels, alike under every symmetry).
template <class Group>
void canonicalize(uint8_t mask, const uint32_t* slot_refs, const typename Group::Set* child_symmetries,
                  bool has_children, CanonicalNode<Group>& out) {
    using Merge = SymmetricMerge<Group>;
    using Set = typename Group::Set;
    const uint32_t count = has_children ? child_count(mask) : 0;
    uint32_t key[8];
    uint32_t best = 0;  // the first symmetry giving the smallest key
    Set ties = 0;       // bit t: symmetry t gives the smallest key
    for (uint32_t t = 0; t < Group::kSize; ++t) {
        const uint8_t moved = Group::transform_mask(t, mask);
        uint32_t n = 0;
        if (has_children)
            for (uint32_t j = 0; j < 8; ++j) {
                if (!(moved & (1u << j))) continue;
                const uint32_t r = slot_refs[Group::source_slot(t, j)];
                const uint32_t id = Merge::ref_id(r);
                key[n++] = Merge::ref(id, Group::reduce(Group::compose(t, Merge::ref_transform(r)), child_symmetries[id]));
            }
        const int order = t == 0 ? -1 : compare_keys(moved, key, out.mask, out.children, count);
        if (order < 0) {
            out.mask = moved;
            std::copy(key, key + n, out.children);
            best = t;
            ties = Set(1) << t;
        } else if (order == 0) {
            ties |= Set(1) << t;
        }
    }
    // The kept node K is the given node N moved by any tied t: N = inverse(t)(K), and K is
    // left unchanged exactly by t ∘ inverse(best).
    out.transform = uint8_t(Group::kSize - 1);
    out.symmetries = 0;
    for (uint32_t t = 0; t < Group::kSize; ++t)
        if (ties & (Set(1) << t)) {
            out.transform = uint8_t(std::min<uint32_t>(out.transform, Group::inverse(t)));
            out.symmetries |= Set(1) << Group::compose(t, Group::inverse(best));
        }
    out.count = uint8_t(count);
    out.hash = DagLevelTable::hash(out.mask, out.children, count);
}

}  // namespace

// One SVDAG level converted: the reference of each of its nodes (by word address from the
// level's first word) and the symmetries of each kept node (by id).
template <class Group>
struct SymmetricMerge<Group>::ConvertedLevel {
    uint32_t first_word = 0;
    std::vector<uint32_t> ref_at;
    std::vector<typename Group::Set> symmetries;

    ConvertedLevel(const Svdag& dag, const std::vector<uint32_t>& nodes) {
        if (nodes.empty()) return;
        first_word = nodes.front();
        ref_at.assign(nodes.back() + 1 + child_count(dag.mask(nodes.back())) - first_word, 0);
    }
    uint32_t ref(uint32_t svdag_address) const { return ref_at[svdag_address - first_word]; }
};

template <class Group>
SymmetricMerge<Group>::SymmetricMerge(const Svdag& dag) : dag_(dag), depth_(dag.depth()) {
    if (dag_.empty() || depth_ == 0) return;
    merged_ = true;
    tables_.resize(size_t(depth_ - 1));
    ConvertedLevel below = convert_leaf_parents();
    for (int l = depth_ - 2; l >= 0; --l) below = convert_level(l, below);
    root_ref_ = below.ref(dag_.root());
}

template <class Group>
size_t SymmetricMerge<Group>::table_bytes() const {
    size_t b = leaf_masks_.capacity();
    for (const auto& t : tables_) b += t.memory_bytes();
    return b;
}

// Level depth-1: a node is its mask alone, so only a few masks survive the symmetries.
template <class Group>
typename SymmetricMerge<Group>::ConvertedLevel SymmetricMerge<Group>::convert_leaf_parents() {
    Stopwatch t;
    const std::vector<uint32_t> nodes = dag_.level_nodes(depth_ - 1);
    ConvertedLevel c(dag_, nodes);
    std::array<uint32_t, 256> id_of;
    id_of.fill(kInvalidNode);
    for (uint32_t a : nodes) {
        CanonicalNode<Group> n;
        canonicalize<Group>(dag_.mask(a), nullptr, nullptr, false, n);
        uint32_t& id = id_of[n.mask];
        if (id == kInvalidNode) {
            id = uint32_t(leaf_masks_.size());
            leaf_masks_.push_back(n.mask);
            c.symmetries.push_back(n.symmetries);
        }
        c.ref_at[a - c.first_word] = ref(id, n.transform);
    }
    dedup_ms_ += t.elapsed_ms();
    return c;
}

template <class Group>
typename SymmetricMerge<Group>::ConvertedLevel SymmetricMerge<Group>::convert_level(int level,
                                                                                    const ConvertedLevel& below) {
    Stopwatch t;
    const std::vector<uint32_t> nodes = dag_.level_nodes(level);
    ConvertedLevel c(dag_, nodes);
    const std::span<const uint32_t> words = dag_.words();
    DagLevelTable& table = tables_[size_t(level)];
    // Keys are made in parallel a chunk at a time (bounded memory), then looked up in
    // order so that ids do not depend on the thread count.
    constexpr size_t kChunk = size_t(1) << 16;
    std::vector<CanonicalNode<Group>> keyed(std::min(nodes.size(), kChunk));
    for (size_t begin = 0; begin < nodes.size(); begin += kChunk) {
        const size_t end = std::min(nodes.size(), begin + kChunk);
        tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, 1024), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t j = r.begin(); j < r.end(); ++j) {
                const uint32_t a = nodes[j];
                const uint32_t mask = words[a] & 0xffu;
                uint32_t slot_refs[8];
                for (uint32_t s = 0, i = 0; s < 8; ++s)
                    if (mask & (1u << s)) slot_refs[s] = below.ref(words[a + 1 + i++]);
                canonicalize<Group>(uint8_t(mask), slot_refs, below.symmetries.data(), true, keyed[j - begin]);
            }
        });
        constexpr size_t kAhead = 16;  // prefetch distance: lookups miss the cache
        for (size_t j = begin; j < end; ++j) {
            if (j + kAhead < end) table.prefetch(keyed[j + kAhead - begin].hash);
            const CanonicalNode<Group>& n = keyed[j - begin];
            const size_t before = table.size();
            const uint32_t id = table.find_or_insert(n.mask, n.children, n.count, n.hash);
            if (table.size() != before) {
                if (id >= kIdLimit)
                    throw Error("symmetric DAG", "level " + std::to_string(level) + " holds more than 2^" +
                                                     std::to_string(32 - Group::kBits) + " nodes");
                c.symmetries.push_back(n.symmetries);
            }
            c.ref_at[nodes[j] - c.first_word] = ref(id, n.transform);
        }
    }
    dedup_ms_ += t.elapsed_ms();
    return c;
}

template <class Group>
SymmetricDagCounts count_symmetric_dag(const Svdag& dag) {
    using Merge = SymmetricMerge<Group>;
    SymmetricDagCounts c;
    c.level_nodes.assign(size_t(dag.depth()) + 1, 0);
    if (dag.empty()) return c;
    c.level_nodes[size_t(dag.depth())] = 1;
    const Merge merge(dag);
    if (merge.merged()) {
        for (size_t l = 0; l < merge.tables().size(); ++l) {
            const DagLevelTable& t = merge.tables()[l];
            c.level_nodes[l] = t.size();
            c.pointers += t.child_count_total();
            c.word_bytes += 4 * (t.size() + t.child_count_total());
            for (uint32_t u = 0; u < t.size(); ++u)
                for (uint32_t r : t.children(u)) {
                    c.transformed_pointers += Merge::ref_transform(r) != 0;
                    c.permuting_pointers += Merge::ref_transform(r) >= 8;
                }
        }
        c.level_nodes[size_t(dag.depth() - 1)] = merge.leaf_masks().size();
        c.word_bytes += 4 * ((merge.leaf_masks().size() + 3) / 4);
    }
    for (uint64_t n : c.level_nodes) c.nodes += n;
    return c;
}

template class SymmetricMerge<ReflectionGroup>;
template class SymmetricMerge<CubeSymmetryGroup>;
template SymmetricDagCounts count_symmetric_dag<ReflectionGroup>(const Svdag&);
template SymmetricDagCounts count_symmetric_dag<CubeSymmetryGroup>(const Svdag&);

}  // namespace gilab
