// Cascaded voxel texture and its fragment voxelizer: the cell layout (a block per level,
// a voxel's six faces together), toroidal addressing round trips (also after scrolling),
// nested snapped placement, per-face opacities of walls, one-sided emission, scroll +
// re-voxelize = voxelize from scratch, scroll filling from the coarser level, the
// anisotropic 2×2×2 filter, the dense mip chain, thread-count independence and input
// errors.
#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include "accel/vct/fragment_voxelizer.hpp"
#include "accel/vct/cascaded_voxel_texture.hpp"
#include "accel/vct/dense_mip_texture.hpp"
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "scenes/builtin_scenes.hpp"
#include "tests/masked_plane.hpp"

namespace gilab {
namespace {

// A world frame made of quads (each two triangles, winding normal as given by corner
// order a→b→c→d, counter-clockwise seen from the normal's side).
struct QuadSpec {
    Vec3 a, b, c, d;
    uint32_t material = 0;
};
SceneFrame frame_of(const std::vector<QuadSpec>& quads) {
    SceneFrame frame;
    WorldMesh mesh;
    for (const QuadSpec& q : quads) {
        uint32_t base = uint32_t(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), {q.a, q.b, q.c, q.d});
        mesh.triangles.push_back({base, base + 1, base + 2});
        mesh.triangles.push_back({base, base + 2, base + 3});
        mesh.material_ids.insert(mesh.material_ids.end(), {q.material, q.material});
    }
    for (const Vec3& p : mesh.positions) frame.bounds.extend(p);
    frame.meshes.push_back(std::move(mesh));
    return frame;
}
std::vector<Material> two_materials() {
    Material grey;
    grey.albedo = Vec3(0.5f, 0.6f, 0.7f);
    Material light;
    light.albedo = Vec3(0.2f);
    light.emission = Vec3(3, 2, 1);
    return {grey, light};
}
// A square wall perpendicular to x at x = x0 spanning [y0,y1]×[z0,z1], normal +X.
QuadSpec wall_x(float x0, float y0, float y1, float z0, float z1, uint32_t material = 0) {
    return {Vec3(x0, y0, z0), Vec3(x0, y1, z0), Vec3(x0, y1, z1), Vec3(x0, y0, z1), material};
}

CascadeConfig small_config(int levels = 3, int resolution = 8, double voxel = 0.25) {
    CascadeConfig c;
    c.levels = levels;
    c.resolution = resolution;
    c.voxel_size = voxel;
    c.anchor = DVec3(0.0);
    return c;
}

TEST(CascadedVoxelTexture, LayoutIsOneBlockPerLevelWithAVoxelsSixFacesTogether) {
    CascadedVoxelTexture t(small_config(3, 8));
    EXPECT_EQ(t.texels_per_level(), 512u);
    EXPECT_EQ(t.level_cells(), 512u * 6u);
    EXPECT_EQ(t.radiance.size(), t.cell_count());
    std::set<size_t> seen;
    for (int f = 0; f < kFaceCount; ++f)
        for (int k = 0; k < 3; ++k)
            for (uint32_t z = 0; z < 8; ++z)
                for (uint32_t y = 0; y < 8; ++y)
                    for (uint32_t x = 0; x < 8; ++x) {
                        size_t i = t.index(f, k, UVec3(x, y, z));
                        // ((level·R + z)·R + y)·R + x)·6 + face
                        EXPECT_EQ(i % 6, size_t(f));
                        EXPECT_EQ((i / 6) % 8, size_t(x));
                        EXPECT_EQ((i / 48) % 8, size_t(y));
                        EXPECT_EQ((i / 384) % 8, size_t(z));
                        EXPECT_EQ(i / 3072, size_t(k));
                        seen.insert(i);
                    }
    EXPECT_EQ(seen.size(), t.cell_count());
    EXPECT_EQ(t.voxel_count(), 3u * 512u);
    EXPECT_EQ(t.opacity_bytes_paper(), 3u * 512u * 6u);
}

TEST(CascadedVoxelTexture, AddressingRoundTripsAlsoAfterScrolling) {
    CascadeConfig config = small_config(4, 8, 0.1);
    config.anchor = DVec3(-3.0, 1.5, 0.25);
    CascadedVoxelTexture t(config);
    const DVec3 viewers[] = {{0.0, 0.0, 0.0}, {-2.7, 1.9, 0.3}, {5.3, -4.1, 7.7}, {-11.0, 3.3, -0.9}};
    for (const DVec3& viewer : viewers) {
        for (int k = 0; k < t.levels(); ++k) {
            t.scroll(k, t.origin_for(viewer, k));
            const VoxelBox box = t.region(k);
            // The viewer is inside and the region is centred on it within one voxel pair.
            IVec3 vv = t.world_to_voxel(viewer, k);
            EXPECT_TRUE(box.contains(vv)) << "level " << k;
            EXPECT_EQ(box.begin.x % 2, 0);
            std::set<size_t> texels;
            for (int z = box.begin.z; z < box.end.z; ++z)
                for (int y = box.begin.y; y < box.end.y; ++y)
                    for (int x = box.begin.x; x < box.end.x; ++x) {
                        const IVec3 v(x, y, z);
                        // world → voxel → world (centre) → voxel
                        EXPECT_EQ(t.world_to_voxel(t.voxel_center(v, k), k), v);
                        // voxel → texel → voxel
                        UVec3 texel = t.texel_of(v);
                        EXPECT_EQ(t.voxel_at_texel(k, texel), v);
                        texels.insert(t.index(0, k, texel));
                    }
            EXPECT_EQ(texels.size(), 512u) << "every voxel of the region has its own texel";
        }
        // Nesting: each region covers whole voxels of the next coarser level, inside it.
        for (int k = 0; k + 1 < t.levels(); ++k) {
            VoxelBox fine = t.region(k), coarse = t.region(k + 1);
            EXPECT_EQ(fine.begin.x % 2, 0);
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(fine.begin[a] / 2, coarse.begin[a]);
                EXPECT_LE(fine.end[a] / 2, coarse.end[a]);
            }
            EXPECT_EQ(t.inner_box(k + 1).volume(), 4 * 4 * 4);
        }
        EXPECT_EQ(t.finest_level_containing(viewer), 0);
    }
    EXPECT_EQ(t.finest_level_containing(DVec3(1e6)), -1);
}

