// The shadow DAG over a light's light space (P2 §3) on its own: gilab.ShadowDag, built
// from a scene and one of its lights (plain depth map S2, or double depth maps S3 that
// fold closed objects' interiors away), or from depth maps given as arrays; with its node
// counts per level, bytes, and per-voxel, light-space and world-space shadow queries.
#include <cmath>
#include <optional>
#include <pybind11/stl.h>
#include "accel/shadow/shadow_dag.hpp"
#include "core/util/error.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/scene/scene.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"
#include "python/loaded_scene.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

// The DAG plus the light it was built for (None when built from depth maps).
struct PyShadowDag {
    ShadowDag dag;
    std::optional<PunctualLight> light;
    double time = 0;
};

ShadowState undefined_as_from(const std::string& s) {
    if (s == "lit") return ShadowState::Lit;
    if (s == "shadow") return ShadowState::Shadow;
    throw Error("undefined_as", "'" + s + "' is not a choice: give \"lit\" or \"shadow\"");
}

uint32_t unsigned_from(int64_t value, const char* what) {
    if (value < 0 || value > int64_t(UINT32_MAX)) throw Error(what, std::to_string(value) + " is out of range");
    return uint32_t(value);
}

// The light the build uses: None → the first directional or spot light (as dag-table4
// chooses), an int → that index, a str → the light of that name.
size_t choose_light(const SceneFrame& frame, const py::object& light, const std::string& scene) {
    const auto& lights = frame.lights;
    if (light.is_none()) {
        for (size_t i = 0; i < lights.size(); ++i)
            if (lights[i].type != LightType::Point) return i;
        throw Error(scene, "has no directional or spot light to cast shadows");
    }
    if (py::isinstance<py::str>(light)) {
        const std::string name = light.cast<std::string>();
        for (size_t i = 0; i < lights.size(); ++i)
            if (lights[i].name == name) return i;
        std::string names;
        for (const auto& l : lights) names += (names.empty() ? "" : ", ") + ("'" + l.name + "'");
        throw Error("light", "no light named '" + name + "' in " + scene + " (it has " +
                                 (names.empty() ? std::string("none") : names) + ")");
    }
    if (py::isinstance<py::int_>(light) && !py::isinstance<py::bool_>(light)) {
        const int64_t index = light.cast<int64_t>();
        if (index < 0 || index >= int64_t(lights.size()))
            throw Error("light", "index " + std::to_string(index) + " is outside 0.." + std::to_string(lights.size()) +
                                     " (exclusive) for " + scene);
        return size_t(index);
    }
    throw Error("light", "expected None, a light index or a light name");
}

py::dict light_dict(const PunctualLight& l) {
    return py::dict("name"_a = l.name, "type"_a = to_string(l.type), "position"_a = to_tuple(l.position),
                    "direction"_a = to_tuple(l.direction));
}

// Light-space coordinates: (n, 3) real numbers, kept in double precision.
std::vector<DVec3> light_coords_from(const py::object& value, const char* what) {
    py::array a = py::module_::import("numpy").attr("asarray")(value);
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u') throw Error(what, "expected real numbers");
    if (a.ndim() != 2 || a.shape(1) != 3) throw Error(what, "expected an (n, 3) array");
    auto v = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
    std::vector<DVec3> out(size_t(a.shape(0)));
    for (size_t i = 0; i < out.size(); ++i) out[i] = DVec3(v.data()[3 * i], v.data()[3 * i + 1], v.data()[3 * i + 2]);
    return out;
}

// Voxels: (n, 3) integers inside the octree.
std::vector<UVec3> voxels_from(const py::object& value, uint32_t size, const char* what) {
    py::array a = py::module_::import("numpy").attr("asarray")(value);
    const char kind = a.dtype().kind();
    if (kind != 'i' && kind != 'u') throw Error(what, "expected integer voxel coordinates");
    if (a.ndim() != 2 || a.shape(1) != 3) throw Error(what, "expected an (n, 3) array");
    auto v = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    std::vector<UVec3> out(size_t(a.shape(0)));
    for (size_t i = 0; i < out.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            const int64_t c = v.data()[3 * i + size_t(k)];
            if (c < 0 || c >= int64_t(size))
                throw Error(what, "voxel " + std::to_string(i) + " has coordinate " + std::to_string(c) + " outside 0.." +
                                      std::to_string(size) + " (exclusive)");
            out[i][k] = uint32_t(c);
        }
    return out;
}

