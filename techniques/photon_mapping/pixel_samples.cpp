#include "techniques/photon_mapping/pixel_samples.hpp"

#include "core/util/memory_budget.hpp"

namespace gilab {

Vec2 sample_offset(const PixelSampling& sampling, uint64_t seed, uint32_t pixel, int sample, uint64_t view) {
    if (!sampling.jitter) return Vec2(0.5f);
    return Rng::for_sample(seed, pixel, uint64_t(sample), view).uniform2();
}

Rng light_sample_stream(const PixelSampling& sampling, uint64_t seed, const EyeCamera* stream_eye, const Vec3& x,
                        uint32_t pixel, int sample, uint64_t view) {
    uint64_t key_pixel = pixel, key_view = view;
    if (stream_eye)
        if (auto q = stream_eye->pixel_of(x))
            key_pixel = uint64_t(q->y) * uint64_t(stream_eye->width()) + uint64_t(q->x), key_view = 0;
    Rng rng = Rng::for_sample(seed, key_pixel, uint64_t(sample), key_view);
    // The jitter comes first in every sample's stream; skipping it lines the light
    // samples up with those of the pixel the stream belongs to.
    if (sampling.jitter) rng.uniform2();
    return rng;
}

Vec3 sample_mean(std::span<const Vec3> samples) {
    DVec3 sum(0.0);
    for (const Vec3& v : samples) sum += DVec3(v);
    return Vec3(sum * (1.0 / double(samples.size())));
}

void check_sample_memory(int width, int height, int spp, uint64_t bytes_per_sample, const std::string& what,
                         const std::string& where) {
    const uint64_t samples = MemoryBudget::times(uint64_t(width) * uint64_t(height), uint64_t(spp));
    MemoryBudget::check(MemoryBudget::times(samples, bytes_per_sample),
                        "setting 'spp' = " + std::to_string(spp) + " at " + std::to_string(width) + "x" +
                            std::to_string(height) + " (" + what + ", " + std::to_string(bytes_per_sample) +
                            " B per sample)",
                        where);
}

}  // namespace gilab