TEST(FragmentVoxelizer, AxisAlignedWallGivesOpaqueXFacesOnly) {
    // Voxels of 1 unit; the wall x = 2.5 cuts voxel column x = 2 through its centre.
    SceneFrame frame = frame_of({wall_x(2.5f, 0.0f, 4.0f, 0.0f, 4.0f)});
    FragmentVoxelizer vox(frame, two_materials());
    auto voxels = vox.voxelize({DVec3(0.0), 1.0}, {IVec3(0), IVec3(4)});
    ASSERT_EQ(voxels.size(), 16u);
    for (const AnisotropicVoxel& v : voxels) {
        EXPECT_EQ(v.coord.x, 2);
        EXPECT_FLOAT_EQ(v.faces[kFacePosX].opacity, 1.0f);
        EXPECT_FLOAT_EQ(v.faces[kFaceNegX].opacity, 1.0f);
        for (int f : {kFacePosY, kFaceNegY, kFacePosZ, kFaceNegZ}) EXPECT_EQ(v.faces[size_t(f)].opacity, 0.0f);
        // Normals oriented towards each face's side; albedo and position carried over.
        EXPECT_NEAR(v.faces[kFacePosX].normal.x, 1.0f, 1e-6f);
        EXPECT_NEAR(v.faces[kFaceNegX].normal.x, -1.0f, 1e-6f);
        EXPECT_NEAR(v.faces[kFacePosX].albedo.y, 0.6f, 1e-6f);
        EXPECT_NEAR(v.faces[kFacePosX].position.x, 2.5f, 1e-6f);
        EXPECT_NEAR(v.faces[kFacePosX].position.y, float(v.coord.y) + 0.5f, 1e-5f);
    }
}

TEST(FragmentVoxelizer, PartialAndSlantedCoverage) {
    // Half of the voxel's cross-section covered: opacity 1/2.
    {
        SceneFrame frame = frame_of({wall_x(0.5f, 0.0f, 0.5f, 0.0f, 1.0f)});
        auto voxels = FragmentVoxelizer(frame, two_materials()).voxelize({DVec3(0.0), 1.0}, {IVec3(0), IVec3(1)});
        ASSERT_EQ(voxels.size(), 1u);
        EXPECT_NEAR(voxels[0].faces[kFacePosX].opacity, 0.5f, 1e-6f);
    }
    // A plane x + y = 1 through one voxel: area √2, |n_x| = |n_y| = 1/√2, so the X and Y
    // faces each see coverage 1 and the Z faces none.
    {
        SceneFrame frame = frame_of({{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 1), Vec3(1, 0, 1)}});
        auto voxels = FragmentVoxelizer(frame, two_materials()).voxelize({DVec3(0.0), 1.0}, {IVec3(0), IVec3(1)});
        ASSERT_EQ(voxels.size(), 1u);
        EXPECT_NEAR(voxels[0].faces[kFacePosX].opacity, 1.0f, 1e-5f);
        EXPECT_NEAR(voxels[0].faces[kFaceNegY].opacity, 1.0f, 1e-5f);
        EXPECT_EQ(voxels[0].faces[kFacePosZ].opacity, 0.0f);
    }
}

