// Embree backend against brute-force ray–triangle tests, streams against single rays,
// and refit after animation.
#include <gtest/gtest.h>
#include "core/render/ray_tracer.hpp"
#include "core/util/rng.hpp"
#include "scenes/builtin_scenes.hpp"

using namespace gilab;

namespace {

// Möller–Trumbore in double precision: the reference the BVH must match.
bool brute_force_hit(const SceneFrame& f, const Ray& r, double& best_t, uint32_t& mesh, uint32_t& tri) {
    bool found = false;
    best_t = r.tmax;
    for (uint32_t mi = 0; mi < f.meshes.size(); ++mi) {
        const WorldMesh& m = f.meshes[mi];
        for (uint32_t ti = 0; ti < m.triangles.size(); ++ti) {
            glm::dvec3 o(r.origin), d(r.direction);
            glm::dvec3 a(m.positions[m.triangles[ti].x]), b(m.positions[m.triangles[ti].y]), c(m.positions[m.triangles[ti].z]);
            glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
            double det = glm::dot(e1, p);
            if (std::abs(det) < 1e-14) continue;
            glm::dvec3 s = o - a;
            double u = glm::dot(s, p) / det;
            glm::dvec3 q = glm::cross(s, e1);
            double v = glm::dot(d, q) / det;
            double t = glm::dot(e2, q) / det;
            if (u < 0 || v < 0 || u + v > 1 || t <= r.tmin || t >= best_t) continue;
            best_t = t;
            mesh = mi;
            tri = ti;
            found = true;
        }
    }
    return found;
}

std::vector<Ray> random_rays(const Bounds3& b, int n, uint64_t seed) {
    Rng rng(seed, 7);
    std::vector<Ray> rays;
    for (int i = 0; i < n; ++i) {
        Ray r;
        r.origin = b.min + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * b.extent();
        r.direction = glm::normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f));
        rays.push_back(r);
    }
    return rays;
}

}  // namespace

TEST(RayTracer, ClosestHitMatchesBruteForceOnRandomRays) {
    Scene scene = make_cornell_box();
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer(frame);
    int agree = 0, hits = 0;
    for (const Ray& r : random_rays(frame.bounds, 2000, 1)) {
        double t;
        uint32_t mesh = 0, tri = 0;
        bool expected = brute_force_hit(frame, r, t, mesh, tri);
        Hit h = tracer.intersect(r);
        ASSERT_EQ(h.valid(), expected);
        if (!expected) continue;
        ++hits;
        EXPECT_NEAR(h.t, t, 1e-4 * std::max(1.0, t));
        // Ties at shared edges may pick either triangle; the distance must agree regardless.
        if (h.triangle == tri) ++agree;
        EXPECT_EQ(tracer.occluded(r), true);
    }
    EXPECT_GT(hits, 500);  // the rays start inside the box: most must hit something
    EXPECT_GT(agree, hits * 99 / 100);
}

TEST(RayTracer, StreamsEqualSingleRays) {
    Scene scene = make_cornell_box();
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer(frame);
    std::vector<Ray> rays = random_rays(frame.bounds, 1000, 2);
    for (size_t i = 0; i < rays.size(); i += 3) rays[i].tmax = 0.05f;  // some short rays
    std::vector<Hit> hits(rays.size());
    std::vector<uint8_t> blocked(rays.size());
    tracer.intersect(rays, hits);
    tracer.occluded(rays, blocked);
    for (size_t i = 0; i < rays.size(); ++i) {
        Hit single = tracer.intersect(rays[i]);
        ASSERT_EQ(single.valid(), hits[i].valid());
        if (single.valid()) {
            EXPECT_EQ(single.triangle, hits[i].triangle);
            EXPECT_FLOAT_EQ(single.t, hits[i].t);
        }
        EXPECT_EQ(tracer.occluded(rays[i]), blocked[i] != 0);
    }
}

TEST(RayTracer, RefitsAnimatedGeometryAndRebuildsOnTopologyChange) {
    Scene scene;
    scene.materials.push_back(Material{});
    Mesh quad;
    quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    quad.triangles = {{0, 1, 2}, {0, 2, 3}};
    quad.material_ids = {0, 0};
    uint32_t node = scene.add_mesh_instance(quad);
    scene.nodes[node].animation.translation.times = {0.0f, 1.0f};
    scene.nodes[node].animation.translation.values = {Vec3(0, 0, 0), Vec3(0, 0, -5)};

    SceneFrame f0 = scene.evaluate(0);
    RayTracer tracer(f0);
    Ray r;
    r.origin = Vec3(0.1f, 0.2f, 10);
    r.direction = Vec3(0, 0, -1);
    EXPECT_NEAR(tracer.intersect(r).t, 10.0f, 1e-5);

    SceneFrame f1 = scene.evaluate(1.0);
    EXPECT_EQ(tracer.update(f1), RayTracer::UpdateKind::Refit);
    EXPECT_NEAR(tracer.intersect(r).t, 15.0f, 1e-5);

    scene.add_mesh_instance(quad, Transform{Vec3(0, 0, 3)});
    SceneFrame f2 = scene.evaluate(1.0);
    EXPECT_EQ(tracer.update(f2), RayTracer::UpdateKind::Rebuild);
    Hit h = tracer.intersect(r);
    EXPECT_NEAR(h.t, 7.0f, 1e-5);
    EXPECT_EQ(h.mesh, 1u);
}
