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
// Split in two so that eight lanes, each with its own plane, multiply the same numbers.
[[gnu::always_inline]] inline float clip_half_unit(const ConeLevel& l) { return 0.501f * l.voxel_size; }
[[gnu::always_inline]] inline float plane_norm1(const Vec4& plane) {
    return std::abs(plane.x) + std::abs(plane.y) + std::abs(plane.z);
}
[[gnu::always_inline]] inline float clip_half_width(const ConeLevel& l, const Vec4& plane) {
    return clip_half_unit(l) * plane_norm1(plane);
}
// In voxels of the sampled level: a sample farther in front of the clip plane than its
// eight voxel centres reach (one voxel per axis) plus clip_mask's half-voxel test is never
// clipped; blending also reads the next level, of twice the voxel.
[[gnu::always_inline]] inline float clip_reach(const Vec4& plane, bool blend_levels) {
    return 1.502f * (blend_levels ? 2.0f : 1.0f) * plane_norm1(plane);
}
// n[a] × the coordinate a of voxel i's centre: one float, or four or eight lanes (GCC and Clang
// vector types take the same operators), so both kernels compute it alike.
template <class T>
[[gnu::always_inline]] inline T clip_centre_term(T n, T anchor, T i, T voxel_size, T half) {
    return n * (anchor + (i + half) * voxel_size);
}
[[gnu::always_inline]] inline ClipGeometry clip_geometry(const ConeLevel& l, const Vec3& anchor, const SampleCorners& c,
                                                         const Vec4& plane) {
    ClipGeometry g;
    g.half = clip_half_width(l, plane);
    const IVec3 i[2] = {c.i0, c.i1};
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 2; ++b)
            g.s[a][b] = clip_centre_term(plane[a], anchor[a], float(i[b][a]), l.voxel_size, 0.5f);
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

using SampleFn = Vec4 (*)(const ConeLevel&, const Vec3&, const Vec3&, const FaceWeights&, const Vec4*);

namespace portable_kernel {
#include "techniques/vct/cone_march.inc"
}  // namespace portable_kernel

ConeResult trace_cone_portable(const VoxelConeView& view, const Cone& cone, const ConeOptions& options) {
    return portable_kernel::march<sample_portable>(view, cone, options);
}

#if GILAB_CONE_AVX2
// Everything up to the matching pop is compiled with AVX2, FMA and F16C.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,fma,f16c"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,fma,f16c")
#endif
// ---- AVX2 kernel: texels in x pairs. A pair, the lower and the upper voxel along x at
// one (y, z) corner for one face, is two 8-byte loads into one register, which F16C
// converts to eight floats in one instruction and FMA weights in one more: 12
// conversions and 12 fused multiply-adds per sample instead of 24 each. The eight texel
// weights (texel_weight's order of products) and the clip plane's masks (clip_mask's
// order of sums) are computed once, eight texels wide, and each pair takes its two lanes
// spread over the lower and upper four lanes. The same sums as the portable kernel in
// another order, with fused rounding.
#define GILAB_AVX2_INLINE [[gnu::always_inline]] inline

GILAB_AVX2_INLINE __m256 load_pair(const HalfRGBA* lower, const HalfRGBA* upper) {
    const __m128 low = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(lower)));
    return _mm256_cvtph_ps(_mm_castps_si128(_mm_loadh_pi(low, reinterpret_cast<const __m64*>(upper))));
}
// Per axis a of lanes (lower voxel: 0–2, upper voxel: 4–6) spread over the eight texels
// (texel k takes bit 0 of k along x, bit 1 along y, bit 2 along z, as texel_offset).
struct Texels8 {
    __m256 x, y, z;
};
GILAB_AVX2_INLINE Texels8 spread(__m128 lower, __m128 upper) {
    const __m256 both = _mm256_insertf128_ps(_mm256_castps128_ps256(lower), upper, 1);
    return {_mm256_permutevar8x32_ps(both, _mm256_setr_epi32(0, 4, 0, 4, 0, 4, 0, 4)),
            _mm256_permutevar8x32_ps(both, _mm256_setr_epi32(1, 1, 5, 5, 1, 1, 5, 5)),
            _mm256_permutevar8x32_ps(both, _mm256_setr_epi32(2, 2, 2, 2, 6, 6, 6, 6))};
}
// Texels 2j and 2j + 1 (the x pair of corner j) of eight lanes, each over four lanes.
GILAB_AVX2_INLINE __m256 pair_lanes(__m256 texels, int j) {
    return _mm256_permutevar8x32_ps(texels, _mm256_setr_epi32(2 * j, 2 * j, 2 * j, 2 * j, 2 * j + 1, 2 * j + 1,
                                                              2 * j + 1, 2 * j + 1));
}

