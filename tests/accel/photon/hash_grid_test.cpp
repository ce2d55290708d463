// The uniform hash-grid photon map: every radius query (27 cells and 9 runs, query
// points on cell borders, at photons, around and far outside the grid, radii smaller and
// larger than the cell) returns exactly the brute-force set; kNN equals brute force; the
// grid's layout (padding, sorted cells, prefix sums) holds; bad radii are errors.
#include <gtest/gtest.h>

#include <random>
#include "accel/photon/hash_grid_photon_map.hpp"
#include "core/util/error.hpp"
#include "tests/photon_test_data.hpp"

namespace gilab {
namespace {

std::vector<Vec3> with_cell_borders(const HashGridPhotonMap& grid, std::vector<Vec3> q, uint32_t seed) {
    std::mt19937 gen(seed);
    const glm::ivec3 g = grid.grid_size();
    std::uniform_int_distribution<int> ix(-1, g.x + 1), iy(-1, g.y + 1), iz(-1, g.z + 1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 60; ++i) {
        Vec3 corner = grid.origin() + Vec3(float(ix(gen)), float(iy(gen)), float(iz(gen))) * grid.cell_size();
        q.push_back(corner);                                                   // a cell corner
        q.push_back(corner + Vec3(u(gen), 0.0f, u(gen)) * grid.cell_size());   // on a face
        q.push_back(std::nextafter(corner.x, -kInfinity) * Vec3(1, 0, 0) + corner * Vec3(0, 1, 1));
    }
    return q;
}

TEST(HashGrid, RadiusQueryEqualsBruteForce) {
    const auto photons = test::random_photons(4000, 7);
    std::mt19937 gen(11);
    std::uniform_real_distribution<float> radius(0.01f, 0.3f);
    std::vector<float> radii = {0.02f, 0.05f, 0.1f, 0.2f, 1.0f / 16.0f};
    for (int i = 0; i < 5; ++i) radii.push_back(radius(gen));
    for (HashQuery mode : {HashQuery::Cells27, HashQuery::Runs9}) {
        for (float r : radii) {
            HashGridPhotonMap grid(mode);
            grid.build(photons, r);
            ASSERT_EQ(grid.size(), photons.size());
            auto queries = with_cell_borders(grid, test::query_points(photons, r, 3, 150), 5);
            size_t nonempty = 0;
            for (const Vec3& x : queries) {
                // The grid's own radius, and radii below and above the cell (other paths).
                for (float rq : {r, 0.5f * r, 2.5f * r}) {
                    PhotonQueryStats stats;
                    auto got = test::map_radius(grid, x, rq, &stats);
                    auto want = test::brute_radius(photons, x, rq);
                    ASSERT_EQ(got, want) << to_string(mode) << " r=" << r << " rq=" << rq << " at (" << x.x << ", "
                                         << x.y << ", " << x.z << ")";
                    EXPECT_EQ(stats.inside, want.size());
                    EXPECT_GE(stats.visited, stats.inside);
                    EXPECT_EQ(stats.queries, 1u);
                    nonempty += !want.empty();
                }
            }
            EXPECT_GT(nonempty, queries.size() / 2) << "the test should exercise non-empty neighbourhoods";
        }
    }
}

TEST(HashGrid, NineRunsVisitExactlyTheTwentySevenCells) {
    const auto photons = test::random_photons(3000, 21);
    HashGridPhotonMap cells(HashQuery::Cells27), runs(HashQuery::Runs9);
    cells.build(photons, 0.07f);
    runs.build(photons, 0.07f);
    for (const Vec3& x : test::query_points(photons, 0.07f, 9, 200)) {
        PhotonQueryStats a, b;
        std::vector<uint32_t> order_a, order_b;
        cells.radius_query(x, 0.07f, [&](uint32_t i, float) { order_a.push_back(i); }, a);
        runs.radius_query(x, 0.07f, [&](uint32_t i, float) { order_b.push_back(i); }, b);
        EXPECT_EQ(a.visited, b.visited);
        EXPECT_EQ(order_a, order_b);  // same storage order, same traversal order
    }
}

TEST(HashGrid, LayoutFollowsThePaper) {
    const auto photons = test::random_photons(2000, 5);
    const float r = 0.05f;
    HashGridPhotonMap grid;
    grid.build(photons, r);
    EXPECT_NEAR(grid.cell_size(), r, 1e-4f * r);
    EXPECT_GE(grid.cell_size(), r);
    Bounds3 box;
    for (const Photon& p : photons) box.extend(p.position);
    for (int a = 0; a < 3; ++a) {
        // Origin one cell below the minimum; ⌈extent/r⌉ cells plus a padding layer each side.
        EXPECT_NEAR(grid.origin()[a], box.min[a] - grid.cell_size(), 1e-6f);
        int interior = int(std::ceil(box.extent()[a] / grid.cell_size()));
        EXPECT_GE(grid.grid_size()[a], interior + 2);
        EXPECT_LE(grid.grid_size()[a], interior + 3);
    }
    const auto& start = grid.start_index();
    ASSERT_EQ(start.size(), grid.cell_count() + 1);
    EXPECT_EQ(start.front(), 0u);
    EXPECT_EQ(start.back(), photons.size());
    EXPECT_TRUE(std::is_sorted(start.begin(), start.end()));
    const glm::ivec3 g = grid.grid_size();
    std::vector<bool> seen(photons.size(), false);
    for (int z = 0; z < g.z; ++z)
        for (int y = 0; y < g.y; ++y)
            for (int x = 0; x < g.x; ++x) {
                uint32_t h = grid.hash({x, y, z});
                EXPECT_EQ(h, uint32_t(z * g.x * g.y + y * g.x + x));
                bool padding = x == 0 || y == 0 || z == 0 || x == g.x - 1 || y == g.y - 1 || z == g.z - 1;
                if (padding) {
                    EXPECT_EQ(start[h], start[h + 1]) << "padding cell holds photons";
                }
                for (uint32_t i = start[h]; i < start[h + 1]; ++i) {
                    EXPECT_EQ(grid.cell_of(grid.photon(i).position), glm::ivec3(x, y, z));
                    EXPECT_EQ(grid.soa().x[i], grid.photon(i).position.x);
                    seen[grid.original_index(i)] = true;
                }
            }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](bool b) { return b; }));
}

