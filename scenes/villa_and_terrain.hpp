#pragma once
// Procedural stand-ins for the shadow-DAG paper's scenes: a closed architectural scene
// (its "Villa" / "Citadel") and an open heightfield (its "Terrain"). Both are
// deterministic and lit by a directional sun, the first light in the scene.
#include "core/scene/scene.hpp"

namespace gilab {

// A walled villa about 40 m across on a thick 52 m × 52 m ground slab: enclosure walls
// with a gate and doorways, crenellations, four round corner towers with cone roofs, a
// square keep, a gable-roofed house and annex, a well. Every mesh is a separate closed,
// outward-wound solid, so solid voxelization and closed-mesh checks work per mesh.
Scene make_villa();

// A grid × grid vertex heightfield over 200 m × 200 m, heights from fixed-seed ridged
// fBm gradient noise (25 m amplitude, about 18 m of actual relief), as one open mesh
// under a low sun.
Scene make_fbm_terrain(int grid = 256);

}  // namespace gilab
