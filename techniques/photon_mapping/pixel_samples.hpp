#pragma once
// Sub-pixel samples of the photon technique (settings spp, jitter). Each of a pixel's spp
// samples traces its own primary ray and draws its own light samples; all of them gather
// from the frame's one photon map. A sample's direct and indirect radiance is kept until
// every sample of its pixel is shaded, then the pixel takes their mean, summed in sample
// order in double precision as the path tracer does, so neither the thread count nor the
// pass or gather order changes a bit. With spp = 1 and no jitter the sample is the pixel
// centre and the mean is the sample itself: the image is the one-ray-per-pixel render.
//
// Random numbers follow the path tracer's scheme: sample s of pixel p in view v draws from
// Rng::for_sample(seed, p, s, v), first its jitter (two numbers, when jittered), then its
// light samples.
#include <cstdint>
#include <span>
#include <string>
#include <vector>
#include "core/scene/camera.hpp"
#include "core/util/rng.hpp"

namespace gilab {

struct PixelSampling {
    int spp = 1;
    bool jitter = false;  // default: spp > 1
};

// The most samples per pixel the technique takes.
inline constexpr int kMaxPhotonSpp = 1024;

// Where sample `sample` of pixel `pixel` looks, in pixels from the pixel's corner: its
// centre, or a uniform jitter inside it.
Vec2 sample_offset(const PixelSampling& sampling, uint64_t seed, uint32_t pixel, int sample, uint64_t view);

// The light-sample stream of sample `sample` of a hit seen by `pixel` of view `view`: its
// own stream after the jitter, or, when `stream_eye` is given (a stereo right eye, with
// the left eye), the stream of the same sample of the left pixel that sees the point, so
// both eyes draw the same light samples there.
Rng light_sample_stream(const PixelSampling& sampling, uint64_t seed, const EyeCamera* stream_eye, const Vec3& x,
                        uint32_t pixel, int sample, uint64_t view);

// Mean of one pixel's sample values, summed in order in double precision.
Vec3 sample_mean(std::span<const Vec3> samples);

// Direct and indirect radiance of every sample of a block of pixels: slot = local pixel ·
// spp + sample.
class SampleRadiance {
public:
    SampleRadiance(size_t pixels, int spp) : spp_(spp), direct_(pixels * size_t(spp)), indirect_(direct_.size()) {}
    Vec3& direct(size_t slot) { return direct_[slot]; }
    Vec3& indirect(size_t slot) { return indirect_[slot]; }
    const Vec3& direct(size_t slot) const { return direct_[slot]; }
    const Vec3& indirect(size_t slot) const { return indirect_[slot]; }
    Vec3 mean_direct(size_t pixel) const { return sample_mean(samples_of(direct_, pixel)); }
    Vec3 mean_indirect(size_t pixel) const { return sample_mean(samples_of(indirect_, pixel)); }

private:
    std::span<const Vec3> samples_of(const std::vector<Vec3>& v, size_t pixel) const {
        return {v.data() + pixel * size_t(spp_), size_t(spp_)};
    }
    int spp_;
    std::vector<Vec3> direct_, indirect_;
};

// Refuses, naming setting 'spp', a per-sample buffer of `bytes_per_sample` for every
// sample of a width × height view that exceeds the memory budget. `what` names the buffer.
void check_sample_memory(int width, int height, int spp, uint64_t bytes_per_sample, const std::string& what,
                         const std::string& where);

}  // namespace gilab
