// Heat maps (core/image/heat_map.hpp): the PNG shows each value in the ramp's colour, NaN in
// cyan, and a colour bar under the map running from the darkest to the brightest colour.
#include <gtest/gtest.h>

#include <cmath>
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#include "core/util/error.hpp"
#include "core/image/heat_map.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

struct Decoded {
    int width = 0, height = 0;
    std::vector<uint8_t> rgb;
    std::array<uint8_t, 3> at(int x, int y) const {
        const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
};

Decoded decode(const std::filesystem::path& path) {
    Decoded d;
    int comp = 0;
    unsigned char* pixels = stbi_load(path.c_str(), &d.width, &d.height, &comp, 3);
    if (pixels) d.rgb.assign(pixels, pixels + size_t(d.width) * size_t(d.height) * 3);
    stbi_image_free(pixels);
    return d;
}

TEST(HeatMap, RampRunsFromDarkToBrightAndClamps) {
    auto brightness = [](const std::array<uint8_t, 3>& c) { return int(c[0]) + int(c[1]) + int(c[2]); };
    int previous = -1;
    for (int i = 0; i <= 16; ++i) {
        const int b = brightness(heat_colour(i / 16.0));
        EXPECT_GT(b, previous) << i;
        previous = b;
    }
    EXPECT_EQ(heat_colour(-3.0), heat_colour(0.0));
    EXPECT_EQ(heat_colour(7.0), heat_colour(1.0));
}

TEST(HeatMap, PngShowsValuesNanAndTheColourBar) {
    ImagePlane map(40, 10);
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 40; ++x) map.at(x, y) = float(x) / 39.0f * 2.0f;  // 0 … 2
    map.at(5, 5) = std::nanf("");
    const auto path = test::temp_dir("heat_map") / "map.png";
    write_heat_map_png(path, map, 0.0, 2.0);
    const Decoded d = decode(path);
    ASSERT_GT(d.width, 0) << "not a PNG";
    EXPECT_GE(d.width, 40);
    EXPECT_GT(d.height, 10 + 12);  // map, colour bar, labels
    EXPECT_EQ(d.at(0, 0), heat_colour(0.0));
    EXPECT_EQ(d.at(39, 3), heat_colour(1.0));
    EXPECT_EQ(d.at(20, 3), heat_colour(map.at(20, 3) / 2.0));
    EXPECT_EQ(d.at(5, 5), (std::array<uint8_t, 3>{0, 255, 255}));
    // The colour bar: darkest at its left end, brightest at its right end.
    EXPECT_EQ(d.at(0, 10 + 6 + 6), heat_colour(0.0));
    EXPECT_EQ(d.at(d.width - 1, 10 + 6 + 6), heat_colour(1.0));
    // The labels are drawn (black pixels below the bar).
    int black = 0;
    for (int y = 10 + 6 + 12; y < d.height; ++y)
        for (int x = 0; x < d.width; ++x) black += d.at(x, y) == std::array<uint8_t, 3>{0, 0, 0};
    EXPECT_GT(black, 20);
}

TEST(HeatMap, BadRangeOrEmptyMapIsRefused) {
    const auto dir = test::temp_dir("heat_map_bad");
    EXPECT_THROW(write_heat_map_png(dir / "a.png", ImagePlane(4, 4), 1.0, 1.0), Error);
    EXPECT_THROW(write_heat_map_png(dir / "b.png", ImagePlane(4, 4), 0.0, std::nan("")), Error);
    EXPECT_THROW(write_heat_map_png(dir / "c.png", ImagePlane(), 0.0, 1.0), Error);
    EXPECT_FALSE(std::filesystem::exists(dir / "a.png"));
}

}  // namespace
}  // namespace gilab
