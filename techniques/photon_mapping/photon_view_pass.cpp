// One eye of the photon technique: primary rays, next-event estimation (indirect
// storage only) and the photon gather, fused per tile or split into a trace and a gather
// pass, per hit, tile-shared (tile_share.hpp) or foveated.
#include <algorithm>
#include <mutex>
#include <optional>
#include <tbb/parallel_sort.h>
#include "core/interaction.hpp"
#include "core/parallel.hpp"
#include "core/rng.hpp"
#include "techniques/photon_mapping/photon_passes.hpp"

namespace gilab {

namespace {

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
    std::atomic<uint64_t> nonfinite{0};
    uint64_t fetched = 0;             // under `merge`
    TileShareCounts share_counts;     // under `merge`
    KeptHits* keep = options.keep;
    if (keep) {
        // Kept from frame to frame: every pixel overwrites its entry, so no clearing.
        keep->per_pixel = size_t(std::max(s.light_samples, 0));
        keep->hits.resize(film.pixel_count());
        keep->samples.resize(film.pixel_count() * keep->per_pixel);
    }

    // Primary ray through (px, py), emission and next-event estimation (no light samples
    // with every-hit storage) for `pixel`; the hit is returned for the gather and its
    // direct radiance written.
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
            Rng rng = light_sample_stream(s.seed, options.stream_eye, si.position, pixel, options.view);
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
    // The map's estimate for a pixel: the indirect part into the indirect layer and, with
    // every-hit storage, the direct part added to what the primary hit wrote (emission).
    const bool map_direct = s.storage == PhotonStorage::EveryHit;
    auto write_gather = [&](uint32_t pixel, const PhotonEstimate& e) {
        write_pixel(indirect, pixel, finite_or_zero(e.indirect, nonfinite));
        if (map_direct) {
            const Vec3 seen(direct[3 * pixel], direct[3 * pixel + 1], direct[3 * pixel + 2]);
            write_pixel(direct, pixel, finite_or_zero(seen + e.direct, nonfinite));
        }
    };
    auto merge_counts = [&](const GatherScratch& scratch, const PhotonQueryStats& qs, const TileShareCounts& tc) {
        std::lock_guard<std::mutex> lock(merge);
        fetched += scratch.fetched;
        query_stats.merge(qs);
        share_counts.merge(tc);
    };
    // Gathers the sorted hits items[b..e): per hit, or (cell_groups) runs of hits sharing a
    // cell together.
    auto gather_sorted = [&](const std::vector<HitRecord>& hits, const std::vector<SortItem>& items, size_t b, size_t e,
                             GatherScratch& scratch, PhotonQueryStats& qs, TileShareCounts& tc) {
        if (s.tile_shared != TileShare::CellGroups) {
            for (size_t i = b; i < e; ++i) {
                const HitRecord& h = hits[items[i].slot];
                write_gather(h.pixel, gatherer.estimate_parts(h.point, scratch, qs));
            }
            return;
        }
        thread_local std::vector<uint64_t> keys;
        thread_local std::vector<const GatherPoint*> points;
        thread_local std::vector<PhotonEstimate> out;
        keys.clear(), points.clear();
        for (size_t i = b; i < e; ++i) {
            keys.push_back(items[i].key);
            points.push_back(&hits[items[i].slot].point);
        }
        out.resize(points.size());
        gather_cell_groups(gatherer, keys, points, out, scratch, qs, tc);
        for (size_t i = b; i < e; ++i) write_gather(hits[items[i].slot].pixel, out[i - b]);
    };
    // Algorithm 1 over one share tile t (hit_of(x, y) gives the hit of image pixel (x, y)).
    auto gather_share_tile = [&](const Tile& t, const auto& hit_of, GatherScratch& scratch, PhotonQueryStats& qs,
                                 TileShareCounts& tc) {
        thread_local std::vector<const GatherPoint*> points;
        thread_local std::vector<PhotonEstimate> out;
        points.clear();
        for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x) {
                const HitRecord& h = hit_of(x, y);
                points.push_back(h.valid ? &h.point : nullptr);
            }
        out.assign(points.size(), PhotonEstimate{});
        if (s.tile_shared == TileShare::Paper) {
            gather_tile_paper(gatherer, points, out, scratch, qs, tc);
        } else {
            for (size_t i = 0; i < points.size(); ++i)
                if (points[i]) out[i] = gatherer.estimate_parts(*points[i], scratch, qs);
        }
        size_t i = 0;
        for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x, ++i) write_gather(pixel_index(x, y), out[i]);
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
                        PhotonEstimate gathered_light;
                        for (int y = sy; y < std::min(sy + b, by1); ++y)
                            for (int x = sx; x < std::min(sx + b, bx1); ++x) {
                                HitRecord rec = trace_pixel(float(x) + 0.5f, float(y) + 0.5f, pixel_index(x, y));
                                if (!rec.valid) {
                                    write_gather(rec.pixel, PhotonEstimate{});
                                } else if (gathered && shares_gather(*gathered, rec)) {
                                    write_gather(rec.pixel, gathered_light);
                                } else {
                                    const PhotonEstimate v = g.estimate_parts(rec.point, scratch, qs);
                                    write_gather(rec.pixel, v);
                                    if (!gathered) gathered = rec, gathered_light = v;
                                }
                            }
                    }
            }
    };
    // The share tiles (image-aligned, share_tile pixels square) inside a region.
    auto for_each_share_tile = [&](const Tile& region, const auto& fn) {
        const int n = s.share_tile;
        for (int y = region.y0; y < region.y1; y += n)
            for (int x = region.x0; x < region.x1; x += n) fn(Tile{x, y, std::min(x + n, region.x1), std::min(y + n, region.y1)});
    };

    if (!s.split) {
        Stopwatch watch;
        parallel_for_tiles(width, height, s.tile_size, [&](const Tile& tile) {
            GatherScratch scratch;
            PhotonQueryStats qs;
            TileShareCounts tc;
            if (s.foveation.enabled) {
                shade_foveated_tile(tile, scratch, qs);
            } else if (s.tile_shared == TileShare::Off) {
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x) {
                        HitRecord rec = trace_pixel(float(x) + 0.5f, float(y) + 0.5f, pixel_index(x, y));
                        write_gather(rec.pixel, rec.valid ? gatherer.estimate_parts(rec.point, scratch, qs) : PhotonEstimate{});
                    }
            } else if (s.tile_shared == TileShare::Paper) {
                // One thread group per share tile (tile_size is a multiple of share_tile):
                // trace its pixels, then Algorithm 1.
                const size_t tw = size_t(tile.x1 - tile.x0);
                std::vector<HitRecord> tile_hits(tw * size_t(tile.y1 - tile.y0));
                auto slot = [&](int x, int y) { return size_t(y - tile.y0) * tw + size_t(x - tile.x0); };
                auto hit_of = [&](int x, int y) -> const HitRecord& { return tile_hits[slot(x, y)]; };
                for_each_share_tile(tile, [&](const Tile& t) {
                    for (int y = t.y0; y < t.y1; ++y)
                        for (int x = t.x0; x < t.x1; ++x)
                            tile_hits[slot(x, y)] = trace_pixel(float(x) + 0.5f, float(y) + 0.5f, pixel_index(x, y));
                    gather_share_tile(t, hit_of, scratch, qs, tc);
                });
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
                            write_gather(rec.pixel, PhotonEstimate{});
                        tile_hits.push_back(rec);
                    }
                std::vector<SortItem> items = sort_items(tile_hits, valid);
                gather_sorted(tile_hits, items, 0, items.size(), scratch, qs, tc);
            }
            merge_counts(scratch, qs, tc);
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
        Stopwatch gather_watch;
        if (s.gather_by_tiles) {
            // Pass 2 as the paper's gather kernel: one thread group per share tile.
            auto hit_of = [&](int x, int y) -> const HitRecord& { return hits[pixel_index(x, y)]; };
            parallel_for_tiles(width, height, s.share_tile, [&](const Tile& t) {
                GatherScratch scratch;
                PhotonQueryStats qs;
                TileShareCounts tc;
                gather_share_tile(t, hit_of, scratch, qs, tc);
                merge_counts(scratch, qs, tc);
            });
        } else {
            // Pass 2: gather in cell order for memory coherence, results written by pixel.
            Stopwatch sort_watch;
            std::vector<uint32_t> valid;
            valid.reserve(hits.size());
            for (const HitRecord& h : hits) {
                if (h.valid)
                    valid.push_back(h.pixel);
                else
                    write_gather(h.pixel, PhotonEstimate{});
            }
            std::vector<SortItem> items = sort_items(hits, valid);
            frame_stats.add("sort_ms", sort_watch.elapsed_ms());
            // Chunks end on cell boundaries so a cell group is never split.
            std::vector<size_t> bounds{0};
            const size_t chunk = 1024;
            for (size_t i = chunk; i < items.size(); i += chunk) {
                if (s.tile_shared == TileShare::CellGroups)
                    while (i < items.size() && items[i].same_group(items[i - 1])) ++i;
                if (i >= items.size()) break;
                bounds.push_back(i);
            }
            bounds.push_back(items.size());
            parallel_for(bounds.size() - 1, 1, [&](size_t cb, size_t ce) {
                GatherScratch scratch;
                PhotonQueryStats qs;
                TileShareCounts tc;
                for (size_t c = cb; c < ce; ++c) gather_sorted(hits, items, bounds[c], bounds[c + 1], scratch, qs, tc);
                merge_counts(scratch, qs, tc);
            });
        }
        frame_stats.add("gather_pass_ms", gather_watch.elapsed_ms());
    }

    float* color = film.layer("color").data.data();
    for (size_t i = 0; i < 3 * film.pixel_count(); ++i) color[i] = direct[i] + indirect[i];
    frame_stats.add("nonfinite_pixels", double(nonfinite.load()));
    frame_stats.add("tile_groups", double(share_counts.groups));
    frame_stats.add("tile_grouped_hits", double(share_counts.grouped_hits));
    frame_stats.add("tile_fetched_photons", double(fetched));
    frame_stats.add("share_tiles_qualified", double(share_counts.tiles_qualified));
    frame_stats.add("share_tiles_mixed", double(share_counts.tiles_mixed));
}

}  // namespace gilab