bool is_single(const py::object& value) {
    py::array a = py::module_::import("numpy").attr("asarray")(value);
    return a.ndim() == 1;
}

// One triple as a (1, 3) array, for the batched parsers.
py::object as_row(const py::object& value, const char* what) {
    py::array a = py::module_::import("numpy").attr("asarray")(value);
    if (a.ndim() != 1 || a.shape(0) != 3) throw Error(what, "expected 3 numbers");
    return a.attr("reshape")(1, 3);
}

py::object as_bool_array(std::vector<uint8_t>&& values) {
    const auto n = py::ssize_t(values.size());
    return to_numpy(std::move(values), {n}).attr("astype")("bool");
}

const LightSpace& space_of(const PyShadowDag& d) {
    if (!d.dag.space()) throw Error("shadow DAG", "world lookups need a DAG built from a scene");
    return *d.dag.space();
}

// A square float image of side 2^k as row-major values (index y * side + x).
std::vector<float> depth_map_from(const py::object& value, const char* what, uint32_t& side) {
    py::array a = py::module_::import("numpy").attr("asarray")(value);
    if (a.dtype().kind() != 'f') throw Error(what, "expected a float32 or float64 depth map");
    if (a.ndim() != 2 || a.shape(0) != a.shape(1))
        throw Error(what, "expected a square (S, S) depth map");
    const auto s = a.shape(0);
    if (s < 8 || s > py::ssize_t(kMaxLightSpaceResolution) || (s & (s - 1)))
        throw Error(what, "side " + std::to_string(s) + " must be a power of two from 8 to " +
                              std::to_string(kMaxLightSpaceResolution));
    side = uint32_t(s);
    auto v = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
    std::vector<float> out(v.data(), v.data() + size_t(s) * size_t(s));
    for (size_t i = 0; i < out.size(); ++i)
        if (std::isnan(out[i])) throw Error(what, "texel (" + std::to_string(i % s) + ", " + std::to_string(i / s) + ") is NaN");
    return out;
}

}  // namespace

