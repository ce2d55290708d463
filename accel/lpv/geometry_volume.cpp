#include "accel/lpv/geometry_volume.hpp"

#include <algorithm>
#include <cmath>
#include "accel/lpv/propagation_stencil.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

GeometryVolume::GeometryVolume(const LpvLattice& light_lattice) : lattice_(light_lattice) {
    const size_t n = size_t(corners());
    const size_t r = size_t(lattice_.resolution);
    blocking_.assign(n * n * n, Sh4{});
    for (auto& f : faces_) f.assign(n * r * r, FaceTransmittance{});
}

void GeometryVolume::clear() { std::fill(blocking_.begin(), blocking_.end(), Sh4{}); }

size_t GeometryVolume::face_index(int axis, const IVec3& c) const {
    // The axis of the face runs over resolution + 1 positions, the other two over
    // resolution; the face's own axis is stored slowest.
    const size_t r = size_t(lattice_.resolution);
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    return (size_t(c[axis]) * r + size_t(c[b])) * r + size_t(c[a]);
}

void GeometryVolume::add(const Surfel& s) {
    // Corner (light-lattice vertex) nearest to the surfel: the cell of the shifted grid.
    const Vec3 g = lattice_.to_grid(s.position);
    const IVec3 c(int(std::floor(g.x + 0.5f)), int(std::floor(g.y + 0.5f)), int(std::floor(g.z + 0.5f)));
    const int n = corners();
    if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= n || c.y >= n || c.z >= n) return;
    const float cell_area = lattice_.cell_size * lattice_.cell_size;
    sh_add_scaled(at(c), sh_clamped_cosine(-s.normal), s.area / cell_area);
}

void GeometryVolume::add_buffer(std::span<const Surfel> surfels, GeometryVolume& scratch) {
    scratch.clear();
    for (const Surfel& s : surfels) scratch.add(s);
    for (size_t i = 0; i < blocking_.size(); ++i)
        if (scratch.blocking_[i][0] > blocking_[i][0]) blocking_[i] = scratch.blocking_[i];
}

void GeometryVolume::update_faces() {
    const int r = lattice_.resolution;
    for (int axis = 0; axis < 3; ++axis) {
        const int a = (axis + 1) % 3, b = (axis + 2) % 3;
        parallel_for(size_t(r + 1), 1, [&](size_t begin, size_t end) {
            for (size_t k = begin; k < end; ++k)
                for (int j = 0; j < r; ++j)
                    for (int i = 0; i < r; ++i) {
                        IVec3 c(0);
                        c[axis] = int(k);
                        c[b] = j;
                        c[a] = i;
                        // The face's 4 corners: c, c + e_a, c + e_b, c + e_a + e_b.
                        Sh4 sum{};
                        for (int corner = 0; corner < 4; ++corner) {
                            IVec3 v = c;
                            v[a] += corner & 1;
                            v[b] += corner >> 1;
                            sh_add_scaled(sum, blocking_[corner_index(v)], 0.25f);
                        }
                        FaceTransmittance& ft = faces_[size_t(axis)][face_index(axis, c)];
                        for (const StencilNeighbour& nb : propagation_stencil()) {
                            if (nb.axis != axis) continue;
                            for (size_t f = 0; f < 5; ++f)
                                ft.t[nb.sign > 0 ? 0 : 1][f] = transmittance(sum, nb.faces[f].direction);
                        }
                    }
        });
    }
}

size_t GeometryVolume::bytes() const {
    size_t b = blocking_.size() * sizeof(Sh4);
    for (const auto& f : faces_) b += f.size() * sizeof(FaceTransmittance);
    return b;
}

}  // namespace gilab
