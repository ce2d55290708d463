#include "scenes/fire_scene.hpp"

#include <cmath>
#include <string>
#include <vector>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/util/rng.hpp"
#include "scenes/procedural_meshes.hpp"

namespace gilab {

namespace {

constexpr float kParticleRadius = 0.005f;  // 1 cm tip to tip
constexpr float kSpawnRadius = 0.25f;      // particles start anywhere on this disc...
constexpr float kSpawnHeight = 0.15f;      // ...at the top of the log pile
constexpr float kMinRiseSpeed = 0.6f, kMaxRiseSpeed = 1.2f;  // m/s
constexpr float kLateralSigma = 0.15f;     // random walk: m per √s along x and along z
constexpr float kSwirl = 0.8f;             // rad/s: the column turns slowly about +Y
constexpr float kMinLife = 0.5f, kMaxLife = 1.5f;  // s
constexpr float kEndScale = 0.3f;          // scale at the end of a life (1 at birth)

// A closed regular octahedron centred on the origin, wound outwards.
Mesh make_octahedron(float radius, uint32_t material) {
    Mesh mesh;
    mesh.name = "particle";
    mesh.positions = {{radius, 0, 0}, {-radius, 0, 0}, {0, radius, 0},
                      {0, -radius, 0}, {0, 0, radius}, {0, 0, -radius}};
    const uint32_t px = 0, nx = 1, py = 2, ny = 3, pz = 4, nz = 5;
    mesh.triangles = {{px, py, pz}, {pz, py, nx}, {nx, py, nz}, {nz, py, px},
                      {pz, ny, px}, {nx, ny, pz}, {nz, ny, nx}, {px, ny, nz}};
    mesh.material_ids.assign(mesh.triangles.size(), material);
    return mesh;
}

float uniform(Rng& rng, float lo, float hi) { return lo + (hi - lo) * rng.uniform(); }

// Standard normal deviate (Box–Muller; 1 − u keeps the logarithm finite).
float gaussian(Rng& rng) {
    const float u1 = 1.0f - rng.uniform(), u2 = rng.uniform();
    return std::sqrt(-2.0f * std::log(u1)) * std::cos(2.0f * kPi * u2);
}

struct Particle {
    Vec3 position{0};
    float speed = 0, life = 1, age = 0;

    void spawn(Rng& rng) {
        const float r = kSpawnRadius * std::sqrt(rng.uniform()), a = 2.0f * kPi * rng.uniform();
        position = Vec3(r * std::cos(a), kSpawnHeight, r * std::sin(a));
        speed = uniform(rng, kMinRiseSpeed, kMaxRiseSpeed);
        life = uniform(rng, kMinLife, kMaxLife);
        age = 0;
    }
    float scale() const { return 1.0f - (1.0f - kEndScale) * (age / life); }

