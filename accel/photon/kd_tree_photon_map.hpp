#pragma once
// Jensen's photon-map kd-tree: a left-balanced (complete) binary tree stored in an array
// without pointers. Node i (1-based) has children 2i and 2i+1; every node holds one
// photon and splits its subtree at the median photon on the longest axis of the
// subtree's bounding box.
#include <cstdint>
#include <vector>
#include "accel/photon/photon_map.hpp"

namespace gilab {

class KdTreePhotonMap final : public PhotonMap {
public:
    static constexpr PhotonMapKind kKind = PhotonMapKind::KdTree;
    PhotonMapKind kind() const override { return kKind; }
    size_t size() const override { return nodes_.size(); }
    const Photon& photon(uint32_t index) const override { return nodes_[index]; }
    uint32_t original_index(uint32_t index) const override { return original_[index]; }
    size_t memory_bytes() const override;

    void radius_query(const Vec3& x, float r, Visitor visit, PhotonQueryStats& stats) const override {
        for_each_in_radius(x, r, visit, stats);
    }
    void knn_query(const Vec3& x, size_t k, float max_r, NeighborHeap& heap, PhotonQueryStats& stats) const override {
        knn(x, k, max_r, heap, stats);
    }

    // Storage index i holds tree node i + 1. Split axis of storage index i (0, 1, 2).
    int split_axis(uint32_t index) const { return axes_[index]; }

    template <typename Visit>
    void for_each_in_radius(const Vec3& x, float r, Visit&& visit, PhotonQueryStats& stats) const {
        ++stats.queries;
        if (nodes_.empty() || !(r >= 0.0f)) return;
        const float r2 = r * r;
        // Iterative depth-first walk with an explicit stack of 1-based node ids.
        uint32_t stack[64];
        int top = 0;
        stack[top++] = 1;
        const uint32_t n = uint32_t(nodes_.size());
        uint64_t visited = 0, inside = 0;
        while (top > 0) {
            uint32_t node = stack[--top];
            const Photon& p = nodes_[node - 1];
            if (2 * node <= n) {  // interior: near child first, far child if the plane is within r
                int axis = axes_[node - 1];
                float delta = x[axis] - p.position[axis];
                uint32_t near_child = delta < 0.0f ? 2 * node : 2 * node + 1;
                uint32_t far_child = near_child ^ 1u;
                // A node with one child has only the left one (2i); the right may be missing.
                if (delta * delta <= r2 && far_child <= n) stack[top++] = far_child;
                if (near_child <= n) stack[top++] = near_child;
            }
            ++visited;
            float d2 = photon_distance2(x, p.position.x, p.position.y, p.position.z);
            if (d2 <= r2) {
                ++inside;
                visit(node - 1, d2);
            }
        }
        stats.visited += visited;
        stats.inside += inside;
    }

    // k nearest within max_r; `accept(index)` filters candidates before they compete.
    template <typename Accept = std::nullptr_t>
    void knn(const Vec3& x, size_t k, float max_r, NeighborHeap& heap, PhotonQueryStats& stats,
             Accept accept = nullptr) const {
        ++stats.queries;
        heap.reset(k, max_r * max_r);
        if (nodes_.empty() || k == 0 || !(max_r >= 0.0f)) return;
        const float max_r2 = max_r * max_r;
        // Recursion order as in Jensen's locate_photons: descend the near side first so
        // the heap fills with close photons and its root prunes the far sides early.
        struct Entry {
            uint32_t node;
            float plane_distance2;  // far-side entries are skipped if this exceeds the bound
        };
        Entry stack[64];
        int top = 0;
        stack[top++] = {1, 0.0f};
        const uint32_t n = uint32_t(nodes_.size());
        uint64_t visited = 0, inside = 0;
        while (top > 0) {
            Entry e = stack[--top];
            if (e.plane_distance2 > heap.bound2()) continue;
            uint32_t node = e.node;
            const Photon& p = nodes_[node - 1];
            if (2 * node <= n) {
                int axis = axes_[node - 1];
                float delta = x[axis] - p.position[axis];
                uint32_t near_child = delta < 0.0f ? 2 * node : 2 * node + 1;
                uint32_t far_child = near_child ^ 1u;
                float plane2 = delta * delta;
                if (plane2 <= heap.bound2() && far_child <= n) stack[top++] = {far_child, plane2};
                if (near_child <= n) stack[top++] = {near_child, 0.0f};
            }
            ++visited;
            float d2 = photon_distance2(x, p.position.x, p.position.y, p.position.z);
            if (d2 <= max_r2) {
                ++inside;
                if constexpr (std::is_same_v<Accept, std::nullptr_t>) {
                    heap.offer(node - 1, d2);
                } else {
                    if (accept(node - 1)) heap.offer(node - 1, d2);
                }
            }
        }
        stats.visited += visited;
        stats.inside += inside;
    }

protected:
    void build_structure(std::vector<Photon> photons, float radius) override;

private:
    std::vector<Photon> nodes_;       // node i + 1 at index i
    std::vector<uint8_t> axes_;
    std::vector<uint32_t> original_;
};

// Number of nodes in the left subtree of a left-balanced tree of n nodes.
size_t left_balanced_left_size(size_t n);

}  // namespace gilab
