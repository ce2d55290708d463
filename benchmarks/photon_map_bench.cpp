// Photon-map radius queries on photons traced in the Cornell box (256² emitted, indirect
// map): the three structures at r = 0.02 / 0.05 / 0.1, queried at the camera's primary
// hit points (64×64). BM_Radius visits photons through each structure's own query
// (a visitor summing flux); BM_Gather is the renderer's density estimate (for the hash
// grid: the 8-lane SIMD loop over contiguous runs of its structure-of-arrays).
#include <benchmark/benchmark.h>

#include <map>
#include "accel/photon/hash_grid_photon_map.hpp"
#include "accel/photon/kd_tree_photon_map.hpp"
#include "accel/photon/nanoflann_photon_map.hpp"
#include "core/render/interaction.hpp"
#include "core/render/light_sampler.hpp"
#include "core/render/ray_tracer.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/photon_mapping/photon_gather.hpp"
#include "techniques/photon_mapping/photon_tracer.hpp"

using namespace gilab;

namespace {

struct CornellPhotons {
    Scene scene = make_cornell_box();
    SceneFrame frame = scene.evaluate(0);
    RayTracer tracer{frame};
    std::vector<Photon> photons;
    std::vector<GatherPoint> points;
    CornellPhotons() {
        LightSampler lights(frame, scene.materials);
        PhotonTraceSettings ts;
        ts.emitted = 256 * 256;
        photons = trace_photons(tracer, frame, scene.materials, lights, ts).photons;
        const SceneCamera& c = *scene.camera;
        EyeCamera cam = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, 64, 64);
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                Ray ray = cam.generate_ray(x + 0.5f, y + 0.5f);
                Hit hit = tracer.intersect(ray);
                if (!hit.valid()) continue;
                SurfaceInteraction si = make_interaction(frame, ray, hit);
                points.push_back({si.position, si.shading_normal, si.wo, si.material, scene.materials[si.material]});
            }
    }
};

CornellPhotons& fixture() {
    static CornellPhotons f;
    return f;
}

const float kRadii[] = {0.02f, 0.05f, 0.1f};

// One built structure per (kind, radius), kept across benchmark repetitions.
const PhotonMap& structure(PhotonMapKind kind, float r) {
    static std::map<std::pair<int, float>, std::unique_ptr<PhotonMap>> cache;
    auto& slot = cache[{int(kind), r}];
    if (!slot) {
        slot = make_photon_map(kind);
        slot->build(fixture().photons, r);
    }
    return *slot;
}

void report(benchmark::State& state, const PhotonQueryStats& stats) {
    state.SetItemsProcessed(int64_t(stats.queries));
    state.counters["visited_per_query"] = stats.visited_per_query();
    state.counters["inside_fraction"] = stats.inside_fraction();
    state.counters["photons"] = double(fixture().photons.size());
}

template <PhotonMapKind Kind>
void BM_Radius(benchmark::State& state) {
    const float r = kRadii[state.range(0)];
    const PhotonMap& map = structure(Kind, r);
    const auto& points = fixture().points;
    PhotonQueryStats stats;
    for (auto _ : state) {
        float sum = 0;
        for (const GatherPoint& p : points) {
            auto visit = [&](uint32_t i, float) { sum += map.photon(i).power.x; };
            if constexpr (Kind == PhotonMapKind::HashGrid)
                static_cast<const HashGridPhotonMap&>(map).for_each_in_radius(p.position, r, visit, stats);
            else if constexpr (Kind == PhotonMapKind::KdTree)
                static_cast<const KdTreePhotonMap&>(map).for_each_in_radius(p.position, r, visit, stats);
            else
                map.radius_query(p.position, r, visit, stats);
        }
        benchmark::DoNotOptimize(sum);
    }
    report(state, stats);
    state.SetLabel("r=" + std::to_string(r).substr(0, 4));
}

template <PhotonMapKind Kind>
void BM_Gather(benchmark::State& state) {
    const float r = kRadii[state.range(0)];
    const PhotonMap& map = structure(Kind, r);
    const auto& f = fixture();
    PhotonGatherer gatherer(map, GatherMode::Radius, 128);
    GatherScratch scratch;
    PhotonQueryStats stats;
    for (auto _ : state) {
        Vec3 sum(0.0f);
        for (const GatherPoint& p : f.points) sum += gatherer.estimate(p, scratch, stats);
        benchmark::DoNotOptimize(sum);
    }
    report(state, stats);
    state.SetLabel("r=" + std::to_string(r).substr(0, 4));
}

}  // namespace

BENCHMARK(BM_Radius<PhotonMapKind::HashGrid>)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Radius<PhotonMapKind::KdTree>)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Radius<PhotonMapKind::Nanoflann>)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Gather<PhotonMapKind::HashGrid>)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Gather<PhotonMapKind::KdTree>)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Gather<PhotonMapKind::Nanoflann>)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
