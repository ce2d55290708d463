#include "accel/temporal/multi_frame_dag.hpp"
#include <algorithm>
#include <array>
#include <string>
#include "accel/dag/child_mask.hpp"
#include "accel/dag/dag_layout.hpp"
#include "accel/dag/svdag_merger.hpp"
#include "core/util/error.hpp"
#include "core/util/stats.hpp"

namespace gilab {
namespace {

constexpr const char* kWhat = "multi-frame DAG";

bool same_grid(const VoxelGrid& a, const VoxelGrid& b) {
    return a.resolution == b.resolution && a.extent == b.extent && a.origin == b.origin;
}

}  // namespace

MultiFrameDag::MultiFrameDag(const VoxelGrid& grid) : grid_(grid) {
    grid_.validate(kWhat);
    depth_ = grid_.depth();
    tables_.resize(depth_ + 1);
    refs_ = DagRefCounts(depth_ + 1);
}

std::vector<std::pair<uint64_t, uint32_t>> MultiFrameDag::cells_below(uint32_t root, int level) const {
    struct Item {
        int level;
        uint32_t id;
        uint64_t code;
    };
    std::vector<std::pair<uint64_t, uint32_t>> out;
    std::vector<Item> stack{{0, root, 0}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        if (it.level == level) {
            out.push_back({it.code, it.id});
            continue;
        }
        const uint32_t mask = tables_[it.level].header(it.id);
        const auto kids = tables_[it.level].children(it.id);
        // Reversed so slot 0 pops first: ascending Morton order.
        for (int s = 7; s >= 0; --s)
            if (mask & (1u << s))
                stack.push_back({it.level + 1, kids[child_rank(mask, s)], it.code << 3 | uint64_t(s)});
    }
    return out;
}

uint32_t MultiFrameDag::merge_frame(const FrameCells& frame, uint32_t reference, FrameMergeStats& stats) {
    const int split = frame.split_level;
    if (split < 0 || split > depth_)
        throw Error(kWhat, "split level " + std::to_string(split) + " is outside 0.." + std::to_string(depth_));
    const int shift = 3 * (depth_ - split);
    const std::vector<uint64_t>* dirty = frame.dirty ? &*frame.dirty : nullptr;
    if (dirty && !std::is_sorted(dirty->begin(), dirty->end()))
        throw Error(kWhat, "dirty cells must be given in ascending Morton order");
    std::vector<std::pair<uint64_t, uint32_t>> reference_cells;
    if (dirty && reference != kEmptyFrame) reference_cells = cells_below(reference, split);

    SvdagMerger merger(tables_, depth_);
    std::vector<uint64_t> top_codes;
    std::vector<uint32_t> top_ids;
    size_t ref = 0;
    for (size_t c = 0; c < frame.cells.size(); ++c) {
        const uint64_t cell = frame.cells[c];
        if (c > 0 && cell <= frame.cells[c - 1])
            throw Error(kWhat, "split cells must be given in strictly ascending Morton order");
        if (split < 21 && (cell >> (3 * split)) != 0)
            throw Error(kWhat, "split cell " + std::to_string(cell) + " lies outside the grid");
        const bool clean = dirty && !std::binary_search(dirty->begin(), dirty->end(), cell);
        if (clean) {
            // Same voxels as the reference: take its subtree (none if it had no voxels here).
            while (ref < reference_cells.size() && reference_cells[ref].first < cell) ++ref;
            if (ref < reference_cells.size() && reference_cells[ref].first == cell) {
                top_codes.push_back(cell);
                top_ids.push_back(reference_cells[ref].second);
                ++stats.cells_reused;
            }
            continue;
        }
        if (!frame.slice) throw Error(kWhat, "a frame with dirty cells needs a slice source");
        std::vector<uint64_t> codes = frame.slice(cell);
        ++stats.cells_rebuilt;
        if (codes.empty()) continue;
        check_voxel_codes(grid_, codes, kWhat);
        if ((codes.front() >> shift) != cell || (codes.back() >> shift) != cell)
            throw Error(kWhat, "a slice holds voxels outside its split cell " + std::to_string(cell));
        top_codes.push_back(cell);
        top_ids.push_back(merger.add_subtree(codes, split));
    }
    return merger.finish_top(split, std::move(top_codes), std::move(top_ids));
}

FrameCells MultiFrameDag::whole_frame(std::span<const uint64_t> codes) const {
    check_voxel_codes(grid_, codes, kWhat);
    FrameCells frame;
    frame.split_level = default_split_level(depth_);
    const int shift = 3 * (depth_ - frame.split_level);
    for (uint64_t c : codes)
        if (frame.cells.empty() || frame.cells.back() != (c >> shift)) frame.cells.push_back(c >> shift);
    frame.slice = [codes, shift](uint64_t cell) {
        auto lo = std::lower_bound(codes.begin(), codes.end(), cell << shift);
        auto hi = lo;
        while (hi != codes.end() && (*hi >> shift) == cell) ++hi;
        return std::vector<uint64_t>(lo, hi);
    };
    return frame;
}

FrameMergeStats MultiFrameDag::append_frame(const FrameCells& frame) {
    Stopwatch clock;
    FrameMergeStats stats;
    const uint64_t before = node_count();
    const uint32_t root = merge_frame(frame, roots_.empty() ? kEmptyFrame : roots_.back(), stats);
    if (root != kEmptyFrame) refs_.acquire(tables_, 0, root);
    roots_.push_back(root);
    stats.nodes_added = node_count() - before;
    stats.ms = clock.elapsed_ms();
    return stats;
}

FrameMergeStats MultiFrameDag::append_frame(std::span<const uint64_t> codes) {
    return append_frame(whole_frame(codes));
}

FrameMergeStats MultiFrameDag::update_frame(size_t frame, const FrameCells& cells) {
    if (frame >= roots_.size())
        throw Error(kWhat, "cannot update frame " + std::to_string(frame) + ": there are " +
                               std::to_string(roots_.size()) + " frames");
    Stopwatch clock;
    FrameMergeStats stats;
    const uint64_t before = node_count();
    const uint32_t old_root = roots_[frame];
    const uint32_t root = merge_frame(cells, old_root, stats);
    // Acquire before releasing, so nodes shared by the old and new frame never die.
    if (root != kEmptyFrame) refs_.acquire(tables_, 0, root);
    auto shared_live = [&] {
        uint64_t n = 0;
        for (int l = 1; l <= depth_; ++l) n += refs_.live(l);
        return n;
    };
    const uint64_t live_before_release = shared_live();
    if (old_root != kEmptyFrame) refs_.release(tables_, 0, old_root);
    roots_[frame] = root;
    stats.nodes_reclaimed = live_before_release - shared_live() + (old_root != kEmptyFrame && old_root != root);
    stats.nodes_added = node_count() + stats.nodes_reclaimed - before;
    stats.ms = clock.elapsed_ms();
    return stats;
}

FrameMergeStats MultiFrameDag::update_frame(size_t frame, std::span<const uint64_t> codes) {
    return update_frame(frame, whole_frame(codes));
}

MultiFrameDag MultiFrameDag::merge_all(std::span<const Svdag> frames) {
    if (frames.empty()) throw Error(kWhat, "merge_all needs at least one frame");
    MultiFrameDag out(frames[0].grid());
    const int depth = out.depth_;
    for (size_t f = 0; f < frames.size(); ++f)
        if (!same_grid(frames[f].grid(), out.grid_))
            throw Error(kWhat, "frame " + std::to_string(f) + " was built on a different voxel grid than frame 0");
    // Level l of every frame is one list (P2 Fig. 10): ids of level l+1 are final before
    // level l is merged. id_of[f] maps frame f's word addresses to table ids.
    std::vector<std::vector<uint32_t>> id_of(frames.size());
    for (size_t f = 0; f < frames.size(); ++f) id_of[f].assign(frames[f].words().size(), kEmptyFrame);
    std::array<uint32_t, 8> kids;
    for (int l = depth; l >= 0; --l) {
        for (size_t f = 0; f < frames.size(); ++f) {
            const Svdag& dag = frames[f];
            if (dag.empty()) continue;
            const auto words = dag.words();
            for (uint32_t a : dag.level_nodes(l)) {
                const uint32_t mask = dag.mask(a);
                const uint32_t k = l < depth ? child_count(mask) : 0;
                for (uint32_t i = 0; i < k; ++i) kids[i] = id_of[f][words[a + 1 + i]];
                id_of[f][a] = out.tables_[l].find_or_insert(mask, kids.data(), k);
            }
        }
    }
    for (size_t f = 0; f < frames.size(); ++f) {
        const uint32_t root = frames[f].empty() ? kEmptyFrame : id_of[f][frames[f].root()];
        if (root != kEmptyFrame) out.refs_.acquire(out.tables_, 0, root);
        out.roots_.push_back(root);
    }
    return out;
}

void MultiFrameDag::compact() {
    std::vector<uint32_t> remap_below;
    std::array<uint32_t, 8> kids;
    for (int l = depth_; l >= 0; --l) {
        const DagLevelTable& old = tables_[l];
        DagLevelTable fresh;
        std::vector<uint32_t> remap(old.size(), kEmptyFrame);
        std::vector<uint32_t> counts;
        for (uint32_t id = 0; id < old.size(); ++id) {
            const uint32_t count = refs_.count(l, id);
            if (count == 0) continue;
            const auto children = old.children(id);
            for (size_t i = 0; i < children.size(); ++i) kids[i] = remap_below[children[i]];
            const uint32_t fresh_id = fresh.find_or_insert(old.header(id), kids.data(), uint32_t(children.size()));
            if (fresh_id != counts.size()) throw Error(kWhat, "internal: two live nodes are identical");
            remap[id] = fresh_id;
            counts.push_back(count);
        }
        tables_[l] = std::move(fresh);
        refs_.set_level(l, std::move(counts));
        remap_below = std::move(remap);
    }
    for (uint32_t& r : roots_)
        if (r != kEmptyFrame) r = remap_below[r];
}

uint64_t MultiFrameDag::node_count() const {
    uint64_t n = 0;
    for (uint32_t r : roots_) n += r != kEmptyFrame;
    for (int l = 1; l <= depth_; ++l) n += refs_.live(l);
    return n;
}

double MultiFrameDag::nodes_per_frame() const {
    return roots_.empty() ? 0.0 : double(node_count()) / double(roots_.size());
}

std::vector<uint64_t> MultiFrameDag::live_level_counts() const {
    std::vector<uint64_t> out(depth_ + 1);
    for (int l = 0; l <= depth_; ++l) out[l] = refs_.live(l);
    return out;
}

std::vector<uint64_t> MultiFrameDag::table_level_counts() const {
    std::vector<uint64_t> out(depth_ + 1);
    for (int l = 0; l <= depth_; ++l) out[l] = tables_[l].size();
    return out;
}

size_t MultiFrameDag::table_bytes() const {
    size_t b = 0;
    for (const auto& t : tables_) b += t.memory_bytes();
    return b;
}

LaidOutMultiFrameDag MultiFrameDag::lay_out() const {
    std::vector<uint32_t> present;
    for (uint32_t r : roots_)
        if (r != kEmptyFrame) present.push_back(r);
    DagLayoutOptions options;
    options.one_root_per_entry = true;
    DagLayout layout = lay_out_dag(tables_, present, options, kWhat);
    std::vector<uint32_t> roots;
    size_t next = 0;
    for (uint32_t r : roots_)
        roots.push_back(r == kEmptyFrame ? LaidOutMultiFrameDag::kEmptyFrame : layout.root_addresses[next++]);
    return LaidOutMultiFrameDag(grid_, std::move(layout.words), std::move(layout.level_begin),
                                std::move(layout.level_counts), std::move(roots), layout.pointer_count);
}

}  // namespace gilab
