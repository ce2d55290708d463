#pragma once
// Conservative surface voxelization: a voxel is occupied when its closed box overlaps a
// triangle (Akenine-Möller's separating-axis triangle/box test). The output is the
// Morton-sorted list of unique occupied voxel coordinates, identical at any thread
// count. Work streams over aligned bricks of at most 64³ voxels, so memory is the
// output list plus a few brick bitmaps — never resolution³. A sub-region of the grid
// can be voxelized alone (cascades, and split builds that go one octree subtree at a time).
//
// Alpha masks (from a scene frame's materials): a masked triangle occupies a voxel only
// where its mask leaves it there. Its part inside the voxel (clipped, core/voxel/
// box_clip.hpp) is looked up at its centroid at the mip level of its size: occupied when
// the mask's mean alpha there is above 0 (some opaque texel reaches the voxel), or, at
// the finest level, when alpha ≥ the cutoff. A part of zero area (a touch) holds nothing.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>
#include "core/scene/material.hpp"
#include "core/util/math.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

struct SceneFrame;
struct WorldMesh;

// The alpha mask of one input triangle.
struct TriangleMask {
    uint32_t triangle = 0;  // index into the voxelizer's triangles
    Vec2 uv[3]{};           // the mask's UV set at the triangle's corners
    TextureRef texture;     // null: the alpha factor alone decides
    float alpha = 1, cutoff = 0.5f;
};

// Appends the masks of `mesh`'s alpha-tested triangles, numbered from first_triangle in
// the mesh's triangle order.
void append_triangle_masks(const WorldMesh& mesh, const std::vector<Material>& materials, uint32_t first_triangle,
                           std::vector<TriangleMask>& out);

struct VoxelizeOptions {
    // Output budget: a call whose estimated voxel count × 8 bytes exceeds it throws
    // Error before allocating anything.
    size_t max_bytes = size_t(4) << 30;
};

struct VoxelizeStats {
    double ms = 0;                   // wall time of the call
    uint64_t estimated_voxels = 0;   // the estimate checked against the budget
    uint64_t triangles = 0;          // triangles whose bounding box meets the region
    uint64_t bricks = 0;             // bricks with at least one triangle
    uint64_t box_tests = 0;          // triangle/voxel tests run
};

// Triangles binned into the aligned cells of 2^cell_log2 voxels per axis that they may
// overlap (the cells touched_cells finds for them): cells ascending, and cell i's triangles
// ascending in triangles[begin[i] .. begin[i + 1]).
struct CellTriangles {
    std::vector<uint64_t> cells;     // Morton codes of the cell coordinates
    std::vector<size_t> begin;       // cells.size() + 1 offsets
    std::vector<uint32_t> triangles;

    std::span<const uint32_t> of(size_t i) const {
        return std::span<const uint32_t>(triangles).subspan(begin[i], begin[i + 1] - begin[i]);
    }
};

struct VoxelList {
    VoxelGrid grid;
    std::vector<uint64_t> codes;     // Morton codes (core/util/morton.hpp), ascending, unique
    VoxelizeStats stats;

    size_t size() const { return codes.size(); }
    bool empty() const { return codes.empty(); }
    UVec3 voxel(size_t i) const;
};

// The same voxels as 4³ blocks, the voxelizer's own form: the Morton code of each block
// that holds a voxel (voxel code >> 6), ascending, and a mask of its voxels (bit i: the
// voxel whose code ends in the six bits i). A surface fills several voxels of a block, so
// this is several times smaller than the codes, and a mask's bytes are already the 2³
// child masks a voxel octree's lowest nodes need.
struct VoxelBlocks {
    VoxelGrid grid;
    std::vector<uint64_t> blocks;
    std::vector<uint64_t> masks;  // never 0
    VoxelizeStats stats;

    bool empty() const { return blocks.empty(); }
    uint64_t voxel_count() const;
    std::vector<uint64_t> codes() const;  // the voxels' Morton codes, ascending
};

// Ascending voxel codes → blocks (the inverse of VoxelBlocks::codes).
void blocks_from_codes(std::span<const uint64_t> codes, std::vector<uint64_t>& blocks, std::vector<uint64_t>& masks);

class Voxelizer {
public:
    // Triangles index `positions`. Throws Error for a bad grid (resolution 0 or above
    // 2^21), no triangles, out-of-range indices or non-finite positions.
    // `masks`: alpha masks of some of the triangles, in any order.
    Voxelizer(std::span<const Vec3> positions, std::span<const UVec3> triangles,
              const VoxelGrid& grid, VoxelizeOptions options = {}, std::span<const TriangleMask> masks = {});
    // Every mesh of a world-space scene frame, alpha masks applied.
    Voxelizer(const SceneFrame& frame, const VoxelGrid& grid, VoxelizeOptions options = {});
    ~Voxelizer();
    Voxelizer(Voxelizer&&) noexcept;
    Voxelizer& operator=(Voxelizer&&) noexcept;

    const VoxelGrid& grid() const;
    const VoxelizeOptions& options() const;
    size_t triangle_count() const;

    // All voxels of the grid / only those inside `region` (clamped to the grid).
    // Throws Error when the estimate exceeds options().max_bytes.
    VoxelList voxelize() const;
    VoxelList voxelize(const VoxelRegion& region) const;
    // The voxels of only `triangles` (indices) inside `region`: the same as voxelize(region)
    // when they include every triangle that meets the region (a bin of bin_triangles over
    // the region's cell does), in time proportional to their count, not the scene's.
    VoxelList voxelize(const VoxelRegion& region, std::span<const uint32_t> triangles) const;
    // The same voxels as blocks, without expanding them into codes.
    VoxelBlocks voxelize_blocks(const VoxelRegion& region, std::span<const uint32_t> triangles) const;

    // Estimate of the occupied voxels inside a region: projected triangle areas plus
    // edge lengths, in voxels, capped by the region volume. On smooth meshes it is
    // about twice the true count (shared edges and voxels are counted per triangle).
    uint64_t estimate_voxels(const VoxelRegion& region) const;
    // Aligned cells of 2^cell_log2 voxels per axis that some triangle overlaps, as the
    // Morton codes of the cell coordinates (cell = voxel >> cell_log2), ascending.
    std::vector<uint64_t> touched_cells(int cell_log2) const;
    // Each triangle binned into the cells it may overlap (bins.cells is touched_cells).
    // Throws Error before allocating when the (cell, triangle) pairs would exceed
    // options().max_bytes.
    CellTriangles bin_triangles(int cell_log2) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// One-call forms.
VoxelList voxelize(std::span<const Vec3> positions, std::span<const UVec3> triangles,
                   const VoxelGrid& grid, VoxelizeOptions options = {});
VoxelList voxelize(const SceneFrame& frame, const VoxelGrid& grid, VoxelizeOptions options = {});

}  // namespace gilab
