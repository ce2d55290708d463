#pragma once
// Checks of a .gltf / .glb file before tinygltf reads it. tinygltf trusts what the file
// declares — a buffer's byteLength, the file a buffer's uri names, GLB chunk lengths —
// and allocates accordingly, and it reports a glTF 1.0 file or a Draco-compressed one
// with a misleading message. Here the GLB container, the glTF version, the required
// extensions and every buffer (against the bytes really there and the memory budget)
// are checked first; errors name the file and the JSON pointer of the value.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace tinygltf {
class TinyGLTF;
}

namespace gilab {

struct GltfInput {
    bool binary = false;        // GLB container
    uint64_t input_bytes = 0;   // the file plus every buffer it references
};

// `bytes` is the whole .gltf or .glb file.
GltfInput check_gltf_file(const std::filesystem::path& path, const std::string& bytes);

// Makes `reader` read external buffers and images only from regular files, each within
// the memory budget (a uri of "." would otherwise read a directory as a huge file).
void use_checked_file_access(tinygltf::TinyGLTF& reader);


}  // namespace gilab
