#include "techniques/lpv/lpv_technique.hpp"

#include <algorithm>
#include <cmath>
#include "core/render/interaction.hpp"
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"
#include "core/util/parallel.hpp"
#include "core/util/rng.hpp"
#include "techniques/film_provenance.hpp"

namespace gilab {

namespace {

// The finest cell when none is given: the coarsest cascade, centred on the scene's
// viewer, reaches the farthest corner of the scene's bounds along every axis, with two
// cells to spare for the snapping.
float derived_cell_size(const Bounds3& bounds, const Vec3& viewer, int cascades, int resolution) {
    float half = 0;
    if (!bounds.empty())
        for (int a = 0; a < 3; ++a) half = std::max(half, std::max(std::abs(bounds.max[a] - viewer[a]), std::abs(bounds.min[a] - viewer[a])));
    if (!(half > 0) || !std::isfinite(half)) half = 1.0f;
    return 2.0f * half / (float(resolution - 4) * float(1 << (cascades - 1)));
}

Vec3 scene_viewer(const Scene& scene, const Bounds3& bounds) {
    if (scene.camera) return scene.camera->position;
    if (scene.hmd) return scene.hmd->pose.position;
    return bounds.empty() ? Vec3(0) : bounds.center();
}

Bounds3 intersect(const Bounds3& a, const Bounds3& b) {
    Bounds3 r;
    r.min = glm::max(a.min, b.min);
    r.max = glm::min(a.max, b.max);
    return r;
}

}  // namespace

void LpvTechnique::prepare(const Scene& scene, const Settings& settings) {
    Stopwatch watch;
    settings_ = LpvSettings::from(settings);
    config_hash_ = settings.hash();
    scene_.load(scene);
    lighting_ = DirectLighting(scene_.frame(), scene_.materials(), settings_.light_samples);
    stats_ = Stats();
    LpvCascadeConfig config;
    config.cascades = settings_.cascades;
    config.resolution = settings_.resolution;
    config.finest_cell_size = settings_.cell_size > 0
                                  ? float(settings_.cell_size)
                                  : derived_cell_size(scene_.frame().bounds, scene_viewer(scene, scene_.frame().bounds),
                                                      settings_.cascades, settings_.resolution);
    // Four SH buffers per cascade and the geometry volume with its faces, the scratch.
    const uint64_t cells = uint64_t(settings_.resolution) * uint64_t(settings_.resolution) * uint64_t(settings_.resolution);
    std::string what = "setting 'resolution' (";
    what += std::to_string(settings_.resolution);
    what += " cells per axis)";
    MemoryBudget::check(uint64_t(settings_.cascades) * cells * (4 * sizeof(ShRgb) + 8 * sizeof(Sh4)), what, "lpv");
    cascades_.emplace(config);
    scratch_.clear();
    for (int k = 0; k < cascades_->count(); ++k) scratch_.emplace_back(cascades_->level(k).lattice());
    maps_.clear();
    vpls_.clear();
    stats_.set("prepare_ms", watch.elapsed_ms());
    stats_.set("finest_cell_size", config.finest_cell_size);
    stats_.set("cells", double(cells) * double(settings_.cascades));
    stats_.set("structure_bytes", double(structure_bytes()));
}

void LpvTechnique::update(double time) {
    if (!scene_.loaded()) throw Error("lpv", "update() called before prepare()");
    if (!scene_.animated()) return;
    Stopwatch watch;
    scene_.set_time(time);
    lighting_ = DirectLighting(scene_.frame(), scene_.materials(), settings_.light_samples);
    stats_.set("scene_update_ms", watch.elapsed_ms());
}

std::vector<Surfel> LpvTechnique::camera_surfels(const EyeCamera& camera, const std::vector<PixelHit>& hits) {
    const size_t width = size_t(camera.width());
    std::vector<float> area(hits.size(), 0.0f);
    parallel_for(hits.size(), 1024, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            const PixelHit& ph = hits[i];
            if (!ph.hit) continue;
            // The pixel's footprint on the surface: its solid angle · depth² / cos.
            const float x = float(i % width), y = float(i / width);
            const Vec3 d0 = glm::normalize(camera.generate_ray(x + 0.5f, y + 0.5f).direction);
            const Vec3 dx = glm::normalize(camera.generate_ray(x + 1.5f, y + 0.5f).direction) - d0;
            const Vec3 dy = glm::normalize(camera.generate_ray(x + 0.5f, y + 1.5f).direction) - d0;
            const float cos_hit = std::max(0.05f, glm::dot(ph.geometric_normal, ph.wo));
            area[i] = glm::length(glm::cross(dx, dy)) * ph.depth * ph.depth / cos_hit;
        }
    });
    std::vector<Surfel> surfels;
    for (size_t i = 0; i < hits.size(); ++i)
        if (hits[i].hit) surfels.push_back(Surfel{hits[i].position, hits[i].geometric_normal, area[i]});
    return surfels;
}

