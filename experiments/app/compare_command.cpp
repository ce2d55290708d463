#include "experiments/app/compare_command.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include "core/util/error.hpp"
#include "core/image/heat_map.hpp"
#include "core/image/image_io.hpp"
#include "core/image/image_metrics.hpp"
#include "core/util/parallel.hpp"
#include "core/util/stats.hpp"
#include "experiments/report/compare_report.hpp"
#include "experiments/runner/experiment_batch.hpp"
#include "experiments/runner/path_reference.hpp"
#include "experiments/app/render_command.hpp"
#include "experiments/runner/result_writers.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

// The technique's quality knob, from its settings schema; null when it has none.
const SettingSpec* find_knob(const std::string& technique) {
    const TechniqueInfo* info = TechniqueRegistry::builtin().find(technique);
    return info ? info->settings_schema().quality_knob() : nullptr;
}

void check_request(const CompareRequest& r) {
    if (r.techniques.empty()) throw Error("compare", "no technique given (-t path,photon,vct)");
    for (const auto& t : r.techniques) {
        if (t.empty()) throw Error("-t", "an empty technique name in the list (two commas, or one at an end)");
        if (!TechniqueRegistry::builtin().find(t)) TechniqueRegistry::builtin().create(t);  // throws listing the known ones
        if (std::count(r.techniques.begin(), r.techniques.end(), t) > 1)
            throw Error("compare", "technique '" + t + "' is listed twice");
    }
    for (const auto& [t, file] : r.settings_files)
        if (std::find(r.techniques.begin(), r.techniques.end(), t) == r.techniques.end())
            throw Error("--settings", "settings for '" + t + "', which is not among the compared techniques");
    for (const auto& [t, list] : r.assignments)
        if (std::find(r.techniques.begin(), r.techniques.end(), t) == r.techniques.end())
            throw Error("--set", "a setting for '" + t + "', which is not among the compared techniques");
    check_resolution(r.width, r.height);
    if (r.reference_spp < 1) throw Error("--reference-spp", "must be at least 1");
    if (r.frames < 1 || r.frames > 1000) throw Error("--frames", "must be 1 to 1000");
    if (r.equal_time_seconds && !(std::isfinite(*r.equal_time_seconds) && *r.equal_time_seconds > 0))
        throw Error("--equal-time", "must be a positive number of seconds");
    if (r.pixels_per_degree && !(std::isfinite(*r.pixels_per_degree) && *r.pixels_per_degree > 0))
        throw Error("--ppd", "must be a positive number");
}

Settings settings_for(const CompareRequest& r, const std::string& technique) {
    Settings s = r.settings_files.count(technique) ? Settings::from_file(r.settings_files.at(technique))
                                                   : Settings(nlohmann::json::object(), "--set " + technique);
    if (r.assignments.count(technique))
        for (const auto& a : r.assignments.at(technique)) s.set_from_string(a);
    s.set("seed", r.seed);
    return s;
}

struct Run {
    double prepare_ms = 0, frame_ms = 0;  // frame: median over the timed renders
    double timed_ms(EqualTimeOf of) const { return of == EqualTimeOf::Frame ? frame_ms : prepare_ms + frame_ms; }
    size_t peak_rss = 0;
    bool peak_rss_exact = false;  // the peak could be reset before the technique ran
    std::vector<Film> films;
    Stats stats;
};

Run run_technique(const std::string& technique, const Scene& scene, const ViewSet& views, const Settings& settings,
                  int frames) {
    Run run;
    run.peak_rss_exact = reset_peak_rss();
    Stopwatch prepare;
    auto t = prepare_technique(technique, scene, settings);
    run.prepare_ms = prepare.elapsed_ms();
    std::vector<double> times;
    for (int f = 0; f < frames; ++f) {
        run.films.assign(views.views.size(), Film());
        Stopwatch frame;
        t->render(views, run.films);
        times.push_back(frame.elapsed_ms());
    }
    std::sort(times.begin(), times.end());
    run.frame_ms = times[times.size() / 2];
    run.stats = t->stats();
    run.peak_rss = peak_rss_bytes();
    return run;
}

