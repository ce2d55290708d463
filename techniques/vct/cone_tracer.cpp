#include "techniques/vct/cone_tracer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define GILAB_CONE_AVX2 1
#include <immintrin.h>
#else
#define GILAB_CONE_AVX2 0
#endif
#include "accel/vct/occupancy_map.hpp"
#include "core/util/error.hpp"

namespace gilab {

VoxelConeView VoxelConeView::of_levels(const Vec3& anchor, bool nested, std::vector<ConeLevel> levels) {
    VoxelConeView view;
    view.anchor_ = anchor;
    view.nested_ = nested;
    view.levels_ = std::move(levels);
    return view;
}

VoxelConeView VoxelConeView::cascade(const CascadedVoxelTexture& t, const std::vector<HalfRGBA>& buffer) {
    if (buffer.size() != t.cell_count()) throw Error("cone tracer", "radiance buffer does not match the cascade texture");
    const int R = t.resolution();
    std::vector<ConeLevel> levels;
    for (int k = 0; k < t.levels(); ++k) {
        ConeLevel l;
        l.data = buffer.data() + t.index(0, k, UVec3(0));
        l.occupancy = t.occupancy(k);
        l.face_stride = 1;
        l.x_stride = kFaceCount;
        l.row_stride = size_t(R) * kFaceCount;
        l.slice_stride = size_t(R) * size_t(R) * kFaceCount;
        l.occupancy_row = size_t(R);
        l.occupancy_slice = size_t(R) * size_t(R);
        l.origin = t.origin(k);
        l.size = R;
        l.wrap_mask = R - 1;
        l.voxel_size = float(t.voxel_size(k));
        l.inv_voxel_size = float(1.0 / t.voxel_size(k));
        levels.push_back(l);
    }
    return of_levels(Vec3(t.config().anchor), true, std::move(levels));
}

VoxelConeView VoxelConeView::dense(const DenseMipTexture& t, const std::vector<std::vector<HalfRGBA>>& buffer) {
    if (int(buffer.size()) != t.level_count()) throw Error("cone tracer", "radiance buffer does not match the mip chain");
    std::vector<ConeLevel> levels;
    for (int k = 0; k < t.level_count(); ++k) {
        const size_t r = size_t(t.resolution(k));
        ConeLevel l;
        l.data = buffer[size_t(k)].data();
        l.occupancy = t.occupancy(k);
        l.face_stride = 1;
        l.x_stride = kFaceCount;
        l.row_stride = r * kFaceCount;
        l.slice_stride = r * r * kFaceCount;
        l.occupancy_row = r;
        l.occupancy_slice = r * r;
        l.origin = IVec3(0);
        l.size = int(r);
        l.wrap_mask = -1;
        l.voxel_size = float(t.voxel_size(k));
        l.inv_voxel_size = float(1.0 / t.voxel_size(k));
        levels.push_back(l);
    }
    return of_levels(Vec3(t.config().anchor), false, std::move(levels));
}

namespace {

// floor(x) as an int for |x| < 2^31, without a libm call.
[[gnu::always_inline]] inline int floor_to_int(float x) {
    const int i = int(x);
    return i - int(x < float(i));
}

// The eight texels of one trilinear sample: per axis (x, y, z) the two cell offsets and
// weights; texel k (0…7) takes bit 0 of k along x, bit 1 along y, bit 2 along z.
struct SampleCorners {
    IVec3 i0, i1;               // lower and upper voxel (world voxel coordinates of the level)
    size_t offset[3][2];        // in cells
    float weight[3][2];
    size_t occupancy;           // texel of i0 in the occupancy map
};

// q: the position in the level's voxel units. Clamped to the centres of the level's
// border voxels, so a sample never reads outside the level or wraps around.
[[gnu::always_inline]] inline SampleCorners corners_of(const ConeLevel& l, const Vec3& q_unclamped) {
    SampleCorners c;
    const size_t stride[3] = {l.x_stride, l.row_stride, l.slice_stride};
    for (int a = 0; a < 3; ++a) {
        const int lo = l.origin[a], hi = l.origin[a] + l.size - 1;
        const float q = std::min(std::max(q_unclamped[a] - 0.5f, float(lo)), float(hi));
        const int i0 = floor_to_int(q);
        const int i1 = std::min(i0 + 1, hi);
        c.i0[a] = i0;
        c.i1[a] = i1;
        c.offset[a][0] = size_t(i0 & l.wrap_mask) * stride[a];
        c.offset[a][1] = size_t(i1 & l.wrap_mask) * stride[a];
        const float t = q - float(i0);
        c.weight[a][0] = 1.0f - t;
        c.weight[a][1] = t;
    }
    c.occupancy = size_t(c.i0.z & l.wrap_mask) * l.occupancy_slice + size_t(c.i0.y & l.wrap_mask) * l.occupancy_row +
                  size_t(c.i0.x & l.wrap_mask);
    return c;
}

[[gnu::always_inline]] inline size_t texel_offset(const SampleCorners& c, int k) {
    return c.offset[2][k >> 2] + c.offset[1][(k >> 1) & 1] + c.offset[0][k & 1];
}
[[gnu::always_inline]] inline float texel_weight(const SampleCorners& c, int k) {
    return (c.weight[2][k >> 2] * c.weight[1][(k >> 1) & 1]) * c.weight[0][k & 1];
}

// The clip plane's rule: voxels entirely behind the plane are empty; voxels it cuts hold
// the cone's own surface, so their faces turned away from the plane (the surface's back
// side, seen only through the wide trilinear footprint of a coarse level) are skipped.
// Texel k's signed distance is s[0][k & 1] + s[1][(k >> 1) & 1] + s[2][k >> 2] − plane.w;
// behind: distance + half ≤ 0, cut: distance − half ≤ 0, with `half` a hair more than
// half a voxel along n, so a surface lying on a voxel face counts as cut.
struct ClipGeometry {
    float s[3][2];  // n[a] × the voxel centre's coordinate a, for the lower and upper voxel
    float half;
};
[[gnu::always_inline]] inline ClipGeometry clip_geometry(const ConeLevel& l, const Vec3& anchor, const SampleCorners& c,
                                                         const Vec4& plane) {
    ClipGeometry g;
    const Vec3 n(plane);
    g.half = 0.501f * l.voxel_size * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z));
    const IVec3 i[2] = {c.i0, c.i1};
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 2; ++b) g.s[a][b] = n[a] * (anchor[a] + (float(i[b][a]) + 0.5f) * l.voxel_size);
    return g;
}
// Whether a face (2a looks along +a, 2a + 1 along −a: anisotropic_voxel.hpp) is turned
// towards the plane's front side.
[[gnu::always_inline]] inline bool faces_plane_front(int face, const Vec4& plane) {
    const float along = plane[face >> 1];
    return ((face & 1) ? -along : along) >= -1e-6f;
}

