// The photon-mapping technique: split and tile-shared passes are bit-identical to the
// fused per-hit gather; the three photon maps agree; the indirect layer of the Cornell
// box matches the path tracer's; the white furnace gives the analytic indirect light;
// an empty photon map gives black indirect without NaN; bad settings are errors naming
// the key; images do not depend on the thread count.
#include <gtest/gtest.h>

#include <cstring>
#include "core/error.hpp"
#include "core/image_metrics.hpp"
#include "core/parallel.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"
#include "techniques/photon_mapping/photon_tracer.hpp"
#include "techniques/technique.hpp"

namespace gilab {
namespace {

Film render(const std::string& technique, const Scene& scene, const EyeCamera& camera, nlohmann::json settings_json,
            Stats* stats = nullptr) {
    auto t = TechniqueRegistry::builtin().create(technique);
    Settings settings(std::move(settings_json), "test settings");
    t->prepare(scene, settings);
    settings.report_unused();
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
            for (const char* gather : {"radius", "knn"}) {
                nlohmann::json s = with(kBase, {{"hash_query", query}, {"gather", gather}});
                Film per_hit = render("photon", scene, camera, s);
                for (const char* pass : {"fused", "split"}) {
                    Stats stats;
                    Film shared = render("photon", scene, camera, with(s, {{"pass", pass}, {"tile_shared", true}}), &stats);
                    expect_identical(per_hit, shared, std::string(query) + "/" + gather + "/" + pass);
                    // Groups must actually form, or the test compares nothing.
                    EXPECT_GT(stats.get("tile_groups"), 10.0) << pass;
                    EXPECT_GT(stats.get("tile_grouped_hits"), 2 * stats.get("tile_groups"));
                    EXPECT_GT(stats.get("tile_fetched_photons"), 0.0);
                }
            }
    }
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
    for (const char* gather : {"radius", "knn"}) {
        Film film = render("photon", scene, camera,
                           {{"photons", 200000}, {"radius", 0.1}, {"gather", gather}, {"k", 1 << 20},
                            {"max_photon_depth", 200}});
        const double expected = E * a * a / (1 - a);
        double got = mean_value(film, "indirect");
        std::printf("[furnace] indirect %.5f expected %.5f (%+.4f)\n", got, expected, got / expected - 1);
        EXPECT_NEAR(got, expected, 0.025 * expected);
        EXPECT_NEAR(mean_value(film, "direct"), E * (1 + a), 0.02 * E);
    }
    Film truncated = render("photon", scene, camera,
                            {{"photons", 200000}, {"radius", 0.1}, {"gather", "knn"}, {"k", 128}, {"max_photon_depth", 200}});
    EXPECT_LT(mean_value(truncated, "indirect"), 0.9 * E * a * a / (1 - a));
}

Scene black_box_with_point_light() {
    // A closed cube, all faces black (they absorb every photon at its first hit).
    Scene scene;
    scene.name = "black_box";
    Material black;
    black.albedo = Vec3(0.0f);
    scene.materials.push_back(black);
    Mesh mesh;
    mesh.name = "cube";
    for (int i = 0; i < 8; ++i) mesh.positions.push_back(Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
    const uint32_t quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (const auto& q : quads) {
        mesh.triangles.push_back({q[0], q[1], q[2]});
        mesh.triangles.push_back({q[0], q[2], q[3]});
    }
    mesh.material_ids.assign(mesh.triangles.size(), 0);
    scene.add_mesh_instance(std::move(mesh));
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
        {{{"gather", "heap"}}, "'gather'"},
        {{{"photon_map", "octree"}}, "photon_map"},
        {{{"hash_query", "cells9"}}, "hash_query"},
        {{{"pass", "hybrid"}}, "'pass'"},
        {{{"tile_shared", true}, {"photon_map", "kd_tree"}}, "'tile_shared'"},
        {{{"max_photon_depth", 0}}, "'max_photon_depth'"},
        {{{"light_samples", -1}}, "'light_samples'"},
        {{{"radius", "big"}}, "'radius'"},
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
                             with(kBase, {{"photon_map", "kd_tree"}, {"light_samples", 3}})}) {
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
