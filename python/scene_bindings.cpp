// gilab.load_scene and gilab.Scene / gilab.SceneFrame: scenes opened exactly as
// `gilab render` and `gilab info` open them.
#include <filesystem>
#include <memory>
#include <pybind11/stl.h>
#include "core/util/error.hpp"
#include "core/scene/mesh_topology.hpp"
#include "experiments/app/render_command.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"
#include "python/loaded_scene.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

// The `assets` argument: None, one path (colon-separated list allowed) or a list of
// paths. Like --assets, every directory named must exist: a typo is an error, not a
// silent fall-back to other copies of the files.
AssetPaths asset_paths_from(const py::object& assets) {
    if (assets.is_none()) return AssetPaths::from_environment();
    std::string list;
    if (py::isinstance<py::str>(assets) || py::hasattr(assets, "__fspath__")) {
        list = py::str(py::module_::import("os").attr("fspath")(assets)).cast<std::string>();
    } else {
        for (auto item : assets) {
            if (!list.empty()) list += ":";
            list += py::str(py::module_::import("os").attr("fspath")(item)).cast<std::string>();
        }
    }
    AssetPaths::require_directories(list, "assets");
    return AssetPaths::from_environment(list);
}

py::tuple bounds_tuple(const Bounds3& b) { return py::make_tuple(to_tuple(b.min), to_tuple(b.max)); }

const Scene& scene_of(const LoadedScene& s) { return s.opened.scene; }

py::list mesh_arrays(const py::object& self) {
    const SceneFrame& frame = self.cast<const SceneFrame&>();
    py::list meshes;
    for (const WorldMesh& mesh : frame.meshes) {
        // Views into the frame (which `self` keeps alive): Vec3/UVec3 are packed triples.
        auto view3 = [&](const auto* data, size_t count, auto tag) {
            using T = decltype(tag);
            return py::array_t<T>({py::ssize_t(count), py::ssize_t(3)}, reinterpret_cast<const T*>(data), self);
        };
        py::dict d("node"_a = mesh.node, "source_mesh"_a = mesh.source_mesh,
                   "positions"_a = view3(mesh.positions.data(), mesh.positions.size(), float{}),
                   "normals"_a = view3(mesh.normals.data(), mesh.normals.size(), float{}),
                   "triangles"_a = view3(mesh.triangles.data(), mesh.triangles.size(), uint32_t{}),
                   "material_ids"_a = py::array_t<uint32_t>(py::ssize_t(mesh.material_ids.size()),
                                                            mesh.material_ids.data(), self));
        meshes.append(d);
    }
    return meshes;
}

// All meshes of a frame as one vertex array and one triangle array (a copy).
py::tuple merged_mesh(const SceneFrame& frame) {
    std::vector<float> positions;
    std::vector<uint32_t> triangles;
    for (const WorldMesh& mesh : frame.meshes) {
        const uint32_t base = uint32_t(positions.size() / 3);
        for (const Vec3& p : mesh.positions) positions.insert(positions.end(), {p.x, p.y, p.z});
        for (const UVec3& t : mesh.triangles) triangles.insert(triangles.end(), {base + t.x, base + t.y, base + t.z});
    }
    const auto vertices = py::ssize_t(positions.size() / 3), faces = py::ssize_t(triangles.size() / 3);
    return py::make_tuple(to_numpy(std::move(positions), {vertices, 3}), to_numpy(std::move(triangles), {faces, 3}));
}

py::list closed_mesh_report(const LoadedScene& loaded) {
    const Scene& scene = scene_of(loaded);
    std::vector<MeshTopology> topologies;
    {
        py::gil_scoped_release release;
        for (const Mesh& mesh : scene.meshes) topologies.push_back(analyze_topology(mesh));
    }
    py::list report;
    for (size_t i = 0; i < scene.meshes.size(); ++i) {
        const MeshTopology& t = topologies[i];
        report.append(py::dict("index"_a = i, "name"_a = scene.meshes[i].name,
                               "triangles"_a = scene.meshes[i].triangles.size(), "closed"_a = t.closed,
                               "boundary_edges"_a = t.boundary_edges, "components"_a = t.connected_components,
                               "closed_components"_a = t.closed_components));
    }
    return report;
}

}  // namespace

