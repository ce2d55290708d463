#include "accel/dag/svdag.hpp"
#include "accel/dag/child_mask.hpp"
#include <bit>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>
#include <tbb/task_arena.h>
#include "accel/dag/dag_level_table.hpp"
#include "accel/dag/svdag_merger.hpp"
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"
#include "core/util/morton.hpp"

namespace gilab {

// Per-level unique-node tables shared by every subtree of a build (merged by
// SvdagMerger), and the final layout into the paper's word format.
class SvdagAssembler {
public:
    explicit SvdagAssembler(const VoxelGrid& grid)
        : grid_(grid), depth_(grid.depth()), tables_(depth_ + 1), merger_(tables_, depth_) {}

    uint32_t leaf_id() { return merger_.leaf_id(); }
    uint32_t bottom_id(uint8_t mask) { return merger_.bottom_id(mask); }
    uint32_t add_subtree(std::span<const uint64_t> codes, int top) { return merger_.add_subtree(codes, top); }
    uint32_t add_subtree(std::span<const uint64_t> blocks, std::span<const uint64_t> masks, int top) {
        return merger_.add_subtree(blocks, masks, top);
    }
    void finish_top(int level, std::vector<uint64_t> codes, std::vector<uint32_t> ids) {
        merger_.finish_top(level, std::move(codes), std::move(ids));
    }

    DagLevelTable& table(int level) { return tables_[level]; }
    double lookup_ms() const { return merger_.lookup_ms(); }

    size_t table_bytes() const {
        size_t b = 0;
        for (const auto& t : tables_) b += t.memory_bytes();
        return b;
    }

    // Lays the levels out top-down in the paper's format and fills `dag`.
    void assemble(Svdag& dag) {
        dag.grid_ = grid_;
        dag.depth_ = depth_;
        dag.level_counts_.assign(depth_ + 1, 0);
        dag.level_begin_.assign(depth_ + 2, 0);
        dag.words_.clear();
        dag.pointer_count_ = 0;
        if (tables_[0].size() == 0) return;
        if (tables_[0].size() != 1) throw Error("SVDAG", "internal: the root level holds more than one node");
        std::vector<std::vector<uint32_t>> address(depth_ + 1);
        uint64_t next = 0;
        for (int l = 0; l <= depth_; ++l) {
            const DagLevelTable& t = tables_[l];
            dag.level_begin_[l] = next;
            dag.level_counts_[l] = t.size();
            address[l].resize(t.size());
            for (uint32_t u = 0; u < t.size(); ++u) {
                address[l][u] = static_cast<uint32_t>(next);
                next += 1 + t.children(u).size();
            }
            dag.pointer_count_ += t.child_count_total();
        }
        dag.level_begin_[depth_ + 1] = next;
        if (next >= kInvalidNode) throw Error("SVDAG", "DAG too large for 32-bit word addresses");
        dag.words_.resize(next);
        for (int l = 0; l <= depth_; ++l) {
            const DagLevelTable& t = tables_[l];
            const std::vector<uint32_t>* below = l < depth_ ? &address[l + 1] : nullptr;
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(t.size()), 4096),
                              [&](const tbb::blocked_range<uint32_t>& r) {
                                  for (uint32_t u = r.begin(); u < r.end(); ++u) {
                                      uint32_t a = address[l][u];
                                      dag.words_[a] = t.header(u);
                                      auto kids = t.children(u);
                                      for (size_t k = 0; k < kids.size(); ++k) dag.words_[a + 1 + k] = (*below)[kids[k]];
                                  }
                              });
            std::vector<uint32_t>().swap(address[l]);
        }
    }

private:
    VoxelGrid grid_;
    int depth_;
    std::vector<DagLevelTable> tables_;
    SvdagMerger merger_;
};

namespace {

int checked_split_level(const VoxelGrid& grid, int split_level) {
    if (split_level < 0 || split_level > grid.depth())
        throw Error("SVDAG", "split level " + std::to_string(split_level) + " is outside 0.." +
                                 std::to_string(grid.depth()));
    return split_level;
}

}  // namespace

