// The dag_raycast technique: its depth agrees with Embree's on a static scene, frames of
// an animation differ exactly where the geometry moved, update(t) picks the nearest
// frame, both build modes give the same images, images do not depend on the thread
// count, and bad settings are errors naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/util/parallel.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/fire_scene.hpp"
#include "scenes/procedural_meshes.hpp"
#include "techniques/dag_raycast/dag_raycast_technique.hpp"
#include "techniques/dag_raycast/voxel_face.hpp"
#include "tests/test_support.hpp"

namespace {

using namespace gilab;
using nlohmann::json;

EyeCamera scene_camera(const Scene& scene, int w, int h) {
    const SceneCamera c = scene.camera.value();
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, w, h);
}

std::unique_ptr<Technique> prepared(const Scene& scene, const json& settings) {
    return prepare_technique("dag_raycast", scene, Settings(settings, "test"));
}

Film render(Technique& t, const EyeCamera& camera) {
    std::vector<Film> films;
    t.render(ViewSet::mono(camera), films);
    return films.at(0);
}

// A floor and a 0.4 m box sliding from x = -0.5 to x = +0.5 in one second (linear keys),
// at 10 fps: 11 frames. The camera looks down -Z at both.
Scene sliding_box_scene() {
    Scene scene;
    scene.name = "sliding_box";
    scene.source = "test:sliding_box";
    scene.frames_per_second = 10;
    Material grey;
    grey.albedo = Vec3(0.5f);
    scene.materials = {grey};
    scene.add_mesh_instance(make_box("floor", Vec3(-1.5f, -0.05f, -1.0f), Vec3(1.5f, 0.0f, 1.0f), 0));
    const uint32_t box = scene.add_mesh_instance(make_box("box", Vec3(-0.2f, 0.0f, -0.2f), Vec3(0.2f, 0.4f, 0.2f), 0));
    TrsAnimation& anim = scene.nodes[box].animation;
    anim.translation.times = {0.0f, 1.0f};
    anim.translation.values = {Vec3(-0.5f, 0, 0), Vec3(0.5f, 0, 0)};
    scene.nodes[box].local.translation = Vec3(-0.5f, 0, 0);
    PunctualLight sun;
    sun.name = "sun";
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(Vec3(-0.3f, -1.0f, -0.5f));
    scene.lights = {sun};
    SceneCamera camera;
    camera.position = Vec3(0, 1.2f, 3.0f);
    camera.target = Vec3(0, 0.1f, 0);
    scene.camera = camera;
    return scene;
}

bool ray_meets_box(const Ray& r, const Vec3& lo, const Vec3& hi) {
    float t0 = 0, t1 = kInfinity;
    for (int k = 0; k < 3; ++k) {
        float a = (lo[k] - r.origin[k]) / r.direction[k], b = (hi[k] - r.origin[k]) / r.direction[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    return t0 <= t1;
}

}  // namespace

TEST(VoxelFace, NormalIsTheEnteredFace) {
    VoxelGrid grid;
    grid.origin = Vec3(0);
    grid.extent = 4.0f;
    grid.resolution = 4;
    Ray r;
    r.origin = Vec3(-1.0f, 1.5f, 1.2f);
    r.direction = Vec3(1.0f, 0.1f, 0.0f);
    EXPECT_EQ(voxel_entry_normal(grid, UVec3(1, 1, 1), r), Vec3(-1, 0, 0));
    r.origin = Vec3(1.5f, 9.0f, 1.5f);
    r.direction = Vec3(0.2f, -1.0f, 0.1f);
    EXPECT_EQ(voxel_entry_normal(grid, UVec3(1, 3, 1), r), Vec3(0, 1, 0));
    // Starting inside the voxel: the nearest face.
    r.origin = Vec3(1.5f, 1.5f, 1.9f);
    r.direction = Vec3(1, 0, 0);
    EXPECT_EQ(voxel_entry_normal(grid, UVec3(1, 1, 1), r), Vec3(0, 0, 1));
}

TEST(DagRaycast, DepthAgreesWithPathTracerOnStaticScene) {
    const Scene cornell = make_cornell_box();
    const EyeCamera camera = scene_camera(cornell, 64, 64);
    auto dag = prepared(cornell, {{"resolution", 128}, {"seed", 3}});
    EXPECT_EQ(dag->stats().get("frames"), 1.0);
    const Film voxels = render(*dag, camera);
    auto path = prepare_technique("path", cornell, Settings(json{{"spp", 1}, {"jitter", false}, {"max_depth", 0}}));
    std::vector<Film> truth;
    path->render(ViewSet::mono(camera), truth);

    const double voxel = dag->stats().get("voxel_size");
    ASSERT_GT(voxel, 0);
    const auto& a = voxels.layer("depth").data;
    const auto& b = truth.at(0).layer("depth").data;
    const Film& reference = truth.at(0);
    size_t both = 0, close = 0, near_surface = 0, not_behind = 0, disagree = 0;
    for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
            const size_t i = size_t(y) * camera.width() + size_t(x);
            if ((a[i] > 0) != (b[i] > 0)) ++disagree;
            if (a[i] <= 0 || b[i] <= 0) continue;
            ++both;
            const double along_ray = std::abs(double(a[i]) - double(b[i]));
            close += along_ray <= 2.0 * voxel;
            // A voxel that overlaps the surface lies within its diagonal of the surface's
            // plane, at any angle: the distance off the surface is the firm bound. Along
            // the ray the gap grows as 1/cos at grazing angles (side walls, floor).
            const Vec3 dir = camera.generate_ray(x + 0.5f, y + 0.5f).direction;
            const float cos_theta = std::abs(glm::dot(dir, reference.get("normal", x, y)));
            near_surface += along_ray * cos_theta <= std::sqrt(3.0) * voxel + 1e-4;
            // Conservative voxels hold the surface: the ray enters one at or before it.
            not_behind += a[i] <= b[i] + 1e-4f;
        }
    ASSERT_GT(both, a.size() / 2);
    EXPECT_LT(double(disagree) / a.size(), 0.02);
    EXPECT_GT(double(near_surface) / both, 0.98);
    EXPECT_GT(double(close) / both, 0.5);
    EXPECT_GT(double(not_behind) / both, 0.99);
    EXPECT_EQ(voxels.metadata.at("seed"), "3");
    EXPECT_EQ(voxels.metadata.at("light"), "headlight");  // the Cornell box has only an area light
}

