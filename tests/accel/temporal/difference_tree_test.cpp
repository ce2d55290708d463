// Difference tree (Ma & Shen 2000), the baseline of P2 §5.3: every frame decodes
// exactly, and a frame stores exactly the nodes whose voxels changed since the frame
// before — the root-to-leaf path of an added voxel, nothing for an identical frame.
#include <gtest/gtest.h>
#include <cstdio>
#include <random>
#include <string>
#include "accel/temporal/difference_tree.hpp"
#include "accel/temporal/minimal_bit_dag.hpp"
#include "accel/temporal/multi_frame_dag.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;
using gilab::test::TriangleSoup;

namespace {

// A static sphere with clutter, and a sphere moving along x.
std::vector<uint64_t> moving_sphere_frame(int frame, uint32_t n = 64) {
    TriangleSoup soup = gilab::test::uv_sphere(Vec3(0.75f, 0.75f, 0.3f), 0.15f, 10, 20);
    std::mt19937 rng(7);
    for (const TriangleSoup& extra :
         {gilab::test::random_triangles(rng, 12, Vec3(0.05f, 0.6f, 0.6f), Vec3(0.45f, 0.95f, 0.95f)),
          gilab::test::uv_sphere(Vec3(0.2f + 0.06f * float(frame), 0.3f, 0.5f), 0.14f, 10, 20)}) {
        const uint32_t base = uint32_t(soup.positions.size());
        soup.positions.insert(soup.positions.end(), extra.positions.begin(), extra.positions.end());
        for (UVec3 t : extra.triangles) soup.triangles.push_back(t + UVec3(base));
    }
    return voxelize(soup.positions, soup.triangles, gilab::test::unit_grid(n)).codes;
}

std::vector<uint64_t> with(std::vector<uint64_t> codes, uint64_t code) {
    codes.insert(std::lower_bound(codes.begin(), codes.end(), code), code);
    return codes;
}

}  // namespace

TEST(DifferenceTree, DecodesEveryFrameExactly) {
    const VoxelGrid grid = gilab::test::unit_grid(64);
    std::vector<std::vector<uint64_t>> frames;
    for (int f = 0; f < 6; ++f) frames.push_back(moving_sphere_frame(f));
    frames.insert(frames.begin() + 3, std::vector<uint64_t>{});  // an empty frame in between
    DifferenceTree tree(grid);
    for (const auto& f : frames) tree.append_frame(f);
    ASSERT_EQ(tree.frame_count(), frames.size());
    for (size_t f = 0; f < frames.size(); ++f) EXPECT_EQ(tree.decode(f), frames[f]) << "frame " << f;
    EXPECT_EQ(tree.nodes_added(0), Svo::build(grid, frames[0]).node_count()) << "frame 0 is the whole SVO";
    EXPECT_EQ(tree.nodes_added(3), 0u) << "an empty frame stores nothing";
    EXPECT_EQ(tree.nodes_added(4), Svo::build(grid, frames[4]).node_count()) << "after an empty frame all is new";
    EXPECT_LT(tree.nodes_added(2), Svo::build(grid, frames[2]).node_count() / 2) << "static parts are shared";
    uint64_t sum = 0;
    for (size_t f = 0; f < frames.size(); ++f) sum += tree.nodes_added(f);
    EXPECT_EQ(sum, tree.node_count());
}

TEST(DifferenceTree, IdenticalFrameAddsNothing) {
    const auto a = moving_sphere_frame(1);
    DifferenceTree tree(gilab::test::unit_grid(64));
    tree.append_frame(a);
    const uint64_t nodes = tree.node_count();
    EXPECT_EQ(tree.append_frame(a), 0u);
    EXPECT_EQ(tree.node_count(), nodes);
    EXPECT_EQ(tree.decode(1), a);
    EXPECT_EQ(tree.bytes(), 4 * (nodes + (nodes - 1) + 2)) << "a tree: one pointer per node but the root";
}

TEST(DifferenceTree, OneAddedVoxelAddsDepthPlusOneNodes) {
    const VoxelGrid grid = gilab::test::unit_grid(64);
    const auto a = moving_sphere_frame(1);
    // A free voxel beside an occupied one, so most of its path already exists.
    uint64_t added = 0;
    bool found = false;
    for (size_t i = 0; i < a.size() && !found; ++i) {
        const UVec3 v = morton_decode(a[i]);
        const uint64_t c = morton_encode(v.x ^ 1u, v.y, v.z);
        if (!std::binary_search(a.begin(), a.end(), c)) added = c, found = true;
    }
    ASSERT_TRUE(found);
    DifferenceTree tree(grid);
    tree.append_frame(a);
    EXPECT_EQ(tree.append_frame(with(a, added)), uint64_t(grid.depth() + 1));
    EXPECT_EQ(tree.decode(1), with(a, added));
}

