#pragma once
// Voxel cone tracing with the cascade cone filter (P3 §1.2).
//
// A cone marches from its apex; at distance l its footprint is d = max(2·l·tan β, w₀)
// (β the half aperture, w₀ the finest voxel size). Eq. 2 picks the level whose voxel
// width matches the footprint — we read it as lod = log2(d / w₀), i.e. voxel width
// w₀·2^lod = d — and the sample is further pushed to the finest level whose region
// contains it (far from the viewer only coarse cascades exist). The level is addressed
// directly (no tree walk); samples are trilinear within one level: the position is
// clamped to the centres of the level's border voxels, so a sample never blends across a
// level border or wraps around the toroidal storage (optionally, fractional levels blend
// the two nearest levels). The three faces turned towards the apex are blended by the
// squared direction components; a sample whose eight texels the level's occupancy map
// marks empty reads nothing. Texels are RGBA16F (accel/vct/half_rgba.hpp), weighted four
// channels at a time (SSE2), or two texels' eight at a time where the CPU has AVX2, F16C
// and FMA (ConeKernel). Samples are composited front to back (eq. 3 on premultiplied
// colour: c += (1 − α)·c₂, α += (1 − α)·α₂; the paper's "c = αc + …" as printed would
// scale earlier samples down and lose energy); the step is a fraction of the sampled
// level's voxel, and optionally the opacity is corrected for it,
// α' = 1 − (1 − α)^(step / voxel width). A cone leaving the scene's bounding box (its
// footprint wholly outside) stops. Ambient occlusion follows eq. 4:
// ao += (1 − ao)·α / (1 + λ·r), r the cone radius at the sample in finest-voxel units.
//
// Thin surfaces are stored two-sided (each face sees the side turned towards it), so a
// cone leaving a surface could see that surface's own dark back side through the wide
// trilinear footprint of a coarse level; the optional clip plane (the surface's tangent
// plane) removes voxels behind it and the back-facing faces of voxels it cuts.
#include <algorithm>
#include <span>
#include <vector>
#include "accel/vct/anisotropic_voxel.hpp"
#include "accel/vct/cascaded_voxel_texture.hpp"
#include "accel/vct/dense_mip_texture.hpp"
#include "accel/vct/half_rgba.hpp"
#include "core/util/math.hpp"

namespace gilab {

// The instructions a sample is computed with: `portable` (SSE2, every x86-64; scalar
// elsewhere) or `avx2` (AVX2 + FMA + F16C, chosen at run time where the CPU has them).
// Both compute the same sums, in another order and with fused multiply-adds, so they
// round differently (about 1e-6 relative): images are bit-identical at any thread count
// on one machine, not across kernels.
enum class ConeKernel { portable, avx2 };
ConeKernel best_cone_kernel();
const char* to_string(ConeKernel kernel);

// One level of a voxel structure as the cone tracer reads it.
struct ConeLevel {
    const HalfRGBA* data = nullptr; // cell of face 0, texel (0, 0, 0)
    const uint64_t* occupancy = nullptr;  // a bit per texel, see CascadedVoxelTexture::refresh_occupancy
    size_t face_stride = 1, x_stride = kFaceCount, row_stride = 0, slice_stride = 0;  // in cells
    size_t occupancy_row = 0, occupancy_slice = 0;  // in texels (x stride 1)
    IVec3 origin{0};                // region [origin, origin + size)
    int size = 0;
    int wrap_mask = -1;             // R − 1 for toroidal storage, all ones for linear
    float voxel_size = 1, inv_voxel_size = 1;
};

// A read-only view of one radiance buffer of a cascade texture or a dense mip chain.
class VoxelConeView {
public:
    static VoxelConeView cascade(const CascadedVoxelTexture& texture, const std::vector<HalfRGBA>& buffer);
    static VoxelConeView dense(const DenseMipTexture& texture, const std::vector<std::vector<HalfRGBA>>& buffer);
    // Any layout: levels as given (nested: each level has its own region, cascades).
    static VoxelConeView of_levels(const Vec3& anchor, bool nested, std::vector<ConeLevel> levels);

