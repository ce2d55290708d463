#include "core/texture/texture.hpp"

namespace gilab {

Vec2 UvTransform::apply(Vec2 uv) const {
    if (is_identity()) return uv;
    const Vec2 s = uv * scale;
    const float c = std::cos(rotation), n = std::sin(rotation);
    // glTF's rotation matrix [[c, s], [-s, c]] acting on (u, v), as the extension defines it.
    return Vec2(c * s.x + n * s.y, -n * s.x + c * s.y) + offset;
}

Vec4 TextureRef::sample(Vec2 uv, float footprint) const {
    const Vec2 st = transform.apply(uv);
    const float lod = footprint > 0.0f ? image->level_for_footprint(footprint * transform.max_stretch()) : 0.0f;
    return image->trilinear(st, lod, wrap_s, wrap_t);
}

}  // namespace gilab
