#pragma once
// Keyframed TRS animation of scene nodes (glTF's model: separate channels for
// translation, rotation and scale, linear/slerp or step interpolation).
#include <vector>
#include "core/util/math.hpp"

namespace gilab {

struct Transform {
    Vec3 translation{0};
    Quat rotation{1, 0, 0, 0};  // w, x, y, z
    Vec3 scale{1};
    Mat4 matrix() const;
    static Transform from_matrix(const Mat4& m);  // decomposes an affine TRS matrix
};

template <typename T>
struct KeyframeChannel {
    std::vector<float> times;   // seconds, strictly increasing
    std::vector<T> values;
    bool empty() const { return times.empty(); }
};

struct TrsAnimation {
    KeyframeChannel<Vec3> translation;
    KeyframeChannel<Quat> rotation;
    KeyframeChannel<Vec3> scale;
    bool step = false;  // true: hold each key until the next (glTF STEP)

    bool empty() const { return translation.empty() && rotation.empty() && scale.empty(); }
    float duration() const;
    // Channels without keys keep the rest pose's value. Times outside the keys clamp.
    Transform sample(float time, const Transform& rest) const;
};

}  // namespace gilab
