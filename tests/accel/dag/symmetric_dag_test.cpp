// Symmetry-aware DAGs: in the SSVDAG subtrees equal up to a reflection share one node with
// the right mirrors, in the cube-symmetric DAG subtrees equal up to an axis permutation as
// well; both hold exactly one node per class of their group on every level, and answer
// decode, point queries and ray casts exactly as the SVDAG they were built from.
#include <gtest/gtest.h>
#include <algorithm>
#include <bit>
#include <initializer_list>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>
#include <tbb/global_control.h>
#include "accel/dag/dag_ray_caster.hpp"
#include "accel/dag/symmetric_dag.hpp"
#include "accel/dag/symmetric_dag_ray_caster.hpp"
#include "accel/dag/svdag.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/scene/scene.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/test_support.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;
using gilab::test::TriangleSoup;

namespace {

TriangleSoup merged(std::vector<TriangleSoup> parts) {
    TriangleSoup all;
    for (const TriangleSoup& p : parts) {
        const uint32_t base = uint32_t(all.positions.size());
        all.positions.insert(all.positions.end(), p.positions.begin(), p.positions.end());
        for (UVec3 t : p.triangles) all.triangles.push_back(t + UVec3(base));
    }
    return all;
}

// Two spheres and random triangles: repeats and noise (as the SVDAG tests use).
std::vector<uint64_t> mixed_voxels(uint32_t n) {
    std::mt19937 rng(n);
    const TriangleSoup soup = merged({gilab::test::uv_sphere(Vec3(0.3f), 0.2f, 10, 20),
                                      gilab::test::uv_sphere(Vec3(0.7f, 0.3f, 0.7f), 0.2f, 10, 20),
                                      gilab::test::random_triangles(rng, 20, Vec3(0.5f, 0.6f, 0.1f),
                                                                    Vec3(0.9f, 0.95f, 0.5f))});
    return voxelize(soup.positions, soup.triangles, gilab::test::unit_grid(n)).codes;
}

// A sphere in the middle of the grid: every octant a mirror image of the others.
std::vector<uint64_t> centred_sphere_voxels(uint32_t n) {
    const TriangleSoup m = gilab::test::uv_sphere(Vec3(0.5f), 0.4f, 24, 48);
    return voxelize(m.positions, m.triangles, gilab::test::unit_grid(n)).codes;
}

std::vector<uint64_t> sorted_codes(std::vector<UVec3> voxels) {
    std::vector<uint64_t> codes;
    for (const UVec3& v : voxels) codes.push_back(morton_encode(v));
    std::sort(codes.begin(), codes.end());
    codes.erase(std::unique(codes.begin(), codes.end()), codes.end());
    return codes;
}

// Voxels of a cell of `side` voxels reflected by `mirror` about the cell's centre planes.
std::vector<UVec3> reflected(const std::vector<UVec3>& voxels, uint32_t mirror, uint32_t side) {
    std::vector<UVec3> out;
    for (UVec3 v : voxels) {
        for (int a = 0; a < 3; ++a)
            if (mirror & (1u << a)) v[a] = side - 1 - v[a];
        out.push_back(v);
    }
    return out;
}

std::vector<UVec3> shifted(std::vector<UVec3> voxels, const UVec3& by) {
    for (UVec3& v : voxels) v += by;
    return voxels;
}

UVec3 octant_corner(int slot, uint32_t half) { return UVec3(slot & 1, (slot >> 1) & 1, (slot >> 2) & 1) * half; }

// An L-shaped tetromino with a stray voxel: no reflection maps it onto itself.
const std::vector<UVec3> kAsymmetric = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {0, 0, 1}, {3, 2, 1}};

// Subtree below a node as sorted local Morton codes, for any DAG: child(node, level, slot)
// returns the child or nullopt.
template <class Node, class Child>
std::vector<uint64_t> subtree_codes(const Node& node, int level, int depth, Child&& child) {
    std::vector<uint64_t> codes;
    struct Item {
        Node node;
        int level;
        uint64_t code;
    };
    std::vector<Item> stack{{node, level, 0}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        if (it.level == depth) {
            codes.push_back(it.code);
            continue;
        }
        for (int s = 0; s < 8; ++s)
            if (auto c = child(it.node, it.level, s)) stack.push_back({*c, it.level + 1, it.code << 3 | uint64_t(s)});
    }
    std::sort(codes.begin(), codes.end());
    return codes;
}

// Voxels of a cell of `side` voxels moved by cube symmetry t (node_symmetry.hpp): the
// axes permuted by t / 8, then reflected by t % 8 (for t < 8, `reflected`).
std::vector<UVec3> transformed(const std::vector<UVec3>& voxels, uint32_t t, uint32_t side) {
    std::vector<UVec3> out;
    for (const UVec3& v : voxels) {
        UVec3 m;
        for (int a = 0; a < 3; ++a) m[a] = v[detail::kAxisOf[t >> 3][a]];
        out.push_back(m);
    }
    return reflected(out, t & 7u, side);
}

