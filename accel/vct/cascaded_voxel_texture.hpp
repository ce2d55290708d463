#pragma once
// Cascaded voxel texture (P3 §1.1): n nested, viewer-centred cascades of R³ voxels,
// level k having voxels of size voxel_size·2^k. Every voxel keeps six faces (see
// accel/vct/anisotropic_voxel.hpp). Each attribute is one allocation: level after level,
// a level an R³ block in (z, y, x) order, and a voxel's six faces side by side, so the
// cell of (face, level, texel) is ((level·R + z)·R + y)·R + x)·6 + face. P3's Fig. 2
// puts the six faces and the levels side by side in one GPU texture (x = faces, y =
// levels) so the texture unit can filter them; a CPU sampler addresses each level
// directly and reads the three faces a cone sees from one place (one cache line per
// texel at RGBA16F), which `vct_bench` measured faster than face blocks.
//
// Voxels are addressed by world voxel coordinates on the level's lattice (voxel v of
// level k spans anchor + [v, v+1)·voxel_size·2^k). A level covers the box
// [origin, origin + R) and stores voxel v at texel v mod R (toroidal), so moving the
// level by a few voxels (scroll) keeps every voxel that stays inside where it is; only
// the newly exposed slabs need new data. Level origins are snapped to even voxel
// coordinates: the region of level k then covers whole voxels of level k + 1, whose
// inner part can be filtered from it 2×2×2 → 1.
#include <cstdint>
#include <vector>
#include "accel/vct/anisotropic_voxel.hpp"
#include "accel/vct/fragment_voxelizer.hpp"
#include "accel/vct/half_rgba.hpp"
#include "accel/vct/packed_surface.hpp"
#include "accel/vct/sparse_gbuffer.hpp"
#include "core/util/math.hpp"

namespace gilab {

struct CascadeConfig {
    int levels = 6;
    int resolution = 32;       // voxels per axis of every level: a power of two, 4..1024
    double voxel_size = 1.0;   // level 0 (the finest)
    DVec3 anchor{0};           // lattice origin shared by every level
    // Throws Error naming the bad field.
    void validate() const;
};

class CascadedVoxelTexture {
public:
    CascadedVoxelTexture() = default;
    explicit CascadedVoxelTexture(const CascadeConfig& config);  // allocates every attribute

    const CascadeConfig& config() const { return config_; }
    int levels() const { return config_.levels; }
    int resolution() const { return config_.resolution; }
    double voxel_size(int level) const { return std::ldexp(config_.voxel_size, level); }
    VoxelLattice lattice(int level) const { return {config_.anchor, voxel_size(level)}; }

    // ---- placement
    IVec3 origin(int level) const { return origins_[size_t(level)]; }
    VoxelBox region(int level) const;
    // The origin that centres `level` on `viewer`: the centre is the even lattice
    // coordinate nearest to the viewer, the region [centre − R/2, centre + R/2).
    IVec3 origin_for(const DVec3& viewer, int level) const;
    // Moves a level without keeping anything: its whole G-buffer and radiance are cleared.
    void place(int level, const IVec3& origin);
    // Moves a level keeping what stays inside; returns the newly exposed boxes (disjoint;
    // the whole region when nothing overlaps). Their G-buffer is cleared and their
    // radiance filled from the next coarser level's voxel holding them (mipmap
    // approximation until the level is lit again), zero if that level does not hold it.
    std::vector<VoxelBox> scroll(int level, const IVec3& new_origin);
    // Part of `level` covered by level − 1, in level units (empty for level 0).
    VoxelBox inner_box(int level) const;

    // ---- addressing
    IVec3 world_to_voxel(const DVec3& p, int level) const;
    DVec3 voxel_center(const IVec3& v, int level) const;
    // Continuous coordinates in level voxel units (voxel v spans [v, v+1)).
    DVec3 to_level_space(const DVec3& p, int level) const { return (p - config_.anchor) / voxel_size(level); }
    bool contains(int level, const IVec3& v) const { return region(level).contains(v); }
    // The finest level whose region holds p at least `margin` voxels (of that level)
    // away from its border; -1 if none does.
    int finest_level_containing(const DVec3& p, double margin = 0) const;
    UVec3 texel_of(const IVec3& v) const {
        const int mask = config_.resolution - 1;
        return UVec3(uint32_t(v.x & mask), uint32_t(v.y & mask), uint32_t(v.z & mask));
    }
    // The voxel of the current region stored at a texel (inverse of texel_of).
    IVec3 voxel_at_texel(int level, const UVec3& texel) const;
    // Cell index of (face, level, texel) in every attribute array.
    size_t index(int face, int level, const UVec3& texel) const {
        const size_t R = size_t(config_.resolution);
        return (((size_t(level) * R + texel.z) * R + texel.y) * R + texel.x) * size_t(kFaceCount) + size_t(face);
    }
    size_t index_of_voxel(int face, int level, const IVec3& v) const { return index(face, level, texel_of(v)); }
    size_t level_cells() const { return texels_per_level() * size_t(kFaceCount); }
    size_t texels_per_level() const {
        const size_t R = size_t(config_.resolution);
        return R * R * R;
    }
    size_t cell_count() const { return size_t(config_.levels) * level_cells(); }

