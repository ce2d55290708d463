// P1 on the headset: Table 5 (both eyes, eyes separately vs stereo reuse), the final
// renders of Figs. 9–11 with their frame times, and the foveated gather the paper leaves as
// future work. Every variant is a setting of the `photon` technique on an HMD stereo
// pair (HTC Vive preset, the scene's fixed head pose). Each task is one scene and one
// point; a probe prepares the point's photon variants once and renders them in turn frame
// by frame (so load changes hit them alike), figures are medians over the frames. A
// reducer lays the probes' rows out as the published tables.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include "core/image/image_io.hpp"
#include "core/image/image_metrics.hpp"
#include "core/scene/hmd.hpp"
#include "core/scene/scene.hpp"
#include "core/util/error.hpp"
#include "core/util/settings.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/interleaved_render.hpp"
#include "experiments/runner/measures.hpp"
#include "experiments/runner/paper_figures.hpp"
#include "experiments/runner/path_reference.hpp"
#include "experiments/runner/spec_functions.hpp"
#include "techniques/photon_mapping/foveation.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace {

using nlohmann::json;

std::string squared(int side) { return std::to_string(side) + "²"; }
int side_of(const json& photons) { return int(std::lround(std::sqrt(photons.get<double>()))); }

// The Cornell box (builtin) and the largest office-like interior of the shared assets,
// the paper's "Office" (~710k triangles; the conference room has 331k).
std::string label_of(const std::string& scene) { return scene == "cornell" ? "cornell" : "conference (Office)"; }
bool is_office(const std::string& scene) { return scene != "cornell"; }

// The task's scene, or a note saying why it is skipped.
const Scene* scene_or_note(const ProbeCall& call, ProbeOutput& out) {
    std::string why;
    const Scene* scene = call.scene_or_null(&why);
    if (!scene) {
        out.notes.push_back("Office scene skipped: " + why);
        call.ctx.say("skipping " + call.task.scene + ": " + why);
    }
    return scene;
}

// Per-eye resolution: the Vive's 1080×1200, a fifth of it per side in quick runs.
HmdRig vive_rig(const Scene& scene, bool quick) {
    HmdRig rig(find_hmd_preset("vive"));
    if (!scene.hmd) throw Error(scene.name, "scene has no HMD pose");
    rig.set_pose(scene.hmd->pose);
    if (scene.hmd->ipd) rig.set_ipd(*scene.hmd->ipd);
    if (quick) rig.set_resolution(216, 240);
    return rig;
}

ViewSet stereo_views(const HmdRig& rig) { return ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right)); }

struct Run {
    std::vector<Film> films;
    Stats stats;  // of the last frame, with medians of the timings
};

// The probe's photon settings (every key but the probe's own), with `own` on top.
json photon_settings(const ProbeCall& call, const std::vector<std::string>& probe_keys, const json& own = json::object()) {
    json s = call.variant.settings;
    for (const std::string& key : probe_keys) s.erase(key);
    s["seed"] = call.ctx.seed;
    s.update(own);
    return s;
}

// Prepares every variant, then renders them in turn for the task's frames.
std::vector<Run> measure(const ProbeCall& call, const Scene& scene, const ViewSet& views,
                         const std::vector<json>& variants) {
    const size_t n = variants.size();
    std::vector<std::unique_ptr<Technique>> techniques;
    for (const json& v : variants)
        techniques.push_back(prepare_technique("photon", scene, Settings(v, call.spec.name + " settings")));
    const std::vector<std::string> timed = {"render_ms", "left_ms", "right_ms", "claim_ms", "right_pass_ms"};
    InterleavedRender rendered = render_interleaved(techniques, views, call.frames, timed);
    std::vector<Run> runs(n);
    for (size_t v = 0; v < n; ++v) {
        runs[v].films = std::move(rendered.runs[v].films);
        runs[v].stats = rendered.runs[v].last;
        for (const std::string& key : timed) runs[v].stats.set(key, median(rendered.runs[v].per_frame.at(key)));
        call.ctx.say(variants[v].dump() + ": " + std::to_string(runs[v].stats.get("render_ms")) + " ms");
    }
    return runs;
}

