#include "accel/peers/octomap_tree.hpp"
#include <octomap/OcTree.h>
#include "core/util/error.hpp"
#include "core/util/morton.hpp"

namespace gilab {
namespace {

constexpr uint32_t kOctomapHalf = 32768;  // OctoMap's key of coordinate 0 (16-bit keys)

}  // namespace

struct OctomapVoxels::Impl {
    VoxelGrid grid;
    std::unique_ptr<octomap::OcTree> tree;
    double build_ms = 0;

    // OctoMap's tree is centred on 0: voxel v of our grid is at (v + 0.5)·h relative to
    // the grid origin, which lands in key v + 32768.
    octomap::OcTreeKey key(const UVec3& v) const {
        return octomap::OcTreeKey(octomap::key_type(v.x + kOctomapHalf), octomap::key_type(v.y + kOctomapHalf),
                                  octomap::key_type(v.z + kOctomapHalf));
    }
};

OctomapVoxels::OctomapVoxels(const VoxelGrid& grid, std::span<const uint64_t> codes, bool prune)
    : impl_(std::make_unique<Impl>()) {
    Stopwatch clock;
    grid.validate("OctoMap tree");
    if (grid.resolution > kOctomapHalf)
        throw Error("OctoMap tree", "resolution " + std::to_string(grid.resolution) +
                                        " exceeds OctoMap's 16-bit keys (at most 32768 voxels per axis)");
    impl_->grid = grid;
    impl_->tree = std::make_unique<octomap::OcTree>(grid.voxel_size());
    for (uint64_t code : codes) impl_->tree->updateNode(impl_->key(morton_decode(code)), true, /*lazy_eval=*/true);
    impl_->tree->updateInnerOccupancy();
    if (prune) impl_->tree->prune();
    impl_->build_ms = clock.elapsed_ms();
}

OctomapVoxels::~OctomapVoxels() = default;
OctomapVoxels::OctomapVoxels(OctomapVoxels&&) noexcept = default;
OctomapVoxels& OctomapVoxels::operator=(OctomapVoxels&&) noexcept = default;

const VoxelGrid& OctomapVoxels::grid() const { return impl_->grid; }
size_t OctomapVoxels::node_count() const { return impl_->tree->size(); }
size_t OctomapVoxels::leaf_node_count() const { return impl_->tree->getNumLeafNodes(); }
size_t OctomapVoxels::bytes() const { return impl_->tree->memoryUsage(); }
double OctomapVoxels::build_ms() const { return impl_->build_ms; }

uint64_t OctomapVoxels::voxel_count() const {
    const octomap::OcTree& t = *impl_->tree;
    const unsigned max_depth = t.getTreeDepth();
    uint64_t n = 0;
    for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it)
        if (t.isNodeOccupied(*it)) n += uint64_t(1) << (3 * (max_depth - it.getDepth()));
    return n;
}

bool OctomapVoxels::contains_voxel(const UVec3& v) const {
    if (v.x >= impl_->grid.resolution || v.y >= impl_->grid.resolution || v.z >= impl_->grid.resolution) return false;
    const octomap::OcTreeNode* node = impl_->tree->search(impl_->key(v));
    return node && impl_->tree->isNodeOccupied(node);
}

bool OctomapVoxels::occupied(const Vec3& p) const {
    const VoxelGrid& g = impl_->grid;
    DVec3 local = DVec3(p) - DVec3(g.origin);
    for (int k = 0; k < 3; ++k)  // OctoMap's tree reaches beyond our grid; clip to it
        if (!(local[k] >= 0) || !(local[k] < double(g.extent))) return false;
    const octomap::OcTreeNode* node = impl_->tree->search(local.x, local.y, local.z);
    return node && impl_->tree->isNodeOccupied(node);
}

Stats OctomapVoxels::stats() const {
    Stats s;
    s.set("voxels", double(voxel_count()));
    s.set("nodes", double(node_count()));
    s.set("leaf_nodes", double(leaf_node_count()));
    s.set("bytes", double(bytes()));
    s.set("build_ms", build_ms());
    return s;
}

}  // namespace gilab
