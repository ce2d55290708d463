#include "accel/dag/svo.hpp"
#include "accel/dag/child_mask.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"

namespace gilab {

Svo Svo::build(const VoxelGrid& grid, std::span<const uint64_t> codes) {
    Stopwatch clock;
    grid.validate("SVO");
    Svo svo;
    svo.grid_ = grid;
    svo.depth_ = grid.depth();
    const int depth = svo.depth_;
    const uint32_t n = grid.resolution;
    for (size_t i = 0; i < codes.size(); ++i) {
        if (i > 0 && codes[i] <= codes[i - 1])
            throw Error("SVO", "voxel codes must be strictly ascending (Morton order); entry " + std::to_string(i) +
                                   " is not");
        UVec3 v = morton_decode(codes[i]);
        if ((codes[i] >> 63) || v.x >= n || v.y >= n || v.z >= n)
            throw Error("SVO", "voxel code " + std::to_string(codes[i]) + " lies outside the " + std::to_string(n) +
                                   "^3 grid");
    }
    svo.level_counts_.assign(depth + 1, 0);
    svo.level_offsets_.assign(depth + 2, 0);
    if (codes.empty()) {
        svo.build_ms_ = clock.elapsed_ms();
        return svo;
    }

    // Bottom-up: each level's node codes are the unique parents of the level below.
    // masks[l][j] is the child mask of node j on level l.
    std::vector<std::vector<uint8_t>> masks(depth + 1);
    std::vector<uint64_t> below(codes.begin(), codes.end()), here;
    masks[depth].assign(codes.size(), 0);
    svo.level_counts_[depth] = codes.size();
    for (int l = depth - 1; l >= 0; --l) {
        here.clear();
        auto& m = masks[l];
        for (uint64_t c : below) {
            uint64_t parent = c >> 3;
            if (here.empty() || here.back() != parent) {
                here.push_back(parent);
                m.push_back(0);
            }
            m.back() |= uint8_t(1u << (c & 7));
        }
        svo.level_counts_[l] = here.size();
        std::swap(below, here);
    }
    below.clear();
    below.shrink_to_fit();

    for (int l = 0; l <= depth; ++l) svo.level_offsets_[l + 1] = svo.level_offsets_[l] + svo.level_counts_[l];
    const uint64_t total = svo.level_offsets_[depth + 1];
    if (total > kInvalidNode) throw Error("SVO", "too many nodes for 32-bit child indices");
    svo.masks_.reserve(total);
    for (int l = 0; l <= depth; ++l) {
        svo.masks_.insert(svo.masks_.end(), masks[l].begin(), masks[l].end());
        if (l < depth) std::vector<uint8_t>().swap(masks[l]);
    }
    // First child of node j on level l: start of level l+1 plus the children of the
    // nodes before j on level l.
    const uint64_t interior = svo.level_offsets_[depth];
    svo.first_child_.resize(interior);
    uint64_t next = svo.level_counts_.empty() ? 0 : svo.level_offsets_[1];
    for (uint64_t i = 0; i < interior; ++i) {
        svo.first_child_[i] = static_cast<uint32_t>(next);
        next += child_count(svo.masks_[i]);
    }
    svo.build_ms_ = clock.elapsed_ms();
    return svo;
}

size_t Svo::voxel_count() const { return empty() ? 0 : level_counts_[depth_]; }

size_t Svo::bytes() const { return masks_.size() * sizeof(uint8_t) + first_child_.size() * sizeof(uint32_t); }

uint32_t Svo::child(uint32_t node, int slot) const {
    if (node >= first_child_.size()) return kInvalidNode;
    uint8_t m = masks_[node];
    if (!(m & (1u << slot))) return kInvalidNode;
    return first_child_[node] + child_rank(m, slot);
}

bool Svo::contains_voxel(const UVec3& v) const {
    if (empty() || v.x >= grid_.resolution || v.y >= grid_.resolution || v.z >= grid_.resolution) return false;
    uint32_t node = 0;
    for (int l = 0; l < depth_; ++l) {
        int shift = depth_ - 1 - l;
        int slot = octree_child_slot(v.x >> shift, v.y >> shift, v.z >> shift);
        node = child(node, slot);
        if (node == kInvalidNode) return false;
    }
    return true;
}

bool Svo::occupied(const Vec3& p) const {
    auto v = grid_.voxel_of(p);
    return v && contains_voxel(*v);
}

std::vector<uint64_t> Svo::decode() const {
    std::vector<uint64_t> codes;
    if (empty()) return codes;
    std::vector<uint64_t> level{0}, next;
    for (int l = 0; l < depth_; ++l) {
        next.clear();
        uint64_t base = level_offsets_[l];
        for (size_t j = 0; j < level.size(); ++j) {
            uint8_t m = masks_[base + j];
            for (int s = 0; s < 8; ++s)
                if (m & (1u << s)) next.push_back(level[j] << 3 | uint64_t(s));
        }
        std::swap(level, next);
    }
    return level;
}

Stats Svo::stats() const {
    Stats s;
    s.set("nodes", double(node_count()));
    s.set("pointers", double(pointer_count()));
    s.set("bytes", double(bytes()));
    s.set("pointerless_bytes", double(pointerless_bytes()));
    s.set("voxels", double(voxel_count()));
    s.set("build_ms", build_ms_);
    for (size_t l = 0; l < level_counts_.size(); ++l) s.set("nodes_level_" + std::to_string(l), double(level_counts_[l]));
    return s;
}

}  // namespace gilab
