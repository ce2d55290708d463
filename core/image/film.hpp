#pragma once
// A film is the output of one view: named float layers of equal size plus provenance
// metadata. "color" is the beauty image; techniques add layers such as "direct",
// "indirect", "albedo", "normal" (3 channels) and "depth" (1 channel).
#include <map>
#include <string>
#include <vector>
#include "core/util/math.hpp"

namespace gilab {

struct Layer {
    int channels = 3;
    std::vector<float> data;  // row-major, top row first, channels interleaved
};

class Film {
public:
    Film() = default;
    Film(int width, int height);  // creates the "color" layer

    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixel_count() const { return size_t(width_) * size_t(height_); }

    Layer& add_layer(const std::string& name, int channels = 3);  // zero-filled; idempotent
    bool has_layer(const std::string& name) const { return layers_.count(name) != 0; }
    Layer& layer(const std::string& name);              // throws Error if missing
    const Layer& layer(const std::string& name) const;
    const std::map<std::string, Layer>& layers() const { return layers_; }

    Vec3 get(const std::string& layer, int x, int y) const;
    void set(const std::string& layer, int x, int y, const Vec3& value);
    void set(const std::string& layer, int x, int y, float value);  // 1-channel layers

    // Provenance written into file headers (technique, spp, seed, render time, ...).
    std::map<std::string, std::string> metadata;

private:
    int width_ = 0, height_ = 0;
    std::map<std::string, Layer> layers_;
};

// Throws Error when width or height is not positive, or when `layers_hint` RGB float
// layers of that size do not fit the memory budget (--memory-limit): checked before
// anything is allocated.
void check_resolution(int width, int height, int layers_hint = 8);

}  // namespace gilab
