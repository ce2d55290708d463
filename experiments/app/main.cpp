// The gilab command line: render, info, list, compare, experiment, sweep, report.
#include <CLI/CLI.hpp>
#include <iostream>
#include <sstream>
#include "core/util/error.hpp"
#include "core/scene/hmd.hpp"
#include "core/util/memory_budget.hpp"
#include "core/util/parallel.hpp"
#include "experiments/app/compare_command.hpp"
#include "experiments/report/compare_report.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/experiment_batch.hpp"
#include "experiments/runner/task_command.hpp"
#include "experiments/sweep/sweep_command.hpp"
#include "experiments/report/html_report.hpp"
#include "experiments/app/render_command.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

using namespace gilab;

namespace {

// `gilab list settings [TECHNIQUE] [--markdown]`: each technique's settings schema.
void print_settings(const std::string& technique, bool markdown) {
    const TechniqueRegistry& registry = TechniqueRegistry::builtin();
    if (!technique.empty() && !registry.find(technique)) registry.create(technique);  // throws listing the known ones
    bool first = true;
    for (const auto& t : registry.list()) {
        if (!technique.empty() && t.name != technique) continue;
        const SettingsSchema& schema = t.settings_schema();
        std::cout << (first ? "" : "\n") << (markdown ? schema.table_markdown() : schema.table_text());
        first = false;
    }
}

void print_list(const std::string& what) {
    bool all = what.empty();
    if (all || what == "techniques") {
        std::cout << "techniques:\n";
        for (const auto& t : TechniqueRegistry::builtin().list()) std::cout << "  " << t.name << " — " << t.description << "\n";
    }
    if (all || what == "experiments") {
        std::cout << "experiments:\n";
        for (const auto& e : ExperimentRegistry::builtin().list())
            std::cout << "  " << e.name << " [" << e.paper << "] — " << e.description << "\n";
    }
    if (all || what == "scenes") {
        std::cout << "scenes (built in):\n";
        for (const auto& s : builtin_scenes()) std::cout << "  " << s.name << " — " << s.description << "\n";
        std::cout << "scenes (files in " << scenes_directory() << "):\n";
        for (const auto& n : scene_file_names()) std::cout << "  " << n << "\n";
    }
    if (all || what == "hmds") {
        std::cout << "HMD presets:\n";
        for (const auto& p : hmd_presets())
            std::cout << "  " << p.name << " — " << p.display_name << ", " << p.width << "×" << p.height
                      << " per eye, IPD " << p.ipd * 1000 << " mm (" << p.source << ")\n";
    }
}

// --assets directories must exist (a typo would silently fall back to other copies of
// the same files); missing $GILAB_ASSETS directories only get a note, since the
// environment is often shared between machines.
void check_asset_directories(const std::string& flag) {
    AssetPaths::require_directories(flag, "--assets");
    if (const char* env = std::getenv("GILAB_ASSETS"))
        for (const std::string& dir : AssetPaths::missing_directories(env))
            std::cerr << "gilab: note: $GILAB_ASSETS: '" << dir << "' is not a directory; ignored\n";
}

constexpr int kMaxThreads = 1024;

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"gilab — global illumination research framework (photon mapping for HMDs, sparse voxel DAGs, "
                 "cascaded voxel cone tracing, reference path tracer)"};
    app.require_subcommand(1);
    int threads = 0;
    std::string assets_flag, memory_limit;
    app.add_option("--threads", threads, "worker threads (0 = all cores)")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                int n = -1;
                try {
                    size_t used = 0;
                    n = std::stoi(text, &used);
                    if (used != text.size()) n = -1;
                } catch (const std::exception&) {
                }
                if (n < 0 || n > kMaxThreads)
                    return "'" + text + "' is not a thread count (0 = all cores, or 1 to " + std::to_string(kMaxThreads) + ")";
                return "";
            },
            "0-" + std::to_string(kMaxThreads), "thread count"));
    app.add_option("--assets", assets_flag,
                   "asset search path, colon-separated; every directory must exist (also $GILAB_ASSETS, whose missing "
                   "directories are noted and skipped; default ../shared/scenes beside the source)");
    app.add_option("--memory-limit", memory_limit,
                   "memory budget for everything sized by input (vertex, face and list counts, glTF buffers, images, "
                   "frames, film size): bytes or a size such as 8G or 512M; default half the physical memory (" +
                       MemoryBudget::format(MemoryBudget::default_limit()) +
                       " here). It applies to each request on its own, not to their sum");

    RenderRequest request;
    uint64_t seed = 1;
    auto* render = app.add_subcommand("render", "render a scene with a technique (mono, or stereo with --hmd)");
    render->add_option("scene", request.scene, "built-in name, scene file name in scenes/, or a path")->capture_default_str();
    render->add_option("-t,--technique", request.technique, "technique name (see `gilab list techniques`)")->capture_default_str();
    render->add_option("--hmd", request.hmd, "render a stereo pair with this HMD preset (see `gilab list hmds`)");
    render->add_option("--ipd", request.ipd, "inter-pupillary distance in metres (overrides the preset)");
    render->add_option("-W,--width", request.width, "image (per-eye) width in pixels");
    render->add_option("-H,--height", request.height, "image (per-eye) height in pixels");
    render->add_option("--spp", request.spp, "samples per pixel");
    render->add_option("--time-budget", request.time_budget,
                       "seconds: a progressive technique stops after the iteration that fills it");
    render->add_option("--seed", seed, "random seed")->capture_default_str();
    render->add_option("--time", request.time, "scene time in seconds (animated scenes)");
    render->add_option("-o,--output", request.output,
                       "output path without extension (writes .exr and .png); its directory must exist, -o never "
                       "creates directories (the default results/render/ is created)");
    render->add_option("--settings", request.settings_file, "technique settings as a JSON object file");
    render->add_option("--set", request.assignments, "technique setting key=value (repeatable)");
    render->add_option("--exposure", request.exposure, "PNG preview exposure in stops");
    render->add_option("--head-trace", request.head_trace,
                       "head-pose trace CSV (t,px,py,pz,qw,qx,qy,qz; needs --hmd): render a frame sequence, the head "
                       "moving from the scene's HMD pose as the trace moves from its first sample");
    render->add_option("--frames", request.frames, "frames to render along the trace (default: duration × fps)");
    render->add_option("--fps", request.fps, "frames per second along the trace (default 30)");
    render->add_option("--trace-scale", request.trace_scale,
                       "scene units per metre of trace motion (default 1, for metre-scale scenes such as cornell)");

    std::string info_scene;
    auto* info = app.add_subcommand("info", "describe a scene: triangles, materials, lights, bounds, animation, closed meshes");
    info->add_option("scene", info_scene, "scene name or path")->required();

    std::string list_what, list_technique;
    bool list_markdown = false;
    auto* list = app.add_subcommand("list", "list techniques, experiments, scenes, HMD presets, or a technique's settings");
    list->add_option("what", list_what, "one of techniques, experiments, scenes, hmds, settings")
        ->check(CLI::IsMember({"techniques", "experiments", "scenes", "hmds", "settings"}));
    list->add_option("technique", list_technique,
                     "with `settings`: the technique whose settings to list (key, type, default, range, description); "
                     "all techniques when left out");
    list->add_flag("--markdown", list_markdown, "with `settings`: print Markdown tables (the README's settings tables)");

    std::vector<std::string> experiment_names;
    bool quick = false;
    std::string results_dir = "results";
    auto* experiment = app.add_subcommand(
        "experiment", "run experiments: `list`, a name, several names, or `all`; for a declared experiment also "
                      "`plan NAME` (its tasks as JSON lines), `run-task NAME ID` (one task, written to "
                      "RESULTS/NAME/tasks/{full|quick}/ID.json), `references NAME ID` (the path-traced references the task "
                      "compares against, rendered into RESULTS/.references) and `merge NAME` (the tables from the "
                      "tasks that exist)");
    experiment->add_option("names", experiment_names, "experiment names, `all`, `list`, or plan|run-task|references|merge NAME [ID]")
        ->required();
    experiment->add_flag("--quick", quick, "small sizes (smoke run, minutes)");
    experiment->add_option("--results", results_dir, "results root directory")->capture_default_str();
    experiment->add_option("--seed", seed, "random seed")->capture_default_str();
    std::vector<std::string> extra_axes;
    experiment->add_option("--axis", extra_axes,
                           "a declared experiment swept along one more axis, SETTING=V1,V2,... (repeatable); an axis "
                           "of the experiment on that setting takes these values instead")
        ->allow_extra_args(false);
    bool resume = false;
    experiment->add_flag("--resume", resume,
                         "skip experiments whose results/NAME holds a finished run of this build with the same "
                         "--quick, --seed and --threads (after an interrupted batch)");

    CompareRequest compare_request;
    std::vector<std::string> compare_settings, compare_assignments;
    std::string compare_techniques = "path,photon,vct";
    auto* compare = app.add_subcommand(
        "compare", "render a scene with several techniques and compare each with a path-traced reference (time, "
                   "memory, relMSE, SSIM, FLIP, heat maps) into RESULTS/compare/SCENE/");
    compare->add_option("scene", compare_request.scene, "built-in name, scene file name in scenes/, or a path")->required();
    compare->add_option("-t,--techniques", compare_techniques, "comma-separated techniques")->capture_default_str();
    compare->add_option("--hmd", compare_request.hmd, "compare stereo pairs of this HMD preset");
    compare->add_option("-W,--width", compare_request.width, "image (per-eye) width")->capture_default_str();
    compare->add_option("-H,--height", compare_request.height, "image (per-eye) height")->capture_default_str();
    compare->add_option("--reference-spp", compare_request.reference_spp,
                        "samples per pixel of the path-traced reference (cached in RESULTS/compare/.references)")
        ->capture_default_str();
    compare->add_option("--frames", compare_request.frames, "renders per technique; the median time is reported")
        ->capture_default_str();
    std::string equal_time_of = "total";
    compare->add_option("--equal-time", compare_request.equal_time_seconds,
                        "seconds: scale each technique's quality setting (path spp, photon photons, vct diffuse_cones, lpv rsm_size) "
                        "until the time of --equal-time-of is about this long");
    compare->add_option("--equal-time-of", equal_time_of,
                        "what --equal-time equalises: total (prepare + one frame, the work that makes a still image) "
                        "or frame (the frame alone, prepare amortised as in an animation)")
        ->capture_default_str();
    compare->add_option("--ppd", compare_request.pixels_per_degree,
                        "FLIP viewing condition in pixels per degree (default 67, a monitor; with --hmd the headset's "
                        "own: width / horizontal field of view)");
    compare->add_option("--settings", compare_settings, "TECHNIQUE=FILE: a technique's settings as a JSON file (repeatable)");
    compare->add_option("--set", compare_assignments, "TECHNIQUE:key=value: one technique setting (repeatable)");
    compare->add_option("--results", compare_request.results, "results root directory")->capture_default_str();
    compare->add_option("--seed", seed, "random seed")->capture_default_str();

    SweepCommand sweep_command;
    auto* sweep = add_sweep_subcommand(app, sweep_command);

    std::string report_dir = "results";
    auto* report = app.add_subcommand("report", "gather every results/NAME/results.json into results/report.html and "
                                                "print a summary of the comparisons (frame time, relMSE, FLIP)");
    report->add_option("--results", report_dir, "results root directory")->capture_default_str();

    CLI11_PARSE(app, argc, argv);

    try {
        if (!memory_limit.empty()) MemoryBudget::set_limit(MemoryBudget::parse_size(memory_limit, "--memory-limit"));
        check_asset_directories(assets_flag);
        ThreadLimit limit(threads);
        AssetPaths assets = AssetPaths::from_environment(assets_flag.empty() ? std::nullopt : std::optional(assets_flag));
        if (*render) {
            request.seed = seed;
            request.assets = assets;
            run_render(request);
        } else if (*info) {
            std::cout << describe_scene(info_scene, assets);
        } else if (*list) {
            if (list_what != "settings" && (!list_technique.empty() || list_markdown))
                throw Error("list", "a technique name and --markdown go with `gilab list settings` only");
            if (list_what == "settings")
                print_settings(list_technique, list_markdown);
            else
                print_list(list_what);
        } else if (*compare) {
            compare_request.techniques.clear();
            std::stringstream list(compare_techniques);
            for (std::string t; std::getline(list, t, ',');) compare_request.techniques.push_back(t);
            if (!compare_techniques.empty() && compare_techniques.back() == ',') compare_request.techniques.push_back("");
            compare_request.equal_time_of = parse_equal_time_of(equal_time_of);
            for (const auto& s : compare_settings) {
                const auto eq = s.find('=');
                if (eq == std::string::npos || eq == 0) throw Error("--settings", "'" + s + "' is not TECHNIQUE=FILE");
                compare_request.settings_files[s.substr(0, eq)] = s.substr(eq + 1);
            }
            for (const auto& a : compare_assignments) {
                const auto colon = a.find(':');
                if (colon == std::string::npos || colon == 0) throw Error("--set", "'" + a + "' is not TECHNIQUE:key=value");
                compare_request.assignments[a.substr(0, colon)].push_back(a.substr(colon + 1));
            }
            compare_request.seed = seed;
            compare_request.threads = threads;
            compare_request.assets = assets;
            const std::string folder = run_compare(compare_request);
            std::cout << "wrote " << folder << "/index.html\n";
        } else if (*sweep) {
            sweep_command.assets = assets_flag;
            sweep_command.threads = threads;
            return run_sweep_command(sweep_command, std::cout, std::cerr);
        } else if (*report) {
            int n = write_html_report(report_dir);
            std::cout << comparison_summary(report_dir);
            std::cout << "wrote " << (std::filesystem::path(report_dir) / "report.html").string() << " (" << n
                      << " experiments)\n";
        } else if (*experiment) {
            if (experiment_names.size() == 1 && experiment_names[0] == "list") {
                print_list("experiments");
                return 0;
            }
            const std::string& verb = experiment_names[0];
            if (verb == "plan" || verb == "run-task" || verb == "references" || verb == "merge") {
                TaskCommand command;
                command.verb = verb;
                command.arguments.assign(experiment_names.begin() + 1, experiment_names.end());
                command.results_root = results_dir;
                command.quick = quick;
                command.seed = seed;
                command.threads = threads;
                command.assets = assets;
                command.axes = extra_axes;
                return run_task_command(command, std::cout);
            }
            ExperimentBatch batch;
            const ExperimentRegistry& registry = ExperimentRegistry::builtin();
            for (const auto& name : experiment_names) {
                if (name == "all") {
                    for (const auto& e : registry.list()) batch.experiments.push_back(&e);
                } else {
                    batch.experiments.push_back(&registry.get(name));  // an unknown name stops before anything runs
                }
            }
            std::vector<Experiment> swept;  // with --axis: the experiments along their extra axes
            if (!extra_axes.empty()) {
                swept.reserve(batch.experiments.size());
                for (const Experiment*& e : batch.experiments) e = &swept.emplace_back(declared_experiment_with_axes(e->name, extra_axes));
            }
            batch.results_root = results_dir;
            batch.quick = quick;
            batch.resume = resume;
            batch.seed = seed;
            batch.threads = threads;
            batch.assets = assets;
            return run_experiment_batch(batch, std::cout, std::cerr);
        }
    } catch (const Error& e) {
        std::cerr << "gilab: error: " << e.what() << std::endl;
        return 1;
    } catch (const std::bad_alloc&) {
        std::cerr << "gilab: error: out of memory (the memory limit is " << MemoryBudget::format(MemoryBudget::limit())
                  << "; see --memory-limit)" << std::endl;
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "gilab: internal error: " << e.what() << std::endl;
        return 2;
    }
    return 0;
}
