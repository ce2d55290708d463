#pragma once
// The occupancy map a cone tracer skips empty samples with: per texel t of one level
// (r³ texels, a voxel's six faces together), whether any face of the 2×2×2 texels from t
// up has opacity — the texels one trilinear sample starting at t reads. One bit per texel
// (bit t % 64 of word t / 64). Toroidal levels (the cascades) wrap at the border; linear
// ones (dense mips) clamp, as the sampler does.
#include <cstddef>
#include <cstdint>
#include "accel/vct/half_rgba.hpp"

namespace gilab {

void build_occupancy_map(const HalfRGBA* cells, int r, bool toroidal, uint64_t* out);
inline size_t occupancy_map_words(int r) { return (size_t(r) * size_t(r) * size_t(r) + 63) / 64; }
inline bool occupancy_bit(const uint64_t* map, size_t texel) { return map[texel >> 6] >> (texel & 63) & 1; }

}  // namespace gilab
