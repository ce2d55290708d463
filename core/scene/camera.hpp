#pragma once
// Pinhole eye camera with an asymmetric frustum, the building block of both the mono
// camera and each eye of an HMD. Camera space: +X right, +Y up, looking down −Z.
// Pixel coordinates are continuous: (0,0) is the top-left corner of the image, pixel
// (i, j) covers [i, i+1) × [j, j+1), its centre is (i + 0.5, j + 0.5).
#include <optional>
#include "core/util/ray.hpp"

namespace gilab {

// Tangents of the four half angles, signed, in camera space (y up):
// left < right, bottom < top; a symmetric 90° frustum is {-1, 1, -1, 1}.
struct FrustumTangents {
    float left = -1, right = 1, bottom = -1, top = 1;

    static FrustumTangents symmetric(float vertical_fov_degrees, float aspect);
    // OpenXR XrFovf: signed angles in radians (angleLeft < 0, angleDown < 0 usually).
    static FrustumTangents from_openxr(float angle_left, float angle_right, float angle_up,
                                       float angle_down);
    // OpenVR IVRSystem::GetProjectionRaw(pfLeft, pfRight, pfTop, pfBottom): pfTop is
    // usually negative and pfBottom positive. Valve's own ComposeProjection maps pfTop to
    // NDC y = -1 and pfBottom to +1, so in y-up terms bottom = pfTop and top = pfBottom
    // (measured on a Rift: pfTop = -1.11 is the larger, downward half angle).
    static FrustumTangents from_openvr(float left, float right, float top, float bottom);
};

class EyeCamera {
public:
    EyeCamera() = default;
    EyeCamera(const Vec3& position, const Quat& orientation, const FrustumTangents& fov,
              int width, int height);
    // Mono pinhole looking from eye to target with a symmetric vertical field of view.
    static EyeCamera look_at(const Vec3& eye, const Vec3& target, const Vec3& up,
                             float vertical_fov_degrees, int width, int height);

    // World-space ray through continuous pixel coordinate (px, py); direction normalized.
    Ray generate_ray(float px, float py) const;
    // Continuous pixel coordinate of a world point; nullopt if it is not in front of the
    // camera. The result may lie outside [0,width)×[0,height): callers bounds-check.
    std::optional<Vec2> project(const Vec3& world_point) const;
    // Integer pixel containing the projection, or nullopt if outside the image/behind.
    std::optional<glm::ivec2> pixel_of(const Vec3& world_point) const;

    const Vec3& position() const { return position_; }
    const Quat& orientation() const { return orientation_; }
    const FrustumTangents& fov() const { return fov_; }
    int width() const { return width_; }
    int height() const { return height_; }
    Vec3 forward() const;  // world direction of camera −Z
    // Angle in radians one pixel subtends at the image centre: the spread of a camera
    // ray's cone for texture filtering (ray cones, Ray Tracing Gems ch. 20).
    float pixel_spread_angle() const { return std::atan((fov_.top - fov_.bottom) / float(height_)); }
    Mat4 view_matrix() const;                 // world → camera
    // OpenGL off-axis frustum (glFrustum of the tangents × near): NDC y points UP, while
    // pixel row 0 is the TOP row, so the row is floor(0.5 (1 − ndc.y) · height).
    Mat4 projection_matrix(float near_plane, float far_plane) const;  // OpenGL clip space
    // Pixel containing an NDC point (after the perspective divide): the reprojection
    // index floor(0.5 (ndc + 1) · size) with y flipped for the top-row-first image.
    // Same pixel as pixel_of(); nullopt if outside the image.
    std::optional<glm::ivec2> pixel_from_ndc(const Vec2& ndc) const;

private:
    Vec3 position_{0};
    Quat orientation_{1, 0, 0, 0};
    FrustumTangents fov_;
    int width_ = 1, height_ = 1;
};

}  // namespace gilab
