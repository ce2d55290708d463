#pragma once
// The faces light crosses in one propagation step (Kaplanyan & Dachsbacher 2010, §4.2,
// Fig. 3). A destination cell gathers from each of its 6 neighbours; light from a source
// cell enters the destination through their shared face and leaves through the
// destination's other 5 faces: the front face (opposite the shared one) and 4 side faces.
// For each of those faces the flux is the source's intensity in the direction of the
// face's centre times the solid angle the face subtends from the source's centre; it is
// then re-emitted from the destination's centre as a clamped-cosine lobe around the
// face's outward normal, which carries the same flux.
//
// Solid angles, seen from the source centre with cells of size 1 (exact, from the
// rectangle formula below, not typed in):
//   front face  Δω = 4·atan(1/(3√11))          ≈ 0.400670 sr,
//   side face   Δω = 2·(atan(3/√11) − π/6)     ≈ 0.423431 sr.
// The paper quotes these as 0.4006/(4π) and 0.4234/(4π), fractions of the sphere; we
// store intensity (W/sr), for which the flux through a face is Δω·I, so we use them in
// steradians. The 5 faces subtend exactly 2π/3, the shared face's solid angle, and the
// 30 faces of the 6 neighbours tile the sphere (Σ Δω = 4π, Σ Δω·ω = 0): a two-band SH
// source sends out exactly its integral, so propagation conserves flux. Face fluxes
// are not clamped at zero: clamping the negative tail of a cosine lobe's two-band
// approximation would add ≈ 14 % flux per step.
#include <array>
#include "accel/lpv/sh2.hpp"

namespace gilab {

// Solid angle of the rectangle [x0, x1] × [y0, y1] in the plane z = d (d > 0) seen from
// the origin.
double rectangle_solid_angle(double x0, double x1, double y0, double y1, double d);

struct StencilFace {
    Vec3 direction{0};  // unit, source centre → face centre
    float solid_angle = 0;
    Vec3 normal{0};     // the face's outward normal: the re-emitted lobe's axis
    Sh4 gather{};       // sh_basis(direction) · solid_angle / π (flux/π per unit coefficient)
    Sh4 lobe{};         // sh_clamped_cosine(normal)
};

// One neighbour of the destination: the source sits at destination − offset, light
// travels along +offset.
struct StencilNeighbour {
    IVec3 offset{0};
    int axis = 0;   // the axis of offset
    int sign = 1;   // its sign
    std::array<StencilFace, 5> faces;  // [0] the front face, then the side faces
    // With nothing in the way the step is linear in the source's coefficients:
    // destination += Σᵢ source[i]·transfer[i], transfer[i][j] = Σ_faces lobe[j]·gather[i]
    // (16 multiply-adds per channel instead of the 5 faces' 40; a column per source
    // coefficient, so the four destination coefficients go together in SIMD).
    std::array<std::array<float, 4>, 4> transfer{};
};

const std::array<StencilNeighbour, 6>& propagation_stencil();

}  // namespace gilab