TEST(DifferenceTree, OneRemovedVoxelAddsDepthNodes) {
    const VoxelGrid grid = gilab::test::unit_grid(64);
    const auto a = moving_sphere_frame(1);
    // A voxel with a sibling in its bottom node, so the path up to the root survives.
    size_t i = 1;
    while (i < a.size() && (a[i] >> 3) != (a[i - 1] >> 3)) ++i;
    ASSERT_LT(i, a.size());
    std::vector<uint64_t> b = a;
    b.erase(b.begin() + long(i));
    DifferenceTree tree(grid);
    tree.append_frame(a);
    EXPECT_EQ(tree.append_frame(b), uint64_t(grid.depth()));
    EXPECT_EQ(tree.decode(1), b);
    EXPECT_EQ(tree.decode(0), a);
}

// Node counts of the four structures P2 Table 5 compares, on a moving sphere; printed
// for the record. Every time-correlated node first appears in a frame where the voxels
// below it changed, so it is a changed difference-tree node (or a root).
TEST(DifferenceTree, TimeCorrelatedNeverLarger) {
    const VoxelGrid grid = gilab::test::unit_grid(64);
    const int frames = 10;
    DifferenceTree tree(grid);
    MultiFrameDag tc(grid);
    uint64_t svo_nn = 0, svdag_nn = 0, svdag_bytes = 0;
    for (int f = 0; f < frames; ++f) {
        const auto codes = moving_sphere_frame(f);
        svo_nn += Svo::build(grid, codes).node_count();
        const Svdag dag = Svdag::from_voxels(grid, codes);
        svdag_nn += dag.node_count();
        svdag_bytes += dag.bytes();
        tree.append_frame(codes);
        tc.append_frame(codes);
    }
    const uint64_t tc_nn = tc.node_count();
    EXPECT_LE(tc_nn, tree.node_count() + frames);
    EXPECT_LE(tc_nn, svdag_nn);
    EXPECT_LT(tree.node_count(), svo_nn);
    std::printf("moving sphere, 64^3 x %d frames, N_n (N_p): SVO %llu (%.0f), difference tree %llu (%.0f), "
                "SVDAG %llu (%.0f), time-correlated %llu (%.0f)\n",
                frames, (unsigned long long)svo_nn, double(svo_nn) / frames, (unsigned long long)tree.node_count(),
                tree.nodes_per_frame(), (unsigned long long)svdag_nn, double(svdag_nn) / frames,
                (unsigned long long)tc_nn, tc.nodes_per_frame());
    const LaidOutMultiFrameDag laid_out = tc.lay_out();
    std::printf("bytes: SVO pointerless %llu, difference tree %zu, SVDAG %llu, time-correlated %zu (32-bit), "
                "%zu (minimal bits, offsets), %zu (minimal bits, indices)\n",
                (unsigned long long)svo_nn, tree.bytes(), (unsigned long long)svdag_bytes, laid_out.bytes(),
                encode_minimal_bits(laid_out, PointerAddressing::BitOffset).bytes(),
                encode_minimal_bits(laid_out, PointerAddressing::NodeIndex).bytes());
}

TEST(DifferenceTree, BadInputIsAnError) {
    DifferenceTree tree(gilab::test::unit_grid(8));
    EXPECT_THROW(tree.append_frame(std::vector<uint64_t>{3, 2}), Error);
    EXPECT_THROW(tree.append_frame(std::vector<uint64_t>{morton_encode(0, 8, 0)}), Error);
    EXPECT_THROW(tree.decode(0), Error);
    EXPECT_EQ(tree.frame_count(), 0u);
}

// Two frames on an 8³ grid (depth 3), counted by hand. Frame 0: voxel 0; frame 1 adds
// voxel 1 beside it, so the bottom node's mask changes and its whole path is copied.
//  * voxels as nodes: frame 0 stores 4 nodes (root, two inner, the voxel) and 3
//    pointers, frame 1 stores 4 nodes (the new voxel, three copies) and 4 pointers (the
//    bottom node now points at two voxels): 4 B × (8 nodes + 7 pointers + 2 roots) = 68 B;
//  * voxels in the bottom masks: 3 nodes and 2 pointers per frame, 2 roots: 4 B × 12 = 48 B.
TEST(DifferenceTree, LeavesInMasksDropTheVoxelNodesAndTheirPointers) {
    DifferenceTree tree(gilab::test::unit_grid(8));
    ASSERT_EQ(tree.depth(), 3);
    EXPECT_EQ(tree.append_frame(std::vector<uint64_t>{0}), 4u);
    EXPECT_EQ(tree.append_frame(std::vector<uint64_t>{0, 1}), 4u);
    EXPECT_EQ(tree.node_count(), 8u);
    EXPECT_EQ(tree.bytes(), 68u);
    EXPECT_EQ(tree.node_count_leaves_in_masks(), 6u);
    EXPECT_EQ(tree.bytes_leaves_in_masks(), 48u);
    // A third frame moving the second voxel within the same bottom node: the voxel
    // variant stores the new voxel too, the mask variant only the three copies.
    tree.append_frame(std::vector<uint64_t>{0, 2});
    EXPECT_EQ(tree.bytes(), 68u + 4 * (4 + 4 + 1));
    EXPECT_EQ(tree.bytes_leaves_in_masks(), 48u + 4 * (3 + 2 + 1));
}
