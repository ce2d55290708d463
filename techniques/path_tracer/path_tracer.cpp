#include "techniques/path_tracer/path_tracer.hpp"

#include <atomic>
#include <cmath>
#include "core/render/bsdf.hpp"
#include "core/util/error.hpp"
#include "core/render/interaction.hpp"
#include "core/render/surface_material.hpp"
#include "core/util/parallel.hpp"
#include "core/util/progress.hpp"
#include "core/util/rng.hpp"
#include "techniques/film_provenance.hpp"


namespace gilab {

namespace {

// What one camera sample contributes to every layer.
struct PathSample {
    Vec3 direct{0}, indirect{0};
    Vec3 albedo{0}, normal{0};
    float depth = 0;
    bool hit = false;
};

// Adds a contribution that reached the eye after `bounces` scattering events.
void add_light(PathSample& s, int bounces, const Vec3& value) {
    (bounces <= 1 ? s.direct : s.indirect) += value;
}

}  // namespace

const SettingsSchema& PathTracerSettings::schema() {
    static const SettingsSchema schema = [] {
        const PathTracerSettings d;
        SettingsSchema s("path", "reference path tracer (next-event estimation + MIS, Russian roulette)");
        s.integer("spp", d.spp).at_least(1).unit("samples per pixel")
            .doc("Camera samples per pixel; every layer is their mean.")
            .quality_knob(1, 1 << 20);
        s.integer("seed", int64_t(d.seed)).at_least(0).doc("Seed of every random stream (same seed, same image).");
        s.integer("max_depth", d.max_depth).at_least(0).unit("bounces")
            .doc("Longest path: scattering events before a path ends.");
        s.integer("rr_depth", d.rr_depth).at_least(0).unit("bounces")
            .doc("Russian roulette starts once a path has this many bounces.");
        s.integer("tile_size", d.tile_size).at_least(1).unit("pixels").doc("Square screen tile of one parallel task.");
        s.boolean("jitter", d.jitter).doc("true: sample positions uniform in the pixel; false: pixel centres.");
        return s;
    }();
    return schema;
}

PathTracerSettings PathTracerSettings::from(const Settings& s) {
    const SettingsSchema& schema = PathTracerSettings::schema();
    PathTracerSettings p;
    p.spp = schema.get<int>(s, "spp");
    p.seed = uint64_t(schema.get<int64_t>(s, "seed"));
    p.max_depth = schema.get<int>(s, "max_depth");
    p.rr_depth = schema.get<int>(s, "rr_depth");
    p.tile_size = schema.get<int>(s, "tile_size");
    p.jitter = schema.get<bool>(s, "jitter");
    return p;
}

void PathTracer::prepare(const Scene& scene, const Settings& settings) {
    Stopwatch watch;
    settings_ = PathTracerSettings::from(settings);
    config_hash_ = settings.hash();
    scene_.load(scene);
    stats_ = Stats();
    stats_.set("prepare_ms", watch.elapsed_ms());
    stats_.set("triangles", double(scene_.frame().triangle_count()));
    stats_.set("lights", double(scene_.lights().light_count()));
}

void PathTracer::update(double time) {
    if (!scene_.loaded()) throw Error("path", "update() called before prepare()");
    scene_.set_time(time, &stats_);
}

namespace {

struct Tracer {
    const RayTracer& tracer;
    const SceneFrame& frame;
    const std::vector<Material>& materials;
    const LightSampler& lights;
    const PathTracerSettings& settings;

