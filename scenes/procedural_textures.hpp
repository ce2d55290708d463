#pragma once
// Texture images built in code, for the built-in textured scene and the tests that check
// what a render makes of them: each comes with the exact pattern it encodes.
#include "core/texture/mip_map.hpp"

namespace gilab {

// checks × checks squares of `texels` texels each, colours a (top-left) and b given in
// linear RGB, stored sRGB-encoded; opaque.
Rgba8Image checkerboard_image(int checks, int texels, const Vec3& a, const Vec3& b);

// A leaf-shaped alpha mask: opaque (alpha 255) inside the leaf, transparent (0) outside,
// white colour. Four leaves on a 2 × 2 grid, each a lens between two circular arcs.
Rgba8Image leaf_mask_image(int size);
// The fraction of the image's texels the mask leaves open (alpha < 128).
double open_fraction(const Rgba8Image& mask);

// Tangent-space normal map of parallel ripples along u: the height field
// h(s) = amplitude · sin(2π · ripples · s) over s ∈ [0, 1) in texture units, so the
// normal is (−h'(s), 0, 1) normalised (x along +s, y towards the image's top row).
// 8-bit linear, (n + 1) / 2 per channel.
struct RippleNormalMap {
    int ripples = 4;
    float amplitude = 0.02f;
    Vec3 normal_at(float s) const;  // the analytic tangent-space normal
    Rgba8Image image(int size) const;
};

}  // namespace gilab
