// Streaming an animation cell by cell (SequenceVoxelizer): the scene's node selection
// (which nodes move, evaluating only some of them) and, for every frame, slices whose
// concatenation is exactly the whole frame's voxelization (crowded cells and faces on
// cell boundaries included), clean cells whose slice is the previous frame's, dirty cells
// ascending inside the frame's cells, no dirty cell in a static scene after the first
// frame, and streamed DAGs (here and in build_animation_dag) equal to all-at-once ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "accel/temporal/multi_frame_dag.hpp"
#include "accel/temporal/sequence_voxelizer.hpp"
#include "accel/dag/svdag.hpp"
#include "core/util/error.hpp"
#include "core/scene/skin.hpp"
#include "core/voxel/voxelizer.hpp"
#include "scenes/fire_scene.hpp"
#include "scenes/procedural_meshes.hpp"
#include "accel/temporal/animation_dag.hpp"
#include "tests/masked_plane.hpp"
#include "tests/test_support.hpp"
#include "tests/voxel_test_meshes.hpp"

namespace {

using namespace gilab;
using gilab::test::error_of;

// Node indices of mixed_scene().
enum MixedNode : uint32_t { kFloor, kWall, kTiltedSlab, kCarrier, kRider, kJoint, kSkinned, kRiderOfSkinned };

// Static floor and wall lying exactly on cell faces of test_grid(), a static tilted slab,
// a carrier sliding and turning with a rider child (moved only by its parent), a joint
// that lifts a skinned box, and a static child of the skinned node. Times 0..1 s.
Scene mixed_scene() {
    Scene scene;
    scene.name = "mixed";
    scene.source = "test:mixed";
    scene.materials = {Material{}};
    scene.add_mesh_instance(make_box("floor", Vec3(-1.5f, -0.25f, -1.5f), Vec3(1.5f, 0.0f, 1.5f), 0));
    scene.add_mesh_instance(make_box("wall", Vec3(-1.5f, 0.0f, -1.5f), Vec3(1.5f, 1.0f, -1.0f), 0));
    Transform tilt;
    tilt.rotation = glm::angleAxis(glm::radians(23.0f), glm::normalize(Vec3(1, 0.4f, -0.3f)));
    tilt.translation = Vec3(0.9f, 0.6f, 0.7f);
    scene.add_mesh_instance(make_box("slab", Vec3(-0.3f, -0.05f, -0.3f), Vec3(0.3f, 0.05f, 0.3f), 0), tilt);

    const uint32_t carrier = scene.add_mesh_instance(make_box("carrier", Vec3(-0.2f), Vec3(0.2f), 0));
    TrsAnimation& slide = scene.nodes[carrier].animation;
    slide.translation = {{0.0f, 1.0f}, {Vec3(-0.8f, 0.3f, 0.2f), Vec3(0.4f, 0.3f, 0.2f)}};
    slide.rotation = {{0.0f, 1.0f}, {Quat(1, 0, 0, 0), glm::angleAxis(glm::radians(60.0f), Vec3(0, 1, 0))}};
    const uint32_t rider = scene.add_mesh_instance(make_box("rider", Vec3(-0.1f), Vec3(0.1f), 0));
    scene.nodes[rider].parent = int(carrier);
    scene.nodes[rider].local.translation = Vec3(0, 0.35f, 0);

    SceneNode joint;
    joint.name = "joint";
    joint.animation.translation = {{0.0f, 1.0f}, {Vec3(0), Vec3(0, 0.5f, 0)}};
    scene.nodes.push_back(joint);
    Mesh lifted = make_box("lifted", Vec3(0.5f, 0.0f, -0.6f), Vec3(0.8f, 0.3f, -0.3f), 0);
    lifted.influences.assign(lifted.positions.size(), VertexInfluences{{0, 0, 0, 0}, Vec4(1, 0, 0, 0)});
    scene.skins.push_back(Skin{"lift", {kJoint}, {Mat4(1.0f)}});
    const uint32_t skinned = scene.add_mesh_instance(std::move(lifted));
    scene.nodes[skinned].skin = 0;
    const uint32_t below = scene.add_mesh_instance(make_box("stool", Vec3(-1.2f, 0.0f, 0.8f), Vec3(-0.9f, 0.4f, 1.1f), 0));
    scene.nodes[below].parent = int(skinned);
    scene.validate();
    return scene;
}

// Voxels of 1/16, cells (split level 3) of 8 voxels = 0.5 units: the floor top (y = 0)
// and the wall front (z = -1) lie on cell faces.
VoxelGrid test_grid() {
    VoxelGrid grid;
    grid.origin = Vec3(-2.0f, -1.0f, -2.0f);
    grid.extent = 4.0f;
    grid.resolution = 64;
    return grid;
}

bool is_subset(const std::vector<uint64_t>& part, const std::vector<uint64_t>& whole) {
    return std::includes(whole.begin(), whole.end(), part.begin(), part.end());
}

struct WalkCounts {
    size_t dirty = 0, clean = 0;
};

// Walks the frames at `times` in order and checks every frame's cells against the whole
// frame's voxelization and the frame before it.
WalkCounts check_sequence(const Scene& scene, const VoxelGrid& grid, int split, const std::vector<double>& times) {
    SequenceVoxelizer sequence(scene, grid, split);
    const int shift = 3 * (grid.depth() - split);
    WalkCounts counts;
    std::map<uint64_t, std::vector<uint64_t>> previous;  // slices of the frame before
    for (size_t k = 0; k < times.size(); ++k) {
        SCOPED_TRACE("frame " + std::to_string(k));
        const FrameCells frame = sequence.frame_cells(times[k]);
        EXPECT_EQ(frame.split_level, split);
        EXPECT_TRUE(std::is_sorted(frame.cells.begin(), frame.cells.end()));
        EXPECT_EQ(std::adjacent_find(frame.cells.begin(), frame.cells.end()), frame.cells.end());
        EXPECT_TRUE(frame.dirty.has_value());
        const std::vector<uint64_t> dirty = frame.dirty.value_or(frame.cells);
        EXPECT_TRUE(std::is_sorted(dirty.begin(), dirty.end()));
        EXPECT_TRUE(is_subset(dirty, frame.cells));
        if (k == 0) {
            EXPECT_EQ(dirty, frame.cells);
        }

        std::vector<uint64_t> streamed;
        std::map<uint64_t, std::vector<uint64_t>> slices;
        for (uint64_t cell : frame.cells) {
            std::vector<uint64_t> codes = frame.slice(cell);
            for (uint64_t c : codes) EXPECT_EQ(c >> shift, cell) << "a voxel outside its cell";
            const bool clean = !std::binary_search(dirty.begin(), dirty.end(), cell);
            if (clean) {
                auto before = previous.find(cell);
                EXPECT_TRUE(before != previous.end() ? before->second == codes : codes.empty())
                    << "clean cell " << cell << " differs from the frame before";
            }
            (clean ? counts.clean : counts.dirty) += 1;
            streamed.insert(streamed.end(), codes.begin(), codes.end());
            slices[cell] = std::move(codes);
        }
        const std::vector<uint64_t> whole = voxelize(scene.evaluate(times[k]), grid).codes;
        EXPECT_EQ(streamed, whole) << streamed.size() << " streamed voxels, " << whole.size() << " whole";
        previous = std::move(slices);
    }
    return counts;
}

std::vector<double> frame_times(int frames, double fps) {
    std::vector<double> times;
    for (int k = 0; k < frames; ++k) times.push_back(double(k) / fps);
    return times;
}

std::vector<double> mixed_times() { return frame_times(11, 10.0); }

Mesh mesh_of(const std::string& name, const gilab::test::TriangleSoup& soup) {
    Mesh mesh;
    mesh.name = name;
    mesh.positions = soup.positions;
    mesh.triangles = soup.triangles;
    mesh.material_ids.assign(soup.triangles.size(), 0);
    return mesh;
}

}  // namespace

