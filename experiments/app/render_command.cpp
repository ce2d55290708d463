#include "experiments/app/render_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include "core/util/error.hpp"
#include "core/image/film.hpp"
#include "core/util/format.hpp"
#include "core/scene/hmd.hpp"
#include "core/image/image_io.hpp"
#include "core/util/memory_budget.hpp"
#include "core/scene/mesh_topology.hpp"
#include "experiments/runner/result_writers.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/stereo_frame.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

Settings read_settings(const RenderRequest& request) {
    Settings settings = request.settings_file ? Settings::from_file(*request.settings_file)
                                              : Settings(nlohmann::json::object(), "--set");
    for (const auto& a : request.assignments) settings.set_from_string(a);
    if (request.spp) settings.set("spp", *request.spp);
    if (request.time_budget) settings.set("time_budget", *request.time_budget);
    settings.set("seed", request.seed);
    return settings;
}

struct TracePlan {
    std::string path;
    std::vector<HeadPoseSample> trace;
    int frames = 1;
    double fps = 30;
    float scale = 1;
};

// Checks the sequence options and loads the trace, before anything is rendered or written.
std::optional<TracePlan> plan_trace(const RenderRequest& request) {
    if (!request.head_trace) {
        if (request.frames || request.fps || request.trace_scale)
            throw Error("--frames/--fps/--trace-scale", "only apply to a head-pose sequence; give --head-trace FILE");
        return std::nullopt;
    }
    if (!request.hmd)
        throw Error("--head-trace", "needs --hmd PRESET (a head-pose trace drives the stereo pair of a headset)");
    TracePlan plan;
    plan.path = *request.head_trace;
    plan.fps = request.fps.value_or(30.0);
    if (!std::isfinite(plan.fps) || !(plan.fps > 0)) throw Error("--fps", "must be a positive number of frames per second");
    plan.scale = request.trace_scale.value_or(1.0f);
    if (!std::isfinite(plan.scale) || plan.scale < 0)
        throw Error("--trace-scale", "must be a finite number ≥ 0 (scene units per trace metre)");
    if (request.frames && *request.frames < 1) throw Error("--frames", "must be at least 1");
    plan.trace = load_head_pose_trace(plan.path);
    double duration = plan.trace.back().time - plan.trace.front().time;
    double frames = request.frames ? double(*request.frames) : std::max(1.0, std::round(duration * plan.fps));
    constexpr double kMaxFrames = 1e6;  // a typo'd --fps should not queue days of rendering
    if (frames > kMaxFrames)
        throw Error(plan.path, "a " + number_as_given(duration) + " s trace at " + number_as_given(plan.fps) +
                                   " fps is more than 1000000 frames; give --frames");
    plan.frames = int(frames);
    return plan;
}

void tag_film(Film& film, const Scene& scene, const std::string& view, const Technique& technique,
              const Settings& settings, const RenderRequest& request, const HmdRig* rig) {
    film.metadata["scene"] = scene.source.empty() ? scene.name : scene.source;
    film.metadata["view"] = view;
    film.metadata["technique"] = technique.name();
    film.metadata["config_hash"] = settings.hash();
    film.metadata["settings"] = settings.json().dump();
    film.metadata["git_revision"] = git_revision();
    film.metadata["seed"] = std::to_string(request.seed);
    if (rig) film.metadata["hmd"] = rig->preset().name;
}

std::string default_output(const Scene& scene, const Technique& technique, bool stereo) {
    return "results/render/" + scene.name + "_" + technique.name() + (stereo ? "_stereo" : "");
}

// Every option is checked before the scene loads, so a bad value never costs a render
// and never leaves a file behind.
void check_options(const RenderRequest& request) {
    if (!std::isfinite(request.time)) throw Error("--time", number_as_given(request.time) + " is not a finite number of seconds");
    if (request.ipd && !(*request.ipd >= 0 && *request.ipd < 1))
        throw Error("--ipd", number_as_given(*request.ipd) + " is out of range: give metres in [0, 1), e.g. 0.063");
    if (!std::isfinite(request.exposure)) throw Error("--exposure", number_as_given(request.exposure) + " is not a finite number of stops");
    if (request.output.empty()) return;
    // An explicit -o never creates directories: a mistyped directory would otherwise
    // scatter results where nobody looks.
    const fs::path out(request.output);
    if (!out.has_filename() || request.output.back() == '/')
        throw Error("-o " + request.output, "names a directory; give a file path without extension, e.g. DIR/image");
    const fs::path dir = out.parent_path();
    std::error_code ec;
    if (!dir.empty() && !fs::is_directory(dir, ec))
        throw Error("-o " + request.output, "directory '" + dir.string() +
                                                "' does not exist (create it first; -o does not create directories)");
}

