#include "accel/vct/dense_mip_texture.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

namespace {

double buffer_bytes(int resolution) {
    double cells = 0;
    for (int r = resolution; r >= 1; r >>= 1) cells += double(kFaceCount) * double(r) * r * r;
    return 2.0 * cells * double(sizeof(Vec4));  // direct + radiance
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
    direct.resize(size_t(levels));
    radiance.resize(size_t(levels));
    for (int k = 0; k < levels; ++k) {
        direct[size_t(k)].assign(cells(k), Vec4(0));
        radiance[size_t(k)].assign(cells(k), Vec4(0));
    }
}

FragmentVoxelizeStats DenseMipTexture::voxelize(const FragmentVoxelizer& voxelizer) {
    FragmentVoxelizeStats stats;
    voxels = voxelizer.voxelize(lattice(), region(), &stats);
    return stats;
}

void DenseMipTexture::clear_level0(std::vector<std::vector<Vec4>>& buffer) {
    auto& level = buffer.at(0);
    parallel_for(level.size(), size_t(1) << 20, [&](size_t b, size_t e) {
        std::memset(static_cast<void*>(level.data() + b), 0, (e - b) * sizeof(Vec4));
    });
}

void DenseMipTexture::build_mips(std::vector<std::vector<Vec4>>& buffer) const {
    for (int k = 1; k < level_count(); ++k) {
        const int r = resolution(k);
        const std::vector<Vec4>& fine = buffer[size_t(k - 1)];
        std::vector<Vec4>& coarse = buffer[size_t(k)];
        parallel_for(size_t(r), 1, [&](size_t z0, size_t z1) {
            for (size_t z = z0; z < z1; ++z)
                for (int y = 0; y < r; ++y)
                    for (int x = 0; x < r; ++x) {
                        const IVec3 v(x, y, int(z));
                        for (int f = 0; f < kFaceCount; ++f) {
                            std::array<Vec4, 8> children;
                            for (int c = 0; c < 8; ++c)
                                children[size_t(c)] = fine[index(k - 1, f, 2 * v + IVec3(c & 1, (c >> 1) & 1, (c >> 2) & 1))];
                            coarse[index(k, f, v)] = downsample_face(f, children);
                        }
                    }
        });
    }
}

size_t DenseMipTexture::radiance_bytes() const {
    size_t bytes = 0;
    for (const auto& l : direct) bytes += l.size() * sizeof(Vec4);
    for (const auto& l : radiance) bytes += l.size() * sizeof(Vec4);
    return bytes;
}

}  // namespace gilab
