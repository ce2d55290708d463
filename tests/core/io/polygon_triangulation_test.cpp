// Polygon faces of OBJ, PLY and OFF files are triangulated in their best-fit plane:
// convex ones fanned from the first corner, concave ones by ear clipping, so triangles
// never overlap and never flip; non-planar faces are reported.
#include <gtest/gtest.h>

#include <sstream>
#include "core/io/mesh_loaders.hpp"
#include "core/io/polygon_triangulation.hpp"
#include "tests/test_support.hpp"

using namespace gilab;

namespace {

// A star with `points` tips (2 × points corners, every inner corner reflex), in the
// plane spanned by u and v.
std::vector<Vec3> star(int points, const Vec3& u, const Vec3& v) {
    std::vector<Vec3> c;
    for (int i = 0; i < 2 * points; ++i) {
        const float a = float(i) * kPi / float(points);
        const float r = i % 2 == 0 ? 1.0f : 0.4f;
        c.push_back(r * std::cos(a) * u + r * std::sin(a) * v + Vec3(0.1f, 0.2f, 0.3f));
    }
    return c;
}

// Twice the signed area of a polygon along `normal` (shoelace / Newell).
double polygon_area(const std::vector<Vec3>& c, const DVec3& normal) {
    DVec3 sum(0);
    for (size_t i = 0; i < c.size(); ++i) sum += glm::cross(DVec3(c[i]), DVec3(c[(i + 1) % c.size()]));
    return 0.5 * glm::dot(sum, normal);
}

// The triangles cover the polygon exactly once: their areas add up to the polygon's
// and none is flipped against the polygon's orientation.
void expect_exact_cover(const std::vector<Vec3>& corners, const std::vector<std::array<uint32_t, 3>>& triangles,
                        const DVec3& normal) {
    ASSERT_EQ(triangles.size(), corners.size() - 2);
    double sum = 0;
    for (const auto& t : triangles) {
        const DVec3 a(corners[t[0]]), b(corners[t[1]]), c(corners[t[2]]);
        const double signed_area = 0.5 * glm::dot(glm::cross(b - a, c - a), normal);
        EXPECT_GT(signed_area, 0.0) << "flipped or degenerate triangle " << t[0] << " " << t[1] << " " << t[2];
        sum += std::abs(signed_area);
    }
    EXPECT_NEAR(sum, polygon_area(corners, normal), 1e-5) << "triangles overlap or leave gaps";
}

}  // namespace

TEST(PolygonTriangulation, ConvexPolygonIsFannedFromTheFirstCorner) {
    const std::vector<Vec3> quad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const PolygonTriangulation t = triangulate_polygon(quad);
    ASSERT_EQ(t.triangles.size(), 2u);
    EXPECT_EQ(t.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(t.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
    EXPECT_EQ(t.non_planarity, 0.0f);
    EXPECT_FALSE(t.fallback);
}

TEST(PolygonTriangulation, ConcaveStarIsCutIntoEarsInATiltedPlane) {
    const Vec3 u = glm::normalize(Vec3(1, 0.3f, -0.2f));
    const Vec3 v = glm::normalize(glm::cross(Vec3(0.2f, 1, 0.5f), u));
    const std::vector<Vec3> corners = star(33, u, v);  // 66 corners
    const PolygonTriangulation t = triangulate_polygon(corners);
    EXPECT_FALSE(t.fallback);
    EXPECT_LT(t.non_planarity, 1e-5f);
    expect_exact_cover(corners, t.triangles, DVec3(glm::normalize(glm::cross(u, v))));
}

TEST(PolygonTriangulation, ClockwiseAndCombShapedPolygons) {
    // A comb of ten teeth on a spine: concave with many reflex corners; counter-clockwise
    // about +z, then the same clockwise.
    std::vector<Vec3> comb = {{0, 0, 0}, {10, 0, 0}, {10, 1, 0}};
    for (int i = 9; i >= 0; --i) {
        const float x = float(i);
        comb.push_back({x + 0.5f, 1, 0});
        comb.push_back({x + 0.5f, 3, 0});
        comb.push_back({x, 3, 0});
        if (i > 0) comb.push_back({x, 1, 0});
    }
    const PolygonTriangulation ccw = triangulate_polygon(comb);
    expect_exact_cover(comb, ccw.triangles, DVec3(0, 0, 1));
    std::reverse(comb.begin(), comb.end());
    const PolygonTriangulation cw = triangulate_polygon(comb);
    expect_exact_cover(comb, cw.triangles, DVec3(0, 0, -1));
}

TEST(PolygonTriangulation, NonPlanarFaceIsMeasured) {
    const std::vector<Vec3> twisted = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.4f}, {0, 1, 0}};
    EXPECT_GT(triangulate_polygon(twisted).non_planarity, kNonPlanarTolerance);
}

TEST(PolygonTriangulation, ObjLoaderCutsA66CornerConcaveFaceWithoutOverlaps) {
    const Vec3 u(1, 0, 0), v(0, 0, -1);  // the floor plane, facing +y
    const std::vector<Vec3> corners = star(33, u, v);
    std::ostringstream obj;
    obj.precision(9);
    for (const Vec3& c : corners) obj << "v " << c.x << " " << c.y << " " << c.z << "\n";
    obj << "f";
    for (size_t i = 0; i < corners.size(); ++i) obj << " " << i + 1;
    obj << "\n";
    const auto dir = test::temp_dir("obj_concave_face");
    const Scene s = load_obj(test::write_file(dir, "star.obj", obj.str()));
    const Mesh& m = s.meshes[0];
    EXPECT_EQ(s.degenerate_triangles_dropped, 0u);
    std::vector<std::array<uint32_t, 3>> triangles;
    for (const UVec3& t : m.triangles) triangles.push_back({t.x, t.y, t.z});
    expect_exact_cover(m.positions, triangles, DVec3(0, 1, 0));
    for (const std::string& w : s.warnings) EXPECT_EQ(w.find("not planar"), std::string::npos) << w;
}

TEST(PolygonTriangulation, OffLoaderCutsConcaveFacesAndWarnsAboutNonPlanarOnes) {
    // An L-shaped hexagon whose fan from corner 0 would cross the notch (and flip a
    // triangle), and a twisted quad.
    const auto dir = test::temp_dir("off_concave_face");
    const Scene s = load_ply_or_off(test::write_file(dir, "l.off",
                                                     "OFF\n10 2 0\n"
                                                     "0 2 0\n0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n"
                                                     "5 0 0\n6 0 0\n6 1 0.5\n5 1 0\n"
                                                     "6 0 1 2 3 4 5\n4 6 7 8 9\n"));
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.triangles.size(), 6u);
    std::vector<Vec3> l(m.positions.begin(), m.positions.begin() + 6);
    std::vector<std::array<uint32_t, 3>> triangles;
    for (size_t i = 0; i < 4; ++i) triangles.push_back({m.triangles[i].x, m.triangles[i].y, m.triangles[i].z});
    expect_exact_cover(l, triangles, DVec3(0, 0, 1));
    bool warned = false;
    for (const std::string& w : s.warnings) warned |= w.find("l.off: 1 faces are not planar") != std::string::npos;
    EXPECT_TRUE(warned) << "no warning about the twisted quad";
}
