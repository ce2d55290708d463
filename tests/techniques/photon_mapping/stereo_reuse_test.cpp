// Stereo reuse in the photon technique (P1 §3.3): the reprojection finds the right-eye
// pixel whose ray hits the same point (asymmetric frusta, both presets); on the Cornell
// box's back wall, where left pixel centres project onto right pixel centres, the reused
// right eye equals the independently rendered one within float rounding for Lambertian
// surfaces and, with the glossy lobe re-evaluated, for glossy ones — while copying the
// left colour is measurably wrong there; occluded and back-side hits never claim a pixel
// and the nearest candidate wins a pixel; strict mode and crack filling trade reuse for
// error as intended; stereo renders do not depend on the thread count; foveation leaves
// the fovea untouched, follows the gaze and gathers less in the periphery.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include "core/util/error.hpp"
#include "core/scene/hmd.hpp"
#include "core/image/image_metrics.hpp"
#include "core/render/interaction.hpp"
#include "core/util/parallel.hpp"
#include "core/render/ray_tracer.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"
#include "techniques/photon_mapping/stereo_reuse.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

const nlohmann::json kBase = {{"photons", 20000}, {"radius", 0.05}, {"light_samples", 1}, {"seed", 7}};

nlohmann::json with(nlohmann::json base, const nlohmann::json& extra) {
    for (auto it = extra.begin(); it != extra.end(); ++it) base[it.key()] = it.value();
    return base;
}

// The same settings with P1's photon map: direct light from first-hit photons, no light samples.
nlohmann::json every_hit(nlohmann::json base) {
    base.erase("light_samples");
    base["photon_storage"] = "every_hit";
    return base;
}

std::vector<Film> render_views(const Scene& scene, const ViewSet& views, const nlohmann::json& settings_json,
                               Stats* stats = nullptr) {
    PhotonMappingTechnique t;
    prepare_technique(t, scene, Settings(settings_json, "test settings"));
    std::vector<Film> films;
    t.render(views, films);
    if (stats) *stats = t.stats();
    return films;
}

FrustumTangents mirrored(const FrustumTangents& f) { return {-f.right, -f.left, f.bottom, f.top}; }

// A stereo pair looking straight at the Cornell box's back wall (a plane of constant z)
// with the Vive's asymmetric left frustum and its mirror image for the right eye, and an
// inter-pupillary distance chosen so the wall's disparity is a whole number of pixels:
// every left pixel centre on the wall then projects onto a right pixel centre.
struct WallPair {
    EyeCamera left, right;
    float wall_z = 0;
};

WallPair wall_pair(const Scene& scene, int width, int height) {
    const HmdPreset& vive = find_hmd_preset("vive");
    const HeadPose pose = scene.hmd->pose;
    auto eye = [&](float x_offset, const FrustumTangents& fov) {
        return EyeCamera(pose.position + pose.orientation * Vec3(x_offset, 0, 0), pose.orientation, fov, width, height);
    };
    WallPair pair;
    pair.wall_z = scene.evaluate(0).bounds.max.z;
    const Vec3 wall_point(pose.position.x, pose.position.y, pair.wall_z);
    auto disparity = [&](float ipd) {
        return eye(-0.5f * ipd, vive.left_fov).project(wall_point)->x -
               eye(0.5f * ipd, mirrored(vive.left_fov)).project(wall_point)->x;
    };
    // Disparity is affine in the IPD: solve for the whole number nearest the preset's.
    const float d0 = disparity(0.0f), d1 = disparity(vive.ipd);
    const float target = std::round(d1);
    const float ipd = vive.ipd * (target - d0) / (d1 - d0);
    pair.left = eye(-0.5f * ipd, vive.left_fov);
    pair.right = eye(0.5f * ipd, mirrored(vive.left_fov));
    return pair;
}

