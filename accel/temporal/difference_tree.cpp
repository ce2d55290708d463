#include "accel/temporal/difference_tree.hpp"
#include <array>
#include <string>
#include "accel/dag/child_mask.hpp"
#include "accel/dag/svdag_merger.hpp"
#include "core/util/error.hpp"

namespace gilab {
namespace {
constexpr const char* kWhat = "difference tree";
}  // namespace

DifferenceTree::DifferenceTree(const VoxelGrid& grid) : grid_(grid) {
    grid_.validate(kWhat);
    depth_ = grid_.depth();
    levels_.resize(depth_ + 1);
    level_counts_.assign(depth_ + 1, 0);
    level_pointers_.assign(depth_ + 1, 0);
    previous_codes_.resize(depth_ + 1);
    previous_ids_.resize(depth_ + 1);
}

uint32_t DifferenceTree::store(int level, uint32_t mask, const uint32_t* kids, uint32_t count) {
    Level& lv = levels_[level];
    if (lv.offsets.size() >= 0xfffffffeu || lv.records.size() + 1 + count >= 0xfffffffeu)
        throw Error(kWhat, "one level exceeds 2^32 nodes or words");
    const uint32_t id = uint32_t(lv.offsets.size());
    lv.offsets.push_back(uint32_t(lv.records.size()));
    lv.records.push_back(mask);
    lv.records.insert(lv.records.end(), kids, kids + count);
    ++level_counts_[level];
    level_pointers_[level] += count;
    return id;
}

uint64_t DifferenceTree::append_frame(std::span<const uint64_t> codes) {
    check_voxel_codes(grid_, codes, kWhat);
    uint64_t added = 0;
    // Level `depth`: the voxels. A voxel is unchanged iff it was there before.
    std::vector<uint64_t> level_codes(codes.begin(), codes.end());
    std::vector<uint32_t> ids(codes.size());
    std::vector<uint8_t> unchanged(codes.size());
    {
        const auto& pc = previous_codes_[depth_];
        const auto& pi = previous_ids_[depth_];
        size_t p = 0;
        for (size_t i = 0; i < codes.size(); ++i) {
            while (p < pc.size() && pc[p] < codes[i]) ++p;
            unchanged[i] = p < pc.size() && pc[p] == codes[i];
            if (unchanged[i]) {
                ids[i] = pi[p];
            } else {
                ids[i] = store(depth_, 0, nullptr, 0);
                ++added;
            }
        }
    }
    std::vector<std::vector<uint64_t>> frame_codes(depth_ + 1);
    std::vector<std::vector<uint32_t>> frame_ids(depth_ + 1);
    // Level l from level l+1: a node is unchanged iff it existed before with the same
    // mask and all its children are unchanged (then the voxels below are the same).
    for (int l = depth_ - 1; l >= 0; --l) {
        std::vector<uint64_t> up_codes;
        std::vector<uint32_t> up_ids;
        std::vector<uint8_t> up_unchanged;
        const auto& pc = previous_codes_[l];
        const auto& pi = previous_ids_[l];
        size_t p = 0, i = 0;
        std::array<uint32_t, 8> kids;
        while (i < level_codes.size()) {
            const uint64_t parent = level_codes[i] >> 3;
            uint32_t m = 0, count = 0;
            bool same = true;
            for (; i < level_codes.size() && (level_codes[i] >> 3) == parent; ++i) {
                m |= 1u << (level_codes[i] & 7);
                kids[count++] = ids[i];
                same = same && unchanged[i];
            }
            while (p < pc.size() && pc[p] < parent) ++p;
            same = same && p < pc.size() && pc[p] == parent && mask(l, pi[p]) == m;
            up_codes.push_back(parent);
            up_unchanged.push_back(same);
            if (same) {
                up_ids.push_back(pi[p]);
            } else {
                up_ids.push_back(store(l, m, kids.data(), count));
                ++added;
            }
        }
        frame_codes[l + 1] = std::move(level_codes);
        frame_ids[l + 1] = std::move(ids);
        level_codes = std::move(up_codes);
        ids = std::move(up_ids);
        unchanged = std::move(up_unchanged);
    }
    roots_.push_back(ids.empty() ? kEmptyFrame : ids.front());
    frame_codes[0] = std::move(level_codes);
    frame_ids[0] = std::move(ids);
    previous_codes_ = std::move(frame_codes);
    previous_ids_ = std::move(frame_ids);
    added_.push_back(added);
    return added;
}

std::vector<uint64_t> DifferenceTree::decode(size_t frame) const {
    if (frame >= roots_.size())
        throw Error(kWhat, "frame " + std::to_string(frame) + " is outside 0.." + std::to_string(roots_.size()) +
                               " (exclusive)");
    if (roots_[frame] == kEmptyFrame) return {};
    // Nodes are addressed by (level << 32 | id), so the generic walker sees one id space.
    auto child = [&](uint64_t node, int slot) -> uint64_t {
        const int level = int(node >> 32);
        const uint32_t id = uint32_t(node);
        const uint32_t m = mask(level, id);
        if (!(m & (1u << slot))) return ~uint64_t(0);
        return uint64_t(level + 1) << 32 | children(level, id)[child_rank(m, slot)];
    };
    struct Item {
        uint64_t node;
        uint64_t code;
    };
    std::vector<uint64_t> out;
    std::vector<Item> stack{{roots_[frame], 0}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        if (int(it.node >> 32) == depth_) {
            out.push_back(it.code);
            continue;
        }
        for (int s = 7; s >= 0; --s) {  // reversed so slot 0 pops first: Morton order
            const uint64_t c = child(it.node, s);
            if (c != ~uint64_t(0)) stack.push_back({c, it.code << 3 | uint64_t(s)});
        }
    }
    return out;
}

uint64_t DifferenceTree::node_count() const {
    uint64_t n = 0;
    for (uint64_t c : level_counts_) n += c;
    return n;
}

double DifferenceTree::nodes_per_frame() const {
    return roots_.empty() ? 0.0 : double(node_count()) / double(roots_.size());
}

size_t DifferenceTree::bytes() const {
    uint64_t pointers = 0;
    for (uint64_t p : level_pointers_) pointers += p;
    return 4 * (node_count() + pointers + roots_.size());
}

uint64_t DifferenceTree::node_count_leaves_in_masks() const { return node_count() - level_counts_[depth_]; }

size_t DifferenceTree::bytes_leaves_in_masks() const {
    // Pointers of the levels above the bottom nodes only: a bottom node's mask is its voxels.
    uint64_t pointers = 0;
    for (int l = 0; l + 1 < depth_; ++l) pointers += level_pointers_[size_t(l)];
    return 4 * (node_count_leaves_in_masks() + pointers + roots_.size());
}

}  // namespace gilab
