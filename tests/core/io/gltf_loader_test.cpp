// glTF loading: files written by tinygltf's own writer (.gltf with an embedded base64
// buffer, and .glb) round-trip through load_gltf; malformed files and bad skins fail
// with the file name; a skinned mesh at its bind-pose time equals the unskinned mesh;
// the animated sample models from ../shared/scenes match the MANIFEST.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/io/scene_file.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;
using gilab::test::error_of;
using gilab::test::write_file;

namespace {

// Builds a model with one buffer; each add_* appends a buffer view and an accessor.
struct ModelBuilder {
    tinygltf::Model model;

    ModelBuilder() {
        model.buffers.emplace_back();
        model.asset.version = "2.0";
    }

    int add_accessor(const void* data, size_t bytes, int component_type, int type, size_t count, bool normalized = false) {
        auto& buf = model.buffers[0].data;
        while (buf.size() % 4) buf.push_back(0);
        tinygltf::BufferView view;
        view.buffer = 0;
        view.byteOffset = buf.size();
        view.byteLength = bytes;
        const auto* p = static_cast<const unsigned char*>(data);
        buf.insert(buf.end(), p, p + bytes);
        model.bufferViews.push_back(view);
        tinygltf::Accessor acc;
        acc.bufferView = int(model.bufferViews.size() - 1);
        acc.byteOffset = 0;
        acc.componentType = component_type;
        acc.type = type;
        acc.count = count;
        acc.normalized = normalized;
        model.accessors.push_back(acc);
        return int(model.accessors.size() - 1);
    }
    int floats(const std::vector<float>& v, int type, int components) {
        return add_accessor(v.data(), v.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT, type, v.size() / size_t(components));
    }
    int vec3s(const std::vector<float>& v) {
        int a = floats(v, TINYGLTF_TYPE_VEC3, 3);
        // POSITION accessors need min/max per the specification.
        auto& acc = model.accessors[size_t(a)];
        acc.minValues = {1e30, 1e30, 1e30};
        acc.maxValues = {-1e30, -1e30, -1e30};
        for (size_t i = 0; i < v.size(); ++i) {
            acc.minValues[i % 3] = std::min(acc.minValues[i % 3], double(v[i]));
            acc.maxValues[i % 3] = std::max(acc.maxValues[i % 3], double(v[i]));
        }
        return a;
    }
    int indices16(const std::vector<uint16_t>& v) {
        return add_accessor(v.data(), v.size() * 2, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR, v.size());
    }
    int add_triangle_mesh(const std::vector<float>& positions, const std::vector<uint16_t>& indices, int material,
                          const std::vector<float>& normals = {}, const std::vector<float>& uvs = {}) {
        tinygltf::Primitive prim;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        prim.material = material;
        prim.attributes["POSITION"] = vec3s(positions);
        if (!normals.empty()) prim.attributes["NORMAL"] = floats(normals, TINYGLTF_TYPE_VEC3, 3);
        if (!uvs.empty()) prim.attributes["TEXCOORD_0"] = floats(uvs, TINYGLTF_TYPE_VEC2, 2);
        if (!indices.empty()) prim.indices = indices16(indices);
        tinygltf::Mesh mesh;
        mesh.name = "mesh" + std::to_string(model.meshes.size());
        mesh.primitives.push_back(prim);
        model.meshes.push_back(mesh);
        return int(model.meshes.size() - 1);
    }
    int add_node(const std::string& name, int mesh = -1) {
        tinygltf::Node n;
        n.name = name;
        n.mesh = mesh;
        model.nodes.push_back(n);
        return int(model.nodes.size() - 1);
    }
    void finish(const std::vector<int>& roots) {
        tinygltf::Scene scene;
        scene.nodes = roots;
        model.scenes = {scene};
        model.defaultScene = 0;
    }
    fs::path write(const fs::path& path, bool binary) {
        tinygltf::TinyGLTF writer;
        EXPECT_TRUE(writer.WriteGltfSceneToFile(&model, path.string(), true, true, true, binary));
        return path;
    }
};

const std::vector<float> kQuad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const std::vector<uint16_t> kQuadIndices = {0, 1, 2, 0, 2, 3};

tinygltf::Value object(std::map<std::string, tinygltf::Value> m) { return tinygltf::Value(m); }

// A scene exercising hierarchy, materials, lights and animation.
ModelBuilder full_model() {
    ModelBuilder b;
    tinygltf::Material mat;
    mat.name = "half_metal";
    mat.pbrMetallicRoughness.baseColorFactor = {0.5, 0.25, 0.8, 1.0};
    mat.pbrMetallicRoughness.metallicFactor = 0.5;
    mat.pbrMetallicRoughness.roughnessFactor = 0.5;
    mat.emissiveFactor = {1.0, 0.5, 0.0};
    mat.extensions["KHR_materials_emissive_strength"] = object({{"emissiveStrength", tinygltf::Value(4.0)}});
    b.model.materials.push_back(mat);
    b.model.extensionsUsed.push_back("KHR_materials_emissive_strength");

    const int quad = b.add_triangle_mesh(kQuad, kQuadIndices, 0, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1},
                                         {0, 0, 1, 0, 1, 1, 0, 1});
    // Non-indexed, no material.
    const int tri = b.add_triangle_mesh({0, 0, 0, 0, 0, 1, 0, 1, 0}, {}, -1);

    const int root = b.add_node("root");
    b.model.nodes[size_t(root)].translation = {1, 2, 3};
    const int child = b.add_node("child", quad);
    b.model.nodes[size_t(child)].matrix = {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 5, 0, 0, 1};  // scale 2, move x+5
    const int other = b.add_node("other", tri);
    b.model.nodes[size_t(root)].children = {child, other};

    tinygltf::Light point;
    point.name = "bulb";
    point.type = "point";
    point.color = {1.0, 0.5, 0.25};
    point.intensity = 8.0;
    tinygltf::Light spot;
    spot.name = "spot";
    spot.type = "spot";
    spot.intensity = 2.0;
    spot.spot.innerConeAngle = 0.25;
    spot.spot.outerConeAngle = 0.5;
    tinygltf::Light sun;
    sun.name = "sun";
    sun.type = "directional";
    sun.intensity = 3.0;
    b.model.lights = {point, spot, sun};
    for (int i = 0; i < 3; ++i) {
        const int n = b.add_node("light" + std::to_string(i));
        b.model.nodes[size_t(n)].extensions["KHR_lights_punctual"] = object({{"light", tinygltf::Value(i)}});
        b.model.nodes[size_t(n)].translation = {0, 10.0 + i, 0};
        b.model.nodes[size_t(root)].children.push_back(n);
    }

