#pragma once
// Embree 3 backend: one Embree geometry per world mesh. Closest hit and occlusion for
// single rays and for streams of rays (Embree's rtcIntersect1M/rtcOccluded1M path).
// `update` refits the BVH when only vertex positions moved (same topology, animation)
// and rebuilds otherwise.
#include <memory>
#include <span>
#include "core/util/ray.hpp"
#include "core/scene/scene.hpp"

namespace gilab {

class RayTracer {
public:
    explicit RayTracer(const SceneFrame& frame);
    ~RayTracer();
    RayTracer(const RayTracer&) = delete;
    RayTracer& operator=(const RayTracer&) = delete;

    enum class UpdateKind { Refit, Rebuild };
    UpdateKind update(const SceneFrame& frame);

    Hit intersect(const Ray& ray) const;
    bool occluded(const Ray& ray) const;
    // Coherent batches (e.g. a tile of primary rays, or all shadow rays of a tile).
    void intersect(std::span<const Ray> rays, std::span<Hit> hits) const;
    void occluded(std::span<const Ray> rays, std::span<uint8_t> blocked) const;

    const SceneFrame& frame() const { return *frame_; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    const SceneFrame* frame_ = nullptr;
};

}  // namespace gilab
