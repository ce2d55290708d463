// Pixel samples (spp, jitter) of the photon technique: one sample without jitter — the
// default — is the one-ray-per-pixel image, bit for bit, and equals a reference computed
// here from the technique's parts; spp samples follow the path tracer's random-number
// scheme, draw their own light samples, gather from the one photon map and average into
// every layer (color = direct + indirect still); every pass, gather and sharing mode
// gives the same image, at any thread count; stereo reuse and foveation work per sample;
// jittered samples lower the error at geometric edges against a path-traced reference;
// the settings are checked and recorded.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include "core/util/error.hpp"
#include "core/scene/hmd.hpp"
#include "core/image/image_metrics.hpp"
#include "core/render/interaction.hpp"
#include "core/render/surface_material.hpp"
#include "core/render/light_sampler.hpp"
#include "core/util/parallel.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/util/rng.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"
#include "techniques/photon_mapping/primary_hit.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

const nlohmann::json kBase = {{"photons", 128 * 128}, {"radius", 0.08}, {"tile_size", 8}, {"seed", 4}, {"light_samples", 2}};

nlohmann::json with(nlohmann::json base, const nlohmann::json& extra) {
    for (auto it = extra.begin(); it != extra.end(); ++it) base[it.key()] = it.value();
    return base;
}

// The same settings with P1's photon map: direct light from first-hit photons, no light samples.
nlohmann::json every_hit(nlohmann::json base) {
    base.erase("light_samples");
    base["photon_storage"] = "every_hit";
    return base;
}

std::vector<Film> render_views(const Scene& scene, const ViewSet& views, const nlohmann::json& settings_json,
                               Stats* stats = nullptr) {
    PhotonMappingTechnique t;
    prepare_technique(t, scene, Settings(settings_json, "test settings"));
    std::vector<Film> films;
    t.render(views, films);
    if (stats) *stats = t.stats();
    return films;
}

Film render(const Scene& scene, const EyeCamera& camera, const nlohmann::json& settings, Stats* stats = nullptr) {
    return render_views(scene, ViewSet::mono(camera), settings, stats).at(0);
}

EyeCamera cornell_camera(const Scene& scene, int size) {
    const SceneCamera& c = *scene.camera;
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
}

ViewSet stereo_views(const Scene& scene, int width, int height) {
    HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
    rig.set_resolution(width, height);
    return ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
}

// A Cornell box whose white surfaces also have a glossy lobe (the glossy shading and
// the stereo reshading run too).
Scene glossy_cornell() {
    Scene scene = make_cornell_box();
    scene.materials[0].specular = Vec3(0.2f);
    scene.materials[0].phong_exponent = 20.0f;
    scene.materials[0].albedo *= 0.75f;
    return scene;
}

bool identical(const Film& a, const Film& b, const std::string& layer) {
    const auto& x = a.layer(layer).data;
    const auto& y = b.layer(layer).data;
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
}

void expect_identical(const Film& a, const Film& b, const std::string& what) {
    for (const char* layer : {"color", "direct", "indirect", "reused"}) {
        if (!a.has_layer(layer) && !b.has_layer(layer)) continue;
        ASSERT_TRUE(a.has_layer(layer) && b.has_layer(layer)) << what << ": layer " << layer;
        EXPECT_TRUE(identical(a, b, layer)) << what << ": layer " << layer << " differs (max |Δ| "
                                            << max_abs_difference(a, b, layer) << ")";
    }
}

// Pixels where color ≠ direct + indirect (bit for bit).
size_t color_mismatches(const Film& film) {
    const auto &c = film.layer("color").data, &d = film.layer("direct").data, &i = film.layer("indirect").data;
    size_t bad = 0;
    for (size_t k = 0; k < c.size(); ++k) bad += c[k] != d[k] + i[k];
    return bad;
}

// The technique's image as documented, computed here from its parts (indirect storage,
// mono view): sample s of pixel p looks through the first two numbers of
// Rng::for_sample(seed, p, s, 0) (or the pixel centre without jitter), draws its light
// samples from the rest of that stream and gathers from the technique's photon map; a
// pixel is the mean of its samples, summed in double precision.
struct ExpectedImage {
    std::vector<Vec3> direct, indirect;
};

