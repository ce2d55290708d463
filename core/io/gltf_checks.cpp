#include "core/io/gltf_checks.hpp"

#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include "core/util/error.hpp"
#include "core/util/input_file.hpp"
#include "core/util/json_document.hpp"
#include "core/util/memory_budget.hpp"

namespace gilab {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

uint32_t read_u32(const std::string& bytes, size_t at) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;  // GLB is little-endian, as is every platform gilab builds on
}

// Extensions gilab reads, or whose absence only changes appearance slightly.
const std::set<std::string>& supported_required_extensions() {
    static const std::set<std::string> names = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                                "KHR_mesh_quantization", "KHR_texture_transform",
                                                "KHR_materials_unlit"};
    return names;
}

std::string compression_message(const std::string& extension) {
    if (extension == "KHR_draco_mesh_compression")
        return "Draco compression (KHR_draco_mesh_compression) is not supported; decompress the file first "
               "(e.g. gltf-transform copy)";
    if (extension == "EXT_meshopt_compression" || extension == "KHR_meshopt_compression")
        return "meshopt compression (" + extension + ") is not supported; decompress the file first";
    return "";
}

std::string percent_decode(const std::string& uri) {
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
            std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
            out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

// Whole non-negative integer, as glTF's counts and lengths must be.
std::optional<uint64_t> json_count(const json& v) {
    if (v.is_number_unsigned()) return v.get<uint64_t>();
    if (v.is_number_integer() && v.get<int64_t>() >= 0) return uint64_t(v.get<int64_t>());
    if (v.is_number_float()) {
        const double d = v.get<double>();
        if (d >= 0 && d < 9.007199254740992e15 && d == std::floor(d)) return uint64_t(d);
    }
    return std::nullopt;
}

void check_version(const json& doc, const std::string& file) {
    const json* asset = doc.contains("asset") && doc["asset"].is_object() ? &doc["asset"] : nullptr;
    const json* version = asset && asset->contains("version") && (*asset)["version"].is_string() ? &(*asset)["version"] : nullptr;
    if (!version) {
        // glTF 1.0 kept its objects in dictionaries and had shaders; 2.0 uses arrays.
        bool v1 = doc.contains("shaders") || doc.contains("programs") || doc.contains("techniques");
        for (const char* key : {"buffers", "meshes", "accessors", "nodes"})
            v1 |= doc.contains(key) && doc[key].is_object();
        if (v1) throw Error(file, "glTF 1.0 is not supported; gilab reads glTF 2.0 (convert the file first)");
        throw Error(file, std::string(asset ? "/asset/version" : "/asset") + ": missing (glTF 2.0 requires asset.version)");
    }
    const std::string text = version->get<std::string>();
    const int major = std::atoi(text.c_str());
    if (major == 1) throw Error(file, "/asset/version: glTF 1.0 is not supported ('" + text + "'); gilab reads glTF 2.0 (convert the file first)");
    if (major != 2 || text.size() < 2 || text[1] != '.')
        throw Error(file, "/asset/version: glTF version '" + text + "' is not supported; gilab reads glTF 2.x");
    if (asset->contains("minVersion") && (*asset)["minVersion"].is_string()) {
        const std::string min = (*asset)["minVersion"].get<std::string>();
        if (min != "2.0")
            throw Error(file, "/asset/minVersion: the file needs a glTF " + min + " reader; gilab reads glTF 2.0");
    }
}

void check_extensions(const json& doc, const std::string& file) {
    if (doc.contains("extensionsRequired") && doc["extensionsRequired"].is_array()) {
        const json& list = doc["extensionsRequired"];
        for (size_t i = 0; i < list.size(); ++i) {
            if (!list[i].is_string()) continue;
            const std::string name = list[i].get<std::string>();
            const std::string ptr = "/extensionsRequired/" + std::to_string(i);
            if (supported_required_extensions().count(name)) continue;
            const std::string compression = compression_message(name);
            throw Error(file, ptr + ": " + (compression.empty() ? "required extension '" + name + "' is not supported" : compression));
        }
    }
    // A compressed primitive whose accessors have no buffer view has no uncompressed
    // fallback, even when the extension is not listed as required.
    if (!doc.contains("meshes") || !doc["meshes"].is_array()) return;
    const json& meshes = doc["meshes"];
    const json* accessors = doc.contains("accessors") && doc["accessors"].is_array() ? &doc["accessors"] : nullptr;
    auto without_data = [&](const json& index) {
        if (!index.is_number_integer() || !accessors) return false;
        const int64_t a = index.get<int64_t>();
        return a >= 0 && size_t(a) < accessors->size() && (*accessors)[size_t(a)].is_object() &&
               !(*accessors)[size_t(a)].contains("bufferView");
    };
    for (size_t m = 0; m < meshes.size(); ++m) {
        if (!meshes[m].is_object() || !meshes[m].contains("primitives") || !meshes[m]["primitives"].is_array()) continue;
        const json& prims = meshes[m]["primitives"];
        for (size_t p = 0; p < prims.size(); ++p) {
            const json& prim = prims[p];
            if (!prim.is_object() || !prim.contains("extensions") || !prim["extensions"].is_object()) continue;
            for (auto it = prim["extensions"].begin(); it != prim["extensions"].end(); ++it) {
                const std::string compression = compression_message(it.key());
                if (compression.empty()) continue;
                bool fallback = true;
                if (prim.contains("attributes") && prim["attributes"].is_object())
                    for (const auto& a : prim["attributes"]) fallback &= !without_data(a);
                if (prim.contains("indices")) fallback &= !without_data(prim["indices"]);
                if (!fallback)
                    throw Error(file, "/meshes/" + std::to_string(m) + "/primitives/" + std::to_string(p) +
                                          "/extensions/" + it.key() + ": " + compression);
            }
        }
    }
}

// Bytes a base64 data URI decodes to.
uint64_t data_uri_bytes(const std::string& uri) {
    const size_t comma = uri.find(',');
    if (comma == std::string::npos) return 0;
    const bool base64 = uri.rfind(";base64", comma) != std::string::npos;
    uint64_t n = uri.size() - comma - 1;
    if (!base64) return n;
    size_t pad = 0;
    for (size_t i = uri.size(); i > comma + 1 && uri[i - 1] == '='; --i) ++pad;
    return (n / 4) * 3 - std::min<uint64_t>(pad, (n / 4) * 3);
}

// The file a uri names, where tinygltf looks for it: beside the glTF file, then in the
// working directory. Empty when there is none; Error(file, "PTR/uri: 'URI' is a ...,
// not a regular file") when the name is taken by a device, FIFO or directory.
fs::path referenced_file(const fs::path& gltf, const std::string& ptr, const std::string& uri) {
    const std::string name = percent_decode(uri);
    const std::string dir = gltf.parent_path().string();
    for (const std::string& candidate : {dir.empty() ? name : dir + "/" + name, "./" + name}) {
        const std::string problem = non_regular_file_problem(candidate);
        if (!problem.empty()) throw Error(gltf.string(), ptr + "/uri: '" + uri + "' " + problem);
        if (regular_file_exists(candidate)) return candidate;
    }
    return {};
}

// External images are read by tinygltf, which turns a failed read into a warning: a
// device or FIFO named as an image must be refused before it starts.
void check_images(const json& doc, const fs::path& path) {
    if (!doc.contains("images") || !doc["images"].is_array()) return;
    const json& images = doc["images"];
    for (size_t i = 0; i < images.size(); ++i) {
        const json& image = images[i];
        if (!image.is_object() || !image.contains("uri") || !image["uri"].is_string()) continue;
        const std::string uri = image["uri"].get<std::string>();
        if (uri.rfind("data:", 0) != 0) referenced_file(path, "/images/" + std::to_string(i), uri);
    }
}

uint64_t check_buffers(const json& doc, const fs::path& path, bool glb, bool has_bin, uint64_t bin_length) {
    const std::string file = path.string();
    if (!doc.contains("buffers")) return 0;
    const json& buffers = doc["buffers"];
    if (!buffers.is_array()) throw Error(file, "/buffers: expected an array");
    uint64_t total = 0;
    for (size_t b = 0; b < buffers.size(); ++b) {
        const std::string ptr = "/buffers/" + std::to_string(b);
        const json& buf = buffers[b];
        if (!buf.is_object()) throw Error(file, ptr + ": expected an object");
        if (!buf.contains("byteLength")) throw Error(file, ptr + ": missing byteLength");
        const auto length = json_count(buf["byteLength"]);
        if (!length || *length == 0)
            throw Error(file, ptr + "/byteLength: " + buf["byteLength"].dump() + " is not a positive integer");
        MemoryBudget::check(*length, "buffer " + std::to_string(b) + " (byteLength " + std::to_string(*length) + ")", file);
        if (!buf.contains("uri")) {
            if (!glb || b != 0) throw Error(file, ptr + ": no uri (only the first buffer of a .glb may use its BIN chunk)");
            if (!has_bin) throw Error(file, ptr + ": byteLength " + std::to_string(*length) + " but the GLB has no BIN chunk");
            if (*length > bin_length)
                throw Error(file, ptr + "/byteLength: " + std::to_string(*length) + " bytes, but the GLB's BIN chunk holds only " +
                                      std::to_string(bin_length) + " (truncated or corrupt file)");
        } else {
            if (!buf["uri"].is_string()) throw Error(file, ptr + "/uri: expected a string");
            const std::string uri = buf["uri"].get<std::string>();
            if (uri.rfind("data:", 0) == 0) {
                const uint64_t held = data_uri_bytes(uri);
                if (held < *length)
                    throw Error(file, ptr + "/byteLength: " + std::to_string(*length) + " bytes, but its data URI holds only " +
                                          std::to_string(held));
            } else {
                const fs::path found = referenced_file(path, ptr, uri);
                if (found.empty()) throw Error(file, ptr + "/uri: buffer file '" + uri + "' not found beside the glTF file");
                const uint64_t size = input_file_size(found);
                if (size != *length)
                    throw Error(file, ptr + "/byteLength: " + std::to_string(*length) + " bytes, but '" + uri + "' holds " +
                                          std::to_string(size) + (size < *length ? " (truncated?)" : " (they must match)"));
            }
        }
        total += *length;
        MemoryBudget::check(total, "the buffers (" + std::to_string(total) + " bytes so far)", file);
    }
    return total;
}

// tinygltf's file-system callbacks, reading only regular files within the budget.
bool file_exists(const std::string& path, void*) {
    std::error_code ec;
    return fs::exists(path, ec);
}

std::string expand_path(const std::string& path, void*) { return path; }

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
    try {
        const std::string bytes = read_input_file(path);
        out->assign(bytes.begin(), bytes.end());
        return true;
    } catch (const Error& e) {
        if (err) *err += std::string(e.what()) + "\n";
        return false;
    }
}

