// Jensen's left-balanced kd-tree photon map: the array is a complete binary tree split at
// the median on the longest axis; radius queries and kNN (max-heap) equal brute force.
#include <gtest/gtest.h>

#include "accel/photon/kd_tree_photon_map.hpp"
#include "core/util/error.hpp"
#include "tests/photon_test_data.hpp"

namespace gilab {
namespace {

TEST(KdTree, LeftSubtreeSizeMakesACompleteTree) {
    // n = 1..: the left subtree of a complete tree, counted directly by heap indices.
    for (size_t n = 1; n < 300; ++n) {
        size_t left = 0;
        for (size_t level = 2; level <= n; level *= 2)
            for (size_t i = level; i < level + level / 2 && i <= n; ++i) ++left;
        EXPECT_EQ(left_balanced_left_size(n), left) << "n=" << n;
    }
}

TEST(KdTree, TreeIsBalancedAndOrdered) {
    const auto photons = test::random_photons(1234, 3);
    KdTreePhotonMap tree;
    tree.build(photons);
    ASSERT_EQ(tree.size(), photons.size());
    std::vector<bool> seen(photons.size(), false);
    for (uint32_t i = 0; i < tree.size(); ++i) {
        ASSERT_LT(tree.original_index(i), photons.size());
        EXPECT_FALSE(seen[tree.original_index(i)]);
        seen[tree.original_index(i)] = true;
        EXPECT_EQ(tree.photon(i).position, photons[tree.original_index(i)].position);
    }
    // Every node splits its subtree: left descendants ≤ split value ≤ right descendants.
    const uint32_t n = uint32_t(tree.size());
    for (uint32_t node = 1; node <= n; ++node) {
        int axis = tree.split_axis(node - 1);
        float split = tree.photon(node - 1).position[axis];
        std::vector<uint32_t> stack;
        for (uint32_t child : {2 * node, 2 * node + 1}) {
            if (child > n) continue;
            bool left = child == 2 * node;
            stack.assign(1, child);
            while (!stack.empty()) {
                uint32_t c = stack.back();
                stack.pop_back();
                float v = tree.photon(c - 1).position[axis];
                if (left) {
                    ASSERT_LE(v, split) << "node " << node;
                } else {
                    ASSERT_GE(v, split) << "node " << node;
                }
                for (uint32_t g : {2 * c, 2 * c + 1})
                    if (g <= n) stack.push_back(g);
            }
        }
    }
    // The root splits on the longest axis of all photons.
    Bounds3 box;
    for (const Photon& p : photons) box.extend(p.position);
    Vec3 e = box.extent();
    int longest = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
    EXPECT_EQ(tree.split_axis(0), longest);
}

TEST(KdTree, RadiusQueryEqualsBruteForce) {
    const auto photons = test::random_photons(4000, 9);
    KdTreePhotonMap tree;
    tree.build(photons);
    for (float r : {0.0f, 0.02f, 0.05f, 0.1f, 0.2f, 0.5f}) {
        for (const Vec3& x : test::query_points(photons, 0.05f, 4, 200)) {
            PhotonQueryStats stats;
            auto got = test::map_radius(tree, x, r, &stats);
            auto want = test::brute_radius(photons, x, r);
            ASSERT_EQ(got, want) << "r=" << r;
            EXPECT_EQ(stats.inside, want.size());
            EXPECT_GE(stats.visited, stats.inside);
        }
    }
}

TEST(KdTree, EveryNodeIsVisitedOnceAndNoneBeyond) {
    // Trees of every small size, including those whose last interior node has only a
    // left child: an unbounded query must visit each node exactly once.
    for (size_t n = 1; n <= 40; ++n) {
        auto photons = test::random_photons(n, uint32_t(n));
        KdTreePhotonMap tree;
        tree.build(photons);
        for (const Vec3& x : {Vec3(-1.0f), Vec3(2.0f), Vec3(0.5f), Vec3(2.0f, -1.0f, 0.5f)}) {
            PhotonQueryStats stats;
            std::vector<uint32_t> seen;
            tree.radius_query(x, 100.0f, [&](uint32_t i, float) { seen.push_back(i); }, stats);
            EXPECT_EQ(stats.visited, n);
            EXPECT_EQ(seen.size(), n);
            for (uint32_t i : seen) EXPECT_LT(i, n);
            NeighborHeap heap;
            PhotonQueryStats knn_stats;
            tree.knn_query(x, n + 5, 100.0f, heap, knn_stats);
            EXPECT_EQ(heap.size(), n);
            EXPECT_LE(knn_stats.visited, n);
        }
    }
}

TEST(KdTree, KnnEqualsBruteForce) {
    const auto photons = test::random_photons(3000, 19);
    KdTreePhotonMap tree;
    tree.build(photons);
    for (float r : {0.05f, 0.1f, 0.3f, kInfinity}) {
        for (size_t k : {size_t(1), size_t(16), size_t(128)}) {
            for (const Vec3& x : test::query_points(photons, 0.05f, 23, 60)) {
                auto got = test::map_knn(tree, x, k, r);
                auto want = test::brute_knn(photons, x, k, r);
                ASSERT_EQ(got.distances2, want.distances2) << "k=" << k << " r=" << r;
                if (!want.tie_at_boundary) {
                    EXPECT_EQ(got.indices, want.indices);
                }
            }
        }
    }
}

TEST(KdTree, HeapShrinksTheSearch) {
    // With a small heap the shrinking radius must prune: fewer photons examined than by a
    // radius query of the same maximum radius.
    const auto photons = test::random_photons(5000, 2);
    KdTreePhotonMap tree;
    tree.build(photons);
    PhotonQueryStats knn_stats, radius_stats;
    NeighborHeap heap;
    for (const Vec3& x : test::query_points(photons, 0.05f, 8, 100)) {
        tree.knn_query(x, 4, 0.5f, heap, knn_stats);
        tree.radius_query(x, 0.5f, [](uint32_t, float) {}, radius_stats);
    }
    EXPECT_LT(knn_stats.visited * 3, radius_stats.visited);
}

TEST(KdTree, EmptyAndBadInput) {
    KdTreePhotonMap tree;
    tree.build({});
    EXPECT_TRUE(test::map_radius(tree, Vec3(0), 1.0f).empty());
    EXPECT_TRUE(test::map_knn(tree, Vec3(0), 5, 1.0f).indices.empty());
    auto bad = test::random_photons(10, 1);
    bad[2].position.x = kInfinity;
    try {
        tree.build(bad);
        FAIL() << "non-finite photon accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("photon 2"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace gilab
