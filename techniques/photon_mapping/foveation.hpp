#pragma once
// Foveated gather (P1's future work): the eye resolves detail only near the gaze
// direction, so away from it the technique shades fewer pixels and gathers over fewer
// photons. Eccentricity is the angle between a pixel's ray and the gaze (the eye's
// forward axis). Within `fovea_degrees` every pixel is shaded with the full photon map;
// up to twice that angle one sample per 2×2 block, beyond it one per 4×4 block, both
// gathering over a map that keeps every `periphery_photon_stride`-th photon with its flux
// scaled by the stride (the same expected density estimate from fewer photons).
//
// The radius is kept: the hash grid's cells are r wide, so a larger radius would need a
// 5×5×5 neighbourhood, and a smaller one removes photons from the disk but not from the
// 27 cells the query visits — cost follows the photons visited, not those inside.
#include "core/camera.hpp"

namespace gilab {

struct FoveationSettings {
    bool enabled = false;
    float fovea_degrees = 10.0f;
    int periphery_photon_stride = 4;
};

// Shading block size (1, 2 or 4 pixels) for a block whose centre is at continuous pixel
// coordinate (px, py).
int foveated_block_size(const EyeCamera& eye, const FoveationSettings& settings, float px, float py);

// Eccentricity in degrees of the ray through (px, py) from the eye's forward axis.
float eccentricity_degrees(const EyeCamera& eye, float px, float py);

}  // namespace gilab
