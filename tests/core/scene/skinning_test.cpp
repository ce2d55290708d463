// Linear blend skinning: a one-joint rig moves its vertices by exactly that joint's
// transform, blends are weighted means, a skin that follows one joint equals the rigid
// mesh under it, bad skins are rejected by validate(), and the shared animated models
// pose to their bind pose at rest and visibly move mid-animation.
#include <gtest/gtest.h>

#include <cstdio>
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/scene/skin.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;
using gilab::test::error_of;

namespace {

// A tetrahedron-ish patch: four vertices, two triangles, normals.
Mesh patch(const std::string& name) {
    Mesh m;
    m.name = name;
    m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0.5f), Vec3(0.3f, 0.2f, 1)};
    m.normals = {Vec3(0, 0, 1), Vec3(0, 0.6f, 0.8f), Vec3(1, 0, 0), glm::normalize(Vec3(1, 1, 1))};
    m.triangles = {UVec3(0, 1, 2), UVec3(0, 2, 3)};
    m.material_ids = {0, 0};
    return m;
}

VertexInfluences one(uint16_t joint) { return VertexInfluences{{joint, 0, 0, 0}, Vec4(1, 0, 0, 0)}; }

Transform pose_a() {
    Transform t;
    t.translation = Vec3(0.5f, -2, 3);
    t.rotation = glm::angleAxis(glm::radians(37.0f), glm::normalize(Vec3(1, 2, -0.5f)));
    t.scale = Vec3(1.5f, 0.75f, 2);
    return t;
}

// Node 0: the joint, animated from identity (t = 0) to `target` (t = 1). Node 1: the
// skinned mesh, whose own transform must be ignored.
Scene one_joint_rig(const Transform& target) {
    Scene s;
    s.name = "rig";
    s.materials.push_back(Material{});
    SceneNode joint;
    joint.name = "joint";
    joint.animation.translation = {{0, 1}, {Vec3(0), target.translation}};
    joint.animation.rotation = {{0, 1}, {Quat(1, 0, 0, 0), target.rotation}};
    joint.animation.scale = {{0, 1}, {Vec3(1), target.scale}};
    s.nodes.push_back(joint);
    Mesh m = patch("body");
    m.influences.assign(m.positions.size(), one(0));
    s.meshes.push_back(m);
    SceneNode body;
    body.name = "body";
    body.local.translation = Vec3(100, 100, 100);
    body.meshes = {0};
    body.skin = 0;
    s.nodes.push_back(body);
    s.skins.push_back(Skin{"skin", {0}, {Mat4(1.0f)}});
    return s;
}

float diagonal(const Bounds3& b) { return glm::length(b.extent()); }

}  // namespace

TEST(Skinning, OneJointRigMovesVerticesByJointTransformExactly) {
    const Transform target = pose_a();
    Scene s = one_joint_rig(target);
    ASSERT_NO_THROW(s.validate());
    const Mat4 j = target.matrix();
    const Mat3 nm = glm::transpose(glm::inverse(Mat3(j)));
    SceneFrame f = s.evaluate(1.0);
    ASSERT_EQ(f.meshes.size(), 1u);
    const WorldMesh& w = f.meshes[0];
    for (size_t v = 0; v < s.meshes[0].positions.size(); ++v) {
        EXPECT_EQ(w.positions[v], Vec3(j * Vec4(s.meshes[0].positions[v], 1.0f))) << "vertex " << v;
        const Vec3 n = glm::normalize(nm * s.meshes[0].normals[v]);
        EXPECT_NEAR(glm::length(w.normals[v] - n), 0.0f, 1e-5f) << "vertex " << v;
    }
    EXPECT_EQ(w.triangles, s.meshes[0].triangles);
    // The keys at t = 0 are the identity: the bind pose equals the unskinned mesh.
    EXPECT_EQ(s.evaluate(0.0).meshes[0].positions, s.meshes[0].positions);
}

TEST(Skinning, InverseBindMatrixCancelsTheBindPose) {
    Transform bind = pose_a();
    Scene s = one_joint_rig(Transform{});
    s.nodes[0].animation = {};
    s.nodes[0].local = bind;
    s.skins[0].inverse_bind = {glm::inverse(bind.matrix())};
    const SceneFrame f = s.evaluate_rest();
    for (size_t v = 0; v < s.meshes[0].positions.size(); ++v)
        EXPECT_NEAR(glm::length(f.meshes[0].positions[v] - s.meshes[0].positions[v]), 0.0f, 1e-5f) << v;
}

