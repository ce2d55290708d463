// P3 Figs. 9 and 10: frame time and structure memory along a camera walk through Sponza
// and Sibenik — dense mip VCT, the cascades updating everything every frame or on their
// schedule (the update strategy), and photon mapping. One task walks one scene with one
// variant; both figures read the same walks (measured once per process).
#include <map>
#include "core/util/error.hpp"
#include "core/util/settings.hpp"
#include "core/util/stats.hpp"
#include "experiments/p3_vct/vct_common.hpp"
#include "experiments/runner/measures.hpp"
#include "experiments/runner/paper_figures.hpp"

namespace gilab::vct {

namespace {

// One variant's figures frame by frame along the walk, as the probe's row holds them.
struct WalkSeries {
    std::vector<double> total_ms, update_ms, injection_ms, bytes, rss;
    nlohmann::json to_row() const {
        return {{"total_ms", total_ms}, {"update_ms", update_ms}, {"injection_ms", injection_ms},
                {"bytes", bytes},       {"rss", rss}};
    }
};

// The walk through the task's scene with `walk` rendering each frame; a missing scene is
// skipped with a note.
ProbeOutput walk_probe(const ProbeCall& call, const std::function<WalkSeries(const Scene&, const std::vector<EyeCamera>&)>& walk) {
    const nlohmann::json what = {{"probe", call.variant.probe}, {"scene", call.task.scene},
                                 {"settings", call.variant.settings}, {"size", call.size}, {"frames", call.frames}};
    return measured_once(call, what, [&] {
        ProbeOutput out;
        const Scene* scene = nullptr;
        try {
            scene = &scene_named(call, call.task.scene);
        } catch (const Error& e) {
            out.notes.push_back(skip_note(call.ctx, call.task.scene, e.what()));
            return out;
        }
        const WalkSeries s = walk(*scene, walk_cameras(camera_walk(call.task.scene), call.size, call.frames));
        call.ctx.say(call.task.scene + ", " + call.variant.name + ": mean frame " + std::to_string(mean(s.total_ms)) + " ms");
        out.rows.push_back(s.to_row());
        return out;
    });
}

// A cone-traced variant (setting "vct", dense resolution from the axis) along the walk.
ProbeOutput vct_walk_probe(const ProbeCall& call) {
    return walk_probe(call, [&](const Scene& scene, const std::vector<EyeCamera>& cams) {
        WalkSeries s;
        auto t = make_vct(scene, vct_settings(call), call.ctx);
        for (const EyeCamera& cam : cams) {
            render(*t, cam);
            const Stats st = t->stats();
            s.total_ms.push_back(st.get("total_ms"));
            s.update_ms.push_back(st.get("update_ms"));
            s.injection_ms.push_back(st.get("injection_ms"));
            s.bytes.push_back(st.get("structure_bytes"));
            s.rss.push_back(double(current_rss_bytes()));
        }
        return s;
    });
}

// The photon technique (setting "photon") along the walk. The photon map is traced and
// built at prepare; the cone-traced variants inject light every frame, so each photon
// frame is charged that pass too (shown as its update).
ProbeOutput photon_walk_probe(const ProbeCall& call) {
    return walk_probe(call, [&](const Scene& scene, const std::vector<EyeCamera>& cams) {
        WalkSeries s;
        nlohmann::json settings = call.setting<nlohmann::json>("photon");
        settings["seed"] = call.ctx.seed;
        auto t = prepare_technique("photon", scene, Settings(settings, call.spec.name + " photon settings"));
        const Stats prepared = t->stats();
        const double photon_pass_ms = prepared.get("photon_trace_ms") + prepared.get("photon_build_ms");
        for (const EyeCamera& cam : cams) {
            render(*t, cam);
            const Stats st = t->stats();
            s.total_ms.push_back(photon_pass_ms + st.get("render_ms"));
            s.update_ms.push_back(photon_pass_ms);
            s.injection_ms.push_back(0.0);
            s.bytes.push_back(st.get("photon_map_bytes"));
            s.rss.push_back(double(current_rss_bytes()));
        }
        return s;
    });
}

// One variant's walk as the reducers read it back.
struct WalkRun {
    std::string name;
    std::vector<double> total_ms, update_ms, injection_ms, bytes, rss;
};

// Every walked scene (in plan order) with its variants' runs; skipped scenes have none.
std::vector<std::pair<std::string, std::vector<WalkRun>>> walks_of(const SpecReduction& r) {
    require_rows(r);
    std::vector<std::pair<std::string, std::vector<WalkRun>>> walks;
    for (const TaskResult& t : r.tasks) {
        if (t.rows.empty()) continue;
        if (walks.empty() || walks.back().first != t.task.scene) walks.push_back({t.task.scene, {}});
        const nlohmann::json& row = t.rows.at(0);
        using Series = std::vector<double>;
        walks.back().second.push_back({row.at("variant").get<std::string>(), row.at("total_ms").get<Series>(),
                                       row.at("update_ms").get<Series>(), row.at("injection_ms").get<Series>(),
                                       row.at("bytes").get<Series>(), row.at("rss").get<Series>()});
    }
    return walks;
}

const WalkRun& run_named(const std::vector<WalkRun>& runs, const std::string& name) {
    for (const WalkRun& r : runs)
        if (r.name == name) return r;
    throw Error("vct walks", "no variant '" + name + "'");
}

std::vector<double> after_first(const std::vector<double>& v) {
    return std::vector<double>(v.begin() + (v.size() > 1 ? 1 : 0), v.end());
}

Plot walk_plot(const std::string& title, const std::string& y_label, const std::vector<WalkRun>& runs,
               double (*value)(const WalkRun&, size_t)) {
    Plot plot{title, "frame", y_label, false, true, {}};
    for (const WalkRun& r : runs) {
        PlotSeries series{r.name, {}, {}, false, true, -1};
        for (size_t f = 0; f < r.total_ms.size(); ++f) {
            series.x.push_back(double(f + 1));
            series.y.push_back(value(r, f));
        }
        plot.series.push_back(std::move(series));
    }
    return plot;
}

ExperimentOutput fig9(const SpecReduction& r) {
    ExperimentOutput out;
    ResultTable summary;
    summary.title = "Fig. 9 summary — mean over each walk (first frame excluded: every variant starts from a full build)";
    summary.columns = {"scene", "variant", "frame_ms", "update_ms", "injection_ms", "fps", "paper"};
    // Fig. 9 prints no values: the paper's findings from its text.
    const PaperFigures& paper = paper_figures("p3/fig9");
    for (const auto& [scene, runs] : walks_of(r)) {
        ResultTable t;
        t.title = "Fig. 9 — frame time along a walk through " + scene;
        t.columns = {"frame"};
        for (const WalkRun& run : runs) {
            t.columns.push_back(run.name + " ms");
            t.columns.push_back(run.name + " fps");
        }
        for (size_t f = 0; f < runs[0].total_ms.size(); ++f) {
            nlohmann::json row = {{"frame", f + 1}};
            for (const WalkRun& run : runs) {
                row[run.name + " ms"] = run.total_ms[f];
                row[run.name + " fps"] = 1000.0 / run.total_ms[f];
            }
            t.rows.push_back(row);
        }
        out.tables.push_back(std::move(t));
        out.plots.push_back({"fig9_" + scene, walk_plot("Fig. 9 — frame time along the walk through " + scene,
                                                         "frame time (ms, log scale)", runs,
                                                         [](const WalkRun& w, size_t f) { return w.total_ms[f]; })});
        for (const WalkRun& run : runs) {
            const double ms = mean(after_first(run.total_ms));
            // The paper's finding for the curve this variant stands for.
            const char* curve = run.name == "dense mip"                   ? "VXGI"
                                : run.name == "cascaded, update strategy" ? "cascaded with update strategy"
                                : run.name == "photon mapping"            ? "PM"
                                                                          : "cascaded without update strategy";
            summary.rows.push_back({{"scene", scene},
                                    {"variant", run.name},
                                    {"frame_ms", ms},
                                    {"update_ms", mean(after_first(run.update_ms))},
                                    {"injection_ms", run.name == "photon mapping" ? nlohmann::json()
                                                                                 : nlohmann::json(mean(after_first(run.injection_ms)))},
                                    {"fps", 1000.0 / ms},
                                    {"paper", paper.row({{"curve", curve}}).text("finding")}});
        }
        const double everything = mean(after_first(run_named(runs, "cascaded, update everything").update_ms));
        const double strategy = mean(after_first(run_named(runs, "cascaded, update strategy").update_ms));
        summary.rows.push_back({{"scene", scene}, {"variant", "update time: everything ÷ strategy"}, {"frame_ms", nullptr},
                                {"update_ms", strategy > 0 ? everything / strategy : 0.0}, {"injection_ms", nullptr},
                                {"fps", nullptr},
                                {"paper", paper.row({{"curve", "update time VXGI / cascaded"}}).text("finding")}});
    }
    out.tables.push_back(std::move(summary));
    out.notes = quick_notes(r.ctx);
    return out;
}

ExperimentOutput fig10(const SpecReduction& r) {
    ExperimentOutput out;
    ResultTable summary;
    summary.title = "Fig. 10 summary — mean structure memory over each walk, each variant ÷ dense";
    summary.columns = {"scene", "variant", "mean structure (MB)", "over_dense", "paper over_dense"};
    // Fig. 10 prints no values: its text gives the cascades' memory as about 40 % of VXGI's.
    auto paper_over_dense = [](const std::string& variant) {
        const char* curve = variant == "dense mip" ? "VXGI" : variant.starts_with("cascaded") ? "cascaded" : nullptr;
        if (!curve) return nlohmann::json();
        return nlohmann::json(paper_figures("p3/fig10").row({{"curve", curve}}).number("memory over VXGI"));
    };
    for (const auto& [scene, runs] : walks_of(r)) {
        ResultTable t;
        t.title = "Fig. 10 — memory along the walk through " + scene + " (MB = 10⁶ B, of each structure; process RSS)";
        t.columns = {"frame"};
        for (const WalkRun& run : runs) t.columns.push_back(run.name + " (MB)");
        t.columns.push_back("process RSS (MB)");
        for (size_t f = 0; f < runs[0].bytes.size(); ++f) {
            nlohmann::json row = {{"frame", f + 1}};
            for (const WalkRun& run : runs) row[run.name + " (MB)"] = mb(run.bytes[f]);
            row["process RSS (MB)"] = mb(runs.back().rss[f]);
            t.rows.push_back(row);
        }
        out.tables.push_back(std::move(t));
        out.plots.push_back({"fig10_" + scene, walk_plot("Fig. 10 — structure memory along the walk through " + scene,
                                                          "memory (MB = 10⁶ B, log scale)", runs,
                                                          [](const WalkRun& w, size_t f) { return mb(w.bytes[f]); })});
        for (const WalkRun& run : runs)
            summary.rows.push_back({{"scene", scene},
                                    {"variant", run.name},
                                    {"mean structure (MB)", mb(mean(run.bytes))},
                                    {"over_dense", mean(run.bytes) / mean(runs[0].bytes)},
                                    {"paper over_dense", paper_over_dense(run.name)}});
    }
    out.tables.push_back(std::move(summary));
    out.notes = quick_notes(r.ctx);
    return out;
}

// The walks and variants both figures take.
const std::vector<std::string> kWalkScenes = {"sponza", "sibenik"};
const std::vector<SpecVariant> kWalkVariants = {
    {.name = "dense mip", .probe = "vct-walk", .settings = {{"vct", {{"structure", "dense"}, {"update", "everything"}}}}},
    {.name = "cascaded, update everything", .probe = "vct-walk", .settings = {{"vct", {{"update", "everything"}}}}},
    {.name = "cascaded, update strategy", .probe = "vct-walk", .settings = {{"vct", {{"update", "strategy"}}}}},
    // P1's middle photon count, a radius of 0.5 m (about 1/70 of either nave's length;
    // both scenes are in metres), direct light by shadow rays as in the cone-traced variants.
    {.name = "photon mapping", .probe = "photon-walk", .settings = {{"photon", {{"photons", 256 * 256}, {"radius", 0.5}}}}}};
const SpecAxis kDenseResolution = {"dense_resolution", {128}, {64}};

std::string walk_note() {
    std::string note = "Camera walks, straight down each nave, looking ahead and slightly up, 60° field of view: ";
    for (const CameraWalk& w : camera_walks()) note += w.scene + ": " + w.description + "; ";
    return note.substr(0, note.size() - 2) + ".";
}

}  // namespace

void register_camera_walks(ExperimentRegistry& registry) {
    add_probe("vct-walk", vct_walk_probe);
    add_probe("photon-walk", photon_walk_probe);
    add_reducer("vct-fig9", fig9);
    add_reducer("vct-fig10", fig10);
    registry.add(declared_experiment({
        .name = "vct-fig9",
        .paper = "P3",
        .figure = "Fig. 9",
        .description = "frame time along walks through Sponza and Sibenik: dense, cascaded without/with the update strategy, photon mapping",
        .scenes = kWalkScenes,
        .size = 192, .quick_size = 32,
        .frames = 30, .quick_frames = 4,
        .variants = kWalkVariants,
        .axes = {kDenseResolution},
        .reducer = "vct-fig9",
        .notes = {walk_note(),
                  "frame_ms for the cone-traced variants = update + injection + primary + direct + diffuse + specular "
                  "for one render() on the CPU, all threads. Photon mapping = the photon pass (trace 256² photons + "
                  "build the hash grid, measured once at prepare and charged to every frame, as the cone tracers "
                  "re-inject light every frame; shown as its update_ms) + the render (primary rays, shadow rays, "
                  "radius gather at r = 0.5 m). LPV, the paper's fifth curve, is not built.",
                  "The plots show our curves only: the paper draws its curves without printing their values."},
    }));
    registry.add(declared_experiment({
        .name = "vct-fig10",
        .paper = "P3",
        .figure = "Fig. 10",
        .description = "structure memory along the walks through Sponza and Sibenik",
        .scenes = kWalkScenes,
        .size = 192, .quick_size = 32,
        .frames = 30, .quick_frames = 4,
        .variants = kWalkVariants,
        .axes = {kDenseResolution},
        .reducer = "vct-fig10",
        .notes = {walk_note(),
                  "Structure memory = every attribute array the technique holds (dense: both radiance mip chains as "
                  "float RGBA × 6 faces + the sparse G-buffer list; cascaded: 6 × 32³ × 6 faces of G-buffer and two "
                  "radiance buffers; photon mapping: the hash-grid photon map). Process RSS is the whole process "
                  "after each frame of the last variant. The paper reports whole-application memory (cascaded ≈ 40 % "
                  "of VXGI; its PM figure is only drawn, not printed)."},
    }));
}

}  // namespace gilab::vct
