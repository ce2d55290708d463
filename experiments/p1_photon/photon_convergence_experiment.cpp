// pm-convergence: image error against wall time for the photon technique with a fixed
// radius (several photon counts), its progressive mode (SPPM, several iteration counts)
// and the path tracer (several spp), on the Cornell box and the conference room, all in
// one run at one thread count. Error is the relative MSE of the color layer against a
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
    int reference_spp;                  // per half of the reference, per scene below
    int conference_reference_spp;
    std::vector<int> fixed_photons;     // (a) photons emitted, fixed radius
    int fixed_spp;
    std::vector<int> iterations;        // (b) progressive iterations
    int photons_per_iteration;
    std::vector<int> path_spp;          // (c)
};

Sizes sizes_for(bool quick) {
    // A reference's noise should be at most a tenth of the smallest error it judges,
    // usually the path tracer's at its most spp: that error is the variance of spp
    // samples, so the reference needs more than 10 × those spp (2 × 8192 ≥ 16 × 1024).
    // The conference room's fireflies make its noise fall more slowly than that: at 1024
    // spp every variant levelled off at relMSE 0.014–0.018, its reference's noise; in
    // quick runs 2 × 512 spp left a noise of 0.0066 under errors from 0.017.
    if (quick) return {48, 1024, 4096, {4096, 16384}, 4, {2, 8, 32}, 4096, {4, 16, 64}};
    return {256, 8192, 8192, {16384, 65536, 262144, 1048576}, 16, {4, 16, 64, 256}, 16384, {16, 64, 256, 1024}};
}

double diagonal(const Scene& scene) {
    const Bounds3 b = scene.evaluate(0).bounds;
    return double(glm::length(b.max - b.min));
}

