#pragma once
// A dense stream of fixed-width unsigned fields (0..64 bits each), least significant bit
// first, for the minimal-bit pointer encodings. A 0-bit field stores nothing and reads 0.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>
#include "core/util/error.hpp"

namespace gilab {

class BitWriter {
public:
    void write(uint64_t value, int bits) {
        if (bits < 0 || bits > 64 || (bits < 64 && (value >> bits) != 0))
            throw Error("bit stream", "value " + std::to_string(value) + " does not fit in " + std::to_string(bits) +
                                          " bits");
        for (int done = 0; done < bits;) {
            const uint64_t bit = size_ & 63;
            if (bit == 0) words_.push_back(0);
            const int take = std::min<int>(bits - done, int(64 - bit));
            const uint64_t part = (value >> done) & (take == 64 ? ~uint64_t(0) : (uint64_t(1) << take) - 1);
            words_.back() |= part << bit;
            size_ += uint64_t(take);
            done += take;
        }
    }
    uint64_t size() const { return size_; }  // bits written
    const std::vector<uint64_t>& words() const { return words_; }
    std::vector<uint64_t> release() { return std::move(words_); }

private:
    std::vector<uint64_t> words_;
    uint64_t size_ = 0;
};

// Reads fields at any bit offset of a stream written by BitWriter.
inline uint64_t read_bits(const std::vector<uint64_t>& words, uint64_t offset, int bits) {
    uint64_t value = 0;
    for (int done = 0; done < bits;) {
        const uint64_t word = (offset + uint64_t(done)) >> 6, bit = (offset + uint64_t(done)) & 63;
        if (word >= words.size()) throw Error("bit stream", "read past the end of the stream");
        const int take = std::min<int>(bits - done, int(64 - bit));
        const uint64_t part = (words[word] >> bit) & (take == 64 ? ~uint64_t(0) : (uint64_t(1) << take) - 1);
        value |= part << done;
        done += take;
    }
    return value;
}

// Bits needed to tell `n` values apart: ceil(log2 n), 0 for n <= 1.
inline int bits_for_count(uint64_t n) {
    int b = 0;
    while (b < 64 && (uint64_t(1) << b) < n) ++b;
    return b;
}

}  // namespace gilab
