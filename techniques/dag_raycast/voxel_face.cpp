#include "techniques/dag_raycast/voxel_face.hpp"

#include <cmath>

namespace gilab {

Vec3 voxel_entry_normal(const VoxelGrid& grid, const UVec3& voxel, const Ray& ray) {
    // Voxel space (voxel v spans [v, v+1)): the map is affine, so ray parameters hold.
    const double scale = double(grid.resolution) / double(grid.extent);
    const DVec3 o = grid.to_voxel_space(ray.origin);
    const DVec3 d = DVec3(ray.direction) * scale;
    int axis = -1;
    double entry = -kInfinity;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0) continue;
        const double face = d[k] > 0 ? double(voxel[k]) : double(voxel[k]) + 1.0;
        const double t = (face - o[k]) / d[k];
        if (t > entry) {
            entry = t;
            axis = k;
        }
    }
    Vec3 n(0);
    if (axis >= 0 && entry >= double(ray.tmin)) {
        n[axis] = d[axis] > 0 ? -1.0f : 1.0f;
        return n;
    }
    // The ray starts inside the voxel: the face nearest to the start point.
    const DVec3 p = o + DVec3(double(ray.tmin)) * d;
    double best = kInfinity;
    for (int k = 0; k < 3; ++k) {
        const double lo = p[k] - double(voxel[k]), hi = double(voxel[k]) + 1.0 - p[k];
        if (lo < best) {
            best = lo;
            n = Vec3(0);
            n[k] = -1.0f;
        }
        if (hi < best) {
            best = hi;
            n = Vec3(0);
            n[k] = 1.0f;
        }
    }
    return n;
}

}  // namespace gilab
