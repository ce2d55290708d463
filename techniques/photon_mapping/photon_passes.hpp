#pragma once
// Pieces the photon technique's passes share (photon_technique.cpp orchestrates,
// photon_view_pass.cpp renders one eye, photon_stereo_pass.cpp the reusing right eye).
#include <atomic>
#include <span>
#include <vector>
#include "core/rng.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"
#include "techniques/photon_mapping/primary_hit.hpp"

namespace gilab {

// The left eye's hits, kept for the right eye (stereo reuse).
struct PhotonMappingTechnique::KeptHits {
    std::vector<PrimaryHit> hits;              // one per left pixel
    std::vector<LightSampleRecord> samples;    // light_samples per left pixel
    size_t per_pixel = 0;
    std::span<const LightSampleRecord> samples_of(size_t pixel) const {
        return {samples.data() + pixel * per_pixel, per_pixel};
    }
};

// What one view's render needs beyond its camera.
struct PhotonMappingTechnique::ViewOptions {
    uint64_t view = 0;                       // light-sample stream of pixels keyed by themselves
    const EyeCamera* stream_eye = nullptr;   // stereo right eye: key by the left pixel seeing the point
    KeptHits* keep = nullptr;                // keep every hit (left eye of a reusing stereo render)
};

// The light-sample stream of a hit seen by `pixel` of view `view`: its own pixel's, or,
// when `stream_eye` is given (a stereo right eye, with the left eye), the stream of the
// left pixel that sees the same point, so both eyes draw the same samples there.
inline Rng light_sample_stream(uint64_t seed, const EyeCamera* stream_eye, const Vec3& x, uint32_t pixel,
                               uint64_t view) {
    if (stream_eye)
        if (auto q = stream_eye->pixel_of(x))
            return Rng::for_sample(seed, uint64_t(q->y) * uint64_t(stream_eye->width()) + uint64_t(q->x), 0, 0);
    return Rng::for_sample(seed, pixel, 0, view);
}

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
