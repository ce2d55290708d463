#pragma once
// Small generated meshes and voxel sets shared by the voxel-structure tests.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>
#include "core/util/math.hpp"
#include "core/util/morton.hpp"
#include "core/util/ray.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab::test {

struct TriangleSoup {
    std::vector<Vec3> positions;
    std::vector<UVec3> triangles;

    void add(const Vec3& a, const Vec3& b, const Vec3& c) {
        uint32_t base = static_cast<uint32_t>(positions.size());
        positions.insert(positions.end(), {a, b, c});
        triangles.push_back(UVec3(base, base + 1, base + 2));
    }
};

// A latitude/longitude sphere.
inline TriangleSoup uv_sphere(const Vec3& center, float radius, int rings = 12, int segments = 24) {
    TriangleSoup m;
    for (int r = 0; r <= rings; ++r) {
        float theta = kPi * float(r) / float(rings);
        for (int s = 0; s <= segments; ++s) {
            float phi = 2.0f * kPi * float(s) / float(segments);
            m.positions.push_back(center + radius * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                         std::sin(theta) * std::sin(phi)));
        }
    }
    auto idx = [&](int r, int s) { return uint32_t(r * (segments + 1) + s); };
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            if (r > 0) m.triangles.push_back(UVec3(idx(r, s), idx(r + 1, s), idx(r, s + 1)));
            if (r + 1 < rings) m.triangles.push_back(UVec3(idx(r, s + 1), idx(r + 1, s), idx(r + 1, s + 1)));
        }
    return m;
}

inline Vec3 random_point(std::mt19937& rng, const Vec3& lo, const Vec3& hi) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    return lo + (hi - lo) * Vec3(u(rng), u(rng), u(rng));
}

// Triangles with corners anywhere in [lo, hi].
inline TriangleSoup random_triangles(std::mt19937& rng, int count, const Vec3& lo, const Vec3& hi) {
    TriangleSoup m;
    for (int i = 0; i < count; ++i) m.add(random_point(rng, lo, hi), random_point(rng, lo, hi), random_point(rng, lo, hi));
    return m;
}

// Random occupied voxels (each with probability `fill`), as ascending Morton codes.
inline std::vector<uint64_t> random_voxels(std::mt19937& rng, uint32_t n, double fill) {
    std::bernoulli_distribution keep(fill);
    std::vector<uint64_t> codes;
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x)
                if (keep(rng)) codes.push_back(morton_encode(x, y, z));
    std::sort(codes.begin(), codes.end());
    return codes;
}

// The unit cube grid [0,1]^3 at resolution n.
inline VoxelGrid unit_grid(uint32_t n) {
    VoxelGrid g;
    g.origin = Vec3(0);
    g.extent = 1.0f;
    g.resolution = n;
    return g;
}

// Rays from a ring of eye points around the unit cube towards random targets inside it,
// plus rays starting inside the grid and axis-parallel rays (zero direction components).
inline std::vector<Ray> traversal_test_rays() {
    std::mt19937 rng(5);
    std::vector<Ray> rays;
    for (int e = 0; e < 6; ++e) {
        const float a = 2.0f * kPi * float(e) / 6.0f;
        const Vec3 eye(0.5f + 1.3f * std::cos(a), 0.5f + 0.4f * float(e % 3 - 1), 0.5f + 1.3f * std::sin(a));
        for (int i = 0; i < 400; ++i) {
            Ray r;
            r.origin = eye;
            r.direction = random_point(rng, Vec3(0.02f), Vec3(0.98f)) - eye;
            rays.push_back(r);
        }
    }
    for (int i = 0; i < 400; ++i) {
        Ray r;
        r.origin = random_point(rng, Vec3(0.1f), Vec3(0.9f));
        r.direction = random_point(rng, Vec3(-1.0f), Vec3(1.0f));
        r.tmin = 0.01f;
        rays.push_back(r);
    }
    for (int i = 0; i < 300; ++i) {
        Ray r;
        r.origin = random_point(rng, Vec3(0.0f), Vec3(1.0f));
        const int axis = i % 3;
        r.origin[axis] = (i / 3) % 2 ? 1.5f : -0.5f;
        r.direction = Vec3(0);
        r.direction[axis] = (i / 3) % 2 ? -1.0f : 1.0f;
        rays.push_back(r);
    }
    return rays;
}

// Random triangles and a sphere in the unit cube: the DAG ray casters' test scene.
inline TriangleSoup clutter_and_sphere(uint32_t seed) {
    std::mt19937 rng(seed);
    TriangleSoup soup = random_triangles(rng, 24, Vec3(0.05f), Vec3(0.95f));
    const TriangleSoup sphere = uv_sphere(Vec3(0.45f, 0.4f, 0.55f), 0.2f, 12, 24);
    const uint32_t base = uint32_t(soup.positions.size());
    soup.positions.insert(soup.positions.end(), sphere.positions.begin(), sphere.positions.end());
    for (UVec3 t : sphere.triangles) soup.triangles.push_back(t + UVec3(base));
    return soup;
}

// Resolution 48 (an octree of 64) on a grid at (-2, 5, 1) with side 3: neither at the
// origin nor a power of two.
inline VoxelGrid offset_grid() {
    VoxelGrid grid;
    grid.origin = Vec3(-2.0f, 5.0f, 1.0f);
    grid.extent = 3.0f;
    grid.resolution = 48;
    return grid;
}

// A mesh and rays set up in the unit cube, moved onto `grid`.
inline TriangleSoup moved_onto(TriangleSoup soup, const VoxelGrid& grid) {
    for (Vec3& p : soup.positions) p = grid.origin + p * grid.extent;
    return soup;
}
inline std::vector<Ray> moved_onto(std::vector<Ray> rays, const VoxelGrid& grid) {
    for (Ray& r : rays) {
        r.origin = grid.origin + r.origin * grid.extent;
        r.direction *= grid.extent;
    }
    return rays;
}

}  // namespace gilab::test
