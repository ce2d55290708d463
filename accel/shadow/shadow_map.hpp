#pragma once
// The plain shadow map the paper compares with (S1 of Table 4): the first-hit depth D1
// of every light-space texel, rendered with the same rays as the shadow DAG's depth
// maps and looked up at the same biased point. Stored either as 32-bit floats or as
// 16-bit fixed point over the grid's depth range [0, N), rounded up so a stored depth is
// never in front of the surface (the two byte counts a shadow map is usually given with;
// one 16-bit step is N/65535 voxels, more than half a voxel above N = 32768).
#include <cstdint>
#include <span>
#include <vector>
#include "accel/shadow/light_space.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/util/stats.hpp"

namespace gilab {

class ShadowMap {
public:
    // Throws Error if resolution² × bytes per texel exceeds `memory_limit_bytes` (checked
    // before anything is allocated; 0 = half the physical memory).
    static ShadowMap build(const RayTracer& tracer, const PunctualLight& light, uint32_t resolution, int bits,
                           size_t memory_limit_bytes = 0);

    static size_t bytes_for(uint32_t resolution, int bits) { return size_t(resolution) * resolution * (bits / 8); }
    size_t bytes() const { return bytes_for(space_.resolution(), bits_); }
    int bits() const { return bits_; }
    const LightSpace& space() const { return space_; }
    double build_ms() const { return build_ms_; }

    // Stored depth of a texel in voxel units (+inf where nothing was hit).
    float depth(uint32_t x, uint32_t y) const;
    bool lit_at(const DVec3& light_coords) const;
    float visibility(const Vec3& p, const Vec3& normal, int pcf = 1) const;
    void visibility(std::span<const Vec3> points, std::span<const Vec3> normals, std::span<float> out,
                    int pcf = 1) const;

private:
    explicit ShadowMap(const LightSpace& space, int bits) : space_(space), bits_(bits) {}
    LightSpace space_;
    int bits_ = 32;
    std::vector<float> depth32_;
    std::vector<uint16_t> depth16_;  // 65535 = nothing hit
    double build_ms_ = 0;
};

}  // namespace gilab