    void advance(Rng& rng, float dt) {
        age += dt;
        if (age >= life) {
            spawn(rng);
            return;
        }
        const float step = kLateralSigma * std::sqrt(dt);
        const float dx = step * gaussian(rng), dz = step * gaussian(rng);
        const float c = std::cos(kSwirl * dt), s = std::sin(kSwirl * dt);
        position = Vec3(c * position.x + s * position.z + dx, position.y + speed * dt,
                        -s * position.x + c * position.z + dz);
    }
};

// Key k sits at float(k / fps), exactly where Scene::evaluate_frame(k) samples. The
// float rounding of the last key may fall a hair short of (frames − 1) / fps, which would
// make animation_frame_count() one short; a repeat of the last value just past it fixes
// the count without changing any frame.
std::vector<float> key_times(int frames, double fps) {
    std::vector<float> times;
    for (int k = 0; k < frames; ++k) times.push_back(float(double(k) / fps));
    float end = times.back();
    while (double(end) * fps < double(frames - 1)) end = std::nextafter(end, kInfinity);
    if (end != times.back()) times.push_back(end);
    return times;
}

void add_logs(Scene& scene, uint32_t material) {
    scene.meshes.push_back(make_box("log", Vec3(-0.3f, -0.05f, -0.05f), Vec3(0.3f, 0.05f, 0.05f), material));
    const uint32_t mesh = uint32_t(scene.meshes.size() - 1);
    for (int i = 0; i < 5; ++i) {
        // Five logs in a star, inner ends resting on each other, outer ends on the ground.
        const float yaw = glm::radians(72.0f * float(i) + 15.0f);
        SceneNode node;
        node.name = "log_" + std::to_string(i);
        node.local.rotation = glm::angleAxis(yaw, Vec3(0, 1, 0)) * glm::angleAxis(glm::radians(-12.0f), Vec3(0, 0, 1));
        node.local.translation = Vec3(0.22f * std::cos(yaw), 0.09f, -0.22f * std::sin(yaw));
        node.meshes.push_back(mesh);
        scene.nodes.push_back(std::move(node));
    }
}

void add_particles(Scene& scene, const FireOptions& options, uint32_t material) {
    scene.meshes.push_back(make_octahedron(kParticleRadius, material));
    const uint32_t mesh = uint32_t(scene.meshes.size() - 1);
    const std::vector<float> times = key_times(options.frames, options.fps);
    const float dt = float(1.0 / options.fps);
    // One stream, drawn particle after particle: the scene depends on the seed alone.
    Rng rng(options.seed, 0x6669726573636e65ull);
    for (int p = 0; p < options.particles; ++p) {
        Particle particle;
        particle.spawn(rng);
        // Start mid-life so frame 0 already shows a full column, not a fresh burst.
        particle.age = particle.life * rng.uniform();
        particle.position.y += particle.speed * particle.age;
        SceneNode node;
        node.name = "particle_" + std::to_string(p);
        node.meshes.push_back(mesh);
        TrsAnimation& anim = node.animation;
        anim.step = true;
        anim.translation.times = times;
        anim.scale.times = times;
        for (int k = 0; k < options.frames; ++k) {
            anim.translation.values.push_back(particle.position);
            anim.scale.values.push_back(Vec3(particle.scale()));
            particle.advance(rng, dt);
        }
        if (times.size() > size_t(options.frames)) {
            anim.translation.values.push_back(anim.translation.values.back());
            anim.scale.values.push_back(anim.scale.values.back());
        }
        node.local.translation = anim.translation.values.front();
        node.local.scale = anim.scale.values.front();
        scene.nodes.push_back(std::move(node));
    }
}

}  // namespace

Scene make_fire_scene(const FireOptions& options) {
    if (options.particles < 1)
        throw Error("fire scene", "needs at least one particle, not " + std::to_string(options.particles));
    if (options.frames < 2) throw Error("fire scene", "needs at least 2 frames, not " + std::to_string(options.frames));
    if (!(options.fps > 0) || !std::isfinite(options.fps))
        throw Error("fire scene", "frames per second must be positive and finite, not " + number_as_given(options.fps));

    Scene scene;
    scene.name = "fire";
    scene.source = "builtin:fire";
    scene.frames_per_second = options.fps;
    scene.materials = {diffuse_material("ground", {0.35f, 0.33f, 0.3f}), diffuse_material("wood", {0.3f, 0.18f, 0.09f}),
                       diffuse_material("ember", {0.9f, 0.5f, 0.15f}, {4.0f, 1.6f, 0.3f})};
    const uint32_t ground = 0, wood = 1, ember = 2;

    // A 2 m disc of ground, 2 cm thick so it is a closed solid; its top is y = 0.
    scene.add_mesh_instance(make_prism("ground", Vec3(0, -0.02f, 0), 1.0f, 0.02f, 48, ground));
    add_logs(scene, wood);
    add_particles(scene, options, ember);

    PunctualLight above;
    above.name = "above";
    above.type = LightType::Point;
    above.position = Vec3(0.3f, 2.4f, 0.4f);
    above.intensity = Vec3(14.0f, 11.0f, 8.0f);
    PunctualLight sky;
    sky.name = "sky";
    sky.type = LightType::Directional;
    sky.direction = glm::normalize(Vec3(-0.5f, -1.0f, -0.35f));
    sky.intensity = Vec3(0.8f, 0.9f, 1.1f);
    scene.lights = {above, sky};

    SceneCamera camera;
    camera.position = Vec3(0, 1.0f, 3.0f);
    camera.target = Vec3(0, 0.6f, 0);
    camera.vertical_fov_degrees = 45.0f;
    scene.camera = camera;
    return scene;
}

}  // namespace gilab
