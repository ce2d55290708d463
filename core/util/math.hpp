#pragma once
// Vector types (GLM) and the few geometric helpers every module needs.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <algorithm>
#include <cmath>
#include <limits>

namespace gilab {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using DVec3 = glm::dvec3;
using IVec3 = glm::ivec3;
using UVec3 = glm::uvec3;
using Mat3 = glm::mat3;
using Mat4 = glm::mat4;
using Quat = glm::quat;

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

inline float max_component(const Vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
inline float luminance(const Vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
inline bool is_black(const Vec3& v) { return v.x <= 0.0f && v.y <= 0.0f && v.z <= 0.0f; }
inline bool is_finite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Axis-aligned box; a default-constructed box is empty (min > max).
struct Bounds3 {
    Vec3 min{kInfinity};
    Vec3 max{-kInfinity};

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void extend(const Vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
    void extend(const Bounds3& b) { min = glm::min(min, b.min); max = glm::max(max, b.max); }
    Vec3 extent() const { return empty() ? Vec3(0) : max - min; }
    Vec3 center() const { return 0.5f * (min + max); }
    bool contains(const Vec3& p) const {
        return p.x >= min.x && p.y >= min.y && p.z >= min.z && p.x <= max.x && p.y <= max.y &&
               p.z <= max.z;
    }
};

// Orthonormal basis around a unit normal (Duff et al. 2017, branchless).
struct Frame {
    Vec3 s, t, n;
    explicit Frame(const Vec3& normal) : n(normal) {
        float sign = std::copysign(1.0f, n.z);
        float a = -1.0f / (sign + n.z);
        float b = n.x * n.y * a;
        s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
        t = Vec3(b, sign + n.y * n.y * a, -n.y);
    }
    Vec3 to_world(const Vec3& v) const { return v.x * s + v.y * t + v.z * n; }
    Vec3 to_local(const Vec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }
};

}  // namespace gilab
