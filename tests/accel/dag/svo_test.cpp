// SVO: breadth-first layout with first-child indices reproduces the voxel set exactly.
#include <gtest/gtest.h>
#include <bit>
#include <random>
#include "accel/dag/svo.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;

namespace {

void check_structure(const Svo& svo, const std::vector<uint64_t>& codes) {
    const int depth = svo.depth();
    ASSERT_EQ(svo.level_node_counts().size(), size_t(depth + 1));
    // Level l holds one node per distinct code >> 3(depth − l).
    for (int l = 0; l <= depth; ++l) {
        std::vector<uint64_t> parents;
        for (uint64_t c : codes) {
            uint64_t p = c >> (3 * (depth - l));
            if (parents.empty() || parents.back() != p) parents.push_back(p);
        }
        EXPECT_EQ(svo.level_node_counts()[l], parents.size()) << "level " << l;
    }
    EXPECT_EQ(svo.voxel_count(), codes.size());
    size_t nodes = 0;
    for (uint64_t c : svo.level_node_counts()) nodes += c;
    EXPECT_EQ(svo.node_count(), nodes);
    // Interior nodes: children contiguous right after the previous node's children.
    size_t interior = svo.level_offset(depth);
    EXPECT_EQ(svo.pointer_count(), interior);
    for (size_t i = 0; i < interior; ++i) {
        ASSERT_NE(svo.mask(uint32_t(i)), 0);
        if (i + 1 < interior) {
            ASSERT_EQ(svo.first_child(uint32_t(i + 1)), svo.first_child(uint32_t(i)) + std::popcount(svo.mask(uint32_t(i))));
        }
    }
    for (size_t i = interior; i < svo.node_count(); ++i) ASSERT_EQ(svo.mask(uint32_t(i)), 0);
    EXPECT_EQ(svo.bytes(), svo.node_count() + 4 * interior);
    EXPECT_EQ(svo.pointerless_bytes(), svo.node_count());
    EXPECT_EQ(svo.decode(), codes);
}

}  // namespace

TEST(Svo, RandomVoxelsRoundTrip) {
    for (uint32_t n : {1u, 2u, 7u, 16u, 21u}) {
        std::mt19937 rng(n);
        auto codes = gilab::test::random_voxels(rng, n, 0.2);
        Svo svo = Svo::build(gilab::test::unit_grid(n), codes);
        EXPECT_EQ(svo.depth(), n == 1 ? 0 : int(std::ceil(std::log2(double(n)))));
        check_structure(svo, codes);
        for (uint32_t z = 0; z < n + 2; ++z)
            for (uint32_t y = 0; y < n + 2; ++y)
                for (uint32_t x = 0; x < n + 2; ++x)
                    ASSERT_EQ(svo.contains_voxel({x, y, z}),
                              std::binary_search(codes.begin(), codes.end(), morton_encode(x, y, z)));
    }
}

TEST(Svo, SphereSurfaceAtNonPowerOfTwoResolution) {
    auto m = gilab::test::uv_sphere(Vec3(0.5f), 0.4f);
    VoxelList v = voxelize(m.positions, m.triangles, gilab::test::unit_grid(50));
    Svo svo = Svo::build(v);
    EXPECT_EQ(svo.depth(), 6);
    check_structure(svo, v.codes);
    EXPECT_EQ(svo.level_node_counts()[0], 1u);
    // World-point membership agrees with the voxel list.
    std::mt19937 rng(1);
    for (int i = 0; i < 2000; ++i) {
        Vec3 p = gilab::test::random_point(rng, Vec3(-0.1f), Vec3(1.1f));
        auto voxel = v.grid.voxel_of(p);
        bool want = voxel && std::binary_search(v.codes.begin(), v.codes.end(), morton_encode(*voxel));
        ASSERT_EQ(svo.occupied(p), want);
    }
    Stats s = svo.stats();
    EXPECT_EQ(s.get("nodes"), double(svo.node_count()));
    EXPECT_EQ(s.get("nodes_level_6"), double(v.size()));
}

TEST(Svo, EmptyAndSingleVoxel) {
    Svo empty = Svo::build(gilab::test::unit_grid(8), {});
    EXPECT_TRUE(empty.empty());
    EXPECT_EQ(empty.node_count(), 0u);
    EXPECT_FALSE(empty.contains_voxel({0, 0, 0}));
    std::vector<uint64_t> one{morton_encode(5, 6, 7)};
    Svo svo = Svo::build(gilab::test::unit_grid(8), one);
    EXPECT_EQ(svo.node_count(), 4u);  // a chain root → … → leaf
    EXPECT_TRUE(svo.contains_voxel({5, 6, 7}));
    EXPECT_EQ(svo.decode(), one);
}

TEST(Svo, RejectsBadVoxelLists) {
    auto g = gilab::test::unit_grid(10);
    auto expect_error = [&](std::vector<uint64_t> codes, const std::string& text) {
        try {
            Svo::build(g, codes);
            ADD_FAILURE() << "no error";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    };
    expect_error({morton_encode(1, 1, 1), morton_encode(0, 0, 0)}, "ascending");
    expect_error({morton_encode(1, 1, 1), morton_encode(1, 1, 1)}, "ascending");
    expect_error({morton_encode(10, 0, 0)}, "outside");
    try {
        Svo::build(gilab::test::unit_grid(0), {});
        ADD_FAILURE();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("at least 1"), std::string::npos);
    }
}