void register_scene_bindings(py::module_& m) {
    py::class_<SceneFrame, std::shared_ptr<SceneFrame>>(m, "SceneFrame", R"doc(The scene flattened into world space at one time: what the ray tracer and the
voxelizer see. ``meshes`` gives NumPy views (positions (n, 3) float32,
triangles (m, 3) uint32, …) into the frame without copying.
)doc")
        .def_readonly("time", &SceneFrame::time)
        .def_property_readonly("triangle_count", &SceneFrame::triangle_count)
        .def_property_readonly("light_count", [](const SceneFrame& f) { return f.lights.size(); },
                               "Punctual lights (emissive triangles are part of the meshes).")
        .def_property_readonly("bounds", [](const SceneFrame& f) { return bounds_tuple(f.bounds); },
                               "((min x, y, z), (max x, y, z)).")
        .def_property_readonly("meshes", &mesh_arrays,
                               "Per world mesh: node, source_mesh, positions, normals, triangles, material_ids.")
        .def("merged", &merged_mesh,
             "(positions (n, 3) float32, triangles (m, 3) uint32) of all meshes together, as one copy.")
        .def("__repr__", [](const SceneFrame& f) {
            return "<gilab.SceneFrame t=" + std::to_string(f.time) + " triangles=" + std::to_string(f.triangle_count()) + ">";
        });

    py::class_<LoadedScene, std::shared_ptr<LoadedScene>>(m, "Scene", R"doc(A scene opened as ``gilab render`` opens it (see gilab.load_scene): meshes,
materials, lights, keyframed animation, and a camera (one framing the bounds
when the scene gave none).
)doc")
        .def_property_readonly("name", [](const LoadedScene& s) { return scene_of(s).name; })
        .def_property_readonly("source", [](const LoadedScene& s) { return scene_of(s).source; },
                               "The file it came from, or \"builtin:NAME\".")
        .def_readonly("spec", &LoadedScene::spec, "What load_scene was given.")
        .def_property_readonly("triangle_count", [](const LoadedScene& s) { return scene_of(s).triangle_count(); },
                               "Triangles over all mesh instances.")
        .def_property_readonly("mesh_count", [](const LoadedScene& s) { return scene_of(s).meshes.size(); })
        .def_property_readonly("node_count", [](const LoadedScene& s) { return scene_of(s).nodes.size(); })
        .def_property_readonly("material_count", [](const LoadedScene& s) { return scene_of(s).materials.size(); })
        .def_property_readonly(
            "emissive_material_count",
            [](const LoadedScene& s) {
                size_t n = 0;
                for (const auto& material : scene_of(s).materials) n += material.is_emissive();
                return n;
            },
            "Materials that emit light (area lights are emissive triangles).")
        .def_property_readonly("light_count", [](const LoadedScene& s) { return scene_of(s).lights.size(); },
                               "Punctual lights (point, spot, directional).")
        .def_property_readonly(
            "lights",
            [](const LoadedScene& s) {
                py::list lights;
                for (const auto& l : scene_of(s).lights) lights.append(py::dict("type"_a = to_string(l.type), "name"_a = l.name));
                return lights;
            },
            "Punctual lights as dicts (type, name).")
        .def_property_readonly("bounds", [](const LoadedScene& s) { return bounds_tuple(scene_of(s).evaluate(0).bounds); },
                               "World bounds at t = 0: ((min x, y, z), (max x, y, z)).")
        .def_property_readonly("is_animated", [](const LoadedScene& s) { return scene_of(s).is_animated(); })
        .def_property_readonly("animation_duration", [](const LoadedScene& s) { return scene_of(s).animation_duration(); },
                               "Seconds (0 for a static scene).")
        .def_property_readonly("frame_count", [](const LoadedScene& s) { return scene_of(s).animation_frame_count(); })
        .def_property_readonly("frames_per_second", [](const LoadedScene& s) { return scene_of(s).frames_per_second; })
        .def_property_readonly("degenerate_triangles_dropped",
                               [](const LoadedScene& s) { return scene_of(s).degenerate_triangles_dropped; })
        .def_property_readonly("warnings", [](const LoadedScene& s) { return s.opened.warnings; },
                               "Notes from loading (unsupported features, the default camera or sun).")
        .def_property_readonly("has_default_camera", [](const LoadedScene& s) { return s.opened.default_camera; },
                               "True when the scene had no camera and one framing its bounds was chosen.")
        .def_property_readonly(
            "camera",
            [](const LoadedScene& s) {
                const SceneCamera& c = *scene_of(s).camera;
                return py::dict("position"_a = to_tuple(c.position), "target"_a = to_tuple(c.target),
                                "up"_a = to_tuple(c.up), "vertical_fov"_a = c.vertical_fov_degrees);
            },
            "The scene camera as a dict (position, target, up, vertical_fov in degrees).")
        .def(
            "camera_view",
            [](const LoadedScene& s, int width, int height) {
                check_resolution(width, height);
                const SceneCamera& c = *scene_of(s).camera;
                return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, width, height);
            },
            "width"_a = 512, "height"_a = 512, "The scene camera as a gilab.Camera of the given size.")
        .def_property_readonly(
            "hmd",
            [](const LoadedScene& s) -> py::object {
                const Scene& scene = scene_of(s);
                if (!scene.hmd) return py::none();
                return py::dict("preset"_a = scene.hmd->preset, "pose"_a = scene.hmd->pose,
                                "ipd"_a = scene.hmd->ipd ? py::cast(*scene.hmd->ipd) : py::none());
            },
            "The scene's HMD rig (preset, pose, ipd) or None.")
        .def(
            "head_pose",
            [](const LoadedScene& s) {
                const Scene& scene = scene_of(s);
                return scene.hmd ? scene.hmd->pose : pose_from_camera(*scene.camera);
            },
            "The head pose `gilab render --hmd` starts from: the scene's HMD pose, else its camera's.")
        .def(
            "evaluate",
            [](const LoadedScene& s, double time) {
                if (!std::isfinite(time)) throw Error("time", "must be a finite number of seconds");
                py::gil_scoped_release release;
                return std::make_shared<SceneFrame>(scene_of(s).evaluate(time));
            },
            "time"_a = 0.0, "The world-space geometry and lights at `time` seconds, as a gilab.SceneFrame.")
        .def("closed_meshes", &closed_mesh_report, R"doc(The closed-mesh report of ``gilab info``: per mesh its name, triangle count,
whether it is closed (a watertight 2-manifold, checked with CGAL), boundary
edges, connected components and how many of them are closed.
)doc")
        .def(
            "describe",
            [](const LoadedScene& s) {
                py::gil_scoped_release release;
                return describe_scene(s.spec, s.assets);
            },
            "The text `gilab info` prints for this scene.")
        .def("__repr__", [](const LoadedScene& s) {
            return "<gilab.Scene " + scene_of(s).name + ": " + std::to_string(scene_of(s).triangle_count()) + " triangles>";
        });

    m.def(
        "load_scene",
        [](const py::object& path_or_name, const py::object& assets) {
            auto loaded = std::make_shared<LoadedScene>();
            loaded->spec = py::str(py::isinstance<py::str>(path_or_name)
                                       ? path_or_name
                                       : py::module_::import("os").attr("fspath")(path_or_name))
                               .cast<std::string>();
            loaded->assets = asset_paths_from(assets);
            py::gil_scoped_release release;
            loaded->opened = open_scene(loaded->spec, loaded->assets);
            return loaded;
        },
        "path_or_name"_a, "assets"_a = py::none(), R"doc(Opens a scene the way ``gilab render`` does: a built-in name ("cornell",
"furnace", "villa", "fbm_terrain", "fire"), the name of a scene file in
scenes/ ("bunny"), or a path to a .json/.obj/.gltf/.glb/.ply/.off file.

Mesh files are looked up in `assets` (a directory, a colon-separated list or a
list of directories; each must exist), then $GILAB_ASSETS, then
../shared/scenes beside the source tree. Bad paths and malformed files raise
gilab.Error with the loader's message (file, line or field, and what is wrong).
)doc");
}

}  // namespace gilab::python