bool write_whole_file(std::string* err, const std::string& path, const std::vector<unsigned char>&, void*) {
    if (err) *err += path + ": writing is not supported\n";
    return false;
}

}  // namespace

GltfInput check_gltf_file(const fs::path& path, const std::string& bytes) {
    const std::string file = path.string();
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    GltfInput input;
    input.binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
    if (ext == ".glb" && !input.binary) {
        const size_t first = bytes.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
        if (first != std::string::npos && bytes[first] == '{')
            throw Error(file, "is a text glTF (JSON), not a binary GLB; rename it to .gltf");
        throw Error(file, "not a GLB file (no 'glTF' magic at its start)");
    }
    if (ext == ".gltf" && input.binary) throw Error(file, "is a binary GLB, not a text glTF; rename it to .glb");

    std::string json_text;
    bool has_bin = false;
    uint64_t bin_length = 0;
    if (input.binary) {
        if (bytes.size() < 20)
            throw Error(file, "malformed glTF: truncated GLB: " + std::to_string(bytes.size()) + " bytes, but the header and first chunk header need 20");
        const uint32_t version = read_u32(bytes, 4), length = read_u32(bytes, 8);
        if (version == 1) throw Error(file, "GLB version 1 (binary glTF 1.0) is not supported; gilab reads GLB version 2 (glTF 2.0)");
        if (version != 2) throw Error(file, "GLB version " + std::to_string(version) + " is not supported; gilab reads version 2");
        if (length < 20) throw Error(file, "malformed glTF: the GLB header declares a total length of " + std::to_string(length) + " bytes");
        if (length > bytes.size())
            throw Error(file, "malformed glTF: truncated GLB: the header declares " + std::to_string(length) + " bytes but the file has " +
                                  std::to_string(bytes.size()));
        const uint32_t json_length = read_u32(bytes, 12), json_type = read_u32(bytes, 16);
        if (json_type != kChunkJson) throw Error(file, "malformed glTF: the GLB's first chunk is not JSON");
        MemoryBudget::check_count(json_length, 1, length - 20, 1, "malformed glTF: GLB JSON chunk length", file);
        json_text = bytes.substr(20, json_length);
        const uint64_t next = 20 + uint64_t(json_length);
        if (next + 8 <= length) {
            const uint32_t chunk_length = read_u32(bytes, size_t(next)), chunk_type = read_u32(bytes, size_t(next) + 4);
            if (chunk_type == kChunkBin) {
                MemoryBudget::check_count(chunk_length, 1, length - next - 8, 1, "malformed glTF: GLB BIN chunk length", file);
                has_bin = true;
                bin_length = chunk_length;
            }
        }
    } else {
        json_text = bytes;
    }
    check_text_encoding(json_text, file, "glTF JSON");
    const json doc = parse_json_document(json_text, file, "malformed glTF: ");
    if (!doc.is_object()) throw Error(file, "/: expected a JSON object, got " + std::string(doc.type_name()));
    check_version(doc, file);
    check_extensions(doc, file);
    input.input_bytes = bytes.size() + check_buffers(doc, path, input.binary, has_bin, bin_length);
    check_images(doc, path);
    return input;
}

void use_checked_file_access(tinygltf::TinyGLTF& reader) {
    tinygltf::FsCallbacks callbacks{};
    callbacks.FileExists = file_exists;
    callbacks.ExpandFilePath = expand_path;
    callbacks.ReadWholeFile = read_whole_file;
    callbacks.WriteWholeFile = write_whole_file;
    callbacks.user_data = nullptr;
    reader.SetFsCallbacks(callbacks);
}

}  // namespace gilab
