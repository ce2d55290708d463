// Experiments on the shared core: ray-tracing throughput of the Embree backend.
#include <algorithm>
#include "core/scene/camera.hpp"
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/measures.hpp"
#include "experiments/runner/spec_functions.hpp"
#include "scenes/scene_library.hpp"

namespace gilab {

namespace {

using nlohmann::json;

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

std::vector<Tile> image_tiles(int size, int tile) {
    std::vector<Tile> tiles;
    for (int y = 0; y < size; y += tile)
        for (int x = 0; x < size; x += tile) tiles.push_back({x, y, std::min(x + tile, size), std::min(y + tile, size)});
    return tiles;
}

// Primary rays through every pixel centre, and for each hit one shadow ray towards the
// light (a ray that left the scene still casts a trivial one, so both sets are as large).
struct RaySets {
    std::vector<Ray> primary, shadow;
    size_t hits = 0;
};

RaySets trace_setup(const Scene& scene, const SceneFrame& frame, const RayTracer& tracer, int size) {
    const EyeCamera camera = camera_for(scene, size, size);
    const ShadowTarget target = shadow_target(scene, frame);
    const float scale = std::max(1e-4f, 1e-5f * glm::length(frame.bounds.extent()));
    const size_t n = size_t(size) * size_t(size);
    RaySets sets;
    sets.primary.resize(n);
    sets.shadow.resize(n);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) sets.primary[size_t(y) * size + x] = camera.generate_ray(x + 0.5f, y + 0.5f);
    std::vector<Hit> hits(n);
    tracer.intersect(sets.primary, hits);
    for (size_t i = 0; i < n; ++i) {
        Ray s;
        if (!hits[i].valid()) {
            s.origin = sets.primary[i].origin;
            s.direction = Vec3(0, 1, 0);
            s.tmax = 0.0f;
        } else {
            ++sets.hits;
            Vec3 p = sets.primary[i].at(hits[i].t) - scale * sets.primary[i].direction;
            s.origin = p;
            if (target.directional) {
                s.direction = target.point_or_direction;
            } else {
                s.direction = target.point_or_direction - p;
                s.tmax = 1.0f - 1e-3f;
            }
        }
        sets.shadow[i] = s;
    }
    return sets;
}

// core-rays, one scene: the primary and the shadow rays, each traced one call per ray and
// one stream call per tile, every pass timed `frames` times.
ProbeOutput ray_throughput(const ProbeCall& call) {
    ProbeOutput out;
    const Scene* loaded = nullptr;
    try {
        loaded = &call.scene();
    } catch (const Error& e) {
        out.notes.push_back("scene '" + call.task.scene + "' skipped: " + std::string(e.what()));
        call.ctx.say("skipping " + call.task.scene + ": " + e.what());
        return out;
    }
    const Scene& scene = *loaded;
    const int size = call.size, repeats = call.frames, tile = call.setting<int>("tile");
    call.ctx.say("scene " + call.task.scene + ": " + std::to_string(scene.triangle_count()) + " triangles");
    const SceneFrame frame = scene.evaluate(0);
    Stopwatch build;
    const RayTracer tracer(frame);
    const double build_ms = build.elapsed_ms();
    const RaySets sets = trace_setup(scene, frame, tracer, size);
    const std::vector<Tile> tiles = image_tiles(size, tile);
    const size_t n = sets.primary.size();

    auto tile_indices = [&](const Tile& t, auto&& fn) {
        for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x) fn(size_t(y) * size + x);
    };
    for (int kind = 0; kind < 2; ++kind) {
        const std::vector<Ray>& rays = kind == 0 ? sets.primary : sets.shadow;
        const double single = measure(tiles, n, repeats, [&](const Tile& t) {
            tile_indices(t, [&](size_t i) {
                if (kind == 0) (void)tracer.intersect(rays[i]);
                else (void)tracer.occluded(rays[i]);
            });
        });
        const double stream = measure(tiles, n, repeats, [&](const Tile& t) {
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
        out.rows.push_back({{"triangles", scene.triangle_count()},
                            {"bvh_build_ms", build_ms},
                            {"ray_kind", kind == 0 ? "primary (closest hit)" : "shadow (occlusion)"},
                            {"rays", n},
                            {"single_mrays_per_s", single},
                            {"stream_mrays_per_s", stream},
                            {"stream_over_single", stream / single},
                            {"hit_fraction", double(sets.hits) / double(n)}});
    }
    return out;
}

// The scenes' rows in one table titled with this run's image size.
ExperimentOutput ray_throughput_table(const SpecReduction& r) {
    ResultTable table;
    table.title = "Embree ray throughput, " + std::to_string(r.size()) + "² primary rays from the scene camera";
    table.columns = {"scene", "triangles", "bvh_build_ms", "ray_kind", "rays", "single_mrays_per_s",
                     "stream_mrays_per_s", "stream_over_single", "hit_fraction"};
    for (const TaskResult& t : r.tasks)
        for (const json& measured : t.rows) {
            json row = {{"scene", t.task.scene}};
            for (const std::string& c : table.columns)
                if (measured.contains(c)) row[c] = measured[c];
            table.rows.push_back(std::move(row));
        }
    if (table.rows.empty()) throw Error("core-rays", "no scene could be loaded");
    ExperimentOutput out;
    out.tables.push_back(std::move(table));
    return out;
}

}  // namespace

void register_core_experiments(ExperimentRegistry& registry) {
    add_probe("core-rays", ray_throughput);
    add_reducer("core-rays", ray_throughput_table);
    registry.add(declared_experiment({
        .name = "core-rays",
        .paper = "core",
        .figure = "Ray throughput",
        .description = "primary and shadow ray throughput, single rays vs streams (Embree 3)",
        .scenes = {"cornell", "bunny", "sponza"},
        .size = 1024, .quick_size = 256,  // primary rays: one per pixel of a square image
        .frames = 7, .quick_frames = 3,   // timed passes over all rays; the median counts
        .variants = {{.name = "embree", .probe = "core-rays", .settings = {{"tile", 16}}}},
        .reducer = "core-rays",
        .notes = {"single = one rtcIntersect1/rtcOccluded1 call per ray; stream = one rtcIntersect1M/rtcOccluded1M "
                  "call per 16×16 tile (coherent flag). Both use all threads, same tiles.",
                  "Mrays/s = the median over the repeated passes (the spec's frames) of all rays of one kind; shadow "
                  "rays go from each primary hit towards the first punctual light (else the emitters' centroid), a "
                  "miss casts a trivial one."},
    }));
}

}  // namespace gilab
