// Voxelizer: equal to a brute-force triangle/box test over every voxel, sorted and
// unique, independent of thread count, streaming regions, clear errors.
#include <gtest/gtest.h>
#include <algorithm>
#include <random>
#include <set>
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/util/morton.hpp"
#include "core/util/parallel.hpp"
#include "core/scene/scene.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/test_support.hpp"
#include "tests/masked_plane.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;
using gilab::test::TriangleSoup;

namespace {

// Akenine-Möller's triangle/box overlap test, written out independently of the
// voxelizer: box centre c, half size h; touching counts as overlap.
bool tri_box_reference(const DVec3& c, const DVec3& h, const DVec3& t0, const DVec3& t1, const DVec3& t2) {
    DVec3 v[3] = {t0 - c, t1 - c, t2 - c};
    DVec3 e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
    for (const DVec3& edge : e)
        for (int k = 0; k < 3; ++k) {
            DVec3 unit(0);
            unit[k] = 1;
            DVec3 a = glm::cross(unit, edge);
            double p0 = glm::dot(a, v[0]), p1 = glm::dot(a, v[1]), p2 = glm::dot(a, v[2]);
            double r = h.x * std::abs(a.x) + h.y * std::abs(a.y) + h.z * std::abs(a.z);
            if (std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r) return false;
        }
    for (int k = 0; k < 3; ++k)
        if (std::min({v[0][k], v[1][k], v[2][k]}) > h[k] || std::max({v[0][k], v[1][k], v[2][k]}) < -h[k]) return false;
    DVec3 n = glm::cross(e[0], e[1]);
    DVec3 vmin, vmax;
    for (int q = 0; q < 3; ++q) {
        if (n[q] > 0) {
            vmin[q] = -h[q] - v[0][q];
            vmax[q] = h[q] - v[0][q];
        } else {
            vmin[q] = h[q] - v[0][q];
            vmax[q] = -h[q] - v[0][q];
        }
    }
    if (glm::dot(n, vmin) > 0) return false;
    return glm::dot(n, vmax) >= 0;
}

DVec3 to_voxels(const VoxelGrid& g, const Vec3& p) {
    return (DVec3(p) - DVec3(g.origin)) * (double(g.resolution) / double(g.extent));
}

// Every voxel of the grid against every triangle.
std::vector<uint64_t> brute_force(const TriangleSoup& m, const VoxelGrid& g) {
    std::vector<uint64_t> codes;
    const uint32_t n = g.resolution;
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x) {
                DVec3 c = DVec3(x, y, z) + 0.5;
                for (const UVec3& t : m.triangles)
                    if (tri_box_reference(c, DVec3(0.5), to_voxels(g, m.positions[t.x]), to_voxels(g, m.positions[t.y]),
                                          to_voxels(g, m.positions[t.z]))) {
                        codes.push_back(morton_encode(x, y, z));
                        break;
                    }
            }
    std::sort(codes.begin(), codes.end());
    return codes;
}

void expect_equal_sets(const std::vector<uint64_t>& got, const std::vector<uint64_t>& want, const std::string& what) {
    ASSERT_EQ(got.size(), want.size()) << what;
    for (size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i], want[i]) << what << ": first difference at entry " << i;
    }
}

void expect_sorted_unique(const std::vector<uint64_t>& codes) {
    for (size_t i = 1; i < codes.size(); ++i) ASSERT_LT(codes[i - 1], codes[i]);
}

// Triangles whose vertices sit on voxel corners, edges and faces (grid units = world
// units): the touching cases of the test.
TriangleSoup grid_aligned_triangles(uint32_t n, std::mt19937& rng) {
    TriangleSoup m;
    float N = float(n);
    m.add({2, 3, 5}, {6, 3, 5}, {2, 6, 5});          // in the plane z = 5
    m.add({0, 0, 0}, {N, 0, 0}, {0, N, 0});          // on the grid's lower face
    m.add({N, 1, 1}, {N, 4, 1}, {N, 1, 4});          // on the grid's upper face
    m.add({1, 1, 1}, {4, 1, 1}, {4, 1, 1});          // segment along an edge line
    m.add({3, 3, 3}, {3, 3, 3}, {3, 3, 3});          // a point on a voxel corner
    m.add({1.5f, 1.5f, 1}, {5.5f, 1.5f, 1}, {1.5f, 5.5f, 1});  // z = 1, half-voxel corners
    m.add({0, 0, 0}, {4, 4, 4}, {4, 4, 0});          // through voxel corners diagonally
    std::uniform_int_distribution<int> coord(0, int(n));
    for (int i = 0; i < 30; ++i) {
        auto p = [&] { return Vec3(float(coord(rng)), float(coord(rng)), float(coord(rng))); };
        m.add(p(), p(), p());
    }
    return m;
}

