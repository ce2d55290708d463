// Ray casting through the multi-frame DAG (the dag_raycast technique, P2 Table 6) on the
// dynamic scenes: one frame at the paper's three image sizes, from the scene camera,
// with the technique's default shadows. Counters: rays per second and nodes entered per
// primary ray. The DAG is built once per scene (two frames at 512³) and kept.
#include <benchmark/benchmark.h>
#include <map>
#include <memory>
#include <string>
#include "core/io/asset_paths.hpp"
#include "core/scene/camera.hpp"
#include "core/image/film.hpp"
#include "core/util/settings.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

using namespace gilab;

namespace {

struct PreparedScene {
    Scene scene;
    std::unique_ptr<Technique> technique;
};

// nullptr when the scene's assets are missing.
PreparedScene* prepared(const std::string& name) {
    static std::map<std::string, std::unique_ptr<PreparedScene>> cache;
    auto it = cache.find(name);
    if (it != cache.end()) return it->second.get();
    std::unique_ptr<PreparedScene> p;
    try {
        p = std::make_unique<PreparedScene>();
        p->scene = open_scene(name, AssetPaths::from_environment()).scene;
        const Settings settings(nlohmann::json{{"resolution", 512}, {"frames", 2}}, "bench");
        p->technique = prepare_technique("dag_raycast", p->scene, settings);
    } catch (const std::exception&) {
        p.reset();
    }
    return (cache[name] = std::move(p)).get();
}

void cast(benchmark::State& state, const std::string& name) {
    PreparedScene* p = prepared(name);
    if (!p) {
        state.SkipWithError((name + ": scene assets not found").c_str());
        return;
    }
    const SceneCamera c = p->scene.camera.value_or(default_camera_for(p->scene.evaluate(0).bounds));
    const int width = int(state.range(0)), height = int(state.range(1));
    ViewSet views;
    views.views.push_back(EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, width, height));
    views.names.push_back("mono");
    p->technique->update(0.0);
    std::vector<Film> films;
    double rays = 0, visits = 0;
    for (auto _ : state) {
        p->technique->render(views, films);
        const Stats s = p->technique->stats();
        rays += s.get("rays");
        visits += s.get("nodes_per_primary_ray");
    }
    state.counters["rays_per_s"] = benchmark::Counter(rays, benchmark::Counter::kIsRate);
    state.counters["nodes_per_primary_ray"] = visits / double(state.iterations());
}

void sizes(benchmark::internal::Benchmark* b) {
    b->Args({400, 300})->Args({1024, 768})->Unit(benchmark::kMillisecond)->UseRealTime();
}

}  // namespace

BENCHMARK_CAPTURE(cast, kitchen, std::string("kitchen"))->Apply(sizes);
BENCHMARK_CAPTURE(cast, robot, std::string("robot"))->Apply(sizes);
BENCHMARK_CAPTURE(cast, fire, std::string("fire"))->Apply(sizes);