TEST(SceneNodeSelection, DynamicMeansAnimatedAboveOrSkinned) {
    const std::vector<bool> dynamic = mixed_scene().dynamic_nodes();
    const std::vector<bool> expected = {false, false, false, true, true, true, true, false};
    EXPECT_EQ(dynamic, expected);
}

TEST(SceneNodeSelection, SelectedNodesMatchTheWholeFrameBitForBit) {
    const Scene scene = mixed_scene();
    const std::vector<bool> dynamic = scene.dynamic_nodes();
    for (double t : {0.0, 0.37, 1.0}) {
        const SceneFrame whole = scene.evaluate(t);
        const SceneFrame part = scene.evaluate(t, dynamic);
        Bounds3 bounds;
        size_t next = 0;
        for (const WorldMesh& mesh : whole.meshes) {
            if (!dynamic[mesh.node]) continue;
            ASSERT_LT(next, part.meshes.size());
            const WorldMesh& picked = part.meshes[next++];
            EXPECT_EQ(picked.node, mesh.node);
            EXPECT_EQ(picked.positions, mesh.positions);  // exact float equality
            EXPECT_EQ(picked.triangles, mesh.triangles);
            for (const Vec3& p : mesh.positions) bounds.extend(p);
        }
        EXPECT_EQ(next, part.meshes.size());
        EXPECT_EQ(part.bounds.min, bounds.min);
        EXPECT_EQ(part.bounds.max, bounds.max);
        EXPECT_EQ(part.lights.size(), whole.lights.size());
    }
    EXPECT_NE(error_of([&] { scene.evaluate(0.0, std::vector<bool>(3, true)); }).find("node selection"),
              std::string::npos);
}

