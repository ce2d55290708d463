// The scene fingerprint that keys cached renders: equal scenes hash equal, and any change
// a renderer would see (a vertex, a material, a light, an animation key, the hierarchy)
// changes it, while a name does not.
#include <gtest/gtest.h>
#include <functional>
#include <string>
#include "core/scene/scene_hash.hpp"
#include "scenes/builtin_scenes.hpp"

namespace {

using namespace gilab;

Scene animated_cornell() {
    Scene s = make_cornell_box();
    s.nodes[0].animation.translation.times = {0.0f, 1.0f};
    s.nodes[0].animation.translation.values = {Vec3(0), Vec3(0.1f, 0, 0)};
    return s;
}

TEST(SceneContentHash, EqualScenesHashEqualAndNamesDoNotCount) {
    const Scene a = animated_cornell();
    Scene b = animated_cornell();
    EXPECT_EQ(scene_content_hash(a), scene_content_hash(b));
    EXPECT_EQ(scene_content_hash(a).size(), 16u);
    b.name = "renamed";
    b.source = "elsewhere.json";
    b.materials[0].name = "other";
    EXPECT_EQ(scene_content_hash(a), scene_content_hash(b));
}

TEST(SceneContentHash, EveryVisibleChangeChangesIt) {
    const std::string base = scene_content_hash(animated_cornell());
    const std::vector<std::pair<const char*, std::function<void(Scene&)>>> edits = {
        {"vertex", [](Scene& s) { s.meshes[0].positions[0].x += 1e-4f; }},
        {"triangle order", [](Scene& s) { std::swap(s.meshes[0].triangles[0], s.meshes[0].triangles[1]); }},
        {"material", [](Scene& s) { s.materials[0].albedo.y *= 0.5f; }},
        {"emission", [](Scene& s) { s.materials.back().emission += Vec3(0.1f); }},
        {"light", [](Scene& s) {
             PunctualLight l;
             s.lights.push_back(l);
         }},
        {"animation key", [](Scene& s) { s.nodes[0].animation.translation.times[1] = 2.0f; }},
        {"rest transform", [](Scene& s) { s.nodes[0].local.scale = Vec3(2); }},
        {"frame rate", [](Scene& s) { s.frames_per_second = 24; }},
    };
    for (const auto& [what, edit] : edits) {
        Scene s = animated_cornell();
        edit(s);
        EXPECT_NE(scene_content_hash(s), base) << what;
    }
}

}  // namespace
