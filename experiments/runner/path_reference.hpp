#pragma once
// The path-traced reference the experiments compare against: pixel centres (as the photon
// technique renders) or jittered, max depth 8, under a name that holds a digest of the
// scene's content, the path tracer's settings and code, and the camera. The images live
// in one store per results folder, RESULTS/.references, shared by every experiment and
// every task — on a cluster by every node — and each is rendered once: the first task to
// need it renders it, others needing it meanwhile wait for it (core/util/produce_once.hpp).
// An experiment's folder gets a link to each reference it used, and a PNG of it.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>
#include "core/scene/camera.hpp"
#include "core/image/film.hpp"
#include "core/scene/scene.hpp"
#include "experiments/runner/experiment.hpp"

namespace gilab {

// The reference draws its samples from a seed of its own. Techniques render with the
// run's seed, and the path tracer and the photon technique draw from the same per-sample
// streams, so a reference on the run's seed would share its first samples with the image
// it judges (a path render with the reference's spp would be the reference itself).
uint64_t reference_seed(uint64_t run_seed);

// One reference image a task needs. `jitter` spreads each pixel's samples over its area
// (an anti-aliased reference, for techniques that sample pixels the same way). `seed`
// replaces reference_seed(run seed), e.g. for a second, independent reference whose
// difference from the first estimates their noise; it is part of the cache key.
struct ReferenceView {
    const Scene* scene = nullptr;
    EyeCamera camera;
    int spp = 0;
    bool jitter = false;
    std::optional<uint64_t> seed;
};

// The store of ctx's results folder: ctx.output_dir's parent / .references.
std::filesystem::path reference_store(const ExperimentContext& ctx);

// The reference, from the store or rendered into it; adds its file name (in
// ctx.output_dir) to `files`.
Film path_reference(const ExperimentContext& ctx, const ReferenceView& view, std::vector<std::string>& files);
Film path_reference(const ExperimentContext& ctx, const Scene& scene, const EyeCamera& camera, int spp,
                    std::vector<std::string>& files, bool jitter = false, std::optional<uint64_t> seed = {});

}  // namespace gilab
