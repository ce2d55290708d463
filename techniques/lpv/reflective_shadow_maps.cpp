#include "techniques/lpv/reflective_shadow_maps.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include "core/render/surface_material.hpp"
#include "core/render/interaction.hpp"
#include "core/render/sampling.hpp"
#include "core/util/parallel.hpp"
#include "core/util/rng.hpp"

namespace gilab {

namespace {

// The ray of one texel and the flux it carries; footprint turns the hit distance and the
// cosine at the hit into the surfel's area.
struct TexelRay {
    Ray ray;
    Vec3 flux{0};
    float solid_angle = 0;   // perspective and emitter texels: area = Δω·t²/cos
    float plane_area = 0;    // orthographic texels: area = texel area/cos
};

// Any map: size² texels, each mapped to its ray by `texel`. A row's rays go to Embree as
// one coherent stream (they leave one light side by side); rows are fixed, so nothing
// depends on the thread count.
template <class TexelFn>
void trace_map(const TracedScene& scene, int size, TexelFn&& texel, ReflectiveShadowMap& out) {
    const size_t n = size_t(size) * size_t(size);
    std::vector<std::optional<VirtualPointLight>> vpl(n);
    std::vector<Surfel> surfel(n);
    parallel_for(size_t(size), 1, [&](size_t begin, size_t end) {
        std::vector<TexelRay> texels;
        std::vector<Ray> rays;
        std::vector<size_t> index;
        std::vector<Hit> hits;
        for (size_t row = begin; row < end; ++row) {
            texels.clear();
            rays.clear();
            index.clear();
            for (int col = 0; col < size; ++col) {
                const size_t i = row * size_t(size) + size_t(col);
                const std::optional<TexelRay> tr = texel(col, int(row), i);
                if (!tr || max_component(tr->flux) <= 0.0f) continue;
                texels.push_back(*tr);
                rays.push_back(tr->ray);
                index.push_back(i);
            }
            hits.resize(rays.size());
            scene.tracer().intersect(rays, hits);
            for (size_t k = 0; k < rays.size(); ++k) {
                const Hit& hit = hits[k];
                if (!hit.valid()) continue;
                const TexelRay& tr = texels[k];
                SurfaceInteraction si = make_interaction(scene.frame(), tr.ray, hit);
                // The RSM texel is the VPL's footprint: textures are filtered over its width.
                const Material& material = scene.materials()[si.material];
                const float texel_width = std::sqrt(tr.plane_area > 0 ? tr.plane_area : tr.solid_angle * hit.t * hit.t *
                                                                                         glm::dot(tr.ray.direction, tr.ray.direction));
                apply_normal_map(material, si, texel_width);
                const SurfaceMaterial m = at_surface(material, si, texel_width);
                const float t = hit.t * glm::length(tr.ray.direction);
                const float cos_hit = std::max(0.05f, std::abs(glm::dot(si.geometric_normal, glm::normalize(tr.ray.direction))));
                const float area = tr.plane_area > 0 ? tr.plane_area / cos_hit : tr.solid_angle * t * t / cos_hit;
                vpl[index[k]] = VirtualPointLight{si.position, si.shading_normal, m.albedo * tr.flux};
                surfel[index[k]] = Surfel{si.position, si.geometric_normal, area};
            }
        }
    });
    out.texels += n;
    for (size_t i = 0; i < n; ++i) {
        if (!vpl[i]) continue;
        if (max_component(vpl[i]->flux) > 0.0f) out.vpls.push_back(*vpl[i]);
        out.surfels.push_back(surfel[i]);
    }
}

// A perspective map along `axis` with half-width tan_half at distance 1: the cube faces of
// a point light, or a spot's cone.
void trace_frustum(const TracedScene& scene, const PunctualLight& light, const Vec3& axis, float tan_half, int size,
                   ReflectiveShadowMap& out) {
    const Frame frame(axis);
    const float texel_side = 2.0f * tan_half / float(size);
    trace_map(scene, size, [&](int col, int row, size_t) -> std::optional<TexelRay> {
        const float u = (float(col) + 0.5f) * texel_side - tan_half;
        const float v = (float(row) + 0.5f) * texel_side - tan_half;
        const Vec3 d = frame.to_world(Vec3(u, v, 1.0f));
        const float len = glm::length(d);
        const Vec3 w = d / len;
        // Δω of a texel on the plane at distance 1: area·cos³α (cos α = 1/len).
        const float solid_angle = texel_side * texel_side / (len * len * len);
        const float falloff = light.type == LightType::Spot ? spot_falloff(light, glm::dot(light.direction, w)) : 1.0f;
        if (falloff <= 0.0f) return std::nullopt;
        TexelRay tr;
        tr.ray.origin = light.position;
        tr.ray.direction = w;
        tr.flux = light.intensity * (falloff * solid_angle);
        tr.solid_angle = solid_angle;
        return tr;
    }, out);
}

void trace_point_or_spot(const TracedScene& scene, const PunctualLight& light, int size, ReflectiveShadowMap& out) {
    if (light.type == LightType::Spot && light.cos_outer >= std::sqrt(0.5f)) {
        const float c = std::min(light.cos_outer, 0.999999f);
        trace_frustum(scene, light, light.direction, std::sqrt(1.0f - c * c) / c, size, out);
        return;
    }
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f}) {
            Vec3 a(0.0f);
            a[axis] = sign;
            trace_frustum(scene, light, a, 1.0f, size, out);
        }
}

