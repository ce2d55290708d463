// SSIM and FLIP (core/image/image_metrics.hpp): their defining properties, and their values on
// a fixed pair of small images pinned against a second, deliberately plain implementation
// written here from the papers' equations (Wang et al. 2004; Andersson et al. 2020).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include "core/util/error.hpp"
#include "core/image/image_metrics.hpp"

namespace gilab {
namespace {

constexpr double kPi = 3.14159265358979323846;

Film constant(int w, int h, Vec3 value) {
    Film film(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) film.set("color", x, y, value);
    return film;
}

// A fixed, deterministic test image: smooth gradients, an edge and a bright dot.
Film pattern(int w, int h, int variant) {
    Film film(w, h);
    uint32_t state = 12345u + uint32_t(variant) * 977u;
    auto noise = [&] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / float(1u << 24);
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Vec3 c(0.2f + 0.6f * float(x) / float(w), 0.5f * float(y) / float(h), x > w / 2 ? 0.8f : 0.1f);
            c += Vec3(0.15f * noise(), 0.15f * noise(), 0.15f * noise());
            if (variant == 1 && x == w / 3 && y == h / 2) c = Vec3(1.5f, 1.5f, 1.5f);
            film.set("color", x, y, c);
        }
    return film;
}

// ------------------------------------------------------------------ a plain SSIM

double srgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055; }

std::vector<double> plain_ssim(const Film& a, const Film& b) {
    const int w = a.width(), h = a.height();
    auto luma = [&](const Film& f, int x, int y) {
        x = std::clamp(x, 0, w - 1), y = std::clamp(y, 0, h - 1);
        const Vec3 c = f.get("color", x, y);
        return 0.2126 * srgb(std::clamp(c.x, 0.0f, 1.0f)) + 0.7152 * srgb(std::clamp(c.y, 0.0f, 1.0f)) +
               0.0722 * srgb(std::clamp(c.z, 0.0f, 1.0f));
    };
    std::vector<double> out;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double wsum = 0, ma = 0, mb = 0, aa = 0, bb = 0, ab = 0;
            for (int j = -5; j <= 5; ++j)
                for (int i = -5; i <= 5; ++i) {
                    const double g = std::exp(-(i * i + j * j) / 4.5);
                    const double va = luma(a, x + i, y + j), vb = luma(b, x + i, y + j);
                    wsum += g, ma += g * va, mb += g * vb, aa += g * va * va, bb += g * vb * vb, ab += g * va * vb;
                }
            ma /= wsum, mb /= wsum, aa /= wsum, bb /= wsum, ab /= wsum;
            const double c1 = 1e-4, c2 = 9e-4;
            out.push_back((2 * ma * mb + c1) * (2 * (ab - ma * mb) + c2) /
                          ((ma * ma + mb * mb + c1) * (aa - ma * ma + bb - mb * mb + c2)));
        }
    return out;
}

// ------------------------------------------------------------------ a plain FLIP

using Triple = std::array<double, 3>;

// The FLIP papers' matrices: the forward one as exact ratios, the inverse as published.
Triple to_xyz(const Triple& c) {
    return {(10135552.0 * c[0] + 8788810.0 * c[1] + 4435075.0 * c[2]) / 24577794.0,
            (2613072.0 * c[0] + 8788810.0 * c[1] + 887015.0 * c[2]) / 12288897.0,
            (1425312.0 * c[0] + 8788810.0 * c[1] + 70074185.0 * c[2]) / 73733382.0};
}
Triple from_xyz(const Triple& v) {
    return {3.241003275 * v[0] - 1.537398934 * v[1] - 0.498615861 * v[2],
            -0.969224334 * v[0] + 1.875930071 * v[1] + 0.041554224 * v[2],
            0.055639423 * v[0] - 0.204011202 * v[1] + 1.057148933 * v[2]};
}
const Triple kW = to_xyz({1, 1, 1});

