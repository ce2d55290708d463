// The photon-mapping technique: split and tile-shared passes (paper tiles and cell
// groups) are bit-identical to the fused per-hit gather; paper tiles share only when all
// their hits lie in one cell; the three photon maps agree; the indirect layer of the
// Cornell box matches the path tracer's; the white furnace gives the analytic indirect
// light; every-hit storage adds a first-hit copy of every photon, splits direct from
// indirect light and agrees with shadow rays; an empty photon map gives black indirect
// without NaN; the gather radius is the photon map's; bad settings are errors naming the
// key; images do not depend on the thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include "core/util/error.hpp"
#include "core/image/image_metrics.hpp"
#include "core/util/parallel.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/procedural_meshes.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"
#include "techniques/photon_mapping/photon_tracer.hpp"
#include "techniques/photon_mapping/tile_share.hpp"
#include "techniques/technique.hpp"

namespace gilab {
namespace {

Film render(const std::string& technique, const Scene& scene, const EyeCamera& camera, nlohmann::json settings_json,
            Stats* stats = nullptr) {
    auto t = prepare_technique(technique, scene, Settings(std::move(settings_json), "test settings"));
    std::vector<Film> films;
    t->render(ViewSet::mono(camera), films);
    if (stats) *stats = t->stats();
    return films.at(0);
}

EyeCamera cornell_camera(const Scene& scene, int size) {
    const SceneCamera& c = *scene.camera;
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
}

bool identical(const Film& a, const Film& b, const std::string& layer) {
    const auto& x = a.layer(layer).data;
    const auto& y = b.layer(layer).data;
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
}

void expect_identical(const Film& a, const Film& b, const std::string& what) {
    for (const char* layer : {"color", "direct", "indirect"})
        EXPECT_TRUE(identical(a, b, layer)) << what << ": layer " << layer << " differs (max |Δ| "
                                            << max_abs_difference(a, b, layer) << ")";
}

// A Cornell box whose white surfaces also have a glossy lobe (exercises the per-photon
// BSDF path of the gather).
Scene glossy_cornell() {
    Scene scene = make_cornell_box();
    scene.materials[0].specular = Vec3(0.2f);
    scene.materials[0].phong_exponent = 20.0f;
    scene.materials[0].albedo *= 0.75f;
    return scene;
}

const nlohmann::json kBase = {{"photons", 128 * 128}, {"radius", 0.08}, {"k", 32}, {"tile_size", 8}, {"seed", 4}};

nlohmann::json with(nlohmann::json base, const nlohmann::json& extra) {
    for (auto it = extra.begin(); it != extra.end(); ++it) base[it.key()] = it.value();
    return base;
}

bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

TEST(PhotonMapping, SplitPassEqualsFusedBitForBit) {
    for (const Scene& scene : {make_cornell_box(), glossy_cornell()}) {
        EyeCamera camera = cornell_camera(scene, 40);
        for (const char* map : {"hash_grid", "kd_tree", "nanoflann"})
            for (const char* gather : {"radius", "knn"}) {
                nlohmann::json s = with(kBase, {{"photon_map", map}, {"gather", gather}});
                Stats fused_stats, split_stats;
                Film fused = render("photon", scene, camera, with(s, {{"pass", "fused"}}), &fused_stats);
                Film split = render("photon", scene, camera, with(s, {{"pass", "split"}}), &split_stats);
                expect_identical(fused, split, std::string(map) + "/" + gather);
                EXPECT_EQ(fused_stats.get("photons_visited"), split_stats.get("photons_visited"));
                EXPECT_GT(mean_value(fused, "indirect"), 0.0);
            }
    }
}

TEST(PhotonMapping, TileSharedGatherEqualsPerHitGather) {
    for (const Scene& scene : {make_cornell_box(), glossy_cornell()}) {
        EyeCamera camera = cornell_camera(scene, 48);
        for (const char* query : {"runs9", "cells27"})
            for (const char* gather : {"radius", "knn"})
                for (const char* storage : {"indirect", "every_hit"}) {
                    nlohmann::json s = with(kBase, {{"hash_query", query}, {"gather", gather}, {"photon_storage", storage}});
                    Film per_hit = render("photon", scene, camera, s);
                    for (const char* mode : {"paper", "cell_groups"}) {
                        Stats by_pass[2];
                        for (int split = 0; split < 2; ++split) {
                            const char* pass = split ? "split" : "fused";
                            const std::string what = std::string(query) + "/" + gather + "/" + storage + "/" + pass + "/" + mode;
                            Stats& stats = by_pass[split];
                            Film shared = render("photon", scene, camera,
                                                 with(s, {{"pass", pass}, {"tile_shared", mode}, {"share_tile", 2}}), &stats);
                            expect_identical(per_hit, shared, what);
                            // Groups must actually form, or the test compares nothing.
                            EXPECT_GT(stats.get("tile_fetched_photons"), 0.0) << what;
                            if (std::string(mode) == "paper") {
                                // Both branches of Algorithm 1 run: tiles in one cell and mixed tiles.
                                EXPECT_GT(stats.get("share_tiles_qualified"), 0.0) << what;
                                EXPECT_GT(stats.get("share_tiles_mixed"), 0.0) << what;
                                EXPECT_EQ(stats.get("tile_groups"), stats.get("share_tiles_qualified")) << what;
                                EXPECT_LE(stats.get("tile_grouped_hits"), 4 * stats.get("tile_groups")) << what;
                            } else {
                                EXPECT_GT(stats.get("tile_groups"), 10.0) << what;
                                EXPECT_GT(stats.get("tile_grouped_hits"), 2 * stats.get("tile_groups")) << what;
                                EXPECT_EQ(stats.get("share_tiles_qualified") + stats.get("share_tiles_mixed"), 0.0);
                            }
                        }
                        // Paper tiles are the same screen tiles in both passes.
                        if (std::string(mode) == "paper") {
                            for (const char* key : {"share_tiles_qualified", "share_tiles_mixed", "tile_groups",
                                                    "tile_grouped_hits", "tile_fetched_photons"}) {
                                EXPECT_EQ(by_pass[0].get(key), by_pass[1].get(key)) << key;
                            }
                        }
                    }
                }
    }
}

// Photons spread over [0, 1]³, all arriving from +z, in a hash grid of cell 0.1.
HashGridPhotonMap uniform_grid(float radius) {
    Rng rng(11, 0);
    std::vector<Photon> photons(20000);
    for (Photon& p : photons) {
        p.position = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
        p.power = Vec3(1e-3f, 2e-3f, 3e-3f) * (0.5f + rng.uniform());
        p.wi = PackedDirection::pack(Vec3(0, 0, 1));
        p.normal = p.wi;
        p.set_hit_index(rng.uniform() < 0.5f ? 1 : 2);
    }
    HashGridPhotonMap grid;
    grid.build(std::move(photons), radius);
    return grid;
}

// The split pass's per-hit gather may walk the hits sorted by cell or by screen tiles (the
// paper's kernel, what tile_shared=paper is timed against): the same image either way, and
// neither shares a fetch.
TEST(PhotonMapping, GatherOrderChangesNothingButTheWalk) {
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 48);
    for (const char* storage : {"indirect", "every_hit"}) {
        const nlohmann::json s = with(kBase, {{"pass", "split"}, {"photon_storage", storage}, {"share_tile", 4}});
        Stats by_cell, by_tiles;
        Film cell = render("photon", scene, camera, with(s, {{"gather_order", "cell"}}), &by_cell);
        Film tiles = render("photon", scene, camera, with(s, {{"gather_order", "tiles"}}), &by_tiles);
        expect_identical(cell, tiles, storage);
        EXPECT_EQ(by_cell.get("tile_groups") + by_tiles.get("tile_groups"), 0.0) << storage;
        EXPECT_EQ(by_cell.get("gather_queries"), by_tiles.get("gather_queries")) << storage;
    }
}

TEST(PhotonMapping, PaperTilesShareOnlyWhenEveryHitIsInOneCell) {
    // A hand-made 8×8 tile of gather points inside one hash cell (one pixel without a
    // hit), then the same tile with one point moved into the neighbouring cell.
    const float r = 0.1f;
    const HashGridPhotonMap grid = uniform_grid(r);
    const PhotonGatherer gatherer(grid, GatherMode::Radius, 32);
    const glm::ivec3 cell = grid.cell_of(Vec3(0.5f));
    auto point_in = [&](const glm::ivec3& c, Rng& rng) {
        GatherPoint p;
        const Vec3 u(0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform());
        p.position = grid.origin() + (Vec3(c) + u) * grid.cell_size();
        p.normal = p.wo = Vec3(0, 0, 1);
        return p;
    };
    Rng rng(5, 0);
    std::vector<GatherPoint> storage(64);
    for (GatherPoint& p : storage) p = point_in(cell, rng);
    std::vector<const GatherPoint*> tile(64);
    for (size_t i = 0; i < 64; ++i) tile[i] = i == 5 ? nullptr : &storage[i];
    for (const GatherPoint* p : tile) {
        if (p) {
            ASSERT_EQ(grid.cell_of(p->position), cell);
        }
    }

    auto check_per_hit = [&](const std::vector<const GatherPoint*>& points, const std::vector<PhotonEstimate>& out) {
        for (size_t i = 0; i < points.size(); ++i) {
            if (!points[i]) continue;
            GatherScratch scratch;
            PhotonQueryStats qs;
            const PhotonEstimate alone = gatherer.estimate_parts(*points[i], scratch, qs);
            EXPECT_TRUE(same_bits(alone.direct, out[i].direct) && same_bits(alone.indirect, out[i].indirect)) << i;
        }
    };
    {
        GatherScratch scratch;
        PhotonQueryStats qs;
        TileShareCounts counts;
        std::vector<PhotonEstimate> out(64);
        gather_tile_paper(gatherer, tile, out, scratch, qs, counts);
        EXPECT_EQ(counts.tiles_qualified, 1u);
        EXPECT_EQ(counts.tiles_mixed, 0u);
        EXPECT_EQ(counts.groups, 1u);
        EXPECT_EQ(counts.grouped_hits, 63u);
        EXPECT_GT(scratch.fetched, 0u);
        EXPECT_GT(max_component(out[0].direct), 0.0f);  // both parts are present in the map
        EXPECT_GT(max_component(out[0].indirect), 0.0f);
        check_per_hit(tile, out);
    }
    // One hit in the next cell along x.
    storage[17] = point_in(cell + glm::ivec3(1, 0, 0), rng);
    {
        GatherScratch scratch;
        PhotonQueryStats qs;
        TileShareCounts counts;
        std::vector<PhotonEstimate> out(64);
        gather_tile_paper(gatherer, tile, out, scratch, qs, counts);
        EXPECT_EQ(counts.tiles_qualified, 0u);
        EXPECT_EQ(counts.tiles_mixed, 1u);
        EXPECT_EQ(counts.groups, 0u);
        EXPECT_EQ(scratch.fetched, 0u) << "paper mode shares nothing in a mixed tile";
        EXPECT_EQ(qs.queries, 63u);
        check_per_hit(tile, out);
    }
    {
        // Cell groups still group the 62 hits that share the cell.
        std::vector<const GatherPoint*> points;
        for (const GatherPoint* p : tile)
            if (p) points.push_back(p);
        std::vector<size_t> order(points.size());
        for (size_t i = 0; i < order.size(); ++i) order[i] = i;
        auto key = [&](size_t i) { return gatherer.sort_key(points[i]->position, uint32_t(i)); };
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
        std::vector<uint64_t> keys;
        std::vector<const GatherPoint*> sorted;
        for (size_t i : order) keys.push_back(key(i)), sorted.push_back(points[i]);
        GatherScratch scratch;
        PhotonQueryStats qs;
        TileShareCounts counts;
        std::vector<PhotonEstimate> out(sorted.size());
        gather_cell_groups(gatherer, keys, sorted, out, scratch, qs, counts);
        EXPECT_EQ(counts.groups, 1u);
        EXPECT_EQ(counts.grouped_hits, 62u);
        EXPECT_GT(scratch.fetched, 0u);
        check_per_hit(sorted, out);
    }
    {
        // A tile without hits is neither qualified nor mixed.
        GatherScratch scratch;
        PhotonQueryStats qs;
        TileShareCounts counts;
        std::vector<const GatherPoint*> empty(64, nullptr);
        std::vector<PhotonEstimate> out(64);
        gather_tile_paper(gatherer, empty, out, scratch, qs, counts);
        EXPECT_EQ(counts.tiles_qualified + counts.tiles_mixed + counts.groups + qs.queries, 0u);
    }
}

// The gather radius is the photon map's: the one it was built for, which a map built
// without one (a tree queried at radii of its own) does not have.
TEST(PhotonMapping, GatherRadiusIsTheMaps) {
    const HashGridPhotonMap grid = uniform_grid(0.1f);
    EXPECT_EQ(PhotonGatherer(grid, GatherMode::Radius, 32).radius(), 0.1f);
    KdTreePhotonMap tree;
    tree.build({}, 0.05f);
    EXPECT_EQ(PhotonGatherer(tree, GatherMode::Knn, 32).radius(), 0.05f);
    tree.build({});
    EXPECT_THROW(PhotonGatherer(tree, GatherMode::Radius, 32), Error);
}

TEST(PhotonMapping, TileSharedSettingReadsOldBooleans) {
    auto mode = [](const nlohmann::json& value) {
        return PhotonMappingSettings::from(Settings(nlohmann::json{{"tile_shared", value}})).tile_shared;
    };
    EXPECT_EQ(PhotonMappingSettings::from(Settings()).tile_shared, TileShare::Off);
    EXPECT_EQ(PhotonMappingSettings::from(Settings()).share_tile, 8);
    EXPECT_EQ(mode(false), TileShare::Off);
    EXPECT_EQ(mode(true), TileShare::CellGroups);
    EXPECT_EQ(mode("off"), TileShare::Off);
    EXPECT_EQ(mode("paper"), TileShare::Paper);
    EXPECT_EQ(mode("cell_groups"), TileShare::CellGroups);
    // And from the command line's key=value form.
    Settings cli;
    cli.set_from_string("tile_shared=true");
    EXPECT_EQ(PhotonMappingSettings::from(cli).tile_shared, TileShare::CellGroups);
    cli.set_from_string("tile_shared=paper");
    EXPECT_EQ(PhotonMappingSettings::from(cli).tile_shared, TileShare::Paper);
}

TEST(PhotonMapping, PhotonMapsGiveTheSameImage) {
    // Same photons and the same photon sets per pixel; only the summation order differs
    // (trees visit in traversal order, the grid in lanes), so agreement is to rounding.
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 32);
    for (const char* gather : {"radius", "knn"}) {
        nlohmann::json s = with(kBase, {{"gather", gather}});
        Stats grid_stats, kd_stats, nano_stats;
        Film grid = render("photon", scene, camera, with(s, {{"photon_map", "hash_grid"}}), &grid_stats);
        Film kd = render("photon", scene, camera, with(s, {{"photon_map", "kd_tree"}}), &kd_stats);
        Film nano = render("photon", scene, camera, with(s, {{"photon_map", "nanoflann"}}), &nano_stats);
        double scale = mean_value(grid, "indirect");
        EXPECT_LT(max_abs_difference(grid, kd, "indirect"), 1e-4 * scale * 100) << gather;
        EXPECT_LT(max_abs_difference(grid, nano, "indirect"), 1e-4 * scale * 100) << gather;
        EXPECT_NEAR(mean_value(grid, "indirect"), mean_value(kd, "indirect"), 1e-5 * scale);
        EXPECT_NEAR(mean_value(grid, "indirect"), mean_value(nano, "indirect"), 1e-5 * scale);
        EXPECT_TRUE(identical(grid, kd, "direct"));
        // The grid examines more photons than it keeps (27 cells ⊃ the sphere).
        EXPECT_LT(grid_stats.get("inside_fraction"), 0.6);
        if (std::string(gather) == "radius") {  // (kNN: the trees' shrinking radius skips photons)
            EXPECT_EQ(grid_stats.get("photons_inside"), kd_stats.get("photons_inside"));
            EXPECT_EQ(grid_stats.get("photons_inside"), nano_stats.get("photons_inside"));
        } else {
            EXPECT_LT(kd_stats.get("photons_visited"), grid_stats.get("photons_visited"));
        }
    }
}

