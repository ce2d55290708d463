// Voxel cone tracing (P3) on Sponza, phase by phase, for the cascaded voxel texture
// (6 levels of 32³) and the dense mip texture (128³) of the same scene with the same
// finest voxel, so each phase compares like for like:
//  - BM_ConeMarch: 16 diffuse cones from each of 96×96 G-buffer points (primary hits of
//    the scene camera), traced cone by cone or as one fan per point (eight cones at a
//    time under the AVX2 kernel), as the technique's final gather traces them;
//  - BM_ConeMarchLayout: the same on one thread with the radiance laid out as the
//    technique stores it (a voxel's six faces together) or as P3's Fig. 2 (one block
//    per face), with and without skipping samples the occupancy map marks empty;
//  - BM_Injection: one full light injection over the occupied voxels (direct light by
//    shadow rays, anisotropic filtering, the voxel bounce, filtering again), with its
//    phases as counters from the technique's stats;
//  - BM_AnisotropicFilter: the mip levels of one radiance buffer (cascades: every
//    level's inner box from the finer level; dense: the whole chain);
//  - BM_SampleLevel: one trilinear face-weighted sample (the inner loop of every cone),
//    from a one-voxel neighbourhood (cache-resident), scattered over the finest level,
//    or scattered over every level; with or without the clip plane.
//  - BM_TexelFloor: the machine's cost of the work every sample of this format must do
//    and nothing else: the 24 RGBA16F texels (8 voxels × 3 faces) of a trilinear,
//    face-weighted sample loaded, converted and weighted, with the addresses and weights
//    already known (the cheapest form we know: x pairs, 12 conversions and 12 fused
//    multiply-adds of 8 lanes), over a level-sized buffer in cache. A frame's sample count
//    times this is the least time a sampler that loads and converts every sample's texels
//    can take;
//  - BM_ReadBandwidth: the machine's read bandwidth (summing 64-bit words) from a buffer
//    the size of one cascade level's radiance (1.5 MiB: cache) and of 256 MiB (memory),
//    the bound a cone sampler would meet if it were limited by the bytes it reads.
// Args name the structure (0 cascaded, 1 dense) and, where given, the worker threads
// (0: all cores) and the sampling kernel (0 portable SSE2, 1 AVX2 + FMA + F16C; see
// ConeKernel), so one run gives the kernels' ratio. Set-up (loading, voxelizing, the first injection) happens once per
// process, outside the timed loops. Sponza comes from GILAB_ASSETS or ../shared/scenes.
#include <benchmark/benchmark.h>

#include <atomic>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include "core/io/asset_paths.hpp"
#include "core/render/interaction.hpp"
#include "core/render/traced_scene.hpp"
#include "core/util/parallel.hpp"
#include "core/util/rng.hpp"
#include "core/util/settings.hpp"
#include "core/util/stats.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/vct/cone_tracer.hpp"
#include "techniques/vct/vct_technique.hpp"

using namespace gilab;

namespace {

constexpr int kGbufferSide = 96;   // G-buffer points per image side
constexpr int kDiffuseCones = 16;  // per point, as the technique's default
const char* const kStructureNames[] = {"cascaded", "dense"};

// A visible surface point: where the final gather starts its cones.
struct GbufferPoint {
    Vec3 position, normal;
};

struct SponzaScene {
    Scene scene;
    TracedScene traced;
    Bounds3 bounds;
    Vec3 viewer{0};
    std::vector<GbufferPoint> points;
};

const SponzaScene* sponza() {
    static std::optional<SponzaScene> cached;
    static std::once_flag once;
    std::call_once(once, [] {
        const AssetPaths assets = AssetPaths::from_environment();
        if (!assets.find("sponza/sponza.obj")) return;
        SponzaScene& s = cached.emplace();
        s.scene = open_scene("sponza", assets).scene;
        s.traced.load(s.scene);
        s.bounds = s.traced.frame().bounds;
        const SceneCamera& c = *s.scene.camera;
        s.viewer = c.position;
        const EyeCamera cam =
            EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, kGbufferSide, kGbufferSide);
        for (int y = 0; y < kGbufferSide; ++y)
            for (int x = 0; x < kGbufferSide; ++x) {
                const Ray ray = cam.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
                const Hit hit = s.traced.tracer().intersect(ray);
                if (!hit.valid()) continue;
                const SurfaceInteraction si = make_interaction(s.traced.frame(), ray, hit);
                s.points.push_back({si.position, si.shading_normal});
            }
    });
    return cached ? &*cached : nullptr;
}

