#include "accel/temporal/laid_out_multi_frame_dag.hpp"
#include <string>
#include <unordered_set>
#include "accel/dag/child_mask.hpp"
#include "accel/dag/octree_path.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"

namespace gilab {

LaidOutMultiFrameDag::LaidOutMultiFrameDag(const VoxelGrid& grid, std::vector<uint32_t> words,
                                           std::vector<uint64_t> level_begin, std::vector<uint64_t> level_counts,
                                           std::vector<uint32_t> roots, uint64_t pointer_count)
    : grid_(grid),
      depth_(grid.depth()),
      words_(std::move(words)),
      level_begin_(std::move(level_begin)),
      level_counts_(std::move(level_counts)),
      roots_(std::move(roots)),
      pointer_count_(pointer_count) {}

uint32_t LaidOutMultiFrameDag::root(size_t frame) const {
    if (frame >= roots_.size())
        throw Error("multi-frame DAG", "frame " + std::to_string(frame) + " is outside 0.." +
                                           std::to_string(roots_.size()) + " (exclusive)");
    return roots_[frame];
}

uint32_t LaidOutMultiFrameDag::child(uint32_t node, int slot) const {
    uint32_t m = words_[node] & 0xffu;
    if (!(m & (1u << slot))) return kEmptyFrame;
    return words_[node + 1 + child_rank(m, slot)];
}

std::vector<uint64_t> LaidOutMultiFrameDag::decode(size_t frame) const {
    const uint32_t r = root(frame);
    if (r == kEmptyFrame) return {};
    return collect_leaf_codes(
        r, kEmptyFrame, [&](uint32_t node, int slot) { return child(node, slot); },
        [&](uint32_t, int level) { return level == depth_; });
}

bool LaidOutMultiFrameDag::contains_voxel(size_t frame, const UVec3& v) const {
    uint32_t node = root(frame);
    if (node == kEmptyFrame || v.x >= grid_.resolution || v.y >= grid_.resolution || v.z >= grid_.resolution)
        return false;
    for (int l = 0; l < depth_; ++l) {
        int shift = depth_ - 1 - l;
        node = child(node, octree_child_slot(v.x >> shift, v.y >> shift, v.z >> shift));
        if (node == kEmptyFrame) return false;
    }
    return true;
}

size_t LaidOutMultiFrameDag::reachable_node_count(size_t frame) const {
    const uint32_t r = root(frame);
    if (r == kEmptyFrame) return 0;
    std::unordered_set<uint32_t> seen{r};
    std::vector<uint32_t> stack{r};
    while (!stack.empty()) {
        uint32_t a = stack.back();
        stack.pop_back();
        const uint32_t k = child_count(words_[a]);
        for (uint32_t i = 0; i < k; ++i)
            if (seen.insert(words_[a + 1 + i]).second) stack.push_back(words_[a + 1 + i]);
    }
    return seen.size();
}

size_t LaidOutMultiFrameDag::node_count() const {
    size_t n = 0;
    for (uint64_t c : level_counts_) n += c;
    return n;
}

double LaidOutMultiFrameDag::nodes_per_frame() const {
    return roots_.empty() ? 0.0 : double(node_count()) / double(roots_.size());
}

Stats LaidOutMultiFrameDag::stats() const {
    Stats s;
    s.set("frames", double(frame_count()));
    s.set("nodes", double(node_count()));
    s.set("nodes_per_frame", nodes_per_frame());
    s.set("pointers", double(pointer_count()));
    s.set("bytes", double(bytes()));
    for (size_t l = 0; l < level_counts_.size(); ++l) s.set("nodes_level_" + std::to_string(l), double(level_counts_[l]));
    return s;
}

DagWordsView dag_view(const LaidOutMultiFrameDag& dag, size_t frame) {
    DagWordsView v;
    v.words = dag.words();
    v.depth = dag.depth();
    v.grid = dag.grid();
    const uint32_t root = dag.root(frame);  // throws for a frame outside the animation
    v.empty = root == LaidOutMultiFrameDag::kEmptyFrame;
    v.root = v.empty ? 0 : root;
    return v;
}

VoxelRayHit trace_voxel_ray(const LaidOutMultiFrameDag& dag, size_t frame, const Ray& ray) {
    return trace_voxel_ray(dag_view(dag, frame), ray);
}

}  // namespace gilab
