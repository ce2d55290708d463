#include "techniques/photon_mapping/photon_tracer.hpp"

#include <atomic>
#include "core/render/bsdf.hpp"
#include "core/util/error.hpp"
#include "core/render/interaction.hpp"
#include "core/render/surface_material.hpp"
#include "core/util/parallel.hpp"
#include "core/util/stats.hpp"

namespace gilab {

namespace {

// Photons per task: each task fills its own vector in photon order.
constexpr uint64_t kChunk = 2048;

uint64_t trace_one(const RayTracer& tracer, const SceneFrame& frame, const std::vector<Material>& materials,
                   const LightSampler& lights, const PhotonTraceSettings& s, uint64_t index, std::vector<Photon>& out,
                   bool& stored) {
    Rng rng = Rng::for_sample(s.seed, index, 0, kPhotonPassBase + s.pass);
    EmissionSample e = lights.sample_emission(rng);
    Vec3 flux = e.power / float(s.emitted);
    if (!(max_component(flux) > 0.0f) || !is_finite(flux)) return 0;
    Ray ray = e.ray;
    uint64_t rays = 0;
    for (int hit_index = 1; hit_index <= s.max_depth; ++hit_index) {
        Hit hit = tracer.intersect(ray);
        ++rays;
        if (!hit.valid()) break;
        SurfaceInteraction si = make_interaction(frame, ray, hit);
        // Photons carry no footprint: the finest texture level at the hit.
        const Material& material = materials[si.material];
        apply_normal_map(material, si, 0.0f);
        const SurfaceMaterial m = at_surface(material, si, 0.0f);
        if (hit_index >= s.first_stored_hit && (max_component(m.albedo) > 0.0f || m.has_glossy_lobe())) {
            Photon p;
            p.position = si.position;
            p.power = flux;
            p.wi = PackedDirection::pack(si.wo);
            p.normal = PackedDirection::pack(si.geometric_normal);
            p.set_hit_index(hit_index);
            out.push_back(p);
            stored = true;
        }
        if (hit_index == s.max_depth) break;
        BsdfSample bs = bsdf_sample(m, si.shading_normal, si.wo, rng);
        if (!bs.valid || glm::dot(bs.wi, si.geometric_normal) <= 0.0f) break;
        // Russian roulette by albedo; the survivor's flux is rescaled by 1/q.
        float q = std::min(1.0f, max_component(bs.weight));
        if (!(q > 0.0f) || rng.uniform() >= q) break;
        flux *= bs.weight / q;
        ray = Ray{si.spawn_origin(bs.wi), bs.wi};
    }
    return rays;
}

}  // namespace

PhotonTraceResult trace_photons(const RayTracer& tracer, const SceneFrame& frame, const std::vector<Material>& materials,
                                const LightSampler& lights, const PhotonTraceSettings& s) {
    if (s.max_depth < 1) throw Error("photon tracing", "max_photon_depth must be at least 1");
    if (s.first_stored_hit < 1) throw Error("photon tracing", "first stored hit must be at least 1");
    Stopwatch watch;
    PhotonTraceResult result;
    result.emitted = s.emitted;
    if (lights.empty() || s.emitted == 0) {
        result.trace_ms = watch.elapsed_ms();
        return result;
    }
    const uint64_t chunks = (s.emitted + kChunk - 1) / kChunk;
    std::vector<std::vector<Photon>> parts(chunks);
    std::atomic<uint64_t> rays{0}, paths{0};
    parallel_for(chunks, 1, [&](size_t b, size_t e) {
        for (size_t c = b; c < e; ++c) {
            uint64_t first = c * kChunk, last = std::min(s.emitted, first + kChunk);
            std::vector<Photon>& out = parts[c];
            out.reserve(size_t(last - first) * 2);
            uint64_t chunk_rays = 0, chunk_paths = 0;
            for (uint64_t i = first; i < last; ++i) {
                bool stored = false;
                chunk_rays += trace_one(tracer, frame, materials, lights, s, i, out, stored);
                chunk_paths += stored;
            }
            rays += chunk_rays;
            paths += chunk_paths;
        }
    });
    size_t total = 0;
    for (const auto& p : parts) total += p.size();
    result.photons.reserve(total);
    for (auto& p : parts) {
        result.photons.insert(result.photons.end(), p.begin(), p.end());
        std::vector<Photon>().swap(p);
    }
    result.rays = rays.load();
    result.paths_stored = paths.load();
    result.trace_ms = watch.elapsed_ms();
    return result;
}

}  // namespace gilab
