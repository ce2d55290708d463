// The `vct` technique: settings, the update schedule (eq. 5), the diffuse cone set,
// level selection by eq. 2, cones through empty space and through walls, energy of the
// diffuse indirect on the Cornell box against the path tracer, the dense-mip baseline
// against the cascades in the innermost cascade, the update strategy, stereo, and
// determinism across thread counts.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstring>
#include <iomanip>
#include "core/util/error.hpp"
#include "core/image/image_metrics.hpp"
#include "core/util/parallel.hpp"
#include "core/util/rng.hpp"
#include "core/scene/skin.hpp"
#include "scenes/builtin_scenes.hpp"
#include "tests/techniques/technique_test_support.hpp"
#include "techniques/technique.hpp"
#include "techniques/vct/cone_tracer.hpp"
#include "techniques/vct/vct_technique.hpp"

namespace gilab {
namespace {

std::unique_ptr<VctTechnique> prepared(const Scene& scene, nlohmann::json settings_json) {
    return test::prepared_technique<VctTechnique>(scene, std::move(settings_json));
}
using test::inside_camera;
using test::render_one;

// ---------------------------------------------------------------------------------

TEST(VctSettings, DefaultsAndErrors) {
    Settings empty;
    VctSettings s = VctSettings::from(empty);
    EXPECT_EQ(s.levels, 6);
    EXPECT_EQ(s.resolution, 32);
    EXPECT_EQ(s.diffuse_cones, 16);
    EXPECT_TRUE(s.specular);
    EXPECT_EQ(s.structure, VctSettings::Structure::Cascaded);
    auto message = [](nlohmann::json j) {
        try {
            VctSettings::from(Settings(j, "cfg"));
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(message({{"structure", "octree"}}).find("'structure' must be one of cascaded, dense"), std::string::npos);
    EXPECT_NE(message({{"resolution", 24}}).find("'resolution'"), std::string::npos);
    EXPECT_NE(message({{"update", "sometimes"}}).find("'update'"), std::string::npos);
    EXPECT_NE(message({{"cone_step", 0}}).find("'cone_step'"), std::string::npos);
    EXPECT_NE(message({{"levels", "six"}}).find("wrong type"), std::string::npos);
    // Unknown keys are left for the caller to report.
    Settings typo(nlohmann::json{{"diffuse_cone", 8}}, "cfg");
    VctSettings::from(typo);
    EXPECT_THROW(typo.report_unused(), Error);
    EXPECT_NE(TechniqueRegistry::builtin().find("vct"), nullptr);
}

TEST(VctSchedule, Equation5UpdatePeriods) {
    using S = VctSettings::Schedule;
    const int log2[] = {1, 1, 2, 2, 3, 3, 3, 3, 4};
    for (int k = 0; k < 9; ++k) EXPECT_EQ(update_period(S::Log2, k), log2[k]) << "level " << k + 1;
    for (int k = 0; k < 6; ++k) EXPECT_EQ(update_period(S::Pow2, k), 1 << k);
    for (int k = 0; k < 6; ++k) EXPECT_EQ(update_period(S::Every, k), 1);
}

TEST(ConeSet, SixteenConesCoverTheHemisphere) {
    ConeSet set = hemisphere_cones(16);
    ASSERT_EQ(set.directions.size(), 16u);
    double w = 0, wc = 0;
    for (size_t i = 0; i < 16; ++i) {
        EXPECT_NEAR(glm::length(set.directions[i]), 1.0f, 1e-5f);
        EXPECT_GT(set.directions[i].z, 0.0f);
        EXPECT_FLOAT_EQ(set.cosines[i], set.directions[i].z);
        w += set.weights[i];
        wc += set.weights[i] * set.cosines[i];
    }
    EXPECT_NEAR(w, 2 * kPi, 1e-4);   // ΣW = 2π
    EXPECT_NEAR(wc, kPi, 1e-4);      // Σ W cosθ = π: a uniform sky L gives E = πL
    // Each cone's solid angle 2π/16 ⇒ cos β = 15/16.
    EXPECT_NEAR(std::atan(set.tan_half_angle), std::acos(15.0 / 16.0), 1e-5);
    EXPECT_LT(phong_cone_tan(200.0f), phong_cone_tan(10.0f));
    EXPECT_NEAR(phong_cone_tan(0.0f), 1.0f, 1e-6f);
}

// A cascade whose radiance is a constant per level (level k: colour k + 1, opacity α),
// to see which level a sample reads.
CascadedVoxelTexture constant_levels(float alpha) {
    CascadeConfig c;
    c.levels = 4;
    c.resolution = 16;
    c.voxel_size = 0.1;
    CascadedVoxelTexture t(c);
    for (int k = 3; k >= 0; --k) t.place(k, t.origin_for(DVec3(0.0), k));
    for (int k = 0; k < 4; ++k)
        for (uint32_t z = 0; z < 16; ++z)
            for (uint32_t y = 0; y < 16; ++y)
                for (uint32_t x = 0; x < 16; ++x)
                    for (int f = 0; f < kFaceCount; ++f)
                        t.radiance[t.index(f, k, UVec3(x, y, z))] = to_half_rgba(Vec4(Vec3(float(k + 1) * alpha), alpha));
    return t;
}

TEST(ConeTracer, Equation2PicksTheLevelMatchingTheFootprint) {
    EXPECT_FLOAT_EQ(cone_level(0.1f, 0.1f), 0.0f);
    EXPECT_FLOAT_EQ(cone_level(0.05f, 0.1f), 0.0f);  // below a voxel: the finest level
    EXPECT_FLOAT_EQ(cone_level(0.2f, 0.1f), 1.0f);
    EXPECT_FLOAT_EQ(cone_level(0.8f, 0.1f), 3.0f);
    EXPECT_NEAR(cone_level(0.4f * std::sqrt(2.0f), 0.1f), 2.5f, 1e-5f);

    CascadedVoxelTexture t = constant_levels(0.01f);
    VoxelConeView view = VoxelConeView::cascade(t, t.radiance);
    EXPECT_EQ(view.finest_level_containing(Vec3(0.0f)), 0);
    EXPECT_EQ(view.finest_level_containing(Vec3(1.0f, 0, 0)), 1);   // level 0 spans ±0.8
    EXPECT_EQ(view.finest_level_containing(Vec3(2.5f, 0, 0)), 2);
    EXPECT_EQ(view.finest_level_containing(Vec3(40.0f, 0, 0)), -1);
    // One sample at distance 0.5 with footprint 2·0.5·tan β: choose tan β so the
    // footprint is 0.4 (4 finest voxels) → level 2 → colour 3α.
    auto one_sample = [&](const Vec3& origin, float tan_beta) {
        ConeOptions o;
        o.start = 0.5f;
        o.max_distance = 0.5001f;
        return trace_cone(view, Cone{origin, Vec3(0, 1, 0), tan_beta}, o);
    };
    ConeResult r = one_sample(Vec3(0, -0.5f, 0), 0.4f);
    ASSERT_EQ(r.samples, 1);
    EXPECT_NEAR(r.radiance.x / r.opacity, 3.0f, 1e-3f);
    // A thin cone near the viewer reads level 0; the same thin cone far away is pushed
    // to the finest level containing its sample (level 2 around x = 2.5).
    EXPECT_NEAR(one_sample(Vec3(0, -0.5f, 0), 0.01f).radiance.x / one_sample(Vec3(0, -0.5f, 0), 0.01f).opacity, 1.0f,
                1e-3f);
    r = one_sample(Vec3(2.5f, -0.5f, 0), 0.01f);
    EXPECT_NEAR(r.radiance.x / r.opacity, 3.0f, 1e-3f);
    // Footprint between levels blends them: 0.4√2 → level 2.5 → colour 3.5α.
    r = one_sample(Vec3(0, -0.5f, 0), 0.4f * std::sqrt(2.0f));
    EXPECT_NEAR(r.radiance.x / r.opacity, 3.5f, 2e-3f);
}

TEST(ConeTracer, EmptySpaceGivesNothingAndAWallSaturates) {
    // Empty cascades: no radiance, no opacity, until the cone leaves the structure.
    CascadedVoxelTexture empty = constant_levels(0.0f);
    ConeResult r = trace_cone(VoxelConeView::cascade(empty, empty.radiance), Cone{Vec3(0.0f), Vec3(0, 0, 1), 0.3f}, {});
    EXPECT_EQ(r.radiance, Vec3(0));
    EXPECT_EQ(r.opacity, 0.0f);
    EXPECT_EQ(r.occlusion, 0.0f);
    EXPECT_GT(r.samples, 5);

    // A solid wall (planes every half finest voxel from z = 1 to 2) across the cone's
    // path, lit with radiance 2 on every face.
    SceneFrame frame;
    WorldMesh wall;
    for (int i = 0; i <= 20; ++i) {
        float z = 1.0f + 0.05f * float(i);
        uint32_t b = uint32_t(wall.positions.size());
        wall.positions.insert(wall.positions.end(), {Vec3(-5, -5, z), Vec3(5, -5, z), Vec3(5, 5, z), Vec3(-5, 5, z)});
        wall.triangles.push_back({b, b + 1, b + 2});
        wall.triangles.push_back({b, b + 2, b + 3});
        wall.material_ids.insert(wall.material_ids.end(), {0, 0});
    }
    frame.meshes.push_back(wall);
    FragmentVoxelizer vox(frame, {Material{}});
    CascadeConfig c;
    c.levels = 4;
    c.resolution = 16;
    c.voxel_size = 0.1;
    c.anchor = DVec3(0.013, 0.021, 0.0);
    CascadedVoxelTexture t(c);
    for (int k = 3; k >= 0; --k) {
        t.place(k, t.origin_for(DVec3(0.0), k));
        t.voxelize(k, vox);
    }
    for (size_t i = 0; i < t.cell_count(); ++i) t.radiance[i] = to_half_rgba(Vec4(Vec3(2.0f * t.opacity_of_cell(i)), t.opacity_of_cell(i)));
    for (int k = 1; k < 4; ++k) t.downsample(k, t.radiance);
    for (int k = 0; k < 4; ++k) t.refresh_occupancy(k, t.radiance);
    VoxelConeView view = VoxelConeView::cascade(t, t.radiance);
    // The occupancy map only skips samples that read nothing: the same cones without it
    // give bit-identical results.
    std::vector<ConeLevel> unskipped;
    for (int k = 0; k < view.level_count(); ++k) {
        unskipped.push_back(view.level(k));
        unskipped.back().occupancy = nullptr;
    }
    const VoxelConeView plain = VoxelConeView::of_levels(view.anchor(), true, unskipped);
    for (float tan_beta : {0.05f, 0.3f, 0.6f})
        for (const Vec3 d : {Vec3(0, 0, 1), Vec3(0, 0, -1), glm::normalize(Vec3(1, 0.5f, 0.8f)), glm::normalize(Vec3(-1, 0.2f, -0.3f))}) {
            const ConeResult a = trace_cone(view, Cone{Vec3(0.0f), d, tan_beta}, {});
            const ConeResult b = trace_cone(plain, Cone{Vec3(0.0f), d, tan_beta}, {});
            EXPECT_EQ(a.radiance, b.radiance);
            EXPECT_EQ(a.opacity, b.opacity);
            EXPECT_EQ(a.samples, b.samples);
        }
    for (float tan_beta : {0.05f, 0.3f, 0.6f}) {
        ConeResult hit = trace_cone(view, Cone{Vec3(0.0f), Vec3(0, 0, 1), tan_beta}, {});
        EXPECT_GE(hit.opacity, 0.99f) << "tan " << tan_beta;
        EXPECT_NEAR(hit.radiance.x, 2.0f * hit.opacity, 0.02f);
        EXPECT_GT(hit.occlusion, 0.5f);
        // Looking away from the wall: nothing.
        ConeResult away = trace_cone(view, Cone{Vec3(0.0f), Vec3(0, 0, -1), tan_beta}, {});
        EXPECT_EQ(away.opacity, 0.0f);
    }
}

// The AVX2 kernel computes the portable kernel's sums in another order with fused
// rounding: on a lit Cornell box, samples (with and without the clip plane) and whole
// cones agree to float rounding, on every level, dense and cascaded.
TEST(ConeTracer, KernelsAgree) {
    if (best_cone_kernel() != ConeKernel::avx2) GTEST_SKIP() << "this CPU lacks AVX2, FMA or F16C: one kernel only";
    Scene scene = make_cornell_box();
    for (const char* structure : {"cascaded", "dense"}) {
        auto vct = prepared(scene, {{"structure", structure}, {"dense_resolution", 64}});
        render_one(*vct, inside_camera(16));
        const VoxelConeView view = vct->radiance_view();
        Rng rng(11, 2);
        auto close = [](const Vec4& a, const Vec4& b) {
            const float scale = std::max({1e-3f, std::abs(a.r), std::abs(a.g), std::abs(a.b), std::abs(a.a)});
            return glm::all(glm::lessThanEqual(glm::abs(a - b), Vec4(2e-6f * scale)));
        };
        int lit = 0;
        for (int i = 0; i < 4000; ++i) {
            const int k = std::min(int(rng.uniform() * float(view.level_count())), view.level_count() - 1);
            const ConeLevel& l = view.level(k);
            const Vec3 u(rng.uniform(), rng.uniform(), rng.uniform());
            const Vec3 p = view.anchor() + (Vec3(l.origin) + u * float(l.size)) * l.voxel_size;
            const Vec3 d = glm::normalize(Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f) + Vec3(1e-3f));
            const FaceWeights faces = faces_seen_along(d);
            const Vec4 plane(d, glm::dot(d, p) - (rng.uniform() - 0.25f) * l.voxel_size);
            for (const Vec4* clip : {static_cast<const Vec4*>(nullptr), &plane}) {
                const Vec4 a = view.sample_level(k, p, faces, clip, ConeKernel::portable);
                const Vec4 b = view.sample_level(k, p, faces, clip, ConeKernel::avx2);
                ASSERT_TRUE(close(a, b)) << structure << " level " << k << " sample " << i << (clip ? " clipped" : "")
                                         << std::setprecision(9) << ": " << a.r << " " << a.g << " " << a.b << " " << a.a << " vs " << b.r << " " << b.g << " " << b.b << " " << b.a;
                lit += a.a > 0;
            }
            ConeOptions o;
            o.clip = true;
            o.clip_plane = plane;
            const Cone cone{p, d, 0.2f + rng.uniform()};
            const ConeResult x = trace_cone(view, cone, o, ConeKernel::portable);
            const ConeResult y = trace_cone(view, cone, o, ConeKernel::avx2);
            EXPECT_NEAR(x.opacity, y.opacity, 1e-4f);
            EXPECT_NEAR(x.radiance.r, y.radiance.r, 1e-4f * std::max(1.0f, x.radiance.r));
        }
        EXPECT_GT(lit, 100) << structure << ": too few samples read anything for the comparison to mean much";
    }
}

// A fan (cones from one apex with one aperture and options) gives each cone exactly
// trace_cone's result under the AVX2 kernel, on cascades and a dense mip chain, for fans of
// 1 to 16 cones (the AVX2 kernel's eight lanes, part-filled and full), with the clip
// plane, level blending, opacity correction, the bounding box and a distance limit each
// on and off. Apexes lie all over the levels, outside them too, so lanes leave the
// finest levels, the box and the structure at different samples.
TEST(ConeTracer, FansGiveEachConeItsOwnResult) {
    // The portable kernel's fan is trace_cone_portable cone by cone, so only the AVX2 fan
    // has a loop of its own to compare.
    if (best_cone_kernel() != ConeKernel::avx2) GTEST_SKIP() << "this CPU lacks AVX2, FMA or F16C: no eight-lane fan";
    Scene scene = make_cornell_box();
    for (const char* structure : {"cascaded", "dense"}) {
        auto vct = prepared(scene, {{"structure", structure}, {"dense_resolution", 64}});
        render_one(*vct, inside_camera(16));
        const VoxelConeView view = vct->radiance_view();
        // A box smaller than the structure (level 1's region), so cones leave it first.
        const ConeLevel& inner = view.level(std::min(1, view.level_count() - 1));
        Bounds3 box;
        box.min = view.anchor() + Vec3(inner.origin) * inner.voxel_size;
        box.max = box.min + Vec3(float(inner.size) * inner.voxel_size);
        Rng rng(5, 3);
        int compared = 0, lit = 0;
        for (int i = 0; i < 300; ++i) {
            const int k = std::min(int(rng.uniform() * float(view.level_count())), view.level_count() - 1);
            const ConeLevel& l = view.level(k);
            const Vec3 u(rng.uniform(), rng.uniform(), rng.uniform());
            const Vec3 apex = view.anchor() + (Vec3(l.origin) + (u * 1.2f - Vec3(0.1f)) * float(l.size)) * l.voxel_size;
            const Vec3 n = glm::normalize(Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f) + Vec3(1e-3f));
            const int count = 1 + i % 16;
            std::vector<Vec3> directions;
            for (int c = 0; c < count; ++c)
                directions.push_back(glm::normalize(n + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f)));
            ConeOptions o;
            o.start = (0.5f + 2.0f * rng.uniform()) * view.base_voxel_size();
            o.clip = i % 2 == 0;
            o.clip_plane = Vec4(n, glm::dot(n, apex) - 0.3f * l.voxel_size);
            o.blend_levels = i % 3 != 0;
            o.correct_opacity = i % 5 == 0;
            if (i % 4 != 3) o.bounds = box;
            if (i % 7 == 0) o.max_distance = 0.5f * glm::length(box.max - box.min);
            o.lod_bias = i % 6 == 0 ? -0.5f : 0.0f;
            const float tan_half = 0.1f + 0.9f * rng.uniform();
            std::vector<ConeResult> fan(directions.size());
            trace_cone_fan(view, apex, directions, tan_half, o, fan, ConeKernel::avx2);
            for (int c = 0; c < count; ++c) {
                const ConeResult one = trace_cone(view, Cone{apex, directions[size_t(c)], tan_half}, o, ConeKernel::avx2);
                const ConeResult& f = fan[size_t(c)];
                ASSERT_EQ(f.samples, one.samples) << structure << " fan " << i << " cone " << c;
                ASSERT_EQ(f.radiance, one.radiance) << structure << " fan " << i << " cone " << c;
                ASSERT_EQ(f.opacity, one.opacity) << structure << " fan " << i << " cone " << c;
                ASSERT_EQ(f.occlusion, one.occlusion) << structure << " fan " << i << " cone " << c;
                ++compared;
                lit += one.opacity > 0.01f;
            }
        }
        EXPECT_GT(lit, compared / 10) << structure << ": too few cones saw anything for the comparison to mean much";
    }
    std::vector<ConeResult> short_results(1);
    const std::vector<Vec3> two{Vec3(0, 0, 1), Vec3(0, 1, 0)};
    const CascadedVoxelTexture empty = constant_levels(0.0f);
    EXPECT_THROW(trace_cone_fan(VoxelConeView::cascade(empty, empty.radiance), Vec3(0.0f), two, 0.3f, {}, short_results),
                 Error);
}

// A batch of unrelated cones (each its own apex, direction, aperture, start and clip plane,
// as neighbouring pixels' specular cones are) gives each cone exactly trace_cone's result
// with the launch's start and plane, under both kernels, on cascades and a dense chain,
// for batches of 1 to 20 cones, with the clip plane, blending and the box on and off.
TEST(ConeTracer, BatchesGiveEachConeItsOwnResult) {
    Scene scene = make_cornell_box();
    std::vector<ConeKernel> kernels{ConeKernel::portable};
    if (best_cone_kernel() == ConeKernel::avx2) kernels.push_back(ConeKernel::avx2);
    for (const char* structure : {"cascaded", "dense"}) {
        auto vct = prepared(scene, {{"structure", structure}, {"dense_resolution", 64}});
        render_one(*vct, inside_camera(16));
        const VoxelConeView view = vct->radiance_view();
        const ConeLevel& inner = view.level(std::min(1, view.level_count() - 1));
        Bounds3 box;
        box.min = view.anchor() + Vec3(inner.origin) * inner.voxel_size;
        box.max = box.min + Vec3(float(inner.size) * inner.voxel_size);
        Rng rng(7, 4);
        int compared = 0, lit = 0;
        for (int i = 0; i < 120; ++i) {
            ConeOptions shared;
            shared.clip = i % 2 == 0;
            shared.blend_levels = i % 3 != 0;
            shared.correct_opacity = i % 5 == 0;
            if (i % 4 != 3) shared.bounds = box;
            const int count = 1 + i % 20;
            std::vector<ConeLaunch> launches;
            for (int c = 0; c < count; ++c) {
                const int k = std::min(int(rng.uniform() * float(view.level_count())), view.level_count() - 1);
                const ConeLevel& l = view.level(k);
                const Vec3 u(rng.uniform(), rng.uniform(), rng.uniform());
                const Vec3 apex = view.anchor() + (Vec3(l.origin) + u * float(l.size)) * l.voxel_size;
                const Vec3 n = glm::normalize(Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f) + Vec3(1e-3f));
                const Vec3 d = glm::normalize(n + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f));
                const float tan_half = 0.02f + 0.6f * rng.uniform();
                const float start = (0.5f + 2.0f * rng.uniform()) * view.base_voxel_size();
                launches.push_back({Cone{apex, d, tan_half}, start, Vec4(n, glm::dot(n, apex) - 0.3f * l.voxel_size)});
            }
            for (ConeKernel kernel : kernels) {
                std::vector<ConeResult> batch(launches.size());
                trace_cones(view, launches, shared, batch, kernel);
                for (int c = 0; c < count; ++c) {
                    const ConeLaunch& launch = launches[size_t(c)];
                    const ConeResult one = trace_cone(view, launch.cone, launch.options_from(shared), kernel);
                    const ConeResult& b = batch[size_t(c)];
                    ASSERT_EQ(b.samples, one.samples)
                        << structure << " batch " << i << " cone " << c << " " << to_string(kernel);
                    ASSERT_EQ(b.radiance, one.radiance) << structure << " batch " << i << " cone " << c;
                    ASSERT_EQ(b.opacity, one.opacity) << structure << " batch " << i << " cone " << c;
                    ASSERT_EQ(b.occlusion, one.occlusion) << structure << " batch " << i << " cone " << c;
                    ++compared;
                    lit += one.opacity > 0.01f;
                }
            }
        }
        EXPECT_GT(lit, compared / 10) << structure << ": too few cones saw anything for the comparison to mean much";
    }
    std::vector<ConeResult> short_results(1);
    const std::vector<ConeLaunch> two(2);
    const CascadedVoxelTexture empty = constant_levels(0.0f);
    EXPECT_THROW(trace_cones(VoxelConeView::cascade(empty, empty.radiance), two, {}, short_results), Error);
}

