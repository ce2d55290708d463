// Texture images, their mip pyramids and filtered lookups, texture transforms, and the
// decoder's refusals.
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>
#include <cmath>
#include "core/texture/image_decode.hpp"
#include "core/texture/texture.hpp"
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"
#include "core/util/rng.hpp"
#include "scenes/procedural_textures.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

std::string png_bytes(const Rgba8Image& img) {
    std::string out;
    stbi_write_png_to_func(
        [](void* context, void* data, int size) { static_cast<std::string*>(context)->append(static_cast<char*>(data), size_t(size)); },
        &out, img.width, img.height, 4, img.texels.data(), img.width * 4);
    return out;
}

std::span<const uint8_t> bytes_of(const std::string& s) { return {reinterpret_cast<const uint8_t*>(s.data()), s.size()}; }

TEST(MipMap, EveryLevelKeepsTheMeanAndHalvesToOneTexel) {
    // 24 × 10: odd sizes on the way (12 × 5, 6 × 2, 3 × 1, 1 × 1) fold their last texel in.
    Rgba8Image img{24, 10, {}};
    Rng rng(3, 0);
    for (int i = 0; i < 24 * 10; ++i)
        for (int c = 0; c < 4; ++c) img.texels.push_back(uint8_t(rng.uniform() * 255.0f));
    const MipMap mip(img, ColorEncoding::Linear, "random");
    ASSERT_EQ(mip.levels(), 5);
    EXPECT_EQ(mip.width(1), 12);
    EXPECT_EQ(mip.height(2), 2);
    EXPECT_EQ(mip.width(3), 3);
    EXPECT_EQ(mip.width(4), 1);
    EXPECT_EQ(mip.height(4), 1);
    Vec4 mean0(0.0f);
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 24; ++x) mean0 += mip.texel(0, x, y, WrapMode::Repeat, WrapMode::Repeat) / 240.0f;
    // 8-bit rounding at each level, and the folded texels' smaller weights, stay within 3 codes.
    const Vec4 top = mip.texel(4, 0, 0, WrapMode::Repeat, WrapMode::Repeat);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(top[c], mean0[c], 3.0f / 255.0f) << c;
    EXPECT_EQ(mip.bytes(), size_t(4) * (240 + 60 + 12 + 3 + 1));
}

TEST(MipMap, SrgbLevelsAverageLinearLight) {
    // Black and white columns: the linear mean is 0.5, whose sRGB code is 188, not 128.
    Rgba8Image img{2, 1, {0, 0, 0, 255, 255, 255, 255, 255}};
    const MipMap mip(img, ColorEncoding::Srgb, "bw");
    EXPECT_EQ(mip.level(1).texels[0], 188);
    EXPECT_NEAR(mip.texel(1, 0, 0, WrapMode::Repeat, WrapMode::Repeat).x, 0.5f, 0.003f);
    EXPECT_NEAR(mip.texel(0, 1, 0, WrapMode::Repeat, WrapMode::Repeat).x, 1.0f, 0.0f);
}

TEST(MipMap, WrapModesFetchTheRightTexel) {
    Rgba8Image img{4, 1, {}};
    for (int x = 0; x < 4; ++x) img.texels.insert(img.texels.end(), {uint8_t(10 * x), 0, 0, 255});
    const MipMap mip(img, ColorEncoding::Linear, "ramp");
    auto red = [&](int x, WrapMode m) { return int(std::lround(mip.texel(0, x, 0, m, m).x * 255.0f)); };
    EXPECT_EQ(red(5, WrapMode::Repeat), 10);
    EXPECT_EQ(red(-1, WrapMode::Repeat), 30);
    EXPECT_EQ(red(5, WrapMode::ClampToEdge), 30);
    EXPECT_EQ(red(-3, WrapMode::ClampToEdge), 0);
    EXPECT_EQ(red(4, WrapMode::MirroredRepeat), 30);  // 0 1 2 3 | 3 2 1 0 | 0 ...
    EXPECT_EQ(red(6, WrapMode::MirroredRepeat), 10);
    EXPECT_EQ(red(-1, WrapMode::MirroredRepeat), 0);
    EXPECT_EQ(red(-5, WrapMode::MirroredRepeat), 30);
    // Bilinear at a texel centre is that texel; halfway between two is their mean.
    EXPECT_NEAR(mip.bilinear(0, Vec2(1.5f / 4, 0.5f), WrapMode::Repeat, WrapMode::Repeat).x, 10.0f / 255, 1e-6f);
    EXPECT_NEAR(mip.bilinear(0, Vec2(2.0f / 4, 0.5f), WrapMode::Repeat, WrapMode::Repeat).x, 15.0f / 255, 1e-6f);
}

