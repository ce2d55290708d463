#pragma once
// Image comparisons used by tests and experiments.
#include <array>
#include <cstdint>
#include <string>
#include <vector>
#include "core/image/film.hpp"
#include "core/image/image_plane.hpp"

namespace gilab {

// Relative MSE (Rousselle et al.): mean over pixels and channels of
// (a − ref)² / (ref² + ε). Layers must have the same size and channel count.
double relative_mse(const Film& image, const Film& reference, const std::string& layer = "color",
                    double epsilon = 1e-2);
// The same over the pixels where mask[pixel] is non-zero (0 when none is).
double relative_mse_masked(const Film& image, const Film& reference, const std::vector<uint8_t>& mask,
                           const std::string& layer = "color", double epsilon = 1e-2);
double mean_value(const Film& image, const std::string& layer = "color");  // over channels
double max_abs_difference(const Film& a, const Film& b, const std::string& layer = "color");

// Throws Error(what, ...) unless both films hold `layer` with the same size and channels.
void check_comparable_layers(const Film& a, const Film& b, const std::string& layer, const char* what);

// A per-pixel map of a perceptual metric and its mean over the image.
struct MetricMap {
    ImagePlane map;
    double mean = 0.0;
};

// The perceptual metrics compare what a display shows: the layer's linear RGB scaled by
// 2^exposure and clamped to [0, 1], as in the PNG previews (a 1-channel layer is grey).
// NaN shows as magenta, as in the PNG previews.

// SSIM (Wang, Bovik, Sheikh & Simoncelli 2004) of the sRGB-encoded luma (Rec. 709
// weights): 11×11 Gaussian window with σ = 1.5 px, K1 = 0.01, K2 = 0.03, dynamic range 1,
// edges clamped. 1 where the images agree; the mean is the usual SSIM index.
MetricMap ssim_map(const Film& image, const Film& reference, const std::string& layer = "color",
                   double exposure = 0.0);

// FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström & Fairchild 2020), the LDR
// version, written from the paper: colour pipeline (YCxCz, contrast-sensitivity filters,
// Hunt-adjusted L*a*b*, HyAB distance, the qc/pc/pt remapping) and feature pipeline (edge
// and point detectors on the achromatic channel), combined as ΔE_c^(1 − ΔE_f). 0 where
// the images agree, 1 for the largest colour difference (green against blue); symmetric
// in its two images. `pixels_per_degree` is the
// viewing condition (67: a 0.7 m wide 4K monitor seen from 0.7 m, the paper's default).
// Edges are clamped.
MetricMap flip_map(const Film& image, const Film& reference, const std::string& layer = "color",
                   double pixels_per_degree = 67.0, double exposure = 0.0);

// LDR-FLIP of two displayed images given as linear RGB planes in [0, 1] (what flip_map
// compares after display_planes); the per-pixel map.
ImagePlane flip_of_display(const std::array<ImagePlane, 3>& image, const std::array<ImagePlane, 3>& reference,
                           double pixels_per_degree);
void check_pixels_per_degree(double pixels_per_degree);  // throws unless positive and finite
// Linear sRGB (D65) to CIE XYZ and back as FLIP converts: with the FLIP papers' matrices.
std::array<double, 3> flip_rgb_to_xyz(const std::array<double, 3>& linear_rgb);
std::array<double, 3> flip_xyz_to_rgb(const std::array<double, 3>& xyz);

// HDR-FLIP (Andersson, Nilsson, Shirley & Akenine-Möller 2021, "Visualizing Errors in
// Rendered High Dynamic Range Images"), for the linear HDR layer itself rather than its
// clamped display: the exposure range comes from the reference's luminance Y (Rec. 709
// weights) — start = log2(x_max / max Y), stop = log2(x_min / median Y), where the ACES
// tone curve reaches 0.85 at x_max = x_min — and is split into
// max(2, ⌈stop − start⌉) evenly spaced exposures. At each, both images are scaled by
// 2^exposure, negative values set to 0, tone-mapped by the ACES fit (Narkowicz 2015,
// with the paper's 0.6 pre-exposure folded into its coefficients) and clamped to
// [0, 1]; LDR-FLIP compares the results and each pixel keeps its largest error.
struct HdrFlip {
    MetricMap flip;
    double start_exposure = 0, stop_exposure = 0;  // stops
    int exposures = 0;
};
HdrFlip hdr_flip_map(const Film& image, const Film& reference, const std::string& layer = "color",
                     double pixels_per_degree = 67.0);
// The ACES fit of HDR-FLIP (0.6-scaled Narkowicz), clamped to [0, 1], and the value it
// maps to t (x_max = x_min at the paper's t = 0.85).
double hdr_flip_tone_map(double x);
double hdr_flip_tone_map_inverse(double t);

}  // namespace gilab