// Right pixels whose own centre ray, and those of their 8 neighbours, hit the back wall.
std::vector<bool> back_wall_pixels(const Scene& scene, const EyeCamera& right, float wall_z) {
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer(frame);
    std::vector<bool> wall(size_t(right.width()) * size_t(right.height()));
    for (int y = 0; y < right.height(); ++y)
        for (int x = 0; x < right.width(); ++x) {
            Ray ray = right.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
            Hit hit = tracer.intersect(ray);
            if (!hit.valid()) continue;
            SurfaceInteraction si = make_interaction(frame, ray, hit);
            wall[size_t(y) * size_t(right.width()) + size_t(x)] =
                std::abs(si.position.z - wall_z) < 1e-4f && si.geometric_normal.z < -0.999f;
        }
    // Keep the wall's interior: at its border a left hit on the neighbouring surface may
    // fall into the same right pixel and, being nearer, claim it (sub-pixel mismatch).
    std::vector<bool> interior(wall.size());
    for (int y = 1; y + 1 < right.height(); ++y)
        for (int x = 1; x + 1 < right.width(); ++x) {
            bool all = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) all = all && wall[size_t(y + dy) * size_t(right.width()) + size_t(x + dx)];
            interior[size_t(y) * size_t(right.width()) + size_t(x)] = all;
        }
    return interior;
}

struct WallComparison {
    size_t compared = 0;
    double max_relative = 0;   // max over pixels of |a − b| / (|b| + 1e-3), per channel
    double mean_relative = 0;  // Σ|a − b| / Σ|b|
};

WallComparison compare_on_wall(const Film& reused, const Film& independent, const std::vector<bool>& wall) {
    WallComparison c;
    double diff = 0, total = 0;
    const Layer& mask = reused.layer("reused");
    for (int y = 0; y < reused.height(); ++y)
        for (int x = 0; x < reused.width(); ++x) {
            const size_t i = size_t(y) * size_t(reused.width()) + size_t(x);
            if (!wall[i] || mask.data[i] != 1.0f) continue;
            ++c.compared;
            Vec3 a = reused.get("color", x, y), b = independent.get("color", x, y);
            for (int k = 0; k < 3; ++k) {
                c.max_relative = std::max(c.max_relative, double(std::abs(a[k] - b[k]) / (std::abs(b[k]) + 1e-3f)));
                diff += std::abs(a[k] - b[k]);
                total += std::abs(b[k]);
            }
        }
    c.mean_relative = total > 0 ? diff / total : 0;
    return c;
}

TEST(StereoReuse, ReprojectionFindsThePixelWhoseRayHitsThePoint) {
    Scene scene = make_cornell_box();
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer(frame);
    for (const char* preset : {"vive", "quest2"}) {
        HmdRig rig(find_hmd_preset(preset), scene.hmd->pose);
        rig.set_resolution(96, 104);
        const EyeCamera left = rig.eye(Eye::Left), right = rig.eye(Eye::Right);
        const Reprojector reproject(right);
        int checked = 0;
        for (int y = 0; y < left.height(); y += 3)
            for (int x = 0; x < left.width(); x += 3) {
                Hit hit = tracer.intersect(left.generate_ray(float(x) + 0.5f, float(y) + 0.5f));
                if (!hit.valid()) continue;
                const Vec3 point = left.generate_ray(float(x) + 0.5f, float(y) + 0.5f).at(hit.t);
                std::optional<glm::ivec2> pixel = reproject.pixel(point);
                std::optional<Vec2> exact = right.project(point);
                ASSERT_TRUE(exact.has_value());
                if (!pixel) {
                    EXPECT_FALSE(right.pixel_of(point).has_value()) << preset;
                    continue;
                }
                // The paper's matrix path names the pixel the exact projection falls in
                // (away from pixel borders, where float rounding may pick a neighbour) ...
                const Vec2 frac = *exact - glm::floor(*exact);
                if (std::min({frac.x, frac.y, 1 - frac.x, 1 - frac.y}) > 1e-3f) {
                    EXPECT_EQ(*pixel, right.pixel_of(point).value()) << preset << " left pixel " << x << "," << y;
                }
                // ... and the right eye's ray through that position reaches the point
                // unless something nearer hides it.
                Ray ray = right.generate_ray(exact->x, exact->y);
                Hit seen = tracer.intersect(ray);
                ASSERT_TRUE(seen.valid());
                const float distance = glm::length(point - right.position());
                EXPECT_LE(seen.t, distance * (1 + 1e-4f));
                if (std::abs(seen.t - distance) < 1e-3f * distance) {
                    EXPECT_LT(glm::length(ray.at(seen.t) - point), 1e-4f * distance);
                    ++checked;
                }
            }
        EXPECT_GT(checked, 500) << preset;
    }
}

