// P3 Figs. 11–13, which the paper shows as images: Sponza cone traced with either
// structure against a path-traced reference (Fig. 11), and the diffuse and specular cones
// turned on and off (Figs. 12 and 13). One task renders one image; the images are
// written beside the results.
#include "core/image/image_metrics.hpp"
#include "core/util/error.hpp"
#include "experiments/p3_vct/vct_common.hpp"
#include "experiments/runner/path_reference.hpp"

namespace gilab::vct {

namespace {

// The probe's camera: setting "camera" ({eye, target, fov}, up +y) where the scene's own
// does not show what the figure is about, else the scene camera.
EyeCamera probe_camera(const ProbeCall& call, const Scene& scene) {
    if (!call.variant.settings.contains("camera")) return scene_camera(scene, call.size);
    const nlohmann::json& c = call.variant.settings.at("camera");
    auto vec = [](const nlohmann::json& v) { return Vec3(v.at(0).get<float>(), v.at(1).get<float>(), v.at(2).get<float>()); };
    return EyeCamera::look_at(vec(c.at("eye")), vec(c.at("target")), Vec3(0, 1, 0), c.at("fov").get<float>(), call.size,
                              call.size);
}

// The path-traced reference of the variant's scene and camera (max depth 8, its own
// seed); none when the scene cannot be loaded (the probe notes the skip).
std::vector<ReferenceView> image_reference(const ProbeCall& call) {
    const Scene* scene = loadable_scene(call, scene_of(call));
    if (!scene) return {};
    return {ReferenceView{scene, probe_camera(call, *scene), call.reference_spp}};
}

// A vct-image variant's reference: only with setting "against_reference".
std::vector<ReferenceView> vct_image_references(const ProbeCall& call) {
    if (!call.setting<bool>("against_reference", false)) return {};
    return image_reference(call);
}

// The reference of image_reference, rendered once per run (the task's variants share it),
// with the files it was written to.
struct Reference {
    Film film;
    std::vector<std::string> files;
};
// Which tasks share image_reference's reference: its scene, camera, size and samples.
std::string image_group(const ProbeCall& call) {
    return "vct reference: " + scene_of(call) + " " + call.variant.settings.value("camera", nlohmann::json()).dump() +
           " " + std::to_string(call.size) + "px " + std::to_string(call.reference_spp) + "spp";
}

const Reference& reference_of(const ProbeCall& call) {
    return call.cache.get<Reference>(image_group(call), [&] {
        Reference r;
        r.film = path_reference(call.ctx, image_reference(call).at(0), r.files);
        return r;
    });
}

// The reference itself as a row of Fig. 11 (its relMSE is 0 by definition). A missing
// scene is skipped with a note.
ProbeOutput reference_image_probe(const ProbeCall& call) {
    ProbeOutput out;
    const Scene* scene = scene_or_skip(call, scene_of(call), out);
    if (!scene) return out;
    const Reference& ref = reference_of(call);
    out.rows.push_back({{"image", call.variant.name}, {"relmse_color", 0.0}, {"relmse_indirect", 0.0},
                        {"mean_color", mean_value(ref.film)}, {"mean_indirect", mean_value(ref.film, "indirect")},
                        {"frame_ms", nullptr}});
    out.files = ref.files;
    return out;
}

// One `vct` image (settings "vct", the axis's dense resolution) of setting "scene",
// written as setting "image_file" (else the variant's name): its layers' means and frame
// time, and with setting "against_reference" its relMSE against the path-traced
// reference. A missing scene is skipped with a note.
ProbeOutput vct_image_probe(const ProbeCall& call) {
    ProbeOutput out;
    const Scene* scene = scene_or_skip(call, scene_of(call), out);
    if (!scene) return out;
    const EyeCamera camera = probe_camera(call, *scene);
    auto tech = make_vct(*scene, vct_settings(call), call.ctx);
    const Film f = render(*tech, camera);
    save_images(call.ctx, out.files, call.setting<std::string>("image_file", call.variant.name), f);
    nlohmann::json row = {{"image", call.variant.name},
                          {"mean_color", mean_value(f)},
                          {"mean_indirect", mean_value(f, "indirect")},
                          {"mean_specular", mean_value(f, "specular")},
                          {"frame_ms", tech->stats().get("total_ms")}};
    if (call.setting<bool>("against_reference", false)) {
        const Reference& ref = reference_of(call);
        row["relmse_color"] = relative_mse(f, ref.film, "color");
        row["relmse_indirect"] = relative_mse(f, ref.film, "indirect");
    }
    out.rows.push_back(std::move(row));
    return out;
}

// The images' rows under `title` with `columns`.
ExperimentOutput image_table(const SpecReduction& r, const std::string& title, std::vector<std::string> columns,
                             QuickNoteParts quick) {
    require_rows(r);
    ExperimentOutput out;
    ResultTable t{title, std::move(columns), {}};
    for (const nlohmann::json& row : all_rows(r)) {
        nlohmann::json cells;
        for (const std::string& c : t.columns) cells[c] = row.value(c, nlohmann::json());
        t.rows.push_back(std::move(cells));
    }
    out.tables.push_back(std::move(t));
    out.notes = quick_notes(r, quick);
    return out;
}

nlohmann::json vct_image(const std::string& file, nlohmann::json vct) {
    return {{"image_file", file}, {"against_reference", true}, {"vct", std::move(vct)}};
}

// Sponza's stone is purely diffuse, so Fig. 13's specular cone is shown on the Cornell
// box holding the glossy gold Happy Buddha, seen from inside the box.
nlohmann::json buddha(bool specular) {
    return {{"scene", "cornell+buddha"},
            {"camera", {{"eye", {0.5, 0.5, 0.05}}, {"target", {0.5, 0.3, 0.6}}, {"fov", 60}}},
            {"vct", {{"specular", specular}, {"dense_resolution", 128}}}};
}

}  // namespace

void register_images(ExperimentRegistry& registry) {
    add_probe("vct-reference-image", reference_image_probe, image_reference, image_group);
    add_probe("vct-image", vct_image_probe, vct_image_references, [](const ProbeCall& call) {
        return call.setting<bool>("against_reference", false) ? image_group(call) : std::string();
    });
    add_reducer("vct-fig11", [](const SpecReduction& r) {
        return image_table(r, "Fig. 11 — Sponza: cone-traced images against a path-traced reference",
                           {"image", "relmse_color", "relmse_indirect", "mean_color", "mean_indirect", "frame_ms"},
                           {.images = true, .reference_spp = true, .cones = true});
    });
    add_reducer("vct-fig12-13", [](const SpecReduction& r) {
        return image_table(r, "Figs. 12/13 — diffuse (Sponza) and specular (Cornell box + glossy Buddha) cones on and off",
                           {"image", "mean_color", "mean_indirect", "mean_specular", "frame_ms"},
                           {.images = true, .cones = true});
    });
    registry.add(declared_experiment({
        .name = "vct-fig11",
        .paper = "P3",
        .figure = "Fig. 11",
        .description = "Sponza images vs a path-traced reference (relMSE)",
        .scenes = {"sponza"},
        .size = 192, .quick_size = 48,
        .frames = 1, .quick_frames = 1,
        .reference_spp = 512, .quick_reference_spp = 32,
        .variants = {{.name = "path tracer", .probe = "vct-reference-image"},
                     {.name = "vct dense", .probe = "vct-image", .settings = vct_image("sponza_vct_dense", {{"structure", "dense"}})},
                     {.name = "vct cascaded", .probe = "vct-image", .settings = vct_image("sponza_vct_cascaded", {{"structure", "cascaded"}})}},
        .axes = {{"dense_resolution", {128}, {64}}},
        .reducer = "vct-fig11",
        .notes = {"The reference is path traced at the same pixel centres to max depth 8, with a seed of its own (it "
                  "shares no samples with the cone-traced images). Its indirect counts every bounce ≥ 2; VCT gathers "
                  "two indirect bounces (pixel cones + the voxel bounce). The paper shows the images only (no figure "
                  "of merit); images are in this directory."},
    }));
    registry.add(declared_experiment({
        .name = "vct-fig12-13",
        .paper = "P3",
        .figure = "Figs. 12/13",
        .description = "diffuse and specular cones on/off (images)",
        .scenes = {"sponza, cornell+buddha"},
        .size = 192, .quick_size = 48,
        .frames = 1, .quick_frames = 1,
        .variants = {{.name = "fig12_sponza_diffuse_off", .probe = "vct-image",
                      .settings = {{"scene", "sponza"}, {"vct", {{"diffuse", false}, {"specular", false}}}}},
                     {.name = "fig12_sponza_diffuse_on", .probe = "vct-image",
                      .settings = {{"scene", "sponza"}, {"vct", {{"diffuse", true}, {"specular", false}}}}},
                     {.name = "fig13_cornell_buddha_specular_off", .probe = "vct-image", .settings = buddha(false)},
                     {.name = "fig13_cornell_buddha_specular_on", .probe = "vct-image", .settings = buddha(true)}},
        .axes = {{"dense_resolution", {128}, {64}}},
        .reducer = "vct-fig12-13",
        .notes = {"Sponza's stone is purely diffuse, so the specular cone is shown on the Cornell box holding the "
                  "glossy gold Happy Buddha (specular 0.4, Phong 80) instead, at dense_resolution 128 in every run; "
                  "the paper's figures are images only."},
    }));
}

}  // namespace gilab::vct
