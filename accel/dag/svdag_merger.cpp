#include "accel/dag/svdag_merger.hpp"
#include <bit>
#include <string>
#include "accel/dag/child_mask.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"
#include "core/util/stats.hpp"

namespace gilab {

void check_voxel_codes(const VoxelGrid& grid, std::span<const uint64_t> codes, const char* where) {
    const uint32_t n = grid.resolution;
    // In a power-of-two grid the codes of its voxels are exactly those below n³: no decode.
    const bool power_of_two = std::has_single_bit(n) && n <= (1u << 21);
    const uint64_t limit = power_of_two ? uint64_t(n) * n * n : 0;
    auto outside = [&](uint64_t code) {
        if (power_of_two) return code >= limit;
        const UVec3 v = morton_decode(code);
        return (code >> 63) || v.x >= n || v.y >= n || v.z >= n;
    };
    for (size_t i = 0; i < codes.size(); ++i) {
        if (i > 0 && codes[i] <= codes[i - 1])
            throw Error(where, "voxel codes must be strictly ascending (Morton order); entry " + std::to_string(i) +
                                   " is not");
        if (outside(codes[i]))
            throw Error(where, "voxel code " + std::to_string(codes[i]) + " lies outside the " + std::to_string(n) +
                                   "^3 grid");
    }
}

SvdagMerger::SvdagMerger(std::vector<DagLevelTable>& tables, int depth) : tables_(tables), depth_(depth) {
    if (int(tables_.size()) != depth_ + 1) throw Error("SVDAG", "internal: merger needs one table per level");
    forget_cache();
}

uint32_t SvdagMerger::leaf_id() {
    if (tables_[depth_].size() == 0) tables_[depth_].find_or_insert(0, nullptr, 0);
    return 0;
}

uint32_t SvdagMerger::bottom_id(uint8_t mask) {
    uint32_t& id = mask_ids_[mask];
    if (id == kNoNode) {
        uint32_t leaf = leaf_id();
        std::array<uint32_t, 8> kids;
        kids.fill(leaf);
        id = tables_[depth_ - 1].find_or_insert(mask, kids.data(), child_count(mask));
    }
    return id;
}

void SvdagMerger::merge_leaves(std::span<const uint64_t> codes, std::vector<uint64_t>& out_codes,
                               std::vector<uint32_t>& out_ids) {
    out_codes.clear();
    masks_.clear();
    size_t i = 0;
    while (i < codes.size()) {
        uint64_t parent = codes[i] >> 3;
        uint8_t mask = 0;
        for (; i < codes.size() && (codes[i] >> 3) == parent; ++i) mask |= uint8_t(1u << (codes[i] & 7));
        out_codes.push_back(parent);
        masks_.push_back(mask);
    }
    look_up_bottom(out_ids);
}

void SvdagMerger::merge_leaf_blocks(std::span<const uint64_t> blocks, std::span<const uint64_t> masks,
                                    std::vector<uint64_t>& out_codes, std::vector<uint32_t>& out_ids) {
    out_codes.clear();
    masks_.clear();
    for (size_t i = 0; i < blocks.size(); ++i)
        for (int octant = 0; octant < 8; ++octant)
            if (const uint8_t mask = uint8_t(masks[i] >> (8 * octant))) {
                out_codes.push_back(blocks[i] << 3 | uint64_t(octant));
                masks_.push_back(mask);
            }
    look_up_bottom(out_ids);
}

void SvdagMerger::look_up_bottom(std::vector<uint32_t>& out_ids) {
    Stopwatch lookup;
    out_ids.resize(masks_.size());
    for (size_t k = 0; k < masks_.size(); ++k) out_ids[k] = bottom_id(masks_[k]);
    lookup_ms_ += lookup.elapsed_ms();
}

void SvdagMerger::merge_up(int level, const std::vector<uint64_t>& codes, const std::vector<uint32_t>& ids,
                           std::vector<uint64_t>& out_codes, std::vector<uint32_t>& out_ids) {
    out_codes.clear();
    masks_.clear();
    kids_.clear();
    size_t i = 0;
    while (i < codes.size()) {
        uint64_t parent = codes[i] >> 3;
        uint8_t mask = 0;
        for (; i < codes.size() && (codes[i] >> 3) == parent; ++i) {
            mask |= uint8_t(1u << (codes[i] & 7));
            kids_.push_back(ids[i]);
        }
        out_codes.push_back(parent);
        masks_.push_back(mask);
    }
    Stopwatch lookup;
    DagLevelTable& table = tables_[level - 1];
    out_ids.resize(masks_.size());
    const uint32_t* kids = kids_.data();
    for (size_t k = 0; k < masks_.size(); ++k) {
        const uint32_t count = child_count(masks_[k]);
        out_ids[k] = table.find_or_insert(masks_[k], kids, count);
        kids += count;
    }
    lookup_ms_ += lookup.elapsed_ms();
}

uint32_t SvdagMerger::add_subtree(std::span<const uint64_t> codes, int top) {
    if (top == depth_) return leaf_id();
    merge_leaves(codes, codes_a_, ids_a_);
    return merge_to(top);
}

uint32_t SvdagMerger::add_subtree(std::span<const uint64_t> blocks, std::span<const uint64_t> masks, int top) {
    if (top == depth_) return leaf_id();
    merge_leaf_blocks(blocks, masks, codes_a_, ids_a_);
    return merge_to(top);
}

uint32_t SvdagMerger::merge_to(int top) {
    for (int l = depth_ - 1; l > top; --l) {
        merge_up(l, codes_a_, ids_a_, codes_b_, ids_b_);
        std::swap(codes_a_, codes_b_);
        std::swap(ids_a_, ids_b_);
    }
    return ids_a_.front();
}

uint32_t SvdagMerger::finish_top(int level, std::vector<uint64_t> codes, std::vector<uint32_t> ids) {
    for (int l = level; l > 0; --l) {
        merge_up(l, codes, ids, codes_b_, ids_b_);
        std::swap(codes, codes_b_);
        std::swap(ids, ids_b_);
    }
    return ids.empty() ? kNoNode : ids.front();
}

}  // namespace gilab
