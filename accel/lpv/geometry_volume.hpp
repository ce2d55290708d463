#pragma once
// The geometry volume of one cascade (Kaplanyan & Dachsbacher 2010, §4.3): per cell the
// probability that light crossing it in direction ω is blocked, as two-band SH. A surfel
// of area A with normal n blocks B(ω) = A/s² · max(0, −n·ω): light travelling into its
// visible side (s: cell size). Surfels come from buffers that see the scene from one
// point each (a light's reflective shadow map, a camera's primary hits); two buffers
// often see the same surface, so each buffer is gathered on its own and merged per cell
// by taking the one with more blocking, as the paper does, instead of counting it twice.
//
// The volume is shifted by half a cell against the light volume: its cell centres are the
// light volume's cell corners ((resolution + 1)³ cells), so the occlusion between two
// light cells is read, trilinearly, at the centre of the face they share — the average of
// the face's 4 corners — and evaluated once per frame for the 5 directions light leaves
// by after entering through that face (face_transmittance).
#include <algorithm>
#include <array>
#include <span>
#include <vector>
#include "accel/lpv/lpv_lattice.hpp"
#include "accel/lpv/sh2.hpp"
#include "accel/lpv/virtual_point_light.hpp"

namespace gilab {

class GeometryVolume {
public:
    GeometryVolume() = default;
    explicit GeometryVolume(const LpvLattice& light_lattice);

    // Follows the light volume to another place of the same resolution (clears nothing).
    void place(const LpvLattice& light_lattice) { lattice_ = light_lattice; }
    const LpvLattice& light_lattice() const { return lattice_; }
    int corners() const { return lattice_.resolution + 1; }  // per axis
    void clear();
    // Adds surfels of one buffer into `scratch` (same lattice), then keeps per cell the
    // larger of this volume and the scratch (by the isotropic part). Surfels outside are
    // skipped. Sequential: the sums do not depend on threads.
    void add_buffer(std::span<const Surfel> surfels, GeometryVolume& scratch);
    // For the face between light cells c − e and c along `axis` (e: the unit step;
    // c[axis] in [0, resolution], the volume's border faces included), light crossing it
    // along +e (sign > 0) or −e: the transmittance towards each of the 5 faces of
    // propagation_stencil's neighbour (axis, sign), in its order; nullptr when all five
    // are 1 (nothing blocks: most faces). Filled by update_faces.
    const float* face_transmittance(int axis, int sign, const IVec3& c) const {
        const size_t i = face_index(c), s = sign > 0 ? 0 : 1;
        return (open_[size_t(axis)][i] >> s) & 1 ? nullptr : faces_[size_t(axis)][i][s].data();
    }
    // The same for a row of faces: those at (x, y, z) for x = 0 … resolution, of `axis`
    // and direction s (0: +e, 1: −e); open_row's bit s says "all five are 1".
    const uint8_t* open_row(int axis, int y, int z) const { return open_[size_t(axis)].data() + corner_index(IVec3(0, y, z)); }
    const std::array<std::array<float, 5>, 2>* face_row(int axis, int y, int z) const {
        return faces_[size_t(axis)].data() + corner_index(IVec3(0, y, z));
    }
    void update_faces();
    const std::vector<Sh4>& blocking() const { return blocking_; }
    Sh4& at(const IVec3& corner) { return blocking_[corner_index(corner)]; }
    size_t bytes() const;

private:
    size_t corner_index(const IVec3& c) const {
        const size_t n = size_t(corners());
        return (size_t(c.z) * n + size_t(c.y)) * n + size_t(c.x);
    }
    // Faces of every axis are indexed like the corners, (z, y, x) over (resolution + 1)³,
    // so the gather, walking cells in x, reads them in order.
    size_t face_index(const IVec3& c) const { return corner_index(c); }
    void add(const Surfel& s);

    LpvLattice lattice_;
    std::vector<Sh4> blocking_;                 // (resolution + 1)³
    using FaceTransmittance = std::array<std::array<float, 5>, 2>;  // [+e, −e][stencil face]
    std::array<std::vector<FaceTransmittance>, 3> faces_;  // per axis
    std::array<std::vector<uint8_t>, 3> open_;             // per axis: bit s set when all of faces_[…][s] are 1
};

// Fraction of light crossing a face in direction w that gets through.
inline float transmittance(const Sh4& blocking, const Vec3& w) {
    return 1.0f - std::clamp(sh_evaluate(blocking, w), 0.0f, 1.0f);
}

}  // namespace gilab