TEST(PhotonMapping, CornellIndirectMatchesThePathTracer) {
    // Tolerance 4 % on the image mean of the indirect layer, 256² photons, r = 0.05. The
    // disk estimator loses area where the disk crosses an edge of the box or a block
    // (bias ≈ −2 % at r = 0.05, growing with r; ≈ −0.5 % at r = 0.02 with 512² photons),
    // photon noise in the image mean is < 0.5 % and the reference's (64², 512 spp) about
    // 0.3 %. A wrong flux normalisation (albedo, 1/N, roulette weight) or storing the
    // first hit (direct light counted twice) is off by 20 % or more.
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 64);
    Film reference = render("path", scene, camera, {{"spp", 512}, {"seed", 3}, {"jitter", false}});
    Film pm = render("photon", scene, camera, {{"photons", 256 * 256}, {"radius", 0.05}, {"light_samples", 8}});
    const double ref = mean_value(reference, "indirect"), got = mean_value(pm, "indirect");
    const double rel = got / ref - 1.0;
    std::printf("[cornell] indirect mean: photon %.5f, path %.5f, relative error %+.4f; relMSE %.4f\n", got, ref, rel,
                relative_mse(pm, reference, "indirect"));
    EXPECT_LT(std::abs(rel), 0.04);
    // Direct light uses the same estimator in both (shadow rays at pixel centres).
    EXPECT_NEAR(mean_value(pm, "direct") / mean_value(reference, "direct"), 1.0, 0.02);
    EXPECT_LT(relative_mse(pm, reference, "indirect"), 0.05);
}