TEST(DagRaycast, FramesDifferWhereTheBoxMoved) {
    const Scene scene = sliding_box_scene();
    ASSERT_EQ(scene.animation_frame_count(), 11);
    auto t = prepared(scene, {{"resolution", 64}});
    const EyeCamera camera = scene_camera(scene, 64, 48);
    EXPECT_EQ(t->stats().get("frames"), 11.0);
    t->update(0.0);
    const Film first = render(*t, camera);
    t->update(1.0);
    const Film last = render(*t, camera);
    const auto& d0 = first.layer("depth").data;
    const auto& d1 = last.layer("depth").data;
    auto depth_at = [&](const std::vector<float>& d, const Vec3& p) {
        const auto px = camera.pixel_of(p);
        EXPECT_TRUE(px.has_value());
        return d[size_t(px->y) * camera.width() + size_t(px->x)];
    };
    const Vec3 front_left(-0.5f, 0.2f, 0.2f), front_right(0.5f, 0.2f, 0.2f);
    EXPECT_LT(depth_at(d0, front_left), depth_at(d1, front_left));   // the box left
    EXPECT_LT(depth_at(d1, front_right), depth_at(d0, front_right)); // and arrived
    // Pixels whose rays miss the box's path (grown by two voxels) are the same in both
    // frames.
    const float margin = 2.0f * float(t->stats().get("voxel_size"));
    const Vec3 path_min = Vec3(-0.7f, 0.0f, -0.2f) - margin, path_max = Vec3(0.7f, 0.4f, 0.2f) + margin;
    size_t changed = 0, changed_off_path = 0;
    for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
            const size_t i = size_t(y) * camera.width() + size_t(x);
            if (d0[i] == d1[i]) continue;
            ++changed;
            changed_off_path += !ray_meets_box(camera.generate_ray(x + 0.5f, y + 0.5f), path_min, path_max);
        }
    EXPECT_GT(changed, 50u);
    EXPECT_EQ(changed_off_path, 0u);
}

TEST(DagRaycast, UpdatePicksTheNearestFrame) {
    auto t = prepared(sliding_box_scene(), {{"resolution", 32}});
    auto* raycast = dynamic_cast<DagRaycastTechnique*>(t.get());
    ASSERT_NE(raycast, nullptr);
    ASSERT_EQ(raycast->frame_count(), 11u);
    for (double time : {0.0, 0.04, 0.06, 0.24, 0.26, 0.51, 0.94, 1.0}) {
        t->update(time);
        EXPECT_EQ(raycast->frame(), size_t(std::lround(time * 10))) << "t = " << time;
        EXPECT_EQ(t->stats().get("frame"), double(raycast->frame()));
        EXPECT_GE(t->stats().get("update_ms"), 0.0);
    }
    t->update(-2.0);
    EXPECT_EQ(raycast->frame(), 0u);
    t->update(40.0);  // past the end the scene holds its last pose
    EXPECT_EQ(raycast->frame(), 10u);
}