// An alpha-masked, textured quad over 8 × 8 voxels whose mask and colour change at the
// voxels' edges: a voxel exists exactly where the mask is opaque, with its block's colour.
TEST(FragmentVoxelizer, MaskedTexturedQuadHoldsOnlyItsOpaqueTexels) {
    const SceneFrame frame = test::masked_block_plane(0.5f, Vec3(0.5f));
    const auto voxels = FragmentVoxelizer(frame, frame.materials).voxelize({DVec3(0.0), 1.0}, {IVec3(0), IVec3(8, 1, 8)});
    std::set<std::pair<int, int>> present;
    for (const AnisotropicVoxel& v : voxels) {
        present.insert({v.coord.x, v.coord.z});
        const VoxelFaceData& f = v.faces[kFacePosY];
        EXPECT_FLOAT_EQ(f.opacity, 1.0f);
        const Vec3 expected = v.coord.x % 2 == 0 ? Vec3(0.5f, 0, 0) : Vec3(0, 0, 0.5f);
        EXPECT_NEAR(f.albedo.x, expected.x, 1e-6f) << v.coord.x << "," << v.coord.z;
        EXPECT_NEAR(f.albedo.z, expected.z, 1e-6f) << v.coord.x << "," << v.coord.z;
    }
    for (int z = 0; z < 8; ++z)
        for (int x = 0; x < 8; ++x)
            EXPECT_EQ(present.count({x, z}) == 1, test::masked_block_opaque(x, z)) << x << "," << z;
}

TEST(FragmentVoxelizer, WallOnALatticePlaneBelongsToOneVoxelLayer) {
    SceneFrame frame = frame_of({wall_x(2.0f, 0.0f, 4.0f, 0.0f, 4.0f)});
    auto voxels = FragmentVoxelizer(frame, two_materials()).voxelize({DVec3(0.0), 1.0}, {IVec3(0), IVec3(4)});
    ASSERT_EQ(voxels.size(), 16u);
    for (const AnisotropicVoxel& v : voxels) EXPECT_EQ(v.coord.x, 2);
}

TEST(FragmentVoxelizer, EmissionIsOneSided) {
    // Emitter facing −Y (a ceiling light): only the −Y face of its voxels emits.
    SceneFrame frame = frame_of({{Vec3(0, 0.5f, 0), Vec3(1, 0.5f, 0), Vec3(1, 0.5f, 1), Vec3(0, 0.5f, 1), 1}});
    auto voxels = FragmentVoxelizer(frame, two_materials()).voxelize({DVec3(0.0), 1.0}, {IVec3(0), IVec3(1)});
    ASSERT_EQ(voxels.size(), 1u);
    EXPECT_EQ(voxels[0].faces[kFaceNegY].emission, Vec3(3, 2, 1));
    EXPECT_EQ(voxels[0].faces[kFacePosY].emission, Vec3(0));
    EXPECT_FLOAT_EQ(voxels[0].faces[kFacePosY].opacity, 1.0f);
}

// Compares the G-buffer of one level over its region; counts the occupied voxels.
void expect_same_level(const CascadedVoxelTexture& a, const CascadedVoxelTexture& b, int level, size_t& occupied) {
    ASSERT_EQ(a.region(level).begin, b.region(level).begin);
    const VoxelBox box = a.region(level);
    for (int z = box.begin.z; z < box.end.z; ++z)
        for (int y = box.begin.y; y < box.end.y; ++y)
            for (int x = box.begin.x; x < box.end.x; ++x) {
                const IVec3 v(x, y, z);
                ASSERT_EQ(a.occupied(level, v), b.occupied(level, v)) << "voxel " << x << "," << y << "," << z;
                ASSERT_EQ(a.gbuffer_voxel(level, v), b.gbuffer_voxel(level, v)) << "voxel " << x << "," << y << "," << z;
                occupied += a.occupied(level, v);
            }
}