TEST(PhotonMapping, WhiteFurnaceIndirectIsAnalytic) {
    // Inside a closed sphere with albedo a emitting E everywhere, light that bounced at
    // least once arrives as E·a²/(1 − a). On a sphere the points within distance r of a
    // surface point cover exactly π r² (Archimedes), so the disk estimator has no edge
    // bias; roulette keeps the flux unbiased. Tolerance 2.5 % (photon noise ≈ 0.5 %,
    // faceting of the icosphere ≈ 1 %).
    const float a = 0.5f, E = 1.0f;
    Scene scene = make_furnace_sphere(a, E, 3);
    EyeCamera camera = EyeCamera::look_at(Vec3(0), Vec3(0, 0, -1), Vec3(0, 1, 0), 90.0f, 24, 24);
    // The kNN gather keeps the k nearest photons in the disk and divides by the disk's
    // area (the paper's heap, Table 2): with k above any disk's photon count it must give
    // the radius estimate; with the paper's k = 128 it drops photons and comes out darker.
    // With every-hit storage the direct layer is emission + the first-hit photons'
    // estimate, E + E·a, with the same tolerance as the indirect light.
    for (const char* storage : {"indirect", "every_hit"})
        for (const char* gather : {"radius", "knn"}) {
            Film film = render("photon", scene, camera,
                               {{"photons", 200000}, {"radius", 0.1}, {"gather", gather}, {"k", 1 << 20},
                                {"max_photon_depth", 200}, {"photon_storage", storage}});
            const double expected = E * a * a / (1 - a);
            double got = mean_value(film, "indirect");
            const double direct = mean_value(film, "direct");
            std::printf("[furnace %s] indirect %.5f expected %.5f (%+.4f); direct %.5f expected %.5f\n", storage, got,
                        expected, got / expected - 1, direct, E * (1 + a));
            EXPECT_NEAR(got, expected, 0.025 * expected);
            EXPECT_NEAR(direct, E * (1 + a), (std::string(storage) == "every_hit" ? 0.025 : 0.02) * E * (1 + a));
        }
    Film truncated = render("photon", scene, camera,
                            {{"photons", 200000}, {"radius", 0.1}, {"gather", "knn"}, {"k", 128}, {"max_photon_depth", 200}});
    EXPECT_LT(mean_value(truncated, "indirect"), 0.9 * E * a * a / (1 - a));
}