// Raises (or lowers) the technique's quality knob until the equalised time (prepare +
// one frame, or the frame alone) is within 10 % of `budget_ms`; at most five tries. The
// first step assumes time in proportion to the knob; later ones fit time = a + b · knob
// through the last two tries, since prepare holds a part (the BVH) that does not scale.
double tune_knob(const SettingSpec& knob, const std::string& technique, const Scene& scene, const ViewSet& views,
                 Settings settings, double budget_ms, EqualTimeOf of, std::ostream& log) {
    const double fallback = knob.default_value.get<double>();
    double value = settings.has(knob.key) ? settings.get<double>(knob.key, fallback) : fallback;
    double last_value = 0, last_ms = 0;
    for (int attempt = 0; attempt < 5; ++attempt) {
        settings.set(knob.key, int64_t(value));
        const Run run = run_technique(technique, scene, views, settings, 1);
        const double ms = run.timed_ms(of);
        log << "  " << technique << ": " << knob.key << "=" << int64_t(value) << " → " << ms << " ms ("
            << to_string(of) << ")" << std::endl;
        if (std::abs(ms - budget_ms) < 0.1 * budget_ms) break;
        double next = value * budget_ms / std::max(ms, 1e-3);
        if (attempt > 0 && value != last_value) {
            const double slope = (ms - last_ms) / (value - last_value);
            if (slope > 0) next = value + (budget_ms - ms) / slope;
        }
        next = std::clamp(std::round(next), knob.knob->low, knob.knob->high);
        if (next == value) break;
        last_value = value, last_ms = ms;
        value = next;
    }
    return value;
}

// Side-by-side for stereo: left eye, then right eye.
ImagePlane join_eyes(const std::vector<ImagePlane>& eyes) {
    if (eyes.size() == 1) return eyes[0];
    ImagePlane out(eyes[0].width * 2, eyes[0].height);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) out.at(x, y) = eyes[size_t(x / eyes[0].width)].at(x % eyes[0].width, y);
    return out;
}

void write_images(const fs::path& dir, const std::string& name, const std::vector<Film>& films) {
    if (films.size() == 2) {
        write_exr_stereo(dir / (name + ".exr"), films[0], films[1]);
        write_png_side_by_side(dir / (name + ".png"), films[0], films[1]);
    } else {
        write_exr(dir / (name + ".exr"), films[0]);
        write_png(dir / (name + ".png"), films[0]);
    }
}

std::string folder_name(const std::string& scene) {
    std::string out;
    for (char c : fs::path(scene).stem().string()) out += std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '_';
    return out.empty() ? "scene" : out;
}

}  // namespace

std::string to_string(EqualTimeOf of) { return of == EqualTimeOf::Frame ? "frame" : "prepare + frame"; }

EqualTimeOf parse_equal_time_of(const std::string& text) {
    if (text == "total") return EqualTimeOf::PrepareAndFrame;
    if (text == "frame") return EqualTimeOf::Frame;
    throw Error("--equal-time-of", "'" + text + "' is neither 'total' (prepare + frame) nor 'frame'");
}

std::string quality_knob(const std::string& technique) {
    const SettingSpec* k = find_knob(technique);
    return k ? k->key : "";
}

