#include "core/scene/camera.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <string>
#include "core/util/error.hpp"
#include "core/util/format.hpp"

namespace gilab {

namespace {

void check_tangents(const FrustumTangents& f, const char* where) {
    bool finite = std::isfinite(f.left) && std::isfinite(f.right) && std::isfinite(f.bottom) &&
                  std::isfinite(f.top);
    if (!finite || !(f.left < f.right) || !(f.bottom < f.top)) {
        throw Error(where, "invalid frustum tangents (left " + number_as_given(f.left) +
                               ", right " + number_as_given(f.right) + ", bottom " +
                               number_as_given(f.bottom) + ", top " + number_as_given(f.top) +
                               "): need finite values with left < right and bottom < top");
    }
}

void check_angle(float a, const char* name) {
    if (!std::isfinite(a) || std::abs(a) >= 0.5f * kPi) {
        throw Error("FrustumTangents::from_openxr",
                    std::string(name) + " = " + number_as_given(a) +
                        " rad is outside (-pi/2, pi/2)");
    }
}

}  // namespace

FrustumTangents FrustumTangents::symmetric(float vertical_fov_degrees, float aspect) {
    if (!(vertical_fov_degrees > 0.0f && vertical_fov_degrees < 180.0f)) {
        throw Error("FrustumTangents::symmetric",
                    "vertical field of view " + number_as_given(vertical_fov_degrees) +
                        " degrees is outside (0, 180)");
    }
    if (!(aspect > 0.0f) || !std::isfinite(aspect)) {
        throw Error("FrustumTangents::symmetric",
                    "aspect ratio " + number_as_given(aspect) + " must be positive");
    }
    float t = std::tan(glm::radians(vertical_fov_degrees) * 0.5f);
    return {-t * aspect, t * aspect, -t, t};
}

FrustumTangents FrustumTangents::from_openxr(float angle_left, float angle_right, float angle_up,
                                             float angle_down) {
    check_angle(angle_left, "angleLeft");
    check_angle(angle_right, "angleRight");
    check_angle(angle_up, "angleUp");
    check_angle(angle_down, "angleDown");
    FrustumTangents f{std::tan(angle_left), std::tan(angle_right), std::tan(angle_down),
                      std::tan(angle_up)};
    // OpenXR allows left > right (a mirrored view); we do not render mirrored views.
    check_tangents(f, "FrustumTangents::from_openxr");
    return f;
}

FrustumTangents FrustumTangents::from_openvr(float left, float right, float top, float bottom) {
    // ComposeProjection (the OpenVR documentation's reference) puts pfTop at NDC y = -1.
    FrustumTangents f{left, right, top, bottom};
    check_tangents(f, "FrustumTangents::from_openvr");
    return f;
}

EyeCamera::EyeCamera(const Vec3& position, const Quat& orientation, const FrustumTangents& fov,
                     int width, int height)
    : position_(position), fov_(fov), width_(width), height_(height) {
    if (width <= 0 || height <= 0) {
        throw Error("EyeCamera", "resolution " + std::to_string(width) + "x" +
                                     std::to_string(height) + " must be positive");
    }
    if (!is_finite(position)) throw Error("EyeCamera", "camera position is not finite");
    float len = glm::length(orientation);
    if (!std::isfinite(len) || len < 1e-6f) {
        throw Error("EyeCamera", "camera orientation quaternion is zero or not finite");
    }
    orientation_ = orientation / len;
    check_tangents(fov, "EyeCamera");
}

EyeCamera EyeCamera::look_at(const Vec3& eye, const Vec3& target, const Vec3& up,
                             float vertical_fov_degrees, int width, int height) {
    if (width <= 0 || height <= 0) {
        throw Error("EyeCamera::look_at", "resolution " + std::to_string(width) + "x" +
                                              std::to_string(height) + " must be positive");
    }
    Vec3 forward = target - eye;
    if (!is_finite(forward) || glm::length(forward) < 1e-12f) {
        throw Error("EyeCamera::look_at", "eye and target coincide or are not finite");
    }
    forward = glm::normalize(forward);
    Vec3 right = glm::cross(forward, up);
    if (!is_finite(right) || glm::length(right) < 1e-6f * std::max(glm::length(up), 1e-30f)) {
        throw Error("EyeCamera::look_at", "up vector is zero or parallel to the view direction");
    }
    right = glm::normalize(right);
    Vec3 true_up = glm::cross(right, forward);
    // Columns are the camera axes in world space: +X right, +Y up, +Z backwards.
    Mat3 basis(right, true_up, -forward);
    Quat orientation = glm::normalize(glm::quat_cast(basis));
    auto fov = FrustumTangents::symmetric(vertical_fov_degrees, float(width) / float(height));
    return EyeCamera(eye, orientation, fov, width, height);
}

Ray EyeCamera::generate_ray(float px, float py) const {
    // Computed in double: callers compare rays against project() to sub-pixel precision.
    double u = double(px) / width_, v = double(py) / height_;
    double x = fov_.left + u * (double(fov_.right) - fov_.left);
    double y = fov_.top - v * (double(fov_.top) - fov_.bottom);
    glm::dvec3 dir = glm::dquat(orientation_) * glm::dvec3(x, y, -1.0);
    Ray ray;
    ray.origin = position_;
    ray.direction = Vec3(glm::normalize(dir));
    return ray;
}

std::optional<Vec2> EyeCamera::project(const Vec3& world_point) const {
    glm::dvec3 local = glm::conjugate(glm::dquat(orientation_)) *
                       (glm::dvec3(world_point) - glm::dvec3(position_));
    double depth = -local.z;
    // Points (numerically) in the eye plane would map to tangents beyond 1e7: no pixel.
    if (!(depth > 1e-7 * glm::length(local)) || !std::isfinite(depth)) return std::nullopt;
    double x = local.x / depth, y = local.y / depth;
    double px = (x - fov_.left) / (double(fov_.right) - fov_.left) * width_;
    double py = (double(fov_.top) - y) / (double(fov_.top) - fov_.bottom) * height_;
    return Vec2(float(px), float(py));
}

std::optional<glm::ivec2> EyeCamera::pixel_of(const Vec3& world_point) const {
    auto p = project(world_point);
    if (!p) return std::nullopt;
    float fx = std::floor(p->x), fy = std::floor(p->y);
    if (!(fx >= 0.0f && fy >= 0.0f && fx < float(width_) && fy < float(height_))) {
        return std::nullopt;
    }
    return glm::ivec2(int(fx), int(fy));
}

std::optional<glm::ivec2> EyeCamera::pixel_from_ndc(const Vec2& ndc) const {
    float fx = std::floor(0.5f * (ndc.x + 1.0f) * float(width_));
    float fy = std::floor(0.5f * (1.0f - ndc.y) * float(height_));
    if (!(fx >= 0.0f && fy >= 0.0f && fx < float(width_) && fy < float(height_))) {
        return std::nullopt;
    }
    return glm::ivec2(int(fx), int(fy));
}

Vec3 EyeCamera::forward() const { return orientation_ * Vec3(0, 0, -1); }

Mat4 EyeCamera::view_matrix() const {
    Mat4 rotation_inverse = glm::mat4_cast(glm::conjugate(orientation_));
    return rotation_inverse * glm::translate(Mat4(1.0f), -position_);
}

Mat4 EyeCamera::projection_matrix(float near_plane, float far_plane) const {
    if (!(near_plane > 0.0f) || !(far_plane > near_plane) || !std::isfinite(far_plane)) {
        throw Error("EyeCamera::projection_matrix",
                    "need 0 < near < far, got near " + number_as_given(near_plane) + ", far " +
                        number_as_given(far_plane));
    }
    return glm::frustum(fov_.left * near_plane, fov_.right * near_plane,
                        fov_.bottom * near_plane, fov_.top * near_plane, near_plane,
                        far_plane);
}

}  // namespace gilab
