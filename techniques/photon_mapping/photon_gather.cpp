#include "techniques/photon_mapping/photon_gather.hpp"

#include "core/render/bsdf.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"

namespace gilab {

namespace {

constexpr int kLanes = 8;

// Σ ΔΦ over photons within r arriving from above the surface, over runs of a SoA, with
// 8 partial sums (a loop the compiler turns into SIMD; lane l takes elements l, l+8, ...
// of each run, so the sum depends only on the runs' contents and boundaries). Compiled
// twice, for AVX2 (one 8-wide vector per step) and the SSE2 baseline (two 4-wide
// vectors), chosen at load time. Each lane performs the same IEEE operations in the same
// order either way (no FMA contraction in ISO C++ mode), so the two should agree bit for
// bit; within one process only one of them is ever used. When the SoA carries first-hit
// flags the first-hit photons go to their own partial sums (the direct part).
__attribute__((target_clones("avx2", "default"))) PhotonEstimate sum_flux_runs(
    const PhotonSoAView& v, const PhotonRun* runs, size_t count, const Vec3& x, const Vec3& n, float r2,
    uint64_t& visited, uint64_t& inside) {
    alignas(32) float ar[kLanes] = {}, ag[kLanes] = {}, ab[kLanes] = {}, ac[kLanes] = {};
    alignas(32) float dr[kLanes] = {}, dg[kLanes] = {}, db[kLanes] = {};
    const float qx = x.x, qy = x.y, qz = x.z, nx = n.x, ny = n.y, nz = n.z;
    const float *px = v.x, *py = v.y, *pz = v.z, *wx = v.wx, *wy = v.wy, *wz = v.wz;
    const float *pr = v.r, *pg = v.g, *pb = v.b, *pf = v.first;
    // Branch-free lane body: masks as 0/1 factors (a photon's flux times 0 or 1 is exact,
    // and per-lane counts stay far below 2^24, so float counters are exact too).
    // (size_t indices: with 32-bit ones the compiler cannot prove that lanes are adjacent
    // in memory, since 32-bit arithmetic may wrap, and builds vectors element by element.)
    // in = 1 inside the radius; the returned weight is `in` for a photon arriving from
    // the surface's side, else 0.
    auto weight = [&](size_t j, float& in) {
        float dx = qx - px[j], dy = qy - py[j], dz = qz - pz[j];
        float d2 = dx * dx + dy * dy + dz * dz;
        float c = wx[j] * nx + wy[j] * ny + wz[j] * nz;
        in = d2 <= r2 ? 1.0f : 0.0f;
        return c > 0.0f ? in : 0.0f;
    };
    auto lane = [&](int l, size_t j) {
        float in;
        const float w = weight(j, in);
        ar[l] += w * pr[j];
        ag[l] += w * pg[j];
        ab[l] += w * pb[j];
        ac[l] += in;
    };
    // The same with the first-hit flag f ∈ {0, 1} splitting w into w·f and w − w·f (exact).
    auto lane_split = [&](int l, size_t j) {
        float in;
        const float w = weight(j, in);
        float wd = w * pf[j], wi = w - wd;
        ar[l] += wi * pr[j];
        ag[l] += wi * pg[j];
        ab[l] += wi * pb[j];
        dr[l] += wd * pr[j];
        dg[l] += wd * pg[j];
        db[l] += wd * pb[j];
        ac[l] += in;
    };
    uint64_t seen = 0;
    for (size_t k = 0; k < count; ++k) {
        size_t i = runs[k].begin;
        const size_t end = runs[k].end;
        seen += end - i;
        if (pf) {
            for (; i + kLanes <= end; i += kLanes)
                for (int l = 0; l < kLanes; ++l) lane_split(l, i + size_t(l));
            for (int l = 0; i < end; ++i, ++l) lane_split(l, i);
        } else {
            for (; i + kLanes <= end; i += kLanes)
                for (int l = 0; l < kLanes; ++l) lane(l, i + size_t(l));
            for (int l = 0; i < end; ++i, ++l) lane(l, i);
        }
    }
    PhotonEstimate sum;
    float in = 0.0f;
    for (int l = 0; l < kLanes; ++l) {
        sum.indirect.x += ar[l];
        sum.indirect.y += ag[l];
        sum.indirect.z += ab[l];
        sum.direct.x += dr[l];
        sum.direct.y += dg[l];
        sum.direct.z += db[l];
        in += ac[l];
    }
    visited += seen;
    inside += uint64_t(in);
    return sum;
}

// The part a photon's contribution belongs to.
Vec3& part_of(PhotonEstimate& e, bool first_hit) { return first_hit ? e.direct : e.indirect; }

}  // namespace

PhotonGatherer::PhotonGatherer(const PhotonMap& map, GatherMode mode, size_t k)
    : map_(map), mode_(mode), radius_(map.radius()), radius2_(radius_ * radius_),
      inv_area_(1.0f / (kPi * radius_ * radius_)), k_(k) {
    if (!(radius_ > 0.0f))
        throw Error("photon gather", "the photon map's radius must be positive (build the map with the gather radius)");
    // The fast paths (null for the other kinds): the grid's runs, the kd-tree's inline
    // queries, nanoflann's filtered kNN.
    grid_ = map.as<HashGridPhotonMap>();
    kd_ = map.as<KdTreePhotonMap>();
    nano_ = map.as<NanoflannPhotonMap>();
    if (!grid_) {  // the trees' sort keys use r-sized cells from the photons' minimum
        Bounds3 box;
        for (uint32_t i = 0; i < map.size(); ++i) box.extend(map.photon(i).position);
        key_origin_ = box.empty() ? Vec3(0) : box.min - radius_;
    }
}

PhotonEstimate PhotonGatherer::finish(const SurfaceMaterial& m, const PhotonEstimate& sum) const {
    if (m.has_glossy_lobe()) return {sum.direct * inv_area_, sum.indirect * inv_area_};
    const Vec3 f = bsdf_diffuse(m);
    return {f * (sum.direct * inv_area_), f * (sum.indirect * inv_area_)};
}

PhotonEstimate PhotonGatherer::sum_over_runs(const PhotonSoAView& v, const PhotonRun* runs, size_t count, const GatherPoint& p,
                                   GatherScratch& scratch, PhotonQueryStats& stats) const {
    const SurfaceMaterial& m = p.surface;
    const bool glossy = m.has_glossy_lobe();
    if (mode_ == GatherMode::Radius && !glossy)
        return sum_flux_runs(v, runs, count, p.position, p.normal, radius2_, stats.visited, stats.inside);

    // Scalar paths: per-photon BSDF (glossy) or the heap (kNN), same run order.
    PhotonEstimate sum;
    auto first_hit = [&](uint32_t j) { return v.first && v.first[j] != 0.0f; };
    uint64_t visited = 0, inside = 0;
    NeighborHeap& heap = scratch.heap;
    if (mode_ == GatherMode::Knn) heap.reset(k_, radius2_);
    for (size_t k = 0; k < count; ++k) {
        visited += runs[k].size();
        for (uint32_t j = runs[k].begin; j < runs[k].end; ++j) {
            float d2 = photon_distance2(p.position, v.x[j], v.y[j], v.z[j]);
            if (!(d2 <= radius2_)) continue;
            ++inside;
            Vec3 w(v.wx[j], v.wy[j], v.wz[j]);
            if (!(glm::dot(w, p.normal) > 0.0f)) continue;
            if (mode_ == GatherMode::Knn) {
                heap.offer(j, d2);
            } else {
                part_of(sum, first_hit(j)) += bsdf_eval(m, p.normal, p.wo, w) * Vec3(v.r[j], v.g[j], v.b[j]);
            }
        }
    }
    if (mode_ == GatherMode::Knn) {
        for (const PhotonNeighbor& nb : heap.items()) {
            Vec3 power(v.r[nb.index], v.g[nb.index], v.b[nb.index]);
            Vec3& part = part_of(sum, first_hit(nb.index));
            if (glossy) {
                Vec3 w(v.wx[nb.index], v.wy[nb.index], v.wz[nb.index]);
                part += bsdf_eval(m, p.normal, p.wo, w) * power;
            } else {
                part += power;
            }
        }
    }
    stats.visited += visited;
    stats.inside += inside;
    return sum;
}

PhotonEstimate PhotonGatherer::estimate_parts(const GatherPoint& p, GatherScratch& scratch,
                                              PhotonQueryStats& stats) const {
    const SurfaceMaterial& m = p.surface;
    const bool glossy = m.has_glossy_lobe();
    if (grid_) {
        ++stats.queries;
        constexpr size_t kMaxRuns = 27;  // 3×3×3 cells: the grid's cell edge is at least its radius
        PhotonRun runs[kMaxRuns];
        size_t count = 0;
        grid_->for_each_run(p.position, radius_, [&](PhotonRun r) {
            if (count == kMaxRuns)
                throw Error("photon gather", "a query met more than 27 grid cells; the grid's cells must be at "
                                             "least the gather radius");
            runs[count++] = r;
        });
        return finish(m, sum_over_runs(grid_->view(), runs, count, p, scratch, stats));
    }
    // Trees: photons come from the structure's own traversal.
    PhotonEstimate sum;
    auto front = [&](uint32_t i) { return glm::dot(map_.photon(i).wi.unpack(), p.normal) > 0.0f; };
    auto add = [&](uint32_t i) {
        const Photon& ph = map_.photon(i);
        part_of(sum, ph.first_hit()) += glossy ? bsdf_eval(m, p.normal, p.wo, ph.incoming()) * ph.power : ph.power;
    };
    if (mode_ == GatherMode::Radius) {
        auto visit = [&](uint32_t i, float) {
            if (front(i)) add(i);
        };
        if (kd_)
            kd_->for_each_in_radius(p.position, radius_, visit, stats);
        else
            map_.radius_query(p.position, radius_, visit, stats);
    } else {
        NeighborHeap& heap = scratch.heap;
        if (kd_)
            kd_->knn(p.position, k_, radius_, heap, stats, front);
        else if (nano_)
            nano_->knn_filtered(p.position, k_, radius_, heap, stats, front);
        else
            throw Error("photon gather", "no kNN filter for this structure");
        for (const PhotonNeighbor& nb : heap.items()) add(nb.index);
    }
    return finish(m, sum);
}

glm::ivec3 PhotonGatherer::cell_of(const Vec3& x) const {
    if (grid_) return grid_->cell_of(x);
    Vec3 c = glm::floor((x - key_origin_) / radius_);
    glm::ivec3 out;
    for (int a = 0; a < 3; ++a) out[a] = c[a] >= -1e9f && c[a] <= 1e9f ? int(c[a]) : -1000000000;
    return out;
}

uint64_t PhotonGatherer::sort_key(const Vec3& x, uint32_t slot) const {
    glm::ivec3 c = cell_of(x);
    if (grid_) {
        const glm::ivec3 g = grid_->grid_size();
        bool inside = c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < g.x && c.y < g.y && c.z < g.z;
        return inside ? uint64_t(grid_->hash(c)) : (kUngrouped | slot);
    }
    UVec3 u;
    for (int a = 0; a < 3; ++a) u[a] = uint32_t(std::clamp(c[a] + 1, 0, int(kMortonMaxCoordinate)));
    return morton_encode(u);
}

void PhotonGatherer::estimate_group(const glm::ivec3& cell, std::span<const GatherPoint* const> points,
                                    std::span<PhotonEstimate> out, GatherScratch& scratch,
                                    PhotonQueryStats& stats) const {
    if (!grid_) throw Error("photon gather", "tile-shared gather needs the hash grid");
    // Fetch the neighbourhood once, run by run, into the local buffer (Algorithm 1).
    PhotonSoA& local = scratch.local;
    std::vector<PhotonRun>& local_runs = scratch.local_runs;
    local_runs.clear();
    uint32_t total = 0;
    grid_->for_each_run(cell, radius_, [&](PhotonRun r) {
        local_runs.push_back({total, total + r.size()});
        total += r.size();
    });
    const PhotonSoA& src = grid_->soa();
    if (local.size() < total || local.has_first_hits() != src.has_first_hits())
        local.resize(std::max<size_t>(local.size(), total), src.has_first_hits());
    size_t k = 0;
    grid_->for_each_run(cell, radius_, [&](PhotonRun r) {
        const uint32_t dst = local_runs[k++].begin, n = r.size();
        auto copy = [&](const std::vector<float>& a, std::vector<float>& b) {
            std::copy_n(a.data() + r.begin, n, b.data() + dst);
        };
        copy(src.x, local.x), copy(src.y, local.y), copy(src.z, local.z);
        copy(src.wx, local.wx), copy(src.wy, local.wy), copy(src.wz, local.wz);
        copy(src.r, local.r), copy(src.g, local.g), copy(src.b, local.b);
        if (src.has_first_hits()) copy(src.first, local.first);
    });
    scratch.fetched += total;
    const PhotonSoAView view = PhotonSoAView::of(local);
    for (size_t i = 0; i < points.size(); ++i) {
        const GatherPoint& p = *points[i];
        ++stats.queries;
        out[i] = finish(p.surface, sum_over_runs(view, local_runs.data(), local_runs.size(), p, scratch, stats));
    }
}

}  // namespace gilab
