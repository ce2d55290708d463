#include "experiments/runner/experiment.hpp"

namespace gilab {

const ExperimentRegistry& ExperimentRegistry::builtin() {
    static const ExperimentRegistry registry = [] {
        ExperimentRegistry r;
        register_core_experiments(r);
        register_photon_experiments(r);
        register_stereo_experiments(r);
        register_dag_experiments(r);
        register_shadow_dag_experiments(r);
        register_dynamic_dag_experiments(r);
        register_vct_experiments(r);
        return r;
    }();
    return registry;
}

}  // namespace gilab
