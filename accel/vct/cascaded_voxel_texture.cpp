#include "accel/vct/cascaded_voxel_texture.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <mutex>
#include <string>
#include "accel/vct/occupancy_map.hpp"
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

void CascadeConfig::validate() const {
    const std::string where = "cascaded voxel texture";
    if (levels < 1 || levels > 16) throw Error(where, "levels must be 1..16, got " + std::to_string(levels));
    if (resolution < 4 || resolution > 1024 || !std::has_single_bit(unsigned(resolution)))
        throw Error(where, "resolution must be a power of two in 4..1024, got " + std::to_string(resolution));
    if (!(voxel_size > 0) || !std::isfinite(voxel_size))
        throw Error(where, "voxel size must be positive and finite, got " + std::to_string(voxel_size));
    if (!std::isfinite(anchor.x) || !std::isfinite(anchor.y) || !std::isfinite(anchor.z))
        throw Error(where, "anchor must be finite");
    // Per cell an RGBA16F radiance value; per texel at most three G-buffer records with
    // their bits, and an occupancy bit.
    double cells = double(levels) * double(resolution) * double(resolution) * double(resolution) * kFaceCount;
    if (cells * (8.0 + 37.0 / kFaceCount) > double(size_t(8) << 30))
        throw Error(where, std::to_string(levels) + " levels of " + std::to_string(resolution) +
                               "³ would need more than 8 GiB");
}

CascadedVoxelTexture::CascadedVoxelTexture(const CascadeConfig& config) : config_(config) {
    config_.validate();
    origins_.assign(size_t(config_.levels), IVec3(-config_.resolution / 2));
    own_inner_.assign(size_t(config_.levels), VoxelBox{});
    gbuffer_.assign(size_t(config_.levels), SparseGBuffer(texels_per_level()));
    radiance.assign(cell_count(), HalfRGBA{});
    occupancy_.assign(size_t(config_.levels) * occupancy_words(), ~uint64_t(0));
}

VoxelBox CascadedVoxelTexture::region(int level) const {
    IVec3 o = origins_.at(size_t(level));
    return {o, o + IVec3(config_.resolution)};
}

IVec3 CascadedVoxelTexture::origin_for(const DVec3& viewer, int level) const {
    DVec3 q = to_level_space(viewer, level);
    IVec3 centre;
    for (int k = 0; k < 3; ++k) centre[k] = 2 * int(std::floor(q[k] * 0.5 + 0.5));
    return centre - IVec3(config_.resolution / 2);
}

IVec3 CascadedVoxelTexture::world_to_voxel(const DVec3& p, int level) const {
    DVec3 q = glm::floor(to_level_space(p, level));
    return IVec3(int(q.x), int(q.y), int(q.z));
}

DVec3 CascadedVoxelTexture::voxel_center(const IVec3& v, int level) const {
    return config_.anchor + (DVec3(v) + DVec3(0.5)) * voxel_size(level);
}

int CascadedVoxelTexture::finest_level_containing(const DVec3& p, double margin) const {
    for (int k = 0; k < config_.levels; ++k) {
        DVec3 q = to_level_space(p, k) - DVec3(origins_[size_t(k)]);
        const double hi = double(config_.resolution) - margin;
        if (q.x >= margin && q.y >= margin && q.z >= margin && q.x < hi && q.y < hi && q.z < hi) return k;
    }
    return -1;
}

IVec3 CascadedVoxelTexture::voxel_at_texel(int level, const UVec3& texel) const {
    const IVec3 o = origins_.at(size_t(level));
    const int R = config_.resolution, mask = R - 1;
    IVec3 v;
    for (int k = 0; k < 3; ++k) v[k] = o[k] + ((int(texel[k]) - o[k]) & mask);
    return v;
}

VoxelBox CascadedVoxelTexture::inner_box(int level) const {
    if (level <= 0) return {};
    VoxelBox finer = region(level - 1);
    VoxelBox box{IVec3(floor_div(finer.begin.x, 2), floor_div(finer.begin.y, 2), floor_div(finer.begin.z, 2)),
                 IVec3(floor_div(finer.end.x + 1, 2), floor_div(finer.end.y + 1, 2), floor_div(finer.end.z + 1, 2))};
    return box.intersect(region(level));
}