    // Animation 0: child translation (LINEAR), other rotation (STEP), root scale (CUBICSPLINE).
    tinygltf::Animation anim;
    anim.name = "main";
    const int times = b.floats({0.0f, 1.0f, 2.0f}, TINYGLTF_TYPE_SCALAR, 1);
    const int moves = b.floats({0, 0, 0, 1, 0, 0, 2, 0, 0}, TINYGLTF_TYPE_VEC3, 3);
    const float s = std::sqrt(0.5f);
    const int turns = b.floats({0, 0, 0, 1, 0, s, 0, s, 0, 1, 0, 0}, TINYGLTF_TYPE_VEC4, 4);  // xyzw
    // Cubic: (in-tangent, value, out-tangent) per key.
    const int scales = b.floats({9, 9, 9, 1, 1, 1, 9, 9, 9, 9, 9, 9, 2, 2, 2, 9, 9, 9, 9, 9, 9, 3, 3, 3, 9, 9, 9},
                                TINYGLTF_TYPE_VEC3, 3);
    auto sampler = [&](int input, int output, const char* interp) {
        tinygltf::AnimationSampler sm;
        sm.input = input;
        sm.output = output;
        sm.interpolation = interp;
        anim.samplers.push_back(sm);
        return int(anim.samplers.size() - 1);
    };
    auto channel = [&](int smp, int node, const char* path) {
        tinygltf::AnimationChannel ch;
        ch.sampler = smp;
        ch.target_node = node;
        ch.target_path = path;
        anim.channels.push_back(ch);
    };
    channel(sampler(times, moves, "LINEAR"), child, "translation");
    channel(sampler(times, turns, "STEP"), other, "rotation");
    channel(sampler(times, scales, "CUBICSPLINE"), root, "scale");
    b.model.animations.push_back(anim);
    // Animation 1 drives the same property again: the first animation must win.
    tinygltf::Animation second;
    second.name = "second";
    const int later = b.floats({0.0f, 5.0f}, TINYGLTF_TYPE_SCALAR, 1);
    const int far = b.floats({7, 7, 7, 8, 8, 8}, TINYGLTF_TYPE_VEC3, 3);
    tinygltf::AnimationSampler sm;
    sm.input = later;
    sm.output = far;
    second.samplers.push_back(sm);
    tinygltf::AnimationChannel ch;
    ch.sampler = 0;
    ch.target_node = child;
    ch.target_path = "translation";
    second.channels.push_back(ch);
    b.model.animations.push_back(second);
    b.finish({root});
    return b;
}

const SceneNode* find_node(const Scene& s, const std::string& name) {
    for (const auto& n : s.nodes)
        if (n.name == name) return &n;
    return nullptr;
}

void check_full_model(const Scene& s) {
    ASSERT_EQ(s.meshes.size(), 2u);
    ASSERT_GE(s.nodes.size(), 6u);
    for (size_t i = 0; i < s.nodes.size(); ++i) EXPECT_LT(s.nodes[i].parent, int(i));
    const SceneNode* root = find_node(s, "root");
    const SceneNode* child = find_node(s, "child");
    ASSERT_TRUE(root && child);
    EXPECT_EQ(root->local.translation, Vec3(1, 2, 3));
    EXPECT_NEAR(child->local.scale.x, 2.0f, 1e-5f);
    EXPECT_NEAR(child->local.translation.x, 5.0f, 1e-5f);
    ASSERT_EQ(child->meshes.size(), 1u);

    const Mesh& quad = s.meshes[child->meshes[0]];
    ASSERT_EQ(quad.positions.size(), 4u);
    EXPECT_EQ(quad.positions[2], Vec3(1, 1, 0));
    ASSERT_EQ(quad.triangles.size(), 2u);
    EXPECT_EQ(quad.triangles[1], UVec3(0, 2, 3));
    ASSERT_EQ(quad.normals.size(), 4u);
    EXPECT_EQ(quad.normals[0], Vec3(0, 0, 1));
    ASSERT_EQ(quad.uvs.size(), 4u);
    EXPECT_EQ(quad.uvs[2], Vec2(1, 1));

    // Material: albedo = base·(1−m), specular = mix(0.04, base, m), emission × strength.
    const Material& m = s.materials[quad.material_ids[0]];
    EXPECT_EQ(m.name, "half_metal");
    EXPECT_NEAR(m.albedo.x, 0.25f, 1e-6f);
    EXPECT_NEAR(m.albedo.y, 0.125f, 1e-6f);
    EXPECT_NEAR(m.specular.x, 0.27f, 1e-6f);
    EXPECT_NEAR(m.specular.z, 0.42f, 1e-6f);
    EXPECT_NEAR(m.phong_exponent, exponent_from_roughness(0.5f), 1e-3f);
    EXPECT_NEAR(m.emission.x, 4.0f, 1e-6f);
    EXPECT_NEAR(m.emission.y, 2.0f, 1e-6f);

    // The non-indexed triangle gets the default material.
    const SceneNode* other = find_node(s, "other");
    ASSERT_TRUE(other);
    const Mesh& tri = s.meshes[other->meshes[0]];
    ASSERT_EQ(tri.triangles.size(), 1u);
    EXPECT_EQ(tri.triangles[0], UVec3(0, 1, 2));
    EXPECT_EQ(s.materials[tri.material_ids[0]].name, "default");

    // Lights on their nodes, intensities as colour × intensity, spot cones as cosines.
    ASSERT_EQ(s.lights.size(), 3u);
    const PunctualLight& bulb = s.lights[0];
    EXPECT_EQ(bulb.type, LightType::Point);
    EXPECT_EQ(bulb.intensity, Vec3(8, 4, 2));
    ASSERT_GE(bulb.node, 0);
    EXPECT_EQ(s.nodes[size_t(bulb.node)].name, "light0");
    EXPECT_EQ(s.lights[1].type, LightType::Spot);
    EXPECT_NEAR(s.lights[1].cos_inner, std::cos(0.25f), 1e-6f);
    EXPECT_NEAR(s.lights[1].cos_outer, std::cos(0.5f), 1e-6f);
    EXPECT_EQ(s.lights[2].type, LightType::Directional);
    EXPECT_EQ(s.lights[2].direction, Vec3(0, 0, -1));

    // Animation channels merged per node.
    EXPECT_TRUE(s.is_animated());
    EXPECT_FLOAT_EQ(float(s.animation_duration()), 2.0f);
    ASSERT_EQ(child->animation.translation.times.size(), 3u);  // the second animation was ignored
    EXPECT_EQ(child->animation.translation.values[2], Vec3(2, 0, 0));
    EXPECT_FALSE(child->animation.step);
    ASSERT_EQ(other->animation.rotation.values.size(), 3u);
    EXPECT_TRUE(other->animation.step);
    EXPECT_NEAR(other->animation.rotation.values[1].w, std::sqrt(0.5f), 1e-6f);
    EXPECT_NEAR(other->animation.rotation.values[1].y, std::sqrt(0.5f), 1e-6f);
    ASSERT_EQ(root->animation.scale.values.size(), 3u);
    EXPECT_EQ(root->animation.scale.values[1], Vec3(2));  // cubic spline: the key's value

    bool warned_overlap = false;
    for (const auto& w : s.warnings) warned_overlap |= w.find("earlier animation") != std::string::npos;
    EXPECT_TRUE(warned_overlap);

    // World space at t=1: root scaled 2, child moved to x=1 in root space.
    SceneFrame f = s.evaluate(1.0);
    EXPECT_EQ(f.lights.size(), 3u);
    EXPECT_NEAR(f.lights[0].position.y, 2.0f + 2.0f * 10.0f, 1e-4f);
}

}  // namespace

