// The shared reflection model: reciprocity, energy conservation, the normalisation of the
// Phong lobe, consistency of eval / pdf / sample, and the sampled distribution itself.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>
#include "core/render/bsdf.hpp"
#include "core/util/rng.hpp"
#include "core/render/sampling.hpp"

namespace gilab {
namespace {

Material lambert(float albedo) {
    Material m;
    m.albedo = Vec3(albedo);
    return m;
}

Material glossy(float diffuse, float specular, float exponent) {
    Material m;
    m.albedo = Vec3(diffuse);
    m.specular = Vec3(specular);
    m.phong_exponent = exponent;
    return m;
}

// A direction in the hemisphere around n whose cosine with n is cos_theta.
Vec3 direction_at(const Vec3& n, float cos_theta, float phi) {
    float s = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
    return Frame(n).to_world(Vec3(s * std::cos(phi), s * std::sin(phi), cos_theta));
}

Vec3 random_upper(const Vec3& n, Rng& rng) {
    Vec3 d = sample_uniform_sphere(rng.uniform2());
    return glm::dot(d, n) < 0 ? -d : d;
}

struct Estimate {
    double mean = 0, standard_error = 0;
};

// Directional albedo ∫ f cosθ dω by uniform hemisphere sampling (independent of
// bsdf_sample), channel 0.
Estimate albedo_uniform(const Material& m, const Vec3& n, const Vec3& wo, int samples, Rng& rng) {
    double sum = 0, sum2 = 0;
    for (int i = 0; i < samples; ++i) {
        Vec3 local = sample_uniform_sphere(rng.uniform2());
        local.z = std::abs(local.z);
        Vec3 wi = Frame(n).to_world(local);
        double v = double(bsdf_eval(m, n, wo, wi).x) * std::max(0.0f, glm::dot(n, wi)) * 2.0 * kPi;
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / samples;
    return {mean, std::sqrt(std::max(0.0, sum2 / samples - mean * mean) / samples)};
}

// The same integral estimated with bsdf_sample's weights (lost samples count as 0).
Estimate albedo_sampled(const Material& m, const Vec3& n, const Vec3& wo, int samples, Rng& rng) {
    double sum = 0, sum2 = 0;
    for (int i = 0; i < samples; ++i) {
        BsdfSample s = bsdf_sample(m, n, wo, rng);
        double v = s.valid ? double(s.weight.x) : 0.0;
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / samples;
    return {mean, std::sqrt(std::max(0.0, sum2 / samples - mean * mean) / samples)};
}

const Vec3 kNormal = glm::normalize(Vec3(0.3f, 0.8f, -0.2f));

TEST(Bsdf, IsReciprocal) {
    Rng rng(1, 1);
    for (const Material& m : {lambert(0.7f), glossy(0.3f, 0.6f, 1.0f), glossy(0.2f, 0.7f, 20.0f),
                              glossy(0.0f, 1.0f, 500.0f)}) {
        for (int i = 0; i < 2000; ++i) {
            Vec3 a = random_upper(kNormal, rng), b = random_upper(kNormal, rng);
            Vec3 fab = bsdf_eval(m, kNormal, a, b), fba = bsdf_eval(m, kNormal, b, a);
            for (int k = 0; k < 3; ++k) ASSERT_NEAR(fab[k], fba[k], 1e-4f * std::max(1.0f, fab[k]));
        }
    }
}

TEST(Bsdf, BelowTheShadingHemisphereIsBlack) {
    Material m = glossy(0.4f, 0.5f, 10.0f);
    Rng rng(2, 1);
    for (int i = 0; i < 500; ++i) {
        Vec3 up = random_upper(kNormal, rng), down = -random_upper(kNormal, rng);
        EXPECT_EQ(bsdf_eval(m, kNormal, up, down), Vec3(0.0f));
        EXPECT_EQ(bsdf_eval(m, kNormal, down, up), Vec3(0.0f));
        EXPECT_EQ(bsdf_pdf(m, kNormal, up, down), 0.0f);
        EXPECT_EQ(bsdf_pdf(m, kNormal, down, up), 0.0f);
        EXPECT_FALSE(bsdf_sample(m, kNormal, down, rng).valid);
        BsdfSample s = bsdf_sample(m, kNormal, up, rng);
        if (s.valid) {
            EXPECT_GT(glm::dot(s.wi, kNormal), 0.0f);
        }
    }
}

TEST(Bsdf, LambertDirectionalAlbedoEqualsAlbedo) {
    Material m = lambert(0.6f);
    Rng rng(3, 1);
    for (float cos_o : {1.0f, 0.5f, 0.05f}) {
        Vec3 wo = direction_at(kNormal, cos_o, 0.4f);
        Estimate u = albedo_uniform(m, kNormal, wo, 100000, rng);
        EXPECT_NEAR(u.mean, 0.6, 4 * u.standard_error);
        // Cosine sampling makes every weight exactly the albedo.
        for (int i = 0; i < 1000; ++i) {
            BsdfSample s = bsdf_sample(m, kNormal, wo, rng);
            if (!s.valid) continue;
            EXPECT_NEAR(s.weight.x, 0.6f, 1e-4f);
        }
    }
}

TEST(Bsdf, PhongLobeIsNormalisedAtNormalIncidence) {
    // ∫ (n+2)/(2π) cos^n θ cosθ dω = 1, so a pure glossy lobe reflects exactly ρ_s when
    // wo is the normal (its mirror lobe lies entirely above the surface).
    Rng rng(4, 1);
    for (float n : {1.0f, 8.0f, 50.0f, 1000.0f}) {
        Material m = glossy(0.0f, 0.9f, n);
        Estimate s = albedo_sampled(m, kNormal, kNormal, 100000, rng);
        EXPECT_NEAR(s.mean, 0.9, 4 * s.standard_error + 1e-4) << "exponent " << n;
    }
}

TEST(Bsdf, DirectionalAlbedoNeverExceedsOne) {
    // Energy conservation for albedo + specular ≤ 1, over many exponents and angles; the
    // two estimators (uniform directions, and bsdf_sample's weights) must also agree.
    Rng rng(5, 1);
    for (float n : {0.5f, 2.0f, 10.0f, 40.0f}) {
        for (Vec2 mix : {Vec2(0.0f, 1.0f), Vec2(0.5f, 0.5f), Vec2(0.2f, 0.8f)}) {
            Material m = glossy(mix.x, mix.y, n);
            for (float cos_o : {1.0f, 0.8f, 0.5f, 0.2f, 0.02f}) {
                Vec3 wo = direction_at(kNormal, cos_o, 1.3f);
                Estimate s = albedo_sampled(m, kNormal, wo, 60000, rng);
                Estimate u = albedo_uniform(m, kNormal, wo, 60000, rng);
                EXPECT_LE(s.mean, 1.0 + 4 * s.standard_error) << "n " << n << " cos_o " << cos_o;
                double combined = std::sqrt(s.standard_error * s.standard_error + u.standard_error * u.standard_error);
                EXPECT_NEAR(s.mean, u.mean, 4 * combined) << "n " << n << " cos_o " << cos_o;
            }
        }
    }
}

TEST(Bsdf, SampleWeightIsEvalTimesCosineOverPdf) {
    Rng rng(6, 1);
    for (const Material& m : {lambert(0.5f), glossy(0.3f, 0.6f, 5.0f), glossy(0.1f, 0.8f, 100.0f)}) {
        for (int i = 0; i < 2000; ++i) {
            Vec3 wo = random_upper(kNormal, rng);
            BsdfSample s = bsdf_sample(m, kNormal, wo, rng);
            if (!s.valid) continue;
            float pdf = bsdf_pdf(m, kNormal, wo, s.wi);
            ASSERT_NEAR(s.pdf, pdf, 1e-5f * std::max(1.0f, pdf));
            Vec3 expected = bsdf_eval(m, kNormal, wo, s.wi) * glm::dot(kNormal, s.wi) / pdf;
            for (int k = 0; k < 3; ++k) ASSERT_NEAR(s.weight[k], expected[k], 1e-4f * std::max(1.0f, expected[k]));
        }
    }
}

TEST(Bsdf, PdfIntegratesToTheFractionOfValidSamples) {
    // Over the hemisphere the mixture pdf integrates to 1 minus the probability that a
    // glossy sample falls below the horizon (exactly 1 for Lambert).
    Rng rng(7, 1);
    struct Case {
        Material m;
        float cos_o;
    };
    for (const Case& c : {Case{lambert(0.5f), 0.3f}, Case{glossy(0.3f, 0.6f, 5.0f), 0.9f},
                          Case{glossy(0.3f, 0.6f, 5.0f), 0.1f}, Case{glossy(0.0f, 1.0f, 3.0f), 0.15f}}) {
        Vec3 wo = direction_at(kNormal, c.cos_o, 2.0f);
        const int n = 200000;
        double sum = 0, sum2 = 0;
        for (int i = 0; i < n; ++i) {
            Vec3 local = sample_uniform_sphere(rng.uniform2());
            local.z = std::abs(local.z);
            double v = bsdf_pdf(c.m, kNormal, wo, Frame(kNormal).to_world(local)) * 2.0 * kPi;
            sum += v;
            sum2 += v * v;
        }
        double integral = sum / n;
        double se = std::sqrt(std::max(0.0, sum2 / n - integral * integral) / n);
        int valid = 0;
        for (int i = 0; i < n; ++i) valid += bsdf_sample(c.m, kNormal, wo, rng).valid ? 1 : 0;
        double fraction = double(valid) / n;
        double se_fraction = std::sqrt(std::max(fraction * (1 - fraction), 1e-12) / n);
        EXPECT_NEAR(integral, fraction, 4 * std::sqrt(se * se + se_fraction * se_fraction));
        if (!c.m.has_glossy_lobe()) {
            EXPECT_NEAR(integral, 1.0, 4 * se);
            EXPECT_EQ(valid, n);
        }
    }
}

TEST(Bsdf, SampledDirectionsFollowThePdf) {
    // Pearson χ² over equal-area bins in (cosθ, φ); expected frequencies by integrating
    // bsdf_pdf on a fine midpoint grid (dω = dcosθ dφ).
    const int bins_theta = 10, bins_phi = 20, sub = 12;
    Rng rng(8, 1);
    for (const Material& m : {lambert(0.5f), glossy(0.4f, 0.6f, 6.0f), glossy(0.1f, 0.9f, 15.0f)}) {
        Vec3 wo = direction_at(kNormal, 0.6f, 0.7f);
        Frame frame(kNormal);
        std::vector<double> expected(size_t(bins_theta * bins_phi), 0.0);
        const double cell = (1.0 / (bins_theta * sub)) * (2.0 * kPi / (bins_phi * sub));
        for (int i = 0; i < bins_theta * sub; ++i) {
            for (int j = 0; j < bins_phi * sub; ++j) {
                float c = (i + 0.5f) / (bins_theta * sub);
                float phi = 2.0f * kPi * (j + 0.5f) / (bins_phi * sub);
                float s = std::sqrt(1 - c * c);
                Vec3 wi = frame.to_world(Vec3(s * std::cos(phi), s * std::sin(phi), c));
                expected[size_t((i / sub) * bins_phi + j / sub)] += bsdf_pdf(m, kNormal, wo, wi) * cell;
            }
        }
        const int n = 200000;
        std::vector<double> observed(expected.size(), 0.0);
        for (int k = 0; k < n; ++k) {
            BsdfSample s = bsdf_sample(m, kNormal, wo, rng);
            if (!s.valid) continue;
            Vec3 l = frame.to_local(s.wi);
            double phi = std::atan2(l.y, l.x);
            if (phi < 0) phi += 2 * kPi;
            int bt = std::min(bins_theta - 1, int(l.z * bins_theta));
            int bp = std::min(bins_phi - 1, int(phi / (2 * kPi) * bins_phi));
            observed[size_t(bt * bins_phi + bp)] += 1;
        }
        double chi2 = 0;
        int dof = 0;
        for (size_t b = 0; b < expected.size(); ++b) {
            double e = expected[b] * n;
            if (e < 5) continue;
            chi2 += (observed[b] - e) * (observed[b] - e) / e;
            ++dof;
        }
        ASSERT_GT(dof, 50);
        // Mean dof, sd √(2 dof): 6 sd above the mean is far beyond chance.
        EXPECT_LT(chi2, dof + 6 * std::sqrt(2.0 * dof)) << "exponent " << m.phong_exponent;
    }
}

TEST(Bsdf, DiffuseOnlyPartIsAlbedoOverPi) {
    Material m = glossy(0.5f, 0.3f, 10.0f);
    EXPECT_FLOAT_EQ(bsdf_diffuse(m).x, 0.5f / kPi);
    Material black = lambert(0.0f);
    Rng rng(9, 1);
    EXPECT_FALSE(bsdf_sample(black, kNormal, kNormal, rng).valid);
}

}  // namespace
}  // namespace gilab
