#include "core/render/sampling.hpp"

#include <algorithm>
#include <cmath>
#include "core/util/error.hpp"

namespace gilab {

namespace {

// Shirley–Chiu concentric map: square → unit disk, area preserving, low distortion.
Vec2 concentric_disk(const Vec2& u) {
    float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    if (a == 0.0f && b == 0.0f) return Vec2(0.0f);
    float r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = (kPi / 4.0f) * (b / a);
    } else {
        r = b;
        phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

// Unit vector around +z with the given cosine and azimuth.
Vec3 spherical_direction(float cos_theta, float phi) {
    float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
    return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

}  // namespace

Vec3 sample_cosine_hemisphere(const Vec2& u) {
    // Malley's method: project uniform disk samples up onto the hemisphere.
    Vec2 d = concentric_disk(u);
    float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}

Vec3 sample_uniform_sphere(const Vec2& u) {
    return spherical_direction(1.0f - 2.0f * u.x, 2.0f * kPi * u.y);
}

Vec3 sample_uniform_cone(const Vec2& u, float cos_max) {
    // Uniform in cosθ over [cos_max, 1] is uniform in solid angle.
    float cos_theta = 1.0f - u.x * (1.0f - cos_max);
    return spherical_direction(cos_theta, 2.0f * kPi * u.y);
}

Vec2 sample_uniform_triangle(const Vec2& u) {
    // b0 = 1 − √u₀ gives the marginal density of a uniform triangle; the remainder
    // splits linearly between vertices 1 and 2.
    float su = std::sqrt(u.x);
    return {su * (1.0f - u.y), su * u.y};
}

Vec3 sample_phong_lobe(const Vec2& u, float exponent) {
    // Inverse of the CDF of (n+1) cos^n θ sinθ: cosθ = u^(1/(n+1)).
    float cos_theta = std::pow(u.x, 1.0f / (exponent + 1.0f));
    return spherical_direction(cos_theta, 2.0f * kPi * u.y);
}

DiscreteDistribution::DiscreteDistribution(std::span<const float> weights)
    : weights_(weights.begin(), weights.end()) {
    cdf_.resize(weights_.size() + 1);
    cdf_[0] = 0.0;
    for (size_t i = 0; i < weights_.size(); ++i) {
        float w = weights_[i];
        if (!std::isfinite(w) || w < 0.0f)
            throw Error("DiscreteDistribution", "weight " + std::to_string(i) + " is negative or not finite (" +
                                                    std::to_string(w) + ")");
        cdf_[i + 1] = cdf_[i] + double(w);
    }
    total_ = float(cdf_.back());
}

size_t DiscreteDistribution::sample(float u) const {
    if (empty()) return 0;
    // First bin whose upper cdf edge exceeds the target; zero-weight bins have an empty
    // interval and are never chosen.
    double target = double(std::clamp(u, 0.0f, 1.0f)) * cdf_.back();
    auto it = std::upper_bound(cdf_.begin(), cdf_.end(), target);
    size_t i = size_t(std::max<std::ptrdiff_t>(it - cdf_.begin() - 1, 0));
    i = std::min(i, weights_.size() - 1);
    while (i > 0 && weights_[i] == 0.0f) --i;  // only reachable for u at the very top
    return i;
}

}  // namespace gilab
