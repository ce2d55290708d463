#include "accel/dag/voxel_ray_traversal.hpp"
#include <utility>
#include "accel/dag/child_mask.hpp"
#include "accel/dag/esvo.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"

namespace gilab {
namespace {

struct SvoAccess {
    const Svo& s;
    uint8_t mask(uint32_t n) const { return s.mask(n); }
    uint32_t child(uint32_t n, int slot) const { return s.child(n, slot); }
};
struct EsvoAccess {
    const Esvo& s;
    uint8_t mask(uint32_t n) const { return s.valid_mask(n); }
    uint32_t child(uint32_t n, int slot) const { return s.child(n, slot); }
};
struct SvdagAccess {
    const Svdag& s;
    uint8_t mask(uint32_t n) const { return s.mask(n); }
    uint32_t child(uint32_t n, int slot) const { return s.child(n, slot); }
};
// The same word format read straight from the words: per node a word with the child
// mask, then one word address per non-empty child.
struct WordsAccess {
    std::span<const uint32_t> words;
    uint8_t mask(uint32_t n) const { return static_cast<uint8_t>(words[n] & 0xffu); }
    uint32_t child(uint32_t n, int slot) const {
        const uint32_t m = words[n] & 0xffu;
        if (!(m & (1u << slot))) return 0xffffffffu;
        return words[n + 1 + child_rank(m, slot)];
    }
};

template <class Tree>
VoxelRayHit traverse(const Tree& tree, const VoxelGrid& grid, int depth, bool empty, uint32_t root, const Ray& ray) {
    VoxelRayHit result;
    if (empty) return result;
    // Voxel space: the map is affine, so ray parameters t are unchanged.
    const double scale = double(grid.resolution) / double(grid.extent);
    const DVec3 o = (DVec3(ray.origin) - DVec3(grid.origin)) * scale;
    const DVec3 d = DVec3(ray.direction) * scale;
    DVec3 inv(0);
    uint32_t dir_mask = 0;
    for (int k = 0; k < 3; ++k) {
        if (d[k] != 0) inv[k] = 1.0 / d[k];
        if (d[k] < 0) dir_mask |= 1u << k;
    }
    auto slab = [&](const UVec3& first, double size, double& t0, double& t1) {
        t0 = ray.tmin;
        t1 = ray.tmax;
        for (int k = 0; k < 3; ++k) {
            double lo = double(first[k]), hi = lo + size;
            if (d[k] == 0) {
                if (o[k] < lo || o[k] > hi) return false;
                continue;
            }
            double a = (lo - o[k]) * inv[k], b = (hi - o[k]) * inv[k];
            if (a > b) std::swap(a, b);
            t0 = std::max(t0, a);
            t1 = std::min(t1, b);
        }
        return t0 <= t1;
    };

    struct Entry {
        uint32_t node;
        int level;
        UVec3 first;
        double t0;
    };
    Entry stack[8 * 24];
    int sp = 0;
    double t0, t1;
    if (!slab(UVec3(0), double(uint64_t(1) << depth), t0, t1)) return result;
    stack[sp++] = {root, 0, UVec3(0), t0};
    while (sp > 0) {
        const Entry e = stack[--sp];
        ++result.nodes_visited;
        if (e.level == depth) {
            result.hit = true;
            result.voxel = e.first;
            result.t = float(e.t0);
            return result;
        }
        const uint8_t mask = tree.mask(e.node);
        const uint32_t half = 1u << (depth - e.level - 1);
        Entry near[8];
        int n = 0;
        // Visiting slots in the order i ^ dir_mask is front to back: a ray passes the
        // children of a node in increasing order of their mirrored slot numbers.
        for (uint32_t i = 0; i < 8; ++i) {
            const int slot = int(i ^ dir_mask);
            if (!(mask & (1u << slot))) continue;
            UVec3 first = e.first + UVec3(slot & 1, (slot >> 1) & 1, (slot >> 2) & 1) * half;
            if (!slab(first, double(half), t0, t1)) continue;
            near[n++] = {tree.child(e.node, slot), e.level + 1, first, t0};
        }
        while (n > 0) stack[sp++] = near[--n];
    }
    return result;
}

}  // namespace

VoxelRayHit trace_voxel_ray(const Svo& svo, const Ray& ray) {
    return traverse(SvoAccess{svo}, svo.grid(), svo.depth(), svo.empty(), svo.root(), ray);
}

VoxelRayHit trace_voxel_ray(const Esvo& esvo, const Ray& ray) {
    return traverse(EsvoAccess{esvo}, esvo.grid(), esvo.depth(), esvo.empty(), esvo.root(), ray);
}

VoxelRayHit trace_voxel_ray(const Svdag& dag, const Ray& ray) {
    return traverse(SvdagAccess{dag}, dag.grid(), dag.depth(), dag.empty(), dag.root(), ray);
}

VoxelRayHit trace_voxel_ray(const DagWordsView& dag, const Ray& ray) {
    return traverse(WordsAccess{dag.words}, dag.grid, dag.depth, dag.empty, dag.root, ray);
}

}  // namespace gilab