// Share of pixels whose luminance differs from the reference's by more than 5 % (+0.01
// absolute): unlike relMSE, not dominated by a few pixels at the edge of a bright light.
double pixels_off_5pct(const Film& image, const Film& reference) {
    size_t off = 0;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x) {
            const float a = luminance(image.get("color", x, y)), b = luminance(reference.get("color", x, y));
            off += std::abs(a - b) > 0.05f * std::abs(b) + 0.01f;
        }
    return double(off) / double(image.pixel_count());
}

// Pixels in full-rate gather blocks (inside = true) or in coarser ones.
std::vector<uint8_t> fovea_mask(const EyeCamera& eye, float degrees, bool inside) {
    FoveationSettings f;
    f.enabled = true;
    f.fovea_degrees = degrees;
    std::vector<uint8_t> mask(size_t(eye.width()) * size_t(eye.height()));
    for (int y = 0; y < eye.height(); ++y)
        for (int x = 0; x < eye.width(); ++x)
            mask[size_t(y) * size_t(eye.width()) + size_t(x)] = (foveated_block_size(eye, f, x, y) == 1) == inside;
    return mask;
}

// The path-traced reference's samples: the scene's in full runs, the spec's quick count
// in quick runs.
int reference_spp_for(const ProbeCall& call) {
    return call.ctx.quick ? call.reference_spp : call.setting<json>("reference_spp").at(call.task.scene).get<int>();
}

// A reducer's table: the probes' rows with `columns`, the rows of `part` only (all when "").
ResultTable rows_table(const SpecReduction& r, std::string title, std::vector<std::string> columns,
                       const std::string& part = "") {
    ResultTable t{std::move(title), std::move(columns), {}};
    for (const TaskResult& task : r.tasks) {
        if (!part.empty() && task.task.axes.value("part", std::string()) != part) continue;
        for (const json& row : task.rows) {
            json shown;
            for (const std::string& c : t.columns) shown[c] = row.value(c, json());
            t.rows.push_back(shown);
        }
    }
    return t;
}

// ---------------------------------------------------------------------------------
// Table 5 and the reuse sweep over eye separation and viewing distance

json reuse_figures(const Run& separate, const Run& reuse) {
    json r;
    const Stats& s = reuse.stats;
    r["separate_ms"] = separate.stats.get("render_ms");
    r["reuse_ms"] = s.get("render_ms");
    r["speedup"] = separate.stats.get("render_ms") / s.get("render_ms");
    r["left_ms"] = s.get("left_ms");
    r["right_ms"] = s.get("right_ms");
    r["right_over_left"] = s.get("right_ms") / s.get("left_ms");
    r["reuse_fraction"] = s.get("reuse_fraction");
    const double claimed = s.get("reuse_claimed_pixels");
    r["depth_conflicts"] = claimed > 0 ? s.get("reuse_depth_conflicts") / claimed : 0.0;
    r["relmse_right"] = relative_mse(reuse.films.at(1), separate.films.at(1), "color");
    r["right_off_5pct"] = pixels_off_5pct(reuse.films.at(1), separate.films.at(1));
    return r;
}

// Keys of the stereo probes' settings that are not photon settings.
const std::vector<std::string> kProbeKeys = {"part", "ipd_m", "wall_distance", "hmd", "reference_spp",
                                             "fovea_angles"};

json with(json base, const json& own) {
    base.update(own);
    return base;
}

