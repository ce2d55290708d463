// The dag_shadows technique: each visibility source against Embree shadow rays on the
// villa, stereo, determinism at any thread count, and bad settings.
#include <gtest/gtest.h>
#include <cmath>
#include "core/util/parallel.hpp"
#include "scenes/villa_and_terrain.hpp"
#include "techniques/dag_shadows/dag_shadows_technique.hpp"
#include "tests/test_support.hpp"

namespace {

using namespace gilab;
using nlohmann::json;

EyeCamera villa_camera(const Scene& scene, int w = 96, int h = 72) {
    const SceneCamera c = scene.camera.value();
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, w, h);
}

std::vector<Film> render(const Scene& scene, const std::string& visibility, uint32_t resolution = 512,
                         int pcf = 1) {
    const Settings s(json{{"visibility", visibility}, {"resolution", resolution}, {"pcf", pcf}}, "test");
    auto t = prepare_technique("dag_shadows", scene, s);
    std::vector<Film> films;
    t->render(ViewSet::mono(villa_camera(scene)), films);
    EXPECT_GE(t->stats().get("shadow_ms"), 0);
    // Every source reports what its structure holds (shadow rays: none, 0 bytes).
    const double bytes = t->stats().get("structure_bytes");
    if (visibility == "ray") EXPECT_EQ(bytes, 0.0);
    else EXPECT_GT(bytes, 0.0) << visibility;
    return films;
}

}  // namespace

TEST(DagShadows, EveryStructureAgreesWithShadowRays) {
    const Scene villa = make_villa();
    const std::vector<float> truth = render(villa, "ray")[0].layer("visibility").data;
    size_t shadowed = 0, lit = 0;
    for (float v : truth) (v > 0.5f ? lit : shadowed)++;
    ASSERT_GT(shadowed, 200u);  // the view holds shadows
    ASSERT_GT(lit, 200u);
    for (const char* vis : {"shadow_map", "shadow_dag", "shadow_dag_double_depth"}) {
        const Film f = render(villa, vis)[0];
        const auto& v = f.layer("visibility").data;
        size_t differ = 0;
        for (size_t i = 0; i < v.size(); ++i) differ += std::abs(v[i] - truth[i]) > 0.5f;
        EXPECT_LT(double(differ) / v.size(), 0.03) << vis;
        for (float c : f.layer("color").data) ASSERT_TRUE(std::isfinite(c) && c >= 0) << vis;
    }
}

TEST(DagShadows, ColorIsDirectLightTimesVisibilityPlusAmbient) {
    const Scene villa = make_villa();
    const Film f = render(villa, "shadow_dag")[0];
    // In shadow only the ambient term (3 % of the light) is left: shadowed pixels are
    // far darker than lit ones on average.
    double lit_sum = 0, dark_sum = 0;
    size_t lit = 0, dark = 0;
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x) {
            const float v = f.get("visibility", x, y).x;
            const float l = luminance(f.get("color", x, y));
            if (l <= 0) continue;
            (v > 0.5f ? lit_sum : dark_sum) += l;
            (v > 0.5f ? lit : dark)++;
        }
    ASSERT_GT(lit, 0u);
    ASSERT_GT(dark, 0u);
    EXPECT_LT(dark_sum / dark, 0.2 * lit_sum / lit);
}

TEST(DagShadows, StereoAndThreadCountsGiveTheSameImages) {
    const Scene villa = make_villa();
    const Settings s(json{{"visibility", "shadow_dag_double_depth"}, {"resolution", 256}, {"pcf", 3}});
    auto t = prepare_technique("dag_shadows", villa, s);
    const EyeCamera cam = villa_camera(villa);
    const EyeCamera right = EyeCamera(cam.position() + Vec3(0.5f, 0, 0), cam.orientation(), cam.fov(), 96, 72);
    std::vector<Film> one, two;
    {
        ThreadLimit limit(1);
        t->render(ViewSet::stereo_pair(cam, right), one);
    }
    {
        ThreadLimit limit(2);
        t->render(ViewSet::stereo_pair(cam, right), two);
    }
    ASSERT_EQ(one.size(), 2u);
    EXPECT_EQ(one[1].metadata.at("view"), "right");
    for (int e = 0; e < 2; ++e)
        for (const char* layer : {"color", "visibility"})
            EXPECT_EQ(one[e].layer(layer).data, two[e].layer(layer).data) << layer;
    EXPECT_NE(one[0].layer("color").data, one[1].layer("color").data);  // the eyes differ
}

TEST(DagShadows, BadSettingsNameTheKey) {
    const Scene villa = make_villa();
    auto t = TechniqueRegistry::builtin().create("dag_shadows");
    EXPECT_NE(test::error_of([&] { t->prepare(villa, Settings(json{{"visibility", "raytrace"}})); })
                  .find("'visibility'"),
              std::string::npos);
    EXPECT_NE(test::error_of([&] { t->prepare(villa, Settings(json{{"resolution", 4}})); }).find("'resolution'"),
              std::string::npos);
    EXPECT_NE(test::error_of([&] { t->prepare(villa, Settings(json{{"light", 7}})); }).find("index 7"),
              std::string::npos);
    EXPECT_NE(test::error_of([&] { t->prepare(villa, Settings(json{{"tile", 100}})); }).find("power of two"),
              std::string::npos);
}
