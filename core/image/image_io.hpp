#pragma once
// Film output. Every writer writes to a temporary file in the target directory and
// renames it into place, so an interrupted or failed write leaves no partial file.
#include <cstdint>
#include <filesystem>
#include <vector>
#include "core/image/film.hpp"

namespace gilab {

// Multi-layer EXR: channels "R,G,B" for color, "<layer>.R/.G/.B" (or "<layer>.Y" for
// 1-channel layers) for the others; metadata as string attributes.
void write_exr(const std::filesystem::path& path, const Film& film);
// Stereo pair in one file using OpenEXR's multi-view convention: a "multiView"
// attribute {left, right}; the default view (left) keeps plain names for color ("R"),
// the right view's are prefixed ("right.R"). Layer channels carry the view before the
// channel, as the convention requires: "direct.left.R", "direct.right.R". Both films must
// have the same size. Metadata from the left film.
void write_exr_stereo(const std::filesystem::path& path, const Film& left, const Film& right);
// Reads back what write_exr wrote (for tests and tools): layers and string metadata.
// For multi-view files, view "" means the default view; otherwise a view name.
Film read_exr(const std::filesystem::path& path, const std::string& view = "");

// Tone-mapped sRGB 8-bit PNG of the "color" layer (exposure in stops, Reinhard-free
// clamp after exposure; NaN shows as magenta so it cannot hide).
void write_png(const std::filesystem::path& path, const Film& film, float exposure = 0.0f,
               const std::string& layer = "color");
void write_png_side_by_side(const std::filesystem::path& path, const Film& left,
                            const Film& right, float exposure = 0.0f);

// An 8-bit RGB PNG of width × height pixels (rows top first), written atomically.
void write_rgb_png(const std::filesystem::path& path, const std::vector<uint8_t>& rgb, int width, int height);

// Atomic text/binary write (temp file + rename). Throws Error on failure.
void write_file_atomically(const std::filesystem::path& path, const std::string& contents);

}  // namespace gilab
