// gilab.render: one scene, one technique, a mono camera or an HMD stereo pair — through
// the same steps as `gilab render` (experiments/app/render_command.hpp), so the images are
// bit-identical to the CLI's for the same scene, camera, settings and seed.
#include <memory>
#include <optional>
#include <variant>
#include <filesystem>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "core/util/stats.hpp"
#include "experiments/app/render_command.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"
#include "python/loaded_scene.hpp"
#include "techniques/technique.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

constexpr int kMaxThreads = 1024;  // as the CLI's --threads

struct RenderOutcome {
    std::vector<std::shared_ptr<Film>> films;
    std::vector<std::string> views;  // "mono", or "left", "right"
    std::string technique;
    Stats stats;
    nlohmann::json settings;
    double render_seconds = 0;  // wall time of the render step (scene update + render)
};

// A settings dict as the CLI's --set assignments (key=JSON text), so the settings go
// through the CLI's own reading: the same values, the same precedence of spp and seed.
std::vector<std::string> assignments_from(const py::dict& settings) {
    std::vector<std::string> assignments;
    for (auto [key, value] : settings) {
        if (!py::isinstance<py::str>(key)) throw Error("settings", "keys must be strings, not " + py::repr(key).cast<std::string>());
        const std::string name = key.cast<std::string>();
        if (name.empty() || name.find('=') != std::string::npos)
            throw Error("settings", "'" + name + "' is not a setting name");
        assignments.push_back(name + "=" + python_to_json(value, "settings['" + name + "']").dump());
    }
    return assignments;
}

// An explicit camera replaces the scene's: a gilab.Camera renders mono, a gilab.HmdRig a
// stereo pair from its current pose.
using CameraChoice = std::variant<std::monostate, EyeCamera, HmdRig>;

CameraChoice camera_from(const py::object& camera) {
    if (camera.is_none()) return std::monostate{};
    if (py::isinstance<EyeCamera>(camera)) return camera.cast<EyeCamera>();
    if (py::isinstance<HmdRig>(camera)) return camera.cast<HmdRig>();
    throw Error("camera", "expected None, a gilab.Camera or a gilab.HmdRig, not " + py::repr(camera).cast<std::string>());
}

RenderOutcome render_scene(const LoadedScene& scene, const RenderRequest& request, const CameraChoice& camera,
                           int threads) {
    ThreadLimit limit(threads);
    TechniqueAndRig setup = begin_render(request);
    ViewSet views;
    if (const auto* eye = std::get_if<EyeCamera>(&camera)) {
        views = ViewSet::mono(*eye);
    } else if (const auto* rig = std::get_if<HmdRig>(&camera)) {
        setup.rig = *rig;
        views = ViewSet::stereo_pair(rig->eye(Eye::Left), rig->eye(Eye::Right));
    } else {
        views = aim_views(setup, request, scene.opened.scene);
    }
    prepare_render(setup, request, scene.opened.scene);
    Stopwatch watch;
    std::vector<Film> films = render_films(setup, request, scene.opened.scene, views);
    RenderOutcome outcome;
    outcome.render_seconds = watch.elapsed_ms() / 1000.0;
    for (Film& film : films) outcome.films.push_back(std::make_shared<Film>(std::move(film)));
    outcome.views = views.names;
    outcome.technique = setup.technique->name();
    outcome.stats = setup.technique->stats();
    outcome.settings = setup.settings.json();
    return outcome;
}

std::shared_ptr<Film> film_named(const RenderOutcome& r, const std::string& view) {
    for (size_t i = 0; i < r.views.size(); ++i)
        if (r.views[i] == view) return r.films[i];
    std::string names;
    for (const auto& v : r.views) names += (names.empty() ? "" : ", ") + v;
    throw Error("view", "this render has no view '" + view + "' (it has: " + names + ")");
}

std::shared_ptr<Film> mono_film(const RenderOutcome& r) {
    if (r.films.size() != 1) throw Error("film", "a stereo render has two films: use .left and .right");
    return r.films[0];
}

}  // namespace

// render's help: the arguments, then every technique's settings table, from the
// techniques' schemas (help(gilab.render) shows what `gilab list settings` prints).
const std::string& render_doc() {
    static const std::string doc = [] {
        std::string text = R"doc(Renders a scene with one technique, exactly as ``gilab render`` does.

scene       a gilab.Scene (gilab.load_scene)
technique   "path", "photon", "vct", … (gilab.techniques())
camera      None: the scene camera (mono) or, with `hmd`, the scene's head pose;
            a gilab.Camera: a mono view; a gilab.HmdRig: a stereo pair
hmd         headset preset name for a stereo pair (like --hmd)
width, height   image (per-eye) size; default 512×512 mono, the preset's in stereo
spp         samples per pixel (the setting "spp"; gilab.Error if the technique takes none)
seed        random seed (same seed and settings ⇒ same image)
settings    technique settings as a dict, e.g. {"photons": 16384, "radius": 0.03};
            unknown keys raise gilab.Error
time        scene time in seconds (animated scenes)
ipd, time_budget, settings_file   as --ipd, --time-budget, --settings
threads     worker threads (0 = all cores); images do not depend on it

Returns a gilab.RenderResult. The GIL is released while rendering.
)doc";
        text += "\nTechnique settings (the `settings` dict; gilab.settings(name) gives them as dicts):\n";
        for (const auto& t : TechniqueRegistry::builtin().list()) text.append("\n").append(t.settings_schema().table_text());
        return text;
    }();
    return doc;
}

