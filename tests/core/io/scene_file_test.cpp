// Scene description files: placement, material overrides and merging, lights, camera,
// HMD, animation, skinned files merged and fitted; every error names the file and the
// JSON path; every shipped scene in scenes/ loads.
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>
#include <fstream>
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/io/scene_file.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;
using gilab::test::error_of;
using gilab::test::write_file;

namespace {

// Two small OBJ files with their own MTLs; "shared" is identical in both.
fs::path fixture_dir(const std::string& name) {
    auto dir = test::temp_dir(name);
    write_file(dir, "models/a.mtl", "newmtl shared\nKd 0.5 0.5 0.5\nnewmtl red\nKd 0.8 0.1 0.1\n");
    write_file(dir, "models/a.obj",
               "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
               "usemtl red\nf 1 2 3\nusemtl shared\nf 1 3 4\n");
    write_file(dir, "models/b.mtl", "newmtl green\nKd 0.1 0.8 0.1\nnewmtl shared\nKd 0.5 0.5 0.5\n");
    write_file(dir, "models/b.obj",
               "mtllib b.mtl\nv 0 0 0\nv 2 0 0\nv 0 4 0\nusemtl shared\nf 1 2 3\nusemtl green\nf 3 2 1\n");
    return dir;
}

Scene load(const fs::path& path) { return load_scene_file(path, AssetPaths{}); }

const std::string kFull = R"({
  "name": "fixture",
  "description": "test scene",
  "materials": {
    "glow": {"emission": [5, 4, 3], "albedo": 0.1},
    "shiny": {"albedo": [0.5, 0.4, 0.3], "specular": 0.2, "roughness": 0.5}
  },
  "meshes": [
    {"name": "first", "file": "models/a.obj", "translate": [1, 2, 3], "rotate_degrees": [0, 90, 0], "scale": 2},
    {"file": "models/b.obj", "scale": [1, 2, 3], "rotate_quaternion": [1, 0, 0, 0]},
    {"name": "lamp", "file": "models/a.obj", "material": "glow"},
    {"name": "fitted", "files": ["models/a.obj", "models/b.obj"],
     "fit_to_box": {"min": [10, 0, 10], "max": [12, 1, 11], "anchor": "bottom"}}
  ],
  "lights": [
    {"type": "point", "name": "bulb", "position": [0, 5, 0], "intensity": [1, 2, 3], "color": 2},
    {"type": "spot", "position": [0, 3, 0], "target": [0, 0, 0], "power": 100,
     "inner_angle_degrees": 20, "outer_angle_degrees": 30},
    {"type": "directional", "direction": [0, -2, 0], "intensity": 4}
  ],
  "camera": {"position": [0, 1, 5], "target": [0, 1, 0], "vertical_fov_degrees": 50},
  "hmd": {"preset": "vive", "position": [0, 1.7, 3], "yaw_pitch_roll_degrees": [90, 0, 0], "ipd": 0.07},
  "animation": {
    "frames_per_second": 24,
    "nodes": {
      "first": {"translation": {"times": [0, 1, 2], "values": [[0, 0, 0], [1, 0, 0], [2, 0, 0]]}},
      "1": {"rotation_degrees": {"times": [0, 4], "values": [[0, 0, 0], [0, 90, 0]]},
            "scale": {"times": [0, 4], "values": [1, 3]}, "interpolation": "step"}
    }
  }
})";

}  // namespace

