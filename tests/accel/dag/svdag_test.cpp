// SVDAG: bottom-up merge decodes to the SVO's voxels, leaves no duplicate node on any
// level, gives the same DAG from a split build, and the position API round-trips.
#include <gtest/gtest.h>
#include <algorithm>
#include <bit>
#include <map>
#include <random>
#include <set>
#include "accel/dag/dag_level_table.hpp"
#include "accel/dag/octree_path.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/util/morton.hpp"
#include "core/util/parallel.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/test_support.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;

namespace {

VoxelList sphere_voxels(uint32_t n) {
    auto m = gilab::test::uv_sphere(Vec3(0.5f), 0.4f, 16, 32);
    return voxelize(m.positions, m.triangles, gilab::test::unit_grid(n));
}

// Two spheres and a box of random triangles: a scene with repeats and with noise.
VoxelList mixed_voxels(uint32_t n) {
    auto a = gilab::test::uv_sphere(Vec3(0.3f), 0.2f, 10, 20);
    auto b = gilab::test::uv_sphere(Vec3(0.7f, 0.3f, 0.7f), 0.2f, 10, 20);
    std::mt19937 rng(n);
    auto c = gilab::test::random_triangles(rng, 20, Vec3(0.5f, 0.6f, 0.1f), Vec3(0.9f, 0.95f, 0.5f));
    for (auto* extra : {&b, &c}) {
        uint32_t base = uint32_t(a.positions.size());
        a.positions.insert(a.positions.end(), extra->positions.begin(), extra->positions.end());
        for (UVec3 t : extra->triangles) a.triangles.push_back(t + UVec3(base));
    }
    return voxelize(a.positions, a.triangles, gilab::test::unit_grid(n));
}

void check_storage(const Svdag& dag) {
    ASSERT_FALSE(dag.empty());
    const auto words = dag.words();
    size_t nodes = 0, pointers = 0;
    for (int l = 0; l <= dag.depth(); ++l) {
        auto level = dag.level_nodes(l);
        EXPECT_EQ(level.size(), dag.level_node_counts()[l]) << "level " << l;
        std::set<std::vector<uint32_t>> seen;
        std::set<uint32_t> next_level;
        if (l < dag.depth()) {
            auto below = dag.level_nodes(l + 1);
            next_level.insert(below.begin(), below.end());
        }
        for (uint32_t a : level) {
            uint32_t mask = words[a];
            int k = std::popcount(mask);
            ASSERT_LE(mask, 0xffu) << "the mask word holds only 8 bits";
            if (l < dag.depth()) {
                ASSERT_GT(k, 0);
                // 8..36 bytes per interior node; each pointer addresses a node one level down.
                size_t bytes = 4 * (1 + k);
                ASSERT_TRUE(bytes >= 8 && bytes <= 36);
                for (int i = 0; i < k; ++i) ASSERT_TRUE(next_level.count(words[a + 1 + i])) << "level " << l;
                for (int s = 0; s < 8; ++s)
                    if (mask & (1u << s)) {
                        ASSERT_EQ(dag.child(a, s), words[a + 1 + std::popcount(mask & ((1u << s) - 1))]);
                    }
            } else {
                ASSERT_EQ(k, 0);
            }
            std::vector<uint32_t> key(words.begin() + a, words.begin() + a + 1 + k);
            EXPECT_TRUE(seen.insert(key).second) << "two identical nodes on level " << l;
            pointers += k;
        }
        nodes += level.size();
    }
    EXPECT_EQ(dag.level_node_counts()[dag.depth()], 1u) << "all leaves merge into one";
    EXPECT_EQ(nodes, dag.node_count());
    EXPECT_EQ(pointers, dag.pointer_count());
    EXPECT_EQ(dag.bytes(), 4 * (nodes + pointers));
}

}  // namespace

TEST(Svdag, FromSvoDecodesToTheSameVoxels) {
    for (uint32_t n : {1u, 2u, 13u, 32u, 64u, 100u}) {
        VoxelList v = mixed_voxels(n);
        Svo svo = Svo::build(v);
        Svdag dag = Svdag::from_svo(svo);
        EXPECT_EQ(dag.decode(), svo.decode()) << "N = " << n;
        EXPECT_EQ(dag.voxel_count(), svo.voxel_count());
        check_storage(dag);
        EXPECT_LE(dag.node_count(), svo.node_count());
        EXPECT_EQ(dag.level_node_counts()[0], 1u);
    }
}

