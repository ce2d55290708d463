#include "accel/vct/fragment_voxelizer.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include "core/util/error.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/box_clip.hpp"

namespace gilab {

const char* face_name(int face) {
    static const char* names[kFaceCount] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
    return face >= 0 && face < kFaceCount ? names[face] : "?";
}

namespace {

constexpr int kBrick = 8;  // voxels per brick side: one task fuses one brick
// Per-voxel running sums, per axis: faces +k and −k weigh a fragment alike (A·|n_k|);
// they differ only in the normal's orientation and in which side emits.
struct AxisSums {
    double weight = 0;
    DVec3 albedo{0}, normal{0}, position{0};  // normal oriented towards +k
    DVec3 emission[2] = {DVec3(0), DVec3(0)};  // emitted towards +k, towards −k
};
struct VoxelSums {
    AxisSums axis[3];
};

}  // namespace

FragmentVoxelizer::FragmentVoxelizer(const SceneFrame& frame, const std::vector<Material>& materials,
                                     const std::vector<bool>& include_mesh) {
    for (size_t m = 0; m < frame.meshes.size(); ++m) {
        if (!include_mesh.empty() && (m >= include_mesh.size() || !include_mesh[m])) continue;
        const WorldMesh& mesh = frame.meshes[m];
        for (size_t t = 0; t < mesh.triangles.size(); ++t) {
            const UVec3& idx = mesh.triangles[t];
            uint32_t id = t < mesh.material_ids.size() ? mesh.material_ids[t] : 0;
            if (id >= materials.size())
                throw Error("fragment voxelizer", "mesh " + std::to_string(m) + " triangle " + std::to_string(t) +
                                                      " uses material " + std::to_string(id) + " but there are " +
                                                      std::to_string(materials.size()));
            Triangle tri;
            for (int k = 0; k < 3; ++k) {
                if (idx[k] >= mesh.positions.size())
                    throw Error("fragment voxelizer", "mesh " + std::to_string(m) + " triangle " +
                                                          std::to_string(t) + " refers to a missing vertex");
                const Vec3& p = mesh.positions[idx[k]];
                if (!is_finite(p))
                    throw Error("fragment voxelizer",
                                "mesh " + std::to_string(m) + " has a non-finite vertex position");
                tri.p[k] = DVec3(p);
            }
            DVec3 c = glm::cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
            double len = glm::length(c);
            if (!(len > 0) || !std::isfinite(len)) continue;  // zero area: covers nothing
            tri.normal = c / len;
            tri.area = 0.5 * len;
            tri.centroid = (tri.p[0] + tri.p[1] + tri.p[2]) / 3.0;
            tri.lo = glm::min(tri.p[0], glm::min(tri.p[1], tri.p[2]));
            tri.hi = glm::max(tri.p[0], glm::max(tri.p[1], tri.p[2]));
            tri.albedo = materials[id].albedo;
            tri.emission = materials[id].emission;
            if (materials[id].has_textures()) {
                TexturedCorners tc;
                tc.material = id;
                for (int k = 0; k < kUvSetCount; ++k) {
                    const std::vector<Vec2>& set = mesh.uv_set(k);
                    if (set.size() != mesh.positions.size()) continue;
                    for (int c = 0; c < 3; ++c) tc.uv[k][c] = set[idx[c]];
                    const Vec2 d1 = tc.uv[k][1] - tc.uv[k][0], d2 = tc.uv[k][2] - tc.uv[k][0];
                    tc.uv_per_length[k] = float(std::sqrt(std::abs(double(d1.x) * d2.y - double(d1.y) * d2.x) / len));
                }
                tri.textured = int32_t(textured_.size());
                textured_.push_back(tc);
            }
            for (int k = 0; k < 3; ++k) bounds_.extend(Vec3(tri.p[k]));
            triangles_.push_back(tri);
        }
    }
    if (!textured_.empty()) materials_ = materials;
}

void FragmentVoxelizer::texture_fragment(const Triangle& t, const DVec3& centroid, double area, Vec3& albedo,
                                         Vec3& emission, double& coverage) const {
    const TexturedCorners& tc = textured_[size_t(t.textured)];
    const Material& m = materials_[tc.material];
    // Barycentrics of the centroid (it lies in the triangle's plane).
    const DVec3 e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0], d = centroid - t.p[0];
    const double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
    const double den = d11 * d22 - d12 * d12;
    double b1 = 0, b2 = 0;
    if (den > 0) {
        b1 = (d22 * glm::dot(d, e1) - d12 * glm::dot(d, e2)) / den;
        b2 = (d11 * glm::dot(d, e2) - d12 * glm::dot(d, e1)) / den;
    }
    const float w1 = float(b1), w2 = float(b2), w0 = 1.0f - w1 - w2;
    const float size = float(std::sqrt(area));
    auto at = [&](const TextureRef& ref, float& footprint) {
        const int k = std::clamp(ref.uv_set, 0, kUvSetCount - 1);
        footprint = size * tc.uv_per_length[k];
        return w0 * tc.uv[k][0] + w1 * tc.uv[k][1] + w2 * tc.uv[k][2];
    };
    float footprint = 0;
    if (m.albedo_texture) {
        const Vec2 uv = at(m.albedo_texture, footprint);
        albedo = t.albedo * Vec3(m.albedo_texture.sample(uv, footprint));
    }
    if (m.emission_texture && m.is_emissive()) {
        const Vec2 uv = at(m.emission_texture, footprint);
        emission = t.emission * Vec3(m.emission_texture.sample(uv, footprint));
    }
    if (m.alpha_tested()) {
        if (!m.alpha_texture) {
            coverage = m.alpha >= m.alpha_cutoff ? 1.0 : 0.0;
        } else {
            const Vec2 uv = at(m.alpha_texture, footprint);
            const MipMap& img = *m.alpha_texture.image;
            const float lod = footprint > 0 ? img.level_for_footprint(footprint * m.alpha_texture.transform.max_stretch()) : 0;
            const float a = m.alpha * m.alpha_texture.sample(uv, footprint).w;
            coverage = lod <= 0.0f ? (a >= m.alpha_cutoff ? 1.0 : 0.0) : std::clamp(double(a), 0.0, 1.0);
        }
    }
}

