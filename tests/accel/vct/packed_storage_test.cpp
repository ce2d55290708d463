// The voxel structures' storage types: RGBA16F radiance (accel/vct/half_rgba.hpp), the
// packed G-buffer record (accel/vct/packed_surface.hpp) and the sparse G-buffer that
// indexes records by rank (accel/vct/sparse_gbuffer.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include "accel/vct/half_rgba.hpp"
#include "accel/vct/packed_surface.hpp"
#include "accel/vct/sparse_gbuffer.hpp"
#include <map>
#include "core/util/error.hpp"
#include "core/util/rng.hpp"

using namespace gilab;

TEST(HalfRgba, RoundTripsHalvesAndRoundsToNearest) {
    // Values a half holds exactly come back exactly.
    for (float v : {0.0f, 1.0f, 0.5f, 2.0f, 3.0f, 1024.0f, 65504.0f, 6.103515625e-05f, 0.099975586f})
        EXPECT_EQ(from_half(to_half(v)), v) << v;
    // 1 + 2^-11 is halfway between two halves: to even (1); 1 + 3·2^-12 rounds up.
    EXPECT_EQ(from_half(to_half(1.0f + 0x1p-11f)), 1.0f);
    EXPECT_EQ(from_half(to_half(1.0f + 3 * 0x1p-12f)), 1.0f + 0x1p-10f);
    // Relative error at most 2^-11 over the normal range.
    Rng rng(3, 1);
    for (int i = 0; i < 10000; ++i) {
        const float v = std::exp2(rng.uniform() * 28.0f - 13.0f);
        EXPECT_NEAR(from_half(to_half(v)), v, v * 0x1p-11f) << v;
    }
}

TEST(HalfRgba, ClampsWhatAHalfCannotHoldAndFlushesSubnormals) {
    EXPECT_EQ(to_half(-1.0f), 0);
    EXPECT_EQ(to_half(std::numeric_limits<float>::quiet_NaN()), 0);
    EXPECT_EQ(from_half(to_half(1e9f)), 65504.0f);
    EXPECT_EQ(from_half(to_half(std::numeric_limits<float>::infinity())), 65504.0f);
    EXPECT_EQ(to_half(5e-5f), 0);  // below the smallest normal half: flushed
    const Vec4 v(0.25f, 1.5f, 7.0f, 0.75f);
    EXPECT_EQ(from_half_rgba(to_half_rgba(v)), v);
    EXPECT_TRUE(has_opacity(to_half_rgba(v)));
    EXPECT_FALSE(has_opacity(to_half_rgba(Vec4(1, 1, 1, 0))));
}

TEST(PackedSurface, KeepsOpacityAlbedoNormalAndPositionToTheirPrecision) {
    Rng rng(5, 2);
    const float size = 0.37f;
    const Vec3 center(1.25f, -3.5f, 0.125f);
    for (int i = 0; i < 5000; ++i) {
        VoxelFaceData f;
        f.opacity = rng.uniform();
        f.albedo = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
        // Directions over the whole sphere, including the octahedron's lower half.
        const float z = 2.0f * rng.uniform() - 1.0f, phi = 2.0f * kPi * rng.uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        f.normal = Vec3(r * std::cos(phi), r * std::sin(phi), z);
        f.position = center + size * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f));
        const PackedSurface p = pack_surface(f, center, size);
        if (!(f.opacity > 0)) continue;
        // Rounded to 1/255, never below one step.
        EXPECT_NEAR(unpack_opacity(p), std::max(f.opacity, 1.0f / 255.0f), 0.5f / 255.0f + 1e-7f);
        // Half an sRGB step: at most 1/(2·255·12.92) near black, ~0.0044 near white.
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(unpack_albedo(p)[k], f.albedo[k], 0.0045f);
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(unpack_albedo(p)[k], f.albedo[k], f.albedo[k] * 0.02f + 0.5f / (255.0f * 12.92f));
        const Vec3 n = unpack_normal(p);
        EXPECT_NEAR(glm::length(n), 1.0f, 1e-6f);
        EXPECT_GT(glm::dot(n, f.normal), std::cos(kPi / 180.0f)) << "normal " << f.normal.x << "," << f.normal.y << "," << f.normal.z;
        EXPECT_LT(glm::length(unpack_position(p, center, size) - f.position), 1e-4f * size);
    }
    // Any coverage keeps a nonzero opacity; none packs to an empty record.
    VoxelFaceData faint;
    faint.opacity = 1e-6f;
    EXPECT_EQ(pack_surface(faint, center, size).opacity, 1);
    EXPECT_EQ(pack_surface(VoxelFaceData{}, center, size), PackedSurface{});
    // The sRGB code book round-trips; axis normals, the octahedron's corners, come back exactly.
    for (int i = 0; i < 256; ++i) EXPECT_EQ(to_srgb8(from_srgb8(uint8_t(i))), i);
    for (int face = 0; face < kFaceCount; ++face) {
        VoxelFaceData f;
        f.opacity = 1;
        f.normal = face_direction(face);
        EXPECT_EQ(unpack_normal(pack_surface(f, center, size)), f.normal) << face_name(face);
    }
}