ExpectedImage expected_image(const Scene& scene, const EyeCamera& camera, const nlohmann::json& settings_json) {
    PhotonMappingTechnique t;
    prepare_technique(t, scene, Settings(settings_json));
    const PhotonMappingSettings& s = t.settings();
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    const LightSampler lights(frame, scene.materials);
    const PhotonGatherer gatherer(t.photon_map(), s.gather, size_t(s.k));
    const PrimaryShadingContext shading{tracer, frame, scene.materials, lights, s.light_samples};
    ExpectedImage out;
    for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
            const uint32_t pixel = uint32_t(y * camera.width() + x);
            DVec3 direct(0.0), indirect(0.0);
            for (int k = 0; k < s.sampling.spp; ++k) {
                Rng rng = Rng::for_sample(s.seed, pixel, uint64_t(k), 0);
                const Vec2 at = s.sampling.jitter ? rng.uniform2() : Vec2(0.5f);
                const Ray ray = camera.generate_ray(float(x) + at.x, float(y) + at.y);
                const Hit hit = tracer.intersect(ray);
                if (!hit.valid()) continue;
                SurfaceInteraction si = make_interaction(frame, ray, hit);
                PrimaryHit ph = primary_hit_of(si, scene.materials[si.material],
                                               cone_width(camera.pixel_spread_angle(), hit.t * glm::length(ray.direction)));
                const SurfaceMaterial& m = ph.point.surface;
                std::vector<LightSampleRecord> samples(shading.records_per_hit());
                sample_direct_light(shading, si, rng, samples, ph);
                direct += DVec3(direct_radiance(m, ph, si.wo, samples));
                GatherScratch scratch;
                PhotonQueryStats qs;
                indirect += DVec3(gatherer.estimate_parts(ph.point, scratch, qs).indirect);
            }
            out.direct.push_back(Vec3(direct * (1.0 / s.sampling.spp)));
            out.indirect.push_back(Vec3(indirect * (1.0 / s.sampling.spp)));
        }
    return out;
}

void expect_matches(const Film& film, const ExpectedImage& expected, const std::string& what) {
    size_t direct_bad = 0, indirect_bad = 0;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            const size_t i = size_t(y * film.width() + x);
            direct_bad += film.get("direct", x, y) != expected.direct[i];
            indirect_bad += film.get("indirect", x, y) != expected.indirect[i];
        }
    EXPECT_EQ(direct_bad, 0u) << what << ": direct layer";
    EXPECT_EQ(indirect_bad, 0u) << what << ": indirect layer";
}

TEST(PhotonSpp, OneSampleIsTheOneRayPerPixelImage) {
    // Without spp, with spp = 1 and with spp = 1, jitter = false: the same bits in every mode.
    const Scene scene = glossy_cornell();
    const EyeCamera camera = cornell_camera(scene, 24);
    const ViewSet stereo = stereo_views(scene, 24, 26);
    for (const nlohmann::json& base : {kBase, every_hit(kBase)})
        for (const nlohmann::json& mode :
             {nlohmann::json::object(), nlohmann::json{{"pass", "split"}},
              nlohmann::json{{"tile_shared", "paper"}, {"share_tile", 4}},
              nlohmann::json{{"pass", "split"}, {"tile_shared", "cell_groups"}}}) {
            const nlohmann::json s = with(base, mode);
            const Film plain = render(scene, camera, s);
            expect_identical(plain, render(scene, camera, with(s, {{"spp", 1}})), "spp=1 " + s.dump());
            expect_identical(plain, render(scene, camera, with(s, {{"spp", 1}, {"jitter", false}})), "jitter=false " + s.dump());
            const nlohmann::json reuse = with(s, {{"stereo_reuse", true}});
            const std::vector<Film> a = render_views(scene, stereo, reuse);
            const std::vector<Film> b = render_views(scene, stereo, with(reuse, {{"spp", 1}, {"jitter", false}}));
            for (size_t v = 0; v < 2; ++v) expect_identical(a[v], b[v], "stereo " + reuse.dump());
        }
    // Jitter is what the default leaves off: a jittered single sample is another image.
    const Film plain = render(scene, camera, kBase);
    EXPECT_FALSE(identical(plain, render(scene, camera, with(kBase, {{"jitter", true}})), "color"));
}

