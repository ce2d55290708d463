// The reference path tracer against closed-form answers: the white furnace (with and
// without path truncation), a diffuse plane under point / directional / area lights, a
// moving scene after update(t); plus determinism across thread counts, settings checks,
// the registry, provenance and statistics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/path_tracer/path_tracer.hpp"
#include "techniques/technique.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

Film render(const Scene& scene, const EyeCamera& camera, nlohmann::json settings_json,
            Stats* stats = nullptr) {
    auto technique = prepare_technique("path", scene, Settings(std::move(settings_json), "test settings"));
    std::vector<Film> films;
    technique->render(ViewSet::mono(camera), films);
    if (stats) *stats = technique->stats();
    EXPECT_EQ(films.size(), 1u);
    return films.at(0);
}

// Mean of one channel over all pixels and its standard error. Pixels are independent
// estimates (each has its own random streams), so the spread of pixel values gives the
// error of their mean.
struct ImageMean {
    double mean = 0, standard_error = 0;
};
ImageMean image_mean(const Film& film, const std::string& layer, int channel) {
    const Layer& l = film.layer(layer);
    const size_t n = film.pixel_count();
    double sum = 0, sum2 = 0;
    for (size_t i = 0; i < n; ++i) {
        double v = l.data[i * size_t(l.channels) + size_t(channel)];
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / double(n);
    double var = std::max(0.0, (sum2 - double(n) * mean * mean) / double(n - 1));
    return {mean, std::sqrt(var / double(n))};
}

// ---------------------------------------------------------------------------------
// White furnace: inside a closed sphere where every surface has albedo a and emits E,
// radiance is E/(1−a) everywhere (L = E + a L).

Scene furnace(float albedo, float emission) {
    Scene scene = make_furnace_sphere(albedo, emission, 3);
    // Emission is one-sided along the winding normal: it must face the centre.
    SceneFrame frame = scene.evaluate(0);
    for (const WorldMesh& m : frame.meshes)
        for (const UVec3& t : m.triangles) {
            Vec3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
            EXPECT_LT(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0f), 0.0f) << "outward-facing triangle";
        }
    return scene;
}

EyeCamera furnace_camera(int size = 32) {
    return EyeCamera::look_at(Vec3(0), Vec3(0, 0, -1), Vec3(0, 1, 0), 90.0f, size, size);
}

struct FurnaceCase {
    float albedo, emission;
};

class Furnace : public ::testing::TestWithParam<FurnaceCase> {};

TEST_P(Furnace, ConvergesToEmissionOverOneMinusAlbedo) {
    const auto [a, E] = GetParam();
    const int spp = 64;
    // Russian roulette keeps it unbiased; max_depth is only a safety net (a^1000 ≈ 0).
    Film film = render(furnace(a, E), furnace_camera(48),
                       {{"spp", spp}, {"max_depth", 1000}, {"rr_depth", 3}, {"seed", 7}});
    const double expected = E / (1.0 - a);
    for (int c = 0; c < 3; ++c) {
        ImageMean m = image_mean(film, "color", c);
        EXPECT_NEAR(m.mean, expected, 3 * m.standard_error) << "channel " << c;
        // The test can tell: a 1% different albedo is far outside the tolerance.
        for (float wrong : {a - 0.01f, a + 0.01f})
            EXPECT_GT(std::abs(m.mean - E / (1.0 - wrong)), 3 * m.standard_error);
        if (c == 0) {
            std::printf("[furnace] a=%.2f E=%.2f: mean %.5f expected %.5f, relative error %.3e, "
                        "3 SE = %.3e relative (%d spp, %dx%d)\n",
                        a, E, m.mean, expected, (m.mean - expected) / expected, 3 * m.standard_error / expected,
                        spp, film.width(), film.height());
        }
    }
    // Layers: direct = E (seen) + a·E (one bounce); indirect = the rest.
    ImageMean direct = image_mean(film, "direct", 0), indirect = image_mean(film, "indirect", 0);
    EXPECT_NEAR(direct.mean, E * (1 + a), 3 * direct.standard_error);
    EXPECT_NEAR(indirect.mean, E * a * a / (1 - a), 3 * indirect.standard_error);
}

INSTANTIATE_TEST_SUITE_P(PathTracer, Furnace, ::testing::Values(FurnaceCase{0.5f, 1.0f}, FurnaceCase{0.8f, 0.5f}),
                         [](const ::testing::TestParamInfo<FurnaceCase>& info) {
                             return "albedo_" + std::to_string(int(std::lround(info.param.albedo * 100)));
                         });

