#pragma once
// PCG32 (O'Neill 2014) seeded from a hash of (seed, pixel, sample, pass), so every
// random decision depends only on what is being computed, never on thread scheduling.
#include <cstdint>
#include "core/util/math.hpp"

namespace gilab {

// 64-bit finalizer (SplitMix64); good avalanche for combining counters.
inline uint64_t mix64(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

class Rng {
public:
    Rng() : Rng(0, 0) {}
    Rng(uint64_t seed, uint64_t stream) { reseed(seed, stream); }

    // The RNG for one (pixel, sample, pass) of a render with the given seed.
    static Rng for_sample(uint64_t seed, uint64_t pixel, uint64_t sample, uint64_t pass = 0) {
        return Rng(mix64(seed ^ mix64(pixel ^ mix64(sample ^ mix64(pass)))), mix64(pixel + 0x632be59bd9b4e019ull));
    }

    void reseed(uint64_t seed, uint64_t stream) {
        state_ = 0;
        inc_ = (stream << 1u) | 1u;
        next_u32();
        state_ += seed;
        next_u32();
    }
    uint32_t next_u32() {
        uint64_t old = state_;
        state_ = old * 6364136223846793005ull + inc_;
        uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32 - rot) & 31));
    }
    // Uniform in [0, 1).
    float uniform() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }
    Vec2 uniform2() { float a = uniform(); return {a, uniform()}; }

private:
    uint64_t state_ = 0, inc_ = 1;
};

}  // namespace gilab