// keep[f][k] is 0 where face f of texel k is skipped by the clip plane.
[[gnu::always_inline]] inline void clip_mask(const ConeLevel& l, const Vec3& anchor, const SampleCorners& c,
                                             const FaceWeights& faces, const Vec4& plane, float (*keep)[8]) {
    float keep_back[8] = {1, 1, 1, 1, 1, 1, 1, 1}, keep_front[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    const ClipGeometry g = clip_geometry(l, anchor, c, plane);
    for (int k = 0; k < 8; ++k) {
        const float d = g.s[0][k & 1] + g.s[1][(k >> 1) & 1] + g.s[2][k >> 2] - plane.w;
        if (d + g.half <= 0.0f) keep_back[k] = keep_front[k] = 0.0f;  // behind
        else if (d - g.half <= 0.0f) keep_back[k] = 0.0f;              // cut
    }
    for (int f = 0; f < 3; ++f)
        std::copy_n(faces_plane_front(faces.face[size_t(f)], plane) ? keep_front : keep_back, 8, keep[f]);
}

// ---- portable kernel: SSE2 (every x86-64) or scalar.
// Σ over the eight texels and the three faces of weight(texel, face) × value, where a
// texel's weight is its trilinear weight × keep[face][texel]. RGBA16F values are read as
// their bits shifted up by 13 (see half_rgba.hpp) and the weights carry 2^112.
template <bool kClip>
[[gnu::always_inline]] inline Vec4 accumulate_portable(const ConeLevel& l, const SampleCorners& c,
                                                       const FaceWeights& faces, const float (*keep)[8]) {
    const HalfRGBA* face0 = l.data + size_t(faces.face[0]) * l.face_stride;
    const HalfRGBA* face1 = l.data + size_t(faces.face[1]) * l.face_stride;
    const HalfRGBA* face2 = l.data + size_t(faces.face[2]) * l.face_stride;
    float w[8];
    for (int k = 0; k < 8; ++k) w[k] = texel_weight(c, k) * kHalfBitsScale;
#if defined(__SSE2__)
    __m128 a0 = _mm_setzero_ps(), a1 = _mm_setzero_ps(), a2 = _mm_setzero_ps();
    const __m128i zero = _mm_setzero_si128();
    auto bits = [&](const HalfRGBA* h) {
        const __m128i v = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(h));
        return _mm_castsi128_ps(_mm_slli_epi32(_mm_unpacklo_epi16(v, zero), 13));
    };
    for (int k = 0; k < 8; ++k) {
        const size_t off = texel_offset(c, k);
        if constexpr (kClip) {
            a0 = _mm_add_ps(a0, _mm_mul_ps(bits(face0 + off), _mm_set1_ps(w[k] * keep[0][k])));
            a1 = _mm_add_ps(a1, _mm_mul_ps(bits(face1 + off), _mm_set1_ps(w[k] * keep[1][k])));
            a2 = _mm_add_ps(a2, _mm_mul_ps(bits(face2 + off), _mm_set1_ps(w[k] * keep[2][k])));
        } else {
            const __m128 wk = _mm_set1_ps(w[k]);
            a0 = _mm_add_ps(a0, _mm_mul_ps(bits(face0 + off), wk));
            a1 = _mm_add_ps(a1, _mm_mul_ps(bits(face1 + off), wk));
            a2 = _mm_add_ps(a2, _mm_mul_ps(bits(face2 + off), wk));
        }
    }
    __m128 sum = _mm_mul_ps(a0, _mm_set1_ps(faces.weight[0]));
    sum = _mm_add_ps(sum, _mm_mul_ps(a1, _mm_set1_ps(faces.weight[1])));
    sum = _mm_add_ps(sum, _mm_mul_ps(a2, _mm_set1_ps(faces.weight[2])));
    alignas(16) float out[4];
    _mm_store_ps(out, sum);
    return {out[0], out[1], out[2], out[3]};
#else
    auto bits = [](const HalfRGBA* h) {
        return Vec4(std::bit_cast<float>(uint32_t(h->c[0]) << 13), std::bit_cast<float>(uint32_t(h->c[1]) << 13),
                    std::bit_cast<float>(uint32_t(h->c[2]) << 13), std::bit_cast<float>(uint32_t(h->c[3]) << 13));
    };
    Vec4 a0(0.0f), a1(0.0f), a2(0.0f);
    for (int k = 0; k < 8; ++k) {
        const size_t off = texel_offset(c, k);
        a0 += bits(face0 + off) * (kClip ? w[k] * keep[0][k] : w[k]);
        a1 += bits(face1 + off) * (kClip ? w[k] * keep[1][k] : w[k]);
        a2 += bits(face2 + off) * (kClip ? w[k] * keep[2][k] : w[k]);
    }
    return a0 * faces.weight[0] + a1 * faces.weight[1] + a2 * faces.weight[2];
#endif
}