TEST(PathTracer, FurnaceTruncatedAtMaxDepthSumsTheFirstBounces) {
    // Without Russian roulette and at most 2 bounces: E(1 + a + a²).
    const float a = 0.7f, E = 1.0f;
    Film film = render(furnace(a, E), furnace_camera(), {{"spp", 8}, {"max_depth", 2}, {"rr_depth", 100}});
    ImageMean m = image_mean(film, "color", 1);
    EXPECT_NEAR(m.mean, E * (1 + a + a * a), 3 * m.standard_error);
    EXPECT_GT(std::abs(m.mean - E * (1 + a + a * a + a * a * a)), 3 * m.standard_error);
    // max_depth 0: emission seen directly, exactly.
    Film zero = render(furnace(a, E), furnace_camera(), {{"spp", 1}, {"max_depth", 0}});
    for (float v : zero.layer("color").data) ASSERT_FLOAT_EQ(v, E);
}

// ---------------------------------------------------------------------------------
// A diffuse plane (y = height) lit by one light; camera above it.

const Vec3 kPlaneAlbedo(0.6f, 0.5f, 0.4f);

Scene lit_plane(std::vector<PunctualLight> lights, float half_size = 50.0f) {
    Scene scene;
    scene.name = "lit_plane";
    Material m;
    m.albedo = kPlaneAlbedo;
    scene.materials.push_back(m);
    Mesh mesh;
    mesh.name = "plane";
    const float s = half_size;
    mesh.positions = {{-s, 0, -s}, {-s, 0, s}, {s, 0, s}, {s, 0, -s}};
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}};  // winding normal +y
    mesh.material_ids = {0, 0};
    scene.add_mesh_instance(std::move(mesh));
    scene.lights = std::move(lights);
    return scene;
}

EyeCamera plane_camera() {
    return EyeCamera::look_at(Vec3(0.7f, 3.0f, 1.3f), Vec3(0, 0, 0), Vec3(0, 1, 0), 50.0f, 48, 40);
}

// The plane point under a pixel centre, or nullopt if the ray misses the plane.
std::optional<Vec3> plane_point(const EyeCamera& camera, int x, int y, float height, float* distance = nullptr) {
    Ray r = camera.generate_ray(x + 0.5f, y + 0.5f);
    if (r.direction.y >= 0) return std::nullopt;
    float t = (height - r.origin.y) / r.direction.y;
    if (distance) *distance = t * glm::length(r.direction);
    return r.at(t);
}

void expect_close_rgb(const Vec3& got, const Vec3& want, float rel, const std::string& where) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], rel * std::abs(want[k]) + 1e-6f) << where << " channel " << k;
}

TEST(PathTracer, PlaneUnderPointLightIsExactAtOneSample) {
    PunctualLight light;
    light.type = LightType::Point;
    light.position = Vec3(0.3f, 2.0f, -0.2f);
    light.intensity = Vec3(5.0f, 4.0f, 3.0f);
    EyeCamera camera = plane_camera();
    Film film = render(lit_plane({light}), camera, {{"spp", 1}, {"jitter", false}});
    int lit = 0;
    for (int y = 0; y < film.height(); ++y) {
        for (int x = 0; x < film.width(); ++x) {
            float distance = 0;
            auto p = plane_point(camera, x, y, 0.0f, &distance);
            Vec3 expected(0);
            if (p) {
                Vec3 d = light.position - *p;
                float d2 = glm::dot(d, d), cos_theta = d.y / std::sqrt(d2);
                expected = kPlaneAlbedo * kInvPi * light.intensity * cos_theta / d2;  // ρ/π · I cosθ / d²
                ++lit;
                EXPECT_NEAR(film.get("depth", x, y).x, distance, 1e-4f * distance);
                expect_close_rgb(film.get("albedo", x, y), kPlaneAlbedo, 1e-6f, "albedo");
                EXPECT_NEAR(film.get("normal", x, y).y, 1.0f, 1e-6f);
            }
            std::string where = "pixel " + std::to_string(x) + "," + std::to_string(y);
            expect_close_rgb(film.get("color", x, y), expected, 2e-4f, where);
            expect_close_rgb(film.get("direct", x, y), expected, 2e-4f, where);
            EXPECT_EQ(film.get("indirect", x, y), Vec3(0)) << where;
        }
    }
    EXPECT_GT(lit, film.width() * film.height() / 2);
}

