#pragma once
// What a display shows of a film layer, as three linear planes in [0, 1]: the layer's
// RGB scaled by 2^exposure and clamped, as in the PNG previews (NaN is magenta, a
// 1-channel layer grey). The perceptual metrics compare these.
#include <array>
#include <functional>
#include <string>
#include "core/image/film.hpp"
#include "core/image/image_plane.hpp"

namespace gilab {

std::array<ImagePlane, 3> display_planes(const Film& film, const std::string& layer, double exposure);
// The same with each of the layer's values through `map` instead of the exposure and
// the clamp (HDR-FLIP's tone curve); NaN is magenta and a 1-channel layer grey all the same.
std::array<ImagePlane, 3> display_planes(const Film& film, const std::string& layer,
                                         const std::function<float(float)>& map);

// The sRGB transfer function (IEC 61966-2-1) and its inverse, on [0, 1].
float srgb_encode(float linear);
float srgb_decode(float encoded);

}  // namespace gilab
