// Closed-mesh checks (CGAL): a cube is closed, a cube missing a face is not, seams
// split by normals still count as closed, non-manifold soups are reported open without
// crashing, and the real Cornell box is open.
#include <gtest/gtest.h>
#include <algorithm>
#include <map>
#include <numeric>
#include <random>

#include "core/io/mesh_loaders.hpp"
#include "core/scene/mesh_topology.hpp"
#include "scenes/procedural_meshes.hpp"
#include "tests/test_support.hpp"

using namespace gilab;

namespace {

// Unit cube, 8 shared vertices, 12 outward-facing triangles, two per face in the order
// x = 0, x = 1, y = 0, y = 1, z = 0, z = 1.
Mesh cube(Vec3 offset = Vec3(0)) { return make_box("cube", offset, offset + Vec3(1), 0); }

// The same cube with 4 vertices per face (as exporters write it for flat normals): each
// face's two triangles get copies of its corners of their own.
Mesh split_cube() {
    Mesh c = cube(), out;
    for (size_t f = 0; f < 6; ++f) {
        std::map<uint32_t, uint32_t> copy;  // the face's corners in c → in out
        for (UVec3 t : {c.triangles[2 * f], c.triangles[2 * f + 1]}) {
            for (int k = 0; k < 3; ++k) {
                const auto [it, added] = copy.try_emplace(t[k], uint32_t(out.positions.size()));
                if (added) out.positions.push_back(c.positions[t[k]]);
                t[k] = it->second;
            }
            out.triangles.push_back(t);
        }
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

TEST(MeshTopology, ClosedPartsOfAnOpenMeshAreFoundTriangleByTriangle) {
    // One mesh: a closed cube, a cube missing its top, and a second closed cube with one
    // triangle wound the wrong way; triangles shuffled so order says nothing.
    Mesh m = cube();
    Mesh open = cube(Vec3(3, 0, 0));
    open.triangles.erase(open.triangles.begin() + 6, open.triangles.begin() + 8);  // the +y face
    Mesh flipped = cube(Vec3(0, 3, 0));
    std::swap(flipped.triangles[5].y, flipped.triangles[5].z);
    std::vector<int> part(m.triangles.size(), 0);
    for (const Mesh* extra : {&open, &flipped}) {
        const uint32_t base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), extra->positions.begin(), extra->positions.end());
        for (const UVec3& t : extra->triangles) m.triangles.push_back(t + UVec3(base));
        part.insert(part.end(), extra->triangles.size(), extra == &open ? 1 : 2);
    }
    const size_t flipped_index = 12 + 10 + 5;
    std::vector<size_t> order(m.triangles.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::mt19937 rng(3);
    std::shuffle(order.begin(), order.end(), rng);
    Mesh shuffled = m;
    std::vector<int> shuffled_part(order.size());
    size_t flipped_at = 0;
    for (size_t i = 0; i < order.size(); ++i) {
        shuffled.triangles[i] = m.triangles[order[i]];
        shuffled_part[i] = part[order[i]];
        if (order[i] == flipped_index) flipped_at = i;
    }
    shuffled.material_ids.assign(shuffled.triangles.size(), 0);

    const MeshTopology t = analyze_topology(shuffled);
    EXPECT_FALSE(t.closed);
    EXPECT_EQ(t.connected_components, 3u);
    EXPECT_EQ(t.closed_components, 2u);
    int closed_id[3] = {-2, -2, -2};
    for (size_t i = 0; i < shuffled.triangles.size(); ++i) {
        const int c = t.closed_component[i];
        if (shuffled_part[i] == 1) {
            EXPECT_EQ(c, -1) << i;
            EXPECT_EQ(t.winding[i], 0);
            continue;
        }
        ASSERT_GE(c, 0) << i;
        int& id = closed_id[shuffled_part[i]];
        if (id == -2) id = c;
        EXPECT_EQ(c, id) << "one part, one component";
    }
    EXPECT_NE(closed_id[0], closed_id[2]);
    // Within each closed cube every triangle winds alike, except the one reversed.
    int8_t first_of_part[3] = {0, 0, 0};
    for (size_t i = 0; i < shuffled.triangles.size(); ++i) {
        if (shuffled_part[i] == 1 || i == flipped_at) continue;
        int8_t& f = first_of_part[shuffled_part[i]];
        if (f == 0) f = t.winding[i];
        EXPECT_EQ(t.winding[i], f) << i;
    }
    EXPECT_EQ(t.winding[flipped_at], -first_of_part[2]);
}
