// P1 on the headset: Table 5 (both eyes, eyes separately vs stereo reuse), the final
// renders of Figs. 9–11 with their frame times, and the foveated gather the paper leaves as
// future work. Every variant is a setting of the `photon` technique on an HMD stereo
// pair (HTC Vive preset, the scene's fixed head pose); variants of a row are prepared
// once and rendered in turn frame by frame, figures are medians over the frames.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include "core/util/error.hpp"
#include "core/scene/hmd.hpp"
#include "core/image/image_io.hpp"
#include "core/image/image_metrics.hpp"
#include "core/util/settings.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/paper_figures.hpp"
#include "experiments/runner/path_reference.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/photon_mapping/foveation.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace {

namespace fs = std::filesystem;

constexpr int kLightSamples = 1;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

std::string squared(int side) { return std::to_string(side) + "²"; }

// The Cornell box (builtin) and the largest office-like interior of the shared assets,
// the paper's "Office" (~710k triangles; the conference room has 331k). A missing
// asset skips the scene with a note.
struct NamedScene {
    std::string label;
    Scene scene;
};

std::vector<NamedScene> p1_scenes(const ExperimentContext& ctx, ExperimentOutput& out) {
    std::vector<NamedScene> scenes;
    scenes.push_back({"cornell", make_cornell_box()});
    try {
        scenes.push_back({"conference (Office)", open_scene("conference", ctx.assets).scene});
    } catch (const Error& e) {
        out.notes.push_back(std::string("Office scene skipped: ") + e.what());
        ctx.say(std::string("skipping conference: ") + e.what());
    }
    return scenes;
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

// Prepares every variant, then renders them in turn for `frames` frames.
std::vector<Run> measure(const ExperimentContext& ctx, const Scene& scene, const ViewSet& views,
                         std::vector<nlohmann::json> variants, int frames) {
    const size_t n = variants.size();
    std::vector<std::unique_ptr<Technique>> techniques;
    for (size_t v = 0; v < n; ++v) {
        variants[v]["seed"] = ctx.seed;
        variants[v]["light_samples"] = kLightSamples;
        techniques.push_back(
            prepare_technique("photon", scene, Settings(variants[v], "pm stereo experiment settings")));
    }
    const char* timed[] = {"render_ms", "left_ms", "right_ms", "claim_ms", "right_pass_ms"};
    std::vector<std::map<std::string, std::vector<double>>> samples(n);
    std::vector<Run> runs(n);
    for (int f = 0; f < frames; ++f) {
        for (size_t v = 0; v < n; ++v) {
            runs[v].films.clear();
            techniques[v]->render(views, runs[v].films);
            runs[v].stats = techniques[v]->stats();
            for (const char* key : timed) samples[v][key].push_back(runs[v].stats.get(key));
        }
    }
    for (size_t v = 0; v < n; ++v) {
        for (const char* key : timed) runs[v].stats.set(key, median(samples[v][key]));
        ctx.say(variants[v].dump() + ": " + std::to_string(runs[v].stats.get("render_ms")) + " ms both eyes");
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

// ---------------------------------------------------------------------------------
// Table 5

// A row of the paper's Table 5 (experiments/papers/p1/table5.csv): photons emitted
// (side²), radius and the Office's two frame times.
struct Table5Row {
    int side;
    double radius;
    double separate_ms, reuse_ms;  // paper, Office
};
std::vector<Table5Row> paper_table5() {
    std::vector<Table5Row> rows;
    for (const PaperRow& r : paper_figures("p1/table5").rows())
        rows.push_back({r.integer("photons_side"), r.number("radius"), r.number("eyes_separately ms"),
                        r.number("stereo_reuse ms")});
    return rows;
}

nlohmann::json reuse_figures(const Run& separate, const Run& reuse) {
    nlohmann::json r;
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

ExperimentOutput run_table5(const ExperimentContext& ctx) {
    ExperimentOutput out;
    const int frames = ctx.quick ? 2 : 5;
    ResultTable t;
    t.title = "Table 5 — both eyes: eyes rendered separately vs stereo reuse (nearest-pixel claim, strict, nearest + crack fill)";
    t.columns = {"scene",          "photons",         "paper photons",  "r",
                 "separate_ms",    "reuse_ms",        "speedup",        "left_ms",
                 "right_ms",       "right_over_left", "reuse_fraction", "depth_conflicts",
                 "relmse_right",   "right_off_5pct",  "strict_ms",       "strict_reuse_fraction",
                 "relmse_right_strict", "right_off_5pct_strict", "fill_ms", "fill_reuse_fraction",
                 "relmse_right_fill", "right_off_5pct_fill",
                 "paper separate ms", "paper reuse ms"};
    HmdRig first_rig;
    for (const NamedScene& named : p1_scenes(ctx, out)) {
        const HmdRig rig = vive_rig(named.scene, ctx.quick);
        first_rig = rig;
        const ViewSet views = stereo_views(rig);
        const bool office = named.label != "cornell";
        for (const Table5Row& p : paper_table5()) {
            const int side = ctx.quick ? p.side / 2 : p.side;
            nlohmann::json base = {{"photons", side * side}, {"radius", p.radius}};
            nlohmann::json nearest = base, strict = base, fill = base;
            nearest["stereo_reuse"] = true;
            strict["stereo_reuse"] = true;
            strict["stereo_match"] = "strict";
            fill["stereo_reuse"] = true;
            fill["stereo_fill"] = true;
            ctx.say(named.label + ": " + squared(side) + " photons, r = " + std::to_string(p.radius));
            std::vector<Run> runs = measure(ctx, named.scene, views, {base, nearest, strict, fill}, frames);
            nlohmann::json r = reuse_figures(runs[0], runs[1]);
            r["scene"] = named.label;
            r["photons"] = squared(side);
            r["paper photons"] = squared(p.side);
            r["r"] = p.radius;
            r["strict_ms"] = runs[2].stats.get("render_ms");
            r["strict_reuse_fraction"] = runs[2].stats.get("reuse_fraction");
            r["relmse_right_strict"] = relative_mse(runs[2].films.at(1), runs[0].films.at(1), "color");
            r["right_off_5pct_strict"] = pixels_off_5pct(runs[2].films.at(1), runs[0].films.at(1));
            r["fill_ms"] = runs[3].stats.get("render_ms");
            r["fill_reuse_fraction"] = runs[3].stats.get("reuse_fraction");
            r["relmse_right_fill"] = relative_mse(runs[3].films.at(1), runs[0].films.at(1), "color");
            r["right_off_5pct_fill"] = pixels_off_5pct(runs[3].films.at(1), runs[0].films.at(1));
            r["paper separate ms"] = office ? nlohmann::json(p.separate_ms) : nlohmann::json();
            r["paper reuse ms"] = office ? nlohmann::json(p.reuse_ms) : nlohmann::json();
            t.rows.push_back(r);
        }
    }
    out.tables.push_back(t);

    // How reuse depends on the eye separation and the distance to what is seen.
    ResultTable sweep;
    sweep.title = "Reuse vs IPD and viewing distance (Cornell box, nearest-pixel claim)";
    sweep.columns = {"ipd_m", "wall_distance", "photons", "r", "separate_ms", "reuse_ms", "speedup",
                     "right_over_left", "reuse_fraction", "depth_conflicts", "relmse_right", "right_off_5pct"};
    {
        const Scene cornell = make_cornell_box();
        const int side = ctx.quick ? 128 : 256;
        const double radius = 0.10;
        const HeadPose base = cornell.hmd->pose;
        const float wall_z = cornell.evaluate(0).bounds.max.z;
        struct Case {
            float ipd, distance;
        };
        const float base_distance = wall_z - base.position.z;
        std::vector<Case> cases = {{0.032f, base_distance}, {0.063f, base_distance}, {0.126f, base_distance},
                                   {0.252f, base_distance}, {0.063f, 1.0f},          {0.063f, 2.5f}};
        nlohmann::json settings = {{"photons", side * side}, {"radius", radius}};
        nlohmann::json reuse = settings;
        reuse["stereo_reuse"] = true;
        for (const Case& c : cases) {
            HmdRig rig = vive_rig(cornell, ctx.quick);
            HeadPose pose = base;
            pose.position.z = wall_z - c.distance;
            rig.set_pose(pose);
            rig.set_ipd(c.ipd);
            ctx.say("sweep: ipd " + std::to_string(c.ipd) + ", wall at " + std::to_string(c.distance));
            std::vector<Run> runs = measure(ctx, cornell, stereo_views(rig), {settings, reuse}, frames);
            nlohmann::json r = reuse_figures(runs[0], runs[1]);
            r["ipd_m"] = c.ipd;
            r["wall_distance"] = c.distance;
            r["photons"] = squared(side);
            r["r"] = radius;
            sweep.rows.push_back(r);
        }
    }
    out.tables.push_back(sweep);

    out.config["hmd"] = "vive";
    out.config["per_eye_resolution"] = {first_rig.preset().width, first_rig.preset().height};
    out.config["frames"] = frames;
    out.config["light_samples"] = kLightSamples;
    out.config["statistic"] = "median render() time of both eyes over the frames";
    out.notes.push_back("Paper figures (\"paper …\" columns) are the Office scene's on an RTX 2080 Ti (OptiX + CUDA, "
                        "Vive resolution); ours are CPU threads on this machine, Office = the conference room (331k "
                        "triangles vs the paper's ~710k). Compare the speedup, not milliseconds. The paper gives no "
                        "Cornell figures for Table 5.");
    out.notes.push_back("separate_ms: both eyes rendered fully (the right eye draws its light samples from the stream "
                        "of the left pixel that sees the same point, so both renders share their noise). reuse_ms: "
                        "left eye, then the claim pass (a visibility ray per left hit, reprojection, depth-tested "
                        "atomic claim), then the right eye shading only unclaimed pixels; right_ms includes the "
                        "claim pass.");
    out.notes.push_back("reuse_fraction = reused right pixels ÷ right pixels showing geometry; depth_conflicts = claimed "
                        "pixels whose candidates lay on different surfaces (depths > 1 % apart), where a first-writer "
                        "claim could keep a hidden surface; relmse_right = relative MSE of the right eye against the "
                        "independently rendered right eye (the error reuse introduces: sub-pixel mismatch), dominated by the few pixels at the "
                        "edge of the light where a reused point from the ceiling and the light's own hit differ 50-fold; "
                        "right_off_5pct = share of right pixels whose luminance is more than 5 % (+0.01) off.");
    out.notes.push_back("strict: the right pixel's own primary ray is traced and a claim is used only when its hit is "
                        "within 0.5 pixel footprints of the claiming left hit (same material, normals within ~8°). "
                        "fill: nearest claims plus crack filling — an unclaimed pixel whose own hit lies within 1.5 "
                        "footprints of a neighbour's claiming hit on the same surface reuses that hit (forward "
                        "reprojection leaves one-pixel cracks where the right eye sees a surface less obliquely).");
    if (ctx.quick) out.notes.push_back("Quick run: 216×240 per eye and a quarter of the paper's photons.");
    return out;
}

// ---------------------------------------------------------------------------------
// Final renders (Figs. 9–11: frame times of Figs. 9 and 10, layers of Fig. 11)

ExperimentOutput run_final(const ExperimentContext& ctx) {
    ExperimentOutput out;
    const int frames = ctx.quick ? 2 : 5;
    const int side = ctx.quick ? 256 : 512;
    ResultTable t;
    t.title = "Final renders (Figs. 9–11): both eyes with stereo reuse; left eye against a path-traced reference";
    t.columns = {"scene",         "photons",       "r",           "frame_ms",     "left_ms",
                 "right_ms",      "reuse_fraction", "relmse_color", "relmse_direct", "relmse_indirect",
                 "reference_spp", "paper ms"};
    struct Final {
        std::string scene;
        double radius, paper_ms;
    };
    for (const NamedScene& named : p1_scenes(ctx, out)) {
        const bool office = named.label != "cornell";
        // The paper's radius and frame time for this scene (text beside its Figs. 9 and 10).
        const PaperRow& paper = paper_figures("p1/fig9_10").row({{"scene", office ? "Office" : "Cornell Box"}});
        const Final f{office ? "office" : "cornell", paper.number("radius"), paper.number("frame ms")};
        const HmdRig rig = vive_rig(named.scene, ctx.quick);
        const ViewSet views = stereo_views(rig);
        nlohmann::json settings = {{"photons", side * side}, {"radius", f.radius}, {"pass", "split"},
                                   {"tile_shared", "cell_groups"}, {"stereo_reuse", true}};
        ctx.say(named.label + ": final render");
        std::vector<Run> runs = measure(ctx, named.scene, views, {settings}, frames);
        const Run& run = runs[0];
        const int spp = ctx.quick ? 64 : (office ? 128 : 256);
        Film reference = path_reference(ctx, named.scene, views.views[0], spp, out.files);
        nlohmann::json r;
        r["scene"] = named.label;
        r["photons"] = squared(side);
        r["r"] = f.radius;
        r["frame_ms"] = run.stats.get("render_ms");
        r["left_ms"] = run.stats.get("left_ms");
        r["right_ms"] = run.stats.get("right_ms");
        r["reuse_fraction"] = run.stats.get("reuse_fraction");
        for (const char* layer : {"color", "direct", "indirect"})
            r[std::string("relmse_") + layer] = relative_mse(run.films[0], reference, layer);
        r["reference_spp"] = spp;
        r["paper ms"] = f.paper_ms;
        t.rows.push_back(r);

        const std::string stem = "final_" + f.scene;
        write_exr_stereo(ctx.output_dir / (stem + ".exr"), run.films[0], run.films[1]);
        write_png_side_by_side(ctx.output_dir / (stem + "_stereo.png"), run.films[0], run.films[1]);
        out.files.push_back(stem + ".exr");
        out.files.push_back(stem + "_stereo.png");
        for (const char* layer : {"color", "direct", "indirect"}) {
            Film single(run.films[0].width(), run.films[0].height());
            single.layer("color") = run.films[0].layer(layer);
            const std::string name = stem + "_left_" + layer + ".png";
            write_png(ctx.output_dir / name, single);
            out.files.push_back(name);
        }
    }
    out.tables.push_back(t);
    out.config["hmd"] = "vive";
    out.config["frames"] = frames;
    out.config["settings"] = "hash grid, radius gather (no heap), split passes, tile-shared gather (cell_groups), "
                             "stereo reuse (nearest), 1 light sample";
    out.notes.push_back("Paper figures: RTX 2080 Ti, Cornell 512² photons r = 0.2 and Office (~710k triangles) 512² "
                        "r = 0.15; ours: CPU threads, Office = the conference room.");
    out.notes.push_back("Images: final_<scene>_left_{color,direct,indirect}.png are Fig. 11's global / direct / "
                        "indirect split of the left eye; final_<scene>_stereo.png both eyes; relMSE columns compare "
                        "the left eye with the path-traced reference at the same pixel centres (max depth 8).");
    if (ctx.quick) out.notes.push_back("Quick run: 216×240 per eye, 256² photons, 64-spp reference.");
    return out;
}

// ---------------------------------------------------------------------------------
// Foveated gather

ExperimentOutput run_foveated(const ExperimentContext& ctx) {
    ExperimentOutput out;
    const int frames = ctx.quick ? 2 : 5;
    const int side = ctx.quick ? 256 : 512;
    const double radius = 0.10;
    const float angles[] = {5.0f, 10.0f, 20.0f};
    ResultTable t;
    t.title = "Foveated gather: left eye, time vs error inside and outside the fovea";
    t.columns = {"scene",          "fovea_angle",        "frame_ms",           "speedup",
                 "gather_fraction", "fovea_pixels",      "relmse_fovea_vs_full", "relmse_periphery_vs_full",
                 "relmse_fovea_vs_path", "relmse_periphery_vs_path",
                 "unfoveated relmse_fovea_vs_path (same mask)", "unfoveated relmse_periphery_vs_path (same mask)",
                 "relmse_vs_path (whole image)"};
    for (const NamedScene& named : p1_scenes(ctx, out)) {
        const HmdRig rig = vive_rig(named.scene, ctx.quick);
        const EyeCamera eye = rig.eye(Eye::Left);
        const ViewSet view = ViewSet::mono(eye);
        std::vector<nlohmann::json> variants = {{{"photons", side * side}, {"radius", radius}}};
        for (float a : angles)
            variants.push_back({{"photons", side * side}, {"radius", radius}, {"foveated", true}, {"fovea_angle", a}});
        ctx.say(named.label + ": foveated gather");
        std::vector<Run> runs = measure(ctx, named.scene, view, variants, frames);
        const int spp = ctx.quick ? 64 : (named.label == "cornell" ? 256 : 128);
        Film reference = path_reference(ctx, named.scene, eye, spp, out.files);
        const double pixels = double(eye.width()) * double(eye.height());
        auto add_row = [&](const Run& run, std::optional<float> angle) {
            const float a = angle.value_or(0.0f);
            nlohmann::json r;
            r["scene"] = named.label;
            r["fovea_angle"] = angle ? nlohmann::json(a) : nlohmann::json("off");
            r["frame_ms"] = run.stats.get("render_ms");
            r["speedup"] = runs[0].stats.get("render_ms") / run.stats.get("render_ms");
            r["gather_fraction"] = run.stats.get("gather_queries") / pixels;
            r["relmse_vs_path (whole image)"] = relative_mse(run.films[0], reference);
            if (angle) {
                const std::vector<uint8_t> inside = fovea_mask(eye, a, true);
                const std::vector<uint8_t> outside = fovea_mask(eye, a, false);
                const Film& unfoveated = runs[0].films[0];
                r["fovea_pixels"] = double(std::count(inside.begin(), inside.end(), 1)) / pixels;
                r["relmse_fovea_vs_full"] = relative_mse_masked(run.films[0], unfoveated, inside);
                r["relmse_periphery_vs_full"] = relative_mse_masked(run.films[0], unfoveated, outside);
                r["relmse_fovea_vs_path"] = relative_mse_masked(run.films[0], reference, inside);
                r["relmse_periphery_vs_path"] = relative_mse_masked(run.films[0], reference, outside);
                // The unfoveated render over this row's own masks: the baseline each
                // fovea and periphery figure is to be read against.
                r["unfoveated relmse_fovea_vs_path (same mask)"] = relative_mse_masked(unfoveated, reference, inside);
                r["unfoveated relmse_periphery_vs_path (same mask)"] = relative_mse_masked(unfoveated, reference, outside);
            } else {
                // No fovea without an angle: the masked figures are in each angle's row
                // (the unfoveated columns), not here over the whole image.
                for (const char* masked : {"fovea_pixels", "relmse_fovea_vs_full", "relmse_periphery_vs_full",
                                           "relmse_fovea_vs_path", "relmse_periphery_vs_path",
                                           "unfoveated relmse_fovea_vs_path (same mask)",
                                           "unfoveated relmse_periphery_vs_path (same mask)"})
                    r[masked] = nullptr;
            }
            t.rows.push_back(r);
        };
        add_row(runs[0], std::nullopt);
        for (size_t i = 0; i < std::size(angles); ++i) add_row(runs[i + 1], angles[i]);
        const std::string name = "foveated_" + std::string(named.label == "cornell" ? "cornell" : "office") + "_10deg.png";
        write_png(ctx.output_dir / name, runs[2].films[0]);
        out.files.push_back(name);
    }
    out.tables.push_back(t);
    out.config["photons"] = squared(side);
    out.config["radius"] = radius;
    out.config["periphery_photon_stride"] = 4;
    out.config["frames"] = frames;
    out.notes.push_back("Not in the paper (its future work). Every pixel traces its own primary and shadow rays; "
                        "photons are gathered at every pixel of the 4×4 blocks whose centre lies within fovea_angle of "
                        "the gaze (the eye's forward axis), once per 2×2 block up to twice the angle and once per 4×4 "
                        "beyond, over a map of every 4th photon with 4× the flux; a block's other pixels take that "
                        "indirect light when they see the same surface nearby (else they gather themselves).");
    out.notes.push_back("fovea = pixels of full-rate blocks (fovea_pixels: their share); gather_fraction = photon "
                        "gathers ÷ pixels. *_vs_full compares with the unfoveated render of the same seed (the fovea "
                        "is identical by construction, so its figure is 0); *_vs_path with the path-traced "
                        "reference, the error a viewer would see. The 'unfoveated … (same mask)' columns give the "
                        "unfoveated render's error over the same fovea and periphery pixels as the row's, so each "
                        "masked figure has its baseline beside it; the 'off' row leaves the masked columns empty "
                        "(its whole-image error is in 'relmse_vs_path (whole image)').");
    return out;
}

}  // namespace

void register_stereo_experiments(ExperimentRegistry& registry) {
    registry.add({"pm-table5", "P1",
                  "Table 5: both eyes, eyes separately vs stereo reuse (nearest and strict), Cornell and Office; "
                  "reuse vs IPD and distance",
                  run_table5});
    registry.add({"pm-final", "P1", "Figs. 9–11: final stereo renders with global/direct/indirect layers vs path tracing",
                  run_final});
    registry.add({"pm-foveated", "P1", "Foveated gather (the paper's future work): time vs error in and out of the fovea",
                  run_foveated});
}

}  // namespace gilab
