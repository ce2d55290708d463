#pragma once
// What gilab.Scene holds: the scene as `gilab render` opens it, plus how it was named, so
// Python calls on it reuse the CLI's own code (open_scene, describe_scene).
#include <string>
#include "core/io/asset_paths.hpp"
#include "scenes/scene_library.hpp"

namespace gilab::python {

struct LoadedScene {
    std::string spec;  // what the user typed: a built-in name, a scene file name or a path
    AssetPaths assets;
    OpenedScene opened;
};

}  // namespace gilab::python
