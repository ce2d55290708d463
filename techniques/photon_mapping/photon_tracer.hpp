#pragma once
// Photon tracing (the first pass of photon mapping): photons leave the lights in
// proportion to emitted power (LightSampler::sample_emission), each carrying flux
// Φ_light / N_emitted, and bounce diffusely (or off the glossy lobe) with Russian
// roulette: a photon survives with probability q = min(1, max(f cosθ / pdf)) (the albedo
// for a Lambertian surface) and its flux is multiplied by (f cosθ / pdf) / q, which keeps
// the estimate unbiased. A copy is stored at every surface hit from `first_stored_hit`
// on (every surface of our BSDF is non-specular), tagged with its hit index
// (Photon::hit_index). With first_stored_hit = 2 the map holds only light that has
// bounced at least once: the indirect layer, with direct lighting computed separately
// by shadow rays. With 1 (P1's photon map) it holds direct light too, and the first-hit
// copies are what a density estimate counts as direct.
//
// Deterministic for a given seed at any thread count: photon i draws from
// Rng::for_sample(seed, i, 0, kPhotonPassBase + pass) and the photons are gathered in
// photon order.
#include <cstdint>
#include <vector>
#include "accel/photon/photon.hpp"
#include "core/render/light_sampler.hpp"
#include "core/scene/material.hpp"
#include "core/render/ray_tracer.hpp"

namespace gilab {

inline constexpr uint64_t kPhotonPassBase = 0x70686f746f6e0000ull;  // keeps photon streams apart from camera streams

struct PhotonTraceSettings {
    uint64_t emitted = 256 * 256;   // photons emitted (the paper's 128², 256², 512²)
    int max_depth = 8;              // surface hits along a photon path (≥ 1)
    int first_stored_hit = 2;       // 1: global map (direct too, P1); 2: indirect only
    uint64_t seed = 1;
    uint64_t pass = 0;
};

struct PhotonTraceResult {
    std::vector<Photon> photons;    // in photon order, then hit order along each path
    uint64_t emitted = 0;
    uint64_t rays = 0;
    uint64_t paths_stored = 0;      // photon paths that stored at least one photon
    double trace_ms = 0;
};

PhotonTraceResult trace_photons(const RayTracer& tracer, const SceneFrame& frame, const std::vector<Material>& materials,
                                const LightSampler& lights, const PhotonTraceSettings& settings);

}  // namespace gilab