// Slivers: nearly collinear corners, exact segments, needles and tiny triangles.
TriangleSoup thin_triangles(std::mt19937& rng) {
    TriangleSoup m;
    std::uniform_real_distribution<float> u(0.05f, 0.95f), tiny(-1e-6f, 1e-6f);
    for (int i = 0; i < 12; ++i) {
        Vec3 a = gilab::test::random_point(rng, Vec3(0.05f), Vec3(0.95f));
        Vec3 b = gilab::test::random_point(rng, Vec3(0.05f), Vec3(0.95f));
        float t = u(rng);
        Vec3 on_line = a + t * (b - a);
        m.add(a, b, on_line + Vec3(tiny(rng), tiny(rng), tiny(rng)));  // sliver
        m.add(a, b, on_line);                                          // collinear
        m.add(a, a + Vec3(1e-5f, 2e-5f, 0), a + Vec3(0, 1e-5f, 3e-5f));  // tiny
    }
    m.add({0.01f, 0.01f, 0.01f}, {0.99f, 0.99f, 0.99f}, {0.99f, 0.99f, 0.990001f});  // diagonal needle
    return m;
}

}  // namespace

TEST(Voxelizer, MatchesBruteForceOnRandomTriangles) {
    for (uint32_t n : {7u, 16u, 33u}) {
        std::mt19937 rng(1234 + n);
        // Some corners fall outside the grid: clipping must match too.
        TriangleSoup m = gilab::test::random_triangles(rng, 25, Vec3(-0.1f), Vec3(1.1f));
        VoxelGrid g = gilab::test::unit_grid(n);
        VoxelList got = voxelize(m.positions, m.triangles, g);
        expect_sorted_unique(got.codes);
        expect_equal_sets(got.codes, brute_force(m, g), "random triangles, N = " + std::to_string(n));
    }
}

TEST(Voxelizer, MatchesBruteForceOnGridAlignedTriangles) {
    for (uint32_t n : {7u, 16u, 33u}) {
        std::mt19937 rng(99 + n);
        TriangleSoup m = grid_aligned_triangles(n, rng);
        VoxelGrid g;
        g.origin = Vec3(0);
        g.extent = float(n);  // one world unit per voxel: every touching case is exact
        g.resolution = n;
        VoxelList got = voxelize(m.positions, m.triangles, g);
        expect_equal_sets(got.codes, brute_force(m, g), "grid-aligned triangles, N = " + std::to_string(n));
        // A triangle in the plane z = 5 touches both layers of voxels beside it.
        EXPECT_TRUE(std::binary_search(got.codes.begin(), got.codes.end(), morton_encode(2, 3, 4)));
        EXPECT_TRUE(std::binary_search(got.codes.begin(), got.codes.end(), morton_encode(2, 3, 5)));
    }
}

TEST(Voxelizer, MatchesBruteForceOnThinAndDegenerateTriangles) {
    for (uint32_t n : {7u, 16u, 33u}) {
        std::mt19937 rng(7 + n);
        TriangleSoup m = thin_triangles(rng);
        VoxelGrid g = gilab::test::unit_grid(n);
        VoxelList got = voxelize(m.positions, m.triangles, g);
        expect_equal_sets(got.codes, brute_force(m, g), "thin triangles, N = " + std::to_string(n));
    }
}

TEST(Voxelizer, SphereAtNonPowerOfTwoResolution) {
    TriangleSoup m = gilab::test::uv_sphere(Vec3(0.5f), 0.4f, 8, 16);
    for (uint32_t n : {5u, 33u, 41u}) {
        VoxelGrid g = gilab::test::unit_grid(n);
        VoxelList got = voxelize(m.positions, m.triangles, g);
        expect_equal_sets(got.codes, brute_force(m, g), "sphere, N = " + std::to_string(n));
        for (uint64_t c : got.codes) {
            UVec3 v = morton_decode(c);
            ASSERT_TRUE(v.x < n && v.y < n && v.z < n);
        }
        EXPECT_GE(got.stats.estimated_voxels, got.size());
    }
}