// A Table 5 row: eyes separately, then stereo reuse with nearest-pixel claims, strict
// claims, and nearest claims with crack filling.
json table5_row(const ProbeCall& call, const Scene& scene, const json& base) {
    const ViewSet views = stereo_views(vive_rig(scene, call.ctx.quick));
    const json nearest = with(base, {{"stereo_reuse", true}});
    const std::vector<Run> runs = measure(call, scene, views,
                                          {base, nearest, with(nearest, {{"stereo_match", "strict"}}),
                                           with(nearest, {{"stereo_fill", true}})});
    json r = reuse_figures(runs[0], runs[1]);
    const int side = side_of(call.variant.settings.at("photons"));
    const int paper_side = call.ctx.quick ? 2 * side : side;  // quick runs emit a quarter
    const double radius = call.setting<double>("radius");
    r["scene"] = label_of(call.task.scene);
    r["photons"] = squared(side);
    r["paper photons"] = squared(paper_side);
    r["r"] = radius;
    const char* suffixes[] = {"strict", "fill"};
    for (int i = 0; i < 2; ++i) {
        const std::string s = suffixes[i];
        const Run& run = runs[size_t(i) + 2];
        r[s + "_ms"] = run.stats.get("render_ms");
        r[s + "_reuse_fraction"] = run.stats.get("reuse_fraction");
        r["relmse_right_" + s] = relative_mse(run.films.at(1), runs[0].films.at(1), "color");
        r["right_off_5pct_" + s] = pixels_off_5pct(run.films.at(1), runs[0].films.at(1));
    }
    // The paper gives the Office's figures only.
    const PaperRow* paper = is_office(call.task.scene)
                                ? paper_figures("p1/table5").find({{"photons_side", paper_side}, {"radius", radius}})
                                : nullptr;
    r["paper separate ms"] = paper ? json(paper->number("eyes_separately ms")) : json();
    r["paper reuse ms"] = paper ? json(paper->number("stereo_reuse ms")) : json();
    return r;
}

// A sweep row: the Cornell box's head moved to `wall_distance` from the back wall (the
// scene's pose when "head pose") with the eyes `ipd_m` apart; separately vs reuse.
json sweep_row(const ProbeCall& call, const Scene& scene, const json& base) {
    const HeadPose pose0 = scene.hmd->pose;
    const float wall_z = scene.evaluate(0).bounds.max.z;
    const json& d = call.variant.settings.at("wall_distance");
    const float distance = d.is_number() ? d.get<float>() : wall_z - pose0.position.z;
    const float ipd = call.setting<float>("ipd_m");
    HmdRig rig = vive_rig(scene, call.ctx.quick);
    HeadPose pose = pose0;
    pose.position.z = wall_z - distance;
    rig.set_pose(pose);
    rig.set_ipd(ipd);
    const std::vector<Run> runs = measure(call, scene, stereo_views(rig), {base, with(base, {{"stereo_reuse", true}})});
    json r = reuse_figures(runs[0], runs[1]);
    r["ipd_m"] = ipd;
    r["wall_distance"] = distance;
    r["photons"] = squared(side_of(call.variant.settings.at("photons")));
    r["r"] = call.setting<double>("radius");
    return r;
}

ProbeOutput table5_probe(const ProbeCall& call) {
    ProbeOutput out;
    const std::string part = call.setting<std::string>("part");
    if (part == "sweep" && call.task.scene != "cornell") return out;  // the sweep is the Cornell box's
    const Scene* scene = scene_or_note(call, out);
    if (!scene) return out;
    const json base = photon_settings(call, kProbeKeys);
    out.rows.push_back(part == "sweep" ? sweep_row(call, *scene, base) : table5_row(call, *scene, base));
    return out;
}

ExperimentOutput reduce_table5(const SpecReduction& r) {
    ExperimentOutput out;
    out.tables.push_back(rows_table(
        r, "Table 5 — both eyes: eyes rendered separately vs stereo reuse (nearest-pixel claim, strict, nearest + crack fill)",
        {"scene", "photons", "paper photons", "r", "separate_ms", "reuse_ms", "speedup", "left_ms", "right_ms",
         "right_over_left", "reuse_fraction", "depth_conflicts", "relmse_right", "right_off_5pct", "strict_ms",
         "strict_reuse_fraction", "relmse_right_strict", "right_off_5pct_strict", "fill_ms", "fill_reuse_fraction",
         "relmse_right_fill", "right_off_5pct_fill", "paper separate ms", "paper reuse ms"},
        "Table 5"));
    out.tables.push_back(rows_table(r, "Reuse vs IPD and viewing distance (Cornell box, nearest-pixel claim)",
                                    {"ipd_m", "wall_distance", "photons", "r", "separate_ms", "reuse_ms", "speedup",
                                     "right_over_left", "reuse_fraction", "depth_conflicts", "relmse_right",
                                     "right_off_5pct"},
                                    "sweep"));
    out.notes.push_back("Frame times: median render() time of both eyes over " + std::to_string(r.frames()) + " frames.");
    if (r.ctx.quick) out.notes.push_back("Quick run: 216×240 per eye and a quarter of the paper's photons.");
    return out;
}

