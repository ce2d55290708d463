#pragma once
// Depth maps rendered from a light with Embree over one square tile of light-space
// texels (P2 §3.2). Per texel, in voxel units of depth:
//  * D1: where the light ray first enters geometry (+inf: no hit);
//  * D2: where it leaves that object again, if the object is a closed mesh entered
//    through its outside; D2 = D1 for open meshes (no undefined region) and for the
//    plain depth map.
// The voxel (x, y, z) of the column is lit when its centre z + 0.5 < D1, undefined when
// D1 ≤ z + 0.5 < D2, and in shadow when z + 0.5 ≥ D2. Where another surface lies inside
// the part or touches it at the exit (a contact), D2 is moved kContactBandVoxels in front
// of that surface: the lookups of that surface land there and must read shadow, not the
// lit that the merge rules may fold undefined space into. Two pyramids of aligned
// power-of-two blocks (max D1, min D2) tell for any aligned cell whether it holds a lit
// voxel (max D1 > its first centre) and a shadow voxel (min D2 ≤ its last centre).
#include <cstdint>
#include <vector>
#include "accel/shadow/light_space.hpp"
#include "accel/shadow/shadow_state.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/scene/scene.hpp"

namespace gilab {

// Undefined space ends this many voxels before a surface inside or touching a closed part.
inline constexpr float kContactBandVoxels = 4.0f;

// The closed surfaces of a frame, per connected component of each mesh (CGAL's check on
// the source mesh): a model of many closed parts counts part by part. For each world
// mesh, the closed component of every triangle (−1: open) and whether the triangle's
// own winding faces out of its part (+1) or into it (−1) in world space: CGAL's
// consistent orientation of the part, turned outward by the sign of its world volume
// (which also undoes a mirroring transform).
struct ClosedSurfaces {
    std::vector<std::vector<int32_t>> component;  // [mesh][triangle]; empty: no closed part
    std::vector<std::vector<int8_t>> outward;     // [mesh][triangle]
    size_t closed_components = 0;
    bool empty() const { return closed_components == 0; }
};
ClosedSurfaces closed_surfaces(const Scene& scene, const SceneFrame& frame);

class LightDepthTile {
public:
    // Renders texels [x0, x0+size) × [y0, y0+size) (size a power of two); texels at or
    // beyond the grid's resolution are empty (+inf). `closed` null (or empty) means the
    // plain depth map (D2 = D1).
    void render(const RayTracer& tracer, const LightSpace& space, const ClosedSurfaces* closed, uint32_t x0,
                uint32_t y0, uint32_t size);
    // Fills the tile from given maps (tests): d1, d2 are size × size, row-major by y.
    void assign(uint32_t x0, uint32_t y0, uint32_t size, std::vector<float> d1, std::vector<float> d2);

    uint32_t x0() const { return x0_; }
    uint32_t y0() const { return y0_; }
    uint32_t size() const { return size_; }
    float d1(uint32_t x, uint32_t y) const { return max_d1_[0][local(x, y, 0)]; }  // global texel coords
    float d2(uint32_t x, uint32_t y) const { return min_d2_[0][local(x, y, 0)]; }

    // State of an aligned cell: `size` voxels per axis, minimum voxel `first` (global
    // coordinates; the cell's columns must lie in the tile).
    ShadowState cell_state(const UVec3& first, uint32_t size) const;
    // State of one voxel (Lit, Shadow or Undefined).
    ShadowState voxel_state(uint32_t x, uint32_t y, uint32_t z) const;

    uint64_t rays_cast() const { return rays_; }
    bool any_hit() const { return !min_d2_.empty() && min_d2_.back()[0] < kInfinity; }
    size_t memory_bytes() const;

private:
    void build_pyramids();
    size_t local(uint32_t x, uint32_t y, int level) const {
        const uint32_t side = size_ >> level;
        return size_t((y - y0_) >> level) * side + ((x - x0_) >> level);
    }
    uint32_t x0_ = 0, y0_ = 0, size_ = 0;
    std::vector<std::vector<float>> max_d1_, min_d2_;  // level 0 = the texels themselves
    uint64_t rays_ = 0;
};

}  // namespace gilab
