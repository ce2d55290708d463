#pragma once
// A fingerprint of everything in a scene that changes what a renderer sees: geometry
// (positions, normals, texture coordinates, triangles, material ids, joint influences),
// materials, the node hierarchy with its rest transforms and animation keys, skins,
// lights and the frame rate. Names, the source path, the camera and loader notes are
// left out. Used to key cached renders, so that an edited scene never reuses one.
#include <string>
#include "core/scene/scene.hpp"

namespace gilab {

// 16 hexadecimal digits (64-bit FNV-1a over the fields above, in a fixed order).
std::string scene_content_hash(const Scene& scene);

}  // namespace gilab