bool need_sponza(benchmark::State& state) {
    if (sponza()) return true;
    state.SkipWithError("sponza/sponza.obj not found (set GILAB_ASSETS)");
    return false;
}

// The technique prepared on Sponza with one structure: voxelized and lit once. Its
// schedule updates every level every frame, so update_voxels at the prepare viewer is
// one full injection with nothing to re-voxelize.
VctTechnique& technique(int structure) {
    static std::unique_ptr<VctTechnique> cache[2];
    auto& slot = cache[structure];
    if (!slot) {
        nlohmann::json settings = {{"structure", kStructureNames[structure]},
                                   {"update", "strategy"},
                                   {"update_schedule", "every"},
                                   {"seed", 1}};
        slot = std::make_unique<VctTechnique>();
        slot->prepare(sponza()->scene, Settings(settings, "vct bench"));
    }
    return *slot;
}

// The cone options of the technique's final gather at one point (cones_at in
// vct_technique.cpp): apex lifted a voxel off the surface, first sample a voxel out,
// clipped to the surface's front half-space.
struct PointCones {
    Vec3 apex;
    ConeOptions options;
};
PointCones cones_at(const VoxelConeView& view, const VctSettings& s, const Bounds3& bounds, const GbufferPoint& p) {
    const int k = view.finest_level_containing(p.position, 1.0f);
    const float w = k < 0 ? view.base_voxel_size() : view.level(k).voxel_size;
    PointCones pc;
    pc.options.step = s.cone_step;
    pc.options.ao_lambda = s.ao_lambda;
    pc.options.correct_opacity = s.opacity_correction;
    pc.options.lod_bias = s.lod_bias;
    pc.options.blend_levels = s.blend_levels;
    pc.options.bounds = bounds;
    if (s.max_distance > 0) pc.options.max_distance = s.max_distance;
    pc.options.start = s.cone_start * w;
    pc.options.clip = s.clip_plane;
    pc.options.clip_plane = Vec4(p.normal, glm::dot(p.normal, p.position));
    pc.apex = p.position + s.cone_offset * w * p.normal;
    return pc;
}

// The avx2 kernel runs only where the CPU has it; elsewhere its benchmarks say so.
bool kernel_available(benchmark::State& state, ConeKernel kernel) {
    if (kernel == ConeKernel::avx2 && best_cone_kernel() != ConeKernel::avx2) {
        state.SkipWithError("this CPU lacks AVX2, FMA or F16C: no avx2 kernel");
        return false;
    }
    return true;
}

void set_structure_label(benchmark::State& state, int structure, int threads, const std::string& more = "") {
    state.SetLabel(std::string(kStructureNames[structure]) + ", " +
                   (threads > 0 ? std::to_string(threads) + " thread(s)" : std::string("all cores")) + more);
}

// One pass over every G-buffer point's diffuse cones, cone by cone or as one fan per
// point (trace_cone_fan, as the technique traces them); returns the samples taken.
uint64_t march_all(const VoxelConeView& view, const SponzaScene& s, const ConeSet& set,
                   const std::vector<PointCones>& setup, ConeKernel kernel, bool fans) {
    std::atomic<uint64_t> samples{0};
    parallel_for(s.points.size(), 64, [&](size_t b, size_t e) {
        uint64_t local = 0;
        Vec3 sum(0);
        std::vector<Vec3> directions(set.directions.size());
        std::vector<ConeResult> results(set.directions.size());
        for (size_t i = b; i < e; ++i) {
            const Frame frame(s.points[i].normal);
            for (size_t c = 0; c < set.directions.size(); ++c) directions[c] = frame.to_world(set.directions[c]);
            if (fans) {
                trace_cone_fan(view, setup[i].apex, directions, set.tan_half_angle, setup[i].options, results, kernel);
            } else {
                for (size_t c = 0; c < set.directions.size(); ++c)
                    results[c] = trace_cone(view, Cone{setup[i].apex, directions[c], set.tan_half_angle},
                                            setup[i].options, kernel);
            }
            for (const ConeResult& r : results) {
                sum += r.radiance;
                local += uint64_t(r.samples);
            }
        }
        benchmark::DoNotOptimize(sum);
        samples += local;
    });
    return samples.load();
}