// The smallest of a subtree's images under the group (coordinates within a cell of `side`
// voxels): equal for two subtrees exactly when the group maps one onto the other.
template <class Group>
std::vector<uint64_t> symmetry_class(const std::vector<uint64_t>& codes, uint32_t side) {
    std::vector<UVec3> voxels;
    for (uint64_t c : codes) voxels.push_back(morton_decode(c));
    std::vector<uint64_t> best;
    for (uint32_t t = 0; t < Group::kSize; ++t) {
        std::vector<uint64_t> r = sorted_codes(transformed(voxels, t, side));
        if (t == 0 || r < best) best = r;
    }
    return best;
}

// Classes of non-empty child masks under the group: the most nodes the voxels' parents' level can hold.
template <class Group>
size_t mask_classes() {
    std::set<uint32_t> smallest;
    for (uint32_t mask = 1; mask < 256; ++mask) {
        uint32_t best = mask;
        for (uint32_t t = 0; t < Group::kSize; ++t) best = std::min<uint32_t>(best, Group::transform_mask(t, mask));
        smallest.insert(best);
    }
    return smallest.size();
}

std::vector<uint64_t> svdag_subtree(const Svdag& dag, uint32_t node, int level) {
    return subtree_codes(node, level, dag.depth(), [&](uint32_t n, int, int s) -> std::optional<uint32_t> {
        const uint32_t c = dag.child(n, s);
        return c == kInvalidNode ? std::nullopt : std::optional<uint32_t>(c);
    });
}

template <class Dag>
std::vector<uint64_t> symmetric_dag_subtree(const Dag& dag, const SymmetricDagPointer& node, int level) {
    return subtree_codes(node, level, dag.depth(),
                         [&](const SymmetricDagPointer& n, int l, int s) { return dag.child(n, l, s); });
}

// The DAG is minimal over its group: on every level its nodes are pairwise inequivalent
// and there are exactly as many as there are classes among the SVDAG's nodes; each stored
// node decodes to a subtree of one of those classes.
template <class Dag>
void expect_one_node_per_class(const Svdag& svdag, const Dag& dag) {
    using Group = typename Dag::SymmetryGroup;
    for (int l = 0; l < dag.depth(); ++l) {
        const uint32_t side = 1u << (dag.depth() - l);
        std::set<std::vector<uint64_t>> svdag_classes, dag_classes;
        for (uint32_t a : svdag.level_nodes(l))
            svdag_classes.insert(symmetry_class<Group>(svdag_subtree(svdag, a, l), side));
        const std::vector<uint32_t> nodes = dag.level_nodes(l);
        ASSERT_EQ(nodes.size(), dag.level_node_counts()[l]);
        for (uint32_t a : nodes) {
            const auto cls = symmetry_class<Group>(symmetric_dag_subtree(dag, SymmetricDagPointer{a, 0}, l), side);
            EXPECT_TRUE(dag_classes.insert(cls).second) << "level " << l << ": two nodes are images of each other";
            EXPECT_TRUE(svdag_classes.count(cls)) << "level " << l << ": a node of no SVDAG subtree";
        }
        EXPECT_EQ(dag_classes.size(), svdag_classes.size()) << "level " << l;
    }
}

// Everything the DAG answers from its units, against the SVDAG.
template <class Dag>
void expect_same_voxels(const Svdag& svdag, const Dag& dag, const std::string& what) {
    EXPECT_EQ(dag.decode(), svdag.decode()) << what;
    EXPECT_EQ(dag.voxel_count(), svdag.voxel_count()) << what;
    EXPECT_EQ(dag.depth(), svdag.depth()) << what;
    EXPECT_LE(dag.node_count(), svdag.node_count()) << what;
    EXPECT_LE(dag.bytes(), svdag.bytes()) << what;
    ASSERT_EQ(dag.level_node_counts().size(), svdag.level_node_counts().size()) << what;
    for (size_t l = 0; l < dag.level_node_counts().size(); ++l)
        EXPECT_LE(dag.level_node_counts()[l], svdag.level_node_counts()[l]) << what << ", level " << l;
    EXPECT_LE(dag.pointer_count(), svdag.pointer_count()) << what;
}

// Units of the node at `address` on an interior level: header, short and long pointers.
template <class Dag>
uint32_t node_units(const Dag& dag, uint32_t address) {
    const uint32_t header = dag.units()[address];
    return 1 + uint32_t(std::popcount(header & 0xffu)) + uint32_t(std::popcount(header >> 8));
}

