#pragma once
// One stereo frame from an HMD rig with any technique: both eyes go to a single render()
// call, so a technique that reuses shading between the eyes can do so.
#include "core/image/film.hpp"
#include "core/scene/hmd.hpp"
#include "techniques/technique.hpp"

namespace gilab {

struct StereoFrame {
    Film left, right;
    double render_ms = 0;  // wall-clock time of the render() call
};

StereoFrame render_stereo_frame(Technique& technique, const HmdRig& rig);

}  // namespace gilab
