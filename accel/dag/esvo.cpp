#include "accel/dag/esvo.hpp"

#include "accel/dag/child_mask.hpp"
#include "accel/dag/octree_path.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"

namespace gilab {
namespace {

constexpr uint64_t kMaxNearOffset = 0x7fff;  // 15-bit child pointer

}  // namespace

Esvo Esvo::from_svo(const Svo& svo) {
    Stopwatch clock;
    Esvo e;
    e.grid_ = svo.grid();
    e.depth_ = svo.depth();
    e.voxel_count_ = svo.voxel_count();
    const int depth = e.depth_;
    e.level_counts_.assign(depth + 1, 0);
    if (svo.empty() || depth == 0) {  // a lone root voxel needs no descriptor
        e.build_ms_ = clock.elapsed_ms();
        return e;
    }
    for (int l = 0; l < depth; ++l) e.level_counts_[l] = svo.level_node_counts()[l];
    const uint64_t interior = svo.level_offset(depth);  // SVO nodes with children = descriptors
    e.descriptors_ = interior;
    // Nodes above the last interior level have descriptor children (a block); the last
    // interior level's children are all leaf voxels.
    const uint64_t with_block = svo.level_offset(depth - 1);
    auto fc = [&](uint64_t x) { return uint64_t(svo.first_child(uint32_t(x))); };
    auto kids = [&](uint64_t x) { return child_count(svo.mask(uint32_t(x))); };

    // Bottom-up: words below each node (its child block, the block's far pointers and
    // the children's subtrees) and how many far pointers its child block needs.
    std::vector<uint64_t> below(with_block, 0);
    std::vector<uint8_t> block_far(with_block, 0);
    auto below_of = [&](uint64_t c) { return c < with_block ? below[c] : 0; };
    for (int l = depth - 2; l >= 0; --l) {
        for (uint64_t x = svo.level_offset(l); x < svo.level_offset(l + 1); ++x) {
            const uint64_t first = fc(x);
            const uint32_t m = kids(x);
            uint32_t f = 0;
            for (;;) {  // far pointers lengthen the offsets: iterate to the fixed point
                uint32_t need = 0;
                uint64_t before = 0;
                for (uint32_t i = 0; i < m; ++i) {
                    if (first + i < with_block && 2ull * (m - i) + f + before > kMaxNearOffset) ++need;
                    before += below_of(first + i);
                }
                if (need <= f) break;
                f = need;
            }
            uint64_t total = 2ull * m + f;
            for (uint32_t i = 0; i < m; ++i) total += below_of(first + i);
            below[x] = total;
            block_far[x] = uint8_t(f);
        }
    }

    const uint64_t total_words = 2 + (with_block > 0 ? below[0] : 0);
    if (total_words >= kLeafChild) throw Error("ESVO", "too large for 32-bit word addresses");
    e.words_.assign(total_words, 0);
    std::vector<uint64_t> pos(interior, 0), block(with_block, 0);
    auto write = [&](uint64_t x, uint64_t field, bool is_far) {
        uint32_t mask = svo.mask(uint32_t(x));
        uint32_t leaf = x < with_block ? 0u : mask;
        e.words_[pos[x]] = uint32_t(field) << 17 | uint32_t(is_far) << 16 | mask << 8 | leaf;
    };
    pos[0] = 0;
    if (with_block > 0) {
        block[0] = 2;
        write(0, 2, false);
        ++e.child_pointers_;
    } else {
        write(0, 0, false);
    }
    // Top-down: each block is placed by its parent; its far pointers follow it, then
    // the subtrees of its children in order.
    for (uint64_t x = 0; x < with_block; ++x) {  // breadth-first order = parents first
        const uint64_t b = block[x], first = fc(x);
        const uint32_t m = kids(x);
        uint64_t next = b + 2ull * m + block_far[x];
        uint32_t far_used = 0;
        for (uint32_t i = 0; i < m; ++i) {
            const uint64_t c = first + i;
            pos[c] = b + 2ull * i;
            if (c >= with_block) {
                write(c, 0, false);
                continue;
            }
            block[c] = next;
            next += below[c];
            ++e.child_pointers_;
            const uint64_t offset = block[c] - pos[c];
            if (offset <= kMaxNearOffset) {
                write(c, offset, false);
            } else {
                const uint64_t slot = b + 2ull * m + far_used++;
                e.words_[slot] = uint32_t(block[c] - slot);
                write(c, slot - pos[c], true);
                ++e.far_pointers_;
            }
        }
    }
    e.build_ms_ = clock.elapsed_ms();
    return e;
}

uint32_t Esvo::child_block(uint32_t d) const {
    uint32_t field = words_[d] >> 17;
    if (far(d)) {
        uint32_t slot = d + field;
        return slot + words_[slot];
    }
    return d + field;
}

uint32_t Esvo::child(uint32_t d, int slot) const {
    uint32_t w = words_[d];
    uint32_t valid = (w >> 8) & 0xffu, leaf = w & 0xffu;
    uint32_t bit = 1u << slot;
    if (!(valid & bit)) return kInvalidNode;
    if (leaf & bit) return kLeafChild;
    uint32_t nonleaf = valid & ~leaf;
    return child_block(d) + 2u * child_rank(nonleaf, slot);
}

bool Esvo::contains_voxel(const UVec3& v) const {
    if (empty() || v.x >= grid_.resolution || v.y >= grid_.resolution || v.z >= grid_.resolution) return false;
    if (depth_ == 0) return true;
    uint32_t d = root();
    for (int l = 0; l < depth_; ++l) {
        int shift = depth_ - 1 - l;
        uint32_t c = child(d, octree_child_slot(v.x >> shift, v.y >> shift, v.z >> shift));
        if (c == kInvalidNode) return false;
        if (c == kLeafChild) return true;
        d = c;
    }
    return true;
}

bool Esvo::occupied(const Vec3& p) const {
    auto v = grid_.voxel_of(p);
    return v && contains_voxel(*v);
}

std::vector<uint64_t> Esvo::decode() const {
    if (empty()) return {};
    if (depth_ == 0) return {0};
    return collect_leaf_codes(
        root(), kInvalidNode, [&](uint32_t d, int slot) { return child(d, slot); },
        [](uint32_t d, int) { return d == kLeafChild; });
}

Stats Esvo::stats() const {
    Stats s;
    s.set("nodes", double(node_count()));
    s.set("descriptors", double(descriptor_count()));
    s.set("pointers", double(pointer_count()));
    s.set("far_pointers", double(far_pointer_count()));
    s.set("bytes", double(bytes()));
    s.set("voxels", double(voxel_count()));
    s.set("build_ms", build_ms_);
    for (size_t l = 0; l < level_counts_.size(); ++l) s.set("nodes_level_" + std::to_string(l), double(level_counts_[l]));
    return s;
}

}  // namespace gilab