// The layout of symmetric_dag.hpp: every pointer names a node of the level below, it is long
// exactly when the child lies beyond a short pointer's reach, each level is ordered by
// references per unit (most first), and the counts and bytes follow from the units.
template <class Dag>
void check_storage(const Dag& dag) {
    ASSERT_FALSE(dag.empty());
    const auto units = dag.units();
    size_t pointers = 0, transformed = 0, long_pointers = 0, interior_units = 0, words = 0;
    for (int l = 0; l + 1 < dag.depth(); ++l) {
        const bool to_leaves = l + 2 == dag.depth();
        const uint32_t below_begin = to_leaves ? 0 : dag.level_begin(l + 1);
        std::vector<uint32_t> below_nodes = dag.level_nodes(l + 1);
        std::map<uint32_t, uint64_t> references;
        for (uint32_t a : dag.level_nodes(l)) {
            const uint32_t mask = units[a] & 0xffu, long_mask = units[a] >> 8u;
            ASSERT_NE(mask, 0u);
            ASSERT_EQ(long_mask & ~mask, 0u) << "long-pointer bits only on children";
            for (uint32_t slot = 0; slot < 8; ++slot) {
                if (!(mask & (1u << slot))) continue;
                const SymmetricDagPointer p = dag.stored_child(a, l, slot);
                ASSERT_TRUE(std::ranges::binary_search(below_nodes, p.address)) << "level " << l;
                const bool is_long = (long_mask >> slot) & 1u;
                EXPECT_EQ(is_long, p.address - below_begin >= Dag::kShortOffsetLimit)
                    << "level " << l << ": a pointer is short exactly when its child is within reach";
                ++references[p.address];
                transformed += p.transform != 0;
                long_pointers += is_long;
                ++pointers;
            }
            interior_units += node_units(dag, a);
            words += 1 + std::popcount(mask);
        }
        // Every node below is reached, and the level is ordered by references per unit.
        EXPECT_EQ(references.size(), below_nodes.size()) << "level " << l + 1;
        for (size_t i = 1; i < below_nodes.size(); ++i) {
            const uint32_t a = below_nodes[i - 1], b = below_nodes[i];
            const uint64_t size_a = to_leaves ? 1 : node_units(dag, a), size_b = to_leaves ? 1 : node_units(dag, b);
            ASSERT_GE(references[a] * size_b, references[b] * size_a) << "level " << l + 1 << ", node " << i;
        }
    }
    EXPECT_EQ(dag.leaf_begin(), interior_units);
    EXPECT_EQ(pointers, dag.pointer_count());
    EXPECT_EQ(transformed, dag.transformed_pointer_count());
    EXPECT_EQ(long_pointers, dag.long_pointer_count());
    const size_t leaves = dag.level_node_counts()[dag.depth() - 1];
    EXPECT_LE(leaves, mask_classes<typename Dag::SymmetryGroup>()) << "one node per class of non-empty masks";
    EXPECT_EQ(dag.bytes(), 2 * (interior_units + (leaves + 1) / 2));
    EXPECT_EQ(dag.word_bytes(), 4 * (words + (leaves + 3) / 4));
    for (uint32_t i = 0; i < leaves; ++i) EXPECT_NE(dag.leaf_mask(i), 0);
}

// Ray casts agree exactly with cast_dag_ray on the SVDAG: both walk the same cells in the
// same order, so hit, voxel, distance and visits are identical.
template <class Dag>
void expect_same_rays(const Svdag& svdag, const Dag& dag, const std::vector<Ray>& rays, const std::string& what) {
    const DagWordsView view = dag_view(svdag);
    int hits = 0, mismatches = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        const VoxelRayHit want = cast_dag_ray(view, rays[i]);
        const VoxelRayHit got = cast_symmetric_dag_ray(dag, rays[i]);
        hits += want.hit;
        const bool same = got.hit == want.hit && got.voxel == want.voxel && got.t == want.t &&
                          got.nodes_visited == want.nodes_visited;
        if (!same && ++mismatches <= 5)
            ADD_FAILURE() << what << ", ray " << i << ": hit " << got.hit << "/" << want.hit << " voxel ("
                          << got.voxel.x << "," << got.voxel.y << "," << got.voxel.z << ")/(" << want.voxel.x << ","
                          << want.voxel.y << "," << want.voxel.z << ") t " << got.t << "/" << want.t << " visits "
                          << got.nodes_visited << "/" << want.nodes_visited;
    }
    EXPECT_EQ(mismatches, 0) << what;
    EXPECT_GT(hits, int(rays.size()) / 8) << what << ": too few rays meet the geometry to test much";
}

// The shared test rays plus random rays from anywhere, some cut short by tmax.
std::vector<Ray> many_rays(uint32_t seed) {
    std::vector<Ray> rays = gilab::test::traversal_test_rays();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 2000; ++i) {
        Ray r;
        r.origin = gilab::test::random_point(rng, Vec3(-0.5f), Vec3(1.5f));
        r.direction = gilab::test::random_point(rng, Vec3(0.1f), Vec3(0.9f)) - r.origin;
        if (i % 4 == 0) r.tmax = 0.3f + u(rng);
        if (i % 7 == 0) r.direction = gilab::test::random_point(rng, Vec3(-1.0f), Vec3(1.0f));
        rays.push_back(r);
    }
    return rays;
}

template <class Dag>
void expect_same_points(const Svdag& svdag, const Dag& dag, const std::vector<uint64_t>& codes, uint32_t seed) {
    std::mt19937 rng(seed);
    const VoxelGrid& g = svdag.grid();
    int occupied = 0;
    for (int i = 0; i < 4000; ++i) {
        Vec3 p = gilab::test::random_point(rng, g.origin - Vec3(0.05f * g.extent), g.origin + Vec3(1.05f * g.extent));
        if (i % 2 == 0 && !codes.empty()) p = g.cell_bounds(morton_decode(codes[rng() % codes.size()])).center();
        const bool want = svdag.occupied(p);
        ASSERT_EQ(dag.occupied(p), want) << "point " << i;
        occupied += want;
    }
    if (!codes.empty()) {
        EXPECT_GT(occupied, 1000);
    }
    for (uint64_t c : codes) ASSERT_TRUE(dag.contains_voxel(morton_decode(c)));
    const uint32_t n = g.octree_size();
    for (int i = 0; i < 4000; ++i) {
        const UVec3 v(rng() % (n + 2), rng() % (n + 2), rng() % (n + 2));
        ASSERT_EQ(dag.contains_voxel(v), svdag.contains_voxel(v));
    }
}

}  // namespace