TEST(StereoReuse, LambertianReusedRightEyeEqualsIndependentRender) {
    Scene scene = make_cornell_box();
    const WallPair pair = wall_pair(scene, 128, 144);
    const ViewSet views = ViewSet::stereo_pair(pair.left, pair.right);
    const std::vector<bool> wall = back_wall_pixels(scene, pair.right, pair.wall_z);
    for (const nlohmann::json& base : {kBase, every_hit(kBase)}) {
        Stats stats;
        std::vector<Film> separate = render_views(scene, views, base);
        std::vector<Film> reused = render_views(scene, views, with(base, {{"stereo_reuse", true}}), &stats);

        // The left eye is the same render either way.
        EXPECT_EQ(std::memcmp(separate[0].layer("color").data.data(), reused[0].layer("color").data.data(),
                              separate[0].layer("color").data.size() * sizeof(float)),
                  0);
        WallComparison c = compare_on_wall(reused[1], separate[1], wall);
        EXPECT_GT(c.compared, 600u) << base.dump();
        EXPECT_LT(c.max_relative, 1e-4) << base.dump()
                                        << ": reused right pixels on the back wall differ from the independent render";
        // Elsewhere the reused point lies anywhere in the right pixel (strict mode's test).
        EXPECT_GT(stats.get("reuse_fraction"), 0.8);
        // Reused pixels keep the direct / indirect split: color = direct + indirect.
        const Film& right = reused[1];
        size_t bad = 0;
        for (size_t k = 0; k < right.layer("color").data.size(); ++k)
            bad += right.layer("color").data[k] != right.layer("direct").data[k] + right.layer("indirect").data[k];
        EXPECT_EQ(bad, 0u) << base.dump();
    }
}

TEST(StereoReuse, GlossyNeedsTheLobeReshadedForTheRightEye) {
    Scene scene = make_cornell_box();
    scene.materials[0].albedo = Vec3(0.3f);
    scene.materials[0].specular = Vec3(0.6f);
    scene.materials[0].phong_exponent = 400.0f;
    const WallPair pair = wall_pair(scene, 128, 144);
    const ViewSet views = ViewSet::stereo_pair(pair.left, pair.right);
    const std::vector<bool> wall = back_wall_pixels(scene, pair.right, pair.wall_z);
    // With every-hit storage the glossy direct light comes from the map too: the right
    // eye re-gathers both parts for its own direction.
    for (const nlohmann::json& base : {kBase, every_hit(kBase)}) {
        std::vector<Film> separate = render_views(scene, views, base);
        std::vector<Film> reshaded = render_views(scene, views, with(base, {{"stereo_reuse", true}}));
        std::vector<Film> copied = render_views(scene, views, with(base, {{"stereo_reuse", true}, {"stereo_reshade", false}}));

        WallComparison good = compare_on_wall(reshaded[1], separate[1], wall);
        WallComparison bad = compare_on_wall(copied[1], separate[1], wall);
        EXPECT_GT(good.compared, 600u) << base.dump();
        EXPECT_LT(good.max_relative, 1e-4) << base.dump();
        EXPECT_GT(bad.mean_relative, 0.05) << base.dump() << ": copying the left eye's glossy colour should be visibly wrong";
    }
}

// Left hits of a small render, as the technique computes them (geometry only).
std::vector<PrimaryHit> left_hits(const SceneFrame& frame, const std::vector<Material>& materials,
                                  const RayTracer& tracer, const EyeCamera& left) {
    std::vector<PrimaryHit> hits(size_t(left.width()) * size_t(left.height()));
    for (int y = 0; y < left.height(); ++y)
        for (int x = 0; x < left.width(); ++x) {
            Ray ray = left.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
            Hit hit = tracer.intersect(ray);
            if (!hit.valid()) continue;
            SurfaceInteraction si = make_interaction(frame, ray, hit);
            hits[size_t(y) * size_t(left.width()) + size_t(x)] = primary_hit_of(si, materials[si.material], 0.0f);
        }
    return hits;
}

