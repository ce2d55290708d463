#pragma once
// The part of a triangle inside an axis-aligned box: the triangle clipped by the box's
// six planes (Sutherland–Hodgman, in double), as its area and centroid. The fragment
// voxelizer weighs a voxel's fragments by it; the conservative voxelizer finds where in
// an alpha mask a voxel's part of a triangle lies.
#include "core/util/math.hpp"

namespace gilab {

struct BoxPiece {
    double area = 0;    // 0 when the triangle misses the box or only touches it
    DVec3 centroid{0};  // area-weighted
};

// `normal`: the triangle's unit normal (the area is measured in its plane).
BoxPiece clip_triangle_to_box(const DVec3 (&p)[3], const DVec3& normal, const DVec3& box_min, const DVec3& box_max);

}  // namespace gilab