// One trilinear, face-weighted sample (position p in world units).
[[gnu::always_inline]] inline Vec4 sample_portable(const ConeLevel& l, const Vec3& anchor, const Vec3& p,
                                                   const FaceWeights& faces, const Vec4* plane) {
    const SampleCorners c = corners_of(l, (p - anchor) * l.inv_voxel_size);
    if (l.occupancy && !occupancy_bit(l.occupancy, c.occupancy)) return Vec4(0.0f);  // all eight texels empty
    if (!plane) return accumulate_portable<false>(l, c, faces, nullptr);
    float keep[3][8];
    clip_mask(l, anchor, c, faces, *plane, keep);
    return accumulate_portable<true>(l, c, faces, keep);
}

#if GILAB_CONE_AVX2
// ---- AVX2 kernel: the eight texel weights and the clip plane's mask in one 8-wide
// register each; F16C converts a texel's four halves in one instruction and FMA folds the
// weighting (the same sums as the portable kernel in another order, with fused rounding).
// Per-axis pairs v[a][0 or 1] spread over the eight texels (texel k takes bit 0 of k
// along x, bit 1 along y, bit 2 along z, as texel_offset).
struct Texels8 {
    __m256 x, y, z;
};
__attribute__((target("avx2,fma,f16c"), always_inline)) inline Texels8 spread(const float (&v)[3][2]) {
    return {_mm256_setr_ps(v[0][0], v[0][1], v[0][0], v[0][1], v[0][0], v[0][1], v[0][0], v[0][1]),
            _mm256_setr_ps(v[1][0], v[1][0], v[1][1], v[1][1], v[1][0], v[1][0], v[1][1], v[1][1]),
            _mm256_setr_ps(v[2][0], v[2][0], v[2][0], v[2][0], v[2][1], v[2][1], v[2][1], v[2][1])};
}
// texel_weight of the eight texels, in texel_weight's order of products.
__attribute__((target("avx2,fma,f16c"), always_inline)) inline __m256 texel_product(const float (&v)[3][2]) {
    const Texels8 t = spread(v);
    return _mm256_mul_ps(_mm256_mul_ps(t.z, t.y), t.x);
}
// clip_mask's sum of the per-axis distances of the eight texels, in its order.
__attribute__((target("avx2,fma,f16c"), always_inline)) inline __m256 texel_sum(const float (&v)[3][2]) {
    const Texels8 t = spread(v);
    return _mm256_add_ps(_mm256_add_ps(t.x, t.y), t.z);
}