// Levels above 512³ voxels take the portable sampler under the AVX2 kernel (its 32-bit
// cells would not hold them): there the two kernels agree bit for bit, while on a level
// of 512³ over the same texels the AVX2 sums, rounded otherwise, differ somewhere.
TEST(ConeTracer, LevelsAbove512TakeThePortableSampler) {
    if (best_cone_kernel() != ConeKernel::avx2) GTEST_SKIP() << "this CPU lacks AVX2, FMA or F16C: one kernel only";
    constexpr int kStored = 16;  // a toroidal store of 16³ texels behind a larger region
    std::vector<HalfRGBA> texels(size_t(kStored) * kStored * kStored * kFaceCount);
    Rng rng(3, 1);
    for (HalfRGBA& t : texels)
        t = to_half_rgba(Vec4(rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()));
    auto view_of = [&](int size) {
        ConeLevel l;
        l.data = texels.data();
        l.x_stride = kFaceCount;
        l.row_stride = size_t(kStored) * kFaceCount;
        l.slice_stride = size_t(kStored) * kStored * kFaceCount;
        l.size = size;
        l.wrap_mask = kStored - 1;
        return VoxelConeView::of_levels(Vec3(0.0f), true, {l});
    };
    for (int size : {512, 513, 4096}) {
        const VoxelConeView view = view_of(size);
        int differing = 0;
        for (int i = 0; i < 2000; ++i) {
            const Vec3 p = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * float(size);
            const Vec3 d = glm::normalize(Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f) + Vec3(1e-3f));
            const Vec4 plane(d, glm::dot(d, p) - (rng.uniform() - 0.25f));
            for (const Vec4* clip : {static_cast<const Vec4*>(nullptr), &plane})
                differing += view.sample_level(0, p, faces_seen_along(d), clip, ConeKernel::portable) !=
                             view.sample_level(0, p, faces_seen_along(d), clip, ConeKernel::avx2);
        }
        if (size > 512)
            EXPECT_EQ(differing, 0) << size << "³";
        else
            EXPECT_GT(differing, 0) << "at 512³ the AVX2 sampler runs and rounds otherwise";
    }
}

