// OpenVDB and OctoMap hold the same voxels as SVO / ESVO / SVDAG: same count, same
// answer for random points.
#include <gtest/gtest.h>
#include <random>
#include "accel/dag/esvo.hpp"
#include "accel/peers/octomap_tree.hpp"
#include "accel/peers/openvdb_grid.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"
#include "core/util/error.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;

namespace {

VoxelList scene_voxels(uint32_t n, const VoxelGrid& grid) {
    auto m = gilab::test::uv_sphere(grid.origin + Vec3(0.5f * grid.extent), 0.4f * grid.extent);
    std::mt19937 rng(n);
    auto r = gilab::test::random_triangles(rng, 8, grid.origin, grid.origin + Vec3(grid.extent));
    uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), r.positions.begin(), r.positions.end());
    for (UVec3 t : r.triangles) m.triangles.push_back(t + UVec3(base));
    return voxelize(m.positions, m.triangles, grid);
}

}  // namespace

TEST(ReferenceStructures, AllAgreeOnCountsAndMembership) {
    for (uint32_t n : {20u, 64u}) {
        VoxelGrid g;
        g.origin = Vec3(-1.5f, 0.25f, 2.0f);
        g.extent = 2.5f;
        g.resolution = n;
        VoxelList v = scene_voxels(n, g);
        Svo svo = Svo::build(v);
        Esvo esvo = Esvo::from_svo(svo);
        Svdag dag = Svdag::from_svo(svo);
        OpenVdbVoxels vdb(v);
        OctomapVoxels octo(v);
        OctomapVoxels pruned(v, /*prune=*/true);
        const uint64_t count = v.size();
        EXPECT_EQ(svo.voxel_count(), count);
        EXPECT_EQ(esvo.voxel_count(), count);
        EXPECT_EQ(dag.voxel_count(), count);
        EXPECT_EQ(vdb.voxel_count(), count);
        EXPECT_EQ(octo.voxel_count(), count);
        EXPECT_EQ(pruned.voxel_count(), count);
        EXPECT_EQ(octo.leaf_node_count(), count);
        EXPECT_LE(pruned.node_count(), octo.node_count());
        EXPECT_GT(vdb.bytes(), 0u);
        EXPECT_GT(octo.bytes(), 0u);
        EXPECT_GT(vdb.leaf_node_count(), 0u);

        std::mt19937 rng(n + 1);
        int inside = 0;
        for (int i = 0; i < 4000; ++i) {
            Vec3 p = gilab::test::random_point(rng, g.origin - Vec3(0.2f), g.origin + Vec3(g.extent + 0.2f));
            if (i % 2 == 0) p = g.cell_bounds(v.voxel(rng() % v.size())).center();
            bool want = svo.occupied(p);
            inside += want;
            ASSERT_EQ(esvo.occupied(p), want) << i;
            ASSERT_EQ(dag.occupied(p), want) << i;
            ASSERT_EQ(vdb.occupied(p), want) << i;
            ASSERT_EQ(octo.occupied(p), want) << i;
            ASSERT_EQ(pruned.occupied(p), want) << i;
            auto voxel = g.voxel_of(p);
            if (voxel) {
                ASSERT_EQ(vdb.contains_voxel(*voxel), want);
                ASSERT_EQ(octo.contains_voxel(*voxel), want);
            }
        }
        EXPECT_GT(inside, 2000);
        Stats s = vdb.stats();
        EXPECT_EQ(s.get("voxels"), double(count));
        EXPECT_EQ(octo.stats().get("voxels"), double(count));
    }
}

TEST(ReferenceStructures, OctomapRefusesGridsBeyondItsKeys) {
    VoxelGrid g = gilab::test::unit_grid(40000);
    try {
        OctomapVoxels tree(g, {});
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("32768"), std::string::npos) << e.what();
    }
}