TEST(PhotonSpp, DefaultImageEqualsTheCentreRayReference) {
    // The reference is computed from spp = 1 without jitter as the technique documents it,
    // not by the technique's sample loop.
    const Scene scene = glossy_cornell();
    const EyeCamera camera = cornell_camera(scene, 32);
    const ExpectedImage reference = expected_image(scene, camera, with(kBase, {{"spp", 1}, {"jitter", false}}));
    expect_matches(render(scene, camera, kBase), reference, "default settings");
    expect_matches(render(scene, camera, with(kBase, {{"pass", "split"}})), reference, "pass=split");
}

TEST(PhotonSpp, SamplesFollowThePathTracersSchemeAndAverage) {
    // Four jittered samples, each with its own light samples, averaged; and four samples at
    // the centre, whose gathers all see the same point, so the indirect layer is the single
    // sample's while the direct layer averages four sets of light samples.
    const Scene scene = glossy_cornell();
    const EyeCamera camera = cornell_camera(scene, 24);
    for (const nlohmann::json& s : {with(kBase, {{"spp", 4}}), with(kBase, {{"spp", 4}, {"jitter", false}}),
                                    with(kBase, {{"spp", 3}, {"light_samples", 1}, {"pass", "split"}})})
        expect_matches(render(scene, camera, s), expected_image(scene, camera, s), s.dump());
    const Film one = render(scene, camera, kBase);
    const Film centred = render(scene, camera, with(kBase, {{"spp", 4}, {"jitter", false}}));
    EXPECT_TRUE(identical(one, centred, "indirect"));
    EXPECT_FALSE(identical(one, centred, "direct"));
}

TEST(PhotonSpp, ColorIsDirectPlusIndirect) {
    const Scene scene = glossy_cornell();
    const EyeCamera camera = cornell_camera(scene, 24);
    const ViewSet stereo = stereo_views(scene, 24, 26);
    for (const nlohmann::json& base : {kBase, every_hit(kBase)})
        for (const char* pass : {"fused", "split"}) {
            const nlohmann::json s = with(base, {{"spp", 4}, {"pass", pass}});
            const Film film = render(scene, camera, s);
            EXPECT_EQ(color_mismatches(film), 0u) << s.dump();
            EXPECT_GT(mean_value(film, "direct"), 0.0) << s.dump();
            EXPECT_GT(mean_value(film, "indirect"), 0.0) << s.dump();
            for (const Film& eye : render_views(scene, stereo, with(s, {{"stereo_reuse", true}})))
                EXPECT_EQ(color_mismatches(eye), 0u) << "stereo " << s.dump();
        }
}

TEST(PhotonSpp, EveryModeGivesTheSameImage) {
    // Tile sharing, the split pass and its gather orders take the samples as more hits:
    // the same image as the fused per-hit gather, bit for bit.
    const Scene scene = glossy_cornell();
    const EyeCamera camera = cornell_camera(scene, 32);
    for (const nlohmann::json& storage : {kBase, every_hit(kBase)})
        for (const char* gather : {"radius", "knn"}) {
            const nlohmann::json s = with(storage, {{"spp", 4}, {"gather", gather}, {"k", 16}});
            Stats fused_stats;
            const Film fused = render(scene, camera, s, &fused_stats);
            EXPECT_GT(fused_stats.get("gather_queries"), 3.0 * 32 * 32) << "a gather per sample, not per pixel";
            const std::pair<const char*, nlohmann::json> modes[] = {
                {"split", {{"pass", "split"}}},
                {"split/tiles", {{"pass", "split"}, {"gather_order", "tiles"}, {"share_tile", 4}}},
                {"fused/paper", {{"tile_shared", "paper"}, {"share_tile", 1}}},
                {"split/paper", {{"pass", "split"}, {"tile_shared", "paper"}, {"share_tile", 1}}},
                {"fused/cell_groups", {{"tile_shared", "cell_groups"}}},
                {"split/cell_groups", {{"pass", "split"}, {"tile_shared", "cell_groups"}}},
            };
            for (const auto& [name, mode] : modes) {
                Stats stats;
                const Film film = render(scene, camera, with(s, mode), &stats);
                expect_identical(fused, film, std::string(name) + " " + s.dump());
                if (mode.contains("tile_shared")) {
                    EXPECT_GT(stats.get("tile_groups"), 0.0) << name;
                    EXPECT_GT(stats.get("tile_grouped_hits"), stats.get("tile_groups")) << name;
                }
            }
        }
    for (const char* map : {"kd_tree", "nanoflann"}) {
        const nlohmann::json s = with(kBase, {{"spp", 4}, {"photon_map", map}});
        expect_identical(render(scene, camera, s), render(scene, camera, with(s, {{"pass", "split"}})), map);
    }
}

