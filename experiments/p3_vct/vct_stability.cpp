// P3 stability: flicker while the camera walks slowly through Sponza (how much the
// cone-traced layer changes between frames beyond what the motion itself changes), and
// light leaking through a wall thinner than a voxel (two closed rooms, the lamp in one,
// the camera in the other) — for the cone tracers and for light propagation volumes,
// whose known failure this is too.
#include <algorithm>
#include <cmath>
#include "core/image/image_metrics.hpp"
#include "core/util/error.hpp"
#include "core/util/stats.hpp"
#include "experiments/p3_vct/vct_common.hpp"
#include "experiments/runner/measures.hpp"
#include "experiments/runner/path_reference.hpp"

namespace gilab::vct {

namespace {

// The mean relative change of `layer` between two frames.
double change(const Film& a, const Film& b, const std::string& layer) {
    const auto& x = a.layer(layer).data;
    const auto& y = b.layer(layer).data;
    double d = 0, m = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        d += std::abs(double(x[i]) - double(y[i]));
        m += 0.5 * (std::abs(double(x[i])) + std::abs(double(y[i])));
    }
    return m > 0 ? d / m : 0.0;
}

// The slow walk: 0.12 m per frame down Sponza's nave (about half a finest voxel at 128³).
std::vector<EyeCamera> slow_walk(int size, int frames) {
    std::vector<EyeCamera> cams;
    for (int i = 0; i < frames; ++i) {
        const Vec3 eye(-6.0f + 0.12f * float(i), 2.0f, 0.3f);
        cams.push_back(EyeCamera::look_at(eye, eye + Vec3(6, 1.2f, 0), Vec3(0, 1, 0), 60.0f, size, size));
    }
    return cams;
}

// One `vct` variant (setting "vct", the axis's dense resolution) along the slow walk of
// "walk_frames" frames at "walk_size": the mean frame-to-frame change of the direct and
// the indirect layer. The walk is laid down Sponza's nave, so setting "scene" (the
// task's scene when absent) must be "sponza"; a missing Sponza is skipped with a note.
ProbeOutput flicker_probe(const ProbeCall& call) {
    const std::string name = scene_of(call);
    if (name != "sponza")
        throw Error(call.spec.name, "variant '" + call.variant.name + "': setting 'scene' is '" + name +
                                        "', but the flicker walk is laid down Sponza's nave (scene 'sponza' only)");
    ProbeOutput out;
    const Scene* scene = scene_or_skip(call, name, out);
    if (!scene) return out;
    auto tech = make_vct(*scene, vct_settings(call), call.ctx);
    std::vector<Film> films;
    for (const EyeCamera& c : slow_walk(call.setting<int>("walk_size"), call.setting<int>("walk_frames")))
        films.push_back(render(*tech, c));
    std::vector<double> dd, di;
    for (size_t i = 1; i < films.size(); ++i) {
        dd.push_back(change(films[i - 1], films[i], "direct"));
        di.push_back(change(films[i - 1], films[i], "indirect"));
    }
    out.rows.push_back({{"direct_change", mean(dd)}, {"indirect_change", mean(di)},
                        {"indirect_minus_direct", mean(di) - mean(dd)}});
    return out;
}

// The leak probe's views of the thin-wall rooms at "leak_size": from the dark room (the
// scene camera) and from the lit one.
struct LeakCameras {
    EyeCamera dark, lit;
};
LeakCameras leak_cameras(const ProbeCall& call, const Scene& rooms) {
    const int size = call.setting<int>("leak_size");
    const SceneCamera& c = *rooms.camera;
    return {EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size),
            EyeCamera::look_at(Vec3(0.2f, 0.5f, 0.5f), Vec3(2.0f, 0.35f, 0.5f), c.up, c.vertical_fov_degrees, size, size)};
}

