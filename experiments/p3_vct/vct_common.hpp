#pragma once
// What the P3 experiments share: the scenes they build (a Stanford model in the Cornell
// box, Sponza with glossy stone, two rooms behind a thin wall), the `vct` technique as
// a probe prepares it, and what the reducers say about quick runs. Every run measures
// its own figures; what a run's tasks share (a loaded scene) lives in its call.cache.
#include <functional>
#include <memory>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "core/scene/scene.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/spec_functions.hpp"
#include "techniques/technique.hpp"

namespace gilab::vct {

// A scene by the name a P3 spec gives it, loaded once per run (call.cache):
//   "cornell+MODEL"  the Cornell box holding a Stanford model (the paper's static scenes),
//   "sponza, glossy" Sponza with its stone made slightly glossy (Table 7's specular cone),
//   "thin_wall"      two closed rooms sharing a wall of `wall_thickness` (light leaking),
//   anything else    the scene as `gilab render` opens it.
// Throws Error when its mesh is missing.
const Scene& scene_named(const ProbeCall& call, const std::string& name);
// The scene `name`, or null with a skip note (skip_note) added to `out` when it cannot be
// loaded.
const Scene* scene_or_skip(const ProbeCall& call, const std::string& name, ProbeOutput& out);
// The scene `name`, or null without a note when it cannot be loaded: for a probe's
// references, whose probe notes the skip itself.
const Scene* loadable_scene(const ProbeCall& call, const std::string& name);

// The probe's scene: its setting "scene", else the task's scene.
std::string scene_of(const ProbeCall& call);

// The scene's camera, for a square image of `size` pixels.
EyeCamera scene_camera(const Scene& scene, int size);

// The camera walks of Figs. 9–10 (and Table 7's update), straight down each scene's nave,
// looking ahead and slightly up. The paper walks through both of its dynamic scenes.
struct CameraWalk {
    std::string scene;
    Vec3 from, to, look;  // eye from → to, looking along `look`
    const char* description;
};
const std::vector<CameraWalk>& camera_walks();
const CameraWalk& camera_walk(const std::string& scene);  // throws Error for a scene without one
// `frames` cameras evenly from `from` to `to`.
std::vector<EyeCamera> walk_cameras(const CameraWalk& walk, int size, int frames);

// The viewer the cascades centre on for Tables 1–6: the scene camera when it stands
// inside the scene (Sponza), else the scene's centre (the Cornell camera stands in front
// of the box, where the cascades would hold nothing of it).
Vec3 scene_viewer(const Scene& scene);

// The `vct` settings of a probe variant: its "vct" object, with the run's dense
// resolution (setting "dense_resolution", an axis with a quick value) where the variant
// does not fix its own, and the run's seed.
nlohmann::json vct_settings(const ProbeCall& call);
// `vct` prepared on `scene`. Quick runs are smoke checks: kQuickInjectionCones
// voxel-bounce cones (half the paper's 16) unless the settings say otherwise.
constexpr int kQuickInjectionCones = 8;
std::unique_ptr<Technique> make_vct(const Scene& scene, nlohmann::json settings, const ExperimentContext& ctx);

Film render(Technique& t, const EyeCamera& camera);
// Writes NAME.exr and NAME.png into the output directory and lists them in `files`.
void save_images(const ExperimentContext& ctx, std::vector<std::string>& files, const std::string& name, const Film& film);

// "scene 'NAME' skipped: why" — the note a probe returns when a mesh is missing.
std::string skip_note(const ExperimentContext& ctx, const std::string& scene, const std::string& why);

// What a quick run's note names besides the axis settings it shrinks: the spec's image
// side, its frames per task and its reference samples where the probes use them, and the
// voxel-bounce cones where they cone trace.
struct QuickNoteParts {
    bool images = false, frames = false, reference_spp = false, cones = false;
};
// The note a quick run carries (none in a full run), from the spec: every axis setting
// whose quick values differ from the full ones, then `parts`.
std::vector<std::string> quick_notes(const SpecReduction& r, QuickNoteParts parts);

// Throws when no task has a row (every scene skipped): there is no table to print.
void require_rows(const SpecReduction& r);

// The rows of every task, in plan order.
std::vector<nlohmann::json> all_rows(const SpecReduction& r);

// Registration of each group, in the order the experiments are listed.
void register_structure_tables(ExperimentRegistry& registry);  // vct-table1..6
void register_phase_times(ExperimentRegistry& registry);       // vct-table7
void register_camera_walks(ExperimentRegistry& registry);      // vct-fig9, vct-fig10
void register_images(ExperimentRegistry& registry);            // vct-fig11, vct-fig12-13
void register_stability(ExperimentRegistry& registry);         // vct-stability
void register_equal_time(ExperimentRegistry& registry);        // vct-equal-time

}  // namespace gilab::vct