TEST(CascadedVoxelTexture, ScrollThenRevoxelizeEqualsVoxelizingFromScratch) {
    Scene cornell = make_cornell_box();
    SceneFrame frame = cornell.evaluate(0);
    FragmentVoxelizer vox(frame, cornell.materials);
    CascadeConfig config = small_config(3, 16, 1.0 / 64.0);
    config.anchor = DVec3(-0.013, 0.002, -0.007);  // an arbitrary lattice
    CascadedVoxelTexture moving(config);
    DVec3 viewer(0.5, 0.5, 0.5);
    for (int k = 2; k >= 0; --k) {
        moving.place(k, moving.origin_for(viewer, k));
        moving.voxelize(k, vox);
    }
    const DVec3 path[] = {{0.53, 0.47, 0.55}, {0.61, 0.41, 0.5}, {0.35, 0.6, 0.7}, {0.1, 0.1, 0.1}, {0.9, 0.2, 0.8}};
    for (const DVec3& p : path) {
        for (int k = 2; k >= 0; --k) {
            IVec3 target = moving.origin_for(p, k);
            for (const VoxelBox& box : moving.scroll(k, target)) moving.voxelize(k, vox, box);
        }
        CascadedVoxelTexture fresh(config);
        for (int k = 2; k >= 0; --k) {
            fresh.place(k, fresh.origin_for(p, k));
            fresh.voxelize(k, vox);
        }
        size_t occupied = 0;
        for (int k = 0; k < 3; ++k) expect_same_level(moving, fresh, k, occupied);
        EXPECT_GT(occupied, 100u);
        // The G-buffer holds at most three records per occupied voxel, exactly (no
        // capacity left over from edits), and three bits per texel with a 32-bit rank
        // count per 256 bits — not a record or a slot per texel.
        const double index_bits = 3.0 * double(moving.voxel_count()) * (1.0 + 32.0 / 256.0);
        EXPECT_LE(double(moving.gbuffer_bytes()), index_bits / 8.0 + 64.0 * 3 + 3.0 * double(occupied) * sizeof(PackedSurface));
    }
}

TEST(CascadedVoxelTexture, ScrollExposesDisjointSlabsAndFillsFromCoarserLevel) {
    CascadedVoxelTexture t(small_config(2, 8, 1.0));
    t.place(1, IVec3(-4));
    t.place(0, IVec3(-4));
    // Mark every level-1 voxel's radiance with its coordinates.
    const VoxelBox coarse = t.region(1);
    for (int z = coarse.begin.z; z < coarse.end.z; ++z)
        for (int y = coarse.begin.y; y < coarse.end.y; ++y)
            for (int x = coarse.begin.x; x < coarse.end.x; ++x)
                for (int f = 0; f < kFaceCount; ++f)
                    t.radiance[t.index_of_voxel(f, 1, IVec3(x, y, z))] =
                        to_half_rgba(Vec4(float(x + 10), float(y + 10), float(z + 10), 0.5f));
    auto exposed = t.scroll(0, IVec3(-2, -5, -4));
    int64_t volume = 0;
    for (const VoxelBox& b : exposed) volume += b.volume();
    // New region minus old: 8³ − overlap (6·7·8).
    EXPECT_EQ(volume, 512 - 6 * 7 * 8);
    for (size_t i = 0; i < exposed.size(); ++i)
        for (size_t j = i + 1; j < exposed.size(); ++j) EXPECT_TRUE(exposed[i].intersect(exposed[j]).empty());
    for (const VoxelBox& b : exposed) {
        EXPECT_TRUE(t.region(0).intersect(b).volume() == b.volume());
        const IVec3 v = b.begin;
        const IVec3 parent(floor_div(v.x, 2), floor_div(v.y, 2), floor_div(v.z, 2));
        EXPECT_EQ(from_half_rgba(t.radiance[t.index_of_voxel(kFacePosY, 0, v)]),
                  Vec4(float(parent.x + 10), float(parent.y + 10), float(parent.z + 10), 0.5f));
    }
    // No overlap: the whole region is new.
    auto all = t.scroll(0, IVec3(40, 0, 0));
    ASSERT_EQ(all.size(), 1u);
    EXPECT_EQ(all[0].volume(), 512);
}

