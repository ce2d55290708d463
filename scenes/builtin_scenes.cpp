#include "scenes/builtin_scenes.hpp"

#include <array>
#include <map>
#include "scenes/fire_scene.hpp"
#include "scenes/procedural_textures.hpp"
#include "scenes/villa_and_terrain.hpp"

namespace gilab {

namespace {

// Cornell's measured coordinates are in millimetres; dividing by this puts the box in
// [0, ~1]³ so the photon-mapping paper's gather radii (0.02 … 0.2) apply directly.
constexpr float kCornellScale = 1.0f / 555.0f;

using Quad = std::array<Vec3, 4>;

// Appends a quad as two triangles whose winding normal points towards `towards`.
void add_quad(Mesh& mesh, const Quad& q, uint32_t material, const Vec3& towards) {
    uint32_t base = uint32_t(mesh.positions.size());
    for (const Vec3& p : q) mesh.positions.push_back(p * kCornellScale);
    Vec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
    Vec3 c = 0.25f * (q[0] + q[1] + q[2] + q[3]);
    bool flip = glm::dot(n, towards - c) < 0;
    UVec3 a{base, base + 1, base + 2}, b{base, base + 2, base + 3};
    if (flip) {
        std::swap(a.y, a.z);
        std::swap(b.y, b.z);
    }
    mesh.triangles.push_back(a);
    mesh.triangles.push_back(b);
    mesh.material_ids.push_back(material);
    mesh.material_ids.push_back(material);
}

// A block given by its four top corners and height: top + four sides, normals outwards.
void add_block(Mesh& mesh, const Quad& top, float height, uint32_t material) {
    Vec3 centre = 0.25f * (top[0] + top[1] + top[2] + top[3]);
    centre.y = 0.5f * height;
    add_quad(mesh, top, material, centre + Vec3(0, 2 * height, 0));
    for (int i = 0; i < 4; ++i) {
        const Vec3& a = top[size_t(i)];
        const Vec3& b = top[size_t((i + 1) % 4)];
        Quad side{Vec3(a.x, 0, a.z), a, b, Vec3(b.x, 0, b.z)};
        Vec3 mid = 0.5f * (a + b);
        mid.y = 0.5f * height;
        add_quad(mesh, side, material, mid + (mid - centre));
    }
}

}  // namespace

Scene make_cornell_box() {
    Scene scene;
    scene.name = "cornell";
    scene.source = "builtin:cornell";
    // Reflectances commonly used for the Cornell box in pbrt/Mitsuba test scenes.
    scene.materials = {diffuse_material("white", {0.725f, 0.71f, 0.68f}), diffuse_material("red", {0.63f, 0.065f, 0.05f}),
                       diffuse_material("green", {0.14f, 0.45f, 0.091f})};
    Material light = diffuse_material("light", {0.78f, 0.78f, 0.78f});
    light.emission = Vec3(17.0f, 12.0f, 4.0f);
    scene.materials.push_back(light);
    const uint32_t white = 0, red = 1, green = 2, emitter = 3;

    Mesh mesh;
    mesh.name = "cornell_box";
    const Vec3 inside(278.0f, 274.4f, 279.6f);
    add_quad(mesh, {Vec3(552.8f, 0, 0), Vec3(0, 0, 0), Vec3(0, 0, 559.2f), Vec3(549.6f, 0, 559.2f)}, white, inside);
    add_quad(mesh, {Vec3(556, 548.8f, 0), Vec3(556, 548.8f, 559.2f), Vec3(0, 548.8f, 559.2f), Vec3(0, 548.8f, 0)},
             white, inside);
    add_quad(mesh, {Vec3(549.6f, 0, 559.2f), Vec3(0, 0, 559.2f), Vec3(0, 548.8f, 559.2f), Vec3(556, 548.8f, 559.2f)},
             white, inside);
    add_quad(mesh, {Vec3(0, 0, 559.2f), Vec3(0, 0, 0), Vec3(0, 548.8f, 0), Vec3(0, 548.8f, 559.2f)}, green, inside);
    add_quad(mesh, {Vec3(552.8f, 0, 0), Vec3(549.6f, 0, 559.2f), Vec3(556, 548.8f, 559.2f), Vec3(556, 548.8f, 0)}, red,
             inside);
    add_block(mesh, {Vec3(130, 165, 65), Vec3(82, 165, 225), Vec3(240, 165, 272), Vec3(290, 165, 114)}, 165, white);
    add_block(mesh, {Vec3(423, 330, 247), Vec3(265, 330, 296), Vec3(314, 330, 456), Vec3(472, 330, 406)}, 330, white);
    // The light hangs a hair below the ceiling so the two never share a plane.
    const float y = 548.8f - 0.5f;
    add_quad(mesh, {Vec3(343, y, 227), Vec3(343, y, 332), Vec3(213, y, 332), Vec3(213, y, 227)}, emitter,
             Vec3(278, 0, 279.5f));
    scene.add_mesh_instance(std::move(mesh));

    SceneCamera camera;
    camera.position = Vec3(278, 273, -800) * kCornellScale;
    camera.target = Vec3(278, 273, 0) * kCornellScale;
    camera.up = Vec3(0, 1, 0);
    camera.vertical_fov_degrees = 39.3077f;
    scene.camera = camera;

    // Head placed where the eyes see the whole opening of the box; HMD looks down +Z.
    SceneHmd hmd;
    hmd.preset = "vive";
    hmd.pose.position = Vec3(278, 273, -180) * kCornellScale;
    hmd.pose.orientation = glm::angleAxis(kPi, Vec3(0, 1, 0));  // camera −Z → world +Z
    scene.hmd = hmd;
    return scene;
}

Scene make_textured_cornell_box() {
    Scene scene = make_cornell_box();
    scene.name = "cornell_textured";
    scene.source = "builtin:cornell_textured";
    auto texture = [](Rgba8Image image, ColorEncoding encoding, const std::string& name) {
        TextureRef t;
        t.image = std::make_shared<const MipMap>(std::move(image), encoding, "builtin:" + name);
        return t;
    };
    Material checker = diffuse_material("checker", Vec3(1.0f));
    checker.albedo_texture = texture(checkerboard_image(8, 16, Vec3(0.8f), Vec3(0.05f, 0.08f, 0.35f)), ColorEncoding::Srgb,
                                     "checkerboard");
    Material floor = scene.materials[0];
    floor.name = "rippled floor";
    RippleNormalMap ripples;
    ripples.ripples = 8;
    floor.normal_texture = texture(ripples.image(256), ColorEncoding::Linear, "ripples");
    Material leaf = diffuse_material("leaf", Vec3(0.25f, 0.45f, 0.12f));
    leaf.alpha_mode = AlphaMode::Mask;
    leaf.alpha_texture = texture(leaf_mask_image(256), ColorEncoding::Linear, "leaf_mask");
    const uint32_t checker_id = uint32_t(scene.materials.size());
    scene.materials.insert(scene.materials.end(), {checker, floor, leaf});

    // make_cornell_box adds quads of 4 vertices and 2 triangles each: floor, ceiling, back wall, ...
    Mesh& box = scene.meshes[0];
    const Vec2 corners[4] = {Vec2(0, 1), Vec2(1, 1), Vec2(1, 0), Vec2(0, 0)};
    box.uvs.resize(box.positions.size());
    for (size_t i = 0; i < box.uvs.size(); ++i) box.uvs[i] = corners[i % 4];
    box.material_ids[0] = box.material_ids[1] = checker_id + 1;  // floor
    box.material_ids[4] = box.material_ids[5] = checker_id;      // back wall

    Mesh panel;
    panel.name = "leaf_panel";
    const float y = 450.0f, lo = 170.0f, hi = 390.0f;
    for (const Vec3& p : {Vec3(hi, y, lo), Vec3(lo, y, lo), Vec3(lo, y, hi), Vec3(hi, y, hi)})
        panel.positions.push_back(p * kCornellScale);
    panel.uvs.assign(corners, corners + 4);
    panel.triangles = {UVec3(0, 1, 2), UVec3(0, 2, 3)};
    panel.material_ids.assign(2, checker_id + 2);
    scene.add_mesh_instance(std::move(panel));
    return scene;
}

Scene make_furnace_sphere(float albedo, float emission, int subdivisions) {
    // Icosphere; winding normals point inwards so the (one-sided) emission faces the
    // centre where the camera sits.
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    std::vector<Vec3> v = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    std::vector<UVec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9},   {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (Vec3& p : v) p = glm::normalize(p);
    for (int s = 0; s < subdivisions; ++s) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoint;
        auto mid = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = midpoint.find(key);
            if (it != midpoint.end()) return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return midpoint[key] = uint32_t(v.size() - 1);
        };
        std::vector<UVec3> next;
        for (const UVec3& tri : f) {
            uint32_t a = mid(tri.x, tri.y), b = mid(tri.y, tri.z), c = mid(tri.z, tri.x);
            next.insert(next.end(), {{tri.x, a, c}, {tri.y, b, a}, {tri.z, c, b}, {a, b, c}});
        }
        f = std::move(next);
    }
    Mesh mesh;
    mesh.name = "furnace_sphere";
    mesh.positions = v;
    for (UVec3 tri : f) mesh.triangles.push_back({tri.x, tri.z, tri.y});  // flip: inward normals
    mesh.material_ids.assign(mesh.triangles.size(), 0);

    Scene scene;
    scene.name = "furnace";
    scene.source = "builtin:furnace";
    Material m;
    m.name = "furnace";
    m.albedo = Vec3(albedo);
    m.emission = Vec3(emission);
    scene.materials.push_back(m);
    scene.add_mesh_instance(std::move(mesh));
    SceneCamera camera;
    camera.position = Vec3(0);
    camera.target = Vec3(0, 0, -1);
    camera.vertical_fov_degrees = 90.0f;
    scene.camera = camera;
    return scene;
}

const std::vector<BuiltinScene>& builtin_scenes() {
    static const std::vector<BuiltinScene> scenes = {
        {"cornell", "Cornell box (original measurements, unit scale) with its ceiling area light", make_cornell_box},
        {"cornell_textured",
         "Cornell box with a checkerboard back wall, a normal-mapped rippled floor and an alpha-masked leaf panel under "
         "the light",
         make_textured_cornell_box},
        {"furnace", "white furnace: inside a closed sphere, albedo 0.5, emission 1 (radiance 2 everywhere)",
         [] { return make_furnace_sphere(0.5f, 1.0f); }},
        {"villa", "walled villa, ~40 m (walls, gate, towers, keep, gable roofs) on a slab; every mesh closed; sun",
         make_villa},
        {"fbm_terrain", "open 256x256 ridged-fBm heightfield, 200 m across, 25 m amplitude; low sun",
         [] { return make_fbm_terrain(); }},
        {"fire", "4000 seeded particles rising from logs; 100 frames at 30 fps", [] { return make_fire_scene(); }},
    };
    return scenes;
}

}  // namespace gilab
