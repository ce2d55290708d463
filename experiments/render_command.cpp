#include "experiments/render_command.hpp"

#include <fstream>
#include <iostream>
#include <sstream>
#include "core/error.hpp"
#include "core/film.hpp"
#include "core/hmd.hpp"
#include "core/image_io.hpp"
#include "core/mesh_topology.hpp"
#include "experiments/result_writers.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

Settings read_settings(const RenderRequest& request) {
    nlohmann::json values = nlohmann::json::object();
    std::string context = "--set";
    if (request.settings_file) {
        std::ifstream in(*request.settings_file);
        if (!in) throw Error(*request.settings_file, "settings file not found or unreadable");
        try {
            values = nlohmann::json::parse(in);
        } catch (const nlohmann::json::parse_error& e) {
            throw Error(*request.settings_file, std::string("malformed JSON: ") + e.what());
        }
        context = *request.settings_file;
    }
    Settings settings(values, context);
    for (const auto& a : request.assignments) settings.set_from_string(a);
    if (request.spp) settings.set("spp", *request.spp);
    settings.set("seed", request.seed);
    return settings;
}

// Head pose when the scene gives none: the mono camera's position and orientation.
HeadPose pose_from_camera(const SceneCamera& c) {
    EyeCamera eye = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, 1, 1);
    return {eye.position(), eye.orientation()};
}

}  // namespace

std::vector<std::string> run_render(const RenderRequest& request) {
    const TechniqueRegistry& registry = TechniqueRegistry::builtin();
    std::unique_ptr<Technique> technique = registry.create(request.technique);  // fail fast on a bad name
    Settings settings = read_settings(request);

    ViewSet views;
    std::optional<HmdRig> rig;
    if (request.hmd) rig = HmdRig(find_hmd_preset(*request.hmd));  // before loading: bad preset fails fast
    if (request.width && request.height) check_resolution(*request.width, *request.height);
    else if (request.width || request.height) throw Error("--width/--height", "give both or neither");

    OpenedScene opened = open_scene(request.scene, request.assets);
    for (const auto& w : opened.warnings) std::cerr << "gilab: note: " << request.scene << ": " << w << "\n";
    const Scene& scene = opened.scene;

    if (rig) {
        if (scene.hmd) rig->set_pose(scene.hmd->pose);
        else rig->set_pose(pose_from_camera(*scene.camera));
        if (scene.hmd && scene.hmd->ipd) rig->set_ipd(*scene.hmd->ipd);
        if (request.ipd) rig->set_ipd(*request.ipd);
        if (request.width) rig->set_resolution(*request.width, *request.height);
        check_resolution(rig->preset().width, rig->preset().height);
        views = ViewSet::stereo_pair(rig->eye(Eye::Left), rig->eye(Eye::Right));
    } else {
        int w = request.width.value_or(512), h = request.height.value_or(512);
        check_resolution(w, h);
        const SceneCamera& c = *scene.camera;
        views = ViewSet::mono(EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, w, h));
    }

    technique->prepare(scene, settings);
    settings.report_unused();
    if (request.time != 0) technique->update(request.time);
    std::vector<Film> films(views.views.size());
    technique->render(views, films);

    for (size_t i = 0; i < films.size(); ++i) {
        films[i].metadata["scene"] = scene.source.empty() ? scene.name : scene.source;
        films[i].metadata["view"] = views.names[i];
        films[i].metadata["technique"] = technique->name();
        films[i].metadata["config_hash"] = settings.hash();
        films[i].metadata["settings"] = settings.json().dump();
        films[i].metadata["git_revision"] = git_revision();
        films[i].metadata["seed"] = std::to_string(request.seed);
        if (rig) films[i].metadata["hmd"] = rig->preset().name;
    }

    std::string base = request.output;
    if (base.empty()) base = "results/render/" + scene.name + "_" + technique->name() + (rig ? "_stereo" : "");
    fs::path exr = base + ".exr", png = base + ".png";
    if (exr.has_parent_path()) fs::create_directories(exr.parent_path());
    if (films.size() == 2) {
        write_exr_stereo(exr, films[0], films[1]);
        write_png_side_by_side(png, films[0], films[1], request.exposure);
    } else {
        write_exr(exr, films[0]);
        write_png(png, films[0], request.exposure);
    }
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
            << topo.boundary_edges << " boundary edges, " << topo.connected_components << " components\n";
    }
    for (const auto& w : opened.warnings) out << "note         " << w << "\n";
    return out.str();
}

}  // namespace gilab
