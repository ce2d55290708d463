#pragma once
// Conversions between NumPy arrays / Python values and the C++ containers the bindings
// hand on. Every check throws gilab::Error naming the argument, so a wrong shape or
// dtype reaches Python as gilab.Error with a message that says what was expected.
#include <memory>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include "core/image/film.hpp"
#include "core/util/math.hpp"
#include "core/util/stats.hpp"

namespace gilab::python {

namespace py = pybind11;

// A float32/float64 array of shape (n, 3) as points. `what` names the argument in errors.
std::vector<Vec3> points_from_array(const py::handle& array, const std::string& what);
// One point: any sequence or array of 3 real numbers.
Vec3 vec3_from(const py::handle& value, const std::string& what);
// An integer array of shape (m, 3) with non-negative entries (vertex indices).
std::vector<UVec3> triangles_from_array(const py::handle& array, const std::string& what);
// A float32/float64 image of shape (H, W), (H, W, 1) or (H, W, 3) as the layer `layer` of
// a new film (1 or 3 channels).
Film film_from_image(const py::handle& image, const std::string& what, const std::string& layer);

// A NumPy view of a film layer, (H, W, 3) or (H, W) for a 1-channel layer. No copy: the
// array keeps `owner` (the Python object holding the film) alive.
py::array layer_view(const Layer& layer, int width, int height, const py::handle& owner);

// A NumPy array that takes over `values` (no copy); `shape` must match its size.
template <typename T>
py::array_t<T> to_numpy(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
    auto* owned = new std::vector<T>(std::move(values));
    py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    return py::array_t<T>(shape, owned->data(), free_when_done);
}

py::tuple to_tuple(const Vec3& v);
py::tuple to_tuple(const UVec3& v);
py::tuple to_tuple(const Quat& q);  // (w, x, y, z)
// A unit quaternion from (w, x, y, z).
Quat quat_from(const py::handle& value, const std::string& what);
// A 4×4 matrix as a NumPy array indexed [row, column] (GLM stores columns).
py::array_t<float> matrix_to_numpy(const Mat4& m);

py::object json_to_python(const nlohmann::json& value);
// Plain Python values (None, bool, int, float, str, lists/tuples, dicts with str keys).
nlohmann::json python_to_json(const py::handle& value, const std::string& what);
py::dict stats_to_dict(const Stats& stats);

}  // namespace gilab::python
