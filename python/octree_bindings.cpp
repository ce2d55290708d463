// The sparse voxel structures on their own: gilab.Svo (pointer SVO), gilab.Esvo
// (Laine & Karras layout) and gilab.Svdag (merged DAG), each with its node counts per
// level, bytes, decoding and point / ray queries.
#include <pybind11/stl.h>
#include "accel/dag/esvo.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/util/error.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

// Points: one (3 numbers → bool) or many ((n, 3) → bool array).
template <typename Structure>
py::object occupied(const Structure& s, const py::object& points) {
    py::array a = py::module_::import("numpy").attr("asarray")(points);
    if (a.ndim() == 1) return py::bool_(s.occupied(vec3_from(points, "point")));
    std::vector<Vec3> p = points_from_array(points, "points");
    std::vector<uint8_t> inside(p.size());
    {
        py::gil_scoped_release release;
        for (size_t i = 0; i < p.size(); ++i) inside[i] = s.occupied(p[i]);
    }
    return to_numpy(std::move(inside), {py::ssize_t(p.size())}).attr("astype")("bool");
}

UVec3 voxel_from(const py::object& voxel) {
    auto v = voxel.cast<std::vector<int64_t>>();
    if (v.size() != 3) throw Error("voxel", "expected 3 integer coordinates");
    for (int64_t c : v)
        if (c < 0 || c > int64_t(UINT32_MAX)) throw Error("voxel", "coordinate " + std::to_string(c) + " is out of range");
    return UVec3(uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2]));
}

// Many rays at once: origins and directions (n, 3) → hit, t, voxel, nodes_visited arrays.
template <typename Structure>
py::dict trace_rays(const Structure& s, const py::object& origins, const py::object& directions) {
    std::vector<Vec3> o = points_from_array(origins, "origins");
    std::vector<Vec3> d = points_from_array(directions, "directions");
    if (o.size() != d.size())
        throw Error("directions", std::to_string(d.size()) + " rows for " + std::to_string(o.size()) + " origins");
    const size_t n = o.size();
    std::vector<uint8_t> hit(n);
    std::vector<float> t(n);
    std::vector<uint32_t> voxel(3 * n), visited(n);
    {
        py::gil_scoped_release release;
        for (size_t i = 0; i < n; ++i) {
            Ray ray;
            ray.origin = o[i];
            ray.direction = d[i];
            VoxelRayHit h = trace_voxel_ray(s, ray);
            hit[i] = h.hit;
            t[i] = h.t;
            voxel[3 * i] = h.voxel.x, voxel[3 * i + 1] = h.voxel.y, voxel[3 * i + 2] = h.voxel.z;
            visited[i] = h.nodes_visited;
        }
    }
    const auto rows = py::ssize_t(n);
    return py::dict("hit"_a = to_numpy(std::move(hit), {rows}).attr("astype")("bool"), "t"_a = to_numpy(std::move(t), {rows}),
                    "voxel"_a = to_numpy(std::move(voxel), {rows, 3}), "nodes_visited"_a = to_numpy(std::move(visited), {rows}));
}

