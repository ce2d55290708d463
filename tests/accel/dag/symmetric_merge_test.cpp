// Merging under node symmetries: the groups' tables, one node per symmetry class of
// subtrees on every level (against a brute force over voxel sets), the merged DAG
// expanding back to the SVDAG's voxels, and the reflections giving the SSVDAG's sizes.
#include <gtest/gtest.h>
#include <algorithm>
#include <random>
#include <set>
#include <vector>
#include <tbb/global_control.h>
#include "accel/dag/child_mask.hpp"
#include "accel/dag/node_symmetry.hpp"
#include "accel/dag/symmetric_dag.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/symmetric_merge.hpp"
#include "core/util/morton.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/test_support.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;

namespace {

UVec3 slot_corner(uint32_t slot) { return UVec3(slot & 1u, (slot >> 1) & 1u, (slot >> 2) & 1u); }

// Symmetry t of the cube group applied to a point of a cell of `side` voxels: the
// coordinates permuted, then reflected about the cell's centre planes.
UVec3 moved(uint32_t t, UVec3 v, uint32_t side) {
    UVec3 out;
    for (int a = 0; a < 3; ++a) {
        out[a] = v[detail::kAxisOf[t >> 3][a]];
        if (t & (1u << a)) out[a] = side - 1 - out[a];
    }
    return out;
}

std::vector<uint64_t> codes_of(const std::vector<UVec3>& voxels) {
    std::vector<uint64_t> codes;
    for (const UVec3& v : voxels) codes.push_back(morton_encode(v));
    std::sort(codes.begin(), codes.end());
    codes.erase(std::unique(codes.begin(), codes.end()), codes.end());
    return codes;
}

// The voxels below an SVDAG node whose cell is `side` voxels wide, in the cell's coordinates.
void subtree_voxels(const Svdag& dag, uint32_t node, uint32_t side, UVec3 origin, std::vector<UVec3>& out) {
    if (side == 1) {
        out.push_back(origin);
        return;
    }
    const uint32_t half = side / 2;
    for (uint32_t s = 0; s < 8; ++s)
        if (const uint32_t c = dag.child(node, int(s)); c != kInvalidNode)
            subtree_voxels(dag, c, half, origin + slot_corner(s) * half, out);
}

// Brute force: per level, the SVDAG's distinct subtrees grouped into classes of voxel sets
// equal under the first `symmetries` cube symmetries (8: the reflections, 48: all).
std::vector<uint64_t> classes_per_level(const Svdag& dag, uint32_t symmetries) {
    std::vector<uint64_t> counts;
    for (int l = 0; l <= dag.depth(); ++l) {
        const uint32_t side = 1u << (dag.depth() - l);
        std::set<std::vector<uint64_t>> classes;
        for (uint32_t node : dag.level_nodes(l)) {
            std::vector<UVec3> voxels;
            subtree_voxels(dag, node, side, UVec3(0), voxels);
            std::vector<uint64_t> best;
            for (uint32_t t = 0; t < symmetries; ++t) {
                std::vector<UVec3> m;
                for (const UVec3& v : voxels) m.push_back(moved(t, v, side));
                const std::vector<uint64_t> codes = codes_of(m);
                if (t == 0 || codes < best) best = codes;
            }
            classes.insert(best);
        }
        counts.push_back(classes.size());
    }
    return counts;
}

// The merged DAG expanded back into voxels: the node `ref` seen through `transform`.
template <class Group>
void expand(const SymmetricMerge<Group>& merge, uint32_t id, uint32_t transform, int level, UVec3 cell,
            std::vector<UVec3>& out) {
    using Merge = SymmetricMerge<Group>;
    if (level == merge.depth() - 1) {
        const uint8_t mask = Group::transform_mask(transform, merge.leaf_masks().at(id));
        for (uint32_t s = 0; s < 8; ++s)
            if (mask & (1u << s)) out.push_back(cell * 2u + slot_corner(s));
        return;
    }
    const DagLevelTable& table = merge.tables().at(size_t(level));
    const uint32_t stored_mask = table.header(id) & 0xffu;
    const auto kids = table.children(id);
    const uint8_t mask = Group::transform_mask(transform, stored_mask);
    for (uint32_t s = 0; s < 8; ++s) {
        if (!(mask & (1u << s))) continue;
        const uint32_t source = Group::source_slot(transform, s);
        ASSERT_TRUE(stored_mask & (1u << source));
        const uint32_t r = kids[child_rank(stored_mask, int(source))];
        expand(merge, Merge::ref_id(r), Group::compose(transform, Merge::ref_transform(r)), level + 1,
               cell * 2u + slot_corner(s), out);
    }
}

template <class Group>
std::vector<uint64_t> expanded_codes(const SymmetricMerge<Group>& merge) {
    using Merge = SymmetricMerge<Group>;
    std::vector<UVec3> voxels;
    expand(merge, Merge::ref_id(merge.root_ref()), Merge::ref_transform(merge.root_ref()), 0, UVec3(0), voxels);
    return codes_of(voxels);
}

std::vector<uint64_t> mixed_voxels(uint32_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    const auto sphere = gilab::test::uv_sphere(Vec3(0.45f, 0.5f, 0.55f), 0.3f, 12, 24);
    auto soup = gilab::test::random_triangles(rng, 16, Vec3(0.05f), Vec3(0.95f));
    const uint32_t base = uint32_t(soup.positions.size());
    soup.positions.insert(soup.positions.end(), sphere.positions.begin(), sphere.positions.end());
    for (UVec3 t : sphere.triangles) soup.triangles.push_back(t + UVec3(base));
    return voxelize(soup.positions, soup.triangles, gilab::test::unit_grid(n)).codes;
}

}  // namespace