TEST(HashGrid, KnnEqualsBruteForce) {
    const auto photons = test::random_photons(3000, 13);
    for (float r : {0.05f, 0.1f, 0.2f}) {
        HashGridPhotonMap grid;
        grid.build(photons, r);
        for (size_t k : {size_t(1), size_t(8), size_t(128)}) {
            for (const Vec3& x : test::query_points(photons, r, 17, 60)) {
                auto got = test::map_knn(grid, x, k, r);
                auto want = test::brute_knn(photons, x, k, r);
                ASSERT_EQ(got.distances2, want.distances2) << "k=" << k << " r=" << r;
                if (!want.tie_at_boundary) {
                    EXPECT_EQ(got.indices, want.indices);
                }
            }
        }
    }
}

TEST(HashGrid, FlatAndSinglePhotonSets) {
    // All photons on one plane (zero extent on an axis) and a single photon.
    std::vector<Photon> flat(200);
    for (size_t i = 0; i < flat.size(); ++i) flat[i].position = Vec3(float(i % 20) * 0.05f, 0.25f, float(i / 20) * 0.05f);
    HashGridPhotonMap grid;
    grid.build(flat, 0.06f);
    EXPECT_EQ(grid.grid_size().y, 3);
    for (const Vec3& x : {Vec3(0.5f, 0.25f, 0.2f), Vec3(0.5f, 0.3f, 0.2f), Vec3(0.0f, 0.25f, 0.0f), Vec3(0.5f, 0.4f, 0.2f)})
        EXPECT_EQ(test::map_radius(grid, x, 0.06f), test::brute_radius(flat, x, 0.06f));
    std::vector<Photon> one(1);
    one[0].position = Vec3(3, 4, 5);
    grid.build(one, 0.1f);
    EXPECT_EQ(test::map_radius(grid, Vec3(3.05f, 4, 5), 0.1f), std::vector<uint32_t>{0});
    EXPECT_TRUE(test::map_radius(grid, Vec3(3.2f, 4, 5), 0.1f).empty());
}

TEST(HashGrid, EmptyMapAnswersNothing) {
    HashGridPhotonMap grid;
    grid.build({}, 0.1f);
    EXPECT_TRUE(grid.empty());
    PhotonQueryStats stats;
    EXPECT_TRUE(test::map_radius(grid, Vec3(0), 0.1f, &stats).empty());
    EXPECT_EQ(stats.visited, 0u);
    NeighborHeap heap;
    grid.knn_query(Vec3(0), 10, 0.1f, heap, stats);
    EXPECT_EQ(heap.size(), 0u);
}

TEST(HashGrid, NonFiniteQueryPointsFindNothing) {
    const auto photons = test::random_photons(500, 3);
    HashGridPhotonMap grid;
    grid.build(photons, 0.1f);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(test::map_radius(grid, Vec3(nan, 0.5f, 0.5f), 0.1f).empty());
    EXPECT_TRUE(test::map_radius(grid, Vec3(kInfinity, 0.5f, 0.5f), 0.1f).empty());
}

TEST(HashGrid, BadInputIsAnError) {
    const auto photons = test::random_photons(100, 1);
    HashGridPhotonMap grid;
    for (float r : {0.0f, -0.1f, std::numeric_limits<float>::quiet_NaN(), kInfinity}) {
        try {
            grid.build(photons, r);
            FAIL() << "radius " << r << " accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("radius must be positive"), std::string::npos) << e.what();
        }
    }
    grid.set_max_cells(1000);
    try {
        grid.build(photons, 0.01f);
        FAIL() << "a grid beyond the cell limit was built";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos) << e.what();
    }
    auto bad = photons;
    bad[3].position.y = std::numeric_limits<float>::quiet_NaN();
    grid.set_max_cells(HashGridPhotonMap::kDefaultMaxCells);
    EXPECT_THROW(grid.build(bad, 0.1f), Error);
    EXPECT_THROW(parse_hash_query("runs8", "test"), Error);
}

}  // namespace
}  // namespace gilab
