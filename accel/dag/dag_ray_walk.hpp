#pragma once
// The first-hit octree walk of Laine & Karras 2010 (ESVO, appendix) shared by the DAG ray
// casters (dag_ray_caster.hpp, symmetric_dag_ray_caster.hpp): single precision in the [1,2]³
// cube, the ray mirrored so that it runs towards −x, −y, −z, children entered front to
// back with no sorting, a step to a neighbour one comparison per axis, and a pop that
// finds the ancestor to resume from the highest differing bit of the position.
//
// A DAG format plugs in its nodes through `Nodes`:
//   DagWalkNode root() const;
//   uint32_t mask(DagWalkNode node, bool voxel_parent) const;   // 8-bit child mask
//   DagWalkNode child(DagWalkNode node, uint32_t mask, uint32_t stored_slot, int level) const;
// voxel_parent: the node's children are voxels; level: the node's, 0 at the root. A node
// may be stored transformed (symmetric_dag.hpp): `child` returns the pointer's own
// transform, and the walk composes the transforms along the path. A format whose
// transforms are more than reflections gives the group's rules as well:
//   static uint32_t compose(uint32_t a, uint32_t b);            // b first, then a
//   static uint32_t source_slot(uint32_t transform, uint32_t slot);
// (the stored slot holding the cell in `slot` of a node seen through `transform`).
// Without them transforms are 3-bit mirrors: composing is XOR and the cell in slot k of
// a node seen through mirror m is its stored slot k ^ m. Formats without transforms
// return 0, which the compiler folds away.
#include <algorithm>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstdint>
#include "accel/dag/voxel_ray_traversal.hpp"

