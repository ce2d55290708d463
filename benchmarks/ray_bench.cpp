// Embree backend micro-benchmarks on the Cornell box: single rays vs streams.
#include <benchmark/benchmark.h>
#include "core/scene/camera.hpp"
#include "core/render/ray_tracer.hpp"
#include "scenes/builtin_scenes.hpp"

using namespace gilab;

namespace {

struct CornellRays {
    Scene scene = make_cornell_box();
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer{frame};
    std::vector<Ray> rays;
    CornellRays() {
        const SceneCamera& c = *scene.camera;
        EyeCamera cam = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, 256, 256);
        for (int y = 0; y < 256; ++y)
            for (int x = 0; x < 256; ++x) rays.push_back(cam.generate_ray(x + 0.5f, y + 0.5f));
    }
};

CornellRays& fixture() {
    static CornellRays f;
    return f;
}

void BM_PrimarySingle(benchmark::State& state) {
    auto& f = fixture();
    for (auto _ : state)
        for (const Ray& r : f.rays) benchmark::DoNotOptimize(f.tracer.intersect(r));
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(f.rays.size()));
}

void BM_PrimaryStream(benchmark::State& state) {
    auto& f = fixture();
    std::vector<Hit> hits(f.rays.size());
    for (auto _ : state) {
        f.tracer.intersect(f.rays, hits);
        benchmark::DoNotOptimize(hits.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(f.rays.size()));
}

}  // namespace

BENCHMARK(BM_PrimarySingle)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PrimaryStream)->Unit(benchmark::kMillisecond);
