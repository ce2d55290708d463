#include "core/voxel/box_clip.hpp"

namespace gilab {
namespace {

constexpr int kMaxPolygon = 12;

struct Polygon {
    int n = 0;
    DVec3 v[kMaxPolygon];
};

// Keeps the part of `in` with sign·(x[axis] − bound) ≥ 0.
void clip(const Polygon& in, Polygon& out, int axis, double bound, double sign) {
    out.n = 0;
    if (in.n == 0) return;
    for (int i = 0; i < in.n; ++i) {
        const DVec3& a = in.v[i];
        const DVec3& b = in.v[i + 1 == in.n ? 0 : i + 1];
        double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
        if (da >= 0) out.v[out.n++] = a;
        if ((da >= 0) != (db >= 0)) {  // the edge crosses the plane
            double t = da / (da - db);
            DVec3 p = a + t * (b - a);
            p[axis] = bound;  // exactly on the plane, whatever the rounding
            out.v[out.n++] = p;
        }
        if (out.n >= kMaxPolygon - 1) break;  // convex polygon clipped by 6 planes: ≤ 9 vertices
    }
}

}  // namespace

BoxPiece clip_triangle_to_box(const DVec3 (&p)[3], const DVec3& normal, const DVec3& box_min, const DVec3& box_max) {
    Polygon a, c;
    a.n = 3;
    a.v[0] = p[0];
    a.v[1] = p[1];
    a.v[2] = p[2];
    for (int k = 0; k < 3 && a.n > 0; ++k) {
        clip(a, c, k, box_min[k], 1.0);
        clip(c, a, k, box_max[k], -1.0);
    }
    BoxPiece piece;
    if (a.n < 3) return piece;
    for (int i = 1; i + 1 < a.n; ++i) {
        double s = 0.5 * std::abs(glm::dot(glm::cross(a.v[i] - a.v[0], a.v[i + 1] - a.v[0]), normal));
        piece.area += s;
        piece.centroid += s * (a.v[0] + a.v[i] + a.v[i + 1]) / 3.0;
    }
    if (piece.area > 0) piece.centroid /= piece.area;
    return piece;
}

}  // namespace gilab
