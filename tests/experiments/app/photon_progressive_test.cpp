// Progressive mode of the photon technique (SPPM, progressive.hpp): the per-pixel update
// follows the α rule on numbers worked out by hand; the white furnace converges to its
// analytic value with the error falling as iterations grow; the Cornell box's indirect
// light approaches the path tracer's; direct light is the shadow-ray estimate averaged
// over the iterations (the spp = iterations image's direct layer, bit for bit); images
// do not depend on the thread count; time_budget stops early; bad settings are refused
// naming the setting, and `gilab render --time-budget` with a technique that reads no
// time budget is refused naming the option.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include "core/util/error.hpp"
#include "core/image/image_metrics.hpp"
#include "core/util/parallel.hpp"
#include "experiments/app/render_command.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"
#include "techniques/photon_mapping/progressive.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

using nlohmann::json;

std::vector<Film> render_views(const std::string& technique, const Scene& scene, const ViewSet& views,
                               const json& settings_json, Stats* stats = nullptr) {
    auto t = prepare_technique(technique, scene, Settings(settings_json, "test settings"));
    std::vector<Film> films;
    t->render(views, films);
    if (stats) *stats = t->stats();
    return films;
}

Film render(const std::string& technique, const Scene& scene, const EyeCamera& camera, const json& settings,
            Stats* stats = nullptr) {
    return render_views(technique, scene, ViewSet::mono(camera), settings, stats).at(0);
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

// Root-mean-square deviation of the indirect layer from a constant, relative to it.
double rms_from(const Film& film, double expected) {
    const auto& v = film.layer("indirect").data;
    double sum = 0;
    for (float x : v) sum += (x - expected) * (x - expected);
    return std::sqrt(sum / double(v.size())) / expected;
}

TEST(PhotonProgressive, PixelUpdateFollowsTheAlphaRule) {
    // By hand, α = 2/3, R = 0.1, N = 0, τ = 0:
    // 10 photons with flux (1, 2, 3): N' = 20/3, R'² = 0.01 · (20/3)/10 = 0.01 · 2/3,
    //   τ' = (1, 2, 3) · 2/3.
    // 5 photons with flux (1/2, 1/2, 1/2): N'' = 20/3 + 10/3 = 10, R''²/R'² = 10/(35/3) = 6/7,
    //   R''² = 0.01 · 4/7, τ'' = (2/3 + 1/2, 4/3 + 1/2, 2 + 1/2) · 6/7 = (1, 11/7, 15/7).
    // An iteration without photons changes nothing. After 2 iterations
    //   L = τ'' / (π R''² · 2) = τ'' · 700 / (8π).
    const double alpha = 2.0 / 3.0;
    SppmPixel p{0.1, 0.0, DVec3(0.0)};
    p.add_iteration(10, DVec3(1, 2, 3), alpha);
    EXPECT_NEAR(p.count, 20.0 / 3.0, 1e-12);
    EXPECT_NEAR(p.radius * p.radius, 0.01 * 2.0 / 3.0, 1e-15);
    EXPECT_NEAR(p.flux.x, 2.0 / 3.0, 1e-12);
    EXPECT_NEAR(p.flux.y, 4.0 / 3.0, 1e-12);
    EXPECT_NEAR(p.flux.z, 2.0, 1e-12);
    p.add_iteration(5, DVec3(0.5), alpha);
    EXPECT_NEAR(p.count, 10.0, 1e-12);
    EXPECT_NEAR(p.radius, 0.2 / std::sqrt(7.0), 1e-14);
    EXPECT_NEAR(p.flux.x, 1.0, 1e-12);
    EXPECT_NEAR(p.flux.y, 11.0 / 7.0, 1e-12);
    EXPECT_NEAR(p.flux.z, 15.0 / 7.0, 1e-12);
    const SppmPixel before = p;
    p.add_iteration(0, DVec3(9.0), alpha);
    EXPECT_EQ(p.radius, before.radius);
    EXPECT_EQ(p.count, before.count);
    EXPECT_EQ(p.flux, before.flux);
    const DVec3 L = p.radiance(2);
    EXPECT_NEAR(L.x, 700.0 / (8.0 * kPi), 1e-9);
    EXPECT_NEAR(L.y, 11.0 / 7.0 * 700.0 / (8.0 * kPi), 1e-9);
    EXPECT_NEAR(L.z, 15.0 / 7.0 * 700.0 / (8.0 * kPi), 1e-9);
}

TEST(PhotonProgressive, WhiteFurnaceConvergesToTheAnalyticValue) {
    // Light that bounced at least once arrives as E·a²/(1 − a) everywhere inside the
    // furnace (photon_mapping_test.cpp); on the sphere the disk estimator has no edge
    // bias, so the per-pixel error is photon noise, which progressive iterations average
    // away while the radii shrink. The image mean must lie within 2.5 % (faceting of the
    // icosphere ≈ 1 %) and the per-pixel RMS error must fall with every 4× more iterations.
    const float a = 0.5f, E = 1.0f;
    const double expected = E * a * a / (1 - a);
    Scene scene = make_furnace_sphere(a, E, 3);
    EyeCamera camera = EyeCamera::look_at(Vec3(0), Vec3(0, 0, -1), Vec3(0, 1, 0), 90.0f, 24, 24);
    double previous = 1e9;
    for (int iterations : {2, 8, 32, 128}) {
        Stats stats;
        Film film = render("photon", scene, camera,
                           {{"progressive", true}, {"iterations", iterations}, {"photons", 4000}, {"radius", 0.15},
                            {"max_photon_depth", 200}, {"seed", 2}},
                           &stats);
        const double mean = mean_value(film, "indirect"), rms = rms_from(film, expected);
        std::printf("[furnace sppm] %2d iterations: mean %.5f expected %.5f (%+.4f), rms %.4f, mean radius %.4f\n",
                    iterations, mean, expected, mean / expected - 1, rms, stats.get("mean_final_radius"));
        EXPECT_NEAR(mean, expected, 0.025 * expected) << iterations;
        EXPECT_LT(rms, 0.85 * previous) << iterations;
        EXPECT_EQ(stats.get("iterations_run"), iterations);
        EXPECT_EQ(stats.get("photons_emitted"), 4000.0 * iterations);
        EXPECT_LT(stats.get("mean_final_radius"), 0.15);
        previous = rms;
    }
    EXPECT_LT(previous, 0.05);
}

TEST(PhotonProgressive, CornellIndirectApproachesThePathTracer) {
    // 32² pixels, 48 iterations of 16k photons from r = 0.05, against a jittered path-traced
    // reference (1024 spp). Tolerance 2 % on the image mean of the indirect layer (the
    // fixed-radius technique's at r = 0.05 is −2 % from disks crossing edges; the shrinking
    // radius lowers that; measured ≈ 0.2 %) and relMSE 0.005 (measured ≈ 0.001, the
    // reference's own noise included); a wrong normalisation is off by far more.
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 32);
    Film reference = render("path", scene, camera, {{"spp", 1024}, {"seed", 3}, {"jitter", true}});
    Film pm = render("photon", scene, camera,
                     {{"progressive", true}, {"iterations", 48}, {"photons", 16384}, {"radius", 0.05}, {"seed", 5}});
    const double ref = mean_value(reference, "indirect"), got = mean_value(pm, "indirect");
    const double relmse = relative_mse(pm, reference, "indirect");
    std::printf("[cornell sppm] indirect mean: sppm %.5f, path %.5f (%+.4f); relMSE %.4f\n", got, ref, got / ref - 1,
                relmse);
    EXPECT_NEAR(got / ref, 1.0, 0.02);
    EXPECT_LT(relmse, 0.005);
    EXPECT_NEAR(mean_value(pm, "direct") / mean_value(reference, "direct"), 1.0, 0.02);
}

