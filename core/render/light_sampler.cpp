#include "core/render/light_sampler.hpp"

#include <cmath>
#include "core/util/error.hpp"
#include "core/render/interaction.hpp"

namespace gilab {

namespace {

float channel_average(const Vec3& c) { return (c.x + c.y + c.z) / 3.0f; }

Vec3 unit_or(const Vec3& v, const Vec3& fallback) {
    float len = glm::length(v);
    return len > 0.0f && std::isfinite(len) ? v / len : fallback;
}

}  // namespace

Vec3 EmissiveTriangle::radiance_at(const Vec2& b) const {
    if (!texture) return radiance;
    return radiance * Vec3(texture.sample((1.0f - b.x - b.y) * uv0 + b.x * uv1 + b.y * uv2, 0.0f));
}

LightSampler::LightSampler(const SceneFrame& frame, const std::vector<Material>& materials) {
    if (!frame.bounds.empty()) {
        scene_center_ = frame.bounds.center();
        scene_radius_ = 0.5f * glm::length(frame.bounds.extent());
    }
    if (!(scene_radius_ > 0.0f) || !std::isfinite(scene_radius_)) scene_radius_ = 1.0f;

    std::vector<float> weights;
    mesh_offsets_.reserve(frame.meshes.size() + 1);
    size_t offset = 0;
    for (const WorldMesh& mesh : frame.meshes) {
        mesh_offsets_.push_back(offset);
        offset += mesh.triangles.size();
    }
    mesh_offsets_.push_back(offset);
    triangle_index_of_.assign(offset, -1);

    for (size_t m = 0; m < frame.meshes.size(); ++m) {
        const WorldMesh& mesh = frame.meshes[m];
        for (size_t t = 0; t < mesh.triangles.size(); ++t) {
            uint32_t id = t < mesh.material_ids.size() ? mesh.material_ids[t] : 0;
            if (id >= materials.size())
                throw Error("LightSampler", "mesh " + std::to_string(m) + " triangle " + std::to_string(t) +
                                                " uses material " + std::to_string(id) + " but there are " +
                                                std::to_string(materials.size()));
            const Material& mat = materials[id];
            if (!mat.is_emissive()) continue;
            EmissiveTriangle e;
            e.mesh = uint32_t(m);
            e.triangle = uint32_t(t);
            e.p0 = mesh.positions[mesh.triangles[t].x];
            e.p1 = mesh.positions[mesh.triangles[t].y];
            e.p2 = mesh.positions[mesh.triangles[t].z];
            Vec3 c = glm::cross(e.p1 - e.p0, e.p2 - e.p0);
            float len = glm::length(c);
            if (!(len > 0.0f) || !std::isfinite(len)) continue;  // degenerate: emits nothing
            e.normal = c / len;
            e.area = 0.5f * len;
            e.radiance = mat.emission;
            Vec3 mean_radiance = e.radiance;
            const std::vector<Vec2>& uvs = mesh.uv_set(std::clamp(mat.emission_texture.uv_set, 0, kUvSetCount - 1));
            if (mat.emission_texture && uvs.size() == mesh.positions.size()) {
                e.texture = mat.emission_texture;
                e.uv0 = uvs[mesh.triangles[t].x];
                e.uv1 = uvs[mesh.triangles[t].y];
                e.uv2 = uvs[mesh.triangles[t].z];
                // Selection by the image's mean (its 1 × 1 level): any positive weight is unbiased.
                const MipMap& img = *e.texture.image;
                mean_radiance *= Vec3(img.texel(img.levels() - 1, 0, 0, WrapMode::Repeat, WrapMode::Repeat));
            }
            triangle_index_of_[mesh_offsets_[m] + t] = int(triangles_.size());
            triangles_.push_back(e);
            weights.push_back(kPi * e.area * std::max(channel_average(mean_radiance), 1e-6f * channel_average(e.radiance)));
        }
    }

    for (PunctualLight l : frame.lights) {
        l.direction = unit_or(l.direction, Vec3(0, -1, 0));
        if (l.type == LightType::Spot && !(l.cos_inner >= l.cos_outer))
            throw Error("light '" + l.name + "'", "spot cos_inner (" + std::to_string(l.cos_inner) +
                                                      ") must be at least cos_outer (" + std::to_string(l.cos_outer) + ")");
        float I = channel_average(l.intensity);
        float power = 0.0f;
        switch (l.type) {
            case LightType::Point: power = 4.0f * kPi * I; break;
            case LightType::Spot: power = 2.0f * kPi * (1.0f - 0.5f * (l.cos_inner + l.cos_outer)) * I; break;
            case LightType::Directional: power = kPi * scene_radius_ * scene_radius_ * I; break;
        }
        if (!(power > 0.0f) || !std::isfinite(power)) continue;  // black light: never sampled
        punctual_.push_back(l);
        weights.push_back(power);
    }
    distribution_ = DiscreteDistribution(weights);
    area_distribution_ = DiscreteDistribution(std::vector<float>(weights.begin(), weights.begin() + triangles_.size()));
}

LightSample LightSampler::sample_incident(const Vec3& x, Rng& rng) const {
    LightSample s;
    float u_light = rng.uniform();
    Vec2 u = rng.uniform2();
    if (empty()) return s;
    size_t index = distribution_.sample(u_light);
    float pmf = distribution_.pmf(index);
    if (index < triangles_.size()) return triangle_incident(triangles_[index], x, u, pmf);
    s = punctual_incident(index - triangles_.size(), x);
    s.pdf *= pmf;
    return s;
}

LightSample LightSampler::sample_area_incident(const Vec3& x, Rng& rng) const {
    float u_light = rng.uniform();
    Vec2 u = rng.uniform2();
    if (triangles_.empty()) return LightSample{};
    size_t index = area_distribution_.sample(u_light);
    return triangle_incident(triangles_[index], x, u, area_distribution_.pmf(index));
}

LightSample LightSampler::triangle_incident(const EmissiveTriangle& e, const Vec3& x, const Vec2& u, float pmf) {
    LightSample s;
    Vec2 b = sample_uniform_triangle(u);
    Vec3 p = (1.0f - b.x - b.y) * e.p0 + b.x * e.p1 + b.y * e.p2;
    Vec3 d = p - x;
    float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0f)) return s;
    float dist = std::sqrt(dist2);
    s.wi = d / dist;
    s.distance = dist;
    float cos_light = -glm::dot(e.normal, s.wi);
    if (cos_light <= 0.0f) return s;  // back of a one-sided emitter
    // Area pdf 1/A converted to solid angle at x.
    s.pdf = pmf * dist2 / (cos_light * e.area);
    s.Li = e.radiance_at(b);
    return s;
}

