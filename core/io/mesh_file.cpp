#include <algorithm>
#include <cctype>
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"

namespace gilab {

Scene load_mesh_file(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".obj") return load_obj(path);
    if (ext == ".gltf" || ext == ".glb") return load_gltf(path);
    if (ext == ".ply" || ext == ".off") return load_ply_or_off(path);
    throw Error(path.string(), "unknown mesh file extension '" + ext + "' (supported: .obj, .gltf, .glb, .ply, .off)");
}

}  // namespace gilab
