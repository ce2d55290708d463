#include "accel/vct/occupancy_map.hpp"

#include <algorithm>
#include <vector>
#include "accel/vct/anisotropic_voxel.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

void build_occupancy_map(const HalfRGBA* cells, int r, bool toroidal, uint64_t* out) {
    const size_t n = size_t(r), texels = n * n * n;
    std::vector<uint8_t> any(texels, 0);
    parallel_for(texels, size_t(1) << 14, [&](size_t b, size_t e) {
        for (size_t t = b; t < e; ++t)
            for (int f = 0; f < kFaceCount; ++f)
                if (has_opacity(cells[t * kFaceCount + size_t(f)])) {
                    any[t] = 1;
                    break;
                }
    });
    // The upper neighbour along an axis: wrapped, or the border texel itself (a sample
    // there reads it twice).
    auto up = [&](int i) { return toroidal ? (i + 1) & (r - 1) : std::min(i + 1, r - 1); };
    std::vector<uint8_t> bytes(texels);
    parallel_for(n, 1, [&](size_t z0, size_t z1) {
        for (int z = int(z0); z < int(z1); ++z)
            for (int y = 0; y < r; ++y)
                for (int x = 0; x < r; ++x) {
                    const int xs[2] = {x, up(x)}, ys[2] = {y, up(y)}, zs[2] = {z, up(z)};
                    uint8_t o = 0;
                    for (int c = 0; c < 8; ++c)
                        o |= any[(size_t(zs[c >> 2]) * n + size_t(ys[(c >> 1) & 1])) * n + size_t(xs[c & 1])];
                    bytes[(size_t(z) * n + size_t(y)) * n + size_t(x)] = o;
                }
    });
    std::fill_n(out, occupancy_map_words(r), uint64_t(0));
    for (size_t t = 0; t < texels; ++t) out[t >> 6] |= uint64_t(bytes[t]) << (t & 63);
}

}  // namespace gilab
