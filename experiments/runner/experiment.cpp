#include "experiments/runner/experiment.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <iostream>
#include <sstream>
#include "core/util/error.hpp"
#include "core/image/image_io.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/plot.hpp"
#include "experiments/runner/result_writers.hpp"
#include "experiments/runner/spec_runner.hpp"

namespace gilab {

namespace {
// Image alt text: brackets and backslashes would end or bend the markdown link.
std::string markdown_alt_text(const std::string& text) {
    std::string out;
    for (char c : text) {
        if (c == '[' || c == ']' || c == '\\') out += '\\';
        out += (c == '\n' || c == '\r') ? ' ' : c;
    }
    return out;
}
}  // namespace

void ExperimentContext::say(const std::string& message) const {
    if (log) *log << "  " << message << std::endl;
}

void ExperimentRegistry::add(Experiment experiment) {
    if (find(experiment.name)) throw Error("experiment registry", "duplicate experiment '" + experiment.name + "'");
    experiments_.push_back(std::move(experiment));
}

const Experiment* ExperimentRegistry::find(const std::string& name) const {
    for (const auto& e : experiments_)
        if (e.name == name) return &e;
    return nullptr;
}

const Experiment& ExperimentRegistry::get(const std::string& name) const {
    if (const Experiment* e = find(name)) return *e;
    std::string known;
    for (const auto& e : experiments_) known += (known.empty() ? "" : ", ") + e.name;
    throw Error(name, "unknown experiment (known: " + known + ")");
}

Experiment declared_experiment(ExperimentSpec spec) {
    spec.check();
    auto shared = std::make_shared<const ExperimentSpec>(std::move(spec));
    Experiment e;
    e.name = shared->name;
    e.paper = shared->paper;
    e.description = shared->figure + ": " + shared->description;
    e.spec = shared;
    e.run = [shared](const ExperimentContext& ctx) { return run_spec(*shared, ctx); };
    return e;
}

namespace {

// " --axis SETTING=V1,V2" for each axis of the experiment's spec that its declared spec
// lacks or sweeps differently (with_extra_axes), so the table says how it was run.
std::string swept_axes(const Experiment& experiment) {
    const Experiment* declared = ExperimentRegistry::builtin().find(experiment.name);
    if (!experiment.spec || !declared || !declared->spec) return "";
    std::string out;
    for (const SpecAxis& axis : experiment.spec->axes) {
        if (axis.setting.empty()) continue;
        const auto& declared_axes = declared->spec->axes;
        const bool same = std::any_of(declared_axes.begin(), declared_axes.end(), [&axis](const SpecAxis& d) {
            return d.setting == axis.setting && d.full == axis.full && d.quick == axis.quick;
        });
        if (same) continue;
        out += " --axis " + axis.setting + "=";
        for (size_t i = 0; i < axis.full.size(); ++i) {
            if (i > 0) out += ',';
            out += axis.full[i].is_string() ? axis.full[i].get<std::string>() : axis.full[i].dump();
        }
    }
    return out;
}

}  // namespace

ExperimentOutput run_and_write(const Experiment& experiment, ExperimentContext context) {
    std::filesystem::create_directories(context.output_dir);
    Stopwatch watch;
    ExperimentOutput output = experiment.run(context);
    double seconds = watch.elapsed_ms() / 1000.0;
    if (output.tables.empty()) throw Error(experiment.name, "experiment produced no table");

    // Figures are drawn before results.json is written, so the files and notes it lists
    // are final. A figure that cannot be drawn must not cost the run its tables.
    std::vector<std::pair<std::string, std::string>> drawn;  // (file, caption)
    std::vector<std::string> plot_names;
    for (const auto& [name, plot] : output.plots) {
        try {
            if (std::find(plot_names.begin(), plot_names.end(), name) != plot_names.end())
                throw Error("plot '" + name + "'", "duplicate plot name");
            plot_names.push_back(name);
            std::string file = write_svg_plot(plot, context.output_dir, name);
            drawn.emplace_back(file, plot.title.empty() ? name : plot.title);
            if (std::find(output.files.begin(), output.files.end(), file) == output.files.end()) output.files.push_back(file);
        } catch (const Error& e) {
            output.notes.push_back("Plot " + name + " was not drawn: " + e.what());
            context.say("plot " + name + " not drawn: " + e.what());
        }
    }

    nlohmann::json doc;
    doc["experiment"] = experiment.name;
    doc["paper"] = experiment.paper;
    doc["description"] = experiment.description;
    doc["quick"] = context.quick;
    doc["seed"] = context.seed;
    doc["threads"] = context.threads > 0 ? context.threads : int(machine_description()["tbb_threads"]);
    doc["git_revision"] = git_revision();
    doc["machine"] = machine_description();
    doc["wall_seconds"] = seconds;
    doc["peak_rss_mib"] = double(peak_rss_bytes()) / (1024.0 * 1024.0);
    std::time_t now = std::time(nullptr);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    doc["finished_utc"] = stamp;
    doc["config"] = output.config;
    doc["notes"] = output.notes;
    doc["files"] = output.files;
    nlohmann::json tables = nlohmann::json::array();
    for (const auto& t : output.tables) tables.push_back({{"title", t.title}, {"columns", t.columns}, {"rows", t.rows}});
    doc["tables"] = tables;

    std::ostringstream md;
    md << "# " << experiment.name << " — " << experiment.description << "\n\n";
    md << "Measured by `gilab experiment " << experiment.name << (context.quick ? " --quick" : "") << swept_axes(experiment)
       << "` at revision `" << git_revision() << "`, seed " << context.seed << ", on "
       << doc["machine"].value("cpu", std::string("unknown CPU")) << " (" << doc["threads"] << " threads). "
       << "Columns named *paper …* are the published figures (reference data, the paper's hardware); "
       << "every other figure was measured by this run.\n\n";
    if (context.quick) md << "**Quick run**: reduced sizes for a smoke check; figures are not comparable to the paper's.\n\n";
    for (const auto& t : output.tables) md << to_markdown(t) << "\n";
    for (const auto& [file, caption] : drawn) md << "![" << markdown_alt_text(caption) << "](" << file << ")\n\n";
    for (const auto& note : output.notes) md << "- " << note << "\n";
    md << "\nWall time " << seconds << " s.\n";

    // Each file is written atomically; results.json goes last so its presence means the
    // run completed.
    write_file_atomically(context.output_dir / "results.csv", to_csv(output.tables.front()));
    write_file_atomically(context.output_dir / "table.md", md.str());
    write_file_atomically(context.output_dir / "results.json", doc.dump(2) + "\n");
    return output;
}

}  // namespace gilab
