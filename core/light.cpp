#include "core/light.hpp"

namespace gilab {

const char* to_string(LightType type) {
    switch (type) {
        case LightType::Point: return "point";
        case LightType::Spot: return "spot";
        case LightType::Directional: return "directional";
    }
    return "unknown";
}

}  // namespace gilab
