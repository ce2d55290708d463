#pragma once
// Skins for linear blend skinning (glTF's model): a skin names its joint nodes and their
// inverse bind matrices; each skinned vertex blends up to four joint matrices.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>
#include "core/util/math.hpp"

namespace gilab {

struct Mesh;

// Up to four joints per vertex: indices into Skin::joints and weights that sum to 1.
// Slots with weight 0 hold joint 0.
struct VertexInfluences {
    std::array<uint16_t, 4> joints{};
    Vec4 weights{0};
};

struct Skin {
    std::string name;
    std::vector<uint32_t> joints;    // scene node indices
    std::vector<Mat4> inverse_bind;  // one per joint: mesh space → the joint's space at bind time
};

// world[joints[k]] · inverse_bind[k] for every joint k; `world` holds every node's world
// matrix. Throws Error on a joint outside `world` or a count mismatch.
std::vector<Mat4> joint_matrices(const Skin& skin, std::span<const Mat4> world);

// Poses the mesh: p' = M_v p and n' ∝ M_v⁻ᵀ n with M_v = Σ_k w_k · joints[j_k]. Throws
// Error unless the mesh has one influence per vertex and every weighted joint index is
// below joints.size().
void skin_vertices(const Mesh& mesh, std::span<const Mat4> joints, std::vector<Vec3>& positions,
                   std::vector<Vec3>& normals);

// Throws Error naming `source` if an influence is not usable by a skin with `joint_count`
// joints: count differing from the vertex count, a joint index out of range, a negative
// or non-finite weight, or weights that do not sum to 1.
void check_influences(const Mesh& mesh, size_t joint_count, const std::string& source);

}  // namespace gilab