void LpvTechnique::update_volumes(const Vec3& viewer, const std::vector<std::vector<Surfel>>& camera_surfels) {
    LpvCascades& cascades = *cascades_;
    Stopwatch watch;
    cascades.place(viewer);
    for (int k = 0; k < cascades.count(); ++k) scratch_[size_t(k)].place(cascades.level(k).lattice());
    const LpvLattice& coarsest = cascades.level(cascades.count() - 1).lattice();
    Bounds3 cover;
    cover.min = coarsest.origin();
    cover.max = coarsest.origin() + Vec3(coarsest.extent());
    RsmOptions options;
    options.size = settings_.rsm_size;
    options.region = intersect(scene_.frame().bounds, cover);
    options.seed = settings_.seed;
    maps_ = render_reflective_shadow_maps(scene_, options);
    vpls_.clear();
    size_t texels = 0, surfels = 0;
    for (const ReflectiveShadowMap& m : maps_) {
        vpls_.insert(vpls_.end(), m.vpls.begin(), m.vpls.end());
        texels += m.texels;
        surfels += m.surfels.size();
    }
    for (const auto& s : camera_surfels) surfels += s.size();
    const double rsm_ms = watch.elapsed_ms();

    watch.reset();
    std::vector<size_t> injected(size_t(cascades.count()), 0);
    parallel_for(size_t(cascades.count()), 1, [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k) {
            LightPropagationVolume& v = cascades.level(int(k));
            GeometryVolume& g = v.geometry();
            g.clear();
            if (settings_.occlusion) {
                for (const ReflectiveShadowMap& m : maps_) g.add_buffer(m.surfels, scratch_[k]);
                for (const auto& s : camera_surfels) g.add_buffer(s, scratch_[k]);
                g.update_faces();
            }
            injected[k] = v.inject(vpls_);
        }
    });
    const double inject_ms = watch.elapsed_ms();

    watch.reset();
    DVec3 left(0);
    for (int k = 0; k < cascades.count(); ++k) left += cascades.level(k).propagate(settings_.iterations, settings_.occlusion).flux_left;
    const double propagate_ms = watch.elapsed_ms();

    size_t in_cascades = 0;
    for (size_t n : injected) in_cascades += n;
    stats_.set("rsm_ms", rsm_ms);
    stats_.set("inject_ms", inject_ms);
    stats_.set("propagate_ms", propagate_ms);
    stats_.set("rsm_texels", double(texels));
    stats_.set("vpls", double(vpls_.size()));
    stats_.set("vpls_injected", double(in_cascades));  // summed over cascades
    stats_.set("surfels", double(surfels));
    stats_.set("flux_left_volumes", left.x + left.y + left.z);
}

