// The `lpv` technique: settings and their errors, the Cornell box's indirect light
// against the path tracer's one-bounce indirect light, stereo layers and stats, and
// identical images at 1 and 2 threads.
#include <gtest/gtest.h>

#include <cstring>
#include "core/image/image_metrics.hpp"
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "scenes/builtin_scenes.hpp"
#include "tests/techniques/technique_test_support.hpp"
#include "techniques/lpv/lpv_technique.hpp"
#include "techniques/technique.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

std::unique_ptr<LpvTechnique> prepared(const Scene& scene, nlohmann::json settings_json) {
    return test::prepared_technique<LpvTechnique>(scene, std::move(settings_json));
}
using test::inside_camera;
using test::render_one;

TEST(LpvSettings, DefaultsAndClearErrors) {
    const LpvSettings d = LpvSettings::from(Settings());
    EXPECT_EQ(d.cascades, 3);
    EXPECT_EQ(d.resolution, 32);
    EXPECT_EQ(d.iterations, 8);
    EXPECT_TRUE(d.occlusion);
    ASSERT_NE(LpvSettings::schema().quality_knob(), nullptr);
    EXPECT_EQ(LpvSettings::schema().quality_knob()->key, "rsm_size");
    auto message = [](nlohmann::json j) {
        return test::error_of([&] { LpvSettings::from(Settings(j, "cfg")); });
    };
    EXPECT_NE(message({{"cascades", 0}}).find("'cascades'"), std::string::npos) << message({{"cascades", 0}});
    EXPECT_NE(message({{"resolution", 30 + 1}}).find("'resolution' must be even"), std::string::npos);
    EXPECT_NE(message({{"resolution", 2}}).find("'resolution'"), std::string::npos);
    EXPECT_NE(message({{"resolution", 1024}}).find("'resolution'"), std::string::npos);
    EXPECT_NE(message({{"iterations", 0}}).find("'iterations'"), std::string::npos);
    EXPECT_NE(message({{"rsm_size", -4}}).find("'rsm_size'"), std::string::npos);
    EXPECT_NE(message({{"cell_size", -1.0}}).find("'cell_size'"), std::string::npos);
    EXPECT_NE(message({{"dampening", -0.5}}).find("'dampening'"), std::string::npos);
    EXPECT_NE(message({{"occlusion", "yes"}}).find("wrong type"), std::string::npos);
    EXPECT_EQ(message({{"resolution", 16}}), "<no error>");
    // Through the registry, a misspelt key is named.
    const std::string typo = test::error_of(
        [] { prepare_technique("lpv", make_cornell_box(), Settings(nlohmann::json{{"iteration", 4}}, "cfg")); });
    EXPECT_NE(typo.find("iteration"), std::string::npos) << typo;
    EXPECT_NE(TechniqueRegistry::builtin().find("lpv"), nullptr);
}

// The Cornell box's indirect layer against the path tracer's with one indirect bounce
// (max_depth 2: LPV carries a single bounce, VPLs lit directly by the light). relMSE over
// the indirect layer, measured 0.0205 (64², path 256 spp), mean indirect 0.81 of the
// path tracer's (two-band SH spreads light like a diffusion, and the lookup's offset
// dampens it); the bounds sit just above and below.
TEST(LpvTechnique, CornellIndirectNearThePathTracersSingleBounce) {
    const Scene scene = make_cornell_box();
    const EyeCamera camera = inside_camera(64);
    auto path = prepare_technique("path", scene, Settings(nlohmann::json{{"spp", 256}, {"max_depth", 2}, {"seed", 3}}, "reference"));
    std::vector<Film> ref;
    path->render(ViewSet::mono(camera), ref);
    auto lpv = prepared(scene, {{"seed", 3}});
    const Film film = render_one(*lpv, camera);
    const double relmse = relative_mse(film, ref[0], "indirect");
    const double ratio = mean_value(film, "indirect") / mean_value(ref[0], "indirect");
    std::printf("indirect relMSE %.4f, mean ratio lpv/path %.3f, direct ratio %.4f\n", relmse, ratio,
                mean_value(film, "direct") / mean_value(ref[0], "direct"));
    EXPECT_LT(relmse, 0.025);
    EXPECT_NEAR(ratio, 0.81, 0.05);
    EXPECT_NEAR(mean_value(film, "direct") / mean_value(ref[0], "direct"), 1.0, 0.05);  // both ray traced
}

TEST(LpvTechnique, StereoLayersAndStats) {
    const Scene scene = make_cornell_box();
    auto t = prepared(scene, {{"resolution", 16}});
    const EyeCamera left = inside_camera(16);
    const EyeCamera right = EyeCamera::look_at(Vec3(0.56f, 0.45f, 0.06f), Vec3(0.56f, 0.42f, 1.0f), Vec3(0, 1, 0), 75.0f, 16, 16);
    std::vector<Film> films;
    t->render(ViewSet::stereo_pair(left, right), films);
    ASSERT_EQ(films.size(), 2u);
    for (const char* layer : {"color", "direct", "indirect", "albedo", "normal", "depth"})
        EXPECT_TRUE(films[0].has_layer(layer)) << layer;
    EXPECT_EQ(films[1].metadata.at("view"), "right");
    EXPECT_EQ(films[0].metadata.at("technique"), "lpv");
    const Stats s = t->stats();
    for (const char* key : {"rsm_ms", "inject_ms", "propagate_ms", "lookup_ms", "direct_ms", "primary_ms", "total_ms",
                            "vpls", "cells", "structure_bytes"})
        EXPECT_TRUE(s.has(key)) << key;
    EXPECT_EQ(s.get("cells"), 3.0 * 16 * 16 * 16);
    EXPECT_GT(s.get("vpls"), 100.0);
    // Four SH buffers of 12 floats per cell, at least, in every cascade.
    EXPECT_GT(s.get("structure_bytes"), 3.0 * 16 * 16 * 16 * 4 * 48);
    for (const Film& film : films) {
        double lit = 0;
        const auto& color = film.layer("color").data;
        for (size_t c = 0; c < color.size(); ++c) {
            EXPECT_FLOAT_EQ(color[c], film.layer("direct").data[c] + film.layer("indirect").data[c]);
            lit += film.layer("indirect").data[c];
        }
        EXPECT_GT(lit, 0.0) << "the indirect layer should not be empty";
    }
}

TEST(LpvTechnique, SameImagesAtOneAndTwoThreads) {
    const Scene scene = make_cornell_box();
    for (const bool occlusion : {true, false}) {
        auto run = [&](int threads) {
            ThreadLimit limit(threads);
            auto t = prepared(scene, {{"resolution", 16}, {"rsm_size", 32}, {"occlusion", occlusion}});
            std::vector<Film> out;
            for (int i = 0; i < 2; ++i) {  // two frames: the second one moves the cascades
                const Vec3 eye(0.4f + 0.1f * float(i), 0.45f, 0.1f);
                out.push_back(render_one(*t, EyeCamera::look_at(eye, eye + Vec3(0, 0, 1), Vec3(0, 1, 0), 70.0f, 24, 24)));
            }
            return out;
        };
        const auto one = run(1), two = run(2);
        for (size_t f = 0; f < one.size(); ++f)
            for (const auto& [name, layer] : one[f].layers())
                ASSERT_EQ(std::memcmp(layer.data.data(), two[f].layer(name).data.data(), layer.data.size() * sizeof(float)), 0)
                    << (occlusion ? "occlusion" : "no occlusion") << " frame " << f << " layer " << name;
    }
}

}  // namespace
}  // namespace gilab
