#include "core/texture/image_decode.hpp"
#include <cstring>
#include <limits>
#include "core/util/error.hpp"
#include "core/util/input_file.hpp"
#include "core/util/memory_budget.hpp"

// A private copy of stb_image: other libraries (tinygltf) and tests link their own.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace gilab {

uint64_t pyramid_bytes(uint64_t width, uint64_t height) {
    uint64_t total = 0;
    for (;;) {
        total += MemoryBudget::times(MemoryBudget::times(width, height), 4);
        if (width <= 1 && height <= 1) return total;
        width = std::max<uint64_t>(1, width / 2);
        height = std::max<uint64_t>(1, height / 2);
    }
}

Rgba8Image decode_image(std::span<const uint8_t> encoded, const std::string& where) {
    if (encoded.empty()) throw Error(where, "empty image file");
    if (encoded.size() > uint64_t(std::numeric_limits<int>::max()))
        throw Error(where, "image file larger than 2 GiB, which the image decoder cannot read");
    const int size = int(encoded.size());
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(encoded.data(), size, &w, &h, &channels))
        throw Error(where, std::string("not a decodable image (") + stbi_failure_reason() + ")");
    if (w <= 0 || h <= 0) throw Error(where, "image header gives a size of zero");
    if (w > kMaxTextureSide || h > kMaxTextureSide)
        throw Error(where, "image of " + std::to_string(w) + " × " + std::to_string(h) + " texels: a side over " +
                               std::to_string(kMaxTextureSide) + " is refused");
    // The decoder's own buffer (up to 16 bits per channel) and the 8-bit pyramid.
    MemoryBudget::check(MemoryBudget::times(uint64_t(w) * uint64_t(h), 8) + pyramid_bytes(uint64_t(w), uint64_t(h)),
                        "decoding a " + std::to_string(w) + " × " + std::to_string(h) + " texture with its mip levels",
                        where);
    int dw = 0, dh = 0, dc = 0;
    stbi_uc* pixels = stbi_load_from_memory(encoded.data(), size, &dw, &dh, &dc, 4);
    if (!pixels) throw Error(where, std::string("image could not be decoded (") + stbi_failure_reason() + ")");
    Rgba8Image out;
    out.width = dw;
    out.height = dh;
    try {
        out.texels.assign(pixels, pixels + size_t(dw) * size_t(dh) * 4);
    } catch (...) {
        stbi_image_free(pixels);
        throw;
    }
    stbi_image_free(pixels);
    if (dw != w || dh != h) throw Error(where, "image decoded to a size other than its header's");
    return out;
}

Rgba8Image decode_image_file(const std::filesystem::path& path) {
    const std::string bytes = read_input_file(path);
    return decode_image(std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), path.string());
}

}  // namespace gilab
