#pragma once
// A material's reference to a texture: the shared image, which UV set of the mesh it
// reads, the glTF KHR_texture_transform of those coordinates, and the wrap modes.
// Materials hold these; images are decoded once and shared between the materials that
// use them (the shared_ptr), so copying a Material is cheap.
#include <memory>
#include "core/texture/mip_map.hpp"

namespace gilab {

// KHR_texture_transform: uv' = T(offset) · R(rotation) · S(scale) · uv, rotation in
// radians counter-clockwise in UV space.
struct UvTransform {
    Vec2 offset{0.0f};
    float rotation = 0.0f;
    Vec2 scale{1.0f};

    bool is_identity() const { return offset == Vec2(0.0f) && rotation == 0.0f && scale == Vec2(1.0f); }
    bool operator==(const UvTransform&) const = default;
    Vec2 apply(Vec2 uv) const;
    // How much the transform stretches a length in UV space, at most (for footprints).
    float max_stretch() const { return std::max(std::abs(scale.x), std::abs(scale.y)); }
};

// Mesh UV sets a texture can read (glTF TEXCOORD_0 and TEXCOORD_1).
inline constexpr int kUvSetCount = 2;

struct TextureRef {
    std::shared_ptr<const MipMap> image;  // null: no texture
    int uv_set = 0;
    UvTransform transform;
    WrapMode wrap_s = WrapMode::Repeat, wrap_t = WrapMode::Repeat;

    explicit operator bool() const { return image != nullptr; }
    // The same image object read the same way.
    bool operator==(const TextureRef&) const = default;
    // Linear RGBA at the mesh UV `uv` filtered over a footprint `footprint` wide in that
    // UV set's units (before the transform); footprint 0 reads the finest level.
    Vec4 sample(Vec2 uv, float footprint) const;
};

}  // namespace gilab