TEST(Ssvdag, MirrorImagesInSiblingOctantsShareOneNode) {
    // Octant 0 holds the shape, octant 1 its reflection along x about the octant's centre.
    const VoxelGrid grid = gilab::test::unit_grid(8);
    std::vector<UVec3> voxels = kAsymmetric;
    const auto mirror_x = shifted(reflected(kAsymmetric, 1, 4), octant_corner(1, 4));
    voxels.insert(voxels.end(), mirror_x.begin(), mirror_x.end());
    const std::vector<uint64_t> codes = sorted_codes(voxels);
    const Svdag svdag = Svdag::from_voxels(grid, codes);
    const Ssvdag dag = Ssvdag::from_svdag(svdag);
    EXPECT_EQ(svdag.level_node_counts()[1], 2u);
    EXPECT_EQ(dag.level_node_counts()[1], 1u) << "a shape and its mirror image are one node";
    const auto a = dag.child(dag.root(), 0, 0), b = dag.child(dag.root(), 0, 1);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->address, b->address);
    EXPECT_EQ(a->transform ^ b->transform, 1u) << "the two views differ by the x reflection";
    // The root's header holds the mask and no long pointers; its two short pointers carry
    // those mirrors in their top 3 bits.
    const uint32_t root = dag.root().address, rm = dag.root().transform;
    ASSERT_EQ(dag.units()[root], uint32_t(reflect_mask(0b11, rm)));
    const uint32_t first = dag.units()[root + 1], second = dag.units()[root + 2];
    EXPECT_EQ(first & Ssvdag::kShortOffsetMask, second & Ssvdag::kShortOffsetMask);
    EXPECT_EQ((first ^ second) >> Ssvdag::kShortTransformShift, 1u);
    EXPECT_EQ(dag.decode(), codes);
    check_storage(dag);
}

TEST(Ssvdag, AllEightReflectionsOfAShapeShareOneNode) {
    // Octant k holds the shape reflected by k: one stored node, seen under all 8 mirrors.
    const VoxelGrid grid = gilab::test::unit_grid(8);
    std::vector<UVec3> voxels;
    for (uint32_t k = 0; k < 8; ++k) {
        const auto part = shifted(reflected(kAsymmetric, k, 4), octant_corner(int(k), 4));
        voxels.insert(voxels.end(), part.begin(), part.end());
    }
    std::set<std::vector<uint64_t>> distinct;
    for (uint32_t m = 0; m < 8; ++m) distinct.insert(sorted_codes(reflected(kAsymmetric, m, 4)));
    ASSERT_EQ(distinct.size(), 8u) << "the test shape must have no symmetry";

    const std::vector<uint64_t> codes = sorted_codes(voxels);
    const Svdag svdag = Svdag::from_voxels(grid, codes);
    const Ssvdag dag = Ssvdag::from_svdag(svdag);
    EXPECT_EQ(svdag.level_node_counts()[1], 8u);
    EXPECT_EQ(dag.level_node_counts()[1], 1u);
    const auto base = dag.child(dag.root(), 0, 0);
    ASSERT_TRUE(base);
    for (int k = 0; k < 8; ++k) {
        const auto c = dag.child(dag.root(), 0, k);
        ASSERT_TRUE(c);
        EXPECT_EQ(c->address, base->address) << "slot " << k;
        EXPECT_EQ(c->transform ^ base->transform, uint32_t(k)) << "slot " << k;
    }
    // The whole scene is symmetric under every reflection: the root is seen unmirrored.
    EXPECT_EQ(dag.root().transform, 0u);
    EXPECT_EQ(dag.decode(), codes);
    expect_same_rays(svdag, dag, many_rays(1), "8 reflections");
}

TEST(Ssvdag, SymmetricSubtreesGetTheSmallestMirror) {
    const VoxelGrid grid = gilab::test::unit_grid(8);
    std::vector<UVec3> voxels;
    // Octant 0: a full 4³ block, unchanged by every reflection: mirror 0.
    for (uint32_t z = 0; z < 4; ++z)
        for (uint32_t y = 0; y < 4; ++y)
            for (uint32_t x = 0; x < 4; ++x) voxels.push_back({x, y, z});
    // Octant 1: a shape symmetric along x only; octant 2 its reflection along y. Each is
    // named by the smaller of its two mirrors, so bit 0 of both is clear.
    const std::vector<UVec3> x_symmetric = {{0, 0, 0}, {3, 0, 0}, {1, 1, 2}, {2, 1, 2}, {1, 3, 3},
                                            {2, 3, 3}, {0, 2, 1}, {3, 2, 1}, {1, 0, 3}, {2, 0, 3}};
    ASSERT_EQ(sorted_codes(reflected(x_symmetric, 1, 4)), sorted_codes(x_symmetric));
    for (uint32_t m : {2u, 4u}) ASSERT_NE(sorted_codes(reflected(x_symmetric, m, 4)), sorted_codes(x_symmetric));
    const auto one = shifted(x_symmetric, octant_corner(1, 4));
    const auto two = shifted(reflected(x_symmetric, 2, 4), octant_corner(2, 4));
    voxels.insert(voxels.end(), one.begin(), one.end());
    voxels.insert(voxels.end(), two.begin(), two.end());
    const std::vector<uint64_t> codes = sorted_codes(voxels);
    const Svdag svdag = Svdag::from_voxels(grid, codes);
    const Ssvdag dag = Ssvdag::from_svdag(svdag);

    const auto pointer_at = [&](int slot) {
        return dag.stored_child(dag.root().address, 0, uint32_t(slot) ^ dag.root().transform);
    };
    // Stored pointers name each subtree by the smallest of its equivalent mirrors.
    EXPECT_EQ(pointer_at(0).transform, 0u);
    const SymmetricDagPointer a = pointer_at(1), b = pointer_at(2);
    EXPECT_EQ(a.address, b.address);
    EXPECT_EQ(a.transform & 1u, 0u);
    EXPECT_EQ(b.transform & 1u, 0u);
    EXPECT_EQ(a.transform ^ b.transform, 2u);
    EXPECT_EQ(dag.child(dag.root(), 0, 1)->address, a.address);
    EXPECT_EQ(dag.level_node_counts()[1], 2u);
    EXPECT_EQ(dag.decode(), codes);
    // Canonical and unique: building again gives the same words and root.
    const Ssvdag again = Ssvdag::from_svdag(svdag);
    EXPECT_TRUE(std::ranges::equal(again.units(), dag.units()));
    EXPECT_EQ(again.root(), dag.root());
}

