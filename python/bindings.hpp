#pragma once
// The pieces of the `gilab` Python module. Each concept registers its own classes and
// functions; module.cpp calls them in dependency order (a class must be registered
// before a docstring signature can name it).
#include <pybind11/pybind11.h>

namespace gilab::python {

namespace py = pybind11;

void register_errors(py::module_& m);
void register_film_bindings(py::module_& m);
void register_camera_bindings(py::module_& m);
void register_scene_bindings(py::module_& m);
void register_render_bindings(py::module_& m);
void register_experiment_bindings(py::module_& m);
void register_voxel_bindings(py::module_& m);
void register_octree_bindings(py::module_& m);
void register_shadow_dag_bindings(py::module_& m);
void register_multi_frame_dag_bindings(py::module_& m);
void register_photon_map_bindings(py::module_& m);
void register_metric_bindings(py::module_& m);
void register_catalogue_bindings(py::module_& m);

}  // namespace gilab::python