TEST(Voxelizer, SameOutputAtAnyThreadCount) {
    std::mt19937 rng(5);
    TriangleSoup m = gilab::test::random_triangles(rng, 60, Vec3(0), Vec3(1));
    VoxelGrid g = gilab::test::unit_grid(300);  // several bricks
    VoxelList many = voxelize(m.positions, m.triangles, g);
    VoxelList one;
    {
        ThreadLimit limit(1);
        one = voxelize(m.positions, m.triangles, g);
    }
    EXPECT_GT(many.stats.bricks, 1u);
    expect_sorted_unique(many.codes);
    EXPECT_EQ(many.codes, one.codes);
}

TEST(Voxelizer, RegionsAreSlicesOfTheWholeGrid) {
    TriangleSoup m = gilab::test::uv_sphere(Vec3(0.5f), 0.45f, 16, 32);
    VoxelGrid g = gilab::test::unit_grid(64);
    Voxelizer vox(m.positions, m.triangles, g);
    VoxelList all = vox.voxelize();
    std::mt19937 rng(3);
    std::uniform_int_distribution<uint32_t> c(0, 64);
    for (int i = 0; i < 10; ++i) {
        VoxelRegion r;
        for (int k = 0; k < 3; ++k) {
            uint32_t a = c(rng), b = c(rng);
            r.begin[k] = std::min(a, b);
            r.end[k] = std::max(a, b) + 1;
        }
        std::vector<uint64_t> want;
        for (uint64_t code : all.codes)
            if (r.contains(morton_decode(code))) want.push_back(code);
        expect_equal_sets(vox.voxelize(r).codes, want, "region " + std::to_string(i));
    }
    // Aligned octree cells in Morton order concatenate to the whole list.
    std::vector<uint64_t> joined;
    for (uint64_t cell : vox.touched_cells(4)) {
        VoxelRegion r{morton_decode(cell) * 16u, morton_decode(cell) * 16u + UVec3(16)};
        auto part = vox.voxelize(r).codes;
        joined.insert(joined.end(), part.begin(), part.end());
    }
    EXPECT_EQ(joined, all.codes);
}

TEST(Voxelizer, TouchedCellsCoverEveryVoxel) {
    std::mt19937 rng(11);
    TriangleSoup m = gilab::test::random_triangles(rng, 40, Vec3(0), Vec3(1));
    VoxelGrid g = gilab::test::unit_grid(40);
    Voxelizer vox(m.positions, m.triangles, g);
    VoxelList all = vox.voxelize();
    for (int log2 : {0, 2, 3, 6}) {
        auto cells = vox.touched_cells(log2);
        for (uint64_t code : all.codes)
            ASSERT_TRUE(std::binary_search(cells.begin(), cells.end(), code >> (3 * log2))) << "cell level " << log2;
    }
}

// A cell voxelized from its bin alone gives the cell's voxels of the whole scene.
TEST(Voxelizer, BinnedCellsGiveTheWholeScenesVoxels) {
    std::mt19937 rng(12);
    TriangleSoup m = gilab::test::random_triangles(rng, 60, Vec3(0), Vec3(1));
    VoxelGrid g = gilab::test::unit_grid(64);
    Voxelizer vox(m.positions, m.triangles, g);
    const VoxelList all = vox.voxelize();
    for (int log2 : {2, 4, 5}) {
        const CellTriangles bins = vox.bin_triangles(log2);
        ASSERT_EQ(bins.begin.size(), bins.cells.size() + 1);
        std::vector<uint64_t> joined;
        size_t binned_below_all = 0;
        for (size_t i = 0; i < bins.cells.size(); ++i) {
            const UVec3 lo = morton_decode(bins.cells[i]) << UVec3(uint32_t(log2));
            const VoxelRegion r{lo, lo + UVec3(1u << log2)};
            const auto part = vox.voxelize(r, bins.of(i)).codes;
            ASSERT_EQ(part, vox.voxelize(r).codes) << "cell " << i << " of " << (1 << log2) << "³";
            joined.insert(joined.end(), part.begin(), part.end());
            binned_below_all += bins.of(i).size() < m.triangles.size();
        }
        EXPECT_EQ(joined, all.codes);
        // The bins are what makes a cell cheap: most cells see only some triangles.
        EXPECT_GT(binned_below_all, bins.cells.size() / 2) << "cells of " << (1 << log2) << "³";
    }
    // Only the given triangles are voxelized: one triangle's voxels are its voxelizer's.
    const uint32_t first[] = {0};
    const std::vector<UVec3> alone = {m.triangles[0]};
    EXPECT_EQ(vox.voxelize(g.full_region(), first).codes, Voxelizer(m.positions, alone, g).voxelize().codes);
    const uint32_t missing[] = {uint32_t(m.triangles.size())};
    EXPECT_THROW(vox.voxelize(g.full_region(), missing), Error);
}