void register_render_bindings(py::module_& m) {
    py::class_<RenderOutcome>(m, "RenderResult", R"doc(What gilab.render returns: one film per view ("mono", or "left" and "right"),
the technique's statistics and the effective settings.

``result["color"]`` (mono) and ``result.images["left"]["color"]`` are NumPy
float32 views into the films (no copy).
)doc")
        .def_readonly("views", &RenderOutcome::views, "View names: [\"mono\"] or [\"left\", \"right\"].")
        .def_property_readonly("stereo", [](const RenderOutcome& r) { return r.films.size() == 2; })
        .def_readonly("films", &RenderOutcome::films, "One gilab.Film per view.")
        .def_property_readonly("film", &mono_film, "The film of a mono render.")
        .def_property_readonly("left", [](const RenderOutcome& r) { return film_named(r, "left"); })
        .def_property_readonly("right", [](const RenderOutcome& r) { return film_named(r, "right"); })
        .def_property_readonly(
            "images",
            [](const RenderOutcome& r) {
                py::dict images;
                for (size_t i = 0; i < r.films.size(); ++i) images[py::str(r.views[i])] = py::cast(r.films[i]).attr("layers");
                return images;
            },
            "{view: {layer: NumPy view}}.")
        .def("__getitem__", [](const RenderOutcome& r, const std::string& layer) -> py::object {
                 return py::cast(mono_film(r)).attr("layer")(layer);
             },
             "layer"_a, "A layer of a mono render as a NumPy view.")
        .def_readonly("technique", &RenderOutcome::technique)
        .def_property_readonly("stats", [](const RenderOutcome& r) { return stats_to_dict(r.stats); },
                               "The technique's figures (prepare_ms, render_ms, counters, bytes) as a dict.")
        .def_property_readonly("settings", [](const RenderOutcome& r) { return json_to_python(r.settings); },
                               "The effective settings (spp and seed included), as the EXR header records them.")
        .def_readonly("render_seconds", &RenderOutcome::render_seconds,
                      "Wall time of the render step alone (not loading or preparing).")
        .def("__repr__", [](const RenderOutcome& r) {
            const Film& f = *r.films.front();
            return "<gilab.RenderResult " + r.technique + " " + std::to_string(r.films.size()) + " view(s) " +
                   std::to_string(f.width()) + "×" + std::to_string(f.height()) + ">";
        });

    m.def(
        "render",
        [](const LoadedScene& scene, const std::string& technique, const py::object& camera,
           const std::optional<std::string>& hmd, const std::optional<int>& width, const std::optional<int>& height,
           const std::optional<int>& spp, uint64_t seed, const std::optional<py::dict>& settings, double time,
           const std::optional<float>& ipd, const std::optional<double>& time_budget,
           const std::optional<std::filesystem::path>& settings_file, int threads) {
            if (threads < 0 || threads > kMaxThreads)
                throw Error("threads", std::to_string(threads) + " is not a thread count (0 = all cores, or 1 to 1024)");
            RenderRequest request;
            request.scene = scene.spec;
            request.assets = scene.assets;
            request.technique = technique;
            request.hmd = hmd;
            request.width = width;
            request.height = height;
            request.spp = spp;
            request.seed = seed;
            request.time = time;
            request.ipd = ipd;
            request.time_budget = time_budget;
            if (settings_file) request.settings_file = settings_file->string();
            if (settings) request.assignments = assignments_from(*settings);
            const CameraChoice choice = camera_from(camera);
            if (!std::holds_alternative<std::monostate>(choice) && (hmd || width || height || ipd))
                throw Error("camera", "an explicit camera sets the views: leave hmd, width, height and ipd out");
            py::gil_scoped_release release;
            return render_scene(scene, request, choice, threads);
        },
        "scene"_a, "technique"_a = "path", "camera"_a = py::none(), "hmd"_a = py::none(), "width"_a = py::none(),
        "height"_a = py::none(), "spp"_a = py::none(), "seed"_a = 1, "settings"_a = py::none(), "time"_a = 0.0,
        "ipd"_a = py::none(), "time_budget"_a = py::none(), "settings_file"_a = py::none(), "threads"_a = 0,
        render_doc().c_str());
}

}  // namespace gilab::python
