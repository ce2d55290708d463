#include "core/render/surface_material.hpp"

namespace gilab {
namespace {

// The footprint of the cone in the texture's UV set, in UV units.
float uv_footprint(const TextureRef& t, const SurfaceInteraction& si, float cone_width) {
    if (!(cone_width > 0.0f)) return 0.0f;
    const int k = std::clamp(t.uv_set, 0, kUvSetCount - 1);
    const float cos_theta = std::max(std::abs(glm::dot(si.geometric_normal, si.wo)), 1e-3f);
    return cone_width / cos_theta * si.uv_per_length[k];
}

Vec4 lookup(const TextureRef& t, const SurfaceInteraction& si, float cone_width) {
    const int k = std::clamp(t.uv_set, 0, kUvSetCount - 1);
    return t.sample(si.uv[k], uv_footprint(t, si, cone_width));
}

}  // namespace

SurfaceMaterial at_surface(const Material& m, const SurfaceInteraction& si, float cone_width) {
    SurfaceMaterial out = m;  // the plain values only
    if (m.albedo_texture) out.albedo *= Vec3(lookup(m.albedo_texture, si, cone_width));
    if (m.emission_texture && m.is_emissive()) out.emission *= Vec3(lookup(m.emission_texture, si, cone_width));
    return out;
}

void apply_normal_map(const Material& m, SurfaceInteraction& si, float cone_width) {
    if (!m.normal_texture) return;
    const int k = std::clamp(m.normal_texture.uv_set, 0, kUvSetCount - 1);
    if (!(si.uv_per_length[k] > 0.0f)) return;  // no tangent frame on this triangle
    // Tangents along the texture's own coordinates (s, t) = A·uv + b: [dp/ds dp/dt] = [dp/du dp/dv]·A⁻¹.
    const UvTransform& tr = m.normal_texture.transform;
    const float c = std::cos(tr.rotation), sn = std::sin(tr.rotation);
    const glm::mat2 a = glm::mat2(Vec2(c * tr.scale.x, -sn * tr.scale.x), Vec2(sn * tr.scale.y, c * tr.scale.y));
    if (!(std::abs(glm::determinant(a)) > 0.0f)) return;
    const glm::mat2 inv = glm::inverse(a);
    const Vec3 dpds = si.dpdu[k] * inv[0][0] + si.dpdv[k] * inv[0][1];
    const Vec3 dpdt = si.dpdu[k] * inv[1][0] + si.dpdv[k] * inv[1][1];

    const Vec3 n = si.shading_normal;
    Vec3 tangent = dpds - n * glm::dot(n, dpds);
    const float tl = glm::length(tangent);
    if (!(tl > 0.0f)) return;
    tangent /= tl;
    Vec3 bitangent = glm::cross(n, tangent);
    // The map's +y points to the image's top row, against +t (t grows down the image).
    if (glm::dot(bitangent, dpdt) > 0.0f) bitangent = -bitangent;

    const Vec4 texel = lookup(m.normal_texture, si, cone_width);
    const Vec3 local(m.normal_scale * (2.0f * texel.x - 1.0f), m.normal_scale * (2.0f * texel.y - 1.0f),
                     2.0f * texel.z - 1.0f);
    Vec3 mapped = local.x * tangent + local.y * bitangent + local.z * n;
    const float ml = glm::length(mapped);
    if (!(ml > 0.0f) || !std::isfinite(ml)) return;
    mapped /= ml;
    // Keep the bent normal on the geometric normal's side, at least this far above it.
    constexpr float kMinCos = 0.01f;
    const float above = glm::dot(mapped, si.geometric_normal);
    if (above < kMinCos) mapped = glm::normalize(mapped + (kMinCos - above) * si.geometric_normal);
    si.shading_normal = mapped;
}

float alpha_at(const Material& m, const Vec2 uv[kUvSetCount]) {
    float a = m.alpha;
    if (m.alpha_texture) {
        const int k = std::clamp(m.alpha_texture.uv_set, 0, kUvSetCount - 1);
        a *= m.alpha_texture.sample(uv[k], 0.0f).w;
    }
    return a;
}

bool surface_present(const Material& m, const Vec2 uv[kUvSetCount]) {
    return !m.alpha_tested() || alpha_at(m, uv) >= m.alpha_cutoff;
}

}  // namespace gilab
