#pragma once
// Sparse voxel DAG (P2 §2.2): the SVO with identical subtrees merged, built bottom-up
// without recursion — leaves first (all leaves are alike), then level by level, nodes
// with the same child mask and the same (already merged) child pointers become one.
// Storage is exactly the paper's: per node a 32-bit word holding the 8-bit child mask,
// then one 32-bit pointer per non-empty child (8..36 B per interior node); the pointer
// of child slot k is at node + 1 + rank(mask, k) words. Pointers are word addresses.
// Nodes are laid out level by level from the root (address 0); the single leaf node is
// one word (mask 0) at the end.
//
// A split build converts the subtrees below a chosen level one at a time (each from its
// own contiguous slice of the Morton-sorted voxels, or voxelized on demand), joins
// their roots and merges the levels above, so the peak memory is the finished DAG plus
// one subtree (two per thread when they are voxelized on demand).
// The minimal DAG is unique, so every split level gives the same DAG.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>
#include "accel/dag/octree_path.hpp"
#include "accel/dag/svo.hpp"
#include "core/util/math.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxel_grid.hpp"
#include "core/voxel/voxelizer.hpp"

namespace gilab {

struct SvdagBuildStats {
    double total_ms = 0;       // t_A: the whole conversion to the final storage
    double dedup_ms = 0;       // t_B: hashing nodes and looking up identical ones
    double voxelize_ms = 0;    // split builds fed cell by cell: time spent waiting for the cells
    uint64_t input_nodes = 0;  // SVO nodes read (from_svo) or voxels read (other builds)
    uint64_t subtrees = 0;     // subtrees converted separately (split builds)
    int split_level = 0;
    size_t table_bytes = 0;    // merge tables at the end of the build
    size_t peak_rss_bytes = 0; // process peak resident memory after the build
};

// Where a point lands in the DAG.
struct DagLocation {
    bool inside_grid = false;
    bool occupied = false;          // the full path exists: the voxel is occupied
    OctreePath path;                // path of the voxel holding the point (grid depth steps)
    int reached_level = -1;         // deepest level whose node exists on that path (-1: empty DAG)
    uint32_t node = 0xffffffffu;    // address of that node
};

// How a split build fed cell by cell (from_slices, from_voxelizer) watches itself.
struct SvdagStreamOptions {
    // Bytes the merge tables may hold (0: no limit), checked before each cell: past it
    // the build stops with an Error saying how far it got.
    size_t max_table_bytes = 0;
    // Called after each cell with the cells done and the cells in all.
    std::function<void(size_t done, size_t cells)> progress;
};

class Svdag {
public:
    Svdag() = default;

    // The paper's conversion: bottom-up merge of an SVO. Timed as t_A / t_B.
    static Svdag from_svo(const Svo& svo);
    // Straight from Morton-sorted voxels. split_level > 0 converts each subtree rooted
    // on that level separately (its slice of `codes`), then joins them.
    static Svdag from_voxels(const VoxelGrid& grid, std::span<const uint64_t> codes, int split_level = 0);
    static Svdag from_voxels(const VoxelList& voxels, int split_level = 0) {
        return from_voxels(voxels.grid, voxels.codes, split_level);
    }
    // Split build from any voxel source: `cells` are the ascending Morton codes of the
    // level-`split_level` cells that may hold voxels; slice(cell) returns that cell's
    // voxels (global Morton codes, ascending). Only one slice is alive at a time.
    using SliceSource = std::function<std::vector<uint64_t>(uint64_t cell)>;
    static Svdag from_slices(const VoxelGrid& grid, int split_level, std::span<const uint64_t> cells,
                             const SliceSource& slice, const SvdagStreamOptions& options = {});
    // Split build that voxelizes the level-`split_level` cells a batch at a time (one per
    // thread, in parallel), each from only the triangles binned into it, so a grid far too
    // large to hold as a voxel list still converts, in time that grows with its voxels.
    // The next batch is voxelized while the current one is merged (two batches alive).
    static Svdag from_voxelizer(const Voxelizer& voxelizer, int split_level,
                                const SvdagStreamOptions& options = {});

    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    bool empty() const { return words_.empty(); }
    uint32_t root() const { return 0; }
    std::span<const uint32_t> words() const { return words_; }

    uint8_t mask(uint32_t node) const { return static_cast<uint8_t>(words_[node] & 0xffu); }
    uint32_t child(uint32_t node, int slot) const;  // address, or 0xffffffff for an empty slot
    // Addresses of the nodes of one level, in storage order.
    std::vector<uint32_t> level_nodes(int level) const;

    size_t node_count() const;                       // unique nodes, leaf node included
    size_t pointer_count() const { return pointer_count_; }  // stored child pointers
    size_t bytes() const { return words_.size() * sizeof(uint32_t); }
    const std::vector<uint64_t>& level_node_counts() const { return level_counts_; }  // depth+1 entries
    uint64_t voxel_count() const;                    // occupied voxels (counted over the DAG)

    bool contains_voxel(const UVec3& voxel) const;
    bool occupied(const Vec3& world_point) const;
    DagLocation locate(const Vec3& world_point) const;
    // Follows a path as far as the DAG has nodes; occupied = the whole path exists.
    DagLocation follow(const OctreePath& path) const;
    std::vector<uint64_t> decode() const;            // Morton codes of all voxels, ascending

    const SvdagBuildStats& build_stats() const { return stats_; }
    // nodes, pointers, bytes, voxels, convert_ms (t_A), dedup_ms (t_B), voxelize_ms,
    // subtrees, split_level, nodes_level_<k>.
    Stats stats() const;

private:
    friend class SvdagAssembler;
    // from_slices with each cell's voxels as blocks (the voxelizer's own form).
    using BlockSliceSource = std::function<VoxelBlocks(uint64_t cell)>;
    static Svdag from_block_slices(const VoxelGrid& grid, int split_level, std::span<const uint64_t> cells,
                                   const BlockSliceSource& slice, const SvdagStreamOptions& options);
    VoxelGrid grid_;
    int depth_ = 0;
    std::vector<uint32_t> words_;
    std::vector<uint64_t> level_counts_;
    std::vector<uint64_t> level_begin_;  // word address where each level starts; depth+2 entries
    size_t pointer_count_ = 0;
    SvdagBuildStats stats_;
};

}  // namespace gilab
