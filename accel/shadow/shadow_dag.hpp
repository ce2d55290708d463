#pragma once
// Shadow DAG over light space (P2 §3): the 3-state shadow octree (ShadowSvo) with
// identical subtrees merged bottom-up into a DAG through the same per-level unique-node
// tables as the SVDAG (DagLevelTable), optionally over double depth maps (§3.2), where
// closed objects' interiors are undefined and the merge rules fold them away.
//
// Storage: an interior node is one 32-bit word holding its 16-bit child mask, then one
// 32-bit word address per Boundary child (4..36 B); a leaf is its 64-bit shadow mask in
// two words (8 B), with no header. Levels are laid out top-down in canonical order
// (lay_out_dag), so the words depend only on the DAG, not on how it was built.
//
// High resolutions are built tile by tile: the light's x–y plane is cut into square
// tiles; for each tile the depth maps are rendered, each cell of the tile's column
// becomes a ShadowSvo that is merged into the shared level tables and dropped, and the
// cells are joined under the root by the same rules. The full SVO is never held.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>
#include "accel/dag/dag_level_table.hpp"
#include "accel/shadow/light_depth_maps.hpp"
#include "accel/shadow/light_space.hpp"
#include "accel/shadow/shadow_svo.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/scene/scene.hpp"
#include "core/util/stats.hpp"

namespace gilab {

struct ShadowDagOptions {
    uint32_t resolution = 1024;  // voxels per axis of the light-space grid
    bool double_depth = false;   // S3: fold closed objects' interiors (§3.2)
    uint32_t tile_texels = 0;    // x–y tile side (power of two); 0: min(octree size, 2048)
    // How undefined space left inside Boundary nodes and mixed leaves is stored, and what
    // a lookup in a wholly undefined node answers (Lit or Shadow; see state_is_lit for
    // why Shadow). Without closed geometry there is none and it changes nothing.
    ShadowState undefined_as = ShadowState::Shadow;
    std::function<void(double)> progress;  // fraction of tiles done, may be empty
    size_t memory_limit_bytes = 0;         // depth tiles and merge tables; 0 = half the RAM
};

struct ShadowDagBuildStats {
    double total_ms = 0;
    double closed_ms = 0;      // deciding which parts are closed (CGAL), double depth only
    double depth_ms = 0;       // depth maps rendered with Embree
    double svo_ms = 0;         // 3-state SVOs of the cells
    double merge_ms = 0;       // bottom-up identical-node merge (hash and look up)
    double layout_ms = 0;      // final word layout
    uint64_t rays = 0;         // depth-map rays (entry and exit)
    uint64_t svo_nodes = 0;    // nodes of all cell SVOs (what the DAG merged)
    uint64_t tiles = 0;
    uint32_t tile_texels = 0;
    size_t table_bytes = 0;    // merge tables at the end of the build
    size_t peak_rss_bytes = 0; // process peak resident memory after the build
};

class ShadowDag {
public:
    // Renders the depth maps of `light` over the frame with `tracer` and builds the DAG.
    // Throws Error for an unsupported light, a bad resolution or tile, or a light that
    // sees no geometry. `scene` supplies the closed-mesh check for double depth maps.
    static ShadowDag build(const Scene& scene, const RayTracer& tracer, const PunctualLight& light,
                           const ShadowDagOptions& options);
    // The look build() takes first: whether any triangle of the tracer's frame may lie in
    // the light's view volume (LightSpace::may_overlap_triangle: conservative, so thin or
    // tiny geometry between depth-map rays is never dropped).
    static bool light_sees_geometry(const RayTracer& tracer, const PunctualLight& light);
    // Builds from depth tiles given by `fill` (tests, or depth maps from elsewhere):
    // fill(x0, y0, size, tile) must fill the tile for that texel square. Of `options`,
    // resolution is ignored (the grid is 2^grid_depth) and the rest apply.
    using TileFill = std::function<void(uint32_t x0, uint32_t y0, uint32_t size, LightDepthTile& tile)>;
    static ShadowDag build(int grid_depth, const TileFill& fill, const ShadowDagOptions& options);