TEST(Svdag, RandomVoxelSets) {
    for (double fill : {0.02, 0.5, 0.97}) {
        std::mt19937 rng(unsigned(fill * 100));
        auto codes = gilab::test::random_voxels(rng, 24, fill);
        Svo svo = Svo::build(gilab::test::unit_grid(24), codes);
        Svdag dag = Svdag::from_svo(svo);
        EXPECT_EQ(dag.decode(), codes);
        check_storage(dag);
    }
}

TEST(Svdag, SplitBuildsGiveTheSameDag) {
    VoxelList v = mixed_voxels(100);  // depth 7
    Svdag whole = Svdag::from_svo(Svo::build(v));
    for (int split = 0; split <= whole.depth(); ++split) {
        Svdag dag = Svdag::from_voxels(v, split);
        EXPECT_EQ(dag.level_node_counts(), whole.level_node_counts()) << "split level " << split;
        // Ids follow first appearance in Morton order either way, so even the words agree.
        EXPECT_TRUE(std::equal(dag.words().begin(), dag.words().end(), whole.words().begin(), whole.words().end()))
            << "split level " << split;
        if (split > 0) {
            EXPECT_GT(dag.build_stats().subtrees, 1u);
        }
    }
}

TEST(Svdag, SplitBuildFromTheVoxelizerStreamsCells) {
    auto m = gilab::test::uv_sphere(Vec3(0.45f, 0.5f, 0.55f), 0.37f, 16, 32);
    VoxelGrid g = gilab::test::unit_grid(200);  // depth 8, not a power of two
    Voxelizer vox(m.positions, m.triangles, g);
    Svdag whole = Svdag::from_svo(Svo::build(vox.voxelize()));
    // Split 7: cells of 2³ voxels, smaller than the voxelizer's 4³ blocks.
    for (int split : {1, 3, 4, 7}) {
        Svdag dag = Svdag::from_voxelizer(vox, split);
        EXPECT_EQ(dag.level_node_counts(), whole.level_node_counts()) << "split level " << split;
        EXPECT_EQ(dag.decode(), whole.decode());
        EXPECT_GE(dag.build_stats().subtrees, 1u);
        EXPECT_GT(dag.build_stats().voxelize_ms, 0.0);
    }
}

// Geometry lying exactly on the faces of the streamed build's cells: axis-aligned quads on
// the planes x = 1/2, y = 1/4, z = 3/4 and a quad along the edge line x = y = 1/2.
TEST(Svdag, StreamedBuildGivesTheInMemoryWordsWithGeometryOnCellFaces) {
    gilab::test::TriangleSoup m;
    auto quad = [&](Vec3 a, Vec3 b, Vec3 c, Vec3 d) { m.add(a, b, c); m.add(a, c, d); };
    quad(Vec3(0.5f, 0.1f, 0.1f), Vec3(0.5f, 0.9f, 0.1f), Vec3(0.5f, 0.9f, 0.9f), Vec3(0.5f, 0.1f, 0.9f));
    quad(Vec3(0.1f, 0.25f, 0.1f), Vec3(0.9f, 0.25f, 0.1f), Vec3(0.9f, 0.25f, 0.9f), Vec3(0.1f, 0.25f, 0.9f));
    quad(Vec3(0.1f, 0.1f, 0.75f), Vec3(0.9f, 0.1f, 0.75f), Vec3(0.9f, 0.9f, 0.75f), Vec3(0.1f, 0.9f, 0.75f));
    quad(Vec3(0.5f, 0.5f, 0.0f), Vec3(0.5f, 0.5f, 1.0f), Vec3(0.55f, 0.55f, 1.0f), Vec3(0.55f, 0.55f, 0.0f));
    const VoxelGrid g = gilab::test::unit_grid(512);
    Voxelizer vox(m.positions, m.triangles, g);
    const Svdag in_memory = Svdag::from_voxels(vox.voxelize());
    for (int split : {1, 2, 3, 5}) {  // cells of 256³, 128³, 64³ and 16³ voxels
        const Svdag streamed = Svdag::from_voxelizer(vox, split);
        EXPECT_TRUE(std::ranges::equal(streamed.words(), in_memory.words())) << "split level " << split;
    }
}