void CascadedVoxelTexture::place(int level, const IVec3& origin) {
    if (level < 0 || level >= config_.levels) throw Error("cascaded voxel texture", "no level " + std::to_string(level));
    origins_[size_t(level)] = origin;
    own_inner_[size_t(level)] = VoxelBox{};
    // Whole level: one z slice per task.
    const int R = config_.resolution;
    gilab::parallel_for(size_t(R), 1, [&](size_t z0, size_t z1) {
        for (size_t z = z0; z < z1; ++z) {
            const size_t first = index(0, level, UVec3(0, 0, uint32_t(z))), n = size_t(R) * size_t(R) * kFaceCount;
            std::fill_n(radiance.begin() + ptrdiff_t(first), n, HalfRGBA{});
        }
    });
    gbuffer_[size_t(level)].clear();
    std::fill_n(occupancy_.begin() + ptrdiff_t(size_t(level) * occupancy_words()), occupancy_words(), ~uint64_t(0));
}

namespace {

// Calls fn(v) for every voxel of the box, z outermost.
template <class Fn>
void for_each_voxel(const VoxelBox& box, Fn&& fn) {
    for (int z = box.begin.z; z < box.end.z; ++z)
        for (int y = box.begin.y; y < box.end.y; ++y)
            for (int x = box.begin.x; x < box.end.x; ++x) fn(IVec3(x, y, z));
}

}  // namespace

// Calls fn(first_cell, count) for every contiguous run of cells (one texel row, all six
// faces) that the box's voxels occupy; a row wraps around the toroidal storage at most once.
template <class Fn>
void CascadedVoxelTexture::for_each_run(int level, const VoxelBox& box, Fn&& fn) const {
    const VoxelBox b = box.intersect(region(level));
    if (b.empty()) return;
    const int R = config_.resolution, mask = R - 1;
    const int x0 = b.begin.x & mask, nx = b.end.x - b.begin.x;
    const int first = std::min(nx, R - x0), second = nx - first;
    for (int z = b.begin.z; z < b.end.z; ++z)
        for (int y = b.begin.y; y < b.end.y; ++y) {
            const UVec3 t(uint32_t(x0), uint32_t(y & mask), uint32_t(z & mask));
            fn(index(0, level, t), size_t(first) * kFaceCount);
            if (second > 0) fn(index(0, level, UVec3(0, t.y, t.z)), size_t(second) * kFaceCount);
        }
}

void CascadedVoxelTexture::clear_gbuffer(int level, const VoxelBox& box) {
    SparseGBuffer& g = gbuffer_[size_t(level)];
    if (g.records() == 0) return;
    for_each_voxel(box.intersect(region(level)), [&](const IVec3& v) { g.erase(texel_index(v)); });
    g.commit();
}

void CascadedVoxelTexture::clear_radiance(int level, const VoxelBox& box) {
    for_each_run(level, box, [&](size_t i, size_t n) {
        std::fill_n(radiance.begin() + ptrdiff_t(i), n, HalfRGBA{});
    });
}

std::vector<VoxelBox> CascadedVoxelTexture::scroll(int level, const IVec3& new_origin) {
    if (level < 0 || level >= config_.levels) throw Error("cascaded voxel texture", "no level " + std::to_string(level));
    const VoxelBox old_box = region(level);
    origins_[size_t(level)] = new_origin;
    const VoxelBox new_box = region(level);
    std::vector<VoxelBox> exposed;
    if (old_box.intersect(new_box).empty()) {
        exposed.push_back(new_box);
    } else {
        // Peel one axis at a time: the slab outside the old box along x, then along y
        // within the old x range, then along z within the old x and y ranges.
        VoxelBox rest = new_box;
        for (int k = 0; k < 3; ++k) {
            if (rest.begin[k] < old_box.begin[k]) {
                VoxelBox slab = rest;
                slab.end[k] = old_box.begin[k];
                exposed.push_back(slab);
                rest.begin[k] = old_box.begin[k];
            }
            if (rest.end[k] > old_box.end[k]) {
                VoxelBox slab = rest;
                slab.begin[k] = old_box.end[k];
                exposed.push_back(slab);
                rest.end[k] = old_box.end[k];
            }
        }
    }
    const bool has_coarser = level + 1 < config_.levels;
    // The exposed texels take new opacity: nothing is skipped until the next refresh.
    std::fill_n(occupancy_.begin() + ptrdiff_t(size_t(level) * occupancy_words()), occupancy_words(), ~uint64_t(0));
    for (const VoxelBox& box : exposed) {
        clear_gbuffer(level, box);
        for_each_voxel(box, [&](const IVec3& v) {
            const IVec3 parent(floor_div(v.x, 2), floor_div(v.y, 2), floor_div(v.z, 2));
            const bool fill = has_coarser && contains(level + 1, parent);
            for (int f = 0; f < kFaceCount; ++f) {
                size_t i = index_of_voxel(f, level, v);
                radiance[i] = fill ? radiance[index_of_voxel(f, level + 1, parent)] : HalfRGBA{};
            }
        });
    }
    return exposed;
}