__attribute__((target("avx2,fma,f16c"))) Vec4 sample_avx2(const ConeLevel& l, const Vec3& anchor, const Vec3& p,
                                                          const FaceWeights& faces, const Vec4* plane) {
    const SampleCorners c = corners_of(l, (p - anchor) * l.inv_voxel_size);
    if (l.occupancy && !occupancy_bit(l.occupancy, c.occupancy)) return Vec4(0.0f);  // all eight texels empty
    const __m256 w = texel_product(c.weight);
    alignas(32) float wf[3][8];
    if (!plane) {
        _mm256_store_ps(wf[0], w);
        _mm256_store_ps(wf[1], w);
        _mm256_store_ps(wf[2], w);
    } else {
        // clip_mask's rule, eight texels at once.
        const ClipGeometry g = clip_geometry(l, anchor, c, *plane);
        const __m256 d = _mm256_sub_ps(texel_sum(g.s), _mm256_set1_ps(plane->w));
        const __m256 h = _mm256_set1_ps(g.half);
        const __m256 front = _mm256_and_ps(w, _mm256_cmp_ps(_mm256_add_ps(d, h), _mm256_setzero_ps(), _CMP_GT_OQ));
        const __m256 back = _mm256_and_ps(w, _mm256_cmp_ps(_mm256_sub_ps(d, h), _mm256_setzero_ps(), _CMP_GT_OQ));
        for (int f = 0; f < 3; ++f) _mm256_store_ps(wf[f], faces_plane_front(faces.face[size_t(f)], *plane) ? front : back);
    }
    const HalfRGBA* face0 = l.data + size_t(faces.face[0]) * l.face_stride;
    const HalfRGBA* face1 = l.data + size_t(faces.face[1]) * l.face_stride;
    const HalfRGBA* face2 = l.data + size_t(faces.face[2]) * l.face_stride;
    // Two accumulators per face (even and odd texels) halve the chain of dependent FMAs.
    __m128 a[3][2] = {{_mm_setzero_ps(), _mm_setzero_ps()}, {_mm_setzero_ps(), _mm_setzero_ps()},
                      {_mm_setzero_ps(), _mm_setzero_ps()}};
#define GILAB_TEXEL(face, off) _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>((face) + (off))))
    for (int k = 0; k < 8; ++k) {
        const size_t off = texel_offset(c, k);
        a[0][k & 1] = _mm_fmadd_ps(GILAB_TEXEL(face0, off), _mm_broadcast_ss(&wf[0][k]), a[0][k & 1]);
        a[1][k & 1] = _mm_fmadd_ps(GILAB_TEXEL(face1, off), _mm_broadcast_ss(&wf[1][k]), a[1][k & 1]);
        a[2][k & 1] = _mm_fmadd_ps(GILAB_TEXEL(face2, off), _mm_broadcast_ss(&wf[2][k]), a[2][k & 1]);
    }
#undef GILAB_TEXEL
    __m128 sum = _mm_mul_ps(_mm_add_ps(a[0][0], a[0][1]), _mm_set1_ps(faces.weight[0]));
    sum = _mm_fmadd_ps(_mm_add_ps(a[1][0], a[1][1]), _mm_set1_ps(faces.weight[1]), sum);
    sum = _mm_fmadd_ps(_mm_add_ps(a[2][0], a[2][1]), _mm_set1_ps(faces.weight[2]), sum);
    alignas(16) float out[4];
    _mm_store_ps(out, sum);
    return {out[0], out[1], out[2], out[3]};
}
#endif

