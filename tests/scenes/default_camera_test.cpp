// The camera a scene gets when it has none must see its geometry: a flat model is looked
// at face-on, from the side the default sun lights, never edge-on.
#include <gtest/gtest.h>

#include "scenes/scene_library.hpp"
#include "tests/test_support.hpp"

using namespace gilab;

namespace {

Vec3 view_direction(const SceneCamera& c) { return glm::normalize(c.target - c.position); }

// The direction the default sun light travels (scenes without lights get it).
const Vec3 kSunTravel = glm::normalize(Vec3(0.3f, -1.0f, 0.4f));

SceneFrame quad_frame(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    SceneFrame frame;
    WorldMesh m;
    m.positions = {a, b, c, d};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    m.material_ids = {0, 0};
    for (const Vec3& p : m.positions) frame.bounds.extend(p);
    frame.meshes.push_back(m);
    return frame;
}

}  // namespace

TEST(DefaultCamera, SolidBoundsKeepTheFrontView) {
    Bounds3 b;
    b.extend(Vec3(-1, 0, -2));
    b.extend(Vec3(1, 2, 2));
    const SceneCamera c = default_camera_for(b);
    const float radius = 0.5f * glm::length(b.extent());
    const float distance = radius / std::tan(glm::radians(45.0f) * 0.5f) * 1.1f;
    EXPECT_EQ(c.target, b.center());
    EXPECT_EQ(c.position, b.center() + Vec3(0, 0.25f * radius, -distance));
}

TEST(DefaultCamera, FlatBoundsAreSeenFaceOnFromTheLitSide) {
    for (int axis = 0; axis < 3; ++axis) {
        Bounds3 b;
        Vec3 hi(2, 3, 4);
        hi[axis] = 0;  // flat: zero extent along `axis`
        b.extend(Vec3(0));
        b.extend(hi);
        const SceneCamera c = default_camera_for(b);
        const Vec3 d = view_direction(c);
        EXPECT_GT(std::abs(d[axis]), 0.999f) << "axis " << axis << ": looks along " << d.x << " " << d.y << " " << d.z;
        EXPECT_GT(glm::dot(d, kSunTravel), 0.0f) << "axis " << axis << ": the camera is on the unlit side";
        EXPECT_GT(glm::length(glm::cross(d, c.up)), 0.5f) << "up is parallel to the view";
    }
}

TEST(DefaultCamera, TiltedFlatModelEdgeOnFromTheFrontIsSeenAlongItsNormal) {
    // A plane containing the front view's direction and the x axis: its bounds are not
    // flat, but the front view sees it exactly edge-on.
    Bounds3 probe;
    probe.extend(Vec3(0));
    probe.extend(Vec3(1, 1, 1));
    const Vec3 along = view_direction(default_camera_for(probe));
    const SceneFrame frame = quad_frame(Vec3(0), Vec3(1, 0, 0), Vec3(1, 0, 0) + 2.0f * along, 2.0f * along);
    const Vec3 normal = glm::normalize(glm::cross(Vec3(1, 0, 0), along));
    bool edge_on = true;
    const SceneCamera c = default_camera_for(frame, &edge_on);
    EXPECT_FALSE(edge_on);
    EXPECT_GT(std::abs(glm::dot(view_direction(c), normal)), 0.99f);
    EXPECT_GT(glm::dot(view_direction(c), kSunTravel), 0.0f);
}

TEST(DefaultCamera, OpenedFlatMeshSaysWhichWayItLooks) {
    const auto dir = test::temp_dir("default_camera_flat");
    const auto path = test::write_file(dir, "flat.obj", "v 0 0 0\nv 0 1 0\nv 0 1 1\nv 0 0 1\nf 1 2 3 4\n");
    const OpenedScene opened = open_scene(path.string(), AssetPaths());
    EXPECT_TRUE(opened.default_camera);
    ASSERT_TRUE(opened.scene.camera);
    EXPECT_GT(std::abs(view_direction(*opened.scene.camera).x), 0.999f);
    bool noted = false;
    for (const std::string& w : opened.warnings) noted |= w.find("scene has no camera") != std::string::npos;
    EXPECT_TRUE(noted);
}
