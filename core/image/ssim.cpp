// SSIM (Wang et al. 2004), declared in core/image/image_metrics.hpp.
#include <cmath>
#include "core/image/display_planes.hpp"
#include "core/image/image_metrics.hpp"

namespace gilab {

namespace {

// The paper's 11×11 circular-symmetric Gaussian window, σ = 1.5 px, summing to one.
Kernel2D ssim_window() {
    Kernel2D k;
    k.radius = 5;
    double sum = 0.0;
    for (int dy = -5; dy <= 5; ++dy)
        for (int dx = -5; dx <= 5; ++dx) {
            const double w = std::exp(-(dx * dx + dy * dy) / (2.0 * 1.5 * 1.5));
            k.weights.push_back(float(w));
            sum += w;
        }
    for (float& w : k.weights) w = float(w / sum);
    return k;
}

ImagePlane luma(const Film& film, const std::string& layer, double exposure) {
    const auto rgb = display_planes(film, layer, exposure);
    ImagePlane y(film.width(), film.height());
    for (size_t i = 0; i < y.values.size(); ++i)
        y.values[i] = 0.2126f * srgb_encode(rgb[0].values[i]) + 0.7152f * srgb_encode(rgb[1].values[i]) +
                      0.0722f * srgb_encode(rgb[2].values[i]);
    return y;
}

ImagePlane product(const ImagePlane& a, const ImagePlane& b) {
    ImagePlane p(a.width, a.height);
    for (size_t i = 0; i < p.values.size(); ++i) p.values[i] = a.values[i] * b.values[i];
    return p;
}

}  // namespace

MetricMap ssim_map(const Film& image, const Film& reference, const std::string& layer, double exposure) {
    check_comparable_layers(image, reference, layer, "ssim");
    const ImagePlane x = luma(image, layer, exposure), y = luma(reference, layer, exposure);
    const Kernel2D window = ssim_window();
    const ImagePlane mu_x = convolve(x, window), mu_y = convolve(y, window);
    const ImagePlane xx = convolve(product(x, x), window), yy = convolve(product(y, y), window),
                     xy = convolve(product(x, y), window);
    constexpr double c1 = (0.01 * 1.0) * (0.01 * 1.0), c2 = (0.03 * 1.0) * (0.03 * 1.0);
    MetricMap out{ImagePlane(x.width, x.height), 0.0};
    for (size_t i = 0; i < x.values.size(); ++i) {
        const double mx = mu_x.values[i], my = mu_y.values[i];
        const double vx = xx.values[i] - mx * mx, vy = yy.values[i] - my * my, cxy = xy.values[i] - mx * my;
        out.map.values[i] = float(((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2)));
    }
    out.mean = out.map.mean();
    return out;
}

}  // namespace gilab