template <class Dag>
class SymmetricDagTest : public ::testing::Test {};
using SymmetricDags = ::testing::Types<Ssvdag, CubeSymmetricDag>;
TYPED_TEST_SUITE(SymmetricDagTest, SymmetricDags);

TYPED_TEST(SymmetricDagTest, EveryLevelHoldsOneNodePerSymmetryClass) {
    for (uint32_t n : {2u, 8u, 13u, 32u}) {
        const VoxelGrid grid = gilab::test::unit_grid(n);
        const std::vector<uint64_t> codes = mixed_voxels(n);
        const Svdag svdag = Svdag::from_voxels(grid, codes);
        const TypeParam dag = TypeParam::from_svdag(svdag);
        expect_one_node_per_class(svdag, dag);
    }
    for (double fill : {0.05, 0.5, 0.95}) {
        std::mt19937 rng(unsigned(fill * 1000));
        const std::vector<uint64_t> codes = gilab::test::random_voxels(rng, 16, fill);
        const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(16), codes);
        expect_one_node_per_class(svdag, TypeParam::from_svdag(svdag));
    }
    const std::vector<uint64_t> sphere = centred_sphere_voxels(32);
    const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(32), sphere);
    expect_one_node_per_class(svdag, TypeParam::from_svdag(svdag));
}

TYPED_TEST(SymmetricDagTest, DecodesToTheSvdagsVoxels) {
    for (uint32_t n : {1u, 2u, 3u, 13u, 32u, 64u, 100u, 256u}) {
        const VoxelGrid grid = gilab::test::unit_grid(n);
        const std::vector<uint64_t> codes = mixed_voxels(n);
        const Svdag svdag = Svdag::from_voxels(grid, codes);
        const TypeParam dag = TypeParam::from_svdag(svdag);
        expect_same_voxels(svdag, dag, "mixed " + std::to_string(n));
        EXPECT_EQ(dag.decode(), codes);
        if (dag.depth() > 0) check_storage(dag);
    }
    for (uint32_t n : {2u, 5u, 24u, 64u})
        for (double fill : {0.01, 0.3, 0.97}) {
            std::mt19937 rng(n * 1000 + unsigned(fill * 100));
            const std::vector<uint64_t> codes = gilab::test::random_voxels(rng, n, fill);
            const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(n), codes);
            const TypeParam dag = TypeParam::from_svdag(svdag);
            expect_same_voxels(svdag, dag, "random " + std::to_string(n) + " fill " + std::to_string(fill));
            if (!codes.empty()) check_storage(dag);
        }
}

TYPED_TEST(SymmetricDagTest, EveryMaskOfADepthOneGrid) {
    const VoxelGrid grid = gilab::test::unit_grid(2);
    const std::vector<Ray> rays = many_rays(3);
    for (uint32_t mask = 1; mask < 256; ++mask) {
        std::vector<uint64_t> codes;
        for (uint64_t s = 0; s < 8; ++s)
            if (mask & (1u << s)) codes.push_back(s);
        const Svdag svdag = Svdag::from_voxels(grid, codes);
        const TypeParam dag = TypeParam::from_svdag(svdag);
        ASSERT_EQ(dag.decode(), codes) << "mask " << mask;
        ASSERT_EQ(dag.mask(dag.root(), 0), mask);
        ASSERT_EQ(dag.voxel_count(), codes.size());
        ASSERT_EQ(dag.bytes(), 2u) << "one mask byte in one unit";
        for (size_t i = 0; i < rays.size(); i += 7) {
            const VoxelRayHit want = cast_dag_ray(dag_view(svdag), rays[i]), got = cast_symmetric_dag_ray(dag, rays[i]);
            ASSERT_EQ(got.hit, want.hit) << "mask " << mask << " ray " << i;
            ASSERT_EQ(got.voxel, want.voxel) << "mask " << mask << " ray " << i;
            ASSERT_EQ(got.t, want.t);
        }
    }
}