TEST(PhotonMapping, EveryHitStoresACopyAtTheFirstHit) {
    // Same seed, same photon paths: every-hit storage keeps the indirect map's photons and
    // adds one copy per photon that reached a surface. Counted independently by tracing
    // the same photons to their first hit only; in a closed sphere every photon hits.
    auto prepared = [](const Scene& scene, const std::string& storage) {
        const Settings s(nlohmann::json{{"photons", 20000}, {"seed", 4}, {"photon_storage", storage}});
        return prepare_technique("photon", scene, s);
    };
    auto first_hits = [](const Scene& scene) {
        SceneFrame frame = scene.evaluate(0);
        RayTracer tracer(frame);
        LightSampler lights(frame, scene.materials);
        PhotonTraceSettings ts;
        ts.emitted = 20000;
        ts.seed = 4;
        ts.max_depth = 1;
        ts.first_stored_hit = 1;
        return double(trace_photons(tracer, frame, scene.materials, lights, ts).photons.size());
    };
    for (const Scene& scene : {make_cornell_box(), make_furnace_sphere(0.5f, 1.0f, 2)}) {
        auto indirect = prepared(scene, "indirect");
        auto every = prepared(scene, "every_hit");
        const double expected_first = first_hits(scene);
        const Stats a = indirect->stats(), b = every->stats();
        EXPECT_GT(b.get("photons_stored"), a.get("photons_stored")) << scene.name;
        EXPECT_EQ(b.get("photons_stored"), a.get("photons_stored") + expected_first) << scene.name;
        EXPECT_EQ(b.get("photons_stored_first_hit"), expected_first) << scene.name;
        EXPECT_EQ(a.get("photons_stored_first_hit"), 0.0) << scene.name;
        // The map itself: first-hit copies tagged as such, the rest from the second hit on.
        const PhotonMap& map = dynamic_cast<const PhotonMappingTechnique&>(*every).photon_map();
        double tagged_first = 0, untagged = 0;
        for (uint32_t i = 0; i < map.size(); ++i) {
            tagged_first += map.photon(i).hit_index() == 1;
            untagged += map.photon(i).hit_index() < 1;
        }
        EXPECT_EQ(tagged_first, expected_first) << scene.name;
        EXPECT_EQ(untagged, 0.0) << scene.name;
        if (scene.name != "cornell") {
            EXPECT_EQ(expected_first, 20000.0) << "every photon hits the closed sphere";
        } else {
            EXPECT_GT(expected_first, 10000.0);
        }
    }
}