void LpvTechnique::render(const ViewSet& views, std::vector<Film>& films) {
    if (!scene_.loaded()) throw Error("lpv", "render() called before prepare()");
    if (views.views.empty()) throw Error("lpv", "render() needs at least one view");
    Stopwatch total_watch;
    Vec3 viewer(0);
    for (const EyeCamera& c : views.views) viewer += c.position();
    viewer /= float(views.views.size());

    Stopwatch watch;
    std::vector<std::vector<PixelHit>> hits(views.views.size());
    std::vector<std::vector<Surfel>> surfels(views.views.size());
    for (size_t vi = 0; vi < views.views.size(); ++vi) {
        check_resolution(views.views[vi].width(), views.views[vi].height(), 6);
        hits[vi] = trace_visible_surfaces(scene_, views.views[vi], settings_.tile_size);
        if (settings_.occlusion) surfels[vi] = camera_surfels(views.views[vi], hits[vi]);  // only occlusion reads them
    }
    const double primary_ms = watch.elapsed_ms();

    update_volumes(viewer, surfels);

    double direct_ms = 0, lookup_ms = 0;
    films.resize(views.views.size());
    for (size_t vi = 0; vi < views.views.size(); ++vi) {
        const EyeCamera& camera = views.views[vi];
        const int width = camera.width(), height = camera.height();
        Film film(width, height);
        for (const char* name : {"direct", "indirect", "albedo", "normal"}) film.add_layer(name);
        film.add_layer("depth", 1);
        const std::vector<PixelHit>& view_hits = hits[vi];
        Layer& direct = film.layer("direct");
        Layer& indirect = film.layer("indirect");
        auto put = [](Layer& l, size_t i, const Vec3& v) {
            for (int k = 0; k < 3; ++k) l.data[3 * i + size_t(k)] = v[k];
        };

        watch.reset();
        shade_direct_light(scene_, lighting_, view_hits, settings_.seed, vi, settings_.tile_size, film);
        direct_ms += watch.elapsed_ms();

        watch.reset();
        parallel_for_tiles(width, height, settings_.tile_size, [&](const Tile& tile) {
            for (int y = tile.y0; y < tile.y1; ++y)
                for (int x = tile.x0; x < tile.x1; ++x) {
                    const size_t i = size_t(y) * size_t(width) + size_t(x);
                    const PixelHit& ph = view_hits[i];
                    if (!ph.hit) continue;
                    const SurfaceMaterial& m = ph.surface;
                    const Vec3 E = cascades_->irradiance(ph.position, ph.normal, settings_.dampening, settings_.gradient_dampening);
                    put(indirect, i, m.albedo * kInvPi * E);
                }
        });
        lookup_ms += watch.elapsed_ms();

        Layer& color = film.layer("color");
        for (size_t j = 0; j < color.data.size(); ++j) color.data[j] = direct.data[j] + indirect.data[j];
        write_film_provenance(film, name(), views, vi, settings_.seed, config_hash_);
        films[vi] = std::move(film);
    }
    const double lpv_ms = stats_.get("rsm_ms") + stats_.get("inject_ms") + stats_.get("propagate_ms");
    stats_.set("primary_ms", primary_ms);
    stats_.set("direct_ms", direct_ms);
    stats_.set("lookup_ms", lookup_ms);
    stats_.set("lpv_ms", lpv_ms);
    stats_.set("total_ms", primary_ms + lpv_ms + direct_ms + lookup_ms);
    stats_.set("structure_bytes", double(structure_bytes()));
    const double ms = total_watch.elapsed_ms();
    stats_.set("render_ms", ms);
    write_render_time(films, ms);
}

size_t LpvTechnique::structure_bytes() const {
    size_t b = cascades_ ? cascades_->bytes() : 0;
    for (const GeometryVolume& g : scratch_) b += g.bytes();
    for (const ReflectiveShadowMap& m : maps_)
        b += m.vpls.capacity() * sizeof(VirtualPointLight) + m.surfels.capacity() * sizeof(Surfel);
    b += vpls_.capacity() * sizeof(VirtualPointLight);
    return b;
}

void register_lpv(TechniqueRegistry& registry) {
    registry.add({"lpv",
                  "cascaded light propagation volumes (Kaplanyan & Dachsbacher 2010): RSM VPLs injected as SH into "
                  "nested 32³ grids, propagated with fuzzy occlusion; direct light ray traced",
                  [] { return std::make_unique<LpvTechnique>(); }, &LpvSettings::schema});
}

}  // namespace gilab
