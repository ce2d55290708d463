// Minimal-bit pointer encoding of the multi-frame DAG: both addressings decode every
// frame from the bitstream, and a hand-made DAG has exactly the bit count worked out by
// hand, so the byte count belongs to a real encoding.
#include <gtest/gtest.h>
#include <random>
#include "accel/dag/bit_stream.hpp"
#include "accel/temporal/minimal_bit_dag.hpp"
#include "accel/temporal/multi_frame_dag.hpp"
#include "core/voxel/voxelizer.hpp"
#include "tests/voxel_test_meshes.hpp"

using namespace gilab;

namespace {

std::vector<uint64_t> moving_sphere_frame(int frame, uint32_t n) {
    auto soup = gilab::test::uv_sphere(Vec3(0.25f + 0.07f * float(frame), 0.4f, 0.5f), 0.2f, 10, 20);
    return voxelize(soup.positions, soup.triangles, gilab::test::unit_grid(n)).codes;
}

LaidOutMultiFrameDag build(const std::vector<std::vector<uint64_t>>& frames, uint32_t n) {
    MultiFrameDag dag(gilab::test::unit_grid(n));
    for (const auto& f : frames) dag.append_frame(f);
    return dag.lay_out();
}

}  // namespace

TEST(BitStream, RoundTripsEveryWidth) {
    BitWriter w;
    std::mt19937_64 rng(3);
    std::vector<std::pair<uint64_t, int>> fields;
    for (int bits = 0; bits <= 64; ++bits)
        for (int k = 0; k < 3; ++k) {
            const uint64_t v = bits == 0 ? 0 : bits == 64 ? rng() : rng() & ((uint64_t(1) << bits) - 1);
            fields.push_back({v, bits});
            w.write(v, bits);
        }
    uint64_t at = 0;
    for (auto [v, bits] : fields) {
        EXPECT_EQ(read_bits(w.words(), at, bits), v) << bits << " bits";
        at += uint64_t(bits);
    }
    EXPECT_EQ(w.size(), at);
    EXPECT_THROW(w.write(4, 2), Error);
    EXPECT_EQ(bits_for_count(0), 0);
    EXPECT_EQ(bits_for_count(1), 0);
    EXPECT_EQ(bits_for_count(2), 1);
    EXPECT_EQ(bits_for_count(41), 6);
}

TEST(MinimalBitDag, BothEncodingsDecodeEveryFrame) {
    for (uint32_t n : {1u, 13u, 64u}) {
        std::vector<std::vector<uint64_t>> frames;
        for (int f = 0; f < 5; ++f) frames.push_back(moving_sphere_frame(f, n));
        frames.insert(frames.begin() + 2, std::vector<uint64_t>{});
        frames.push_back(frames[0]);
        const LaidOutMultiFrameDag t = build(frames, n);
        for (PointerAddressing a : {PointerAddressing::BitOffset, PointerAddressing::NodeIndex}) {
            const MinimalBitDag m = encode_minimal_bits(t, a);
            ASSERT_EQ(m.frame_count(), frames.size());
            for (size_t f = 0; f < frames.size(); ++f) EXPECT_EQ(m.decode(f), frames[f]) << "N " << n << " frame " << f;
            EXPECT_LT(m.bytes(), t.bytes() + MinimalBitDag::kHeaderBytesPerLevel * size_t(t.depth()) + 8);
        }
    }
}

// Grid 4^3 (depth 2). Frame A = voxels {0, 9}, frame B = {0, 9, 63}: bottom nodes with
// masks 0x01, 0x02, 0x80 (N_1 = 3, 8 bits each, w_1 = 0 since the leaf is one node);
// roots 0x03 (2 children) and 0x83 (3 children).
//  * bit offsets: B_1 = 24 → w_0 = 5; roots 8+10 and 8+15 bits → B_0 = 41; stream 65
//    bits = 9 B; root table 2 × ceil(log2 41) = 12 bits = 2 B; headers 2 × 9 B → 29 B.
//  * node indices: w_0 = ceil(log2 3) = 2; roots 12 + 14 → stream 50 bits = 7 B; root
//    table 2 × 1 bit = 1 B; headers 18 B → 26 B.
TEST(MinimalBitDag, HandMadeExampleHasTheExactBitCount) {
    const LaidOutMultiFrameDag t = build({{0, 9}, {0, 9, 63}}, 4);
    ASSERT_EQ(t.level_node_counts(), (std::vector<uint64_t>{2, 3, 1}));
    const MinimalBitDag offset = encode_minimal_bits(t, PointerAddressing::BitOffset);
    EXPECT_EQ(offset.pointer_bits(1), 0);
    EXPECT_EQ(offset.pointer_bits(0), 5);
    EXPECT_EQ(offset.level_bits(1), 24u);
    EXPECT_EQ(offset.level_bits(0), 41u);
    EXPECT_EQ(offset.level_bits(2), 0u);
    EXPECT_EQ(offset.stream_bits(), 65u);
    EXPECT_EQ(offset.root_bits(), 6);
    EXPECT_EQ(offset.bytes(), 29u);
    const MinimalBitDag index = encode_minimal_bits(t, PointerAddressing::NodeIndex);
    EXPECT_EQ(index.pointer_bits(0), 2);
    EXPECT_EQ(index.stream_bits(), 50u);
    EXPECT_EQ(index.root_bits(), 1);
    EXPECT_EQ(index.bytes(), 26u);
    EXPECT_EQ(offset.decode(1), (std::vector<uint64_t>{0, 9, 63}));
    EXPECT_EQ(index.decode(0), (std::vector<uint64_t>{0, 9}));
}

TEST(MinimalBitDag, NoPointerBitsAboveALevelOfOneNode) {
    const LaidOutMultiFrameDag t = build({moving_sphere_frame(0, 64), moving_sphere_frame(3, 64)}, 64);
    for (PointerAddressing a : {PointerAddressing::BitOffset, PointerAddressing::NodeIndex}) {
        const MinimalBitDag m = encode_minimal_bits(t, a);
        EXPECT_EQ(m.pointer_bits(t.depth() - 1), 0) << "the leaf level holds one node";
        for (int l = 0; l + 1 < t.depth(); ++l) EXPECT_GT(m.pointer_bits(l), 0) << "level " << l;
    }
}

TEST(MinimalBitDag, OffsetBytesAtLeastIndexBytes) {
    std::vector<std::vector<uint64_t>> frames;
    for (int f = 0; f < 6; ++f) frames.push_back(moving_sphere_frame(f, 64));
    const LaidOutMultiFrameDag t = build(frames, 64);
    const MinimalBitDag offset = encode_minimal_bits(t, PointerAddressing::BitOffset);
    const MinimalBitDag index = encode_minimal_bits(t, PointerAddressing::NodeIndex);
    EXPECT_GE(offset.bytes(), index.bytes());
    EXPECT_LT(offset.bytes(), t.bytes() / 2) << "minimal pointers beat 32-bit ones";
    for (int l = 0; l < t.depth(); ++l) EXPECT_GE(offset.pointer_bits(l), index.pointer_bits(l));
    EXPECT_THROW(offset.decode(6), Error);
}
