// pm-convergence: image error against wall time for the photon technique with a fixed
// radius (several photon counts), its progressive mode (SPPM, several iteration counts)
// and the path tracer (several spp), on the Cornell box and the conference room, all in
// one run at one thread count. Each point of a curve is one task; the reducer draws the
// curves, the times to reach the targets and their slopes. Error is the relative MSE of the color layer against a
// jittered path-traced reference with many samples; wall time is what each variant spends
// making its image once the scene's ray-tracing structure exists (photon tracing and map
// building included), so the scene load, the same for all, is left out. The reference is
// the mean of two path-traced halves on independent seeds; their difference estimates
// the noise it adds to every error, and errors below that estimate are left blank.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/image/image_metrics.hpp"
#include "core/util/settings.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/path_reference.hpp"
#include "experiments/runner/spec_functions.hpp"
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

double diagonal(const Scene& scene) {
    const Bounds3 b = scene.evaluate(0).bounds;
    return double(glm::length(b.max - b.min));
}

// The photon pass prepare() made: only the fixed-radius photon map is traced and built
// there (the progressive mode traces each iteration inside render(), the path tracer
// traces no photons), so the others have none to charge.
double photon_pass_ms(const Stats& prepared) {
    if (!prepared.has("photon_trace_ms")) return 0;
    return prepared.get("photon_trace_ms") + prepared.get("photon_build_ms");
}

// A reference and the noise it adds to every relMSE measured against it.
struct NoisyReference {
    Film image;    // the mean of the two halves
    double noise;  // estimated relMSE of `image` against the noise-free image
    std::vector<std::string> files;
};

// The second half's seed: independent of the first half's and of the run's.
uint64_t second_half_seed(uint64_t run_seed) { return reference_seed(run_seed) ^ 0x48414c46ull; }

// Samples per pixel of each reference half, for the task's plan and scene.
int reference_spp_per_half(const ProbeCall& call) {
    return call.setting<json>("reference_spp_per_half").at(call.ctx.quick ? "quick" : "full").at(call.task.scene).get<int>();
}

// A task's reference halves A and B, jittered, at the scene camera and the run's size:
// A on the reference's seed, B on second_half_seed. None when the scene cannot be loaded
// (the probe notes the skip).
std::vector<ReferenceView> point_references(const ProbeCall& call) {
    const Scene* scene = call.scene_or_null();
    if (!scene) return {};
    if (!scene->camera) throw Error("pm-convergence", call.task.scene + " has no camera");
    const SceneCamera& c = *scene->camera;
    const EyeCamera camera = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, call.size, call.size);
    const int spp_per_half = reference_spp_per_half(call);
    return {ReferenceView{scene, camera, spp_per_half, /*jitter=*/true},
            ReferenceView{scene, camera, spp_per_half, /*jitter=*/true, second_half_seed(call.ctx.seed)}};
}

// The two halves A and B (point_references; each cached like every reference), averaged:
// R = (A + B) / 2. A pixel's error of R has variance σ²/2 where σ² is one half's, and
// E[((A − B) / 2)²] = σ²/2 too, so the relMSE of R + (A − B) / 2 against R estimates the
// relMSE R's own noise adds to any error measured against it.
NoisyReference noisy_reference(const ExperimentContext& ctx, const std::vector<ReferenceView>& halves) {
    NoisyReference r;
    const Film a = path_reference(ctx, halves.at(0), r.files);
    const Film b = path_reference(ctx, halves.at(1), r.files);
    Film mean(a.width(), a.height()), off_by_noise(a.width(), a.height());
    const auto& da = a.layer("color").data;
    const auto& db = b.layer("color").data;
    auto& m = mean.layer("color").data;
    auto& o = off_by_noise.layer("color").data;
    for (size_t i = 0; i < da.size(); ++i) {
        m[i] = 0.5f * (da[i] + db[i]);
        o[i] = m[i] + 0.5f * (da[i] - db[i]);
    }
    r.noise = relative_mse(off_by_noise, mean, "color");
    r.image = std::move(mean);
    return r;
}