TEST(GltfLoader, EmbeddedGltfRoundTrip) {
    auto dir = test::temp_dir("gltf_round_trip");
    ModelBuilder b = full_model();
    Scene s = load_gltf(b.write(dir / "full.gltf", false));
    check_full_model(s);
    EXPECT_EQ(s.source, (dir / "full.gltf").string());
}

TEST(GltfLoader, BinaryGlbRoundTrip) {
    auto dir = test::temp_dir("glb_round_trip");
    ModelBuilder b = full_model();
    Scene s = load_gltf(b.write(dir / "full.glb", true));
    check_full_model(s);
}

TEST(GltfLoader, MeshFileDispatch) {
    auto dir = test::temp_dir("gltf_dispatch");
    ModelBuilder b = full_model();
    EXPECT_EQ(load_mesh_file(b.write(dir / "x.GLB", true)).meshes.size(), 2u);
}

// A strip of three vertex rows (y = 0, 1, 2) skinned to two joints: the bottom row to
// the root joint, the middle row half and half, the top row to the tip joint. The tip
// turns 90° about z between t = 0 (its rest rotation) and t = 1. Without `skinned` the
// same mesh is a plain mesh at the origin.
struct SkinFixture {
    std::vector<uint16_t> joints = {0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0.5f, 0.5f, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    size_t inverse_binds = 2;

    ModelBuilder build(bool skinned) const {
        ModelBuilder b;
        const std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0, 1, 2, 0};
        std::vector<float> nrm;
        for (int i = 0; i < 6; ++i) nrm.insert(nrm.end(), {0, 0, 1});
        const int mesh = b.add_triangle_mesh(pos, {0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4}, -1, nrm);
        const int body = b.add_node("body", mesh);
        if (!skinned) {
            b.finish({body});
            return b;
        }
        auto& prim = b.model.meshes[size_t(mesh)].primitives[0];
        prim.attributes["JOINTS_0"] = b.add_accessor(joints.data(), joints.size() * 2, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                                     TINYGLTF_TYPE_VEC4, joints.size() / 4);
        prim.attributes["WEIGHTS_0"] = b.floats(weights, TINYGLTF_TYPE_VEC4, 4);
        const int root = b.add_node("root_joint");
        b.model.nodes[size_t(root)].translation = {0, 0, 4};
        const int tip = b.add_node("tip_joint");
        b.model.nodes[size_t(tip)].translation = {0, 1, 0};
        b.model.nodes[size_t(root)].children = {tip};
        b.model.nodes[size_t(body)].translation = {100, 100, 100};  // ignored for skinned meshes
        b.model.nodes[size_t(body)].scale = {3, 3, 3};
        b.model.nodes[size_t(body)].skin = 0;
        // Inverse bind matrices: the inverse of each joint's rest world matrix, column-major.
        const std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -4, 1,
                                        1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, -4, 1};
        tinygltf::Skin skin;
        skin.name = "strip";
        skin.joints = {root, tip};
        skin.inverseBindMatrices = b.floats(std::vector<float>(ibm.begin(), ibm.begin() + long(16 * inverse_binds)),
                                            TINYGLTF_TYPE_MAT4, 16);
        b.model.skins.push_back(skin);
        const float h = std::sqrt(0.5f);
        tinygltf::Animation anim;
        tinygltf::AnimationSampler sm;
        sm.input = b.floats({0.0f, 1.0f}, TINYGLTF_TYPE_SCALAR, 1);
        sm.output = b.floats({0, 0, 0, 1, 0, 0, h, h}, TINYGLTF_TYPE_VEC4, 4);  // xyzw
        anim.samplers.push_back(sm);
        tinygltf::AnimationChannel ch;
        ch.sampler = 0;
        ch.target_node = tip;
        ch.target_path = "rotation";
        anim.channels.push_back(ch);
        b.model.animations.push_back(anim);
        b.finish({root, body});
        return b;
    }
};