TEST(StereoReuse, OccludedPointsNeverClaimAndTheNearestCandidateWins) {
    Scene scene = make_cornell_box();
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer(frame);
    HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
    rig.set_resolution(80, 88);
    rig.set_ipd(0.25f);  // wide eyes: the boxes hide much of what the left eye sees
    const EyeCamera left = rig.eye(Eye::Left), right = rig.eye(Eye::Right);
    const std::vector<PrimaryHit> hits = left_hits(frame, scene.materials, tracer, left);
    const StereoClaims claims(hits, left, right, tracer);
    EXPECT_GT(claims.stats().occluded, 100u);
    EXPECT_GT(claims.stats().claimed_pixels, 3000u);

    // Brute force: every visible candidate of each right pixel.
    const Reprojector reproject(right);
    std::vector<float> nearest(size_t(right.width()) * size_t(right.height()), kInfinity);
    for (const PrimaryHit& h : hits) {
        if (!h.valid) continue;
        auto p = reproject.pixel(h.point.position);
        if (!p) continue;
        const Vec3 x = h.point.position;
        Ray towards_eye;
        towards_eye.origin = right.position();
        towards_eye.direction = glm::normalize(x - right.position());
        Hit first = tracer.intersect(towards_eye);
        const float distance = glm::length(x - right.position());
        if (!first.valid() || first.t < distance * (1 - 1e-3f)) continue;  // hidden from the right eye
        float& n = nearest[size_t(p->y) * size_t(right.width()) + size_t(p->x)];
        n = std::min(n, distance);
    }
    size_t claimed = 0;
    for (size_t i = 0; i < nearest.size(); ++i) {
        const uint32_t source = claims.source(i);
        if (source == StereoClaims::kNone) continue;
        ++claimed;
        const Vec3 x = hits[source].point.position;
        const float distance = glm::length(x - right.position());
        // The claiming point is visible from the right eye ...
        Ray towards_eye;
        towards_eye.origin = right.position();
        towards_eye.direction = glm::normalize(x - right.position());
        Hit first = tracer.intersect(towards_eye);
        ASSERT_TRUE(first.valid());
        EXPECT_GE(first.t, distance * (1 - 1e-3f)) << "right pixel " << i << " reuses a point hidden from the right eye";
        // ... and no visible candidate of that pixel is nearer.
        EXPECT_LE(distance, nearest[i] * (1 + 1e-3f) + 1e-6f) << "right pixel " << i;
    }
    EXPECT_EQ(claimed, claims.stats().claimed_pixels);
}

TEST(StereoReuse, SurfacesSeenFromOppositeSidesAreNotReused) {
    // A thin vertical card straight ahead, edge-on between the eyes: the left eye sees
    // its −x face, the right eye its +x face.
    Scene scene;
    scene.name = "card";
    Material card;
    card.albedo = Vec3(0.5f);
    scene.materials = {card};
    Mesh mesh;
    mesh.name = "card";
    mesh.positions = {Vec3(0, -1, -1), Vec3(0, -1, -4), Vec3(0, 1, -4), Vec3(0, 1, -1)};
    mesh.triangles = {UVec3(0, 1, 2), UVec3(0, 2, 3)};
    mesh.material_ids = {0, 0};
    scene.add_mesh_instance(std::move(mesh));
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer(frame);
    HmdRig rig(find_hmd_preset("vive"), HeadPose{});
    rig.set_resolution(64, 64);
    const EyeCamera left = rig.eye(Eye::Left), right = rig.eye(Eye::Right);
    const std::vector<PrimaryHit> hits = left_hits(frame, scene.materials, tracer, left);
    const StereoClaims claims(hits, left, right, tracer);
    EXPECT_GT(claims.stats().left_hits, 20u);
    EXPECT_EQ(claims.stats().back_side, claims.stats().left_hits);
    EXPECT_EQ(claims.stats().claimed_pixels, 0u);
}

