// The time-correlated multi-frame DAG (P2 §4) on its own: gilab.MultiFrameDag (frames
// merged across space and time, appended or replaced one at a time, or merged all at
// once from per-frame SVDAGs), gilab.LaidOutMultiFrameDag (its 32-bit layout, with per-frame
// decoding and point queries) and gilab.build_animation_dag (every frame of an animated
// scene, as the dag_raycast technique and dag-table5 build it).
#include <algorithm>
#include <cmath>
#include <optional>
#include <pybind11/stl.h>
#include "accel/temporal/multi_frame_dag.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/temporal/laid_out_multi_frame_dag.hpp"
#include "core/util/error.hpp"
#include "core/voxel/voxelizer.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"
#include "python/loaded_scene.hpp"
#include "accel/temporal/animation_dag.hpp"
#include "techniques/dag_raycast/dag_raycast_settings.hpp"

namespace gilab::python {

using namespace pybind11::literals;

namespace {

size_t frame_index(int64_t frame) {
    if (frame < 0) throw Error("frame", "must be a frame index from 0, got " + std::to_string(frame));
    return size_t(frame);
}

bool same_grid(const VoxelGrid& a, const VoxelGrid& b) {
    return a.origin == b.origin && a.extent == b.extent && a.resolution == b.resolution;
}

// One frame's voxels: a gilab.VoxelList on the DAG's grid, or Morton codes (uint64,
// ascending, unique; MultiFrameDag checks them against the grid).
std::vector<uint64_t> frame_codes(const py::object& voxels, const VoxelGrid& grid) {
    if (py::isinstance<VoxelList>(voxels)) {
        const VoxelList& list = voxels.cast<const VoxelList&>();
        if (!same_grid(list.grid, grid))
            throw Error("voxels", "the voxel list was made on a different grid than the DAG's (voxelize with grid=dag.grid)");
        return list.codes;
    }
    py::array a = py::module_::import("numpy").attr("asarray")(voxels);
    if (a.dtype().kind() != 'u' && a.dtype().kind() != 'i')
        throw Error("voxels", "expected a gilab.VoxelList or an array of uint64 Morton codes");
    if (a.ndim() != 1) throw Error("voxels", "Morton codes must be a 1-D array");
    if (a.dtype().kind() == 'i' && a.size() > 0 && py::int_(a.attr("min")()).cast<int64_t>() < 0)
        throw Error("voxels", "Morton codes cannot be negative");
    auto v = py::array_t<uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    return std::vector<uint64_t>(v.data(), v.data() + v.size());
}

py::dict merge_stats(const FrameMergeStats& s) {
    return py::dict("nodes_added"_a = s.nodes_added, "nodes_reclaimed"_a = s.nodes_reclaimed,
                    "cells_rebuilt"_a = s.cells_rebuilt, "cells_reused"_a = s.cells_reused, "ms"_a = s.ms);
}

DagBuildMode build_mode_from(const std::string& s) {
    if (s == "incremental") return DagBuildMode::Incremental;
    if (s == "all_at_once") return DagBuildMode::AllAtOnce;
    throw Error("build", "'" + s + "' is not a build mode: give \"incremental\" or \"all_at_once\"");
}

py::object root_or_none(uint32_t root, uint32_t empty) { return root == empty ? py::object(py::none()) : py::int_(root); }

}  // namespace

void register_multi_frame_dag_bindings(py::module_& m) {
    py::class_<LaidOutMultiFrameDag>(m, "LaidOutMultiFrameDag", R"doc(The time-correlated multi-frame DAG laid out in P2's 32-bit format (§2.2, §4):
per node a word holding the 8-bit child mask, then one 32-bit word address per
non-empty child. Level 0 holds one root per non-empty frame in time order, so
frame f starts at root(f); everything below is shared across space and time.

node_count is the paper's N_n (one root per non-empty frame plus the shared
nodes below, the leaf node included), nodes_per_frame N_p = N_n / F, bytes the
32-bit storage — the "TC" columns of dag-table5 (MB = bytes / 10⁶).
Get one from MultiFrameDag.lay_out() or build_animation_dag(...).dag.
)doc")
        .def_property_readonly("grid", &LaidOutMultiFrameDag::grid)
        .def_property_readonly("depth", &LaidOutMultiFrameDag::depth, "Octree depth, ceil(log2 resolution).")
        .def_property_readonly("frame_count", &LaidOutMultiFrameDag::frame_count)
        .def("__len__", &LaidOutMultiFrameDag::frame_count)
        .def_property_readonly("node_count", [](const LaidOutMultiFrameDag& d) { return d.node_count(); }, "N_n.")
        .def_property_readonly("nodes_per_frame", &LaidOutMultiFrameDag::nodes_per_frame, "N_p = N_n / F.")
        .def_property_readonly("pointer_count", [](const LaidOutMultiFrameDag& d) { return d.pointer_count(); })
        .def_property_readonly("bytes", [](const LaidOutMultiFrameDag& d) { return d.bytes(); },
                               "32-bit storage: 4 B per node word and per pointer.")
        .def_property_readonly("level_node_counts", [](const LaidOutMultiFrameDag& d) { return d.level_node_counts(); },
                               "Nodes per level, level 0 (the roots, one per non-empty frame) first; depth + 1 entries.")
        .def_property_readonly(
            "words",
            [](const py::object& self) {
                const LaidOutMultiFrameDag& d = self.cast<const LaidOutMultiFrameDag&>();
                return py::array_t<uint32_t>(py::ssize_t(d.words().size()), d.words().data(), self);
            },
            "The 32-bit words (a view, no copy): canonical, so equal DAGs give equal words however they were built.")
        .def(
            "root",
            [](const LaidOutMultiFrameDag& d, int64_t frame) {
                return root_or_none(d.root(frame_index(frame)), LaidOutMultiFrameDag::kEmptyFrame);
            },
            "frame"_a, "Word address of frame's root, or None for a frame without voxels.")
        .def(
            "reachable_node_count",
            [](const LaidOutMultiFrameDag& d, int64_t frame) { return d.reachable_node_count(frame_index(frame)); },
            "frame"_a,
            "Nodes below root(frame), root and leaf included: that frame's own SVDAG node count.")
        .def(
            "decode",
            [](const LaidOutMultiFrameDag& d, int64_t frame) {
                const size_t f = frame_index(frame);
                std::vector<uint64_t> codes;
                {
                    py::gil_scoped_release release;
                    codes = d.decode(f);
                }
                const auto n = py::ssize_t(codes.size());
                return to_numpy(std::move(codes), {n});
            },
            "frame"_a, "Morton codes of frame's occupied voxels, ascending (uint64): equal to the voxels it was built from.")
        .def(
            "contains_voxel",
            [](const LaidOutMultiFrameDag& d, int64_t frame, const py::object& voxel) {
                auto v = voxel.cast<std::vector<int64_t>>();
                if (v.size() != 3) throw Error("voxel", "expected 3 integer coordinates");
                for (int64_t c : v)
                    if (c < 0 || c > int64_t(UINT32_MAX)) throw Error("voxel", "coordinate " + std::to_string(c) + " is out of range");
                return d.contains_voxel(frame_index(frame), UVec3(uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2])));
            },
            "frame"_a, "voxel"_a, "Whether voxel (x, y, z) is occupied in frame.")
        .def(
            "occupied",
            [](const LaidOutMultiFrameDag& d, int64_t frame, const py::object& points) {
                const size_t f = frame_index(frame);
                d.root(f);  // the frame must exist
                std::vector<Vec3> p = points_from_array(points, "points");
                std::vector<uint8_t> inside(p.size());
                {
                    py::gil_scoped_release release;
                    for (size_t i = 0; i < p.size(); ++i) {
                        const auto v = d.grid().voxel_of(p[i]);
                        inside[i] = v && d.contains_voxel(f, *v);
                    }
                }
                const auto n = py::ssize_t(inside.size());
                return to_numpy(std::move(inside), {n}).attr("astype")("bool");
            },
            "frame"_a, "points"_a, "Whether (n, 3) world points lie in voxels occupied in frame: bool array.")
        .def_property_readonly("stats", [](const LaidOutMultiFrameDag& d) { return stats_to_dict(d.stats()); },
                               "frames, nodes, nodes_per_frame, pointers, bytes, nodes_level_<k>.")
        .def("__repr__", [](const LaidOutMultiFrameDag& d) {
            return "<gilab.LaidOutMultiFrameDag " + std::to_string(d.frame_count()) + " frames, " +
                   std::to_string(d.node_count()) + " nodes>";
        });

    py::class_<MultiFrameDag>(m, "MultiFrameDag", R"doc(Time-correlated multi-frame SVDAG (P2 §4), the builder: the SVOs of all
frames in time order, each level of all frames treated as one list, identical
nodes merged bottom-up across space and time, one root per frame.

  dag = gilab.MultiFrameDag(grid)          # empty, on a gilab.VoxelGrid
  dag.append_frame(voxels)                 # mode (b): frame n into frames 0..n-1
  dag.update_frame(k, voxels)              # replace frame k; dead nodes are kept
  dag.compact()                            # until compact() drops them
  gilab.MultiFrameDag.merge_all(svdags)    # mode (a): per-frame Svdags at once
  dag.lay_out()                            # → gilab.LaidOutMultiFrameDag (32-bit words)

`voxels` is a gilab.VoxelList on the DAG's grid (voxelize(..., grid=dag.grid))
or an array of uint64 Morton codes, ascending and unique.
)doc")
        .def(py::init([](const VoxelGrid& grid) { return MultiFrameDag(grid); }), "grid"_a,
             "An empty DAG over a gilab.VoxelGrid.")
        .def_static(
            "merge_all",
            [](const py::list& frames) {
                std::vector<Svdag> dags;
                dags.reserve(frames.size());
                for (auto f : frames) {
                    if (!py::isinstance<Svdag>(f)) throw Error("frames", "expected a list of gilab.Svdag");
                    dags.push_back(f.cast<const Svdag&>());
                }
                py::gil_scoped_release release;
                return MultiFrameDag::merge_all(dags);
            },
            "frames"_a, "Build mode (a): per-frame gilab.Svdag (same grid) merged level by level over all frames (GIL released).")
        .def(
            "append_frame",
            [](MultiFrameDag& d, const py::object& voxels) {
                std::vector<uint64_t> codes = frame_codes(voxels, d.grid());
                FrameMergeStats s;
                {
                    py::gil_scoped_release release;
                    s = d.append_frame(codes);
                }
                return merge_stats(s);
            },
            "voxels"_a, R"doc(Build mode (b): merges one more frame into the DAG of the frames before it
(GIL released). Returns {nodes_added, nodes_reclaimed, cells_rebuilt,
cells_reused, ms}.
)doc")
        .def(
            "update_frame",
            [](MultiFrameDag& d, int64_t frame, const py::object& voxels) {
                const size_t f = frame_index(frame);
                std::vector<uint64_t> codes = frame_codes(voxels, d.grid());
                FrameMergeStats s;
                {
                    py::gil_scoped_release release;
                    s = d.update_frame(f, codes);
                }
                return merge_stats(s);
            },
            "frame"_a, "voxels"_a,
            "Replaces frame `frame`'s voxels; nodes no frame references any more die (kept until compact()).")
        .def("compact", &MultiFrameDag::compact, "Drops dead nodes from the tables (the laid-out words do not change).")
        .def_property_readonly("grid", &MultiFrameDag::grid)
        .def_property_readonly("depth", &MultiFrameDag::depth)
        .def_property_readonly("frame_count", &MultiFrameDag::frame_count)
        .def("__len__", &MultiFrameDag::frame_count)
        .def_property_readonly("node_count", &MultiFrameDag::node_count, "N_n: one root per non-empty frame plus the live shared nodes below.")
        .def_property_readonly("nodes_per_frame", &MultiFrameDag::nodes_per_frame, "N_p = N_n / F.")
        .def_property_readonly("live_level_counts", &MultiFrameDag::live_level_counts,
                               "Live unique nodes per level (roots counted once).")
        .def_property_readonly("table_level_counts", &MultiFrameDag::table_level_counts,
                               "Nodes held per level, dead ones included.")
        .def_property_readonly("table_bytes", &MultiFrameDag::table_bytes, "Memory of the merge tables.")
        .def_property_readonly(
            "root_ids",
            [](const MultiFrameDag& d) {
                py::list roots;
                for (uint32_t r : d.root_ids()) roots.append(root_or_none(r, MultiFrameDag::kEmptyFrame));
                return roots;
            },
            "Root node id of each frame in the level-0 table (None for a frame without voxels).")
        .def(
            "lay_out",
            [](const MultiFrameDag& d) {
                py::gil_scoped_release release;
                return d.lay_out();
            },
            "The 32-bit layout as a gilab.LaidOutMultiFrameDag (canonical: equal DAGs give equal words).")
        .def("__repr__", [](const MultiFrameDag& d) {
            return "<gilab.MultiFrameDag " + std::to_string(d.frame_count()) + " frames, " + std::to_string(d.node_count()) +
                   " nodes>";
        });

    py::class_<AnimationDag>(m, "AnimationDag", R"doc(What build_animation_dag returns: ``dag`` (a
gilab.LaidOutMultiFrameDag), ``times`` (scene time of each frame) and ``stats``
(build_ms, voxelize_ms, merge_ms, layout_ms, voxels_per_frame, voxel_size,
table_bytes, peak_rss_mib; for the incremental build also cells_rebuilt and
cells_reused).
)doc")
        .def_readonly("dag", &AnimationDag::dag)
        .def_readonly("times", &AnimationDag::times)
        .def_property_readonly("stats", [](const AnimationDag& a) { return stats_to_dict(a.stats); })
        .def_property_readonly(
            "lights",
            [](const AnimationDag& a) {
                py::list frames;
                for (const auto& lights : a.lights) {
                    py::list l;
                    for (const PunctualLight& light : lights)
                        l.append(py::dict("name"_a = light.name, "type"_a = to_string(light.type),
                                          "position"_a = to_tuple(light.position), "direction"_a = to_tuple(light.direction)));
                    frames.append(l);
                }
                return frames;
            },
            "World-space punctual lights of each frame (name, type, position, direction).")
        .def("__repr__", [](const AnimationDag& a) {
            return "<gilab.AnimationDag " + std::to_string(a.dag.frame_count()) + " frames, " +
                   std::to_string(a.dag.node_count()) + " nodes>";
        });

    m.def(
        "build_animation_dag",
        [](const LoadedScene& scene, int64_t resolution, const std::optional<int64_t>& frames,
           const std::optional<double>& fps, const std::string& build) {
            const Scene& s = scene.opened.scene;
            AnimationDagOptions o;
            if (resolution < 1 || resolution > int64_t(kMaxVoxelResolution))
                throw Error("resolution", std::to_string(resolution) + " is out of range: give 1 to " +
                                              std::to_string(kMaxVoxelResolution) + " voxels per axis");
            o.resolution = uint32_t(resolution);
            if (frames && (*frames < 1 || *frames > INT32_MAX))
                throw Error("frames", "must be at least 1, got " + std::to_string(*frames));
            o.frames = frames ? int(*frames) : std::min(s.animation_frame_count(), DagRaycastSettings::kDefaultMaxFrames);
            o.fps = fps ? *fps : s.frames_per_second;
            if (!std::isfinite(o.fps)) throw Error("fps", "must be a finite, positive frame rate");
            o.build = build_mode_from(build);
            py::gil_scoped_release release;
            return build_animation_dag(s, o);
        },
        "scene"_a, "resolution"_a = 256, "frames"_a = py::none(), "fps"_a = py::none(), "build"_a = "incremental",
        R"doc(Voxelizes every frame of a scene's animation on one shared grid (enclosing the
scene's bounds over all frames) and merges them into one time-correlated DAG,
as the dag_raycast technique and dag-table5 do (GIL released).

resolution  voxels per axis of the grid
frames      frame count (None: the scene's animation frames, at most 100);
            frame k is the scene at time k / fps
fps         None: the scene's frame rate
build       "incremental" (mode (b): frames streamed cell by cell, only the
            cells moving triangles touch re-voxelized) or "all_at_once"
            (mode (a): per-frame SVDAGs merged at the end); both give the
            same words

Returns a gilab.AnimationDag (.dag, .times, .stats, .lights).
)doc");
}

}  // namespace gilab::python