// What a point spends and how it is labelled: photons (fixed radius), iterations
// (progressive) or spp (path tracer).
std::pair<std::string, double> setting_of(const std::string& technique, const json& settings) {
    if (technique == "path") return {std::to_string(settings.at("spp").get<int>()) + " spp", settings.at("spp").get<double>()};
    if (settings.value("progressive", false))
        return {std::to_string(settings.at("iterations").get<int>()) + " iterations", settings.at("iterations").get<double>()};
    return {std::to_string(settings.at("photons").get<int>()) + " photons", settings.at("photons").get<double>()};
}

// One point of a curve: the point's technique and settings (the axis value) rendered once
// and compared with the scene's reference (shared by the run's tasks). Raw relMSE: the
// reducer leaves the ones below the reference's noise blank.
ProbeOutput point_probe(const ProbeCall& call) {
    ProbeOutput out;
    const Scene* scene = nullptr;
    try {
        scene = &call.scene();
    } catch (const Error& e) {
        out.notes.push_back(call.task.scene + " skipped: " + e.what());
        call.ctx.say("skipping " + call.task.scene + ": " + e.what());
        return out;
    }
    // The point is rendered with the reference's camera; the run's tasks share the
    // reference (the cache), so only the first to need it reads or renders it.
    const std::vector<ReferenceView> halves = point_references(call);
    const EyeCamera& camera = halves.at(0).camera;
    const int spp_per_half = halves.at(0).spp;
    const NoisyReference& ref = call.cache.get<NoisyReference>(
        "pm-convergence reference:" + call.task.scene + ":" + std::to_string(call.size) + ":" + std::to_string(spp_per_half),
        [&] { return noisy_reference(call.ctx, halves); });
    out.files = ref.files;

    const std::string technique = call.setting<std::string>("technique");
    json settings = call.variant.settings;
    for (const char* key : {"curve", "technique", "reference_spp_per_half"}) settings.erase(key);
    settings["seed"] = call.ctx.seed;
    if (technique == "photon") {
        const Scene& cornell = call.cache.get<Scene>("scene:cornell", [&] { return open_scene("cornell", call.ctx.assets).scene; });
        settings["radius"] = kCornellRadius * diagonal(*scene) / diagonal(cornell);
    }
    auto t = prepare_technique(technique, *scene, Settings(settings, "pm-convergence settings"));
    const Stats prepared = t->stats();
    std::vector<Film> films;
    Stopwatch watch;
    t->render(ViewSet::mono(camera), films);
    const double ms = watch.elapsed_ms() + photon_pass_ms(prepared);
    const Stats rendered = t->stats();
    const auto [label, count] = setting_of(technique, settings);
    const double relmse = relative_mse(films.at(0), ref.image, "color");
    call.ctx.say(call.task.scene + " " + call.setting<std::string>("curve") + " " + label + ": " + format_number(ms) +
                 " ms, relMSE " + format_number(relmse));
    out.rows.push_back({{"variant", call.setting<std::string>("curve")},
                        {"setting", label},
                        {"count", count},
                        {"wall ms", ms},
                        {"relMSE", relmse},
                        {"reference noise (relMSE)", ref.noise},
                        {"reference spp per half", spp_per_half},
                        {"radius", technique == "photon" ? settings.at("radius") : json()},
                        {"photons emitted", technique == "photon" ? json(rendered.get("photons_emitted")) : json()},
                        {"mean final radius",
                         settings.value("progressive", false) ? json(rendered.get("mean_final_radius")) : json()}});
    return out;
}

// ---------------------------------------------------------------------------------
// The reducer

struct Point {
    std::string setting;
    double count = 0, ms = 0, relmse = 0;
    bool below_noise = false;  // relmse is under the reference's noise: not a measurement
};

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

