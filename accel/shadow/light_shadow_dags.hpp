#pragma once
// The shadow DAGs (P2 §3) that cover everything one light can shadow: one over the light
// space of a directional or spot light, and for a point light six, over spot frusta on
// the faces of a cube around it. Each face's frustum is widened from 45° to 46° half-angle
// so that a lookup point, which is moved a few voxels off the surface (LightSpace::
// lookup_coords), still falls inside the face it was assigned to near a seam. A face that
// has no triangle overlapping its frustum (a conservative test of every triangle, so a
// face holding only tiny or thin geometry still gets its DAG) holds no DAG, and points
// assigned to it are lit.
#include <array>
#include <cstddef>
#include <optional>
#include "accel/shadow/shadow_dag.hpp"

namespace gilab {

class LightShadowDags {
public:
    static constexpr int kCubeFaces = 6;
    static constexpr float kCubeFaceHalfAngleDegrees = 46.0f;

    // Throws Error as ShadowDag::build does; a point light's faces that see nothing are
    // skipped, but a light that sees nothing at all is an error.
    static LightShadowDags build(const Scene& scene, const RayTracer& tracer, const PunctualLight& light,
                                 const ShadowDagOptions& options);

    // One lookup path per DAG, kept between lookups (ShadowDag::Cursor). One per thread.
    struct Cursor {
        std::array<ShadowDag::Cursor, kCubeFaces> dags;
    };
    float visibility(const Vec3& p, const Vec3& normal, int pcf, Cursor& cursor) const;

    bool cube() const { return cube_; }
    size_t dag_count() const;      // DAGs built (1, or up to 6 for a point light)
    size_t bytes() const;          // stored words of every DAG
    double build_ms() const { return build_ms_; }
    const std::optional<ShadowDag>& dag(int i) const { return dags_[size_t(i)]; }
    // The spot light standing for cube face i (+x, −x, +y, −y, +z, −z) of a point light.
    static PunctualLight cube_face(const PunctualLight& point, int face);

private:
    bool cube_ = false;
    Vec3 position_{0};
    std::array<std::optional<ShadowDag>, kCubeFaces> dags_;  // [0] only, unless cube_
    double build_ms_ = 0;
};

}  // namespace gilab
