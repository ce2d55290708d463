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
#include "techniques/photon_mapping/primary_hit.hpp"

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

Vec3 finite_or_zero(const Vec3& v, std::atomic<uint64_t>& nonfinite) {
    if (is_finite(v)) return v;
    ++nonfinite;
    return Vec3(0.0f);
}

void write_pixel(float* layer, size_t pixel, const Vec3& v) {
    for (int c = 0; c < 3; ++c) layer[3 * pixel + size_t(c)] = v[c];
}

struct SortItem {
    uint64_t key;   // PhotonGatherer::sort_key
    uint32_t slot;  // index into the hit buffer
    bool operator<(const SortItem& o) const { return key != o.key ? key < o.key : slot < o.slot; }
    bool same_group(const SortItem& o) const { return key == o.key && key < PhotonGatherer::kUngrouped; }
};

}  // namespace

// The left eye's hits, kept for the right eye (stereo reuse).
struct PhotonMappingTechnique::KeptHits {
    std::vector<PrimaryHit> hits;              // one per left pixel
    std::vector<LightSampleRecord> samples;    // light_samples per left pixel
    size_t per_pixel = 0;
    std::span<const LightSampleRecord> samples_of(size_t pixel) const {
        return {samples.data() + pixel * per_pixel, per_pixel};
    }
};

// What one view's render needs beyond its camera.
struct PhotonMappingTechnique::ViewOptions {
    uint64_t view = 0;                       // light-sample stream of pixels keyed by themselves
    const EyeCamera* stream_eye = nullptr;   // stereo right eye: key by the left pixel seeing the point
    KeptHits* keep = nullptr;                // keep every hit (left eye of a reusing stereo render)
};

PhotonMappingTechnique::PhotonMappingTechnique() = default;
PhotonMappingTechnique::~PhotonMappingTechnique() = default;

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
    p.stereo.enabled = s.get<bool>("stereo_reuse", p.stereo.enabled);
    std::string match = s.get<std::string>("stereo_match", to_string(p.stereo.match));
    p.stereo.tolerance = s.get<float>("stereo_tolerance", p.stereo.tolerance);
    p.stereo.reshade = s.get<bool>("stereo_reshade", p.stereo.reshade);
    p.foveation.enabled = s.get<bool>("foveated", p.foveation.enabled);
    p.foveation.fovea_degrees = s.get<float>("fovea_angle", p.foveation.fovea_degrees);
    p.foveation.periphery_photon_stride = s.get<int>("periphery_photon_stride", p.foveation.periphery_photon_stride);
    p.foveation.gaze_yaw_degrees = s.get<float>("gaze_yaw", p.foveation.gaze_yaw_degrees);
    p.foveation.gaze_pitch_degrees = s.get<float>("gaze_pitch", p.foveation.gaze_pitch_degrees);

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
    if (match == "nearest")
        p.stereo.match = StereoMatch::Nearest;
    else if (match == "strict")
        p.stereo.match = StereoMatch::Strict;
    else
        throw Error(where, "setting 'stereo_match' must be 'nearest' or 'strict', got '" + match + "'");
    if (!(p.stereo.tolerance >= 0.0f) || !std::isfinite(p.stereo.tolerance))
        throw Error(where, "setting 'stereo_tolerance' must be a finite number of pixels ≥ 0, got " + number(p.stereo.tolerance));
    if (p.light_samples > 0xffff)
        throw Error(where, "setting 'light_samples' must be at most 65535, got " + std::to_string(p.light_samples));
    if (p.foveation.enabled) {
        const float angle = p.foveation.fovea_degrees;
        if (!(angle > 0.0f && angle < 180.0f))
            throw Error(where, "setting 'fovea_angle' must be in (0, 180) degrees, got " + number(angle));
        for (auto [key, value] : {std::pair{"gaze_yaw", p.foveation.gaze_yaw_degrees},
                                  std::pair{"gaze_pitch", p.foveation.gaze_pitch_degrees}})
            if (!(std::abs(value) <= 90.0f))
                throw Error(where, std::string("setting '") + key + "' must be within ±90 degrees, got " + number(value));
        if (p.foveation.periphery_photon_stride < 1)
            throw Error(where, "setting 'periphery_photon_stride' must be at least 1, got " +
                                   std::to_string(p.foveation.periphery_photon_stride));
        if (p.split || p.tile_shared)
            throw Error(where, "setting 'foveated' needs pass=fused and tile_shared=false (it picks the shading rate per block)");
        if (p.tile_size % 4 != 0)
            throw Error(where, "setting 'foveated' needs a tile_size that is a multiple of 4 (4×4 shading blocks), got " +
                                   std::to_string(p.tile_size));
        if (p.stereo.enabled)
            throw Error(where, "settings 'foveated' and 'stereo_reuse' cannot be combined yet");
    }
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
        auto periphery = make_photon_map(settings_.photon_map);
        if (auto* grid = dynamic_cast<HashGridPhotonMap*>(periphery.get())) grid->set_query_mode(settings_.hash_query);
        periphery->build(std::move(kept), settings_.radius);
        stats_.set("periphery_photons_stored", double(periphery->size()));
        periphery_map_ = std::move(periphery);
    }
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

