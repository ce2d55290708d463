#pragma once
// A decoded texture image and its mip pyramid. Texels stay 8 bits per channel in the
// image's own encoding, as pbrt-v4 keeps 8-bit images: colour channels sRGB-encoded for
// colour textures (base colour, emission), linear for data (normal maps); alpha is
// always linear. Lookups return linear values.
//
// Level k + 1 is a box filter of level k in linear space: each texel averages the 2 × 2
// texels below it (the last row or column of an odd-sized level folds a third texel in,
// which then weighs a little less than the others), so every level keeps the image's mean
// up to 8-bit rounding. Sizes halve, rounding down, to 1 × 1.
#include <cstdint>
#include <string>
#include <vector>
#include "core/util/math.hpp"

namespace gilab {

enum class ColorEncoding { Linear, Srgb };

// How texture coordinates outside [0, 1) map onto the image (glTF sampler wrapS/wrapT).
enum class WrapMode { Repeat, MirroredRepeat, ClampToEdge };

// Width × height texels of 4 channels (RGBA), rows from the top of the image.
struct Rgba8Image {
    int width = 0, height = 0;
    std::vector<uint8_t> texels;
};

class MipMap {
public:
    // Builds the pyramid; the image's size must already be checked (decode_image does).
    MipMap(Rgba8Image base, ColorEncoding encoding, std::string name);

    const std::string& name() const { return name_; }
    ColorEncoding encoding() const { return encoding_; }
    int levels() const { return int(levels_.size()); }
    int width(int level = 0) const { return levels_[size_t(level)].width; }
    int height(int level = 0) const { return levels_[size_t(level)].height; }
    const Rgba8Image& level(int k) const { return levels_[size_t(k)]; }
    // Bytes of every level's texels.
    size_t bytes() const;

    // Linear RGBA of texel (x, y) of `level`; x and y are wrapped first.
    Vec4 texel(int level, int x, int y, WrapMode wrap_s, WrapMode wrap_t) const;
    // Bilinear filter of `level` at texture coordinates st (0..1 spans the image; t = 0
    // is the top row, as glTF's UV origin).
    Vec4 bilinear(int level, Vec2 st, WrapMode wrap_s, WrapMode wrap_t) const;
    // Trilinear: bilinear in the two levels around the continuous level `lod`, clamped to
    // [0, levels − 1].
    Vec4 trilinear(Vec2 st, float lod, WrapMode wrap_s, WrapMode wrap_t) const;
    // The level whose texels are `footprint` wide in texture coordinates (log2 of the
    // footprint in level-0 texels along the longer side); −∞ for 0.
    float level_for_footprint(float footprint) const;

    // The linear value of an 8-bit code in this image's colour encoding.
    float decode(uint8_t code) const;

private:
    ColorEncoding encoding_;
    std::string name_;
    std::vector<Rgba8Image> levels_;
};

}  // namespace gilab
