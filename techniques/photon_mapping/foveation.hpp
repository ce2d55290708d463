#pragma once
// Foveated gather (P1's future work): the eye resolves detail only near the gaze
// direction, so away from it the technique gathers photons less often and over fewer of
// them. Eccentricity is the angle between a ray and the gaze: the eye's forward axis
// turned by gaze_yaw (to the right) and gaze_pitch (up), as an eye tracker would report.
// The image is cut into 4×4 blocks; a block whose centre lies within `fovea_degrees`
// gathers at every pixel with the full photon map. Up to twice that angle it gathers once
// per 2×2 block, beyond it once per 4×4 block, both over a map that keeps every
// `periphery_photon_stride`-th photon with its flux scaled by the stride (the same
// expected density estimate from fewer photons). Every pixel still traces its own primary
// ray and shadow rays, so edges, emitters and direct light stay sharp: a pixel takes the
// block's gathered (indirect) light only when its hit is on the same surface near the
// gathered point (same material, normals within ~18°, closer than the gather radius),
// and gathers itself otherwise.
//
// The radius is kept: the hash grid's cells are r wide, so a larger radius would need a
// 5×5×5 neighbourhood, and a smaller one removes photons from the disk but not from the
// 27 cells the query visits — cost follows the photons visited, not those inside.
#include "core/scene/camera.hpp"

namespace gilab {

struct FoveationSettings {
    bool enabled = false;
    float fovea_degrees = 10.0f;
    int periphery_photon_stride = 4;
    float gaze_yaw_degrees = 0.0f;    // gaze relative to the eye's forward axis
    float gaze_pitch_degrees = 0.0f;
};

// World-space gaze direction of an eye.
Vec3 gaze_direction(const EyeCamera& eye, const FoveationSettings& settings);

// Gather block size (1, 2 or 4 pixels) of the 4×4 block (aligned to multiples of 4,
// clipped to the image) that contains pixel (x, y).
int foveated_block_size(const EyeCamera& eye, const FoveationSettings& settings, int x, int y);

// Eccentricity in degrees of the ray through (px, py) from the gaze.
float eccentricity_degrees(const EyeCamera& eye, const FoveationSettings& settings, float px, float py);

}  // namespace gilab