// Real scenes, whose triangles cross the cells' faces everywhere: the streamed build
// (voxelize a cell, merge its subtree, go on) gives the in-memory build's words.
TEST(Svdag, StreamedBuildGivesTheInMemoryWordsOnSharedScenes) {
    struct Case {
        std::string asset;
        uint32_t resolution;
        std::vector<int> splits;
    };
    const Case cases[] = {{"bunny/stanford-bunny.obj", 512, {1, 4}},
                          {"sponza/sponza.obj", 1024, {2, 5}},
                          {"bunny/stanford-bunny.obj", 2048, {3}}};
    std::string missing;
    for (const Case& c : cases) {
        const auto path = gilab::test::shared_asset(c.asset);
        if (!path) {
            missing += c.asset + " ";
            continue;
        }
        const SceneFrame frame = load_mesh_file(*path).evaluate(0.0);
        Voxelizer vox(frame, VoxelGrid::enclosing(frame.bounds, c.resolution));
        const Svdag in_memory = Svdag::from_voxels(vox.voxelize());
        ASSERT_GT(in_memory.node_count(), 1000u) << c.asset;
        for (int split : c.splits) {
            const Svdag streamed = Svdag::from_voxelizer(vox, split);
            EXPECT_TRUE(std::ranges::equal(streamed.words(), in_memory.words()))
                << c.asset << " at " << c.resolution << "³, split level " << split;
            EXPECT_GT(streamed.build_stats().subtrees, 1u);
        }
    }
    if (!missing.empty()) GTEST_SKIP() << "not found in the shared scenes: " << missing;
}

// The streamed build reports each cell as it goes, and stops with an Error naming how
// far it got when its merge tables pass their limit; at any thread count it gives the
// same words (the next batch is voxelized while one merges).
TEST(Svdag, StreamedBuildReportsProgressAndStopsAtItsTableLimit) {
    auto m = gilab::test::uv_sphere(Vec3(0.45f, 0.5f, 0.55f), 0.37f, 16, 32);
    Voxelizer vox(m.positions, m.triangles, gilab::test::unit_grid(256));
    const Svdag whole = Svdag::from_voxels(vox.voxelize());
    std::vector<size_t> done;
    size_t cells = 0;
    SvdagStreamOptions options;
    options.progress = [&](size_t d, size_t c) {
        done.push_back(d);
        cells = c;
    };
    const Svdag streamed = Svdag::from_voxelizer(vox, 3, options);
    EXPECT_TRUE(std::ranges::equal(streamed.words(), whole.words()));
    ASSERT_GT(cells, 8u);
    ASSERT_FALSE(done.empty());
    EXPECT_TRUE(std::ranges::is_sorted(done));
    EXPECT_EQ(done.back(), cells);
    for (int threads : {1, 2}) {
        ThreadLimit limit(threads);
        EXPECT_TRUE(std::ranges::equal(Svdag::from_voxelizer(vox, 3).words(), whole.words())) << threads << " threads";
    }

    options.progress = nullptr;
    options.max_table_bytes = whole.build_stats().table_bytes / 4;
    ASSERT_GT(options.max_table_bytes, 0u);
    const std::string error = gilab::test::error_of([&] { Svdag::from_voxelizer(vox, 3, options); });
    EXPECT_NE(error.find("merge tables hold"), std::string::npos) << error;
    EXPECT_NE(error.find("of " + std::to_string(cells) + " cells"), std::string::npos) << error;
}