// Views the fans' eight-lane level tables cannot hold take each lane's sample from the
// kernel's own sampler: ten nested levels (more than eight lanes of levels) and a level of
// 4096³ (cells beyond 32 bits). There too every cone of a fan gets trace_cone's result.
TEST(ConeTracer, FansOverTenLevelsAndAbove512) {
    if (best_cone_kernel() != ConeKernel::avx2) GTEST_SKIP() << "this CPU lacks AVX2, FMA or F16C: one kernel only";
    constexpr int kStored = 16;  // a toroidal store of 16³ texels behind every level
    std::vector<HalfRGBA> texels(size_t(kStored) * kStored * kStored * kFaceCount);
    Rng rng(9, 4);
    for (HalfRGBA& t : texels) {
        const float a = rng.uniform() < 0.95f ? 0.0f : 0.1f * rng.uniform();
        t = to_half_rgba(Vec4(a * rng.uniform(), a * rng.uniform(), a * rng.uniform(), a));
    }
    auto level = [&](int size, int origin, float voxel) {
        ConeLevel l;
        l.data = texels.data();
        l.x_stride = kFaceCount;
        l.row_stride = size_t(kStored) * kFaceCount;
        l.slice_stride = size_t(kStored) * kStored * kFaceCount;
        l.origin = IVec3(origin);
        l.size = size;
        l.wrap_mask = kStored - 1;
        l.voxel_size = voxel;
        l.inv_voxel_size = 1.0f / voxel;
        return l;
    };
    std::vector<ConeLevel> ten;
    for (int k = 0; k < 10; ++k) ten.push_back(level(32, -16, std::ldexp(1.0f, k)));
    const VoxelConeView views[] = {VoxelConeView::of_levels(Vec3(0.0f), true, ten),
                                   VoxelConeView::of_levels(Vec3(0.0f), true, {level(4096, -2048, 1.0f)})};
    int compared = 0, lit = 0, coarse = 0;
    for (const VoxelConeView& view : views) {
        for (int i = 0; i < 60; ++i) {
            const Vec3 apex = (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f)) * 20.0f;
            const Vec3 n = glm::normalize(Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f) + Vec3(1e-3f));
            std::vector<Vec3> directions;
            for (int c = 0; c < 16; ++c)
                directions.push_back(glm::normalize(n + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f)));
            ConeOptions o;
            o.clip = i % 2 == 0;
            o.clip_plane = Vec4(n, glm::dot(n, apex) - 0.3f);
            o.blend_levels = i % 3 == 0;
            o.max_distance = 3000.0f;
            // Narrow cones reach levels 8 and 9 while their footprint asks for a finer one.
            const float tan_half = i % 4 == 1 ? 0.02f : 0.2f + rng.uniform();
            std::vector<ConeResult> fan(directions.size());
            trace_cone_fan(view, apex, directions, tan_half, o, fan, ConeKernel::avx2);
            for (size_t c = 0; c < directions.size(); ++c) {
                const ConeResult one = trace_cone(view, Cone{apex, directions[c], tan_half}, o, ConeKernel::avx2);
                ASSERT_EQ(fan[c].samples, one.samples) << "view " << (&view - views) << " fan " << i << " cone " << c;
                ASSERT_EQ(fan[c].radiance, one.radiance) << "view " << (&view - views) << " fan " << i << " cone " << c;
                ASSERT_EQ(fan[c].opacity, one.opacity);
                ASSERT_EQ(fan[c].occlusion, one.occlusion);
                ++compared;
                lit += one.opacity > 0.01f;
                coarse += one.samples > 40;
            }
        }
    }
    EXPECT_GT(lit, compared / 10) << "too few cones saw anything for the comparison to mean much";
    EXPECT_GT(coarse, 0) << "no cone marched far enough to reach the coarse levels";
}

