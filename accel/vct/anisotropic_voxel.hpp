#pragma once
// Anisotropic voxels: every voxel keeps six directional values, one per face
// (+X −X +Y −Y +Z −Z). Face f describes the voxel as seen from its side: the value a ray
// meets when it enters the voxel through that face, travelling along −direction(f).
// Radiance values are premultiplied by their opacity (rgb = α·L, a = α), so averaging
// and compositing are linear.
#include <array>
#include "core/util/math.hpp"

namespace gilab {

inline constexpr int kFaceCount = 6;
enum VoxelFaceIndex : int { kFacePosX = 0, kFaceNegX = 1, kFacePosY = 2, kFaceNegY = 3, kFacePosZ = 4, kFaceNegZ = 5 };

inline int face_axis(int face) { return face >> 1; }
inline float face_sign(int face) { return (face & 1) ? -1.0f : 1.0f; }
inline Vec3 face_direction(int face) {
    Vec3 d(0.0f);
    d[face_axis(face)] = face_sign(face);
    return d;
}
const char* face_name(int face);  // "+X", "-X", ...

// The three faces a sample meets when looked at along unit direction d (a cone marching
// along d sees the faces turned towards its apex), weighted by d's squared components
// (the weights sum to 1).
struct FaceWeights {
    std::array<int, 3> face{};
    std::array<float, 3> weight{};
};
inline FaceWeights faces_seen_along(const Vec3& d) {
    FaceWeights w;
    for (int a = 0; a < 3; ++a) {
        w.face[size_t(a)] = 2 * a + (d[a] > 0.0f ? 1 : 0);  // travelling +a meets the −a face
        w.weight[size_t(a)] = d[a] * d[a];
    }
    float sum = w.weight[0] + w.weight[1] + w.weight[2];
    if (sum > 0.0f)
        for (float& x : w.weight) x /= sum;
    return w;
}

// Front-to-back "over" of premultiplied values: what the viewer sees of `front` with
// `back` behind it (P3 eq. 3 with premultiplied colour).
inline Vec4 composite_over(const Vec4& front, const Vec4& back) {
    float t = 1.0f - front.a;
    return {front.r + t * back.r, front.g + t * back.g, front.b + t * back.b, front.a + t * back.a};
}

// Anisotropic 2×2×2 → 1 filter for one face: children[x + 2y + 4z] hold the eight
// finer voxels' values for that same face. Along the face's axis the child nearer the
// viewer (on the face's side) is composited over the farther one; the four columns are
// averaged.
inline Vec4 downsample_face(int face, const std::array<Vec4, 8>& children) {
    const int axis = face_axis(face);
    const int front = (face & 1) ? 0 : 1;  // +face: the viewer is on the + side
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    Vec4 sum(0.0f);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            int c[3];
            c[u] = i;
            c[v] = j;
            c[axis] = front;
            const Vec4& f = children[size_t(c[0] + 2 * c[1] + 4 * c[2])];
            c[axis] = 1 - front;
            const Vec4& b = children[size_t(c[0] + 2 * c[1] + 4 * c[2])];
            sum += composite_over(f, b);
        }
    return 0.25f * sum;
}

// The G-buffer of one face: what the fused fragments seen from that side look like.
struct VoxelFaceData {
    float opacity = 0;      // projected coverage along the face's axis, clamped to 1
    Vec3 albedo{0};         // coverage-weighted mean diffuse albedo
    Vec3 normal{0};         // mean normal of the fragments, oriented towards the face's side
    Vec3 emission{0};       // mean emitted radiance towards the face's side
    Vec3 position{0};       // coverage-weighted mean fragment position (world space)
};

// One occupied voxel with its world voxel coordinate (in units of its grid's voxels).
struct AnisotropicVoxel {
    IVec3 coord{0};
    std::array<VoxelFaceData, kFaceCount> faces{};
    bool empty() const {
        for (const VoxelFaceData& f : faces)
            if (f.opacity > 0.0f) return false;
        return true;
    }
};

}  // namespace gilab
