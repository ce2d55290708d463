#include "accel/dag/symmetric_dag.hpp"
#include <algorithm>
#include <string>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include "accel/dag/child_mask.hpp"
#include "accel/dag/dag_level_table.hpp"
#include "accel/dag/symmetric_merge.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"

namespace gilab {

template <class Group>
uint32_t SymmetricDag<Group>::encode_long_pointer(uint64_t address, uint32_t transform) {
    if (address >= kAddressLimit)
        throw Error("symmetric DAG", "address " + std::to_string(address) + " does not fit in the " +
                                         std::to_string(kLongTransformShift) + " bits of a pointer");
    if (transform >= Group::kSize)
        throw Error("symmetric DAG", "transform " + std::to_string(transform) + " is not one of the " +
                                         std::to_string(Group::kSize) + " " + Group::kName);
    return transform << kLongTransformShift | uint32_t(address);
}

// The layout of the merged levels into units.
template <class Group>
class SymmetricDagBuilder {
public:
    using Dag = SymmetricDag<Group>;
    using Merge = SymmetricMerge<Group>;
    static uint32_t ref_id(uint32_t ref) { return Merge::ref_id(ref); }
    static uint32_t ref_transform(uint32_t ref) { return Merge::ref_transform(ref); }

    explicit SymmetricDagBuilder(const Svdag& dag) : dag_(dag), depth_(dag.depth()) {}

    Dag build() {
        Stopwatch clock;
        Dag out;
        out.grid_ = dag_.grid();
        out.depth_ = depth_;
        out.level_counts_.assign(depth_ + 1, 0);
        double dedup_ms = 0;
        if (!dag_.empty()) {
            out.empty_ = false;
            out.level_counts_[depth_] = 1;
            if (depth_ > 0) {
                const Merge merge(dag_);
                dedup_ms = merge.dedup_ms();
                out.stats_.table_bytes = merge.table_bytes();
                lay_out(out, merge);
            }
        }
        out.stats_.input_nodes = dag_.node_count();
        out.stats_.dedup_ms = dedup_ms;
        out.stats_.total_ms = clock.elapsed_ms();
        return out;
    }

private:
    // How many pointers of level `level` reach each node of level `level` + 1, by id.
    static std::vector<uint32_t> references_to_level_below(const Merge& merge, int level, size_t below_count) {
        std::vector<uint32_t> refs(below_count, 0);
        const DagLevelTable& t = merge.tables()[size_t(level)];
        for (uint32_t u = 0; u < t.size(); ++u)
            for (uint32_t ref : t.children(u)) ++refs[ref_id(ref)];
        return refs;
    }

    // The storage order of a level's nodes: most references per unit first, ties by id (so
    // the order, and the units, are the same for every build). Returns each id's offset
    // from the level's start in units; `total` gets the level's units.
    static std::vector<uint32_t> order_by_references(const std::vector<uint32_t>& refs,
                                                     const std::vector<uint8_t>& units, uint64_t& total) {
        std::vector<uint32_t> ids(refs.size());
        for (uint32_t i = 0; i < ids.size(); ++i) ids[i] = i;
        std::sort(ids.begin(), ids.end(), [&](uint32_t a, uint32_t b) {
            const uint64_t da = uint64_t(refs[a]) * units[b], db = uint64_t(refs[b]) * units[a];
            return da != db ? da > db : a < b;
        });
        std::vector<uint32_t> offset(refs.size());
        total = 0;
        for (uint32_t id : ids) {
            offset[id] = uint32_t(std::min<uint64_t>(total, Dag::kAddressLimit));
            total += units[id];
        }
        return offset;
    }