Svdag Svdag::from_svo(const Svo& svo) {
    Stopwatch clock;
    Svdag dag;
    SvdagAssembler as(svo.grid());
    const int depth = svo.depth();
    double dedup_ms = 0;
    if (!svo.empty()) {
        if (depth == 0) {
            as.leaf_id();
        } else {
            // Level depth-1: every child is the one leaf, so the mask is the whole key.
            std::vector<uint32_t> ids_below, ids;
            {
                Stopwatch t;
                uint64_t begin = svo.level_offset(depth - 1), end = svo.level_offset(depth);
                ids_below.resize(end - begin);
                for (uint64_t j = begin; j < end; ++j) ids_below[j - begin] = as.bottom_id(svo.mask(uint32_t(j)));
                dedup_ms += t.elapsed_ms();
            }
            std::vector<uint64_t> hashes;
            for (int l = depth - 2; l >= 0; --l) {
                const uint64_t begin = svo.level_offset(l), end = svo.level_offset(l + 1);
                const uint64_t child_base = svo.level_offset(l + 1);
                const uint64_t n = end - begin;
                Stopwatch t;
                // Hash every node's key (mask + merged child ids) in parallel, then look
                // them up in order so ids stay deterministic.
                hashes.resize(n);
                tbb::parallel_for(tbb::blocked_range<uint64_t>(0, n, 8192), [&](const tbb::blocked_range<uint64_t>& r) {
                    for (uint64_t j = r.begin(); j < r.end(); ++j) {
                        uint32_t node = uint32_t(begin + j);
                        uint8_t m = svo.mask(node);
                        hashes[j] = DagLevelTable::hash(m, ids_below.data() + (svo.first_child(node) - child_base),
                                                        child_count(m));
                    }
                });
                DagLevelTable& table = as.table(l);
                ids.resize(n);
                constexpr uint64_t kAhead = 16;  // prefetch distance: lookups miss the cache
                for (uint64_t j = 0; j < n; ++j) {
                    if (j + kAhead < n) table.prefetch(hashes[j + kAhead]);
                    uint32_t node = uint32_t(begin + j);
                    uint8_t m = svo.mask(node);
                    ids[j] = table.find_or_insert(m, ids_below.data() + (svo.first_child(node) - child_base),
                                                  child_count(m), hashes[j]);
                }
                dedup_ms += t.elapsed_ms();
                std::swap(ids, ids_below);
            }
        }
    }
    dag.stats_.table_bytes = as.table_bytes();
    as.assemble(dag);
    dag.stats_.input_nodes = svo.node_count();
    dag.stats_.dedup_ms = dedup_ms;
    dag.stats_.total_ms = clock.elapsed_ms();
    dag.stats_.peak_rss_bytes = peak_rss_bytes();
    return dag;
}

Svdag Svdag::from_voxels(const VoxelGrid& grid, std::span<const uint64_t> codes, int split_level) {
    Stopwatch clock;
    grid.validate("SVDAG");
    checked_split_level(grid, split_level);
    check_voxel_codes(grid, codes, "SVDAG");
    const int depth = grid.depth();
    const int shift = 3 * (depth - split_level);
    SvdagAssembler as(grid);
    Svdag dag;
    std::vector<uint64_t> top_codes;
    std::vector<uint32_t> top_ids;
    size_t i = 0;
    while (i < codes.size()) {
        // Morton order makes each subtree a contiguous slice.
        uint64_t cell = codes[i] >> shift;
        size_t j = i;
        while (j < codes.size() && (codes[j] >> shift) == cell) ++j;
        top_codes.push_back(cell);
        top_ids.push_back(as.add_subtree(codes.subspan(i, j - i), split_level));
        ++dag.stats_.subtrees;
        i = j;
    }
    as.finish_top(split_level, std::move(top_codes), std::move(top_ids));
    dag.stats_.dedup_ms = as.lookup_ms();
    dag.stats_.table_bytes = as.table_bytes();
    as.assemble(dag);
    dag.stats_.input_nodes = codes.size();
    dag.stats_.split_level = split_level;
    dag.stats_.total_ms = clock.elapsed_ms();
    dag.stats_.peak_rss_bytes = peak_rss_bytes();
    return dag;
}

Svdag Svdag::from_slices(const VoxelGrid& grid, int split_level, std::span<const uint64_t> cells,
                         const SliceSource& slice, const SvdagStreamOptions& options) {
    return from_block_slices(
        grid, split_level, cells,
        [&](uint64_t cell) {
            VoxelBlocks blocks;
            const std::vector<uint64_t> codes = slice(cell);
            check_voxel_codes(grid, codes, "SVDAG");
            blocks_from_codes(codes, blocks.blocks, blocks.masks);
            return blocks;
        },
        options);
}