// A leak variant renders with a real-time technique when it has settings for one ("vct"
// or "lpv"), else it is the path-traced ground truth.
bool real_time_variant(const ProbeCall& call) {
    return call.variant.settings.contains("vct") || call.variant.settings.contains("lpv");
}

// The path-traced variant's references ("leak_reference_spp"): the dark room's view, then
// the lit room's. None for a real-time variant or without the scene.
std::vector<ReferenceView> leak_references(const ProbeCall& call) {
    if (real_time_variant(call)) return {};
    const Scene* rooms = loadable_scene(call, scene_of(call));
    if (!rooms) return {};
    const LeakCameras cams = leak_cameras(call, *rooms);
    const int spp = call.setting<int>("leak_reference_spp");
    return {ReferenceView{rooms, cams.dark, spp}, ReferenceView{rooms, cams.lit, spp}};
}

// The thin-wall rooms seen from the dark room and from the lit one: their mean radiance,
// path traced (leak_references) for a variant without technique settings, else cone
// traced ("vct") or from light propagation volumes ("lpv"); setting "image_file" keeps
// the dark room's image.
ProbeOutput leak_probe(const ProbeCall& call) {
    const Scene& rooms = scene_named(call, scene_of(call));
    ProbeOutput out;
    Film dark, lit;
    if (!real_time_variant(call)) {
        const std::vector<ReferenceView> views = leak_references(call);
        dark = path_reference(call.ctx, views.at(0), out.files);
        lit = path_reference(call.ctx, views.at(1), out.files);
    } else {
        const auto [dark_cam, lit_cam] = leak_cameras(call, rooms);
        std::unique_ptr<Technique> tech;
        if (call.variant.settings.contains("vct")) {
            tech = make_vct(rooms, vct_settings(call), call.ctx);
        } else {
            nlohmann::json settings = call.setting<nlohmann::json>("lpv");
            settings["seed"] = call.ctx.seed;
            tech = prepare_technique("lpv", rooms, Settings(settings, call.spec.name + " lpv settings"));
        }
        lit = render(*tech, lit_cam);
        dark = render(*tech, dark_cam);
        if (call.variant.settings.contains("image_file"))
            save_images(call.ctx, out.files, call.setting<std::string>("image_file"), dark);
    }
    out.rows.push_back({{"technique", call.variant.name},
                        {"dark_room_mean", mean_value(dark)},
                        {"lit_room_mean", mean_value(lit)},
                        {"leak_ratio", mean_value(dark) / std::max(mean_value(lit), 1e-12)}});
    return out;
}

// The flicker rows (variant, changes) and the leak rows (technique, means) as two tables;
// a table whose probes were all skipped is empty (the skip notes say why).
ExperimentOutput stability(const SpecReduction& r) {
    require_rows(r);
    ExperimentOutput out;
    ResultTable flicker{"Flicker — mean relative change between consecutive frames while walking (Sponza)",
                        {"variant", "direct_change", "indirect_change", "indirect_minus_direct"}, {}};
    ResultTable leak{"Light leaking — mean radiance seen in the dark room (camera in room B, lamp in room A)",
                     {"technique", "dark_room_mean", "lit_room_mean", "leak_ratio"}, {}};
    for (const nlohmann::json& row : all_rows(r)) {
        ResultTable& t = row.contains("technique") ? leak : flicker;
        nlohmann::json cells;
        for (const std::string& c : t.columns) cells[c] = row.at(c);
        t.rows.push_back(std::move(cells));
    }
    out.tables = {std::move(flicker), std::move(leak)};
    out.notes = quick_notes(r, {.cones = true});
    return out;
}

SpecVariant flicker_variant(const std::string& name, nlohmann::json vct) {
    return {.name = name, .probe = "vct-flicker", .settings = {{"scene", "sponza"}, {"vct", std::move(vct)}}};
}

