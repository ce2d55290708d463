#pragma once
// OctoMap reference structure (Hornung et al.'s Morton-keyed occupancy octree): an
// octomap::OcTree with resolution = voxel size, each voxel centre inserted as occupied,
// inner occupancy updated, optionally pruned (eight occupied children → one node).
// OctoMap keys are 16 bits per axis, so grids above 32768 voxels per axis are refused.
#include <cstdint>
#include <memory>
#include <span>
#include "core/util/math.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxel_grid.hpp"
#include "core/voxel/voxelizer.hpp"

namespace gilab {

class OctomapVoxels {
public:
    OctomapVoxels(const VoxelGrid& grid, std::span<const uint64_t> morton_codes, bool prune = false);
    explicit OctomapVoxels(const VoxelList& voxels, bool prune = false)
        : OctomapVoxels(voxels.grid, voxels.codes, prune) {}
    ~OctomapVoxels();
    OctomapVoxels(OctomapVoxels&&) noexcept;
    OctomapVoxels& operator=(OctomapVoxels&&) noexcept;

    const VoxelGrid& grid() const;
    uint64_t voxel_count() const;     // occupied leaves, a pruned leaf counting for all its voxels
    size_t node_count() const;        // size()
    size_t leaf_node_count() const;   // getNumLeafNodes()
    size_t bytes() const;             // memoryUsage()
    bool contains_voxel(const UVec3& voxel) const;
    bool occupied(const Vec3& world_point) const;  // search() at the point
    double build_ms() const;
    Stats stats() const;              // voxels, nodes, leaf_nodes, bytes, build_ms

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace gilab
