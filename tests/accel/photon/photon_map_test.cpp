// The photon-map front end: every structure keeps the gather radius it was built for
// (a failed build leaves it as it was), and as<Map>() gives the concrete structure of
// the map's kind and null for the others.
#include <gtest/gtest.h>

#include "accel/photon/hash_grid_photon_map.hpp"
#include "accel/photon/kd_tree_photon_map.hpp"
#include "accel/photon/nanoflann_photon_map.hpp"
#include "core/util/error.hpp"
#include "tests/photon_test_data.hpp"

namespace gilab {
namespace {

TEST(PhotonMap, KeepsTheRadiusItWasBuiltFor) {
    const auto photons = test::random_photons(500, 3);
    for (PhotonMapKind kind : {PhotonMapKind::HashGrid, PhotonMapKind::KdTree, PhotonMapKind::Nanoflann}) {
        auto map = make_photon_map(kind);
        EXPECT_EQ(map->radius(), 0.0f) << to_string(kind);
        map->build(photons, 0.07f);
        EXPECT_EQ(map->radius(), 0.07f) << to_string(kind);
        map->build({}, 0.05f);
        EXPECT_EQ(map->radius(), 0.05f) << to_string(kind);
    }
    HashGridPhotonMap grid;
    grid.build(photons, 0.1f);
    EXPECT_GE(grid.cell_size(), grid.radius());
    EXPECT_THROW(grid.build(photons, -1.0f), Error);
    EXPECT_EQ(grid.radius(), 0.1f);
    KdTreePhotonMap tree;
    tree.build(photons);
    EXPECT_EQ(tree.radius(), 0.0f);
}

TEST(PhotonMap, AsGivesTheStructureOfItsKindOnly) {
    auto grid = make_photon_map(PhotonMapKind::HashGrid);
    auto tree = make_photon_map(PhotonMapKind::KdTree);
    auto nano = make_photon_map(PhotonMapKind::Nanoflann);
    EXPECT_EQ(grid->as<HashGridPhotonMap>(), grid.get());
    EXPECT_EQ(tree->as<KdTreePhotonMap>(), tree.get());
    EXPECT_EQ(nano->as<NanoflannPhotonMap>(), nano.get());
    EXPECT_EQ(grid->as<KdTreePhotonMap>(), nullptr);
    EXPECT_EQ(grid->as<NanoflannPhotonMap>(), nullptr);
    EXPECT_EQ(tree->as<HashGridPhotonMap>(), nullptr);
    EXPECT_EQ(tree->as<NanoflannPhotonMap>(), nullptr);
    EXPECT_EQ(nano->as<HashGridPhotonMap>(), nullptr);
    EXPECT_EQ(nano->as<KdTreePhotonMap>(), nullptr);
    const PhotonMap& view = *grid;
    const HashGridPhotonMap* typed = view.as<HashGridPhotonMap>();
    EXPECT_EQ(typed, grid.get());
    grid->as<HashGridPhotonMap>()->set_query_mode(HashQuery::Cells27);
    EXPECT_EQ(typed->query_mode(), HashQuery::Cells27);
}

}  // namespace
}  // namespace gilab
