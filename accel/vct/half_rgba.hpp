#pragma once
// RGBA16F texels: the storage type of every radiance buffer (cascades and the dense
// mip texture alike), premultiplied radiance and opacity as IEEE half floats.
//
// Stored values are clamped to [0, 65504] (radiance and opacity are never negative; NaN
// becomes 0) and values below the smallest normal half (6.1e-5) are flushed to zero, as
// GPUs do for render targets. Flushing keeps decoding to a shift: a normal half's bits
// moved up by 13 are the bits of the same value × 2^-112, a normal float, so a sampler
// can weight the shifted bits directly with weights pre-scaled by 2^112 (no denormals).
#include <bit>
#include <cstdint>
#include "core/util/math.hpp"

namespace gilab {

struct HalfRGBA {
    uint16_t c[4] = {0, 0, 0, 0};
    bool operator==(const HalfRGBA&) const = default;
};

// Scale from the shifted bits (h << 13 read as float) to the half's value.
inline constexpr float kHalfBitsScale = 0x1p112f;

inline uint16_t to_half(float value) {
    if (!(value >= 6.103515625e-05f)) return 0;        // negative, NaN, zero or subnormal half
    if (value >= 65504.0f) return 0x7bff;              // largest finite half
    uint32_t u = std::bit_cast<uint32_t>(value);
    // Round to nearest even while dropping 13 mantissa bits, then rebias the exponent.
    u += 0xfffu + ((u >> 13) & 1u);
    return uint16_t((u - (112u << 23)) >> 13);
}

inline float from_half(uint16_t h) { return std::bit_cast<float>(uint32_t(h) << 13) * kHalfBitsScale; }

inline HalfRGBA to_half_rgba(const Vec4& v) { return {{to_half(v.r), to_half(v.g), to_half(v.b), to_half(v.a)}}; }
inline Vec4 from_half_rgba(const HalfRGBA& h) {
    return {from_half(h.c[0]), from_half(h.c[1]), from_half(h.c[2]), from_half(h.c[3])};
}
inline bool has_opacity(const HalfRGBA& h) { return h.c[3] != 0; }

}  // namespace gilab
