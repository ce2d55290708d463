// gilab.Film: a rendered (or read) image with named float layers, shown to NumPy without
// copying, and the project's EXR/PNG readers and writers.
#include <memory>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include "core/image/film.hpp"
#include "core/image/image_io.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

py::dict layer_dict(const py::object& self) {
    const Film& film = self.cast<const Film&>();
    py::dict layers;
    for (const auto& [name, layer] : film.layers())
        layers[py::str(name)] = layer_view(layer, film.width(), film.height(), self);
    return layers;
}

py::array layer_of(const py::object& self, const std::string& name) {
    const Film& film = self.cast<const Film&>();
    return layer_view(film.layer(name), film.width(), film.height(), self);
}

}  // namespace

void register_film_bindings(py::module_& m) {
    py::class_<Film, std::shared_ptr<Film>>(m, "Film", R"doc(An image of named float layers of equal size, as a technique renders it.

"color" is the beauty image; techniques add "direct", "indirect", "albedo",
"normal" (3 channels), "depth" (1 channel) and more. ``film["color"]`` is a
NumPy float32 view of shape (height, width, 3) — or (height, width) for a
1-channel layer — sharing memory with the film (no copy; the array keeps the
film alive). ``metadata`` holds the provenance written into EXR headers.
)doc")
        .def_property_readonly("width", &Film::width, "Width in pixels.")
        .def_property_readonly("height", &Film::height, "Height in pixels.")
        .def_property_readonly("shape", [](const Film& f) { return py::make_tuple(f.height(), f.width()); },
                               "(height, width).")
        .def_property_readonly(
            "layer_names",
            [](const Film& f) {
                std::vector<std::string> names;
                for (const auto& entry : f.layers()) names.push_back(entry.first);
                return names;
            },
            "Names of the layers, sorted.")
        .def_property_readonly("layers", &layer_dict, "All layers as {name: NumPy view}.")
        .def("layer", &layer_of, "name"_a, "The layer `name` as a NumPy view (gilab.Error if the film has none).")
        .def("__getitem__", &layer_of, "name"_a)
        .def("__contains__", &Film::has_layer, "name"_a)
        .def("__len__", [](const Film& f) { return f.layers().size(); })
        .def("channels", [](const Film& f, const std::string& name) { return f.layer(name).channels; }, "name"_a,
             "Channel count of a layer (1 or 3).")
        .def_readwrite("metadata", &Film::metadata, "Provenance as {key: text} (a copy; assign to change).")
        .def(
            "write_exr", [](const Film& f, const std::filesystem::path& path) { write_exr(path, f); }, "path"_a,
            py::call_guard<py::gil_scoped_release>(),
            "Writes every layer and the metadata as one multi-layer EXR (atomically).")
        .def(
            "write_png",
            [](const Film& f, const std::filesystem::path& path, float exposure, const std::string& layer) {
                write_png(path, f, exposure, layer);
            },
            "path"_a, "exposure"_a = 0.0f, "layer"_a = "color", py::call_guard<py::gil_scoped_release>(),
            "Writes a tone-mapped 8-bit sRGB PNG of one layer (exposure in stops; NaN shows magenta).")
        .def("__repr__", [](const Film& f) {
            std::string names;
            for (const auto& entry : f.layers()) names += (names.empty() ? "" : ", ") + entry.first;
            return "<gilab.Film " + std::to_string(f.width()) + "×" + std::to_string(f.height()) + " [" + names + "]>";
        });

    m.def(
        "read_exr",
        [](const std::filesystem::path& path, const std::string& view) {
            return std::make_shared<Film>(read_exr(path, view));
        },
        "path"_a, "view"_a = "", py::call_guard<py::gil_scoped_release>(), R"doc(Reads an EXR written by gilab (``gilab render`` or Film.write_exr) into a Film.

For a stereo (multi-view) file, ``view`` is "left" or "right"; "" reads the
default view. Layers and string metadata come back as written.
)doc");
    m.def(
        "write_png_side_by_side",
        [](const std::filesystem::path& path, const Film& left, const Film& right, float exposure) {
            write_png_side_by_side(path, left, right, exposure);
        },
        "path"_a, "left"_a, "right"_a, "exposure"_a = 0.0f, py::call_guard<py::gil_scoped_release>(),
        "Writes the colour layers of a stereo pair side by side into one PNG, as ``gilab render --hmd`` does.");
}

}  // namespace gilab::python