Svdag Svdag::from_block_slices(const VoxelGrid& grid, int split_level, std::span<const uint64_t> cells,
                               const BlockSliceSource& slice, const SvdagStreamOptions& options) {
    Stopwatch clock;
    grid.validate("SVDAG");
    checked_split_level(grid, split_level);
    const int depth = grid.depth();
    const int shift = 3 * (depth - split_level);
    SvdagAssembler as(grid);
    Svdag dag;
    std::vector<uint64_t> top_codes;
    std::vector<uint32_t> top_ids;
    double slice_ms = 0;
    uint64_t voxels = 0;
    for (size_t c = 0; c < cells.size(); ++c) {
        if (c > 0 && cells[c] <= cells[c - 1])
            throw Error("SVDAG", "split cells must be given in strictly ascending Morton order");
        if (options.max_table_bytes > 0 && as.table_bytes() > options.max_table_bytes)
            throw Error("SVDAG", "the merge tables hold " + MemoryBudget::format(as.table_bytes()) + " after " + std::to_string(c) +
                                     " of " + std::to_string(cells.size()) + " cells, over the build's limit of " +
                                     MemoryBudget::format(options.max_table_bytes));
        if (options.progress && c > 0) options.progress(c, cells.size());
        Stopwatch t;
        const VoxelBlocks blocks = slice(cells[c]);
        slice_ms += t.elapsed_ms();
        if (blocks.empty()) continue;
        // Blocks ascending with a voxel each; the first and last voxel inside the cell
        // (a block may hold several cells when the cells are smaller than 4³).
        for (size_t i = 0; i < blocks.blocks.size(); ++i)
            if (blocks.masks[i] == 0 || (i > 0 && blocks.blocks[i] <= blocks.blocks[i - 1]))
                throw Error("SVDAG", "a slice's voxel blocks must be ascending and non-empty; block " + std::to_string(i) +
                                         " is not");
        const uint64_t first = blocks.blocks.front() << 6 | uint64_t(std::countr_zero(blocks.masks.front()));
        const uint64_t last = blocks.blocks.back() << 6 | uint64_t(63 - std::countl_zero(blocks.masks.back()));
        if ((first >> shift) != cells[c] || (last >> shift) != cells[c])
            throw Error("SVDAG", "a slice holds voxels outside its split cell " + std::to_string(cells[c]));
        top_codes.push_back(cells[c]);
        top_ids.push_back(as.add_subtree(blocks.blocks, blocks.masks, split_level));
        voxels += blocks.voxel_count();
        ++dag.stats_.subtrees;
    }
    if (options.progress) options.progress(cells.size(), cells.size());
    as.finish_top(split_level, std::move(top_codes), std::move(top_ids));
    dag.stats_.table_bytes = as.table_bytes();
    as.assemble(dag);
    dag.stats_.input_nodes = voxels;
    dag.stats_.split_level = split_level;
    dag.stats_.dedup_ms = as.lookup_ms();
    dag.stats_.voxelize_ms = slice_ms;
    dag.stats_.total_ms = clock.elapsed_ms() - slice_ms;
    dag.stats_.peak_rss_bytes = peak_rss_bytes();
    return dag;
}

Svdag Svdag::from_voxelizer(const Voxelizer& voxelizer, int split_level, const SvdagStreamOptions& options) {
    const VoxelGrid& grid = voxelizer.grid();
    checked_split_level(grid, split_level);
    const int cell_log2 = grid.depth() - split_level;
    // Each cell voxelizes only its own triangles, so the build's time grows with the
    // voxels, not with cells × the scene's triangles.
    const CellTriangles bins = voxelizer.bin_triangles(cell_log2);
    const size_t cell_count = bins.cells.size();
    // A batch of cells, one per thread, is voxelized in parallel (a small cell's
    // voxelization is mostly serial); the merge takes them in order, one at a time, while
    // the next batch is voxelized: the merge is serial and would leave the other threads idle.
    const size_t batch_cells = size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    struct Batch {
        size_t begin = 0;
        std::vector<VoxelBlocks> cells;
        bool holds(size_t i) const { return i >= begin && i < begin + cells.size(); }
    };
    auto voxelize_batch = [&](size_t begin, Batch& batch) {
        batch.begin = begin;
        batch.cells.assign(std::min(batch_cells, cell_count - begin), {});
        tbb::parallel_for(size_t(0), batch.cells.size(), [&](size_t i) {
            VoxelRegion region;
            region.begin = morton_decode(bins.cells[begin + i]) << UVec3(uint32_t(cell_log2));
            region.end = region.begin + UVec3(1u << cell_log2);
            batch.cells[i] = voxelizer.voxelize_blocks(region, bins.of(begin + i));
        });
    };
    Batch current, upcoming;
    tbb::task_group ahead;
    bool voxelizing_ahead = false;
    // The batch being voxelized ahead refers to `upcoming`: wait for it on every way out.
    struct WaitOnExit {
        tbb::task_group& group;
        bool& running;
        ~WaitOnExit() {
            if (!running) return;
            group.cancel();
            try {
                group.wait();
            } catch (...) {  // the build is already leaving with its own error
            }
        }
    } wait_on_exit{ahead, voxelizing_ahead};
    size_t next = 0;  // from_block_slices asks for the cells in ascending order
    return from_block_slices(
        grid, split_level, bins.cells,
        [&](uint64_t cell) {
            while (bins.cells[next] != cell) ++next;
            if (!current.holds(next)) {
                if (voxelizing_ahead) {
                    voxelizing_ahead = false;
                    ahead.wait();  // rethrows the voxelizer's error
                    std::swap(current, upcoming);
                }
                if (!current.holds(next)) voxelize_batch(next, current);
                const size_t after = current.begin + current.cells.size();
                if (after < cell_count) {
                    voxelizing_ahead = true;
                    ahead.run([&, after] { voxelize_batch(after, upcoming); });
                }
            }
            return std::move(current.cells[next - current.begin]);
        },
        options);
}

