// Ray casting through the multi-frame DAG (the dag_raycast technique, P2 Table 6) on the
// dynamic scenes: one frame at the paper's three image sizes, from the scene camera,
// with the technique's default shadows. Counters: rays per second and nodes entered per
// primary ray. The DAG is built once per scene (two frames at 512³) and kept.
//
// Then the symmetry-aware DAGs against the SVDAG they are built from: frame 0 of a scene
// on a grid around it, the same primary rays from the scene camera cast with cast_dag_ray
// and cast_symmetric_dag_ray through the SSVDAG (reflections) and the cube-symmetric DAG
// (reflections and axis permutations), no shading, and the DAGs' nodes and bytes.
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>
#include "accel/dag/dag_ray_caster.hpp"
#include "accel/dag/symmetric_dag.hpp"
#include "accel/dag/symmetric_dag_ray_caster.hpp"
#include "accel/dag/svdag.hpp"
#include "core/io/asset_paths.hpp"
#include "core/scene/camera.hpp"
#include "core/image/film.hpp"
#include "core/util/settings.hpp"
#include "core/voxel/voxelizer.hpp"
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

// Frame 0 of a scene as an SVDAG and the symmetric DAGs made from it, with the scene's camera.
struct SymmetryDags {
    Svdag svdag;
    Ssvdag ssvdag;
    CubeSymmetricDag cube;
    SceneCamera camera;
};

// nullptr when the scene's assets are missing. Split build, one cell of 2^8 voxels per
// axis at a time, so the large grids never hold their whole voxel list.
SymmetryDags* symmetry_dags(const std::string& name, uint32_t resolution) {
    static std::map<std::pair<std::string, uint32_t>, std::unique_ptr<SymmetryDags>> cache;
    const auto key = std::make_pair(name, resolution);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second.get();
    std::unique_ptr<SymmetryDags> d;
    try {
        const Scene scene = open_scene(name, AssetPaths::from_environment()).scene;
        const SceneFrame frame = scene.evaluate(0.0);
        const Voxelizer voxelizer(frame, VoxelGrid::enclosing(frame.bounds, resolution));
        d = std::make_unique<SymmetryDags>();
        d->svdag = Svdag::from_voxelizer(voxelizer, std::max(0, voxelizer.grid().depth() - 8));
        d->ssvdag = Ssvdag::from_svdag(d->svdag);
        d->cube = CubeSymmetricDag::from_svdag(d->svdag);
        d->camera = scene.camera.value_or(default_camera_for(frame.bounds));
    } catch (const std::exception&) {
        d.reset();
    }
    return (cache[key] = std::move(d)).get();
}

enum class DagKind { svdag, ssvdag, cube };

// Args: resolution, image width, height. The same rays through one of the DAGs, on all threads.
template <DagKind kKind>
void cast_symmetry(benchmark::State& state, const std::string& name) {
    SymmetryDags* d = symmetry_dags(name, uint32_t(state.range(0)));
    if (!d) {
        state.SkipWithError((name + ": scene assets not found").c_str());
        return;
    }
    const int width = int(state.range(1)), height = int(state.range(2));
    const SceneCamera& c = d->camera;
    const EyeCamera cam = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, width, height);
    std::vector<Ray> rays;
    rays.reserve(size_t(width) * size_t(height));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) rays.push_back(cam.generate_ray(float(x) + 0.5f, float(y) + 0.5f));
    const DagWordsView view = dag_view(d->svdag);
    std::atomic<uint64_t> visits{0}, hits{0};
    for (auto _ : state) {
        visits = 0;
        hits = 0;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
            uint64_t v = 0, h = 0;
            for (size_t i = r.begin(); i < r.end(); ++i) {
                const VoxelRayHit hit = kKind == DagKind::ssvdag ? cast_symmetric_dag_ray(d->ssvdag, rays[i])
                                        : kKind == DagKind::cube ? cast_symmetric_dag_ray(d->cube, rays[i])
                                                                 : cast_dag_ray(view, rays[i]);
                v += hit.nodes_visited;
                h += hit.hit;
            }
            visits += v;
            hits += h;
        });
    }
    state.counters["rays_per_s"] =
        benchmark::Counter(double(rays.size()), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["nodes_per_ray"] = double(visits) / double(rays.size());
    state.counters["hit_fraction"] = double(hits) / double(rays.size());
    state.counters["threads"] = double(tbb::this_task_arena::max_concurrency());
    state.counters["dag_bytes"] = double(kKind == DagKind::ssvdag ? d->ssvdag.bytes()
                                         : kKind == DagKind::cube ? d->cube.bytes()
                                                                  : d->svdag.bytes());
    state.counters["dag_nodes"] = double(kKind == DagKind::ssvdag ? d->ssvdag.node_count()
                                         : kKind == DagKind::cube ? d->cube.node_count()
                                                                  : d->svdag.node_count());
}