// ---------------------------------------------------------------------------------

// The Cornell box's diffuse indirect against the path tracer's indirect with the same
// bounce count (max_depth 3: one direct + two indirect bounces; the voxel bounce gives
// the second). VCT is an approximation: coarse voxels (1/128 of the box, coarser
// further out), 16 cones, anisotropic filtering. We require the image-mean indirect
// within 30 % of the reference: tight enough to catch a lost or doubled bounce (±50 %
// or more), a missing cosine (×2) or a wrong ΣW normalisation, loose enough for the
// known cone-tracing bias (over-occlusion near corners, leaking through coarse voxels).
TEST(VctTechnique, CornellIndirectEnergyNearThePathTracer) {
    Scene scene = make_cornell_box();
    EyeCamera camera = inside_camera(48);
    const Settings ps(nlohmann::json{{"spp", 256}, {"max_depth", 3}, {"seed", 3}}, "reference");
    auto path = prepare_technique("path", scene, ps);
    std::vector<Film> ref;
    path->render(ViewSet::mono(camera), ref);

    auto vct = prepared(scene, {{"seed", 3}});
    Film film = render_one(*vct, camera);
    const double ref_indirect = mean_value(ref[0], "indirect");
    const double vct_indirect = mean_value(film, "indirect");
    const double ref_direct = mean_value(ref[0], "direct");
    const double vct_direct = mean_value(film, "direct");
    std::printf("indirect: path %.4f vct %.4f (ratio %.3f); direct: path %.4f vct %.4f\n", ref_indirect, vct_indirect,
                vct_indirect / ref_indirect, ref_direct, vct_direct);
    EXPECT_NEAR(vct_indirect / ref_indirect, 1.0, 0.30);
    // The direct part is ray traced by both: same up to noise.
    EXPECT_NEAR(vct_direct / ref_direct, 1.0, 0.05);
    // Without the voxel bounce one bounce is missing: clearly less indirect light.
    auto one = prepared(scene, {{"seed", 3}, {"second_bounce", false}});
    const double single = mean_value(render_one(*one, camera), "indirect");
    std::printf("single bounce %.4f\n", single);
    EXPECT_LT(single, 0.9 * vct_indirect);
    EXPECT_GT(single, 0.3 * vct_indirect);
}