TEST(GltfLoader, SkinnedMeshAtBindPoseTimeEqualsTheUnskinnedMesh) {
    auto dir = test::temp_dir("gltf_skin");
    const SkinFixture fx;
    const Scene skinned = load_gltf(fx.build(true).write(dir / "skin.gltf", false));
    const Scene plain = load_gltf(fx.build(false).write(dir / "plain.glb", true));
    for (const auto& w : skinned.warnings) EXPECT_EQ(w.find("skin"), std::string::npos) << w;
    ASSERT_EQ(skinned.skins.size(), 1u);
    EXPECT_EQ(skinned.skins[0].joints.size(), 2u);
    EXPECT_NO_THROW(skinned.validate());
    const SceneFrame a = skinned.evaluate(0.0), b = plain.evaluate(0.0);
    ASSERT_EQ(a.meshes.size(), 1u);
    ASSERT_EQ(b.meshes.size(), 1u);
    EXPECT_EQ(a.meshes[0].triangles, b.meshes[0].triangles);
    for (size_t v = 0; v < b.meshes[0].positions.size(); ++v) {
        EXPECT_NEAR(glm::length(a.meshes[0].positions[v] - b.meshes[0].positions[v]), 0.0f, 1e-6f) << "vertex " << v;
        EXPECT_NEAR(glm::length(a.meshes[0].normals[v] - b.meshes[0].normals[v]), 0.0f, 1e-6f) << "vertex " << v;
    }
    // At t = 1 the tip turns 90° about z through its joint at (0, 1, 0) in mesh space; the
    // bottom row stays, the middle row is the mean of staying and turning.
    const std::vector<Vec3> expected = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5f, 1.5f, 0}, {-1, 1, 0}, {-1, 2, 0}};
    const SceneFrame turned = skinned.evaluate(1.0);
    for (size_t v = 0; v < expected.size(); ++v)
        EXPECT_NEAR(glm::length(turned.meshes[0].positions[v] - expected[v]), 0.0f, 1e-5f) << "vertex " << v;
}

// A scene file fits a skinned model by its bind pose as skinning places it, not by the
// skinned node's own (ignored) transform.
TEST(GltfLoader, SceneFileFitsASkinnedModelInItsBindPose) {
    auto dir = test::temp_dir("gltf_skin_fit");
    SkinFixture().build(true).write(dir / "strip.glb", true);
    const fs::path json = write_file(dir, "fit.json", R"({
  "meshes": [{"file": "strip.glb", "fit_to_box": {"min": [0, 0, 0], "max": [1, 1, 1], "anchor": "bottom"}}],
  "lights": [{"type": "point", "position": [0, 5, 0], "intensity": 1}]
})");
    const Scene s = load_scene_file(json, AssetPaths{});
    const Bounds3 b = s.evaluate_rest().bounds;  // 1 × 2 × 0 in mesh space: scaled by 1/2
    EXPECT_NEAR(b.min.y, 0.0f, 1e-5f);
    EXPECT_NEAR(b.max.y, 1.0f, 1e-5f);
    EXPECT_NEAR(b.extent().x, 0.5f, 1e-5f);
    EXPECT_NEAR(b.center().x, 0.5f, 1e-5f);
}

TEST(GltfLoader, BadSkinsAreErrorsNamingTheFile) {
    auto dir = test::temp_dir("gltf_bad_skin");
    struct Case {
        const char* file;
        std::function<void(SkinFixture&)> spoil;
        const char* message;
    };
    const std::vector<Case> cases = {
        {"joint.gltf", [](SkinFixture& f) { f.joints[16] = 5; }, "joint index out of range"},
        {"weights.gltf", [](SkinFixture& f) { f.weights.resize(20); }, "count mismatch"},
        {"zero.gltf", [](SkinFixture& f) { std::fill(f.weights.begin() + 8, f.weights.begin() + 12, 0.0f); },
         "summing to zero"},
        {"negative.gltf", [](SkinFixture& f) { f.weights[1] = -0.5f; }, "negative"},
        {"ibm.gltf", [](SkinFixture& f) { f.inverse_binds = 1; }, "count mismatch"},
    };
    for (const Case& c : cases) {
        SkinFixture fx;
        c.spoil(fx);
        const fs::path path = fx.build(true).write(dir / c.file, false);
        const std::string msg = error_of([&] { load_gltf(path); });
        EXPECT_NE(msg.find(c.file), std::string::npos) << msg;
        EXPECT_NE(msg.find(c.message), std::string::npos) << msg;
    }
}

TEST(GltfLoader, MorphTargetsStayUnsupportedWithWarning) {
    auto dir = test::temp_dir("gltf_morph");
    ModelBuilder b;
    b.add_triangle_mesh(kQuad, kQuadIndices, -1);
    b.model.meshes[0].primitives[0].targets.push_back({{"POSITION", b.vec3s(kQuad)}});
    b.finish({b.add_node("n", 0)});
    Scene s = load_gltf(b.write(dir / "morph.gltf", false));
    bool warned = false;
    for (const auto& w : s.warnings) warned |= w.find("morph targets are not supported") != std::string::npos;
    EXPECT_TRUE(warned);
}

