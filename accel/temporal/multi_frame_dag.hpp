#pragma once
// Time-correlated multi-frame SVDAG (P2 §4): the SVOs of all frames in time order, each
// level of all frames treated as one list, identical nodes merged bottom-up across
// space and time. There is one root per frame, in time order, even when two frames are
// identical.
//
// Build modes: (a) merge_all — per-frame DAGs merged at once, level by level over all
// frames; (b) append_frame — frame n merged into the DAG of frames 0..n-1, streaming one
// split cell's voxels at a time, so the peak is the shared DAG plus one cell. Cells the
// caller marks clean reuse the previous frame's subtree without touching voxels.
//
// update_frame replaces one frame: only the dirty cells are merged again, and nodes no
// longer referenced by any frame die (reference counts). Dead nodes stay in the tables
// until compact(), so a subtree that comes back (a door swinging shut) is revived.
//
// Node counts follow the paper's Table 5: N_n = one root per non-empty frame plus the
// live shared nodes below (leaf node included); N_p = N_n / F.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>
#include "accel/dag/dag_level_table.hpp"
#include "accel/dag/dag_ref_counts.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/temporal/laid_out_multi_frame_dag.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

// One frame handed over cell by cell (streaming).
struct FrameCells {
    int split_level = 0;                         // cells are the nodes of this level
    std::vector<uint64_t> cells;                 // ascending codes of the cells that may hold voxels
    // Cells that may differ from the reference frame (the previous frame when appending,
    // none counting as empty; the frame's current content when updating), ascending;
    // nullopt = every cell.
    std::optional<std::vector<uint64_t>> dirty;
    // This frame's voxels in one cell: global Morton codes, ascending.
    std::function<std::vector<uint64_t>(uint64_t cell)> slice;
};

struct FrameMergeStats {
    uint64_t nodes_added = 0;      // growth of N_n plus nodes_reclaimed
    uint64_t nodes_reclaimed = 0;  // nodes no frame references any more (roots included)
    uint64_t cells_rebuilt = 0;    // cells whose voxels were merged again
    uint64_t cells_reused = 0;     // clean cells that took the reference frame's subtree
    double ms = 0;
};

class MultiFrameDag {
public:
    explicit MultiFrameDag(const VoxelGrid& grid);

    // (b) incremental: the frame is merged into the DAG of the frames before it.
    FrameMergeStats append_frame(const FrameCells& frame);
    // Whole frame from ascending voxel codes (split into cells internally).
    FrameMergeStats append_frame(std::span<const uint64_t> codes);
    // (a) all at once: per-frame DAGs (same grid) merged level by level over all frames.
    static MultiFrameDag merge_all(std::span<const Svdag> frames);

    // Replaces frame `frame`; dirty cells are relative to its current content.
    FrameMergeStats update_frame(size_t frame, const FrameCells& cells);
    FrameMergeStats update_frame(size_t frame, std::span<const uint64_t> codes);
    // Drops dead nodes from the tables and renumbers; the laid-out words do not change.
    void compact();

    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    size_t frame_count() const { return roots_.size(); }
    uint64_t node_count() const;                  // N_n
    double nodes_per_frame() const;               // N_p
    std::vector<uint64_t> live_level_counts() const;   // live unique nodes per level (roots counted once)
    std::vector<uint64_t> table_level_counts() const;  // nodes held per level, dead ones included
    size_t table_bytes() const;
    uint32_t reference_count(int level, uint32_t id) const { return refs_.count(level, id); }
    const std::vector<DagLevelTable>& tables() const { return tables_; }
    const std::vector<uint32_t>& root_ids() const { return roots_; }  // kEmptyFrame for an empty frame

    // The 32-bit layout (canonical: equal DAGs give equal words however they were built).
    LaidOutMultiFrameDag lay_out() const;

    static constexpr uint32_t kEmptyFrame = 0xffffffffu;
    // Default split: cells of 32^3 voxels.
    static int default_split_level(int depth) { return depth > 5 ? depth - 5 : 0; }

private:
    // Root id (level 0) of `frame`, reusing the subtrees of `reference` (a root id or
    // kEmptyFrame) for clean cells.
    uint32_t merge_frame(const FrameCells& frame, uint32_t reference, FrameMergeStats& stats);
    // (cell code, id) of the nodes on `level` below `root`, ascending codes.
    std::vector<std::pair<uint64_t, uint32_t>> cells_below(uint32_t root, int level) const;
    FrameCells whole_frame(std::span<const uint64_t> codes) const;

    VoxelGrid grid_;
    int depth_ = 0;
    std::vector<DagLevelTable> tables_;
    DagRefCounts refs_;
    std::vector<uint32_t> roots_;
};

}  // namespace gilab
