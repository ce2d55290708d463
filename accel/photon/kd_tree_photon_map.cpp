#include "accel/photon/kd_tree_photon_map.hpp"

#include <algorithm>
#include <numeric>
#include "core/util/error.hpp"

namespace gilab {

size_t left_balanced_left_size(size_t n) {
    if (n <= 1) return 0;
    // h full levels above the last one hold 2^h − 1 nodes; the last level fills from the left.
    size_t h = 0;
    while ((size_t(2) << h) - 1 <= n) ++h;     // largest h with 2^h − 1 ≤ n
    size_t full = (size_t(1) << h) - 1;
    size_t last = n - full;                    // nodes on the partial last level
    size_t half = size_t(1) << (h - 1);        // last-level slots under the left child
    return (half - 1) + std::min(last, half);
}

void KdTreePhotonMap::build_structure(std::vector<Photon> photons, float) {
    const size_t n = photons.size();
    if (n >= (size_t(1) << 31)) throw Error("kd-tree photon map", "too many photons: " + std::to_string(n));
    for (size_t i = 0; i < n; ++i)
        if (!is_finite(photons[i].position))
            throw Error("kd-tree photon map", "photon " + std::to_string(i) + " has a non-finite position");
    nodes_.assign(n, Photon{});
    axes_.assign(n, 0);
    original_.assign(n, 0);
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);

    // Explicit stack of (node, range) so deep trees need no recursion.
    struct Task {
        uint32_t node;
        size_t lo, hi;
    };
    std::vector<Task> tasks;
    if (n > 0) tasks.push_back({1, 0, n});
    while (!tasks.empty()) {
        Task t = tasks.back();
        tasks.pop_back();
        Bounds3 box;
        for (size_t i = t.lo; i < t.hi; ++i) box.extend(photons[order[i]].position);
        Vec3 e = box.extent();
        int axis = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
        size_t median = t.lo + left_balanced_left_size(t.hi - t.lo);
        // Ties broken by input index so the tree does not depend on the sort's internals.
        std::nth_element(order.begin() + std::ptrdiff_t(t.lo), order.begin() + std::ptrdiff_t(median),
                         order.begin() + std::ptrdiff_t(t.hi), [&](uint32_t a, uint32_t b) {
                             float pa = photons[a].position[axis], pb = photons[b].position[axis];
                             return pa < pb || (pa == pb && a < b);
                         });
        nodes_[t.node - 1] = photons[order[median]];
        axes_[t.node - 1] = uint8_t(axis);
        original_[t.node - 1] = order[median];
        if (median > t.lo) tasks.push_back({2 * t.node, t.lo, median});
        if (t.hi > median + 1) tasks.push_back({2 * t.node + 1, median + 1, t.hi});
    }
}

size_t KdTreePhotonMap::memory_bytes() const {
    return nodes_.capacity() * sizeof(Photon) + axes_.capacity() + original_.capacity() * sizeof(uint32_t);
}

}  // namespace gilab