TEST(PhotonMapping, EveryHitStorageAgreesWithShadowRays) {
    // Cornell box, 256² photons, r = 0.05. The later-hit photons are the same photons in
    // both modes (same seed, same paths), so the indirect layers agree to rounding (the
    // lanes of the sum differ once first-hit photons sit between them). Direct light by
    // density estimation agrees with 16 shadow rays per pixel in the image mean within
    // 4 %: the disk estimator's bias at edges and corners is a few per cent at r = 0.05
    // (as for the indirect light), photon noise in the mean is < 0.5 % and the shadow
    // rays' < 0.5 %. Counting the first hit twice or dropping it would be off by 50 % or
    // more.
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 48);
    const nlohmann::json base = {{"photons", 256 * 256}, {"radius", 0.05}, {"seed", 2}};
    Film rays = render("photon", scene, camera, with(base, {{"light_samples", 16}}));
    Film map = render("photon", scene, camera, with(base, {{"photon_storage", "every_hit"}}));
    const double indirect = mean_value(rays, "indirect");
    EXPECT_LT(max_abs_difference(rays, map, "indirect"), 1e-4 * indirect);
    EXPECT_NEAR(mean_value(map, "indirect") / indirect, 1.0, 1e-5);
    const double direct_rays = mean_value(rays, "direct"), direct_map = mean_value(map, "direct");
    const double color_rays = mean_value(rays, "color"), color_map = mean_value(map, "color");
    std::printf("[cornell] direct: shadow rays %.5f, photon map %.5f (%+.4f); color %+.4f; relMSE(direct) %.4f\n",
                direct_rays, direct_map, direct_map / direct_rays - 1, color_map / color_rays - 1,
                relative_mse(map, rays, "direct"));
    EXPECT_NEAR(direct_map / direct_rays, 1.0, 0.04);
    EXPECT_NEAR(color_map / color_rays, 1.0, 0.04);
    // Per pixel too, the map's direct light is a noisy but unbiased copy, not another image.
    EXPECT_LT(relative_mse(map, rays, "direct"), 0.1);
}

