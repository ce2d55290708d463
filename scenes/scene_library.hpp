#pragma once
// Opening a scene by what a user types: a built-in name ("cornell"), the name of a scene
// file in scenes/ ("bunny" → scenes/bunny.json), or a path to a .json/.obj/.gltf/.glb/
// .ply/.off file. Mesh files without lights or a camera get a default sun and a camera
// framing the bounds (with a note in `warnings`).
#include <string>
#include <vector>
#include "core/asset_paths.hpp"
#include "core/scene.hpp"

namespace gilab {

struct OpenedScene {
    Scene scene;
    std::vector<std::string> warnings;
};

OpenedScene open_scene(const std::string& spec, const AssetPaths& assets);
// Names of the scene description files shipped in scenes/ (without ".json").
std::vector<std::string> scene_file_names();
// The directory holding the shipped scene files.
std::string scenes_directory();

// A camera looking at the scene bounds from the front (−Z side), used when none is given.
SceneCamera default_camera_for(const Bounds3& bounds);

}  // namespace gilab
