#pragma once
// Fragment voxelization with per-face attributes, for voxel cone tracing. P3 (§1.1)
// rasterises each triangle into fragments and fuses the fragments of a voxel; here every
// triangle is clipped against every voxel box it may meet (Sutherland–Hodgman, in double)
// and a clipped piece of non-zero area is a fragment. Fragments in one voxel are fused: for
// face f (axis k) a fragment of area A and unit normal n weighs A·|n_k|; the face's
// opacity is Σ A·|n_k| / voxel_area clamped to 1 (projected coverage), its albedo,
// oriented normal, emission and position are the weighted means. Emission counts only
// on the side the triangle's winding normal faces (emitters are one-sided).
//
// Textured triangles: a fragment's albedo and emission are their textures filtered over
// the fragment (looked up at its centroid, at the mip level of its size, so a voxel holds
// the texture's average over its part of the triangle). An alpha-masked fragment weighs
// A times its mask coverage: the mean alpha over the fragment at that level, or, for a
// fragment smaller than a texel, 1 where alpha ≥ the cutoff and 0 elsewhere; a voxel
// that only transparent texels reach therefore stays empty.
//
// Voxels live on an infinite lattice: world voxel v spans anchor + [v, v+1)·voxel_size,
// so the same voxel gets identical values whatever region it is voxelized in (the
// cascades rely on it when they scroll). A triangle lying exactly in a voxel's upper
// face plane belongs to the voxel above. Triangles are summed per voxel in index order
// by one task, so results are identical at any thread count.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>
#include "accel/vct/anisotropic_voxel.hpp"
#include "core/scene/material.hpp"
#include "core/util/math.hpp"
#include "core/scene/scene.hpp"

namespace gilab {

// A box of world voxel coordinates, [begin, end) per axis.
struct VoxelBox {
    IVec3 begin{0}, end{0};
    bool empty() const { return end.x <= begin.x || end.y <= begin.y || end.z <= begin.z; }
    int64_t volume() const {
        return empty() ? 0 : int64_t(end.x - begin.x) * int64_t(end.y - begin.y) * int64_t(end.z - begin.z);
    }
    bool contains(const IVec3& v) const {
        return v.x >= begin.x && v.y >= begin.y && v.z >= begin.z && v.x < end.x && v.y < end.y && v.z < end.z;
    }
    VoxelBox intersect(const VoxelBox& o) const { return {glm::max(begin, o.begin), glm::min(end, o.end)}; }
};

// The lattice: world position of voxel v's minimum corner is anchor + v·voxel_size.
struct VoxelLattice {
    DVec3 anchor{0};
    double voxel_size = 1;
};

struct FragmentVoxelizeStats {
    double ms = 0;
    uint64_t triangles = 0;   // triangles whose box meets the region
    uint64_t clips = 0;       // triangle/voxel clips run
    uint64_t fragments = 0;   // clips that gave a piece of non-zero area
    uint64_t voxels = 0;      // occupied voxels returned
};

class FragmentVoxelizer {
public:
    FragmentVoxelizer() = default;
    // Triangles of the frame's meshes for which include_mesh[m] is true (all meshes when
    // include_mesh is empty). Materials give albedo and emission. Throws Error for a
    // material id out of range or a non-finite vertex.
    FragmentVoxelizer(const SceneFrame& frame, const std::vector<Material>& materials,
                      const std::vector<bool>& include_mesh = {});

    size_t triangle_count() const { return triangles_.size(); }
    Bounds3 bounds() const { return bounds_; }

    // Occupied voxels of `region` on `lattice`, sorted by (z, y, x). Throws Error for a
    // non-positive voxel size.
    std::vector<AnisotropicVoxel> voxelize(const VoxelLattice& lattice, const VoxelBox& region,
                                           FragmentVoxelizeStats* stats = nullptr) const;
    // Streaming form for regions too large to hold as a list: `emit` is called once per
    // occupied voxel, concurrently from worker threads (voxels of one brick of 8³ in
    // (z, y, x) order, bricks in any order).
    using VoxelSink = std::function<void(const AnisotropicVoxel&)>;
    // Voxels inside `exclude` are skipped (a cascade level minus its finer level's box).
    void voxelize_each(const VoxelLattice& lattice, const VoxelBox& region, const VoxelSink& emit,
                       FragmentVoxelizeStats* stats = nullptr, const VoxelBox& exclude = {}) const;
    // Several boxes in one pass (one scan of the triangles): the union of `boxes`.
    void voxelize_each(const VoxelLattice& lattice, std::span<const VoxelBox> boxes, const VoxelSink& emit,
                       FragmentVoxelizeStats* stats = nullptr, const VoxelBox& exclude = {}) const;

private:
    using GroupSink = std::function<void(size_t group, const AnisotropicVoxel&)>;
    void run(const VoxelLattice& lattice, std::span<const VoxelBox> boxes, const VoxelBox& exclude,
             FragmentVoxelizeStats& stats,
             const std::function<void(size_t groups)>& on_groups, const GroupSink& sink) const;

    struct Triangle {
        DVec3 p[3];
        DVec3 normal;        // unit winding normal
        DVec3 lo, hi;        // bounding box
        DVec3 centroid;
        double area;
        Vec3 albedo, emission;
        int32_t textured = -1;  // index into textured_, or −1
    };
    // What a textured triangle's fragments read: its material and its corners' UVs.
    struct TexturedCorners {
        uint32_t material = 0;
        Vec2 uv[kUvSetCount][3]{};
        float uv_per_length[kUvSetCount]{};
    };
    // A fragment's material values and weight factor (mask coverage) at `centroid`.
    void texture_fragment(const Triangle& t, const DVec3& centroid, double area, Vec3& albedo, Vec3& emission,
                          double& coverage) const;
    std::vector<Triangle> triangles_;
    std::vector<TexturedCorners> textured_;
    std::vector<Material> materials_;  // the scene's (textures shared, not copied)
    Bounds3 bounds_;
};

}  // namespace gilab