TEST(StereoReuse, StrictModeReusesOnlyMatchingPointsAndErrsLess) {
    Scene scene = make_cornell_box();
    HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
    rig.set_resolution(72, 80);
    const ViewSet views = ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
    Stats nearest_stats, strict_stats;
    std::vector<Film> separate = render_views(scene, views, kBase);
    std::vector<Film> nearest = render_views(scene, views, with(kBase, {{"stereo_reuse", true}}), &nearest_stats);
    std::vector<Film> strict = render_views(
        scene, views, with(kBase, {{"stereo_reuse", true}, {"stereo_match", "strict"}, {"stereo_tolerance", 0.25}}),
        &strict_stats);
    EXPECT_GT(strict_stats.get("reuse_strict_rejected"), 0);
    EXPECT_LT(strict_stats.get("reuse_fraction"), nearest_stats.get("reuse_fraction"));
    EXPECT_GT(strict_stats.get("reuse_fraction"), 0.05);
    const double nearest_error = relative_mse(nearest[1], separate[1], "color");
    const double strict_error = relative_mse(strict[1], separate[1], "color");
    EXPECT_GT(nearest_error, 0.0);
    EXPECT_LT(strict_error, nearest_error);
}

TEST(StereoReuse, CrackFillingReusesMoreWithSmallError) {
    Scene scene = make_cornell_box();
    HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
    rig.set_resolution(216, 240);
    const ViewSet views = ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
    // Many light samples: a filled pixel draws the neighbour's light samples, not those
    // of its own point, so with one sample the comparison would measure noise.
    const nlohmann::json base = with(kBase, {{"light_samples", 16}});
    Stats nearest_stats, fill_stats;
    std::vector<Film> separate = render_views(scene, views, base);
    std::vector<Film> nearest = render_views(scene, views, with(base, {{"stereo_reuse", true}}), &nearest_stats);
    std::vector<Film> filled =
        render_views(scene, views, with(base, {{"stereo_reuse", true}, {"stereo_fill", true}}), &fill_stats);
    EXPECT_EQ(nearest_stats.get("reuse_crack_filled"), 0);
    EXPECT_GT(fill_stats.get("reuse_crack_filled"), 100);
    EXPECT_GT(fill_stats.get("reuse_fraction"), nearest_stats.get("reuse_fraction"));
    // Filled pixels (reused only with filling) differ from the independent render about as
    // much as the nearest-pixel claims do (both reuse a point up to a pixel or so away).
    auto mean_relative_difference = [&](const Film& image, auto&& selected) {
        double diff = 0, total = 0;
        size_t count = 0;
        for (int y = 0; y < image.height(); ++y)
            for (int x = 0; x < image.width(); ++x) {
                if (!selected(size_t(y) * size_t(image.width()) + size_t(x))) continue;
                ++count;
                diff += std::abs(luminance(image.get("color", x, y)) - luminance(separate[1].get("color", x, y)));
                total += luminance(separate[1].get("color", x, y));
            }
        return std::pair{count, diff / total};
    };
    const auto& fill_mask = filled[1].layer("reused").data;
    const auto& nearest_mask = nearest[1].layer("reused").data;
    auto [fill_count, fill_error] =
        mean_relative_difference(filled[1], [&](size_t i) { return fill_mask[i] == 1.0f && nearest_mask[i] != 1.0f; });
    auto [nearest_count, nearest_error] =
        mean_relative_difference(nearest[1], [&](size_t i) { return nearest_mask[i] == 1.0f; });
    EXPECT_EQ(double(fill_count), fill_stats.get("reuse_crack_filled"));
    EXPECT_GT(nearest_count, fill_count);
    EXPECT_LT(fill_error, 2.0 * nearest_error);
}

