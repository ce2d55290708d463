// The right eye of a reusing stereo render: claims by the left eye's hits
// (stereo_reuse.hpp), then every right sample either composes the claiming hit's
// view-independent shading with its own glossy lobe, or is shaded as an independent eye
// (its own gather per hit; with every-hit storage the map's first-hit part is its direct
// light, as in the left eye). With spp samples per pixel the reuse runs per sample: sample
// s of the left pixels (one image-sized layer of hits) claims and fills sample s of the
// right pixels, and each right pixel averages its samples as the left eye does.
#include <mutex>
#include <optional>
#include "core/render/surface_material.hpp"
#include "core/render/interaction.hpp"
#include "core/util/parallel.hpp"
#include "core/util/rng.hpp"
#include "techniques/photon_mapping/photon_passes.hpp"

namespace gilab {

void PhotonMappingTechnique::render_right_reusing(const EyeCamera& left, const EyeCamera& right, const KeptHits& kept,
                                                  Film& film, PhotonQueryStats& query_stats, Stats& frame_stats) const {
    const PhotonMappingSettings& s = settings_;
    const int spp = s.sampling.spp;
    Stopwatch claim_watch;
    check_sample_memory(right.width(), right.height(), spp, sizeof(uint32_t), "the right eye's claims", "photon");
    std::vector<StereoClaims> claims;
    claims.reserve(size_t(spp));
    StereoClaimStats claim_stats;
    for (int sample = 0; sample < spp; ++sample) {
        claims.emplace_back(kept.layer(sample), left, right, scene_.tracer());
        claim_stats.merge(claims.back().stats());
    }
    frame_stats.add("claim_ms", claim_watch.elapsed_ms());

    Stopwatch right_watch;
    const int width = right.width();
    const PhotonGatherer gatherer(*map_, s.gather, size_t(s.k));
    const PrimaryShadingContext shading{scene_.tracer(), scene_.frame(), scene_.materials(), scene_.lights(),
                                        s.light_samples};
    float* direct = film.layer("direct").data.data();
    float* indirect = film.layer("indirect").data.data();
    float* reused_layer = film.add_layer("reused", 1).data.data();
    const Vec3 eye = right.position();
    const float right_spread = right.pixel_spread_angle();
    // Every-hit storage: direct light is the map's first-hit part, not the light samples.
    const bool map_direct = s.storage == PhotonStorage::EveryHit;
    std::mutex merge;
    std::atomic<uint64_t> nonfinite{0}, reused{0}, reshaded_glossy{0}, strict_rejected{0}, shaded{0}, filled{0};

    parallel_for_tiles(width, right.height(), s.tile_size, [&](const Tile& tile) {
        GatherScratch scratch;
        PhotonQueryStats qs;
        std::vector<LightSampleRecord> samples(shading.records_per_hit());
        std::vector<Vec3> sample_direct(static_cast<size_t>(spp)), sample_indirect(static_cast<size_t>(spp));
        uint64_t n_reused = 0, n_glossy = 0, n_rejected = 0, n_shaded = 0, n_filled = 0;
        for (int y = tile.y0; y < tile.y1; ++y)
            for (int x = tile.x0; x < tile.x1; ++x) {
                const uint32_t pixel = uint32_t(size_t(y) * size_t(width) + size_t(x));
                int pixel_reused = 0;
                for (int sample = 0; sample < spp; ++sample) {
                    const StereoClaims& layer = claims[size_t(sample)];
                    Vec3 Ld(0.0f), Li(0.0f);
                    uint32_t source = layer.source(pixel);  // a left pixel, its hit in this sample's layer
                    bool from_left = source != StereoClaims::kNone;
                    std::optional<SurfaceInteraction> own;  // the right sample's own hit, if traced
                    PrimaryHit mine;                          // and with its material resolved
                    if (!from_left || s.stereo.match == StereoMatch::Strict) {
                        const Vec2 at = Vec2(float(x), float(y)) + sample_offset(s.sampling, s.seed, pixel, sample, 1);
                        Ray ray = right.generate_ray(at.x, at.y);
                        Hit hit = scene_.tracer().intersect(ray);
                        if (hit.valid()) own = make_interaction(scene_.frame(), ray, hit);
                        if (own)
                            mine = primary_hit_of(*own, scene_.materials()[own->material],
                                                  cone_width(right_spread, hit.t * glm::length(ray.direction)));
                        if (from_left) {
                            from_left = same_surface_point(kept.hits[kept.slot(source, sample)], mine, right,
                                                           s.stereo.tolerance);
                            n_rejected += !from_left;
                        } else if (own && s.stereo.fill && s.stereo.match == StereoMatch::Nearest) {
                            source = crack_fill_source(layer, kept.layer(sample), mine, right, x, y);
                            from_left = source != StereoClaims::kNone;
                            n_filled += from_left;
                        }
                    }
                    if (from_left) {
                        const size_t k = kept.slot(source, sample);
                        const PrimaryHit& h = kept.hits[k];
                        const SurfaceMaterial& m = h.point.surface;
                        if (s.stereo.reshade && map_direct && !m.has_glossy_lobe()) {
                            // Every-hit storage, Lambertian: the left eye's light is view-independent.
                            Ld = kept.direct[k];
                            Li = kept.indirect[k];
                        } else if (s.stereo.reshade) {
                            // View-independent parts from the left eye; the glossy lobe for this eye.
                            const Vec3 wo = glm::normalize(eye - h.point.position);
                            Ld = direct_radiance(m, h, wo, kept.samples_of(k));
                            if (m.has_glossy_lobe()) {
                                GatherPoint p = h.point;
                                p.wo = wo;
                                const PhotonEstimate e = gatherer.estimate_parts(p, scratch, qs);
                                Li = e.indirect;
                                if (map_direct) Ld += e.direct;
                                ++n_glossy;
                            } else {
                                Li = kept.indirect[k];
                            }
                        } else {
                            Ld = kept.direct[k];
                            Li = kept.indirect[k];
                        }
                        ++n_reused;
                        ++pixel_reused;
                    } else if (own) {
                        // Nobody claimed it (or strict mode refused): shade it as an independent eye.
                        // `mine` holds the hit with its material resolved (the normal map already bent own's normal).
                        PrimaryHit ph = mine;
                        const SurfaceMaterial& m = ph.point.surface;
                        Rng rng = light_sample_stream(s.sampling, s.seed, &left, own->position, pixel, sample, 1);
                        sample_direct_light(shading, *own, rng, samples, ph);
                        Ld = direct_radiance(m, ph, own->wo, samples);
                        const PhotonEstimate e = gatherer.estimate_parts(ph.point, scratch, qs);
                        Li = e.indirect;
                        if (map_direct) Ld += e.direct;
                        ++n_shaded;
                    }
                    sample_direct[size_t(sample)] = finite_or_zero(Ld, nonfinite);
                    sample_indirect[size_t(sample)] = finite_or_zero(Li, nonfinite);
                }
                write_pixel(direct, pixel, sample_mean(sample_direct));
                write_pixel(indirect, pixel, sample_mean(sample_indirect));
                reused_layer[pixel] = float(pixel_reused) / float(spp);
            }
        reused += n_reused, reshaded_glossy += n_glossy, strict_rejected += n_rejected, shaded += n_shaded;
        filled += n_filled;
        std::lock_guard<std::mutex> lock(merge);
        query_stats.merge(qs);
    });
    float* color = film.layer("color").data.data();
    for (size_t i = 0; i < 3 * film.pixel_count(); ++i) color[i] = direct[i] + indirect[i];
    frame_stats.add("right_pass_ms", right_watch.elapsed_ms());
    frame_stats.set("reuse_left_hits", double(claim_stats.left_hits));
    frame_stats.set("reuse_back_side", double(claim_stats.back_side));
    frame_stats.set("reuse_outside", double(claim_stats.outside));
    frame_stats.set("reuse_occluded", double(claim_stats.occluded));
    frame_stats.set("reuse_candidates", double(claim_stats.candidates));
    frame_stats.set("reuse_claimed_pixels", double(claim_stats.claimed_pixels));
    frame_stats.set("reuse_depth_conflicts", double(claim_stats.depth_conflicts));
    frame_stats.set("reuse_strict_rejected", double(strict_rejected.load()));
    frame_stats.set("reused_pixels", double(reused.load()));
    frame_stats.set("reuse_crack_filled", double(filled.load()));
    // Of the right samples that show geometry (reused or shaded), the share reused.
    const double covered = double(reused.load() + shaded.load());
    frame_stats.set("reuse_fraction", covered > 0 ? double(reused.load()) / covered : 0.0);
    frame_stats.set("reuse_reshaded_glossy", double(reshaded_glossy.load()));
    frame_stats.set("right_shaded_pixels", double(shaded.load()));
    frame_stats.add("nonfinite_pixels", double(nonfinite.load()));
}

}  // namespace gilab