uint32_t Svdag::child(uint32_t node, int slot) const {
    uint32_t m = words_[node] & 0xffu;
    if (!(m & (1u << slot))) return kInvalidNode;
    return words_[node + 1 + child_rank(m, slot)];
}

std::vector<uint32_t> Svdag::level_nodes(int level) const {
    std::vector<uint32_t> nodes;
    if (empty() || level < 0 || level > depth_) return nodes;
    for (uint64_t a = level_begin_[level]; a < level_begin_[level + 1]; a += 1 + child_count(words_[a]))
        nodes.push_back(uint32_t(a));
    return nodes;
}

size_t Svdag::node_count() const {
    size_t n = 0;
    for (uint64_t c : level_counts_) n += c;
    return n;
}

uint64_t Svdag::voxel_count() const {
    if (empty()) return 0;
    // Voxels below each node, from the leaf level up; indexed by word address.
    std::vector<uint64_t> below(words_.size(), 0);
    for (uint32_t a : level_nodes(depth_)) below[a] = 1;
    for (int l = depth_ - 1; l >= 0; --l)
        for (uint32_t a : level_nodes(l)) {
            int k = int(child_count(words_[a]));
            uint64_t sum = 0;
            for (int i = 0; i < k; ++i) sum += below[words_[a + 1 + i]];
            below[a] = sum;
        }
    return below[0];
}

DagLocation Svdag::follow(const OctreePath& path) const {
    DagLocation loc;
    loc.inside_grid = true;
    loc.path = path;
    if (empty()) return loc;
    uint32_t node = root();
    loc.reached_level = 0;
    loc.node = node;
    for (int k = 0; k < path.level() && k < depth_; ++k) {
        uint32_t c = child(node, path.slots[k]);
        if (c == kInvalidNode) return loc;
        node = c;
        loc.reached_level = k + 1;
        loc.node = node;
    }
    loc.occupied = loc.reached_level == path.level();
    return loc;
}

DagLocation Svdag::locate(const Vec3& p) const {
    auto v = grid_.voxel_of(p);
    if (!v) return DagLocation{};
    return follow(voxel_path(*v, depth_, depth_));
}

bool Svdag::contains_voxel(const UVec3& v) const {
    if (empty() || v.x >= grid_.resolution || v.y >= grid_.resolution || v.z >= grid_.resolution) return false;
    uint32_t node = root();
    for (int l = 0; l < depth_; ++l) {
        int shift = depth_ - 1 - l;
        node = child(node, octree_child_slot(v.x >> shift, v.y >> shift, v.z >> shift));
        if (node == kInvalidNode) return false;
    }
    return true;
}

bool Svdag::occupied(const Vec3& p) const {
    auto v = grid_.voxel_of(p);
    return v && contains_voxel(*v);
}

std::vector<uint64_t> Svdag::decode() const {
    if (empty()) return {};
    return collect_leaf_codes(
        root(), kInvalidNode, [&](uint32_t node, int slot) { return child(node, slot); },
        [&](uint32_t, int level) { return level == depth_; });
}

Stats Svdag::stats() const {
    Stats s;
    s.set("nodes", double(node_count()));
    s.set("pointers", double(pointer_count()));
    s.set("bytes", double(bytes()));
    s.set("convert_ms", stats_.total_ms);
    s.set("dedup_ms", stats_.dedup_ms);
    s.set("voxelize_ms", stats_.voxelize_ms);
    s.set("subtrees", double(stats_.subtrees));
    s.set("split_level", double(stats_.split_level));
    s.set("table_bytes", double(stats_.table_bytes));
    for (size_t l = 0; l < level_counts_.size(); ++l) s.set("nodes_level_" + std::to_string(l), double(level_counts_[l]));
    return s;
}

}  // namespace gilab
