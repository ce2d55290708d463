#include "core/scene/light.hpp"

namespace gilab {

const char* to_string(LightType type) {
    switch (type) {
        case LightType::Point: return "point";
        case LightType::Spot: return "spot";
        case LightType::Directional: return "directional";
    }
    return "unknown";
}

float spot_falloff(const PunctualLight& l, float cos_theta) {
    if (cos_theta >= l.cos_inner) return 1.0f;
    if (cos_theta <= l.cos_outer) return 0.0f;
    float t = (cos_theta - l.cos_outer) / (l.cos_inner - l.cos_outer);
    return t * t * (3.0f - 2.0f * t);
}

}  // namespace gilab
