#pragma once
// OpenVDB reference structure: the same voxels as an openvdb::MaskGrid, for memory and
// counts side by side with SVO/ESVO/SVDAG. Voxel (i,j,k) of the grid is OpenVDB index
// coordinate (i,j,k); the grid's transform places its centre at the voxel's centre.
#include <cstdint>
#include <memory>
#include <span>
#include "core/util/math.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxel_grid.hpp"
#include "core/voxel/voxelizer.hpp"

namespace gilab {

class OpenVdbVoxels {
public:
    OpenVdbVoxels(const VoxelGrid& grid, std::span<const uint64_t> morton_codes);
    explicit OpenVdbVoxels(const VoxelList& voxels) : OpenVdbVoxels(voxels.grid, voxels.codes) {}
    ~OpenVdbVoxels();
    OpenVdbVoxels(OpenVdbVoxels&&) noexcept;
    OpenVdbVoxels& operator=(OpenVdbVoxels&&) noexcept;

    const VoxelGrid& grid() const;
    uint64_t voxel_count() const;     // activeVoxelCount()
    size_t bytes() const;             // memUsage()
    size_t leaf_node_count() const;   // 8³ leaf nodes
    size_t internal_node_count() const;  // 16³ and 32³ internal nodes (the root not counted)
    bool contains_voxel(const UVec3& voxel) const;
    bool occupied(const Vec3& world_point) const;  // through OpenVDB's own transform
    double build_ms() const;
    Stats stats() const;              // voxels, bytes, leaf_nodes, build_ms

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace gilab