TEST(NodeSymmetry, CubeGroupTablesFormTheGroupOfTheCube) {
    using G = CubeSymmetryGroup;
    std::set<std::vector<uint32_t>> maps;
    for (uint32_t t = 0; t < G::kSize; ++t) {
        std::vector<uint32_t> map;
        for (uint32_t k = 0; k < 8; ++k) map.push_back(detail::kCubeTables.slot_map[t][k]);
        EXPECT_EQ(std::set<uint32_t>(map.begin(), map.end()).size(), 8u) << t;
        maps.insert(map);
        // The slot map is the point map on a 2-voxel cell.
        for (uint32_t k = 0; k < 8; ++k) EXPECT_EQ(slot_corner(map[k]), moved(t, slot_corner(k), 2)) << t;
        EXPECT_EQ(G::compose(t, G::inverse(t)), 0u);
        EXPECT_EQ(G::compose(G::inverse(t), t), 0u);
        for (uint32_t k = 0; k < 8; ++k) EXPECT_EQ(G::source_slot(t, map[k]), k);
        for (uint32_t mask : {0x01u, 0x03u, 0x16u, 0x81u, 0xffu})
            for (uint32_t k = 0; k < 8; ++k)
                EXPECT_EQ(bool(G::transform_mask(t, mask) & (1u << map[k])), bool(mask & (1u << k)));
    }
    EXPECT_EQ(maps.size(), 48u);
    for (uint32_t a = 0; a < G::kSize; ++a)
        for (uint32_t b = 0; b < G::kSize; ++b) {
            for (uint32_t k = 0; k < 8; ++k)
                EXPECT_EQ(detail::kCubeTables.slot_map[G::compose(a, b)][k],
                          detail::kCubeTables.slot_map[a][detail::kCubeTables.slot_map[b][k]]);
            if (a < 8 && b < 8) {
                EXPECT_EQ(G::compose(a, b), ReflectionGroup::compose(a, b));
            }
        }
    for (uint32_t t = 0; t < 8; ++t)
        for (uint32_t mask = 0; mask < 256; ++mask)
            EXPECT_EQ(G::transform_mask(t, mask), ReflectionGroup::transform_mask(t, mask));
}

TEST(SymmetricMerge, EveryLevelHoldsOneNodePerSymmetryClass) {
    for (uint32_t n : {4u, 8u, 16u}) {
        for (uint32_t seed : {1u, 2u}) {
            const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(n), mixed_voxels(n, seed));
            std::mt19937 rng(seed * 7 + n);
            const Svdag noise = Svdag::from_voxels(gilab::test::unit_grid(n), gilab::test::random_voxels(rng, n, 0.3));
            for (const Svdag* dag : {&svdag, &noise}) {
                EXPECT_EQ(count_symmetric_dag<ReflectionGroup>(*dag).level_nodes, classes_per_level(*dag, 8)) << n;
                EXPECT_EQ(count_symmetric_dag<CubeSymmetryGroup>(*dag).level_nodes, classes_per_level(*dag, 48)) << n;
            }
        }
    }
}

