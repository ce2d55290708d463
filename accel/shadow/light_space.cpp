#include "accel/shadow/light_space.hpp"
#include <algorithm>
#include <cmath>
#include <string>
#include "core/util/error.hpp"

namespace gilab {
namespace {

void orthonormal_basis(const Vec3& dir, Vec3& right, Vec3& up) {
    // Any stable perpendicular; the choice only rotates the grid about the beam.
    const Vec3 helper = std::abs(dir.y) < 0.9f ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
    right = glm::normalize(glm::cross(helper, dir));
    up = glm::cross(dir, right);
}

std::string light_label(const PunctualLight& light) {
    return "light '" + (light.name.empty() ? std::string("(unnamed)") : light.name) + "'";
}

// Greatest depth of the box's corners along a spot light's axis.
double farthest_axial_depth(const PunctualLight& light, const Bounds3& bounds) {
    const Vec3 dir = glm::normalize(light.direction);
    double zmax = -1e300;
    for (int i = 0; i < 8; ++i) {
        const Vec3 c(i & 1 ? bounds.max.x : bounds.min.x, i & 2 ? bounds.max.y : bounds.min.y,
                     i & 4 ? bounds.max.z : bounds.min.z);
        zmax = std::max(zmax, double(glm::dot(c - light.position, dir)));
    }
    return zmax;
}

}  // namespace

bool LightSpace::faces_any_of(const PunctualLight& light, const Bounds3& bounds) {
    if (light.type != LightType::Spot) return true;
    return !bounds.empty() && glm::length(light.direction) > 0 && farthest_axial_depth(light, bounds) > 0;
}

LightSpace::LightSpace(const PunctualLight& light, const Bounds3& bounds, uint32_t resolution) : n_(resolution) {
    const std::string where = "shadow light space (" + light_label(light) + ")";
    if (resolution < 8 || resolution > kMaxLightSpaceResolution)
        throw Error(where, "resolution " + std::to_string(resolution) + " is outside 8.." +
                               std::to_string(kMaxLightSpaceResolution));
    if (bounds.empty() || !is_finite(bounds.min) || !is_finite(bounds.max))
        throw Error(where, "the scene has no finite geometry to cast shadows");
    depth_ = 0;
    while ((1u << depth_) < n_) ++depth_;
    if (light.type == LightType::Point)
        throw Error(where, "point lights are not supported by the shadow DAG; use a spot or directional light");
    const float len = glm::length(light.direction);
    if (!(len > 0.0f) || !std::isfinite(len)) throw Error(where, "the light has no direction");
    dir_ = light.direction / len;
    orthonormal_basis(dir_, right_, up_);

    const Vec3 corners[8] = {
        {bounds.min.x, bounds.min.y, bounds.min.z}, {bounds.max.x, bounds.min.y, bounds.min.z},
        {bounds.min.x, bounds.max.y, bounds.min.z}, {bounds.max.x, bounds.max.y, bounds.min.z},
        {bounds.min.x, bounds.min.y, bounds.max.z}, {bounds.max.x, bounds.min.y, bounds.max.z},
        {bounds.min.x, bounds.max.y, bounds.max.z}, {bounds.max.x, bounds.max.y, bounds.max.z}};
    if (light.type == LightType::Directional) {
        DVec3 lo(1e300), hi(-1e300);
        for (const Vec3& c : corners) {
            const DVec3 q(glm::dot(c, right_), glm::dot(c, up_), glm::dot(c, dir_));
            lo = glm::min(lo, q);
            hi = glm::max(hi, q);
        }
        // A small margin keeps surfaces on the box faces strictly inside.
        const DVec3 margin = glm::max(hi - lo, DVec3(1e-6)) * 1e-3;
        lo_ = lo - margin;
        ext_ = (hi - lo) + 2.0 * margin;
        perspective_ = false;
        return;
    }
    // Spot light.
    const double half = std::acos(std::clamp(double(light.cos_outer), -1.0, 1.0));
    if (!(half < 80.0 * kPi / 180.0))
        throw Error(where, "spot cone half-angle " + std::to_string(half * 180.0 / kPi) +
                               "° is too wide for one light-space frustum (at most 80°)");
    perspective_ = true;
    position_ = light.position;
    tan_half_ = std::tan(half);
    double zmin = 1e300, zmax = -1e300;
    for (const Vec3& c : corners) {
        const double z = glm::dot(c - position_, dir_);
        zmin = std::min(zmin, z);
        zmax = std::max(zmax, z);
    }
    if (!(zmax > 0)) throw Error(where, "the scene lies behind the spot light");
    far_ = zmax * 1.001;
    near_ = std::max(zmin * 0.999, far_ * 1e-4);
}

Ray LightSpace::texel_ray(uint32_t x, uint32_t y) const {
    const double s = (x + 0.5) / n_, t = (y + 0.5) / n_;
    Ray ray;
    if (!perspective_) {
        const DVec3 q(lo_.x + s * ext_.x, lo_.y + t * ext_.y, lo_.z);
        ray.origin = Vec3(double(right_.x) * q.x + double(up_.x) * q.y + double(dir_.x) * q.z,
                          double(right_.y) * q.x + double(up_.y) * q.y + double(dir_.y) * q.z,
                          double(right_.z) * q.x + double(up_.z) * q.y + double(dir_.z) * q.z);
        ray.direction = dir_ * float(ext_.z / n_);
        return ray;
    }
    // Axial component 1 per unit t; scale so t counts voxels of depth, measured from near.
    const double scale = (far_ - near_) / n_;
    const Vec3 d = dir_ + right_ * float(tan_half_ * (2 * s - 1)) + up_ * float(tan_half_ * (2 * t - 1));
    ray.direction = d * float(scale);
    ray.origin = position_ + d * float(near_);
    return ray;
}

DVec3 LightSpace::to_light(const Vec3& p) const {
    if (!perspective_) {
        const DVec3 q(glm::dot(p, right_), glm::dot(p, up_), glm::dot(p, dir_));
        return (q - lo_) / ext_ * double(n_);
    }
    const Vec3 r = p - position_;
    const double z = glm::dot(r, dir_);
    if (!(z > 0)) return DVec3(-1.0);  // behind the light: outside
    const double px = glm::dot(r, right_) / (z * tan_half_), py = glm::dot(r, up_) / (z * tan_half_);
    return DVec3((px * 0.5 + 0.5) * n_, (py * 0.5 + 0.5) * n_, (z - near_) / (far_ - near_) * n_);
}

bool LightSpace::may_overlap_triangle(const Vec3& a, const Vec3& b, const Vec3& c) const {
    if (!perspective_) return true;
    // Each plane as (side, up-or-right axis sign): outside when ±(r·axis) > tan · (r·dir).
    const Vec3 r[3] = {a - position_, b - position_, c - position_};
    auto all_outside = [&](const Vec3& axis, float sign) {
        for (const Vec3& q : r)
            if (sign * glm::dot(q, axis) <= float(tan_half_) * glm::dot(q, dir_)) return false;
        return true;
    };
    if (all_outside(right_, 1) || all_outside(right_, -1) || all_outside(up_, 1) || all_outside(up_, -1)) return false;
    const bool behind = glm::dot(r[0], dir_) <= 0 && glm::dot(r[1], dir_) <= 0 && glm::dot(r[2], dir_) <= 0;
    return !behind;
}

float LightSpace::voxel_world_size(const Vec3& p) const {
    if (!perspective_) return float(std::max({ext_.x, ext_.y, ext_.z}) / n_);
    const double z = std::max(glm::dot(p - position_, dir_), float(near_));
    return float(std::max(2.0 * z * tan_half_, far_ - near_) / n_);
}

Vec3 LightSpace::to_light_direction(const Vec3& p) const {
    if (!perspective_) return -dir_;
    const Vec3 d = position_ - p;
    const float len = glm::length(d);
    return len > 0 ? d / len : -dir_;
}

DVec3 LightSpace::lookup_coords(const Vec3& p, const Vec3& normal) const {
    const Vec3 l = to_light_direction(p);
    Vec3 n = glm::length(normal) > 0 ? glm::normalize(normal) : l;
    if (glm::dot(n, l) < 0) n = -n;
    const Vec3 q = p + n * (1.5f * voxel_world_size(p));
    DVec3 c = to_light(q);
    if (c.x >= 0) c.z -= 1.0;
    return c;
}

}  // namespace gilab