std::vector<AnisotropicVoxel> FragmentVoxelizer::voxelize(const VoxelLattice& lattice, const VoxelBox& region,
                                                          FragmentVoxelizeStats* stats) const {
    Stopwatch clock;
    FragmentVoxelizeStats local_stats;
    std::vector<std::vector<AnisotropicVoxel>> results;
    run(lattice, std::span<const VoxelBox>(&region, 1), VoxelBox{}, local_stats,
        [&](size_t groups) { results.resize(groups); },
        [&](size_t group, const AnisotropicVoxel& v) { results[group].push_back(v); });
    size_t total = 0;
    for (const auto& l : results) total += l.size();
    std::vector<AnisotropicVoxel> out;
    out.reserve(total);
    for (auto& l : results) out.insert(out.end(), l.begin(), l.end());
    std::sort(out.begin(), out.end(), [](const AnisotropicVoxel& a, const AnisotropicVoxel& b) {
        if (a.coord.z != b.coord.z) return a.coord.z < b.coord.z;
        if (a.coord.y != b.coord.y) return a.coord.y < b.coord.y;
        return a.coord.x < b.coord.x;
    });
    local_stats.ms = clock.elapsed_ms();
    if (stats) *stats = local_stats;
    return out;
}

void FragmentVoxelizer::voxelize_each(const VoxelLattice& lattice, const VoxelBox& region, const VoxelSink& emit,
                                      FragmentVoxelizeStats* stats, const VoxelBox& exclude) const {
    voxelize_each(lattice, std::span<const VoxelBox>(&region, 1), emit, stats, exclude);
}

void FragmentVoxelizer::voxelize_each(const VoxelLattice& lattice, std::span<const VoxelBox> boxes,
                                      const VoxelSink& emit, FragmentVoxelizeStats* stats,
                                      const VoxelBox& exclude) const {
    Stopwatch clock;
    FragmentVoxelizeStats local_stats;
    run(lattice, boxes, exclude, local_stats, [](size_t) {}, [&](size_t, const AnisotropicVoxel& v) { emit(v); });
    local_stats.ms = clock.elapsed_ms();
    if (stats) *stats = local_stats;
}