TEST(SymmetricMerge, ExpandsBackToTheSvdagsVoxels) {
    for (uint32_t n : {2u, 13u, 32u, 64u}) {
        const std::vector<uint64_t> codes = mixed_voxels(n, n);
        const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(n), codes);
        EXPECT_EQ(expanded_codes(SymmetricMerge<ReflectionGroup>(svdag)), codes) << n;
        EXPECT_EQ(expanded_codes(SymmetricMerge<CubeSymmetryGroup>(svdag)), codes) << n;
    }
}

TEST(SymmetricMerge, AnAxisSwappedCopyMergesOnlyUnderPermutations) {
    // Two voxels side by side along x in one 2³ cell, along y in the next: no reflection
    // turns one into the other, swapping x and y does.
    const std::vector<uint64_t> codes = codes_of({UVec3(0, 0, 0), UVec3(1, 0, 0), UVec3(2, 0, 0), UVec3(2, 1, 0)});
    const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(4), codes);
    const SymmetricDagCounts reflections = count_symmetric_dag<ReflectionGroup>(svdag);
    const SymmetricDagCounts cube = count_symmetric_dag<CubeSymmetryGroup>(svdag);
    EXPECT_EQ(reflections.level_nodes, (std::vector<uint64_t>{1, 2, 1}));
    EXPECT_EQ(cube.level_nodes, (std::vector<uint64_t>{1, 1, 1}));
    EXPECT_EQ(cube.pointers, 2u);
    EXPECT_EQ(cube.permuting_pointers, 1u);
    EXPECT_EQ(reflections.permuting_pointers, 0u);
    EXPECT_EQ(cube.word_bytes, 4u * (1 + 2) + 4u);  // the root's header and 2 pointers, one word of masks
    const SymmetricMerge<CubeSymmetryGroup> merge(svdag);
    EXPECT_EQ(expanded_codes(merge), codes);
}

TEST(SymmetricMerge, ReflectionsGiveTheSsvdagsSizes) {
    for (uint32_t n : {1u, 8u, 32u, 100u}) {
        const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(n), mixed_voxels(n, 3));
        const Ssvdag ssvdag = Ssvdag::from_svdag(svdag);
        const SymmetricDagCounts c = count_symmetric_dag<ReflectionGroup>(svdag);
        EXPECT_EQ(c.nodes, ssvdag.node_count()) << n;
        EXPECT_EQ(c.level_nodes, ssvdag.level_node_counts()) << n;
        EXPECT_EQ(c.pointers, ssvdag.pointer_count()) << n;
        EXPECT_EQ(c.transformed_pointers, ssvdag.transformed_pointer_count()) << n;
        EXPECT_EQ(c.word_bytes, ssvdag.word_bytes()) << n;
        const SymmetricDagCounts cube = count_symmetric_dag<CubeSymmetryGroup>(svdag);
        EXPECT_LE(cube.nodes, c.nodes) << n;
        EXPECT_LE(cube.word_bytes, c.word_bytes) << n;
    }
}

TEST(SymmetricMerge, SameNodesWithOneAndTwoThreads) {
    const std::vector<uint64_t> codes = mixed_voxels(64, 5);
    const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(64), codes);
    auto tables_of = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        const SymmetricMerge<CubeSymmetryGroup> merge(svdag);
        std::vector<std::vector<uint32_t>> words;
        for (const DagLevelTable& t : merge.tables()) {
            words.emplace_back();
            for (uint32_t u = 0; u < t.size(); ++u) {
                words.back().push_back(t.header(u));
                for (uint32_t r : t.children(u)) words.back().push_back(r);
            }
        }
        words.emplace_back(merge.leaf_masks().begin(), merge.leaf_masks().end());
        words.push_back({merge.root_ref()});
        return words;
    };
    EXPECT_EQ(tables_of(1), tables_of(2));
}

TEST(SymmetricMerge, EmptyAndSingleVoxelGrids) {
    const Svdag empty = Svdag::from_voxels(gilab::test::unit_grid(8), std::vector<uint64_t>{});
    const SymmetricDagCounts none = count_symmetric_dag<CubeSymmetryGroup>(empty);
    EXPECT_EQ(none.nodes, 0u);
    EXPECT_EQ(none.word_bytes, 0u);
    const std::vector<uint64_t> voxel = {morton_encode(UVec3(5, 2, 7))};
    const Svdag one = Svdag::from_voxels(gilab::test::unit_grid(8), voxel);
    const SymmetricDagCounts single = count_symmetric_dag<CubeSymmetryGroup>(one);
    EXPECT_EQ(single.level_nodes, (std::vector<uint64_t>{1, 1, 1, 1}));
    EXPECT_EQ(expanded_codes(SymmetricMerge<CubeSymmetryGroup>(one)), voxel);
}
