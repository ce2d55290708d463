// Multi-frame DAG (P2 §4): every frame's root decodes to that frame, both build modes
// give the same node set, identical frames share everything below their roots, and
// updates rebuild only what differs while reclaiming what no frame uses any more.
#include <gtest/gtest.h>
#include <algorithm>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include "accel/dag/child_mask.hpp"
#include "accel/temporal/multi_frame_dag.hpp"
#include "accel/dag/svdag.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;
using gilab::test::TriangleSoup;

namespace {

void append(TriangleSoup& to, const TriangleSoup& from) {
    const uint32_t base = uint32_t(to.positions.size());
    to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
    for (UVec3 t : from.triangles) to.triangles.push_back(t + UVec3(base));
}

// A static sphere and static clutter, with a sphere moving along x: most cells are the
// same from frame to frame.
std::vector<uint64_t> moving_sphere_frame(int frame, uint32_t n = 64) {
    TriangleSoup soup = gilab::test::uv_sphere(Vec3(0.75f, 0.75f, 0.3f), 0.15f, 10, 20);
    std::mt19937 rng(7);
    append(soup, gilab::test::random_triangles(rng, 12, Vec3(0.05f, 0.6f, 0.6f), Vec3(0.45f, 0.95f, 0.95f)));
    append(soup, gilab::test::uv_sphere(Vec3(0.2f + 0.06f * float(frame), 0.3f, 0.5f), 0.14f, 10, 20));
    return voxelize(soup.positions, soup.triangles, gilab::test::unit_grid(n)).codes;
}

std::vector<std::vector<uint64_t>> moving_sphere_frames(int count, uint32_t n = 64) {
    std::vector<std::vector<uint64_t>> frames;
    for (int f = 0; f < count; ++f) frames.push_back(moving_sphere_frame(f, n));
    return frames;
}

MultiFrameDag build_incremental(const std::vector<std::vector<uint64_t>>& frames, uint32_t n = 64) {
    MultiFrameDag dag(gilab::test::unit_grid(n));
    for (const auto& f : frames) dag.append_frame(f);
    return dag;
}

std::vector<uint32_t> words_of(const LaidOutMultiFrameDag& t) { return {t.words().begin(), t.words().end()}; }

// The cells of `split` level holding voxels of either frame, and those whose voxels differ.
std::vector<uint64_t> cells_of(const std::vector<uint64_t>& codes, int shift) {
    std::vector<uint64_t> cells;
    for (uint64_t c : codes)
        if (cells.empty() || cells.back() != (c >> shift)) cells.push_back(c >> shift);
    return cells;
}

// Streaming input for `now` with dirty cells relative to `before`.
FrameCells streamed(const std::vector<uint64_t>& now, const std::vector<uint64_t>& before, int split, int depth) {
    const int shift = 3 * (depth - split);
    FrameCells fc;
    fc.split_level = split;
    fc.cells = cells_of(now, shift);
    std::vector<uint64_t> changed;
    std::set_symmetric_difference(now.begin(), now.end(), before.begin(), before.end(), std::back_inserter(changed));
    fc.dirty = cells_of(changed, shift);
    fc.dirty->erase(std::unique(fc.dirty->begin(), fc.dirty->end()), fc.dirty->end());
    fc.slice = [&now, shift](uint64_t cell) {
        std::vector<uint64_t> out;
        for (uint64_t c : now)
            if ((c >> shift) == cell) out.push_back(c);
        return out;
    };
    return fc;
}

template <class Fn>
void expect_error(Fn&& fn, const std::string& text) {
    try {
        fn();
        ADD_FAILURE() << "no error for: " << text;
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
}

}  // namespace

TEST(MultiFrameDag, EveryRootDecodesItsFrame) {
    const auto frames = moving_sphere_frames(6);
    ASSERT_NE(frames[0], frames[1]);
    MultiFrameDag dag = build_incremental(frames);
    LaidOutMultiFrameDag t = dag.lay_out();
    ASSERT_EQ(t.frame_count(), frames.size());
    EXPECT_EQ(t.level_node_counts()[0], frames.size()) << "one root per frame";
    for (size_t f = 0; f < frames.size(); ++f) {
        EXPECT_EQ(t.decode(f), frames[f]) << "frame " << f;
        const Svdag alone = Svdag::from_voxels(gilab::test::unit_grid(64), frames[f]);
        EXPECT_EQ(t.reachable_node_count(f), alone.node_count()) << "frame " << f;
        const UVec3 v = morton_decode(frames[f][frames[f].size() / 2]);
        EXPECT_TRUE(t.contains_voxel(f, v));
    }
    EXPECT_EQ(t.node_count(), dag.node_count());
    EXPECT_EQ(t.bytes(), 4 * (t.node_count() + t.pointer_count()));
    EXPECT_DOUBLE_EQ(t.nodes_per_frame(), double(t.node_count()) / double(frames.size()));
}

TEST(MultiFrameDag, IncrementalEqualsAllAtOnce) {
    auto frames = moving_sphere_frames(5);
    frames.insert(frames.begin() + 2, std::vector<uint64_t>{});  // an empty frame in between
    const VoxelGrid grid = gilab::test::unit_grid(64);
    const int depth = grid.depth();

    MultiFrameDag incremental = build_incremental(frames);
    std::vector<Svdag> per_frame;
    for (const auto& f : frames) per_frame.push_back(Svdag::from_voxels(grid, f, 2));
    MultiFrameDag at_once = MultiFrameDag::merge_all(per_frame);

    MultiFrameDag streaming(grid);
    uint64_t reused = 0;
    for (size_t f = 0; f < frames.size(); ++f) {
        const std::vector<uint64_t> none;
        FrameMergeStats s = streaming.append_frame(streamed(frames[f], f ? frames[f - 1] : none, 3, depth));
        reused += s.cells_reused;
    }
    EXPECT_GT(reused, 0u) << "clean cells must reuse the previous frame's subtrees";

    const LaidOutMultiFrameDag a = incremental.lay_out(), b = at_once.lay_out(), c = streaming.lay_out();
    EXPECT_EQ(words_of(a), words_of(b));
    EXPECT_EQ(words_of(a), words_of(c));
    EXPECT_EQ(a.level_node_counts(), b.level_node_counts());
    EXPECT_EQ(incremental.node_count(), at_once.node_count());
    EXPECT_EQ(incremental.live_level_counts(), at_once.live_level_counts());
    EXPECT_EQ(incremental.live_level_counts(), streaming.live_level_counts());
    EXPECT_EQ(a.root(2), LaidOutMultiFrameDag::kEmptyFrame);
    EXPECT_EQ(c.decode(3), frames[3]);
}

TEST(MultiFrameDag, IdenticalFramesShareEverythingBelowTheRoot) {
    const auto a = moving_sphere_frame(0), b = moving_sphere_frame(3);
    MultiFrameDag aba = build_incremental({a, b, a});
    MultiFrameDag ab = build_incremental({a, b});
    const LaidOutMultiFrameDag t = aba.lay_out();
    EXPECT_EQ(t.level_node_counts()[0], 3u) << "a repeated frame keeps its own root";
    const uint32_t r0 = t.root(0), r2 = t.root(2);
    ASSERT_NE(r0, r2);
    const uint32_t k = child_count(t.words()[r0]);
    EXPECT_TRUE(std::equal(t.words().begin() + r0, t.words().begin() + r0 + 1 + k, t.words().begin() + r2))
        << "the two roots of frame A point at the same children";
    EXPECT_EQ(aba.node_count(), ab.node_count() + 1);

    MultiFrameDag aa = build_incremental({a, a});
    const Svdag alone = Svdag::from_voxels(gilab::test::unit_grid(64), a);
    EXPECT_EQ(aa.node_count(), alone.node_count() + 1);
}

TEST(MultiFrameDag, OneFrameEqualsPlainSvdag) {
    for (uint32_t n : {1u, 13u, 64u}) {
        const auto a = moving_sphere_frame(2, n);
        const Svdag plain = Svdag::from_voxels(gilab::test::unit_grid(n), a);
        const LaidOutMultiFrameDag t = build_incremental({a}, n).lay_out();
        EXPECT_EQ(t.decode(0), plain.decode()) << "N = " << n;
        EXPECT_EQ(t.level_node_counts(), plain.level_node_counts()) << "N = " << n;
        EXPECT_EQ(t.node_count(), plain.node_count());
        EXPECT_EQ(t.pointer_count(), plain.pointer_count());
        EXPECT_EQ(t.bytes(), plain.bytes());
    }
}

TEST(MultiFrameDag, UpdateThatChangesNothingAddsNoNode) {
    const auto frames = moving_sphere_frames(3);
    MultiFrameDag dag = build_incremental(frames);
    const auto tables = dag.table_level_counts();
    const auto words = words_of(dag.lay_out());
    FrameMergeStats s = dag.update_frame(1, frames[1]);
    EXPECT_EQ(s.nodes_added, 0u);
    EXPECT_EQ(s.nodes_reclaimed, 0u);
    EXPECT_EQ(dag.table_level_counts(), tables);
    EXPECT_EQ(words_of(dag.lay_out()), words);
    // Streamed with no dirty cell: nothing is voxelized or merged again.
    FrameMergeStats streamed_stats = dag.update_frame(1, streamed(frames[1], frames[1], 3, dag.depth()));
    EXPECT_EQ(streamed_stats.cells_rebuilt, 0u);
    EXPECT_EQ(streamed_stats.nodes_added, 0u);
    EXPECT_EQ(words_of(dag.lay_out()), words);
}

TEST(MultiFrameDag, UpdateReclaimsUnreferencedNodes) {
    const auto a = moving_sphere_frame(0), b = moving_sphere_frame(2), c = moving_sphere_frame(4);
    const auto d = moving_sphere_frame(7), e = moving_sphere_frame(9);
    for (bool use_dirty_cells : {false, true}) {
        MultiFrameDag dag = build_incremental({a, b, c});
        const uint64_t before = dag.node_count();
        FrameMergeStats s = use_dirty_cells ? dag.update_frame(1, streamed(d, b, 3, dag.depth()))
                                            : dag.update_frame(1, d);
        MultiFrameDag fresh = build_incremental({a, d, c});
        EXPECT_EQ(words_of(dag.lay_out()), words_of(fresh.lay_out()));
        EXPECT_EQ(dag.node_count(), fresh.node_count());
        EXPECT_GT(s.nodes_reclaimed, 0u) << "frame B's own nodes are no longer used";
        EXPECT_GT(s.nodes_added, 0u);
        EXPECT_EQ(s.nodes_reclaimed, before + s.nodes_added - fresh.node_count());
        if (use_dirty_cells) {
            EXPECT_GT(s.cells_reused, 0u);
        }

        const auto words = words_of(dag.lay_out());
        EXPECT_NE(dag.table_level_counts(), dag.live_level_counts()) << "dead nodes wait for compact()";
        dag.compact();
        EXPECT_EQ(dag.table_level_counts(), dag.live_level_counts());
        EXPECT_EQ(words_of(dag.lay_out()), words);
        EXPECT_EQ(dag.live_level_counts(), fresh.live_level_counts());
        // Appending after compaction (fresh ids, no stale caches) still merges correctly.
        dag.append_frame(e);
        fresh.append_frame(e);
        EXPECT_EQ(words_of(dag.lay_out()), words_of(fresh.lay_out()));
        EXPECT_EQ(dag.lay_out().decode(3), e);
    }
}

TEST(MultiFrameDag, RefCountsMatchRecount) {
    const auto frames = moving_sphere_frames(10);
    MultiFrameDag dag = build_incremental({frames[0], frames[1], frames[2], frames[3]});
    std::mt19937 rng(11);
    for (int step = 0; step < 12; ++step) {
        const size_t slot = rng() % dag.frame_count();
        const auto& with = frames[rng() % frames.size()];
        if (step % 3 == 2)
            dag.update_frame(slot, std::vector<uint64_t>{});  // an empty frame
        else
            dag.update_frame(slot, with);
        if (step == 6) dag.compact();
    }
    // Recount: one per frame for each root, one per pointer from a live node.
    const auto& tables = dag.tables();
    std::vector<std::map<uint32_t, uint32_t>> expected(dag.depth() + 1);
    std::vector<std::pair<int, uint32_t>> stack;
    for (uint32_t r : dag.root_ids())
        if (r != MultiFrameDag::kEmptyFrame && expected[0][r]++ == 0) stack.push_back({0, r});
    while (!stack.empty()) {
        auto [l, id] = stack.back();
        stack.pop_back();
        for (uint32_t c : tables[l].children(id))
            if (expected[l + 1][c]++ == 0) stack.push_back({l + 1, c});
    }
    for (int l = 0; l <= dag.depth(); ++l) {
        EXPECT_EQ(dag.live_level_counts()[l], expected[l].size()) << "level " << l;
        for (uint32_t id = 0; id < tables[l].size(); ++id) {
            auto it = expected[l].find(id);
            ASSERT_EQ(dag.reference_count(l, id), it == expected[l].end() ? 0u : it->second)
                << "level " << l << " node " << id;
        }
    }
    const LaidOutMultiFrameDag t = dag.lay_out();
    for (size_t f = 0; f < dag.frame_count(); ++f) EXPECT_EQ(t.decode(f).empty(), dag.root_ids()[f] == MultiFrameDag::kEmptyFrame);
}

TEST(MultiFrameDag, EmptyFrameAndBadInput) {
    const VoxelGrid grid = gilab::test::unit_grid(16);
    MultiFrameDag dag(grid);
    dag.append_frame(std::vector<uint64_t>{1, 5, 9});
    dag.append_frame(std::vector<uint64_t>{});
    dag.append_frame(std::vector<uint64_t>{1, 5, 9});
    const LaidOutMultiFrameDag t = dag.lay_out();
    EXPECT_EQ(t.root(1), LaidOutMultiFrameDag::kEmptyFrame);
    EXPECT_TRUE(t.decode(1).empty());
    EXPECT_EQ(t.decode(2), (std::vector<uint64_t>{1, 5, 9}));
    EXPECT_EQ(t.level_node_counts()[0], 2u) << "an empty frame has no root node";

    expect_error([&] { dag.append_frame(std::vector<uint64_t>{5, 1}); }, "strictly ascending");
    expect_error([&] { dag.append_frame(std::vector<uint64_t>{1, morton_encode(16, 0, 0)}); }, "outside the 16^3 grid");
    expect_error([&] { dag.update_frame(3, std::vector<uint64_t>{1}); }, "cannot update frame 3");
    expect_error([&] { (void)t.decode(7); }, "frame 7");
    EXPECT_EQ(dag.frame_count(), 3u) << "a rejected frame is not appended";

    FrameCells bad;
    bad.split_level = 1;
    bad.cells = {0};
    bad.slice = [](uint64_t) { return std::vector<uint64_t>{morton_encode(15, 15, 15)}; };
    expect_error([&] { dag.append_frame(bad); }, "outside its split cell");
    bad.cells = {3, 2};
    bad.slice = [](uint64_t) { return std::vector<uint64_t>{}; };
    expect_error([&] { dag.append_frame(bad); }, "ascending");

    std::vector<Svdag> mixed{Svdag::from_voxels(grid, std::vector<uint64_t>{1}),
                             Svdag::from_voxels(gilab::test::unit_grid(32), std::vector<uint64_t>{1})};
    expect_error([&] { MultiFrameDag::merge_all(mixed); }, "different voxel grid");
}