// Lane-wise integer and rounding operations under one name for four and eight lanes, so
// the one-cone sampler (the three axes in four lanes) and the fan (eight cones per axis)
// share the corner arithmetic below. Float arithmetic uses the vector types' operators.
GILAB_AVX2_INLINE __m128 lanes_floor(__m128 v) { return _mm_floor_ps(v); }
GILAB_AVX2_INLINE __m256 lanes_floor(__m256 v) { return _mm256_floor_ps(v); }
GILAB_AVX2_INLINE __m128 lanes_min(__m128 a, __m128 b) { return _mm_min_ps(a, b); }
GILAB_AVX2_INLINE __m256 lanes_min(__m256 a, __m256 b) { return _mm256_min_ps(a, b); }
GILAB_AVX2_INLINE __m128 lanes_max(__m128 a, __m128 b) { return _mm_max_ps(a, b); }
GILAB_AVX2_INLINE __m256 lanes_max(__m256 a, __m256 b) { return _mm256_max_ps(a, b); }
GILAB_AVX2_INLINE __m128 lanes_float(__m128i v) { return _mm_cvtepi32_ps(v); }
GILAB_AVX2_INLINE __m256 lanes_float(__m256i v) { return _mm256_cvtepi32_ps(v); }
GILAB_AVX2_INLINE __m128i lanes_truncate(__m128 v) { return _mm_cvttps_epi32(v); }
GILAB_AVX2_INLINE __m256i lanes_truncate(__m256 v) { return _mm256_cvttps_epi32(v); }
GILAB_AVX2_INLINE __m128i lanes_add(__m128i a, __m128i b) { return _mm_add_epi32(a, b); }
GILAB_AVX2_INLINE __m256i lanes_add(__m256i a, __m256i b) { return _mm256_add_epi32(a, b); }
GILAB_AVX2_INLINE __m128i lanes_and(__m128i a, __m128i b) { return _mm_and_si128(a, b); }
GILAB_AVX2_INLINE __m256i lanes_and(__m256i a, __m256i b) { return _mm256_and_si256(a, b); }
GILAB_AVX2_INLINE __m128i lanes_mul(__m128i a, __m128i b) { return _mm_mullo_epi32(a, b); }
GILAB_AVX2_INLINE __m256i lanes_mul(__m256i a, __m256i b) { return _mm256_mullo_epi32(a, b); }
GILAB_AVX2_INLINE __m128i lanes_min(__m128i a, __m128i b) { return _mm_min_epi32(a, b); }
GILAB_AVX2_INLINE __m256i lanes_min(__m256i a, __m256i b) { return _mm256_min_epi32(a, b); }
// The vector types of four and eight lanes (named here, not as template arguments, which
// would drop their attributes).
template <int kLanes>
struct LaneTypes;
template <>
struct LaneTypes<4> {
    using F = __m128;
    using I = __m128i;
    static I of(int v) { return _mm_set1_epi32(v); }
};
template <>
struct LaneTypes<8> {
    using F = __m256;
    using I = __m256i;
    static I of(int v) { return _mm256_set1_epi32(v); }
};