// The dense mip chain and the cascades share the finest lattice (voxel_size = 0 gives
// the scene cube / dense_resolution for both): inside the innermost cascade their
// G-buffers and injected direct light agree exactly (compared in the V-buffers of
// techniques without the voxel bounce, which then hold direct light only), level 1's
// filtered part equals the first mip, and the rendered images agree closely.
TEST(VctTechnique, DenseMipBaselineAgreesInTheInnermostCascade) {
    Scene scene = make_cornell_box();
    EyeCamera camera = inside_camera(32);
    auto cascaded = prepared(scene, {{"dense_resolution", 64}, {"levels", 5}, {"resolution", 32}});
    auto dense = prepared(scene, {{"dense_resolution", 64}, {"structure", "dense"}});
    Film a = render_one(*cascaded, camera), b = render_one(*dense, camera);
    auto cascaded_direct = prepared(scene, {{"dense_resolution", 64}, {"levels", 5}, {"resolution", 32}, {"second_bounce", false}});
    auto dense_direct = prepared(scene, {{"dense_resolution", 64}, {"structure", "dense"}, {"second_bounce", false}});
    render_one(*cascaded_direct, camera);
    render_one(*dense_direct, camera);
    const CascadedVoxelTexture& c = *cascaded_direct->cascade();
    const DenseMipTexture& d = *dense_direct->dense();
    ASSERT_EQ(c.config().anchor, d.config().anchor);
    ASSERT_EQ(c.voxel_size(0), d.voxel_size(0));
    size_t compared = 0;
    for (int level = 0; level < 2; ++level) {
        const VoxelBox box = level == 0 ? c.region(0) : c.inner_box(1);
        const std::vector<HalfRGBA>& mip = d.radiance[size_t(level)];
        for (int z = box.begin.z; z < box.end.z; ++z)
            for (int y = box.begin.y; y < box.end.y; ++y)
                for (int x = box.begin.x; x < box.end.x; ++x) {
                    const IVec3 v(x, y, z);
                    if (glm::any(glm::lessThan(v, IVec3(0))) || glm::any(glm::greaterThanEqual(v, IVec3(d.resolution(level)))))
                        continue;
                    for (int f = 0; f < kFaceCount; ++f) {
                        const Vec4 cv = from_half_rgba(c.radiance[c.index_of_voxel(f, level, v)]);
                        const Vec4 dv = from_half_rgba(mip[d.index(level, f, v)]);
                        ASSERT_NEAR(cv.a, dv.a, 1e-6f) << "level " << level << " voxel " << x << "," << y << "," << z;
                        ASSERT_NEAR(cv.r, dv.r, 1e-5f * std::max(1.0f, dv.r));
                        compared += cv.a > 0;
                    }
                }
    }
    EXPECT_GT(compared, 500u);
    // Images: the same direct light, and indirect light within 25 % of each other (they
    // differ only beyond the innermost cascades, where the cascades are coarser).
    EXPECT_LT(max_abs_difference(a, b, "direct"), 1e-6);
    EXPECT_NEAR(mean_value(a, "indirect") / mean_value(b, "indirect"), 1.0, 0.25);
}