TEST(PhotonMapping, EveryHitColorIsDirectPlusIndirect) {
    Scene scene = glossy_cornell();
    EyeCamera camera = cornell_camera(scene, 32);
    for (const char* map : {"hash_grid", "kd_tree", "nanoflann"})
        for (const char* gather : {"radius", "knn"})
            for (const char* pass : {"fused", "split"}) {
                const std::string what = std::string(map) + "/" + gather + "/" + pass;
                Film film = render("photon", scene, camera,
                                   with(kBase, {{"photon_map", map}, {"gather", gather}, {"pass", pass},
                                                {"photon_storage", "every_hit"}}));
                const auto &c = film.layer("color").data, &d = film.layer("direct").data,
                           &i = film.layer("indirect").data;
                size_t bad = 0;
                for (size_t k = 0; k < c.size(); ++k) bad += c[k] != d[k] + i[k];
                EXPECT_EQ(bad, 0u) << what;
                EXPECT_GT(mean_value(film, "direct"), 0.0) << what;
                EXPECT_GT(mean_value(film, "indirect"), 0.0) << what;
            }
    // No shadow rays: with a single photon emitted, almost no pixel has direct light
    // beyond what it emits, where one shadow ray per pixel lights most of the image.
    auto lit_pixels = [&](const nlohmann::json& s) {
        Film film = render("photon", scene, camera, s);
        size_t lit = 0;
        for (int y = 0; y < film.height(); ++y)
            for (int x = 0; x < film.width(); ++x) {
                const Vec3 d = film.get("direct", x, y);
                lit += max_component(d) > 0.0f && max_component(d) < 5.0f;  // (the light's own pixels are brighter)
            }
        return double(lit) / double(film.pixel_count());
    };
    EXPECT_LT(lit_pixels({{"photons", 1}, {"radius", 0.05}, {"photon_storage", "every_hit"}}), 0.05);
    EXPECT_GT(lit_pixels({{"photons", 1}, {"radius", 0.05}}), 0.5);
}

Scene black_box_with_point_light() {
    // A closed cube, all faces black (they absorb every photon at its first hit).
    Scene scene;
    scene.name = "black_box";
    Material black;
    black.albedo = Vec3(0.0f);
    scene.materials.push_back(black);
    scene.add_mesh_instance(make_box("cube", Vec3(-1), Vec3(1), 0));
    PunctualLight light;
    light.position = Vec3(0.2f, 0.3f, 0.1f);
    light.intensity = Vec3(5.0f);
    scene.lights.push_back(light);
    return scene;
}

