#include "accel/vct/dense_mip_texture.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include "accel/vct/occupancy_map.hpp"
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

namespace {

double buffer_bytes(int resolution) {
    double cells = 0;
    for (int r = resolution; r >= 1; r >>= 1) cells += double(kFaceCount) * double(r) * r * r;
    return cells * double(sizeof(HalfRGBA));
}

}  // namespace

void DenseMipConfig::validate() const {
    const std::string where = "dense mip texture";
    if (resolution < 1 || resolution > 2048 || !std::has_single_bit(unsigned(resolution)))
        throw Error(where, "resolution must be a power of two in 1..2048, got " + std::to_string(resolution));
    if (!(voxel_size > 0) || !std::isfinite(voxel_size))
        throw Error(where, "voxel size must be positive and finite, got " + std::to_string(voxel_size));
    double need = buffer_bytes(resolution);
    if (need > double(max_bytes)) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "resolution %d needs %.2f GiB of radiance textures, more than the %.2f GiB budget",
                      resolution, need / double(1ull << 30), double(max_bytes) / double(1ull << 30));
        throw Error(where, buf);
    }
}

DenseMipTexture::DenseMipTexture(const DenseMipConfig& config) : config_(config) {
    config_.validate();
    const int levels = std::countr_zero(unsigned(config_.resolution)) + 1;
    radiance.resize(size_t(levels));
    occupancy_.resize(size_t(levels));
    for (int k = 0; k < levels; ++k) {
        radiance[size_t(k)].assign(cells(k), HalfRGBA{});
        occupancy_[size_t(k)].assign(occupancy_map_words(resolution(k)), ~uint64_t(0));
    }
}

FragmentVoxelizeStats DenseMipTexture::voxelize(const FragmentVoxelizer& voxelizer) {
    FragmentVoxelizeStats stats;
    const std::vector<AnisotropicVoxel> full = voxelizer.voxelize(lattice(), region(), &stats);
    voxels.clear();
    voxels.shrink_to_fit();
    voxels.reserve(full.size());
    for (const AnisotropicVoxel& v : full) voxels.push_back({v.coord, pack_voxel(v, lattice())});
    return stats;
}

void DenseMipTexture::clear_level0(std::vector<std::vector<HalfRGBA>>& buffer) {
    auto& level = buffer.at(0);
    parallel_for(level.size(), size_t(1) << 20, [&](size_t b, size_t e) {
        std::memset(static_cast<void*>(level.data() + b), 0, (e - b) * sizeof(HalfRGBA));
    });
}

void DenseMipTexture::build_mips(std::vector<std::vector<HalfRGBA>>& buffer) const {
    for (int k = 1; k < level_count(); ++k) {
        const int r = resolution(k);
        const std::vector<HalfRGBA>& fine = buffer[size_t(k - 1)];
        std::vector<HalfRGBA>& coarse = buffer[size_t(k)];
        parallel_for(size_t(r), 1, [&](size_t z0, size_t z1) {
            for (size_t z = z0; z < z1; ++z)
                for (int y = 0; y < r; ++y)
                    for (int x = 0; x < r; ++x) {
                        const IVec3 v(x, y, int(z));
                        std::array<std::array<Vec4, 8>, kFaceCount> children;
                        for (int c = 0; c < 8; ++c) {
                            const size_t first = index(k - 1, 0, 2 * v + IVec3(c & 1, (c >> 1) & 1, (c >> 2) & 1));
                            for (int f = 0; f < kFaceCount; ++f)
                                children[size_t(f)][size_t(c)] = from_half_rgba(fine[first + size_t(f)]);
                        }
                        const size_t out = index(k, 0, v);
                        for (int f = 0; f < kFaceCount; ++f)
                            coarse[out + size_t(f)] = to_half_rgba(downsample_face(f, children[size_t(f)]));
                    }
        });
    }
}

void DenseMipTexture::refresh_occupancy(const std::vector<std::vector<HalfRGBA>>& buffer) {
    for (int k = 0; k < level_count(); ++k)
        build_occupancy_map(buffer[size_t(k)].data(), resolution(k), false, occupancy_[size_t(k)].data());
}

size_t DenseMipTexture::radiance_bytes() const {
    size_t bytes = 0;
    for (const auto& l : radiance) bytes += l.size() * sizeof(HalfRGBA);
    for (const auto& l : occupancy_) bytes += l.size() * sizeof(uint64_t);
    return bytes;
}

}  // namespace gilab