TEST(VctTechnique, UpdateStrategyFollowsTheViewer) {
    Scene scene = make_cornell_box();
    auto strategy = prepared(scene, {{"dense_resolution", 64}, {"levels", 4}, {"resolution", 16}, {"diffuse", false}});
    auto everything = prepared(scene, {{"dense_resolution", 64}, {"levels", 4}, {"resolution", 16}, {"diffuse", false},
                                       {"update", "everything"}});
    // A walk through the box: the strategy updates few levels per frame and voxelizes
    // only new border slabs; the result keeps the G-buffer equal to a full rebuild.
    double strategy_voxels = 0, everything_voxels = 0, levels = 0;
    for (int i = 0; i < 8; ++i) {
        Vec3 eye(0.2f + 0.08f * float(i), 0.45f, 0.3f + 0.03f * float(i));
        EyeCamera cam = EyeCamera::look_at(eye, eye + Vec3(0, 0, 1), Vec3(0, 1, 0), 60.0f, 8, 8);
        render_one(*strategy, cam);
        render_one(*everything, cam);
        strategy_voxels += strategy->stats().get("voxels_revoxelized");
        everything_voxels += everything->stats().get("voxels_revoxelized");
        levels += strategy->stats().get("levels_updated");
        EXPECT_EQ(everything->stats().get("levels_updated"), 4.0);
    }
    EXPECT_LT(levels, 8 * 4);
    EXPECT_LT(strategy_voxels, 0.5 * everything_voxels);
    // Every level updated on the last frame (frame 8: periods 1, 1, 2, 2) sits where a
    // full rebuild puts it, with the same G-buffer.
    const CascadedVoxelTexture& s = *strategy->cascade();
    const CascadedVoxelTexture& e = *everything->cascade();
    for (int k = 0; k < 4; ++k) {
        ASSERT_EQ(s.origin(k), e.origin(k)) << "level " << k;
        for (const IVec3& v : e.occupied_in(k, e.region(k))) {
            ASSERT_TRUE(s.occupied(k, v)) << "level " << k;
            ASSERT_EQ(s.gbuffer_voxel(k, v), e.gbuffer_voxel(k, v)) << "level " << k;
        }
        EXPECT_EQ(s.occupied_voxels(k), e.occupied_voxels(k));
    }
}

