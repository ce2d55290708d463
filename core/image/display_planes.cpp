#include "core/image/display_planes.hpp"

#include <algorithm>
#include <cmath>

namespace gilab {

std::array<ImagePlane, 3> display_planes(const Film& film, const std::string& layer_name,
                                         const std::function<float(float)>& map) {
    const Layer& layer = film.layer(layer_name);
    std::array<ImagePlane, 3> planes;
    for (auto& p : planes) p = ImagePlane(film.width(), film.height());
    const int ch = layer.channels;
    for (size_t i = 0; i < film.pixel_count(); ++i) {
        const float* p = layer.data.data() + i * size_t(ch);
        const float c[3] = {p[0], ch >= 3 ? p[1] : p[0], ch >= 3 ? p[2] : p[0]};
        const bool nan = std::isnan(c[0]) || std::isnan(c[1]) || std::isnan(c[2]);
        for (int k = 0; k < 3; ++k) planes[size_t(k)].values[i] = nan ? (k == 1 ? 0.0f : 1.0f) : map(c[k]);
    }
    return planes;
}

std::array<ImagePlane, 3> display_planes(const Film& film, const std::string& layer_name, double exposure) {
    const float scale = float(std::exp2(exposure));
    return display_planes(film, layer_name, [scale](float v) { return std::clamp(v * scale, 0.0f, 1.0f); });
}

float srgb_encode(float v) { return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f; }

float srgb_decode(float s) { return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f); }

}  // namespace gilab