// The points of Table 5: each published row (photons and radius together; a quarter of
// the photons in quick runs), then the reuse sweep's cases on the Cornell box.
SpecAxis table5_axis() {
    SpecAxis axis;
    for (const PaperRow& row : paper_figures("p1/table5").rows()) {
        const int side = row.integer("photons_side");
        const double radius = row.number("radius");
        axis.full.push_back({{"part", "Table 5"}, {"photons", side * side}, {"radius", radius}});
        axis.quick.push_back({{"part", "Table 5"}, {"photons", (side / 2) * (side / 2)}, {"radius", radius}});
    }
    const json cases[] = {{{"ipd_m", 0.032}, {"wall_distance", "head pose"}}, {{"ipd_m", 0.063}, {"wall_distance", "head pose"}},
                          {{"ipd_m", 0.126}, {"wall_distance", "head pose"}}, {{"ipd_m", 0.252}, {"wall_distance", "head pose"}},
                          {{"ipd_m", 0.063}, {"wall_distance", 1.0}},         {{"ipd_m", 0.063}, {"wall_distance", 2.5}}};
    for (const json& c : cases) {
        axis.full.push_back(with(c, {{"part", "sweep"}, {"photons", 256 * 256}, {"radius", 0.10}}));
        axis.quick.push_back(with(c, {{"part", "sweep"}, {"photons", 128 * 128}, {"radius", 0.10}}));
    }
    return axis;
}

// ---------------------------------------------------------------------------------
// Final renders (Figs. 9–11: frame times of Figs. 9 and 10, layers of Fig. 11)

// The final renders' reference: the left eye of the stereo pair (none without the scene).
std::vector<ReferenceView> final_references(const ProbeCall& call) {
    std::string why;
    const Scene* scene = call.scene_or_null(&why);
    if (!scene) return {};
    return {ReferenceView{scene, stereo_views(vive_rig(*scene, call.ctx.quick)).views[0], reference_spp_for(call)}};
}

ProbeOutput final_probe(const ProbeCall& call) {
    ProbeOutput out;
    const Scene* scene = scene_or_note(call, out);
    if (!scene) return out;
    const bool office = is_office(call.task.scene);
    // The paper's radius and frame time for this scene (text beside its Figs. 9 and 10).
    const PaperRow& paper = paper_figures("p1/fig9_10").row({{"scene", office ? "Office" : "Cornell Box"}});
    const double radius = paper.number("radius");
    const ViewSet views = stereo_views(vive_rig(*scene, call.ctx.quick));
    const Run run = measure(call, *scene, views, {photon_settings(call, kProbeKeys, {{"radius", radius}})})[0];
    const ReferenceView left = final_references(call).at(0);
    const int spp = left.spp;
    const Film reference = path_reference(call.ctx, left, out.files);
    json r = {{"scene", label_of(call.task.scene)},
              {"photons", squared(side_of(call.variant.settings.at("photons")))},
              {"r", radius},
              {"frame_ms", run.stats.get("render_ms")},
              {"left_ms", run.stats.get("left_ms")},
              {"right_ms", run.stats.get("right_ms")},
              {"reuse_fraction", run.stats.get("reuse_fraction")},
              {"reference_spp", spp},
              {"paper ms", paper.number("frame ms")}};
    for (const char* layer : {"color", "direct", "indirect"})
        r[std::string("relmse_") + layer] = relative_mse(run.films[0], reference, layer);
    out.rows.push_back(r);

    const std::string stem = std::string("final_") + (office ? "office" : "cornell");
    write_exr_stereo(call.ctx.output_dir / (stem + ".exr"), run.films[0], run.films[1]);
    write_png_side_by_side(call.ctx.output_dir / (stem + "_stereo.png"), run.films[0], run.films[1]);
    out.files.insert(out.files.end(), {stem + ".exr", stem + "_stereo.png"});
    for (const char* layer : {"color", "direct", "indirect"}) {
        Film single(run.films[0].width(), run.films[0].height());
        single.layer("color") = run.films[0].layer(layer);
        const std::string name = stem + "_left_" + layer + ".png";
        write_png(call.ctx.output_dir / name, single);
        out.files.push_back(name);
    }
    return out;
}

