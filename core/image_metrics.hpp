#pragma once
// Image comparisons used by tests and experiments.
#include <cstdint>
#include <string>
#include <vector>
#include "core/film.hpp"

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

}  // namespace gilab