TEST(PhotonProgressive, DirectLightIsTheShadowRayEstimateAveragedOverIterations) {
    // Iteration k draws its jitter and light samples as sample k of the pixel would with
    // spp samples, so the progressive direct layer is the non-progressive spp = iterations
    // image's, bit for bit; color is direct + indirect.
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 16);
    const json base = {{"photons", 2000}, {"radius", 0.08}, {"seed", 7}, {"light_samples", 2}};
    json progressive = base;
    progressive["progressive"] = true;
    progressive["iterations"] = 6;
    json sampled = base;
    sampled["spp"] = 6;
    Film p = render("photon", scene, camera, progressive);
    Film s = render("photon", scene, camera, sampled);
    EXPECT_TRUE(identical(p, s, "direct"));
    EXPECT_GT(mean_value(p, "indirect"), 0.0);
    const auto& c = p.layer("color").data;
    const auto& d = p.layer("direct").data;
    const auto& i = p.layer("indirect").data;
    for (size_t k = 0; k < c.size(); ++k) ASSERT_EQ(c[k], d[k] + i[k]) << k;
}

TEST(PhotonProgressive, ImagesDoNotDependOnTheThreadCount) {
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 40);
    const json settings = {{"progressive", true}, {"iterations", 6}, {"photons", 6000}, {"radius", 0.06}, {"seed", 9}};
    Film one, two;
    {
        ThreadLimit limit(1);
        one = render("photon", scene, camera, settings);
    }
    {
        ThreadLimit limit(2);
        two = render("photon", scene, camera, settings);
    }
    for (const char* layer : {"color", "direct", "indirect"}) EXPECT_TRUE(identical(one, two, layer)) << layer;
    // Another seed changes the image: the comparison above can tell images apart.
    json other = settings;
    other["seed"] = 10;
    EXPECT_FALSE(identical(one, render("photon", scene, camera, other), "indirect"));
}

