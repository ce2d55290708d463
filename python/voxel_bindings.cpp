// Voxel grids and the conservative voxelizer every sparse structure is built from:
// gilab.VoxelGrid, gilab.voxelize (a scene or a mesh given as arrays), gilab.VoxelList.
#include <memory>
#include <optional>
#include <pybind11/stl.h>
#include "core/util/error.hpp"
#include "core/util/morton.hpp"
#include "core/scene/scene.hpp"
#include "core/voxel/voxel_grid.hpp"
#include "core/voxel/voxelizer.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"
#include "python/loaded_scene.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

uint32_t resolution_from(int64_t resolution) {
    if (resolution < 1 || resolution > int64_t(kMaxVoxelResolution))
        throw Error("resolution", std::to_string(resolution) + " is out of range: give 1 to 2097152 voxels per axis");
    return uint32_t(resolution);
}

py::array_t<uint32_t> codes_to_voxels(const uint64_t* codes, size_t count) {
    std::vector<uint32_t> xyz(count * 3);
    for (size_t i = 0; i < count; ++i) {
        UVec3 v = morton_decode(codes[i]);
        xyz[3 * i] = v.x, xyz[3 * i + 1] = v.y, xyz[3 * i + 2] = v.z;
    }
    return to_numpy(std::move(xyz), {py::ssize_t(count), 3});
}

VoxelGrid grid_or_enclosing(const std::optional<VoxelGrid>& grid, const Bounds3& bounds, uint32_t resolution) {
    if (!grid) return VoxelGrid::enclosing(bounds, resolution);
    VoxelGrid g = *grid;
    g.resolution = resolution;
    g.validate("grid");
    return g;
}

}  // namespace

void register_voxel_bindings(py::module_& m) {
    py::class_<VoxelGrid>(m, "VoxelGrid", R"doc(A cubic voxel grid: a world-space cube (min corner `origin`, side `extent`) cut
into resolution³ voxels. Octrees over it have depth ceil(log2 resolution).
)doc")
        .def(py::init([](const py::object& origin, float extent, int64_t resolution) {
                 VoxelGrid g{vec3_from(origin, "origin"), extent, resolution_from(resolution)};
                 g.validate("VoxelGrid");
                 return g;
             }),
             "origin"_a, "extent"_a, "resolution"_a)
        .def_static(
            "enclosing",
            [](const py::object& lo, const py::object& hi, int64_t resolution, double margin) {
                Bounds3 b;
                b.extend(vec3_from(lo, "min"));
                b.extend(vec3_from(hi, "max"));
                return VoxelGrid::enclosing(b, resolution_from(resolution), margin);
            },
            "min"_a, "max"_a, "resolution"_a, "margin"_a = 1e-3,
            "The smallest cube holding the box, grown by `margin` (a fraction of its side).")
        .def_property_readonly("origin", [](const VoxelGrid& g) { return to_tuple(g.origin); })
        .def_readonly("extent", &VoxelGrid::extent)
        .def_readonly("resolution", &VoxelGrid::resolution)
        .def_property_readonly("depth", &VoxelGrid::depth, "ceil(log2 resolution).")
        .def_property_readonly("voxel_size", &VoxelGrid::voxel_size)
        .def(
            "voxel_of",
            [](const VoxelGrid& g, const py::object& point) -> py::object {
                auto v = g.voxel_of(vec3_from(point, "point"));
                return v ? py::object(to_tuple(*v)) : py::none();
            },
            "point"_a, "The voxel (x, y, z) holding a world point, or None outside the grid.")
        .def("__repr__", [](const VoxelGrid& g) {
            return "<gilab.VoxelGrid " + std::to_string(g.resolution) + "³ extent " + std::to_string(g.extent) + ">";
        });

    py::class_<VoxelList, std::shared_ptr<VoxelList>>(m, "VoxelList", R"doc(The occupied voxels of a voxelization: Morton codes ascending and unique
(``codes``, uint64) or coordinates (``voxels()``, (n, 3) uint32).
)doc")
        .def_readonly("grid", &VoxelList::grid)
        .def("__len__", &VoxelList::size)
        .def_property_readonly(
            "codes",
            [](const py::object& self) {
                const VoxelList& v = self.cast<const VoxelList&>();
                return py::array_t<uint64_t>(py::ssize_t(v.codes.size()), v.codes.data(), self);
            },
            "Morton codes (a view, no copy).")
        .def("voxels", [](const VoxelList& v) { return codes_to_voxels(v.codes.data(), v.codes.size()); },
             "Voxel coordinates, (n, 3) uint32, in Morton order.")
        .def_property_readonly(
            "stats",
            [](const VoxelList& v) {
                const VoxelizeStats& s = v.stats;
                return py::dict("ms"_a = s.ms, "estimated_voxels"_a = s.estimated_voxels, "triangles"_a = s.triangles,
                                "bricks"_a = s.bricks, "box_tests"_a = s.box_tests);
            },
            "Voxelizer figures: ms, estimated_voxels, triangles, bricks, box_tests.");

    m.def(
        "voxelize",
        [](const LoadedScene& scene, int64_t resolution, double time, const std::optional<VoxelGrid>& grid) {
            const uint32_t n = resolution_from(resolution);
            if (!std::isfinite(time)) throw Error("time", "must be a finite number of seconds");
            py::gil_scoped_release release;
            SceneFrame frame = scene.opened.scene.evaluate(time);
            return std::make_shared<VoxelList>(voxelize(frame, grid_or_enclosing(grid, frame.bounds, n)));
        },
        "scene"_a, "resolution"_a, "time"_a = 0.0, "grid"_a = py::none(), R"doc(Conservatively voxelizes a scene at `time` into resolution³ voxels (a voxel is
occupied when its closed box touches a triangle). The grid encloses the scene's
bounds unless `grid` (a gilab.VoxelGrid, whose resolution is replaced) is given.
The GIL is released while it runs.
)doc");
    m.def(
        "voxelize",
        [](const py::object& positions, const py::object& triangles, int64_t resolution,
           const std::optional<VoxelGrid>& grid) {
            const uint32_t n = resolution_from(resolution);
            std::vector<Vec3> p = points_from_array(positions, "positions");
            std::vector<UVec3> t = triangles_from_array(triangles, "triangles");
            Bounds3 bounds;
            for (const Vec3& v : p) bounds.extend(v);
            VoxelGrid g = grid_or_enclosing(grid, bounds, n);
            py::gil_scoped_release release;
            return std::make_shared<VoxelList>(voxelize(p, t, g));
        },
        "positions"_a, "triangles"_a, "resolution"_a, "grid"_a = py::none(), R"doc(Voxelizes a triangle mesh given as arrays: positions (n, 3) float32/float64 and
triangles (m, 3) integer vertex indices.
)doc");
}

}  // namespace gilab::python
