// P3 Figs. 9 and 10: frame time and structure memory along a camera walk through Sponza
// and Sibenik — dense mip VCT, the cascades updating everything every frame or on their
// schedule (the update strategy), light propagation volumes and photon mapping. One task walks one scene with one
// variant; each figure walks in its own run. A partial merge leaves the cells of the
// tasks that have not run empty.
#include <functional>
#include <map>
#include <optional>
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
    ProbeOutput out;
    const Scene* scene = scene_or_skip(call, call.task.scene, out);
    if (!scene) return out;
    const WalkSeries s = walk(*scene, walk_cameras(camera_walk(call.task.scene), call.size, call.frames));
    call.ctx.say(call.task.scene + ", " + call.variant.name + ": mean frame " + std::to_string(mean(s.total_ms)) + " ms");
    out.rows.push_back(s.to_row());
    return out;
}

// The stats a technique names its frame time, update, injection and structure bytes by.
struct WalkStats {
    const char *total, *update, *injection, *bytes;
};

// Technique `t` rendering every camera of the walk, its figures after each frame.
WalkSeries walk_technique(Technique& t, const std::vector<EyeCamera>& cams, const WalkStats& keys) {
    WalkSeries s;
    for (const EyeCamera& cam : cams) {
        render(t, cam);
        const Stats st = t.stats();
        s.total_ms.push_back(st.get(keys.total));
        s.update_ms.push_back(st.get(keys.update));
        s.injection_ms.push_back(st.get(keys.injection));
        s.bytes.push_back(st.get(keys.bytes));
        s.rss.push_back(double(current_rss_bytes()));
    }
    return s;
}

