#include "core/render/direct_lighting.hpp"

#include <cmath>
#include "core/render/bsdf.hpp"
#include "core/render/interaction.hpp"

namespace gilab {

namespace {

// A shadow ray from `origin` to `target` (a point), stopping just short of it.
Ray segment(const Vec3& origin, const Vec3& target) {
    Ray r;
    r.origin = origin;
    Vec3 d = target - origin;
    float dist = glm::length(d);
    r.direction = dist > 0 ? d / dist : Vec3(0, 1, 0);
    r.tmax = std::max(0.0f, dist - ray_epsilon(target));
    return r;
}

}  // namespace

DirectLighting::DirectLighting(const SceneFrame& frame, const std::vector<Material>& materials, int area_samples)
    : area_samples_(std::max(area_samples, 1)) {
    LightSampler sampler(frame, materials);
    triangles_ = sampler.emissive_triangles();
    std::vector<float> weights;
    for (const EmissiveTriangle& e : triangles_) weights.push_back(e.area * (e.radiance.x + e.radiance.y + e.radiance.z));
    distribution_ = DiscreteDistribution(weights);
    for (PunctualLight l : frame.lights) {
        float len = glm::length(l.direction);
        l.direction = len > 0 && std::isfinite(len) ? l.direction / len : Vec3(0, -1, 0);
        if (max_component(l.intensity) > 0.0f) punctual_.push_back(l);
    }
}

template <class Weight>
void DirectLighting::queries(const Vec3& p, const Vec3& ng, float offset, Rng& rng, Weight&& weight,
                             std::vector<ShadowQuery>& out) const {
    const Vec3 origin = p + offset * ng;
    for (const PunctualLight& l : punctual_) {
        Vec3 wi, Li;
        Ray ray;
        if (l.type == LightType::Directional) {
            wi = -l.direction;
            Li = l.intensity;
            ray.origin = origin;
            ray.direction = wi;
        } else {
            Vec3 d = l.position - p;
            float dist2 = glm::dot(d, d);
            if (!(dist2 > 0.0f)) continue;
            wi = d / std::sqrt(dist2);
            float falloff = l.type == LightType::Spot ? spot_falloff(l, glm::dot(l.direction, -wi)) : 1.0f;
            if (falloff <= 0.0f) continue;
            Li = l.intensity * (falloff / dist2);
            ray = segment(origin, l.position);
        }
        if (glm::dot(wi, ng) <= 0.0f) continue;
        Vec3 f = weight(wi);
        if (max_component(f) <= 0.0f) continue;
        out.push_back({ray, f * Li});
    }
    if (!distribution_.empty()) {
        const int n = area_samples_;
        for (int j = 0; j < n; ++j) {
            float u_light = (float(j) + rng.uniform()) / float(n);
            Vec2 u = rng.uniform2();
            size_t index = distribution_.sample(std::min(u_light, 0.99999994f));
            const EmissiveTriangle& e = triangles_[index];
            Vec2 b = sample_uniform_triangle(u);
            Vec3 q = (1.0f - b.x - b.y) * e.p0 + b.x * e.p1 + b.y * e.p2;
            Vec3 d = q - p;
            float dist2 = glm::dot(d, d);
            if (!(dist2 > 0.0f)) continue;
            Vec3 wi = d / std::sqrt(dist2);
            float cos_light = -glm::dot(e.normal, wi);
            if (cos_light <= 0.0f || glm::dot(wi, ng) <= 0.0f) continue;
            Vec3 f = weight(wi);
            if (max_component(f) <= 0.0f) continue;
            float pdf_area = distribution_.pmf(index) / e.area;
            if (!(pdf_area > 0.0f)) continue;
            out.push_back({segment(origin, q), f * e.radiance * (cos_light / (dist2 * pdf_area * float(n)))});
        }
    }
}

template <class Weight>
Vec3 DirectLighting::accumulate(const RayTracer& tracer, const Vec3& p, const Vec3& ng, float offset, Rng& rng,
                                Weight&& weight) const {
    thread_local std::vector<ShadowQuery> pending;
    pending.clear();
    queries(p, ng, offset, rng, weight, pending);
    Vec3 sum(0.0f);
    for (const ShadowQuery& q : pending)
        if (!tracer.occluded(q.ray)) sum += q.contribution;
    return sum;
}

void DirectLighting::irradiance_queries(const Vec3& p, const Vec3& n, float offset, Rng& rng,
                                        std::vector<ShadowQuery>& out) const {
    queries(p, n, offset, rng, [&](const Vec3& wi) { return Vec3(std::max(0.0f, glm::dot(n, wi))); }, out);
}

Vec3 DirectLighting::irradiance(const RayTracer& tracer, const Vec3& p, const Vec3& n, float offset, Rng& rng) const {
    return accumulate(tracer, p, n, offset, rng, [&](const Vec3& wi) { return Vec3(std::max(0.0f, glm::dot(n, wi))); });
}

Vec3 DirectLighting::reflected(const RayTracer& tracer, const SurfaceMaterial& m, const Vec3& p, const Vec3& n,
                               const Vec3& ng, const Vec3& wo, float offset, Rng& rng) const {
    return accumulate(tracer, p, ng, offset, rng, [&](const Vec3& wi) {
        float c = glm::dot(n, wi);
        if (c <= 0.0f) return Vec3(0.0f);
        return bsdf_eval(m, n, wo, wi) * c;
    });
}

}  // namespace gilab
