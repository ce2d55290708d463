#include "core/render/traced_scene.hpp"

#include "core/util/error.hpp"

namespace gilab {

void TracedScene::load(const Scene& scene) {
    scene.validate();
    materials_ = scene.materials;
    if (scene.is_animated()) animated_scene_ = scene;
    else animated_scene_.reset();
    tracer_.reset();
    frame_ = scene.evaluate(0.0);
    tracer_ = std::make_unique<RayTracer>(frame_);
    lights_ = LightSampler(frame_, materials_);
}

void TracedScene::set_time(double time, Stats* stats) {
    if (!tracer_) throw Error("scene", "set_time() called before load()");
    if (!animated_scene_) return;  // static: every time looks the same
    Stopwatch watch;
    frame_ = animated_scene_->evaluate(time);
    RayTracer::UpdateKind kind = tracer_->update(frame_);
    lights_ = LightSampler(frame_, materials_);
    if (stats) {
        stats->set("update_ms", watch.elapsed_ms());
        stats->set("bvh_rebuilt", kind == RayTracer::UpdateKind::Rebuild ? 1.0 : 0.0);
    }
}

}  // namespace gilab
