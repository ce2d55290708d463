#include "core/image/image_plane.hpp"

#include <algorithm>
#include "core/util/parallel.hpp"

namespace gilab {

float ImagePlane::clamped(int x, int y) const {
    return at(std::clamp(x, 0, width - 1), std::clamp(y, 0, height - 1));
}

double ImagePlane::mean() const {
    double sum = 0.0;
    for (float v : values) sum += v;
    return values.empty() ? 0.0 : sum / double(values.size());
}

ImagePlane convolve(const ImagePlane& in, const Kernel2D& kernel) {
    ImagePlane out(in.width, in.height);
    const int r = kernel.radius;
    parallel_for(size_t(in.height), 4, [&](size_t begin, size_t end) {
        for (int y = int(begin); y < int(end); ++y)
            for (int x = 0; x < in.width; ++x) {
                double sum = 0.0;
                for (int dy = -r; dy <= r; ++dy)
                    for (int dx = -r; dx <= r; ++dx) sum += double(kernel.at(dx, dy)) * double(in.clamped(x + dx, y + dy));
                out.at(x, y) = float(sum);
            }
    });
    return out;
}

}  // namespace gilab