// A checkerboard of single texels, seen minified: point lookups at the finest level alias
// (each is black or white), filtered lookups over the footprint converge to the mean.
TEST(MipMap, MinifiedCheckerboardConvergesToItsMeanWithoutAliasing) {
    const MipMap mip(checkerboard_image(256, 1, Vec3(1.0f), Vec3(0.0f)), ColorEncoding::Srgb, "checker");
    TextureRef t;
    t.image = std::make_shared<const MipMap>(mip);
    Rng rng(11, 0);
    double point_var = 0, filtered_var = 0, filtered_mean = 0;
    const int n = 2000;
    for (int i = 0; i < n; ++i) {
        const Vec2 uv = rng.uniform2();
        const double point = t.sample(uv, 0.0f).x - 0.5;
        const double filtered = t.sample(uv, 16.0f / 256.0f).x;  // a footprint of 16 texels
        point_var += point * point / n;
        filtered_var += (filtered - 0.5) * (filtered - 0.5) / n;
        filtered_mean += filtered / n;
    }
    EXPECT_GT(point_var, 0.02);       // aliased: bilinear between black and white texels (1/36 for uniform positions)
    EXPECT_LT(filtered_var, 1e-4);    // filtered: the grey of the mean everywhere
    EXPECT_NEAR(filtered_mean, 0.5, 0.005);
    // The level follows the footprint: 16 texels wide is level 4.
    EXPECT_FLOAT_EQ(mip.level_for_footprint(16.0f / 256.0f), 4.0f);
}

TEST(UvTransform, FollowsKhrTextureTransform) {
    UvTransform t;
    EXPECT_EQ(t.apply(Vec2(0.3f, 0.7f)), Vec2(0.3f, 0.7f));
    t.offset = Vec2(0.5f, 0.25f);
    t.scale = Vec2(2.0f, 4.0f);
    const Vec2 a = t.apply(Vec2(0.25f, 0.5f));  // scale, then offset
    EXPECT_NEAR(a.x, 1.0f, 1e-6f);
    EXPECT_NEAR(a.y, 2.25f, 1e-6f);
    // The extension's rotation matrix [[c, s], [-s, c]]: +90° takes +u to −v.
    UvTransform r;
    r.rotation = kPi / 2;
    const Vec2 b = r.apply(Vec2(1.0f, 0.0f));
    EXPECT_NEAR(b.x, 0.0f, 1e-6f);
    EXPECT_NEAR(b.y, -1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(t.max_stretch(), 4.0f);
}

TEST(ImageDecode, DecodesAPngAndRefusesWhatIsNotOne) {
    const Rgba8Image img = checkerboard_image(2, 3, Vec3(1, 0, 0), Vec3(0, 0, 1));
    const Rgba8Image back = decode_image(bytes_of(png_bytes(img)), "checker.png");
    EXPECT_EQ(back.width, 6);
    EXPECT_EQ(back.height, 6);
    EXPECT_EQ(back.texels, img.texels);

    std::string msg = test::error_of([] { decode_image(bytes_of("not an image at all"), "junk.png"); });
    EXPECT_NE(msg.find("junk.png"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not a decodable image"), std::string::npos) << msg;
    msg = test::error_of([] { decode_image({}, "empty.png"); });
    EXPECT_NE(msg.find("empty.png: empty image file"), std::string::npos) << msg;
    // A truncated file: its header is fine, its pixels are missing.
    const std::string png = png_bytes(checkerboard_image(8, 8, Vec3(1), Vec3(0)));
    msg = test::error_of([&] { decode_image(bytes_of(png.substr(0, png.size() / 2)), "cut.png"); });
    EXPECT_NE(msg.find("cut.png"), std::string::npos) << msg;
}

TEST(ImageDecode, RefusesHugeImagesBeforeDecoding) {
    // A PNG header declaring 40000 × 16 texels, with no pixel data behind it.
    std::string png = "\x89PNG\r\n\x1a\n";
    png += std::string("\0\0\0\x0dIHDR", 8);
    png += std::string("\0\0\x9c\x40\0\0\0\x10\x08\x06\0\0\0\0\0\0\0", 17);
    std::string msg = test::error_of([&] { decode_image(bytes_of(png), "huge.png"); });
    EXPECT_NE(msg.find("huge.png: image of 40000 × 16 texels"), std::string::npos) << msg;
    // Within the side limit but over the memory budget: 4096² needs 128 MiB + its pyramid.
    png = "\x89PNG\r\n\x1a\n";
    png += std::string("\0\0\0\x0dIHDR", 8);
    png += std::string("\0\0\x10\0\0\0\x10\0\x08\x06\0\0\0\0\0\0\0", 17);
    ScopedMemoryLimit limit(uint64_t(64) << 20);
    msg = test::error_of([&] { decode_image(bytes_of(png), "big.png"); });
    EXPECT_NE(msg.find("big.png"), std::string::npos) << msg;
    EXPECT_NE(msg.find("memory limit"), std::string::npos) << msg;
}

TEST(ImageDecode, NamesTheFileItCannotRead) {
    const auto dir = test::temp_dir("texture_decode_files");
    std::string msg = test::error_of([&] { decode_image_file(dir / "missing.png"); });
    EXPECT_NE(msg.find("missing.png"), std::string::npos) << msg;
    msg = test::error_of([&] { decode_image_file(dir); });
    EXPECT_NE(msg.find("directory"), std::string::npos) << msg;
}

}  // namespace
}  // namespace gilab