void PhotonMappingTechnique::render_view(const EyeCamera& camera, const ViewOptions& options, Film& film,
                                         PhotonQueryStats& query_stats, Stats& frame_stats) const {
    const int width = camera.width(), height = camera.height();
    const PhotonMappingSettings& s = settings_;
    const PhotonGatherer gatherer(*map_, scene_.materials(), s.gather, s.radius, size_t(s.k));
    std::optional<PhotonGatherer> periphery;
    if (periphery_map_) periphery.emplace(*periphery_map_, scene_.materials(), s.gather, s.radius, size_t(s.k));
    const PrimaryShadingContext shading{scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(),
                                        s.light_samples};
    float* direct = film.layer("direct").data.data();
    float* indirect = film.layer("indirect").data.data();
    std::mutex merge;
    std::atomic<uint64_t> nonfinite{0}, groups{0}, grouped_hits{0}, fetched{0};
    KeptHits* keep = options.keep;
    if (keep) {
        // Kept from frame to frame: every pixel overwrites its entry, so no clearing.
        keep->per_pixel = size_t(std::max(s.light_samples, 0));
        keep->hits.resize(film.pixel_count());
        keep->samples.resize(film.pixel_count() * keep->per_pixel);
    }

    // The light-sample stream of a hit: its own pixel's, or in a stereo right eye the
    // stream of the left pixel that sees the same point (stereo-consistent noise).
    auto stream_of = [&](const Vec3& x, uint32_t pixel) {
        if (options.stream_eye)
            if (auto q = options.stream_eye->pixel_of(x))
                return Rng::for_sample(s.seed, uint64_t(q->y) * uint64_t(options.stream_eye->width()) + uint64_t(q->x), 0, 0);
        return Rng::for_sample(s.seed, pixel, 0, options.view);
    };
    // Primary ray through (px, py), emission and next-event estimation for `pixel`; the
    // hit is returned for the gather and its direct radiance written.
    auto trace_pixel = [&](float px, float py, uint32_t pixel) {
        thread_local std::vector<LightSampleRecord> scratch_samples;
        HitRecord rec;
        rec.pixel = pixel;
        Vec3 L(0.0f);
        Ray ray = camera.generate_ray(px, py);
        Hit hit = scene_.tracer().intersect(ray);
        if (hit.valid()) {
            SurfaceInteraction si = make_interaction(scene_.frame(), ray, hit);
            const Material& m = scene_.materials()[si.material];
            PrimaryHit ph = primary_hit_of(si, m);
            std::span<LightSampleRecord> samples;
            if (keep) {
                samples = {keep->samples.data() + size_t(pixel) * keep->per_pixel, keep->per_pixel};
            } else {
                scratch_samples.resize(size_t(std::max(s.light_samples, 0)));
                samples = scratch_samples;
            }
            Rng rng = stream_of(si.position, pixel);
            sample_direct_light(shading, si, rng, samples, ph);
            L = direct_radiance(m, ph, si.wo, samples);
            rec.point = ph.point;
            rec.valid = true;
            if (keep) keep->hits[pixel] = ph;
        } else if (keep) {
            keep->hits[pixel].valid = false;
        }
        write_pixel(direct, pixel, finite_or_zero(L, nonfinite));
        return rec;
    };
    auto pixel_index = [&](int x, int y) { return uint32_t(size_t(y) * size_t(width) + size_t(x)); };
    auto write_indirect = [&](uint32_t pixel, Vec3 v) { write_pixel(indirect, pixel, finite_or_zero(v, nonfinite)); };
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
    // Foveated tile (foveation.hpp): every pixel traces its primary and shadow rays; in
    // 2×2 and 4×4 gather blocks the first hit gathers (over the periphery map) and the
    // block's other hits on the same surface nearby take its indirect light.
    const float share_distance2 = s.radius * s.radius;
    auto shares_gather = [&](const HitRecord& a, const HitRecord& b) {
        return a.point.material == b.point.material && glm::dot(a.point.normal, b.point.normal) > 0.95f &&
               glm::dot(a.point.position - b.point.position, a.point.position - b.point.position) < share_distance2;
    };
    auto shade_foveated_tile = [&](const Tile& tile, GatherScratch& scratch, PhotonQueryStats& qs) {
        for (int by = tile.y0; by < tile.y1; by += 4)
            for (int bx = tile.x0; bx < tile.x1; bx += 4) {
                const int bx1 = std::min(bx + 4, tile.x1), by1 = std::min(by + 4, tile.y1);
                const int b = foveated_block_size(camera, s.foveation, bx, by);
                const PhotonGatherer& g = b == 1 ? gatherer : *periphery;
                for (int sy = by; sy < by1; sy += b)
                    for (int sx = bx; sx < bx1; sx += b) {
                        std::optional<HitRecord> gathered;
                        Vec3 gathered_light(0.0f);
                        for (int y = sy; y < std::min(sy + b, by1); ++y)
                            for (int x = sx; x < std::min(sx + b, bx1); ++x) {
                                HitRecord rec = trace_pixel(float(x) + 0.5f, float(y) + 0.5f, pixel_index(x, y));
                                if (!rec.valid) {
                                    write_indirect(rec.pixel, Vec3(0.0f));
                                } else if (gathered && shares_gather(*gathered, rec)) {
                                    write_indirect(rec.pixel, gathered_light);
                                } else {
                                    const Vec3 v = g.estimate(rec.point, scratch, qs);
                                    write_indirect(rec.pixel, v);
                                    if (!gathered) gathered = rec, gathered_light = v;
                                }
                            }
                    }
            }
    };

    if (!s.split) {
        Stopwatch watch;
        parallel_for_tiles(width, height, s.tile_size, [&](const Tile& tile) {
            GatherScratch scratch;
            PhotonQueryStats qs;
            if (s.foveation.enabled) {
                shade_foveated_tile(tile, scratch, qs);
            } else if (!s.tile_shared) {
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x) {
                        HitRecord rec = trace_pixel(float(x) + 0.5f, float(y) + 0.5f, pixel_index(x, y));
                        write_indirect(rec.pixel, rec.valid ? gatherer.estimate(rec.point, scratch, qs) : Vec3(0.0f));
                    }
            } else {
                // Trace the tile, then group its hits by cell.
                std::vector<HitRecord> tile_hits;
                std::vector<uint32_t> valid;
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x) {
                        HitRecord rec = trace_pixel(float(x) + 0.5f, float(y) + 0.5f, pixel_index(x, y));
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
                    HitRecord rec = trace_pixel(float(x) + 0.5f, float(y) + 0.5f, pixel_index(x, y));
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

void PhotonMappingTechnique::render_right_reusing(const EyeCamera& left, const EyeCamera& right, const KeptHits& kept,
                                                  const Film& left_film, Film& film, PhotonQueryStats& query_stats,
                                                  Stats& frame_stats) const {
    const PhotonMappingSettings& s = settings_;
    Stopwatch claim_watch;
    const StereoClaims claims(kept.hits, left, right, scene_.tracer());
    frame_stats.add("claim_ms", claim_watch.elapsed_ms());

    Stopwatch right_watch;
    const int width = right.width();
    const PhotonGatherer gatherer(*map_, scene_.materials(), s.gather, s.radius, size_t(s.k));
    const PrimaryShadingContext shading{scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(),
                                        s.light_samples};
    const float* left_direct = left_film.layer("direct").data.data();
    const float* left_indirect = left_film.layer("indirect").data.data();
    float* direct = film.layer("direct").data.data();
    float* indirect = film.layer("indirect").data.data();
    float* reused_layer = film.add_layer("reused", 1).data.data();
    const Vec3 eye = right.position();
    std::mutex merge;
    std::atomic<uint64_t> nonfinite{0}, reused{0}, reshaded_glossy{0}, strict_rejected{0}, shaded{0};

    auto load = [](const float* layer, size_t pixel) {
        return Vec3(layer[3 * pixel], layer[3 * pixel + 1], layer[3 * pixel + 2]);
    };

    parallel_for_tiles(width, right.height(), s.tile_size, [&](const Tile& tile) {
        GatherScratch scratch;
        PhotonQueryStats qs;
        std::vector<LightSampleRecord> samples(size_t(std::max(s.light_samples, 0)));
        uint64_t n_reused = 0, n_glossy = 0, n_rejected = 0, n_shaded = 0;
        for (int y = tile.y0; y < tile.y1; ++y)
            for (int x = tile.x0; x < tile.x1; ++x) {
                const uint32_t pixel = uint32_t(size_t(y) * size_t(width) + size_t(x));
                const uint32_t source = claims.source(pixel);
                Vec3 Ld(0.0f), Li(0.0f);
                bool from_left = source != StereoClaims::kNone;
                std::optional<SurfaceInteraction> own;  // the right pixel's own hit, if traced
                Ray ray;
                if (!from_left || s.stereo.match == StereoMatch::Strict) {
                    ray = right.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
                    Hit hit = scene_.tracer().intersect(ray);
                    if (hit.valid()) own = make_interaction(scene_.frame(), ray, hit);
                    if (from_left) {
                        PrimaryHit mine;
                        if (own) mine = primary_hit_of(*own, scene_.materials()[own->material]);
                        from_left = same_surface_point(kept.hits[source], mine, right, s.stereo.tolerance);
                        n_rejected += !from_left;
                    }
                }
                if (from_left) {
                    const PrimaryHit& h = kept.hits[source];
                    const Material& m = scene_.materials()[h.point.material];
                    if (s.stereo.reshade) {
                        // View-independent parts from the left eye; the glossy lobe for this eye.
                        const Vec3 wo = glm::normalize(eye - h.point.position);
                        Ld = direct_radiance(m, h, wo, kept.samples_of(source));
                        if (m.has_glossy_lobe()) {
                            GatherPoint p = h.point;
                            p.wo = wo;
                            Li = gatherer.estimate(p, scratch, qs);
                            ++n_glossy;
                        } else {
                            Li = load(left_indirect, source);
                        }
                    } else {
                        Ld = load(left_direct, source);
                        Li = load(left_indirect, source);
                    }
                    ++n_reused;
                    reused_layer[pixel] = 1.0f;
                } else if (own) {
                    // Nobody claimed it (or strict mode refused): shade it as an independent eye.
                    const Material& m = scene_.materials()[own->material];
                    PrimaryHit ph = primary_hit_of(*own, m);
                    Rng rng = [&] {
                        if (auto q = left.pixel_of(own->position))
                            return Rng::for_sample(s.seed, uint64_t(q->y) * uint64_t(left.width()) + uint64_t(q->x), 0, 0);
                        return Rng::for_sample(s.seed, pixel, 0, 1);
                    }();
                    sample_direct_light(shading, *own, rng, samples, ph);
                    Ld = direct_radiance(m, ph, own->wo, samples);
                    Li = gatherer.estimate(ph.point, scratch, qs);
                    ++n_shaded;
                }
                write_pixel(direct, pixel, finite_or_zero(Ld, nonfinite));
                write_pixel(indirect, pixel, finite_or_zero(Li, nonfinite));
            }
        reused += n_reused, reshaded_glossy += n_glossy, strict_rejected += n_rejected, shaded += n_shaded;
        std::lock_guard<std::mutex> lock(merge);
        query_stats.merge(qs);
    });
    float* color = film.layer("color").data.data();
    for (size_t i = 0; i < 3 * film.pixel_count(); ++i) color[i] = direct[i] + indirect[i];
    frame_stats.add("right_pass_ms", right_watch.elapsed_ms());
    const StereoClaimStats& c = claims.stats();
    frame_stats.set("reuse_left_hits", double(c.left_hits));
    frame_stats.set("reuse_back_side", double(c.back_side));
    frame_stats.set("reuse_outside", double(c.outside));
    frame_stats.set("reuse_occluded", double(c.occluded));
    frame_stats.set("reuse_candidates", double(c.candidates));
    frame_stats.set("reuse_claimed_pixels", double(c.claimed_pixels));
    frame_stats.set("reuse_depth_conflicts", double(c.depth_conflicts));
    frame_stats.set("reuse_strict_rejected", double(strict_rejected.load()));
    frame_stats.set("reused_pixels", double(reused.load()));
    // Of the right pixels that show geometry (reused or shaded), the share reused.
    const double covered = double(reused.load() + shaded.load());
    frame_stats.set("reuse_fraction", covered > 0 ? double(reused.load()) / covered : 0.0);
    frame_stats.set("reuse_reshaded_glossy", double(reshaded_glossy.load()));
    frame_stats.set("right_shaded_pixels", double(shaded.load()));
    frame_stats.add("nonfinite_pixels", double(nonfinite.load()));
}

void PhotonMappingTechnique::render(const ViewSet& views, std::vector<Film>& films) {
    if (!scene_.loaded() || !map_) throw Error("photon", "render() called before prepare()");
    Stopwatch watch;
    films.assign(views.views.size(), Film());
    PhotonQueryStats queries;
    Stats frame;
    const bool stereo = views.stereo();
    const bool reuse = stereo && settings_.stereo.enabled;
    if (reuse && !kept_) kept_ = std::make_unique<KeptHits>();
    for (size_t v = 0; v < views.views.size(); ++v) {
        const EyeCamera& camera = views.views[v];
        check_resolution(camera.width(), camera.height(), 4);
        Film film(camera.width(), camera.height());
        film.add_layer("direct");
        film.add_layer("indirect");
        Stopwatch view_watch;
        if (reuse && v == 1) {
            render_right_reusing(views.views[0], camera, *kept_, films[0], film, queries, frame);
        } else {
            ViewOptions options;
            options.view = v;
            if (stereo && v == 1) options.stream_eye = &views.views[0];
            if (reuse && v == 0) options.keep = kept_.get();
            render_view(camera, options, film, queries, frame);
        }
        const double view_ms = view_watch.elapsed_ms();
        if (stereo) frame.set(v == 0 ? "left_ms" : "right_ms", view_ms);
        film.metadata["technique"] = "photon";
        film.metadata["view"] = v < views.names.size() ? views.names[v] : "mono";
        film.metadata["photons"] = std::to_string(settings_.photons);
        film.metadata["radius"] = number(settings_.radius);
        film.metadata["gather"] = settings_.gather == GatherMode::Knn ? "knn" : "radius";
        film.metadata["photon_map"] = to_string(settings_.photon_map);
        film.metadata["seed"] = std::to_string(settings_.seed);
        if (stereo) film.metadata["stereo_reuse"] = reuse ? to_string(settings_.stereo.match) : "off";
        film.metadata["config_hash"] = config_hash_;
        film.metadata["git_revision"] = GILAB_GIT_REVISION;
        films[v] = std::move(film);
    }
    double ms = watch.elapsed_ms();
    for (Film& film : films) film.metadata["render_time_seconds"] = number(ms / 1000.0);
    // Per-frame figures replace the previous frame's.
    for (const char* key : {"fused_ms", "trace_pass_ms", "sort_ms", "gather_pass_ms", "nonfinite_pixels", "tile_groups",
                            "tile_grouped_hits", "tile_fetched_photons", "left_ms", "right_ms",
                            "claim_ms", "right_pass_ms", "reuse_left_hits", "reuse_back_side", "reuse_outside",
                            "reuse_occluded", "reuse_candidates", "reuse_claimed_pixels", "reuse_depth_conflicts",
                            "reuse_strict_rejected", "reused_pixels", "reuse_fraction", "reuse_reshaded_glossy",
                            "right_shaded_pixels"})
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
