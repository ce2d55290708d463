// pm-radius-sweep: the photon technique's two quality knobs against each other on the
// conference room — gather radius × photons emitted, frame time and image error. A
// declared experiment: the spec below is all of it.
#include "experiments/runner/experiment.hpp"

namespace gilab {

Experiment radius_sweep_experiment() {
    using Source = SpecMeasure::Source;
    return declared_experiment({
        .name = "pm-radius-sweep",
        .paper = "P1",
        .figure = "Radius × photons",
        .description = "photon gather radius × photons emitted on the conference room: frame time and relMSE",
        .scenes = {"conference"},
        .size = 256, .quick_size = 48,
        .frames = 3, .quick_frames = 1,
        .reference_spp = 1024, .quick_reference_spp = 32,
        .variants = {{.name = "hash grid, radius gather", .technique = "photon", .settings = {{"photon_map", "hash_grid"}, {"gather", "radius"}}}},
        .axes = {{"photons", {65536, 262144, 1048576}, {8192, 32768}},
                 {"radius", {0.1, 0.2, 0.4}, {0.15, 0.3}}},
        .measures = {{"frame_ms", Source::FrameStat, "render_ms"},
                     {"photon_trace_ms", Source::PrepareStat, "photon_trace_ms"},
                     {"photons_stored", Source::PrepareStat, "photons_stored"},
                     {"relmse_indirect", Source::RelMse, "indirect"},
                     {"relmse_color", Source::RelMse, "color"}},
        .notes = {"The conference room is about 9.8 m across its bounding-box diagonal; the technique's default radius "
                  "is 3 % of it (0.29 m). Direct light comes from shadow rays (photon_storage=indirect), so "
                  "relmse_indirect isolates the photon estimate: a larger radius trades noise for blur, more photons "
                  "lower both.",
                  "frame_ms = median render() time over the task's frames (primary rays, shadow rays, gather); photon "
                  "tracing and the map build happen in prepare and are not in it. relMSE against a path-traced "
                  "reference at the same pixel centres."},
    });
}

}  // namespace gilab