// Blocks hold exactly the brute-force voxels, each block once with its voxels' bits,
// also in grids smaller than one 4³ block and at a resolution that is no power of two.
TEST(Voxelizer, BlocksAreTheVoxelsFourByFour) {
    std::mt19937 rng(5);
    TriangleSoup m = gilab::test::random_triangles(rng, 40, Vec3(0), Vec3(1));
    std::vector<uint32_t> every(m.triangles.size());
    for (uint32_t i = 0; i < every.size(); ++i) every[i] = i;
    for (uint32_t res : {1u, 2u, 3u, 37u, 64u}) {
        const VoxelGrid g = gilab::test::unit_grid(res);
        const VoxelBlocks blocks = Voxelizer(m.positions, m.triangles, g).voxelize_blocks(g.full_region(), every);
        const std::vector<uint64_t> expected = brute_force(m, g);
        ASSERT_FALSE(expected.empty()) << res;
        std::vector<uint64_t> expected_blocks, expected_masks;
        for (uint64_t code : expected) {
            if (expected_blocks.empty() || expected_blocks.back() != code / 64) {
                expected_blocks.push_back(code / 64);
                expected_masks.push_back(0);
            }
            expected_masks.back() |= uint64_t(1) << (code % 64);
        }
        EXPECT_EQ(blocks.blocks, expected_blocks) << res << "³";
        EXPECT_EQ(blocks.masks, expected_masks) << res << "³";
        EXPECT_EQ(blocks.voxel_count(), expected.size()) << res << "³";
        EXPECT_EQ(blocks.codes(), expected) << res << "³";
        std::vector<uint64_t> round_blocks, round_masks;
        blocks_from_codes(expected, round_blocks, round_masks);
        EXPECT_EQ(round_blocks, expected_blocks) << res << "³";
        EXPECT_EQ(round_masks, expected_masks) << res << "³";
    }
}

TEST(Voxelizer, BinningBeyondTheBudgetIsRefusedBeforeAllocating) {
    TriangleSoup m = gilab::test::uv_sphere(Vec3(0.5f), 0.45f);
    VoxelizeOptions small;
    small.max_bytes = 1024;
    Voxelizer vox(m.positions, m.triangles, gilab::test::unit_grid(512), small);
    try {
        vox.bin_triangles(0);
        FAIL() << "binning a sphere into single voxels at 512³ fits in 1 KiB";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("memory budget"), std::string::npos) << e.what();
    }
}

TEST(Voxelizer, SceneFrameGathersAllMeshes) {
    TriangleSoup a = gilab::test::uv_sphere(Vec3(0.3f), 0.2f), b = gilab::test::uv_sphere(Vec3(0.7f), 0.2f);
    SceneFrame frame;
    frame.meshes.resize(2);
    frame.meshes[0].positions = a.positions;
    frame.meshes[0].triangles = a.triangles;
    frame.meshes[1].positions = b.positions;
    frame.meshes[1].triangles = b.triangles;
    TriangleSoup both = a;
    uint32_t base = uint32_t(a.positions.size());
    both.positions.insert(both.positions.end(), b.positions.begin(), b.positions.end());
    for (UVec3 t : b.triangles) both.triangles.push_back(t + UVec3(base));
    VoxelGrid g = gilab::test::unit_grid(24);
    EXPECT_EQ(voxelize(frame, g).codes, brute_force(both, g));
}