// The least-squares slope of log relMSE against log count (photons, iterations, spp)
// over the measured points above the reference's noise; null with fewer than two.
json log_log_slope(const std::vector<Point>& curve) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const Point& p : curve) {
        if (p.below_noise) continue;
        const double x = std::log(p.count), y = std::log(p.relmse);
        n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    if (n < 2) return nullptr;
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

std::string noise_floor_text(double noise) { return "below the reference's noise (" + format_number(noise) + ")"; }

// One scene's measured points, curve by curve in plan order.
struct SceneCurves {
    std::string scene;
    double noise = 0, radius = 0;
    int spp_per_half = 0;
    std::vector<std::pair<std::string, std::vector<Point>>> curves;
    std::vector<Point>& curve(const std::string& name) {
        for (auto& [n, points] : curves)
            if (n == name) return points;
        return curves.emplace_back(name, std::vector<Point>{}).second;
    }
};

ExperimentOutput reduce(const SpecReduction& r) {
    ExperimentOutput out;
    ResultTable table{"relMSE (color) against a path-traced reference vs wall time (blank: below the reference's noise)",
                      {"scene", "variant", "setting", "wall ms", "relMSE", "reference noise (relMSE)", "photons emitted",
                       "mean final radius"},
                      {}};
    ResultTable reach{"Time to reach a relMSE (interpolated in log–log between measured points)", {"scene", "variant"}, {}};
    for (double target : kTargets) reach.columns.push_back(target_column(target));
    reach.columns.push_back("log–log slope of relMSE vs count (photons, iterations or spp)");

    std::vector<SceneCurves> scenes;
    for (const TaskResult& task : r.tasks)
        for (const json& row : task.rows) {
            if (scenes.empty() || scenes.back().scene != task.task.scene) scenes.push_back({task.task.scene});
            SceneCurves& s = scenes.back();
            s.noise = row.at("reference noise (relMSE)").get<double>();
            s.spp_per_half = row.at("reference spp per half").get<int>();
            if (row.at("radius").is_number()) s.radius = row.at("radius").get<double>();
            Point p{row.at("setting"), row.at("count").get<double>(), row.at("wall ms").get<double>(),
                    row.at("relMSE").get<double>()};
            p.below_noise = p.relmse < s.noise;
            table.rows.push_back({{"scene", task.task.scene}, {"variant", row.at("variant")}, {"setting", p.setting},
                                  {"wall ms", p.ms}, {"relMSE", p.below_noise ? json() : json(p.relmse)},
                                  {"reference noise (relMSE)", s.noise}, {"photons emitted", row.at("photons emitted")},
                                  {"mean final radius", row.at("mean final radius")}});
            s.curve(row.at("variant")).push_back(p);
        }

    for (SceneCurves& s : scenes) {
        out.notes.push_back(s.scene + ": reference = path tracer, two halves of " + std::to_string(s.spp_per_half) +
                            " jittered spp on independent seeds of their own (no variant shares their samples), "
                            "averaged (" + std::to_string(2 * s.spp_per_half) + " spp), at " + std::to_string(r.size()) +
                            "², max depth 8. Its noise, estimated from the halves, is relMSE " + format_number(s.noise) +
                            ": a floor under every error measured against it. Fixed radius " + format_number(s.radius) +
                            " (0.05 on the Cornell box, scaled by the bounding-box diagonal).");
        Plot plot;
        plot.title = s.scene + ": relMSE vs wall time";
        plot.x_label = "wall time (ms)";
        plot.y_label = "relMSE (color)";
        plot.log_x = plot.log_y = true;
        double smallest_reported = std::numeric_limits<double>::infinity();
        for (auto& [variant, points] : s.curves) {
            PlotSeries series;
            series.label = variant;
            std::vector<Point> curve = points;
            std::sort(curve.begin(), curve.end(), [](const Point& a, const Point& b) { return a.ms < b.ms; });
            for (const Point& p : curve)
                if (!p.below_noise) {
                    series.x.push_back(p.ms), series.y.push_back(p.relmse);
                    smallest_reported = std::min(smallest_reported, p.relmse);
                }
            json row = {{"scene", s.scene}, {"variant", variant}};
            for (double target : kTargets)
                row[target_column(target)] = target < s.noise ? json(noise_floor_text(s.noise)) : time_to_reach(curve, target);
            row["log–log slope of relMSE vs count (photons, iterations or spp)"] = log_log_slope(curve);
            reach.rows.push_back(row);
            plot.series.push_back(series);
        }
        out.plots.push_back({"convergence_" + s.scene, plot});
        // The reference should add at most a tenth of the smallest error reported.
        if (std::isfinite(smallest_reported) && s.noise > 0.1 * smallest_reported)
            out.notes.push_back(s.scene + ": the reference's noise (" + format_number(s.noise) +
                                ") is more than a tenth of the smallest error reported (" +
                                format_number(smallest_reported) + "); a quieter reference needs about " +
                                format_number(std::ceil(s.noise / (0.1 * smallest_reported))) +
                                "× its samples, more than this run spends on it.");
    }
    out.tables = {table, reach};
    return out;
}

// The points of the three curves, in order: the fixed radius at several photon counts,
// progressive at several iteration counts, the path tracer at several spp.
struct Curves {
    std::vector<int> fixed_photons;
    int fixed_spp;
    std::vector<int> iterations;
    int photons_per_iteration;
    std::vector<int> path_spp;
};

std::vector<json> points(const Curves& c) {
    std::vector<json> p;
    const std::string fixed = "photon r fixed, spp " + std::to_string(c.fixed_spp);
    for (int photons : c.fixed_photons)
        p.push_back({{"curve", fixed}, {"technique", "photon"}, {"photons", photons}, {"spp", c.fixed_spp}});
    for (int iterations : c.iterations)
        p.push_back({{"curve", "photon progressive"}, {"technique", "photon"}, {"progressive", true},
                     {"iterations", iterations}, {"photons", c.photons_per_iteration}});
    for (int spp : c.path_spp) p.push_back({{"curve", "path"}, {"technique", "path"}, {"spp", spp}, {"max_depth", 8}});
    return p;
}

}  // namespace