namespace {

// A mesh from the shared scenes at several resolutions: storage, decode, points and rays.
template <class Dag>
void check_shared_mesh(const std::string& asset, std::initializer_list<uint32_t> resolutions) {
    const auto path = gilab::test::shared_asset(asset);
    if (!path) GTEST_SKIP() << asset << " not found in the shared scenes";
    const Scene scene = load_mesh_file(*path);
    const SceneFrame frame = scene.evaluate(0.0);
    for (uint32_t n : resolutions) {
        const VoxelGrid grid = VoxelGrid::enclosing(frame.bounds, n);
        const std::vector<uint64_t> codes = voxelize(frame, grid).codes;
        const Svdag svdag = Svdag::from_voxels(grid, codes);
        const Dag dag = Dag::from_svdag(svdag);
        const std::string what = asset + " at " + std::to_string(n);
        expect_same_voxels(svdag, dag, what);
        check_storage(dag);
        EXPECT_LT(dag.node_count(), svdag.node_count()) << what;
        EXPECT_LT(dag.bytes(), dag.word_bytes()) << what << ": short pointers save bytes";
        expect_same_points(svdag, dag, codes, n);
        // The shared rays are set up for the unit cube: move them onto the grid.
        expect_same_rays(svdag, dag, gilab::test::moved_onto(many_rays(n), grid), what);
    }
}

}  // namespace

TYPED_TEST(SymmetricDagTest, StanfordBunnyMatchesTheSvdag) { check_shared_mesh<TypeParam>("bunny/stanford-bunny.obj", {64, 256}); }

TYPED_TEST(SymmetricDagTest, SponzaMatchesTheSvdag) { check_shared_mesh<TypeParam>("sponza/sponza.obj", {512}); }

TYPED_TEST(SymmetricDagTest, PointQueriesMatchTheSvdag) {
    for (uint32_t n : {16u, 48u, 100u}) {
        const std::vector<uint64_t> codes = mixed_voxels(n);
        const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(n), codes);
        expect_same_points(svdag, TypeParam::from_svdag(svdag), codes, n);
    }
    std::mt19937 rng(4);
    const std::vector<uint64_t> codes = gilab::test::random_voxels(rng, 32, 0.2);
    const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(32), codes);
    expect_same_points(svdag, TypeParam::from_svdag(svdag), codes, 4);
}

TYPED_TEST(SymmetricDagTest, RayCastsMatchCastDagRay) {
    for (uint32_t resolution : {4u, 8u, 64u, 512u}) {
        const VoxelGrid grid = gilab::test::unit_grid(resolution);
        const TriangleSoup soup = gilab::test::clutter_and_sphere(3);
        const Svdag svdag = Svdag::from_voxels(grid, voxelize(soup.positions, soup.triangles, grid).codes);
        expect_same_rays(svdag, TypeParam::from_svdag(svdag), many_rays(resolution), std::to_string(resolution) + "³");
    }
    std::mt19937 rng(17);
    const std::vector<uint64_t> random = gilab::test::random_voxels(rng, 32, 0.01);
    const Svdag random_dag = Svdag::from_voxels(gilab::test::unit_grid(32), random);
    expect_same_rays(random_dag, TypeParam::from_svdag(random_dag), many_rays(32), "random voxels");

    const Svdag sphere = Svdag::from_voxels(gilab::test::unit_grid(128), centred_sphere_voxels(128));
    expect_same_rays(sphere, TypeParam::from_svdag(sphere), many_rays(128), "centred sphere");

    // The offset grid: the rays move with it.
    const VoxelGrid grid = gilab::test::offset_grid();
    const TriangleSoup soup = gilab::test::moved_onto(gilab::test::clutter_and_sphere(9), grid);
    const Svdag offset = Svdag::from_voxels(grid, voxelize(soup.positions, soup.triangles, grid).codes);
    const std::vector<Ray> rays = gilab::test::moved_onto(many_rays(48), grid);
    expect_same_rays(offset, TypeParam::from_svdag(offset), rays, "offset 48³ grid");
}

TYPED_TEST(SymmetricDagTest, NodesBeyondAShortPointersReachGetLongPointers) {
    // Random voxels: about 4000 distinct nodes of 9–17 units on the level above the
    // voxels' parents, far more than a short pointer's 2^13 units reach.
    std::mt19937 rng(23);
    const std::vector<uint64_t> codes = gilab::test::random_voxels(rng, 64, 0.3);
    const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(64), codes);
    const TypeParam dag = TypeParam::from_svdag(svdag);
    ASSERT_GT(dag.level_begin(dag.depth() - 1) - dag.level_begin(dag.depth() - 2), 2 * TypeParam::kShortOffsetLimit);
    EXPECT_GT(dag.long_pointer_count(), 0u);
    EXPECT_LT(dag.long_pointer_count(), dag.pointer_count()) << "the most referenced nodes stay within reach";
    check_storage(dag);
    expect_same_voxels(svdag, dag, "random 64³");
    expect_same_points(svdag, dag, codes, 5);
    expect_same_rays(svdag, dag, many_rays(64), "random 64³");
}

