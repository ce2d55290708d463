#pragma once
// The sparse G-buffer of one block of texels (a cascade level): only surface voxels
// carry one, and of a voxel only the axes whose faces see a fragment. One bit per texel
// and axis (bit 3·texel + axis) says whether the record exists; the records of the set
// bits are stored in bit order and found by rank — a count per 256 bits plus popcounts.
// For 32³ texels the index is 13.8 KB per level: 12 KB of bits and 1.5 KB of counts.
//
// Edits are batched: stage() collects written voxels (from any one thread at a time),
// erase() marks texels to drop, and commit() rebuilds the records in one ordered pass.
// find() and occupied() read the last committed state. The result depends only on what
// was staged and erased, not on the order voxels were staged in (a texel staged twice in
// one batch keeps the later record).
#include <cstdint>
#include <vector>
#include "accel/vct/packed_surface.hpp"

namespace gilab {

class SparseGBuffer {
public:
    SparseGBuffer() = default;
    explicit SparseGBuffer(size_t texels);

    size_t texels() const { return texels_; }
    const PackedSurface* find(size_t texel, int axis) const {
        const size_t bit = 3 * texel + size_t(axis);
        if (!(bits_[bit >> 6] >> (bit & 63) & 1)) return nullptr;
        return &records_[rank(bit)];
    }
    bool occupied(size_t texel) const;
    size_t records() const { return records_.size(); }
    size_t occupied_texels() const;

    void stage(size_t texel, const PackedVoxel& voxel) { staged_.push_back({texel, voxel}); }
    void erase(size_t texel) {
        if (erased_.empty()) erased_.assign((texels_ + 63) / 64, 0);
        erased_[texel >> 6] |= uint64_t(1) << (texel & 63);
        pending_erase_ = true;
    }
    bool pending() const { return pending_erase_ || !staged_.empty(); }
    void commit();
    void clear();  // everything, at once

    // What the structure holds, at capacity: bits, rank counts, records and pending edits.
    size_t bytes() const;
    // Of those, what encodes occupancy: the bits, the rank counts and a byte of opacity
    // per record.
    size_t occupancy_bytes() const;

private:
    static constexpr size_t kWordsPerBlock = 4;  // a rank count per 256 bits
    size_t rank(size_t bit) const {
        const size_t word = bit >> 6, block = word / kWordsPerBlock;
        size_t r = block_rank_[block];
        for (size_t w = block * kWordsPerBlock; w < word; ++w) r += size_t(__builtin_popcountll(bits_[w]));
        const uint64_t below = (uint64_t(1) << (bit & 63)) - 1;
        return r + size_t(__builtin_popcountll(bits_[word] & below));
    }
    struct Staged {
        size_t texel;
        PackedVoxel voxel;
    };
    size_t texels_ = 0;
    std::vector<uint64_t> bits_;         // 3 per texel
    std::vector<uint32_t> block_rank_;   // set bits before each block of kWordsPerBlock words
    std::vector<PackedSurface> records_; // in bit order
    std::vector<uint64_t> erased_;       // per texel, allocated by erase() until the next commit
    std::vector<Staged> staged_;
    bool pending_erase_ = false;
};

}  // namespace gilab