TEST(DagRaycast, BothBuildModesGiveTheSameDagAndImage) {
    const Scene scene = sliding_box_scene();
    const EyeCamera camera = scene_camera(scene, 48, 36);
    auto a = prepared(scene, {{"resolution", 64}, {"build", "incremental"}});
    auto b = prepared(scene, {{"resolution", 64}, {"build", "all_at_once"}});
    for (const char* key : {"nodes", "nodes_per_frame", "bytes_32bit", "frames"})
        EXPECT_EQ(a->stats().get(key), b->stats().get(key)) << key;
    a->update(0.5);
    b->update(0.5);
    EXPECT_EQ(render(*a, camera).layer("color").data, render(*b, camera).layer("color").data);
}

TEST(DagRaycast, ImagesDoNotDependOnTheThreadCount) {
    FireOptions fire;
    fire.particles = 300;
    fire.frames = 6;
    const Scene scene = make_fire_scene(fire);
    auto t = prepared(scene, {{"resolution", 64}});
    t->update(4 / 30.0);
    const EyeCamera camera = scene_camera(scene, 64, 48);
    Film one, two;
    {
        ThreadLimit limit(1);
        one = render(*t, camera);
    }
    {
        ThreadLimit limit(2);
        two = render(*t, camera);
    }
    for (const char* layer : {"color", "normal", "depth", "visibility"})
        EXPECT_EQ(one.layer(layer).data, two.layer(layer).data) << layer;
    EXPECT_EQ(one.metadata.at("frame"), "4");
    EXPECT_EQ(one.metadata.at("light"), "above");
    // The view holds lit and shadowed surfaces, and every pixel costs at least one ray.
    size_t lit = 0;
    for (float v : one.layer("visibility").data) lit += v > 0.5f;
    EXPECT_GT(lit, 100u);
    EXPECT_GE(t->stats().get("rays"), double(camera.width() * camera.height()));
    for (float c : one.layer("color").data) ASSERT_TRUE(std::isfinite(c) && c >= 0);
}

TEST(DagRaycast, BadSettingsAreErrors) {
    const Scene scene = sliding_box_scene();
    auto t = TechniqueRegistry::builtin().create("dag_raycast");
    {
        Settings s(json{{"resolution", 16}, {"bogus", 1}}, "dag_raycast settings");
        t->prepare(scene, s);
        EXPECT_NE(test::error_of([&] { s.report_unused(); }).find("'bogus'"), std::string::npos);
    }
    auto error = [&](const json& settings) {
        return test::error_of([&] { t->prepare(scene, Settings(settings)); });
    };
    EXPECT_NE(error({{"build", "sideways"}}).find("'build'"), std::string::npos);
    EXPECT_NE(error({{"resolution", 1}}).find("'resolution'"), std::string::npos);
    EXPECT_NE(error({{"spp", 4}}).find("'spp'"), std::string::npos);
    EXPECT_NE(error({{"light", 3}}).find("index 3"), std::string::npos);
    EXPECT_NE(error({{"fps", -1}}).find("'fps'"), std::string::npos);
    auto fresh = TechniqueRegistry::builtin().create("dag_raycast");
    EXPECT_NE(test::error_of([&] { fresh->update(0.1); }).find("before prepare"), std::string::npos);
}