// A cone-traced variant (setting "vct", dense resolution from the axis) along the walk.
ProbeOutput vct_walk_probe(const ProbeCall& call) {
    return walk_probe(call, [&](const Scene& scene, const std::vector<EyeCamera>& cams) {
        auto t = make_vct(scene, vct_settings(call), call.ctx);
        return walk_technique(*t, cams, {"total_ms", "update_ms", "injection_ms", "structure_bytes"});
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

// Cascaded light propagation volumes (setting "lpv") along the walk: every frame renders
// the reflective shadow maps, injects, propagates and looks up (its update), as the
// cone tracers re-inject every frame.
ProbeOutput lpv_walk_probe(const ProbeCall& call) {
    return walk_probe(call, [&](const Scene& scene, const std::vector<EyeCamera>& cams) {
        nlohmann::json settings = call.setting<nlohmann::json>("lpv");
        settings["seed"] = call.ctx.seed;
        auto t = prepare_technique("lpv", scene, Settings(settings, call.spec.name + " lpv settings"));
        return walk_technique(*t, cams, {"total_ms", "lpv_ms", "inject_ms", "structure_bytes"});
    });
}

// One variant's walk as the reducers read it back.
struct WalkRun {
    std::string name;
    std::vector<double> total_ms, update_ms, injection_ms, bytes, rss;
};

// One walked scene: each variant of the spec, in its order, with its run or null when its
// task has not been merged.
struct SceneWalks {
    std::string scene;
    std::vector<std::pair<std::string, std::optional<WalkRun>>> variants;
    const WalkRun* run(const std::string& variant) const {
        for (const auto& [name, run] : variants)
            if (name == variant && run) return &*run;
        return nullptr;
    }
    std::vector<WalkRun> runs() const {  // the variants that ran
        std::vector<WalkRun> out;
        for (const auto& [name, run] : variants)
            if (run) out.push_back(*run);
        return out;
    }
};

// Every scene with at least one walk (in plan order); scenes skipped or not merged have
// none. `notes` gains, per scene, the variants without a walk.
std::vector<SceneWalks> walks_of(const SpecReduction& r, std::vector<std::string>& notes) {
    require_rows(r);
    std::vector<SceneWalks> walks;
    for (const TaskResult& t : r.tasks) {
        if (t.rows.empty()) continue;
        if (walks.empty() || walks.back().scene != t.task.scene) {
            walks.push_back({t.task.scene, {}});
            for (const SpecVariant& v : r.spec.variants) walks.back().variants.push_back({v.name, std::nullopt});
        }
        for (const nlohmann::json& row : t.rows) {
            using Series = std::vector<double>;
            WalkRun run{row.at("variant").get<std::string>(), row.at("total_ms").get<Series>(),
                        row.at("update_ms").get<Series>(),    row.at("injection_ms").get<Series>(),
                        row.at("bytes").get<Series>(),        row.at("rss").get<Series>()};
            for (auto& [name, slot] : walks.back().variants)
                if (name == run.name) slot = std::move(run);
        }
    }
    for (const SceneWalks& w : walks) {
        std::string absent;
        for (const auto& [name, run] : w.variants)
            if (!run) absent += (absent.empty() ? "'" : ", '") + name + "'";
        if (!absent.empty())
            notes.push_back(w.scene + ": no walk for " + absent + " (task not merged); its cells are empty.");
    }
    return walks;
}

// `value` of `run`, or null without a run.
nlohmann::json cell(const WalkRun* run, const std::function<double(const WalkRun&)>& value) {
    return run ? nlohmann::json(value(*run)) : nlohmann::json();
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
    std::vector<std::string> absent;
    for (const SceneWalks& walk : walks_of(r, absent)) {
        const std::string& scene = walk.scene;
        ResultTable t;
        t.title = "Fig. 9 — frame time along a walk through " + scene;
        t.columns = {"frame"};
        for (const auto& [name, run] : walk.variants) {
            t.columns.push_back(name + " ms");
            t.columns.push_back(name + " fps");
        }
        for (size_t f = 0; f < size_t(r.frames()); ++f) {
            nlohmann::json row = {{"frame", f + 1}};
            for (const auto& [name, run] : walk.variants) {
                const bool measured = run && f < run->total_ms.size();
                row[name + " ms"] = measured ? nlohmann::json(run->total_ms[f]) : nlohmann::json();
                row[name + " fps"] = measured ? nlohmann::json(1000.0 / run->total_ms[f]) : nlohmann::json();
            }
            t.rows.push_back(row);
        }
        out.tables.push_back(std::move(t));
        out.plots.push_back({"fig9_" + scene, walk_plot("Fig. 9 — frame time along the walk through " + scene,
                                                         "frame time (ms, log scale)", walk.runs(),
                                                         [](const WalkRun& w, size_t f) { return w.total_ms[f]; })});
        for (const auto& [name, run] : walk.variants) {
            const WalkRun* w = run ? &*run : nullptr;
            // The paper's finding for the curve this variant stands for.
            const char* curve = name == "dense mip"                   ? "VXGI"
                                : name == "cascaded, update strategy" ? "cascaded with update strategy"
                                : name == "photon mapping"            ? "PM"
                                : name == "LPV"                       ? "LPV"
                                                                      : "cascaded without update strategy";
            summary.rows.push_back(
                {{"scene", scene},
                 {"variant", name},
                 {"frame_ms", cell(w, [](const WalkRun& x) { return mean(after_first(x.total_ms)); })},
                 {"update_ms", cell(w, [](const WalkRun& x) { return mean(after_first(x.update_ms)); })},
                 {"injection_ms", name == "photon mapping"
                                      ? nlohmann::json()
                                      : cell(w, [](const WalkRun& x) { return mean(after_first(x.injection_ms)); })},
                 {"fps", cell(w, [](const WalkRun& x) { return 1000.0 / mean(after_first(x.total_ms)); })},
                 {"paper", paper.row({{"curve", curve}}).text("finding")}});
        }
        const WalkRun* everything = walk.run("cascaded, update everything");
        const WalkRun* strategy = walk.run("cascaded, update strategy");
        nlohmann::json ratio;
        if (everything && strategy) {
            const double e = mean(after_first(everything->update_ms)), s = mean(after_first(strategy->update_ms));
            ratio = s > 0 ? e / s : 0.0;
        }
        summary.rows.push_back({{"scene", scene}, {"variant", "update time: everything ÷ strategy"}, {"frame_ms", nullptr},
                                {"update_ms", ratio}, {"injection_ms", nullptr},
                                {"fps", nullptr},
                                {"paper", paper.row({{"curve", "update time VXGI / cascaded"}}).text("finding")}});
    }
    out.tables.push_back(std::move(summary));
    out.notes = quick_notes(r, {.images = true, .frames = true, .cones = true});
    out.notes.insert(out.notes.end(), absent.begin(), absent.end());
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
    std::vector<std::string> absent;
    for (const SceneWalks& walk : walks_of(r, absent)) {
        const std::string& scene = walk.scene;
        // The process RSS column follows the last variant of the spec.
        const WalkRun* last = walk.variants.back().second ? &*walk.variants.back().second : nullptr;
        ResultTable t;
        t.title = "Fig. 10 — memory along the walk through " + scene + " (MB = 10⁶ B, of each structure; process RSS)";
        t.columns = {"frame"};
        for (const auto& [name, run] : walk.variants) t.columns.push_back(name + " (MB)");
        t.columns.push_back("process RSS (MB)");
        for (size_t f = 0; f < size_t(r.frames()); ++f) {
            nlohmann::json row = {{"frame", f + 1}};
            for (const auto& [name, run] : walk.variants)
                row[name + " (MB)"] =
                    run && f < run->bytes.size() ? nlohmann::json(mb(run->bytes[f])) : nlohmann::json();
            row["process RSS (MB)"] = last && f < last->rss.size() ? nlohmann::json(mb(last->rss[f])) : nlohmann::json();
            t.rows.push_back(row);
        }
        out.tables.push_back(std::move(t));
        out.plots.push_back({"fig10_" + scene, walk_plot("Fig. 10 — structure memory along the walk through " + scene,
                                                          "memory (MB = 10⁶ B, log scale)", walk.runs(),
                                                          [](const WalkRun& w, size_t f) { return mb(w.bytes[f]); })});
        const WalkRun* dense = walk.run("dense mip");
        for (const auto& [name, run] : walk.variants) {
            const WalkRun* w = run ? &*run : nullptr;
            const WalkRun* over = dense ? w : nullptr;  // no ratio without the dense walk
            summary.rows.push_back(
                {{"scene", scene},
                 {"variant", name},
                 {"mean structure (MB)", cell(w, [](const WalkRun& x) { return mb(mean(x.bytes)); })},
                 {"over_dense", cell(over, [&](const WalkRun& x) { return mean(x.bytes) / mean(dense->bytes); })},
                 {"paper over_dense", paper_over_dense(name)}});
        }
    }
    out.tables.push_back(std::move(summary));
    out.notes = quick_notes(r, {.images = true, .frames = true, .cones = true});
    out.notes.insert(out.notes.end(), absent.begin(), absent.end());
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
    {.name = "photon mapping", .probe = "photon-walk", .settings = {{"photon", {{"photons", 256 * 256}, {"radius", 0.5}}}}},
    // Kaplanyan & Dachsbacher's defaults (lpv's): 3 cascades of 32³, 8 iterations.
    {.name = "LPV", .probe = "lpv-walk", .settings = {{"lpv", nlohmann::json::object()}}}};
const SpecAxis kDenseResolution = {"dense_resolution", {128}, {32}};

std::string walk_note() {
    std::string note = "Camera walks, straight down each nave, looking ahead and slightly up, 60° field of view: ";
    for (const CameraWalk& w : camera_walks()) note += w.scene + ": " + w.description + "; ";
    return note.substr(0, note.size() - 2) + ".";
}

}  // namespace

void register_camera_walks(ExperimentRegistry& registry) {
    add_probe("vct-walk", vct_walk_probe);
    add_probe("photon-walk", photon_walk_probe);
    add_probe("lpv-walk", lpv_walk_probe);
    add_reducer("vct-fig9", fig9);
    add_reducer("vct-fig10", fig10);
    registry.add(declared_experiment({
        .name = "vct-fig9",
        .paper = "P3",
        .figure = "Fig. 9",
        .description = "frame time along walks through Sponza and Sibenik: dense, cascaded without/with the update strategy, photon mapping, LPV",
        .scenes = kWalkScenes,
        .size = 192, .quick_size = 32,
        .frames = 30, .quick_frames = 2,
        .variants = kWalkVariants,
        .axes = {kDenseResolution},
        .reducer = "vct-fig9",
        .notes = {walk_note(),
                  "frame_ms for the cone-traced variants = update + injection + primary + direct + diffuse + specular "
                  "for one render() on the CPU, all threads. Photon mapping = the photon pass (trace 256² photons + "
                  "build the hash grid, measured once at prepare and charged to every frame, as the cone tracers "
                  "re-inject light every frame; shown as its update_ms) + the render (primary rays, shadow rays, "
                  "radius gather at r = 0.5 m). LPV = reflective shadow maps + injection + propagation (its update_ms; "
                  "injection_ms the VPL and geometry-volume injection) + primary + direct + lookup, every frame.",
                  "The plots show our curves only: the paper draws its curves without printing their values."},
    }));
    registry.add(declared_experiment({
        .name = "vct-fig10",
        .paper = "P3",
        .figure = "Fig. 10",
        .description = "structure memory along the walks through Sponza and Sibenik",
        .scenes = kWalkScenes,
        .size = 192, .quick_size = 32,
        .frames = 30, .quick_frames = 2,
        .variants = kWalkVariants,
        .axes = {kDenseResolution},
        .reducer = "vct-fig10",
        .notes = {walk_note(),
                  "Structure memory = every attribute array the technique holds (dense: the radiance mip chain as "
                  "RGBA16F × 6 faces, its occupancy bits and the sparse G-buffer list; cascaded: the radiance "
                  "buffer of 6 × 32³ × 6 faces RGBA16F, its occupancy bits and the sparse G-buffer — a bit per "
                  "texel and axis, rank counts and a 12-byte record per occupied axis of a voxel; photon mapping: the hash-grid photon map; LPV: per cascade its four SH volumes, geometry "
                  "volume and face transmittances, and the frame's VPLs and surfels). Process RSS is the whole process "
                  "after each frame of the last variant. The paper reports whole-application memory (cascaded ≈ 40 % "
                  "of VXGI; its PM figure is only drawn, not printed)."},
    }));
}

}  // namespace gilab::vct