// A 4 × 4 embedded image (top rows red, bottom rows green; left half opaque, right half
// transparent), its sampler, and materials reading it through texCoord 1 overridden by
// KHR_texture_transform, as a mask, a normal map and an emission texture.
TEST(GltfLoader, TexturesKeepTheirSetSamplerTransformAndMask) {
    ModelBuilder b;
    tinygltf::Image img;
    img.name = "blocks";
    img.width = img.height = 4;
    img.component = 4;
    img.bits = 8;
    img.pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    img.mimeType = "image/png";
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x)
            img.image.insert(img.image.end(), {uint8_t(y < 2 ? 255 : 0), uint8_t(y < 2 ? 0 : 255), 0, uint8_t(x < 2 ? 255 : 0)});
    b.model.images.push_back(img);
    tinygltf::Sampler sampler;
    sampler.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    sampler.wrapT = TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
    b.model.samplers.push_back(sampler);
    tinygltf::Texture tex;
    tex.source = 0;
    tex.sampler = 0;
    b.model.textures.push_back(tex);
    tinygltf::Material m;
    m.name = "masked";
    m.pbrMetallicRoughness.baseColorTexture.index = 0;
    m.pbrMetallicRoughness.baseColorTexture.texCoord = 1;
    m.pbrMetallicRoughness.baseColorTexture.extensions["KHR_texture_transform"] = object(
        {{"offset", tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(0.5), tinygltf::Value(0.0)})},
         {"scale", tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(2.0), tinygltf::Value(2.0)})},
         {"rotation", tinygltf::Value(0.25)},
         {"texCoord", tinygltf::Value(0)}});
    m.alphaMode = "MASK";
    m.alphaCutoff = 0.3;
    m.normalTexture.index = 0;
    m.normalTexture.scale = 0.7;
    m.emissiveFactor = {1.0, 1.0, 1.0};
    m.emissiveTexture.index = 0;
    m.emissiveTexture.texCoord = 1;
    b.model.materials.push_back(m);
    tinygltf::Material blend;
    blend.name = "blended";
    blend.alphaMode = "BLEND";
    blend.pbrMetallicRoughness.baseColorTexture.index = 0;
    b.model.materials.push_back(blend);
    b.model.extensionsUsed.push_back("KHR_texture_transform");
    const int quad = b.add_triangle_mesh(kQuad, kQuadIndices, 0, {}, {0, 0, 1, 0, 1, 1, 0, 1});
    b.model.meshes[size_t(quad)].primitives[0].attributes["TEXCOORD_1"] =
        b.floats({0, 0, 0.5f, 0, 0.5f, 0.5f, 0, 0.5f}, TINYGLTF_TYPE_VEC2, 2);
    const int tri = b.add_triangle_mesh({0, 0, 1, 1, 0, 1, 0, 1, 1}, {}, 1, {}, {0, 0, 1, 0, 0, 1});
    b.finish({b.add_node("quad", quad), b.add_node("tri", tri)});
    const fs::path path = b.write(test::temp_dir("gltf_textures") / "textured.gltf", false);

    const Scene s = load_gltf(path);
    ASSERT_EQ(s.materials.size(), 2u);
    const Material& masked = s.materials[0];
    ASSERT_TRUE(masked.albedo_texture);
    EXPECT_EQ(masked.albedo_texture.uv_set, 0);  // the extension's texCoord overrides 1
    EXPECT_EQ(masked.albedo_texture.transform.offset, Vec2(0.5f, 0.0f));
    EXPECT_EQ(masked.albedo_texture.transform.scale, Vec2(2.0f));
    EXPECT_FLOAT_EQ(masked.albedo_texture.transform.rotation, 0.25f);
    EXPECT_EQ(masked.albedo_texture.wrap_s, WrapMode::ClampToEdge);
    EXPECT_EQ(masked.albedo_texture.wrap_t, WrapMode::MirroredRepeat);
    const MipMap& image = *masked.albedo_texture.image;
    EXPECT_EQ(image.encoding(), ColorEncoding::Srgb);
    EXPECT_EQ(image.texel(0, 0, 0, WrapMode::Repeat, WrapMode::Repeat), Vec4(1, 0, 0, 1));
    EXPECT_EQ(image.texel(0, 3, 3, WrapMode::Repeat, WrapMode::Repeat), Vec4(0, 1, 0, 0));
    EXPECT_TRUE(masked.alpha_tested());
    EXPECT_FLOAT_EQ(masked.alpha_cutoff, 0.3f);
    EXPECT_EQ(masked.alpha_texture.image, masked.albedo_texture.image);
    ASSERT_TRUE(masked.normal_texture);
    EXPECT_EQ(masked.normal_texture.image->encoding(), ColorEncoding::Linear);
    EXPECT_FLOAT_EQ(masked.normal_scale, 0.7f);
    ASSERT_TRUE(masked.emission_texture);
    EXPECT_EQ(masked.emission_texture.uv_set, 1);
    EXPECT_EQ(masked.emission_texture.image, masked.albedo_texture.image) << "one image, decoded once per encoding";
    const Material& blended = s.materials[1];
    EXPECT_TRUE(blended.alpha_tested());
    EXPECT_FLOAT_EQ(blended.alpha_cutoff, 0.5f);
    bool warned = false;
    for (const std::string& w : s.warnings) warned |= w.find("BLEND") != std::string::npos;
    EXPECT_TRUE(warned);
    ASSERT_EQ(s.meshes[0].uvs1.size(), s.meshes[0].positions.size());
    EXPECT_EQ(s.meshes[0].uvs1[2], Vec2(0.5f));
    EXPECT_EQ(s.texture_use().images, 2u);  // the sRGB and the linear reading of one file

    // A transform that is not numbers is an error naming its place.
    std::ifstream in(path);
    nlohmann::json doc = nlohmann::json::parse(in);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["offset"] = {"a", 0};
    const fs::path bad = test::write_file(path.parent_path(), "bad_transform.gltf", doc.dump());
    const std::string msg = test::error_of([&] { load_gltf(bad); });
    EXPECT_NE(msg.find("/materials/0/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/offset/0"),
              std::string::npos) << msg;
}