TEST(PathTracer, PlaneUnderDirectionalLightIsExact) {
    PunctualLight sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(Vec3(0.4f, -1.0f, 0.3f));
    sun.intensity = Vec3(2.0f, 3.0f, 1.0f);
    EyeCamera camera = plane_camera();
    Film film = render(lit_plane({sun}), camera, {{"spp", 1}, {"jitter", false}});
    const Vec3 expected = kPlaneAlbedo * kInvPi * sun.intensity * (-sun.direction.y);  // ρ/π · E cosθ
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x)
            if (plane_point(camera, x, y, 0.0f)) expect_close_rgb(film.get("color", x, y), expected, 1e-5f, "sun");
}

// Irradiance at x (normal n) from a polygon of radiance L facing x (Lambert's formula).
double polygon_irradiance(const Vec3& x, const Vec3& n, const std::vector<Vec3>& poly, double radiance) {
    double sum = 0;
    for (size_t i = 0; i < poly.size(); ++i) {
        DVec3 a = glm::normalize(DVec3(poly[i] - x)), b = glm::normalize(DVec3(poly[(i + 1) % poly.size()] - x));
        double theta = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        sum += theta * glm::dot(DVec3(n), glm::normalize(glm::cross(a, b)));
    }
    return 0.5 * radiance * std::abs(sum);
}

TEST(PathTracer, PlaneUnderAreaLightMatchesAnalyticIrradiance) {
    // NEE and BSDF sampling both reach the emitter; MIS must neither drop nor double
    // count. The light (albedo 0, facing down) is out of the camera's view.
    Scene scene = lit_plane({}, 20.0f);
    Material emitter;
    emitter.albedo = Vec3(0.0f);
    emitter.emission = Vec3(10.0f);
    scene.materials.push_back(emitter);
    const std::vector<Vec3> quad = {{-0.3f, 1, -0.2f}, {0.3f, 1, -0.2f}, {0.3f, 1, 0.2f}, {-0.3f, 1, 0.2f}};
    Mesh light;
    light.name = "light";
    light.positions = quad;
    light.triangles = {{0, 1, 2}, {0, 2, 3}};  // (x → z) winding: normal −y, facing the plane
    light.material_ids = {1, 1};
    ASSERT_LT(glm::cross(quad[1] - quad[0], quad[2] - quad[0]).y, 0.0f);
    scene.add_mesh_instance(std::move(light));

    EyeCamera camera = EyeCamera::look_at(Vec3(0, 0.5f, 3.0f), Vec3(0, 0, -0.5f), Vec3(0, 1, 0), 30.0f, 32, 32);
    Film film = render(scene, camera, {{"spp", 64}, {"jitter", false}, {"seed", 3}});
    double sum_diff = 0, sum_diff2 = 0, sum_expected = 0;
    int n = 0;
    for (int y = 0; y < film.height(); ++y) {
        for (int x = 0; x < film.width(); ++x) {
            Ray r = camera.generate_ray(x + 0.5f, y + 0.5f);
            if (r.direction.y > 0) {
                Vec3 q = r.at((1.0f - r.origin.y) / r.direction.y);
                ASSERT_FALSE(std::abs(q.x) <= 0.3f && std::abs(q.z) <= 0.2f) << "the light is visible; move the camera";
            }
            auto p = plane_point(camera, x, y, 0.0f);
            if (p && (std::abs(p->x) > 20.0f || std::abs(p->z) > 20.0f)) p.reset();
            double expected = p ? kPlaneAlbedo.x * kInvPi * polygon_irradiance(*p, Vec3(0, 1, 0), quad, 10.0) : 0.0;
            if (!p) {
                EXPECT_EQ(film.get("color", x, y), Vec3(0));  // escaped: nothing to see
            }
            double got = film.get("color", x, y).x;
            sum_diff += got - expected;
            sum_diff2 += (got - expected) * (got - expected);
            sum_expected += expected;
            ++n;
            EXPECT_EQ(film.get("indirect", x, y), Vec3(0));
        }
    }
    double mean_diff = sum_diff / n;
    double se = std::sqrt(std::max(0.0, sum_diff2 / n - mean_diff * mean_diff) / n);
    EXPECT_NEAR(mean_diff, 0.0, 3 * se);
    EXPECT_LT(3 * se, 0.01 * sum_expected / n);  // the tolerance is under 1% of the signal
}