TEST(VctTechnique, StereoLayersAndProvenance) {
    Scene scene = make_cornell_box();
    auto t = prepared(scene, {{"dense_resolution", 64}});
    EyeCamera left = inside_camera(16);
    EyeCamera right = EyeCamera::look_at(Vec3(0.56f, 0.45f, 0.06f), Vec3(0.56f, 0.42f, 1.0f), Vec3(0, 1, 0), 75.0f, 16, 16);
    std::vector<Film> films;
    t->render(ViewSet::stereo_pair(left, right), films);
    ASSERT_EQ(films.size(), 2u);
    for (const char* layer : {"color", "direct", "indirect", "specular", "ao", "albedo", "normal", "depth"})
        EXPECT_TRUE(films[0].has_layer(layer)) << layer;
    EXPECT_EQ(films[1].metadata.at("view"), "right");
    EXPECT_EQ(films[0].metadata.at("technique"), "vct");
    Stats s = t->stats();
    for (const char* key : {"update_ms", "injection_ms", "primary_ms", "direct_ms", "diffuse_ms", "specular_ms", "total_ms",
                            "structure_bytes", "occupied_voxels"})
        EXPECT_TRUE(s.has(key)) << key;
    // ao in [0, 1]; colour = direct + indirect + specular, channel by channel.
    for (const Film& film : films) {
        const auto& color = film.layer("color").data;
        const auto& direct = film.layer("direct").data;
        const auto& indirect = film.layer("indirect").data;
        const auto& specular = film.layer("specular").data;
        double lit = 0;
        for (size_t i = 0; i < film.pixel_count(); ++i) {
            EXPECT_GE(film.layer("ao").data[i], 0.0f);
            EXPECT_LE(film.layer("ao").data[i], 1.0f);
            for (size_t c = 3 * i; c < 3 * i + 3; ++c) {
                const float sum = direct[c] + indirect[c] + specular[c];
                EXPECT_NEAR(color[c], sum, 1e-5f * std::max(1.0f, std::abs(sum))) << "pixel " << i;
                lit += indirect[c];
            }
        }
        EXPECT_GT(lit, 0.0) << "the indirect layer should not be empty";
    }
}

TEST(VctTechnique, SameImagesAtOneAndTwoThreads) {
    Scene scene = make_cornell_box();
    for (const char* structure : {"cascaded", "dense"})
    for (const bool temporal : {false, true}) {
        auto run = [&](int threads) {
            ThreadLimit limit(threads);
            auto t = prepared(scene, {{"dense_resolution", 32}, {"structure", structure}, {"levels", 4}, {"resolution", 16},
                                      {"injection_cones", 4}, {"diffuse_cones", 8}, {"temporal_bounces", temporal}});
            std::vector<Film> out;
            for (int i = 0; i < 2; ++i) {  // two frames: the second one scrolls
                Vec3 eye(0.4f + 0.1f * float(i), 0.45f, 0.1f);
                out.push_back(render_one(*t, EyeCamera::look_at(eye, eye + Vec3(0, 0, 1), Vec3(0, 1, 0), 70.0f, 24, 24)));
            }
            return out;
        };
        auto one = run(1), two = run(2);
        for (size_t f = 0; f < one.size(); ++f)
            for (const auto& [name, layer] : one[f].layers())
                ASSERT_EQ(std::memcmp(layer.data.data(), two[f].layer(name).data.data(), layer.data.size() * sizeof(float)), 0)
                    << structure << (temporal ? " temporal" : "") << " frame " << f << " layer " << name;
    }
}

