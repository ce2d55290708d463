#include "accel/lpv/lpv_cascades.hpp"

#include <algorithm>
#include <limits>

namespace gilab {

LpvCascades::LpvCascades(const LpvCascadeConfig& config) : config_(config) {
    for (int k = 0; k < config.cascades; ++k)
        levels_.emplace_back(LpvLattice::centred_on(Vec3(0), cell_size(k), config.resolution));
}

void LpvCascades::place(const Vec3& viewer) {
    for (int k = 0; k < count(); ++k) levels_[size_t(k)].place(LpvLattice::centred_on(viewer, cell_size(k), config_.resolution));
}

float LpvCascades::border_distance(int k, const Vec3& p) const {
    const LpvLattice& l = levels_[size_t(k)].lattice();
    const Vec3 g = l.to_grid(p);
    const float hi = float(l.resolution) - 0.5f;
    float d = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) d = std::min(d, std::min(g[a] - 0.5f, hi - g[a]));
    return d;
}

int LpvCascades::finest_containing(const Vec3& p) const {
    for (int k = 0; k < count(); ++k)
        if (border_distance(k, p) >= 0.0f) return k;
    return -1;
}

Vec3 LpvCascades::irradiance_at(int k, const Vec3& p, const Sh4& cosine) const {
    const ShRgb I = levels_[size_t(k)].sample(p);
    const float s = cell_size(k);
    const float to_radiance = 1.0f / (s * s);
    Vec3 E;
    for (int ch = 0; ch < 3; ++ch) E[ch] = std::max(0.0f, sh_dot(I[size_t(ch)], cosine) * to_radiance);
    return E;
}

Vec3 LpvCascades::irradiance_in(int k, const Vec3& p, const Vec3& n, bool gradient_dampening) const {
    const Sh4 cosine = sh_clamped_cosine(-n);
    Vec3 E = irradiance_at(k, p, cosine);
    if (!gradient_dampening) return E;
    const Vec3 half_cell = 0.5f * cell_size(k) * n;
    const Vec3 front = irradiance_at(k, p + half_cell, cosine);
    const Vec3 behind = irradiance_at(k, p - half_cell, cosine);
    for (int ch = 0; ch < 3; ++ch)
        if (behind[ch] > front[ch]) E[ch] *= front[ch] / behind[ch];
    return E;
}

Vec3 LpvCascades::irradiance(const Vec3& p, const Vec3& n, float offset_cells, bool gradient_dampening) const {
    for (int k = 0; k < count(); ++k) {
        const Vec3 q = p + offset_cells * cell_size(k) * n;
        const float d = border_distance(k, q);
        if (d < 0.0f) continue;
        const Vec3 E = irradiance_in(k, q, n, gradient_dampening);
        if (d >= kBlendCells || k + 1 == count()) return E;
        const Vec3 q_coarse = p + offset_cells * cell_size(k + 1) * n;
        if (border_distance(k + 1, q_coarse) < 0.0f) return E;
        const float w = d / kBlendCells;
        return w * E + (1.0f - w) * irradiance_in(k + 1, q_coarse, n, gradient_dampening);
    }
    return Vec3(0);
}

size_t LpvCascades::bytes() const {
    size_t b = 0;
    for (const LightPropagationVolume& v : levels_) b += v.bytes();
    return b;
}

}  // namespace gilab
