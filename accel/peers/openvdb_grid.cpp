#include "accel/peers/openvdb_grid.hpp"
#include <mutex>
#include <openvdb/openvdb.h>
#include "core/util/morton.hpp"

namespace gilab {

struct OpenVdbVoxels::Impl {
    VoxelGrid grid;
    openvdb::MaskGrid::Ptr vdb;
    double build_ms = 0;
};

OpenVdbVoxels::OpenVdbVoxels(const VoxelGrid& grid, std::span<const uint64_t> codes) : impl_(std::make_unique<Impl>()) {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
    Stopwatch clock;
    grid.validate("OpenVDB grid");
    impl_->grid = grid;
    impl_->vdb = openvdb::MaskGrid::create();
    const double h = grid.voxel_size();
    auto xform = openvdb::math::Transform::createLinearTransform(h);
    xform->postTranslate(openvdb::Vec3d(grid.origin.x + 0.5 * h, grid.origin.y + 0.5 * h, grid.origin.z + 0.5 * h));
    impl_->vdb->setTransform(xform);
    auto acc = impl_->vdb->getAccessor();
    for (uint64_t code : codes) {
        UVec3 v = morton_decode(code);
        acc.setValueOn(openvdb::Coord(int(v.x), int(v.y), int(v.z)));
    }
    impl_->build_ms = clock.elapsed_ms();
}

OpenVdbVoxels::~OpenVdbVoxels() = default;
OpenVdbVoxels::OpenVdbVoxels(OpenVdbVoxels&&) noexcept = default;
OpenVdbVoxels& OpenVdbVoxels::operator=(OpenVdbVoxels&&) noexcept = default;

const VoxelGrid& OpenVdbVoxels::grid() const { return impl_->grid; }
uint64_t OpenVdbVoxels::voxel_count() const { return impl_->vdb->activeVoxelCount(); }
size_t OpenVdbVoxels::bytes() const { return impl_->vdb->memUsage(); }
size_t OpenVdbVoxels::leaf_node_count() const { return impl_->vdb->tree().leafCount(); }
size_t OpenVdbVoxels::internal_node_count() const { return impl_->vdb->tree().nonLeafCount() - 1; }
double OpenVdbVoxels::build_ms() const { return impl_->build_ms; }

bool OpenVdbVoxels::contains_voxel(const UVec3& v) const {
    return impl_->vdb->tree().isValueOn(openvdb::Coord(int(v.x), int(v.y), int(v.z)));
}

bool OpenVdbVoxels::occupied(const Vec3& p) const {
    openvdb::Coord c = impl_->vdb->transform().worldToIndexCellCentered(openvdb::Vec3d(p.x, p.y, p.z));
    return impl_->vdb->tree().isValueOn(c);
}

Stats OpenVdbVoxels::stats() const {
    Stats s;
    s.set("voxels", double(voxel_count()));
    s.set("bytes", double(bytes()));
    s.set("leaf_nodes", double(leaf_node_count()));
    s.set("build_ms", build_ms());
    return s;
}

}  // namespace gilab