    // ---- G-buffer: sparse, as only surface voxels carry one: per level a SparseGBuffer
    // (accel/vct/sparse_gbuffer.hpp) of one 12-byte record per occupied axis of a voxel
    // (accel/vct/packed_surface.hpp).
    void clear_gbuffer(int level, const VoxelBox& box);         // box ∩ region
    void clear_radiance(int level, const VoxelBox& box);
    // One voxel, committed at once (the voxelize calls stage a whole pass, then commit).
    void write(int level, const AnisotropicVoxel& voxel);       // must lie in the region
    // The G-buffer record of an axis of world voxel v of the level, or nullptr (empty or outside).
    const PackedSurface* gbuffer_axis(int level, const IVec3& v, int axis) const;
    // All three axes (empty where nothing is stored).
    PackedVoxel gbuffer_voxel(int level, const IVec3& v) const;
    // The opacity of cell `cell` (index()), 0 when its voxel is empty.
    float opacity_of_cell(size_t cell) const;
    // Voxelizes box ∩ region of the level into the G-buffer (clearing it first).
    FragmentVoxelizeStats voxelize(int level, const FragmentVoxelizer& voxelizer, const VoxelBox& box);
    FragmentVoxelizeStats voxelize(int level, const FragmentVoxelizer& voxelizer) {
        return voxelize(level, voxelizer, region(level));
    }
    // The cascades proper: a level voxelizes only its own part, box ∩ region minus the
    // inner box the finer level covers (whose radiance is filtered from that level);
    // the inner box's G-buffer is left clear. The inner box used is remembered.
    FragmentVoxelizeStats voxelize_own(int level, const FragmentVoxelizer& voxelizer, const VoxelBox& box);
    FragmentVoxelizeStats voxelize_own(int level, const FragmentVoxelizer& voxelizer) {
        return voxelize_own(level, voxelizer, region(level));
    }
    // After the finer level moved: voxelizes what left the inner box and clears what
    // entered it, so the level again holds exactly its own part. `exposed` (boxes a
    // scroll just uncovered) are voxelized in the same pass, minus the inner box.
    FragmentVoxelizeStats follow_inner(int level, const FragmentVoxelizer& voxelizer,
                                       const std::vector<VoxelBox>& exposed = {});
    bool occupied(int level, const IVec3& v) const;   // any face with opacity > 0
    size_t occupied_voxels(int level) const;
    // World voxel coordinates of the occupied voxels of a level inside `box`, (z, y, x) order.
    std::vector<IVec3> occupied_in(int level, const VoxelBox& box) const;

    // ---- anisotropic filtering: the inner box of `level` from level − 1 (2×2×2 → 1 per
    // face, front-to-back along the face's axis) in a radiance buffer laid out as `radiance`.
    void downsample(int level, std::vector<HalfRGBA>& buffer) const;

    // ---- occupancy for cone marching: per level and texel t, whether any face of the
    // 2×2×2 texels from t up (toroidally) has opacity in `buffer` — the texels one
    // trilinear sample reads, one bit per texel (occupancy_map.hpp). A sample whose bit is
    // 0 reads nothing and is skipped. Starts all 1 (nothing skipped) and is exact after a
    // refresh.
    void refresh_occupancy(int level, const std::vector<HalfRGBA>& buffer);
    const uint64_t* occupancy(int level) const { return occupancy_.data() + size_t(level) * occupancy_words(); }

    // ---- memory
    size_t voxel_count() const { return size_t(config_.levels) * texels_per_level(); }
    size_t gbuffer_bytes() const;   // the sparse G-buffers (their capacity)
    size_t radiance_bytes() const;  // the radiance buffer and the occupancy map
    // What encodes occupancy alone: the G-buffers' bits, rank counts and opacity bytes.
    size_t occupancy_encoding_bytes() const;
    size_t bytes() const { return gbuffer_bytes() + radiance_bytes(); }
    // What the paper's Tables 5/6 count: opacity only, one byte per voxel per face.
    size_t opacity_bytes_paper() const { return voxel_count() * size_t(kFaceCount); }

    // Radiance (V-buffer), one allocation: premultiplied RGBA16F with alpha the opacity.
    // The injection writes a level's direct light here, gathers the voxel bounce from
    // it, then overwrites it with direct + bounce, which the pixels' cones read
    // (vct_technique.cpp). The G-buffer keeps what the injection reads; emitters are lit
    // by shadow rays, not injected, so the voxelizer's emission is not kept.
    std::vector<HalfRGBA> radiance;

private:
    template <class Fn>
    void for_each_run(int level, const VoxelBox& box, Fn&& fn) const;
    size_t texel_index(const IVec3& v) const {  // within a level
        const UVec3 t = texel_of(v);
        const size_t R = size_t(config_.resolution);
        return (size_t(t.z) * R + t.y) * R + t.x;
    }
    size_t occupancy_words() const { return (texels_per_level() + 63) / 64; }
    // Voxelizes `boxes` minus `exclude` into the level.
    FragmentVoxelizeStats voxelize_boxes(int level, const FragmentVoxelizer& voxelizer,
                                         const std::vector<VoxelBox>& boxes, const VoxelBox& exclude);
    CascadeConfig config_;
    std::vector<IVec3> origins_;
    std::vector<VoxelBox> own_inner_;  // inner box excluded by the last voxelize_own / follow_inner
    std::vector<uint64_t> occupancy_;  // see refresh_occupancy
    std::vector<SparseGBuffer> gbuffer_;  // per level
};

// a − b as disjoint boxes (at most six).
std::vector<VoxelBox> subtract(const VoxelBox& a, const VoxelBox& b);

// floor(a / b) for b > 0, also for negative a.
inline int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace gilab
