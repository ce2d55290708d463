// The photon technique's progressive mode (progressive.hpp): the iteration loop over
// visible points, photon passes and per-pixel statistics.
//
// The hash grid is built over each iteration's photons (the technique's usual layout),
// not over the visible points as in Hachisuka & Jensen's paper: every pixel then sums
// its own photons in the grid's fixed run order, one task per pixel, so the image is the
// same at any thread count without atomic float additions, and the non-progressive
// gather keeps its structure. The grid's cell is the largest current radius, so every
// pixel's query stays within its 3×3×3 cells; the price is that the photons of one
// iteration are stored, which the paper's grid over visible points avoids.
#include <algorithm>
#include <atomic>
#include "core/render/surface_material.hpp"
#include "core/render/bsdf.hpp"
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/render/interaction.hpp"
#include "core/util/parallel.hpp"
#include "core/util/progress.hpp"
#include "core/util/stats.hpp"
#include "techniques/film_provenance.hpp"
#include "techniques/photon_mapping/photon_passes.hpp"
#include "techniques/photon_mapping/photon_tracer.hpp"


namespace gilab {

namespace {

// The photons one visible point finds within r: their number M and Σ f_r ΔΦ. Photons
// arriving from below the surface cannot light it and are not counted, so a wall's far
// side does not shrink the radius on its near side.
struct FoundPhotons {
    uint64_t count = 0;
    DVec3 flux{0.0};
};

FoundPhotons photons_within(const HashGridPhotonMap& grid, const SurfaceMaterial& m, const GatherPoint& p, float r) {
    FoundPhotons found;
    const PhotonSoA& v = grid.soa();
    const float r2 = r * r;
    const bool glossy = m.has_glossy_lobe();
    const Vec3 diffuse = bsdf_diffuse(m);
    grid.for_each_run(p.position, r, [&](PhotonRun run) {
        for (uint32_t j = run.begin; j < run.end; ++j) {
            if (!(photon_distance2(p.position, v.x[j], v.y[j], v.z[j]) <= r2)) continue;
            const Vec3 w(v.wx[j], v.wy[j], v.wz[j]);
            if (!(glm::dot(w, p.normal) > 0.0f)) continue;
            const Vec3 f = glossy ? bsdf_eval(m, p.normal, p.wo, w) : diffuse;
            ++found.count;
            found.flux += DVec3(f * Vec3(v.r[j], v.g[j], v.b[j]));
        }
    });
    return found;
}

// One view's state across iterations.
struct ProgressiveView {
    std::vector<SppmPixel> pixels;
    std::vector<DVec3> direct_sum;    // shadow-ray direct light, summed over iterations
    std::vector<GatherPoint> points;  // this iteration's visible points
    std::vector<uint8_t> visible;     // 1 where this iteration's ray hit a surface that reflects light
};

}  // namespace

void PhotonMappingTechnique::render_progressive(const ViewSet& views, std::vector<Film>& films) {
    const PhotonMappingSettings& s = settings_;
    const ProgressiveSettings& g = s.progressive;
    Stopwatch watch;
    std::vector<ProgressiveView> state(views.views.size());
    for (size_t v = 0; v < views.views.size(); ++v) {
        const EyeCamera& camera = views.views[v];
        check_resolution(camera.width(), camera.height(), 4);
        check_sample_memory(camera.width(), camera.height(), 1,
                            sizeof(SppmPixel) + sizeof(DVec3) + sizeof(GatherPoint) + 1,
                            "progressive per-pixel statistics", "photon");
        const size_t n = size_t(camera.width()) * size_t(camera.height());
        state[v].pixels.assign(n, SppmPixel{double(s.radius), 0.0, DVec3(0.0)});
        state[v].direct_sum.assign(n, DVec3(0.0));
        state[v].points.assign(n, GatherPoint{});
        state[v].visible.assign(n, 0);
    }
    const PrimaryShadingContext shading{scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(),
                                        s.light_samples};
    std::atomic<uint64_t> nonfinite{0};
    Progress progress("photon progressive", size_t(g.iterations));
    double camera_ms = 0, trace_ms = 0, build_ms = 0, gather_ms = 0;
    uint64_t emitted = 0, stored = 0;
    int done = 0;
    HashGridPhotonMap grid(s.hash_query);
    for (int iteration = 0; iteration < g.iterations; ++iteration) {
        // Visible points and their direct light; sample `iteration` of each pixel.
        Stopwatch phase;
        for (size_t v = 0; v < views.views.size(); ++v) {
            const EyeCamera& camera = views.views[v];
            const float spread = camera.pixel_spread_angle();
            ProgressiveView& view = state[v];
            parallel_for_tiles(camera.width(), camera.height(), s.tile_size, [&](const Tile& tile) {
                std::vector<LightSampleRecord> samples(shading.records_per_hit());
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x) {
                        const uint32_t pixel = uint32_t(size_t(y) * size_t(camera.width()) + size_t(x));
                        const Vec2 at = Vec2(float(x), float(y)) + sample_offset(s.sampling, s.seed, pixel, iteration, v);
                        Ray ray = camera.generate_ray(at.x, at.y);
                        Hit hit = scene_.tracer().intersect(ray);
                        view.visible[pixel] = 0;
                        if (!hit.valid()) continue;
                        SurfaceInteraction si = make_interaction(scene_.frame(), ray, hit);
                        PrimaryHit ph = primary_hit_of(si, scene_.materials()[si.material],
                                                       cone_width(spread, hit.t * glm::length(ray.direction)));
                        const SurfaceMaterial& m = ph.point.surface;
                        Rng rng = light_sample_stream(s.sampling, s.seed, nullptr, si.position, pixel, iteration, v);
                        sample_direct_light(shading, si, rng, samples, ph);
                        view.direct_sum[pixel] += DVec3(finite_or_zero(direct_radiance(m, ph, si.wo, samples), nonfinite));
                        view.points[pixel] = ph.point;
                        // A surface that reflects nothing gathers nothing: its radius,
                        // which would never shrink, stays out of the grid's cell size.
                        view.visible[pixel] = max_component(m.albedo) > 0.0f || m.has_glossy_lobe();
                    }
            });
        }
        camera_ms += phase.elapsed_ms();

        // A fresh photon pass: its own random streams (pass = iteration).
        PhotonTraceSettings ts;
        ts.emitted = s.photons;
        ts.max_depth = s.max_photon_depth;
        ts.first_stored_hit = 2;
        ts.seed = s.seed;
        ts.pass = uint64_t(iteration);
        PhotonTraceResult traced = trace_photons(scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(), ts);
        trace_ms += traced.trace_ms;
        emitted += traced.emitted;
        stored += traced.photons.size();

        phase.reset();
        float cell = 0.0f;
        for (const ProgressiveView& view : state)
            for (size_t i = 0; i < view.pixels.size(); ++i)
                if (view.visible[i]) cell = std::max(cell, float(view.pixels[i].radius));
        grid.build(std::move(traced.photons), cell > 0.0f ? cell : s.radius);
        build_ms += phase.elapsed_ms();

        phase.reset();
        for (size_t v = 0; v < views.views.size(); ++v) {
            ProgressiveView& view = state[v];
            parallel_for(view.pixels.size(), 256, [&](size_t b, size_t e) {
                for (size_t i = b; i < e; ++i) {
                    if (!view.visible[i]) continue;
                    SppmPixel& px = view.pixels[i];
                    const GatherPoint& p = view.points[i];
                    const FoundPhotons found = photons_within(grid, p.surface, p, float(px.radius));
                    px.add_iteration(found.count, found.flux, g.alpha);
                }
            });
        }
        gather_ms += phase.elapsed_ms();
        done = iteration + 1;
        progress.advance();
        if (g.time_budget && watch.elapsed_ms() >= *g.time_budget * 1000.0) break;
    }
    progress.finish();

