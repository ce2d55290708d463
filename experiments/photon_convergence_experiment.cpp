// pm-convergence: image error against wall time for the photon technique with a fixed
// radius (several photon counts), its progressive mode (SPPM, several iteration counts)
// and the path tracer (several spp), on the Cornell box and the conference room, all in
// one run at one thread count. Error is the relative MSE of the color layer against a
// jittered path-traced reference with many samples; wall time is what each variant spends
// making its image once the scene's ray-tracing structure exists (photon tracing and map
// building included), so the scene load, the same for all, is left out.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/image_metrics.hpp"
#include "core/settings.hpp"
#include "core/stats.hpp"
#include "experiments/experiment.hpp"
#include "experiments/path_reference.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace {

using nlohmann::json;

// The relMSE levels whose reaching time the second table gives.
const double kTargets[] = {0.002, 0.001, 0.0005};

// The fixed radius on the Cornell box (about one unit wide); other scenes scale it with
// their bounding-box diagonal.
constexpr double kCornellRadius = 0.05;

struct Sizes {
    int size;                           // image side, pixels
    int reference_spp;                  // per scene below; the conference room's is lower
    int conference_reference_spp;
    std::vector<int> fixed_photons;     // (a) photons emitted, fixed radius
    int fixed_spp;
    std::vector<int> iterations;        // (b) progressive iterations
    int photons_per_iteration;
    std::vector<int> path_spp;          // (c)
};

Sizes sizes_for(bool quick) {
    if (quick) return {48, 1024, 512, {4096, 16384}, 4, {2, 8, 32}, 4096, {4, 16, 64}};
    return {256, 4096, 1024, {16384, 65536, 262144, 1048576}, 16, {4, 16, 64, 256}, 16384, {16, 64, 256, 1024}};
}

double diagonal(const Scene& scene) {
    const Bounds3 b = scene.evaluate(0).bounds;
    return double(glm::length(b.max - b.min));
}

struct Point {
    std::string variant, setting;
    double ms = 0, relmse = 0;
    json photons = nullptr;
    json mean_radius = nullptr;
};

// The photon pass prepare() made: only the fixed-radius photon map is traced and built
// there (the progressive mode traces each iteration inside render(), the path tracer
// traces no photons), so the others have none to charge.
double photon_pass_ms(const Stats& prepared) {
    if (!prepared.has("photon_trace_ms")) return 0;
    return prepared.get("photon_trace_ms") + prepared.get("photon_build_ms");
}

// Renders one variant and measures it (see the file comment for what the time covers).
Point measure(const Scene& scene, const EyeCamera& camera, const Film& reference, const std::string& technique,
              const json& settings_json) {
    auto t = TechniqueRegistry::builtin().create(technique);
    Settings settings(settings_json, "pm-convergence settings");
    t->prepare(scene, settings);
    settings.report_unused();
    const Stats prepared = t->stats();
    std::vector<Film> films;
    Stopwatch watch;
    t->render(ViewSet::mono(camera), films);
    Point p;
    p.ms = watch.elapsed_ms() + photon_pass_ms(prepared);
    p.relmse = relative_mse(films.at(0), reference, "color");
    const Stats rendered = t->stats();
    if (technique == "photon") p.photons = rendered.get("photons_emitted");
    if (settings_json.value("progressive", false)) p.mean_radius = rendered.get("mean_final_radius");
    return p;
}

// The time at which a curve first reaches `target`, interpolated between the measured
// points around the crossing in log–log; null when it never does.
json time_to_reach(std::vector<Point> curve, double target) {
    std::sort(curve.begin(), curve.end(), [](const Point& a, const Point& b) { return a.ms < b.ms; });
    for (size_t i = 0; i < curve.size(); ++i) {
        if (!(curve[i].relmse <= target)) continue;
        if (i == 0) return "≤ " + format_number(curve[0].ms) + " (first point)";
        const Point& a = curve[i - 1];
        const Point& b = curve[i];
        const double f = (std::log(target) - std::log(a.relmse)) / (std::log(b.relmse) - std::log(a.relmse));
        return std::exp(std::log(a.ms) + f * (std::log(b.ms) - std::log(a.ms)));
    }
    return "not reached";
}

std::string target_column(double target) {
    std::ostringstream s;
    s << "ms to relMSE " << target;
    return s.str();
}

