// Light sampling for next-event estimation (pdfs, one-sidedness, irradiance against the
// analytic polygon formula, spot falloff) and emission for photon tracing (flux).
#include <gtest/gtest.h>

#include <cmath>
#include "core/util/error.hpp"
#include "core/render/light_sampler.hpp"

namespace gilab {
namespace {

// Appends one triangle as its own world mesh (vertices in winding order).
void add_triangle(SceneFrame& frame, Vec3 a, Vec3 b, Vec3 c, uint32_t material) {
    WorldMesh m;
    m.source_mesh = uint32_t(frame.meshes.size());
    m.positions = {a, b, c};
    m.triangles = {UVec3(0, 1, 2)};
    m.material_ids = {material};
    for (const Vec3& p : m.positions) frame.bounds.extend(p);
    frame.meshes.push_back(m);
}

std::vector<Material> test_materials() {
    Material plain;
    plain.albedo = Vec3(0.5f);
    Material warm;
    warm.emission = Vec3(4.0f, 2.0f, 1.0f);
    Material cool;
    cool.emission = Vec3(0.5f, 1.0f, 3.0f);
    return {plain, warm, cool};
}

// A floor, and two emitters facing down (winding normal −y) at different heights.
SceneFrame area_frame() {
    SceneFrame frame;
    add_triangle(frame, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, 0);
    add_triangle(frame, {-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0, 2, 0.7f}, 1);
    add_triangle(frame, {1, 1.5f, 0}, {2, 1.5f, 0}, {1, 1.5f, 0.6f}, 2);
    return frame;
}

Vec3 winding_normal(const WorldMesh& m) {
    return glm::normalize(glm::cross(m.positions[1] - m.positions[0], m.positions[2] - m.positions[0]));
}

// Irradiance at x (normal n) from a uniformly emitting polygon seen from its front, by
// Lambert's formula: E = L/2 · |Σ_i θ_i (n · γ_i)|, γ_i the unit normal of the plane
// through x and edge (v_i, v_i+1), θ_i the angle that edge subtends at x.
double polygon_irradiance(const Vec3& x, const Vec3& n, const std::vector<Vec3>& poly, double radiance) {
    double sum = 0;
    for (size_t i = 0; i < poly.size(); ++i) {
        DVec3 a = glm::normalize(DVec3(poly[i] - x)), b = glm::normalize(DVec3(poly[(i + 1) % poly.size()] - x));
        double theta = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        sum += theta * glm::dot(DVec3(n), glm::normalize(glm::cross(a, b)));
    }
    return 0.5 * radiance * std::abs(sum);
}

TEST(LightSampler, FindsEmissiveTrianglesAndPowers) {
    SceneFrame frame = area_frame();
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    ASSERT_EQ(lights.light_count(), 2u);
    ASSERT_EQ(lights.emissive_triangles().size(), 2u);
    const EmissiveTriangle& e = lights.emissive_triangles()[0];
    EXPECT_EQ(e.mesh, 1u);
    EXPECT_NEAR(e.normal.y, -1.0f, 1e-6f);
    EXPECT_NEAR(e.area, 0.5f * 1.0f * 1.2f, 1e-6f);
    double expected = kPi * 0.6 * (7.0 / 3.0) + kPi * 0.3 * (4.5 / 3.0);
    EXPECT_NEAR(lights.total_power(), expected, 1e-4 * expected);
}

TEST(LightSampler, PdfIncidentMatchesSampleIncident) {
    SceneFrame frame = area_frame();
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    Rng rng(1, 2);
    int checked = 0;
    for (Vec3 x : {Vec3(0, 0, 0), Vec3(1.3f, 0, 0.4f), Vec3(-1.5f, 0, 1.9f), Vec3(0.2f, 1.0f, 0.1f)}) {
        for (int i = 0; i < 2000; ++i) {
            LightSample s = lights.sample_incident(x, rng);
            if (s.pdf <= 0) continue;
            ASSERT_FALSE(s.delta);
            Vec3 p = x + s.distance * s.wi;
            // Which emitter did it land on? The one whose plane contains p.
            uint32_t mesh = std::abs(p.y - 2.0f) < 1e-4f ? 1u : 2u;
            float pdf = lights.pdf_incident(x, mesh, 0, p);
            ASSERT_NEAR(pdf, s.pdf, 1e-4f * s.pdf);
            ++checked;
        }
    }
    EXPECT_GT(checked, 7000);
    // Non-emissive triangles and unknown meshes have no light pdf.
    EXPECT_EQ(lights.pdf_incident(Vec3(0, 1, 0), 0, 0, Vec3(0, 0, 0)), 0.0f);
    EXPECT_EQ(lights.pdf_incident(Vec3(0, 1, 0), 7, 0, Vec3(0, 0, 0)), 0.0f);
}

TEST(LightSampler, EmittersAreOneSided) {
    SceneFrame frame = area_frame();
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    Rng rng(2, 2);
    // Above both emitters: everything is seen from the back.
    for (int i = 0; i < 1000; ++i) {
        LightSample s = lights.sample_incident(Vec3(0.5f, 3.0f, 0.2f), rng);
        EXPECT_EQ(s.pdf, 0.0f);
    }
    EXPECT_EQ(lights.pdf_incident(Vec3(0, 3, 0), 1, 0, Vec3(0, 2, 0)), 0.0f);
}

TEST(LightSampler, NextEventEstimateGivesAnalyticIrradiance) {
    // One emitter only, so the estimate Li cosθ / pdf has no light-selection noise from
    // the other triangle; compare with Lambert's closed form at several receivers.
    SceneFrame frame;
    add_triangle(frame, {-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0, 2, 0.7f}, 1);
    add_triangle(frame, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, 0);
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    const std::vector<Vec3> poly = frame.meshes[0].positions;
    Rng rng(3, 2);
    for (auto [x, n] : {std::pair{Vec3(0, 0, 0), Vec3(0, 1, 0)}, std::pair{Vec3(1.5f, 0.3f, -0.4f), Vec3(0, 1, 0)},
                        std::pair{Vec3(0.2f, 1.0f, 0.1f), glm::normalize(Vec3(0.3f, 1, 0.2f))}}) {
        const int samples = 100000;
        double sum = 0, sum2 = 0;
        for (int i = 0; i < samples; ++i) {
            LightSample s = lights.sample_incident(x, rng);
            double v = s.pdf > 0 ? double(s.Li.x) * std::max(0.0f, glm::dot(n, s.wi)) / s.pdf : 0.0;
            sum += v;
            sum2 += v * v;
        }
        double mean = sum / samples, se = std::sqrt(std::max(0.0, sum2 / samples - mean * mean) / samples);
        double analytic = polygon_irradiance(x, n, poly, 4.0);
        EXPECT_NEAR(mean, analytic, 4 * se + 1e-6) << "receiver " << x.x << "," << x.y << "," << x.z;
        EXPECT_LT(se, 0.02 * analytic);  // the tolerance is tight enough to matter
    }
}

TEST(LightSampler, PunctualLights) {
    SceneFrame frame;
    add_triangle(frame, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, 0);
    PunctualLight point;
    point.type = LightType::Point;
    point.position = Vec3(0, 2, 0);
    point.intensity = Vec3(3.0f);
    frame.lights.push_back(point);
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    ASSERT_EQ(lights.light_count(), 1u);
    EXPECT_NEAR(lights.total_power(), 4 * kPi * 3.0f, 1e-4f);
    Rng rng(4, 2);
    LightSample s = lights.sample_incident(Vec3(1, 0, 0), rng);
    EXPECT_TRUE(s.delta);
    EXPECT_FLOAT_EQ(s.pdf, 1.0f);
    EXPECT_NEAR(s.distance, std::sqrt(5.0f), 1e-5f);
    EXPECT_NEAR(s.Li.x, 3.0f / 5.0f, 1e-5f);
    EXPECT_NEAR(glm::length(s.wi - glm::normalize(Vec3(-1, 2, 0))), 0.0f, 1e-5f);
}

TEST(LightSampler, AreaSamplingAndExactPunctualLights) {
    // Area lights alone: sample_area_incident draws exactly what sample_incident draws.
    const std::vector<Material> mats = test_materials();
    const LightSampler area_only(area_frame(), mats);
    ASSERT_TRUE(area_only.has_area_lights());
    EXPECT_EQ(area_only.punctual_count(), 0u);
    for (uint64_t k = 0; k < 64; ++k) {
        Rng a(9, k), b(9, k);
        const LightSample x = area_only.sample_incident(Vec3(0.2f, 0, 0.1f), a);
        const LightSample y = area_only.sample_area_incident(Vec3(0.2f, 0, 0.1f), b);
        EXPECT_EQ(x.wi, y.wi);
        EXPECT_EQ(x.pdf, y.pdf);
        EXPECT_EQ(x.Li, y.Li);
    }
    // With a point light beside them, the area samples' pdf leaves the point's power out,
    // and punctual_incident gives the point with pdf 1; sample_incident's point samples
    // carry the point's selection probability.
    SceneFrame frame = area_frame();
    PunctualLight point;
    point.type = LightType::Point;
    point.position = Vec3(0, 3, 0);
    point.intensity = Vec3(100.0f);
    frame.lights.push_back(point);
    const LightSampler mixed(frame, mats);
    ASSERT_EQ(mixed.punctual_count(), 1u);
    const LightSample p = mixed.punctual_incident(0, Vec3(0, 1, 0));
    EXPECT_TRUE(p.delta);
    EXPECT_EQ(p.pdf, 1.0f);
    EXPECT_NEAR(p.Li.x, 100.0f / 4.0f, 1e-4f);
    EXPECT_NEAR(glm::length(p.wi - Vec3(0, 1, 0)), 0.0f, 1e-6f);
    bool saw_point = false;
    for (uint64_t k = 0; k < 256; ++k) {
        Rng a(3, k), b(3, k);
        const LightSample area = mixed.sample_area_incident(Vec3(0.2f, 0, 0.1f), a);
        EXPECT_FALSE(area.delta);
        if (area.pdf > 0) {
            Rng c(3, k);
            const LightSample alone = area_only.sample_area_incident(Vec3(0.2f, 0, 0.1f), c);
            EXPECT_EQ(area.pdf, alone.pdf);
        }
        const LightSample any = mixed.sample_incident(Vec3(0.2f, 0, 0.1f), b);
        if (any.delta) {
            saw_point = true;
            EXPECT_GT(any.pdf, 0.5f);
            EXPECT_LT(any.pdf, 1.0f);
        }
    }
    EXPECT_TRUE(saw_point);
}

TEST(LightSampler, SpotFalloffIsSmoothBetweenTheCones) {
    SceneFrame frame;
    add_triangle(frame, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, 0);
    PunctualLight spot;
    spot.type = LightType::Spot;
    spot.position = Vec3(0, 1, 0);
    spot.direction = Vec3(0, -1, 0);
    spot.intensity = Vec3(2.0f);
    spot.cos_inner = std::cos(0.3f);
    spot.cos_outer = std::cos(0.6f);
    frame.lights.push_back(spot);
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    Rng rng(5, 2);
    float previous = kInfinity;
    for (float angle = 0.0f; angle < 0.9f; angle += 0.01f) {
        Vec3 x = spot.position + Vec3(std::sin(angle), -std::cos(angle), 0);  // distance 1
        LightSample s = lights.sample_incident(x, rng);
        float value = s.Li.x;
        if (angle <= 0.3f - 1e-3f) {
            EXPECT_NEAR(value, 2.0f, 1e-4f);
        }
        if (angle >= 0.6f + 1e-3f) {
            EXPECT_EQ(value, 0.0f);
        }
        if (angle > 0.3f + 1e-3f && angle < 0.6f - 1e-3f) {
            EXPECT_GT(value, 0.0f);
            EXPECT_LT(value, 2.0f);
        }
        EXPECT_LE(value, previous + 1e-6f);
        previous = value;
    }
    spot.cos_inner = 0.2f;  // inner cone wider than the outer one
    frame.lights = {spot};
    EXPECT_THROW(LightSampler(frame, mats), Error);
}

// Mean flux per emission sample must equal the total emitted power per channel.
TEST(LightSampler, EmissionFluxAveragesToTotalPower) {
    SceneFrame frame = area_frame();
    PunctualLight point;
    point.type = LightType::Point;
    point.position = Vec3(0, 1, 0);
    point.intensity = Vec3(1.0f, 2.0f, 0.5f);
    PunctualLight spot;
    spot.type = LightType::Spot;
    spot.position = Vec3(0, 1.8f, 0);
    spot.direction = Vec3(0.2f, -1, 0);
    spot.intensity = Vec3(5.0f, 5.0f, 2.0f);
    spot.cos_inner = 0.9f;
    spot.cos_outer = 0.7f;
    PunctualLight sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(Vec3(0.3f, -1, 0.2f));
    sun.intensity = Vec3(0.8f, 0.7f, 0.6f);
    frame.lights = {point, spot, sun};
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    ASSERT_EQ(lights.light_count(), 5u);

    const float r = 0.5f * glm::length(frame.bounds.extent());
    Vec3 expected = kPi * 0.6f * mats[1].emission + kPi * 0.3f * mats[2].emission + 4 * kPi * point.intensity +
                    2 * kPi * (1 - 0.5f * (0.9f + 0.7f)) * spot.intensity + kPi * r * r * sun.intensity;
    EXPECT_NEAR(lights.total_power(), (expected.x + expected.y + expected.z) / 3, 1e-4 * expected.x);

    Rng rng(6, 2);
    const int n = 400000;
    DVec3 sum(0), sum2(0);
    int directional = 0;
    for (int i = 0; i < n; ++i) {
        EmissionSample e = lights.sample_emission(rng);
        ASSERT_NEAR(glm::length(e.ray.direction), 1.0f, 1e-4f);
        DVec3 p(e.power);
        sum += p;
        sum2 += p * p;
        if (glm::length(e.ray.direction - sun.direction) < 1e-6f) {
            ++directional;
            // Sun rays start outside the scene's bounds and travel along the light.
            EXPECT_FALSE(frame.bounds.contains(e.ray.origin));
        }
    }
    EXPECT_GT(directional, 0);
    for (int k = 0; k < 3; ++k) {
        double mean = sum[k] / n, se = std::sqrt(std::max(0.0, sum2[k] / n - mean * mean) / n);
        EXPECT_NEAR(mean, expected[k], 4 * se + 1e-6) << "channel " << k;
        EXPECT_LT(se, 0.02 * expected[k]);
    }
}

TEST(LightSampler, AreaEmissionIsCosineDistributedOnTheFront) {
    SceneFrame frame;
    add_triangle(frame, {-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0, 2, 0.7f}, 1);
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    Vec3 n = winding_normal(frame.meshes[0]);
    Rng rng(7, 2);
    const int samples = 100000;
    double sum = 0;
    for (int i = 0; i < samples; ++i) {
        EmissionSample e = lights.sample_emission(rng);
        float c = glm::dot(e.ray.direction, n);
        ASSERT_GT(c, 0.0f);
        ASSERT_NEAR(e.ray.origin.y, 2.0f, 1e-3f);
        sum += c;
    }
    // E[cosθ] = 2/3 under a cosine distribution; sd of cosθ is √(1/2 − 4/9).
    EXPECT_NEAR(sum / samples, 2.0 / 3.0, 4 * std::sqrt(0.5 - 4.0 / 9.0) / std::sqrt(double(samples)));
}

TEST(LightSampler, BadMaterialIdIsReported) {
    SceneFrame frame;
    add_triangle(frame, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, 9);
    std::vector<Material> mats = test_materials();
    try {
        LightSampler lights(frame, mats);
        FAIL() << "expected an Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("material 9"), std::string::npos) << e.what();
    }
}

TEST(LightSampler, EmptySceneHasNoLights) {
    SceneFrame frame;
    add_triangle(frame, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, 0);
    std::vector<Material> mats = test_materials();
    LightSampler lights(frame, mats);
    EXPECT_TRUE(lights.empty());
    Rng rng(8, 2);
    EXPECT_EQ(lights.sample_incident(Vec3(0), rng).pdf, 0.0f);
    EXPECT_EQ(lights.sample_emission(rng).power, Vec3(0));
}

}  // namespace
}  // namespace gilab
