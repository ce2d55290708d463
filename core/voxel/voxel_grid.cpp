#include "core/voxel/voxel_grid.hpp"
#include "core/util/error.hpp"
#include <cmath>

namespace gilab {

uint64_t VoxelRegion::volume() const {
    if (empty()) return 0;
    return uint64_t(end.x - begin.x) * uint64_t(end.y - begin.y) * uint64_t(end.z - begin.z);
}

VoxelRegion VoxelRegion::intersect(const VoxelRegion& other) const {
    return {glm::max(begin, other.begin), glm::min(end, other.end)};
}

VoxelGrid VoxelGrid::enclosing(const Bounds3& bounds, uint32_t resolution, double margin) {
    if (bounds.empty() || !is_finite(bounds.min) || !is_finite(bounds.max))
        throw Error("voxel grid", "cannot enclose an empty or non-finite bounding box");
    Vec3 size = bounds.extent();
    double side = std::max<double>(max_component(size), 1e-6);
    side *= 1.0 + 2.0 * std::max(margin, 0.0);
    VoxelGrid grid;
    grid.extent = static_cast<float>(side);
    grid.origin = bounds.center() - Vec3(static_cast<float>(0.5 * side));
    grid.resolution = resolution;
    grid.validate();
    return grid;
}

void VoxelGrid::validate(const std::string& where) const {
    if (resolution == 0) throw Error(where, "voxel resolution must be at least 1");
    if (resolution > kMaxVoxelResolution)
        throw Error(where, "voxel resolution " + std::to_string(resolution) +
                               " exceeds the maximum of 2^21 = " + std::to_string(kMaxVoxelResolution) +
                               " per axis (64-bit Morton codes)");
    if (!std::isfinite(extent) || !(extent > 0.0f))
        throw Error(where, "voxel grid side length must be positive and finite");
    if (!is_finite(origin)) throw Error(where, "voxel grid origin is not finite");
}

int VoxelGrid::depth() const {
    int d = 0;
    while ((uint64_t(1) << d) < resolution) ++d;
    return d;
}

Bounds3 VoxelGrid::bounds() const {
    Bounds3 b;
    b.min = origin;
    b.max = origin + Vec3(extent);
    return b;
}

Bounds3 VoxelGrid::cell_bounds(const UVec3& first, uint32_t size) const {
    double h = voxel_size();
    DVec3 lo = DVec3(origin) + DVec3(first) * h;
    DVec3 hi = lo + DVec3(double(size) * h);
    Bounds3 b;
    b.min = Vec3(lo);
    b.max = Vec3(hi);
    return b;
}

DVec3 VoxelGrid::to_voxel_space(const Vec3& p) const {
    double scale = double(resolution) / double(extent);
    return (DVec3(p) - DVec3(origin)) * scale;
}

std::optional<UVec3> VoxelGrid::voxel_of(const Vec3& p) const {
    DVec3 v = to_voxel_space(p);
    if (!(v.x >= 0 && v.y >= 0 && v.z >= 0)) return std::nullopt;
    DVec3 f = glm::floor(v);
    if (f.x >= resolution || f.y >= resolution || f.z >= resolution) return std::nullopt;
    return UVec3(uint32_t(f.x), uint32_t(f.y), uint32_t(f.z));
}

}  // namespace gilab