    int level_count() const { return int(levels_.size()); }
    float base_voxel_size() const { return levels_.empty() ? 1.0f : levels_[0].voxel_size; }
    const Vec3& anchor() const { return anchor_; }  // world position of voxel (0, 0, 0)'s corner
    bool nested() const { return nested_; }         // cascades (own regions) or mips (level 0's region)
    const ConeLevel& level(int k) const { return levels_[size_t(k)]; }
    // Finest level whose region holds p at least `margin` voxels inside; -1 if none.
    int finest_level_containing(const Vec3& p, float margin = 1.0f) const {
        return level_containing(p, 0, margin);
    }
    // The finest level from `from` up whose region holds p `margin` voxels inside (the
    // mips of a dense texture share level 0's region); -1 if none.
    int level_containing(const Vec3& p, int from, float margin = 1.0f) const;
    // Trilinear, face-weighted sample of one level (position clamped into the level).
    // With a plane (n, d), voxels whose box reaches n·x ≤ d count as empty.
    Vec4 sample_level(int level, const Vec3& p, const FaceWeights& faces, const Vec4* plane = nullptr,
                      ConeKernel kernel = best_cone_kernel()) const;

private:
    bool contains(const ConeLevel& l, const Vec3& p, float margin) const {
        const Vec3 q = (p - anchor_) * l.inv_voxel_size - Vec3(l.origin);
        const float hi = float(l.size) - margin;
        return q.x >= margin && q.y >= margin && q.z >= margin && q.x < hi && q.y < hi && q.z < hi;
    }
    Vec3 anchor_{0};
    bool nested_ = true;            // cascades: each level has its own region; mips share one
    std::vector<ConeLevel> levels_;
};

inline int VoxelConeView::level_containing(const Vec3& p, int from, float margin) const {
    const int n = level_count();
    if (n == 0) return -1;
    from = std::clamp(from, 0, n - 1);
    if (!nested_) return contains(levels_[0], p, margin) ? from : -1;
    // If `from` holds p, the finest level holding p is `from` or a finer one: either way
    // the answer is `from`.
    if (contains(levels_[size_t(from)], p, margin)) return from;
    for (int k = 0; k < n; ++k)
        if (contains(levels_[size_t(k)], p, margin)) return std::max(k, from);
    return -1;
}

struct Cone {
    Vec3 origin{0};
    Vec3 direction{0, 0, 1};        // unit
    float tan_half_angle = 0.5f;
};

struct ConeOptions {
    float step = 0.25f;             // step = (voxel size of the level sampled) × step
    float start = 1.0f;             // first sample distance (world units)
    float max_distance = kInfinity;
    float ao_lambda = 0.1f;         // eq. 4's λ, per finest voxel of cone radius
    float opacity_cutoff = 0.99f;   // stop once the cone is this opaque
    bool blend_levels = true;       // fractional levels blend the two nearest (off: the finer one)
    bool correct_opacity = false;   // α' = 1 − (1 − α)^(step / voxel); off: eq. 3 as printed
    float lod_bias = 0.0f;          // added to eq. 2's level (negative: sharper, more samples)
    // The tangent plane of the surface the cone leaves (n·x = d): voxels touching it or
    // behind it are skipped, so a cone never sees its own surface (or that surface's
    // dark back side) through the wide trilinear footprint of a coarse level.
    bool clip = false;
    Vec4 clip_plane{0};
    // The scene's bounding box: a cone whose footprint has left it sees nothing more.
    Bounds3 bounds;
};

struct ConeResult {
    Vec3 radiance{0};               // composited incoming radiance along the cone
    float opacity = 0;              // composited opacity (eq. 3)
    float occlusion = 0;            // eq. 4 ambient occlusion term
    int samples = 0;
};

// Eq. 2: the (continuous) level whose voxel width matches a footprint diameter.
inline float cone_level(float diameter, float base_voxel_size) {
    return std::log2(std::max(diameter / base_voxel_size, 1.0f));
}

ConeResult trace_cone(const VoxelConeView& view, const Cone& cone, const ConeOptions& options);  // best kernel
// With a chosen kernel (Error if this CPU lacks it).
ConeResult trace_cone(const VoxelConeView& view, const Cone& cone, const ConeOptions& options, ConeKernel kernel);

// A fan: cones that share apex, aperture and options (a surface point's diffuse cones, a
// voxel side's bounce cones). results[i] is trace_cone's result for directions[i], bit for
// bit; the AVX2 kernel marches the fan eight cones at a time, the loop's bookkeeping eight
// lanes wide. `results` must be as long as `directions`.
void trace_cone_fan(const VoxelConeView& view, const Vec3& apex, std::span<const Vec3> directions,
                    float tan_half_angle, const ConeOptions& options, std::span<ConeResult> results);
void trace_cone_fan(const VoxelConeView& view, const Vec3& apex, std::span<const Vec3> directions,
                    float tan_half_angle, const ConeOptions& options, std::span<ConeResult> results,
                    ConeKernel kernel);

// One cone of a batch whose cones share their options but for where each starts and the
// plane that clips it (neighbouring pixels' specular cones: each its own apex, aperture,
// first sample and surface).
struct ConeLaunch {
    Cone cone;
    float start = 1.0f;       // replaces ConeOptions::start
    Vec4 clip_plane{0};       // replaces ConeOptions::clip_plane (used where options.clip)
    ConeOptions options_from(const ConeOptions& shared) const {
        ConeOptions o = shared;
        o.start = start;
        o.clip_plane = clip_plane;
        return o;
    }
};

// results[i] is trace_cone(view, launches[i].cone, launches[i].options_from(options)), bit
// for bit; the AVX2 kernel marches eight launches at a time as a fan does.
void trace_cones(const VoxelConeView& view, std::span<const ConeLaunch> launches, const ConeOptions& options,
                 std::span<ConeResult> results);
void trace_cones(const VoxelConeView& view, std::span<const ConeLaunch> launches, const ConeOptions& options,
                 std::span<ConeResult> results, ConeKernel kernel);

// Fixed cones over the hemisphere around +z (P3: 16 cones): equal solid angle 2π/N each
// (axes on a spiral, uniform in cos θ), half aperture with that solid angle. The weights
// W_k are the solid angles (ΣW = 2π); the irradiance estimate is Σ L_k cos θ_k W_k and
// Σ cos θ_k W_k = π exactly, so a uniform sky of radiance L gives E = πL.
struct ConeSet {
    std::vector<Vec3> directions;   // local frame, z = normal
    std::vector<float> weights;     // solid angles
    std::vector<float> cosines;     // cos θ_k
    float tan_half_angle = 0;
};
ConeSet hemisphere_cones(int count);

// Half aperture of a specular cone for a Phong exponent n: the angle at which cos^n
// falls to one half, clamped to [0.5°, 45°] (exponent 0 gives 45°).
float phong_cone_tan(float exponent);

}  // namespace gilab