TEST(Skinning, HalfAndHalfLandsOnTheMeanOfTwoJoints) {
    Scene s = one_joint_rig(pose_a());
    SceneNode second;
    second.name = "second";
    second.local.translation = Vec3(0, 4, 0);
    second.local.rotation = glm::angleAxis(glm::radians(90.0f), Vec3(0, 0, 1));
    s.nodes.insert(s.nodes.begin() + 1, second);  // before the body, which moves to node 2
    s.skins[0] = Skin{"skin", {0, 1}, {Mat4(1.0f), Mat4(1.0f)}};
    s.meshes[0].influences = {VertexInfluences{{0, 1, 0, 0}, Vec4(0.5f, 0.5f, 0, 0)}, one(1), one(0),
                              VertexInfluences{{1, 0, 0, 0}, Vec4(0.25f, 0.75f, 0, 0)}};
    ASSERT_NO_THROW(s.validate());
    const double t = 0.5;
    const std::vector<Mat4> world = s.node_transforms(t);
    const SceneFrame f = s.evaluate(t);
    const std::vector<Vec3>& p = s.meshes[0].positions;
    auto at = [&](size_t joint, size_t v) { return Vec3(world[joint] * Vec4(p[v], 1.0f)); };
    const std::vector<Vec3> expected = {0.5f * (at(0, 0) + at(1, 0)), at(1, 1), at(0, 2), 0.25f * at(1, 3) + 0.75f * at(0, 3)};
    for (size_t v = 0; v < p.size(); ++v)
        EXPECT_NEAR(glm::length(f.meshes[0].positions[v] - expected[v]), 0.0f, 1e-5f) << "vertex " << v;
}

TEST(Skinning, FollowingOneJointEqualsTheRigidMeshUnderIt) {
    // A mirroring joint too: winding and normals must match the rigid path's.
    for (Vec3 scale : {Vec3(1.5f, 0.75f, 2), Vec3(-1, 1, 1)}) {
        Transform target = pose_a();
        target.scale = scale;
        Scene s = one_joint_rig(target);
        s.meshes.push_back(patch("rigid"));
        s.nodes[0].meshes = {1};  // the same patch, rigidly under the joint
        for (double t : {0.0, 0.3, 1.0}) {
            SceneFrame f = s.evaluate(t);
            ASSERT_EQ(f.meshes.size(), 2u);
            const WorldMesh& rigid = f.meshes[0];
            const WorldMesh& skinned = f.meshes[1];
            EXPECT_EQ(skinned.triangles, rigid.triangles) << "t = " << t;
            for (size_t v = 0; v < rigid.positions.size(); ++v) {
                EXPECT_EQ(skinned.positions[v], rigid.positions[v]) << "t = " << t << " vertex " << v;
                EXPECT_NEAR(glm::length(skinned.normals[v] - rigid.normals[v]), 0.0f, 1e-5f) << "t = " << t;
            }
        }
    }
}

TEST(Skinning, ValidateRejectsBadSkins) {
    struct Case {
        std::function<void(Scene&)> spoil;
        std::string message;
    };
    const std::vector<Case> cases = {
        {[](Scene& s) { s.meshes[0].influences[2].joints[0] = 1; }, "joint index out of range"},
        {[](Scene& s) { s.meshes[0].influences[1].weights = Vec4(0.5f, 0, 0, 0); }, "summing to"},
        {[](Scene& s) { s.meshes[0].influences[1].weights = Vec4(0); }, "summing to"},
        {[](Scene& s) { s.meshes[0].influences.pop_back(); }, "count mismatch"},
        {[](Scene& s) { s.skins[0].inverse_bind.push_back(Mat4(1.0f)); }, "count mismatch"},
        {[](Scene& s) { s.skins[0].joints = {7}; }, "joint index out of range"},
        {[](Scene& s) { s.nodes[1].skin = 3; }, "references skin 3"},
        {[](Scene& s) { s.meshes[0].influences.clear(); }, "no joint influences"},
    };
    for (const Case& c : cases) {
        Scene s = one_joint_rig(pose_a());
        s.source = "rig.gltf";
        c.spoil(s);
        const std::string msg = error_of([&] { s.validate(); });
        EXPECT_NE(msg.find("rig.gltf"), std::string::npos) << msg;
        EXPECT_NE(msg.find(c.message), std::string::npos) << msg;
    }
}

// ---- The shared animated models (skipped when ../shared/scenes is absent) ----

class SkinnedGlb : public ::testing::TestWithParam<const char*> {};

