#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include "core/util/error.hpp"
#include "core/image/image_metrics.hpp"

namespace gilab {
namespace {

Film constant(int w, int h, float value) {
    Film film(w, h);
    for (float& v : film.layer("color").data) v = value;
    return film;
}

TEST(ImageMetrics, IdenticalImagesHaveZeroError) {
    Film a = constant(8, 6, 0.3f);
    a.set("color", 2, 3, Vec3(5.0f, -1.0f, 0.0f));
    EXPECT_EQ(relative_mse(a, a), 0.0);
    EXPECT_EQ(max_abs_difference(a, a), 0.0);
}

TEST(ImageMetrics, MaskedRelativeMseCountsOnlyMaskedPixels) {
    Film ref = constant(4, 4, 1.0f), img = constant(4, 4, 1.0f);
    img.set("color", 1, 2, Vec3(1.1f));  // pixel 9
    std::vector<uint8_t> mask(16, 0);
    EXPECT_EQ(relative_mse_masked(img, ref, mask), 0.0);  // nothing selected
    mask[9] = 1;
    EXPECT_NEAR(relative_mse_masked(img, ref, mask), 0.01 / 1.01, 1e-6);
    mask[0] = 1;  // an exact pixel halves the mean
    EXPECT_NEAR(relative_mse_masked(img, ref, mask), 0.5 * 0.01 / 1.01, 1e-6);
    std::fill(mask.begin(), mask.end(), 1);
    EXPECT_NEAR(relative_mse_masked(img, ref, mask), relative_mse(img, ref), 1e-12);
    EXPECT_THROW(relative_mse_masked(img, ref, std::vector<uint8_t>(3, 1)), Error);
}

TEST(ImageMetrics, RelativeMseMatchesTheDefinition) {
    Film ref = constant(4, 4, 1.0f);
    Film img = constant(4, 4, 1.1f);
    // (1.1 - 1)^2 / (1^2 + 0.01) everywhere.
    EXPECT_NEAR(relative_mse(img, ref), 0.01 / 1.01, 1e-7);
    EXPECT_NEAR(relative_mse(img, ref, "color", 1.0), 0.01 / 2.0, 1e-7);
    // One channel of one pixel off by 2 on a black reference: 4 / 0.01 / 48 values.
    Film black = constant(4, 4, 0.0f), one = constant(4, 4, 0.0f);
    one.layer("color").data[7] = 2.0f;
    EXPECT_NEAR(relative_mse(one, black), 4.0 / 0.01 / 48.0, 1e-9);
    // Relative: the same absolute error counts less where the reference is bright.
    Film bright = constant(4, 4, 10.0f), bright_off = constant(4, 4, 10.0f);
    bright_off.layer("color").data[7] = 12.0f;
    EXPECT_LT(relative_mse(bright_off, bright), relative_mse(one, black) / 100.0);
    // Not symmetric: the reference is the second argument.
    EXPECT_NE(relative_mse(one, black), relative_mse(black, one));
}

TEST(ImageMetrics, MeanAndMaxDifference) {
    Film a = constant(3, 2, 0.5f);
    a.set("color", 1, 1, Vec3(0.5f, 0.5f, 2.0f));
    EXPECT_NEAR(mean_value(a), (17 * 0.5 + 2.0) / 18.0, 1e-9);
    Film b = constant(3, 2, 0.5f);
    EXPECT_NEAR(max_abs_difference(a, b), 1.5, 1e-9);
    EXPECT_NEAR(max_abs_difference(b, a), 1.5, 1e-9);
    a.add_layer("depth", 1);
    a.set("depth", 0, 0, 4.0f);
    EXPECT_NEAR(mean_value(a, "depth"), 4.0 / 6.0, 1e-9);
}

TEST(ImageMetrics, NanIsNeverHidden) {
    Film a = constant(2, 2, 1.0f), b = constant(2, 2, 1.0f);
    a.layer("color").data[5] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(std::isnan(max_abs_difference(a, b)));
    EXPECT_TRUE(std::isnan(relative_mse(a, b)));
    EXPECT_TRUE(std::isnan(mean_value(a)));
}

TEST(ImageMetrics, MismatchedImagesAreErrors) {
    Film a = constant(4, 4, 1.0f), b = constant(4, 3, 1.0f);
    EXPECT_THROW(relative_mse(a, b), Error);
    EXPECT_THROW(max_abs_difference(a, b), Error);
    Film c = constant(4, 4, 1.0f);
    c.add_layer("depth", 1);
    Film d = constant(4, 4, 1.0f);
    d.add_layer("depth", 3);
    EXPECT_THROW(relative_mse(c, d, "depth"), Error);
    EXPECT_THROW(relative_mse(a, c, "depth"), Error);
    EXPECT_THROW(mean_value(a, "albedo"), Error);
    EXPECT_THROW(relative_mse(a, a, "color", 0.0), Error);
}

}  // namespace
}  // namespace gilab