struct Point {
    std::string variant, setting;
    double ms = 0, relmse = 0;
    bool below_noise = false;  // relmse is under the reference's noise: not a measurement
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
    auto t = prepare_technique(technique, scene, Settings(settings_json, "pm-convergence settings"));
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

// A reference and the noise it adds to every relMSE measured against it.
struct NoisyReference {
    Film image;    // the mean of the two halves
    double noise;  // estimated relMSE of `image` against the noise-free image
    int spp;       // both halves together
};

// The second half's seed: independent of the first half's and of the run's.
uint64_t second_half_seed(uint64_t run_seed) { return reference_seed(run_seed) ^ 0x48414c46ull; }

// Two path-traced references A and B on independent seeds (each cached like every
// reference), averaged: R = (A + B) / 2. A pixel's error of R has variance σ²/2 where σ²
// is one half's, and E[((A − B) / 2)²] = σ²/2 too, so the relMSE of R + (A − B) / 2
// against R estimates the relMSE R's own noise adds to any error measured against it.
NoisyReference noisy_reference(const ExperimentContext& ctx, const Scene& scene, const EyeCamera& camera,
                               int spp_per_half, std::vector<std::string>& files) {
    const Film a = path_reference(ctx, scene, camera, spp_per_half, files, /*jitter=*/true);
    const Film b = path_reference(ctx, scene, camera, spp_per_half, files, /*jitter=*/true, second_half_seed(ctx.seed));
    Film mean(a.width(), a.height()), off_by_noise(a.width(), a.height());
    const auto& da = a.layer("color").data;
    const auto& db = b.layer("color").data;
    auto& m = mean.layer("color").data;
    auto& o = off_by_noise.layer("color").data;
    for (size_t i = 0; i < da.size(); ++i) {
        m[i] = 0.5f * (da[i] + db[i]);
        o[i] = m[i] + 0.5f * (da[i] - db[i]);
    }
    return {mean, relative_mse(off_by_noise, mean, "color"), 2 * spp_per_half};
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

// The least-squares slope of log relMSE against log count (photons, iterations, spp)
// over the measured points above the reference's noise; null with fewer than two.
json log_log_slope(const std::vector<Point>& curve, const std::map<std::string, double>& count_of) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const Point& p : curve) {
        if (p.below_noise) continue;
        const double x = std::log(count_of.at(p.setting)), y = std::log(p.relmse);
        n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    if (n < 2) return nullptr;
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

std::string noise_floor_text(double noise) { return "below the reference's noise (" + format_number(noise) + ")"; }

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

    ResultTable table{"relMSE (color) against a path-traced reference vs wall time (blank: below the reference's noise)",
                      {"scene", "variant", "setting", "wall ms", "relMSE", "reference noise (relMSE)", "photons emitted",
                       "mean final radius"},
                      {}};
    ResultTable reach{"Time to reach a relMSE (interpolated in log–log between measured points)",
                      {"scene", "variant"},
                      {}};
    for (double target : kTargets) reach.columns.push_back(target_column(target));
    reach.columns.push_back("log–log slope of relMSE vs count (photons, iterations or spp)");
    json scene_config = json::object();

    for (const Named& named : scenes) {
        const Scene& scene = named.scene;
        if (!scene.camera) throw Error("pm-convergence", named.name + " has no camera");
        const SceneCamera& c = *scene.camera;
        const EyeCamera camera = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, z.size, z.size);
        const NoisyReference ref = noisy_reference(ctx, scene, camera, named.reference_spp, out.files);
        const Film& reference = ref.image;
        const double radius = kCornellRadius * diagonal(scene) / cornell_diagonal;
        scene_config[named.name] = {{"resolution", {z.size, z.size}}, {"reference_spp", ref.spp},
                                    {"reference_noise_relmse", ref.noise}, {"radius", radius}};
        out.notes.push_back(named.name + ": reference = path tracer, two halves of " + std::to_string(named.reference_spp) +
                            " jittered spp on independent seeds of their own (no variant shares their samples), "
                            "averaged (" + std::to_string(ref.spp) + " spp), at " + std::to_string(z.size) +
                            "², max depth 8. Its noise, estimated from the halves, is relMSE " + format_number(ref.noise) +
                            ": a floor under every error measured against it.");

        std::map<std::string, std::vector<Point>> curves;
        std::map<std::string, double> count_of;  // setting → photons, iterations or spp
        double smallest_reported = std::numeric_limits<double>::infinity();
        auto record = [&](Point p, double count) {
            p.below_noise = p.relmse < ref.noise;
            if (!p.below_noise) smallest_reported = std::min(smallest_reported, p.relmse);
            ctx.say(named.name + " " + p.variant + " " + p.setting + ": " + format_number(p.ms) + " ms, relMSE " +
                    format_number(p.relmse) + (p.below_noise ? " (below the reference's noise)" : ""));
            table.rows.push_back({{"scene", named.name}, {"variant", p.variant}, {"setting", p.setting},
                                  {"wall ms", p.ms}, {"relMSE", p.below_noise ? json() : json(p.relmse)},
                                  {"reference noise (relMSE)", ref.noise}, {"photons emitted", p.photons},
                                  {"mean final radius", p.mean_radius}});
            count_of[p.setting] = count;
            curves[p.variant].push_back(p);
        };
        const std::string fixed = "photon r fixed, spp " + std::to_string(z.fixed_spp);
        for (int photons : z.fixed_photons) {
            Point p = measure(scene, camera, reference, "photon",
                              {{"photons", photons}, {"radius", radius}, {"spp", z.fixed_spp}, {"seed", ctx.seed}});
            p.variant = fixed, p.setting = std::to_string(photons) + " photons";
            record(p, photons);
        }
        const std::string progressive = "photon progressive";
        for (int iterations : z.iterations) {
            Point p = measure(scene, camera, reference, "photon",
                              {{"progressive", true}, {"iterations", iterations}, {"photons", z.photons_per_iteration},
                               {"radius", radius}, {"seed", ctx.seed}});
            p.variant = progressive, p.setting = std::to_string(iterations) + " iterations";
            record(p, iterations);
        }
        const std::string path = "path";
        for (int spp : z.path_spp) {
            Point p = measure(scene, camera, reference, "path", {{"spp", spp}, {"seed", ctx.seed}, {"max_depth", 8}});
            p.variant = path, p.setting = std::to_string(spp) + " spp";
            record(p, spp);
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
            for (const Point& p : curve)
                if (!p.below_noise) series.x.push_back(p.ms), series.y.push_back(p.relmse);
            for (double target : kTargets)
                row[target_column(target)] = target < ref.noise ? json(noise_floor_text(ref.noise)) : time_to_reach(curve, target);
            row["log–log slope of relMSE vs count (photons, iterations or spp)"] = log_log_slope(curve, count_of);
            reach.rows.push_back(row);
            plot.series.push_back(series);
        }
        out.plots.push_back({"convergence_" + named.name, plot});
        // The reference should add at most a tenth of the smallest error reported.
        if (std::isfinite(smallest_reported) && ref.noise > 0.1 * smallest_reported)
            out.notes.push_back(named.name + ": the reference's noise (" + format_number(ref.noise) +
                                ") is more than a tenth of the smallest error reported (" +
                                format_number(smallest_reported) + "); a quieter reference needs about " +
                                format_number(std::ceil(ref.noise / (0.1 * smallest_reported))) +
                                "× its samples, more than this run spends on it.");
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
                        "point)\" when the cheapest point is already below it, \"not reached\" when no point is, "
                        "\"below the reference's noise\" when the target is.");
    out.notes.push_back("Reference noise = mean over pixels and channels of ((A − B)/2)² / (R² + 0.01) for the halves "
                        "A, B and R = (A + B)/2: the expected relMSE R's own noise adds to an error. relMSE cells "
                        "below it are left blank (and out of the plots and slopes): they measure the reference. The "
                        "slope is the least-squares slope of log relMSE against log photons, iterations or spp.");
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
