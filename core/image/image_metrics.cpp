#include "core/image/image_metrics.hpp"

#include <cmath>
#include <limits>
#include "core/util/error.hpp"

namespace gilab {

// Both layers must exist with the same size and channel count.
void check_comparable_layers(const Film& a, const Film& b, const std::string& layer, const char* what) {
    if (a.width() != b.width() || a.height() != b.height()) {
        throw Error(what, "images differ in size: " + std::to_string(a.width()) + "x" +
                              std::to_string(a.height()) + " vs " + std::to_string(b.width()) +
                              "x" + std::to_string(b.height()));
    }
    if (!a.has_layer(layer) || !b.has_layer(layer)) {
        throw Error(what, "layer '" + layer + "' is missing from " +
                              (a.has_layer(layer) ? "the second image" : "the first image"));
    }
    int ca = a.layer(layer).channels, cb = b.layer(layer).channels;
    if (ca != cb) {
        throw Error(what, "layer '" + layer + "' has " + std::to_string(ca) + " vs " +
                              std::to_string(cb) + " channels");
    }
}

double relative_mse(const Film& image, const Film& reference, const std::string& layer,
                    double epsilon) {
    check_comparable_layers(image, reference, layer, "relative_mse");
    if (!(epsilon > 0.0)) throw Error("relative_mse", "epsilon must be positive");
    const auto& a = image.layer(layer).data;
    const auto& r = reference.layer(layer).data;
    if (a.empty()) return 0.0;
    double sum = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
        double d = double(a[i]) - double(r[i]);
        sum += d * d / (double(r[i]) * double(r[i]) + epsilon);
    }
    return sum / double(a.size());
}

double relative_mse_masked(const Film& image, const Film& reference, const std::vector<uint8_t>& mask,
                           const std::string& layer, double epsilon) {
    check_comparable_layers(image, reference, layer, "relative_mse_masked");
    if (!(epsilon > 0.0)) throw Error("relative_mse_masked", "epsilon must be positive");
    if (mask.size() != image.pixel_count())
        throw Error("relative_mse_masked", "mask has " + std::to_string(mask.size()) + " entries for " +
                                               std::to_string(image.pixel_count()) + " pixels");
    const Layer& a = image.layer(layer);
    const Layer& r = reference.layer(layer);
    const size_t channels = size_t(a.channels);
    double sum = 0.0;
    size_t count = 0;
    for (size_t p = 0; p < mask.size(); ++p) {
        if (!mask[p]) continue;
        for (size_t c = 0; c < channels; ++c) {
            double d = double(a.data[p * channels + c]) - double(r.data[p * channels + c]);
            double ref = double(r.data[p * channels + c]);
            sum += d * d / (ref * ref + epsilon);
        }
        count += channels;
    }
    return count ? sum / double(count) : 0.0;
}

double mean_value(const Film& image, const std::string& layer) {
    const auto& data = image.layer(layer).data;
    if (data.empty()) return 0.0;
    double sum = 0.0;
    for (float v : data) sum += v;
    return sum / double(data.size());
}

double max_abs_difference(const Film& a, const Film& b, const std::string& layer) {
    check_comparable_layers(a, b, layer, "max_abs_difference");
    const auto& x = a.layer(layer).data;
    const auto& y = b.layer(layer).data;
    double worst = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
        double d = std::abs(double(x[i]) - double(y[i]));
        // A NaN on either side is a difference nothing can excuse.
        if (std::isnan(d)) return std::numeric_limits<double>::quiet_NaN();
        worst = std::max(worst, d);
    }
    return worst;
}

}  // namespace gilab
