#pragma once
// Pieces the photon technique's passes share (photon_technique.cpp orchestrates,
// photon_view_pass.cpp renders one eye, photon_stereo_pass.cpp the reusing right eye).
#include <atomic>
#include <span>
#include <vector>
#include "core/util/rng.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"
#include "techniques/photon_mapping/primary_hit.hpp"

namespace gilab {

// The left eye's hits, kept for the right eye (stereo reuse): every sample of every left
// pixel, sample-major (slot = sample · pixels + pixel), so each sample's hits form one
// image-sized layer for the claims, with their light samples and final radiance.
struct PhotonMappingTechnique::KeptHits {
    std::vector<PrimaryHit> hits;
    std::vector<LightSampleRecord> samples;  // per_hit per hit
    std::vector<Vec3> direct, indirect;      // the left eye's radiance of each hit's sample
    size_t pixels = 0;
    size_t per_hit = 0;
    int spp = 1;

    // Kept from frame to frame: every slot is overwritten, so no clearing.
    void resize(size_t pixel_count, int samples_per_pixel, size_t light_samples) {
        pixels = pixel_count, spp = samples_per_pixel, per_hit = light_samples;
        const size_t n = pixels * size_t(spp);
        hits.resize(n);
        samples.resize(n * per_hit);
        direct.resize(n);
        indirect.resize(n);
    }
    size_t slot(size_t pixel, int sample) const { return size_t(sample) * pixels + pixel; }
    std::span<const PrimaryHit> layer(int sample) const { return {hits.data() + slot(0, sample), pixels}; }
    std::span<LightSampleRecord> samples_of(size_t slot) { return {samples.data() + slot * per_hit, per_hit}; }
    std::span<const LightSampleRecord> samples_of(size_t slot) const { return {samples.data() + slot * per_hit, per_hit}; }
};

// What one view's render needs beyond its camera.
struct PhotonMappingTechnique::ViewOptions {
    uint64_t view = 0;                       // light-sample stream of pixels keyed by themselves
    const EyeCamera* stream_eye = nullptr;   // stereo right eye: key by the left pixel seeing the point
    KeptHits* keep = nullptr;                // keep every hit (left eye of a reusing stereo render)
};

// A non-finite radiance is counted and written as black.
inline Vec3 finite_or_zero(const Vec3& v, std::atomic<uint64_t>& nonfinite) {
    if (is_finite(v)) return v;
    ++nonfinite;
    return Vec3(0.0f);
}

inline void write_pixel(float* layer, size_t pixel, const Vec3& v) {
    for (int c = 0; c < 3; ++c) layer[3 * pixel + size_t(c)] = v[c];
}

}  // namespace gilab
