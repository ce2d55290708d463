#pragma once
// Two-band real spherical harmonics (4 coefficients), the representation of light
// propagation volumes (Kaplanyan & Dachsbacher 2010, §3): low enough to store 12 floats
// per cell (RGB), smooth enough that light diffuses from cell to cell without ringing.
//
// Basis order (Y₀₀, Y₁x, Y₁y, Y₁z): Y₀₀ = 1/(2√π), Y₁· = √(3/(4π))·(x, y, z). With an
// orthonormal basis the integral of a product of two functions is the dot product of
// their coefficients, and the integral of a function over the sphere is 4π·Y₀₀·c₀.
#include <array>
#include "core/util/math.hpp"

namespace gilab {

using Sh4 = std::array<float, 4>;
using ShRgb = std::array<Sh4, 3>;  // one Sh4 per colour channel

inline constexpr float kShY0 = 0.28209479177387814f;  // 1/(2√π)
inline constexpr float kShY1 = 0.48860251190291992f;  // √(3/(4π))
// The clamped cosine max(0, n·ω) projected on the basis: c₀ = √π/2, c₁ = √(π/3)·n
// (Ramamoorthi & Hanrahan 2001). Reconstructed it reads 1/4 + (n·ω)/2: 3/4 along n,
// −1/4 against n, and it integrates to π over the sphere, as the exact lobe does.
inline constexpr float kShCosine0 = 0.88622692545275801f;  // √π/2
inline constexpr float kShCosine1 = 1.02332670794648848f;  // √(π/3)

// The basis evaluated in direction w (unit).
inline Sh4 sh_basis(const Vec3& w) { return {kShY0, kShY1 * w.x, kShY1 * w.y, kShY1 * w.z}; }

// The clamped cosine lobe around unit n.
inline Sh4 sh_clamped_cosine(const Vec3& n) {
    return {kShCosine0, kShCosine1 * n.x, kShCosine1 * n.y, kShCosine1 * n.z};
}

inline float sh_dot(const Sh4& a, const Sh4& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

// The function the coefficients describe, evaluated in direction w.
inline float sh_evaluate(const Sh4& c, const Vec3& w) { return sh_dot(c, sh_basis(w)); }

// ∫ f(ω) dω over the sphere.
inline float sh_integral(const Sh4& c) { return 4.0f * kPi * kShY0 * c[0]; }

inline void sh_add_scaled(Sh4& to, const Sh4& c, float s) {
    for (int i = 0; i < 4; ++i) to[size_t(i)] += s * c[size_t(i)];
}

}  // namespace gilab