TEST(StereoReuse, IdenticalAtAnyThreadCount) {
    Scene scene = make_cornell_box();
    HmdRig rig(find_hmd_preset("quest2"), scene.hmd->pose);
    rig.set_resolution(48, 50);
    const ViewSet views = ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
    for (nlohmann::json s : {with(kBase, {{"stereo_reuse", true}}),
                             with(kBase, {{"stereo_reuse", true}, {"stereo_match", "strict"}, {"light_samples", 2}}),
                             with(kBase, {{"stereo_reuse", true}, {"stereo_fill", true}}),
                             with(every_hit(kBase), {{"stereo_reuse", true}, {"stereo_match", "strict"}}),
                             with(kBase, {{"foveated", true}, {"fovea_angle", 15}}),
                             with(kBase, {{"foveated", true}, {"fovea_angle", 15}, {"stereo_reuse", true}})}) {
        std::vector<Film> one, two;
        {
            ThreadLimit limit(1);
            one = render_views(scene, views, s);
        }
        {
            ThreadLimit limit(2);
            two = render_views(scene, views, s);
        }
        for (size_t v = 0; v < 2; ++v) {
            const auto& a = one[v].layer("color").data;
            const auto& b = two[v].layer("color").data;
            ASSERT_EQ(a.size(), b.size());
            EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << s.dump() << " view " << v;
        }
    }
}

TEST(Foveation, FoveaIsUntouchedAndThePeripheryGathersLess) {
    Scene scene = make_cornell_box();
    HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
    rig.set_resolution(192, 208);
    const EyeCamera eye = rig.eye(Eye::Left);
    const nlohmann::json base = with(kBase, {{"radius", 0.1}});
    Stats full_stats, foveated_stats;
    const Film full = render_views(scene, ViewSet::mono(eye), base, &full_stats).at(0);
    FoveationSettings fovea;
    fovea.enabled = true;
    fovea.fovea_degrees = 12;
    const nlohmann::json fov = with(base, {{"foveated", true}, {"fovea_angle", 12}});
    const Film foveated = render_views(scene, ViewSet::mono(eye), fov, &foveated_stats).at(0);
    size_t inside = 0, outside = 0, outside_differs = 0;
    for (int y = 0; y < eye.height(); ++y)
        for (int x = 0; x < eye.width(); ++x) {
            // Direct light is traced per pixel everywhere.
            EXPECT_EQ(foveated.get("direct", x, y), full.get("direct", x, y)) << "pixel " << x << "," << y;
            const Vec3 a = foveated.get("indirect", x, y), b = full.get("indirect", x, y);
            const int block = foveated_block_size(eye, fovea, x, y);
            if (block == 1) {
                ++inside;
                EXPECT_EQ(a, b) << "pixel " << x << "," << y << " inside the fovea";
            } else if (block == 4) {
                ++outside;
                outside_differs += a != b;
            }
        }
    EXPECT_GT(inside, 600u);
    EXPECT_GT(outside, 12000u);
    EXPECT_GT(outside_differs, outside / 2);
    EXPECT_LT(foveated_stats.get("gather_queries"), 0.25 * full_stats.get("gather_queries"));
    EXPECT_LT(relative_mse(foveated, full, "color"), 0.05);

    // A fovea wider than the field of view changes nothing.
    const Film all = render_views(scene, ViewSet::mono(eye), with(base, {{"foveated", true}, {"fovea_angle", 170}})).at(0);
    EXPECT_EQ(std::memcmp(all.layer("color").data.data(), full.layer("color").data.data(),
                          full.layer("color").data.size() * sizeof(float)),
              0);
}

