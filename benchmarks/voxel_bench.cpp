// Sparse voxel structures on the Stanford bunny: voxelization, SVO build, SVO→SVDAG
// conversion (the paper's t_A / t_B, Table 3), split builds, and primary-ray traversal
// in SVO vs ESVO vs SVDAG (Fig. 13). Each case reports the process's peak RSS; run one
// case per process (--benchmark_filter) to read a case's own peak.
#include <benchmark/benchmark.h>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include "accel/dag/esvo.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/io/asset_paths.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/scene/scene.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxelizer.hpp"

using namespace gilab;

namespace {

struct Bunny {
    std::vector<Vec3> positions;
    std::vector<UVec3> triangles;
    Bounds3 bounds;
};

const Bunny* bunny() {
    static std::optional<Bunny> cached;
    static std::once_flag once;
    std::call_once(once, [] {
        auto path = AssetPaths::from_environment().find("bunny/stanford-bunny.obj");
        if (!path) return;
        Scene scene = load_mesh_file(*path);
        SceneFrame frame = scene.evaluate(0.0);
        Bunny b;
        for (const WorldMesh& m : frame.meshes) {
            uint32_t base = uint32_t(b.positions.size());
            b.positions.insert(b.positions.end(), m.positions.begin(), m.positions.end());
            for (UVec3 t : m.triangles) b.triangles.push_back(t + UVec3(base));
        }
        for (const Vec3& p : b.positions) b.bounds.extend(p);
        cached = std::move(b);
    });
    return cached ? &*cached : nullptr;
}

VoxelGrid bunny_grid(uint32_t n) { return VoxelGrid::enclosing(bunny()->bounds, n); }

// Voxels and SVO per resolution, kept across benchmark cases of one process.
struct Prepared {
    VoxelList voxels;
    std::unique_ptr<Svo> svo;
};
Prepared& prepared(uint32_t n) {
    static std::map<uint32_t, Prepared> cache;
    auto it = cache.find(n);
    if (it != cache.end()) return it->second;
    Prepared& p = cache[n];
    p.voxels = voxelize(bunny()->positions, bunny()->triangles, bunny_grid(n));
    p.svo = std::make_unique<Svo>(Svo::build(p.voxels));
    return p;
}

// The paper's SVO→SVDAG conversion times t_A on the bunny (Table 3, ms).
double paper_t_a(uint32_t n) {
    switch (n) {
        case 128: return 6.14;
        case 256: return 24.06;
        case 512: return 250;
        case 1000: return 1020;
        case 2000: return 4250;
        default: return 0;
    }
}

bool need_bunny(benchmark::State& state) {
    if (bunny()) return true;
    state.SkipWithError("bunny/stanford-bunny.obj not found (set GILAB_ASSETS)");
    return false;
}

void set_memory(benchmark::State& state) {
    state.counters["peak_rss_MiB"] = double(peak_rss_bytes()) / (1 << 20);
}

void BM_VoxelizeBunny(benchmark::State& state) {
    if (!need_bunny(state)) return;
    const uint32_t n = uint32_t(state.range(0));
    Voxelizer vox(bunny()->positions, bunny()->triangles, bunny_grid(n));
    size_t voxels = 0;
    for (auto _ : state) {
        VoxelList v = vox.voxelize();
        voxels = v.size();
        benchmark::DoNotOptimize(v.codes.data());
    }
    state.counters["voxels"] = double(voxels);
    state.counters["voxels_per_s"] = benchmark::Counter(double(voxels), benchmark::Counter::kIsIterationInvariantRate);
    set_memory(state);
}
BENCHMARK(BM_VoxelizeBunny)->Arg(128)->Arg(256)->Arg(512)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SvoBuild(benchmark::State& state) {
    if (!need_bunny(state)) return;
    const uint32_t n = uint32_t(state.range(0));
    Prepared& p = prepared(n);
    for (auto _ : state) {
        Svo svo = Svo::build(p.voxels);
        benchmark::DoNotOptimize(svo.node_count());
    }
    state.counters["svo_nodes"] = double(p.svo->node_count());
    state.counters["svo_pointers"] = double(p.svo->pointer_count());
    set_memory(state);
}
BENCHMARK(BM_SvoBuild)->Arg(128)->Arg(256)->Arg(512)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();

// Table 3: SVO→SVDAG; t_A is the benchmark time, t_B the dedup counter.
void BM_SvoToSvdag(benchmark::State& state) {
    if (!need_bunny(state)) return;
    const uint32_t n = uint32_t(state.range(0));
    Prepared& p = prepared(n);
    double dedup = 0, total = 0;
    size_t nodes = 0, bytes = 0, iterations = 0;
    for (auto _ : state) {
        Svdag dag = Svdag::from_svo(*p.svo);
        dedup += dag.build_stats().dedup_ms;
        total += dag.build_stats().total_ms;
        nodes = dag.node_count();
        bytes = dag.bytes();
        ++iterations;
    }
    state.counters["t_A_ms"] = total / double(iterations);
    state.counters["t_B_ms"] = dedup / double(iterations);
    state.counters["paper_t_A_ms"] = paper_t_a(n);
    state.counters["svo_nodes"] = double(p.svo->node_count());
    state.counters["dag_nodes"] = double(nodes);
    state.counters["dag_MB"] = double(bytes) / 1e6;
    set_memory(state);
}
BENCHMARK(BM_SvoToSvdag)->Arg(128)->Arg(256)->Arg(512)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();

// Split build straight from the mesh: one level-`split` cell voxelized at a time.
void BM_SvdagSplitFromMesh(benchmark::State& state) {
    if (!need_bunny(state)) return;
    const uint32_t n = uint32_t(state.range(0));
    Voxelizer vox(bunny()->positions, bunny()->triangles, bunny_grid(n));
    const int split = std::max(0, vox.grid().depth() - int(state.range(1)));
    SvdagBuildStats stats;
    size_t nodes = 0;
    for (auto _ : state) {
        Svdag dag = Svdag::from_voxelizer(vox, split);
        stats = dag.build_stats();
        nodes = dag.node_count();
    }
    state.counters["split_level"] = split;
    state.counters["subtrees"] = double(stats.subtrees);
    state.counters["voxels"] = double(stats.input_nodes);
    state.counters["voxelize_ms"] = stats.voxelize_ms;
    state.counters["convert_ms"] = stats.total_ms;
    state.counters["dag_nodes"] = double(nodes);
    set_memory(state);
}
// Args: resolution, log2 of the cell size converted at once.
BENCHMARK(BM_SvdagSplitFromMesh)->Args({512, 8})->Args({1000, 8})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// Large grids only on request (GILAB_BENCH_LARGE=1): the 2000³ SVO path and split
// builds at 2000³, 4096³ and 8192³ (1024³ and 256³ subtrees).
const bool kLargeRegistered = [] {
    if (!std::getenv("GILAB_BENCH_LARGE")) return false;
    benchmark::RegisterBenchmark("BM_SvoToSvdag", BM_SvoToSvdag)->Arg(2000)->Unit(benchmark::kMillisecond)->UseRealTime();
    benchmark::RegisterBenchmark("BM_SvdagSplitFromMesh", BM_SvdagSplitFromMesh)
        ->Args({2000, 8})
        ->Args({4096, 10})
        ->Args({8192, 10})
        ->Args({8192, 8})
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(1);
    return true;
}();

// Fig. 13: primary rays from a fixed viewpoint, 256×256 pinhole camera.
std::vector<Ray> primary_rays(const VoxelGrid& g, int width) {
    Vec3 center = g.origin + Vec3(0.5f * g.extent);
    Vec3 eye = center + Vec3(0.3f, 0.2f, 1.6f) * g.extent;
    Vec3 forward = glm::normalize(center - eye), right = glm::normalize(glm::cross(forward, Vec3(0, 1, 0)));
    Vec3 up = glm::cross(right, forward);
    std::vector<Ray> rays;
    const float tan_half = 0.35f;
    for (int y = 0; y < width; ++y)
        for (int x = 0; x < width; ++x) {
            float u = (2.0f * (x + 0.5f) / width - 1.0f) * tan_half, v = (2.0f * (y + 0.5f) / width - 1.0f) * tan_half;
            Ray r;
            r.origin = eye;
            r.direction = glm::normalize(forward + u * right + v * up);
            rays.push_back(r);
        }
    return rays;
}

template <class Structure>
void run_traversal(benchmark::State& state, const Structure& s, const VoxelGrid& g) {
    std::vector<Ray> rays = primary_rays(g, 256);
    std::vector<VoxelRayHit> hits(rays.size());
    for (auto _ : state) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) hits[i] = trace_voxel_ray(s, rays[i]);
        });
    }
    double visited = 0, hit = 0;
    for (const auto& h : hits) {
        visited += h.nodes_visited;
        hit += h.hit;
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(rays.size()));
    state.counters["nodes_per_ray"] = visited / double(rays.size());
    state.counters["hit_fraction"] = hit / double(rays.size());
}

void BM_TraceSvo(benchmark::State& state) {
    if (!need_bunny(state)) return;
    Prepared& p = prepared(uint32_t(state.range(0)));
    run_traversal(state, *p.svo, p.voxels.grid);
}
void BM_TraceEsvo(benchmark::State& state) {
    if (!need_bunny(state)) return;
    Prepared& p = prepared(uint32_t(state.range(0)));
    Esvo e = Esvo::from_svo(*p.svo);
    run_traversal(state, e, p.voxels.grid);
}
void BM_TraceSvdag(benchmark::State& state) {
    if (!need_bunny(state)) return;
    Prepared& p = prepared(uint32_t(state.range(0)));
    Svdag d = Svdag::from_svo(*p.svo);
    run_traversal(state, d, p.voxels.grid);
}
BENCHMARK(BM_TraceSvo)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TraceEsvo)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TraceSvdag)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
