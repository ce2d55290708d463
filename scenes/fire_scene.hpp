#pragma once
// The `fire` scene: the DAG paper's "mostly random motion" regime (P2 §4, Table 5). A
// ground disc and five logs stay still while thousands of tiny particles rise from the
// logs, wander sideways, shrink and respawn. Every particle is its own node with one
// step key per frame, so frame k shows exactly the simulated state k (a respawn never
// smears between keys), and all randomness comes from one stream seeded by `seed`, so
// the same options always give the same scene.
#include <cstdint>
#include "core/scene/scene.hpp"

namespace gilab {

struct FireOptions {
    int particles = 4000;   // closed 1 cm octahedra
    int frames = 100;       // animation_frame_count() of the result
    double fps = 30.0;
    uint64_t seed = 1;
};

// Throws Error for a non-positive particle count, fewer than 2 frames or fps ≤ 0.
Scene make_fire_scene(const FireOptions& options = {});

}  // namespace gilab