TEST(SequenceVoxelizer, SlicesConcatenateToTheWholeFrame) {
    const Scene scene = mixed_scene();
    for (int split : {1, 3, 5}) {
        SCOPED_TRACE("split level " + std::to_string(split));
        const WalkCounts counts = check_sequence(scene, test_grid(), split, mixed_times());
        EXPECT_GT(counts.dirty, 0u);
    }
}

// The masked block plane (tests/masked_plane.hpp) streamed cell by cell: the same voxels
// as the whole frame's, which hold only the opaque blocks, while a second copy of the
// plane moves below it (so its cells are dirty).
TEST(SequenceVoxelizer, AlphaMasksCutTheStreamedVoxelsAsTheWholeFrames) {
    const SceneFrame plane = test::masked_block_plane(4.5f, Vec3(1.0f));
    Scene scene;
    scene.name = "masked_plane";
    scene.materials = plane.materials;
    Mesh mesh;
    mesh.name = "plane";
    mesh.positions = plane.meshes[0].positions;
    mesh.uvs = plane.meshes[0].uvs;
    mesh.triangles = plane.meshes[0].triangles;
    mesh.material_ids = plane.meshes[0].material_ids;
    scene.add_mesh_instance(mesh);
    const uint32_t moving = scene.add_mesh_instance(mesh, Transform{Vec3(0, -2, 0), Quat(1, 0, 0, 0), Vec3(1)});
    scene.nodes[moving].animation.translation.times = {0.0, 1.0};
    scene.nodes[moving].animation.translation.values = {Vec3(0, -2, 0), Vec3(0, -3, 0)};
    VoxelGrid grid;
    grid.origin = Vec3(0);
    grid.extent = 8.0f;
    grid.resolution = 8;
    check_sequence(scene, grid, 1, {0.0, 1.0});
    const VoxelList whole = voxelize(scene.evaluate(0.0), grid);
    size_t on_plane = 0, opaque = 0;
    for (size_t i = 0; i < whole.size(); ++i) on_plane += whole.voxel(i).y == 4;
    for (int z = 0; z < 8; ++z)
        for (int x = 0; x < 8; ++x) opaque += test::masked_block_opaque(x, z);
    EXPECT_EQ(on_plane, opaque);
    EXPECT_EQ(whole.size(), 2 * opaque);  // and the moving copy at y = 2.5
}

TEST(SequenceVoxelizer, CleanCellsKeepThePreviousFramesVoxels) {
    // Mostly static: most cells must be clean, and each clean one equal to the frame before.
    const WalkCounts counts = check_sequence(mixed_scene(), test_grid(), 3, mixed_times());
    EXPECT_GT(counts.clean, counts.dirty);
}

TEST(SequenceVoxelizer, CrowdedCellsLoseNoVoxel) {
    // Far more triangles per cell than one voxelizer takes at a time.
    Scene scene = mixed_scene();
    scene.add_mesh_instance(mesh_of("dense", gilab::test::uv_sphere(Vec3(0.02f, 0.5f, 0.03f), 0.45f, 80, 100)));
    const uint32_t spinner =
        scene.add_mesh_instance(mesh_of("spinner", gilab::test::uv_sphere(Vec3(0.0f), 0.3f, 70, 90)));
    scene.nodes[spinner].local.translation = Vec3(-0.6f, 0.4f, 0.6f);
    scene.nodes[spinner].animation.translation = {{0.0f, 1.0f}, {Vec3(-0.6f, 0.4f, 0.6f), Vec3(-0.1f, 0.6f, 0.5f)}};
    ASSERT_GT(scene.triangle_count(), 4u * 4096u);
    for (int split : {0, 2}) {
        SCOPED_TRACE("split level " + std::to_string(split));
        check_sequence(scene, test_grid(), split, frame_times(4, 3.0));
    }
}

TEST(SequenceVoxelizer, FireSceneSlicesConcatenateToTheWholeFrame) {
    FireOptions fire;
    fire.particles = 300;
    fire.frames = 5;
    const Scene scene = make_fire_scene(fire);
    Bounds3 bounds;
    const std::vector<double> times = frame_times(fire.frames, fire.fps);
    for (double t : times) bounds.extend(scene.evaluate(t).bounds);
    const VoxelGrid grid = VoxelGrid::enclosing(bounds, 96);  // not a power of two
    check_sequence(scene, grid, MultiFrameDag::default_split_level(grid.depth()) + 1, times);
}

