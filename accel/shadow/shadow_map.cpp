#include "accel/shadow/shadow_map.hpp"
#include <algorithm>
#include <cmath>
#include "accel/shadow/light_depth_maps.hpp"
#include "accel/shadow/shadow_dag.hpp"
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "core/util/stats.hpp"

namespace gilab {

ShadowMap ShadowMap::build(const RayTracer& tracer, const PunctualLight& light, uint32_t resolution, int bits,
                           size_t memory_limit_bytes) {
    if (bits != 16 && bits != 32) throw Error("shadow map", "depth bits must be 16 or 32, not " + std::to_string(bits));
    const LightSpace space(light, tracer.frame().bounds, resolution);
    const size_t limit = memory_limit_bytes ? memory_limit_bytes : default_memory_limit_bytes();
    const size_t need = bytes_for(resolution, bits);
    if (need > limit)
        throw Error("shadow map", "a " + std::to_string(resolution) + "² map of " + std::to_string(bits) +
                                      "-bit depths needs " + std::to_string(need / 1000000) + " MB, over the " +
                                      std::to_string(limit / 1000000) + " MB memory limit");
    Stopwatch clock;
    ShadowMap map(space, bits);
    const size_t texels = size_t(resolution) * resolution;
    if (bits == 32) map.depth32_.assign(texels, kInfinity);
    else map.depth16_.assign(texels, 0xffff);
    const uint32_t tile = std::min(space.octree_size(), 1024u);
    LightDepthTile t;
    for (uint32_t y0 = 0; y0 < resolution; y0 += tile)
        for (uint32_t x0 = 0; x0 < resolution; x0 += tile) {
            t.render(tracer, space, nullptr, x0, y0, tile);
            for (uint32_t y = y0; y < std::min(y0 + tile, resolution); ++y)
                for (uint32_t x = x0; x < std::min(x0 + tile, resolution); ++x) {
                    const float d = t.d1(x, y);
                    const size_t i = size_t(y) * resolution + x;
                    if (bits == 32) {
                        map.depth32_[i] = d;
                    } else if (d < kInfinity) {
                        // Fixed point over [0, N), rounded up; 65535 means nothing hit.
                        map.depth16_[i] = uint16_t(std::clamp(std::ceil(double(d) / resolution * 65535.0), 0.0, 65534.0));
                    }
                }
        }
    map.build_ms_ = clock.elapsed_ms();
    return map;
}

float ShadowMap::depth(uint32_t x, uint32_t y) const {
    const size_t i = size_t(y) * space_.resolution() + x;
    if (bits_ == 32) return depth32_[i];
    return depth16_[i] == 0xffff ? kInfinity : float(depth16_[i] / 65535.0 * space_.resolution());
}

bool ShadowMap::lit_at(const DVec3& c) const {
    const double n = space_.resolution();
    if (!(c.x >= 0 && c.y >= 0 && c.x < n && c.y < n) || !(c.z >= 0)) return true;
    return c.z < depth(uint32_t(c.x), uint32_t(c.y));
}

float ShadowMap::visibility(const Vec3& p, const Vec3& normal, int pcf) const {
    if (!space_.faces_light(p, normal)) return 0.0f;
    return pcf_visibility(space_.lookup_coords(p, normal), pcf, [&](const DVec3& c) { return lit_at(c); });
}

void ShadowMap::visibility(std::span<const Vec3> points, std::span<const Vec3> normals, std::span<float> out,
                           int pcf) const {
    if (points.size() != normals.size() || points.size() != out.size())
        throw Error("shadow map", "batched lookup needs as many normals and outputs as points");
    parallel_for(points.size(), 4096, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) out[i] = visibility(points[i], normals[i], pcf);
    });
}

}  // namespace gilab
