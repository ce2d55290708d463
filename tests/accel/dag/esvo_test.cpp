// ESVO: Laine–Karras child descriptors, far pointers when 15 bits are not enough.
#include <gtest/gtest.h>
#include <bit>
#include <random>
#include "accel/dag/esvo.hpp"
#include "accel/dag/svo.hpp"
#include "core/util/morton.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;

namespace {

void check_against_svo(const Esvo& e, const Svo& svo) {
    EXPECT_EQ(e.decode(), svo.decode());
    EXPECT_EQ(e.voxel_count(), svo.voxel_count());
    EXPECT_EQ(e.descriptor_count(), svo.empty() ? 0 : svo.level_offset(svo.depth()));
    EXPECT_EQ(e.bytes(), 8 * e.descriptor_count() + 4 * e.far_pointer_count());
    for (int l = 0; l < svo.depth(); ++l) EXPECT_EQ(e.level_node_counts()[l], svo.level_node_counts()[l]);
    // Descriptor children: leaf mask only on the last interior level, valid masks match.
    if (!e.empty() && e.depth() > 0) {
        std::vector<uint32_t> stack{e.root()};
        size_t seen = 0;
        while (!stack.empty()) {
            uint32_t d = stack.back();
            stack.pop_back();
            ++seen;
            uint8_t valid = e.valid_mask(d), leaf = e.leaf_mask(d);
            ASSERT_NE(valid, 0);
            ASSERT_EQ(leaf & ~valid, 0);
            ASSERT_TRUE(leaf == 0 || leaf == valid);
            for (int s = 0; s < 8; ++s) {
                uint32_t c = e.child(d, s);
                if (c != kInvalidNode && c != Esvo::kLeafChild) stack.push_back(c);
            }
        }
        EXPECT_EQ(seen, e.descriptor_count());
    }
}

}  // namespace

TEST(Esvo, MatchesSvoOnSphere) {
    auto m = gilab::test::uv_sphere(Vec3(0.5f), 0.4f);
    for (uint32_t n : {1u, 2u, 9u, 32u, 50u}) {
        VoxelList v = voxelize(m.positions, m.triangles, gilab::test::unit_grid(n));
        Svo svo = Svo::build(v);
        Esvo e = Esvo::from_svo(svo);
        check_against_svo(e, svo);
        EXPECT_EQ(e.far_pointer_count(), 0u) << "small trees need no far pointers";
        std::mt19937 rng(n);
        for (int i = 0; i < 1000; ++i) {
            Vec3 p = gilab::test::random_point(rng, Vec3(-0.1f), Vec3(1.1f));
            ASSERT_EQ(e.occupied(p), svo.occupied(p));
        }
    }
}

TEST(Esvo, FarPointersWhenOffsetsExceed15Bits) {
    // A dense random 64³ set: the subtrees of the root's first children hold tens of
    // thousands of words, so later siblings' child blocks are out of 15-bit reach.
    std::mt19937 rng(42);
    auto codes = gilab::test::random_voxels(rng, 64, 0.3);
    Svo svo = Svo::build(gilab::test::unit_grid(64), codes);
    Esvo e = Esvo::from_svo(svo);
    EXPECT_GT(e.far_pointer_count(), 0u);
    EXPECT_EQ(e.pointer_count(), svo.level_offset(svo.depth() - 1) + e.far_pointer_count());
    check_against_svo(e, svo);
    size_t far_seen = 0;
    std::vector<uint32_t> stack{e.root()};
    while (!stack.empty()) {
        uint32_t d = stack.back();
        stack.pop_back();
        if (e.leaf_mask(d)) continue;
        if (e.far(d)) {
            ++far_seen;
            EXPECT_GT(e.child_block(d) - d, 0x7fffu);
        } else {
            EXPECT_LE(e.child_block(d) - d, 0x7fffu);
        }
        for (int s = 0; s < 8; ++s) {
            uint32_t c = e.child(d, s);
            if (c != kInvalidNode && c != Esvo::kLeafChild) stack.push_back(c);
        }
    }
    EXPECT_EQ(far_seen, e.far_pointer_count());
    for (uint32_t z = 0; z < 64; z += 3)
        for (uint32_t y = 0; y < 64; ++y)
            for (uint32_t x = 0; x < 64; ++x) ASSERT_EQ(e.contains_voxel({x, y, z}), svo.contains_voxel({x, y, z}));
}

TEST(Esvo, Empty) {
    Svo svo = Svo::build(gilab::test::unit_grid(16), {});
    Esvo e = Esvo::from_svo(svo);
    EXPECT_TRUE(e.empty());
    EXPECT_EQ(e.bytes(), 0u);
    EXPECT_TRUE(e.decode().empty());
}