// corners_of along one axis, lane by lane (the same clamps, floors and weights, so the
// same numbers): the lower and upper voxel, their weights and their cells (stride ×
// the voxel wrapped into the level's store). Cells are computed in 32 bits, which holds
// levels of at most 512³ voxels of six faces (sample_avx2_inline checks).
template <int kLanes>
struct AxisCorners {
    using F = typename LaneTypes<kLanes>::F;
    using I = typename LaneTypes<kLanes>::I;
    I i0, i1, cell0, cell1;
    F w0, w1;
};
template <int kLanes, class F = typename LaneTypes<kLanes>::F, class I = typename LaneTypes<kLanes>::I>
GILAB_AVX2_INLINE AxisCorners<kLanes> axis_corners(F p, F anchor, F inv_voxel, I lo, I hi, I wrap, I stride) {
    const F q = lanes_min(lanes_max((p - anchor) * inv_voxel - 0.5f, lanes_float(lo)), lanes_float(hi));
    const F f = lanes_floor(q);
    AxisCorners<kLanes> c;
    c.i0 = lanes_truncate(f);
    c.i1 = lanes_min(lanes_add(c.i0, LaneTypes<kLanes>::of(1)), hi);
    c.w1 = q - f;
    c.w0 = 1.0f - c.w1;
    c.cell0 = lanes_mul(lanes_and(c.i0, wrap), stride);
    c.cell1 = lanes_mul(lanes_and(c.i1, wrap), stride);
    return c;
}

// clip_mask's rule on eight texel weights, given each texel's signed distance d to the
// plane and the level's clip_half_width: a face turned to the plane's front keeps the
// texels whose box reaches in front of it, the other faces only the texels wholly in front.
struct ClipWeights {
    __m256 front, back;
};
GILAB_AVX2_INLINE ClipWeights clip_weights(__m256 weight, __m256 d, __m256 half) {
    const __m256 zero = _mm256_setzero_ps();
    return {_mm256_and_ps(weight, _mm256_cmp_ps(_mm256_add_ps(d, half), zero, _CMP_GT_OQ)),
            _mm256_and_ps(weight, _mm256_cmp_ps(_mm256_sub_ps(d, half), zero, _CMP_GT_OQ))};
}

// A sample's sum: for each (y, z) corner j (bit 0 along y, bit 1 along z) and face f, the
// x pair at cells `lower(j)` and `upper(j)` weighted by `pair_weight(f, j)` (the lower
// texel's weight over lanes 0–3, the upper's over 4–7), then the three faces by how much
// the cone sees them. The one-cone sampler and the fan both sum here, in this order.
template <class Lower, class Upper, class PairWeight>
GILAB_AVX2_INLINE Vec4 sum_pairs(const ConeLevel& l, const FaceWeights& faces, Lower lower, Upper upper,
                                 PairWeight pair_weight) {
    const HalfRGBA* face[3];
    for (int f = 0; f < 3; ++f) face[f] = l.data + size_t(faces.face[size_t(f)]) * l.face_stride;
    const __m256 zero = _mm256_setzero_ps();
    __m256 acc[3] = {zero, zero, zero};
    for (int j = 0; j < 4; ++j)
        for (int f = 0; f < 3; ++f)
            acc[f] = _mm256_fmadd_ps(load_pair(face[f] + lower(j), face[f] + upper(j)), pair_weight(f, j), acc[f]);
    __m256 sum = _mm256_mul_ps(acc[0], _mm256_set1_ps(faces.weight[0]));
    sum = _mm256_fmadd_ps(acc[1], _mm256_set1_ps(faces.weight[1]), sum);
    sum = _mm256_fmadd_ps(acc[2], _mm256_set1_ps(faces.weight[2]), sum);
    alignas(16) float out[4];
    _mm_store_ps(out, _mm_add_ps(_mm256_castps256_ps128(sum), _mm256_extractf128_ps(sum, 1)));
    return {out[0], out[1], out[2], out[3]};
}