// The default output directory (results/render) is created when missing, with a note.
void make_default_directory(const fs::path& base) {
    const fs::path dir = base.parent_path();
    std::error_code ec;
    if (dir.empty() || fs::is_directory(dir, ec)) return;
    fs::create_directories(dir, ec);
    if (ec) throw Error(dir.string(), "cannot create the output directory: " + ec.message());
    std::cerr << "gilab: note: created directory " << dir.string() << "\n";
}

// Outputs go to hidden temporary names and are renamed into place only when every one
// has been written, so a failed run leaves nothing half-written behind.
class StagedOutputs {
public:
    StagedOutputs() = default;
    StagedOutputs(const StagedOutputs&) = delete;
    StagedOutputs& operator=(const StagedOutputs&) = delete;
    ~StagedOutputs() {
        for (const auto& [temp, target] : files_) {
            std::error_code ec;
            fs::remove(temp, ec);
        }
    }
    // Where to write `target` for now.
    fs::path stage(const fs::path& target) {
        // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "." + std::string.
        std::string name(1, '.');
        name += target.filename().string();
        name += ".partial";
        const fs::path temp = target.parent_path() / name;
        files_.emplace_back(temp, target);
        return temp;
    }
    void commit() {
        for (size_t i = 0; i < files_.size(); ++i) {
            std::error_code ec;
            fs::rename(files_[i].first, files_[i].second, ec);
            if (ec) throw Error(files_[i].second.string(), "cannot move the finished file into place: " + ec.message());
        }
        files_.clear();
    }

private:
    std::vector<std::pair<fs::path, fs::path>> files_;  // temporary, target
};

// A default camera that looks past the geometry (or at its edge) gives a black image;
// say so instead of leaving a silent black file.
void warn_if_unseen(const OpenedScene& opened, const std::vector<Film>& films) {
    if (!opened.default_camera) return;
    for (const Film& film : films)
        for (float v : film.layer("color").data)
            if (v != 0.0f) return;
    std::cerr << "gilab: warning: " << opened.scene.name
              << ": the default camera sees nothing (the image is black); give the scene a camera\n";
}

// The films a render allocates (a handful of 3-channel float layers per view) come out of
// the memory budget like everything else sized by input.
void check_film_memory(int width, int height, int views) {
    constexpr uint64_t kLayerBytesPerPixel = 8 * 3 * sizeof(float);
    MemoryBudget::check(MemoryBudget::times(uint64_t(width) * uint64_t(height) * uint64_t(views), kLayerBytesPerPixel),
                        "a " + std::to_string(width) + "×" + std::to_string(height) + " film" + (views > 1 ? " per eye" : ""),
                        "--width/--height");
}

std::string format_number(double value, int precision) {
    std::ostringstream out;
    out << std::fixed << std::setprecision(precision) << value;
    return out.str();
}

// Frame k at t = k / fps: the head follows the trace from the rig's starting pose.
std::vector<std::string> render_sequence(const TracePlan& plan, Technique& technique, HmdRig& rig,
                                         const OpenedScene& opened, const Settings& settings, const RenderRequest& request) {
    const Scene& scene = opened.scene;
    std::string base = request.output.empty() ? default_output(scene, technique, true) : request.output;
    fs::path csv_path = base + "_frames.csv";
    if (request.output.empty()) make_default_directory(csv_path);
    StagedOutputs staged;

    const HeadPose start = rig.pose();
    std::ostringstream csv;
    csv << "frame,time,px,py,pz,qw,qx,qy,qz,render_ms\n";
    std::vector<std::string> written;
    double total_ms = 0;
    for (int k = 0; k < plan.frames; ++k) {
        double t = k / plan.fps;
        double scene_time = request.time + t;
        if (scene.is_animated() || (k == 0 && request.time != 0)) technique.update(scene_time);
        rig.set_pose(trace_pose_relative_to(start, plan.trace, plan.trace.front().time + t, plan.scale));
        StereoFrame frame = render_stereo_frame(technique, rig);
        total_ms += frame.render_ms;

        const HeadPose& pose = rig.pose();
        const Vec3& p = pose.position;
        const Quat& q = pose.orientation;
        std::string pose_text = format_number(p.x, 6) + "," + format_number(p.y, 6) + "," + format_number(p.z, 6) +
                                "," + format_number(q.w, 7) + "," + format_number(q.x, 7) + "," +
                                format_number(q.y, 7) + "," + format_number(q.z, 7);
        for (auto [film, view] : {std::pair{&frame.left, "left"}, std::pair{&frame.right, "right"}}) {
            tag_film(*film, scene, view, technique, settings, request, &rig);
            film->metadata["frame"] = std::to_string(k);
            film->metadata["time"] = format_number(scene_time, 6);
            film->metadata["head_trace"] = plan.path;
            film->metadata["head_pose"] = pose_text;  // px,py,pz,qw,qx,qy,qz
        }

        char suffix[32];
        std::snprintf(suffix, sizeof suffix, "_%04d", k);
        fs::path exr = base + suffix + ".exr", png = base + suffix + ".png";
        if (k == 0) warn_if_unseen(opened, {frame.left, frame.right});
        write_exr_stereo(staged.stage(exr), frame.left, frame.right);
        write_png_side_by_side(staged.stage(png), frame.left, frame.right, request.exposure);
        written.push_back(exr.string());
        written.push_back(png.string());
        csv << k << "," << format_number(t, 6) << "," << pose_text << "," << format_number(frame.render_ms, 3) << "\n";
        std::cout << "frame " << (k + 1) << "/" << plan.frames << "  t = " << format_number(t, 4) << " s  render "
                  << format_number(frame.render_ms, 1) << " ms  " << exr.string() << std::endl;
    }
    write_file_atomically(staged.stage(csv_path), csv.str());
    staged.commit();
    written.push_back(csv_path.string());
    std::cout << "rendered " << scene.name << " with " << technique.name() << " (2 eyes, " << rig.preset().width
              << "×" << rig.preset().height << "), " << plan.frames << " frames along " << plan.path << " in "
              << format_number(total_ms / 1000.0, 3) << " s\n  " << csv_path.string() << "\n";
    return written;
}

}  // namespace