void FragmentVoxelizer::run(const VoxelLattice& lattice, std::span<const VoxelBox> all_boxes,
                            const VoxelBox& exclude, FragmentVoxelizeStats& stats,
                            const std::function<void(size_t)>& on_groups, const GroupSink& sink) const {
    const double w = lattice.voxel_size;
    if (!(w > 0) || !std::isfinite(w))
        throw Error("fragment voxelizer", "voxel size must be positive and finite, got " + std::to_string(w));
    std::vector<VoxelBox> boxes;
    VoxelBox region{IVec3(std::numeric_limits<int>::max()), IVec3(std::numeric_limits<int>::min())};
    for (const VoxelBox& b : all_boxes)
        if (!b.empty()) {
            boxes.push_back(b);
            region.begin = glm::min(region.begin, b.begin);
            region.end = glm::max(region.end, b.end);
        }
    auto in_boxes = [&](const IVec3& v) {
        for (const VoxelBox& b : boxes)
            if (b.contains(v)) return true;
        return false;
    };
    if (boxes.empty() || triangles_.empty()) {
        on_groups(0);
        return;
    }
    const DVec3 A = lattice.anchor;
    const DVec3 region_lo = A + DVec3(region.begin) * w;
    const DVec3 region_hi = A + DVec3(region.end) * w;
    const IVec3 dims = region.end - region.begin;
    const IVec3 bricks = (dims + IVec3(kBrick - 1)) / kBrick;

    auto voxel_range = [&](const Triangle& t, IVec3& lo, IVec3& hi) {
        for (int k = 0; k < 3; ++k) {
            double a = std::floor((t.lo[k] - A[k]) / w), b = std::floor((t.hi[k] - A[k]) / w);
            lo[k] = int(std::clamp(a, double(region.begin[k]), double(region.end[k] - 1)));
            hi[k] = int(std::clamp(b, double(region.begin[k]), double(region.end[k] - 1)));
        }
    };

    // 1. (brick, triangle) pairs, sorted so every brick sees its triangles in index order.
    struct Pair {
        uint32_t brick, triangle;
        bool operator<(const Pair& o) const { return brick != o.brick ? brick < o.brick : triangle < o.triangle; }
    };
    tbb::enumerable_thread_specific<std::vector<Pair>> local_pairs;
    std::atomic<uint64_t> used{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles_.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
        auto& pairs = local_pairs.local();
        uint64_t n = 0;
        for (size_t i = r.begin(); i < r.end(); ++i) {
            const Triangle& t = triangles_[i];
            if (t.lo.x > region_hi.x || t.lo.y > region_hi.y || t.lo.z > region_hi.z || t.hi.x < region_lo.x ||
                t.hi.y < region_lo.y || t.hi.z < region_lo.z)
                continue;
            IVec3 lo, hi;
            voxel_range(t, lo, hi);
            if (exclude.contains(lo) && exclude.contains(hi)) continue;  // wholly in the excluded box
            const size_t before = pairs.size();
            for (const VoxelBox& b : boxes) {
                const IVec3 l = glm::max(lo, b.begin), h = glm::min(hi, b.end - IVec3(1));
                if (l.x > h.x || l.y > h.y || l.z > h.z) continue;
                IVec3 blo = (l - region.begin) / kBrick, bhi = (h - region.begin) / kBrick;
                for (int z = blo.z; z <= bhi.z; ++z)
                    for (int y = blo.y; y <= bhi.y; ++y)
                        for (int x = blo.x; x <= bhi.x; ++x)
                            pairs.push_back({uint32_t((z * bricks.y + y) * bricks.x + x), uint32_t(i)});
            }
            n += pairs.size() != before;
        }
        used += n;
    });
    std::vector<Pair> pairs;
    for (auto& p : local_pairs) pairs.insert(pairs.end(), p.begin(), p.end());
    tbb::parallel_sort(pairs.begin(), pairs.end());
    if (boxes.size() > 1)  // a triangle may have reached a brick through two boxes
        pairs.erase(std::unique(pairs.begin(), pairs.end(),
                                [](const Pair& a, const Pair& b) { return a.brick == b.brick && a.triangle == b.triangle; }),
                    pairs.end());
    std::vector<size_t> group_begin;
    for (size_t i = 0; i < pairs.size(); ++i)
        if (i == 0 || pairs[i].brick != pairs[i - 1].brick) group_begin.push_back(i);
    const size_t groups = group_begin.size();
    group_begin.push_back(pairs.size());

    // 2. Each brick: clip its triangles against its voxels, fuse, finalise.
    on_groups(groups);
    std::atomic<uint64_t> clips_total{0}, fragments_total{0}, voxels_total{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, groups, 1), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<int> slot(size_t(kBrick * kBrick * kBrick));
        std::vector<VoxelSums> sums;
        for (size_t g = r.begin(); g < r.end(); ++g) {
            const uint32_t b = pairs[group_begin[g]].brick;
            const IVec3 bc(int(b % uint32_t(bricks.x)), int((b / uint32_t(bricks.x)) % uint32_t(bricks.y)),
                           int(b / uint32_t(bricks.x * bricks.y)));
            const IVec3 brick_lo = region.begin + bc * kBrick;
            const IVec3 brick_hi = glm::min(brick_lo + IVec3(kBrick), region.end);  // exclusive
            std::fill(slot.begin(), slot.end(), -1);
            sums.clear();
            uint64_t clips = 0, fragments = 0;
            for (size_t p = group_begin[g]; p < group_begin[g + 1]; ++p) {
                const Triangle& t = triangles_[pairs[p].triangle];
                IVec3 lo, hi;
                voxel_range(t, lo, hi);
                lo = glm::max(lo, brick_lo);
                hi = glm::min(hi, brick_hi - IVec3(1));
                const DVec3 an = glm::abs(t.normal);
                const double radius = 0.5 * w * (an.x + an.y + an.z) * (1 + 1e-9);
                // An axis-aligned triangle lying in a plane of the lattice belongs to the voxel above it.
                int plane_axis = -1;
                double plane_value = 0;
                for (int k = 0; k < 3; ++k)
                    if (an[k] > 1.0 - 1e-12) {
                        plane_axis = k;
                        plane_value = (t.p[0][k] - A[k]) / w;
                    }
                for (int z = lo.z; z <= hi.z; ++z)
                    for (int y = lo.y; y <= hi.y; ++y)
                        for (int x = lo.x; x <= hi.x; ++x) {
                            const IVec3 v(x, y, z);
                            if (exclude.contains(v) || (boxes.size() > 1 && !in_boxes(v))) continue;
                            const DVec3 vmin = A + DVec3(v) * w;
                            const DVec3 vmax = A + DVec3(v + IVec3(1)) * w;
                            if (plane_axis >= 0 && std::abs(plane_value - double(v[plane_axis] + 1)) <= 1e-9) continue;
                            const DVec3 centre = 0.5 * (vmin + vmax);
                            if (std::abs(glm::dot(t.normal, centre - t.p[0])) > radius) continue;
                            double area = 0;
                            DVec3 centroid(0);
                            if (glm::all(glm::greaterThanEqual(t.lo, vmin)) && glm::all(glm::lessThanEqual(t.hi, vmax))) {
                                area = t.area;  // wholly inside: nothing to clip
                                centroid = t.centroid;
                            } else {
                                ++clips;
                                const BoxPiece piece = clip_triangle_to_box(t.p, t.normal, vmin, vmax);
                                if (!(piece.area > 0)) continue;
                                area = piece.area;
                                centroid = piece.centroid;
                            }
                            Vec3 albedo = t.albedo, emission = t.emission;
                            if (t.textured >= 0) {
                                double coverage = 1;
                                texture_fragment(t, centroid, area, albedo, emission, coverage);
                                area *= coverage;
                                if (!(area > 0)) continue;  // only transparent texels reach this voxel
                            }
                            ++fragments;
                            const IVec3 l = v - brick_lo;
                            int& s = slot[size_t((l.z * kBrick + l.y) * kBrick + l.x)];
                            if (s < 0) {
                                s = int(sums.size());
                                sums.emplace_back();
                            }
                            VoxelSums& vs = sums[size_t(s)];
                            for (int k = 0; k < 3; ++k) {
                                const double nk = t.normal[k];
                                const double weight = area * std::abs(nk);
                                if (!(weight > 0)) continue;
                                AxisSums& as = vs.axis[k];
                                as.weight += weight;
                                as.albedo += weight * DVec3(albedo);
                                as.normal += (nk > 0 ? weight : -weight) * t.normal;
                                as.emission[nk > 0 ? 0 : 1] += weight * DVec3(emission);
                                as.position += weight * centroid;
                            }
                        }
            }
            clips_total += clips;
            fragments_total += fragments;
            uint64_t voxels_here = 0;
            const double voxel_area = w * w;
            for (int z = brick_lo.z; z < brick_hi.z; ++z)
                for (int y = brick_lo.y; y < brick_hi.y; ++y)
                    for (int x = brick_lo.x; x < brick_hi.x; ++x) {
                        const IVec3 l = IVec3(x, y, z) - brick_lo;
                        int s = slot[size_t((l.z * kBrick + l.y) * kBrick + l.x)];
                        if (s < 0) continue;
                        AnisotropicVoxel voxel;
                        voxel.coord = IVec3(x, y, z);
                        for (int f = 0; f < kFaceCount; ++f) {
                            const AxisSums& as = sums[size_t(s)].axis[face_axis(f)];
                            if (!(as.weight > 0)) continue;
                            const double sign = face_sign(f);
                            VoxelFaceData& d = voxel.faces[size_t(f)];
                            d.opacity = float(std::min(1.0, as.weight / voxel_area));
                            d.albedo = Vec3(as.albedo / as.weight);
                            double nl = glm::length(as.normal);
                            d.normal = nl > 0 ? Vec3(sign * as.normal / nl) : face_direction(f);
                            d.emission = Vec3(as.emission[f & 1] / as.weight);
                            d.position = Vec3(as.position / as.weight);
                        }
                        if (!voxel.empty()) {
                            ++voxels_here;
                            sink(g, voxel);
                        }
                    }
            voxels_total += voxels_here;
        }
    });
    stats.triangles = used;
    stats.clips = clips_total;
    stats.fragments = fragments_total;
    stats.voxels = voxels_total;
}

}  // namespace gilab