    // `spread`: the camera ray's cone angle. The cone keeps widening at that rate along
    // the whole path (its width is what the textures are filtered over); bounces do not
    // widen it further, so secondary hits read sharper levels than a full ray-cone
    // curvature term would pick (that only costs texture-cache locality, not bias).
    PathSample trace(Ray ray, float spread, Rng& rng, uint64_t& rays) const {
        PathSample out;
        float width = 0.0f;  // cone width at the ray's origin
        Vec3 beta(1.0f);
        float prev_pdf = 0.0f;
        Vec3 prev_position(0.0f);
        for (int depth = 0;; ++depth) {
            Hit hit = tracer.intersect(ray);
            ++rays;
            if (!hit.valid()) break;  // no environment light: escaped paths carry nothing
            SurfaceInteraction si = make_interaction(frame, ray, hit);
            width += cone_width(spread, hit.t * glm::length(ray.direction));
            apply_normal_map(materials[si.material], si, width);
            const SurfaceMaterial m = at_surface(materials[si.material], si, width);
            if (depth == 0) {
                out.hit = true;
                out.albedo = m.albedo + m.specular;
                out.normal = si.shading_normal;
                out.depth = hit.t * glm::length(ray.direction);
            }

            // Emission reached by BSDF sampling (or seen directly), weighted against NEE.
            if (m.is_emissive() && !si.back_face) {
                float w = 1.0f;
                if (depth > 0) {
                    float light_pdf = lights.pdf_incident(prev_position, si.mesh, si.triangle, si.position);
                    w = power_heuristic(prev_pdf, light_pdf);
                }
                add_light(out, depth, beta * m.emission * w);
            }
            if (depth >= settings.max_depth) break;

            const Vec3& n = si.shading_normal;
            // Next-event estimation.
            if (!lights.empty()) {
                LightSample ls = lights.sample_incident(si.position, rng);
                if (ls.pdf > 0.0f && !is_black(ls.Li) && glm::dot(ls.wi, si.geometric_normal) > 0.0f) {
                    Vec3 f = bsdf_eval(m, n, si.wo, ls.wi);
                    if (!is_black(f)) {
                        ++rays;
                        if (!tracer.occluded(shadow_ray(si, ls))) {
                            float w = ls.delta ? 1.0f : power_heuristic(ls.pdf, bsdf_pdf(m, n, si.wo, ls.wi));
                            float cos_i = glm::dot(n, ls.wi);
                            add_light(out, depth + 1, beta * f * ls.Li * (cos_i * w / ls.pdf));
                        }
                    }
                }
            }

            // Continue the path by sampling the BSDF.
            BsdfSample bs = bsdf_sample(m, n, si.wo, rng);
            if (!bs.valid || glm::dot(bs.wi, si.geometric_normal) <= 0.0f) break;
            beta *= bs.weight;
            prev_pdf = bs.pdf;
            prev_position = si.position;
            if (depth + 1 >= settings.rr_depth) {
                float q = std::min(max_component(beta), 0.95f);
                if (!(q > 0.0f) || rng.uniform() >= q) break;
                beta /= q;
            }
            ray = Ray{si.spawn_origin(bs.wi), bs.wi};
        }
        return out;
    }
};

}  // namespace

void PathTracer::render(const ViewSet& views, std::vector<Film>& films) {
    if (!scene_.loaded()) throw Error("path", "render() called before prepare()");
    Stopwatch watch;
    const Tracer tracer{scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(), settings_};
    std::atomic<uint64_t> rays{0}, dropped{0};
    films.resize(views.views.size());
    double samples = 0;

    for (size_t v = 0; v < views.views.size(); ++v) {
        const EyeCamera& camera = views.views[v];
        const int width = camera.width(), height = camera.height();
        check_resolution(width, height, 6);
        Film film(width, height);
        film.add_layer("direct");
        film.add_layer("indirect");
        film.add_layer("albedo");
        film.add_layer("normal");
        film.add_layer("depth", 1);
        float* color = film.layer("color").data.data();
        float* direct = film.layer("direct").data.data();
        float* indirect = film.layer("indirect").data.data();
        float* albedo = film.layer("albedo").data.data();
        float* normal = film.layer("normal").data.data();
        float* depth = film.layer("depth").data.data();

        const int ts = settings_.tile_size;
        size_t tiles = size_t((width + ts - 1) / ts) * size_t((height + ts - 1) / ts);
        std::string label = "path";
        if (views.views.size() > 1 && v < views.names.size()) label += " " + views.names[v];
        Progress progress(label, tiles);
        const int spp = settings_.spp;
        const double inv_spp = 1.0 / double(spp);
        const float spread = camera.pixel_spread_angle();

        parallel_for_tiles(width, height, ts, [&](const Tile& tile) {
            uint64_t tile_rays = 0, tile_dropped = 0;
            for (int y = tile.y0; y < tile.y1; ++y) {
                for (int x = tile.x0; x < tile.x1; ++x) {
                    const size_t pixel = size_t(y) * size_t(width) + size_t(x);
                    // Samples are summed in order by this one task: thread count never
                    // changes the floating-point result.
                    DVec3 sum_direct(0), sum_indirect(0), sum_albedo(0), sum_normal(0);
                    double sum_depth = 0;
                    int hits = 0;
                    for (int s = 0; s < spp; ++s) {
                        Rng rng = Rng::for_sample(settings_.seed, pixel, uint64_t(s), uint64_t(v));
                        Vec2 jitter = settings_.jitter ? rng.uniform2() : Vec2(0.5f);
                        Ray ray = camera.generate_ray(float(x) + jitter.x, float(y) + jitter.y);
                        PathSample ps = tracer.trace(ray, spread, rng, tile_rays);
                        if (!is_finite(ps.direct) || !is_finite(ps.indirect)) {
                            ++tile_dropped;  // counted and reported, never averaged in
                            continue;
                        }
                        sum_direct += DVec3(ps.direct);
                        sum_indirect += DVec3(ps.indirect);
                        if (ps.hit) {
                            sum_albedo += DVec3(ps.albedo);
                            sum_normal += DVec3(ps.normal);
                            sum_depth += ps.depth;
                            ++hits;
                        }
                    }
                    Vec3 d = Vec3(sum_direct * inv_spp), i = Vec3(sum_indirect * inv_spp);
                    Vec3 c = d + i;
                    Vec3 a = Vec3(sum_albedo * inv_spp);
                    Vec3 nrm = glm::length(sum_normal) > 0 ? Vec3(glm::normalize(sum_normal)) : Vec3(0);
                    for (int k = 0; k < 3; ++k) {
                        color[3 * pixel + k] = c[k];
                        direct[3 * pixel + k] = d[k];
                        indirect[3 * pixel + k] = i[k];
                        albedo[3 * pixel + k] = a[k];
                        normal[3 * pixel + k] = nrm[k];
                    }
                    depth[pixel] = hits > 0 ? float(sum_depth / hits) : 0.0f;
                }
            }
            rays += tile_rays;
            dropped += tile_dropped;
            progress.advance();
        });
        progress.finish();
        samples += double(width) * double(height) * double(spp);
        write_film_provenance(film, name(), views, v, settings_.seed, config_hash_);
        film.metadata["spp"] = std::to_string(spp);
        film.metadata["max_depth"] = std::to_string(settings_.max_depth);
        film.metadata["rr_depth"] = std::to_string(settings_.rr_depth);
        films[v] = std::move(film);
    }
    double ms = watch.elapsed_ms();
    write_render_time(films, ms);
    stats_.set("render_ms", ms);
    stats_.set("rays", double(rays.load()));
    stats_.set("samples", samples);
    stats_.set("nonfinite_samples", double(dropped.load()));
}

void register_path_tracer(TechniqueRegistry& registry) {
    registry.add({"path",
                  "reference unidirectional path tracer (next-event estimation + MIS, Russian roulette)",
                  [] { return std::make_unique<PathTracer>(); }, &PathTracerSettings::schema});
}

}  // namespace gilab
