#include "scenes/villa_and_terrain.hpp"

#include <cstdint>
#include <string>
#include <vector>
#include "core/util/error.hpp"
#include "scenes/procedural_meshes.hpp"

namespace gilab {

namespace {

PunctualLight sun(const Vec3& direction, float intensity) {
    PunctualLight light;
    light.name = "sun";
    light.type = LightType::Directional;
    light.direction = glm::normalize(direction);
    light.intensity = Vec3(intensity);
    return light;
}

// Head orientation looking from `position` towards `target` with +Y up (the camera looks
// down its −Z axis, as HeadPose expects).
SceneHmd hmd_looking_at(const Vec3& position, const Vec3& target) {
    const Vec3 f = glm::normalize(target - position);
    const Vec3 r = glm::normalize(glm::cross(f, Vec3(0, 1, 0)));
    const Vec3 u = glm::cross(r, f);
    SceneHmd hmd;
    hmd.preset = "vive";
    hmd.pose.position = position;
    hmd.pose.orientation = glm::normalize(glm::quat_cast(Mat3(r, u, -f)));
    return hmd;
}

// ---- Villa ---------------------------------------------------------------------------

constexpr float kHalf = 18.0f;         // enclosure walls run along x, z = ±kHalf
constexpr float kWallHeight = 6.0f;
constexpr float kWallThickness = 0.4f;
constexpr float kTowerRadius = 2.2f;
constexpr float kTowerHeight = 9.0f;
// Solids standing on something reach a little into it, so no two meshes share a
// coplanar contact face (a source of cracks and z-fighting for rays and rasterizers).
constexpr float kGroundSink = 0.2f;
constexpr float kStackSink = 0.05f;

// One straight stretch of enclosure wall: along X (at z = offset) or along Z (at x = offset).
struct WallSide {
    std::string name;
    bool along_x;
    float offset;
    std::vector<std::pair<float, float>> openings;  // gaps [from, to] along the wall
};

// Box spanning [a, b] along the wall axis, `half_thickness` either side, heights [y0, y1].
Mesh wall_box(const std::string& name, const WallSide& side, float a, float b, float half_thickness, float y0,
              float y1, uint32_t material) {
    if (side.along_x)
        return make_box(name, {a, y0, side.offset - half_thickness}, {b, y1, side.offset + half_thickness}, material);
    return make_box(name, {side.offset - half_thickness, y0, a}, {side.offset + half_thickness, y1, b}, material);
}

void add_wall_side(Scene& scene, const WallSide& side, uint32_t stone) {
    // Walls end inside the corner towers (the towers' inradius exceeds 18 − 16.5 plus
    // half the wall thickness), so the enclosure has no slits at the corners.
    const float end = kHalf - 1.5f;
    std::vector<std::pair<float, float>> segments;
    float from = -end;
    for (const auto& [a, b] : side.openings) {
        segments.emplace_back(from, a);
        from = b;
    }
    segments.emplace_back(from, end);

    // Merlons: 0.8 m teeth every 1.6 m, a little thicker than the wall so their faces
    // are never coplanar with it; none inside the towers.
    constexpr float kMerlon = 0.8f, kPitch = 1.6f;
    const float clear = kHalf - kTowerRadius - 0.2f;
    int index = 0;
    for (const auto& [a, b] : segments) {
        const std::string name = side.name + "_wall_" + std::to_string(index++);
        scene.add_mesh_instance(
            wall_box(name, side, a, b, 0.5f * kWallThickness, -kGroundSink, kWallHeight, stone));
        const float lo = std::max(a, -clear), hi = std::min(b, clear);
        if (hi - lo < kMerlon) continue;
        const int count = int((hi - lo - kMerlon) / kPitch) + 1;
        const float start = lo + 0.5f * ((hi - lo) - ((count - 1) * kPitch + kMerlon));
        for (int k = 0; k < count; ++k) {
            const float m0 = start + float(k) * kPitch;
            scene.add_mesh_instance(wall_box(name + "_merlon_" + std::to_string(k), side, m0, m0 + kMerlon,
                                             0.5f * kWallThickness + 0.05f, kWallHeight - kStackSink,
                                             kWallHeight + kMerlon, stone));
        }
    }
}

// ---- Terrain -------------------------------------------------------------------------

constexpr uint32_t kTerrainSeed = 0x5eed7e22u;
constexpr float kTerrainHalf = 100.0f;   // 200 m × 200 m
constexpr float kTerrainRelief = 25.0f;  // metres

// Integer lattice hash (murmur3's 32-bit finalizer over the mixed coordinates).
uint32_t lattice_hash(int32_t x, int32_t z, uint32_t seed) {
    uint32_t h = seed ^ (uint32_t(x) * 0x8da6b343u) ^ (uint32_t(z) * 0xd8163841u);
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

// 2D Perlin gradient noise, roughly in [−1, 1]. Eight fixed gradient directions (no
// trigonometry) keep it cheap and bit-identical across runs.
float gradient_noise(float x, float z, uint32_t seed) {
    static constexpr float kD = 0.70710678f;
    static constexpr Vec2 kGradients[8] = {{1, 0},   {-1, 0},  {0, 1},   {0, -1},
                                           {kD, kD}, {-kD, kD}, {kD, -kD}, {-kD, -kD}};
    const float fx = std::floor(x), fz = std::floor(z);
    const int32_t ix = int32_t(fx), iz = int32_t(fz);
    const float tx = x - fx, tz = z - fz;
    auto corner = [&](int32_t dx, int32_t dz) {
        const Vec2 g = kGradients[lattice_hash(ix + dx, iz + dz, seed) & 7u];
        return g.x * (tx - float(dx)) + g.y * (tz - float(dz));
    };
    auto fade = [](float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); };  // C2 quintic
    const float u = fade(tx), v = fade(tz);
    const float bottom = glm::mix(corner(0, 0), corner(1, 0), u);
    const float top = glm::mix(corner(0, 1), corner(1, 1), u);
    return 1.41421356f * glm::mix(bottom, top, v);
}

// Ridged fBm: each octave's 1 − |noise| turns the noise's zero crossings into sharp
// crests; weighting an octave by the crest of the one before (Musgrave's ridged
// multifractal) keeps valleys smooth and ridges detailed. Plain fBm adds broad hills.
float terrain_height(float x, float z) {
    float frequency = 1.0f / 90.0f, amplitude = 1.0f, weight = 1.0f;
    float ridged = 0, hills = 0, norm = 0;
    for (int octave = 0; octave < 7; ++octave) {
        const uint32_t seed = kTerrainSeed + 0x9e3779b9u * uint32_t(octave);
        const float n = gradient_noise(x * frequency, z * frequency, seed);
        float crest = 1.0f - std::abs(n);
        crest *= crest * weight;
        weight = std::clamp(crest * 1.5f, 0.0f, 1.0f);
        ridged += amplitude * crest;
        hills += amplitude * gradient_noise(x * frequency * 0.5f, z * frequency * 0.5f, ~seed);
        norm += amplitude;
        frequency *= 2.0f;
        amplitude *= 0.5f;
    }
    return kTerrainRelief * (0.75f * ridged / norm + 0.25f * (0.5f + 0.5f * hills / norm));
}

}  // namespace

Scene make_villa() {
    Scene scene;
    scene.name = "villa";
    scene.source = "builtin:villa";
    scene.materials = {diffuse_material("stone", {0.55f, 0.52f, 0.47f}), diffuse_material("roof", {0.5f, 0.2f, 0.12f}),
                       diffuse_material("ground", {0.3f, 0.34f, 0.24f}), diffuse_material("plaster", {0.75f, 0.72f, 0.64f})};
    const uint32_t stone = 0, roof = 1, ground = 2, plaster = 3;

    // Ground: a thick slab (closed, unlike a quad) whose top face is y = 0.
    scene.add_mesh_instance(make_box("ground", {-26, -1, -26}, {26, 0, 26}, ground));

    // Enclosure: a gate in the south (+Z) wall, doorways in the others except the west.
    const std::vector<WallSide> sides = {{"south", true, kHalf, {{-2.5f, 2.5f}}},
                                         {"north", true, -kHalf, {{5.0f, 7.0f}}},
                                         {"east", false, kHalf, {{-3.0f, -1.0f}}},
                                         {"west", false, -kHalf, {}}};
    for (const WallSide& side : sides) add_wall_side(scene, side, stone);
    // Gatehouse lintel over the gate, reaching into the wall ends and standing proud of them.
    scene.add_mesh_instance(
        make_box("south_gate_lintel", {-2.8f, 4.2f, kHalf - 0.35f}, {2.8f, 6.4f, kHalf + 0.35f}, stone));

    // Corner towers: 12-sided capped prisms with cone roofs that overhang them.
    int corner = 0;
    for (float sx : {-1.0f, 1.0f})
        for (float sz : {-1.0f, 1.0f}) {
            const Vec3 base(sx * kHalf, -kGroundSink, sz * kHalf);
            const std::string name = "tower_" + std::to_string(corner++);
            scene.add_mesh_instance(make_prism(name, base, kTowerRadius, kTowerHeight + kGroundSink, 12, stone));
            scene.add_mesh_instance(make_cone(name + "_roof", {base.x, kTowerHeight - kStackSink, base.z},
                                              kTowerRadius + 0.5f, 4.5f, 12, roof));
        }

    // Keep: a tall square tower with a pyramid roof (a 4-sided cone turned 45°).
    scene.add_mesh_instance(make_box("keep", {-12, -kGroundSink, -12}, {-7, 11, -7}, stone));
    scene.add_mesh_instance(
        make_cone("keep_roof", {-9.5f, 11 - kStackSink, -9.5f}, 2.5f * std::sqrt(2.0f) + 0.4f, 4.0f, 4, roof, 45.0f));

    // House with a gable roof along X, and an annex with its ridge along Z.
    scene.add_mesh_instance(make_box("house", {-5, -kGroundSink, -5}, {7, 5, 3}, plaster));
    scene.add_mesh_instance(
        make_gable_prism("house_roof", {-5.6f, 5 - kStackSink, -5.6f}, {7.6f, 0, 3.6f}, 3.2f, true, roof));
    scene.add_mesh_instance(make_box("annex", {9, -kGroundSink, -14}, {14, 3.5f, -5}, plaster));
    scene.add_mesh_instance(
        make_gable_prism("annex_roof", {8.6f, 3.5f - kStackSink, -14.4f}, {14.4f, 0, -4.6f}, 2.2f, false, roof));

    // A well in the courtyard: a low 12-sided prism.
    scene.add_mesh_instance(make_prism("well", {-6, -kGroundSink, 9}, 1.0f, 1.0f + kGroundSink, 12, stone));

    scene.lights.push_back(sun({-0.5f, -1.0f, -0.3f}, 3.0f));

    SceneCamera camera;
    camera.position = Vec3(16, 30, 50);
    camera.target = Vec3(0, 1, -1);
    camera.vertical_fov_degrees = 45.0f;
    scene.camera = camera;
    // Standing in the courtyard inside the gate, looking past the house towards the keep.
    scene.hmd = hmd_looking_at(Vec3(4, 1.7f, 14), Vec3(-4, 5, -6));
    return scene;
}

Scene make_fbm_terrain(int grid) {
    if (grid < 2) throw Error("builtin:fbm_terrain", "grid must be at least 2 vertices, got " + std::to_string(grid));
    Scene scene;
    scene.name = "fbm_terrain";
    scene.source = "builtin:fbm_terrain";
    scene.materials = {diffuse_material("ground", {0.4f, 0.37f, 0.3f})};
    scene.add_mesh_instance(make_heightfield("terrain", grid, grid, Vec2(-kTerrainHalf), Vec2(kTerrainHalf),
                                             terrain_height, 0));

    // Low sun (about 15° above the horizon) so ridges cast long shadows.
    scene.lights.push_back(sun({-1.0f, -0.3f, -0.45f}, 3.0f));

    SceneCamera camera;
    camera.position = Vec3(-30, 75, 150);
    camera.target = Vec3(0, 8, 0);
    camera.vertical_fov_degrees = 45.0f;
    scene.camera = camera;
    // Standing on the ground, looking across the terrain.
    const Vec3 head(10, terrain_height(10, 50) + 1.7f, 50);
    scene.hmd = hmd_looking_at(head, Vec3(-10, terrain_height(-10, -40) + 5.0f, -40));
    return scene;
}

}  // namespace gilab