TEST(PhotonSpp, IdenticalAtOneAndTwoThreads) {
    const Scene scene = glossy_cornell();
    const ViewSet mono = ViewSet::mono(cornell_camera(scene, 32));
    const ViewSet stereo = stereo_views(scene, 32, 36);
    const nlohmann::json s = with(kBase, {{"spp", 4}});
    const std::pair<const ViewSet*, nlohmann::json> cases[] = {
        {&mono, s},
        {&mono, with(s, {{"pass", "split"}})},
        {&mono, with(s, {{"pass", "split"}, {"tile_shared", "cell_groups"}, {"gather", "knn"}})},
        {&mono, with(every_hit(s), {{"tile_shared", "paper"}, {"share_tile", 4}})},
        {&mono, with(every_hit(s), {{"pass", "split"}, {"tile_shared", "paper"}})},
        {&stereo, s},
        {&stereo, with(s, {{"stereo_reuse", true}, {"stereo_match", "strict"}})},
        {&stereo, with(s, {{"stereo_reuse", true}, {"stereo_fill", true}, {"pass", "split"}})},
        {&stereo, with(s, {{"foveated", true}, {"fovea_angle", 10}, {"stereo_reuse", true}})},
    };
    for (const auto& [views, settings] : cases) {
        std::vector<Film> one, two;
        {
            ThreadLimit limit(1);
            one = render_views(scene, *views, settings);
        }
        {
            ThreadLimit limit(2);
            two = render_views(scene, *views, settings);
        }
        ASSERT_EQ(one.size(), two.size());
        for (size_t v = 0; v < one.size(); ++v) expect_identical(one[v], two[v], settings.dump() + " view " + std::to_string(v));
    }
}