// A thin wall of 0.01 m: the rooms are 4 m long, so at 64³ a voxel is 0.0625 m and the
// wall 0.16 of it.
SpecVariant leak_variant(const std::string& name, nlohmann::json vct, const std::string& image_file = "",
                         const std::string& technique = "vct") {
    nlohmann::json settings = {{"scene", "thin_wall"}, {"wall_thickness", 0.01}};
    if (!vct.is_null()) settings[technique] = std::move(vct);
    if (!image_file.empty()) settings["image_file"] = image_file;
    return {.name = name, .probe = "vct-leak", .settings = std::move(settings)};
}

nlohmann::json leak_vct(const std::string& structure, bool clip_plane) {
    return {{"structure", structure}, {"dense_resolution", 64}, {"clip_plane", clip_plane}};
}

}  // namespace

void register_stability(ExperimentRegistry& registry) {
    add_probe("vct-flicker", flicker_probe);
    add_probe("vct-leak", leak_probe, leak_references, [](const ProbeCall& call) {
        return real_time_variant(call) ? std::string() : call.spec.name + "/" + std::to_string(call.task.id);
    });
    add_reducer("vct-stability", stability);
    registry.add(declared_experiment({
        .name = "vct-stability",
        .paper = "P3",
        .figure = "Stability",
        .description = "flicker while walking, and light leaking through a wall thinner than a voxel (cone tracers and LPV)",
        .scenes = {"sponza walk, thin-wall rooms"},
        .variants = {flicker_variant("dense mip", {{"structure", "dense"}}),
                     flicker_variant("cascaded, update everything", {{"update", "everything"}}),
                     flicker_variant("cascaded, update strategy", nlohmann::json::object()),
                     leak_variant("path tracer", nullptr),
                     leak_variant("vct dense", leak_vct("dense", true), "leak_dark_room_dense"),
                     leak_variant("vct dense, clip_plane off", leak_vct("dense", false)),
                     leak_variant("vct cascaded", leak_vct("cascaded", true), "leak_dark_room_cascaded"),
                     leak_variant("vct cascaded, clip_plane off", leak_vct("cascaded", false)),
                     // LPV's defaults (3 cascades of 32³, cells far thicker than the wall); its
                     // geometry volume blocks only where the RSMs and the camera saw surfels.
                     leak_variant("lpv", nlohmann::json::object(), "leak_dark_room_lpv", "lpv"),
                     leak_variant("lpv, occlusion off", {{"occlusion", false}}, "", "lpv"),
                     leak_variant("lpv, gradient dampening", {{"gradient_dampening", true}}, "", "lpv")},
        .axes = {{"",
                  {nlohmann::json{{"dense_resolution", 128}, {"walk_size", 192}, {"walk_frames", 16},
                                  {"leak_size", 96}, {"leak_reference_spp", 64}}},
                  {nlohmann::json{{"dense_resolution", 64}, {"walk_size", 32}, {"walk_frames", 3},
                                  {"leak_size", 32}, {"leak_reference_spp", 16}}}}},
        .reducer = "vct-stability",
        .notes = {"Flicker: a walk of walk_frames frames, 0.12 m per frame down Sponza's nave. The direct layer is ray "
                  "traced exactly (its change is what the camera motion itself causes); indirect_minus_direct is the "
                  "extra change of the cone-traced layer — voxel popping as cascades scroll and levels update on "
                  "their schedule.",
                  "Leaking: a wall of 0.01 m between two closed 2 m rooms (voxel at 64³: 4 m / 64 = 0.0625 m, the wall "
                  "0.16 of it). Room B has no light and is closed, so the path tracer sees ≈ 0 there. The cones in "
                  "room B meet the partition's room-B side first (dark, opaque); light gets through where the wide "
                  "trilinear footprint of a coarse level reaches the lit side. LPV: light injected in room A propagates "
                  "cell to cell; only the geometry volume (the wall's surfels seen by the lamp's shadow maps and the "
                  "camera) holds it back, fuzzily, and a cell straddling the wall holds light of both sides."},
    }));
}

}  // namespace gilab::vct
