// HDR-FLIP (Andersson et al. 2021), declared in core/image/image_metrics.hpp: LDR-FLIP over a
// range of exposures chosen from the reference, the per-pixel maximum.
#include <algorithm>
#include <cmath>
#include "core/image/display_planes.hpp"
#include "core/util/error.hpp"
#include "core/image/image_metrics.hpp"

namespace gilab {

namespace {

// ACES (Narkowicz 2015) as a rational function (k0 x² + k1 x + k2) / (k3 x² + k4 x + k5),
// the input pre-scaled by 0.6 as the paper does.
constexpr double kK0 = 0.6 * 0.6 * 2.51, kK1 = 0.6 * 0.03, kK2 = 0.0;
constexpr double kK3 = 0.6 * 0.6 * 2.43, kK4 = 0.6 * 0.59, kK5 = 0.14;
constexpr double kExposureTarget = 0.85;  // t_max = t_min in the paper

double luminance(const float* c, int channels) {
    if (channels < 3) return c[0];
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

// The median as the paper's code takes it: the mean of the two middle values of an even count.
double median(std::vector<double> v) {
    const size_t n = v.size(), mid = n / 2;
    std::nth_element(v.begin(), v.begin() + long(mid), v.end());
    if (n % 2 == 1) return v[mid];
    const double upper = v[mid];
    const double lower = *std::max_element(v.begin(), v.begin() + long(mid));
    return 0.5 * (lower + upper);
}

// The image at one exposure, tone-mapped as linear RGB planes in [0, 1] (NaN magenta, a
// 1-channel layer grey, as display_planes shows them).
std::array<ImagePlane, 3> tone_mapped(const Film& film, const std::string& layer, double exposure) {
    const double scale = std::exp2(exposure);
    return display_planes(film, layer,
                          [scale](float v) { return float(hdr_flip_tone_map(scale * std::max(double(v), 0.0))); });
}

}  // namespace

double hdr_flip_tone_map(double x) {
    if (std::isinf(x)) return 1.0;
    const double y = (kK0 * x * x + kK1 * x + kK2) / (kK3 * x * x + kK4 * x + kK5);
    return std::clamp(y, 0.0, 1.0);
}

double hdr_flip_tone_map_inverse(double t) {
    // Solve (k0 − t k3) x² + (k1 − t k4) x + (k2 − t k5) = 0 for its positive root.
    const double c0 = (kK1 - kK4 * t) / (kK0 - kK3 * t), c1 = (kK2 - kK5 * t) / (kK0 - kK3 * t);
    return -0.5 * c0 + std::sqrt(0.25 * c0 * c0 - c1);
}

HdrFlip hdr_flip_map(const Film& image, const Film& reference, const std::string& layer_name, double ppd) {
    check_comparable_layers(image, reference, layer_name, "hdr-flip");
    check_pixels_per_degree(ppd);
    const Layer& ref_layer = reference.layer(layer_name);
    const int w = image.width(), h = image.height();

    std::vector<double> y;
    y.reserve(reference.pixel_count());
    for (size_t i = 0; i < reference.pixel_count(); ++i) {
        const double v = luminance(ref_layer.data.data() + i * size_t(ref_layer.channels), ref_layer.channels);
        y.push_back(std::isfinite(v) ? std::max(v, 0.0) : 0.0);  // a NaN or negative reference pixel adds no exposure
    }
    HdrFlip out;
    const double y_hi = y.empty() ? 0.0 : *std::max_element(y.begin(), y.end());
    const double y_lo = y.empty() ? 0.0 : median(y);
    const double x_target = hdr_flip_tone_map_inverse(kExposureTarget);
    // An all-black reference has no range: both ends at exposure 0, as the paper's code does.
    if (y_hi > 0.0) {
        out.start_exposure = std::log2(x_target / y_hi);
        // A median of zero (mostly black) would put the stop at infinity; the darkest
        // non-zero level is then the stop's luminance.
        double lo = y_lo;
        if (!(lo > 0.0)) {
            lo = y_hi;
            for (double v : y)
                if (v > 0.0) lo = std::min(lo, v);
        }
        out.stop_exposure = std::log2(x_target / lo);
    }
    out.exposures = std::max(2, int(std::ceil(out.stop_exposure - out.start_exposure)));
    const double step = (out.stop_exposure - out.start_exposure) / double(out.exposures - 1);

    out.flip.map = ImagePlane(w, h, 0.0f);
    for (int e = 0; e < out.exposures; ++e) {
        const double exposure = out.start_exposure + e * step;
        const ImagePlane ldr = flip_of_display(tone_mapped(image, layer_name, exposure),
                                               tone_mapped(reference, layer_name, exposure), ppd);
        for (size_t i = 0; i < ldr.values.size(); ++i)
            out.flip.map.values[i] = std::max(out.flip.map.values[i], ldr.values[i]);
    }
    out.flip.mean = out.flip.map.mean();
    return out;
}

}  // namespace gilab