void time_march(benchmark::State& state, const VoxelConeView& view, const VctTechnique& t,
                ConeKernel kernel = best_cone_kernel(), bool fans = false) {
    const SponzaScene& s = *sponza();
    const ConeSet set = hemisphere_cones(kDiffuseCones);
    std::vector<PointCones> setup;
    for (const GbufferPoint& p : s.points) setup.push_back(cones_at(view, t.settings(), s.bounds, p));
    const uint64_t per_pass = march_all(view, s, set, setup, kernel, fans);  // warm-up, outside the timed loop
    uint64_t total = 0;
    for (auto _ : state) total += march_all(view, s, set, setup, kernel, fans);
    const double cones = double(s.points.size()) * double(set.directions.size());
    state.counters["points"] = double(s.points.size());
    state.counters["samples_per_cone"] = double(per_pass) / cones;
    state.counters["cones_per_s"] = benchmark::Counter(cones * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["samples_per_s"] = benchmark::Counter(double(total), benchmark::Counter::kIsRate);
    state.counters["s_per_sample"] =
        benchmark::Counter(double(total), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_ConeMarch(benchmark::State& state) {
    if (!need_sponza(state)) return;
    const int structure = int(state.range(0)), threads = int(state.range(1));
    const ConeKernel kernel = state.range(2) ? ConeKernel::avx2 : ConeKernel::portable;
    const bool fans = state.range(3) != 0;
    if (!kernel_available(state, kernel)) return;
    VctTechnique& t = technique(structure);
    ThreadLimit limit(threads);
    time_march(state, t.radiance_view(), t, kernel, fans);
    set_structure_label(state, structure, threads,
                        std::string(", ") + to_string(kernel) + " kernel" + (fans ? ", fans" : ", cone by cone"));
}
BENCHMARK(BM_ConeMarch)
    ->ArgsProduct({{0, 1}, {1, 0}, {0, 1}, {0, 1}})
    ->ArgNames({"structure", "threads", "kernel", "fan"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A copy of a view's radiance with each level stored face block by face block
// ([face][z][y][x], P3's Fig. 2 order within a level), and its levels pointing there.
struct FaceBlockCopy {
    std::vector<std::vector<HalfRGBA>> levels;
    VoxelConeView view;
};
FaceBlockCopy face_blocks(const VoxelConeView& view, const Vec3& anchor, bool nested) {
    FaceBlockCopy copy;
    std::vector<ConeLevel> levels;
    for (int k = 0; k < view.level_count(); ++k) {
        const ConeLevel& from = view.level(k);
        const size_t r = size_t(from.size);
        std::vector<HalfRGBA>& cells = copy.levels.emplace_back(r * r * r * kFaceCount);
        for (size_t z = 0; z < r; ++z)
            for (size_t y = 0; y < r; ++y)
                for (size_t x = 0; x < r; ++x)
                    for (int f = 0; f < kFaceCount; ++f)
                        cells[size_t(f) * r * r * r + (z * r + y) * r + x] =
                            from.data[z * from.slice_stride + y * from.row_stride + x * from.x_stride +
                                      size_t(f) * from.face_stride];
        ConeLevel to = from;
        to.data = cells.data();
        to.face_stride = r * r * r;
        to.x_stride = 1;
        to.row_stride = r;
        to.slice_stride = r * r;
        levels.push_back(to);
    }
    copy.view = VoxelConeView::of_levels(anchor, nested, std::move(levels));
    return copy;
}

void BM_ConeMarchLayout(benchmark::State& state) {
    if (!need_sponza(state)) return;
    const int structure = int(state.range(0)), layout = int(state.range(1));
    const bool skip = state.range(2) != 0;
    VctTechnique& t = technique(structure);
    ThreadLimit limit(1);
    const Vec3 anchor = structure == 0 ? Vec3(t.cascade()->config().anchor) : Vec3(t.dense()->config().anchor);
    FaceBlockCopy copy;
    VoxelConeView view = t.radiance_view();
    if (layout == 1) {
        copy = face_blocks(view, anchor, structure == 0);
        view = copy.view;
    }
    if (!skip) {
        std::vector<ConeLevel> levels;
        for (int k = 0; k < view.level_count(); ++k) {
            levels.push_back(view.level(k));
            levels.back().occupancy = nullptr;
        }
        view = VoxelConeView::of_levels(anchor, structure == 0, std::move(levels));
    }
    time_march(state, view, t);
    state.SetLabel(std::string(kStructureNames[structure]) + (layout == 0 ? ", faces together" : ", face blocks") +
                   (skip ? ", occupancy skip" : ", no skip"));
}
BENCHMARK(BM_ConeMarchLayout)
    ->ArgsProduct({{0, 1}, {0, 1}, {1, 0}})
    ->ArgNames({"structure", "layout", "skip"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Injection(benchmark::State& state) {
    if (!need_sponza(state)) return;
    const int structure = int(state.range(0)), threads = int(state.range(1));
    VctTechnique& t = technique(structure);
    const Vec3 viewer = sponza()->viewer;
    ThreadLimit limit(threads);
    double update = 0, direct = 0, bounce = 0, filter = 0, samples = 0;
    Stats stats;
    for (auto _ : state) {
        t.update_voxels(viewer);
        stats = t.stats();
        update += stats.get("update_ms");
        direct += stats.get("injection_direct_ms");
        bounce += stats.get("injection_bounce_ms");
        filter += stats.get("filter_ms");
        samples += stats.get("injection_cone_samples");
    }
    const double n = double(state.iterations());
    state.counters["voxels_lit"] = stats.get("voxels_lit");
    state.counters["faces_lit"] = stats.get("injection_faces_lit");
    state.counters["bounce_cones"] = stats.get("injection_cones_traced");
    state.counters["bounce_samples"] = stats.get("injection_cone_samples");
    state.counters["update_ms"] = update / n;
    state.counters["direct_ms"] = direct / n;
    state.counters["bounce_ms"] = bounce / n;
    state.counters["filter_ms"] = filter / n;
    state.counters["bounce_samples_per_s"] = bounce > 0 ? samples / (bounce * 1e-3) : 0.0;
    state.counters["samples_per_s"] = benchmark::Counter(samples, benchmark::Counter::kIsRate);
    set_structure_label(state, structure, threads);
}
BENCHMARK(BM_Injection)
    ->ArgsProduct({{0, 1}, {1, 0}})
    ->ArgNames({"structure", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_AnisotropicFilter(benchmark::State& state) {
    if (!need_sponza(state)) return;
    const int structure = int(state.range(0)), threads = int(state.range(1));
    VctTechnique& t = technique(structure);
    ThreadLimit limit(threads);
    double cells = 0;  // coarse cells written per pass, each from 8 finer ones
    if (const CascadedVoxelTexture* c = t.cascade()) {
        std::vector<HalfRGBA> buffer = c->radiance;  // each pass rewrites the same values
        for (int k = 1; k < c->levels(); ++k) cells += double(c->inner_box(k).volume()) * kFaceCount;
        for (auto _ : state) {
            for (int k = 1; k < c->levels(); ++k) c->downsample(k, buffer);
            benchmark::DoNotOptimize(buffer.data());
        }
    } else {
        const DenseMipTexture& d = *t.dense();
        std::vector<std::vector<HalfRGBA>> buffer = d.radiance;
        for (int k = 1; k < d.level_count(); ++k) cells += double(d.cells(k));
        for (auto _ : state) {
            d.build_mips(buffer);
            benchmark::DoNotOptimize(buffer.back().data());
        }
    }
    const double n = double(state.iterations());
    state.counters["cells"] = cells;
    state.counters["cells_per_s"] = benchmark::Counter(cells * n, benchmark::Counter::kIsRate);
    // Eight finer cells read and one written per coarse cell.
    state.counters["bytes_per_s"] = benchmark::Counter(cells * n * 9.0 * sizeof(HalfRGBA), benchmark::Counter::kIsRate);
    set_structure_label(state, structure, threads);
}
BENCHMARK(BM_AnisotropicFilter)
    ->ArgsProduct({{0, 1}, {1, 0}})
    ->ArgNames({"structure", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One thread. Pattern 0: positions within one finest voxel's neighbourhood (every
// texel in L1); 1: scattered over the finest level's region; 2: scattered over every
// level's region (cascades: a random level, dense: a random mip level).
void BM_SampleLevel(benchmark::State& state) {
    if (!need_sponza(state)) return;
    const int structure = int(state.range(0)), pattern = int(state.range(1));
    const bool with_plane = state.range(2) != 0;
    const ConeKernel kernel = state.range(3) ? ConeKernel::avx2 : ConeKernel::portable;
    if (!kernel_available(state, kernel)) return;
    VctTechnique& t = technique(structure);
    const VoxelConeView view = t.radiance_view();
    const Vec3 centre = sponza()->points[sponza()->points.size() / 2].position;
    constexpr size_t kCount = size_t(1) << 16;
    std::vector<int> level(kCount);
    std::vector<Vec3> position(kCount);
    std::vector<FaceWeights> faces(kCount);
    std::vector<Vec4> plane(kCount);
    Rng rng(7, 1);
    const Vec3 anchor = structure == 0 ? Vec3(t.cascade()->config().anchor) : Vec3(t.dense()->config().anchor);
    for (size_t i = 0; i < kCount; ++i) {
        int k = 0;
        if (pattern == 2) k = std::min(int(rng.uniform() * float(view.level_count())), view.level_count() - 1);
        const ConeLevel& l = view.level(k);
        Vec3 p;
        if (pattern == 0) {
            p = centre + (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f)) * (2.0f * l.voxel_size);
        } else {
            const Vec3 u(rng.uniform(), rng.uniform(), rng.uniform());
            p = anchor + (Vec3(l.origin) + u * float(l.size)) * l.voxel_size;
        }
        level[i] = k;
        position[i] = p;
        const Vec3 d = glm::normalize(Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - Vec3(0.5f) + Vec3(1e-3f));
        faces[i] = faces_seen_along(d);
        // A surface half a voxel behind the sample, facing along the cone: the plane cuts
        // some of the eight voxels, as it does for the first samples of a cone.
        plane[i] = Vec4(d, glm::dot(d, p) - 0.5f * l.voxel_size);
    }
    Vec4 sum(0);
    for (auto _ : state) {
        for (size_t i = 0; i < kCount; ++i)
            sum += view.sample_level(level[i], position[i], faces[i], with_plane ? &plane[i] : nullptr, kernel);
        benchmark::DoNotOptimize(sum);
    }
    const double n = double(state.iterations()) * double(kCount);
    state.counters["samples_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
    state.counters["s_per_sample"] = benchmark::Counter(n, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    static const char* const kPatterns[] = {"one voxel", "finest level", "every level"};
    state.SetLabel(std::string(kStructureNames[structure]) + ", " + kPatterns[pattern] +
                   (with_plane ? ", clip plane" : "") + ", " + to_string(kernel) + " kernel");
}
BENCHMARK(BM_SampleLevel)
    ->ArgsProduct({{0, 1}, {0, 1, 2}, {0, 1}, {0, 1}})
    ->ArgNames({"structure", "pattern", "plane", "kernel"})
    ->Unit(benchmark::kMicrosecond);

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// One precomputed sample for BM_TexelFloor: the cells of the lower and upper voxel along
// x of its four (y, z) corners, its three faces, and its weights.
struct FloorSample {
    int lower[4], upper[4];
    int face[3];
    float wzy[4], wx[2], face_weight[3];
};

__attribute__((target("avx2,fma,f16c"))) float texel_floor_pass(const HalfRGBA* cells,
                                                                const std::vector<FloorSample>& samples) {
    __m128 total = _mm_setzero_ps();
    for (const FloorSample& s : samples) {
        const __m256 wx = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_set1_ps(s.wx[0])), _mm_set1_ps(s.wx[1]), 1);
        __m256 acc[3] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
        for (int j = 0; j < 4; ++j) {
            const __m256 w = _mm256_mul_ps(_mm256_set1_ps(s.wzy[j]), wx);
            for (int f = 0; f < 3; ++f) {
                const HalfRGBA* face = cells + s.face[f];
                const __m128 low = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(face + s.lower[j])));
                const __m128 both = _mm_loadh_pi(low, reinterpret_cast<const __m64*>(face + s.upper[j]));
                acc[f] = _mm256_fmadd_ps(_mm256_cvtph_ps(_mm_castps_si128(both)), w, acc[f]);
            }
        }
        __m256 sum = _mm256_mul_ps(acc[0], _mm256_set1_ps(s.face_weight[0]));
        sum = _mm256_fmadd_ps(acc[1], _mm256_set1_ps(s.face_weight[1]), sum);
        sum = _mm256_fmadd_ps(acc[2], _mm256_set1_ps(s.face_weight[2]), sum);
        total = _mm_add_ps(total, _mm_add_ps(_mm256_castps256_ps128(sum), _mm256_extractf128_ps(sum, 1)));
    }
    return _mm_cvtss_f32(total);
}

// One thread; samples scattered over one 32³ level of six faces (1.5 MiB, the cascades'
// level size) or over a 4³ block of it (every texel in L1).
void BM_TexelFloor(benchmark::State& state) {
    if (best_cone_kernel() != ConeKernel::avx2) {
        state.SkipWithError("this CPU lacks AVX2, FMA or F16C");
        return;
    }
    const int span = int(state.range(0));
    constexpr int kR = 32;
    std::vector<HalfRGBA> cells(size_t(kR) * kR * kR * kFaceCount);
    Rng rng(5, 3);
    for (HalfRGBA& c : cells) c = to_half_rgba(Vec4(rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()));
    std::vector<FloorSample> samples(size_t(1) << 16);
    auto cell = [](int x, int y, int z) { return ((z * kR + y) * kR + x) * kFaceCount; };
    for (FloorSample& s : samples) {
        int v[3];
        for (int& c : v) c = std::min(int(rng.uniform() * float(span - 1)), span - 2);
        for (int j = 0; j < 4; ++j) {
            s.lower[j] = cell(v[0], v[1] + (j & 1), v[2] + (j >> 1));
            s.upper[j] = s.lower[j] + kFaceCount;
        }
        for (int a = 0; a < 3; ++a) {
            s.face[a] = 2 * a + (rng.uniform() < 0.5f ? 1 : 0);
            s.face_weight[a] = rng.uniform();
        }
        for (float& w : s.wzy) w = rng.uniform();
        s.wx[0] = rng.uniform();
        s.wx[1] = 1.0f - s.wx[0];
    }
    benchmark::DoNotOptimize(texel_floor_pass(cells.data(), samples));  // warm-up
    for (auto _ : state) benchmark::DoNotOptimize(texel_floor_pass(cells.data(), samples));
    const double n = double(state.iterations()) * double(samples.size());
    state.counters["s_per_sample"] = benchmark::Counter(n, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.SetLabel(span == kR ? "one 32³ level (1.5 MiB)" : "a " + std::to_string(span) + "³ block (L1)");
}
BENCHMARK(BM_TexelFloor)->Arg(4)->Arg(32)->ArgName("span")->Unit(benchmark::kMicrosecond);
#endif

void BM_ReadBandwidth(benchmark::State& state) {
    const size_t bytes = size_t(state.range(0)) << 10;
    const int threads = int(state.range(1));
    ThreadLimit limit(threads);
    std::vector<uint64_t> buffer(bytes / sizeof(uint64_t));
    for (size_t i = 0; i < buffer.size(); ++i) buffer[i] = i;
    // Each task sums its part of the buffer; four independent sums keep the adds off the
    // critical path, so the loads set the pace.
    auto pass = [&] {
        std::atomic<uint64_t> total{0};
        parallel_for(buffer.size(), buffer.size() / 64 + 1, [&](size_t b, size_t e) {
            uint64_t s0 = 0, s1 = 0, s2 = 0, s3 = 0;
            size_t i = b;
            for (; i + 4 <= e; i += 4) {
                s0 += buffer[i];
                s1 += buffer[i + 1];
                s2 += buffer[i + 2];
                s3 += buffer[i + 3];
            }
            for (; i < e; ++i) s0 += buffer[i];
            total += s0 + s1 + s2 + s3;
        });
        return total.load();
    };
    benchmark::DoNotOptimize(pass());  // warm-up: pages touched, caches filled
    for (auto _ : state) benchmark::DoNotOptimize(pass());
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(bytes));
    state.SetLabel(std::to_string(bytes >> 10) + " KiB, " +
                   (threads > 0 ? std::to_string(threads) + " thread(s)" : std::string("all cores")));
}
BENCHMARK(BM_ReadBandwidth)
    ->ArgsProduct({{1536, 256 << 10}, {1, 0}})
    ->ArgNames({"kib", "threads"})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace
