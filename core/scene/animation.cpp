#include "core/scene/animation.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtx/matrix_decompose.hpp>

namespace gilab {

Mat4 Transform::matrix() const {
    Mat4 t = glm::translate(Mat4(1.0f), translation);
    Mat4 r = glm::mat4_cast(rotation);
    Mat4 s = glm::scale(Mat4(1.0f), scale);
    return t * r * s;
}

Transform Transform::from_matrix(const Mat4& m) {
    Transform result;
    Vec3 skew;
    Vec4 perspective;
    glm::decompose(m, result.scale, result.rotation, result.translation, skew, perspective);
    result.rotation = glm::normalize(result.rotation);
    return result;
}

namespace {

// Index of the last key with time ≤ t and the blend factor towards the next key.
template <typename T>
std::pair<size_t, float> locate(const KeyframeChannel<T>& channel, float time) {
    const auto& times = channel.times;
    if (time <= times.front()) return {0, 0.0f};
    if (time >= times.back()) return {times.size() - 1, 0.0f};
    size_t hi = size_t(std::upper_bound(times.begin(), times.end(), time) - times.begin());
    size_t lo = hi - 1;
    float span = times[hi] - times[lo];
    return {lo, span > 0 ? (time - times[lo]) / span : 0.0f};
}

Vec3 sample_channel(const KeyframeChannel<Vec3>& c, float time, bool step) {
    auto [i, f] = locate(c, time);
    if (step || f == 0.0f || i + 1 >= c.values.size()) return c.values[i];
    return glm::mix(c.values[i], c.values[i + 1], f);
}

Quat sample_channel(const KeyframeChannel<Quat>& c, float time, bool step) {
    auto [i, f] = locate(c, time);
    if (step || f == 0.0f || i + 1 >= c.values.size()) return c.values[i];
    return glm::normalize(glm::slerp(c.values[i], c.values[i + 1], f));
}

}  // namespace

float TrsAnimation::duration() const {
    float d = 0;
    if (!translation.empty()) d = std::max(d, translation.times.back());
    if (!rotation.empty()) d = std::max(d, rotation.times.back());
    if (!scale.empty()) d = std::max(d, scale.times.back());
    return d;
}

Transform TrsAnimation::sample(float time, const Transform& rest) const {
    Transform t = rest;
    if (!translation.empty()) t.translation = sample_channel(translation, time, step);
    if (!rotation.empty()) t.rotation = sample_channel(rotation, time, step);
    if (!scale.empty()) t.scale = sample_channel(scale, time, step);
    return t;
}

}  // namespace gilab
