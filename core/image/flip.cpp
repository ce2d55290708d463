// FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"),
// the LDR version, declared in core/image/image_metrics.hpp. Constants and steps follow the
// paper's Sections 4 (colour) and 5 (features).
#include <algorithm>
#include <array>
#include <cmath>
#include "core/image/display_planes.hpp"
#include "core/util/error.hpp"
#include "core/image/image_metrics.hpp"

namespace gilab {

// Linear sRGB (D65) ↔ CIE XYZ with the matrices of the FLIP papers (Andersson et al.
// 2020, 2021): the forward one as exact ratios, the inverse as they publish it, so that
// our FLIP matches theirs rather than a differently rounded sRGB standard.
std::array<double, 3> flip_rgb_to_xyz(const std::array<double, 3>& c) {
    return {(10135552.0 * c[0] + 8788810.0 * c[1] + 4435075.0 * c[2]) / 24577794.0,
            (2613072.0 * c[0] + 8788810.0 * c[1] + 887015.0 * c[2]) / 12288897.0,
            (1425312.0 * c[0] + 8788810.0 * c[1] + 70074185.0 * c[2]) / 73733382.0};
}
std::array<double, 3> flip_xyz_to_rgb(const std::array<double, 3>& c) {
    return {3.241003275 * c[0] - 1.537398934 * c[1] - 0.498615861 * c[2],
            -0.969224334 * c[0] + 1.875930071 * c[1] + 0.041554224 * c[2],
            0.055639423 * c[0] - 0.204011202 * c[1] + 1.057148933 * c[2]};
}

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kQc = 0.7, kQf = 0.5, kPc = 0.4, kPt = 0.95;  // exponents and remapping breakpoints
constexpr double kFeatureWidth = 0.082;                          // w, degrees

using Rgb = std::array<double, 3>;

// The reference white: linear RGB (1, 1, 1).
const Rgb kWhite = flip_rgb_to_xyz({1.0, 1.0, 1.0});

// YCxCz: CIELAB's opponent space without its non-linearity, where filtering is linear.
Rgb xyz_to_ycxcz(const Rgb& c) {
    const double x = c[0] / kWhite[0], y = c[1] / kWhite[1], z = c[2] / kWhite[2];
    return {116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)};
}
Rgb ycxcz_to_xyz(const Rgb& c) {
    const double y = (c[0] + 16.0) / 116.0;
    return {(c[1] / 500.0 + y) * kWhite[0], y * kWhite[1], (y - c[2] / 200.0) * kWhite[2]};
}

Rgb xyz_to_lab(const Rgb& c) {
    auto f = [](double t) {
        constexpr double delta = 6.0 / 29.0;
        return t > delta * delta * delta ? std::cbrt(t) : t / (3.0 * delta * delta) + 4.0 / 29.0;
    };
    const double fx = f(c[0] / kWhite[0]), fy = f(c[1] / kWhite[1]), fz = f(c[2] / kWhite[2]);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

// Hunt effect: chroma scaled by lightness (a*, b* ← 0.01 L* a*, 0.01 L* b*).
Rgb hunt(const Rgb& lab) { return {lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]}; }

double hyab(const Rgb& a, const Rgb& b) {
    return std::abs(a[0] - b[0]) + std::hypot(a[1] - b[1], a[2] - b[2]);
}

// The largest colour difference: HyAB between Hunt-adjusted green and blue, to the power qc.
double max_colour_difference() {
    static const double cmax =
        std::pow(hyab(hunt(xyz_to_lab(flip_rgb_to_xyz({0, 1, 0}))), hunt(xyz_to_lab(flip_rgb_to_xyz({0, 0, 1})))), kQc);
    return cmax;
}

// Contrast sensitivity of one opponent channel as a sum of two Gaussians over visual
// angle (degrees): a1·√(π/b1)·exp(−π²r²/b1) + a2·√(π/b2)·exp(−π²r²/b2), normalised to one.
struct CsfParameters {
    double a1, b1, a2, b2;
};
constexpr CsfParameters kCsf[3] = {
    {1.0, 0.0047, 0.0, 1e-5},    // achromatic (Y)
    {1.0, 0.0053, 0.0, 1e-5},    // red–green (Cx)
    {34.1, 0.04, 13.5, 0.025},   // blue–yellow (Cz)
};

Kernel2D csf_kernel(const CsfParameters& p, double ppd) {
    // One radius for all three channels: three standard deviations of the widest Gaussian.
    const double widest_b = 0.04;
    Kernel2D k;
    k.radius = int(std::ceil(3.0 * std::sqrt(widest_b / (2.0 * kPi * kPi)) * ppd));
    double sum = 0.0;
    std::vector<double> w;
    for (int dy = -k.radius; dy <= k.radius; ++dy)
        for (int dx = -k.radius; dx <= k.radius; ++dx) {
            const double r2 = (dx * dx + dy * dy) / (ppd * ppd);
            const double g = p.a1 * std::sqrt(kPi / p.b1) * std::exp(-kPi * kPi * r2 / p.b1) +
                             p.a2 * std::sqrt(kPi / p.b2) * std::exp(-kPi * kPi * r2 / p.b2);
            w.push_back(g);
            sum += g;
        }
    for (double g : w) k.weights.push_back(float(g / sum));
    return k;
}

