// The nanoflann adapter answers the same queries as brute force and as our own kd-tree
// and hash grid (radius: squared-radius convention and strict leaf test handled; kNN
// with the shared max-heap).
#include <gtest/gtest.h>

#include "accel/photon/hash_grid_photon_map.hpp"
#include "accel/photon/kd_tree_photon_map.hpp"
#include "accel/photon/nanoflann_photon_map.hpp"
#include "core/util/error.hpp"
#include "tests/photon_test_data.hpp"

namespace gilab {
namespace {

TEST(Nanoflann, RadiusQueryEqualsBruteForceAndTheOtherStructures) {
    const auto photons = test::random_photons(4000, 31);
    NanoflannPhotonMap nano;
    KdTreePhotonMap kd;
    nano.build(photons);
    kd.build(photons);
    for (float r : {0.02f, 0.05f, 0.1f, 0.2f}) {
        HashGridPhotonMap grid;
        grid.build(photons, r);
        for (const Vec3& x : test::query_points(photons, r, 6, 200)) {
            PhotonQueryStats stats;
            auto got = test::map_radius(nano, x, r, &stats);
            auto want = test::brute_radius(photons, x, r);
            ASSERT_EQ(got, want) << "r=" << r;
            EXPECT_EQ(stats.inside, want.size());
            EXPECT_GE(stats.visited, stats.inside);
            EXPECT_EQ(got, test::map_radius(kd, x, r));
            EXPECT_EQ(got, test::map_radius(grid, x, r));
        }
    }
}

TEST(Nanoflann, BoundaryPhotonAtExactlyRIsInside) {
    // nanoflann keeps d² < bound; a photon at exactly r must still be found.
    std::vector<Photon> photons(3);
    photons[0].position = Vec3(0.5f, 0.0f, 0.0f);
    photons[1].position = Vec3(0.0f, 0.25f, 0.0f);
    photons[2].position = Vec3(0.75f, 0.0f, 0.0f);
    NanoflannPhotonMap nano;
    nano.build(photons);
    EXPECT_EQ(test::map_radius(nano, Vec3(0), 0.5f), (std::vector<uint32_t>{0, 1}));
    EXPECT_EQ(test::map_knn(nano, Vec3(0), 5, 0.5f).indices, (std::vector<uint32_t>{0, 1}));
}

TEST(Nanoflann, KnnEqualsBruteForce) {
    const auto photons = test::random_photons(3000, 37);
    NanoflannPhotonMap nano(16);
    nano.build(photons);
    for (float r : {0.05f, 0.1f, 0.3f}) {
        for (size_t k : {size_t(1), size_t(16), size_t(128)}) {
            for (const Vec3& x : test::query_points(photons, 0.05f, 41, 60)) {
                auto got = test::map_knn(nano, x, k, r);
                auto want = test::brute_knn(photons, x, k, r);
                ASSERT_EQ(got.distances2, want.distances2) << "k=" << k << " r=" << r;
                if (!want.tie_at_boundary) {
                    EXPECT_EQ(got.indices, want.indices);
                }
            }
        }
    }
}

TEST(Nanoflann, FilteredKnnSkipsRejectedPhotons) {
    const auto photons = test::random_photons(2000, 43);
    NanoflannPhotonMap nano;
    nano.build(photons);
    NeighborHeap heap;
    PhotonQueryStats stats;
    nano.knn_filtered(Vec3(0.5f), 32, 0.3f, heap, stats, [](uint32_t i) { return i % 2 == 0; });
    ASSERT_EQ(heap.size(), 32u);
    std::vector<Photon> even;
    for (size_t i = 0; i < photons.size(); i += 2) even.push_back(photons[i]);
    auto want = test::brute_knn(even, Vec3(0.5f), 32, 0.3f);
    std::vector<float> got;
    for (const auto& n : heap.items()) {
        EXPECT_EQ(n.index % 2, 0u);
        got.push_back(n.distance2);
    }
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want.distances2);
}

TEST(Nanoflann, EmptyMapAndMakeByName) {
    NanoflannPhotonMap nano;
    nano.build({});
    EXPECT_TRUE(test::map_radius(nano, Vec3(0), 1.0f).empty());
    EXPECT_TRUE(test::map_knn(nano, Vec3(0), 3, 1.0f).indices.empty());
    EXPECT_EQ(make_photon_map(parse_photon_map_kind("nanoflann", "test"))->name(), "nanoflann");
    EXPECT_EQ(make_photon_map(parse_photon_map_kind("kd_tree", "test"))->name(), "kd_tree");
    EXPECT_EQ(make_photon_map(parse_photon_map_kind("hash_grid", "test"))->name(), "hash_grid");
    try {
        parse_photon_map_kind("octree", "settings");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("photon_map 'octree'"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace gilab
