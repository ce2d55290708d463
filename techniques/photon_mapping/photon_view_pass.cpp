// One eye of the photon technique: primary rays (spp samples per pixel,
// pixel_samples.hpp), next-event estimation (indirect storage only) and the photon gather,
// fused per tile or split into a trace and a gather pass, per hit, tile-shared
// (tile_share.hpp) or foveated. Each sample's hit is one more hit to the gather: tile
// sharing and the split pass's cell order take a pixel's samples like its neighbours'.
#include <algorithm>
#include <limits>
#include <mutex>
#include <optional>
#include <tbb/parallel_sort.h>
#include "core/render/surface_material.hpp"
#include "core/util/error.hpp"
#include "core/render/interaction.hpp"
#include "core/util/parallel.hpp"
#include "core/util/rng.hpp"
#include "techniques/photon_mapping/photon_passes.hpp"

namespace gilab {

namespace {

// A primary hit (one sample of one pixel) waiting for its gather.
struct HitRecord {
    GatherPoint point;
    uint32_t slot = 0;  // its sample's slot in the SampleRadiance it writes, and in the hit buffer
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
    const float spread = camera.pixel_spread_angle();
    const PhotonMappingSettings& s = settings_;
    const int spp = s.sampling.spp;
    const PhotonGatherer gatherer(*map_, s.gather, size_t(s.k));
    std::optional<PhotonGatherer> periphery;
    if (periphery_map_) periphery.emplace(*periphery_map_, s.gather, size_t(s.k));
    const PrimaryShadingContext shading{scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(),
                                        s.light_samples};
    const size_t light_samples = shading.records_per_hit();
    float* direct = film.layer("direct").data.data();
    float* indirect = film.layer("indirect").data.data();
    std::mutex merge;
    std::atomic<uint64_t> nonfinite{0};
    uint64_t fetched = 0;             // under `merge`
    TileShareCounts share_counts;     // under `merge`
    KeptHits* keep = options.keep;
    if (keep) {
        check_sample_memory(width, height, spp,
                            sizeof(PrimaryHit) + light_samples * sizeof(LightSampleRecord) + 2 * sizeof(Vec3),
                            "the left eye's hits kept for stereo reuse", "photon");
        keep->resize(film.pixel_count(), spp, light_samples);
    }

    auto pixel_index = [&](int x, int y) { return uint32_t(size_t(y) * size_t(width) + size_t(x)); };
    // Buffers cover a region (a render tile, or the whole image in the split pass): a
    // pixel's samples sit next to each other, pixels in row order.
    auto local_pixel = [&](const Tile& region, int x, int y) {
        return size_t(y - region.y0) * size_t(region.x1 - region.x0) + size_t(x - region.x0);
    };
    auto slot_of = [&](const Tile& region, int x, int y, int sample) {
        return uint32_t(local_pixel(region, x, y) * size_t(spp) + size_t(sample));
    };
    auto region_pixels = [](const Tile& t) { return size_t(t.x1 - t.x0) * size_t(t.y1 - t.y0); };

