#pragma once
// Head-mounted display rig: a head pose plus two eyes offset by ±IPD/2 along the head's
// +X axis, each with its own asymmetric frustum and resolution (as the runtimes report).
#include <string>
#include <vector>
#include "core/scene/camera.hpp"

namespace gilab {

enum class Eye { Left = 0, Right = 1 };

struct HeadPose {
    Vec3 position{0};
    Quat orientation{1, 0, 0, 0};
};

struct HmdPreset {
    std::string name;          // e.g. "vive"
    std::string display_name;  // e.g. "HTC Vive"
    int width = 0, height = 0; // per-eye render resolution
    float ipd = 0.063f;        // metres
    FrustumTangents left_fov, right_fov;
    std::string source;        // where the figures come from
};

const std::vector<HmdPreset>& hmd_presets();
const HmdPreset& find_hmd_preset(const std::string& name);  // throws Error if unknown

class HmdRig {
public:
    HmdRig() = default;
    explicit HmdRig(HmdPreset preset, HeadPose pose = {});

    void set_pose(const HeadPose& pose) { pose_ = pose; }
    void set_ipd(float ipd) { preset_.ipd = ipd; }
    void set_resolution(int width, int height);
    const HeadPose& pose() const { return pose_; }
    const HmdPreset& preset() const { return preset_; }

    EyeCamera eye(Eye which) const;
    Vec3 eye_position(Eye which) const;

private:
    HmdPreset preset_;
    HeadPose pose_;
};

// Head-pose trace: CSV rows "t,px,py,pz,qw,qx,qy,qz" (a header line is allowed).
struct HeadPoseSample {
    double time = 0;
    HeadPose pose;
};
std::vector<HeadPoseSample> load_head_pose_trace(const std::string& path);
// Pose at time t: linear in position, slerp in orientation, clamped at the ends.
HeadPose sample_head_pose(const std::vector<HeadPoseSample>& trace, double time);
// The trace's motion since its first sample, replayed from `base`: the head turns by
// q0⁻¹·q(t) and moves by q0⁻¹·(p(t) − p0) (in the head's own frame, times `scale`), so a
// trace recorded in any tracking space drives any scene from that scene's own head pose.
// `scale` converts trace metres to scene units. Throws Error on an empty trace.
HeadPose trace_pose_relative_to(const HeadPose& base, const std::vector<HeadPoseSample>& trace,
                                double time, float scale = 1.0f);

}  // namespace gilab