TEST(PhotonSpp, JitteredSamplesLowerTheErrorAtEdges) {
    // 32×32 Cornell box against a path-traced reference whose samples are jittered over
    // the pixel (the box-filtered image). One photon map for both renders (same seed,
    // 256² photons, r = 0.04) and the same shadow rays per pixel (16 light samples at one
    // sample, 1 at sixteen), so what differs is the pixel coverage: a centre ray per pixel
    // aliases every edge of the boxes and the walls. The pixels next to the light are left
    // out: it is about 100 times brighter than the ceiling around it, so where it covers a
    // sliver of a pixel one of sixteen random samples landing on it or not decides the
    // error there, for a path tracer at 16 spp too; the rest is the edges.
    const Scene scene = make_cornell_box();
    const int size = 32;
    const EyeCamera camera = cornell_camera(scene, size);
    Film reference;
    {
        auto path = prepare_technique("path", scene, Settings(nlohmann::json{{"spp", 1024}, {"seed", 9}}));
        std::vector<Film> films;
        path->render(ViewSet::mono(camera), films);
        reference = films.at(0);
    }
    std::vector<uint8_t> away_from_light(size_t(size * size), 1);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = std::clamp(x + dx, 0, size - 1), ny = std::clamp(y + dy, 0, size - 1);
                    if (max_component(reference.get("direct", nx, ny)) > 1.0f) away_from_light[size_t(y * size + x)] = 0;
                }
    const size_t kept = size_t(std::count(away_from_light.begin(), away_from_light.end(), 1));
    ASSERT_GT(kept, size_t(size * size) * 9 / 10);

    const nlohmann::json base = {{"photons", 256 * 256}, {"radius", 0.04}, {"seed", 5}};
    const Film one = render(scene, camera, with(base, {{"light_samples", 16}}));
    const Film sixteen = render(scene, camera, with(base, {{"light_samples", 1}, {"spp", 16}}));
    const double error_one = relative_mse_masked(one, reference, away_from_light);
    const double error_sixteen = relative_mse_masked(sixteen, reference, away_from_light);
    std::printf("[cornell 32x32] relMSE vs path reference away from the light (%zu pixels): spp=1 %.5f, spp=16 %.5f; "
                "whole image %.5f, %.5f\n",
                kept, error_one, error_sixteen, relative_mse(one, reference), relative_mse(sixteen, reference));
    EXPECT_LT(error_sixteen, 0.5 * error_one);
    // The indirect layer's edges too (the same photon map gathered at the samples' points).
    EXPECT_LT(relative_mse_masked(sixteen, reference, away_from_light, "indirect"),
              0.7 * relative_mse_masked(one, reference, away_from_light, "indirect"));
}

TEST(PhotonSpp, StereoReuseRunsPerSample) {
    const Scene scene = glossy_cornell();
    const ViewSet views = stereo_views(scene, 48, 52);
    const double pixels = 48 * 52;
    // Samples at the pixel centre: every sample layer claims the same right pixels as one
    // sample does, and every reused or reshaded sample gathers at the same point, so the
    // right eye's indirect light is the one-sample image's while its direct light averages
    // four sets of light samples.
    {
        Stats one_stats, four_stats;
        const std::vector<Film> one = render_views(scene, views, with(kBase, {{"stereo_reuse", true}}), &one_stats);
        const std::vector<Film> four = render_views(
            scene, views, with(kBase, {{"stereo_reuse", true}, {"spp", 4}, {"jitter", false}}), &four_stats);
        EXPECT_TRUE(identical(one[1], four[1], "indirect"));
        EXPECT_TRUE(identical(one[1], four[1], "reused"));
        EXPECT_FALSE(identical(one[1], four[1], "direct"));
        EXPECT_EQ(four_stats.get("reused_pixels"), 4 * one_stats.get("reused_pixels"));  // counted per sample
        EXPECT_EQ(four_stats.get("reuse_fraction"), one_stats.get("reuse_fraction"));
    }
    // Jittered: sample s of the left pixels claims sample s of the right pixels. Forward
    // reprojection of jittered points leaves more right samples unclaimed than a regular
    // grid does (they are shaded as an independent eye), pixels on a silhouette reuse only
    // some of their samples, and the reused right eye is at least as close to its
    // independent render as with one sample.
    const nlohmann::json s = with(kBase, {{"spp", 4}});
    Stats stats;
    const std::vector<Film> separate = render_views(scene, views, s);
    const std::vector<Film> reused = render_views(scene, views, with(s, {{"stereo_reuse", true}}), &stats);
    expect_identical(separate[0], reused[0], "the left eye");
    const std::vector<Film> separate_one = render_views(scene, views, kBase);
    const std::vector<Film> reused_one = render_views(scene, views, with(kBase, {{"stereo_reuse", true}}));
    const double error = relative_mse(reused[1], separate[1]), error_one = relative_mse(reused_one[1], separate_one[1]);
    std::printf("[stereo spp=4] reuse fraction %.3f, right-eye relMSE vs independent %.5f (spp=1: %.5f)\n",
                stats.get("reuse_fraction"), error, error_one);
    EXPECT_LT(error, error_one);
    EXPECT_GT(stats.get("reuse_fraction"), 0.6);
    EXPECT_LE(stats.get("reused_pixels") + stats.get("right_shaded_pixels"), 4 * pixels);
    size_t partly = 0, whole = 0;
    for (float r : reused[1].layer("reused").data) {
        ASSERT_TRUE(r == 0.0f || r == 0.25f || r == 0.5f || r == 0.75f || r == 1.0f) << r;
        partly += r > 0.0f && r < 1.0f;
        whole += r == 1.0f;
    }
    EXPECT_GT(partly, 100u);
    EXPECT_GT(whole, 200u);
    EXPECT_NEAR(stats.get("reused_pixels"), std::accumulate(reused[1].layer("reused").data.begin(),
                                                            reused[1].layer("reused").data.end(), 0.0) * 4, 1e-9);
}

