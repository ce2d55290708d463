#pragma once
// Warps from the unit square and discrete distributions.
#include <span>
#include <vector>
#include "core/util/math.hpp"

namespace gilab {

Vec3 sample_cosine_hemisphere(const Vec2& u);      // local frame, z up; pdf = cosθ/π
inline float cosine_hemisphere_pdf(float cos_theta) { return std::max(cos_theta, 0.0f) * kInvPi; }
Vec3 sample_uniform_sphere(const Vec2& u);          // pdf = 1/(4π)
Vec3 sample_uniform_cone(const Vec2& u, float cos_max);  // around +z; pdf = 1/(2π(1−cos_max))
Vec2 sample_uniform_triangle(const Vec2& u);        // barycentrics (b1, b2)
// Phong lobe cos^n around +z; pdf = (n+1)/(2π) cos^n.
Vec3 sample_phong_lobe(const Vec2& u, float exponent);

inline float power_heuristic(float pdf_a, float pdf_b) {
    float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
    return a + b > 0 ? a / (a + b) : 0.0f;
}

// Piecewise-constant 1D distribution over weights (e.g. lights by power).
class DiscreteDistribution {
public:
    DiscreteDistribution() = default;
    explicit DiscreteDistribution(std::span<const float> weights);
    bool empty() const { return cdf_.size() <= 1 || total_ <= 0; }
    size_t size() const { return weights_.size(); }
    // Index for u ∈ [0,1); pdf of returning i is weight(i)/total.
    size_t sample(float u) const;
    float pmf(size_t i) const { return total_ > 0 ? weights_[i] / total_ : 0.0f; }
    float total() const { return total_; }

private:
    std::vector<float> weights_;
    std::vector<double> cdf_;
    float total_ = 0;
};

}  // namespace gilab
