#include "scenes/procedural_meshes.hpp"

#include <vector>
#include "core/util/error.hpp"

namespace gilab {

namespace {

// Builds a convex solid from its corners and faces (each a convex polygon of corner
// indices, fan-triangulated). Every solid here is convex, so a triangle faces outwards
// exactly when its normal points away from the centroid of the corners; orienting each
// triangle that way makes the winding right whatever order the faces were listed in.
Mesh convex_solid(const std::string& name, std::vector<Vec3> corners, const std::vector<std::vector<uint32_t>>& faces,
                  uint32_t material) {
    Vec3 inside(0);
    for (const Vec3& p : corners) inside += p;
    inside /= float(corners.size());

    Mesh mesh;
    mesh.name = name;
    mesh.positions = std::move(corners);
    for (const auto& face : faces) {
        for (size_t k = 1; k + 1 < face.size(); ++k) {
            UVec3 t{face[0], face[k], face[k + 1]};
            const Vec3 &a = mesh.positions[t.x], &b = mesh.positions[t.y], &c = mesh.positions[t.z];
            if (glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0f - inside) < 0) std::swap(t.y, t.z);
            mesh.triangles.push_back(t);
        }
    }
    mesh.material_ids.assign(mesh.triangles.size(), material);
    return mesh;
}

void check_sides(const std::string& name, int sides) {
    if (sides < 3) throw Error(name, "a prism or cone needs at least 3 sides, got " + std::to_string(sides));
}

// Corners of a regular n-gon in the plane y = centre.y.
std::vector<Vec3> ring(const Vec3& centre, float radius, int sides, float start_degrees) {
    std::vector<Vec3> points;
    for (int i = 0; i < sides; ++i) {
        const float a = glm::radians(start_degrees) + 2.0f * kPi * float(i) / float(sides);
        points.push_back(centre + radius * Vec3(std::cos(a), 0.0f, std::sin(a)));
    }
    return points;
}

}  // namespace

Mesh make_box(const std::string& name, const Vec3& min, const Vec3& max, uint32_t material) {
    std::vector<Vec3> corners;
    for (int i = 0; i < 8; ++i)
        corners.emplace_back(i & 1 ? max.x : min.x, i & 2 ? max.y : min.y, i & 4 ? max.z : min.z);
    // Faces by fixed axis: x = min, x = max, y = min, y = max, z = min, z = max.
    return convex_solid(name, std::move(corners),
                        {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}},
                        material);
}

Mesh make_prism(const std::string& name, const Vec3& base_centre, float radius, float height, int sides,
                uint32_t material, float start_degrees) {
    check_sides(name, sides);
    std::vector<Vec3> corners = ring(base_centre, radius, sides, start_degrees);
    const std::vector<Vec3> top = ring(base_centre + Vec3(0, height, 0), radius, sides, start_degrees);
    corners.insert(corners.end(), top.begin(), top.end());
    const uint32_t n = uint32_t(sides);
    std::vector<std::vector<uint32_t>> faces(2);
    for (uint32_t i = 0; i < n; ++i) {
        faces[0].push_back(i);
        faces[1].push_back(n + i);
        faces.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
    }
    return convex_solid(name, std::move(corners), faces, material);
}

Mesh make_cone(const std::string& name, const Vec3& base_centre, float radius, float height, int sides,
               uint32_t material, float start_degrees) {
    check_sides(name, sides);
    std::vector<Vec3> corners = ring(base_centre, radius, sides, start_degrees);
    const uint32_t n = uint32_t(sides);
    corners.push_back(base_centre + Vec3(0, height, 0));  // apex, index n
    std::vector<std::vector<uint32_t>> faces(1);
    for (uint32_t i = 0; i < n; ++i) {
        faces[0].push_back(i);
        faces.push_back({i, (i + 1) % n, n});
    }
    return convex_solid(name, std::move(corners), faces, material);
}

Mesh make_gable_prism(const std::string& name, const Vec3& min, const Vec3& max, float ridge_height,
                      bool ridge_along_x, uint32_t material) {
    const float y = min.y, top = min.y + ridge_height;
    std::vector<Vec3> corners = {{min.x, y, min.z}, {max.x, y, min.z}, {max.x, y, max.z}, {min.x, y, max.z}};
    if (ridge_along_x) {
        const float zc = 0.5f * (min.z + max.z);
        corners.insert(corners.end(), {{min.x, top, zc}, {max.x, top, zc}});
        // Base, the two slopes (z = min and z = max sides), the two gable ends.
        return convex_solid(name, std::move(corners), {{0, 1, 2, 3}, {0, 1, 5, 4}, {3, 2, 5, 4}, {0, 3, 4}, {1, 2, 5}},
                            material);
    }
    const float xc = 0.5f * (min.x + max.x);
    corners.insert(corners.end(), {{xc, top, min.z}, {xc, top, max.z}});
    return convex_solid(name, std::move(corners), {{0, 1, 2, 3}, {0, 3, 5, 4}, {1, 2, 5, 4}, {0, 1, 4}, {3, 2, 5}},
                        material);
}

Mesh make_heightfield(const std::string& name, int nx, int nz, const Vec2& min, const Vec2& max,
                      const std::function<float(float, float)>& height, uint32_t material) {
    if (nx < 2 || nz < 2) throw Error(name, "a heightfield needs at least 2 × 2 vertices");
    Mesh mesh;
    mesh.name = name;
    const Vec2 step = (max - min) / Vec2(float(nx - 1), float(nz - 1));
    auto index = [nx](int i, int j) { return uint32_t(j * nx + i); };
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            const float x = min.x + float(i) * step.x, z = min.y + float(j) * step.y;
            const float y = height(x, z);
            if (!std::isfinite(y)) throw Error(name, "heightfield value is not finite");
            mesh.positions.emplace_back(x, y, z);
        }
    // Central differences (one-sided at the border) give smooth shading normals.
    mesh.normals.resize(mesh.positions.size());
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            const int i0 = std::max(i - 1, 0), i1 = std::min(i + 1, nx - 1);
            const int j0 = std::max(j - 1, 0), j1 = std::min(j + 1, nz - 1);
            const Vec3 dx = mesh.positions[index(i1, j)] - mesh.positions[index(i0, j)];
            const Vec3 dz = mesh.positions[index(i, j1)] - mesh.positions[index(i, j0)];
            mesh.normals[index(i, j)] = glm::normalize(glm::cross(dz, dx));  // +Y side
        }
    // Two triangles per cell, wound so their normals point up (+Z × +X = +Y).
    for (int j = 0; j + 1 < nz; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            const uint32_t a = index(i, j), b = index(i + 1, j), c = index(i, j + 1), d = index(i + 1, j + 1);
            mesh.triangles.emplace_back(a, c, b);
            mesh.triangles.emplace_back(b, c, d);
        }
    mesh.material_ids.assign(mesh.triangles.size(), material);
    return mesh;
}

double signed_volume(const Mesh& mesh) {
    double volume = 0;
    for (const UVec3& t : mesh.triangles) {
        const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
        volume += glm::dot(a, glm::cross(b, c));
    }
    return volume / 6.0;
}

}  // namespace gilab
