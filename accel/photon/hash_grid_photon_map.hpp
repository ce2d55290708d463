#pragma once
// Uniform hash grid photon map (P1 §3.1). Cell edge = the gather radius r, origin = the
// minimum photon position minus one cell, and one empty layer of cells at both ends of
// every axis, so the 3×3×3 neighbourhood of any cell holding a photon needs no bounds
// checks. Cells are numbered hash = z·gx·gy + y·gx + x; photons are counting-sorted by
// cell and startIdx (prefix sums) gives cell i the range startIdx[i] .. startIdx[i+1]−1.
//
// A query visits the 27 neighbour cells through a precomputed offset table, either cell
// by cell (Cells27) or as 9 contiguous runs of three x-adjacent cells (Runs9). Queries
// whose cell is outside the grid's interior, or with a radius larger than the cell,
// take a bounds-checked path that clamps the cell range (empty or partial results).
//
// The grid depends on r: build again when r changes. The cell edge is r·(1 + 2⁻¹⁶): the
// extra 0.0015 % guarantees that a photon within r of x (as photon_distance2 decides)
// never lies two cells away from x after floating-point rounding.
#include <array>
#include <cstdint>
#include <vector>
#include "accel/photon/photon_map.hpp"

namespace gilab {

enum class HashQuery { Cells27, Runs9 };
const char* to_string(HashQuery mode);  // "cells27", "runs9"
HashQuery parse_hash_query(const std::string& name, const std::string& where);

class HashGridPhotonMap final : public PhotonMap {
public:
    static constexpr PhotonMapKind kKind = PhotonMapKind::HashGrid;
    explicit HashGridPhotonMap(HashQuery mode = HashQuery::Runs9) : mode_(mode) {}
    PhotonMapKind kind() const override { return kKind; }
    size_t size() const override { return photons_.size(); }
    const Photon& photon(uint32_t index) const override { return photons_[index]; }
    uint32_t original_index(uint32_t index) const override { return original_[index]; }
    size_t memory_bytes() const override;

    void radius_query(const Vec3& x, float r, Visitor visit, PhotonQueryStats& stats) const override {
        for_each_in_radius(x, r, visit, stats);
    }
    void knn_query(const Vec3& x, size_t k, float max_r, NeighborHeap& heap, PhotonQueryStats& stats) const override {
        knn(x, k, max_r, heap, stats);
    }

    HashQuery query_mode() const { return mode_; }
    void set_query_mode(HashQuery mode) { mode_ = mode; }
    float cell_size() const { return cell_; }
    const Vec3& origin() const { return origin_; }
    const glm::ivec3& grid_size() const { return size_; }
    size_t cell_count() const { return start_.empty() ? 0 : start_.size() - 1; }
    const std::vector<uint32_t>& start_index() const { return start_; }
    // Positions, incoming directions, power and first-hit flags in the sorted (cell) order.
    const PhotonSoA& soa() const { return soa_; }
    PhotonSoAView view() const { return PhotonSoAView::of(soa_); }

    static constexpr size_t kDefaultMaxCells = size_t(1) << 26;
    void set_max_cells(size_t cells) { max_cells_ = cells; }

    // Integer cell coordinates of a point (any point; clamped to ±2^30 so far-away and
    // non-finite points get a cell with no photons around it).
    glm::ivec3 cell_of(const Vec3& x) const;
    uint32_t hash(const glm::ivec3& c) const { return uint32_t((c.z * size_.y + c.y) * size_.x + c.x); }

    // Calls run(PhotonRun) for the storage ranges that cover every photon within r of
    // any point of `cell` (r ≤ cell edge: the 3×3×3 neighbourhood, 27 or 9 runs in a
    // fixed order; larger r: the ⌈r/cell⌉ neighbourhood, one run per cell row or cell).
    // Empty runs are skipped. The order depends only on the cell.
    template <typename RunFn>
    void for_each_run(const glm::ivec3& cell, float r, RunFn&& run) const {
        if (start_.empty()) return;
        const uint32_t* s = start_.data();
        if (r <= cell_ && interior(cell)) {  // the paper's fast path: no bounds checks
            const int base = int(hash(cell));
            if (mode_ == HashQuery::Runs9) {
                for (int j = 0; j < 9; ++j) {
                    int h = base + offsets9_[size_t(j)];
                    uint32_t b = s[h], e = s[h + 3];
                    if (e > b) run(PhotonRun{b, e});
                }
            } else {
                for (int j = 0; j < 27; ++j) {
                    int h = base + offsets27_[size_t(j)];
                    uint32_t b = s[h], e = s[h + 1];
                    if (e > b) run(PhotonRun{b, e});
                }
            }
            return;
        }
        bounded_runs(cell, r, run);
    }
    template <typename RunFn>
    void for_each_run(const Vec3& x, float r, RunFn&& run) const {
        for_each_run(cell_of(x), r, run);
    }

