// The `fire` scene: deterministic for a seed and different for another, exactly the
// requested number of frames, closed particles that rise, wander and respawn, and step
// keys that never blend two simulated states.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/scene/mesh_topology.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/fire_scene.hpp"
#include "scenes/procedural_meshes.hpp"
#include "tests/test_support.hpp"

using namespace gilab;

namespace {

// All world-space vertex positions of a frame, in node order.
std::vector<Vec3> positions_at(const Scene& scene, int frame) {
    std::vector<Vec3> out;
    for (const WorldMesh& m : scene.evaluate_frame(frame).meshes)
        out.insert(out.end(), m.positions.begin(), m.positions.end());
    return out;
}

// Centre of every particle (the mean of its octahedron's vertices) at a time.
std::vector<Vec3> particle_centres(const Scene& scene, double time) {
    std::vector<Vec3> out;
    for (const WorldMesh& m : scene.evaluate(time).meshes) {
        if (scene.nodes[m.node].name.rfind("particle_", 0) != 0) continue;
        Vec3 c(0);
        for (const Vec3& p : m.positions) c += p;
        out.push_back(c / float(m.positions.size()));
    }
    return out;
}

}  // namespace

TEST(FireScene, SameSeedGivesIdenticalFrame) {
    FireOptions o;
    o.seed = 7;
    const Scene a = make_fire_scene(o), b = make_fire_scene(o);
    EXPECT_EQ(positions_at(a, 37), positions_at(b, 37));
}

TEST(FireScene, OtherSeedGivesDifferentFrame) {
    FireOptions o;
    o.seed = 7;
    const Scene a = make_fire_scene(o);
    o.seed = 8;
    const Scene b = make_fire_scene(o);
    const std::vector<Vec3> pa = positions_at(a, 37), pb = positions_at(b, 37);
    ASSERT_EQ(pa.size(), pb.size());
    EXPECT_NE(pa, pb);
}

TEST(FireScene, DefaultsAreOneHundredFramesAtThirtyFps) {
    const Scene scene = make_fire_scene();
    scene.validate();
    EXPECT_TRUE(scene.is_animated());
    EXPECT_EQ(scene.frames_per_second, 30.0);
    EXPECT_EQ(scene.animation_frame_count(), 100);
    EXPECT_EQ(particle_centres(scene, 0).size(), 4000u);
    ASSERT_EQ(scene.lights.size(), 2u);
    EXPECT_EQ(scene.lights[0].type, LightType::Point);
    EXPECT_EQ(scene.lights[1].type, LightType::Directional);
    EXPECT_TRUE(scene.camera.has_value());
}

TEST(FireScene, FrameCountHoldsForOtherLengthsAndRates) {
    // Float key times must not lose the last frame to rounding.
    for (int frames : {2, 7, 70, 100, 101})
        for (double fps : {24.0, 29.97, 30.0, 60.0}) {
            FireOptions o;
            o.particles = 3;
            o.frames = frames;
            o.fps = fps;
            EXPECT_EQ(make_fire_scene(o).animation_frame_count(), frames) << frames << " frames at " << fps;
        }
}

TEST(FireScene, ParticlesAreClosedOctahedra) {
    const Scene scene = make_fire_scene();
    bool found = false;
    for (const Mesh& m : scene.meshes) {
        if (m.name != "particle") continue;
        found = true;
        EXPECT_EQ(m.triangles.size(), 8u);
        EXPECT_TRUE(analyze_topology(m).closed);
        EXPECT_GT(signed_volume(m), 0.0);
    }
    EXPECT_TRUE(found);
}

TEST(FireScene, ParticlesRiseWanderAndRespawn) {
    FireOptions o;
    o.particles = 200;
    const Scene scene = make_fire_scene(o);
    int rose = 0, respawned = 0, moved_sideways = 0;
    std::vector<Vec3> before = particle_centres(scene, 0);
    for (int k = 1; k < o.frames; ++k) {
        const std::vector<Vec3> now = particle_centres(scene, k / o.fps);
        for (size_t i = 0; i < now.size(); ++i) {
            rose += now[i].y > before[i].y;
            respawned += now[i].y < before[i].y;
            moved_sideways += now[i].x != before[i].x || now[i].z != before[i].z;
        }
        before = now;
    }
    const int steps = o.particles * (o.frames - 1);
    EXPECT_GT(rose, steps * 9 / 10);
    EXPECT_GT(respawned, o.particles);  // lives of 0.5–1.5 s in 3.3 s: every particle respawns
    EXPECT_EQ(moved_sideways, steps);
}

TEST(FireScene, StepKeysHoldBetweenFrames) {
    FireOptions o;
    o.particles = 50;
    const Scene scene = make_fire_scene(o);
    for (int k : {0, 12, 98}) {
        const double mid = (k + 0.5) / o.fps;
        EXPECT_EQ(particle_centres(scene, k / o.fps), particle_centres(scene, mid)) << "frame " << k;
    }
}

TEST(FireScene, IsABuiltinScene) {
    bool found = false;
    for (const BuiltinScene& b : builtin_scenes()) found |= b.name == "fire";
    EXPECT_TRUE(found);
}

TEST(FireScene, BadOptionsAreErrors) {
    FireOptions o;
    o.particles = 0;
    EXPECT_NE(gilab::test::error_of([&] { make_fire_scene(o); }).find("particle"), std::string::npos);
    o = {};
    o.frames = 1;
    EXPECT_NE(gilab::test::error_of([&] { make_fire_scene(o); }).find("frames"), std::string::npos);
    o = {};
    o.fps = 0;
    EXPECT_NE(gilab::test::error_of([&] { make_fire_scene(o); }).find("frames per second"), std::string::npos);
    o.fps = -1e-300;  // quoted as given, not as -0.000000
    EXPECT_NE(gilab::test::error_of([&] { make_fire_scene(o); }).find("not -1e-300"), std::string::npos);
}
