#include "python/array_helpers.hpp"

#include <cstring>
#include <limits>
#include "core/util/error.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

std::string shape_text(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtype_text(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

// An ndarray as given, or a list/tuple turned into one with numpy's default dtype for
// its contents (so [[0, 1, 2]] becomes int64 and [[0.5, 1, 2]] float64).
py::array as_array(const py::handle& value, const std::string& what) {
    if (py::isinstance<py::array>(value)) return py::reinterpret_borrow<py::array>(value);
    try {
        return py::module_::import("numpy").attr("asarray")(value);
    } catch (py::error_already_set& e) {
        throw Error(what, std::string("is not an array: ") + e.what());
    }
}

// Real floating point only: an integer, boolean or complex array is a mistake worth
// reporting rather than silently converting.
py::array float_array(const py::handle& value, const std::string& what) {
    py::array a = as_array(value, what);
    const char kind = a.dtype().kind();
    if (kind == 'i' || kind == 'u') {
        // Plain Python lists of whole numbers are fine as coordinates; integer ndarrays are not.
        if (!py::isinstance<py::array>(value)) return a.attr("astype")("float64");
    }
    if (kind != 'f' || (a.itemsize() != 4 && a.itemsize() != 8))
        throw Error(what, "has dtype " + dtype_text(a) + "; expected float32 or float64");
    return a;
}

}  // namespace

std::vector<Vec3> points_from_array(const py::handle& array, const std::string& what) {
    py::array a = float_array(array, what);
    if (a.ndim() != 2 || a.shape(1) != 3) throw Error(what, "has shape " + shape_text(a) + "; expected (n, 3)");
    auto values = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
    std::vector<Vec3> points(size_t(a.shape(0)));
    if (!points.empty()) std::memcpy(points.data(), values.data(), points.size() * sizeof(Vec3));
    return points;
}

Vec3 vec3_from(const py::handle& value, const std::string& what) {
    py::array a = float_array(value, what);
    if (a.ndim() != 1 || a.shape(0) != 3) throw Error(what, "has shape " + shape_text(a) + "; expected 3 numbers");
    auto v = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
    return Vec3(float(v.at(0)), float(v.at(1)), float(v.at(2)));
}

Quat quat_from(const py::handle& value, const std::string& what) {
    py::array a = float_array(value, what);
    if (a.ndim() != 1 || a.shape(0) != 4)
        throw Error(what, "has shape " + shape_text(a) + "; expected a quaternion (w, x, y, z)");
    auto v = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
    Quat q(float(v.at(0)), float(v.at(1)), float(v.at(2)), float(v.at(3)));
    float length = glm::length(q);
    if (!std::isfinite(length) || length < 1e-6f) throw Error(what, "is not a rotation (zero or non-finite quaternion)");
    return q / length;
}

std::vector<UVec3> triangles_from_array(const py::handle& array, const std::string& what) {
    py::array a = as_array(array, what);
    const char kind = a.dtype().kind();
    if (kind != 'i' && kind != 'u') throw Error(what, "has dtype " + dtype_text(a) + "; expected an integer array");
    if (a.ndim() != 2 || a.shape(1) != 3) throw Error(what, "has shape " + shape_text(a) + "; expected (m, 3)");
    auto values = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    std::vector<UVec3> triangles(size_t(a.shape(0)));
    const int64_t* v = values.data();
    for (size_t i = 0; i < triangles.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            int64_t index = v[3 * i + size_t(k)];
            if (index < 0 || index > int64_t(std::numeric_limits<uint32_t>::max()))
                throw Error(what, "triangle " + std::to_string(i) + " has vertex index " + std::to_string(index));
            triangles[i][k] = uint32_t(index);
        }
    }
    return triangles;
}

Film film_from_image(const py::handle& image, const std::string& what, const std::string& layer) {
    py::array a = float_array(image, what);
    const bool grey = a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) == 1);
    if (!grey && !(a.ndim() == 3 && a.shape(2) == 3))
        throw Error(what, "has shape " + shape_text(a) + "; expected an image (H, W), (H, W, 1) or (H, W, 3)");
    if (a.shape(0) == 0 || a.shape(1) == 0) throw Error(what, "is an empty image " + shape_text(a));
    if (a.shape(0) > std::numeric_limits<int>::max() || a.shape(1) > std::numeric_limits<int>::max())
        throw Error(what, "is too large " + shape_text(a));
    Film film(int(a.shape(1)), int(a.shape(0)));
    Layer& target = film.add_layer(layer, grey ? 1 : 3);
    auto values = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
    std::memcpy(target.data.data(), values.data(), target.data.size() * sizeof(float));
    return film;
}

