#include "accel/vct/sparse_gbuffer.hpp"

#include <algorithm>
#include "core/util/error.hpp"

namespace gilab {

namespace {
size_t words_for(size_t bits) { return (bits + 63) / 64; }
}  // namespace

SparseGBuffer::SparseGBuffer(size_t texels) : texels_(texels) {
    if (3 * texels >= (size_t(1) << 32)) throw Error("sparse G-buffer", "too many texels: " + std::to_string(texels));
    bits_.assign(words_for(3 * texels), 0);
    block_rank_.assign(bits_.size() / kWordsPerBlock + 1, 0);
}

bool SparseGBuffer::occupied(size_t texel) const {
    for (int axis = 0; axis < 3; ++axis) {
        const size_t bit = 3 * texel + size_t(axis);
        if (bits_[bit >> 6] >> (bit & 63) & 1) return true;
    }
    return false;
}

size_t SparseGBuffer::occupied_texels() const {
    size_t n = 0;
    for (size_t t = 0; t < texels_; ++t) n += occupied(t) ? 1 : 0;
    return n;
}

void SparseGBuffer::clear() {
    std::fill(bits_.begin(), bits_.end(), 0);
    std::fill(block_rank_.begin(), block_rank_.end(), 0);
    erased_.clear();
    erased_.shrink_to_fit();
    records_.clear();
    records_.shrink_to_fit();
    staged_.clear();
    staged_.shrink_to_fit();
    pending_erase_ = false;
}

void SparseGBuffer::commit() {
    if (!pending()) return;
    // Later stagings of a texel win: a stable sort keeps their order, then the last of
    // each run is kept.
    std::stable_sort(staged_.begin(), staged_.end(), [](const Staged& a, const Staged& b) { return a.texel < b.texel; });
    if (erased_.empty()) erased_.assign(words_for(texels_), 0);
    for (const Staged& s : staged_) {
        if (s.texel >= texels_) throw Error("sparse G-buffer", "texel " + std::to_string(s.texel) + " out of range");
        erased_[s.texel >> 6] |= uint64_t(1) << (s.texel & 63);  // replaced
    }
    std::vector<uint64_t> bits(bits_.size(), 0);
    std::vector<PackedSurface> records;
    records.reserve(records_.size() + 3 * staged_.size());
    size_t old = 0;    // next old record
    size_t next = 0;   // next staged entry
    auto emit_staged_before = [&](size_t texel_end) {
        while (next < staged_.size() && staged_[next].texel < texel_end) {
            const size_t t = staged_[next].texel;
            if (next + 1 < staged_.size() && staged_[next + 1].texel == t) {
                ++next;  // a later record of the same texel follows
                continue;
            }
            for (int axis = 0; axis < 3; ++axis) {
                const PackedSurface& s = staged_[next].voxel.axis[size_t(axis)];
                if (!s.opacity) continue;
                const size_t bit = 3 * t + size_t(axis);
                bits[bit >> 6] |= uint64_t(1) << (bit & 63);
                records.push_back(s);
            }
            ++next;
        }
    };
    for (size_t w = 0; w < bits_.size(); ++w) {
        uint64_t word = bits_[w];
        while (word) {
            const size_t bit = w * 64 + size_t(__builtin_ctzll(word));
            word &= word - 1;
            const size_t t = bit / 3;
            emit_staged_before(t);  // staged texels before t (t itself, if staged, was erased)
            if (!(erased_[t >> 6] >> (t & 63) & 1)) {
                bits[bit >> 6] |= uint64_t(1) << (bit & 63);
                records.push_back(records_[old]);
            }
            ++old;
        }
    }
    emit_staged_before(texels_);
    bits_ = std::move(bits);
    records.shrink_to_fit();
    records_ = std::move(records);
    uint32_t count = 0;
    for (size_t b = 0; b < block_rank_.size(); ++b) {
        block_rank_[b] = count;
        for (size_t w = b * kWordsPerBlock; w < std::min(bits_.size(), (b + 1) * kWordsPerBlock); ++w)
            count += uint32_t(__builtin_popcountll(bits_[w]));
    }
    erased_.clear();
    erased_.shrink_to_fit();
    staged_.clear();
    staged_.shrink_to_fit();
    pending_erase_ = false;
}

size_t SparseGBuffer::bytes() const {
    return bits_.capacity() * sizeof(uint64_t) + block_rank_.capacity() * sizeof(uint32_t) +
           records_.capacity() * sizeof(PackedSurface) + erased_.capacity() * sizeof(uint64_t) +
           staged_.capacity() * sizeof(Staged);
}

size_t SparseGBuffer::occupancy_bytes() const {
    return bits_.capacity() * sizeof(uint64_t) + block_rank_.capacity() * sizeof(uint32_t) + records_.size();
}

}  // namespace gilab