TEST(PackedVoxel, AnAxisRecordServesBothOfItsFaces) {
    const VoxelLattice lattice{DVec3(0.5, -1, 2), 0.25};
    AnisotropicVoxel v;
    v.coord = IVec3(3, -2, 7);
    const Vec3 c = voxel_center(lattice, v.coord);
    // x: both faces covered (the voxelizer's case: same data, normal negated);
    // y: only −y covered (the +y record is made from it, normal turned towards +y).
    const Vec3 n = glm::normalize(Vec3(0.8f, 0.1f, -0.3f));
    v.faces[kFacePosX] = {0.75f, Vec3(0.2f, 0.4f, 0.6f), n, Vec3(0), c + Vec3(0.01f, 0.02f, -0.03f)};
    v.faces[kFaceNegX] = v.faces[kFacePosX];
    v.faces[kFaceNegX].normal = -n;
    v.faces[kFaceNegY] = {0.5f, Vec3(0.9f, 0.1f, 0.1f), Vec3(0, -1, 0), Vec3(0), c};
    const PackedVoxel p = pack_voxel(v, lattice);
    EXPECT_EQ(p.axis[0], pack_surface(v.faces[kFacePosX], c, 0.25f));
    VoxelFaceData plus_y = v.faces[kFaceNegY];
    plus_y.normal = Vec3(0, 1, 0);
    EXPECT_EQ(p.axis[1], pack_surface(plus_y, c, 0.25f));
    EXPECT_EQ(p.axis[2], PackedSurface{});
    EXPECT_FALSE(p.empty());
    EXPECT_TRUE(PackedVoxel{}.empty());
}

namespace {

size_t below(Rng& rng, size_t n) { return size_t(rng.next_u32()) % n; }

PackedVoxel random_voxel(Rng& rng) {
    PackedVoxel v;
    for (PackedSurface& s : v.axis) {
        if (rng.uniform() < 0.4f) continue;  // an empty axis
        s.opacity = uint8_t(1 + below(rng, 255));
        s.albedo[0] = uint8_t(below(rng, 256));
        s.offset[2] = int16_t(below(rng, 65535) - 32767);
    }
    return v;
}

void expect_holds(const SparseGBuffer& g, const std::map<size_t, PackedVoxel>& reference) {
    size_t records = 0, occupied = 0;
    for (size_t t = 0; t < g.texels(); ++t) {
        const auto it = reference.find(t);
        const PackedVoxel want = it == reference.end() ? PackedVoxel{} : it->second;
        ASSERT_EQ(g.occupied(t), !want.empty()) << "texel " << t;
        occupied += !want.empty();
        for (int axis = 0; axis < 3; ++axis) {
            const PackedSurface* s = g.find(t, axis);
            ASSERT_EQ(s != nullptr, want.axis[size_t(axis)].opacity != 0) << "texel " << t << " axis " << axis;
            if (s) {
                ASSERT_EQ(*s, want.axis[size_t(axis)]) << "texel " << t << " axis " << axis;
                ++records;
            }
        }
    }
    EXPECT_EQ(g.records(), records);
    EXPECT_EQ(g.occupied_texels(), occupied);
}

}  // namespace

TEST(SparseGBuffer, FindsWhatWasStagedAndForgetsWhatWasErased) {
    // 1000 texels: 3000 bits, not a whole number of rank blocks.
    SparseGBuffer g(1000);
    std::map<size_t, PackedVoxel> reference;
    Rng rng(11, 4);
    for (int batch = 0; batch < 40; ++batch) {
        const int erases = int(below(rng, 60)), writes = int(below(rng, 80));
        for (int i = 0; i < erases; ++i) {
            const size_t t = below(rng, 1000);
            g.erase(t);
            reference.erase(t);
        }
        for (int i = 0; i < writes; ++i) {
            const size_t t = below(rng, 1000);
            const PackedVoxel v = random_voxel(rng);
            g.stage(t, v);  // staged after this batch's erases: the write stands
            if (v.empty()) reference.erase(t);
            else reference[t] = v;
        }
        g.commit();
        ASSERT_FALSE(g.pending());
        expect_holds(g, reference);
    }
    // A texel staged twice in one batch keeps the later record.
    PackedVoxel first, second;
    first.axis[0].opacity = 10;
    second.axis[2].opacity = 20;
    g.stage(7, first);
    g.stage(7, second);
    g.commit();
    reference[7] = second;
    expect_holds(g, reference);
    g.clear();
    expect_holds(g, {});
}

TEST(SparseGBuffer, TheResultDoesNotDependOnTheStagingOrder) {
    Rng rng(12, 1);
    std::vector<std::pair<size_t, PackedVoxel>> writes;
    for (size_t t = 0; t < 4096; t += 1 + below(rng, 5)) writes.push_back({t, random_voxel(rng)});
    SparseGBuffer forward(4096), backward(4096);
    for (const auto& [t, v] : writes) forward.stage(t, v);
    for (auto it = writes.rbegin(); it != writes.rend(); ++it) backward.stage(it->first, it->second);
    forward.commit();
    backward.commit();
    std::map<size_t, PackedVoxel> reference;
    for (const auto& [t, v] : writes)
        if (!v.empty()) reference[t] = v;
    expect_holds(forward, reference);
    expect_holds(backward, reference);
    // Three bits per texel and a 32-bit count per 256 bits, plus the records exactly.
    EXPECT_EQ(forward.bytes(), backward.bytes());
    EXPECT_LE(forward.bytes(), 3 * 4096 / 8 + (3 * 4096 / 256 + 1) * 4 + forward.records() * sizeof(PackedSurface));
    EXPECT_THROW(SparseGBuffer(size_t(1) << 31), Error);
}