void register_shadow_dag_bindings(py::module_& m) {
    py::class_<PyShadowDag> c(m, "ShadowDag", R"doc(Shadow DAG over a light's light space (P2 §3).

The light's view volume is cut into N³ voxels (N texels across the beam, N
layers of depth); each voxel is lit, in shadow, or — over double depth maps —
undefined (inside a closed object). The 3-state octree over them (interior
nodes: a 16-bit mask of 2-bit child states, 0 shadow / 1 lit / 2 boundary;
leaves: 4×4×4 shadow bitmasks) has identical subtrees merged bottom-up into a
DAG. Storage: an interior node is a 32-bit mask word plus one 32-bit pointer
per boundary child, a leaf 8 bytes — ``bytes`` is the figure dag-table4
reports as S2 / S3 (MB = bytes / 10⁶), ``node_count`` its "S2/S3 nodes".

Build with ShadowDag.build(scene, ...) (depth maps rendered with Embree, as
dag-table4 and the dag_shadows technique do) or ShadowDag.from_depth_maps(d1,
d2). Query with lit(points) (world points as they are), visibility(points,
normals) (surface lookups with the shadow-acne bias and optional PCF),
lit_at(light_coords) or voxel_states(voxels).
)doc");
    c.def_static(
         "build",
         [](const LoadedScene& scene, const py::object& light, int64_t resolution, bool double_depth, double time,
            int64_t tile_texels, const std::string& undefined_as) {
             if (!std::isfinite(time)) throw Error("time", "must be a finite number of seconds");
             ShadowDagOptions o;
             o.resolution = unsigned_from(resolution, "resolution");
             o.double_depth = double_depth;
             o.tile_texels = unsigned_from(tile_texels, "tile_texels");
             o.undefined_as = undefined_as_from(undefined_as);
             const Scene& s = scene.opened.scene;
             const std::string where = "scene '" + s.name + "'";
             std::optional<SceneFrame> frame;
             {
                 py::gil_scoped_release release;
                 frame.emplace(s.evaluate(time));
             }
             const size_t index = choose_light(*frame, light, where);
             PyShadowDag out{ShadowDag(), frame->lights[index], time};
             {
                 py::gil_scoped_release release;
                 const RayTracer tracer(*frame);
                 out.dag = ShadowDag::build(s, tracer, frame->lights[index], o);
             }
             return out;
         },
         "scene"_a, "light"_a = py::none(), "resolution"_a = 1024, "double_depth"_a = false, "time"_a = 0.0,
         "tile_texels"_a = 0, "undefined_as"_a = "shadow", R"doc(Renders the light's depth maps over the scene at `time` and builds the DAG
(ShadowDag::build; the GIL is released).

scene          a gilab.Scene
light          None: the first directional or spot light (what dag-table4
               uses); an index into the scene's lights, or a light's name.
               Point lights are refused (they need a cube of six DAGs).
resolution     N, voxels per axis of the light-space grid (8 .. 131072);
               the octree has depth ceil(log2 N)
double_depth   False: S2, the plain depth map. True: S3, double depth maps —
               space inside closed objects (connected components CGAL finds
               closed) is undefined and folded away by the merge rules
time           scene time in seconds
tile_texels    side of the x–y tiles built one at a time (power of two;
               0: min(octree size, 2048)); the DAG does not depend on it
undefined_as   "shadow" or "lit": how undefined space left inside boundary
               nodes is stored and what lookups there answer (S3 only).
               "shadow" (default) answers as a plain depth map at D1: a
               lookup pushed by the bias into a closed part that touches
               the surface is behind that part

Raises gilab.Error for a point light, a bad resolution or tile, or a light
that sees no geometry.
)doc")
        .def_static(
            "from_depth_maps",
            [](const py::object& d1, const py::object& d2, int64_t tile_texels, const std::string& undefined_as) {
                uint32_t side = 0, side2 = 0;
                std::vector<float> first = depth_map_from(d1, "d1", side);
                std::vector<float> second = d2.is_none() ? first : depth_map_from(d2, "d2", side2);
                if (!d2.is_none()) {
                    if (side2 != side)
                        throw Error("d2", "is " + std::to_string(side2) + "² but d1 is " + std::to_string(side) + "²");
                    for (size_t i = 0; i < first.size(); ++i)
                        if (second[i] < first[i])
                            throw Error("d2", "texel (" + std::to_string(i % side) + ", " + std::to_string(i / side) +
                                                  ") exits before it enters (d2 < d1)");
                }
                ShadowDagOptions o;
                o.tile_texels = unsigned_from(tile_texels, "tile_texels");
                o.undefined_as = undefined_as_from(undefined_as);
                const int depth = __builtin_ctz(side);
                PyShadowDag out;
                py::gil_scoped_release release;
                out.dag = ShadowDag::build(
                    depth,
                    [&](uint32_t x0, uint32_t y0, uint32_t size, LightDepthTile& tile) {
                        std::vector<float> a(size_t(size) * size), b(size_t(size) * size);
                        for (uint32_t y = 0; y < size; ++y)
                            for (uint32_t x = 0; x < size; ++x) {
                                const size_t from = size_t(y0 + y) * side + (x0 + x), to = size_t(y) * size + x;
                                a[to] = first[from];
                                b[to] = second[from];
                            }
                        tile.assign(x0, y0, size, std::move(a), std::move(b));
                    },
                    o);
                return out;
            },
            "d1"_a, "d2"_a = py::none(), "tile_texels"_a = 0, "undefined_as"_a = "shadow",
            R"doc(Builds the DAG from depth maps given as arrays (ShadowDag::build over
LightDepthTile::assign): d1 and d2 are (S, S) float arrays indexed [y, x], S a
power of two from 8 up, depths in voxel units along the beam (+inf: no hit).
Voxel (x, y, z) is lit when z + 0.5 < d1[y, x], undefined when
d1 ≤ z + 0.5 < d2, in shadow when z + 0.5 ≥ d2. d2 = None means d2 = d1 (a
plain depth map: no undefined space). The grid is S³; such a DAG answers
voxel_states and lit_at but not world lookups.
)doc")
        .def_property_readonly("depth", [](const PyShadowDag& d) { return d.dag.depth(); },
                               "Octree depth, ceil(log2 N).")
        .def_property_readonly("octree_size", [](const PyShadowDag& d) { return d.dag.octree_size(); },
                               "2^depth voxels per axis (columns and layers past N hold no geometry).")
        .def_property_readonly(
            "resolution",
            [](const PyShadowDag& d) { return d.dag.space() ? d.dag.space()->resolution() : d.dag.octree_size(); },
            "N, voxels per axis of the light-space grid.")
        .def_property_readonly(
            "perspective", [](const PyShadowDag& d) { return d.dag.space() && d.dag.space()->perspective(); },
            "True for a spot light's frustum, False for a directional light's box (or depth maps).")
        .def_property_readonly(
            "light", [](const PyShadowDag& d) -> py::object { return d.light ? py::object(light_dict(*d.light)) : py::none(); },
            "The world-space light it was built for (name, type, position, direction), or None.")
        .def_readonly("time", &PyShadowDag::time, "Scene time it was built at.")
        .def_property_readonly("root_state", [](const PyShadowDag& d) { return std::string(to_string(d.dag.root_state())); },
                               "\"boundary\" unless the whole grid is one state (\"lit\", \"shadow\", \"undefined\").")
        .def_property_readonly("bytes", [](const PyShadowDag& d) { return d.dag.bytes(); },
                               "Stored size: every 32-bit word of every node and leaf (dag-table4's S2 / S3 × 10⁶).")
        .def_property_readonly("node_count", [](const PyShadowDag& d) { return d.dag.node_count(); },
                               "Interior nodes plus leaves (dag-table4's \"S2 nodes\" / \"S3 nodes\").")
        .def_property_readonly("leaf_count", [](const PyShadowDag& d) { return d.dag.leaf_count(); },
                               "Unique 4×4×4 leaves (the last level).")
        .def_property_readonly("pointer_count", [](const PyShadowDag& d) { return d.dag.pointer_count(); },
                               "Pointers stored (one per boundary child).")
        .def_property_readonly("level_node_counts", [](const PyShadowDag& d) { return d.dag.level_node_counts(); },
                               "Unique nodes per level, root first, leaves last (sums to node_count).")
        .def_property_readonly(
            "words",
            [](const py::object& self) {
                const ShadowDag& dag = self.cast<const PyShadowDag&>().dag;
                return py::array_t<uint32_t>(py::ssize_t(dag.words().size()), dag.words().data(), self);
            },
            "The stored 32-bit words (a read-only view, no copy): canonical, so equal DAGs give equal words.")
        .def_property_readonly(
            "build_stats",
            [](const PyShadowDag& d) {
                const ShadowDagBuildStats& s = d.dag.build_stats();
                return py::dict("total_ms"_a = s.total_ms, "closed_ms"_a = s.closed_ms, "depth_ms"_a = s.depth_ms,
                                "svo_ms"_a = s.svo_ms, "merge_ms"_a = s.merge_ms, "layout_ms"_a = s.layout_ms,
                                "rays"_a = s.rays, "svo_nodes"_a = s.svo_nodes, "tiles"_a = s.tiles,
                                "tile_texels"_a = s.tile_texels, "table_bytes"_a = s.table_bytes,
                                "peak_rss_bytes"_a = s.peak_rss_bytes);
            },
            "Build figures: total_ms, closed_ms, depth_ms, svo_ms, merge_ms, layout_ms, rays, svo_nodes (of all the\n"
            "cell SVOs merged), tiles, tile_texels, table_bytes, peak_rss_bytes.")
        .def_property_readonly("stats", [](const PyShadowDag& d) { return stats_to_dict(d.dag.stats()); },
                               "The C++ figures as a dict (nodes, leaves, pointers, bytes, build times, ...).")
        .def(
            "voxel_state",
            [](const PyShadowDag& d, const py::object& voxel) {
                const UVec3 v = voxels_from(as_row(voxel, "voxel"), d.dag.octree_size(), "voxel")[0];
                return std::string(to_string(d.dag.voxel_state(v)));
            },
            "voxel"_a, "State of one voxel (x, y, z): \"lit\", \"shadow\" or \"undefined\" (a wholly undefined node).")
        .def(
            "voxel_states",
            [](const PyShadowDag& d, const py::object& voxels) {
                std::vector<UVec3> v = voxels_from(voxels, d.dag.octree_size(), "voxels");
                std::vector<uint8_t> out(v.size());
                {
                    py::gil_scoped_release release;
                    ShadowDag::Cursor cursor;
                    for (size_t i = 0; i < v.size(); ++i) out[i] = uint8_t(d.dag.voxel_state(v[i], cursor));
                }
                const auto n = py::ssize_t(out.size());
                return to_numpy(std::move(out), {n});
            },
            "voxels"_a, "States of (n, 3) voxels as uint8 codes: 0 shadow, 1 lit, 3 undefined.")
        .def(
            "lit_at",
            [](const PyShadowDag& d, const py::object& coords) -> py::object {
                const bool single = is_single(coords);
                std::vector<DVec3> c = light_coords_from(single ? as_row(coords, "light_coords") : coords, "light_coords");
                std::vector<uint8_t> out(c.size());
                {
                    py::gil_scoped_release release;
                    ShadowDag::Cursor cursor;
                    for (size_t i = 0; i < c.size(); ++i) out[i] = d.dag.lit_at(c[i], cursor);
                }
                if (single) return py::bool_(out[0] != 0);
                return as_bool_array(std::move(out));
            },
            "light_coords"_a, R"doc(Lit or not at continuous light-space coordinates (u, v, w) in voxel units:
one point (3 numbers) → bool, (n, 3) → bool array. Outside the grid's x–y
square and in front of it is lit; past its far end the last layer answers.
)doc")
        .def(
            "to_light",
            [](const PyShadowDag& d, const py::object& points) {
                const LightSpace& space = space_of(d);
                std::vector<Vec3> p = points_from_array(points, "points");
                std::vector<double> out(3 * p.size());
                for (size_t i = 0; i < p.size(); ++i) {
                    const DVec3 c = space.to_light(p[i]);
                    out[3 * i] = c.x, out[3 * i + 1] = c.y, out[3 * i + 2] = c.z;
                }
                return to_numpy(std::move(out), {py::ssize_t(p.size()), 3});
            },
            "points"_a, "Light-space coordinates (u, v, w) of (n, 3) world points, float64, voxel units.")
        .def(
            "to_light_direction",
            [](const PyShadowDag& d, const py::object& points) {
                const LightSpace& space = space_of(d);
                std::vector<Vec3> p = points_from_array(points, "points");
                std::vector<float> out(3 * p.size());
                for (size_t i = 0; i < p.size(); ++i) {
                    const Vec3 w = space.to_light_direction(p[i]);
                    out[3 * i] = w.x, out[3 * i + 1] = w.y, out[3 * i + 2] = w.z;
                }
                return to_numpy(std::move(out), {py::ssize_t(p.size()), 3});
            },
            "points"_a, "Unit directions from (n, 3) world points toward the light, float32.")
        .def(
            "lit",
            [](const PyShadowDag& d, const py::object& points) -> py::object {
                const LightSpace& space = space_of(d);
                const bool single = is_single(points);
                std::vector<Vec3> p = single ? std::vector<Vec3>{vec3_from(points, "point")} : points_from_array(points, "points");
                std::vector<uint8_t> out(p.size());
                {
                    py::gil_scoped_release release;
                    ShadowDag::Cursor cursor;
                    for (size_t i = 0; i < p.size(); ++i) out[i] = d.dag.lit_at(space.to_light(p[i]), cursor);
                }
                if (single) return py::bool_(out[0] != 0);
                return as_bool_array(std::move(out));
            },
            "points"_a, R"doc(Whether world points lie in lit space, looked up where they are (no bias):
one point → bool, (n, 3) → bool array. For points on surfaces use
visibility(), which moves the lookup off the surface as renderers do.
)doc")
        .def(
            "visibility",
            [](const PyShadowDag& d, const py::object& points, const py::object& normals, int pcf) -> py::object {
                space_of(d);
                if (pcf < 1) throw Error("pcf", "must be at least 1, got " + std::to_string(pcf));
                const bool single = is_single(points);
                std::vector<Vec3> p, n;
                if (single) {
                    p = {vec3_from(points, "point")};
                    n = {vec3_from(normals, "normal")};
                } else {
                    p = points_from_array(points, "points");
                    n = points_from_array(normals, "normals");
                    if (n.size() != p.size())
                        throw Error("normals", std::to_string(n.size()) + " rows for " + std::to_string(p.size()) + " points");
                }
                std::vector<float> out(p.size());
                {
                    py::gil_scoped_release release;
                    d.dag.visibility(p, n, out, pcf);
                }
                if (single) return py::float_(out[0]);
                const auto rows = py::ssize_t(out.size());
                return to_numpy(std::move(out), {rows});
            },
            "points"_a, "normals"_a, "pcf"_a = 1, R"doc(Shadow lookups of surface points with their normals, as the dag_shadows
technique does (ShadowDag::visibility, in parallel): 1 lit, 0 in shadow or
turned away from the light; pcf = k > 1 averages k×k neighbouring columns.
The lookup point is moved 1.5 voxels off the surface and 1 voxel toward the
light, so a lit surface does not shadow itself. One point and normal → float,
(n, 3) each → float32 array.
)doc")
        .def("__repr__", [](const PyShadowDag& d) {
            return "<gilab.ShadowDag " + std::to_string(d.dag.octree_size()) + "³ octree, " +
                   std::to_string(d.dag.node_count()) + " nodes, " + std::to_string(d.dag.bytes()) + " bytes>";
        });
}

}  // namespace gilab::python