TEST(PhotonSpp, FoveationTakesSamples) {
    const Scene scene = make_cornell_box();
    HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
    rig.set_resolution(64, 68);
    const EyeCamera eye = rig.eye(Eye::Left);
    const nlohmann::json s = with(kBase, {{"spp", 4}, {"light_samples", 1}});
    Stats full_stats, foveated_stats;
    const Film full = render(scene, eye, s, &full_stats);
    const Film foveated = render(scene, eye, with(s, {{"foveated", true}, {"fovea_angle", 8}}), &foveated_stats);
    // Direct light is traced per sample everywhere; the periphery gathers less.
    EXPECT_TRUE(identical(full, foveated, "direct"));
    EXPECT_FALSE(identical(full, foveated, "indirect"));
    EXPECT_LT(foveated_stats.get("gather_queries"), 0.5 * full_stats.get("gather_queries"));
    EXPECT_LT(relative_mse(foveated, full), 0.05);
    // A fovea wider than the field of view changes nothing.
    expect_identical(full, render(scene, eye, with(s, {{"foveated", true}, {"fovea_angle", 170}})), "wide fovea");
}

TEST(PhotonSpp, SettingsAreCheckedAndRecorded) {
    auto sampling = [](const nlohmann::json& s) { return PhotonMappingSettings::from(Settings(s)).sampling; };
    EXPECT_EQ(sampling(nlohmann::json::object()).spp, 1);
    EXPECT_FALSE(sampling(nlohmann::json::object()).jitter);
    EXPECT_TRUE(sampling({{"spp", 4}}).jitter);
    EXPECT_FALSE(sampling({{"spp", 4}, {"jitter", false}}).jitter);
    EXPECT_TRUE(sampling({{"spp", 1}, {"jitter", true}}).jitter);
    EXPECT_EQ(sampling({{"spp", kMaxPhotonSpp}}).spp, kMaxPhotonSpp);

    const Scene scene = make_cornell_box();
    const std::pair<nlohmann::json, const char*> bad[] = {
        {{{"spp", 0}}, "'spp'"},       {{{"spp", -3}}, "'spp'"},       {{{"spp", kMaxPhotonSpp + 1}}, "'spp'"},
        {{{"spp", 2.5}}, "'spp'"},     {{{"spp", 1e12}}, "'spp'"},     {{{"spp", "many"}}, "'spp'"},
        {{{"jitter", "yes"}}, "'jitter'"},
    };
    for (const auto& [s, key] : bad) {
        const std::string message = test::error_of([&] {
            PhotonMappingTechnique t;
            t.prepare(scene, Settings(s, "photon settings"));
        });
        EXPECT_NE(message.find(key), std::string::npos) << s.dump() << ": " << message;
        EXPECT_NE(message.find("photon settings"), std::string::npos) << message;
    }

    Stats stats;
    const std::vector<Film> films = render_views(scene, stereo_views(scene, 16, 18), with(kBase, {{"spp", 4}}), &stats);
    for (const Film& film : films) {
        EXPECT_EQ(film.metadata.at("spp"), "4");
        EXPECT_EQ(film.metadata.at("jitter"), "true");
    }
    EXPECT_EQ(stats.get("spp"), 4.0);
    EXPECT_EQ(stats.get("samples"), 2.0 * 16 * 18 * 4);
    EXPECT_EQ(render(scene, cornell_camera(scene, 8), kBase).metadata.at("spp"), "1");
}

}  // namespace
}  // namespace gilab
