#pragma once
// The gilab scene description (.json): mesh files with transforms, material overrides,
// extra lights, a camera or HMD rig, and a keyframed animation. Errors name the file
// and the JSON path of the offending value (e.g. "scene.json: /meshes/2/file: ...").
#include <filesystem>
#include "core/io/asset_paths.hpp"
#include "core/scene/scene.hpp"

namespace gilab {

Scene load_scene_file(const std::filesystem::path& path, const AssetPaths& assets);

}  // namespace gilab
