// gilab.PhotonMap: a photon-map structure (hash grid, kd-tree or nanoflann) built from
// photon positions, with radius and k-nearest-neighbour queries that return indices
// into the array it was built from.
#include <algorithm>
#include <memory>
#include <pybind11/stl.h>
#include "accel/photon/photon_map.hpp"
#include "core/util/error.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

struct PythonPhotonMap {
    std::unique_ptr<PhotonMap> map;
    PhotonQueryStats stats;  // summed over every query made through Python
};

std::vector<Photon> photons_from(const py::object& positions, const py::object& powers) {
    std::vector<Vec3> p = points_from_array(positions, "positions");
    std::vector<Vec3> power;
    if (!powers.is_none()) {
        power = points_from_array(powers, "powers");
        if (power.size() != p.size())
            throw Error("powers", std::to_string(power.size()) + " rows for " + std::to_string(p.size()) + " positions");
    }
    std::vector<Photon> photons(p.size());
    for (size_t i = 0; i < p.size(); ++i) {
        photons[i].position = p[i];
        photons[i].power = power.empty() ? Vec3(1.0f) : power[i];
    }
    return photons;
}

float radius_from(float r, const char* what) {
    if (!std::isfinite(r) || !(r > 0)) throw Error(what, std::to_string(r) + " is not a positive finite radius");
    return r;
}

// Indices into the build input: photons within r of x, ascending (the structures visit
// them in their own storage order).
std::vector<uint32_t> in_radius(const PythonPhotonMap& pm, const Vec3& x, float r, PhotonQueryStats& stats) {
    std::vector<uint32_t> found;
    pm.map->radius_query(x, r, [&](uint32_t index, float) { found.push_back(pm.map->original_index(index)); }, stats);
    std::sort(found.begin(), found.end());
    return found;
}

// The k nearest within max_r, nearest first (ties by index), with squared distances.
std::pair<std::vector<uint32_t>, std::vector<float>> nearest(const PythonPhotonMap& pm, const Vec3& x, size_t k,
                                                             float max_r, PhotonQueryStats& stats) {
    NeighborHeap heap(k);
    pm.map->knn_query(x, k, max_r, heap, stats);
    std::vector<std::pair<float, uint32_t>> items;
    for (const PhotonNeighbor& n : heap.items()) items.emplace_back(n.distance2, pm.map->original_index(n.index));
    std::sort(items.begin(), items.end());
    std::pair<std::vector<uint32_t>, std::vector<float>> out;
    for (const auto& [d2, index] : items) {
        out.first.push_back(index);
        out.second.push_back(d2);
    }
    return out;
}

bool is_single_point(const py::object& points) {
    return py::module_::import("numpy").attr("ndim")(points).cast<int>() == 1;
}

py::array_t<uint32_t> index_array(std::vector<uint32_t>&& v) {
    const auto n = py::ssize_t(v.size());
    return to_numpy(std::move(v), {n});
}

}  // namespace

void register_photon_map_bindings(py::module_& m) {
    py::class_<PythonPhotonMap>(m, "PhotonMap", R"doc(A photon map built from photon positions, (n, 3) float32/float64.

kind     "hash_grid" (P1's uniform grid, cell edge = radius), "kd_tree" or "nanoflann"
radius   the gather radius the structure is tuned for (the hash grid's cell)
powers   optional (n, 3) photon powers (default 1)

Queries return indices into the `positions` array. "Within r" is exact and the
same for every kind: a radius query returns the same indices from each.
)doc")
        .def(py::init([](const py::object& positions, float radius, const std::string& kind, const py::object& powers) {
                 auto pm = std::make_unique<PythonPhotonMap>();
                 radius_from(radius, "radius");
                 pm->map = make_photon_map(parse_photon_map_kind(kind, "kind"));
                 std::vector<Photon> photons = photons_from(positions, powers);
                 py::gil_scoped_release release;
                 pm->map->build(std::move(photons), radius);
                 return pm;
             }),
             "positions"_a, "radius"_a = 0.05f, "kind"_a = "hash_grid", "powers"_a = py::none())
        .def_property_readonly("kind", [](const PythonPhotonMap& pm) { return pm.map->name(); })
        .def_property_readonly("radius", [](const PythonPhotonMap& pm) { return pm.map->radius(); })
        .def("__len__", [](const PythonPhotonMap& pm) { return pm.map->size(); })
        .def_property_readonly("memory_bytes", [](const PythonPhotonMap& pm) { return pm.map->memory_bytes(); })
        .def(
            "radius_query",
            [](PythonPhotonMap& pm, const py::object& points, float r) -> py::object {
                radius_from(r, "r");
                if (is_single_point(points)) return index_array(in_radius(pm, vec3_from(points, "point"), r, pm.stats));
                std::vector<Vec3> queries = points_from_array(points, "points");
                std::vector<std::vector<uint32_t>> results(queries.size());
                PhotonQueryStats stats;  // merged once the GIL is back: another thread may query too
                {
                    py::gil_scoped_release release;
                    for (size_t i = 0; i < queries.size(); ++i) results[i] = in_radius(pm, queries[i], r, stats);
                }
                pm.stats.merge(stats);
                py::list list;
                for (auto& found : results) list.append(index_array(std::move(found)));
                return list;
            },
            "points"_a, "r"_a, R"doc(Indices (uint32, ascending) of the photons within distance r of a point; for
an (m, 3) array of points, a list of m such arrays.
)doc")
        .def(
            "knn",
            [](PythonPhotonMap& pm, const py::object& point, int64_t k, float max_radius, bool return_distances) -> py::object {
                if (k < 0) throw Error("k", "must not be negative");
                if (!(max_radius > 0)) throw Error("max_radius", "must be positive");
                auto [indices, distance2] = nearest(pm, vec3_from(point, "point"), size_t(k), max_radius, pm.stats);
                const auto n = py::ssize_t(indices.size());
                py::array_t<uint32_t> idx = to_numpy(std::move(indices), {n});
                if (!return_distances) return idx;
                return py::make_tuple(idx, to_numpy(std::move(distance2), {n}));
            },
            "point"_a, "k"_a, "max_radius"_a = kInfinity, "return_distances"_a = false, R"doc(Indices (uint32) of the k nearest photons within max_radius, nearest first
(ties by index). With return_distances, (indices, squared distances float32).
)doc")
        .def_property_readonly(
            "query_stats",
            [](const PythonPhotonMap& pm) {
                return py::dict("queries"_a = pm.stats.queries, "visited"_a = pm.stats.visited, "inside"_a = pm.stats.inside);
            },
            "Work of every query so far: queries, photons visited (distance computed), inside the radius.")
        .def("__repr__", [](const PythonPhotonMap& pm) {
            return "<gilab.PhotonMap " + pm.map->name() + " " + std::to_string(pm.map->size()) + " photons>";
        });
}

}  // namespace gilab::python