TEST(AnisotropicFilter, FrontChildHidesTheBackOneAlongTheFaceAxis) {
    std::array<Vec4, 8> children{};
    const Vec4 red(1, 0, 0, 1), green(0, 1, 0, 1);
    // Column x: child x = 1 (the +X side) red and opaque, x = 0 green, all four columns.
    for (int c = 0; c < 8; ++c) children[size_t(c)] = (c & 1) ? red : green;
    EXPECT_EQ(downsample_face(kFacePosX, children), red);    // seen from +X: red in front
    EXPECT_EQ(downsample_face(kFaceNegX, children), green);  // seen from −X: green in front
    // Seen along Y, both colours are side by side: average.
    EXPECT_EQ(downsample_face(kFacePosY, children), Vec4(0.5f, 0.5f, 0, 1));
    // Half-transparent front: c = c_f + (1 − α_f) c_b.
    for (int c = 0; c < 8; ++c) children[size_t(c)] = (c & 1) ? Vec4(0.5f, 0, 0, 0.5f) : green;
    EXPECT_EQ(downsample_face(kFacePosX, children), Vec4(0.5f, 0.5f, 0, 1));
    // A quarter of the columns occupied by one opaque voxel: α = 1/4.
    children.fill(Vec4(0));
    children[0] = red;
    EXPECT_EQ(downsample_face(kFacePosZ, children).a, 0.25f);
    // Faces a direction sees: travelling +X meets −X faces; weights are squared components.
    FaceWeights w = faces_seen_along(glm::normalize(Vec3(1, -2, 0)));
    EXPECT_EQ(w.face[0], kFaceNegX);
    EXPECT_EQ(w.face[1], kFacePosY);
    EXPECT_NEAR(w.weight[0], 0.2f, 1e-6f);
    EXPECT_NEAR(w.weight[1], 0.8f, 1e-6f);
}

TEST(CascadedVoxelTexture, DownsampleFillsTheInnerBoxFromTheFinerLevel) {
    SceneFrame frame = frame_of({wall_x(0.3f, -4.0f, 4.0f, -4.0f, 4.0f)});
    FragmentVoxelizer vox(frame, two_materials());
    CascadedVoxelTexture t(small_config(2, 8, 0.25));
    for (int k = 1; k >= 0; --k) {
        t.place(k, t.origin_for(DVec3(0.0), k));
        t.voxelize(k, vox);
    }
    for (size_t i = 0; i < t.cell_count(); ++i) t.radiance[i] = to_half_rgba(Vec4(Vec3(2.0f * t.opacity_of_cell(i)), t.opacity_of_cell(i)));
    t.downsample(1, t.radiance);
    const VoxelBox inner = t.inner_box(1);
    ASSERT_FALSE(inner.empty());
    // Level-1 voxel column holding x = 0.3 (voxel size 0.5 → x index 0); level 0 covers
    // it with children x = 0, 1 (size 0.25), the wall in child 1.
    for (int y = inner.begin.y; y < inner.end.y; ++y) {
        Vec4 v = from_half_rgba(t.radiance[t.index_of_voxel(kFaceNegX, 1, IVec3(0, y, 0))]);
        EXPECT_NEAR(v.a, 1.0f, 1e-3f);
        EXPECT_NEAR(v.r, 2.0f, 2e-3f);
        Vec4 side = from_half_rgba(t.radiance[t.index_of_voxel(kFacePosY, 1, IVec3(0, y, 0))]);
        EXPECT_EQ(side.a, 0.0f);
    }
}

TEST(FragmentVoxelizer, SameVoxelsAtAnyThreadCount) {
    Scene cornell = make_cornell_box();
    SceneFrame frame = cornell.evaluate(0);
    FragmentVoxelizer vox(frame, cornell.materials);
    auto run = [&](int threads) {
        ThreadLimit limit(threads);
        return vox.voxelize({DVec3(-0.01), 1.0 / 48.0}, {IVec3(0), IVec3(50)});
    };
    auto a = run(1), b = run(2);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GT(a.size(), 1000u);
    for (size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].coord, b[i].coord);
        ASSERT_EQ(std::memcmp(&a[i].faces, &b[i].faces, sizeof(a[i].faces)), 0);
    }
    // Streaming gives the same set.
    std::atomic<size_t> streamed{0};
    vox.voxelize_each({DVec3(-0.01), 1.0 / 48.0}, {IVec3(0), IVec3(50)}, [&](const AnisotropicVoxel&) { ++streamed; });
    EXPECT_EQ(streamed.load(), a.size());
}

