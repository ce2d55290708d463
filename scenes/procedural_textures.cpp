#include "scenes/procedural_textures.hpp"

#include <cmath>
#include "core/image/display_planes.hpp"

namespace gilab {
namespace {

uint8_t code(float v) { return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

Rgba8Image blank(int width, int height) {
    Rgba8Image img;
    img.width = width;
    img.height = height;
    img.texels.assign(size_t(width) * size_t(height) * 4, 255);
    return img;
}

}  // namespace

Rgba8Image checkerboard_image(int checks, int texels, const Vec3& a, const Vec3& b) {
    const int size = checks * texels;
    Rgba8Image img = blank(size, size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const Vec3& c = ((x / texels + y / texels) % 2 == 0) ? a : b;
            uint8_t* t = &img.texels[(size_t(y) * size_t(size) + size_t(x)) * 4];
            for (int k = 0; k < 3; ++k) t[k] = code(srgb_encode(c[k]));
        }
    return img;
}

Rgba8Image leaf_mask_image(int size) {
    Rgba8Image img = blank(size, size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            // Position within its quarter of the image, in [-1, 1]².
            const float half = float(size) / 2.0f;
            const float u = 2.0f * (std::fmod(float(x) + 0.5f, half) / half) - 1.0f;
            const float v = 2.0f * (std::fmod(float(y) + 0.5f, half) / half) - 1.0f;
            // A lens along the diagonal: inside both circles of radius 1.1 whose centres
            // sit 0.75 off the diagonal on either side.
            const float d = 0.75f / std::sqrt(2.0f);
            const float r2 = 1.1f * 1.1f;
            const bool inside = (u - d) * (u - d) + (v + d) * (v + d) < r2 && (u + d) * (u + d) + (v - d) * (v - d) < r2 &&
                                std::abs(u) < 0.95f && std::abs(v) < 0.95f;
            img.texels[(size_t(y) * size_t(size) + size_t(x)) * 4 + 3] = inside ? 255 : 0;
        }
    return img;
}

double open_fraction(const Rgba8Image& mask) {
    size_t open = 0, n = 0;
    for (size_t i = 3; i < mask.texels.size(); i += 4, ++n) open += mask.texels[i] < 128;
    return n ? double(open) / double(n) : 0.0;
}

Vec3 RippleNormalMap::normal_at(float s) const {
    const float w = 2.0f * kPi * float(ripples);
    const float slope = amplitude * w * std::cos(w * s);
    return glm::normalize(Vec3(-slope, 0.0f, 1.0f));
}

Rgba8Image RippleNormalMap::image(int size) const {
    Rgba8Image img = blank(size, size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const Vec3 n = normal_at((float(x) + 0.5f) / float(size));
            uint8_t* t = &img.texels[(size_t(y) * size_t(size) + size_t(x)) * 4];
            for (int k = 0; k < 3; ++k) t[k] = code(0.5f * (n[k] + 1.0f));
        }
    return img;
}

}  // namespace gilab