    int depth() const { return depth_; }
    uint32_t octree_size() const { return 1u << depth_; }
    const std::optional<LightSpace>& space() const { return space_; }
    ShadowState root_state() const { return root_state_; }
    ShadowState undefined_as() const { return undefined_as_; }  // what undefined space answers
    std::span<const uint32_t> words() const { return words_; }

    // Stored size: every word of every node and leaf.
    size_t bytes() const { return words_.size() * sizeof(uint32_t); }
    size_t node_count() const;                      // interior nodes plus leaves
    size_t leaf_count() const { return level_counts_.empty() ? 0 : level_counts_.back(); }
    uint64_t pointer_count() const { return pointer_count_; }
    const std::vector<uint64_t>& level_node_counts() const { return level_counts_; }  // levels 0..leaf

    // A lookup's path, kept between lookups: the next one restarts from the deepest node
    // both voxels share, so coherent lookups (neighbouring pixels) skip the top levels.
    // The answer never depends on it. One per thread.
    struct Cursor {
        UVec3 voxel{0};
        int levels = 1;                   // node[0 .. levels-1] hold the path to `voxel`
        std::array<uint32_t, 18> node{};  // word address per level; node[0] is the root
    };

    // State of one voxel (Lit, Shadow, or Undefined where a whole node is undefined), by
    // descending from the root: O(depth).
    ShadowState voxel_state(const UVec3& voxel) const {
        Cursor fresh;
        return voxel_state(voxel, fresh);
    }
    ShadowState voxel_state(const UVec3& voxel, Cursor& cursor) const;
    // The answer for light-space coordinates: lit outside the grid's x–y square and in
    // front of it; past its far end the last layer answers; undefined space answers as
    // undefined_as().
    bool lit_at(const DVec3& light_coords) const {
        Cursor fresh;
        return lit_at(light_coords, fresh);
    }
    bool lit_at(const DVec3& light_coords, Cursor& cursor) const;
    // World surface point with its normal (needs the light space of a scene build);
    // pcf = k > 1 averages k×k neighbouring columns (percentage-closer filtering).
    float visibility(const Vec3& p, const Vec3& normal, int pcf = 1) const {
        Cursor fresh;
        return visibility(p, normal, pcf, fresh);
    }
    float visibility(const Vec3& p, const Vec3& normal, int pcf, Cursor& cursor) const;
    // A frame's hit points at once, in parallel.
    void visibility(std::span<const Vec3> points, std::span<const Vec3> normals, std::span<float> out,
                    int pcf = 1) const;

    // The whole 3-state SVO again, expanded from the DAG (level 0 cell = the grid).
    ShadowSvo expand() const;

    const ShadowDagBuildStats& build_stats() const { return stats_; }
    // nodes, leaves, pointers, bytes, total_ms, depth_ms, svo_ms, merge_ms, rays, ...
    Stats stats() const;

private:
    int depth_ = 0;
    std::optional<LightSpace> space_;
    ShadowState root_state_ = ShadowState::Lit;
    ShadowState undefined_as_ = ShadowState::Shadow;
    std::vector<uint32_t> words_;
    std::vector<uint64_t> level_counts_;
    std::vector<uint64_t> level_begin_;
    uint64_t pointer_count_ = 0;
    ShadowDagBuildStats stats_;
};

// k×k percentage-closer filter over any lit_at(coords) answer, shared by the shadow map
// and the shadow DAGs: columns offset by whole texels around the lookup point.
template <typename LitAt>
float pcf_visibility(const DVec3& c, int k, LitAt&& lit_at) {
    if (k <= 1) return lit_at(c) ? 1.0f : 0.0f;
    const double h = 0.5 * (k - 1);
    int lit = 0;
    for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) lit += lit_at(DVec3(c.x + i - h, c.y + j - h, c.z)) ? 1 : 0;
    return float(lit) / float(k * k);
}

}  // namespace gilab
