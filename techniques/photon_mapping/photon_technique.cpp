#include "techniques/photon_mapping/photon_technique.hpp"

#include <algorithm>
#include <cmath>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "techniques/film_provenance.hpp"
#include "techniques/photon_mapping/photon_passes.hpp"
#include "techniques/photon_mapping/photon_tracer.hpp"


namespace gilab {

namespace {

// A photon map of the configured kind and hash query, built over `photons` for the
// gather radius.
std::unique_ptr<PhotonMap> build_photon_map(const PhotonMappingSettings& s, std::vector<Photon> photons) {
    auto map = make_photon_map(s.photon_map);
    if (auto* grid = map->as<HashGridPhotonMap>()) grid->set_query_mode(s.hash_query);
    map->build(std::move(photons), s.radius);
    return map;
}

}  // namespace

PhotonMappingTechnique::PhotonMappingTechnique() = default;
PhotonMappingTechnique::~PhotonMappingTechnique() = default;

void PhotonMappingTechnique::prepare(const Scene& scene, const Settings& settings) {
    Stopwatch watch;
    settings_ = PhotonMappingSettings::from(settings);
    config_hash_ = settings.hash();
    scene_.load(scene);
    stats_ = Stats();
    const Bounds3& bounds = scene_.frame().bounds;
    const float diagonal = bounds.empty() ? 0.0f : glm::length(bounds.max - bounds.min);
    if (settings_.radius_from_scene && diagonal > 0.0f && std::isfinite(diagonal))
        settings_.radius = PhotonMappingSettings::kRadiusPerDiagonal * diagonal;
    stats_.set("radius", double(settings_.radius));
    map_.reset();
    // Progressive mode traces fresh photons every iteration of a render instead.
    if (!settings_.progressive.enabled) trace_and_build();
    stats_.set("prepare_ms", watch.elapsed_ms());
    stats_.set("triangles", double(scene_.frame().triangle_count()));
    stats_.set("lights", double(scene_.lights().light_count()));
}

void PhotonMappingTechnique::trace_and_build() {
    PhotonTraceSettings ts;
    ts.emitted = settings_.photons;
    ts.max_depth = settings_.max_photon_depth;
    ts.first_stored_hit = settings_.storage == PhotonStorage::EveryHit ? 1 : 2;
    ts.seed = settings_.seed;
    PhotonTraceResult traced = trace_photons(scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(), ts);
    const size_t stored = traced.photons.size();
    const size_t first_hits = size_t(
        std::count_if(traced.photons.begin(), traced.photons.end(), [](const Photon& p) { return p.first_hit(); }));
    Stopwatch build;
    periphery_map_.reset();
    if (settings_.foveation.enabled) {
        // Every stride-th photon in trace order (a random subset) carrying stride × the flux.
        const size_t stride = size_t(settings_.foveation.periphery_photon_stride);
        std::vector<Photon> kept;
        kept.reserve(stored / stride + 1);
        for (size_t i = 0; i < stored; i += stride) {
            Photon p = traced.photons[i];
            p.power *= float(stride);
            kept.push_back(p);
        }
        periphery_map_ = build_photon_map(settings_, std::move(kept));
        stats_.set("periphery_photons_stored", double(periphery_map_->size()));
    }
    map_ = build_photon_map(settings_, std::move(traced.photons));
    stats_.set("photon_trace_ms", traced.trace_ms);
    stats_.set("photon_build_ms", build.elapsed_ms());
    stats_.set("photons_emitted", double(traced.emitted));
    stats_.set("photons_stored", double(stored));
    stats_.set("photons_stored_first_hit", double(first_hits));
    stats_.set("photon_rays", double(traced.rays));
    stats_.set("photon_map_bytes", double(map_->memory_bytes()));
    if (const auto* grid = map_->as<HashGridPhotonMap>()) stats_.set("hash_cells", double(grid->cell_count()));
}

void PhotonMappingTechnique::update(double time) {
    if (!scene_.loaded()) throw Error("photon", "update() called before prepare()");
    if (!scene_.animated()) return;
    Stopwatch watch;
    scene_.set_time(time, &stats_);
    if (!settings_.progressive.enabled) trace_and_build();  // photons follow the moved geometry and lights
    stats_.set("update_ms", watch.elapsed_ms());
}

void PhotonMappingTechnique::render(const ViewSet& views, std::vector<Film>& films) {
    if (!scene_.loaded() || (!map_ && !settings_.progressive.enabled))
        throw Error("photon", "render() called before prepare()");
    if (settings_.progressive.enabled) return render_progressive(views, films);
    Stopwatch watch;
    films.assign(views.views.size(), Film());
    PhotonQueryStats queries;
    Stats frame;
    const bool stereo = views.stereo();
    const bool reuse = stereo && settings_.stereo.enabled;
    if (reuse && !kept_) kept_ = std::make_unique<KeptHits>();
    double samples = 0;  // primary rays' samples, all views
    for (size_t v = 0; v < views.views.size(); ++v) {
        const EyeCamera& camera = views.views[v];
        check_resolution(camera.width(), camera.height(), 4);
        Film film(camera.width(), camera.height());
        samples += double(film.pixel_count()) * double(settings_.sampling.spp);
        film.add_layer("direct");
        film.add_layer("indirect");
        Stopwatch view_watch;
        if (reuse && v == 1) {
            render_right_reusing(views.views[0], camera, *kept_, film, queries, frame);
        } else {
            ViewOptions options;
            options.view = v;
            if (stereo && v == 1) options.stream_eye = &views.views[0];
            if (reuse && v == 0) options.keep = kept_.get();
            render_view(camera, options, film, queries, frame);
        }
        const double view_ms = view_watch.elapsed_ms();
        if (stereo) frame.set(v == 0 ? "left_ms" : "right_ms", view_ms);
        write_film_provenance(film, name(), views, v, settings_.seed, config_hash_);
        film.metadata["photons"] = std::to_string(settings_.photons);
        film.metadata["radius"] = format_number(settings_.radius);
        film.metadata["gather"] = settings_.gather == GatherMode::Knn ? "knn" : "radius";
        film.metadata["photon_map"] = to_string(settings_.photon_map);
        film.metadata["photon_storage"] = to_string(settings_.storage);
        film.metadata["tile_shared"] = to_string(settings_.tile_shared);
        film.metadata["spp"] = std::to_string(settings_.sampling.spp);
        film.metadata["jitter"] = settings_.sampling.jitter ? "true" : "false";
        if (stereo) film.metadata["stereo_reuse"] = reuse ? to_string(settings_.stereo.match) : "off";
        films[v] = std::move(film);
    }
    double ms = watch.elapsed_ms();
    write_render_time(films, ms);
    // Per-frame figures replace the previous frame's. A figure this frame's path did not
    // produce (no stereo reuse, no tile sharing, ...) is work not done: 0 this frame.
    for (const char* key : {"fused_ms", "trace_pass_ms", "sort_ms", "gather_pass_ms", "nonfinite_pixels", "tile_groups",
                            "tile_grouped_hits", "tile_fetched_photons", "share_tiles_qualified",
                            "share_tiles_mixed", "left_ms", "right_ms",
                            "claim_ms", "right_pass_ms", "reuse_left_hits", "reuse_back_side", "reuse_outside",
                            "reuse_occluded", "reuse_candidates", "reuse_claimed_pixels", "reuse_depth_conflicts",
                            "reuse_strict_rejected", "reused_pixels", "reuse_crack_filled", "reuse_fraction", "reuse_reshaded_glossy",
                            "right_shaded_pixels"})
        stats_.set(key, frame.get_or(key, 0));
    stats_.set("render_ms", ms);
    stats_.set("spp", double(settings_.sampling.spp));
    stats_.set("samples", samples);
    stats_.set("gather_queries", double(queries.queries));
    stats_.set("photons_visited", double(queries.visited));
    stats_.set("photons_inside", double(queries.inside));
    stats_.set("photons_visited_per_hit", queries.visited_per_query());
    stats_.set("inside_fraction", queries.inside_fraction());
}

void register_photon_mapping(TechniqueRegistry& registry) {
    registry.add({"photon",
                  "photon mapping (P1): hash-grid / kd-tree / nanoflann photon map, radius or kNN gather, "
                  "indirect or every-hit photon storage, fused or split passes, tile-shared gather, progressive (SPPM)",
                  [] { return std::make_unique<PhotonMappingTechnique>(); },
                  &PhotonMappingSettings::schema});
}

}  // namespace gilab