TEST(GltfLoader, MissingFile) {
    std::string msg = error_of([] { load_gltf("/nonexistent/model.glb"); });
    EXPECT_NE(msg.find("model.glb"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not found"), std::string::npos) << msg;
}

TEST(GltfLoader, TruncatedFiles) {
    auto dir = test::temp_dir("gltf_truncated");
    ModelBuilder b = full_model();
    for (bool binary : {false, true}) {
        fs::path p = b.write(dir / (binary ? "cut.glb" : "cut.gltf"), binary);
        std::string bytes;
        {
            std::ifstream in(p, std::ios::binary);
            bytes.assign(std::istreambuf_iterator<char>(in), {});
        }
        std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() * 2 / 3);
        std::string msg = error_of([&] { load_gltf(p); });
        EXPECT_NE(msg.find(p.filename().string()), std::string::npos) << msg;
        EXPECT_NE(msg.find("malformed glTF"), std::string::npos) << msg;
    }
}

TEST(GltfLoader, OutOfRangeIndex) {
    auto dir = test::temp_dir("gltf_bad_index");
    ModelBuilder b;
    b.add_triangle_mesh(kQuad, {0, 1, 2, 0, 2, 7}, -1);
    b.finish({b.add_node("n", 0)});
    std::string msg = error_of([&] { load_gltf(b.write(dir / "bad.gltf", false)); });
    EXPECT_NE(msg.find("bad.gltf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("index 5 is 7"), std::string::npos) << msg;
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
}

TEST(GltfLoader, OutOfRangeAccessor) {
    auto dir = test::temp_dir("gltf_bad_accessor");
    ModelBuilder b;
    b.add_triangle_mesh(kQuad, kQuadIndices, -1);
    b.model.meshes[0].primitives[0].attributes["NORMAL"] = 42;
    b.finish({b.add_node("n", 0)});
    std::string msg = error_of([&] { load_gltf(b.write(dir / "bad_accessor.gltf", false)); });
    EXPECT_NE(msg.find("bad_accessor.gltf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
}

TEST(GltfLoader, AccessorPastEndOfBuffer) {
    auto dir = test::temp_dir("gltf_overrun");
    ModelBuilder b;
    b.add_triangle_mesh(kQuad, kQuadIndices, -1);
    b.model.accessors[size_t(b.model.meshes[0].primitives[0].indices)].count = 600;  // 6 stored
    b.finish({b.add_node("n", 0)});
    std::string msg = error_of([&] { load_gltf(b.write(dir / "overrun.glb", true)); });
    EXPECT_NE(msg.find("overrun.glb"), std::string::npos) << msg;
    EXPECT_NE(msg.find("past the end"), std::string::npos) << msg;
}

TEST(GltfLoader, NanVertexIsAnError) {
    auto dir = test::temp_dir("gltf_nan");
    ModelBuilder b;
    std::vector<float> pos = kQuad;
    pos[4] = std::numeric_limits<float>::quiet_NaN();
    b.add_triangle_mesh(pos, kQuadIndices, -1);
    b.model.accessors[0].minValues = {0, 0, 0};
    b.model.accessors[0].maxValues = {1, 1, 0};
    b.finish({b.add_node("n", 0)});
    std::string msg = error_of([&] { load_gltf(b.write(dir / "nan.glb", true)); });
    EXPECT_NE(msg.find("nan.glb"), std::string::npos) << msg;
    EXPECT_NE(msg.find("vertex 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;
}

TEST(GltfLoader, ZeroAreaTrianglesDropped) {
    auto dir = test::temp_dir("gltf_degenerate");
    ModelBuilder b;
    // Quad plus a collinear triangle (0,1,4) with vertex 4 on the x axis, and one with
    // a repeated index.
    std::vector<float> pos = kQuad;
    pos.insert(pos.end(), {3, 0, 0});
    b.add_triangle_mesh(pos, {0, 1, 2, 0, 1, 4, 0, 2, 3, 2, 2, 3}, -1);
    b.finish({b.add_node("n", 0)});
    Scene s = load_gltf(b.write(dir / "deg.gltf", false));
    EXPECT_EQ(s.degenerate_triangles_dropped, 2u);
    ASSERT_EQ(s.meshes[0].triangles.size(), 2u);
    EXPECT_EQ(s.meshes[0].triangles[1], UVec3(0, 2, 3));
    EXPECT_EQ(s.meshes[0].material_ids.size(), 2u);
}

TEST(GltfLoader, NonTrianglePrimitiveIsSkippedWithWarning) {
    auto dir = test::temp_dir("gltf_lines");
    ModelBuilder b;
    b.add_triangle_mesh(kQuad, kQuadIndices, -1);
    tinygltf::Primitive lines = b.model.meshes[0].primitives[0];
    lines.mode = TINYGLTF_MODE_LINE;
    b.model.meshes[0].primitives.push_back(lines);
    b.finish({b.add_node("n", 0)});
    Scene s = load_gltf(b.write(dir / "lines.gltf", false));
    EXPECT_EQ(s.meshes[0].triangles.size(), 2u);
    bool warned = false;
    for (const auto& w : s.warnings) warned |= w.find("points/lines") != std::string::npos;
    EXPECT_TRUE(warned);
}

// ---- Real animated models (skipped when ../shared/scenes is absent) ----

struct GlbAsset {
    const char* path;
    size_t vertices;
    size_t triangles;
};

class RealGlb : public ::testing::TestWithParam<GlbAsset> {};

TEST_P(RealGlb, MatchesManifestAndIsAnimated) {
    const GlbAsset a = GetParam();
    auto path = test::shared_asset(a.path);
    if (!path) GTEST_SKIP() << "shared asset " << a.path << " not found";
    Scene s = load_gltf(*path);
    size_t vertices = 0, triangles = 0;
    for (const auto& m : s.meshes) {
        vertices += m.positions.size();
        triangles += m.triangles.size();
    }
    EXPECT_EQ(vertices, a.vertices);
    EXPECT_EQ(triangles + s.degenerate_triangles_dropped, a.triangles);
    EXPECT_TRUE(s.is_animated());
    EXPECT_GT(s.animation_duration(), 0.0);
    // Skinned, with one influence per vertex of every skinned mesh.
    EXPECT_FALSE(s.skins.empty());
    for (const auto& node : s.nodes)
        for (uint32_t m : node.meshes)
            if (node.skin >= 0) {
                EXPECT_EQ(s.meshes[m].influences.size(), s.meshes[m].positions.size());
            }
    for (const auto& w : s.warnings) EXPECT_EQ(w.find("skin"), std::string::npos) << w;
    EXPECT_NO_THROW(s.validate());
}

INSTANTIATE_TEST_SUITE_P(Manifest, RealGlb,
                         ::testing::Values(GlbAsset{"animated/BrainStem.glb", 34159, 61666},
                                           GlbAsset{"animated/CesiumMan.glb", 3273, 4672},
                                           GlbAsset{"animated/Fox.glb", 1728, 576},
                                           GlbAsset{"animated/RiggedFigure.glb", 370, 256},
                                           GlbAsset{"animated/RiggedSimple.glb", 160, 188}),
                         [](const auto& info) { return fs::path(info.param.path).stem().string(); });

TEST(RealGlb, CesiumManKeepsItsTexturePerTexel) {
    auto path = test::shared_asset("animated/CesiumMan.glb");
    if (!path) GTEST_SKIP() << "shared asset animated/CesiumMan.glb not found";
    Scene s = load_gltf(*path);
    ASSERT_FALSE(s.materials.empty());
    const Material& m = s.materials[0];
    // The factor stays the file's (white); the texture is kept whole, not averaged into it.
    EXPECT_EQ(m.albedo, Vec3(1.0f));
    ASSERT_TRUE(m.albedo_texture);
    const MipMap& img = *m.albedo_texture.image;
    EXPECT_GT(img.width(), 1);
    EXPECT_GT(img.height(), 1);
    EXPECT_EQ(img.encoding(), ColorEncoding::Srgb);
    // Its texels differ (a real texture, not a flat colour) and its mean is a darker tint.
    float lo = 1.0f, hi = 0.0f;
    for (int y = 0; y < img.height(); y += 7)
        for (int x = 0; x < img.width(); x += 7) {
            const float v = luminance(Vec3(img.texel(0, x, y, WrapMode::Repeat, WrapMode::Repeat)));
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    EXPECT_GT(hi - lo, 0.2f);
    const Vec3 mean = Vec3(img.texel(img.levels() - 1, 0, 0, WrapMode::Repeat, WrapMode::Repeat));
    EXPECT_LT(max_component(mean), 0.9f);
    EXPECT_GT(max_component(mean), 0.0f);
    ASSERT_FALSE(s.meshes.empty());
    EXPECT_EQ(s.meshes[0].uvs.size(), s.meshes[0].positions.size());
    for (const std::string& w : s.warnings) EXPECT_EQ(w.find("mean"), std::string::npos) << w;
}

// ---------------------------------------------------------------- deep node hierarchies

namespace {

// tests/data/bad/base/triangle.gltf as JSON, to build variants of.
nlohmann::json triangle_gltf() {
    std::ifstream in(fs::path(GILAB_SOURCE_DIR) / "tests" / "data" / "bad" / "base" / "triangle.gltf");
    return nlohmann::json::parse(in);
}

// The triangle under a chain of `depth` nodes, each the only child of the one before,
// every node built from `node_template` (its transform).
nlohmann::json node_chain(size_t depth, const nlohmann::json& node_template) {
    nlohmann::json doc = triangle_gltf();
    doc["nodes"] = nlohmann::json::array();
    for (size_t i = 0; i < depth; ++i) {
        nlohmann::json node = node_template;
        if (i + 1 < depth) node["children"] = {i + 1};
        else node["mesh"] = 0;
        doc["nodes"].push_back(node);
    }
    doc["scenes"] = {{{"nodes", {0}}}};
    return doc;
}

}  // namespace

TEST(GltfDeepHierarchy, ChainsThousandsOfNodesDeepLoad) {
    // The hierarchy was walked recursively: 20000 levels overflowed the stack (SIGSEGV).
    const fs::path dir = test::temp_dir("gltf_deep_chain");
    for (size_t depth : {size_t(5000), size_t(50000)}) {
        const std::string name = "chain" + std::to_string(depth) + ".gltf";
        const Scene s = load_gltf(write_file(dir, name, node_chain(depth, {{"translation", {0.0, 0.0, 0.0}}}).dump()));
        ASSERT_EQ(s.nodes.size(), depth);
        for (size_t i = 1; i < s.nodes.size(); ++i) ASSERT_EQ(s.nodes[i].parent, int(i - 1));
        EXPECT_EQ(s.nodes.back().meshes.size(), 1u);
        EXPECT_EQ(s.triangle_count(), 1u);
    }
}

TEST(GltfDeepHierarchy, IdentityChainOfHundredNodesLoads) {
    // Each node's rotation was bounded by √3 and the bounds multiplied: 100 identity
    // nodes were refused as reaching "coordinates of about 1.35e+18".
    const nlohmann::json identity = {{"translation", {0.0, 0.0, 0.0}}, {"rotation", {0.0, 0.0, 0.0, 1.0}}, {"scale", {1.0, 1.0, 1.0}}};
    const fs::path dir = test::temp_dir("gltf_identity_chain");
    const Scene s = load_gltf(write_file(dir, "identity.gltf", node_chain(100, identity).dump()));
    EXPECT_EQ(s.nodes.size(), 100u);
    const SceneFrame frame = s.evaluate(0.0);
    EXPECT_NEAR(frame.bounds.max.x, 1.0f, 1e-5f);
    // A quarter turn per node composes to whole turns, not to a product of bounds.
    const double s2 = std::sqrt(0.5);
    const nlohmann::json quarter_turn = {{"rotation", {0.0, 0.0, s2, s2}}};
    EXPECT_NO_THROW(load_gltf(write_file(dir, "turns.gltf", node_chain(100, quarter_turn).dump())));
}

TEST(GltfDeepHierarchy, ComposedTransformBeyondTheRangeIsStillRefused) {
    // Scale 100 at each of 10 levels: 1e20, beyond ±1e18, though each node is modest.
    const fs::path path = write_file(test::temp_dir("gltf_composed_overflow"), "far.gltf",
                                     node_chain(10, {{"scale", {100.0, 100.0, 100.0}}}).dump());
    const std::string msg = error_of([&] { load_gltf(path); });
    EXPECT_NE(msg.find("far.gltf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("beyond the supported range"), std::string::npos) << msg;
}

// ---------------------------------------------------------------- extension and camera numbers

namespace {

// The triangle plus a node carrying a KHR_lights_punctual light.
nlohmann::json with_light(const nlohmann::json& light) {
    nlohmann::json doc = triangle_gltf();
    doc["extensionsUsed"] = {"KHR_lights_punctual"};
    doc["extensions"]["KHR_lights_punctual"]["lights"] = {light};
    doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    doc["scenes"][0]["nodes"] = {0, 1};
    return doc;
}

// The triangle plus a node carrying a perspective camera.
nlohmann::json with_camera(const nlohmann::json& perspective) {
    nlohmann::json doc = triangle_gltf();
    doc["cameras"] = {{{"type", "perspective"}, {"name", "view"}, {"perspective", perspective}}};
    doc["nodes"].push_back({{"camera", 0}, {"translation", {0.0, 0.0, 5.0}}});
    doc["scenes"][0]["nodes"] = {0, 1};
    return doc;
}

struct NumberCase {
    const char* name;
    nlohmann::json doc;
    std::vector<std::string> expected;  // substrings of the error
};

}  // namespace

TEST(GltfNumbers, LightAndCameraValuesAreCheckedLikeTheSceneFile) {
    // Each was accepted: a negative colour rendered negative pixels, a degenerate camera
    // was dropped silently for the default view.
    const nlohmann::json point = {{"type", "point"}, {"name", "lamp"}};
    auto light = [&](nlohmann::json changes) {
        nlohmann::json l = point;
        l.update(changes);
        return with_light(l);
    };
    const NumberCase cases[] = {
        {"negative_colour", light({{"color", {-1.0, 1.0, 1.0}}}), {"/extensions/KHR_lights_punctual/lights/0/color/0", "light 'lamp'", "-1"}},
        {"huge_colour", light({{"color", {1.0, 1e39, 1.0}}}), {"lights/0/color/1", "light 'lamp'", "1e+39"}},
        {"negative_intensity", light({{"intensity", -5.0}}), {"lights/0/intensity", "light 'lamp'", "-5"}},
        {"outer_cone_beyond_90_degrees", light({{"type", "spot"}, {"spot", {{"outerConeAngle", 2.0}}}}),
         {"lights/0/spot/outerConeAngle", "light 'lamp'", "2 is out of range"}},
        {"inner_cone_beyond_outer", light({{"type", "spot"}, {"spot", {{"innerConeAngle", 0.6}, {"outerConeAngle", 0.5}}}}),
         {"lights/0/spot/innerConeAngle", "0.6 is out of range [0, outerConeAngle = 0.5]"}},
        {"negative_inner_cone", light({{"type", "spot"}, {"spot", {{"innerConeAngle", -0.1}}}}), {"spot/innerConeAngle", "-0.1"}},
        {"yfov_zero", with_camera({{"yfov", 0.0}, {"znear", 0.1}}), {"/cameras/0/perspective/yfov", "camera 0 'view'", "0 is out of range"}},
        {"yfov_beyond_pi", with_camera({{"yfov", 4.0}, {"znear", 0.1}}), {"perspective/yfov", "4 is out of range"}},
        {"znear_negative", with_camera({{"yfov", 0.8}, {"znear", -0.1}}), {"perspective/znear", "-0.1"}},
        {"zfar_before_znear", with_camera({{"yfov", 0.8}, {"znear", 0.1}, {"zfar", 0.05}}), {"perspective/zfar", "0.05", "znear = 0.1"}},
        {"negative_emissive_strength", [] {
             nlohmann::json doc = triangle_gltf();
             doc["materials"] = {{{"name", "glow"}, {"emissiveFactor", {1.0, 1.0, 1.0}},
                                  {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -3.5}}}}}}};
             doc["meshes"][0]["primitives"][0]["material"] = 0;
             return doc;
         }(), {"/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength", "material 'glow'", "-3.5"}},
        {"aspect_ratio_negative", with_camera({{"yfov", 0.8}, {"znear", 0.1}, {"aspectRatio", -1.5}}), {"perspective/aspectRatio", "-1.5"}},
    };
    const fs::path dir = test::temp_dir("gltf_numbers");
    for (const NumberCase& c : cases) {
        const std::string file = std::string(c.name) + ".gltf";
        const fs::path path = write_file(dir, file, c.doc.dump());
        const std::string msg = error_of([&] { load_gltf(path); });
        EXPECT_NE(msg.find(file), std::string::npos) << c.name << ": " << msg;
        for (const std::string& part : c.expected) EXPECT_NE(msg.find(part), std::string::npos) << c.name << ": missing '" << part << "' in: " << msg;
    }
}

TEST(GltfNumbers, ValidLightsAndCamerasLoad) {
    const fs::path dir = test::temp_dir("gltf_numbers_valid");
    const Scene spot = load_gltf(write_file(dir, "spot.gltf",
                                            with_light({{"type", "spot"}, {"color", {1.0, 0.5, 0.0}}, {"intensity", 0.0},
                                                        {"spot", {{"innerConeAngle", 0.0}, {"outerConeAngle", kPi / 2}}}})
                                                .dump()));
    ASSERT_EQ(spot.lights.size(), 1u);
    EXPECT_EQ(spot.lights[0].intensity, Vec3(0.0f));
    // A hard-edged cone (inner = outer), as Blender writes one without blend.
    EXPECT_NO_THROW(load_gltf(write_file(
        dir, "hard_spot.gltf",
        with_light({{"type", "spot"}, {"spot", {{"innerConeAngle", 0.5}, {"outerConeAngle", 0.5}}}}).dump())));
    const Scene cam = load_gltf(write_file(dir, "camera.gltf",
                                           with_camera({{"yfov", 0.8}, {"znear", 0.1}, {"zfar", 100.0}, {"aspectRatio", 1.5}}).dump()));
    ASSERT_TRUE(cam.camera.has_value());
    EXPECT_NEAR(cam.camera->vertical_fov_degrees, glm::degrees(0.8f), 1e-4f);
    const Scene infinite = load_gltf(write_file(dir, "infinite.gltf", with_camera({{"yfov", 0.8}, {"znear", 0.1}}).dump()));
    EXPECT_TRUE(infinite.camera.has_value());
}

TEST(GltfNumbers, ZeroScaleThatLeavesNothingVisibleIsAnError) {
    // Rendered an all-black image with exit status 0.
    const fs::path dir = test::temp_dir("gltf_zero_scale");
    nlohmann::json doc = triangle_gltf();
    doc["nodes"][0]["name"] = "model";
    doc["nodes"][0]["scale"] = {0.0, 0.0, 0.0};
    const std::string msg = error_of([&] { load_gltf(write_file(dir, "zero.gltf", doc.dump())); });
    EXPECT_NE(msg.find("zero.gltf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("nothing visible"), std::string::npos) << msg;
    EXPECT_NE(msg.find("node 'model' has scale [0, 0, 0]"), std::string::npos) << msg;
    // The triangle lies in z = 0: flattening z leaves it whole.
    doc["nodes"][0]["scale"] = {1.0, 1.0, 0.0};
    EXPECT_NO_THROW(load_gltf(write_file(dir, "flat.gltf", doc.dump())));
    // Flattening y collapses it to a line.
    doc["nodes"][0]["scale"] = {1.0, 0.0, 1.0};
    EXPECT_NE(error_of([&] { load_gltf(write_file(dir, "line.gltf", doc.dump())); }).find("nothing visible"), std::string::npos);
    // A model that grows from scale 0 (key times 0 and 1, scales 0 and 1) is visible later.
    doc["nodes"][0]["scale"] = {0.0, 0.0, 0.0};
    doc["buffers"].push_back({{"uri", "data:application/octet-stream;base64,AAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AACAPwAAgD8="},
                              {"byteLength", 32}});
    doc["bufferViews"].push_back({{"buffer", 1}, {"byteLength", 8}});
    doc["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 8}, {"byteLength", 24}});
    doc["accessors"].push_back({{"bufferView", 1}, {"componentType", 5126}, {"count", 2}, {"type", "SCALAR"}, {"min", {0}}, {"max", {1}}});
    doc["accessors"].push_back({{"bufferView", 2}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}});
    nlohmann::json animation;
    animation["samplers"] = nlohmann::json::array({nlohmann::json{{"input", 1}, {"output", 2}}});
    animation["channels"] =
        nlohmann::json::array({nlohmann::json{{"sampler", 0}, {"target", {{"node", 0}, {"path", "scale"}}}}});
    doc["animations"] = nlohmann::json::array({animation});
    const Scene grows = load_gltf(write_file(dir, "grows.gltf", doc.dump()));
    EXPECT_TRUE(grows.is_animated());
}