ExperimentOutput reduce_final(const SpecReduction& r) {
    ExperimentOutput out;
    out.tables.push_back(rows_table(
        r, "Final renders (Figs. 9–11): both eyes with stereo reuse; left eye against a path-traced reference",
        {"scene", "photons", "r", "frame_ms", "left_ms", "right_ms", "reuse_fraction", "relmse_color", "relmse_direct",
         "relmse_indirect", "reference_spp", "paper ms"}));
    out.notes.push_back("frame_ms: median render() time of both eyes over " + std::to_string(r.frames()) + " frames.");
    if (r.ctx.quick)
        out.notes.push_back("Quick run: 216×240 per eye, 256² photons, " + std::to_string(r.reference_spp()) +
                            "-spp reference.");
    return out;
}

// ---------------------------------------------------------------------------------
// Foveated gather

// The left eye's reference (none without the scene); the probe renders that eye.
std::vector<ReferenceView> foveated_references(const ProbeCall& call) {
    std::string why;
    const Scene* scene = call.scene_or_null(&why);
    if (!scene) return {};
    return {ReferenceView{scene, vive_rig(*scene, call.ctx.quick).eye(Eye::Left), reference_spp_for(call)}};
}

ProbeOutput foveated_probe(const ProbeCall& call) {
    ProbeOutput out;
    const Scene* scene = scene_or_note(call, out);
    if (!scene) return out;
    const ReferenceView view = foveated_references(call).at(0);
    const EyeCamera& eye = view.camera;
    const std::vector<float> angles = call.setting<std::vector<float>>("fovea_angles");
    const json unfoveated = photon_settings(call, kProbeKeys);
    std::vector<json> variants = {unfoveated};
    for (float a : angles) variants.push_back(with(unfoveated, {{"foveated", true}, {"fovea_angle", a}}));
    const std::vector<Run> runs = measure(call, *scene, ViewSet::mono(eye), variants);
    const Film reference = path_reference(call.ctx, view, out.files);
    const double pixels = double(eye.width()) * double(eye.height());
    const Film& full = runs[0].films[0];
    auto row = [&](const Run& run, std::optional<float> angle) {
        json r = {{"scene", label_of(call.task.scene)},
                  {"fovea_angle", angle ? json(*angle) : json("off")},
                  {"frame_ms", run.stats.get("render_ms")},
                  {"speedup", runs[0].stats.get("render_ms") / run.stats.get("render_ms")},
                  {"gather_fraction", run.stats.get("gather_queries") / pixels},
                  {"relmse_vs_path (whole image)", relative_mse(run.films[0], reference)}};
        // No fovea without an angle: the masked figures are in each angle's row (the
        // unfoveated columns), not in the 'off' row over the whole image.
        if (!angle) return r;
        const std::vector<uint8_t> inside = fovea_mask(eye, *angle, true), outside = fovea_mask(eye, *angle, false);
        r["fovea_pixels"] = double(std::count(inside.begin(), inside.end(), 1)) / pixels;
        r["relmse_fovea_vs_full"] = relative_mse_masked(run.films[0], full, inside);
        r["relmse_periphery_vs_full"] = relative_mse_masked(run.films[0], full, outside);
        r["relmse_fovea_vs_path"] = relative_mse_masked(run.films[0], reference, inside);
        r["relmse_periphery_vs_path"] = relative_mse_masked(run.films[0], reference, outside);
        // The unfoveated render over this row's own masks: the baseline each fovea and
        // periphery figure is to be read against.
        r["unfoveated relmse_fovea_vs_path (same mask)"] = relative_mse_masked(full, reference, inside);
        r["unfoveated relmse_periphery_vs_path (same mask)"] = relative_mse_masked(full, reference, outside);
        return r;
    };
    out.rows.push_back(row(runs[0], std::nullopt));
    for (size_t i = 0; i < angles.size(); ++i) out.rows.push_back(row(runs[i + 1], angles[i]));
    // The 10° render's image.
    const auto ten = std::find(angles.begin(), angles.end(), 10.0f);
    if (ten != angles.end()) {
        const std::string name =
            std::string("foveated_") + (is_office(call.task.scene) ? "office" : "cornell") + "_10deg.png";
        write_png(call.ctx.output_dir / name, runs[size_t(ten - angles.begin()) + 1].films[0]);
        out.files.push_back(name);
    }
    return out;
}

