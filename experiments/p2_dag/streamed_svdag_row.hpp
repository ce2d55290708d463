#pragma once
// One model at one resolution built as the scale experiments build it: the streamed split
// SVDAG (Svdag::from_voxelizer, 256³ subtrees) within the row's memory budget, half the
// available memory. The guards run before anything is built and say why a row cannot be.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include "accel/dag/svdag.hpp"
#include "core/voxel/voxelizer.hpp"
#include "experiments/p2_dag/dag_models.hpp"

namespace gilab::p2 {

class StreamedSvdagRow {
public:
    // Each streamed subtree is 2^kSubtreeLog2 voxels per axis (dag-table3's split rule).
    static constexpr int kSubtreeLog2 = 8;
    // Rows are attempted up to this many voxels by the voxelizer's estimate (above the
    // true count): over an hour of voxelizing on a two-core machine.
    static constexpr uint64_t kMaxEstimatedVoxels = uint64_t(1) << 37;

    StreamedSvdagRow(const Model& model, uint32_t resolution, int threads);

    // Why the row cannot be built (the grid's limit, the voxel limit, or the cells being
    // voxelized over the budget); empty when it can.
    const std::string& refusal() const { return refusal_; }
    const std::string& name() const { return name_; }  // "Castle 8192³"
    const Voxelizer& voxelizer() const { return *voxelizer_; }
    int split_level() const { return split_level_; }
    size_t budget_bytes() const { return budget_; }
    // The cells being voxelized while the build merges (two batches of one cell per
    // thread, 8 B per voxel by the voxelizer's estimate).
    uint64_t in_flight_bytes() const { return in_flight_; }
    std::string build_text() const;  // "split build at level 5 (256³ subtrees)"

    // The build on the current thread limit; `say` hears its progress at most once a
    // minute. Throws Error when the merge tables pass the budget left beside the cells in
    // flight, or when the DAG is beyond its pointers' reach.
    Svdag build(const std::function<void(const std::string&)>& say) const;

private:
    std::string name_, refusal_;
    std::unique_ptr<Voxelizer> voxelizer_;
    int split_level_ = 0;
    size_t budget_ = 0;
    uint64_t in_flight_ = 0;
};

}  // namespace gilab::p2
