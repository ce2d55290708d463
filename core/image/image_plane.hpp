#pragma once
// A single-channel float image and the 2D convolution the image metrics (SSIM, FLIP)
// filter with. Edges are clamped (the nearest pixel is repeated), so a constant image
// stays constant under any kernel that sums to one.
#include <cstddef>
#include <vector>

namespace gilab {

struct ImagePlane {
    int width = 0, height = 0;
    std::vector<float> values;  // row-major, top row first

    ImagePlane() = default;
    ImagePlane(int w, int h, float fill = 0.0f) : width(w), height(h), values(std::size_t(w) * std::size_t(h), fill) {}
    float& at(int x, int y) { return values[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
    float at(int x, int y) const { return values[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
    // Clamped to the nearest pixel inside the image.
    float clamped(int x, int y) const;
    double mean() const;
};

// A square kernel of odd side 2·radius + 1, row-major.
struct Kernel2D {
    int radius = 0;
    std::vector<float> weights;
    float at(int dx, int dy) const { return weights[std::size_t(dy + radius) * std::size_t(2 * radius + 1) + std::size_t(dx + radius)]; }
};

// out(x, y) = Σ kernel(dx, dy) · in(x + dx, y + dy), rows in parallel; deterministic.
ImagePlane convolve(const ImagePlane& in, const Kernel2D& kernel);

}  // namespace gilab
