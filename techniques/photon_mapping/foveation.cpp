#include "techniques/photon_mapping/foveation.hpp"

#include <algorithm>
#include <cmath>

namespace gilab {

Vec3 gaze_direction(const EyeCamera& eye, const FoveationSettings& settings) {
    const float yaw = glm::radians(settings.gaze_yaw_degrees), pitch = glm::radians(settings.gaze_pitch_degrees);
    // Camera space: +X right, +Y up, forward −Z.
    const Vec3 local(std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw));
    return glm::normalize(eye.orientation() * local);
}

float eccentricity_degrees(const EyeCamera& eye, const FoveationSettings& settings, float px, float py) {
    const Vec3 gaze = gaze_direction(eye, settings);
    const float c = std::clamp(glm::dot(eye.generate_ray(px, py).direction, gaze), -1.0f, 1.0f);
    return std::acos(c) * (180.0f / kPi);
}

int foveated_block_size(const EyeCamera& eye, const FoveationSettings& settings, int x, int y) {
    if (!settings.enabled) return 1;
    const int x0 = x / 4 * 4, y0 = y / 4 * 4;
    const int x1 = std::min(x0 + 4, eye.width()), y1 = std::min(y0 + 4, eye.height());
    const float e = eccentricity_degrees(eye, settings, 0.5f * float(x0 + x1), 0.5f * float(y0 + y1));
    if (e <= settings.fovea_degrees) return 1;
    return e <= 2.0f * settings.fovea_degrees ? 2 : 4;
}

}  // namespace gilab
