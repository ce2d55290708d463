#pragma once
#include <cstdint>
#include "core/util/math.hpp"

namespace gilab {

struct Ray {
    Vec3 origin{0};
    Vec3 direction{0, 0, -1};   // need not be normalized; t is in units of |direction|
    float tmin = 0.0f;
    float tmax = kInfinity;
    Vec3 at(float t) const { return origin + t * direction; }
};

inline constexpr uint32_t kInvalidId = 0xffffffffu;

// Closest-hit record: which world mesh and triangle, barycentrics (u, v) of vertices 1, 2.
struct Hit {
    float t = kInfinity;
    uint32_t mesh = kInvalidId;
    uint32_t triangle = kInvalidId;
    float u = 0, v = 0;
    Vec3 geometric_normal{0};  // unnormalized, as Embree reports it
    bool valid() const { return mesh != kInvalidId; }
};

}  // namespace gilab
