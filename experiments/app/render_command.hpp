#pragma once
// `gilab render`: one scene, one technique, a mono camera or an HMD stereo pair.
#include <optional>
#include <string>
#include <vector>
#include "core/io/asset_paths.hpp"
#include "core/scene/hmd.hpp"
#include "core/scene/scene.hpp"
#include "core/util/settings.hpp"
#include "techniques/technique.hpp"

namespace gilab {

struct RenderRequest {
    std::string scene = "cornell";
    std::string technique = "path";
    std::optional<std::string> hmd;   // preset name → stereo
    std::optional<float> ipd;
    std::optional<int> width, height; // default: preset's per-eye size, or 512×512 mono
    std::optional<int> spp;
    std::optional<double> time_budget;  // seconds: the technique setting 'time_budget'
    uint64_t seed = 1;
    double time = 0;
    std::string output;               // path without extension; default results/render/SCENE_TECHNIQUE
    std::optional<std::string> settings_file;
    std::vector<std::string> assignments;  // key=value
    float exposure = 0;
    // Head-pose trace (needs hmd): renders a sequence, frame k at t = k / fps, the head
    // moving from the scene's HMD pose as the trace moves from its first sample.
    std::optional<std::string> head_trace;
    std::optional<int> frames;         // default: trace duration × fps, at least 1
    std::optional<double> fps;        // default 30
    std::optional<float> trace_scale;  // scene units per trace metre; default 1
    AssetPaths assets;
};

// The steps of `gilab render` that make the images, in order. The Python module runs the
// same steps, so both give bit-identical images for the same request. They share what the
// render is made with: the technique, its settings and, for a stereo pair, the HMD rig.
struct TechniqueAndRig {
    std::unique_ptr<Technique> technique;
    Settings settings;
    std::optional<HmdRig> rig;  // set: a stereo pair
};
// Checks the options and creates the technique, its settings and the HMD rig, all before
// the scene loads, so a bad option never costs a scene load.
TechniqueAndRig begin_render(const RenderRequest& request);
// The views of the scene: the rig's pair (posed by the scene's HMD or its camera, with
// the request's ipd and size) or the scene camera at the request's size (512² default).
ViewSet aim_views(TechniqueAndRig& setup, const RenderRequest& request, const Scene& scene);
// Prepares the technique for the scene; settings it never read are errors (and --spp or
// --time-budget given to a technique that takes none).
void prepare_render(TechniqueAndRig& setup, const RenderRequest& request, const Scene& scene);
// Moves the scene to request.time when it is not 0, renders every view and tags each film
// with its provenance (scene, view, technique, settings, seed, HMD).
std::vector<Film> render_films(TechniqueAndRig& setup, const RenderRequest& request, const Scene& scene,
                               const ViewSet& views);

// Renders and writes OUTPUT.exr and OUTPUT.png; returns the paths written. With a head
// trace: OUTPUT_0000.exr/.png per frame and OUTPUT_frames.csv (head pose, render time).
std::vector<std::string> run_render(const RenderRequest& request);

// Head pose when the scene gives none: the mono camera's position and orientation.
HeadPose pose_from_camera(const SceneCamera& camera);

// `gilab info`: a human-readable summary of a scene.
std::string describe_scene(const std::string& spec, const AssetPaths& assets);

}  // namespace gilab
