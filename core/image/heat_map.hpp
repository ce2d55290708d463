#pragma once
// Error maps as pictures: a per-pixel map drawn with a dark-to-bright colour ramp (black
// purple → red → orange → pale yellow, after matplotlib's magma), with a colour bar under
// it labelled with the values at its two ends.
#include <array>
#include <cstdint>
#include <filesystem>
#include "core/image/image_plane.hpp"

namespace gilab {

// The ramp at t in [0, 1] (clamped) as 8-bit RGB.
std::array<uint8_t, 3> heat_colour(double t);

// Writes `map` as a PNG: values from `low` (darkest) to `high` (brightest), clamped; NaN
// is drawn cyan, which the ramp never reaches. Below the map, a colour bar with `low`
// and `high` printed at its ends. Throws Error naming the path on bad input.
void write_heat_map_png(const std::filesystem::path& path, const ImagePlane& map, double low, double high);

}  // namespace gilab
