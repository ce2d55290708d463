// Textured materials as the techniques see them, on the built-in textured Cornell box:
// the checkerboard wall in every technique's image, the leaf panel's alpha mask in
// every kind of ray query, the rippled floor's normal map against its analytic normals,
// and the white furnace with a constant texture against the untextured one, bit for bit.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include "core/render/interaction.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/render/surface_material.hpp"
#include "core/scene/hmd.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/procedural_textures.hpp"
#include "techniques/technique.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

uint32_t material_named(const Scene& scene, const std::string& name) {
    for (size_t i = 0; i < scene.materials.size(); ++i)
        if (scene.materials[i].name == name) return uint32_t(i);
    ADD_FAILURE() << "no material " << name;
    return 0;
}

EyeCamera scene_camera(const Scene& scene, int size) {
    const SceneCamera& c = *scene.camera;
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
}

Film render(const std::string& technique, const Scene& scene, const EyeCamera& camera, nlohmann::json settings) {
    auto t = prepare_technique(technique, scene, Settings(std::move(settings), "test settings"));
    std::vector<Film> films;
    t->render(ViewSet::mono(camera), films);
    return films.at(0);
}

// The primary hit of each pixel centre: which check of the back wall it sees (0 or 1),
// or −1 elsewhere and near the checks' edges (where filtering mixes both).
std::vector<int> check_of_pixels(const Scene& scene, const EyeCamera& camera) {
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    const uint32_t checker = material_named(scene, "checker");
    std::vector<int> out(size_t(camera.width()) * size_t(camera.height()), -1);
    for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
            const Ray ray = camera.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
            const Hit hit = tracer.intersect(ray);
            if (!hit.valid()) continue;
            const SurfaceInteraction si = make_interaction(frame, ray, hit);
            if (si.material != checker) continue;
            const Vec2 c = si.uv[0] * 8.0f;  // 8 × 8 checks
            const Vec2 f = c - glm::floor(c);
            if (glm::any(glm::lessThan(f, Vec2(0.25f))) || glm::any(glm::greaterThan(f, Vec2(0.75f)))) continue;
            out[size_t(y) * size_t(camera.width()) + size_t(x)] = (int(c.x) + int(c.y)) % 2;
        }
    return out;
}

// Mean luminance of the colour layer over the pixels of each kind of check; the counts
// of those pixels go to `counts`.
std::array<double, 2> check_luminance(const Film& film, const std::vector<int>& check, std::array<int, 2>& counts) {
    const Layer& color = film.layer("color");
    std::array<double, 2> sum = {0, 0};
    counts = {0, 0};
    for (size_t i = 0; i < check.size(); ++i)
        if (check[i] >= 0) {
            sum[size_t(check[i])] += luminance(Vec3(color.data[3 * i], color.data[3 * i + 1], color.data[3 * i + 2]));
            ++counts[size_t(check[i])];
        }
    for (int k = 0; k < 2; ++k) sum[size_t(k)] /= std::max(counts[size_t(k)], 1);
    return sum;
}

TEST(TexturedMaterials, CheckerboardSeenHeadOnIsACheckerboard) {
    const Scene scene = make_textured_cornell_box();
    const EyeCamera camera = scene_camera(scene, 128);
    const Film film = render("path", scene, camera, {{"spp", 1}, {"jitter", false}, {"max_depth", 0}});
    const std::vector<int> check = check_of_pixels(scene, camera);
    const Vec3 expected[2] = {Vec3(0.8f), Vec3(0.05f, 0.08f, 0.35f)};
    int counted[2] = {0, 0};
    const Layer& albedo = film.layer("albedo");
    for (size_t i = 0; i < check.size(); ++i) {
        if (check[i] < 0) continue;
        const Vec3 a(albedo.data[3 * i], albedo.data[3 * i + 1], albedo.data[3 * i + 2]);
        // 8-bit sRGB storage: within a code of the linear colour.
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], expected[check[i]][k], 0.01f) << "pixel " << i;
        ++counted[check[i]];
    }
    EXPECT_GT(counted[0], 200);
    EXPECT_GT(counted[1], 200);
}

// Every technique's image shows the checks: the light the wall reflects follows its
// texture (the mean-colour stand-in would make both kinds of check alike).
TEST(TexturedMaterials, EveryTechniqueShowsTheCheckerboard) {
    const Scene scene = make_textured_cornell_box();
    const EyeCamera camera = scene_camera(scene, 64);
    const std::vector<int> check = check_of_pixels(scene, camera);
    const std::vector<std::pair<std::string, nlohmann::json>> runs = {
        {"path", {{"spp", 16}}},
        {"photon", {{"photons", 20000}}},
        {"vct", nlohmann::json::object()},
        {"lpv", nlohmann::json::object()},
    };
    for (const auto& [name, settings] : runs) {
        std::array<int, 2> n;
        const std::array<double, 2> mean = check_luminance(render(name, scene, camera, settings), check, n);
        ASSERT_GT(n[0], 20) << name;
        ASSERT_GT(n[1], 20) << name;
        // Luminance of the albedos: 0.8 against 0.083, lit alike; at least a factor of 4 survives noise.
        EXPECT_GT(mean[0], 4.0 * mean[1]) << name;
    }
}