// The sliding box's sun: the shadow DAG (auto for a directional light) and shadow rays
// through the frame's DAG agree on the floor, where voxel faces and triangles coincide;
// the box's shadow moves with it; `none` lights every surface facing the sun.
TEST(DagRaycast, ShadowDagAndShadowRaysAgreeOnTheFloor) {
    Scene scene = sliding_box_scene();
    scene.lights[0].direction = glm::normalize(Vec3(-1.0f, -1.0f, -0.3f));  // long shadows along -x
    auto by_dag = prepared(scene, {{"resolution", 128}});
    auto by_ray = prepared(scene, {{"resolution", 128}, {"shadows", "dag_ray"}});
    auto unshadowed = prepared(scene, {{"resolution", 128}, {"shadows", "none"}});
    EXPECT_EQ(by_dag->stats().get("shadow_dag_resolution"), 128.0);
    EXPECT_GT(by_dag->stats().get("shadow_dag_bytes"), 0.0);
    // From above, so the shadow behind the box is in view.
    const EyeCamera camera = EyeCamera::look_at(Vec3(0, 3.0f, 0.5f), Vec3(0), Vec3(0, 1, 0), 50.0f, 128, 96);
    std::vector<float> shadow_at_start;
    for (double t : {0.0, 1.0}) {
        by_dag->update(t);
        by_ray->update(t);
        unshadowed->update(t);
        const Film a = render(*by_dag, camera), b = render(*by_ray, camera), c = render(*unshadowed, camera);
        EXPECT_EQ(a.metadata.at("shadows"), "shadow_dag");
        EXPECT_EQ(b.metadata.at("shadows"), "dag_ray");
        const auto& va = a.layer("visibility").data;
        const auto& vb = b.layer("visibility").data;
        const auto& vc = c.layer("visibility").data;
        const auto& normal = a.layer("normal").data;
        size_t floor = 0, agree = 0, shadowed = 0;
        std::vector<float> shadow(va.size(), 0.0f);
        for (size_t i = 0; i < va.size(); ++i) {
            if (normal[3 * i + 1] < 0.99f) continue;  // floor and box top: faces pointing up
            ++floor;
            agree += (va[i] > 0.5f) == (vb[i] > 0.5f);
            shadowed += va[i] < 0.5f;
            shadow[i] = va[i] < 0.5f ? 1.0f : 0.0f;
            EXPECT_EQ(vc[i], 1.0f);
        }
        EXPECT_GT(floor, va.size() / 3);
        EXPECT_GT(shadowed, floor / 100) << "the box should shadow part of the floor at t = " << t;
        EXPECT_GE(agree, floor - floor / 50) << "t = " << t;
        if (t == 0.0)
            shadow_at_start = shadow;
        else
            EXPECT_NE(shadow, shadow_at_start) << "the shadow should move with the box";
    }
}

// A point light: its shadow DAGs are a cube of six spot frusta, and they agree with
// shadow rays through the frame's DAG on the floor, seams included.
TEST(DagRaycast, PointLightShadowsComeFromACubeOfShadowDags) {
    Scene scene = sliding_box_scene();
    scene.lights[0].type = LightType::Point;
    scene.lights[0].position = Vec3(0.3f, 0.9f, 0.2f);
    scene.lights[0].intensity = Vec3(1);
    auto by_dag = prepared(scene, {{"resolution", 128}});
    auto by_ray = prepared(scene, {{"resolution", 128}, {"shadows", "dag_ray"}});

    EXPECT_GE(by_dag->stats().get("shadow_dags"), by_dag->stats().get("frames"));
    const EyeCamera camera = EyeCamera::look_at(Vec3(0, 3.0f, 0.5f), Vec3(0), Vec3(0, 1, 0), 70.0f, 128, 96);
    const Film a = render(*by_dag, camera), b = render(*by_ray, camera);
    EXPECT_EQ(a.metadata.at("shadows"), "shadow_dag");
    const auto& va = a.layer("visibility").data;
    const auto& vb = b.layer("visibility").data;
    const auto& depth = a.layer("depth").data;
    size_t floor = 0, agree = 0, shadowed = 0;
    for (size_t i = 0; i < va.size(); ++i) {
        // Floor pixels only (not the box top, whose rim the voxel shadow rays graze).
        const Ray r = camera.generate_ray(float(i % 128) + 0.5f, float(i / 128) + 0.5f);
        if (!(depth[i] > 0) || std::abs((r.origin + glm::normalize(r.direction) * depth[i]).y) > 0.03f) continue;
        ++floor;
        agree += (va[i] > 0.5f) == (vb[i] > 0.5f);
        shadowed += va[i] < 0.5f;
    }
    EXPECT_GT(floor, va.size() / 5);
    EXPECT_GT(shadowed, floor / 100);
    // They differ on the ring of floor at the box's foot, where the voxelized box reaches
    // up to a voxel beyond its triangles and shadows the floor for the rays only.
    EXPECT_GE(agree, floor - floor / 25);
}

TEST(DagRaycast, ShadowSettingsAreChecked) {
    const Scene scene = sliding_box_scene();
    auto error = [&](const json& settings) {
        auto t = TechniqueRegistry::builtin().create("dag_raycast");
        return test::error_of([&] { t->prepare(scene, Settings(settings)); });
    };
    EXPECT_NE(error({{"resolution", 16}, {"shadows", "sometimes"}}).find("'shadows'"), std::string::npos);
    EXPECT_NE(error({{"resolution", 16}, {"shadow_resolution", 3}}).find("'shadow_resolution'"),
              std::string::npos);
}