    // Levels ordered bottom-up (a node's size depends on which of its children sit within
    // a short pointer's reach), then laid out top-down, then the leaf masks.
    void lay_out(Dag& out, const Merge& merge) {
        const std::vector<DagLevelTable>& tables = merge.tables();  // levels 0..depth-2
        const std::vector<uint8_t>& leaf_masks = merge.leaf_masks();  // level depth-1, by id
        const uint32_t root_ref = merge.root_ref();
        const int interior = depth_ - 1;  // levels stored as header + pointers
        // offset[l][id]: from level l's start, in units (mask index on level depth-1).
        std::vector<std::vector<uint32_t>> offset(static_cast<size_t>(depth_));
        std::vector<uint64_t> level_units(size_t(interior), 0);
        {
            const std::vector<uint32_t> refs = depth_ == 1
                                                   ? std::vector<uint32_t>(leaf_masks.size(), 1)
                                                   : references_to_level_below(merge, interior - 1, leaf_masks.size());
            uint64_t masks_total = 0;  // one per mask: the level's size is known already
            offset[size_t(interior)] =
                order_by_references(refs, std::vector<uint8_t>(leaf_masks.size(), 1), masks_total);
        }
        const auto is_short = [](uint32_t child_offset) { return child_offset < Dag::kShortOffsetLimit; };
        for (int l = interior - 1; l >= 0; --l) {
            const DagLevelTable& t = tables[size_t(l)];
            std::vector<uint8_t> units(t.size());
            for (uint32_t u = 0; u < t.size(); ++u) {
                uint32_t n = 1;
                for (uint32_t ref : t.children(u)) n += is_short(offset[size_t(l + 1)][ref_id(ref)]) ? 1 : 2;
                units[u] = uint8_t(n);
            }
            const std::vector<uint32_t> refs =
                l == 0 ? std::vector<uint32_t>(t.size(), 1) : references_to_level_below(merge, l - 1, t.size());
            offset[size_t(l)] = order_by_references(refs, units, level_units[size_t(l)]);
        }

        out.level_begin_.assign(size_t(interior) + 1, 0);
        uint64_t next = 0;
        for (int l = 0; l < interior; ++l) {
            out.level_begin_[size_t(l)] = next;
            out.level_counts_[size_t(l)] = tables[size_t(l)].size();
            out.pointer_count_ += tables[size_t(l)].child_count_total();
            out.word_bytes_ += 4 * (tables[size_t(l)].size() + tables[size_t(l)].child_count_total());
            next += level_units[size_t(l)];
        }
        out.level_begin_[size_t(interior)] = next;
        out.level_counts_[size_t(depth_ - 1)] = leaf_masks.size();
        out.word_bytes_ += 4 * ((leaf_masks.size() + 3) / 4);
        // Every interior address must fit a long pointer; checked before allocating the units.
        if (next > Dag::kAddressLimit)
            throw Error("symmetric DAG", "the DAG under the " + std::string(Group::kName) + " needs " +
                                             std::to_string(next) + " units of nodes, more than the 2^" +
                                             std::to_string(Dag::kLongTransformShift) + " that " +
                                             std::to_string(Dag::kLongTransformShift) + "-bit pointers address");
        out.child_level_begin_.assign(size_t(std::max(interior, 0)), 0);
        for (int l = 0; l + 1 < interior; ++l) out.child_level_begin_[size_t(l)] = uint32_t(out.level_begin_[size_t(l + 1)]);
        out.leaf_begin_ = uint32_t(next);
        out.units_.assign(next + (leaf_masks.size() + 1) / 2, 0);
        for (size_t id = 0; id < leaf_masks.size(); ++id) {
            const uint32_t index = offset[size_t(interior)][id];
            out.units_[next + index / 2] |= uint16_t(uint32_t(leaf_masks[id]) << (8 * (index % 2)));
        }

        for (int l = 0; l < interior; ++l) {
            const DagLevelTable& t = tables[size_t(l)];
            const std::vector<uint32_t>& below = offset[size_t(l + 1)];
            const uint32_t below_begin = out.child_level_begin_[size_t(l)];
            const uint64_t begin = out.level_begin_[size_t(l)];
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(t.size()), 4096),
                              [&](const tbb::blocked_range<uint32_t>& r) {
                                  for (uint32_t u = r.begin(); u < r.end(); ++u) {
                                      const uint32_t header = t.header(u);
                                      const auto kids = t.children(u);
                                      uint16_t* node = out.units_.data() + begin + offset[size_t(l)][u];
                                      uint32_t long_mask = 0, at = 1;
                                      for (uint32_t slot = 0, k = 0; slot < 8; ++slot) {
                                          if (!(header & (1u << slot))) continue;
                                          const uint32_t child_offset = below[ref_id(kids[k])];
                                          const uint32_t transform = ref_transform(kids[k++]);
                                          if (is_short(child_offset)) {
                                              node[at++] = uint16_t(transform << Dag::kShortTransformShift | child_offset);
                                          } else {
                                              const uint32_t word = transform << Dag::kLongTransformShift | (below_begin + child_offset);
                                              node[at++] = uint16_t(word & 0xffffu);
                                              node[at++] = uint16_t(word >> 16);
                                              long_mask |= 1u << slot;
                                          }
                                      }
                                      node[0] = uint16_t(header | long_mask << 8);
                                  }
                              });
            for (uint32_t u = 0; u < t.size(); ++u)
                for (uint32_t ref : t.children(u)) {
                    out.transformed_pointer_count_ += ref_transform(ref) != 0;
                    out.permuting_pointer_count_ += ref_transform(ref) >= ReflectionGroup::kSize;
                    out.long_pointer_count_ += !is_short(below[ref_id(ref)]);
                }
            std::vector<uint32_t>().swap(offset[size_t(l)]);
        }
        out.root_ = {depth_ == 1 ? offset[0][ref_id(root_ref)] : 0u, ref_transform(root_ref)};
    }

    const Svdag& dag_;
    int depth_;
};

template <class Group>
SymmetricDag<Group> SymmetricDag<Group>::from_svdag(const Svdag& dag) {
    return SymmetricDagBuilder<Group>(dag).build();
}

