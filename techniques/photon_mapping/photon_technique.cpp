#include "techniques/photon_mapping/photon_technique.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <numeric>
#include <sstream>
#include <tbb/parallel_sort.h>
#include "core/bsdf.hpp"
#include "core/error.hpp"
#include "core/interaction.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "techniques/photon_mapping/photon_tracer.hpp"

#ifndef GILAB_GIT_REVISION
#define GILAB_GIT_REVISION "unknown"
#endif

namespace gilab {

namespace {

std::string number(double v) {
    std::ostringstream out;
    out.precision(9);
    out << v;
    return out.str();
}

// A primary hit waiting for its gather.
struct HitRecord {
    GatherPoint point;
    uint32_t pixel = 0;
    bool valid = false;
};

struct SortItem {
    uint64_t key;   // PhotonGatherer::sort_key
    uint32_t slot;  // index into the hit buffer
    bool operator<(const SortItem& o) const { return key != o.key ? key < o.key : slot < o.slot; }
    bool same_group(const SortItem& o) const { return key == o.key && key < PhotonGatherer::kUngrouped; }
};

}  // namespace

PhotonMappingSettings PhotonMappingSettings::from(const Settings& s) {
    PhotonMappingSettings p;
    const std::string& where = s.context();
    int64_t photons = s.get<int64_t>("photons", int64_t(p.photons));
    p.radius = s.get<float>("radius", p.radius);
    std::string gather = s.get<std::string>("gather", "radius");
    p.k = s.get<int>("k", p.k);
    std::string map = s.get<std::string>("photon_map", to_string(p.photon_map));
    std::string hash_query = s.get<std::string>("hash_query", to_string(p.hash_query));
    std::string pass = s.get<std::string>("pass", "fused");
    p.tile_shared = s.get<bool>("tile_shared", p.tile_shared);
    int64_t seed = s.get<int64_t>("seed", int64_t(p.seed));
    p.light_samples = s.get<int>("light_samples", p.light_samples);
    p.max_photon_depth = s.get<int>("max_photon_depth", p.max_photon_depth);
    p.tile_size = s.get<int>("tile_size", p.tile_size);

    if (photons < 1) throw Error(where, "setting 'photons' must be at least 1, got " + std::to_string(photons));
    p.photons = uint64_t(photons);
    if (!(p.radius > 0.0f) || !std::isfinite(p.radius))
        throw Error(where, "setting 'radius' must be positive and finite, got " + number(p.radius));
    if (gather == "radius")
        p.gather = GatherMode::Radius;
    else if (gather == "knn")
        p.gather = GatherMode::Knn;
    else
        throw Error(where, "setting 'gather' must be 'radius' or 'knn', got '" + gather + "'");
    if (p.k < 1) throw Error(where, "setting 'k' must be at least 1, got " + std::to_string(p.k));
    p.photon_map = parse_photon_map_kind(map, where + ": setting 'photon_map'");
    p.hash_query = parse_hash_query(hash_query, where + ": setting 'hash_query'");
    if (pass == "fused")
        p.split = false;
    else if (pass == "split")
        p.split = true;
    else
        throw Error(where, "setting 'pass' must be 'fused' or 'split', got '" + pass + "'");
    if (p.tile_shared && p.photon_map != PhotonMapKind::HashGrid)
        throw Error(where, "setting 'tile_shared' needs photon_map=hash_grid (it shares hash-grid cells), got " + map);
    if (seed < 0) throw Error(where, "setting 'seed' must not be negative, got " + std::to_string(seed));
    p.seed = uint64_t(seed);
    if (p.light_samples < 0)
        throw Error(where, "setting 'light_samples' must not be negative, got " + std::to_string(p.light_samples));
    if (p.max_photon_depth < 1)
        throw Error(where, "setting 'max_photon_depth' must be at least 1, got " + std::to_string(p.max_photon_depth));
    if (p.tile_size < 1) throw Error(where, "setting 'tile_size' must be at least 1, got " + std::to_string(p.tile_size));
    return p;
}

void PhotonMappingTechnique::prepare(const Scene& scene, const Settings& settings) {
    Stopwatch watch;
    settings_ = PhotonMappingSettings::from(settings);
    config_hash_ = settings.hash();
    scene_.load(scene);
    stats_ = Stats();
    trace_and_build();
    stats_.set("prepare_ms", watch.elapsed_ms());
    stats_.set("triangles", double(scene_.frame().triangle_count()));
    stats_.set("lights", double(scene_.lights().light_count()));
}

void PhotonMappingTechnique::trace_and_build() {
    PhotonTraceSettings ts;
    ts.emitted = settings_.photons;
    ts.max_depth = settings_.max_photon_depth;
    ts.first_stored_hit = 2;
    ts.seed = settings_.seed;
    PhotonTraceResult traced = trace_photons(scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(), ts);
    const size_t stored = traced.photons.size();
    Stopwatch build;
    auto map = make_photon_map(settings_.photon_map);
    if (auto* grid = dynamic_cast<HashGridPhotonMap*>(map.get())) grid->set_query_mode(settings_.hash_query);
    map->build(std::move(traced.photons), settings_.radius);
    map_ = std::move(map);
    stats_.set("photon_trace_ms", traced.trace_ms);
    stats_.set("photon_build_ms", build.elapsed_ms());
    stats_.set("photons_emitted", double(traced.emitted));
    stats_.set("photons_stored", double(stored));
    stats_.set("photon_rays", double(traced.rays));
    stats_.set("photon_map_bytes", double(map_->memory_bytes()));
    if (auto* grid = dynamic_cast<const HashGridPhotonMap*>(map_.get())) stats_.set("hash_cells", double(grid->cell_count()));
}

void PhotonMappingTechnique::update(double time) {
    if (!scene_.loaded()) throw Error("photon", "update() called before prepare()");
    if (!scene_.animated()) return;
    Stopwatch watch;
    scene_.set_time(time, &stats_);
    trace_and_build();  // photons follow the moved geometry and lights
    stats_.set("update_ms", watch.elapsed_ms());
}

void PhotonMappingTechnique::render_view(const EyeCamera& camera, uint64_t view, Film& film,
                                         PhotonQueryStats& query_stats, Stats& frame_stats) const {
    const int width = camera.width(), height = camera.height();
    const PhotonMappingSettings& s = settings_;
    const PhotonGatherer gatherer(*map_, scene_.materials(), s.gather, s.radius, size_t(s.k));
    float* direct = film.layer("direct").data.data();
    float* indirect = film.layer("indirect").data.data();
    std::mutex merge;
    std::atomic<uint64_t> nonfinite{0}, groups{0}, grouped_hits{0}, fetched{0};

    // Primary ray, emission and next-event estimation; the hit is returned for the gather.
    auto trace_pixel = [&](int x, int y) {
        HitRecord rec;
        rec.pixel = uint32_t(size_t(y) * size_t(width) + size_t(x));
        Vec3 L(0.0f);
        Ray ray = camera.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
        Hit hit = scene_.tracer().intersect(ray);
        if (hit.valid()) {
            SurfaceInteraction si = make_interaction(scene_.frame(), ray, hit);
            const Material& m = scene_.materials()[si.material];
            if (m.is_emissive() && !si.back_face) L += m.emission;
            if (s.light_samples > 0 && !scene_.lights().empty()) {
                Rng rng = Rng::for_sample(s.seed, rec.pixel, 0, view);
                Vec3 sum(0.0f);
                for (int k = 0; k < s.light_samples; ++k) {
                    LightSample ls = scene_.lights().sample_incident(si.position, rng);
                    if (!(ls.pdf > 0.0f) || is_black(ls.Li) || glm::dot(ls.wi, si.geometric_normal) <= 0.0f) continue;
                    Vec3 f = bsdf_eval(m, si.shading_normal, si.wo, ls.wi);
                    if (is_black(f) || scene_.tracer().occluded(shadow_ray(si, ls))) continue;
                    sum += f * ls.Li * (glm::dot(si.shading_normal, ls.wi) / ls.pdf);
                }
                L += sum / float(s.light_samples);
            }
            rec.point = {si.position, si.shading_normal, si.wo, si.material};
            rec.valid = true;
        }
        if (!is_finite(L)) {
            ++nonfinite;
            L = Vec3(0.0f);
        }
        for (int c = 0; c < 3; ++c) direct[3 * size_t(rec.pixel) + size_t(c)] = L[c];
        return rec;
    };
    auto write_indirect = [&](uint32_t pixel, Vec3 v) {
        if (!is_finite(v)) {
            ++nonfinite;
            v = Vec3(0.0f);
        }
        for (int c = 0; c < 3; ++c) indirect[3 * size_t(pixel) + size_t(c)] = v[c];
    };
    // Gathers hits[items[b..e).slot]: runs of hits sharing a cell together (Algorithm 1)
    // when `shared`, else one by one.
    auto gather_sorted = [&](const std::vector<HitRecord>& hits, const std::vector<SortItem>& items, size_t b, size_t e,
                             GatherScratch& scratch, PhotonQueryStats& qs, bool shared) {
        std::vector<const GatherPoint*> points;
        std::vector<Vec3> out;
        uint64_t local_groups = 0, local_grouped = 0;
        for (size_t i = b; i < e;) {
            size_t j = i + 1;
            if (shared)
                while (j < e && items[j].same_group(items[i])) ++j;
            if (j - i >= 2) {
                points.clear();
                for (size_t t = i; t < j; ++t) points.push_back(&hits[items[t].slot].point);
                out.resize(points.size());
                gatherer.estimate_group(gatherer.cell_of(points[0]->position), points, out, scratch, qs);
                for (size_t t = i; t < j; ++t) write_indirect(hits[items[t].slot].pixel, out[t - i]);
                ++local_groups;
                local_grouped += j - i;
            } else {
                const HitRecord& h = hits[items[i].slot];
                write_indirect(h.pixel, gatherer.estimate(h.point, scratch, qs));
            }
            i = j;
        }
        groups += local_groups;
        grouped_hits += local_grouped;
    };
    // Hits in cell order (then by slot: a total order, so the parallel sort is
    // deterministic).
    auto sort_items = [&](const std::vector<HitRecord>& hits, const std::vector<uint32_t>& slots) {
        std::vector<SortItem> items(slots.size());
        auto fill = [&](size_t b, size_t e) {
            for (size_t i = b; i < e; ++i) {
                items[i] = {gatherer.sort_key(hits[slots[i]].point.position, slots[i]), slots[i]};
            }
        };
        if (items.size() < 4096) {
            fill(0, items.size());
            std::sort(items.begin(), items.end());
        } else {
            parallel_for(items.size(), 2048, fill);
            tbb::parallel_sort(items.begin(), items.end());
        }
        return items;
    };

    if (!s.split) {
        Stopwatch watch;
        parallel_for_tiles(width, height, s.tile_size, [&](const Tile& tile) {
            GatherScratch scratch;
            PhotonQueryStats qs;
            if (!s.tile_shared) {
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x) {
                        HitRecord rec = trace_pixel(x, y);
                        write_indirect(rec.pixel, rec.valid ? gatherer.estimate(rec.point, scratch, qs) : Vec3(0.0f));
                    }
            } else {
                // Trace the tile, then group its hits by cell.
                std::vector<HitRecord> tile_hits;
                std::vector<uint32_t> valid;
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x) {
                        HitRecord rec = trace_pixel(x, y);
                        if (rec.valid)
                            valid.push_back(uint32_t(tile_hits.size()));
                        else
                            write_indirect(rec.pixel, Vec3(0.0f));
                        tile_hits.push_back(rec);
                    }
                std::vector<SortItem> items = sort_items(tile_hits, valid);
                gather_sorted(tile_hits, items, 0, items.size(), scratch, qs, true);
            }
            fetched += scratch.fetched;
            std::lock_guard<std::mutex> lock(merge);
            query_stats.merge(qs);
        });
        frame_stats.add("fused_ms", watch.elapsed_ms());
    } else {
        // Pass 1: every primary hit into a buffer (position, normal, direction, material).
        Stopwatch trace_watch;
        std::vector<HitRecord> hits(size_t(width) * size_t(height));
        parallel_for_tiles(width, height, s.tile_size, [&](const Tile& tile) {
            for (int y = tile.y0; y < tile.y1; ++y)
                for (int x = tile.x0; x < tile.x1; ++x) {
                    HitRecord rec = trace_pixel(x, y);
                    hits[rec.pixel] = rec;
                }
        });
        frame_stats.add("trace_pass_ms", trace_watch.elapsed_ms());
        // Pass 2: gather in cell order for memory coherence, results written by pixel.
        Stopwatch sort_watch;
        std::vector<uint32_t> valid;
        valid.reserve(hits.size());
        for (const HitRecord& h : hits) {
            if (h.valid)
                valid.push_back(h.pixel);
            else
                write_indirect(h.pixel, Vec3(0.0f));
        }
        std::vector<SortItem> items = sort_items(hits, valid);
        frame_stats.add("sort_ms", sort_watch.elapsed_ms());
        Stopwatch gather_watch;
        // Chunks end on cell boundaries so a tile-shared group is never split.
        std::vector<size_t> bounds{0};
        const size_t chunk = 1024;
        for (size_t i = chunk; i < items.size(); i += chunk) {
            if (s.tile_shared)
                while (i < items.size() && items[i].same_group(items[i - 1])) ++i;
            if (i >= items.size()) break;
            bounds.push_back(i);
        }
        bounds.push_back(items.size());
        parallel_for(bounds.size() - 1, 1, [&](size_t cb, size_t ce) {
            GatherScratch scratch;
            PhotonQueryStats qs;
            for (size_t c = cb; c < ce; ++c)
                gather_sorted(hits, items, bounds[c], bounds[c + 1], scratch, qs, s.tile_shared);
            fetched += scratch.fetched;
            std::lock_guard<std::mutex> lock(merge);
            query_stats.merge(qs);
        });
        frame_stats.add("gather_pass_ms", gather_watch.elapsed_ms());
    }

    float* color = film.layer("color").data.data();
    for (size_t i = 0; i < 3 * film.pixel_count(); ++i) color[i] = direct[i] + indirect[i];
    frame_stats.add("nonfinite_pixels", double(nonfinite.load()));
    frame_stats.add("tile_groups", double(groups.load()));
    frame_stats.add("tile_grouped_hits", double(grouped_hits.load()));
    frame_stats.add("tile_fetched_photons", double(fetched.load()));
}