TEST(PhotonMapping, EmptyPhotonMapGivesBlackIndirectWithoutNaN) {
    Scene scene = black_box_with_point_light();
    EyeCamera camera = EyeCamera::look_at(Vec3(0), Vec3(0, 0, -1), Vec3(0, 1, 0), 90.0f, 16, 16);
    for (const char* map : {"hash_grid", "kd_tree", "nanoflann"})
        for (const char* gather : {"radius", "knn"})
            for (const char* pass : {"fused", "split"}) {
                Stats stats;
                nlohmann::json s = {{"photon_map", map}, {"gather", gather}, {"pass", pass}, {"photons", 4096}};
                if (std::string(map) == "hash_grid") s["tile_shared"] = true;
                Film film = render("photon", scene, camera, s, &stats);
                EXPECT_EQ(stats.get("photons_stored"), 0.0);
                EXPECT_GT(stats.get("photon_rays"), 0.0);  // photons were traced, none stored
                for (const char* layer : {"color", "direct", "indirect"})
                    for (float v : film.layer(layer).data) ASSERT_TRUE(std::isfinite(v)) << layer;
                for (float v : film.layer("indirect").data) ASSERT_EQ(v, 0.0f);
                EXPECT_EQ(stats.get("nonfinite_pixels"), 0.0);
            }
    // Cornell box with photons stopped at their first hit: nothing stored either.
    Scene cornell = make_cornell_box();
    Stats stats;
    Film film = render("photon", cornell, cornell_camera(cornell, 16), {{"max_photon_depth", 1}, {"photons", 1024}}, &stats);
    EXPECT_EQ(stats.get("photons_stored"), 0.0);
    EXPECT_EQ(mean_value(film, "indirect"), 0.0);
    EXPECT_GT(mean_value(film, "direct"), 0.0);
}

TEST(PhotonMapping, BadSettingsAreErrorsNamingTheKey) {
    Scene scene = make_cornell_box();
    auto technique = TechniqueRegistry::builtin().create("photon");
    const std::pair<nlohmann::json, const char*> cases[] = {
        {{{"radius", 0.0}}, "'radius'"},
        {{{"radius", -0.1}}, "'radius'"},
        {{{"k", 0}}, "'k'"},
        {{{"k", 0}, {"gather", "knn"}}, "'k'"},
        {{{"photons", 0}}, "'photons'"},
        {{{"photons", 1e12}}, "'photons'"},  // beyond any memory budget: refused before tracing
        {{{"photons", 1e19}}, "'photons'"},  // beyond 64 bits: no longer wraps to a negative count
        {{{"photons", 2.5}}, "'photons'"},
        {{{"gather", "heap"}}, "'gather'"},
        {{{"photon_map", "octree"}}, "photon_map"},
        {{{"hash_query", "cells9"}}, "hash_query"},
        {{{"pass", "hybrid"}}, "'pass'"},
        {{{"gather_order", "morton"}, {"pass", "split"}}, "'gather_order'"},
        {{{"gather_order", "tiles"}}, "'gather_order'"},  // pass=fused has no gather pass to order
        {{{"gather_order", "cell"}, {"pass", "split"}, {"tile_shared", "paper"}}, "gather_order=tiles"},
        {{{"gather_order", "tiles"}, {"pass", "split"}, {"tile_shared", "cell_groups"}}, "gather_order=cell"},
        {{{"tile_shared", true}, {"photon_map", "kd_tree"}}, "'tile_shared'"},
        {{{"max_photon_depth", 0}}, "'max_photon_depth'"},
        {{{"light_samples", -1}}, "'light_samples'"},
        {{{"radius", "big"}}, "'radius'"},
        {{{"photon_storage", "all"}}, "'photon_storage'"},
        {{{"photon_storage", "every_hit"}, {"light_samples", 1}}, "'light_samples'"},
        {{{"tile_shared", "yes"}}, "'tile_shared'"},
        {{{"tile_shared", 1}}, "'tile_shared'"},
        {{{"tile_shared", "paper"}, {"photon_map", "nanoflann"}}, "'tile_shared'"},
        {{{"share_tile", 0}}, "'share_tile'"},
        {{{"tile_shared", "paper"}, {"tile_size", 12}, {"share_tile", 8}}, "share_tile"},
    };
    for (const auto& [bad, key] : cases) {
        try {
            technique->prepare(scene, Settings(bad, "photon settings"));
            FAIL() << "accepted " << bad.dump();
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("photon settings"), std::string::npos) << e.what();
        }
    }
    Settings misspelt(nlohmann::json{{"radius", 0.1}, {"photon_count", 5}}, "photon settings");
    technique->prepare(scene, misspelt);
    EXPECT_THROW(misspelt.report_unused(), Error);
    std::vector<Film> films;
    EXPECT_THROW(TechniqueRegistry::builtin().create("photon")->render(ViewSet::mono(cornell_camera(scene, 4)), films),
                 Error);
}

