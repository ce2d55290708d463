// Ray traversal through one frame's root of a laid-out multi-frame DAG: every ray finds
// the same voxel, entry distance and visit count as through that frame's own SVDAG,
// whether the frame shares its subtrees with other frames or not.
#include <gtest/gtest.h>
#include <random>
#include <string>
#include <vector>
#include "accel/temporal/multi_frame_dag.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/temporal/laid_out_multi_frame_dag.hpp"
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/util/error.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/test_support.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;
using gilab::test::TriangleSoup;

namespace {

constexpr uint32_t kResolution = 64;

void append(TriangleSoup& to, const TriangleSoup& from) {
    const uint32_t base = uint32_t(to.positions.size());
    to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
    for (UVec3 t : from.triangles) to.triangles.push_back(t + UVec3(base));
}

// Static clutter and a sphere moving along x, so frames share most subtrees.
std::vector<uint64_t> moving_sphere_frame(int frame) {
    std::mt19937 rng(11);
    TriangleSoup soup = gilab::test::random_triangles(rng, 16, Vec3(0.05f, 0.6f, 0.6f), Vec3(0.45f, 0.95f, 0.95f));
    append(soup, gilab::test::uv_sphere(Vec3(0.2f + 0.07f * float(frame), 0.35f, 0.5f), 0.15f, 10, 20));
    return voxelize(soup.positions, soup.triangles, gilab::test::unit_grid(kResolution)).codes;
}

// The frame's rays through the laid-out DAG and through the frame's own SVDAG agree exactly.
// Returns the number of hits, so callers can check the rays met something.
int expect_same_hits(const LaidOutMultiFrameDag& laid_out, size_t frame, const Svdag& own,
                     const std::vector<Ray>& rays) {
    int hits = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        const VoxelRayHit a = trace_voxel_ray(laid_out, frame, rays[i]);
        const VoxelRayHit b = trace_voxel_ray(own, rays[i]);
        EXPECT_EQ(a.hit, b.hit) << "frame " << frame << " ray " << i;
        EXPECT_EQ(a.nodes_visited, b.nodes_visited) << "frame " << frame << " ray " << i;
        if (!a.hit || !b.hit) continue;
        ++hits;
        EXPECT_EQ(a.voxel, b.voxel) << "frame " << frame << " ray " << i;
        EXPECT_EQ(a.t, b.t) << "frame " << frame << " ray " << i;
    }
    return hits;
}

}  // namespace

TEST(LaidOutMultiFrameDagTraversal, EveryFrameMatchesItsOwnSvdag) {
    const VoxelGrid grid = gilab::test::unit_grid(kResolution);
    // Frame 3 repeats frame 0: it has its own root over frame 0's subtrees.
    std::vector<std::vector<uint64_t>> frames = {moving_sphere_frame(0), moving_sphere_frame(1),
                                                 moving_sphere_frame(4), moving_sphere_frame(0)};
    MultiFrameDag builder(grid);
    for (const auto& codes : frames) builder.append_frame(codes);
    const LaidOutMultiFrameDag laid_out = builder.lay_out();
    ASSERT_EQ(laid_out.frame_count(), frames.size());
    const std::vector<Ray> rays = gilab::test::traversal_test_rays();
    for (size_t f = 0; f < frames.size(); ++f) {
        const Svdag own = Svdag::from_voxels(grid, frames[f]);
        const int hits = expect_same_hits(laid_out, f, own, rays);
        EXPECT_GT(hits, int(rays.size()) / 8) << "frame " << f << ": too few rays meet the geometry to test much";
    }
}

TEST(LaidOutMultiFrameDagTraversal, FramesDifferWhereTheGeometryMoved) {
    const VoxelGrid grid = gilab::test::unit_grid(kResolution);
    MultiFrameDag builder(grid);
    builder.append_frame(moving_sphere_frame(0));
    builder.append_frame(moving_sphere_frame(6));
    const LaidOutMultiFrameDag laid_out = builder.lay_out();
    // A ray along +z through the sphere's centre in frame 0 misses frame 6's sphere.
    Ray r;
    r.origin = Vec3(0.2f, 0.35f, -0.5f);
    r.direction = Vec3(0, 0, 1);
    EXPECT_TRUE(trace_voxel_ray(laid_out, 0, r).hit);
    EXPECT_FALSE(trace_voxel_ray(laid_out, 1, r).hit);
}

TEST(LaidOutMultiFrameDagTraversal, EmptyFrameIsNeverHit) {
    const VoxelGrid grid = gilab::test::unit_grid(kResolution);
    MultiFrameDag builder(grid);
    builder.append_frame(moving_sphere_frame(0));
    builder.append_frame(std::vector<uint64_t>{});
    const LaidOutMultiFrameDag laid_out = builder.lay_out();
    int hits = 0;
    for (const Ray& r : gilab::test::traversal_test_rays()) {
        EXPECT_FALSE(trace_voxel_ray(laid_out, 1, r).hit);
        hits += trace_voxel_ray(laid_out, 0, r).hit;
    }
    EXPECT_GT(hits, 0);
}

TEST(LaidOutMultiFrameDagTraversal, FrameOutsideTheAnimationIsAnError) {
    MultiFrameDag builder(gilab::test::unit_grid(kResolution));
    builder.append_frame(moving_sphere_frame(0));
    const LaidOutMultiFrameDag laid_out = builder.lay_out();
    const std::string message = gilab::test::error_of([&] { trace_voxel_ray(laid_out, 1, Ray{}); });
    EXPECT_NE(message.find("frame 1"), std::string::npos) << message;
}