TEST(SceneFile, FullRoundTrip) {
    auto dir = fixture_dir("scene_full");
    Scene s = load(write_file(dir, "full.json", kFull));
    EXPECT_EQ(s.name, "fixture");
    EXPECT_EQ(s.meshes.size(), 5u);  // a, b, a again (override), a + b (fitted)

    // Entry nodes are roots; the file's nodes hang below them.
    ASSERT_GE(s.nodes.size(), 4u);
    const SceneNode& first = s.nodes[0];
    EXPECT_EQ(first.name, "first");
    EXPECT_EQ(first.parent, -1);
    EXPECT_EQ(first.local.translation, Vec3(1, 2, 3));
    EXPECT_EQ(first.local.scale, Vec3(2));
    EXPECT_NEAR(glm::angle(first.local.rotation), glm::radians(90.0f), 1e-5f);
    EXPECT_EQ(s.nodes[1].parent, 0);

    // World position of a.obj's vertex (1,0,0): scaled 2, turned 90° about Y (x → −z),
    // moved by the animated translation (0 at t = 0) instead of the rest one.
    SceneFrame f = s.evaluate(0.0);
    ASSERT_EQ(f.meshes.size(), 5u);
    EXPECT_NEAR(f.meshes[0].positions[1].x, 0.0f, 1e-5f);
    EXPECT_NEAR(f.meshes[0].positions[1].z, -2.0f, 1e-5f);
    // b's (0,4,0): the scale channel (1 at t = 0) replaces the rest scale [1, 2, 3].
    EXPECT_NEAR(f.meshes[1].positions[2].y, 4.0f, 1e-5f);
    EXPECT_EQ(s.nodes[2].local.scale, Vec3(1, 2, 3));

    // Materials: named ones first, the files' merged with "shared" stored once.
    std::map<std::string, int> count;
    for (const auto& m : s.materials) ++count[m.name];
    EXPECT_EQ(count["shared"], 1);
    EXPECT_EQ(count["red"], 1);
    EXPECT_EQ(count["green"], 1);
    EXPECT_EQ(count["glow"], 1);
    auto material_of = [&](size_t mesh, size_t tri) { return s.materials[s.meshes[mesh].material_ids[tri]]; };
    EXPECT_EQ(material_of(0, 0).name, "red");
    EXPECT_EQ(material_of(0, 1).name, "shared");
    EXPECT_EQ(material_of(1, 0).name, "shared");
    EXPECT_EQ(material_of(1, 1).name, "green");
    EXPECT_EQ(s.meshes[0].material_ids[1], s.meshes[1].material_ids[0]);
    EXPECT_EQ(material_of(2, 0).name, "glow");  // override on every face
    EXPECT_EQ(material_of(2, 1).name, "glow");
    EXPECT_EQ(material_of(2, 0).emission, Vec3(5, 4, 3));
    const Material* shiny = nullptr;
    for (const auto& m : s.materials)
        if (m.name == "shiny") shiny = &m;
    ASSERT_TRUE(shiny);
    EXPECT_NEAR(shiny->phong_exponent, exponent_from_roughness(0.5f), 1e-4f);

    // fit_to_box with anchor bottom: inside the box, resting on min.y, touching on the
    // limiting axis (b.obj is 4 tall → height 1 limits).
    Bounds3 fitted;
    for (size_t m = 3; m < 5; ++m)
        for (const Vec3& p : f.meshes[m].positions) fitted.extend(p);
    EXPECT_NEAR(fitted.min.y, 0.0f, 1e-5f);
    EXPECT_NEAR(fitted.max.y, 1.0f, 1e-5f);
    EXPECT_GE(fitted.min.x, 10.0f - 1e-5f);
    EXPECT_LE(fitted.max.x, 12.0f + 1e-5f);
    EXPECT_NEAR(0.5f * (fitted.min.x + fitted.max.x), 11.0f, 1e-5f);
    EXPECT_NEAR(0.5f * (fitted.min.z + fitted.max.z), 10.5f, 1e-5f);

    // Lights.
    ASSERT_EQ(s.lights.size(), 3u);
    EXPECT_EQ(s.lights[0].name, "bulb");
    EXPECT_EQ(s.lights[0].intensity, Vec3(2, 4, 6));
    EXPECT_EQ(s.lights[0].node, -1);
    EXPECT_EQ(s.lights[1].type, LightType::Spot);
    EXPECT_NEAR(s.lights[1].direction.y, -1.0f, 1e-6f);
    const float cone = 2 * kPi * (1 - 0.5f * (std::cos(glm::radians(20.0f)) + std::cos(glm::radians(30.0f))));
    EXPECT_NEAR(s.lights[1].intensity.x, 100.0f / cone, 1e-3f);
    EXPECT_NEAR(s.lights[1].cos_outer, std::cos(glm::radians(30.0f)), 1e-6f);
    EXPECT_EQ(s.lights[2].type, LightType::Directional);
    EXPECT_EQ(s.lights[2].direction, Vec3(0, -1, 0));

    // Camera and HMD.
    ASSERT_TRUE(s.camera);
    EXPECT_EQ(s.camera->position, Vec3(0, 1, 5));
    EXPECT_FLOAT_EQ(s.camera->vertical_fov_degrees, 50.0f);
    ASSERT_TRUE(s.hmd);
    EXPECT_EQ(s.hmd->preset, "vive");
    ASSERT_TRUE(s.hmd->ipd);
    EXPECT_FLOAT_EQ(*s.hmd->ipd, 0.07f);
    const Vec3 forward = s.hmd->pose.orientation * Vec3(0, 0, -1);  // yaw 90° left: looks down −X
    EXPECT_NEAR(forward.x, -1.0f, 1e-5f);

    // Animation on entries by name and by index.
    EXPECT_DOUBLE_EQ(s.frames_per_second, 24.0);
    EXPECT_TRUE(s.is_animated());
    EXPECT_FLOAT_EQ(float(s.animation_duration()), 4.0f);
    ASSERT_EQ(first.animation.translation.values.size(), 3u);
    EXPECT_EQ(first.animation.translation.values[2], Vec3(2, 0, 0));
    const SceneNode* second = nullptr;
    for (const auto& n : s.nodes)
        if (n.name == "b" && n.parent < 0) second = &n;  // the entry, not the file's node
    ASSERT_TRUE(second);
    EXPECT_TRUE(second->animation.step);
    EXPECT_EQ(second->animation.scale.values[1], Vec3(3));
    EXPECT_NEAR(glm::angle(second->animation.rotation.values[1]), glm::radians(90.0f), 1e-5f);
    SceneFrame later = s.evaluate(1.0);
    EXPECT_NEAR(later.meshes[0].positions[0].x, 1.0f, 1e-5f);  // vertex at the origin follows the translation
}