void PhotonMappingTechnique::render(const ViewSet& views, std::vector<Film>& films) {
    if (!scene_.loaded() || !map_) throw Error("photon", "render() called before prepare()");
    Stopwatch watch;
    films.resize(views.views.size());
    PhotonQueryStats queries;
    Stats frame;
    for (size_t v = 0; v < views.views.size(); ++v) {
        const EyeCamera& camera = views.views[v];
        check_resolution(camera.width(), camera.height(), 3);
        Film film(camera.width(), camera.height());
        film.add_layer("direct");
        film.add_layer("indirect");
        render_view(camera, v, film, queries, frame);
        film.metadata["technique"] = "photon";
        film.metadata["view"] = v < views.names.size() ? views.names[v] : "mono";
        film.metadata["photons"] = std::to_string(settings_.photons);
        film.metadata["radius"] = number(settings_.radius);
        film.metadata["gather"] = settings_.gather == GatherMode::Knn ? "knn" : "radius";
        film.metadata["photon_map"] = to_string(settings_.photon_map);
        film.metadata["seed"] = std::to_string(settings_.seed);
        film.metadata["config_hash"] = config_hash_;
        film.metadata["git_revision"] = GILAB_GIT_REVISION;
        films[v] = std::move(film);
    }
    double ms = watch.elapsed_ms();
    for (Film& film : films) film.metadata["render_time_seconds"] = number(ms / 1000.0);
    for (const char* key : {"fused_ms", "trace_pass_ms", "sort_ms", "gather_pass_ms", "nonfinite_pixels", "tile_groups",
                            "tile_grouped_hits", "tile_fetched_photons"})
        stats_.set(key, frame.get(key));
    stats_.set("render_ms", ms);
    stats_.set("gather_queries", double(queries.queries));
    stats_.set("photons_visited", double(queries.visited));
    stats_.set("photons_inside", double(queries.inside));
    stats_.set("photons_visited_per_hit", queries.visited_per_query());
    stats_.set("inside_fraction", queries.inside_fraction());
}

void register_photon_mapping(TechniqueRegistry& registry) {
    registry.add({"photon",
                  "photon mapping (P1): hash-grid / kd-tree / nanoflann photon map, radius or kNN gather, "
                  "fused or split passes, tile-shared gather",
                  [] { return std::make_unique<PhotonMappingTechnique>(); }});
}

}  // namespace gilab