HeadPose pose_from_camera(const SceneCamera& c) {
    EyeCamera eye = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, 1, 1);
    return {eye.position(), eye.orientation()};
}

namespace {

// Everything the technique's schema can tell before a scene is loaded: --spp and
// --time-budget need the settings they set, and every --set key must be declared.
void check_settings_against_schema(const Technique& technique, const RenderRequest& request, const Settings& settings) {
    // --spp is stored as the setting 'spp'; a technique that declares no such setting
    // takes no pixel samples, which is the option's fault, not an unknown --set key.
    const SettingsSchema& schema = TechniqueRegistry::builtin().find(technique.name())->settings_schema();
    if (request.spp && !schema.declares("spp"))
        throw Error("--spp", "technique '" + technique.name() +
                                 "' takes no pixel samples (it has no setting 'spp'); leave --spp out");
    if (request.time_budget && !schema.declares("time_budget"))
        throw Error("--time-budget", "technique '" + technique.name() +
                                         "' takes no time budget (it has no setting 'time_budget'); leave --time-budget out");
    check_settings_known(technique, settings);
}

}  // namespace

TechniqueAndRig begin_render(const RenderRequest& request) {
    check_options(request);
    TechniqueAndRig setup;
    setup.technique = TechniqueRegistry::builtin().create(request.technique);  // fail fast on a bad name
    setup.settings = read_settings(request);
    check_settings_against_schema(*setup.technique, request, setup.settings);
    if (request.hmd) setup.rig = HmdRig(find_hmd_preset(*request.hmd));  // before loading: bad preset fails fast
    if (request.width && request.height) check_resolution(*request.width, *request.height);
    else if (request.width || request.height) throw Error("--width/--height", "give both or neither");
    return setup;
}

ViewSet aim_views(TechniqueAndRig& setup, const RenderRequest& request, const Scene& scene) {
    if (std::optional<HmdRig>& rig = setup.rig) {
        if (scene.hmd) rig->set_pose(scene.hmd->pose);
        else rig->set_pose(pose_from_camera(*scene.camera));
        if (scene.hmd && scene.hmd->ipd) rig->set_ipd(*scene.hmd->ipd);
        if (request.ipd) rig->set_ipd(*request.ipd);
        if (request.width) rig->set_resolution(*request.width, *request.height);
        check_resolution(rig->preset().width, rig->preset().height);
        check_film_memory(rig->preset().width, rig->preset().height, 2);
        return ViewSet::stereo_pair(rig->eye(Eye::Left), rig->eye(Eye::Right));
    }
    int w = request.width.value_or(512), h = request.height.value_or(512);
    check_resolution(w, h);
    check_film_memory(w, h, 1);
    const SceneCamera& c = *scene.camera;
    return ViewSet::mono(EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, w, h));
}

void prepare_render(TechniqueAndRig& setup, const RenderRequest& request, const Scene& scene) {
    Technique& technique = *setup.technique;
    const Settings& settings = setup.settings;
    technique.prepare(scene, settings);
    report_unused_settings(technique, settings);
}

std::vector<Film> render_films(TechniqueAndRig& setup, const RenderRequest& request, const Scene& scene,
                               const ViewSet& views) {
    Technique& technique = *setup.technique;
    if (request.time != 0) technique.update(request.time);
    std::vector<Film> films(views.views.size());
    technique.render(views, films);
    for (size_t i = 0; i < films.size(); ++i)
        tag_film(films[i], scene, views.names[i], technique, setup.settings, request, setup.rig ? &*setup.rig : nullptr);
    return films;
}

