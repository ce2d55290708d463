#pragma once
// Scenes built in code, available by name without any asset files.
#include <functional>
#include <string>
#include <vector>
#include "core/scene/scene.hpp"

namespace gilab {

// The Cornell box from the original Cornell measurements, scaled so the box is about one
// unit wide (the photon-mapping paper's radii are in these units). 30 triangles of walls
// and blocks (five faces per block), plus the two-triangle ceiling light.
Scene make_cornell_box();

// The Cornell box with textures that show each material feature: a checkerboard back
// wall (material "checker", base colour texture), a rippled floor ("rippled floor", a
// normal map: RippleNormalMap's defaults, 8 ripples across) and a horizontal panel of
// four leaves hanging under the light ("leaf", an alpha mask tested at 0.5), whose
// patterned shadow falls on the floor and the blocks. Every quad's UVs span [0, 1]².
Scene make_textured_cornell_box();

// A closed sphere seen from inside, uniform albedo and emission: the white furnace.
Scene make_furnace_sphere(float albedo, float emission, int subdivisions = 3);

struct BuiltinScene {
    std::string name;
    std::string description;
    std::function<Scene()> make;
};
const std::vector<BuiltinScene>& builtin_scenes();

}  // namespace gilab
