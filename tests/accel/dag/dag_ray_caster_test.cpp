// The fast single-precision DAG ray caster against the double-precision reference walk
// (trace_voxel_ray): same hits, same voxels, same entry distances to single precision and
// the same visit counts, on SVDAGs of several depths, grids that are not powers of two,
// rays limited by tmax, and every frame of a multi-frame DAG.
#include <gtest/gtest.h>
#include <cmath>
#include <random>
#include <string>
#include <vector>
#include "accel/dag/dag_ray_caster.hpp"
#include "accel/temporal/multi_frame_dag.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/temporal/laid_out_multi_frame_dag.hpp"
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/util/morton.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/test_support.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;
using gilab::test::TriangleSoup;

namespace {

struct Agreement {
    int rays = 0, hits = 0, same_voxel = 0, same_visits = 0;
};

// Compares every ray. A different voxel is accepted only as a tie: both voxels occupied
// and entered at the same distance (the ray passes through their shared edge or corner).
Agreement compare(const DagWordsView& fast, const std::vector<Ray>& rays, auto&& reference,
                  auto&& occupied) {
    Agreement a;
    for (size_t i = 0; i < rays.size(); ++i) {
        const VoxelRayHit got = cast_dag_ray(fast, rays[i]);
        const VoxelRayHit want = reference(rays[i]);
        ++a.rays;
        EXPECT_EQ(got.hit, want.hit) << "ray " << i;
        if (got.hit != want.hit) continue;
        a.same_visits += got.nodes_visited == want.nodes_visited;
        if (!want.hit) {
            ++a.same_voxel;
            continue;
        }
        ++a.hits;
        const float scale = std::max(1.0f, std::abs(want.t)) * glm::length(rays[i].direction);
        EXPECT_NEAR(got.t, want.t, 2e-5f * std::max(1.0f, scale)) << "ray " << i;
        if (got.voxel == want.voxel) {
            ++a.same_voxel;
        } else {
            EXPECT_TRUE(occupied(got.voxel)) << "ray " << i << " hit an empty voxel";
        }
    }
    return a;
}

// All but a handful of rays agree in every respect.
void expect_close_agreement(const Agreement& a, const std::string& what) {
    EXPECT_GT(a.hits, a.rays / 8) << what << ": too few rays meet the geometry to test much";
    EXPECT_GE(a.same_voxel, a.rays - a.rays / 200) << what;
    EXPECT_GE(a.same_visits, a.rays - a.rays / 100) << what;
}

void check_svdag(const Svdag& dag, const std::vector<uint64_t>& codes, const std::vector<Ray>& rays,
                 const std::string& what) {
    const auto occupied = [&](const UVec3& v) {
        return std::binary_search(codes.begin(), codes.end(), morton_encode(v.x, v.y, v.z));
    };
    const Agreement a = compare(dag_view(dag), rays, [&](const Ray& r) { return trace_voxel_ray(dag, r); }, occupied);
    expect_close_agreement(a, what);
}

}  // namespace

TEST(DagRayCaster, MatchesTheReferenceWalkAtSeveralDepths) {
    for (uint32_t resolution : {8u, 64u, 512u}) {
        const VoxelGrid grid = gilab::test::unit_grid(resolution);
        const TriangleSoup soup = gilab::test::clutter_and_sphere(3);
        const std::vector<uint64_t> codes = voxelize(soup.positions, soup.triangles, grid).codes;
        check_svdag(Svdag::from_voxels(grid, codes), codes, gilab::test::traversal_test_rays(),
                    std::to_string(resolution) + "³");
    }
}

TEST(DagRayCaster, MatchesOnRandomVoxelsAndAnOffsetGridThatIsNotAPowerOfTwo) {
    std::mt19937 rng(17);
    const VoxelGrid unit = gilab::test::unit_grid(32);
    const std::vector<uint64_t> random = gilab::test::random_voxels(rng, 32, 0.01);
    check_svdag(Svdag::from_voxels(unit, random), random, gilab::test::traversal_test_rays(), "random voxels");

    // The offset grid: the rays move with it.
    const VoxelGrid grid = gilab::test::offset_grid();
    const TriangleSoup soup = gilab::test::moved_onto(gilab::test::clutter_and_sphere(9), grid);
    const std::vector<uint64_t> codes = voxelize(soup.positions, soup.triangles, grid).codes;
    const std::vector<Ray> rays = gilab::test::moved_onto(gilab::test::traversal_test_rays(), grid);
    check_svdag(Svdag::from_voxels(grid, codes), codes, rays, "offset 48³ grid");
}

TEST(DagRayCaster, StopsAtTmaxLikeTheReference) {
    const VoxelGrid grid = gilab::test::unit_grid(64);
    const TriangleSoup soup = gilab::test::clutter_and_sphere(5);
    const std::vector<uint64_t> codes = voxelize(soup.positions, soup.triangles, grid).codes;
    const Svdag dag = Svdag::from_voxels(grid, codes);
    std::vector<Ray> rays = gilab::test::traversal_test_rays();
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> length(0.2f, 1.5f);
    int cut = 0;
    for (Ray& r : rays) {
        r.tmax = length(rng);
        const VoxelRayHit unlimited = trace_voxel_ray(dag, Ray{r.origin, r.direction, r.tmin});
        cut += unlimited.hit && unlimited.t > r.tmax;
    }
    EXPECT_GT(cut, 20) << "tmax should cut off some hits";
    check_svdag(dag, codes, rays, "rays with tmax");
}

TEST(DagRayCaster, EveryFrameOfAMultiFrameDagMatches) {
    const VoxelGrid grid = gilab::test::unit_grid(128);
    MultiFrameDag builder(grid);
    std::vector<std::vector<uint64_t>> frames;
    for (uint32_t seed : {1u, 2u, 1u}) {
        const TriangleSoup soup = gilab::test::clutter_and_sphere(seed);
        frames.push_back(voxelize(soup.positions, soup.triangles, grid).codes);
        builder.append_frame(frames.back());
    }
    builder.append_frame(std::vector<uint64_t>{});
    const LaidOutMultiFrameDag temporal = builder.lay_out();
    const std::vector<Ray> rays = gilab::test::traversal_test_rays();
    for (size_t f = 0; f < frames.size(); ++f) {
        const auto occupied = [&](const UVec3& v) { return temporal.contains_voxel(f, v); };
        const Agreement a = compare(dag_view(temporal, f), rays,
                                    [&](const Ray& r) { return trace_voxel_ray(temporal, f, r); }, occupied);
        expect_close_agreement(a, "frame " + std::to_string(f));
    }
    for (const Ray& r : rays) EXPECT_FALSE(cast_dag_ray(dag_view(temporal, 3), r).hit);
    EXPECT_FALSE(gilab::test::error_of([&] { dag_view(temporal, 4); }).empty());
}

TEST(DagRayCaster, ASingleVoxelGridIsHitWhereTheRayEntersIt) {
    const VoxelGrid grid = gilab::test::unit_grid(1);
    const std::vector<uint64_t> one = {0};
    const Svdag dag = Svdag::from_voxels(grid, one);
    Ray r;
    r.origin = Vec3(0.5f, 0.5f, -1.0f);
    r.direction = Vec3(0, 0, 1);
    const VoxelRayHit hit = cast_dag_ray(dag_view(dag), r);
    ASSERT_TRUE(hit.hit);
    EXPECT_EQ(hit.voxel, UVec3(0));
    EXPECT_FLOAT_EQ(hit.t, 1.0f);
    r.origin.x = 1.5f;
    EXPECT_FALSE(cast_dag_ray(dag_view(dag), r).hit);
}