std::vector<std::string> run_render(const RenderRequest& request) {
    TechniqueAndRig setup = begin_render(request);
    std::optional<TracePlan> plan = plan_trace(request);  // a bad trace fails before the scene loads

    OpenedScene opened = open_scene(request.scene, request.assets);
    for (const auto& w : opened.warnings) std::cerr << "gilab: note: " << request.scene << ": " << w << "\n";
    const Scene& scene = opened.scene;

    const ViewSet views = aim_views(setup, request, scene);
    prepare_render(setup, request, scene);
    if (plan) return render_sequence(*plan, *setup.technique, *setup.rig, opened, setup.settings, request);

    std::vector<Film> films = render_films(setup, request, scene, views);
    Technique* technique = setup.technique.get();
    const std::optional<HmdRig>& rig = setup.rig;

    warn_if_unseen(opened, films);
    std::string base = request.output;
    if (base.empty()) base = default_output(scene, *technique, rig.has_value());
    fs::path exr = base + ".exr", png = base + ".png";
    if (request.output.empty()) make_default_directory(exr);
    StagedOutputs staged;
    if (films.size() == 2) {
        write_exr_stereo(staged.stage(exr), films[0], films[1]);
        write_png_side_by_side(staged.stage(png), films[0], films[1], request.exposure);
    } else {
        write_exr(staged.stage(exr), films[0]);
        write_png(staged.stage(png), films[0], request.exposure);
    }
    staged.commit();
    Stats stats = technique->stats();
    std::cout << "rendered " << scene.name << " with " << technique->name() << " (" << views.views.size()
              << (views.views.size() == 2 ? " eyes" : " view") << ", " << films[0].width() << "×" << films[0].height()
              << ")";
    if (stats.has("render_ms")) std::cout << " in " << stats.get("render_ms") / 1000.0 << " s";
    std::cout << "\n  " << exr.string() << "\n  " << png.string() << "\n";
    return {exr.string(), png.string()};
}

std::string describe_scene(const std::string& spec, const AssetPaths& assets) {
    OpenedScene opened = open_scene(spec, assets);
    const Scene& s = opened.scene;
    std::ostringstream out;
    SceneFrame frame = s.evaluate(0);
    out << "scene        " << s.name << " (" << s.source << ")\n";
    out << "triangles    " << s.triangle_count() << "\n";
    out << "meshes       " << s.meshes.size() << " in " << s.nodes.size() << " nodes\n";
    out << "materials    " << s.materials.size();
    size_t emissive = 0;
    for (const auto& m : s.materials) emissive += m.is_emissive();
    out << " (" << emissive << " emissive)\n";
    const TextureUse textures = s.texture_use();
    out << "textures     " << textures.images << (textures.images == 1 ? " image, " : " images, ") << format_number(double(textures.bytes) / 1e6, 2)
        << " MB with mip levels, used by " << textures.textured_materials
        << (textures.textured_materials == 1 ? " material\n" : " materials\n");
    out << "lights       " << s.lights.size() << " punctual";
    for (const auto& l : s.lights) out << " [" << to_string(l.type) << (l.name.empty() ? "" : " " + l.name) << "]";
    out << "\n";
    const Bounds3& b = frame.bounds;
    out << "bounds       [" << b.min.x << ", " << b.min.y << ", " << b.min.z << "] .. [" << b.max.x << ", " << b.max.y
        << ", " << b.max.z << "]\n";
    out << "animation    " << (s.is_animated() ? std::to_string(s.animation_frame_count()) + " frames over " +
                                                     std::to_string(s.animation_duration()) + " s at " +
                                                     std::to_string(s.frames_per_second) + " fps"
                                               : std::string("static (1 frame)"))
        << "\n";
    if (s.degenerate_triangles_dropped) out << "dropped      " << s.degenerate_triangles_dropped << " zero-area triangles\n";
    out << "camera       " << (s.camera ? "yes" : "no") << ", hmd " << (s.hmd ? s.hmd->preset : std::string("no")) << "\n";
    out << "meshes (closed = watertight 2-manifold, checked with CGAL):\n";
    for (size_t i = 0; i < s.meshes.size(); ++i) {
        MeshTopology topo = analyze_topology(s.meshes[i]);
        out << "  " << i << " " << (s.meshes[i].name.empty() ? "(unnamed)" : s.meshes[i].name) << ": "
            << s.meshes[i].triangles.size() << " triangles, " << (topo.closed ? "closed" : "open") << ", "
            << topo.boundary_edges << " boundary edges, " << topo.connected_components << " components ("
            << topo.closed_components << " closed)\n";
    }
    for (const auto& w : opened.warnings) out << "note         " << w << "\n";
    return out.str();
}

}  // namespace gilab