    template <typename Visit>
    void for_each_in_radius(const Vec3& x, float r, Visit&& visit, PhotonQueryStats& stats) const {
        ++stats.queries;
        if (!(r >= 0.0f)) return;
        const float r2 = r * r;
        const float *px = soa_.x.data(), *py = soa_.y.data(), *pz = soa_.z.data();
        uint64_t visited = 0, inside = 0;
        for_each_run(x, r, [&](PhotonRun run) {
            visited += run.size();
            for (uint32_t i = run.begin; i < run.end; ++i) {
                float d2 = photon_distance2(x, px[i], py[i], pz[i]);
                if (d2 <= r2) {
                    ++inside;
                    visit(i, d2);
                }
            }
        });
        stats.visited += visited;
        stats.inside += inside;
    }

    template <typename Accept = std::nullptr_t>
    void knn(const Vec3& x, size_t k, float max_r, NeighborHeap& heap, PhotonQueryStats& stats,
             Accept accept = nullptr) const {
        heap.reset(k, max_r * max_r);
        for_each_in_radius(x, max_r, [&](uint32_t i, float d2) {
            if constexpr (std::is_same_v<Accept, std::nullptr_t>) {
                heap.offer(i, d2);
            } else {
                if (accept(i)) heap.offer(i, d2);
            }
        }, stats);
    }

protected:
    // Throws Error if r is not positive and finite, or the grid would need more than
    // max_cells cells (r far too small for the photons' extent).
    void build_structure(std::vector<Photon> photons, float radius) override;

private:
    bool interior(const glm::ivec3& c) const {
        return c.x >= 1 && c.y >= 1 && c.z >= 1 && c.x <= size_.x - 2 && c.y <= size_.y - 2 && c.z <= size_.z - 2;
    }
    template <typename RunFn>
    void bounded_runs(const glm::ivec3& cell, float r, RunFn&& run) const {
        if (!(r >= 0.0f)) return;
        // Cells within reach of the centre cell; huge radii clamp to the grid below.
        // (Slightly over-reached so rounding at an exact multiple of the cell cannot miss.)
        const int reach = int(std::min(std::ceil(r * (1.0f + 0x1p-20f) / cell_), float(1 << 20)));
        glm::ivec3 lo, hi;
        for (int a = 0; a < 3; ++a) {
            int64_t l = int64_t(cell[a]) - reach, h = int64_t(cell[a]) + reach;
            lo[a] = int(std::max<int64_t>(l, 0));
            hi[a] = int(std::min<int64_t>(h, size_[a] - 1));
            if (lo[a] > hi[a]) return;  // the neighbourhood misses the grid
        }
        const uint32_t* s = start_.data();
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y) {
                if (mode_ == HashQuery::Runs9) {
                    uint32_t b = s[hash({lo.x, y, z})], e = s[hash({hi.x, y, z}) + 1];
                    if (e > b) run(PhotonRun{b, e});
                } else {
                    for (int xx = lo.x; xx <= hi.x; ++xx) {
                        uint32_t h = hash({xx, y, z});
                        if (s[h + 1] > s[h]) run(PhotonRun{s[h], s[h + 1]});
                    }
                }
            }
    }

    HashQuery mode_;
    float cell_ = 0;
    double inv_cell_ = 0;
    Vec3 origin_{0};
    glm::ivec3 size_{0};
    size_t max_cells_ = kDefaultMaxCells;
    std::array<int, 9> offsets9_{};
    std::array<int, 27> offsets27_{};
    std::vector<uint32_t> start_;      // cell_count + 1 prefix sums
    std::vector<Photon> photons_;      // sorted by cell
    std::vector<uint32_t> original_;
    PhotonSoA soa_;
};

}  // namespace gilab