TEST(PhotonMapping, IdenticalAtAnyThreadCount) {
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 32);
    for (nlohmann::json s : {with(kBase, {}), with(kBase, {{"pass", "split"}, {"tile_shared", true}, {"gather", "knn"}}),
                             with(kBase, {{"photon_map", "kd_tree"}, {"light_samples", 3}}),
                             with(kBase, {{"photon_storage", "every_hit"}, {"tile_shared", "paper"}, {"share_tile", 4}}),
                             with(kBase, {{"photon_storage", "every_hit"}, {"pass", "split"}, {"tile_shared", "paper"}})}) {
        Film one, two;
        Stats one_stats, two_stats;
        {
            ThreadLimit limit(1);
            one = render("photon", scene, camera, s, &one_stats);
        }
        {
            ThreadLimit limit(2);
            two = render("photon", scene, camera, s, &two_stats);
        }
        expect_identical(one, two, s.dump());
        EXPECT_EQ(one_stats.get("photons_stored"), two_stats.get("photons_stored"));
    }
    // The photon tracer itself: same photons in the same order.
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer(frame);
    LightSampler lights(frame, scene.materials);
    PhotonTraceSettings ts;
    ts.emitted = 5000;
    PhotonTraceResult a, b;
    {
        ThreadLimit limit(1);
        a = trace_photons(tracer, frame, scene.materials, lights, ts);
    }
    {
        ThreadLimit limit(2);
        b = trace_photons(tracer, frame, scene.materials, lights, ts);
    }
    ASSERT_EQ(a.photons.size(), b.photons.size());
    EXPECT_EQ(std::memcmp(a.photons.data(), b.photons.data(), a.photons.size() * sizeof(Photon)), 0);
}

TEST(PhotonMapping, PhotonsCarryTheLightsPowerAndBounce) {
    // Inside a closed sphere every photon hits: the photons stored at first hits carry
    // the total emitted power. In the Cornell box every stored photon lies on the box.
    Scene sphere = make_furnace_sphere(0.5f, 2.0f, 2);
    SceneFrame frame = sphere.evaluate(0);
    RayTracer tracer(frame);
    LightSampler lights(frame, sphere.materials);
    PhotonTraceSettings ts;
    ts.emitted = 20000;
    ts.first_stored_hit = 1;
    ts.max_depth = 1;
    PhotonTraceResult first = trace_photons(tracer, frame, sphere.materials, lights, ts);
    Vec3 total(0.0f);
    for (const Photon& p : first.photons) total += p.power;
    EXPECT_EQ(first.photons.size(), ts.emitted);
    EXPECT_NEAR((total.x + total.y + total.z) / 3.0f / lights.total_power(), 1.0, 1e-3);
    // Second hits: roulette with survival a = 0.5 keeps the expected stored power at a·Φ.
    ts.first_stored_hit = 2;
    ts.max_depth = 2;
    PhotonTraceResult second = trace_photons(tracer, frame, sphere.materials, lights, ts);
    Vec3 bounced(0.0f);
    for (const Photon& p : second.photons) bounced += p.power;
    EXPECT_NEAR(bounced.x / total.x, 0.5, 0.02);
    EXPECT_NEAR(double(second.photons.size()) / double(ts.emitted), 0.5, 0.02);

    Scene scene = make_cornell_box();
    SceneFrame cornell = scene.evaluate(0);
    RayTracer cornell_tracer(cornell);
    LightSampler cornell_lights(cornell, scene.materials);
    ts.max_depth = 8;
    PhotonTraceResult indirect = trace_photons(cornell_tracer, cornell, scene.materials, cornell_lights, ts);
    EXPECT_GT(indirect.photons.size(), ts.emitted / 2);
    Bounds3 box = cornell.bounds;
    for (const Photon& p : indirect.photons) {
        ASSERT_TRUE(box.contains(p.position + 1e-4f * (box.center() - p.position)));
        ASSERT_GT(max_component(p.power), 0.0f);
    }
}

TEST(PhotonMapping, IsRegistered) {
    auto t = TechniqueRegistry::builtin().create("photon");
    EXPECT_EQ(t->name(), "photon");
    PhotonMappingSettings d = PhotonMappingSettings::from(Settings());
    EXPECT_EQ(d.photons, 65536u);
    EXPECT_FLOAT_EQ(d.radius, 0.05f);
    EXPECT_EQ(d.k, 128);
    EXPECT_EQ(d.photon_map, PhotonMapKind::HashGrid);
    EXPECT_EQ(d.gather, GatherMode::Radius);
    EXPECT_FALSE(d.split);
}

}  // namespace
}  // namespace gilab