py::array layer_view(const Layer& layer, int width, int height, const py::handle& owner) {
    std::vector<py::ssize_t> shape{height, width};
    if (layer.channels != 1) shape.push_back(layer.channels);
    // The layer's vector lives as long as its film, which `owner` holds.
    return py::array_t<float>(shape, layer.data.data(), owner);
}

py::tuple to_tuple(const Vec3& v) { return py::make_tuple(v.x, v.y, v.z); }
py::tuple to_tuple(const UVec3& v) { return py::make_tuple(v.x, v.y, v.z); }
py::tuple to_tuple(const Quat& q) { return py::make_tuple(q.w, q.x, q.y, q.z); }

py::array_t<float> matrix_to_numpy(const Mat4& m) {
    py::array_t<float> out({4, 4});
    auto r = out.mutable_unchecked<2>();
    for (int row = 0; row < 4; ++row)
        for (int column = 0; column < 4; ++column) r(row, column) = m[column][row];
    return out;
}

py::object json_to_python(const nlohmann::json& value) {
    using Type = nlohmann::json::value_t;
    switch (value.type()) {
        case Type::null:
        case Type::discarded: return py::none();
        case Type::boolean: return py::bool_(value.get<bool>());
        case Type::number_integer: return py::int_(value.get<int64_t>());
        case Type::number_unsigned: return py::int_(value.get<uint64_t>());
        case Type::number_float: return py::float_(value.get<double>());
        case Type::string: return py::str(value.get_ref<const std::string&>());
        case Type::binary: {
            const auto& bytes = value.get_binary();
            return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
        }
        case Type::array: {
            py::list list;
            for (const auto& item : value) list.append(json_to_python(item));
            return list;
        }
        case Type::object: {
            py::dict dict;
            for (auto it = value.begin(); it != value.end(); ++it) dict[py::str(it.key())] = json_to_python(it.value());
            return dict;
        }
    }
    return py::none();
}

nlohmann::json python_to_json(const py::handle& value, const std::string& what) {
    if (value.is_none()) return nullptr;
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
    if (py::isinstance<py::int_>(value)) {
        // Python ints are unbounded; JSON settings hold 64-bit integers.
        try {
            return value.cast<int64_t>();
        } catch (const py::cast_error&) {
        }
        try {
            return value.cast<uint64_t>();
        } catch (const py::cast_error&) {
            throw Error(what, py::repr(value).cast<std::string>() + " does not fit a 64-bit integer");
        }
    }
    if (py::isinstance<py::float_>(value)) return value.cast<double>();
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    // NumPy scalars (np.float32(0.1), np.int64(3)) as their Python value.
    if (py::isinstance(value, py::module_::import("numpy").attr("generic")))
        return python_to_json(value.attr("item")(), what);
    if (py::isinstance<py::dict>(value)) {
        nlohmann::json object = nlohmann::json::object();
        for (auto [key, item] : py::reinterpret_borrow<py::dict>(value)) {
            if (!py::isinstance<py::str>(key)) throw Error(what, "keys must be strings, not " + py::repr(key).cast<std::string>());
            const std::string name = key.cast<std::string>();
            object[name] = python_to_json(item, what + "['" + name + "']");
        }
        return object;
    }
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
        nlohmann::json array = nlohmann::json::array();
        for (auto item : value) array.push_back(python_to_json(item, what));
        return array;
    }
    throw Error(what, "cannot hold " + py::repr(value).cast<std::string>() +
                          " (give None, bool, int, float, str, lists or dicts of them)");
}

py::dict stats_to_dict(const Stats& stats) {
    py::dict dict;
    for (const auto& [key, value] : stats.values()) dict[py::str(key)] = value;
    return dict;
}

}  // namespace gilab::python
