// Scene evaluation: node hierarchy, keyframed TRS animation, validation errors.
#include <gtest/gtest.h>
#include "core/util/error.hpp"
#include "core/scene/scene.hpp"
#include "scenes/builtin_scenes.hpp"
#include "tests/test_support.hpp"

using namespace gilab;

namespace {

Mesh unit_triangle() {
    Mesh m;
    m.name = "tri";
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.triangles = {{0, 1, 2}};
    m.material_ids = {0};
    return m;
}

Scene one_triangle_scene() {
    Scene s;
    s.name = "test";
    s.materials.push_back(Material{});
    s.add_mesh_instance(unit_triangle());
    return s;
}

}  // namespace

TEST(Animation, InterpolatesTranslationLinearlyAndClampsOutsideKeys) {
    TrsAnimation anim;
    anim.translation.times = {0.0f, 2.0f};
    anim.translation.values = {Vec3(0), Vec3(4, 0, 0)};
    Transform rest;
    EXPECT_FLOAT_EQ(anim.sample(1.0f, rest).translation.x, 2.0f);
    EXPECT_FLOAT_EQ(anim.sample(-1.0f, rest).translation.x, 0.0f);
    EXPECT_FLOAT_EQ(anim.sample(5.0f, rest).translation.x, 4.0f);
    anim.step = true;
    EXPECT_FLOAT_EQ(anim.sample(1.9f, rest).translation.x, 0.0f);
    EXPECT_FLOAT_EQ(anim.duration(), 2.0f);
}

TEST(Animation, SlerpsRotationAndKeepsRestForMissingChannels) {
    TrsAnimation anim;
    anim.rotation.times = {0.0f, 1.0f};
    anim.rotation.values = {Quat(1, 0, 0, 0), glm::angleAxis(kPi / 2, Vec3(0, 1, 0))};
    Transform rest;
    rest.translation = Vec3(7, 0, 0);
    Transform t = anim.sample(0.5f, rest);
    EXPECT_FLOAT_EQ(t.translation.x, 7.0f);
    Vec3 x = t.rotation * Vec3(1, 0, 0);
    EXPECT_NEAR(x.x, std::cos(kPi / 4), 1e-5);
    EXPECT_NEAR(x.z, -std::sin(kPi / 4), 1e-5);
}

TEST(Transform, MatrixDecompositionRoundTrips) {
    Transform t;
    t.translation = Vec3(1, 2, 3);
    t.rotation = glm::normalize(Quat(0.9f, 0.1f, -0.3f, 0.2f));
    t.scale = Vec3(2, 0.5f, 3);
    Transform back = Transform::from_matrix(t.matrix());
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(back.translation[i], t.translation[i], 1e-5);
        EXPECT_NEAR(back.scale[i], t.scale[i], 1e-5);
    }
    EXPECT_NEAR(std::abs(glm::dot(back.rotation, t.rotation)), 1.0f, 1e-5);
}

TEST(Scene, EvaluatesParentChildTransformsAndAnimation) {
    Scene s = one_triangle_scene();
    SceneNode parent;
    parent.name = "parent";
    parent.local.translation = Vec3(10, 0, 0);
    parent.animation.translation.times = {0.0f, 1.0f};
    parent.animation.translation.values = {Vec3(10, 0, 0), Vec3(10, 5, 0)};
    s.nodes.insert(s.nodes.begin(), parent);
    s.nodes[1].parent = 0;
    s.frames_per_second = 10;

    EXPECT_TRUE(s.is_animated());
    EXPECT_EQ(s.animation_frame_count(), 11);
    SceneFrame f0 = s.evaluate(0.0);
    ASSERT_EQ(f0.meshes.size(), 1u);
    EXPECT_FLOAT_EQ(f0.meshes[0].positions[1].x, 11.0f);
    SceneFrame f5 = s.evaluate_frame(5);
    EXPECT_NEAR(f5.meshes[0].positions[2].y, 3.5f, 1e-5);
    EXPECT_NEAR(f5.bounds.max.y, 3.5f, 1e-5);
}

TEST(Scene, MirroringTransformKeepsOutwardWinding) {
    Scene s = one_triangle_scene();
    s.nodes[0].local.scale = Vec3(-1, 1, 1);
    SceneFrame f = s.evaluate(0);
    const auto& m = f.meshes[0];
    Vec3 n = glm::cross(m.positions[m.triangles[0].y] - m.positions[m.triangles[0].x],
                        m.positions[m.triangles[0].z] - m.positions[m.triangles[0].x]);
    EXPECT_GT(n.z, 0.0f);  // the unmirrored triangle faces +z; mirroring in x must not flip it
}

TEST(Scene, ValidateRejectsEmptyAndDanglingIndices) {
    Scene empty;
    empty.source = "empty.json";
    try {
        empty.validate();
        FAIL() << "empty scene accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("empty.json"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("no triangles"), std::string::npos);
    }
    Scene bad = one_triangle_scene();
    bad.meshes[0].material_ids[0] = 3;
    EXPECT_THROW(bad.validate(), Error);
    Scene dangling = one_triangle_scene();
    dangling.nodes[0].meshes.push_back(9);
    // Named before anything counts triangles through it (the sanitizer build caught a read
    // past the mesh array when the count came first).
    EXPECT_NE(test::error_of([&] { dangling.validate(); }).find("references mesh 9"), std::string::npos);
}

TEST(CornellBox, HasThirtyGeometryTrianglesPlusTheLight) {
    Scene s = make_cornell_box();
    s.validate();
    size_t emissive = 0;
    for (uint32_t id : s.meshes[0].material_ids) emissive += s.materials[id].is_emissive();
    EXPECT_EQ(s.triangle_count() - emissive, 30u);
    EXPECT_EQ(emissive, 2u);
    SceneFrame f = s.evaluate(0);
    EXPECT_NEAR(f.bounds.max.x, 556.0f / 555.0f, 1e-5);
    // Walls face the inside of the box, the light faces down.
    const auto& m = f.meshes[0];
    Vec3 inside(0.5f, 0.5f, 0.5f);
    for (size_t i = 0; i < m.triangles.size(); ++i) {
        const UVec3& t = m.triangles[i];
        Vec3 n = glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]);
        if (s.materials[m.material_ids[i]].is_emissive()) {
            EXPECT_LT(n.y, 0.0f);
        }
    }
    (void)inside;
}
