#include "experiments/p2_dag/streamed_svdag_row.hpp"
#include <algorithm>
#include "core/util/stats.hpp"

namespace gilab::p2 {

namespace {
constexpr double kProgressEverySeconds = 60;
}

StreamedSvdagRow::StreamedSvdagRow(const Model& model, uint32_t resolution, int threads)
    : name_(model.label + " " + cube(resolution)) {
    if (resolution > kMaxVoxelResolution) {
        refusal_ = "the grid holds at most " + cube(kMaxVoxelResolution) + " voxels";
        return;
    }
    voxelizer_ = std::make_unique<Voxelizer>(model.positions, model.triangles, model_grid(model, resolution));
    const VoxelGrid& grid = voxelizer_->grid();
    split_level_ = std::max(0, grid.depth() - kSubtreeLog2);
    budget_ = available_memory_bytes() / 2;
    const uint64_t voxels = voxelizer_->estimate_voxels(grid.full_region());
    if (voxels > kMaxEstimatedVoxels) {
        refusal_ = "about " + std::to_string(voxels) + " voxels by the voxelizer's estimate, more than the 2³⁷ a row voxelizes";
        return;
    }
    const int cell_log2 = grid.depth() - split_level_;
    const uint64_t cell_volume = uint64_t(1) << (3 * std::min(cell_log2, 20));
    in_flight_ = 8 * std::min(voxels, 2 * cell_volume * uint64_t(std::max(threads, 1)));
    if (in_flight_ >= budget_) refusal_ = budget_text(in_flight_, budget_) + " for the cells being voxelized";
}

std::string StreamedSvdagRow::build_text() const {
    return split_level_ > 0 ? "split build at level " + std::to_string(split_level_) + " (" +
                                  cube(1u << kSubtreeLog2) + " subtrees)"
                            : "whole build";
}

Svdag StreamedSvdagRow::build(const std::function<void(const std::string&)>& say) const {
    SvdagStreamOptions stream;
    stream.max_table_bytes = budget_ - in_flight_;
    Stopwatch watch;
    double last_s = 0;
    stream.progress = [&](size_t done, size_t cells) {
        const double now = watch.elapsed_ms() * 1e-3;
        if (done == cells || now - last_s < kProgressEverySeconds) return;
        last_s = now;
        say(name_ + ": " + std::to_string(done * 100 / cells) + " % of " + std::to_string(cells) +
            " cells merged, " + std::to_string(int(now)) + " s");
    };
    return Svdag::from_voxelizer(*voxelizer_, split_level_, stream);
}

}  // namespace gilab::p2