using SampleFn = Vec4 (*)(const ConeLevel&, const Vec3&, const Vec3&, const FaceWeights&, const Vec4*);

// The cone loop, instantiated once per kernel.
template <SampleFn kSample>
[[gnu::always_inline]] inline ConeResult march(const VoxelConeView& view, const Cone& cone, const ConeOptions& options) {
    ConeResult r;
    const int n = view.level_count();
    if (n == 0) return r;
    const float w0 = view.base_voxel_size(), inv_w0 = 1.0f / w0;
    const float coarsest = view.level(n - 1).voxel_size;
    const float bias_scale = std::exp2(options.lod_bias);
    const FaceWeights faces = faces_seen_along(cone.direction);
    const Vec4* plane = options.clip ? &options.clip_plane : nullptr;
    // A sample farther in front of the clip plane than its eight voxel centres reach (one
    // voxel per axis) plus clip_mask's half-voxel test is never clipped; blending also
    // reads the next level, of twice the voxel.
    const float plane_reach = plane ? 1.502f * (options.blend_levels ? 2.0f : 1.0f) *
                                          (std::abs(plane->x) + std::abs(plane->y) + std::abs(plane->z))
                                    : 0.0f;
    float dist = options.start;
    while (dist < options.max_distance) {
        const Vec3 p = cone.origin + dist * cone.direction;
        const float diameter = std::max(2.0f * cone.tan_half_angle * dist, w0);
        if (!options.bounds.empty()) {
            // The footprint has left the box (convex): nothing further along is met.
            const Vec3 grow(0.5f * diameter + 2.0f * w0);
            const Vec3 lo = options.bounds.min - grow, hi = options.bounds.max + grow;
            if (p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z) break;
        }
        // Eq. 2: the voxel width matching the footprint, w0·2^lod (lod continuous, with
        // the bias), read at level max(⌊lod⌋, finest level holding p), at most the coarsest.
        const float lod_width = diameter * bias_scale;
        const float ratio = lod_width * inv_w0;
        const int lod = ratio < 1.0f ? 0 : int((std::bit_cast<uint32_t>(ratio) >> 23) & 0xffu) - 127;
        const int l0 = view.level_containing(p, lod, 1.0f);
        if (l0 < 0) break;  // left the structure
        // The continuous level's voxel: the footprint's own width unless p is held only by
        // a coarser level (then that level's voxel) or beyond the coarsest.
        const float voxel = l0 > lod ? view.level(l0).voxel_size : std::clamp(lod_width, w0, coarsest);
        const Vec4* clip = plane && glm::dot(Vec3(*plane), p) - plane->w <= plane_reach * voxel ? plane : nullptr;
        Vec4 s = kSample(view.level(l0), view.anchor(), p, faces, clip);
        if (options.blend_levels && l0 + 1 < n) {
            const float frac = std::log2(voxel / view.level(l0).voxel_size);
            if (frac > 0.0f) s = glm::mix(s, kSample(view.level(l0 + 1), view.anchor(), p, faces, clip), frac);
        }
        const float step = voxel * options.step;  // the sampled level's voxel: never skips over it
        ++r.samples;
        if (s.a > 1e-6f) {
            const float a = std::min(s.a, 0.9999f);
            const float corrected = options.correct_opacity ? 1.0f - std::pow(1.0f - a, step / voxel) : a;
            const Vec3 col = Vec3(s) * (corrected / s.a);
            const float t = 1.0f - r.opacity;
            r.radiance += t * col;
            const float radius = 0.5f * diameter / w0;
            r.occlusion += (1.0f - r.occlusion) * corrected / (1.0f + options.ao_lambda * radius);
            r.opacity += t * corrected;
            if (r.opacity >= options.opacity_cutoff) break;
        }
        dist += step;
    }
    return r;
}

