#pragma once
// The occupancy map a cone tracer skips empty samples with: per texel t of one level
// (r³ texels, a voxel's six faces together), whether any face of the 2×2×2 texels from t
// up has opacity — the texels one trilinear sample starting at t reads. Toroidal levels
// (the cascades) wrap at the border; linear ones (dense mips) clamp, as the sampler does.
#include <cstdint>
#include "accel/vct/half_rgba.hpp"

namespace gilab {

void build_occupancy_map(const HalfRGBA* cells, int r, bool toroidal, uint8_t* out);

}  // namespace gilab