std::string run_compare(const CompareRequest& request) {
    check_request(request);
    for (const auto& [t, file] : request.settings_files) Settings::from_file(file);  // a bad file fails before rendering

    OpenedScene opened = open_scene(request.scene, request.assets);
    for (const auto& w : opened.warnings) std::cerr << "gilab: note: " << request.scene << ": " << w << "\n";
    const Scene& scene = opened.scene;

    ViewSet views;
    double ppd = request.pixels_per_degree.value_or(67.0);
    if (request.hmd) {
        HmdRig rig(find_hmd_preset(*request.hmd));
        rig.set_pose(scene.hmd ? scene.hmd->pose : pose_from_camera(*scene.camera));
        if (scene.hmd && scene.hmd->ipd) rig.set_ipd(*scene.hmd->ipd);
        rig.set_resolution(request.width, request.height);
        views = ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
        // On a headset the viewing condition is the display's own: pixels per degree of view.
        const FrustumTangents& f = views.views[0].fov();
        const double degrees = (std::atan(f.right) - std::atan(f.left)) * 180.0 / 3.14159265358979323846;
        if (!request.pixels_per_degree) ppd = double(request.width) / degrees;
    } else {
        const SceneCamera& c = *scene.camera;
        views = ViewSet::mono(EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, request.width, request.height));
    }

    const fs::path root = fs::path(request.results) / "compare";
    const std::string name = folder_name(request.scene);
    const fs::path final_dir = root / name, staging = staging_directory(root, name);
    std::error_code ec;
    fs::remove_all(staging, ec);
    fs::create_directories(staging);
    // Nothing half-written is left when a technique fails (a bad setting, say).
    struct RemoveOnFailure {
        fs::path dir;
        bool armed = true;
        ~RemoveOnFailure() {
            std::error_code ignored;
            if (armed) fs::remove_all(dir, ignored);
        }
    } cleanup{staging};

    // The reference, cached across runs by the digest of everything it depends on.
    ExperimentContext cache;
    cache.output_dir = root / "reference_cache";
    cache.seed = request.seed;
    cache.log = &std::cout;
    fs::create_directories(cache.output_dir);
    std::vector<Film> reference;
    std::vector<std::string> cached_files;
    for (const EyeCamera& eye : views.views)
        reference.push_back(path_reference(cache, scene, eye, request.reference_spp, cached_files, /*jitter=*/true));
    write_images(staging, "reference", reference);

    CompareReport report;
    report.scene = request.scene;
    report.views = views.stereo() ? "stereo (" + *request.hmd + ")" : "mono";
    report.width = request.width;
    report.height = request.height;
    report.reference_spp = request.reference_spp;
    report.pixels_per_degree = ppd;
    report.frames = request.frames;
    report.equal_time_seconds = request.equal_time_seconds;
    report.equal_time_of = to_string(request.equal_time_of);
    report.threads = request.threads > 0 ? request.threads : default_thread_count();

    for (const std::string& technique : request.techniques) {
        std::cout << "compare: " << technique << std::endl;
        Settings settings = settings_for(request, technique);
        CompareEntry entry;
        entry.technique = technique;
        if (request.equal_time_seconds) {
            if (const SettingSpec* knob = find_knob(technique)) {
                const double value = tune_knob(*knob, technique, scene, views, settings, *request.equal_time_seconds * 1000.0,
                                               request.equal_time_of, std::cout);
                settings = settings_for(request, technique);
                settings.set(knob->key, int64_t(value));
                entry.knob = knob->key + "=" + std::to_string(int64_t(value));
            } else {
                entry.knob = "no quality knob: its settings as given";
            }
        }
        Run run = run_technique(technique, scene, views, settings, request.frames);
        if (request.equal_time_seconds && find_knob(technique)) {
            // Said, not hidden: a knob at its limit (one cone, one sample) may not reach the budget.
            const double budget_ms = *request.equal_time_seconds * 1000.0, ms = run.timed_ms(request.equal_time_of);
            if (std::abs(ms - budget_ms) > 0.1 * budget_ms) {
                std::ostringstream off;
                off << " (" << std::lround(ms) << " ms: outside ±10 % of the budget)";
                entry.knob += off.str();
            }
        }
        entry.prepare_ms = run.prepare_ms;
        entry.frame_ms = run.frame_ms;
        entry.peak_rss_mib = double(run.peak_rss) / double(1 << 20);
        entry.peak_rss_exact = run.peak_rss_exact;
        entry.settings = settings.json();
        entry.stats = run.stats.to_json();
        std::vector<ImagePlane> flip_eyes, hdr_flip_eyes, ssim_eyes;
        const double eyes = double(run.films.size());
        for (size_t v = 0; v < run.films.size(); ++v) {
            entry.relmse += relative_mse(run.films[v], reference[v]) / eyes;
            MetricMap s = ssim_map(run.films[v], reference[v]);
            MetricMap f = flip_map(run.films[v], reference[v], "color", ppd);
            HdrFlip hdr = hdr_flip_map(run.films[v], reference[v], "color", ppd);
            entry.ssim += s.mean / eyes;
            entry.flip += f.mean / eyes;
            entry.hdr_flip += hdr.flip.mean / eyes;
            entry.hdr_flip_exposures.push_back({hdr.start_exposure, hdr.stop_exposure, hdr.exposures});
            for (float& x : s.map.values) x = 1.0f - x;  // dissimilarity, 0 where equal
            ssim_eyes.push_back(std::move(s.map));
            flip_eyes.push_back(std::move(f.map));
            hdr_flip_eyes.push_back(std::move(hdr.flip.map));
        }
        write_images(staging, technique, run.films);
        write_heat_map_png(staging / (technique + "_flip.png"), join_eyes(flip_eyes), 0.0, 1.0);
        write_heat_map_png(staging / (technique + "_hdrflip.png"), join_eyes(hdr_flip_eyes), 0.0, 1.0);
        write_heat_map_png(staging / (technique + "_ssim.png"), join_eyes(ssim_eyes), 0.0, 1.0);
        std::cout << "  prepare " << entry.prepare_ms << " ms, frame " << entry.frame_ms << " ms, relMSE " << entry.relmse
                  << ", SSIM " << entry.ssim << ", FLIP " << entry.flip << ", HDR-FLIP " << entry.hdr_flip << std::endl;
        report.entries.push_back(std::move(entry));
    }
    write_compare_report(staging, report);
    publish_directory(staging, final_dir);
    cleanup.armed = false;
    return final_dir.string();
}

}  // namespace gilab