// Stereo reuse on textured surfaces: the normal-mapped floor and the leaf panel do not
// stop the right eye reusing the left eye's hits (strict matching compares normals), and
// the reused colour still shows the checkerboard (albedo is view-independent).
TEST(TexturedMaterials, StereoReuseKeepsWorkingAndShowsTheTexture) {
    const Scene textured = make_textured_cornell_box();
    Scene plain = textured;
    for (Material& m : plain.materials) {
        m.albedo_texture = m.normal_texture = m.alpha_texture = TextureRef{};
        m.alpha_mode = AlphaMode::Opaque;
    }
    HmdRig rig(find_hmd_preset("vive"), textured.hmd->pose);
    rig.set_resolution(64, 64);
    const ViewSet views = ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
    const nlohmann::json settings = {{"photons", 20000}, {"stereo_reuse", true}, {"stereo_match", "strict"}};
    auto fraction = [&](const Scene& scene, std::vector<Film>& films) {
        auto t = prepare_technique("photon", scene, Settings(settings, "test settings"));
        t->render(views, films);
        return t->stats().get("reuse_fraction");
    };
    std::vector<Film> textured_films, plain_films;
    const double textured_reuse = fraction(textured, textured_films), plain_reuse = fraction(plain, plain_films);
    EXPECT_GT(plain_reuse, 0.3);
    EXPECT_GT(textured_reuse, 0.9 * plain_reuse);
    const std::vector<int> check = check_of_pixels(textured, views.views[1]);
    std::array<int, 2> n;
    const std::array<double, 2> mean = check_luminance(textured_films.at(1), check, n);
    ASSERT_GT(n[0], 10);
    ASSERT_GT(n[1], 10);
    EXPECT_GT(mean[0], 4.0 * mean[1]);
}

// Rays straight up from the floor through the leaf panel: blocked exactly where the mask
// is opaque, by every kind of query.
TEST(TexturedMaterials, LeafPanelShadowFollowsItsMask) {
    const Scene scene = make_textured_cornell_box();
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    const Rgba8Image mask = leaf_mask_image(256);
    const float s = 1.0f / 555.0f, lo = 170.0f * s, hi = 390.0f * s;
    const int n = 96;
    std::vector<Ray> rays;
    std::vector<int> opaque;  // per ray: 1 opaque, 0 open, −1 too close to the mask's edge to say
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const float x = lo + (hi - lo) * (float(i) + 0.5f) / float(n), z = lo + (hi - lo) * (float(j) + 0.5f) / float(n);
            // The panel's UV: u runs from x = hi to lo, v from z = hi to lo.
            const float u = (hi - x) / (hi - lo), v = (hi - z) / (hi - lo);
            int state = -2;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    const int tx = std::clamp(int(u * 256.0f) + dx, 0, 255), ty = std::clamp(int(v * 256.0f) + dy, 0, 255);
                    const int here = mask.texels[(size_t(ty) * 256 + size_t(tx)) * 4 + 3] >= 128;
                    state = state == -2 ? here : (state == here ? state : -1);
                }
            // From just above the tall block's top (330 mm) or the floor, up to under the light.
            Ray r{Vec3(x, 335.0f * s, z), Vec3(0, 1, 0)};
            r.tmax = (500.0f - 335.0f) * s;
            rays.push_back(r);
            opaque.push_back(state);
        }
    std::vector<uint8_t> blocked(rays.size());
    std::vector<Hit> hits(rays.size());
    tracer.occluded(rays, blocked);
    tracer.intersect(rays, hits);
    size_t decided = 0, mismatches = 0, blocked_count = 0;
    for (size_t k = 0; k < rays.size(); ++k) {
        const bool single = tracer.occluded(rays[k]);
        EXPECT_EQ(single, bool(blocked[k])) << k;
        EXPECT_EQ(tracer.intersect(rays[k]).valid(), hits[k].valid()) << k;
        EXPECT_EQ(hits[k].valid(), bool(blocked[k])) << k;
        blocked_count += blocked[k];
        if (opaque[k] < 0) continue;
        ++decided;
        mismatches += bool(blocked[k]) != bool(opaque[k]);
    }
    EXPECT_GT(decided, rays.size() / 2);
    EXPECT_EQ(mismatches, 0u);
    // The lit fraction under the panel is the mask's open fraction.
    EXPECT_NEAR(1.0 - double(blocked_count) / double(rays.size()), open_fraction(mask), 0.02);
}