TEST(SceneFile, FilesAreFoundThroughTheAssetSearchPath) {
    auto assets = fixture_dir("scene_assets");
    auto other = test::temp_dir("scene_assets_json");
    auto json = write_file(other, "s.json", R"({"meshes": [{"file": "models/b.obj"}]})");
    // Not next to the json: found only through the search path.
    EXPECT_NE(error_of([&] { load(json); }).find("not found"), std::string::npos);
    Scene s = load_scene_file(json, AssetPaths({other / "nowhere", assets}));
    EXPECT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].positions[2], Vec3(0, 4, 0));
}

// Two OBJ parts whose materials share a name and colour but not a texture stay two
// materials.
TEST(SceneFile, MaterialsThatDifferOnlyInTheirTextureAreNotMerged) {
    auto dir = test::temp_dir("scene_file_textures");
    for (const char* name : {"a", "b"}) {
        const uint8_t grey = name[0] == 'a' ? 40 : 200;
        const std::vector<uint8_t> texels(16, grey);
        std::string png;
        stbi_write_png_to_func([](void* c, void* d, int n) { static_cast<std::string*>(c)->append(static_cast<char*>(d), size_t(n)); },
                               &png, 2, 2, 4, texels.data(), 8);
        write_file(dir, std::string(name) + ".png", png);
        write_file(dir, std::string(name) + ".mtl", "newmtl wall\nKd 1 1 1\nmap_Kd " + std::string(name) + ".png\n");
        write_file(dir, std::string(name) + ".obj",
                   "mtllib " + std::string(name) + ".mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl wall\nf 1/1 2/2 3/3\n");
    }
    const Scene s = load(write_file(dir, "s.json", R"({"meshes": [{"file": "a.obj"}, {"file": "b.obj"}]})"));
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_NE(s.materials[0].albedo_texture.image, s.materials[1].albedo_texture.image);
    EXPECT_NE(s.meshes[0].material_ids[0], s.meshes[1].material_ids[0]);
}