void trace_directional(const TracedScene& scene, const PunctualLight& light, const Bounds3& region, int size,
                       ReflectiveShadowMap& out) {
    if (region.empty()) return;
    const Vec3 d = light.direction;
    const Frame frame(d);
    const Vec3 centre = region.center();
    const float radius = std::max(0.5f * glm::length(region.extent()), 1e-6f);
    // Rays start outside the whole scene, so occluders beyond the region cast shadows.
    const Bounds3& all = scene.frame().bounds;
    const float back = glm::length(all.extent()) + glm::length(all.center() - centre) + radius;
    const float texel_side = 2.0f * radius / float(size);
    trace_map(scene, size, [&](int col, int row, size_t) -> std::optional<TexelRay> {
        const float u = (float(col) + 0.5f) * texel_side - radius;
        const float v = (float(row) + 0.5f) * texel_side - radius;
        TexelRay tr;
        tr.ray.origin = centre + frame.to_world(Vec3(u, v, 0.0f)) - back * d;
        tr.ray.direction = d;
        tr.flux = light.intensity * (texel_side * texel_side);
        tr.plane_area = texel_side * texel_side;
        return tr;
    }, out);
}

void trace_emitters(const TracedScene& scene, const RsmOptions& options, ReflectiveShadowMap& out) {
    const std::vector<EmissiveTriangle>& triangles = scene.lights().emissive_triangles();
    std::vector<float> weights;
    for (const EmissiveTriangle& e : triangles) weights.push_back(e.area * (e.radiance.x + e.radiance.y + e.radiance.z));
    const DiscreteDistribution distribution(weights);
    if (distribution.empty()) return;
    const size_t texels = size_t(options.size) * size_t(options.size);
    trace_map(scene, options.size, [&](int, int, size_t i) -> std::optional<TexelRay> {
        Rng rng = Rng::for_sample(options.seed, i, 0, 0x72736d);
        const float u_light = std::min((float(i) + rng.uniform()) / float(texels), 0.99999994f);
        const size_t index = distribution.sample(u_light);
        const EmissiveTriangle& e = triangles[index];
        const Vec2 b = sample_uniform_triangle(rng.uniform2());
        const Vec3 q = (1.0f - b.x - b.y) * e.p0 + b.x * e.p1 + b.y * e.p2;
        const Vec3 local = sample_cosine_hemisphere(rng.uniform2());
        const float cos_emit = std::max(local.z, 1e-3f);
        const float pmf = distribution.pmf(index);
        TexelRay tr;
        tr.ray.direction = Frame(e.normal).to_world(local);
        tr.ray.origin = q + 4.0f * ray_epsilon(q) * e.normal;
        tr.flux = e.radiance * (kPi * e.area / (pmf * float(texels)));
        // The solid angle one sample stands for, seen from the emitter: 1/(N·pdf(ω)).
        tr.solid_angle = kPi / (float(texels) * cos_emit);
        return tr;
    }, out);
}

}  // namespace

std::vector<ReflectiveShadowMap> render_reflective_shadow_maps(const TracedScene& scene, const RsmOptions& options) {
    std::vector<ReflectiveShadowMap> maps;
    for (PunctualLight light : scene.frame().lights) {
        if (max_component(light.intensity) <= 0.0f) continue;
        const float len = glm::length(light.direction);
        light.direction = len > 0 && std::isfinite(len) ? light.direction / len : Vec3(0, -1, 0);
        ReflectiveShadowMap map;
        map.light = light.name;
        if (light.type == LightType::Directional)
            trace_directional(scene, light, options.region, options.size, map);
        else
            trace_point_or_spot(scene, light, options.size, map);
        maps.push_back(std::move(map));
    }
    if (scene.lights().has_area_lights()) {
        ReflectiveShadowMap map;
        map.light = "emissive triangles";
        trace_emitters(scene, options, map);
        maps.push_back(std::move(map));
    }
    return maps;
}

}  // namespace gilab