LightSample LightSampler::punctual_incident(size_t i, const Vec3& x) const {
    const PunctualLight& l = punctual_.at(i);
    LightSample s;
    s.delta = true;
    s.pdf = 1.0f;
    if (l.type == LightType::Directional) {
        s.wi = -l.direction;
        s.distance = kInfinity;
        s.Li = l.intensity;
        return s;
    }
    Vec3 d = l.position - x;
    float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0f)) {
        s.pdf = 0.0f;
        return s;
    }
    float dist = std::sqrt(dist2);
    s.wi = d / dist;
    s.distance = dist;
    float falloff = l.type == LightType::Spot ? spot_falloff(l, glm::dot(l.direction, -s.wi)) : 1.0f;
    s.Li = l.intensity * (falloff / dist2);
    return s;
}

float LightSampler::pdf_incident(const Vec3& x, uint32_t mesh, uint32_t triangle, const Vec3& p_light) const {
    if (mesh + 1 >= mesh_offsets_.size()) return 0.0f;
    size_t flat = mesh_offsets_[mesh] + triangle;
    if (triangle >= mesh_offsets_[mesh + 1] - mesh_offsets_[mesh]) return 0.0f;
    int index = triangle_index_of_[flat];
    if (index < 0) return 0.0f;
    const EmissiveTriangle& e = triangles_[size_t(index)];
    Vec3 d = p_light - x;
    float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0f)) return 0.0f;
    float cos_light = -glm::dot(e.normal, d) / std::sqrt(dist2);
    if (cos_light <= 0.0f) return 0.0f;
    return distribution_.pmf(size_t(index)) * dist2 / (cos_light * e.area);
}

EmissionSample LightSampler::sample_emission(Rng& rng) const {
    EmissionSample s;
    float u_light = rng.uniform();
    Vec2 u_pos = rng.uniform2();
    Vec2 u_dir = rng.uniform2();
    if (empty()) return s;
    size_t index = distribution_.sample(u_light);
    float pmf = distribution_.pmf(index);
    if (!(pmf > 0.0f)) return s;
    if (index < triangles_.size()) {
        const EmissiveTriangle& e = triangles_[index];
        Vec2 b = sample_uniform_triangle(u_pos);
        Vec3 p = (1.0f - b.x - b.y) * e.p0 + b.x * e.p1 + b.y * e.p2;
        Vec3 w = Frame(e.normal).to_world(sample_cosine_hemisphere(u_dir));
        s.ray.origin = p + ray_epsilon(p) * e.normal;
        s.ray.direction = glm::normalize(w);
        // Le cosθ / (pdf_A · pdf_ω) = Le cosθ · A · π / cosθ.
        s.power = e.radiance_at(b) * (kPi * e.area / pmf);
        return s;
    }
    const PunctualLight& l = punctual_[index - triangles_.size()];
    switch (l.type) {
        case LightType::Point:
            s.ray.origin = l.position;
            s.ray.direction = sample_uniform_sphere(u_dir);
            s.power = l.intensity * (4.0f * kPi / pmf);
            break;
        case LightType::Spot: {
            float cos_max = std::clamp(l.cos_outer, -1.0f, 1.0f);
            Vec3 local = sample_uniform_cone(u_dir, cos_max);
            s.ray.origin = l.position;
            s.ray.direction = glm::normalize(Frame(l.direction).to_world(local));
            float cone_pdf = 1.0f / (2.0f * kPi * (1.0f - cos_max));
            if (!(cone_pdf < kInfinity)) break;  // zero-width cone emits nothing
            s.power = l.intensity * (spot_falloff(l, local.z) / (cone_pdf * pmf));
            break;
        }
        case LightType::Directional: {
            // A disk covering the scene's bounding sphere, outside it, facing along the light.
            float r = scene_radius_;
            Frame frame(l.direction);
            float radius = std::sqrt(u_pos.x), phi = 2.0f * kPi * u_pos.y;
            Vec3 offset = frame.to_world(Vec3(r * radius * std::cos(phi), r * radius * std::sin(phi), 0.0f));
            s.ray.origin = scene_center_ - 1.01f * r * l.direction + offset;
            s.ray.direction = l.direction;
            s.power = l.intensity * (kPi * r * r / pmf);
            break;
        }
    }
    return s;
}

Ray shadow_ray(const SurfaceInteraction& si, const LightSample& ls) {
    Ray r;
    r.origin = si.spawn_origin(ls.wi);
    r.direction = ls.wi;
    if (std::isinf(ls.distance)) return r;
    Vec3 target = si.position + ls.distance * ls.wi;
    Vec3 d = target - r.origin;
    float dist = glm::length(d);
    if (!(dist > 0.0f)) return r;
    r.direction = d / dist;
    r.tmax = std::max(0.0f, dist - ray_epsilon(target));
    return r;
}

}  // namespace gilab