Experiment photon_convergence_experiment() {
    add_probe("pm-convergence", point_probe, point_references, [](const ProbeCall& call) {
        return "pm-convergence halves: " + call.task.scene + " " + std::to_string(call.size) + "px " +
               std::to_string(reference_spp_per_half(call)) + "spp";
    });
    add_reducer("pm-convergence", reduce);
    return declared_experiment({
        .name = "pm-convergence",
        .paper = "P1",
        .figure = "Convergence",
        .description = "relMSE vs wall time: photon mapping with a fixed radius (photon counts), progressive photon "
                       "mapping (iterations) and the path tracer (spp) on the Cornell box and the conference room",
        .scenes = {"cornell", "conference"},
        .size = 256, .quick_size = 48,
        .frames = 1, .quick_frames = 1,
        // A reference's noise should be at most a tenth of the smallest error it judges,
        // usually the path tracer's at its most spp: that error is the variance of spp
        // samples, so the reference needs more than 10 × those spp (2 × 8192 ≥ 16 × 1024).
        // The conference room's fireflies make its noise fall more slowly than that: at
        // 1024 spp every variant levelled off at relMSE 0.014–0.018, its reference's noise;
        // in quick runs 2 × 512 spp left a noise of 0.0066 under errors from 0.017.
        .variants = {{.name = "point",
                      .probe = "pm-convergence",
                      .settings = {{"reference_spp_per_half",
                                    {{"full", {{"cornell", 8192}, {"conference", 8192}}},
                                     {"quick", {{"cornell", 1024}, {"conference", 4096}}}}}}}},
        .axes = {{"",
                  points({{16384, 65536, 262144, 1048576}, 16, {4, 16, 64, 256}, 16384, {16, 64, 256, 1024}}),
                  points({{4096, 16384}, 4, {2, 8, 32}, 4096, {4, 16, 64}})}},
        .reducer = "pm-convergence",
        .notes =
            {"Both photon variants store photons from their second hit on and take direct light from shadow rays "
             "(photon_storage=indirect, one light sample per visible point); the progressive radius starts at the "
             "fixed radius and shrinks with alpha = 2/3. Path tracer: max depth 8, jittered.",
             "Wall time: render() plus, for the fixed-radius photon map, its photon tracing and map building in "
             "prepare(); the scene's ray-tracing structure (built by every technique alike) is left out. One run per "
             "point, at the run's thread count.",
             "Time to reach: the first crossing of the target on the measured curve; \"≤ t (first point)\" when the "
             "cheapest point is already below it, \"not reached\" when no point is, \"below the reference's noise\" "
             "when the target is.",
             "Reference noise = mean over pixels and channels of ((A − B)/2)² / (R² + 0.01) for the halves A, B and "
             "R = (A + B)/2: the expected relMSE R's own noise adds to an error. relMSE cells below it are left blank "
             "(and out of the plots and slopes): they measure the reference. The slope is the least-squares slope of "
             "log relMSE against log photons, iterations or spp."},
    });
}

}  // namespace gilab
