#pragma once
// One cascade of a light propagation volume (Kaplanyan & Dachsbacher 2010): a grid of
// cells, each holding the radiant intensity I(ω) (W/sr) of the light in it as two-band SH
// per colour channel, and its geometry volume.
//
//  1. inject    — every virtual point light goes into the cell containing its position
//                 moved half a cell along its normal (§4.1: the shift keeps a VPL from
//                 lighting its own surface from behind), as a clamped-cosine lobe of its
//                 flux: I = Φ/π · max(0, n·ω). Summed in the order given, so the result
//                 does not depend on threads.
//  2. propagate — iterations of gathering (§4.2, propagation_stencil.hpp): each cell
//                 collects from its 6 neighbours through its 5 far faces; a face's flux
//                 is scaled by the geometry volume's transmittance at the face the light
//                 enters by, except in the first iteration (§4.3: the VPLs sit on the
//                 surfaces that block, and would shadow themselves). Each iteration's
//                 result is added to the accumulated volume, which the lookups read: the
//                 light of every distance up to `iterations` cells.
//  3. sample    — trilinear interpolation of the accumulated SH between cell centres.
#include <span>
#include <vector>
#include "accel/lpv/geometry_volume.hpp"
#include "accel/lpv/lpv_lattice.hpp"
#include "accel/lpv/sh2.hpp"
#include "accel/lpv/virtual_point_light.hpp"

namespace gilab {

struct PropagationResult {
    DVec3 flux_left{0};  // flux that crossed the volume's border (lost), summed over iterations
};

class LightPropagationVolume {
public:
    LightPropagationVolume() = default;
    // Allocates for the lattice's resolution and places it.
    explicit LightPropagationVolume(const LpvLattice& lattice);
    // Moves to another place on the same resolution (clears nothing: inject does).
    void place(const LpvLattice& lattice);
    const LpvLattice& lattice() const { return lattice_; }
    GeometryVolume& geometry() { return geometry_; }
    const GeometryVolume& geometry() const { return geometry_; }

    // Replaces the injected light by these VPLs; returns how many fell inside.
    size_t inject(std::span<const VirtualPointLight> vpls);
    // Step 2; occlusion reads the geometry volume's face_transmittance (update_faces first).
    PropagationResult propagate(int iterations, bool occlusion);

    const std::vector<ShRgb>& injected() const { return injected_; }
    const std::vector<ShRgb>& in_transit() const { return current_; }  // after the last iteration
    const std::vector<ShRgb>& accumulated() const { return accumulated_; }
    // Accumulated intensity at world point p, trilinear (clamped to the border cells).
    ShRgb sample(const Vec3& p) const;
    size_t bytes() const;

private:
    // One gathering step from `from` into `to`; returns the flux that left the volume.
    DVec3 gather(const std::vector<ShRgb>& from, std::vector<ShRgb>& to, bool occlusion) const;

    LpvLattice lattice_;
    GeometryVolume geometry_;
    std::vector<ShRgb> injected_, current_, next_, accumulated_;
};

// Σ over cells of ∫ I dω per channel: the flux a buffer holds.
DVec3 total_flux(const std::vector<ShRgb>& cells);

}  // namespace gilab
