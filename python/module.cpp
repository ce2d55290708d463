// The `gilab` Python module: bindings over the C++ libraries, one file per concept.
#include "core/util/error.hpp"
#include "python/bindings.hpp"

namespace gilab::python {

// gilab::Error is bad input (a missing file, a malformed mesh, an unknown setting, a
// wrong array shape), so in Python it is a ValueError carrying the C++ message.
void register_errors(py::module_& m) {
    py::register_exception<Error>(m, "Error", PyExc_ValueError).doc() =
        "Bad input: the message names where the problem is (file, file:line, setting or argument) and what is wrong.";
}

// The module is built for one interpreter (GILAB_PYTHON_EXECUTABLE, chosen by CMake) and
// hands out NumPy arrays; another interpreter of the same version may load it and lack
// NumPy. Fail at import with the interpreter to use, not at the first array.
void require_numpy() {
    try {
        py::module_::import("numpy");
    } catch (py::error_already_set&) {
        const std::string here = py::module_::import("sys").attr("executable").cast<std::string>();
        throw py::import_error("gilab needs NumPy, which this interpreter (" + here +
                               ") cannot import. The module was built for " GILAB_PYTHON_EXECUTABLE
                               " (Python " GILAB_PYTHON_VERSION "), which has Debian's python3-numpy: run it with that "
                               "interpreter, or rebuild with cmake -DPython3_EXECUTABLE=<yours> after installing NumPy "
                               "and pybind11 for it.");
    }
}

}  // namespace gilab::python

PYBIND11_MODULE(gilab, m) {
    using namespace gilab::python;
    m.doc() = R"doc(gilab — a global-illumination research framework (photon mapping for HMDs,
sparse voxel DAGs, cascaded voxel cone tracing, a reference path tracer).

These bindings wrap the C++ code; they compute nothing of their own:

  load_scene, Scene, SceneFrame        scenes as `gilab render` opens them
  Camera, HmdRig, hmd, HeadPose        cameras and the HMD stereo rig
  render, RenderResult, Film           renders (bit-identical to `gilab render`)
  read_exr                             EXR files written by gilab
  experiments, run_experiment          the experiment runner
  voxelize, VoxelList, Svo, Esvo, Svdag   sparse voxel structures
  ShadowDag                            shadow DAG over a light's light space
  MultiFrameDag, LaidOutMultiFrameDag  time-correlated multi-frame DAG
  build_animation_dag
  PhotonMap                            photon maps with radius / kNN queries
  relative_mse, ssim, flip             image metrics on NumPy arrays
  techniques, scenes, hmd_presets      what is available (as `gilab list`)
  set_memory_limit                     the memory budget (as --memory-limit)

Bad input raises gilab.Error (a ValueError) with the C++ message. Long calls
(renders, builds, experiments) release the GIL.
)doc";
    require_numpy();
    register_errors(m);
    register_film_bindings(m);
    register_camera_bindings(m);
    register_scene_bindings(m);
    register_render_bindings(m);
    register_experiment_bindings(m);
    register_voxel_bindings(m);
    register_octree_bindings(m);
    register_shadow_dag_bindings(m);
    register_multi_frame_dag_bindings(m);
    register_photon_map_bindings(m);
    register_metric_bindings(m);
    register_catalogue_bindings(m);
}
