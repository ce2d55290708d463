#pragma once
// Texture images decoded by stb_image (PNG, JPEG, TGA, BMP, PSD, GIF, HDR, PIC, PNM) into
// 8-bit RGBA. The header is read first: a size of zero, a side over kMaxTextureSide or a
// pyramid over the memory budget is refused before any texel is allocated.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include "core/texture/mip_map.hpp"

namespace gilab {

// Longer sides are refused: no real texture is this large, a corrupt header often is.
inline constexpr int kMaxTextureSide = 32768;

// Throws Error(where, ...) naming the problem when the bytes are not a decodable image,
// its size is refused, or its pyramid would exceed the memory budget.
Rgba8Image decode_image(std::span<const uint8_t> encoded, const std::string& where);
// The same for a file, read with read_input_file's checks.
Rgba8Image decode_image_file(const std::filesystem::path& path);

// Bytes of the 8-bit RGBA pyramid of a width × height image, at most 4/3 of its level 0.
uint64_t pyramid_bytes(uint64_t width, uint64_t height);

}  // namespace gilab