    films.assign(views.views.size(), Film());
    double radius_sum = 0;
    uint64_t radius_pixels = 0;
    for (size_t v = 0; v < views.views.size(); ++v) {
        const EyeCamera& camera = views.views[v];
        Film film(camera.width(), camera.height());
        film.add_layer("direct");
        film.add_layer("indirect");
        float* color = film.layer("color").data.data();
        float* direct = film.layer("direct").data.data();
        float* indirect = film.layer("indirect").data.data();
        const ProgressiveView& view = state[v];
        for (size_t i = 0; i < view.pixels.size(); ++i) {
            // The arithmetic of sample_mean: the mean of `done` samples is the spp = done image's.
            const Vec3 d = finite_or_zero(Vec3(view.direct_sum[i] * (1.0 / double(done))), nonfinite);
            const Vec3 ind = finite_or_zero(Vec3(view.pixels[i].radiance(done)), nonfinite);
            write_pixel(direct, i, d);
            write_pixel(indirect, i, ind);
            write_pixel(color, i, d + ind);
            // Pixels whose radius never moved saw no photons (or no surface): they say
            // nothing about how far the radii shrank.
            if (view.pixels[i].count > 0) radius_sum += view.pixels[i].radius, ++radius_pixels;
        }
        write_film_provenance(film, name(), views, v, s.seed, config_hash_);
        film.metadata["progressive"] = "true";
        film.metadata["iterations"] = std::to_string(done);
        film.metadata["alpha"] = format_number(g.alpha);
        film.metadata["photons"] = std::to_string(s.photons);
        film.metadata["radius"] = format_number(s.radius);
        film.metadata["photon_storage"] = to_string(s.storage);
        films[v] = std::move(film);
    }
    const double ms = watch.elapsed_ms();
    write_render_time(films, ms);
    stats_.set("render_ms", ms);
    stats_.set("iterations_run", double(done));
    stats_.set("iterations_requested", double(g.iterations));
    stats_.set("photons_emitted", double(emitted));
    stats_.set("photons_stored", double(stored));
    stats_.set("mean_final_radius", radius_pixels ? radius_sum / double(radius_pixels) : double(s.radius));
    stats_.set("visible_point_ms", camera_ms);
    stats_.set("photon_trace_ms", trace_ms);
    stats_.set("photon_build_ms", build_ms);
    stats_.set("gather_pass_ms", gather_ms);
    stats_.set("nonfinite_pixels", double(nonfinite.load()));
}

}  // namespace gilab
