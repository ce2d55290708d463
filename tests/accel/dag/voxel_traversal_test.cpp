// Ray traversal: SVO, ESVO and SVDAG find the same first voxel as a brute-force
// ray/box test against every occupied voxel.
#include <gtest/gtest.h>
#include <random>
#include "accel/dag/esvo.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/util/morton.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;

namespace {

struct Reference {
    bool hit = false;
    double t = 0;
    UVec3 voxel{0};
};

// Entry parameter of the ray into a closed voxel box within [tmin, tmax], or nothing.
std::optional<double> enter(const VoxelGrid& g, const Ray& ray, const UVec3& v) {
    const double h = g.voxel_size();
    double t0 = ray.tmin, t1 = ray.tmax;
    for (int k = 0; k < 3; ++k) {
        double lo = double(g.origin[k]) + v[k] * h, hi = lo + h;
        double o = ray.origin[k], d = ray.direction[k];
        if (d == 0) {
            if (o < lo || o > hi) return std::nullopt;
            continue;
        }
        double a = (lo - o) / d, b = (hi - o) / d;
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    if (t0 > t1) return std::nullopt;
    return t0;
}

Reference brute_force(const VoxelList& v, const Ray& ray) {
    Reference r;
    for (uint64_t code : v.codes) {
        UVec3 voxel = morton_decode(code);
        auto t = enter(v.grid, ray, voxel);
        if (t && (!r.hit || *t < r.t)) r = {true, *t, voxel};
    }
    return r;
}

void check_rays(const VoxelList& v, const std::vector<Ray>& rays) {
    Svo svo = Svo::build(v);
    Esvo esvo = Esvo::from_svo(svo);
    Svdag dag = Svdag::from_svo(svo);
    int hits = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        const Ray& ray = rays[i];
        VoxelRayHit a = trace_voxel_ray(svo, ray), b = trace_voxel_ray(esvo, ray), c = trace_voxel_ray(dag, ray);
        // The three encode one tree: identical answers and visit counts.
        ASSERT_EQ(a.hit, b.hit);
        ASSERT_EQ(a.hit, c.hit);
        ASSERT_EQ(a.nodes_visited, b.nodes_visited);
        ASSERT_EQ(a.nodes_visited, c.nodes_visited);
        if (a.hit) {
            ASSERT_EQ(a.voxel, b.voxel);
            ASSERT_EQ(a.voxel, c.voxel);
            ASSERT_EQ(a.t, b.t);
            ASSERT_EQ(a.t, c.t);
        }
        Reference r = brute_force(v, ray);
        ASSERT_EQ(a.hit, r.hit) << "ray " << i;
        if (!r.hit) continue;
        ++hits;
        const double tol = 1e-4 * std::max(1.0, std::abs(r.t));
        ASSERT_NEAR(a.t, r.t, tol) << "ray " << i;
        if (a.voxel != r.voxel) {
            // A tie: the ray enters both voxels at the same point.
            auto t = enter(v.grid, ray, a.voxel);
            ASSERT_TRUE(t.has_value()) << "ray " << i;
            ASSERT_NEAR(*t, r.t, tol) << "ray " << i;
        }
        ASSERT_TRUE(std::binary_search(v.codes.begin(), v.codes.end(), morton_encode(a.voxel)));
        ASSERT_GE(a.nodes_visited, uint32_t(svo.depth() + 1));
    }
    EXPECT_GT(hits, int(rays.size() / 10));
}

std::vector<Ray> random_rays(const VoxelGrid& g, int count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.0f, 1.0f);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Vec3 lo = g.origin - Vec3(0.5f * g.extent), hi = g.origin + Vec3(1.5f * g.extent);
    std::vector<Ray> rays;
    for (int i = 0; i < count; ++i) {
        Ray r;
        r.origin = gilab::test::random_point(rng, lo, hi);
        if (i % 3 == 0) {  // aim at the grid so most rays matter
            Vec3 target = gilab::test::random_point(rng, g.origin, g.origin + Vec3(g.extent));
            r.direction = target - r.origin;
        } else {
            r.direction = Vec3(n(rng), n(rng), n(rng));
        }
        if (i % 7 == 0) {  // axis-parallel rays: zero direction components
            int keep = i % 3;
            Vec3 d(0);
            d[keep] = r.direction[keep] >= 0 ? 1.0f : -1.0f;
            r.direction = d;
        }
        if (i % 5 == 0) {
            r.tmin = 0.2f * u(rng);
            r.tmax = r.tmin + 2.0f * u(rng);
        }
        rays.push_back(r);
    }
    return rays;
}

}  // namespace

TEST(VoxelTraversal, SphereMatchesBruteForce) {
    auto m = gilab::test::uv_sphere(Vec3(0.5f), 0.4f);
    for (uint32_t n : {16u, 21u}) {
        VoxelList v = voxelize(m.positions, m.triangles, gilab::test::unit_grid(n));
        check_rays(v, random_rays(v.grid, 600, n));
    }
}

TEST(VoxelTraversal, RandomVoxelsInAnOffsetGrid) {
    std::mt19937 rng(4);
    VoxelGrid g;
    g.origin = Vec3(-3.0f, 2.0f, 0.25f);
    g.extent = 5.0f;
    g.resolution = 13;
    VoxelList v;
    v.grid = g;
    v.codes = gilab::test::random_voxels(rng, 13, 0.03);
    check_rays(v, random_rays(g, 800, 77));
}

TEST(VoxelTraversal, RayStartingInsideAnOccupiedVoxel) {
    VoxelList v;
    v.grid = gilab::test::unit_grid(8);
    v.codes = {morton_encode(3, 4, 5)};
    Svo svo = Svo::build(v);
    Ray ray;
    ray.origin = v.grid.cell_bounds({3, 4, 5}).center();
    ray.direction = Vec3(0.3f, -1.0f, 0.2f);
    VoxelRayHit hit = trace_voxel_ray(svo, ray);
    ASSERT_TRUE(hit.hit);
    EXPECT_EQ(hit.voxel, UVec3(3, 4, 5));
    EXPECT_EQ(hit.t, 0.0f);
    EXPECT_EQ(hit.nodes_visited, 4u);  // root, two interior nodes, the leaf
    ray.tmax = -1.0f;                   // an empty interval never hits
    EXPECT_FALSE(trace_voxel_ray(Svdag::from_svo(svo), ray).hit);
}

TEST(VoxelTraversal, EmptyStructuresMiss) {
    Svo svo = Svo::build(gilab::test::unit_grid(8), {});
    Ray ray;
    ray.origin = Vec3(-1.0f);
    ray.direction = Vec3(1.0f);
    EXPECT_FALSE(trace_voxel_ray(svo, ray).hit);
    EXPECT_FALSE(trace_voxel_ray(Esvo::from_svo(svo), ray).hit);
    EXPECT_FALSE(trace_voxel_ray(Svdag::from_svo(svo), ray).hit);
}
