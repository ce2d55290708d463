#include "accel/lpv/geometry_volume.hpp"

#include <algorithm>
#include <cmath>
#include "accel/lpv/propagation_stencil.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

GeometryVolume::GeometryVolume(const LpvLattice& light_lattice) : lattice_(light_lattice) {
    const size_t n = size_t(corners());
    blocking_.assign(n * n * n, Sh4{});
    for (auto& f : faces_) f.assign(n * n * n, FaceTransmittance{});
    for (auto& o : open_) o.assign(n * n * n, uint8_t(3));
}

void GeometryVolume::clear() { std::fill(blocking_.begin(), blocking_.end(), Sh4{}); }

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
        // Faces of this axis: c[axis] in [0, r], the other two in [0, r); walked in
        // (z, y, x) order, the order they are stored in.
        const IVec3 end(axis == 0 ? r + 1 : r, axis == 1 ? r + 1 : r, axis == 2 ? r + 1 : r);
        parallel_for(size_t(end.z), 1, [&](size_t z0, size_t z1) {
            for (int z = int(z0); z < int(z1); ++z)
                for (int y = 0; y < end.y; ++y)
                    for (int x = 0; x < end.x; ++x) {
                        const IVec3 c(x, y, z);
                        // The face's 4 corners: c, c + e_a, c + e_b, c + e_a + e_b.
                        Sh4 sum{};
                        for (int corner = 0; corner < 4; ++corner) {
                            IVec3 v = c;
                            v[a] += corner & 1;
                            v[b] += corner >> 1;
                            sh_add_scaled(sum, blocking_[corner_index(v)], 0.25f);
                        }
                        const size_t fi = face_index(c);
                        uint8_t& open = open_[size_t(axis)][fi];
                        if (sum[0] == 0.0f && sum[1] == 0.0f && sum[2] == 0.0f && sum[3] == 0.0f) {
                            open = 3;  // nothing here: every transmittance is 1
                            continue;
                        }
                        FaceTransmittance& ft = faces_[size_t(axis)][fi];
                        open = 0;
                        for (const StencilNeighbour& nb : propagation_stencil()) {
                            if (nb.axis != axis) continue;
                            const size_t s = nb.sign > 0 ? 0 : 1;
                            bool all_one = true;
                            for (size_t f = 0; f < 5; ++f) {
                                ft[s][f] = transmittance(sum, nb.faces[f].direction);
                                all_one = all_one && ft[s][f] == 1.0f;
                            }
                            open |= uint8_t(all_one ? 1u << s : 0u);
                        }
                    }
        });
    }
}

size_t GeometryVolume::bytes() const {
    size_t b = blocking_.size() * sizeof(Sh4);
    for (const auto& f : faces_) b += f.size() * sizeof(FaceTransmittance);
    for (const auto& o : open_) b += o.size();
    return b;
}

}  // namespace gilab