// What every structure offers, with the same names and meanings.
template <typename Structure, typename Class>
void add_common_methods(Class& c) {
    c.def_property_readonly("grid", &Structure::grid)
        .def_property_readonly("depth", &Structure::depth, "Octree depth, ceil(log2 resolution).")
        .def_property_readonly("node_count", [](const Structure& s) { return s.node_count(); })
        .def_property_readonly("pointer_count", [](const Structure& s) { return s.pointer_count(); })
        .def_property_readonly("bytes", [](const Structure& s) { return s.bytes(); }, "Storage size as laid out.")
        .def_property_readonly("voxel_count", [](const Structure& s) { return uint64_t(s.voxel_count()); },
                               "Occupied voxels.")
        .def_property_readonly("level_node_counts", [](const Structure& s) { return s.level_node_counts(); },
                               "Nodes per level, root level first (depth + 1 entries).")
        .def(
            "decode",
            [](const Structure& s) {
                std::vector<uint64_t> codes;
                {
                    py::gil_scoped_release release;
                    codes = s.decode();
                }
                const auto n = py::ssize_t(codes.size());
                return to_numpy(std::move(codes), {n});
            },
            "Morton codes of every occupied voxel, ascending (uint64): equal to the voxel list it came from.")
        .def(
            "contains_voxel", [](const Structure& s, const py::object& voxel) { return s.contains_voxel(voxel_from(voxel)); },
            "voxel"_a, "Whether the voxel (x, y, z) is occupied.")
        .def("occupied", &occupied<Structure>, "points"_a,
             "Whether world points lie in occupied voxels: one point (3 numbers) → bool, (n, 3) → bool array.")
        .def(
            "trace_ray",
            [](const Structure& s, const py::object& origin, const py::object& direction, float tmin, float tmax) {
                Ray ray;
                ray.origin = vec3_from(origin, "origin");
                ray.direction = vec3_from(direction, "direction");
                ray.tmin = tmin;
                ray.tmax = tmax;
                VoxelRayHit h = trace_voxel_ray(s, ray);
                return py::dict("hit"_a = h.hit, "voxel"_a = h.hit ? py::object(to_tuple(h.voxel)) : py::none(),
                                "t"_a = h.t, "nodes_visited"_a = h.nodes_visited);
            },
            "origin"_a, "direction"_a, "tmin"_a = 0.0f, "tmax"_a = kInfinity, R"doc(The first occupied voxel along a ray: {"hit", "voxel", "t" (entry distance in
units of |direction|), "nodes_visited"}. Svo, Esvo and Svdag of the same voxels
give the same answer.
)doc")
        .def("trace_rays", &trace_rays<Structure>, "origins"_a, "directions"_a,
             "Many rays, (n, 3) each: {\"hit\" bool, \"t\" float32, \"voxel\" (n, 3) uint32, \"nodes_visited\"} arrays.")
        .def_property_readonly("stats", [](const Structure& s) { return stats_to_dict(s.stats()); },
                               "Figures as a dict (nodes, pointers, bytes, voxels, build times, nodes_level_<k>).");
}

}  // namespace

void register_octree_bindings(py::module_& m) {
    py::class_<Svo> svo(m, "Svo", R"doc(Sparse voxel octree (P2 §2.1): per node an 8-bit child mask and, for nodes with
children, the index of the first child; breadth-first, Morton order per level.
Build with Svo.build(voxel_list).
)doc");
    svo.def_static(
        "build",
        [](const VoxelList& voxels) {
            py::gil_scoped_release release;
            return Svo::build(voxels);
        },
        "voxels"_a, "Builds the octree bottom-up from a gilab.VoxelList (GIL released).");
    add_common_methods<Svo>(svo);
    svo.def_property_readonly("pointerless_bytes", &Svo::pointerless_bytes, "1 byte per node (Schnabel & Klein).")
        .def("__repr__", [](const Svo& s) { return "<gilab.Svo " + std::to_string(s.node_count()) + " nodes>"; });

    py::class_<Esvo> esvo(m, "Esvo", R"doc(Efficient sparse voxel octree layout (Laine & Karras 2010): 64-bit child
descriptors with 15-bit relative child pointers and far pointers. Contours are
not built. Convert with Esvo.from_svo(svo).
)doc");
    esvo.def_static(
        "from_svo",
        [](const Svo& svo) {
            py::gil_scoped_release release;
            return Esvo::from_svo(svo);
        },
        "svo"_a);
    add_common_methods<Esvo>(esvo);
    esvo.def_property_readonly("far_pointer_count", &Esvo::far_pointer_count)
        .def("__repr__", [](const Esvo& e) { return "<gilab.Esvo " + std::to_string(e.node_count()) + " descriptors>"; });

    py::class_<Svdag> svdag(m, "Svdag", R"doc(Sparse voxel DAG (P2 §2.2): the SVO with identical subtrees merged bottom-up,
stored as a 32-bit mask word plus one 32-bit pointer per child. Build with
Svdag.from_svo(svo) (the paper's conversion) or Svdag.from_voxels(voxels).
)doc");
    svdag
        .def_static(
            "from_svo",
            [](const Svo& svo) {
                py::gil_scoped_release release;
                return Svdag::from_svo(svo);
            },
            "svo"_a)
        .def_static(
            "from_voxels",
            [](const VoxelList& voxels, int split_level) {
                py::gil_scoped_release release;
                return Svdag::from_voxels(voxels, split_level);
            },
            "voxels"_a, "split_level"_a = 0,
            "Straight from a voxel list; split_level > 0 converts each subtree below that level separately "
            "(the same DAG, less peak memory).");
    add_common_methods<Svdag>(svdag);
    svdag.def("__repr__", [](const Svdag& d) { return "<gilab.Svdag " + std::to_string(d.node_count()) + " nodes>"; });
}

}  // namespace gilab::python
