#include "accel/shadow/light_shadow_dags.hpp"

#include <cmath>
#include <string>
#include "core/util/error.hpp"
#include "core/util/stats.hpp"

namespace gilab {

PunctualLight LightShadowDags::cube_face(const PunctualLight& point, int face) {
    static const char* const kNames[kCubeFaces] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    PunctualLight spot = point;
    spot.type = LightType::Spot;
    spot.name = point.name + " " + kNames[face];
    spot.direction = Vec3(0);
    spot.direction[face / 2] = face % 2 ? -1.0f : 1.0f;
    spot.cos_outer = spot.cos_inner = std::cos(kCubeFaceHalfAngleDegrees * kPi / 180.0f);
    return spot;
}

LightShadowDags LightShadowDags::build(const Scene& scene, const RayTracer& tracer, const PunctualLight& light,
                                       const ShadowDagOptions& options) {
    Stopwatch clock;
    LightShadowDags out;
    if (light.type != LightType::Point) {
        out.dags_[0] = ShadowDag::build(scene, tracer, light, options);
    } else {
        out.cube_ = true;
        out.position_ = light.position;
        for (int f = 0; f < kCubeFaces; ++f) {
            const PunctualLight face = cube_face(light, f);
            if (ShadowDag::light_sees_geometry(tracer, face))
                out.dags_[size_t(f)] = ShadowDag::build(scene, tracer, face, options);
        }
        if (out.dag_count() == 0)
            throw Error("shadow DAG (light '" + light.name + "')", "the point light sees no geometry in any direction");
    }
    out.build_ms_ = clock.elapsed_ms();
    return out;
}

float LightShadowDags::visibility(const Vec3& p, const Vec3& normal, int pcf, Cursor& cursor) const {
    if (!cube_) return dags_[0]->visibility(p, normal, pcf, cursor.dags[0]);
    // The face whose frustum axis is nearest the direction from the light to p.
    const Vec3 r = p - position_;
    const Vec3 a = glm::abs(r);
    const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    const int face = 2 * axis + (r[axis] < 0 ? 1 : 0);
    const std::optional<ShadowDag>& dag = dags_[size_t(face)];
    if (!dag) {
        // Nothing in this face's view to cast a shadow; a surface turned away is still unlit.
        return glm::dot(normal, -r) > 0 ? 1.0f : 0.0f;
    }
    return dag->visibility(p, normal, pcf, cursor.dags[size_t(face)]);
}

size_t LightShadowDags::dag_count() const {
    size_t n = 0;
    for (const auto& d : dags_) n += d.has_value();
    return n;
}

size_t LightShadowDags::bytes() const {
    size_t n = 0;
    for (const auto& d : dags_)
        if (d) n += d->bytes();
    return n;
}

}  // namespace gilab
