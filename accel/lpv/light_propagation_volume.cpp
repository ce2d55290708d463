#include "accel/lpv/light_propagation_volume.hpp"

#include <algorithm>
#include <cmath>
#include "accel/lpv/propagation_stencil.hpp"
#include "core/util/parallel.hpp"
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace gilab {

LightPropagationVolume::LightPropagationVolume(const LpvLattice& lattice) : lattice_(lattice), geometry_(lattice) {
    const size_t n = lattice.cells();
    injected_.assign(n, ShRgb{});
    current_.assign(n, ShRgb{});
    next_.assign(n, ShRgb{});
    accumulated_.assign(n, ShRgb{});
}

void LightPropagationVolume::place(const LpvLattice& lattice) {
    if (lattice.resolution != lattice_.resolution) {
        *this = LightPropagationVolume(lattice);
        return;
    }
    lattice_ = lattice;
    geometry_.place(lattice);
}

size_t LightPropagationVolume::inject(std::span<const VirtualPointLight> vpls) {
    std::fill(injected_.begin(), injected_.end(), ShRgb{});
    const float half = 0.5f * lattice_.cell_size;
    size_t inside = 0;
    for (const VirtualPointLight& v : vpls) {
        const IVec3 c = lattice_.cell_of(v.position + half * v.normal);
        if (!lattice_.inside(c)) continue;
        ShRgb& cell = injected_[lattice_.index(c)];
        const Sh4 lobe = sh_clamped_cosine(v.normal);
        for (int ch = 0; ch < 3; ++ch) sh_add_scaled(cell[size_t(ch)], lobe, v.flux[ch] * kInvPi);
        ++inside;
    }
    return inside;
}

namespace {

// The flux (over π) a source cell sends through the 5 faces of one neighbour, per
// channel, added to the destination as clamped-cosine lobes around the face normals.
// The lobes share their constant term and differ in the linear term only, so the sum is
// c₀·Σw in coefficient 0 and c₁·Σ w·normal in the others.
// `transmit`: the 5 faces' transmittances, null when nothing blocks (then the
// neighbour's transfer matrix does the same in fewer operations).
inline void send(const ShRgb& source, const StencilNeighbour& nb, const float* transmit, ShRgb& to) {
    if (!transmit) {
#if defined(__SSE2__)
        // The four destination coefficients of a channel in one register.
        const __m128 m0 = _mm_loadu_ps(nb.transfer[0].data()), m1 = _mm_loadu_ps(nb.transfer[1].data()),
                     m2 = _mm_loadu_ps(nb.transfer[2].data()), m3 = _mm_loadu_ps(nb.transfer[3].data());
        for (size_t ch = 0; ch < 3; ++ch) {
            const float* s = source[ch].data();
            __m128 acc = _mm_loadu_ps(to[ch].data());
            acc = _mm_add_ps(acc, _mm_mul_ps(_mm_set1_ps(s[0]), m0));
            acc = _mm_add_ps(acc, _mm_mul_ps(_mm_set1_ps(s[1]), m1));
            acc = _mm_add_ps(acc, _mm_mul_ps(_mm_set1_ps(s[2]), m2));
            acc = _mm_add_ps(acc, _mm_mul_ps(_mm_set1_ps(s[3]), m3));
            _mm_storeu_ps(to[ch].data(), acc);
        }
#else
        for (size_t ch = 0; ch < 3; ++ch)
            for (size_t i = 0; i < 4; ++i) {
                const float s = source[ch][i];
                for (size_t j = 0; j < 4; ++j) to[ch][j] += s * nb.transfer[i][j];
            }
#endif
        return;
    }
    const float* t = transmit;
    for (size_t ch = 0; ch < 3; ++ch) {
        float total = 0;
        Vec3 linear(0);
        for (size_t f = 0; f < 5; ++f) {
            const float w = t[f] * sh_dot(source[ch], nb.faces[f].gather);
            total += w;
            linear += w * nb.faces[f].normal;
        }
        to[ch][0] += kShCosine0 * total;
        to[ch][1] += kShCosine1 * linear.x;
        to[ch][2] += kShCosine1 * linear.y;
        to[ch][3] += kShCosine1 * linear.z;
    }
}

// A cell with no light sends none (most cells in the first iterations).
inline bool is_dark(const ShRgb& s) {
    for (const Sh4& c : s)
        if (c[0] != 0.0f || c[1] != 0.0f || c[2] != 0.0f || c[3] != 0.0f) return false;
    return true;
}

}  // namespace

DVec3 LightPropagationVolume::gather(const std::vector<ShRgb>& from, std::vector<ShRgb>& to, bool occlusion) const {
    const int r = lattice_.resolution;
    const auto& stencil = propagation_stencil();
    std::vector<DVec3> left_per_slice(size_t(r), DVec3(0));
    // Which sources hold light, decided once per cell rather than once per neighbour.
    std::vector<uint8_t> lit(from.size());
    parallel_for(from.size(), 4096, [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) lit[i] = !is_dark(from[i]);
    });
    // Row by row: for each neighbour direction, the whole source row (shifted by the
    // neighbour's offset) goes into the destination row, so both are read in order.
    parallel_for(size_t(r), 1, [&](size_t begin, size_t end) {
        for (int z = int(begin); z < int(end); ++z)
            for (int y = 0; y < r; ++y) {
                ShRgb* out = to.data() + lattice_.index(IVec3(0, y, z));
                std::fill(out, out + r, ShRgb{});
                for (const StencilNeighbour& nb : stencil) {
                    const IVec3 o = nb.offset;
                    const int sy = y - o.y, sz = z - o.z;
                    if (sy < 0 || sz < 0 || sy >= r || sz >= r) continue;
                    const size_t src_first = lattice_.index(IVec3(0, sy, sz));
                    const ShRgb* src = from.data() + src_first;
                    const uint8_t* src_lit = lit.data() + src_first;
                    // The shared face, where the light enters: at the destination for a
                    // positive step, at the source for a negative one.
                    const int fy = nb.sign > 0 ? y : sy, fz = nb.sign > 0 ? z : sz;
                    const uint8_t* open = occlusion ? geometry_.open_row(nb.axis, fy, fz) : nullptr;
                    const auto* faces = occlusion ? geometry_.face_row(nb.axis, fy, fz) : nullptr;
                    const size_t s = nb.sign > 0 ? 0 : 1;
                    const int x0 = std::max(0, o.x), x1 = std::min(r, r + o.x);
                    for (int x = x0; x < x1; ++x) {
                        const int sx = x - o.x;
                        if (!src_lit[sx]) continue;
                        const int fx = nb.sign > 0 ? x : sx;
                        const float* t = open && !((open[fx] >> s) & 1) ? faces[fx][s].data() : nullptr;
                        send(src[sx], nb, t, out[x]);
                    }
                }
                // What a border cell sends across the volume's border is lost.
                const bool border_row = y == 0 || z == 0 || y == r - 1 || z == r - 1;
                for (int x = 0; x < r; ++x) {
                    if (!border_row && x != 0 && x != r - 1) continue;
                    const IVec3 c(x, y, z);
                    const ShRgb& source = from[lattice_.index(c)];
                    if (is_dark(source)) continue;
                    for (const StencilNeighbour& nb : stencil) {
                        const IVec3 dst = c + nb.offset;
                        if (lattice_.inside(dst)) continue;
                        const float* t = occlusion ? geometry_.face_transmittance(nb.axis, nb.sign, nb.sign > 0 ? dst : c) : nullptr;
                        ShRgb lost{};
                        send(source, nb, t, lost);
                        for (size_t ch = 0; ch < 3; ++ch) left_per_slice[size_t(z)][int(ch)] += double(sh_integral(lost[ch]));
                    }
                }
            }
    });
    DVec3 left(0);
    for (const DVec3& l : left_per_slice) left += l;  // fixed order
    return left;
}