TEST(SceneFile, MissingSceneFile) {
    std::string msg = error_of([] { load("/nonexistent/scene.json"); });
    EXPECT_NE(msg.find("scene.json"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not found"), std::string::npos) << msg;
}

TEST(SceneFile, BadJsonNamesLineAndColumn) {
    auto dir = fixture_dir("scene_bad_json");
    auto p = write_file(dir, "bad.json", "{\n  \"meshes\": [\n    {\"file\": \"models/a.obj\",}\n  ]\n}\n");
    std::string msg = error_of([&] { load(p); });
    EXPECT_NE(msg.find("bad.json:3:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("JSON syntax error"), std::string::npos) << msg;
}

TEST(SceneFile, UnknownKeysAreErrorsWithTheirPath) {
    auto dir = fixture_dir("scene_unknown_key");
    auto top = write_file(dir, "top.json", R"({"meshes": [{"file": "models/a.obj"}], "lightz": []})");
    std::string msg = error_of([&] { load(top); });
    EXPECT_NE(msg.find("top.json: /lightz: unknown key 'lightz'"), std::string::npos) << msg;

    auto nested = write_file(dir, "nested.json", R"({"meshes": [{"file": "models/a.obj"}, {"file": "models/b.obj", "scal": 2}]})");
    msg = error_of([&] { load(nested); });
    EXPECT_NE(msg.find("nested.json: /meshes/1/scal: unknown key"), std::string::npos) << msg;

    auto light = write_file(dir, "light.json",
                            R"({"meshes": [{"file": "models/a.obj"}], "lights": [{"type": "point", "position": [0,0,0], "intensity": 1, "direction": [0,1,0]}]})");
    msg = error_of([&] { load(light); });
    EXPECT_NE(msg.find("light.json: /lights/0/direction: unknown key"), std::string::npos) << msg;

    auto material = write_file(dir, "mat.json", R"({"materials": {"a/b": {"albedo": 0.5, "colour": 1}}, "meshes": [{"file": "models/a.obj"}]})");
    msg = error_of([&] { load(material); });
    EXPECT_NE(msg.find("mat.json: /materials/a~1b/colour: unknown key"), std::string::npos) << msg;
}

TEST(SceneFile, WrongTypesAreErrorsWithTheirPath) {
    auto dir = fixture_dir("scene_wrong_type");
    struct Case {
        const char* json;
        const char* expected;
    } cases[] = {
        {R"({"meshes": [{"file": 3}]})", "/meshes/0/file: expected a string, got number"},
        {R"({"meshes": [{"file": "models/a.obj", "translate": [1, 2]}]})", "/meshes/0/translate: expected an array of 3 numbers"},
        {R"({"meshes": [{"file": "models/a.obj", "scale": "big"}]})", "/meshes/0/scale: expected a number or an array of 3 numbers, got string"},
        {R"({"meshes": [{"file": "models/a.obj", "translate": [1, "x", 3]}]})", "/meshes/0/translate/1: expected a number"},
        {R"({"meshes": {"file": "models/a.obj"}})", "/meshes: expected a non-empty array"},
        {R"({"meshes": []})", "/meshes: expected a non-empty array of meshes, got an empty array"},
        {R"({"lights": []})", "/meshes: missing"},
        {R"([1, 2])", "/: expected an object"},
        {R"({"meshes": [{"file": "models/a.obj"}], "camera": {"position": [0,0,1], "target": [0,0,0], "vertical_fov_degrees": 200}})", "/camera/vertical_fov_degrees: must be in (0, 180)"},
        {R"({"meshes": [{"file": "models/a.obj"}], "lights": [{"type": "area"}]})", "/lights/0/type: unknown light type 'area'"},
        {R"({"meshes": [{"file": "models/a.obj"}], "lights": [{"type": "point", "position": [0,0,0]}]})", "/lights/0: missing 'intensity'"},
        {R"({"meshes": [{"file": "models/a.obj"}], "materials": {"m": {"albedo": [0.9, 0.9, 0.9], "specular": 0.5}}})", "/materials/m: albedo + specular exceeds 1"},
        {R"({"meshes": [{"file": "models/a.obj"}], "materials": {"m": {"albedo": -1}}})", "/materials/m/albedo: colour components must not be negative"},
        {R"({"meshes": [{"file": "models/a.obj", "material": "nope"}]})", "/meshes/0/material: material 'nope' is not defined"},
        {R"({"meshes": [{"file": "models/a.obj", "translate": [0,0,0], "fit_to_box": {"min": [0,0,0], "max": [1,1,1]}}]})", "/meshes/0: keys fit_to_box, translate cannot be given together"},
        {R"({"meshes": [{"file": "models/a.obj", "fit_to_box": {"min": [0,0,0], "max": [1,0,1]}}]})", "/meshes/0/fit_to_box: 'max' must exceed 'min'"},
        {R"({"meshes": [{"file": "models/a.obj"}], "hmd": {"preset": "nosuchheadset"}})", "/hmd/preset: unknown HMD preset 'nosuchheadset'"},
        {R"({"meshes": [{"file": "models/a.obj"}], "hmd": {"target": [0,0,-1], "yaw_pitch_roll_degrees": [0,0,0]}})", "/hmd: keys yaw_pitch_roll_degrees, target cannot be given together"},
        {R"({"meshes": [{"file": "models/a.obj"}], "animation": {"nodes": {"7": {"translation": {"times": [0], "values": [[0,0,0]]}}}}})", "/animation/nodes/7: mesh index 7 is out of range"},
        {R"({"meshes": [{"file": "models/a.obj"}], "animation": {"nodes": {"ghost": {"translation": {"times": [0], "values": [[0,0,0]]}}}}})", "/animation/nodes/ghost: no mesh is named 'ghost'"},
        {R"({"meshes": [{"file": "models/a.obj"}], "animation": {"nodes": {"0": {"translation": {"times": [1, 0], "values": [[0,0,0], [1,1,1]]}}}}})", "/animation/nodes/0/translation/times/1: times must be strictly increasing"},
        {R"({"meshes": [{"file": "models/a.obj"}], "animation": {"nodes": {"0": {"rotation": {"times": [0], "values": [[0,0,0,0]]}}}}})", "/animation/nodes/0/rotation/values/0: quaternion [w, x, y, z] must not be zero"},
        {R"({"meshes": [{"file": "models/a.obj"}], "animation": {"nodes": {"0": {"scale": {"times": [0, 1], "values": [1]}}}}})", "/animation/nodes/0/scale/values: 1 values for 2 times"},
    };
    int i = 0;
    for (const Case& c : cases) {
        const std::string name = "case" + std::to_string(i++) + ".json";
        auto p = write_file(dir, name, c.json);
        std::string msg = error_of([&] { load(p); });
        EXPECT_NE(msg.find(name + ": "), std::string::npos) << c.json << "\n  → " << msg;
        EXPECT_NE(msg.find(c.expected), std::string::npos) << c.json << "\n  → " << msg;
    }
}

TEST(SceneFile, MessagesQuoteNumbersAsGiven) {
    // std::to_string printed 1e-300 as 0.000000 and six digits rounded 1234.5678 away.
    auto dir = fixture_dir("scene_numbers_as_given");
    const std::string mesh = R"({"meshes": [{"file": "models/a.obj"}], )";
    const std::pair<const char*, const char*> cases[] = {
        {R"("animation": {"frames_per_second": 1e-300}})", "/animation/frames_per_second: 1e-300 is too small"},
        {R"("animation": {"frames_per_second": -0.001}})", "expected a positive number, got -0.001"},
        {R"("animation": {"frames_per_second": 1234.5678}})", "1234.5678 is out of range (0, 1000]"},
        {R"("animation": {"frames_per_second": 1.2345678901234567e300}})", "1.2345678901234567e+300 is out of range"},
    };
    int i = 0;
    for (const auto& [json, expected] : cases) {
        auto p = write_file(dir, "numbers" + std::to_string(i++) + ".json", mesh + json);
        const std::string msg = error_of([&] { load(p); });
        EXPECT_NE(msg.find(expected), std::string::npos) << json << "\n  → " << msg;
        EXPECT_EQ(msg.find("0.000000"), std::string::npos) << msg;
    }
}

TEST(SceneFile, MissingMeshFileNamesPathAndSearchedDirectories) {
    auto dir = fixture_dir("scene_missing_mesh");
    auto p = write_file(dir, "x.json", R"({"meshes": [{"file": "models/a.obj"}, {"file": "foo.obj"}]})");
    std::string msg = error_of([&] { load_scene_file(p, AssetPaths({"/some/asset/dir"})); });
    EXPECT_NE(msg.find("x.json: /meshes/1/file: file 'foo.obj' not found in"), std::string::npos) << msg;
    EXPECT_NE(msg.find("/some/asset/dir"), std::string::npos) << msg;
    EXPECT_NE(msg.find(dir.string()), std::string::npos) << msg;

    auto q = write_file(dir, "y.json", R"({"meshes": [{"files": ["models/a.obj", "gone.obj"]}]})");
    msg = error_of([&] { load(q); });
    EXPECT_NE(msg.find("y.json: /meshes/0/files/1: file 'gone.obj' not found"), std::string::npos) << msg;
}

TEST(SceneFile, BrokenMeshFileErrorCarriesBothLocations) {
    auto dir = fixture_dir("scene_broken_mesh");
    write_file(dir, "broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n");
    auto p = write_file(dir, "z.json", R"({"meshes": [{"file": "broken.obj"}]})");
    std::string msg = error_of([&] { load(p); });
    EXPECT_NE(msg.find("z.json: /meshes/0/file: "), std::string::npos) << msg;
    EXPECT_NE(msg.find("broken.obj:4"), std::string::npos) << msg;
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
}

TEST(SceneFile, DegenerateCountsAreSummed) {
    auto dir = fixture_dir("scene_degenerate");
    write_file(dir, "deg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n");
    auto p = write_file(dir, "d.json", R"({"meshes": [{"file": "deg.obj"}, {"file": "deg.obj", "translate": [5, 0, 0]}]})");
    Scene s = load(p);
    EXPECT_EQ(s.degenerate_triangles_dropped, 2u);
    EXPECT_EQ(s.triangle_count(), 2u);
}

// ---- Every shipped scene file loads ----

TEST(ShippedScenes, EveryJsonInScenesLoads) {
    if (!test::shared_asset("MANIFEST.md")) GTEST_SKIP() << "../shared/scenes (MANIFEST.md) not found";
    const fs::path dir = fs::path(GILAB_SOURCE_DIR) / "scenes";
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == ".json") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    ASSERT_GE(files.size(), 14u);
    const AssetPaths assets = AssetPaths::from_environment();
    for (const fs::path& f : files) {
        SCOPED_TRACE(f.string());
        Scene s;
        ASSERT_NO_THROW(s = load_scene_file(f, assets)) << error_of([&] { load_scene_file(f, assets); });
        EXPECT_GT(s.triangle_count(), 0u);
        EXPECT_TRUE(s.has_emitters()) << "no light";
        EXPECT_TRUE(s.camera.has_value());
        EXPECT_TRUE(s.hmd.has_value());
        EXPECT_NO_THROW(s.validate());
        // The camera looks at something inside the scene's bounds.
        const Bounds3 b = s.evaluate(0.0).bounds;
        EXPECT_TRUE(b.contains(s.camera->target)) << "camera target outside the scene bounds";
    }
}

TEST(ShippedScenes, KitchenMergesAllPartsWithManifestCounts) {
    if (!test::shared_asset("kitchen-interior/part0.obj")) GTEST_SKIP() << "kitchen-interior not found";
    Scene s = load_scene_file(fs::path(GILAB_SOURCE_DIR) / "scenes" / "kitchen_interior.json", AssetPaths::from_environment());
    EXPECT_EQ(s.meshes.size(), 174u);
    EXPECT_EQ(s.triangle_count() + s.degenerate_triangles_dropped, 247265u);
    // Decimetres, Z up → metres, Y up: about 6.9 × 2.8 × 4.1 m with the floor at 0.
    const Bounds3 b = s.evaluate(0.0).bounds;
    EXPECT_NEAR(b.extent().x, 6.86f, 0.02f);
    EXPECT_NEAR(b.extent().y, 2.80f, 0.02f);
    EXPECT_NEAR(b.extent().z, 4.07f, 0.02f);
    EXPECT_NEAR(b.min.y, 0.0f, 1e-3f);
    // bedroom.mtl is shared by 173 parts: its materials are stored once each.
    std::map<std::string, int> names;
    for (const auto& m : s.materials) ++names[m.name];
    for (const auto& [name, n] : names) EXPECT_LE(n, 2) << name;
}

// P3 measures Sibenik from inside its nave: the camera stands between the floor (a
// standing eye height below it), the vault above and the side walls, and sees down the
// nave (its forward ray travels at least half the cathedral's length).
TEST(ShippedScenes, SibenikCameraStandsInsideTheNave) {
    if (!test::shared_asset("sibenik/sibenik.obj")) GTEST_SKIP() << "sibenik not found";
    Scene s = load_scene_file(fs::path(GILAB_SOURCE_DIR) / "scenes" / "sibenik.json", AssetPaths::from_environment());
    EXPECT_EQ(s.triangle_count() + s.degenerate_triangles_dropped, 75284u);
    const SceneFrame frame = s.evaluate(0.0);
    const RayTracer tracer(frame);
    const Vec3 eye = s.camera->position;
    auto distance = [&](Vec3 direction) {
        const Hit h = tracer.intersect(Ray{eye, glm::normalize(direction)});
        return h.valid() ? h.t : kInfinity;
    };
    const float floor = distance(Vec3(0, -1, 0));
    EXPECT_GT(floor, 1.0f);
    EXPECT_LT(floor, 3.0f);
    EXPECT_LT(distance(Vec3(0, 1, 0)), 30.0f) << "no vault above the camera";
    EXPECT_LT(distance(Vec3(0, 0, 1)), 9.0f) << "no wall on the +z side";
    EXPECT_LT(distance(Vec3(0, 0, -1)), 9.0f) << "no wall on the -z side";
    EXPECT_GT(distance(s.camera->target - eye), 0.5f * frame.bounds.extent().x);
}

// The five animated samples move by their own skinned animation, not a turntable, and
// their bind pose as skinning places it fills their fit box.
TEST(ShippedScenes, SkinnedModelsUseTheirOwnAnimationAndFitTheirBox) {
    struct Model {
        const char* scene;
        const char* asset;
        Vec3 box_min, box_max;
    };
    const Model models[] = {{"brainstem", "animated/BrainStem.glb", {-1.2f, 0, -1.2f}, {1.2f, 1.8f, 1.2f}},
                            {"cesium_man", "animated/CesiumMan.glb", {}, {}},
                            {"fox", "animated/Fox.glb", {}, {}},
                            {"rigged_figure", "animated/RiggedFigure.glb", {}, {}},
                            {"rigged_simple", "animated/RiggedSimple.glb", {-0.4f, 0, -0.4f}, {0.4f, 1.8f, 0.4f}}};
    for (const Model& m : models) {
        SCOPED_TRACE(m.scene);
        if (!test::shared_asset(m.asset)) GTEST_SKIP() << m.asset << " not found";
        const Scene s = load_scene_file(fs::path(GILAB_SOURCE_DIR) / "scenes" / (std::string(m.scene) + ".json"),
                                        AssetPaths::from_environment());
        const Scene file = load_gltf(*test::shared_asset(m.asset));
        EXPECT_FALSE(s.skins.empty());
        for (const SceneNode& n : s.nodes)
            if (n.name == "model") {
                EXPECT_TRUE(n.animation.empty()) << "the entry must not carry a turntable";
            }
        EXPECT_DOUBLE_EQ(s.animation_duration(), file.animation_duration());
        if (m.box_max == m.box_min) continue;
        Bounds3 b;  // the model alone, at rest
        const SceneFrame rest = s.evaluate_rest();
        for (const WorldMesh& wm : rest.meshes)
            if (s.nodes[wm.node].skin >= 0)
                for (const Vec3& p : wm.positions) b.extend(p);
        const Vec3 target = m.box_max - m.box_min;
        EXPECT_NEAR(b.min.y, m.box_min.y, 1e-4f);  // anchor "bottom"
        float fill = 0;
        for (int c = 0; c < 3; ++c) {
            EXPECT_LE(b.extent()[c], target[c] + 1e-4f) << "axis " << c;
            fill = std::max(fill, b.extent()[c] / target[c]);
        }
        EXPECT_NEAR(fill, 1.0f, 1e-4f) << "the fitted model touches its box on one axis";
    }
}

// A skinned file used by two entries loads once and is merged twice: each copy's skin
// must point at its own joints, so the second copy is the first one moved.
TEST(SceneFile, SkinnedFileMergedTwiceKeepsItsOwnJoints) {
    auto asset = test::shared_asset("animated/RiggedSimple.glb");
    if (!asset) GTEST_SKIP() << "animated/RiggedSimple.glb not found";
    auto dir = test::temp_dir("scene_two_skins");
    const fs::path path = write_file(dir, "two.json", R"({
  "meshes": [
    {"name": "a", "file": ")" + asset->string() + R"("},
    {"name": "b", "file": ")" + asset->string() + R"(", "translate": [5, 0, 0]}
  ],
  "lights": [{"type": "point", "position": [0, 5, 0], "intensity": 1}]
})");
    const Scene s = load(path);
    ASSERT_EQ(s.skins.size(), 2u);
    EXPECT_NO_THROW(s.validate());
    for (uint32_t j : s.skins[0].joints) EXPECT_LT(j, s.skins[1].joints.front());
    const SceneFrame f = s.evaluate(1.0);
    ASSERT_EQ(f.meshes.size(), 2u);
    for (size_t v = 0; v < f.meshes[0].positions.size(); ++v)
        EXPECT_NEAR(glm::length(f.meshes[1].positions[v] - (f.meshes[0].positions[v] + Vec3(5, 0, 0))), 0.0f, 1e-4f);
}

TEST(AssetPathsTest, SearchOrderFlagThenEnvironmentThenSharedScenes) {
    const char* old = std::getenv("GILAB_ASSETS");
    const std::string saved = old ? old : "";
    setenv("GILAB_ASSETS", "/env/one::/env/two", 1);
    AssetPaths paths = AssetPaths::from_environment(std::string("/flag/a:/flag/b"));
    if (old) setenv("GILAB_ASSETS", saved.c_str(), 1);
    else unsetenv("GILAB_ASSETS");
    const auto& dirs = paths.dirs();
    ASSERT_EQ(dirs.size(), 5u);
    EXPECT_EQ(dirs[0], fs::path("/flag/a"));
    EXPECT_EQ(dirs[1], fs::path("/flag/b"));
    EXPECT_EQ(dirs[2], fs::path("/env/one"));
    EXPECT_EQ(dirs[3], fs::path("/env/two"));
    EXPECT_EQ(dirs[4].filename(), "scenes");
    EXPECT_EQ(dirs[4].parent_path().filename(), "shared");
    EXPECT_EQ(paths.describe().substr(0, 16), "/flag/a:/flag/b:");

    std::string msg = error_of([&] { paths.resolve("no/such/file.obj"); });
    EXPECT_NE(msg.find("no/such/file.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("/flag/a:/flag/b:/env/one:/env/two"), std::string::npos) << msg;
}

TEST(AssetPathsTest, LaterDirectoriesAreUsedWhenEarlierOnesLackTheFile) {
    auto first = test::temp_dir("asset_paths_first");
    auto second = test::temp_dir("asset_paths_second");
    write_file(second, "sub/m.obj", "v 0 0 0\n");
    write_file(first, "other.obj", "v 0 0 0\n");
    AssetPaths paths({first, second});
    EXPECT_EQ(paths.resolve("sub/m.obj"), second / "sub/m.obj");
    EXPECT_EQ(paths.resolve("other.obj"), first / "other.obj");
    EXPECT_FALSE(paths.find("sub/none.obj").has_value());
    // An absolute path that exists is used as it is.
    EXPECT_EQ(paths.resolve((second / "sub/m.obj").string()), second / "sub/m.obj");
}
