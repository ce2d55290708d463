#include "accel/lpv/propagation_stencil.hpp"

#include <cmath>

namespace gilab {

namespace {

// Solid angle of [0, x] × [0, y] at distance d, signed by x·y.
double corner_solid_angle(double x, double y, double d) {
    return std::atan(x * y / (d * std::sqrt(x * x + y * y + d * d)));
}

Vec3 unit_axis(int axis, int sign) {
    Vec3 v(0.0f);
    v[axis] = float(sign);
    return v;
}

StencilFace make_face(const Vec3& centre, double solid_angle, const Vec3& normal) {
    StencilFace f;
    f.direction = glm::normalize(centre);
    f.solid_angle = float(solid_angle);
    f.normal = normal;
    f.gather = sh_basis(f.direction);
    for (float& c : f.gather) c *= f.solid_angle * kInvPi;
    f.lobe = sh_clamped_cosine(normal);
    return f;
}

}  // namespace

double rectangle_solid_angle(double x0, double x1, double y0, double y1, double d) {
    return corner_solid_angle(x1, y1, d) - corner_solid_angle(x0, y1, d) - corner_solid_angle(x1, y0, d) +
           corner_solid_angle(x0, y0, d);
}

const std::array<StencilNeighbour, 6>& propagation_stencil() {
    static const std::array<StencilNeighbour, 6> stencil = [] {
        // Source at the origin, destination centred at `main` (one cell away): its front
        // face is the unit square at distance 1.5, a side face spans [0.5, 1.5] along
        // `main` at distance 0.5 to the side.
        const double front = rectangle_solid_angle(-0.5, 0.5, -0.5, 0.5, 1.5);
        const double side = rectangle_solid_angle(-0.5, 0.5, 0.5, 1.5, 0.5);
        std::array<StencilNeighbour, 6> s;
        int n = 0;
        for (int axis = 0; axis < 3; ++axis)
            for (int sign : {1, -1}) {
                StencilNeighbour& nb = s[size_t(n++)];
                nb.axis = axis;
                nb.sign = sign;
                const Vec3 main = unit_axis(axis, sign);
                nb.offset = IVec3(main);
                nb.faces[0] = make_face(1.5f * main, front, main);
                int f = 1;
                for (int other = 0; other < 3; ++other) {
                    if (other == axis) continue;
                    for (int side_sign : {1, -1}) {
                        const Vec3 to_side = unit_axis(other, side_sign);
                        nb.faces[size_t(f++)] = make_face(main + 0.5f * to_side, side, to_side);
                    }
                }
                for (const StencilFace& face : nb.faces)
                    for (size_t j = 0; j < 4; ++j)
                        for (size_t i = 0; i < 4; ++i) nb.transfer[i][j] += face.lobe[j] * face.gather[i];
            }
        return s;
    }();
    return stencil;
}

}  // namespace gilab
