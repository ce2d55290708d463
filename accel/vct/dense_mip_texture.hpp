#pragma once
// Dense anisotropic 3D texture with a full mip chain: the baseline "original VCT"
// (VXGI-style) structure. Level 0 covers the whole grid, resolution N (a power of two),
// with the same six faces per voxel as the cascades; level k has N/2^k voxels per axis
// and is filtered from level k − 1 with the same anisotropic 2×2×2 → 1 filter
// (front-to-back along the face's axis, accel/vct/anisotropic_voxel.hpp). Each level of a
// buffer is one allocation of RGBA16F texels laid out [z][y][x][face], as the cascades'
// levels (accel/vct/cascaded_voxel_texture.hpp), and has the same occupancy map.
//
// The G-buffer stays sparse (the occupied voxels as a list with their coordinates, each
// voxel's three axis records packed as the cascades pack theirs,
// accel/vct/packed_surface.hpp): a dense G-buffer per cell would not fit at the sizes
// the baseline runs at.
#include <cstdint>
#include <vector>
#include "accel/vct/anisotropic_voxel.hpp"
#include "accel/vct/fragment_voxelizer.hpp"
#include "accel/vct/half_rgba.hpp"
#include "accel/vct/packed_surface.hpp"
#include "core/util/math.hpp"

namespace gilab {

struct DenseMipConfig {
    int resolution = 128;      // level-0 voxels per axis, a power of two
    double voxel_size = 1.0;   // of level 0
    DVec3 anchor{0};           // world position of voxel (0,0,0)'s minimum corner
    size_t max_bytes = size_t(4) << 30;  // the radiance buffer with its mips
    void validate() const;     // throws Error naming the bad field (and the memory it would need)
};

class DenseMipTexture {
public:
    DenseMipTexture() = default;
    explicit DenseMipTexture(const DenseMipConfig& config);

    const DenseMipConfig& config() const { return config_; }
    int level_count() const { return int(radiance.size()); }
    int resolution(int level) const { return config_.resolution >> level; }
    double voxel_size(int level) const { return std::ldexp(config_.voxel_size, level); }
    VoxelLattice lattice() const { return {config_.anchor, config_.voxel_size}; }
    VoxelBox region() const { return {IVec3(0), IVec3(config_.resolution)}; }
    size_t index(int level, int face, const IVec3& v) const {
        const size_t r = size_t(resolution(level));
        return ((size_t(v.z) * r + size_t(v.y)) * r + size_t(v.x)) * size_t(kFaceCount) + size_t(face);
    }
    size_t cells(int level) const {
        const size_t r = size_t(resolution(level));
        return size_t(kFaceCount) * r * r * r;
    }

    // Replaces the G-buffer by voxelizing the whole grid.
    FragmentVoxelizeStats voxelize(const FragmentVoxelizer& voxelizer);
    // Zeroes level 0 of a buffer, then the caller writes occupied voxels into it.
    static void clear_level0(std::vector<std::vector<HalfRGBA>>& buffer);
    // Levels 1.. of a buffer from level 0.
    void build_mips(std::vector<std::vector<HalfRGBA>>& buffer) const;
    // Per level and texel t: whether any face of the 2×2×2 texels from t up has opacity
    // in `buffer` (what one trilinear sample reads; 0: the sample is skipped). All 1
    // until the first refresh.
    void refresh_occupancy(const std::vector<std::vector<HalfRGBA>>& buffer);
    const uint64_t* occupancy(int level) const { return occupancy_[size_t(level)].data(); }

    size_t voxel_count() const { return size_t(config_.resolution) * config_.resolution * config_.resolution; }
    size_t radiance_bytes() const;  // the radiance buffer and the occupancy maps
    size_t gbuffer_bytes() const { return voxels.capacity() * sizeof(PackedVoxelAt); }
    size_t bytes() const { return radiance_bytes() + gbuffer_bytes(); }

    std::vector<PackedVoxelAt> voxels;          // sparse G-buffer, (z, y, x) order
    // Per level, premultiplied RGBA16F: the injection writes direct light, gathers the
    // voxel bounce from it, then overwrites it with direct + bounce (as the cascades).
    std::vector<std::vector<HalfRGBA>> radiance;

private:
    DenseMipConfig config_;
    std::vector<std::vector<uint64_t>> occupancy_;  // per level, a bit per texel, see refresh_occupancy
};

}  // namespace gilab
