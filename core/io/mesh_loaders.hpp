#pragma once
// Mesh-file loaders. Each returns a Scene (meshes, materials, nodes, lights where the
// format has them) or throws Error naming the file (and line where the format has
// lines) and what is wrong. NaN/Inf vertices and out-of-range indices are errors;
// zero-area triangles are dropped and counted in Scene::degenerate_triangles_dropped.
#include <filesystem>
#include "core/scene/scene.hpp"

namespace gilab {

Scene load_obj(const std::filesystem::path& path);    // OBJ + MTL (Kd, Ks, Ns, Ke) via tinyobjloader
Scene load_gltf(const std::filesystem::path& path);   // .gltf / .glb via tinygltf
Scene load_ply_or_off(const std::filesystem::path& path);  // .ply / .off via CGAL
// Picks the loader by extension (case-insensitive); unknown extension → Error.
Scene load_mesh_file(const std::filesystem::path& path);

}  // namespace gilab
