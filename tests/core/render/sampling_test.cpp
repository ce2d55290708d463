// Warps and discrete distributions: every warp lands in its domain and reproduces known
// moments of its density; discrete sampling frequencies match the pmf.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>
#include "core/util/error.hpp"
#include "core/util/rng.hpp"
#include "core/render/sampling.hpp"

namespace gilab {
namespace {

constexpr int kSamples = 200000;

// Mean of g over the warp and its standard error.
struct Moment {
    double mean = 0, standard_error = 0;
};
template <typename F>
Moment moment(int n, F&& g) {
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        double v = g(i);
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / n;
    double var = std::max(0.0, sum2 / n - mean * mean);
    return {mean, std::sqrt(var / n)};
}

// |estimate − expected| within four standard errors (plus a float-rounding floor).
void expect_close(const Moment& m, double expected, const char* what) {
    double tolerance = 4.0 * m.standard_error + 1e-6;
    EXPECT_NEAR(m.mean, expected, tolerance) << what;
}

TEST(Sampling, CosineHemisphereIsUnitUpperAndHasCosineMoments) {
    Rng rng(7, 1);
    std::vector<Vec3> dirs(kSamples);
    for (Vec3& d : dirs) d = sample_cosine_hemisphere(rng.uniform2());
    for (const Vec3& d : dirs) {
        ASSERT_GE(d.z, 0.0f);
        ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
    }
    // pdf cosθ/π: E[cosθ] = 2/3, E[cos²θ] = 1/2, E[x] = E[y] = 0.
    expect_close(moment(kSamples, [&](int i) { return dirs[size_t(i)].z; }), 2.0 / 3.0, "E[cos]");
    expect_close(moment(kSamples, [&](int i) { return dirs[size_t(i)].z * dirs[size_t(i)].z; }), 0.5, "E[cos^2]");
    expect_close(moment(kSamples, [&](int i) { return dirs[size_t(i)].x; }), 0.0, "E[x]");
    expect_close(moment(kSamples, [&](int i) { return dirs[size_t(i)].y; }), 0.0, "E[y]");
    EXPECT_FLOAT_EQ(cosine_hemisphere_pdf(1.0f), kInvPi);
    EXPECT_EQ(cosine_hemisphere_pdf(-0.5f), 0.0f);
}

TEST(Sampling, UniformSphereMoments) {
    Rng rng(8, 1);
    std::vector<Vec3> dirs(kSamples);
    for (Vec3& d : dirs) d = sample_uniform_sphere(rng.uniform2());
    for (const Vec3& d : dirs) ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
    for (int axis = 0; axis < 3; ++axis) {
        expect_close(moment(kSamples, [&](int i) { return dirs[size_t(i)][axis]; }), 0.0, "E[axis]");
        expect_close(moment(kSamples, [&](int i) { return dirs[size_t(i)][axis] * dirs[size_t(i)][axis]; }),
                     1.0 / 3.0, "E[axis^2]");
    }
}

TEST(Sampling, UniformConeStaysInsideAndIsUniformInCosine) {
    Rng rng(9, 1);
    for (float cos_max : {0.9f, 0.3f, -0.5f}) {
        std::vector<Vec3> dirs(kSamples);
        for (Vec3& d : dirs) d = sample_uniform_cone(rng.uniform2(), cos_max);
        for (const Vec3& d : dirs) {
            ASSERT_GE(d.z, cos_max - 1e-6f);
            ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
        }
        expect_close(moment(kSamples, [&](int i) { return dirs[size_t(i)].z; }), 0.5 * (1.0 + cos_max), "E[cos]");
    }
}

TEST(Sampling, TriangleBarycentricsAreUniform) {
    Rng rng(10, 1);
    std::vector<Vec3> b(kSamples);
    for (Vec3& w : b) {
        Vec2 s = sample_uniform_triangle(rng.uniform2());
        w = Vec3(1.0f - s.x - s.y, s.x, s.y);
    }
    for (const Vec3& w : b) {
        ASSERT_GE(w.x, -1e-6f);
        ASSERT_GE(w.y, 0.0f);
        ASSERT_GE(w.z, 0.0f);
    }
    // Uniform on a triangle: E[b_i] = 1/3, E[b_i²] = 1/6, and the corner sub-triangle
    // b_i > 1/2 holds a quarter of the area.
    for (int k = 0; k < 3; ++k) {
        expect_close(moment(kSamples, [&](int i) { return b[size_t(i)][k]; }), 1.0 / 3.0, "E[b]");
        expect_close(moment(kSamples, [&](int i) { return b[size_t(i)][k] * b[size_t(i)][k]; }), 1.0 / 6.0, "E[b^2]");
        expect_close(moment(kSamples, [&](int i) { return b[size_t(i)][k] > 0.5f ? 1.0 : 0.0; }), 0.25, "corner");
    }
}

TEST(Sampling, PhongLobeMatchesItsDensity) {
    Rng rng(11, 1);
    for (float n : {0.0f, 1.0f, 10.0f, 200.0f}) {
        std::vector<float> c(kSamples);
        for (float& z : c) {
            Vec3 d = sample_phong_lobe(rng.uniform2(), n);
            ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
            z = d.z;
        }
        // pdf (n+1)/(2π) cos^n: E[cosθ] = (n+1)/(n+2), E[cos²θ] = (n+1)/(n+3).
        expect_close(moment(kSamples, [&](int i) { return c[size_t(i)]; }), (n + 1.0) / (n + 2.0), "E[cos]");
        expect_close(moment(kSamples, [&](int i) { return double(c[size_t(i)]) * c[size_t(i)]; }),
                     (n + 1.0) / (n + 3.0), "E[cos^2]");
    }
}

TEST(Sampling, PowerHeuristic) {
    EXPECT_FLOAT_EQ(power_heuristic(1.0f, 1.0f), 0.5f);
    EXPECT_FLOAT_EQ(power_heuristic(3.0f, 1.0f), 0.9f);
    EXPECT_FLOAT_EQ(power_heuristic(1.0f, 0.0f), 1.0f);
    EXPECT_FLOAT_EQ(power_heuristic(0.0f, 0.0f), 0.0f);
    EXPECT_FLOAT_EQ(power_heuristic(2.0f, 5.0f) + power_heuristic(5.0f, 2.0f), 1.0f);
}

TEST(DiscreteDistribution, FrequenciesMatchPmfAndZeroWeightsAreNeverChosen) {
    std::vector<float> w = {0.0f, 1.0f, 3.0f, 0.0f, 0.5f, 2.5f, 0.0f};
    DiscreteDistribution dist(w);
    ASSERT_FALSE(dist.empty());
    EXPECT_EQ(dist.size(), w.size());
    EXPECT_FLOAT_EQ(dist.total(), 7.0f);
    double pmf_sum = 0;
    for (size_t i = 0; i < w.size(); ++i) pmf_sum += dist.pmf(i);
    EXPECT_NEAR(pmf_sum, 1.0, 1e-6);

    Rng rng(12, 3);
    const int n = 400000;
    std::vector<int> counts(w.size(), 0);
    for (int i = 0; i < n; ++i) ++counts[dist.sample(rng.uniform())];
    for (size_t i = 0; i < w.size(); ++i) {
        double p = dist.pmf(i);
        if (w[i] == 0.0f) {
            EXPECT_EQ(counts[i], 0) << "zero-weight entry " << i << " was sampled";
            continue;
        }
        double se = std::sqrt(p * (1 - p) / n);
        EXPECT_NEAR(double(counts[i]) / n, p, 4 * se) << "entry " << i;
    }
    // The ends of [0, 1) map to the first and last non-zero entries.
    EXPECT_EQ(dist.sample(0.0f), 1u);
    EXPECT_EQ(dist.sample(std::nextafter(1.0f, 0.0f)), 5u);
    EXPECT_EQ(dist.sample(1.0f), 5u);
}

TEST(DiscreteDistribution, EmptyAndInvalidWeights) {
    EXPECT_TRUE(DiscreteDistribution().empty());
    std::vector<float> zeros = {0.0f, 0.0f};
    EXPECT_TRUE(DiscreteDistribution(zeros).empty());
    std::vector<float> bad = {1.0f, -2.0f};
    EXPECT_THROW(DiscreteDistribution{bad}, Error);
    std::vector<float> nan = {1.0f, std::nanf("")};
    EXPECT_THROW(DiscreteDistribution{nan}, Error);
}

}  // namespace
}  // namespace gilab
