#pragma once
// The world-space state a technique renders from: the scene evaluated at the current
// time, its Embree BVH and its light distribution, kept in step by set_time().
#include <memory>
#include <optional>
#include "core/render/light_sampler.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/scene/scene.hpp"
#include "core/util/stats.hpp"

namespace gilab {

class TracedScene {
public:
    // Validates the scene, evaluates it at t = 0 and builds the BVH and light sampler.
    void load(const Scene& scene);
    // Moves an animated scene to `time` (refitting or rebuilding the BVH); a static scene
    // is left as it is. Records update_ms and bvh_rebuilt in stats when given.
    void set_time(double time, Stats* stats = nullptr);

    bool loaded() const { return tracer_ != nullptr; }
    bool animated() const { return animated_scene_.has_value(); }
    const SceneFrame& frame() const { return frame_; }
    const RayTracer& tracer() const { return *tracer_; }
    const LightSampler& lights() const { return lights_; }
    const std::vector<Material>& materials() const { return materials_; }

private:
    std::optional<Scene> animated_scene_;  // kept only when set_time has work to do
    std::vector<Material> materials_;
    SceneFrame frame_;                     // the ray tracer points at this member
    std::unique_ptr<RayTracer> tracer_;
    LightSampler lights_;
};

}  // namespace gilab