TEST(PathTracer, UpdateMovesAnimatedGeometry) {
    PunctualLight light;
    light.type = LightType::Point;
    light.position = Vec3(0, 2.0f, 0);
    light.intensity = Vec3(3.0f);
    Scene scene = lit_plane({light});
    scene.nodes[0].animation.translation.times = {0.0f, 1.0f};
    scene.nodes[0].animation.translation.values = {Vec3(0), Vec3(0, -1.0f, 0)};
    ASSERT_TRUE(scene.is_animated());

    EyeCamera camera = plane_camera();
    auto technique = prepare_technique("path", scene, Settings(nlohmann::json{{"spp", 1}, {"jitter", false}}));
    technique->update(1.0);
    std::vector<Film> films;
    technique->render(ViewSet::mono(camera), films);
    for (int y = 0; y < camera.height(); y += 3) {
        for (int x = 0; x < camera.width(); x += 3) {
            auto p = plane_point(camera, x, y, -1.0f);
            if (!p) continue;
            Vec3 d = light.position - *p;
            float d2 = glm::dot(d, d);
            Vec3 expected = kPlaneAlbedo * kInvPi * light.intensity * (d.y / std::sqrt(d2)) / d2;
            expect_close_rgb(films[0].get("color", x, y), expected, 2e-4f, "after update");
        }
    }
}

// ---------------------------------------------------------------------------------

EyeCamera cornell_camera(const Scene& scene, int w, int h) {
    const SceneCamera& c = *scene.camera;
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, w, h);
}

TEST(PathTracer, ImageIsIdenticalAtAnyThreadCount) {
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 40, 40);
    nlohmann::json s = {{"spp", 4}, {"tile_size", 8}, {"seed", 5}};
    Film one, two, again;
    {
        ThreadLimit limit(1);
        one = render(scene, camera, s);
    }
    {
        ThreadLimit limit(2);
        two = render(scene, camera, s);
        again = render(scene, camera, s);
    }
    for (const auto& [name, layer] : one.layers()) {
        const Layer& other = two.layer(name);
        ASSERT_EQ(layer.data.size(), other.data.size());
        EXPECT_EQ(std::memcmp(layer.data.data(), other.data.data(), layer.data.size() * sizeof(float)), 0)
            << "layer " << name << " differs between 1 and 2 threads";
        EXPECT_EQ(std::memcmp(layer.data.data(), again.layer(name).data.data(), layer.data.size() * sizeof(float)), 0);
    }
    // A different seed gives a different (noisy) image.
    s["seed"] = 6;
    Film other_seed = render(scene, camera, s);
    EXPECT_NE(std::memcmp(one.layer("color").data.data(), other_seed.layer("color").data.data(),
                          one.layer("color").data.size() * sizeof(float)),
              0);
}

TEST(PathTracer, CornellBoxLayersAreConsistent) {
    Scene scene = make_cornell_box();
    EyeCamera camera = cornell_camera(scene, 24, 24);
    Stats stats;
    Film film = render(scene, camera, {{"spp", 4}}, &stats);
    double total = 0;
    for (int y = 0; y < film.height(); ++y) {
        for (int x = 0; x < film.width(); ++x) {
            Vec3 c = film.get("color", x, y), d = film.get("direct", x, y), i = film.get("indirect", x, y);
            ASSERT_TRUE(is_finite(c));
            EXPECT_GE(std::min({c.x, c.y, c.z}), 0.0f);
            EXPECT_EQ(c, d + i);
            EXPECT_GE(film.get("depth", x, y).x, 0.0f);
            total += c.x;
        }
    }
    EXPECT_GT(total, 0.0);
    EXPECT_GT(film.get("depth", 12, 12).x, 1.0f);  // the back wall, beyond the opening
    EXPECT_EQ(stats.get("samples"), 24.0 * 24.0 * 4.0);
    EXPECT_GE(stats.get("rays"), 24.0 * 24.0 * 4.0);
    EXPECT_EQ(stats.get("nonfinite_samples"), 0.0);
    EXPECT_TRUE(stats.has("render_ms"));
    EXPECT_TRUE(stats.has("prepare_ms"));
    for (const char* key : {"technique", "spp", "seed", "render_time_seconds", "config_hash", "git_revision"})
        EXPECT_TRUE(film.metadata.count(key)) << "missing metadata " << key;
    EXPECT_EQ(film.metadata["technique"], "path");
    EXPECT_EQ(film.metadata["spp"], "4");
    EXPECT_EQ(film.metadata["config_hash"], Settings(nlohmann::json{{"spp", 4}}).hash());
}

