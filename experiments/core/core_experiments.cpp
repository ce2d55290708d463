// Experiments on the shared core: ray-tracing throughput of the Embree backend.
#include <algorithm>
#include "core/scene/camera.hpp"
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/experiment.hpp"
#include "scenes/scene_library.hpp"

namespace gilab {

namespace {

EyeCamera camera_for(const Scene& scene, int width, int height) {
    SceneCamera c = scene.camera.value_or(default_camera_for(scene.evaluate(0).bounds));
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, width, height);
}

// Where shadow rays go: the first punctual light, else the centroid of the emitters.
struct ShadowTarget {
    bool directional = false;
    Vec3 point_or_direction{0};
};

ShadowTarget shadow_target(const Scene& scene, const SceneFrame& frame) {
    ShadowTarget target;
    if (!frame.lights.empty()) {
        const PunctualLight& l = frame.lights.front();
        target.directional = l.type == LightType::Directional;
        target.point_or_direction = target.directional ? -l.direction : l.position;
        return target;
    }
    Vec3 sum(0);
    float count = 0;
    for (const WorldMesh& m : frame.meshes)
        for (size_t i = 0; i < m.triangles.size(); ++i)
            if (scene.materials[m.material_ids[i]].is_emissive()) {
                const UVec3& t = m.triangles[i];
                sum += (m.positions[t.x] + m.positions[t.y] + m.positions[t.z]) / 3.0f;
                count += 1;
            }
    target.point_or_direction = count > 0 ? sum / count : frame.bounds.max;
    return target;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

struct Throughput {
    double single_mrays = 0, stream_mrays = 0;
    size_t rays = 0;
};

// Times `trace_tile` over every tile, `repeats` times, and returns the median Mrays/s.
template <typename TraceTile>
double measure(const std::vector<Tile>& tiles, size_t rays, int repeats, TraceTile trace_tile) {
    std::vector<double> rates;
    for (int r = 0; r < repeats; ++r) {
        Stopwatch watch;
        parallel_for(tiles.size(), 1, [&](size_t b, size_t e) {
            for (size_t i = b; i < e; ++i) trace_tile(tiles[i]);
        });
        rates.push_back(double(rays) / (watch.elapsed_ms() * 1e3));
    }
    return median(rates);
}

ExperimentOutput run_core_rays(const ExperimentContext& ctx) {
    const int size = ctx.quick ? 256 : 1024;
    const int repeats = ctx.quick ? 3 : 7;
    const int tile = 16;
    ResultTable table;
    table.title = "Embree ray throughput, " + std::to_string(size) + "² primary rays from the scene camera";
    table.columns = {"scene", "triangles", "bvh_build_ms", "ray_kind", "rays", "single_mrays_per_s",
                     "stream_mrays_per_s", "stream_over_single", "hit_fraction"};
    ExperimentOutput out;
    std::vector<std::string> scenes = {"cornell", "bunny", "sponza"};
    out.config = {{"resolution", size}, {"repeats", repeats}, {"tile", tile}, {"scenes", scenes},
                  {"statistic", "median over repeats"}};

    std::vector<Tile> tiles;
    for (int y = 0; y < size; y += tile)
        for (int x = 0; x < size; x += tile) tiles.push_back({x, y, std::min(x + tile, size), std::min(y + tile, size)});

    for (const std::string& name : scenes) {
        Scene scene;
        try {
            scene = open_scene(name, ctx.assets).scene;
        } catch (const Error& e) {
            out.notes.push_back("scene '" + name + "' skipped: " + std::string(e.what()));
            ctx.say("skipping " + name + ": " + e.what());
            continue;
        }
        ctx.say("scene " + name + ": " + std::to_string(scene.triangle_count()) + " triangles");
        SceneFrame frame = scene.evaluate(0);
        Stopwatch build;
        RayTracer tracer(frame);
        double build_ms = build.elapsed_ms();
        EyeCamera camera = camera_for(scene, size, size);
        ShadowTarget target = shadow_target(scene, frame);
        float scale = std::max(1e-4f, 1e-5f * glm::length(frame.bounds.extent()));

        // Primary rays, and for each hit one shadow ray towards the light.
        const size_t n = size_t(size) * size_t(size);
        std::vector<Ray> primary(n), shadow(n);
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) primary[size_t(y) * size + x] = camera.generate_ray(x + 0.5f, y + 0.5f);
        std::vector<Hit> hits(n);
        tracer.intersect(primary, hits);
        size_t hit_count = 0;
        for (size_t i = 0; i < n; ++i) {
            Ray s;
            if (!hits[i].valid()) {  // a ray that left the scene still casts a (trivial) shadow ray
                s.origin = primary[i].origin;
                s.direction = Vec3(0, 1, 0);
                s.tmax = 0.0f;
            } else {
                ++hit_count;
                Vec3 p = primary[i].at(hits[i].t) - scale * primary[i].direction;
                s.origin = p;
                if (target.directional) {
                    s.direction = target.point_or_direction;
                } else {
                    s.direction = target.point_or_direction - p;
                    s.tmax = 1.0f - 1e-3f;
                }
            }
            shadow[i] = s;
        }

        auto tile_indices = [&](const Tile& t, auto&& fn) {
            for (int y = t.y0; y < t.y1; ++y)
                for (int x = t.x0; x < t.x1; ++x) fn(size_t(y) * size + x);
        };
        for (int kind = 0; kind < 2; ++kind) {
            const std::vector<Ray>& rays = kind == 0 ? primary : shadow;
            double single = measure(tiles, n, repeats, [&](const Tile& t) {
                tile_indices(t, [&](size_t i) {
                    if (kind == 0) (void)tracer.intersect(rays[i]);
                    else (void)tracer.occluded(rays[i]);
                });
            });
            double stream = measure(tiles, n, repeats, [&](const Tile& t) {
                std::vector<Ray> batch;
                batch.reserve(size_t(tile * tile));
                tile_indices(t, [&](size_t i) { batch.push_back(rays[i]); });
                if (kind == 0) {
                    std::vector<Hit> h(batch.size());
                    tracer.intersect(batch, h);
                } else {
                    std::vector<uint8_t> b(batch.size());
                    tracer.occluded(batch, b);
                }
            });
            table.rows.push_back({{"scene", name},
                                  {"triangles", scene.triangle_count()},
                                  {"bvh_build_ms", build_ms},
                                  {"ray_kind", kind == 0 ? "primary (closest hit)" : "shadow (occlusion)"},
                                  {"rays", n},
                                  {"single_mrays_per_s", single},
                                  {"stream_mrays_per_s", stream},
                                  {"stream_over_single", stream / single},
                                  {"hit_fraction", double(hit_count) / double(n)}});
        }
    }
    if (table.rows.empty()) throw Error("core-rays", "no scene could be loaded");
    out.tables.push_back(std::move(table));
    out.notes.push_back("single = one rtcIntersect1/rtcOccluded1 call per ray; stream = one rtcIntersect1M/rtcOccluded1M "
                        "call per 16×16 tile (coherent flag). Both use all threads, same tiles.");
    return out;
}

}  // namespace

void register_core_experiments(ExperimentRegistry& registry) {
    registry.add({"core-rays", "core", "primary and shadow ray throughput, single rays vs streams (Embree 3)",
                  run_core_rays});
}

}  // namespace gilab