PropagationResult LightPropagationVolume::propagate(int iterations, bool occlusion) {
    PropagationResult result;
    current_ = injected_;
    accumulated_ = injected_;
    for (int i = 0; i < iterations; ++i) {
        result.flux_left += gather(current_, next_, occlusion && i > 0);
        std::swap(current_, next_);
        const size_t n = accumulated_.size();
        parallel_for(n, 4096, [&](size_t begin, size_t end) {
            for (size_t k = begin; k < end; ++k)
                for (int ch = 0; ch < 3; ++ch)
                    for (int j = 0; j < 4; ++j) accumulated_[k][size_t(ch)][size_t(j)] += current_[k][size_t(ch)][size_t(j)];
        });
    }
    return result;
}

ShRgb LightPropagationVolume::sample(const Vec3& p) const {
    const int r = lattice_.resolution;
    const Vec3 g = lattice_.to_grid(p) - Vec3(0.5f);  // cell centres at integers
    const Vec3 base = glm::floor(g);
    const Vec3 f = g - base;
    ShRgb out{};
    for (int corner = 0; corner < 8; ++corner) {
        IVec3 c(int(base.x) + (corner & 1), int(base.y) + ((corner >> 1) & 1), int(base.z) + (corner >> 2));
        const float w = ((corner & 1) ? f.x : 1.0f - f.x) * (((corner >> 1) & 1) ? f.y : 1.0f - f.y) *
                        ((corner >> 2) ? f.z : 1.0f - f.z);
        if (w == 0.0f) continue;
        c = glm::clamp(c, IVec3(0), IVec3(r - 1));
        const ShRgb& cell = accumulated_[lattice_.index(c)];
        for (int ch = 0; ch < 3; ++ch) sh_add_scaled(out[size_t(ch)], cell[size_t(ch)], w);
    }
    return out;
}

size_t LightPropagationVolume::bytes() const {
    return (injected_.size() + current_.size() + next_.size() + accumulated_.size()) * sizeof(ShRgb) + geometry_.bytes();
}

DVec3 total_flux(const std::vector<ShRgb>& cells) {
    DVec3 sum(0);
    for (const ShRgb& c : cells)
        for (int ch = 0; ch < 3; ++ch) sum[ch] += double(sh_integral(c[size_t(ch)]));
    return sum;
}

}  // namespace gilab
