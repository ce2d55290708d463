// Image metrics of core/image/image_metrics.hpp on NumPy images: relMSE, SSIM, FLIP.
#include "core/image/image_metrics.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

// Both images as films holding the layer "image" (1 or 3 channels); the metrics check
// that the sizes and channel counts agree.
struct ImagePair {
    Film image, reference;
};

ImagePair pair_from(const py::object& image, const py::object& reference) {
    return {film_from_image(image, "image", "image"), film_from_image(reference, "reference", "image")};
}

py::object metric_result(MetricMap&& metric, bool return_map) {
    if (!return_map) return py::float_(metric.mean);
    const py::ssize_t h = metric.map.height, w = metric.map.width;
    return py::make_tuple(metric.mean, to_numpy(std::move(metric.map.values), {h, w}));
}

constexpr const char* kImageShapes =
    "Images are float32/float64 NumPy arrays of shape (H, W), (H, W, 1) or (H, W, 3), both the same; "
    "wrong shapes or dtypes raise gilab.Error.";

}  // namespace

void register_metric_bindings(py::module_& m) {
    m.def(
        "relative_mse",
        [](const py::object& image, const py::object& reference, double epsilon) {
            ImagePair p = pair_from(image, reference);
            py::gil_scoped_release release;
            return relative_mse(p.image, p.reference, "image", epsilon);
        },
        "image"_a, "reference"_a, "epsilon"_a = 1e-2,
        (std::string("Relative MSE (Rousselle et al.): mean over pixels and channels of "
                     "(image − reference)² / (reference² + epsilon). ") +
         kImageShapes)
            .c_str());
    m.def(
        "ssim",
        [](const py::object& image, const py::object& reference, double exposure, bool return_map) {
            ImagePair p = pair_from(image, reference);
            MetricMap metric;
            {
                py::gil_scoped_release release;
                metric = ssim_map(p.image, p.reference, "image", exposure);
            }
            return metric_result(std::move(metric), return_map);
        },
        "image"_a, "reference"_a, "exposure"_a = 0.0, "return_map"_a = false,
        (std::string("SSIM of the displayed images (linear × 2^exposure, clamped to [0, 1], sRGB luma; 11×11 "
                     "Gaussian window, σ 1.5): 1 where they agree. With return_map, (mean, per-pixel map (H, W)). ") +
         kImageShapes)
            .c_str());
    m.def(
        "flip",
        [](const py::object& image, const py::object& reference, double pixels_per_degree, double exposure,
           bool return_map) {
            ImagePair p = pair_from(image, reference);
            MetricMap metric;
            {
                py::gil_scoped_release release;
                metric = flip_map(p.image, p.reference, "image", pixels_per_degree, exposure);
            }
            return metric_result(std::move(metric), return_map);
        },
        "image"_a, "reference"_a, "pixels_per_degree"_a = 67.0, "exposure"_a = 0.0, "return_map"_a = false,
        (std::string("LDR FLIP (Andersson et al. 2020) of the displayed images: 0 where they agree, 1 for the "
                     "largest colour difference. pixels_per_degree is the viewing condition (67: a 0.7 m wide 4K "
                     "monitor at 0.7 m). With return_map, (mean, per-pixel map (H, W)). ") +
         kImageShapes)
            .c_str());
}

}  // namespace gilab::python
