// P3 (voxel cone tracing on cascaded voxel textures): Tables 1–7 and Figs. 9–13, plus a
// stability experiment (flicker while the camera moves, light leaking through a wall
// thinner than a voxel) and an equal-time study of LPV, VCT and photon mapping. Every
// VCT variant is a setting of the one `vct` technique; the comparison structures (SVO, MSVO = OctoMap, SVDAG, OpenVDB) come from accel/ and are
// fed the same conservative voxelization (core/voxel/voxelizer). Each group of
// experiments is declared in its own file of this folder.
#include "experiments/p3_vct/vct_common.hpp"
#include "experiments/runner/experiment.hpp"

namespace gilab {

void register_vct_experiments(ExperimentRegistry& registry) {
    vct::register_structure_tables(registry);  // vct-table1..6
    vct::register_phase_times(registry);       // vct-table7
    vct::register_camera_walks(registry);      // vct-fig9, vct-fig10
    vct::register_images(registry);            // vct-fig11, vct-fig12-13
    vct::register_stability(registry);         // vct-stability
    vct::register_equal_time(registry);        // vct-equal-time
}

}  // namespace gilab
