#pragma once
// Stochastic progressive photon mapping (Hachisuka & Jensen 2009, SPPM), the photon
// technique's `progressive` mode. Every iteration traces a fresh jittered primary ray
// per pixel to its visible point (our BSDFs have no specular lobe, so the first hit is
// the visible point), a fresh photon pass, and updates per-pixel statistics: radius R,
// accumulated photon count N and accumulated BSDF-weighted flux τ. With M photons found
// within R this iteration, carrying BSDF-weighted flux Φ_M:
//   N' = N + αM,   R' = R·sqrt((N + αM)/(N + M)),   τ' = (τ + Φ_M)·R'²/R².
// The indirect radiance after k iterations is τ / (π R² · k): the photons already carry
// Φ_light / (photons per iteration), so dividing by k is dividing by every emitted photon.
// Direct light is the technique's shadow-ray estimate at each iteration's visible point,
// averaged over the iterations (progressive mode needs photon_storage=indirect).
//
// Settings: progressive (false), iterations (16), alpha (2/3, in (0, 1)), radius (the
// initial R), time_budget (seconds, optional: stop after the iteration that fills it).
#include <cmath>
#include <cstdint>
#include <optional>
#include "core/util/math.hpp"

namespace gilab {

struct ProgressiveSettings {
    bool enabled = false;
    int iterations = 16;
    double alpha = 2.0 / 3.0;                // fraction of new photons kept (the paper's α)
    std::optional<double> time_budget;       // seconds
};

// The statistics of one pixel, all in double: N and τ grow over many iterations.
struct SppmPixel {
    double radius = 0;   // R
    double count = 0;    // N
    DVec3 flux{0.0};     // τ

    // One iteration that found `found` photons within R with BSDF-weighted flux `found_flux`.
    // No photon found leaves the pixel as it was (R' = R, N' = N, τ' = τ).
    void add_iteration(uint64_t found, const DVec3& found_flux, double alpha) {
        if (found == 0) return;
        const double m = double(found);
        const double n_new = count + alpha * m;
        const double shrink2 = n_new / (count + m);  // R'² / R²
        radius *= std::sqrt(shrink2);
        count = n_new;
        flux = (flux + found_flux) * shrink2;
    }

    // Reflected indirect radiance after `iterations` photon passes.
    DVec3 radiance(int iterations) const {
        if (iterations < 1 || !(radius > 0)) return DVec3(0.0);
        return flux / (kPi * radius * radius * double(iterations));
    }
};

}  // namespace gilab