TYPED_TEST(SymmetricDagTest, NeverMoreNodesAndFewerOnASymmetricScene) {
    for (uint32_t n : {32u, 128u, 256u}) {
        const std::vector<uint64_t> codes = centred_sphere_voxels(n);
        const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(n), codes);
        const TypeParam dag = TypeParam::from_svdag(svdag);
        expect_same_voxels(svdag, dag, "sphere " + std::to_string(n));
        EXPECT_LT(dag.node_count(), svdag.node_count()) << n;
        EXPECT_LT(dag.bytes(), svdag.bytes()) << n;
        // Mirror images of one another: the root's children are one node.
        EXPECT_EQ(dag.level_node_counts()[1], 1u) << n;
        EXPECT_GT(dag.transformed_pointer_count(), 0u);
    }
}

TYPED_TEST(SymmetricDagTest, SameUnitsWithOneAndTwoThreads) {
    std::mt19937 rng(6);
    const std::vector<uint64_t> codes = gilab::test::random_voxels(rng, 100, 0.05);
    const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(100), codes);
    ASSERT_GT(svdag.level_node_counts()[5], 10000u) << "enough nodes on a level to split among threads";
    std::vector<TypeParam> builds;
    for (size_t threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        builds.push_back(TypeParam::from_svdag(svdag));
    }
    EXPECT_TRUE(std::ranges::equal(builds[0].units(), builds[1].units()));
    EXPECT_EQ(builds[0].root(), builds[1].root());
    EXPECT_EQ(builds[0].level_node_counts(), builds[1].level_node_counts());
    EXPECT_EQ(builds[0].decode(), codes);
}

TYPED_TEST(SymmetricDagTest, EmptyAndSingleVoxelGrids) {
    const Svdag empty_svdag = Svdag::from_voxels(gilab::test::unit_grid(8), std::vector<uint64_t>{});
    const TypeParam empty = TypeParam::from_svdag(empty_svdag);
    EXPECT_TRUE(empty.empty());
    EXPECT_TRUE(empty.decode().empty());
    EXPECT_EQ(empty.node_count(), 0u);
    EXPECT_EQ(empty.bytes(), 0u);
    EXPECT_EQ(empty.voxel_count(), 0u);
    EXPECT_FALSE(empty.contains_voxel({0, 0, 0}));
    EXPECT_FALSE(empty.occupied(Vec3(0.5f)));
    for (const Ray& r : gilab::test::traversal_test_rays()) ASSERT_FALSE(cast_symmetric_dag_ray(empty, r).hit);
    EXPECT_FALSE(cast_symmetric_dag_ray(TypeParam{}, Ray{}).hit);

    const std::vector<uint64_t> one{0};
    const Svdag single_svdag = Svdag::from_voxels(gilab::test::unit_grid(1), one);
    const TypeParam single = TypeParam::from_svdag(single_svdag);
    EXPECT_FALSE(single.empty());
    EXPECT_EQ(single.depth(), 0);
    EXPECT_EQ(single.decode(), one);
    EXPECT_EQ(single.voxel_count(), 1u);
    EXPECT_TRUE(single.occupied(Vec3(0.5f)));
    Ray r;
    r.origin = Vec3(0.5f, 0.5f, -1.0f);
    r.direction = Vec3(0, 0, 1);
    const VoxelRayHit hit = cast_symmetric_dag_ray(single, r);
    ASSERT_TRUE(hit.hit);
    EXPECT_FLOAT_EQ(hit.t, 1.0f);
    r.origin.x = 1.5f;
    EXPECT_FALSE(cast_symmetric_dag_ray(single, r).hit);
}

TEST(Ssvdag, PointersHold29BitAddressesAnd3BitMirrors) {
    const uint32_t w = Ssvdag::encode_long_pointer(Ssvdag::kAddressLimit - 1, 5);
    EXPECT_EQ(Ssvdag::decode_long_pointer(w), (SymmetricDagPointer{Ssvdag::kAddressLimit - 1, 5}));
    EXPECT_EQ(Ssvdag::decode_long_pointer(Ssvdag::encode_long_pointer(12345, 0)), (SymmetricDagPointer{12345, 0}));
    EXPECT_NE(gilab::test::error_of([] { Ssvdag::encode_long_pointer(Ssvdag::kAddressLimit, 0); }).find("29 bits"),
              std::string::npos);
    EXPECT_NE(gilab::test::error_of([] { Ssvdag::encode_long_pointer(uint64_t(1) << 40, 1); }).find("29 bits"),
              std::string::npos);
    EXPECT_NE(gilab::test::error_of([] { Ssvdag::encode_long_pointer(0, 8); }).find("not one of the 8 reflections"), std::string::npos);
    for (uint32_t m = 0; m < 8; ++m)
        for (uint32_t mask = 0; mask < 256; ++mask) {
            ASSERT_EQ(reflect_mask(reflect_mask(mask, m), m), mask) << "a reflection is its own inverse";
            ASSERT_EQ(std::popcount(uint32_t(reflect_mask(mask, m))), std::popcount(mask));
        }
    EXPECT_EQ(reflect_mask(0b00000001, 1), 0b00000010);
    EXPECT_EQ(reflect_mask(0b00000001, 6), 0b01000000);
}

