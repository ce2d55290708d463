#pragma once
// Reading a file the user named. It must exist and be a regular file (a directory or a
// device would read as garbage or as "infinitely" long); its size counts against the
// memory budget before it is read; text formats refuse UTF-16 and NUL bytes, which
// parsers otherwise read as an empty or nonsensical file.
#include <cstdint>
#include <filesystem>
#include <string>

namespace gilab {

// Why `path` cannot be read although something is there: "is a directory, not a
// regular file", "is a character device, not a regular file", "is a FIFO (named pipe),
// not a regular file", ... Empty when it is a regular file or when nothing is there.
// Every file gilab reads — meshes, MTL libraries, glTF buffers and images, scene-file
// references — is checked with this before it is opened: a device reads forever, a
// FIFO blocks, a directory reads as garbage.
std::string non_regular_file_problem(const std::filesystem::path& path);

// True when `path` is a regular file, false when nothing is there; throws
// Error(path, non_regular_file_problem(path)) when something else is.
bool regular_file_exists(const std::filesystem::path& path);

// Size in bytes; throws Error(path, "file not found" | non_regular_file_problem(path) | ...).
uint64_t input_file_size(const std::filesystem::path& path);

// The whole file, after input_file_size's checks and MemoryBudget::check of its size.
std::string read_input_file(const std::filesystem::path& path);

// Throws Error(file, ...) when `bytes` is UTF-16 (byte-order mark or NUL bytes) or holds
// NUL bytes; `format` names the expected text format, e.g. "OBJ".
void check_text_encoding(const std::string& bytes, const std::string& file, const std::string& format);

}  // namespace gilab