namespace gilab {

struct DagWalkNode {
    uint32_t address = 0;
    uint32_t transform = 0;  // for mirrors, bit a: reflected along axis a
};

namespace dag_walk {
template <class Nodes>
concept HasGroupRules = requires(uint32_t t) {
    { Nodes::compose(t, t) } -> std::convertible_to<uint32_t>;
    { Nodes::source_slot(t, t) } -> std::convertible_to<uint32_t>;
};
template <class Nodes>
inline uint32_t compose(uint32_t a, uint32_t b) {
    if constexpr (HasGroupRules<Nodes>) return Nodes::compose(a, b);
    else return a ^ b;
}
template <class Nodes>
inline uint32_t source_slot(uint32_t transform, uint32_t slot) {
    if constexpr (HasGroupRules<Nodes>) return Nodes::source_slot(transform, slot);
    else return slot ^ transform;
}
// Positions live in [1,2), where a float's mantissa bit k stands for a cell of size
// 2^(k − 23): scale k is the level whose cells have that size.
inline constexpr int kMaxScale = 23;
inline uint32_t bits_of(float f) { return std::bit_cast<uint32_t>(f); }
inline float float_of(uint32_t b) { return std::bit_cast<float>(b); }
}  // namespace dag_walk

// Nearest voxel along the ray between ray.tmin and ray.tmax in the octree of `depth`
// levels below the root laid over `grid`.
template <class Nodes>
VoxelRayHit walk_dag_ray(const Nodes& nodes, const VoxelGrid& grid, int depth, const Ray& ray) {
    using namespace dag_walk;
    VoxelRayHit out;
    // The octree's cube (2^depth voxels per axis) mapped to [1,2]³. The map is affine,
    // so ray parameters are unchanged; it is done in double so that large scenes keep
    // their precision up to the final rounding.
    const double cube = grid.voxel_size() * std::ldexp(1.0, depth);
    const double inv_cube = 1.0 / cube;
    const DVec3 origin = 1.0 + (DVec3(ray.origin) - DVec3(grid.origin)) * inv_cube;
    const DVec3 direction = DVec3(ray.direction) * inv_cube;
    const float min_component = std::ldexp(1.0f, -kMaxScale);

    // t on axis k at coordinate x is x·coef[k] − bias[k]. Axes with a positive direction
    // are mirrored (x → 3 − x), so the walk always runs towards −x, −y, −z; `ray_mirror`
    // turns a mirrored child index back into the cell's slot.
    float coef[3], bias[3];
    uint32_t ray_mirror = 0;
    for (int k = 0; k < 3; ++k) {
        float d = float(direction[k]);
        if (std::abs(d) < min_component) d = std::copysign(min_component, d);
        coef[k] = 1.0f / -std::abs(d);
        bias[k] = coef[k] * float(origin[k]);
        if (d > 0) {
            ray_mirror |= 1u << k;
            bias[k] = 3.0f * coef[k] - bias[k];
        }
    }
    float t_min = std::max({2 * coef[0] - bias[0], 2 * coef[1] - bias[1], 2 * coef[2] - bias[2]});
    float t_max = std::min({coef[0] - bias[0], coef[1] - bias[1], coef[2] - bias[2]});
    t_min = std::max(t_min, ray.tmin);
    t_max = std::min(t_max, ray.tmax);
    if (!(t_min <= t_max)) return out;
    out.nodes_visited = 1;  // the root
    if (depth == 0) {       // a single voxel: the root itself
        out.hit = true;
        out.voxel = UVec3(0);
        out.t = t_min;
        return out;
    }

    struct StackEntry {
        DagWalkNode parent;  // with the transform composed from the root
        float t_max;
    };
    const int voxel_scale = kMaxScale - depth;
    StackEntry stack[kMaxScale + 1];
    DagWalkNode parent = nodes.root();
    int scale = kMaxScale - 1;
    uint32_t mask = nodes.mask(parent, scale == voxel_scale);
    float scale_exp2 = 0.5f;  // side of a child at `scale`
    float pos[3] = {1.0f, 1.0f, 1.0f};  // minimum corner of the current child, mirrored
    uint32_t idx = 0;                   // the current child, mirrored
    for (int k = 0; k < 3; ++k)
        if (1.5f * coef[k] - bias[k] > t_min) idx ^= 1u << k, pos[k] = 1.5f;

    while (scale < kMaxScale) {
        const float tc[3] = {pos[0] * coef[0] - bias[0], pos[1] * coef[1] - bias[1], pos[2] * coef[2] - bias[2]};
        const float tc_max = std::min({tc[0], tc[1], tc[2]});  // where the ray leaves the child
        const uint32_t stored_slot = source_slot<Nodes>(parent.transform, idx ^ ray_mirror);
        if ((mask >> stored_slot) & 1u) {
            const float tv_max = std::min(t_max, tc_max);
            if (t_min <= tv_max) {
                ++out.nodes_visited;
                if (scale == voxel_scale) {
                    float first[3];
                    for (int k = 0; k < 3; ++k)
                        first[k] = (ray_mirror >> k) & 1u ? 3.0f - scale_exp2 - pos[k] : pos[k];
                    out.hit = true;
                    out.t = t_min;
                    out.voxel = UVec3(uint32_t(std::ldexp(first[0] - 1.0f, depth)),
                                      uint32_t(std::ldexp(first[1] - 1.0f, depth)),
                                      uint32_t(std::ldexp(first[2] - 1.0f, depth)));
                    return out;
                }
                // Push: descend into the child, remembering where to resume.
                stack[scale] = {parent, t_max};
                const DagWalkNode child = nodes.child(parent, mask, stored_slot, kMaxScale - 1 - scale);
                parent = {child.address, compose<Nodes>(parent.transform, child.transform)};
                const float half = scale_exp2 * 0.5f;
                --scale;
                scale_exp2 = half;
                mask = nodes.mask(parent, scale == voxel_scale);
                // Branch-free: the half the ray enters on each axis (these branches would
                // be mispredicted about half the time).
                const uint32_t upper[3] = {half * coef[0] + tc[0] > t_min, half * coef[1] + tc[1] > t_min,
                                           half * coef[2] + tc[2] > t_min};
                idx = upper[0] | upper[1] << 1 | upper[2] << 2;
                for (int k = 0; k < 3; ++k) pos[k] += upper[k] ? half : 0.0f;
                t_max = tv_max;
                continue;
            }
        }
        // Advance to the neighbour the ray enters next.
        const uint32_t crossed[3] = {tc[0] <= tc_max, tc[1] <= tc_max, tc[2] <= tc_max};
        const uint32_t step = crossed[0] | crossed[1] << 1 | crossed[2] << 2;
        for (int k = 0; k < 3; ++k) pos[k] -= crossed[k] ? scale_exp2 : 0.0f;
        t_min = tc_max;
        idx ^= step;
        if (t_min > ray.tmax) break;
        if (idx & step) {
            // Pop: the step left the parent. The highest bit in which the old and new
            // positions differ names the level of the common ancestor (above the voxels'
            // parents, so its children are nodes).
            uint32_t differing = 0;
            for (int k = 0; k < 3; ++k)
                differing |= (bits_of(pos[k]) ^ bits_of(pos[k] + scale_exp2)) & (0u - crossed[k]);
            scale = int(bits_of(float(differing)) >> 23) - 127;
            if (scale >= kMaxScale) break;  // left the root
            scale_exp2 = float_of(uint32_t(scale - kMaxScale + 127) << 23);
            parent = stack[scale].parent;
            t_max = stack[scale].t_max;
            mask = nodes.mask(parent, false);
            idx = 0;
            for (int k = 0; k < 3; ++k) {
                const uint32_t shifted = bits_of(pos[k]) >> scale;
                pos[k] = float_of(shifted << scale);
                idx |= (shifted & 1u) << k;
            }
        }
    }
    return out;
}

}  // namespace gilab
