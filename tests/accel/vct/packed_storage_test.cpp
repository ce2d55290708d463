// The voxel structures' storage types: RGBA16F radiance (accel/vct/half_rgba.hpp) and the
// packed G-buffer face (accel/vct/packed_surface.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include "accel/vct/half_rgba.hpp"
#include "accel/vct/packed_surface.hpp"
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

TEST(PackedSurface, KeepsAlbedoNormalAndPositionToTheirPrecision) {
    Rng rng(5, 2);
    const float size = 0.37f;
    const Vec3 center(1.25f, -3.5f, 0.125f);
    for (int i = 0; i < 5000; ++i) {
        VoxelFaceData f;
        f.opacity = 1;
        f.albedo = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
        // Directions over the whole sphere, including the octahedron's lower half.
        const float z = 2.0f * rng.uniform() - 1.0f, phi = 2.0f * kPi * rng.uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        f.normal = Vec3(r * std::cos(phi), r * std::sin(phi), z);
        f.position = center + size * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f));
        const PackedSurface p = pack_surface(f, center, size);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(unpack_albedo(p)[k], f.albedo[k], f.albedo[k] * 0x1p-11f + 6.2e-5f);
        const Vec3 n = unpack_normal(p);
        EXPECT_NEAR(glm::length(n), 1.0f, 1e-6f);
        EXPECT_GT(glm::dot(n, f.normal), std::cos(1e-3f)) << "normal " << f.normal.x << "," << f.normal.y << "," << f.normal.z;
        EXPECT_LT(glm::length(unpack_position(p, center, size) - f.position), 1e-4f * size);
    }
    // Axis normals, the octahedron's corners, come back exactly.
    for (int face = 0; face < kFaceCount; ++face) {
        VoxelFaceData f;
        f.normal = face_direction(face);
        EXPECT_EQ(unpack_normal(pack_surface(f, center, size)), f.normal) << face_name(face);
    }
}