void CascadedVoxelTexture::write(int level, const AnisotropicVoxel& voxel) {
    if (!contains(level, voxel.coord))
        throw Error("cascaded voxel texture", "voxel outside level " + std::to_string(level) + "'s region");
    SparseGBuffer& g = gbuffer_[size_t(level)];
    g.stage(texel_index(voxel.coord), pack_voxel(voxel, lattice(level)));
    g.commit();
}

const PackedSurface* CascadedVoxelTexture::gbuffer_axis(int level, const IVec3& v, int axis) const {
    if (!contains(level, v)) return nullptr;
    return gbuffer_[size_t(level)].find(texel_index(v), axis);
}

PackedVoxel CascadedVoxelTexture::gbuffer_voxel(int level, const IVec3& v) const {
    PackedVoxel p;
    for (int axis = 0; axis < 3; ++axis)
        if (const PackedSurface* s = gbuffer_axis(level, v, axis)) p.axis[size_t(axis)] = *s;
    return p;
}

float CascadedVoxelTexture::opacity_of_cell(size_t cell) const {
    if (cell >= cell_count()) throw Error("cascaded voxel texture", "no cell " + std::to_string(cell));
    const size_t level = cell / level_cells(), texel = (cell % level_cells()) / kFaceCount;
    const PackedSurface* s = gbuffer_[level].find(texel, int(cell % kFaceCount) >> 1);
    return s ? unpack_opacity(*s) : 0.0f;
}

FragmentVoxelizeStats CascadedVoxelTexture::voxelize_boxes(int level, const FragmentVoxelizer& voxelizer,
                                                           const std::vector<VoxelBox>& boxes,
                                                           const VoxelBox& exclude) {
    FragmentVoxelizeStats stats;
    std::mutex stage_lock;  // the voxelizer emits from worker threads; staging is one at a time
    const VoxelLattice on = lattice(level);
    SparseGBuffer& g = gbuffer_[size_t(level)];
    voxelizer.voxelize_each(on, boxes, [&](const AnisotropicVoxel& v) {
        const PackedVoxel packed = pack_voxel(v, on);  // outside the lock
        const size_t texel = texel_index(v.coord);
        const std::lock_guard<std::mutex> hold(stage_lock);
        g.stage(texel, packed);
    }, &stats, exclude);
    g.commit();
    return stats;
}

FragmentVoxelizeStats CascadedVoxelTexture::voxelize(int level, const FragmentVoxelizer& voxelizer,
                                                     const VoxelBox& box) {
    const VoxelBox b = box.intersect(region(level));
    clear_gbuffer(level, b);
    if (b.empty()) return {};
    return voxelize_boxes(level, voxelizer, {b}, VoxelBox{});
}

std::vector<VoxelBox> subtract(const VoxelBox& a, const VoxelBox& b) {
    std::vector<VoxelBox> out;
    if (a.empty()) return out;
    if (a.intersect(b).empty()) {
        out.push_back(a);
        return out;
    }
    VoxelBox rest = a;
    for (int k = 0; k < 3; ++k) {
        if (rest.begin[k] < b.begin[k]) {
            VoxelBox slab = rest;
            slab.end[k] = b.begin[k];
            out.push_back(slab);
            rest.begin[k] = b.begin[k];
        }
        if (rest.end[k] > b.end[k]) {
            VoxelBox slab = rest;
            slab.begin[k] = b.end[k];
            out.push_back(slab);
            rest.end[k] = b.end[k];
        }
    }
    return out;
}