TEST(Foveation, TheFoveaFollowsTheGaze) {
    Scene scene = make_cornell_box();
    HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
    rig.set_resolution(192, 208);
    const EyeCamera eye = rig.eye(Eye::Left);
    FoveationSettings f;
    f.enabled = true;
    f.fovea_degrees = 8;
    f.gaze_yaw_degrees = 30;  // looking right: the fovea moves to the image's right half
    double centre_x = 0;
    size_t count = 0;
    for (int y = 0; y < eye.height(); ++y)
        for (int x = 0; x < eye.width(); ++x)
            if (foveated_block_size(eye, f, x, y) == 1) centre_x += x, ++count;
    ASSERT_GT(count, 100u);
    const std::optional<Vec2> gaze_pixel = eye.project(eye.position() + gaze_direction(eye, f));
    ASSERT_TRUE(gaze_pixel.has_value());
    EXPECT_GT(gaze_pixel->x, 0.6f * float(eye.width()));
    EXPECT_NEAR(centre_x / double(count), gaze_pixel->x, 4.0);
    // The rendered fovea is where the setting puts it: full-rate pixels equal the full render.
    const nlohmann::json base = with(kBase, {{"radius", 0.1}});
    const Film full = render_views(scene, ViewSet::mono(eye), base).at(0);
    const Film gazed =
        render_views(scene, ViewSet::mono(eye), with(base, {{"foveated", true}, {"fovea_angle", 8}, {"gaze_yaw", 30}})).at(0);
    for (int y = 0; y < eye.height(); ++y)
        for (int x = 0; x < eye.width(); ++x)
            if (foveated_block_size(eye, f, x, y) == 1) {
                ASSERT_EQ(gazed.get("color", x, y), full.get("color", x, y));
            }
}

TEST(Foveation, CombinesWithStereoReuse) {
    Scene scene = make_cornell_box();
    HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
    rig.set_resolution(108, 120);
    const ViewSet views = ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
    const nlohmann::json foveated = with(kBase, {{"foveated", true}, {"fovea_angle", 10}});
    Stats plain_stats, foveated_stats;
    std::vector<Film> separate = render_views(scene, views, foveated);
    render_views(scene, views, with(kBase, {{"stereo_reuse", true}}), &plain_stats);
    std::vector<Film> reused = render_views(scene, views, with(foveated, {{"stereo_reuse", true}}), &foveated_stats);
    // The left eye is the foveated render either way; the right eye reuses as many pixels.
    EXPECT_EQ(std::memcmp(separate[0].layer("color").data.data(), reused[0].layer("color").data.data(),
                          separate[0].layer("color").data.size() * sizeof(float)),
              0);
    EXPECT_EQ(foveated_stats.get("reused_pixels"), plain_stats.get("reused_pixels"));
    EXPECT_GT(foveated_stats.get("reuse_fraction"), 0.8);
}

TEST(StereoReuse, BadSettingsAreErrorsNamingTheKey) {
    Scene scene = make_cornell_box();
    auto error = [&](const nlohmann::json& s) {
        return test::error_of([&] {
            PhotonMappingTechnique t;
            Settings settings(s, "test settings");
            t.prepare(scene, settings);
        });
    };
    EXPECT_NE(error(with(kBase, {{"stereo_match", "closest"}})).find("stereo_match"), std::string::npos);
    EXPECT_NE(error(with(kBase, {{"stereo_tolerance", -1}})).find("stereo_tolerance"), std::string::npos);
    EXPECT_NE(error(with(kBase, {{"stereo_fill", true}, {"stereo_match", "strict"}})).find("stereo_fill"),
              std::string::npos);
    EXPECT_NE(error(with(kBase, {{"foveated", true}, {"fovea_angle", 0}})).find("fovea_angle"), std::string::npos);
    EXPECT_NE(error(with(kBase, {{"foveated", true}, {"periphery_photon_stride", 0}})).find("periphery_photon_stride"),
              std::string::npos);
    EXPECT_NE(error(with(kBase, {{"foveated", true}, {"pass", "split"}})).find("foveated"), std::string::npos);
    EXPECT_NE(error(with(kBase, {{"foveated", true}, {"tile_size", 6}})).find("tile_size"), std::string::npos);
    EXPECT_NE(error(with(kBase, {{"foveated", true}, {"gaze_yaw", 120}})).find("gaze_yaw"), std::string::npos);
    // Foveation keeps direct light per pixel by shadow rays: not with direct light from the map.
    EXPECT_NE(error(with(every_hit(kBase), {{"foveated", true}})).find("photon_storage"), std::string::npos);
}

}  // namespace
}  // namespace gilab
