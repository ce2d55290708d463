#pragma once
// Density estimation (P1 eq. 1): reflected radiance at a surface point from the photons
// around it, L ≈ 1/(π r²) Σ f_r(x, ω_p, ω) ΔΦ_p, with the disk estimator over a fixed r:
// the photon map's radius (PhotonMap::radius(): the one the map was built for, which also
// sizes the hash grid's cells). The map must outlive the gatherer and not be built again
// while the gatherer is in use.
// f_r is the view-independent diffuse part ρ/π for Lambertian materials (one multiply
// after summing the flux) and the full BSDF (diffuse + glossy lobe) per photon for
// glossy ones; photons arriving from below the surface (ω_p·n ≤ 0) contribute nothing.
//
// Modes: Radius sums every photon within r (no heap); Knn keeps the k nearest within r
// in a max-heap and sums those (with the same 1/(π r²), so a full heap under-counts
// dense regions: the darkening of the paper's Fig. 8).
//
// The estimate comes in two parts: photons stored at their path's first hit (direct
// light, present only in a map built with every-hit storage) and the rest (indirect);
// each part is summed on its own, so a map without first-hit photons gives a zero
// direct part and the same indirect part, bit for bit, as a single sum.
//
// With the hash grid the sums run over contiguous runs of its structure-of-arrays in a
// fixed lane order (8 partial sums), so the result depends only on the point, whatever
// pass order (fused/split) or grouping (tile-shared) is used; estimate_group fetches a
// cell's neighbourhood once into a local buffer with the same run boundaries and so
// returns bit-identical values.
#include <cstdint>
#include <span>
#include <vector>
#include "accel/photon/hash_grid_photon_map.hpp"
#include "accel/photon/kd_tree_photon_map.hpp"
#include "accel/photon/nanoflann_photon_map.hpp"
#include "core/scene/material.hpp"

namespace gilab {

enum class GatherMode { Radius, Knn };

// Reflected radiance from the photon map, split by the bounce the photons arrived on.
struct PhotonEstimate {
    Vec3 direct{0};     // photons stored at their first hit
    Vec3 indirect{0};   // photons stored at later hits
    Vec3 total() const { return direct + indirect; }
};

struct GatherPoint {
    Vec3 position{0};
    Vec3 normal{0};       // shading normal on the viewer's side
    Vec3 wo{0};           // towards the viewer
    uint32_t material = 0;
    SurfaceMaterial surface;  // the material at the point, textures resolved
};

// Per-thread working memory.
struct GatherScratch {
    NeighborHeap heap;
    PhotonSoA local;                    // tile-shared neighbourhood copy
    std::vector<PhotonRun> local_runs;
    uint64_t fetched = 0;               // photons copied into local buffers
};

class PhotonGatherer {
public:
    // Throws Error if the map has no positive radius.
    PhotonGatherer(const PhotonMap& map, GatherMode mode, size_t k);

    // Σ f_r ΔΦ / (π r²) at p, by part, and in total.
    PhotonEstimate estimate_parts(const GatherPoint& p, GatherScratch& scratch, PhotonQueryStats& stats) const;
    Vec3 estimate(const GatherPoint& p, GatherScratch& scratch, PhotonQueryStats& stats) const {
        return estimate_parts(p, scratch, stats).total();
    }

    // Tile-shared gather (needs the hash grid): every point must lie in `cell`.
    bool supports_groups() const { return grid_ != nullptr; }
    glm::ivec3 cell_of(const Vec3& x) const;
    void estimate_group(const glm::ivec3& cell, std::span<const GatherPoint* const> points,
                        std::span<PhotonEstimate> out, GatherScratch& scratch, PhotonQueryStats& stats) const;

    // A sort key that puts points near each other next to each other. With the hash grid
    // it is the cell's hash for points in the grid (equal keys ⇔ same cell, so sorted
    // runs of equal keys are tile-shared groups) and unique (≥ 2^63, from `slot`) for
    // points outside it; otherwise the Morton code of an r-sized cell.
    uint64_t sort_key(const Vec3& x, uint32_t slot) const;
    static constexpr uint64_t kUngrouped = uint64_t(1) << 63;

    float radius() const { return radius_; }

private:
    PhotonEstimate finish(const SurfaceMaterial& m, const PhotonEstimate& sum) const;
    PhotonEstimate sum_over_runs(const PhotonSoAView& v, const PhotonRun* runs, size_t count, const GatherPoint& p,
                                 GatherScratch& scratch, PhotonQueryStats& stats) const;

    const PhotonMap& map_;
    const HashGridPhotonMap* grid_ = nullptr;
    const KdTreePhotonMap* kd_ = nullptr;
    const NanoflannPhotonMap* nano_ = nullptr;
    GatherMode mode_;
    float radius_, radius2_, inv_area_;
    size_t k_;
    Vec3 key_origin_{0};
};

}  // namespace gilab