Triple lab_hunt(const Triple& rgb) {
    const Triple xyz = to_xyz(rgb);
    auto f = [](double t) { return t > std::pow(6.0 / 29, 3) ? std::cbrt(t) : t / (3 * std::pow(6.0 / 29, 2)) + 4.0 / 29; };
    const double L = 116 * f(xyz[1] / kW[1]) - 16;
    const double A = 500 * (f(xyz[0] / kW[0]) - f(xyz[1] / kW[1])), B = 200 * (f(xyz[1] / kW[1]) - f(xyz[2] / kW[2]));
    return {L, L * A / 100, L * B / 100};
}
double hyab_distance(const Triple& p, const Triple& q) {
    return std::abs(p[0] - q[0]) + std::sqrt((p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

std::vector<double> plain_flip(const Film& test, const Film& ref, double ppd) {
    const int w = test.width(), h = test.height();
    auto ycxcz = [&](const Film& f, int x, int y) {
        x = std::clamp(x, 0, w - 1), y = std::clamp(y, 0, h - 1);
        const Vec3 c = f.get("color", x, y);
        const Triple xyz = to_xyz({std::clamp(c.x, 0.0f, 1.0f), std::clamp(c.y, 0.0f, 1.0f), std::clamp(c.z, 0.0f, 1.0f)});
        return Triple{116 * xyz[1] / kW[1] - 16, 500 * (xyz[0] / kW[0] - xyz[1] / kW[1]), 200 * (xyz[1] / kW[1] - xyz[2] / kW[2])};
    };
    const double params[3][4] = {{1, 0.0047, 0, 1e-5}, {1, 0.0053, 0, 1e-5}, {34.1, 0.04, 13.5, 0.025}};
    const int rc = int(std::ceil(3 * std::sqrt(0.04 / (2 * kPi * kPi)) * ppd));
    auto csf = [&](int k, int i, int j) {
        const double r2 = (i * i + j * j) / (ppd * ppd);
        const double* p = params[k];
        return p[0] * std::sqrt(kPi / p[1]) * std::exp(-kPi * kPi * r2 / p[1]) + p[2] * std::sqrt(kPi / p[3]) * std::exp(-kPi * kPi * r2 / p[3]);
    };
    const double sigma = 0.5 * 0.082 * ppd;
    const int rf = int(std::ceil(3 * sigma));
    // Derivative-of-Gaussian weights, positive part normalised to 1 and negative to −1.
    auto raw = [&](int order, int u, int i, int j) {
        const double g = std::exp(-(i * i + j * j) / (2 * sigma * sigma));
        return order == 1 ? -u * g : (u * u / (sigma * sigma) - 1) * g;
    };
    double pos[3] = {0, 0, 0}, neg[3] = {0, 0, 0};
    for (int order = 1; order <= 2; ++order)
        for (int j = -rf; j <= rf; ++j)
            for (int i = -rf; i <= rf; ++i) {
                const double v = raw(order, i, i, j);
                (v > 0 ? pos[order] : neg[order]) += v;
            }
    auto feature_weight = [&](int order, int u, int i, int j) {
        const double v = raw(order, u, i, j);
        return v > 0 ? v / pos[order] : v < 0 ? v / -neg[order] : 0.0;
    };
    auto perceived = [&](const Film& f, int x, int y) {
        Triple filtered{0, 0, 0};
        for (int k = 0; k < 3; ++k) {
            double sum = 0, norm = 0;
            for (int j = -rc; j <= rc; ++j)
                for (int i = -rc; i <= rc; ++i) {
                    sum += csf(k, i, j) * ycxcz(f, x + i, y + j)[size_t(k)];
                    norm += csf(k, i, j);
                }
            filtered[size_t(k)] = sum / norm;
        }
        const double yy = (filtered[0] + 16) / 116;
        Triple rgb = from_xyz({(filtered[1] / 500 + yy) * kW[0], yy * kW[1], (yy - filtered[2] / 200) * kW[2]});
        for (double& c : rgb) c = std::clamp(c, 0.0, 1.0);
        return lab_hunt(rgb);
    };
    auto feature = [&](const Film& f, int x, int y, int order) {
        double gx = 0, gy = 0;
        for (int j = -rf; j <= rf; ++j)
            for (int i = -rf; i <= rf; ++i) {
                const double v = (ycxcz(f, x + i, y + j)[0] + 16) / 116;
                gx += feature_weight(order, i, i, j) * v;
                gy += feature_weight(order, j, i, j) * v;
            }
        return std::sqrt(gx * gx + gy * gy);
    };
    const double cmax = std::pow(hyab_distance(lab_hunt({0, 1, 0}), lab_hunt({0, 0, 1})), 0.7);
    std::vector<double> out;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double d = std::pow(hyab_distance(perceived(test, x, y), perceived(ref, x, y)), 0.7);
            const double colour = d < 0.4 * cmax ? 0.95 / (0.4 * cmax) * d : 0.95 + (d - 0.4 * cmax) / (cmax - 0.4 * cmax) * 0.05;
            const double fe = std::abs(feature(test, x, y, 1) - feature(ref, x, y, 1));
            const double fp = std::abs(feature(test, x, y, 2) - feature(ref, x, y, 2));
            out.push_back(std::pow(colour, 1 - std::pow(std::max(fe, fp) / std::sqrt(2.0), 0.5)));
        }
    return out;
}

// ------------------------------------------------------------------ tests

TEST(PerceptualMetrics, IdenticalImagesGiveSsimOneAndFlipZero) {
    const Film a = pattern(24, 16, 1);
    const MetricMap s = ssim_map(a, a), f = flip_map(a, a);
    for (float v : s.map.values) EXPECT_EQ(v, 1.0f);
    for (float v : f.map.values) EXPECT_EQ(v, 0.0f);
    EXPECT_EQ(s.mean, 1.0);
    EXPECT_EQ(f.mean, 0.0);
}

TEST(PerceptualMetrics, FlipIsSymmetricInItsTwoImages) {
    const Film a = pattern(24, 16, 0), b = pattern(24, 16, 1);
    const MetricMap ab = flip_map(a, b), ba = flip_map(b, a);
    ASSERT_GT(ab.mean, 0.0);
    for (size_t i = 0; i < ab.map.values.size(); ++i) EXPECT_NEAR(ab.map.values[i], ba.map.values[i], 1e-6) << i;
}

// A uniform grey raised by a small step: no edges or points differ, so FLIP is the
// remapped colour difference of the two greys, |ΔL*|^0.7 · pt / (pc · cmax); SSIM is
// (2ab + C1) / (a² + b² + C1) of the two sRGB-encoded greys.
TEST(PerceptualMetrics, AUniformSmallShiftGivesTheKnownSmallError) {
    const float lo = 0.18f, hi = 0.20f;
    const Film a = constant(20, 20, Vec3(lo)), b = constant(20, 20, Vec3(hi));
    auto lightness = [](double y) { return 116 * std::cbrt(y) - 16; };  // Y/Yn = grey level for grey
    const double cmax = std::pow(hyab_distance(lab_hunt({0, 1, 0}), lab_hunt({0, 0, 1})), 0.7);
    const double expected_flip = 0.95 / (0.4 * cmax) * std::pow(lightness(hi) - lightness(lo), 0.7);
    const MetricMap f = flip_map(a, b);
    for (float v : f.map.values) EXPECT_NEAR(v, expected_flip, 2e-4);
    EXPECT_GT(expected_flip, 0.05);
    EXPECT_LT(expected_flip, 0.2);
    const double sa = srgb(lo), sb = srgb(hi);
    const double expected_ssim = (2 * sa * sb + 1e-4) / (sa * sa + sb * sb + 1e-4);
    const MetricMap s = ssim_map(a, b);
    for (float v : s.map.values) EXPECT_NEAR(v, expected_ssim, 1e-5);
    EXPECT_LT(expected_ssim, 1.0);
}

TEST(PerceptualMetrics, SsimPinnedAgainstAPlainImplementation) {
    const Film a = pattern(21, 13, 0), b = pattern(21, 13, 1);
    const std::vector<double> expected = plain_ssim(a, b);
    const MetricMap s = ssim_map(a, b);
    ASSERT_EQ(s.map.values.size(), expected.size());
    double mean = 0;
    for (size_t i = 0; i < expected.size(); ++i) {
        EXPECT_NEAR(s.map.values[i], expected[i], 1e-4) << i;
        mean += expected[i] / double(expected.size());
    }
    EXPECT_NEAR(s.mean, mean, 1e-5);
    EXPECT_LT(s.mean, 0.99);
}

TEST(PerceptualMetrics, FlipPinnedAgainstAPlainImplementation) {
    const Film a = pattern(19, 12, 0), b = pattern(19, 12, 1);
    for (double ppd : {67.0, 20.0}) {
        SCOPED_TRACE(ppd);
        const std::vector<double> expected = plain_flip(a, b, ppd);
        const MetricMap f = flip_map(a, b, "color", ppd);
        ASSERT_EQ(f.map.values.size(), expected.size());
        for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(f.map.values[i], expected[i], 2e-4) << i;
        EXPECT_GT(f.mean, 0.01);
    }
}

TEST(PerceptualMetrics, ExposureAndClampingFollowThePngPreview) {
    // Values above 1 are clamped like the preview: two images that differ only above 1
    // are identical on screen.
    const Film a = constant(12, 12, Vec3(1.5f)), b = constant(12, 12, Vec3(3.0f));
    EXPECT_EQ(flip_map(a, b).mean, 0.0);
    EXPECT_EQ(ssim_map(a, b).mean, 1.0);
    // One stop down, they differ.
    EXPECT_GT(flip_map(a, b, "color", 67.0, -2.0).mean, 0.1);
}

// ------------------------------------------------------------------ HDR-FLIP

// The library converts with the FLIP papers' matrices (to_xyz and from_xyz above), and
// the published matrices are each other's inverse to the digits they give.
TEST(PerceptualMetrics, FlipColourMatricesAreTheFlipPapers) {
    for (int j = 0; j < 3; ++j) {  // column j: the image of the j-th unit vector
        Triple unit{0, 0, 0};
        unit[size_t(j)] = 1;
        const Triple forward = flip_rgb_to_xyz(unit), paper_forward = to_xyz(unit);
        const Triple inverse = flip_xyz_to_rgb(unit), paper_inverse = from_xyz(unit);
        for (int i = 0; i < 3; ++i) {
            EXPECT_DOUBLE_EQ(forward[size_t(i)], paper_forward[size_t(i)]) << "rgb → xyz row " << i << " column " << j;
            EXPECT_DOUBLE_EQ(inverse[size_t(i)], paper_inverse[size_t(i)]) << "xyz → rgb row " << i << " column " << j;
        }
    }
    const Triple white = flip_rgb_to_xyz({1, 1, 1});
    EXPECT_NEAR(white[0], 0.950428545, 1e-9);  // the D65 white the FLIP code states
    EXPECT_NEAR(white[1], 1.0, 1e-12);
    EXPECT_NEAR(white[2], 1.088900371, 1e-9);
    for (const Triple& c : {Triple{1, 0, 0}, Triple{0, 1, 0}, Triple{0.2, 0.5, 0.9}}) {
        const Triple back = flip_xyz_to_rgb(flip_rgb_to_xyz(c));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[size_t(k)], c[size_t(k)], 1e-7);
    }
}

// Two uniform colours: no filter changes them, so FLIP is the remapped HyAB distance of
// their Hunt-adjusted L*a*b* through the papers' matrices: 0.892991 here, where the sRGB
// standard's rounded matrices give 0.893016 (computed in double precision); the library's
// float planes land within 7e-6 of the former.
TEST(PerceptualMetrics, FlipOfUniformColoursFollowsTheFlipPapersMatrices) {
    const Triple a{0.0, 0.0, 1.0}, b{0.0, 0.3, 1.0};
    auto perceived = [](const Triple& c) {
        Triple rgb = from_xyz(to_xyz(c));
        for (double& v : rgb) v = std::clamp(v, 0.0, 1.0);
        return lab_hunt(rgb);
    };
    const double cmax = std::pow(hyab_distance(lab_hunt({0, 1, 0}), lab_hunt({0, 0, 1})), 0.7);
    const double d = std::pow(hyab_distance(perceived(a), perceived(b)), 0.7);
    const double expected = d < 0.4 * cmax ? 0.95 / (0.4 * cmax) * d : 0.95 + (d - 0.4 * cmax) / (0.6 * cmax) * 0.05;
    const MetricMap f = flip_map(constant(12, 12, Vec3(float(a[0]), float(a[1]), float(a[2]))),
                                 constant(12, 12, Vec3(float(b[0]), float(b[1]), float(b[2]))));
    EXPECT_NEAR(f.map.at(6, 6), expected, 1e-5);
    EXPECT_NEAR(expected, 0.892991, 1e-6);
}

// ACES as HDR-FLIP uses it, from the paper's equation: t(x) = (k0 x² + k1 x) / (k3 x² +
// k4 x + k5) with k0 = 0.6²·2.51, k1 = 0.6·0.03, k3 = 0.6²·2.43, k4 = 0.6·0.59, k5 = 0.14.
double aces(double x) {
    const double k0 = 0.36 * 2.51, k1 = 0.018, k3 = 0.36 * 2.43, k4 = 0.354, k5 = 0.14;
    return std::clamp((k0 * x * x + k1 * x) / (k3 * x * x + k4 * x + k5), 0.0, 1.0);
}

TEST(PerceptualMetrics, HdrFlipToneCurveReachesPoint85AtTheExposureTarget) {
    // (0.9036 − 0.85·0.8748) x² + (0.018 − 0.85·0.354) x − 0.85·0.14 = 0:
    // 0.16002 x² − 0.2829 x − 0.119 = 0, whose positive root is
    // (0.2829 + √0.15620193) / 0.32004 = 2.11887 (by hand).
    EXPECT_NEAR(hdr_flip_tone_map_inverse(0.85), 2.11887, 2e-5);
    EXPECT_NEAR(hdr_flip_tone_map(2.11887), 0.85, 2e-6);
    for (double x : {0.0, 0.01, 0.3, 1.0, 7.0, 1e6}) EXPECT_NEAR(hdr_flip_tone_map(x), aces(x), 1e-12) << x;
    EXPECT_EQ(hdr_flip_tone_map(INFINITY), 1.0);
}

// Two wide uniform bands of the reference (grey 4 on the left, grey 0.25 on the right)
// and a test image 25 % brighter everywhere. Far from the band edge no filter sees the
// edge, so each pixel's LDR-FLIP at an exposure is the remapped colour difference of two
// uniform greys, and HDR-FLIP is its maximum over the exposures. The exposure range
// follows from the paper: start = log2(2.11887 / 4), stop = log2(2.11887 / median Y),
// the median of two equal halves being the mean of 4 and 0.25.
TEST(PerceptualMetrics, HdrFlipPinnedAtTheEndsOfItsExposureRange) {
    const int w = 96, h = 8;
    const double bright = 4.0, dark = 0.25, gain = 1.25;
    Film ref(w, h), test(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float v = float(x < w / 2 ? bright : dark);
            ref.set("color", x, y, Vec3(v));
            test.set("color", x, y, Vec3(float(v * gain)));
        }
    const HdrFlip f = hdr_flip_map(test, ref, "color", 67.0);
    const double start = std::log2(2.11887 / bright), stop = std::log2(2.11887 / (0.5 * (bright + dark)));
    EXPECT_NEAR(f.start_exposure, start, 1e-4);  // −0.9167 stops
    EXPECT_NEAR(f.stop_exposure, stop, 1e-4);    // −0.0042 stops
    EXPECT_EQ(f.exposures, 2);                   // max(2, ⌈0.91⌉)

    auto lightness = [](double grey) { return 116 * std::cbrt(grey) - 16; };  // Y/Yn = grey
    const double cmax = std::pow(hyab_distance(lab_hunt({0, 1, 0}), lab_hunt({0, 0, 1})), 0.7);
    auto uniform_flip = [&](double a, double b) {
        const double d = std::pow(std::abs(lightness(aces(a)) - lightness(aces(b))), 0.7);
        return d < 0.4 * cmax ? 0.95 / (0.4 * cmax) * d : 0.95 + (d - 0.4 * cmax) / (cmax - 0.4 * cmax) * 0.05;
    };
    for (double grey : {bright, dark}) {
        double expected = 0;
        for (double e : {start, stop})
            expected = std::max(expected, uniform_flip(grey * std::exp2(e), grey * gain * std::exp2(e)));
        const int x = grey == bright ? 8 : w - 9;  // 8 px from the border, > 20 px from the band edge
        SCOPED_TRACE(grey);
        EXPECT_NEAR(f.flip.map.at(x, h / 2), expected, 2e-4);
        EXPECT_GT(expected, 0.005);
    }
    // The bright band is clamped to white on a display, so LDR-FLIP sees no error there:
    // the case HDR-FLIP exists for.
    EXPECT_EQ(flip_map(test, ref).map.at(8, h / 2), 0.0f);
    EXPECT_GT(f.flip.map.at(8, h / 2), 0.01f);
}

TEST(PerceptualMetrics, HdrFlipOfIdenticalImagesIsZeroAndOfABlackReferenceUsesExposureZero) {
    const Film a = pattern(24, 16, 1);
    const HdrFlip same = hdr_flip_map(a, a);
    EXPECT_EQ(same.flip.mean, 0.0);
    const Film black = constant(8, 8, Vec3(0.0f)), grey = constant(8, 8, Vec3(0.5f));
    const HdrFlip f = hdr_flip_map(grey, black);
    EXPECT_EQ(f.start_exposure, 0.0);
    EXPECT_EQ(f.stop_exposure, 0.0);
    EXPECT_GT(f.flip.mean, 0.1);
}

TEST(PerceptualMetrics, MismatchedImagesAreRefused) {
    EXPECT_THROW(ssim_map(constant(4, 4, Vec3(0.5f)), constant(5, 4, Vec3(0.5f))), Error);
    EXPECT_THROW(flip_map(constant(4, 4, Vec3(0.5f)), constant(4, 4, Vec3(0.5f)), "albedo"), Error);
    EXPECT_THROW(flip_map(constant(4, 4, Vec3(0.5f)), constant(4, 4, Vec3(0.5f)), "color", 0.0), Error);
    EXPECT_THROW(hdr_flip_map(constant(4, 4, Vec3(0.5f)), constant(5, 4, Vec3(0.5f))), Error);
    EXPECT_THROW(hdr_flip_map(constant(4, 4, Vec3(0.5f)), constant(4, 4, Vec3(0.5f)), "color", NAN), Error);
}

}  // namespace
}  // namespace gilab