void cast_svdag(benchmark::State& state, const std::string& name) { cast_symmetry<DagKind::svdag>(state, name); }
void cast_ssvdag(benchmark::State& state, const std::string& name) { cast_symmetry<DagKind::ssvdag>(state, name); }
void cast_cube_dag(benchmark::State& state, const std::string& name) { cast_symmetry<DagKind::cube>(state, name); }

// Nodes and bytes of the DAGs (arg: resolution); the time is the SVDAG → SSVDAG conversion.
void ssvdag_size(benchmark::State& state, const std::string& name) {
    SymmetryDags* d = symmetry_dags(name, uint32_t(state.range(0)));
    if (!d) {
        state.SkipWithError((name + ": scene assets not found").c_str());
        return;
    }
    for (auto _ : state) {
        const Ssvdag s = Ssvdag::from_svdag(d->svdag);
        benchmark::DoNotOptimize(s.units().data());
    }
    state.counters["svdag_nodes"] = double(d->svdag.node_count());
    state.counters["ssvdag_nodes"] = double(d->ssvdag.node_count());
    state.counters["svdag_bytes"] = double(d->svdag.bytes());
    state.counters["ssvdag_bytes"] = double(d->ssvdag.bytes());
    state.counters["bytes_ratio"] = double(d->ssvdag.bytes()) / double(d->svdag.bytes());
    state.counters["ssvdag_word_bytes"] = double(d->ssvdag.word_bytes());
    state.counters["mirrored_pointers"] = double(d->ssvdag.transformed_pointer_count());
    state.counters["long_pointers"] = double(d->ssvdag.long_pointer_count());
    state.counters["cube_nodes"] = double(d->cube.node_count());
    state.counters["cube_bytes"] = double(d->cube.bytes());
    state.counters["cube_over_ssvdag_bytes"] = double(d->cube.bytes()) / double(d->ssvdag.bytes());
    state.counters["cube_permuting_pointers"] = double(d->cube.permuting_pointer_count());
    state.counters["cube_long_pointers"] = double(d->cube.long_pointer_count());
    state.counters["voxels"] = double(d->ssvdag.voxel_count());
}

void symmetry_sizes(benchmark::internal::Benchmark* b) {
    b->Args({512, 1024, 768})->Args({2048, 1024, 768})->Unit(benchmark::kMillisecond)->UseRealTime();
}

}  // namespace

BENCHMARK_CAPTURE(cast, kitchen, std::string("kitchen"))->Apply(sizes);
BENCHMARK_CAPTURE(cast, robot, std::string("robot"))->Apply(sizes);
BENCHMARK_CAPTURE(cast, fire, std::string("fire"))->Apply(sizes);

BENCHMARK_CAPTURE(cast_svdag, kitchen, std::string("kitchen"))->Apply(symmetry_sizes);
BENCHMARK_CAPTURE(cast_ssvdag, kitchen, std::string("kitchen"))->Apply(symmetry_sizes);
BENCHMARK_CAPTURE(cast_cube_dag, kitchen, std::string("kitchen"))->Apply(symmetry_sizes);
BENCHMARK_CAPTURE(cast_svdag, sponza, std::string("sponza"))->Apply(symmetry_sizes);
BENCHMARK_CAPTURE(cast_ssvdag, sponza, std::string("sponza"))->Apply(symmetry_sizes);
BENCHMARK_CAPTURE(cast_cube_dag, sponza, std::string("sponza"))->Apply(symmetry_sizes);
// The bunny mesh alone (the bunny scene adds a ground six times its size).
BENCHMARK_CAPTURE(ssvdag_size, bunny, std::string("bunny/stanford-bunny.obj"))
    ->Arg(512)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(ssvdag_size, sponza, std::string("sponza"))
    ->Arg(512)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(ssvdag_size, kitchen, std::string("kitchen"))
    ->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// Large grids only on request (GILAB_BENCH_LARGE=1): the conversion on DAGs of about a
// million nodes and more.
const bool kLargeSymmetryRegistered = [] {
    if (!std::getenv("GILAB_BENCH_LARGE")) return false;
    for (const char* scene : {"bunny/stanford-bunny.obj", "sponza"})
        benchmark::RegisterBenchmark((std::string("ssvdag_size/") + scene).c_str(), ssvdag_size, std::string(scene))
            ->Arg(8192)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime()
            ->Iterations(1);
    return true;
}();