// axis_corners for the three axes at once (SSE lanes x, y, z) and the cells of the x
// pairs, lower[j] and upper[j] for the (y, z) corner j.
struct PairCorners {
    __m128i i0, i1;
    __m128 w0, w1;
    int lower[4], upper[4];
    int occupancy;
};
GILAB_AVX2_INLINE PairCorners pair_corners_of(const ConeLevel& l, const Vec3& anchor, const Vec3& p) {
    const __m128i lo = _mm_setr_epi32(l.origin.x, l.origin.y, l.origin.z, 0);
    const AxisCorners<4> a = axis_corners<4>(
        _mm_setr_ps(p.x, p.y, p.z, 0.0f), _mm_setr_ps(anchor.x, anchor.y, anchor.z, 0.0f),
        _mm_set1_ps(l.inv_voxel_size), lo, _mm_add_epi32(lo, _mm_set1_epi32(l.size - 1)), _mm_set1_epi32(l.wrap_mask),
        _mm_setr_epi32(int(l.x_stride), int(l.row_stride), int(l.slice_stride), 0));
    PairCorners c;
    c.i0 = a.i0, c.i1 = a.i1, c.w0 = a.w0, c.w1 = a.w1;
    const __m128i o0 = a.cell0, o1 = a.cell1;
    // Rows: the z and y cells of corner j, then the x cells added.
    const __m128i xy = _mm_unpacklo_epi32(o0, o1);                                         // x0 x1 y0 y1
    const __m128i oy = _mm_shuffle_epi32(xy, _MM_SHUFFLE(3, 2, 3, 2));                     // y0 y1 y0 y1
    const __m128i oz = _mm_shuffle_epi32(_mm_unpackhi_epi32(o0, o1), _MM_SHUFFLE(1, 1, 0, 0));  // z0 z0 z1 z1
    const __m128i row = _mm_add_epi32(oz, oy);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(c.lower), _mm_add_epi32(row, _mm_shuffle_epi32(o0, 0)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(c.upper), _mm_add_epi32(row, _mm_shuffle_epi32(o1, 0)));
    const __m128i occ = _mm_mullo_epi32(_mm_and_si128(a.i0, _mm_set1_epi32(l.wrap_mask)),
                                        _mm_setr_epi32(1, int(l.occupancy_row), int(l.occupancy_slice), 0));
    c.occupancy =
        _mm_cvtsi128_si32(_mm_add_epi32(_mm_add_epi32(occ, _mm_shuffle_epi32(occ, 1)), _mm_shuffle_epi32(occ, 2)));
    return c;
}

GILAB_AVX2_INLINE Vec4 sample_avx2_inline(const ConeLevel& l, const Vec3& anchor, const Vec3& p,
                                          const FaceWeights& faces, const Vec4* plane) {
    if (l.size > 512) return sample_portable(l, anchor, p, faces, plane);
    const PairCorners c = pair_corners_of(l, anchor, p);
    if (l.occupancy && !occupancy_bit(l.occupancy, size_t(c.occupancy))) return Vec4(0.0f);  // all eight texels empty
    const Texels8 w = spread(c.w0, c.w1);
    const __m256 weight = _mm256_mul_ps(_mm256_mul_ps(w.z, w.y), w.x);
    auto lower = [&](int j) { return c.lower[j]; };
    auto upper = [&](int j) { return c.upper[j]; };
    if (!plane) return sum_pairs(l, faces, lower, upper, [&](int, int j) { return pair_lanes(weight, j); });
    // clip_geometry: n[a] × (anchor[a] + (i + 0.5) × voxel) for i0 and i1, summed over
    // the axes for each texel.
    const __m128 n = _mm_setr_ps(plane->x, plane->y, plane->z, 0.0f);
    const __m128 anc = _mm_setr_ps(anchor.x, anchor.y, anchor.z, 0.0f), vs = _mm_set1_ps(l.voxel_size);
    const __m128 h = _mm_set1_ps(0.5f);
    const Texels8 s = spread(clip_centre_term(n, anc, _mm_cvtepi32_ps(c.i0), vs, h),
                             clip_centre_term(n, anc, _mm_cvtepi32_ps(c.i1), vs, h));
    const __m256 d = _mm256_sub_ps(_mm256_add_ps(_mm256_add_ps(s.x, s.y), s.z), _mm256_set1_ps(plane->w));
    const ClipWeights clip = clip_weights(weight, d, _mm256_set1_ps(clip_half_width(l, *plane)));
    __m256 face_weight[3];
    for (int f = 0; f < 3; ++f) face_weight[f] = faces_plane_front(faces.face[size_t(f)], *plane) ? clip.front : clip.back;
    return sum_pairs(l, faces, lower, upper, [&](int f, int j) { return pair_lanes(face_weight[f], j); });
}
#undef GILAB_AVX2_INLINE

