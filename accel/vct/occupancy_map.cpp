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
    // One task per run of 64-bit words: each word's 64 texels are written by one thread.
    const size_t words = occupancy_map_words(r);
    parallel_for(words, 64, [&](size_t w0, size_t w1) {
        for (size_t w = w0; w < w1; ++w) {
            uint64_t word = 0;
            for (size_t t = w * 64; t < std::min(texels, (w + 1) * 64); ++t) {
                const int x = int(t % n), y = int(t / n % n), z = int(t / (n * n));
                const int xs[2] = {x, up(x)}, ys[2] = {y, up(y)}, zs[2] = {z, up(z)};
                uint64_t o = 0;
                for (int c = 0; c < 8; ++c)
                    o |= any[(size_t(zs[c >> 2]) * n + size_t(ys[(c >> 1) & 1])) * n + size_t(xs[c & 1])];
                word |= o << (t & 63);
            }
            out[w] = word;
        }
    });
}

}  // namespace gilab