TEST(SequenceVoxelizer, StaticSceneHasNoDirtyCellAfterTheFirstFrame) {
    Scene scene = mixed_scene();
    for (SceneNode& node : scene.nodes) node.animation = TrsAnimation();
    for (SceneNode& node : scene.nodes) node.skin = -1;
    for (Mesh& mesh : scene.meshes) mesh.influences.clear();
    SequenceVoxelizer sequence(scene, test_grid(), 3);
    const FrameCells first = sequence.frame_cells(0.0);
    ASSERT_FALSE(first.cells.empty());
    EXPECT_EQ(first.dirty.value_or(std::vector<uint64_t>{}), first.cells);
    for (double t : {0.1, 0.5, 1.0}) {
        const FrameCells frame = sequence.frame_cells(t);
        EXPECT_EQ(frame.cells, first.cells);
        ASSERT_TRUE(frame.dirty.has_value());
        EXPECT_TRUE(frame.dirty->empty()) << frame.dirty->size() << " dirty cells at t = " << t;
    }
}

TEST(SequenceVoxelizer, StreamedDagEqualsAllAtOnce) {
    const Scene scene = mixed_scene();
    const VoxelGrid grid = test_grid();
    SequenceVoxelizer sequence(scene, grid, 3);
    MultiFrameDag streamed(grid);
    std::vector<Svdag> frames;
    uint64_t reused = 0;
    for (double t : mixed_times()) {
        reused += streamed.append_frame(sequence.frame_cells(t)).cells_reused;
        frames.push_back(Svdag::from_voxels(grid, voxelize(scene.evaluate(t), grid).codes));
    }
    EXPECT_GT(reused, 0u);
    const LaidOutMultiFrameDag a = streamed.lay_out(), b = MultiFrameDag::merge_all(frames).lay_out();
    EXPECT_EQ(a.node_count(), b.node_count());
    EXPECT_TRUE(std::ranges::equal(a.words(), b.words()));
}

TEST(SequenceVoxelizer, BadSplitLevelIsAnError) {
    const Scene scene = mixed_scene();
    EXPECT_NE(error_of([&] { SequenceVoxelizer(scene, test_grid(), 7); }).find("split level 7"), std::string::npos);
    EXPECT_NE(error_of([&] { SequenceVoxelizer(scene, test_grid(), -1); }).find("split level -1"), std::string::npos);
}

TEST(AnimationDagBuild, IncrementalAndAllAtOnceGiveTheSameWords) {
    const Scene scene = mixed_scene();
    AnimationDagOptions options;
    options.resolution = 96;
    options.frames = 11;
    options.fps = 10.0;
    options.build = DagBuildMode::Incremental;
    const AnimationDag incremental = build_animation_dag(scene, options);
    options.build = DagBuildMode::AllAtOnce;
    const AnimationDag all_at_once = build_animation_dag(scene, options);
    EXPECT_EQ(incremental.dag.grid().origin, all_at_once.dag.grid().origin);
    EXPECT_EQ(incremental.dag.grid().extent, all_at_once.dag.grid().extent);
    EXPECT_EQ(incremental.dag.node_count(), all_at_once.dag.node_count());
    EXPECT_TRUE(std::ranges::equal(incremental.dag.words(), all_at_once.dag.words()));
    EXPECT_EQ(incremental.stats.get("voxels_per_frame"), all_at_once.stats.get("voxels_per_frame"));
    EXPECT_GT(incremental.stats.get("cells_reused"), 0.0);
    EXPECT_GT(incremental.stats.get("cells_rebuilt"), 0.0);
    EXPECT_GT(incremental.stats.get("table_bytes"), 0.0);
    EXPECT_EQ(incremental.lights.size(), 11u);
}

TEST(AnimationDagBuild, GridEnclosesEveryWholeFrame) {
    // The bounds pass flattens static nodes once and moving ones per frame; the grid must
    // be the one the union of whole frames gives.
    const Scene scene = mixed_scene();
    AnimationDagOptions options;
    options.resolution = 64;
    options.frames = 11;
    options.fps = 10.0;
    const AnimationDag built = build_animation_dag(scene, options);
    Bounds3 bounds;
    for (double t : built.times) bounds.extend(scene.evaluate(t).bounds);
    const VoxelGrid expected = VoxelGrid::enclosing(bounds, 64);
    EXPECT_EQ(built.dag.grid().origin, expected.origin);
    EXPECT_EQ(built.dag.grid().extent, expected.extent);
}