ExperimentOutput reduce_foveated(const SpecReduction& r) {
    ExperimentOutput out;
    out.tables.push_back(rows_table(r, "Foveated gather: left eye, time vs error inside and outside the fovea",
                                    {"scene", "fovea_angle", "frame_ms", "speedup", "gather_fraction", "fovea_pixels",
                                     "relmse_fovea_vs_full", "relmse_periphery_vs_full", "relmse_fovea_vs_path",
                                     "relmse_periphery_vs_path", "unfoveated relmse_fovea_vs_path (same mask)",
                                     "unfoveated relmse_periphery_vs_path (same mask)", "relmse_vs_path (whole image)"}));
    out.notes.push_back("frame_ms: median render() time over " + std::to_string(r.frames()) + " frames.");
    return out;
}

// The path-traced references' samples in full runs, per scene (quick runs: 64).
const json kReferenceSpp = {{"cornell", 256}, {"conference", 128}};

}  // namespace

void register_stereo_experiments(ExperimentRegistry& registry) {
    add_probe("pm-table5", table5_probe);
    add_reducer("pm-table5", reduce_table5);
    add_probe("pm-final", final_probe, final_references);
    add_reducer("pm-final", reduce_final);
    add_probe("pm-foveated", foveated_probe, foveated_references);
    add_reducer("pm-foveated", reduce_foveated);

    const std::vector<std::string> scenes = {"cornell", "conference"};
    const std::string hmd_note =
        "HMD: HTC Vive preset (1080×1200 per eye; 216×240 in quick runs) at the scene's fixed head pose.";
    registry.add(declared_experiment({
        .name = "pm-table5",
        .paper = "P1",
        .figure = "Table 5",
        .description = "both eyes, eyes separately vs stereo reuse (nearest and strict), Cornell and Office; "
                       "reuse vs IPD and distance",
        .scenes = scenes,
        .frames = 5, .quick_frames = 2,
        .variants = {{.name = "separately vs reuse", .probe = "pm-table5",
                      .settings = {{"hmd", "vive"}, {"light_samples", 1}}}},
        .axes = {table5_axis()},
        .reducer = "pm-table5",
        .notes =
            {hmd_note,
             "Paper figures (\"paper …\" columns) are the Office scene's on an RTX 2080 Ti (OptiX + CUDA, Vive "
             "resolution); ours are CPU threads on this machine, Office = the conference room (331k triangles vs the "
             "paper's ~710k). Compare the speedup, not milliseconds. The paper gives no Cornell figures for Table 5.",
             "separate_ms: both eyes rendered fully (the right eye draws its light samples from the stream of the left "
             "pixel that sees the same point, so both renders share their noise). reuse_ms: left eye, then the claim "
             "pass (a visibility ray per left hit, reprojection, depth-tested atomic claim), then the right eye shading "
             "only unclaimed pixels; right_ms includes the claim pass.",
             "reuse_fraction = reused right pixels ÷ right pixels showing geometry; depth_conflicts = claimed pixels "
             "whose candidates lay on different surfaces (depths > 1 % apart), where a first-writer claim could keep a "
             "hidden surface; relmse_right = relative MSE of the right eye against the independently rendered right "
             "eye (the error reuse introduces: sub-pixel mismatch), dominated by the few pixels at the edge of the "
             "light where a reused point from the ceiling and the light's own hit differ 50-fold; right_off_5pct = "
             "share of right pixels whose luminance is more than 5 % (+0.01) off.",
             "strict: the right pixel's own primary ray is traced and a claim is used only when its hit is within 0.5 "
             "pixel footprints of the claiming left hit (same material, normals within ~8°). fill: nearest claims plus "
             "crack filling — an unclaimed pixel whose own hit lies within 1.5 footprints of a neighbour's claiming "
             "hit on the same surface reuses that hit (forward reprojection leaves one-pixel cracks where the right "
             "eye sees a surface less obliquely).",
             "The sweep (second table) runs on the Cornell box only: wall_distance 'head pose' is the scene's own "
             "distance to the back wall."},
    }));
    registry.add(declared_experiment({
        .name = "pm-final",
        .paper = "P1",
        .figure = "Figs. 9–11",
        .description = "final stereo renders with global/direct/indirect layers vs path tracing",
        .scenes = scenes,
        .frames = 5, .quick_frames = 2,
        .reference_spp = 256, .quick_reference_spp = 64,
        .variants = {{.name = "final", .probe = "pm-final",
                      .settings = {{"hmd", "vive"}, {"light_samples", 1}, {"pass", "split"},
                                   {"tile_shared", "cell_groups"}, {"stereo_reuse", true},
                                   {"reference_spp", kReferenceSpp}}}},
        .axes = {{"photons", {512 * 512}, {256 * 256}}},
        .reducer = "pm-final",
        .notes = {hmd_note,
                  "Settings: hash grid, radius gather (no heap), split passes, tile-shared gather (cell_groups), stereo "
                  "reuse (nearest), 1 light sample; the radius is the paper's for the scene (p1/fig9_10: Cornell r = "
                  "0.2, Office r = 0.15).",
                  "Paper figures: RTX 2080 Ti, Cornell 512² photons r = 0.2 and Office (~710k triangles) 512² r = "
                  "0.15; ours: CPU threads, Office = the conference room.",
                  "Images: final_<scene>_left_{color,direct,indirect}.png are Fig. 11's global / direct / indirect "
                  "split of the left eye; final_<scene>_stereo.png both eyes; relMSE columns compare the left eye "
                  "with the path-traced reference at the same pixel centres (max depth 8)."},
    }));
    registry.add(declared_experiment({
        .name = "pm-foveated",
        .paper = "P1",
        .figure = "Foveated gather",
        .description = "the paper's future work: time vs error in and out of the fovea",
        .scenes = scenes,
        .frames = 5, .quick_frames = 2,
        .reference_spp = 256, .quick_reference_spp = 64,
        .variants = {{.name = "foveated", .probe = "pm-foveated",
                      .settings = {{"hmd", "vive"}, {"light_samples", 1}, {"radius", 0.10},
                                   {"periphery_photon_stride", 4}, {"fovea_angles", {5.0, 10.0, 20.0}},
                                   {"reference_spp", kReferenceSpp}}}},
        .axes = {{"photons", {512 * 512}, {256 * 256}}},
        .reducer = "pm-foveated",
        .notes = {hmd_note,
                  "Not in the paper (its future work). Every pixel traces its own primary and shadow rays; photons are "
                  "gathered at every pixel of the 4×4 blocks whose centre lies within fovea_angle of the gaze (the "
                  "eye's forward axis), once per 2×2 block up to twice the angle and once per 4×4 beyond, over a map "
                  "of every 4th photon with 4× the flux; a block's other pixels take that indirect light when they see "
                  "the same surface nearby (else they gather themselves).",
                  "fovea = pixels of full-rate blocks (fovea_pixels: their share); gather_fraction = photon gathers ÷ "
                  "pixels. *_vs_full compares with the unfoveated render of the same seed (the fovea is identical by "
                  "construction, so its figure is 0); *_vs_path with the path-traced reference, the error a viewer "
                  "would see. The 'unfoveated … (same mask)' columns give the unfoveated render's error over the same "
                  "fovea and periphery pixels as the row's, so each masked figure has its baseline beside it; the "
                  "'off' row leaves the masked columns empty (its whole-image error is in 'relmse_vs_path (whole "
                  "image)')."},
    }));
}

}  // namespace gilab