    // Sample `sample` of pixel (x, y): primary ray, emission and next-event estimation (no
    // light samples with every-hit storage); its direct radiance is written to `out` at
    // `slot` and the hit returned for the gather.
    auto trace_sample = [&](int x, int y, int sample, uint32_t slot, SampleRadiance& out) {
        thread_local std::vector<LightSampleRecord> scratch_samples;
        const uint32_t pixel = pixel_index(x, y);
        const size_t kept = keep ? keep->slot(pixel, sample) : 0;
        HitRecord rec;
        rec.slot = slot;
        Vec3 L(0.0f);
        const Vec2 at = Vec2(float(x), float(y)) + sample_offset(s.sampling, s.seed, pixel, sample, options.view);
        Ray ray = camera.generate_ray(at.x, at.y);
        Hit hit = scene_.tracer().intersect(ray);
        if (hit.valid()) {
            SurfaceInteraction si = make_interaction(scene_.frame(), ray, hit);
            PrimaryHit ph = primary_hit_of(si, scene_.materials()[si.material],
                                           cone_width(spread, hit.t * glm::length(ray.direction)));
            std::span<LightSampleRecord> samples;
            if (keep) {
                samples = keep->samples_of(kept);
            } else {
                scratch_samples.resize(light_samples);
                samples = scratch_samples;
            }
            Rng rng = light_sample_stream(s.sampling, s.seed, options.stream_eye, si.position, pixel, sample, options.view);
            sample_direct_light(shading, si, rng, samples, ph);
            L = direct_radiance(ph.point.surface, ph, si.wo, samples);
            rec.point = ph.point;
            rec.valid = true;
            if (keep) keep->hits[kept] = ph;
        } else if (keep) {
            keep->hits[kept].valid = false;
        }
        out.direct(slot) = finite_or_zero(L, nonfinite);
        return rec;
    };
    // The map's estimate for a sample: the indirect part and, with every-hit storage, the
    // direct part added to what the primary hit wrote (emission).
    const bool map_direct = s.storage == PhotonStorage::EveryHit;
    auto write_gather = [&](SampleRadiance& out, uint32_t slot, const PhotonEstimate& e) {
        out.indirect(slot) = finite_or_zero(e.indirect, nonfinite);
        if (map_direct) out.direct(slot) = finite_or_zero(out.direct(slot) + e.direct, nonfinite);
    };
    // The pixels of `part` take the mean of their samples in `out` (the buffers of
    // `region`); the kept hits take each sample's radiance for the right eye.
    auto resolve = [&](const Tile& region, const Tile& part, const SampleRadiance& out) {
        for (int y = part.y0; y < part.y1; ++y)
            for (int x = part.x0; x < part.x1; ++x) {
                const uint32_t pixel = pixel_index(x, y);
                const size_t local = local_pixel(region, x, y);
                write_pixel(direct, pixel, out.mean_direct(local));
                write_pixel(indirect, pixel, out.mean_indirect(local));
                if (!keep) continue;
                for (int sample = 0; sample < spp; ++sample) {
                    const size_t slot = local * size_t(spp) + size_t(sample);
                    keep->direct[keep->slot(pixel, sample)] = out.direct(slot);
                    keep->indirect[keep->slot(pixel, sample)] = out.indirect(slot);
                }
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
                             SampleRadiance& out, GatherScratch& scratch, PhotonQueryStats& qs, TileShareCounts& tc) {
        if (s.tile_shared != TileShare::CellGroups) {
            for (size_t i = b; i < e; ++i)
                write_gather(out, items[i].slot, gatherer.estimate_parts(hits[items[i].slot].point, scratch, qs));
            return;
        }
        thread_local std::vector<uint64_t> keys;
        thread_local std::vector<const GatherPoint*> points;
        thread_local std::vector<PhotonEstimate> estimates;
        keys.clear(), points.clear();
        for (size_t i = b; i < e; ++i) {
            keys.push_back(items[i].key);
            points.push_back(&hits[items[i].slot].point);
        }
        estimates.resize(points.size());
        gather_cell_groups(gatherer, keys, points, estimates, scratch, qs, tc);
        for (size_t i = b; i < e; ++i) write_gather(out, items[i].slot, estimates[i - b]);
    };
    // Algorithm 1 over one share tile t (hit_of(x, y, sample) gives the hit of a sample of
    // image pixel (x, y)); every sample of the tile's pixels is one of its hits.
    auto gather_share_tile = [&](const Tile& t, const auto& hit_of, SampleRadiance& out, GatherScratch& scratch,
                                 PhotonQueryStats& qs, TileShareCounts& tc) {
        thread_local std::vector<const GatherPoint*> points;
        thread_local std::vector<PhotonEstimate> estimates;
        points.clear();
        for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x)
                for (int sample = 0; sample < spp; ++sample) {
                    const HitRecord& h = hit_of(x, y, sample);
                    points.push_back(h.valid ? &h.point : nullptr);
                }
        estimates.assign(points.size(), PhotonEstimate{});
        if (s.tile_shared == TileShare::Paper) {
            gather_tile_paper(gatherer, points, estimates, scratch, qs, tc);
        } else {
            for (size_t i = 0; i < points.size(); ++i)
                if (points[i]) estimates[i] = gatherer.estimate_parts(*points[i], scratch, qs);
        }
        size_t i = 0;
        for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x)
                for (int sample = 0; sample < spp; ++sample, ++i) write_gather(out, hit_of(x, y, sample).slot, estimates[i]);
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
    // Foveated tile (foveation.hpp): every sample traces its primary and shadow rays; in
    // 2×2 and 4×4 gather blocks the first hit of each sample index gathers (over the
    // periphery map) and the block's other hits of that index on the same surface nearby
    // take its indirect light, so the periphery gathers at the same reduced rate at any spp.
    const float share_distance2 = s.radius * s.radius;
    auto shares_gather = [&](const HitRecord& a, const HitRecord& b) {
        return a.point.material == b.point.material && glm::dot(a.point.normal, b.point.normal) > 0.95f &&
               glm::dot(a.point.position - b.point.position, a.point.position - b.point.position) < share_distance2;
    };
    auto shade_foveated_tile = [&](const Tile& tile, SampleRadiance& out, GatherScratch& scratch, PhotonQueryStats& qs) {
        std::vector<std::optional<HitRecord>> gathered(static_cast<size_t>(spp));
        std::vector<PhotonEstimate> gathered_light(static_cast<size_t>(spp));
        for (int by = tile.y0; by < tile.y1; by += 4)
            for (int bx = tile.x0; bx < tile.x1; bx += 4) {
                const int bx1 = std::min(bx + 4, tile.x1), by1 = std::min(by + 4, tile.y1);
                const int b = foveated_block_size(camera, s.foveation, bx, by);
                const PhotonGatherer& g = b == 1 ? gatherer : *periphery;
                for (int sy = by; sy < by1; sy += b)
                    for (int sx = bx; sx < bx1; sx += b) {
                        std::fill(gathered.begin(), gathered.end(), std::nullopt);
                        for (int y = sy; y < std::min(sy + b, by1); ++y)
                            for (int x = sx; x < std::min(sx + b, bx1); ++x)
                                for (int sample = 0; sample < spp; ++sample) {
                                    HitRecord rec = trace_sample(x, y, sample, slot_of(tile, x, y, sample), out);
                                    std::optional<HitRecord>& first = gathered[size_t(sample)];
                                    if (!rec.valid) {
                                        write_gather(out, rec.slot, PhotonEstimate{});
                                    } else if (first && shares_gather(*first, rec)) {
                                        write_gather(out, rec.slot, gathered_light[size_t(sample)]);
                                    } else {
                                        const PhotonEstimate v = g.estimate_parts(rec.point, scratch, qs);
                                        write_gather(out, rec.slot, v);
                                        if (!first) first = rec, gathered_light[size_t(sample)] = v;
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
            SampleRadiance out(region_pixels(tile), spp);
            if (s.foveation.enabled) {
                shade_foveated_tile(tile, out, scratch, qs);
            } else if (s.tile_shared == TileShare::Off) {
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x)
                        for (int sample = 0; sample < spp; ++sample) {
                            HitRecord rec = trace_sample(x, y, sample, slot_of(tile, x, y, sample), out);
                            write_gather(out, rec.slot,
                                         rec.valid ? gatherer.estimate_parts(rec.point, scratch, qs) : PhotonEstimate{});
                        }
            } else if (s.tile_shared == TileShare::Paper) {
                // One thread group per share tile (tile_size is a multiple of share_tile):
                // trace its pixels' samples, then Algorithm 1.
                std::vector<HitRecord> tile_hits(region_pixels(tile) * size_t(spp));
                auto hit_of = [&](int x, int y, int sample) -> const HitRecord& {
                    return tile_hits[slot_of(tile, x, y, sample)];
                };
                for_each_share_tile(tile, [&](const Tile& t) {
                    for (int y = t.y0; y < t.y1; ++y)
                        for (int x = t.x0; x < t.x1; ++x)
                            for (int sample = 0; sample < spp; ++sample) {
                                const uint32_t slot = slot_of(tile, x, y, sample);
                                tile_hits[slot] = trace_sample(x, y, sample, slot, out);
                            }
                    gather_share_tile(t, hit_of, out, scratch, qs, tc);
                });
            } else {
                // Trace the tile, then group its hits by cell.
                std::vector<HitRecord> tile_hits(region_pixels(tile) * size_t(spp));
                std::vector<uint32_t> valid;
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x)
                        for (int sample = 0; sample < spp; ++sample) {
                            const uint32_t slot = slot_of(tile, x, y, sample);
                            const HitRecord& rec = tile_hits[slot] = trace_sample(x, y, sample, slot, out);
                            if (rec.valid)
                                valid.push_back(slot);
                            else
                                write_gather(out, slot, PhotonEstimate{});
                        }
                std::vector<SortItem> items = sort_items(tile_hits, valid);
                gather_sorted(tile_hits, items, 0, items.size(), out, scratch, qs, tc);
            }
            resolve(tile, tile, out);
            merge_counts(scratch, qs, tc);
        });
        frame_stats.add("fused_ms", watch.elapsed_ms());
    } else {
        // Pass 1: every sample's primary hit into a buffer (position, normal, direction,
        // material), the hits of all pixels at once.
        Stopwatch trace_watch;
        const Tile image{0, 0, width, height};
        const uint64_t samples = uint64_t(film.pixel_count()) * uint64_t(spp);
        if (samples > std::numeric_limits<uint32_t>::max())
            throw Error("photon", "setting 'spp' = " + std::to_string(spp) + " at " + std::to_string(width) + "x" +
                                      std::to_string(height) + " gives " + std::to_string(samples) +
                                      " samples, more than pass=split indexes (2^32 - 1); lower spp or use pass=fused");
        check_sample_memory(width, height, spp, sizeof(HitRecord) + sizeof(SortItem) + sizeof(uint32_t) + 2 * sizeof(Vec3),
                            "pass=split's buffer of every sample's hit", "photon");
        std::vector<HitRecord> hits(samples);
        SampleRadiance out(film.pixel_count(), spp);
        parallel_for_tiles(width, height, s.tile_size, [&](const Tile& tile) {
            for (int y = tile.y0; y < tile.y1; ++y)
                for (int x = tile.x0; x < tile.x1; ++x)
                    for (int sample = 0; sample < spp; ++sample) {
                        const uint32_t slot = slot_of(image, x, y, sample);
                        hits[slot] = trace_sample(x, y, sample, slot, out);
                    }
        });
        frame_stats.add("trace_pass_ms", trace_watch.elapsed_ms());
        Stopwatch gather_watch;
        if (s.gather_by_tiles) {
            // Pass 2 as the paper's gather kernel: one thread group per share tile.
            auto hit_of = [&](int x, int y, int sample) -> const HitRecord& { return hits[slot_of(image, x, y, sample)]; };
            parallel_for_tiles(width, height, s.share_tile, [&](const Tile& t) {
                GatherScratch scratch;
                PhotonQueryStats qs;
                TileShareCounts tc;
                gather_share_tile(t, hit_of, out, scratch, qs, tc);
                merge_counts(scratch, qs, tc);
            });
        } else {
            // Pass 2: gather in cell order for memory coherence, results written by slot.
            Stopwatch sort_watch;
            std::vector<uint32_t> valid;
            valid.reserve(hits.size());
            for (const HitRecord& h : hits) {
                if (h.valid)
                    valid.push_back(h.slot);
                else
                    write_gather(out, h.slot, PhotonEstimate{});
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
                for (size_t c = cb; c < ce; ++c) gather_sorted(hits, items, bounds[c], bounds[c + 1], out, scratch, qs, tc);
                merge_counts(scratch, qs, tc);
            });
        }
        parallel_for_tiles(width, height, s.tile_size, [&](const Tile& tile) { resolve(image, tile, out); });
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
