#include "core/render/visible_surfaces.hpp"

#include "core/render/interaction.hpp"
#include "core/render/surface_material.hpp"
#include "core/util/parallel.hpp"
#include "core/util/rng.hpp"

namespace gilab {

std::vector<PixelHit> trace_visible_surfaces(const TracedScene& scene, const EyeCamera& camera, int tile_size) {
    const int width = camera.width(), height = camera.height();
    const float spread = camera.pixel_spread_angle();
    std::vector<PixelHit> hits(size_t(width) * size_t(height));
    parallel_for_tiles(width, height, tile_size, [&](const Tile& tile) {
        for (int y = tile.y0; y < tile.y1; ++y)
            for (int x = tile.x0; x < tile.x1; ++x) {
                const Ray ray = camera.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
                const Hit hit = scene.tracer().intersect(ray);
                PixelHit& ph = hits[size_t(y) * size_t(width) + size_t(x)];
                if (!hit.valid()) continue;
                SurfaceInteraction si = make_interaction(scene.frame(), ray, hit);
                const Material& material = scene.materials()[si.material];
                const float width_at_hit = cone_width(spread, hit.t * glm::length(ray.direction));
                apply_normal_map(material, si, width_at_hit);
                ph.surface = at_surface(material, si, width_at_hit);
                ph.hit = true;
                ph.position = si.position;
                ph.normal = si.shading_normal;
                ph.geometric_normal = si.geometric_normal;
                ph.wo = si.wo;
                ph.material = si.material;
                ph.depth = hit.t * glm::length(ray.direction);
                ph.emissive_front = ph.surface.is_emissive() && !si.back_face;
            }
    });
    return hits;
}

void shade_direct_light(const TracedScene& scene, const DirectLighting& lighting, const std::vector<PixelHit>& hits,
                        uint64_t seed, size_t view, int tile_size, Film& film) {
    Layer& direct = film.layer("direct");
    Layer& albedo = film.layer("albedo");
    Layer& normal = film.layer("normal");
    Layer& depth = film.layer("depth");
    auto put = [](Layer& l, size_t i, const Vec3& v) {
        for (int k = 0; k < 3; ++k) l.data[3 * i + size_t(k)] = v[k];
    };
    const int width = film.width();
    parallel_for_tiles(width, film.height(), tile_size, [&](const Tile& tile) {
        for (int y = tile.y0; y < tile.y1; ++y)
            for (int x = tile.x0; x < tile.x1; ++x) {
                const size_t i = size_t(y) * size_t(width) + size_t(x);
                const PixelHit& ph = hits[i];
                if (!ph.hit) continue;
                const SurfaceMaterial& m = ph.surface;
                Rng rng = Rng::for_sample(seed, i, 0, view);
                Vec3 L = lighting.reflected(scene.tracer(), m, ph.position, ph.normal, ph.geometric_normal, ph.wo,
                                            4.0f * ray_epsilon(ph.position), rng);
                if (ph.emissive_front) L += m.emission;
                put(direct, i, L);
                put(albedo, i, m.albedo + m.specular);
                put(normal, i, ph.normal);
                depth.data[i] = ph.depth;
            }
    });
}

}  // namespace gilab