FragmentVoxelizeStats CascadedVoxelTexture::voxelize_own(int level, const FragmentVoxelizer& voxelizer,
                                                         const VoxelBox& box) {
    const VoxelBox inner = inner_box(level);
    own_inner_[size_t(level)] = inner;
    const VoxelBox b = box.intersect(region(level));
    clear_gbuffer(level, b);
    if (b.empty()) return {};
    return voxelize_boxes(level, voxelizer, {b}, inner);
}

FragmentVoxelizeStats CascadedVoxelTexture::follow_inner(int level, const FragmentVoxelizer& voxelizer,
                                                         const std::vector<VoxelBox>& exposed) {
    FragmentVoxelizeStats stats;
    const VoxelBox old_inner = own_inner_[size_t(level)].intersect(region(level));
    const VoxelBox inner = inner_box(level);
    own_inner_[size_t(level)] = inner;
    std::vector<VoxelBox> pending;
    for (const VoxelBox& b : exposed) pending.push_back(b.intersect(region(level)));
    if (!(old_inner.begin == inner.begin && old_inner.end == inner.end)) {
        for (const VoxelBox& part : subtract(inner, old_inner)) clear_gbuffer(level, part);
        for (const VoxelBox& part : subtract(old_inner, inner)) {
            clear_gbuffer(level, part);
            pending.push_back(part);
        }
    }
    if (pending.empty()) return stats;
    return voxelize_boxes(level, voxelizer, pending, inner);
}

bool CascadedVoxelTexture::occupied(int level, const IVec3& v) const {
    return contains(level, v) && gbuffer_[size_t(level)].occupied(texel_index(v));
}

size_t CascadedVoxelTexture::occupied_voxels(int level) const { return occupied_in(level, region(level)).size(); }

std::vector<IVec3> CascadedVoxelTexture::occupied_in(int level, const VoxelBox& box) const {
    std::vector<IVec3> out;
    for_each_voxel(box.intersect(region(level)), [&](const IVec3& v) {
        if (occupied(level, v)) out.push_back(v);
    });
    return out;
}

void CascadedVoxelTexture::downsample(int level, std::vector<HalfRGBA>& buffer) const {
    const VoxelBox box = inner_box(level);
    if (box.empty()) return;
    const int zs = box.end.z - box.begin.z;
    parallel_for(size_t(zs), 1, [&](size_t z0, size_t z1) {
        for (size_t dz = z0; dz < z1; ++dz) {
            const int z = box.begin.z + int(dz);
            for (int y = box.begin.y; y < box.end.y; ++y)
                for (int x = box.begin.x; x < box.end.x; ++x) {
                    const IVec3 v(x, y, z);
                    // The eight children with all six faces, decoded once.
                    std::array<std::array<Vec4, 8>, kFaceCount> children{};
                    for (int c = 0; c < 8; ++c) {
                        const IVec3 child = 2 * v + IVec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
                        if (!contains(level - 1, child)) continue;
                        const size_t first = index_of_voxel(0, level - 1, child);
                        for (int f = 0; f < kFaceCount; ++f)
                            children[size_t(f)][size_t(c)] = from_half_rgba(buffer[first + size_t(f)]);
                    }
                    const size_t out = index_of_voxel(0, level, v);
                    for (int f = 0; f < kFaceCount; ++f)
                        buffer[out + size_t(f)] = to_half_rgba(downsample_face(f, children[size_t(f)]));
                }
        }
    });
}

void CascadedVoxelTexture::refresh_occupancy(int level, const std::vector<HalfRGBA>& buffer) {
    build_occupancy_map(buffer.data() + size_t(level) * level_cells(), config_.resolution, true,
                        occupancy_.data() + size_t(level) * occupancy_words());
}

size_t CascadedVoxelTexture::gbuffer_bytes() const {
    size_t bytes = 0;
    for (const SparseGBuffer& g : gbuffer_) bytes += g.bytes();
    return bytes;
}

size_t CascadedVoxelTexture::occupancy_encoding_bytes() const {
    size_t bytes = 0;
    for (const SparseGBuffer& g : gbuffer_) bytes += g.occupancy_bytes();
    return bytes;
}

size_t CascadedVoxelTexture::radiance_bytes() const {
    return radiance.size() * sizeof(HalfRGBA) + occupancy_.size() * sizeof(uint64_t);
}

}  // namespace gilab