template <class Group>
std::optional<SymmetricDagPointer> SymmetricDag<Group>::child(const SymmetricDagPointer& node, int level,
                                                               int slot) const {
    const uint32_t stored_slot = Group::source_slot(node.transform, uint32_t(slot));
    const uint32_t m = stored_mask(node.address, level);
    if (!(m & (1u << stored_slot))) return std::nullopt;
    if (level == depth_ - 1) return SymmetricDagPointer{0, node.transform};  // a voxel: not stored
    SymmetricDagPointer c = stored_child(node.address, level, stored_slot);
    c.transform = Group::compose(node.transform, c.transform);
    return c;
}

template <class Group>
std::vector<uint32_t> SymmetricDag<Group>::level_nodes(int level) const {
    std::vector<uint32_t> nodes;
    if (empty_ || level < 0 || level >= depth_) return nodes;
    if (level == depth_ - 1) {
        for (uint32_t i = 0; i < level_counts_[level]; ++i) nodes.push_back(i);
        return nodes;
    }
    for (uint64_t a = level_begin_[level]; a < level_begin_[level + 1];
         a += 1 + child_count(units_[a]) + child_count(units_[a] >> 8))
        nodes.push_back(uint32_t(a));
    return nodes;
}

template <class Group>
size_t SymmetricDag<Group>::node_count() const {
    size_t n = 0;
    for (uint64_t c : level_counts_) n += c;
    return n;
}

template <class Group>
uint64_t SymmetricDag<Group>::voxel_count() const {
    if (empty_) return 0;
    if (depth_ == 0) return 1;
    // Voxels below each stored node, from the leaf masks up; symmetries keep the count.
    std::vector<uint64_t> leaf_voxels(level_counts_[depth_ - 1]);
    for (uint32_t i = 0; i < leaf_voxels.size(); ++i) leaf_voxels[i] = child_count(leaf_mask(i));
    if (depth_ == 1) return leaf_voxels[root_.address];
    std::vector<uint64_t> below(leaf_begin_, 0);
    for (int l = depth_ - 2; l >= 0; --l) {
        const std::vector<uint64_t>& source = l == depth_ - 2 ? leaf_voxels : below;
        for (uint32_t a : level_nodes(l)) {
            uint64_t sum = 0;
            for (uint32_t slot = 0; slot < 8; ++slot)
                if (units_[a] & (1u << slot)) sum += source[stored_child(a, l, slot).address];
            below[a] = sum;
        }
    }
    return below[root_.address];
}

template <class Group>
bool SymmetricDag<Group>::contains_voxel(const UVec3& v) const {
    if (empty_ || v.x >= grid_.resolution || v.y >= grid_.resolution || v.z >= grid_.resolution) return false;
    SymmetricDagPointer node = root_;
    for (int l = 0; l < depth_; ++l) {
        const int shift = depth_ - 1 - l;
        const auto c = child(node, l, octree_child_slot(v.x >> shift, v.y >> shift, v.z >> shift));
        if (!c) return false;
        node = *c;
    }
    return true;
}

template <class Group>
bool SymmetricDag<Group>::occupied(const Vec3& p) const {
    const auto v = grid_.voxel_of(p);
    return v && contains_voxel(*v);
}

template <class Group>
std::vector<uint64_t> SymmetricDag<Group>::decode() const {
    std::vector<uint64_t> codes;
    if (empty_) return codes;
    if (depth_ == 0) return {0};
    struct Item {
        SymmetricDagPointer node;
        int level;
        uint64_t code;
    };
    std::vector<Item> stack{{root_, 0, 0}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        if (it.level == depth_ - 1) {
            const uint8_t m = mask(it.node, it.level);
            for (uint32_t s = 0; s < 8; ++s)
                if (m & (1u << s)) codes.push_back(it.code << 3 | s);
            continue;
        }
        for (int s = 7; s >= 0; --s)  // reversed so slot 0 pops first: Morton order
            if (const auto c = child(it.node, it.level, s))
                stack.push_back({*c, it.level + 1, it.code << 3 | uint64_t(s)});
    }
    return codes;
}

template <class Group>
Stats SymmetricDag<Group>::stats() const {
    Stats s;
    s.set("nodes", double(node_count()));
    s.set("pointers", double(pointer_count()));
    s.set("transformed_pointers", double(transformed_pointer_count()));
    s.set("permuting_pointers", double(permuting_pointer_count()));
    s.set("long_pointers", double(long_pointer_count()));
    s.set("bytes", double(bytes()));
    s.set("word_bytes", double(word_bytes()));
    s.set("convert_ms", stats_.total_ms);
    s.set("dedup_ms", stats_.dedup_ms);
    s.set("input_nodes", double(stats_.input_nodes));
    s.set("table_bytes", double(stats_.table_bytes));
    for (size_t l = 0; l < level_counts_.size(); ++l)
        s.set("nodes_level_" + std::to_string(l), double(level_counts_[l]));
    return s;
}

template class SymmetricDag<ReflectionGroup>;
template class SymmetricDag<CubeSymmetryGroup>;

}  // namespace gilab
