#pragma once
// Opening a scene by what a user types: a built-in name ("cornell"), the name of a scene
// file in scenes/ ("bunny" → scenes/bunny.json), or a path to a .json/.obj/.gltf/.glb/
// .ply/.off file. Mesh files without lights or a camera get a default sun and a camera
// framing the bounds (with a note in `warnings`).
#include <string>
#include <vector>
#include "core/io/asset_paths.hpp"
#include "core/scene/scene.hpp"

namespace gilab {

struct OpenedScene {
    Scene scene;
    std::vector<std::string> warnings;
    bool default_camera = false;  // the scene had no camera; default_camera_for chose one
};

OpenedScene open_scene(const std::string& spec, const AssetPaths& assets);
// Names of the scene description files shipped in scenes/ (without ".json").
std::vector<std::string> scene_file_names();
// The directory holding the shipped scene files.
std::string scenes_directory();

// A camera framing the bounds, used when a scene gives none: from the front (−Z side),
// a little above; for flat bounds (one extent under 1% of the largest) straight along
// the thin axis, so a flat model is seen face-on rather than edge-on.
SceneCamera default_camera_for(const Bounds3& bounds);
// The same, but when that view would see the surface nearly edge-on (under 5% of its
// area face-on, e.g. a tilted flat model), looks along the direction most of the
// surface faces instead. `edge_on` tells whether even that view sees it edge-on.
SceneCamera default_camera_for(const SceneFrame& frame, bool* edge_on = nullptr);

}  // namespace gilab
