#pragma once
// Where one cascade of a light propagation volume sits in the world: a cube of
// resolution³ cells of one size, placed on the world lattice of that size so that a
// moving viewer moves the cube by whole cells only (the paper snaps the cascades to
// their cell size so the propagated light does not swim).
#include <cstddef>
#include <cmath>
#include "core/util/math.hpp"

namespace gilab {

struct LpvLattice {
    int resolution = 32;
    float cell_size = 1.0f;
    IVec3 origin_cell{0};  // world cell index of cell (0, 0, 0)

    // The lattice of `resolution`³ cells of `cell_size` whose centre is the world-lattice
    // corner nearest below `centre` (resolution is even, so that corner is a cell corner
    // of the grid).
    static LpvLattice centred_on(const Vec3& centre, float cell_size, int resolution) {
        LpvLattice l;
        l.resolution = resolution;
        l.cell_size = cell_size;
        const IVec3 c(int(std::floor(centre.x / cell_size)), int(std::floor(centre.y / cell_size)),
                      int(std::floor(centre.z / cell_size)));
        l.origin_cell = c - IVec3(resolution / 2);
        return l;
    }

    size_t cells() const { return size_t(resolution) * size_t(resolution) * size_t(resolution); }
    Vec3 origin() const { return Vec3(origin_cell) * cell_size; }  // min corner, world
    float extent() const { return float(resolution) * cell_size; }
    // Continuous grid coordinate of a world point: cell i spans [i, i + 1).
    Vec3 to_grid(const Vec3& p) const { return (p - origin()) / cell_size; }
    bool inside(const IVec3& c) const {
        return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < resolution && c.y < resolution && c.z < resolution;
    }
    size_t index(const IVec3& c) const {
        return (size_t(c.z) * size_t(resolution) + size_t(c.y)) * size_t(resolution) + size_t(c.x);
    }
    IVec3 cell_of(const Vec3& p) const {
        const Vec3 g = to_grid(p);
        return IVec3(int(std::floor(g.x)), int(std::floor(g.y)), int(std::floor(g.z)));
    }
};

}  // namespace gilab