// At rest every model is in its bind pose: each joint's rest world matrix times its
// inverse bind matrix is one matrix P, so the skinned mesh is P·POSITION. Mid-animation
// the vertices must have moved by a visible fraction of the model's size.
TEST_P(SkinnedGlb, RestIsBindPoseAndTheAnimationMovesIt) {
    auto path = test::shared_asset(GetParam());
    if (!path) GTEST_SKIP() << "shared asset " << GetParam() << " not found";
    Scene s = load_gltf(*path);
    ASSERT_FALSE(s.skins.empty());
    for (const auto& w : s.warnings) EXPECT_EQ(w.find("skin"), std::string::npos) << w;
    const std::vector<Mat4> rest = s.rest_node_transforms();
    const SceneFrame at_rest = s.evaluate_rest();
    const float diag = diagonal(at_rest.bounds);
    ASSERT_GT(diag, 0.0f);
    float bind_error = 0;
    for (const WorldMesh& wm : at_rest.meshes) {
        const SceneNode& node = s.nodes[wm.node];
        ASSERT_GE(node.skin, 0) << "every mesh of these models is skinned";
        const Skin& skin = s.skins[size_t(node.skin)];
        const Mat4 p = rest[skin.joints[0]] * skin.inverse_bind[0];
        const Mesh& mesh = s.meshes[wm.source_mesh];
        for (size_t v = 0; v < mesh.positions.size(); ++v)
            bind_error = std::max(bind_error, glm::length(wm.positions[v] - Vec3(p * Vec4(mesh.positions[v], 1.0f))));
    }
    EXPECT_LE(bind_error, 1e-4f * diag);

    const double mid = 0.5 * s.animation_duration();
    const SceneFrame moved = s.evaluate(mid);
    ASSERT_EQ(moved.meshes.size(), at_rest.meshes.size());
    float max_move = 0;
    double mean_move = 0;
    size_t n = 0;
    for (size_t m = 0; m < moved.meshes.size(); ++m)
        for (size_t v = 0; v < moved.meshes[m].positions.size(); ++v) {
            const float d = glm::length(moved.meshes[m].positions[v] - at_rest.meshes[m].positions[v]);
            max_move = std::max(max_move, d);
            mean_move += d;
            ++n;
            const Vec3& nrm = moved.meshes[m].normals.empty() ? Vec3(0, 0, 1) : moved.meshes[m].normals[v];
            ASSERT_TRUE(is_finite(nrm) && std::abs(glm::length(nrm) - 1.0f) < 1e-4f);
        }
    EXPECT_GT(max_move, 0.01f * diag);
    std::printf("%s: diagonal %.4g, bind-pose error %.3g, at t = %.3g s max displacement %.4g (%.1f%% of the "
                "diagonal), mean %.4g\n",
                GetParam(), diag, bind_error, mid, max_move, 100.0f * max_move / diag, mean_move / double(n));
}

INSTANTIATE_TEST_SUITE_P(Shared, SkinnedGlb,
                         ::testing::Values("animated/BrainStem.glb", "animated/CesiumMan.glb", "animated/Fox.glb",
                                           "animated/RiggedFigure.glb", "animated/RiggedSimple.glb"),
                         [](const auto& info) { return fs::path(info.param).stem().string(); });

// RiggedSimple's first keys equal its rest pose, so t = 0 is a real animation time in
// bind pose; its skinned node's own matrix differs from the bind placement, which a
// loader that applied it would get wrong.
TEST(SkinnedGlbTimes, RiggedSimpleAtTimeZeroIsItsBindPose) {
    auto path = test::shared_asset("animated/RiggedSimple.glb");
    if (!path) GTEST_SKIP() << "shared asset animated/RiggedSimple.glb not found";
    Scene s = load_gltf(*path);
    const SceneFrame rest = s.evaluate_rest(), start = s.evaluate(0.0);
    const float tol = 1e-5f * diagonal(rest.bounds);
    ASSERT_EQ(rest.meshes.size(), start.meshes.size());
    for (size_t m = 0; m < rest.meshes.size(); ++m)
        for (size_t v = 0; v < rest.meshes[m].positions.size(); ++v)
            EXPECT_NEAR(glm::length(start.meshes[m].positions[v] - rest.meshes[m].positions[v]), 0.0f, tol);
    const std::vector<Mat4> world = s.rest_node_transforms();
    const WorldMesh& wm = rest.meshes[0];
    const Vec3 rigid = Vec3(world[wm.node] * Vec4(s.meshes[wm.source_mesh].positions[0], 1.0f));
    EXPECT_GT(glm::length(rigid - wm.positions[0]), tol);
}
