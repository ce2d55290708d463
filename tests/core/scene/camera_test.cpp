#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>
#include "core/scene/camera.hpp"
#include "core/util/error.hpp"
#include "core/scene/hmd.hpp"

namespace gilab {
namespace {

struct NamedCamera {
    std::string name;
    EyeCamera camera;
};

// A head pose that is neither at the origin nor axis-aligned, so rotation bugs show.
HeadPose tilted_pose() {
    HeadPose pose;
    pose.position = Vec3(1.5f, 1.7f, -3.25f);
    pose.orientation = glm::normalize(glm::angleAxis(glm::radians(37.0f), Vec3(0, 1, 0)) *
                                      glm::angleAxis(glm::radians(-12.0f), Vec3(1, 0, 0)) *
                                      glm::angleAxis(glm::radians(5.0f), Vec3(0, 0, 1)));
    return pose;
}

std::vector<NamedCamera> all_cameras() {
    std::vector<NamedCamera> cameras;
    for (const auto& preset : hmd_presets()) {
        HmdRig rig(preset, tilted_pose());
        cameras.push_back({preset.name + "/left", rig.eye(Eye::Left)});
        cameras.push_back({preset.name + "/right", rig.eye(Eye::Right)});
    }
    cameras.push_back({"mono", EyeCamera::look_at(Vec3(0.3f, 1.0f, 4.0f), Vec3(0, 0.5f, 0),
                                                  Vec3(0, 1, 0), 55.0f, 160, 90)});
    cameras.push_back({"skewed", EyeCamera(Vec3(-2, 0.5f, 1), tilted_pose().orientation,
                                           FrustumTangents{-0.3f, 1.2f, -0.9f, 0.1f}, 33, 71)});
    return cameras;
}

TEST(FrustumTangents, SymmetricFromVerticalFovAndAspect) {
    auto f = FrustumTangents::symmetric(90.0f, 2.0f);
    EXPECT_NEAR(f.left, -2.0f, 1e-6f);
    EXPECT_NEAR(f.right, 2.0f, 1e-6f);
    EXPECT_NEAR(f.bottom, -1.0f, 1e-6f);
    EXPECT_NEAR(f.top, 1.0f, 1e-6f);
    EXPECT_THROW(FrustumTangents::symmetric(0.0f, 1.0f), Error);
    EXPECT_THROW(FrustumTangents::symmetric(180.0f, 1.0f), Error);
    EXPECT_THROW(FrustumTangents::symmetric(60.0f, -1.0f), Error);
}

TEST(FrustumTangents, FromOpenXrTakesTangentsOfSignedAngles) {
    auto f = FrustumTangents::from_openxr(-kPi / 4, kPi / 4, kPi / 4, -kPi / 4);
    EXPECT_NEAR(f.left, -1.0f, 1e-6f);
    EXPECT_NEAR(f.right, 1.0f, 1e-6f);
    EXPECT_NEAR(f.bottom, -1.0f, 1e-6f);
    EXPECT_NEAR(f.top, 1.0f, 1e-6f);
    // Quest 2 left eye: -52/+45 deg horizontal, +48/-50 deg vertical; the runtime's raw
    // tangents for the same eye are 1.279942, 1.0, 1.110613 (up), 1.191754 (down).
    auto q = FrustumTangents::from_openxr(glm::radians(-52.0f), glm::radians(45.0f),
                                          glm::radians(48.0f), glm::radians(-50.0f));
    EXPECT_NEAR(q.left, -1.279942f, 1e-5f);
    EXPECT_NEAR(q.right, 1.0f, 1e-5f);
    EXPECT_NEAR(q.top, 1.110613f, 1e-5f);
    EXPECT_NEAR(q.bottom, -1.191754f, 1e-5f);
    EXPECT_THROW(FrustumTangents::from_openxr(-kPi / 2, 0.5f, 0.5f, -0.5f), Error);
    EXPECT_THROW(FrustumTangents::from_openxr(0.5f, -0.5f, 0.5f, -0.5f), Error);  // mirrored
}

TEST(FrustumTangents, FromOpenVrFollowsComposeProjection) {
    // HTC Vive left eye as SteamVR reports GetProjectionRaw(left, right, top, bottom).
    auto v = FrustumTangents::from_openvr(-1.3975f, 1.25023f, -1.47588f, 1.46464f);
    EXPECT_FLOAT_EQ(v.left, -1.3975f);
    EXPECT_FLOAT_EQ(v.right, 1.25023f);
    EXPECT_FLOAT_EQ(v.bottom, -1.47588f);
    EXPECT_FLOAT_EQ(v.top, 1.46464f);
    // Oculus Rift CV1: SteamVR reports pfTop = -1.11092532, pfBottom = 0.889498115 while
    // libOVR gives UpTan 0.889, DownTan 1.111: the frustum looks further down than up.
    auto r = FrustumTangents::from_openvr(-0.964925885f, 0.715263784f, -1.11092532f, 0.889498115f);
    EXPECT_NEAR(r.top, 0.889498f, 1e-6f);
    EXPECT_NEAR(r.bottom, -1.110925f, 1e-6f);
    EXPECT_GT(-r.bottom, r.top);
    // And the matrix agrees with Valve's ComposeProjection: pfTop maps to NDC y = -1.
    EyeCamera cam(Vec3(0), Quat(1, 0, 0, 0), r, 100, 100);
    Mat4 p = cam.projection_matrix(0.1f, 100.0f);
    Vec4 clip = p * Vec4(0.0f, -1.11092532f, -1.0f, 1.0f);
    EXPECT_NEAR(clip.y / clip.w, -1.0f, 1e-5f);
    EXPECT_THROW(FrustumTangents::from_openvr(1.0f, -1.0f, -1.0f, 1.0f), Error);
}

TEST(EyeCamera, RejectsBadConstruction) {
    FrustumTangents f;
    EXPECT_THROW(EyeCamera(Vec3(0), Quat(1, 0, 0, 0), f, 0, 10), Error);
    EXPECT_THROW(EyeCamera(Vec3(0), Quat(1, 0, 0, 0), f, 10, -1), Error);
    EXPECT_THROW(EyeCamera(Vec3(0), Quat(0, 0, 0, 0), f, 10, 10), Error);
    EXPECT_THROW(EyeCamera(Vec3(0), Quat(1, 0, 0, 0), FrustumTangents{1, -1, -1, 1}, 10, 10), Error);
    EXPECT_THROW(EyeCamera::look_at(Vec3(1), Vec3(1), Vec3(0, 1, 0), 60, 10, 10), Error);
    EXPECT_THROW(EyeCamera::look_at(Vec3(0), Vec3(0, 5, 0), Vec3(0, 1, 0), 60, 10, 10), Error);
}

TEST(EyeCamera, GenerateRayThenProjectReturnsTheSamePixel) {
    std::mt19937 rng(1234);
    for (const auto& [name, cam] : all_cameras()) {
        std::uniform_real_distribution<float> ux(0.0f, float(cam.width()));
        std::uniform_real_distribution<float> uy(0.0f, float(cam.height()));
        std::uniform_real_distribution<float> ut(0.5f, 80.0f);
        for (int i = 0; i < 2000; ++i) {
            float px = ux(rng), py = uy(rng);
            Ray ray = cam.generate_ray(px, py);
            ASSERT_NEAR(glm::length(ray.direction), 1.0f, 1e-5f) << name;
            ASSERT_EQ(ray.origin, cam.position()) << name;
            auto p = cam.project(ray.at(ut(rng)));
            ASSERT_TRUE(p.has_value()) << name;
            ASSERT_NEAR(p->x, px, 1e-3f) << name << " pixel (" << px << ", " << py << ")";
            ASSERT_NEAR(p->y, py, 1e-3f) << name << " pixel (" << px << ", " << py << ")";
        }
    }
}

TEST(EyeCamera, ImageCornersAndOrientation) {
    for (const auto& [name, cam] : all_cameras()) {
        const auto& f = cam.fov();
        Quat q = cam.orientation();
        // Pixel (0,0) is the top-left corner: direction (left, top, -1) in camera space.
        Vec3 top_left = glm::normalize(q * Vec3(f.left, f.top, -1.0f));
        Vec3 bottom_right = glm::normalize(q * Vec3(f.right, f.bottom, -1.0f));
        EXPECT_LT(glm::length(cam.generate_ray(0, 0).direction - top_left), 1e-5f) << name;
        EXPECT_LT(glm::length(cam.generate_ray(float(cam.width()), float(cam.height())).direction -
                              bottom_right),
                  1e-5f)
            << name;
        // Rows grow downwards: a point above the optical axis has a smaller row.
        Vec3 up = q * Vec3(0, 1, 0);
        auto a = cam.project(cam.position() + cam.forward() + 0.05f * up);
        auto b = cam.project(cam.position() + cam.forward() - 0.05f * up);
        ASSERT_TRUE(a && b);
        EXPECT_LT(a->y, b->y) << name;
    }
}

TEST(EyeCamera, PointsBehindOrBesideTheCameraHaveNoPixel) {
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (const auto& [name, cam] : all_cameras()) {
        Quat q = cam.orientation();
        for (int i = 0; i < 200; ++i) {
            // Camera-space z > 0 is behind the eye, whatever x and y are.
            Vec3 local(5.0f * u(rng), 5.0f * u(rng), 0.01f + 3.0f * (u(rng) + 1.0f));
            Vec3 world = cam.position() + q * local;
            EXPECT_FALSE(cam.project(world).has_value()) << name;
            EXPECT_FALSE(cam.pixel_of(world).has_value()) << name;
        }
        // In the eye plane (z = 0) nothing projects either.
        EXPECT_FALSE(cam.project(cam.position() + q * Vec3(1, 0, 0)).has_value()) << name;
        // In front but outside the frustum: project works, pixel_of refuses.
        Vec3 outside = cam.position() + q * Vec3(cam.fov().right * 2.0f + 0.5f, 0.0f, -1.0f);
        auto p = cam.project(outside);
        ASSERT_TRUE(p.has_value()) << name;
        EXPECT_GT(p->x, float(cam.width())) << name;
        EXPECT_FALSE(cam.pixel_of(outside).has_value()) << name;
    }
}

TEST(EyeCamera, ProjectionMatrixPathMatchesPixelOf) {
    const float near_plane = 0.05f, far_plane = 200.0f;
    std::mt19937 rng(7);
    for (const auto& [name, cam] : all_cameras()) {
        Mat4 view_proj = cam.projection_matrix(near_plane, far_plane) * cam.view_matrix();
        std::uniform_real_distribution<float> ux(0.0f, float(cam.width()));
        std::uniform_real_distribution<float> uy(0.0f, float(cam.height()));
        std::uniform_real_distribution<float> ut(0.1f, 150.0f);
        int checked = 0;
        for (int i = 0; i < 2000; ++i) {
            float px = ux(rng), py = uy(rng);
            // Stay clear of pixel borders, where float rounding may pick either side.
            if (std::abs(px - std::round(px)) < 2e-3f || std::abs(py - std::round(py)) < 2e-3f) continue;
            Vec3 world = cam.generate_ray(px, py).at(ut(rng));
            auto expected = cam.pixel_of(world);
            ASSERT_TRUE(expected.has_value()) << name;
            ASSERT_EQ(*expected, glm::ivec2(int(px), int(py))) << name;

            Vec4 clip = view_proj * Vec4(world, 1.0f);
            ASSERT_GT(clip.w, 0.0f) << name;
            Vec3 ndc = Vec3(clip) / clip.w;
            EXPECT_GE(ndc.z, -1.0f - 1e-4f) << name;
            EXPECT_LE(ndc.z, 1.0f + 1e-4f) << name;
            // The paper's reprojection: index = floor(0.5 (ndc.xy + 1) * size). NDC y is up,
            // so its y index counts rows from the bottom.
            int ix = int(std::floor(0.5f * (ndc.x + 1.0f) * float(cam.width())));
            int iy_from_bottom = int(std::floor(0.5f * (ndc.y + 1.0f) * float(cam.height())));
            EXPECT_EQ(ix, expected->x) << name;
            EXPECT_EQ(cam.height() - 1 - iy_from_bottom, expected->y) << name;
            auto via_ndc = cam.pixel_from_ndc(Vec2(ndc));
            ASSERT_TRUE(via_ndc.has_value()) << name;
            EXPECT_EQ(*via_ndc, *expected) << name;
            ++checked;
        }
        EXPECT_GT(checked, 1500) << name;
        EXPECT_FALSE(cam.pixel_from_ndc(Vec2(1.5f, 0.0f)).has_value());
        EXPECT_FALSE(cam.pixel_from_ndc(Vec2(0.0f, -1.01f)).has_value());
    }
}

TEST(EyeCamera, ProjectionMatrixIsTheOffAxisGlFrustum) {
    FrustumTangents f{-1.3975f, 1.25023f, -1.47588f, 1.46464f};
    EyeCamera cam(Vec3(0), Quat(1, 0, 0, 0), f, 1080, 1200);
    const float n = 0.1f, fa = 100.0f;
    Mat4 p = cam.projection_matrix(n, fa);
    // glm is column-major: p[column][row].
    EXPECT_NEAR(p[0][0], 2.0f / (f.right - f.left), 1e-6f);
    EXPECT_NEAR(p[1][1], 2.0f / (f.top - f.bottom), 1e-6f);
    EXPECT_NEAR(p[2][0], (f.right + f.left) / (f.right - f.left), 1e-6f);
    EXPECT_NEAR(p[2][1], (f.top + f.bottom) / (f.top - f.bottom), 1e-6f);
    EXPECT_NEAR(p[2][2], -(fa + n) / (fa - n), 1e-6f);
    EXPECT_NEAR(p[3][2], -2.0f * fa * n / (fa - n), 1e-6f);
    EXPECT_FLOAT_EQ(p[2][3], -1.0f);
    EXPECT_FLOAT_EQ(p[3][3], 0.0f);
    // Frustum edges land on the NDC borders; near and far planes on z = -1 and +1.
    Vec4 c = p * Vec4(f.left * n, f.top * n, -n, 1.0f);
    EXPECT_NEAR(c.x / c.w, -1.0f, 1e-5f);
    EXPECT_NEAR(c.y / c.w, 1.0f, 1e-5f);
    EXPECT_NEAR(c.z / c.w, -1.0f, 1e-5f);
    c = p * Vec4(f.right * fa, f.bottom * fa, -fa, 1.0f);
    EXPECT_NEAR(c.x / c.w, 1.0f, 1e-5f);
    EXPECT_NEAR(c.y / c.w, -1.0f, 1e-5f);
    EXPECT_NEAR(c.z / c.w, 1.0f, 1e-4f);
    EXPECT_THROW(cam.projection_matrix(0.0f, 1.0f), Error);
    EXPECT_THROW(cam.projection_matrix(1.0f, 1.0f), Error);
}

TEST(EyeCamera, ViewMatrixMovesTheEyeToTheOrigin) {
    for (const auto& [name, cam] : all_cameras()) {
        Mat4 v = cam.view_matrix();
        Vec4 eye = v * Vec4(cam.position(), 1.0f);
        EXPECT_LT(glm::length(Vec3(eye)), 1e-5f) << name;
        Vec4 fwd = v * Vec4(cam.forward(), 0.0f);
        EXPECT_LT(glm::length(Vec3(fwd) - Vec3(0, 0, -1)), 1e-5f) << name;
    }
}

TEST(EyeCamera, HeadsetFrustaAreReallyAsymmetric) {
    for (const auto& preset : hmd_presets()) {
        HmdRig rig(preset);
        for (Eye eye : {Eye::Left, Eye::Right}) {
            EyeCamera cam = rig.eye(eye);
            const auto& f = cam.fov();
            // Each eye sees further outwards (temporal) than inwards (nasal).
            if (eye == Eye::Left) {
                EXPECT_GT(-f.left, f.right * 1.05f) << preset.name;
            } else {
                EXPECT_GT(f.right, -f.left * 1.05f) << preset.name;
            }
            // So the optical axis is off the image centre, towards the nose.
            auto axis = cam.project(cam.position() + cam.forward());
            ASSERT_TRUE(axis.has_value());
            float centre = 0.5f * float(cam.width());
            if (eye == Eye::Left) {
                EXPECT_GT(axis->x, centre + 0.02f * float(cam.width())) << preset.name;
            } else {
                EXPECT_LT(axis->x, centre - 0.02f * float(cam.width())) << preset.name;
            }
        }
        // The two eyes mirror each other closely.
        EXPECT_NEAR(preset.left_fov.left, -preset.right_fov.right, 0.02f) << preset.name;
        EXPECT_NEAR(preset.left_fov.right, -preset.right_fov.left, 0.02f) << preset.name;
    }
}

TEST(EyeCamera, LookAtCentresTheTarget) {
    Vec3 eye(1, 2, 3), target(-2, 0.5f, -4);
    auto cam = EyeCamera::look_at(eye, target, Vec3(0, 1, 0), 60.0f, 200, 100);
    EXPECT_LT(glm::length(cam.forward() - glm::normalize(target - eye)), 1e-5f);
    auto p = cam.project(target);
    ASSERT_TRUE(p.has_value());
    EXPECT_NEAR(p->x, 100.0f, 1e-3f);
    EXPECT_NEAR(p->y, 50.0f, 1e-3f);
    auto above = cam.project(target + Vec3(0, 0.5f, 0));
    ASSERT_TRUE(above.has_value());
    EXPECT_LT(above->y, p->y);
    EXPECT_NEAR(cam.fov().top, std::tan(glm::radians(30.0f)), 1e-6f);
    EXPECT_NEAR(cam.fov().right, 2.0f * std::tan(glm::radians(30.0f)), 1e-6f);
}

TEST(HmdRig, EyeSeparationIsTheIpdAlongTheRotatedHeadX) {
    for (const auto& preset : hmd_presets()) {
        HeadPose pose = tilted_pose();
        HmdRig rig(preset, pose);
        rig.set_ipd(0.0712f);
        Vec3 l = rig.eye_position(Eye::Left), r = rig.eye_position(Eye::Right);
        EXPECT_NEAR(glm::distance(l, r), 0.0712f, 1e-6f) << preset.name;
        Vec3 head_x = pose.orientation * Vec3(1, 0, 0);
        EXPECT_LT(glm::length(glm::normalize(r - l) - head_x), 1e-5f) << preset.name;
        EXPECT_LT(glm::length(0.5f * (l + r) - pose.position), 1e-6f) << preset.name;
        // Unrotated head: the left eye is at -X.
        HmdRig straight(preset);
        EXPECT_NEAR(straight.eye_position(Eye::Left).x, -0.5f * preset.ipd, 1e-7f);
        EXPECT_NEAR(straight.eye_position(Eye::Right).x, 0.5f * preset.ipd, 1e-7f);
        // Each eye camera sits at its eye, looks where the head looks, has its own frustum.
        EyeCamera lc = rig.eye(Eye::Left), rc = rig.eye(Eye::Right);
        EXPECT_EQ(lc.position(), l);
        EXPECT_EQ(rc.position(), r);
        EXPECT_LT(glm::length(lc.forward() - pose.orientation * Vec3(0, 0, -1)), 1e-6f);
        EXPECT_FLOAT_EQ(lc.fov().left, preset.left_fov.left);
        EXPECT_FLOAT_EQ(rc.fov().left, preset.right_fov.left);
        EXPECT_EQ(lc.width(), preset.width);
        EXPECT_EQ(rc.height(), preset.height);
    }
}

}  // namespace
}  // namespace gilab