// The same, as a function of its own (sample_level calls it from code built without AVX2).
Vec4 sample_avx2(const ConeLevel& l, const Vec3& anchor, const Vec3& p, const FaceWeights& faces, const Vec4* plane) {
    return sample_avx2_inline(l, anchor, p, faces, plane);
}

namespace avx2_kernel {
#include "techniques/vct/cone_march.inc"
}  // namespace avx2_kernel

ConeResult trace_cone_avx2(const VoxelConeView& view, const Cone& cone, const ConeOptions& options) {
    return avx2_kernel::march<sample_avx2_inline>(view, cone, options);
}

namespace avx2_kernel {
#define GILAB_FAN_INLINE [[gnu::always_inline]] inline
#include "techniques/vct/cone_fan.inc"
#undef GILAB_FAN_INLINE
}  // namespace avx2_kernel

void trace_fan_avx2(const VoxelConeView& view, const Vec3& apex, std::span<const Vec3> directions,
                    float tan_half_angle, const ConeOptions& options, std::span<ConeResult> results) {
    avx2_kernel::FanStart start;
    for (size_t b = 0; b < directions.size(); b += 8) {
        const int count = int(std::min<size_t>(8, directions.size() - b));
        avx2_kernel::fan_start_shared(start, apex, directions.data() + b, count, tan_half_angle, options);
        avx2_kernel::march_fan8<sample_avx2_inline>(view, start, options, results.data() + b);
    }
}

void trace_cones_avx2(const VoxelConeView& view, std::span<const ConeLaunch> launches, const ConeOptions& options,
                      std::span<ConeResult> results) {
    avx2_kernel::FanStart start;
    for (size_t b = 0; b < launches.size(); b += 8) {
        avx2_kernel::fan_start_each(start, launches.data() + b, int(std::min<size_t>(8, launches.size() - b)), options);
        avx2_kernel::march_fan8<sample_avx2_inline>(view, start, options, results.data() + b);
    }
}

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif  // GILAB_CONE_AVX2

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

void trace_cone_fan(const VoxelConeView& view, const Vec3& apex, std::span<const Vec3> directions,
                    float tan_half_angle, const ConeOptions& options, std::span<ConeResult> results,
                    ConeKernel kernel) {
    require_supported(kernel);
    if (results.size() != directions.size())
        throw Error("cone tracer", "a fan of " + std::to_string(directions.size()) + " cones needs as many results, got " +
                                       std::to_string(results.size()));
#if GILAB_CONE_AVX2
    if (kernel == ConeKernel::avx2) return trace_fan_avx2(view, apex, directions, tan_half_angle, options, results);
#endif
    for (size_t i = 0; i < directions.size(); ++i)
        results[i] = trace_cone_portable(view, Cone{apex, directions[i], tan_half_angle}, options);
}

void trace_cone_fan(const VoxelConeView& view, const Vec3& apex, std::span<const Vec3> directions,
                    float tan_half_angle, const ConeOptions& options, std::span<ConeResult> results) {
    trace_cone_fan(view, apex, directions, tan_half_angle, options, results, best_cone_kernel());
}

void trace_cones(const VoxelConeView& view, std::span<const ConeLaunch> launches, const ConeOptions& options,
                 std::span<ConeResult> results, ConeKernel kernel) {
    require_supported(kernel);
    if (results.size() != launches.size())
        throw Error("cone tracer", "a batch of " + std::to_string(launches.size()) +
                                       " cones needs as many results, got " + std::to_string(results.size()));
#if GILAB_CONE_AVX2
    if (kernel == ConeKernel::avx2) return trace_cones_avx2(view, launches, options, results);
#endif
    for (size_t i = 0; i < launches.size(); ++i)
        results[i] = trace_cone_portable(view, launches[i].cone, launches[i].options_from(options));
}

void trace_cones(const VoxelConeView& view, std::span<const ConeLaunch> launches, const ConeOptions& options,
                 std::span<ConeResult> results) {
    trace_cones(view, launches, options, results, best_cone_kernel());
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