// The rippled floor's shading normals against the analytic ripples, seen from above so a
// pixel's footprint is below a texel (the finest level; at grazing angles ray cones
// filter wide and flatten the ripples, as they should).
TEST(TexturedMaterials, NormalMappedFloorBendsLikeTheAnalyticRipples) {
    const Scene scene = make_textured_cornell_box();
    const EyeCamera camera = EyeCamera::look_at(Vec3(0.2f, 0.45f, 0.8f), Vec3(0.2f, 0.0f, 0.8f), Vec3(0, 0, 1), 60.0f, 256, 256);
    const Film film = render("path", scene, camera, {{"spp", 1}, {"jitter", false}, {"max_depth", 0}});
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    const uint32_t floor = material_named(scene, "rippled floor");
    RippleNormalMap ripples;
    ripples.ripples = 8;
    const Layer& normal = film.layer("normal");
    int checked = 0, bent = 0;
    float worst = 0;
    for (int y = 2; y < 256; y += 5)
        for (int x = 2; x < 256; x += 5) {
            const Ray ray = camera.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
            const Hit hit = tracer.intersect(ray);
            if (!hit.valid()) continue;
            const SurfaceInteraction si = make_interaction(frame, ray, hit);
            if (si.material != floor) continue;
            const Vec3 n = si.geometric_normal;
            const Vec3 t = glm::normalize(si.dpdu[0] - n * glm::dot(n, si.dpdu[0]));
            Vec3 b = glm::cross(n, t);
            if (glm::dot(b, si.dpdv[0]) > 0) b = -b;
            const Vec3 local = ripples.normal_at(si.uv[0].x);
            const Vec3 expected = glm::normalize(local.x * t + local.y * b + local.z * n);
            const size_t i = size_t(y) * 256 + size_t(x);
            const Vec3 got(normal.data[3 * i], normal.data[3 * i + 1], normal.data[3 * i + 2]);
            const float angle = std::acos(std::clamp(glm::dot(got, expected), -1.0f, 1.0f));
            worst = std::max(worst, angle);
            ++checked;
            bent += std::acos(std::clamp(glm::dot(got, n), -1.0f, 1.0f)) > glm::radians(10.0f);
        }
    EXPECT_GT(checked, 300);
    EXPECT_GT(bent, checked / 4) << "the map must visibly bend the normals";
    EXPECT_LT(glm::degrees(worst), 3.0f);
}

// The furnace with its albedo as factor 0.5 × a white texture takes the untextured path's
// values exactly: the same image, bit for bit.
TEST(TexturedMaterials, FurnaceWithAWhiteTextureIsBitForBitTheUntexturedOne) {
    const Scene plain = make_furnace_sphere(0.5f, 1.0f);
    Scene textured = plain;
    Mesh& mesh = textured.meshes[0];
    mesh.uvs.clear();
    for (const Vec3& p : mesh.positions) mesh.uvs.emplace_back(0.5f + 0.5f * p.x, 0.5f + 0.5f * p.y);
    Rgba8Image white{4, 4, std::vector<uint8_t>(64, 255)};
    textured.materials[0].albedo_texture.image = std::make_shared<const MipMap>(white, ColorEncoding::Srgb, "white");
    const EyeCamera camera = scene_camera(plain, 24);
    const nlohmann::json settings = {{"spp", 8}, {"max_depth", 6}};
    const Film a = render("path", plain, camera, settings), b = render("path", textured, camera, settings);
    const std::vector<float>& ca = a.layer("color").data;
    const std::vector<float>& cb = b.layer("color").data;
    ASSERT_EQ(ca.size(), cb.size());
    EXPECT_EQ(std::memcmp(ca.data(), cb.data(), ca.size() * sizeof(float)), 0);

    // A grey texture (code 188, linear 0.5029) under factor 1: the furnace converges to
    // Le / (1 − ρ) with that ρ.
    Rgba8Image grey{4, 4, {}};
    for (int i = 0; i < 16; ++i) grey.texels.insert(grey.texels.end(), {188, 188, 188, 255});
    const MipMap grey_map(grey, ColorEncoding::Srgb, "grey");
    const float rho = grey_map.texel(0, 0, 0, WrapMode::Repeat, WrapMode::Repeat).x;
    textured.materials[0].albedo = Vec3(1.0f);
    textured.materials[0].albedo_texture.image = std::make_shared<const MipMap>(grey_map);
    const Film c = render("path", textured, camera, {{"spp", 64}, {"max_depth", 200}, {"rr_depth", 200}});
    double mean = 0;
    for (size_t i = 0; i < c.pixel_count(); ++i) mean += c.layer("color").data[3 * i] / double(c.pixel_count());
    EXPECT_NEAR(mean, 1.0 / (1.0 - rho), 0.02 / (1.0 - rho));
}

}  // namespace
}  // namespace gilab
