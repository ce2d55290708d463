#pragma once
// The path-traced reference the photon experiments compare against: pixel centres (as
// the photon technique renders), max depth 8, cached in the experiment's directory (or
// copied from a sibling pm-* directory that already rendered it) under a name that holds
// a digest of the scene's content, the path tracer's settings and code, and the camera.
#include <cstdint>
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

// Adds the reference's file name to `files`. `jitter` spreads each pixel's samples over
// its area (an anti-aliased reference, for techniques that sample pixels the same way).
// `seed` replaces reference_seed(ctx.seed), e.g. for a second, independent reference
// whose difference from the first estimates their noise; it is part of the cache key.
Film path_reference(const ExperimentContext& ctx, const Scene& scene, const EyeCamera& camera, int spp,
                    std::vector<std::string>& files, bool jitter = false, std::optional<uint64_t> seed = {});

}  // namespace gilab
