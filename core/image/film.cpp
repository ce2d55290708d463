#include "core/image/film.hpp"

#include <cstdio>
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"

namespace gilab {

namespace {

void check_pixel(const Film& film, const std::string& layer, int x, int y) {
    if (x < 0 || y < 0 || x >= film.width() || y >= film.height()) {
        throw Error("film layer '" + layer + "'",
                    "pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                        ") is outside the " + std::to_string(film.width()) + "x" +
                        std::to_string(film.height()) + " image");
    }
}

}  // namespace

void check_resolution(int width, int height, int layers_hint) {
    std::string resolution = std::to_string(width) + "x" + std::to_string(height);
    if (width <= 0 || height <= 0) {
        throw Error("resolution " + resolution + " is invalid: width and height must be positive");
    }
    if (layers_hint < 1) layers_hint = 1;
    // Both factors are below 2^31, so their product and the saturating multiplications
    // cannot wrap.
    const uint64_t pixels = uint64_t(width) * uint64_t(height);
    const uint64_t bytes = MemoryBudget::times(pixels, uint64_t(layers_hint) * 3 * sizeof(float));
    MemoryBudget::check(bytes, std::to_string(layers_hint) + " RGB float layer(s) of " + resolution + " pixels",
                        "resolution " + resolution);
}

Film::Film(int width, int height) : width_(width), height_(height) {
    check_resolution(width, height, 1);
    add_layer("color", 3);
}

Layer& Film::add_layer(const std::string& name, int channels) {
    if (name.empty() || name.find('.') != std::string::npos) {
        throw Error("film layer '" + name + "'",
                    "layer names must be non-empty and contain no '.' (EXR channel separator)");
    }
    if (channels != 1 && channels != 3 && channels != 4) {
        throw Error("film layer '" + name + "'",
                    "unsupported channel count " + std::to_string(channels) + " (use 1, 3 or 4)");
    }
    auto it = layers_.find(name);
    if (it != layers_.end()) {
        if (it->second.channels != channels) {
            throw Error("film layer '" + name + "'",
                        "already exists with " + std::to_string(it->second.channels) +
                            " channels, requested " + std::to_string(channels));
        }
        return it->second;
    }
    Layer layer;
    layer.channels = channels;
    layer.data.assign(pixel_count() * size_t(channels), 0.0f);
    return layers_.emplace(name, std::move(layer)).first->second;
}

Layer& Film::layer(const std::string& name) {
    auto it = layers_.find(name);
    if (it == layers_.end()) throw Error("film", "no layer named '" + name + "'");
    return it->second;
}

const Layer& Film::layer(const std::string& name) const {
    auto it = layers_.find(name);
    if (it == layers_.end()) throw Error("film", "no layer named '" + name + "'");
    return it->second;
}

Vec3 Film::get(const std::string& name, int x, int y) const {
    const Layer& l = layer(name);
    check_pixel(*this, name, x, y);
    const float* p = l.data.data() + (size_t(y) * size_t(width_) + size_t(x)) * size_t(l.channels);
    if (l.channels == 1) return Vec3(p[0]);
    return Vec3(p[0], p[1], p[2]);
}

void Film::set(const std::string& name, int x, int y, const Vec3& value) {
    Layer& l = layer(name);
    check_pixel(*this, name, x, y);
    if (l.channels < 3) {
        throw Error("film layer '" + name + "'", "has 1 channel; set it with a float value");
    }
    float* p = l.data.data() + (size_t(y) * size_t(width_) + size_t(x)) * size_t(l.channels);
    p[0] = value.x;
    p[1] = value.y;
    p[2] = value.z;
}

void Film::set(const std::string& name, int x, int y, float value) {
    Layer& l = layer(name);
    check_pixel(*this, name, x, y);
    if (l.channels != 1) {
        throw Error("film layer '" + name + "'",
                    "has " + std::to_string(l.channels) + " channels; set it with a Vec3 value");
    }
    l.data[size_t(y) * size_t(width_) + size_t(x)] = value;
}

}  // namespace gilab