TEST(DenseMipTexture, MipChainAndMemoryBudget) {
    DenseMipConfig config;
    config.resolution = 8;
    config.voxel_size = 0.5;
    DenseMipTexture t(config);
    ASSERT_EQ(t.level_count(), 4);
    EXPECT_EQ(t.resolution(3), 1);
    // One opaque voxel with radiance 1 on all faces: each mip level sees it as 1/4 of a
    // column per face, composited opaque in front → alpha 1/4 per level.
    for (int f = 0; f < kFaceCount; ++f) t.radiance[0][t.index(0, f, IVec3(0))] = to_half_rgba(Vec4(1, 1, 1, 1));
    t.build_mips(t.radiance);
    EXPECT_FLOAT_EQ(from_half_rgba(t.radiance[1][t.index(1, kFacePosX, IVec3(0))]).a, 0.25f);
    EXPECT_FLOAT_EQ(from_half_rgba(t.radiance[2][t.index(2, kFacePosX, IVec3(0))]).a, 0.0625f);
    config.resolution = 512;
    config.max_bytes = size_t(1) << 30;
    try {
        DenseMipTexture big(config);
        FAIL() << "expected the memory budget to refuse 512³";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("budget"), std::string::npos) << e.what();
    }
}

TEST(CascadedVoxelTexture, RejectsBadConfigurations) {
    auto message = [](CascadeConfig c) {
        try {
            CascadedVoxelTexture t(c);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    CascadeConfig c = small_config();
    c.resolution = 24;
    EXPECT_NE(message(c).find("power of two"), std::string::npos);
    c = small_config();
    c.levels = 0;
    EXPECT_NE(message(c).find("levels"), std::string::npos);
    c = small_config();
    c.voxel_size = -1;
    EXPECT_NE(message(c).find("voxel size"), std::string::npos);
    SceneFrame frame = frame_of({wall_x(0.5f, 0, 1, 0, 1, 7)});
    try {
        FragmentVoxelizer v(frame, two_materials());
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("material 7"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace gilab

namespace gilab {
namespace {

// The cascades proper: each level holds only its own part (minus the inner box its
// finer level covers). Scrolling every level and following the finer level's inner box
// gives the same G-buffer as placing and voxelizing from scratch.
TEST(CascadedVoxelTexture, OwnPartsFollowTheFinerLevelWhenScrolling) {
    Scene cornell = make_cornell_box();
    SceneFrame frame = cornell.evaluate(0);
    FragmentVoxelizer vox(frame, cornell.materials);
    CascadeConfig config = small_config(3, 16, 1.0 / 64.0);
    auto build = [&](const DVec3& p) {
        CascadedVoxelTexture t(config);
        for (int k = 2; k >= 0; --k) t.place(k, t.origin_for(p, k));
        for (int k = 2; k >= 0; --k) t.voxelize_own(k, vox);
        return t;
    };
    CascadedVoxelTexture moving = build(DVec3(0.5));
    // Inner boxes hold nothing; the own part does.
    for (int k = 1; k < 3; ++k) EXPECT_TRUE(moving.occupied_in(k, moving.inner_box(k)).empty());
    const DVec3 path[] = {{0.55, 0.45, 0.52}, {0.7, 0.3, 0.6}, {0.2, 0.8, 0.1}, {0.21, 0.79, 0.12}};
    for (const DVec3& p : path) {
        std::vector<VoxelBox> exposed[3];
        for (int k = 2; k >= 0; --k) exposed[k] = moving.scroll(k, moving.origin_for(p, k));
        for (int k = 2; k >= 0; --k) moving.follow_inner(k, vox, exposed[k]);
        CascadedVoxelTexture fresh = build(p);
        size_t occupied = 0;
        for (int k = 0; k < 3; ++k) expect_same_level(moving, fresh, k, occupied);
        EXPECT_GT(occupied, 100u);
    }
    // Box subtraction: disjoint pieces whose volumes add up.
    VoxelBox a{IVec3(0), IVec3(10)}, b{IVec3(2, -3, 4), IVec3(5, 6, 20)};
    int64_t volume = 0;
    auto parts = subtract(a, b);
    for (const VoxelBox& p : parts) {
        volume += p.volume();
        EXPECT_TRUE(p.intersect(b).empty());
    }
    EXPECT_EQ(volume, a.volume() - a.intersect(b).volume());
}

}  // namespace
}  // namespace gilab