TEST(PhotonProgressive, EachIterationTracesFreshPhotons) {
    // Two iterations with one photon pass reused would equal one iteration's radiance
    // shrunk in radius; fresh passes give a different, less noisy image. Checked through
    // the photons stored: each pass stores its own photons, about as many every time.
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 16);
    Stats one, four;
    render("photon", scene, camera, {{"progressive", true}, {"iterations", 1}, {"photons", 3000}, {"seed", 3}}, &one);
    render("photon", scene, camera, {{"progressive", true}, {"iterations", 4}, {"photons", 3000}, {"seed", 3}}, &four);
    EXPECT_EQ(four.get("photons_emitted"), 4 * one.get("photons_emitted"));
    EXPECT_NE(four.get("photons_stored"), 4 * one.get("photons_stored"));  // different random streams
    EXPECT_NEAR(four.get("photons_stored") / (4 * one.get("photons_stored")), 1.0, 0.1);
}

TEST(PhotonProgressive, TimeBudgetStopsAfterTheIterationThatFillsIt) {
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 16);
    const json base = {{"progressive", true}, {"iterations", 40}, {"photons", 2000}, {"seed", 1}};
    Stats unlimited, limited;
    render("photon", scene, camera, base, &unlimited);
    EXPECT_EQ(unlimited.get("iterations_run"), 40.0);
    json budget = base;
    budget["time_budget"] = 1e-6;  // filled by the first iteration
    Film film = render("photon", scene, camera, budget, &limited);
    EXPECT_EQ(limited.get("iterations_run"), 1.0);
    EXPECT_LT(limited.get("iterations_run"), 40.0);
    EXPECT_EQ(limited.get("photons_emitted"), 2000.0);
    EXPECT_EQ(film.metadata.at("iterations"), "1");
}

TEST(PhotonProgressive, BadSettingsAreRefusedNamingTheSetting) {
    Scene scene = make_cornell_box();
    auto error = [&](const json& extra) {
        json s = {{"progressive", true}, {"photons", 1000}};
        for (auto it = extra.begin(); it != extra.end(); ++it) s[it.key()] = it.value();
        return test::error_of([&] {
            PhotonMappingTechnique t;
            t.prepare(scene, Settings(s, "test settings"));
        });
    };
    const std::pair<json, const char*> cases[] = {
        {{{"alpha", 0.0}}, "'alpha'"},
        {{{"alpha", 1.0}}, "'alpha'"},
        {{{"alpha", -0.5}}, "'alpha'"},
        {{{"alpha", 1.5}}, "'alpha'"},
        {{{"iterations", 0}}, "'iterations'"},
        {{{"iterations", -3}}, "'iterations'"},
        {{{"time_budget", 0.0}}, "'time_budget'"},
        {{{"time_budget", -1.0}}, "'time_budget'"},
        {{{"stereo_reuse", true}}, "'stereo_reuse'"},
        {{{"foveated", true}}, "'foveated'"},
        {{{"photon_storage", "every_hit"}}, "photon_storage"},
        {{{"gather", "knn"}}, "gather"},
        {{{"photon_map", "kd_tree"}}, "photon_map"},
        {{{"pass", "split"}}, "pass"},
        {{{"spp", 4}}, "'spp'"},
        {{{"jitter", false}}, "'jitter'"},
        {{{"progressive", false}, {"iterations", 4}}, "'iterations'"},
        {{{"progressive", false}, {"alpha", 0.5}}, "'alpha'"},
        {{{"progressive", false}, {"time_budget", 2.0}}, "'time_budget'"},
    };
    for (const auto& [extra, name] : cases) {
        const std::string message = error(extra);
        EXPECT_NE(message.find(name), std::string::npos) << extra.dump() << " → " << message;
    }
    // The same settings without the bad value are accepted.
    EXPECT_EQ(error({{"alpha", 0.5}, {"iterations", 3}, {"time_budget", 10.0}}), "<no error>");
}

TEST(PhotonProgressive, RenderRefusesATimeBudgetForATechniqueThatReadsNone) {
    RenderRequest request;
    request.scene = "cornell";
    request.technique = "path";
    request.width = request.height = 8;
    request.spp = 1;
    request.time_budget = 1.0;
    request.output = (test::temp_dir("progressive_time_budget") / "path").string();
    const std::string message = test::error_of([&] { run_render(request); });
    EXPECT_NE(message.find("--time-budget"), std::string::npos) << message;
    // The photon technique's progressive mode takes it.
    request.technique = "photon";
    request.spp.reset();
    request.assignments = {"progressive=true", "iterations=2", "photons=500"};
    request.output = (test::temp_dir("progressive_time_budget_photon") / "photon").string();
    EXPECT_EQ(test::error_of([&] { run_render(request); }), "<no error>");
}

}  // namespace
}  // namespace gilab