TYPED_TEST(SymmetricDagTest, StatsReportTheStorage) {
    const std::vector<uint64_t> codes = mixed_voxels(64);
    const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(64), codes);
    const TypeParam dag = TypeParam::from_svdag(svdag);
    const Stats s = dag.stats();
    EXPECT_EQ(s.get("nodes"), double(dag.node_count()));
    EXPECT_EQ(s.get("bytes"), double(dag.bytes()));
    EXPECT_EQ(s.get("pointers"), double(dag.pointer_count()));
    EXPECT_EQ(s.get("transformed_pointers"), double(dag.transformed_pointer_count()));
    EXPECT_EQ(s.get("long_pointers"), double(dag.long_pointer_count()));
    EXPECT_EQ(s.get("word_bytes"), double(dag.word_bytes()));
    EXPECT_EQ(s.get("input_nodes"), double(svdag.node_count()));
    EXPECT_EQ(s.get("nodes_level_0"), 1.0);
    EXPECT_GE(s.get("convert_ms"), s.get("dedup_ms"));
    EXPECT_GT(s.get("table_bytes"), 0.0);
}

TEST(CubeSymmetricDag, AnAxisPermutedSubtreeSharesOneNode) {
    // Octant 0 holds the asymmetric shape, octant 1 the same shape with x and y swapped:
    // no reflection maps one onto the other, a permutation does.
    std::vector<UVec3> voxels = kAsymmetric;
    const auto swapped = shifted(transformed(kAsymmetric, 2 * 8, 4), octant_corner(1, 4));  // permutation (y, x, z)
    voxels.insert(voxels.end(), swapped.begin(), swapped.end());
    const std::vector<uint64_t> codes = sorted_codes(voxels);
    const Svdag svdag = Svdag::from_voxels(gilab::test::unit_grid(8), codes);
    const Ssvdag reflections = Ssvdag::from_svdag(svdag);
    const CubeSymmetricDag dag = CubeSymmetricDag::from_svdag(svdag);
    EXPECT_EQ(reflections.level_node_counts()[1], 2u) << "the reflections keep both shapes";
    EXPECT_EQ(dag.level_node_counts()[1], 1u) << "a shape and its axis-swapped copy are one node";
    EXPECT_EQ(dag.decode(), codes);
    const auto a = dag.child(dag.root(), 0, 0), b = dag.child(dag.root(), 0, 1);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->address, b->address);
    // The two views differ by the x–y swap: b's transform is the swap after a's.
    EXPECT_EQ(b->transform, CubeSymmetryGroup::compose(2 * 8, a->transform));
    EXPECT_GE(dag.permuting_pointer_count(), 1u);
    // Rays through the swapped octant walk it in the stored node's permuted slot order.
    const DagWordsView view = dag_view(svdag);
    int hits = 0;
    for (const Ray& r : many_rays(8)) {
        const VoxelRayHit want = cast_dag_ray(view, r), got = cast_symmetric_dag_ray(dag, r);
        ASSERT_EQ(got.hit, want.hit);
        ASSERT_EQ(got.voxel, want.voxel);
        ASSERT_EQ(got.t, want.t);
        hits += want.voxel.x >= 4 && want.hit;
    }
    EXPECT_GT(hits, 50) << "rays reach the swapped octant";
}

TEST(CubeSymmetricDag, NeverMoreNodesThanTheSsvdagOnAnyLevel) {
    const auto path = gilab::test::shared_asset("bunny/stanford-bunny.obj");
    std::vector<Svdag> dags;
    for (uint32_t n : {32u, 64u}) dags.push_back(Svdag::from_voxels(gilab::test::unit_grid(n), mixed_voxels(n)));
    if (path) {
        const SceneFrame frame = load_mesh_file(*path).evaluate(0.0);
        const VoxelGrid grid = VoxelGrid::enclosing(frame.bounds, 256);
        dags.push_back(Svdag::from_voxels(grid, voxelize(frame, grid).codes));
    }
    bool fewer = false;
    for (const Svdag& svdag : dags) {
        const Ssvdag reflections = Ssvdag::from_svdag(svdag);
        const CubeSymmetricDag cube = CubeSymmetricDag::from_svdag(svdag);
        for (size_t l = 0; l < cube.level_node_counts().size(); ++l)
            EXPECT_LE(cube.level_node_counts()[l], reflections.level_node_counts()[l]) << "level " << l;
        EXPECT_LE(cube.word_bytes(), reflections.word_bytes());
        fewer |= cube.node_count() < reflections.node_count();
    }
    EXPECT_TRUE(fewer) << "the permutations merge some subtree the reflections cannot";
}

TEST(CubeSymmetricDag, PointersHold26BitAddressesAnd6BitTransforms) {
    using Dag = CubeSymmetricDag;
    EXPECT_EQ(Dag::kShortOffsetLimit, 1u << 10);
    const uint32_t w = Dag::encode_long_pointer(Dag::kAddressLimit - 1, 47);
    EXPECT_EQ(Dag::decode_long_pointer(w), (SymmetricDagPointer{Dag::kAddressLimit - 1, 47}));
    EXPECT_EQ(Dag::decode_long_pointer(Dag::encode_long_pointer(12345, 9)), (SymmetricDagPointer{12345, 9}));
    EXPECT_NE(gilab::test::error_of([] { Dag::encode_long_pointer(Dag::kAddressLimit, 0); }).find("26 bits"),
              std::string::npos);
    EXPECT_NE(gilab::test::error_of([] { Dag::encode_long_pointer(0, 48); }).find("not one of the 48 cube symmetries"),
              std::string::npos);
}