TEST(Svdag, FromSlicesRejectsBadSlices) {
    VoxelGrid g = gilab::test::unit_grid(16);
    auto expect_error = [&](auto&& fn, const std::string& text) {
        try {
            fn();
            ADD_FAILURE() << "no error";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    };
    std::vector<uint64_t> cells{0, 1};
    expect_error([&] { Svdag::from_slices(g, 1, cells, [](uint64_t) { return std::vector<uint64_t>{morton_encode(15, 15, 15)}; }); },
                 "outside its split cell");
    expect_error([&] { Svdag::from_voxels(g, std::vector<uint64_t>{5, 3}, 0); }, "ascending");
    expect_error([&] { Svdag::from_voxels(g, std::vector<uint64_t>{}, 9); }, "split level");
}

TEST(Svdag, EmptyAndTinyGrids) {
    Svdag empty = Svdag::from_svo(Svo::build(gilab::test::unit_grid(8), {}));
    EXPECT_TRUE(empty.empty());
    EXPECT_EQ(empty.node_count(), 0u);
    EXPECT_FALSE(empty.contains_voxel({0, 0, 0}));
    EXPECT_FALSE(empty.locate(Vec3(0.5f)).occupied);
    std::vector<uint64_t> one{0};
    Svdag single = Svdag::from_voxels(gilab::test::unit_grid(1), one);
    EXPECT_EQ(single.depth(), 0);
    EXPECT_EQ(single.decode(), one);
    EXPECT_TRUE(single.occupied(Vec3(0.5f)));
}

TEST(Svdag, PathAndBoxRoundTrip) {
    VoxelGrid g;
    g.origin = Vec3(-2.0f, 1.0f, 0.5f);
    g.extent = 3.0f;
    g.resolution = 45;  // octree of 64 voxels per axis
    const int depth = g.depth();
    ASSERT_EQ(depth, 6);
    std::mt19937 rng(8);
    std::uniform_int_distribution<int> slot(0, 7), level(0, depth);
    for (int i = 0; i < 500; ++i) {
        OctreePath p;
        int l = level(rng);
        for (int k = 0; k < l; ++k) p.slots.push_back(uint8_t(slot(rng)));
        OctreeCell c = path_to_cell(p, depth);
        EXPECT_EQ(c.size, 1u << (depth - l));
        EXPECT_EQ(voxel_path(c.first, l, depth), p);
        EXPECT_EQ(morton_path(path_morton(p), l), p);
        Bounds3 box = path_to_box(g, p);
        auto back = box_to_path(g, box, l);
        ASSERT_TRUE(back.has_value());
        EXPECT_EQ(*back, p);
        // The box's centre lies in the cell, so its leaf path starts with p.
        auto leaf = point_to_path(g, box.center());
        if (leaf) {
            EXPECT_TRUE(std::equal(p.slots.begin(), p.slots.end(), leaf->slots.begin()));
        }
    }
    EXPECT_THROW(path_to_cell(OctreePath{{1, 2, 3, 4, 5, 6, 7}}, depth), Error);
    EXPECT_THROW(path_to_cell(OctreePath{{9}}, depth), Error);
}

TEST(Svdag, LocateFollowsTheDagToTheLeaf) {
    VoxelList v = sphere_voxels(48);
    Svo svo = Svo::build(v);
    Svdag dag = Svdag::from_svo(svo);
    std::mt19937 rng(21);
    int occupied = 0;
    for (int i = 0; i < 3000; ++i) {
        // Half the points inside occupied voxels, half anywhere.
        Vec3 p = gilab::test::random_point(rng, Vec3(-0.05f), Vec3(1.05f));
        if (i % 2 == 0) {
            UVec3 vox = v.voxel(rng() % v.size());
            Bounds3 b = v.grid.cell_bounds(vox);
            p = b.center();
        }
        DagLocation loc = dag.locate(p);
        ASSERT_EQ(loc.occupied, svo.occupied(p));
        auto path = point_to_path(v.grid, p);
        ASSERT_EQ(loc.inside_grid, path.has_value());
        if (!path) continue;
        EXPECT_EQ(loc.path, *path);
        if (loc.occupied) {
            ++occupied;
            EXPECT_EQ(loc.reached_level, dag.depth());
            EXPECT_TRUE(path_to_box(v.grid, loc.path).contains(p));
        } else {
            EXPECT_LT(loc.reached_level, dag.depth());
        }
        // The node reached is the one the path prefix leads to.
        OctreePath prefix{std::vector<uint8_t>(loc.path.slots.begin(), loc.path.slots.begin() + loc.reached_level)};
        DagLocation again = dag.follow(prefix);
        EXPECT_TRUE(again.occupied);
        EXPECT_EQ(again.node, loc.node);
    }
    EXPECT_GT(occupied, 1000);
}

TEST(DagLevelTable, SameKeySameIdAcrossGrowth) {
    DagLevelTable table;
    std::mt19937 rng(2);
    std::vector<std::vector<uint32_t>> keys;
    std::set<std::vector<uint32_t>> distinct;
    for (int i = 0; i < 20000; ++i) {
        std::vector<uint32_t> key{uint32_t(rng() % 256)};  // header, then up to 8 children
        int k = int(rng() % 9);
        for (int c = 0; c < k; ++c) key.push_back(rng() % 50);
        keys.push_back(key);
        distinct.insert(key);
    }
    std::map<std::vector<uint32_t>, uint32_t> first_id;
    for (const auto& key : keys) {
        uint32_t id = table.find_or_insert(key[0], key.data() + 1, uint32_t(key.size() - 1));
        auto [it, fresh] = first_id.emplace(key, id);
        ASSERT_EQ(it->second, id);
        if (fresh) {
            ASSERT_EQ(id, first_id.size() - 1) << "ids are dense, in order of first insertion";
        }
    }
    EXPECT_EQ(table.size(), distinct.size());
    for (const auto& [key, id] : first_id) {
        ASSERT_EQ(table.header(id), key[0]);
        auto kids = table.children(id);
        ASSERT_TRUE(std::equal(kids.begin(), kids.end(), key.begin() + 1, key.end()));
    }
}