TEST(PathTracer, StereoPairRendersBothViews) {
    Scene scene = make_cornell_box();
    EyeCamera left = cornell_camera(scene, 16, 12);
    auto technique = prepare_technique("path", scene, Settings(nlohmann::json{{"spp", 1}}));
    std::vector<Film> films;
    technique->render(ViewSet::stereo_pair(left, left), films);
    ASSERT_EQ(films.size(), 2u);
    EXPECT_EQ(films[1].width(), 16);
    EXPECT_EQ(films[1].metadata["view"], "right");
    // Independent random streams per view: same camera, different noise.
    EXPECT_NE(std::memcmp(films[0].layer("color").data.data(), films[1].layer("color").data.data(),
                          films[0].layer("color").data.size() * sizeof(float)),
              0);
}

TEST(PathTracer, MisspeltSettingIsReported) {
    Scene scene = make_cornell_box();
    auto technique = TechniqueRegistry::builtin().create("path");
    Settings settings(nlohmann::json{{"sp", 4}, {"seed", 2}}, "path settings");
    technique->prepare(scene, settings);
    try {
        settings.report_unused();
        FAIL() << "an unknown key was not reported";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("'sp'"), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find("seed"), std::string::npos) << e.what();
    }
    Settings good(nlohmann::json{{"spp", 1}, {"seed", 2}, {"max_depth", 3}, {"rr_depth", 2}, {"tile_size", 4},
                                 {"jitter", true}});
    technique->prepare(scene, good);
    EXPECT_NO_THROW(good.report_unused());
}

// prepare_technique creates, prepares and reports the keys never read: its error names
// the settings' context, the key and the technique.
TEST(PathTracer, PrepareTechniqueReportsUnreadKeys) {
    const Scene scene = make_cornell_box();
    EXPECT_NO_THROW(prepare_technique("path", scene, Settings(nlohmann::json{{"spp", 1}})));
    const std::string unread = test::error_of(
        [&] { prepare_technique("path", scene, Settings(nlohmann::json{{"sp", 4}, {"seed", 2}}, "path settings")); });
    EXPECT_NE(unread.find("path settings: unknown setting 'sp'"), std::string::npos) << unread;
    EXPECT_NE(unread.find("technique 'path'"), std::string::npos) << unread;
    EXPECT_EQ(unread.find("seed"), std::string::npos) << unread;
    const std::string unknown = test::error_of([&] { prepare_technique("paht", scene, Settings()); });
    EXPECT_NE(unknown.find("unknown technique"), std::string::npos) << unknown;
}

TEST(PathTracer, BadSettingValuesAreErrors) {
    Scene scene = make_cornell_box();
    auto technique = TechniqueRegistry::builtin().create("path");
    for (auto bad : {nlohmann::json{{"spp", 0}}, nlohmann::json{{"max_depth", -1}}, nlohmann::json{{"tile_size", 0}},
                     nlohmann::json{{"spp", "many"}}}) {
        try {
            technique->prepare(scene, Settings(bad, "cfg"));
            FAIL() << "accepted " << bad.dump();
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(bad.begin().key()), std::string::npos) << e.what();
        }
    }
}

TEST(TechniqueRegistry, PathIsBuiltinAndUnknownNamesAreListed) {
    const TechniqueRegistry& registry = TechniqueRegistry::builtin();
    ASSERT_NE(registry.find("path"), nullptr);
    EXPECT_EQ(registry.create("path")->name(), "path");
    try {
        registry.create("pathh");
        FAIL() << "unknown technique accepted";
    } catch (const Error& e) {
        std::string what = e.what();
        EXPECT_NE(what.find("pathh"), std::string::npos) << what;
        EXPECT_NE(what.find("known: "), std::string::npos) << what;
        EXPECT_NE(what.find("path", what.find("known: ")), std::string::npos) << what;
    }
    TechniqueRegistry local;
    register_path_tracer(local);
    EXPECT_THROW(register_path_tracer(local), Error);  // names are unique
}

}  // namespace
}  // namespace gilab