ExperimentOutput run(const ExperimentContext& ctx) {
    ExperimentOutput out;
    const Sizes z = sizes_for(ctx.quick);
    struct Named {
        std::string name;
        Scene scene;
        int reference_spp;
    };
    std::vector<Named> scenes;
    scenes.push_back({"cornell", make_cornell_box(), z.reference_spp});
    try {
        scenes.push_back({"conference", open_scene("conference", ctx.assets).scene, z.conference_reference_spp});
    } catch (const Error& e) {
        out.notes.push_back(std::string("conference skipped: ") + e.what());
        ctx.say(std::string("skipping conference: ") + e.what());
    }
    const double cornell_diagonal = diagonal(scenes.front().scene);

    ResultTable table{"relMSE (color) against a path-traced reference vs wall time",
                      {"scene", "variant", "setting", "wall ms", "relMSE", "photons emitted", "mean final radius"},
                      {}};
    ResultTable reach{"Time to reach a relMSE (interpolated in log–log between measured points)",
                      {"scene", "variant"},
                      {}};
    for (double target : kTargets) reach.columns.push_back(target_column(target));
    json scene_config = json::object();

    for (const Named& named : scenes) {
        const Scene& scene = named.scene;
        if (!scene.camera) throw Error("pm-convergence", named.name + " has no camera");
        const SceneCamera& c = *scene.camera;
        const EyeCamera camera = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, z.size, z.size);
        const Film reference = path_reference(ctx, scene, camera, named.reference_spp, out.files, /*jitter=*/true);
        const double radius = kCornellRadius * diagonal(scene) / cornell_diagonal;
        scene_config[named.name] = {{"resolution", {z.size, z.size}}, {"reference_spp", named.reference_spp},
                                    {"radius", radius}};
        out.notes.push_back(named.name + ": reference = path tracer, " + std::to_string(named.reference_spp) +
                            " jittered spp at " + std::to_string(z.size) + "², max depth 8, on a seed of its own (no variant "
                            "shares its samples); its own noise is a floor under every measured relMSE.");

        std::map<std::string, std::vector<Point>> curves;
        auto record = [&](Point p) {
            ctx.say(named.name + " " + p.variant + " " + p.setting + ": " + format_number(p.ms) + " ms, relMSE " +
                    format_number(p.relmse));
            table.rows.push_back({{"scene", named.name}, {"variant", p.variant}, {"setting", p.setting},
                                  {"wall ms", p.ms}, {"relMSE", p.relmse}, {"photons emitted", p.photons},
                                  {"mean final radius", p.mean_radius}});
            curves[p.variant].push_back(p);
        };
        const std::string fixed = "photon r fixed, spp " + std::to_string(z.fixed_spp);
        for (int photons : z.fixed_photons) {
            Point p = measure(scene, camera, reference, "photon",
                              {{"photons", photons}, {"radius", radius}, {"spp", z.fixed_spp}, {"seed", ctx.seed}});
            p.variant = fixed, p.setting = std::to_string(photons) + " photons";
            record(p);
        }
        const std::string progressive = "photon progressive";
        for (int iterations : z.iterations) {
            Point p = measure(scene, camera, reference, "photon",
                              {{"progressive", true}, {"iterations", iterations}, {"photons", z.photons_per_iteration},
                               {"radius", radius}, {"seed", ctx.seed}});
            p.variant = progressive, p.setting = std::to_string(iterations) + " iterations";
            record(p);
        }
        const std::string path = "path";
        for (int spp : z.path_spp) {
            Point p = measure(scene, camera, reference, "path", {{"spp", spp}, {"seed", ctx.seed}, {"max_depth", 8}});
            p.variant = path, p.setting = std::to_string(spp) + " spp";
            record(p);
        }

        Plot plot;
        plot.title = named.name + ": relMSE vs wall time";
        plot.x_label = "wall time (ms)";
        plot.y_label = "relMSE (color)";
        plot.log_x = plot.log_y = true;
        for (const std::string& variant : {fixed, progressive, path}) {
            PlotSeries series;
            series.label = variant;
            json row = {{"scene", named.name}, {"variant", variant}};
            std::vector<Point> curve = curves[variant];
            std::sort(curve.begin(), curve.end(), [](const Point& a, const Point& b) { return a.ms < b.ms; });
            for (const Point& p : curve) series.x.push_back(p.ms), series.y.push_back(p.relmse);
            for (double target : kTargets) row[target_column(target)] = time_to_reach(curve, target);
            reach.rows.push_back(row);
            plot.series.push_back(series);
        }
        out.plots.push_back({"convergence_" + named.name, plot});
    }
    out.tables.push_back(table);
    out.tables.push_back(reach);
    out.config["scenes"] = scene_config;
    out.config["fixed_radius"] = {{"photons", z.fixed_photons}, {"spp", z.fixed_spp}, {"jitter", true}};
    out.config["progressive"] = {{"iterations", z.iterations}, {"photons_per_iteration", z.photons_per_iteration},
                                 {"alpha", 2.0 / 3.0}, {"initial_radius", "the fixed radius"}};
    out.config["path"] = {{"spp", z.path_spp}, {"max_depth", 8}, {"jitter", true}};
    out.config["photon_storage"] = "indirect";
    out.notes.push_back("Both photon variants store photons from their second hit on and take direct light from "
                        "shadow rays (photon_storage=indirect, one light sample per visible point); the progressive "
                        "radius starts at the fixed radius and shrinks with alpha = 2/3.");
    out.notes.push_back("Wall time: render() plus, for the fixed-radius photon map, its photon tracing and map "
                        "building in prepare(); the scene's ray-tracing structure (built by every technique alike) is "
                        "left out. One run per point, at the run's thread count.");
    out.notes.push_back("Time to reach: the first crossing of the target on the measured curve; \"≤ t (first "
                        "point)\" when the cheapest point is already below it, \"not reached\" when no point is.");
    return out;
}

}  // namespace

Experiment photon_convergence_experiment() {
    return {"pm-convergence", "P1",
            "relMSE vs wall time: photon mapping with a fixed radius (photon counts), progressive photon mapping "
            "(iterations) and the path tracer (spp) on the Cornell box and the conference room",
            run};
}

}  // namespace gilab
