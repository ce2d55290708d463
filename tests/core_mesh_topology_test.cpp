// Closed-mesh checks (CGAL): a cube is closed, a cube missing a face is not, seams
// split by normals still count as closed, non-manifold soups are reported open without
// crashing, and the real Cornell box is open.
#include <gtest/gtest.h>

#include "core/mesh_loaders.hpp"
#include "core/mesh_topology.hpp"
#include "tests/test_support.hpp"

using namespace gilab;

namespace {

// Unit cube, 8 shared vertices, 12 outward-facing triangles (two per face).
Mesh cube(Vec3 offset = Vec3(0)) {
    Mesh m;
    m.name = "cube";
    for (int i = 0; i < 8; ++i) m.positions.push_back(offset + Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
    const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        m.triangles.emplace_back(q[0], q[1], q[2]);
        m.triangles.emplace_back(q[0], q[2], q[3]);
    }
    m.material_ids.assign(m.triangles.size(), 0);
    return m;
}

// The same cube with 4 vertices per face (as exporters write it for flat normals).
Mesh split_cube() {
    Mesh c = cube(), out;
    for (size_t f = 0; f < 6; ++f) {
        const uint32_t base = uint32_t(out.positions.size());
        const UVec3 a = c.triangles[2 * f], b = c.triangles[2 * f + 1];
        for (uint32_t v : {a.x, a.y, a.z, b.z}) out.positions.push_back(c.positions[v]);
        out.triangles.emplace_back(base, base + 1, base + 2);
        out.triangles.emplace_back(base, base + 2, base + 3);
    }
    out.material_ids.assign(out.triangles.size(), 0);
    return out;
}

}  // namespace

TEST(MeshTopology, CubeIsClosed) {
    MeshTopology t = analyze_topology(cube());
    EXPECT_TRUE(t.closed);
    EXPECT_EQ(t.boundary_edges, 0u);
    EXPECT_EQ(t.connected_components, 1u);
}

TEST(MeshTopology, CubeMissingOneFaceIsOpen) {
    Mesh m = cube();
    m.triangles.resize(10);
    m.material_ids.resize(10);
    MeshTopology t = analyze_topology(m);
    EXPECT_FALSE(t.closed);
    EXPECT_EQ(t.boundary_edges, 4u);
    EXPECT_EQ(t.connected_components, 1u);
}

TEST(MeshTopology, InconsistentWindingIsRepairedBeforeTheCheck) {
    Mesh m = cube();
    std::swap(m.triangles[3].y, m.triangles[3].z);  // one triangle flipped
    EXPECT_TRUE(analyze_topology(m).closed);
}

TEST(MeshTopology, VerticesSplitAtSeamsAreWelded) {
    MeshTopology t = analyze_topology(split_cube());
    EXPECT_TRUE(t.closed);
    EXPECT_EQ(t.connected_components, 1u);
}

TEST(MeshTopology, TwoCubesAreTwoComponents) {
    Mesh a = cube(), b = cube(Vec3(3, 0, 0));
    const uint32_t n = uint32_t(a.positions.size());
    a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
    for (UVec3 t : b.triangles) a.triangles.push_back(t + UVec3(n));
    a.material_ids.assign(a.triangles.size(), 0);
    MeshTopology t = analyze_topology(a);
    EXPECT_TRUE(t.closed);
    EXPECT_EQ(t.connected_components, 2u);
}

TEST(MeshTopology, NonManifoldSoupIsOpenAndDoesNotCrash) {
    // Three triangles sharing one edge (a "book" with three pages), plus a duplicate.
    Mesh m;
    m.positions = {Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 0, 1)};
    m.triangles = {UVec3(0, 1, 2), UVec3(0, 1, 3), UVec3(1, 0, 4), UVec3(0, 1, 2)};
    m.material_ids.assign(m.triangles.size(), 0);
    MeshTopology t = analyze_topology(m);
    EXPECT_FALSE(t.closed);
    EXPECT_GT(t.boundary_edges, 0u);

    // A closed cube with one face duplicated: every edge of that face has 3 faces.
    Mesh c = cube();
    c.triangles.push_back(c.triangles[0]);
    c.triangles.push_back(c.triangles[1]);
    c.material_ids.assign(c.triangles.size(), 0);
    EXPECT_FALSE(analyze_topology(c).closed);
}

TEST(MeshTopology, EmptyMeshIsNotClosed) {
    MeshTopology t = analyze_topology(Mesh{});
    EXPECT_FALSE(t.closed);
    EXPECT_EQ(t.connected_components, 0u);
}

TEST(MeshTopology, CornellBoxIsOpen) {
    auto path = test::shared_asset("cornell-box/CornellBox-Original.obj");
    if (!path) GTEST_SKIP() << "shared asset cornell-box/CornellBox-Original.obj not found";
    MeshTopology t = analyze_topology(load_obj(*path).meshes[0]);
    EXPECT_FALSE(t.closed);
    EXPECT_GT(t.boundary_edges, 0u);
}

TEST(MeshTopology, RealClosedModels) {
    // The dragon decimation and the CesiumMan figure are watertight; the bunny scan has
    // holes in its base.
    if (auto dragon = test::shared_asset("dragon/dragon.obj")) {
        MeshTopology t = analyze_topology(load_obj(*dragon).meshes[0]);
        EXPECT_TRUE(t.closed);
        EXPECT_EQ(t.connected_components, 1u);
    }
    if (auto bunny = test::shared_asset("bunny/stanford-bunny.obj")) {
        MeshTopology t = analyze_topology(load_obj(*bunny).meshes[0]);
        EXPECT_FALSE(t.closed);
        EXPECT_GT(t.boundary_edges, 0u);
    } else {
        GTEST_SKIP() << "shared assets dragon/bunny not found";
    }
}
