#include "accel/shadow/shadow_svo.hpp"
#include <numeric>
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

const char* to_string(ShadowState state) {
    switch (state) {
        case ShadowState::Shadow: return "shadow";
        case ShadowState::Lit: return "lit";
        case ShadowState::Boundary: return "boundary";
        case ShadowState::Undefined: return "undefined";
    }
    return "?";
}

ShadowState combine_child_states(std::span<const ShadowState, 8> children) {
    bool lit = false, shadow = false;
    for (ShadowState s : children) {
        if (s == ShadowState::Boundary) return ShadowState::Boundary;
        lit |= s == ShadowState::Lit;
        shadow |= s == ShadowState::Shadow;
    }
    return cell_state(lit, shadow);
}

uint64_t shadow_leaf_bits(const LightDepthTile& tile, const UVec3& first, ShadowState undefined_as) {
    const bool undefined_shadow = undefined_as == ShadowState::Shadow;
    uint64_t bits = 0;
    for (uint32_t y = 0; y < 4; ++y)
        for (uint32_t x = 0; x < 4; ++x) {
            const float d1 = tile.d1(first.x + x, first.y + y), d2 = tile.d2(first.x + x, first.y + y);
            for (uint32_t z = 0; z < 4; ++z) {
                const float c = float(first.z + z) + 0.5f;
                // Shadow at or past the exit depth; between entry and exit as chosen.
                const bool shadow = !(c < d1) && (c >= d2 || undefined_shadow);
                if (shadow) bits |= uint64_t(1) << (x + 4 * y + 16 * z);
            }
        }
    return bits;
}

ShadowSvo ShadowSvo::build(const LightDepthTile& tile, const UVec3& cell_first, int cell_level, int grid_depth,
                           ShadowState undefined_as) {
    if (undefined_as != ShadowState::Lit && undefined_as != ShadowState::Shadow)
        throw Error("shadow SVO", "undefined space can only be stored as lit or shadow");
    if (grid_depth < 3) throw Error("shadow SVO", "the light-space grid needs at least 8 voxels per axis");
    const int leaf_level = grid_depth - kShadowLeafLevels;
    if (cell_level < 0 || cell_level > leaf_level) throw Error("shadow SVO", "cell level outside the octree");
    ShadowSvo svo;
    svo.cell_level_ = cell_level;
    svo.grid_depth_ = grid_depth;
    const uint32_t cell_size = 1u << (grid_depth - cell_level);
    svo.root_state_ = tile.cell_state(cell_first, cell_size);
    if (svo.root_state_ != ShadowState::Boundary) return svo;

    std::vector<UVec3> cells{cell_first}, next;
    for (int level = cell_level; level < leaf_level; ++level) {
        const uint32_t half = 1u << (grid_depth - level - 1);
        std::vector<uint16_t> masks(cells.size());
        std::vector<uint32_t> counts(cells.size());
        parallel_for(cells.size(), 256, [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; ++i) {
                uint32_t mask = 0, count = 0;
                for (int s = 0; s < 8; ++s) {
                    const UVec3 c = cells[i] + UVec3(s & 1, (s >> 1) & 1, (s >> 2) & 1) * half;
                    const ShadowState st = stored_child_state(tile.cell_state(c, half), undefined_as);
                    mask = with_child_state(mask, s, st);
                    count += st == ShadowState::Boundary;
                }
                masks[i] = uint16_t(mask);
                counts[i] = count;
            }
        });
        std::vector<uint32_t> first(cells.size());
        uint64_t total = 0;
        for (size_t i = 0; i < cells.size(); ++i) {
            first[i] = uint32_t(total);
            total += counts[i];
        }
        if (total >= 0xffffffffull) throw Error("shadow SVO", "one level exceeds 2^32 nodes; build in smaller tiles");
        next.resize(total);
        parallel_for(cells.size(), 256, [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; ++i) {
                uint32_t k = first[i];
                for (int s = 0; s < 8; ++s)
                    if (child_state(masks[i], s) == ShadowState::Boundary)
                        next[k++] = cells[i] + UVec3(s & 1, (s >> 1) & 1, (s >> 2) & 1) * half;
            }
        });
        svo.masks_.push_back(std::move(masks));
        svo.first_child_.push_back(std::move(first));
        cells.swap(next);
    }
    svo.leaves_.resize(cells.size());
    parallel_for(cells.size(), 1024, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) svo.leaves_[i] = shadow_leaf_bits(tile, cells[i], undefined_as);
    });
    return svo;
}

ShadowSvo ShadowSvo::from_parts(ShadowState root_state, int cell_level, int grid_depth,
                                std::vector<std::vector<uint16_t>> masks,
                                std::vector<std::vector<uint32_t>> first_child, std::vector<uint64_t> leaves) {
    ShadowSvo svo;
    svo.root_state_ = root_state;
    svo.cell_level_ = cell_level;
    svo.grid_depth_ = grid_depth;
    svo.masks_ = std::move(masks);
    svo.first_child_ = std::move(first_child);
    svo.leaves_ = std::move(leaves);
    return svo;
}

size_t ShadowSvo::node_count() const {
    size_t n = leaves_.size();
    for (const auto& m : masks_) n += m.size();
    return n;
}

}  // namespace gilab
