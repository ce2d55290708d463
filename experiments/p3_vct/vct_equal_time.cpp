// A study beside P3's Fig. 9: light propagation volumes, cascaded VCT and photon mapping
// at equal time on Sponza and Sibenik, each against a path-traced reference (relMSE,
// FLIP) with its image and FLIP heat map — the comparison `gilab compare --equal-time`
// makes, run as an experiment so that it lands in the tables and the report. Where a
// technique fails shows in its heat map; the thin-wall leak of LPV and the cone tracers is
// measured by vct-stability.
#include <fstream>
#include "core/util/error.hpp"
#include "experiments/app/compare_command.hpp"
#include "experiments/p3_vct/vct_common.hpp"

namespace gilab::vct {

namespace {

namespace fs = std::filesystem;

// One scene compared at equal time: every technique's knob (photons, diffuse cones,
// reflective-shadow-map size) tuned until prepare + one frame takes the budget, as compare
// does. The comparison's folder lives under the experiment's (equal_time/compare/SCENE/).
ProbeOutput equal_time_probe(const ProbeCall& call) {
    ProbeOutput out;
    const std::string scene = scene_of(call);
    if (!scene_or_skip(call, scene, out)) return out;
    CompareRequest request;
    request.scene = scene;
    request.techniques = call.setting<std::vector<std::string>>("techniques");
    request.width = request.height = call.size;
    request.reference_spp = call.reference_spp;
    request.frames = call.frames;
    request.equal_time_seconds = call.setting<double>("budget_ms") / 1000.0;
    request.equal_time_of = EqualTimeOf::PrepareAndFrame;
    request.results = (call.ctx.output_dir / "equal_time").string();
    request.seed = call.ctx.seed;
    request.threads = call.ctx.threads;
    request.assets = call.ctx.assets;
    // Technique settings other than the defaults, {"vct": {"resolution": 16}} say.
    for (const std::string& technique : request.techniques)
        if (call.variant.settings.contains(technique))
            for (const auto& [key, value] : call.variant.settings.at(technique).items())
                request.assignments[technique].push_back(key + "=" + (value.is_string() ? value.get<std::string>() : value.dump()));
    const fs::path dir = run_compare(request);

    std::ifstream in(dir / "results.json");
    const nlohmann::json compared = nlohmann::json::parse(in);
    const std::string folder = fs::relative(dir, call.ctx.output_dir).generic_string();
    out.files.push_back(folder + "/reference.png");
    for (const nlohmann::json& e : compared.at("techniques")) {
        const std::string technique = e.at("technique").get<std::string>();
        out.rows.push_back({{"scene", scene},
                            {"technique", technique},
                            {"quality setting at equal time", e.at("quality_setting")},
                            {"prepare_ms", e.at("prepare_ms")},
                            {"frame_ms", e.at("frame_ms")},
                            {"prepare + frame (ms)", e.at("prepare_plus_frame_ms")},
                            {"relMSE at equal time", e.at("relmse")},
                            {"FLIP at equal time", e.at("flip")}});
        out.files.push_back(folder + "/" + technique + ".png");
        out.files.push_back(folder + "/" + technique + "_flip.png");
    }
    call.ctx.say(scene + ": compared at " + std::to_string(int(call.setting<double>("budget_ms"))) + " ms");
    return out;
}

ExperimentOutput equal_time_table(const SpecReduction& r) {
    require_rows(r);
    ExperimentOutput out;
    ResultTable t{"LPV vs cascaded VCT vs photon mapping at equal time (prepare + one frame), against a path-traced "
                  "reference",
                  {"scene", "technique", "quality setting at equal time", "prepare_ms", "frame_ms", "prepare + frame (ms)",
                   "relMSE at equal time", "FLIP at equal time"},
                  {}};
    for (const nlohmann::json& row : all_rows(r)) t.rows.push_back(row);
    out.tables = {std::move(t)};
    out.notes = quick_notes(r, {.images = true, .reference_spp = true, .cones = true});
    return out;
}

}  // namespace

void register_equal_time(ExperimentRegistry& registry) {
    add_probe("equal-time-compare", equal_time_probe);
    add_reducer("vct-equal-time", equal_time_table);
    registry.add(declared_experiment({
        .name = "vct-equal-time",
        .paper = "P3",
        .figure = "Study beside Fig. 9",
        .description = "LPV, cascaded VCT and photon mapping at equal time on Sponza and Sibenik: relMSE and FLIP "
                       "against a path-traced reference, images and FLIP heat maps",
        .scenes = {"walk scenes"},
        .size = 192, .quick_size = 32,
        .frames = 3, .quick_frames = 1,
        .reference_spp = 1024, .quick_reference_spp = 16,
        .variants = {{.name = "equal time",
                      .probe = "equal-time-compare",
                      .settings = {{"techniques", {"photon", "vct", "lpv"}}}}},
        // The quick plan is a smoke check: Sponza alone, and cascades of 16³ so that the
        // cone tracer's fixed cost does not dominate the test suite's time.
        .axes = {{"scene", {"sponza", "sibenik"}, {"sponza"}},
                 {"", {nlohmann::json{{"budget_ms", 1000.0}}},
                  {nlohmann::json{{"budget_ms", 300.0}, {"vct", {{"resolution", 16}}}}}}},
        .reducer = "vct-equal-time",
        .notes = {"Each technique's quality knob (photon: photons; vct: diffuse_cones; lpv: rsm_size) is tuned, at "
                  "most five tries, until prepare + one frame takes budget_ms — the work that makes one image, the "
                  "photon pass and the voxelization included; a knob that cannot reach it within 10 % says so in "
                  "'quality setting at equal time'. The setting reached, and so the errors, depend on this machine's "
                  "speed. frame_ms is then the median of the task's frames. Techniques otherwise at their defaults, "
                  "the scene camera, all threads. The reference is path traced with jittered pixel "
                  "samples and cached under equal_time/compare/reference_cache.",
                  "Images: each technique's image and its FLIP map (0 black … 1 bright: where it differs from the "
                  "reference as a viewer would see it). Light leaking through a wall thinner than a cell or voxel is "
                  "measured in vct-stability.",
                  "The quick plan compares on Sponza alone, with the cascades at 16³ (vct resolution=16)."},
    }));
}

}  // namespace gilab::vct