ConeResult trace_cone_portable(const VoxelConeView& view, const Cone& cone, const ConeOptions& options) {
    return march<sample_portable>(view, cone, options);
}

#if GILAB_CONE_AVX2
__attribute__((target("avx2,fma,f16c"))) ConeResult trace_cone_avx2(const VoxelConeView& view, const Cone& cone,
                                                                    const ConeOptions& options) {
    return march<sample_avx2>(view, cone, options);
}
#endif

void require_supported(ConeKernel kernel) {
    if (kernel == ConeKernel::avx2 && best_cone_kernel() != ConeKernel::avx2)
        throw Error("cone tracer", "the avx2 cone kernel needs a CPU with AVX2, FMA and F16C");
}

}  // namespace

ConeKernel best_cone_kernel() {
#if GILAB_CONE_AVX2
    static const ConeKernel best = [] {
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("f16c")
                   ? ConeKernel::avx2
                   : ConeKernel::portable;
    }();
    return best;
#else
    return ConeKernel::portable;
#endif
}

const char* to_string(ConeKernel kernel) { return kernel == ConeKernel::avx2 ? "avx2" : "portable"; }

Vec4 VoxelConeView::sample_level(int level, const Vec3& p, const FaceWeights& faces, const Vec4* plane,
                                 ConeKernel kernel) const {
    require_supported(kernel);
    const ConeLevel& l = levels_[size_t(level)];
#if GILAB_CONE_AVX2
    if (kernel == ConeKernel::avx2) return sample_avx2(l, anchor_, p, faces, plane);
#endif
    return sample_portable(l, anchor_, p, faces, plane);
}

namespace {

ConeResult trace_with(ConeKernel kernel, const VoxelConeView& view, const Cone& cone, const ConeOptions& options) {
#if GILAB_CONE_AVX2
    if (kernel == ConeKernel::avx2) return trace_cone_avx2(view, cone, options);
#endif
    return trace_cone_portable(view, cone, options);
}

}  // namespace

ConeResult trace_cone(const VoxelConeView& view, const Cone& cone, const ConeOptions& options, ConeKernel kernel) {
    require_supported(kernel);
    return trace_with(kernel, view, cone, options);
}

ConeResult trace_cone(const VoxelConeView& view, const Cone& cone, const ConeOptions& options) {
    return trace_with(best_cone_kernel(), view, cone, options);
}

ConeSet hemisphere_cones(int count) {
    if (count < 1) throw Error("cone tracer", "a cone set needs at least one cone, got " + std::to_string(count));
    ConeSet set;
    const float golden = kPi * (3.0f - std::sqrt(5.0f));
    const float solid_angle = 2.0f * kPi / float(count);
    for (int i = 0; i < count; ++i) {
        float z = 1.0f - (float(i) + 0.5f) / float(count);
        float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
        float phi = golden * float(i);
        set.directions.push_back(Vec3(s * std::cos(phi), s * std::sin(phi), z));
        set.weights.push_back(solid_angle);
        set.cosines.push_back(z);
    }
    // A cone of solid angle Ω = 2π(1 − cos β).
    float cos_beta = 1.0f - solid_angle / (2.0f * kPi);
    float sin_beta = std::sqrt(std::max(0.0f, 1.0f - cos_beta * cos_beta));
    set.tan_half_angle = cos_beta > 0.25f ? sin_beta / cos_beta : 4.0f;  // one or two cones: very wide
    return set;
}

float phong_cone_tan(float exponent) {
    const float min_angle = 0.5f * kPi / 180.0f, max_angle = 0.25f * kPi;
    float angle = max_angle;
    if (exponent > 0.0f) angle = std::acos(std::pow(0.5f, 1.0f / exponent));
    return std::tan(std::clamp(angle, min_angle, max_angle));
}

}  // namespace gilab