// Edge (first derivative of a Gaussian) or point (second derivative) detector along x,
// σ = w·ppd/2; positive weights sum to 1 and negative ones to −1.
Kernel2D feature_kernel(bool second_derivative, double ppd, bool along_y) {
    const double sigma = 0.5 * kFeatureWidth * ppd;
    Kernel2D k;
    k.radius = int(std::ceil(3.0 * sigma));
    std::vector<double> w;
    double positive = 0.0, negative = 0.0;
    for (int dy = -k.radius; dy <= k.radius; ++dy)
        for (int dx = -k.radius; dx <= k.radius; ++dx) {
            const double u = along_y ? dy : dx;
            const double g = std::exp(-(dx * dx + dy * dy) / (2.0 * sigma * sigma));
            const double v = second_derivative ? (u * u / (sigma * sigma) - 1.0) * g : -u * g;
            w.push_back(v);
            (v > 0 ? positive : negative) += v;
        }
    for (double v : w) k.weights.push_back(float(v > 0 ? v / positive : (v < 0 ? v / -negative : 0.0)));
    return k;
}

std::array<ImagePlane, 3> to_ycxcz(const std::array<ImagePlane, 3>& rgb) {
    std::array<ImagePlane, 3> out;
    for (auto& p : out) p = ImagePlane(rgb[0].width, rgb[0].height);
    for (size_t i = 0; i < rgb[0].values.size(); ++i) {
        const Rgb c = xyz_to_ycxcz(flip_rgb_to_xyz({rgb[0].values[i], rgb[1].values[i], rgb[2].values[i]}));
        for (int k = 0; k < 3; ++k) out[size_t(k)].values[i] = float(c[size_t(k)]);
    }
    return out;
}

// Filtered by the CSF, back to linear RGB clamped to [0, 1], then Hunt-adjusted L*a*b*.
std::vector<Rgb> perceived_colours(const std::array<ImagePlane, 3>& ycxcz, double ppd) {
    std::array<ImagePlane, 3> filtered;
    for (int k = 0; k < 3; ++k) filtered[size_t(k)] = convolve(ycxcz[size_t(k)], csf_kernel(kCsf[k], ppd));
    std::vector<Rgb> lab(ycxcz[0].values.size());
    for (size_t i = 0; i < lab.size(); ++i) {
        Rgb rgb = flip_xyz_to_rgb(ycxcz_to_xyz({filtered[0].values[i], filtered[1].values[i], filtered[2].values[i]}));
        for (double& c : rgb) c = std::clamp(c, 0.0, 1.0);
        lab[i] = hunt(xyz_to_lab(flip_rgb_to_xyz(rgb)));
    }
    return lab;
}

// Edge and point strength of the achromatic channel normalised to [0, 1].
struct Features {
    ImagePlane edges, points;
};

Features features(const ImagePlane& y_channel, double ppd) {
    ImagePlane y(y_channel.width, y_channel.height);
    for (size_t i = 0; i < y.values.size(); ++i) y.values[i] = (y_channel.values[i] + 16.0f) / 116.0f;
    const ImagePlane ex = convolve(y, feature_kernel(false, ppd, false)), ey = convolve(y, feature_kernel(false, ppd, true));
    const ImagePlane px = convolve(y, feature_kernel(true, ppd, false)), py = convolve(y, feature_kernel(true, ppd, true));
    Features f{ImagePlane(y.width, y.height), ImagePlane(y.width, y.height)};
    for (size_t i = 0; i < y.values.size(); ++i) {
        f.edges.values[i] = std::hypot(ex.values[i], ey.values[i]);
        f.points.values[i] = std::hypot(px.values[i], py.values[i]);
    }
    return f;
}

}  // namespace

ImagePlane flip_of_display(const std::array<ImagePlane, 3>& image, const std::array<ImagePlane, 3>& reference,
                           double ppd) {
    const auto test = to_ycxcz(image);
    const auto ref = to_ycxcz(reference);
    const std::vector<Rgb> lab_test = perceived_colours(test, ppd), lab_ref = perceived_colours(ref, ppd);
    const Features f_test = features(test[0], ppd), f_ref = features(ref[0], ppd);

    const double cmax = max_colour_difference();
    ImagePlane out(image[0].width, image[0].height);
    for (size_t i = 0; i < out.values.size(); ++i) {
        const double d = std::pow(hyab(lab_test[i], lab_ref[i]), kQc);
        const double colour = d < kPc * cmax ? kPt / (kPc * cmax) * d
                                             : kPt + (d - kPc * cmax) / (cmax - kPc * cmax) * (1.0 - kPt);
        const double feature = std::pow(
            std::max(std::abs(f_test.edges.values[i] - f_ref.edges.values[i]),
                     std::abs(f_test.points.values[i] - f_ref.points.values[i])) / std::sqrt(2.0),
            kQf);
        out.values[i] = float(std::pow(colour, 1.0 - feature));
    }
    return out;
}

void check_pixels_per_degree(double ppd) {
    if (!(ppd > 0.0) || !std::isfinite(ppd)) throw Error("flip", "pixels per degree must be positive and finite");
}

MetricMap flip_map(const Film& image, const Film& reference, const std::string& layer, double ppd, double exposure) {
    check_comparable_layers(image, reference, layer, "flip");
    check_pixels_per_degree(ppd);
    MetricMap out{flip_of_display(display_planes(image, layer, exposure), display_planes(reference, layer, exposure), ppd), 0.0};
    out.mean = out.map.mean();
    return out;
}

}  // namespace gilab