TEST(Voxelizer, BadInputIsAClearError) {
    TriangleSoup m = gilab::test::uv_sphere(Vec3(0.5f), 0.4f);
    auto expect_error = [&](auto&& fn, const std::string& text) {
        try {
            fn();
            ADD_FAILURE() << "no error; expected one mentioning '" << text << "'";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    };
    expect_error([&] { voxelize(m.positions, m.triangles, gilab::test::unit_grid(0)); }, "at least 1");
    expect_error([&] { voxelize(m.positions, m.triangles, gilab::test::unit_grid((1u << 21) + 1)); }, "2^21");
    expect_error([&] { voxelize(m.positions, {}, gilab::test::unit_grid(8)); }, "no triangles");
    expect_error([&] { voxelize(SceneFrame{}, gilab::test::unit_grid(8)); }, "no triangles");
    std::vector<UVec3> bad{UVec3(0, 1, 99999)};
    expect_error([&] { voxelize(m.positions, bad, gilab::test::unit_grid(8)); }, "refers to vertex 99999");
    std::vector<Vec3> nan_positions = m.positions;
    nan_positions[3].y = std::nanf("");
    expect_error([&] { voxelize(nan_positions, m.triangles, gilab::test::unit_grid(8)); }, "non-finite");
    // 2^21 per axis: a sphere's surface alone is ~10^13 voxels. Refused before allocating.
    expect_error([&] { voxelize(m.positions, m.triangles, gilab::test::unit_grid(1u << 21)); }, "memory budget");
    VoxelizeOptions small;
    small.max_bytes = 1000;
    expect_error([&] { voxelize(m.positions, m.triangles, gilab::test::unit_grid(64), small); }, "memory budget");
}

TEST(Voxelizer, StanfordBunnyAt64MatchesPerTriangleBruteForce) {
    auto path = gilab::test::shared_asset("bunny/stanford-bunny.obj");
    if (!path) GTEST_SKIP() << "bunny/stanford-bunny.obj not found in the shared scenes";
    Scene scene = load_mesh_file(*path);
    TriangleSoup m;
    for (const Mesh& mesh : scene.meshes) {
        uint32_t base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), mesh.positions.begin(), mesh.positions.end());
        for (UVec3 t : mesh.triangles) m.triangles.push_back(t + UVec3(base));
    }
    Bounds3 b;
    for (const Vec3& p : m.positions) b.extend(p);
    VoxelGrid g = VoxelGrid::enclosing(b, 64);
    VoxelList got = voxelize(m.positions, m.triangles, g);
    // Brute force per triangle over its bounding box of voxels.
    std::vector<uint64_t> want;
    for (const UVec3& t : m.triangles) {
        DVec3 p[3] = {to_voxels(g, m.positions[t.x]), to_voxels(g, m.positions[t.y]), to_voxels(g, m.positions[t.z])};
        DVec3 lo = glm::floor(glm::min(p[0], glm::min(p[1], p[2]))) - 1.0;
        DVec3 hi = glm::floor(glm::max(p[0], glm::max(p[1], p[2])));
        for (double z = std::max(0.0, lo.z); z <= std::min(63.0, hi.z); ++z)
            for (double y = std::max(0.0, lo.y); y <= std::min(63.0, hi.y); ++y)
                for (double x = std::max(0.0, lo.x); x <= std::min(63.0, hi.x); ++x)
                    if (tri_box_reference(DVec3(x, y, z) + 0.5, DVec3(0.5), p[0], p[1], p[2]))
                        want.push_back(morton_encode(uint32_t(x), uint32_t(y), uint32_t(z)));
    }
    std::sort(want.begin(), want.end());
    want.erase(std::unique(want.begin(), want.end()), want.end());
    expect_equal_sets(got.codes, want, "bunny at 64^3");
    EXPECT_GT(got.size(), 5000u);
}

// An alpha-masked plane over 8 × 8 voxels whose mask changes at the voxels' edges: the
// conservative voxelizer keeps exactly the voxels the opaque texels reach; the same plane
// unmasked fills all 64.
TEST(Voxelizer, AlphaMaskedTrianglesOccupyOnlyWhereTheirMaskIsOpaque) {
    SceneFrame frame = test::masked_block_plane(4.5f, Vec3(1.0f));
    VoxelGrid grid;
    grid.origin = Vec3(0);
    grid.extent = 8.0f;
    grid.resolution = 8;
    const VoxelList masked = Voxelizer(frame, grid).voxelize();
    std::set<std::pair<uint32_t, uint32_t>> present;
    for (size_t i = 0; i < masked.size(); ++i) {
        const UVec3 v = masked.voxel(i);
        EXPECT_EQ(v.y, 4u);
        present.insert({v.x, v.z});
    }
    for (uint32_t z = 0; z < 8; ++z)
        for (uint32_t x = 0; x < 8; ++x)
            EXPECT_EQ(present.count({x, z}) == 1, test::masked_block_opaque(int(x), int(z))) << x << "," << z;
    frame.materials[0].alpha_mode = AlphaMode::Opaque;
    EXPECT_EQ(Voxelizer(frame, grid).voxelize().size(), 64u);
}
