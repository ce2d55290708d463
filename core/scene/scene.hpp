#pragma once
// The scene: meshes in local space placed by a node hierarchy (with optional keyframed
// TRS animation), materials, punctual lights, and optionally a camera or HMD rig.
// `evaluate(t)` flattens it into world space for the ray tracer and the techniques.
#include <optional>
#include <string>
#include <vector>
#include "core/scene/animation.hpp"
#include "core/scene/camera.hpp"
#include "core/scene/hmd.hpp"
#include "core/scene/light.hpp"
#include "core/scene/material.hpp"
#include "core/scene/mesh.hpp"

namespace gilab {

struct SceneNode {
    std::string name;
    int parent = -1;                 // index of an earlier node, or -1 for a root
    Transform local;                 // rest pose
    TrsAnimation animation;          // empty = static
    std::vector<uint32_t> meshes;    // indices into Scene::meshes
    int skin = -1;                   // index into Scene::skins: its meshes are posed by their joints
};

struct SceneCamera {
    Vec3 position{0, 0, 1};
    Vec3 target{0};
    Vec3 up{0, 1, 0};
    float vertical_fov_degrees = 45.0f;
};

struct SceneHmd {
    std::string preset = "vive";
    HeadPose pose;
    std::optional<float> ipd;  // overrides the preset's IPD
};

// One mesh instance in world space at a given time.
struct WorldMesh {
    uint32_t source_mesh = 0;
    uint32_t node = 0;
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;       // empty if the source mesh has none
    std::vector<Vec2> uvs, uvs1;     // the source mesh's UV sets (empty if it has none)
    std::vector<UVec3> triangles;
    std::vector<uint32_t> material_ids;

    const std::vector<Vec2>& uv_set(int k) const { return k == 0 ? uvs : uvs1; }
};

struct SceneFrame {
    double time = 0;
    std::vector<WorldMesh> meshes;
    std::vector<PunctualLight> lights;  // in world space
    std::vector<Material> materials;    // the scene's; textures are shared, not copied
    Bounds3 bounds;
    size_t triangle_count() const;
};

// The texture images a scene's materials use: each counted once however many materials
// share it, with every mip level's bytes.
struct TextureUse {
    size_t images = 0;
    uint64_t bytes = 0;
    size_t textured_materials = 0;
};

// More frames than this is a mistyped rate or key time, not an animation to step through.
inline constexpr int kMaxAnimationFrames = 1000000;

struct Scene {
    std::string name;
    std::string source;              // file it was loaded from, or "builtin:NAME"
    std::vector<Material> materials;
    std::vector<Mesh> meshes;
    std::vector<SceneNode> nodes;    // parents come before children
    std::vector<Skin> skins;         // joints are node indices
    std::vector<PunctualLight> lights;  // in the space of their node (world if node = -1)
    std::optional<SceneCamera> camera;
    std::optional<SceneHmd> hmd;
    double frames_per_second = 30.0;
    size_t degenerate_triangles_dropped = 0;  // reported by loaders
    std::vector<std::string> warnings;        // non-fatal loader notes (unsupported features)

    // Adds a root node holding the given mesh and returns the node index.
    uint32_t add_mesh_instance(Mesh mesh, const Transform& transform = {});

    bool is_animated() const;
    double animation_duration() const;     // seconds; 0 for a static scene
    int animation_frame_count() const;     // frames at frames_per_second, ≥ 1 (validate() bounds it)
    size_t triangle_count() const;         // over all instances
    bool has_emitters() const;             // any emissive triangle or punctual light
    TextureUse texture_use() const;

    // World-space geometry and lights at time t (seconds) / at frame k. A skinned node's
    // meshes follow its joints by linear blend skinning; the node's own transform is
    // ignored, as glTF specifies.
    SceneFrame evaluate(double time) const;
    // Only the meshes of the nodes with include_nodes[i] set (lights: all of them; bounds:
    // of those meshes only). An included node's world positions are bit-identical to
    // evaluate(time)'s. Throws Error if include_nodes does not have one entry per node.
    SceneFrame evaluate(double time, const std::vector<bool>& include_nodes) const;
    // Per node: true when its world geometry can change with time — it or an ancestor
    // has a non-empty animation, or it is skinned (its joints may move).
    std::vector<bool> dynamic_nodes() const;
    SceneFrame evaluate_frame(int frame) const { return evaluate(frame / frames_per_second); }
    // Every node at its rest transform, animation ignored. For glTF skins this is
    // normally the bind pose, which their animations need not pass through.
    SceneFrame evaluate_rest() const;
    // World transform of every node at time t / at rest.
    std::vector<Mat4> node_transforms(double time) const;
    std::vector<Mat4> rest_node_transforms() const;

    // Throws Error naming `source` if the scene cannot be rendered: no geometry,
    // dangling mesh/material/parent/skin/joint indices, unusable joint influences,
    // non-finite transforms, geometry that any transform (rest or animated) could carry
    // beyond kMaxCoordinate, or more than kMaxAnimationFrames frames.
    void validate() const;

private:
    void check_world_reach(const std::string& where) const;
};

}  // namespace gilab