// Temporal bounces: each frame's voxel bounce gathers the radiance of the frames before.
// The first frame after prepare sees P3's two bounces (prepare lit the voxels with direct
// light only); every later frame adds one: more indirect light each frame.
TEST(VctTechnique, TemporalBouncesAddABounceEachFrame) {
    Scene scene = make_cornell_box();
    const EyeCamera camera = inside_camera(24);
    auto two = prepared(scene, {{"dense_resolution", 32}, {"structure", "dense"}});
    auto many = prepared(scene, {{"dense_resolution", 32}, {"structure", "dense"}, {"temporal_bounces", true}});
    double previous = 0;
    for (int frame = 0; frame < 3; ++frame) {
        const double fixed = mean_value(render_one(*two, camera), "indirect");
        const double growing = mean_value(render_one(*many, camera), "indirect");
        if (frame == 0) EXPECT_NEAR(growing, fixed, 1e-6 * fixed);
        else EXPECT_GT(growing, previous * 1.02) << "frame " << frame;
        previous = growing;
    }
}

// P3 does not write dynamic objects into the G-buffer: a mesh under an animated node is
// not voxelized (it is still seen and shadowed by Embree).
TEST(VctTechnique, DynamicMeshesAreNotVoxelized) {
    Scene scene = make_cornell_box();
    Mesh block;
    block.name = "moving";
    block.positions = {Vec3(0.45f, 0.5f, 0.45f), Vec3(0.55f, 0.5f, 0.45f), Vec3(0.55f, 0.5f, 0.55f), Vec3(0.45f, 0.5f, 0.55f)};
    block.triangles = {{0, 1, 2}, {0, 2, 3}};
    block.material_ids = {0, 0};
    uint32_t node = scene.add_mesh_instance(block);
    scene.nodes[node].animation.translation.times = {0.0f, 1.0f};
    scene.nodes[node].animation.translation.values = {Vec3(0), Vec3(0, 0.1f, 0)};
    auto with = prepared(scene, {{"dense_resolution", 64}, {"diffuse", false}});
    auto without = prepared(make_cornell_box(), {{"dense_resolution", 64}, {"diffuse", false}});
    const CascadedVoxelTexture& a = *with->cascade();
    const CascadedVoxelTexture& b = *without->cascade();
    ASSERT_EQ(a.cell_count(), b.cell_count());
    for (size_t i = 0; i < a.cell_count(); ++i) ASSERT_EQ(a.opacity_of_cell(i), b.opacity_of_cell(i)) << "cell " << i;
    EXPECT_EQ(with->stats().get("voxelized_triangles") + 2, with->stats().get("triangles"));
    // Still seen by the primary rays: the image differs.
    with->update(0.5);
    EyeCamera camera = EyeCamera::look_at(Vec3(0.5f, 0.9f, 0.5f), Vec3(0.5f, 0.0f, 0.5f), Vec3(0, 0, 1), 60.0f, 16, 16);
    EXPECT_GT(max_abs_difference(render_one(*with, camera), render_one(*without, camera), "depth"), 0.01);
}

TEST(VctTechnique, SpecularConeReflectsTheScene) {
    Scene scene = make_cornell_box();
    scene.materials[0].specular = Vec3(0.5f);   // glossy white surfaces
    scene.materials[0].phong_exponent = 200.0f;
    EyeCamera camera = inside_camera(24);
    auto on = prepared(scene, {{"dense_resolution", 64}});
    auto off = prepared(scene, {{"dense_resolution", 64}, {"specular", false}});
    Film a = render_one(*on, camera), b = render_one(*off, camera);
    EXPECT_GT(mean_value(a, "specular"), 1e-4);
    EXPECT_EQ(mean_value(b, "specular"), 0.0);
    EXPECT_TRUE(on->stats().has("specular_ms"));
    // The diffuse part does not depend on the specular cone.
    EXPECT_LT(max_abs_difference(a, b, "indirect"), 1e-6);
}

TEST(VctTechnique, SkinnedMeshesMovingWithTheirJointsAreNotVoxelized) {
    // A quad bound to a joint node that is animated elsewhere in the hierarchy: its own
    // node has no keys, yet it moves, so it must be left out like any dynamic mesh.
    Scene scene = make_cornell_box();
    Mesh quad;
    quad.name = "skinned";
    quad.positions = {Vec3(0.45f, 0.5f, 0.45f), Vec3(0.55f, 0.5f, 0.45f), Vec3(0.55f, 0.5f, 0.55f), Vec3(0.45f, 0.5f, 0.55f)};
    quad.triangles = {{0, 1, 2}, {0, 2, 3}};
    quad.material_ids = {0, 0};
    VertexInfluences follow_joint;
    follow_joint.weights = Vec4(1, 0, 0, 0);
    quad.influences.assign(4, follow_joint);
    const uint32_t mesh_node = scene.add_mesh_instance(quad);
    SceneNode joint;
    joint.name = "joint";
    joint.animation.translation.times = {0.0f, 1.0f};
    joint.animation.translation.values = {Vec3(0), Vec3(0, 0.1f, 0)};
    scene.nodes.push_back(joint);
    Skin skin;
    skin.joints = {uint32_t(scene.nodes.size() - 1)};
    skin.inverse_bind = {Mat4(1.0f)};
    scene.skins.push_back(skin);
    scene.nodes[mesh_node].skin = 0;
    auto with = prepared(scene, {{"dense_resolution", 64}, {"diffuse", false}});
    EXPECT_EQ(with->stats().get("voxelized_triangles") + 2, with->stats().get("triangles"));
}

}  // namespace
}  // namespace gilab
