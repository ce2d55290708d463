#pragma once
// Cascaded light propagation volumes (Kaplanyan & Dachsbacher 2010, §5): nested grids of
// the same resolution, cascade k with cells 2^k times the finest, all centred on the
// viewer and snapped to their own cell size. Each cascade is injected and propagated on
// its own; coarse cascades carry light further (iterations × their cell size) and cover
// what the fine ones do not.
//
// Lookup: the finest cascade whose cell centres enclose the point, blended linearly with
// the next coarser one over the last `kBlendCells` cells before its border, so no seam
// shows where the cascades meet. The point is first moved `offset_cells` of the
// cascade's cells along the surface normal: the paper's dampening of self-illumination
// (a surface's own VPLs sit in the cells around it and would otherwise light it, and
// light from behind a thin wall, trilinearly interpolated, would leak through).
// Irradiance from the intensity SH (§5): radiance L(ω) ≈ I(ω)/s² in a cell of size s,
// and E(n) = ∫ L · max(0, −n·ω) dω over directions of travel ω, one SH dot product.
//
// Gradient dampening (optional): the paper dampens the lookup by the directional
// derivative of the intensity along the normal without giving a formula; ours: the light
// a surface receives travels towards it from the side it faces, so it cannot grow into
// the surface. E is also evaluated half a cell in front (E₊) and half a cell behind (E₋);
// where E₋ > E₊ the light comes from behind (a thin wall's other side, spread by the
// trilinear lookup and the two-band SH) and E is scaled by E₊ / E₋, per channel.
#include <vector>
#include "accel/lpv/light_propagation_volume.hpp"

namespace gilab {

struct LpvCascadeConfig {
    int cascades = 3;
    int resolution = 32;          // even
    float finest_cell_size = 1.0f;
};

class LpvCascades {
public:
    static constexpr float kBlendCells = 2.0f;

    LpvCascades() = default;
    explicit LpvCascades(const LpvCascadeConfig& config);
    // Re-centres every cascade on the viewer (whole cells of its own size).
    void place(const Vec3& viewer);
    int count() const { return int(levels_.size()); }
    LightPropagationVolume& level(int k) { return levels_[size_t(k)]; }
    const LightPropagationVolume& level(int k) const { return levels_[size_t(k)]; }
    const LpvCascadeConfig& config() const { return config_; }
    float cell_size(int k) const { return config_.finest_cell_size * float(1 << k); }
    // Irradiance at p on a surface with unit normal n (0 outside every cascade).
    Vec3 irradiance(const Vec3& p, const Vec3& n, float offset_cells, bool gradient_dampening) const;
    // The finest cascade whose cell centres enclose p, or −1.
    int finest_containing(const Vec3& p) const;
    size_t bytes() const;

private:
    Vec3 irradiance_in(int k, const Vec3& p, const Vec3& n, bool gradient_dampening) const;
    Vec3 irradiance_at(int k, const Vec3& p, const Sh4& cosine) const;
    // Cells from p to the nearest border of cascade k's cell-centre box (< 0: outside).
    float border_distance(int k, const Vec3& p) const;

    LpvCascadeConfig config_;
    std::vector<LightPropagationVolume> levels_;
};

}  // namespace gilab
