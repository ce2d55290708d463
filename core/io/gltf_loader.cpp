// glTF 2.0 (.gltf / .glb) through tinygltf: node hierarchy, triangle meshes, metallic-
// roughness materials mapped onto the Lambert + Phong model, KHR_lights_punctual and
// node TRS animations.
//
// Units and conventions:
//  * Light intensities are taken as they are: candela (lm/sr) for point/spot lights is
//    used as W/sr, lux (lm/m²) for directional lights as W/m²; `color` multiplies it.
//  * Textures: baseColorTexture (sRGB; its alpha is the mask's), emissiveTexture (sRGB),
//    normalTexture (linear, with its scale), each with its texCoord set (0 or 1), its
//    sampler's wrap modes and KHR_texture_transform. Images are decoded once (through
//    core/texture/image_decode.hpp, within the memory budget) and shared between
//    materials. An image that cannot be decoded or is refused leaves its materials with
//    their factors alone and a warning naming it. alphaMode MASK tests alphaCutoff;
//    BLEND is read as MASK at 0.5 with a warning. The base colour texture multiplies the
//    diffuse albedo; a metal's glossy lobe keeps its factor's colour. metallicRoughness and occlusion
//    textures are not read (the Phong lobe has one roughness per material).
//  * CUBICSPLINE animation samplers use each key's value and ignore the tangents (the
//    curve is then interpolated linearly between keys).
//  * When several animations drive the same property of a node, the first one wins.
//  * Skins (JOINTS_0/WEIGHTS_0, inverse bind matrices) are kept for linear blend skinning
//    at evaluation time; the joints are ordinary nodes animated by the TRS channels.
//    JOINTS_1/WEIGHTS_1 are ignored (four influences per vertex) with a warning.
//  * Morph targets are not supported: the base shape is used and a warning says so.
//  * Numbers of extensions and cameras are checked like the scene file's own: a light's
//    colour and intensity and a material's emissiveStrength must be finite and ≥ 0,
//    spot cones 0 ≤ inner ≤ outer ≤ π/2 with outer > 0; a perspective camera needs yfov
//    in (0, π), 0 < znear < zfar and aspectRatio > 0. A degenerate camera is an error
//    naming it (not dropped for the default view); orthographic cameras are ignored
//    with a warning. Node scales that collapse every triangle to zero area, at rest and
//    across the animation, are an error ("nothing visible"), not a black image.
//  * Every accessor and index is range-checked: a bad file throws Error, never reads
//    outside its buffers. The file itself is checked before tinygltf reads it
//    (core/io/gltf_checks.hpp), and every allocation sized by the file is checked against
//    the memory budget first.
#include <tiny_gltf.h>

#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/io/gltf_checks.hpp"
#include "core/util/input_file.hpp"
#include "core/util/memory_budget.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/scene/skin.hpp"
#include "core/texture/image_decode.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

struct Context {
    const tinygltf::Model& model;
    std::string file;
    Scene& scene;
    uint64_t input_bytes = 0;  // the file and its buffers
    // Each image decoded once per encoding, shared by every material that uses it.
    std::map<std::pair<int, ColorEncoding>, std::shared_ptr<const MipMap>> images;
    void warn(const std::string& message) {
        const std::string w = file + ": " + message;
        for (const auto& existing : scene.warnings)
            if (existing == w) return;
        scene.warnings.push_back(w);
    }
};

// A validated window onto an accessor's bytes.
struct AccessorView {
    const unsigned char* data = nullptr;  // null: all zeros (accessor without buffer view)
    size_t stride = 0;
    size_t count = 0;
    int components = 0;
    int component_type = 0;
    bool normalized = false;
};

std::string accessor_label(int index, const std::string& what) {
    return what + " (accessor " + std::to_string(index) + ")";
}

AccessorView view_accessor(const Context& ctx, int index, const std::string& what) {
    const auto& m = ctx.model;
    if (index < 0 || size_t(index) >= m.accessors.size())
        throw Error(ctx.file, what + ": accessor " + std::to_string(index) + " is out of range (the file has " +
                                  std::to_string(m.accessors.size()) + " accessors)");
    const tinygltf::Accessor& a = m.accessors[size_t(index)];
    const std::string label = accessor_label(index, what);
    if (a.sparse.isSparse) throw Error(ctx.file, label + ": sparse accessors are not supported");
    AccessorView v;
    v.components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    if (v.components <= 0 || csize <= 0 || a.componentType == TINYGLTF_COMPONENT_TYPE_DOUBLE)
        throw Error(ctx.file, label + ": invalid accessor type or component type");
    v.count = a.count;
    v.component_type = a.componentType;
    v.normalized = a.normalized;
    const size_t element = size_t(v.components) * size_t(csize);
    if (a.bufferView < 0) {
        // All zeros, per the specification. Without sparse accessors such data carries
        // nothing, and one larger than the whole input can only be a corrupt count.
        MemoryBudget::check_count(v.count, element, ctx.input_bytes, element, label + " count (no buffer view)", ctx.file);
        return v;
    }
    if (size_t(a.bufferView) >= m.bufferViews.size())
        throw Error(ctx.file, label + ": buffer view " + std::to_string(a.bufferView) + " is out of range");
    const tinygltf::BufferView& bv = m.bufferViews[size_t(a.bufferView)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= m.buffers.size())
        throw Error(ctx.file, label + ": buffer " + std::to_string(bv.buffer) + " is out of range");
    const tinygltf::Buffer& buffer = m.buffers[size_t(bv.buffer)];
    if (bv.byteOffset > buffer.data.size() || bv.byteLength > buffer.data.size() - bv.byteOffset)
        throw Error(ctx.file, label + ": buffer view " + std::to_string(a.bufferView) +
                                  " reaches past the end of its buffer (truncated file?)");
    v.stride = bv.byteStride ? bv.byteStride : element;
    if (v.stride < element) throw Error(ctx.file, label + ": byte stride is smaller than one element");
    if (v.count > 0) {
        const size_t needed = a.byteOffset + v.stride * (v.count - 1) + element;
        if (a.byteOffset > bv.byteLength || needed > bv.byteLength || (v.count - 1) > bv.byteLength / v.stride)
            throw Error(ctx.file, label + ": " + std::to_string(v.count) + " elements reach past the end of buffer view " +
                                      std::to_string(a.bufferView) + " (out of range or truncated)");
    }
    v.data = buffer.data.data() + bv.byteOffset + a.byteOffset;
    return v;
}

float read_component(const unsigned char* p, int type, bool normalized) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float f;
            std::memcpy(&f, p, 4);
            return f;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(*p) / 255.0f : float(*p);
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            float f = float(int8_t(*p));
            return normalized ? std::max(f / 127.0f, -1.0f) : f;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t s;
            std::memcpy(&s, p, 2);
            return normalized ? float(s) / 65535.0f : float(s);
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t s;
            std::memcpy(&s, p, 2);
            return normalized ? std::max(float(s) / 32767.0f, -1.0f) : float(s);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t u;
            std::memcpy(&u, p, 4);
            return float(u);
        }
        default: return 0.0f;
    }
}

// All elements of an accessor as floats, `components` per element.
std::vector<float> read_floats(const Context& ctx, int index, int components, const std::string& what) {
    AccessorView v = view_accessor(ctx, index, what);
    if (v.components != components)
        throw Error(ctx.file, accessor_label(index, what) + ": has " + std::to_string(v.components) +
                                  " components per element, expected " + std::to_string(components));
    MemoryBudget::check(MemoryBudget::times(v.count, size_t(components) * sizeof(float)),
                        accessor_label(index, what) + " (" + std::to_string(v.count) + " elements)", ctx.file);
    std::vector<float> out(v.count * size_t(components), 0.0f);
    if (!v.data) return out;
    const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(v.component_type));
    for (size_t i = 0; i < v.count; ++i)
        for (int c = 0; c < components; ++c)
            out[i * size_t(components) + size_t(c)] =
                read_component(v.data + i * v.stride + size_t(c * csize), v.component_type, v.normalized);
    return out;
}

std::vector<uint32_t> read_indices(const Context& ctx, int index, const std::string& what) {
    AccessorView v = view_accessor(ctx, index, what);
    if (v.components != 1) throw Error(ctx.file, accessor_label(index, what) + ": indices must be scalars");
    MemoryBudget::check(MemoryBudget::times(v.count, sizeof(uint32_t) + 16),  // and the triangles they make
                        accessor_label(index, what) + " (" + std::to_string(v.count) + " indices)", ctx.file);
    std::vector<uint32_t> out(v.count, 0);
    if (!v.data) return out;
    for (size_t i = 0; i < v.count; ++i) {
        const unsigned char* p = v.data + i * v.stride;
        switch (v.component_type) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: out[i] = *p; break;
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                uint16_t s;
                std::memcpy(&s, p, 2);
                out[i] = s;
                break;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: std::memcpy(&out[i], p, 4); break;
            default:
                throw Error(ctx.file, accessor_label(index, what) +
                                          ": indices must be unsigned byte, short or int");
        }
    }
    return out;
}

// JOINTS_0: unsigned byte or short, four per vertex (the specification allows no other).
std::vector<uint16_t> read_joints(const Context& ctx, int index, const std::string& what) {
    AccessorView v = view_accessor(ctx, index, what);
    if (v.components != 4) throw Error(ctx.file, accessor_label(index, what) + ": joints must be VEC4");
    if (v.normalized || (v.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                         v.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT))
        throw Error(ctx.file, accessor_label(index, what) + ": joints must be unnormalised unsigned byte or short");
    const std::vector<float> f = read_floats(ctx, index, 4, what);
    return std::vector<uint16_t>(f.begin(), f.end());  // exact: at most 65535
}

// A node's translation, rotation and scale (glTF's default for each part it leaves out).
Transform node_trs(const tinygltf::Node& n) {
    Transform t;
    if (n.translation.size() == 3) t.translation = Vec3(n.translation[0], n.translation[1], n.translation[2]);
    if (n.rotation.size() == 4)
        t.rotation = glm::normalize(Quat(float(n.rotation[3]), float(n.rotation[0]), float(n.rotation[1]),
                                         float(n.rotation[2])));
    if (n.scale.size() == 3) t.scale = Vec3(n.scale[0], n.scale[1], n.scale[2]);
    return t;
}

Mat4 node_local_matrix(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) {
        Mat4 m;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[c][r] = float(n.matrix[size_t(c * 4 + r)]);
        return m;
    }
    return node_trs(n).matrix();
}

// Values are used in single precision: 1e300 would become infinity on the way.
void check_node_transform(const std::string& file, int index, const tinygltf::Node& n) {
    const std::pair<const char*, const std::vector<double>*> parts[] = {
        {"matrix", &n.matrix}, {"translation", &n.translation}, {"rotation", &n.rotation}, {"scale", &n.scale}};
    for (const auto& [name, values] : parts)
        for (size_t k = 0; k < values->size(); ++k) {
            const double v = (*values)[k];
            if (!std::isfinite(v) || std::abs(v) > double(std::numeric_limits<float>::max()))
                throw Error(file, "/nodes/" + std::to_string(index) + "/" + name + "/" + std::to_string(k) + ": " +
                                      number_as_given(v) + " is out of range (single precision holds at most ±3.4e38)");
        }
}

Transform node_local_transform(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) return Transform::from_matrix(node_local_matrix(n));
    return node_trs(n);
}

// KHR_lights_punctual numbers are checked like the scene file's own: a negative colour
// or intensity would add negative radiance (negative pixels), a cone outside
// 0 ≤ inner ≤ outer ≤ π/2 has no meaning. Errors name the light and its JSON path.
PunctualLight convert_light(const std::string& file, const tinygltf::Light& gl, int index) {
    PunctualLight light;
    light.name = gl.name.empty() ? "light" + std::to_string(index) : gl.name;
    const std::string ptr = "/extensions/KHR_lights_punctual/lights/" + std::to_string(index);
    auto fail = [&](const std::string& key, double value, const std::string& rule) {
        throw Error(file, ptr + "/" + key + ": light '" + light.name + "': " + number_as_given(value) + " " + rule);
    };
    auto finite_float = [](double v) { return std::isfinite(v) && std::abs(v) <= double(std::numeric_limits<float>::max()); };
    Vec3 color(1.0f);
    if (gl.color.size() >= 3) {
        for (size_t k = 0; k < 3; ++k)
            if (!finite_float(gl.color[k]) || gl.color[k] < 0)
                fail("color/" + std::to_string(k), gl.color[k], "is not a colour component (need a finite number ≥ 0)");
        color = Vec3(gl.color[0], gl.color[1], gl.color[2]);
    }
    if (!finite_float(gl.intensity) || gl.intensity < 0)
        fail("intensity", gl.intensity, "is not an intensity (need a finite number ≥ 0)");
    light.intensity = color * float(gl.intensity);
    light.position = Vec3(0.0f);
    light.direction = Vec3(0, 0, -1);  // glTF lights shine down their node's -Z
    if (gl.type == "point") {
        light.type = LightType::Point;
    } else if (gl.type == "spot") {
        light.type = LightType::Spot;
        const double inner = gl.spot.innerConeAngle, outer = gl.spot.outerConeAngle;
        if (!(outer > 0 && outer <= kPi / 2))
            fail("spot/outerConeAngle", outer, "is out of range (0, π/2]");
        if (!(inner >= 0 && inner <= outer))  // equal, as Blender writes a hard-edged cone, like the scene file
            fail("spot/innerConeAngle", inner, "is out of range [0, outerConeAngle = " + number_as_given(outer) + "]");
        light.cos_inner = std::cos(float(inner));
        light.cos_outer = std::cos(float(outer));
    } else if (gl.type == "directional") {
        light.type = LightType::Directional;
    } else {
        throw Error(file, ptr + "/type: light '" + light.name + "' has unknown type '" + gl.type + "'");
    }
    return light;
}

std::string camera_label(const tinygltf::Camera& c, int index) {
    return "camera " + std::to_string(index) + (c.name.empty() ? "" : " '" + c.name + "'");
}

// A degenerate camera is an error, as in the scene file, not a camera silently dropped
// for the default view: yfov in (0, π), 0 < znear < zfar (zfar absent: infinite),
// aspectRatio > 0 when given (the image's own aspect is used for rendering).
void check_perspective_camera(const std::string& file, const tinygltf::Camera& c, int index) {
    const tinygltf::PerspectiveCamera& p = c.perspective;
    const std::string ptr = "/cameras/" + std::to_string(index) + "/perspective/";
    auto fail = [&](const char* key, double value, const std::string& rule) {
        throw Error(file, ptr + key + ": " + camera_label(c, index) + ": " + number_as_given(value) + " " + rule);
    };
    if (!(std::isfinite(p.yfov) && p.yfov > 0 && p.yfov < kPi)) fail("yfov", p.yfov, "is out of range (0, π) radians");
    if (!(std::isfinite(p.znear) && p.znear > 0)) fail("znear", p.znear, "must be a finite number > 0");
    if (p.zfar != 0 && !(std::isfinite(p.zfar) && p.zfar > p.znear))  // 0: absent, an infinite far plane
        fail("zfar", p.zfar, "must be a finite number > znear = " + number_as_given(p.znear));
    if (p.aspectRatio != 0 && !(std::isfinite(p.aspectRatio) && p.aspectRatio > 0))  // 0: absent
        fail("aspectRatio", p.aspectRatio, "must be a finite number > 0");
}

// The camera of a node: it looks down the node's -Z with +Y up. A zero scale on the way
// leaves no direction to look in.
SceneCamera camera_at_node(const std::string& file, const tinygltf::Camera& c, int index, const Mat4& world, int node) {
    SceneCamera cam;
    cam.position = Vec3(world * Vec4(0, 0, 0, 1));
    const Vec3 forward = Vec3(world * Vec4(0, 0, -1, 0)), up = Vec3(world * Vec4(0, 1, 0, 0));
    if (!is_finite(cam.position) || !(glm::length(forward) > 0) || !(glm::length(up) > 0) ||
        !(glm::length(glm::cross(forward, up)) > 0))
        throw Error(file, "node " + std::to_string(node) + ": its transform leaves " + camera_label(c, index) +
                              " no position or viewing direction (a zero scale?)");
    cam.target = cam.position + glm::normalize(forward);
    cam.up = glm::normalize(up);
    cam.vertical_fov_degrees = glm::degrees(float(c.perspective.yfov));
    return cam;
}

WrapMode wrap_mode(int gl) {
    switch (gl) {
        case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return WrapMode::ClampToEdge;
        case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return WrapMode::MirroredRepeat;
        default: return WrapMode::Repeat;  // REPEAT, and glTF's default when absent
    }
}

// A finite number from an extension object, or `fallback` when absent.
double extension_number(const std::string& file, const tinygltf::Value& obj, const char* key, double fallback,
                        const std::string& ptr) {
    if (!obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    const double x = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
    if (!(std::isfinite(x) && std::abs(x) <= 1e30)) throw Error(file, ptr + "/" + key + ": not a finite number");
    return x;
}

Vec2 extension_pair(const std::string& file, const tinygltf::Value& obj, const char* key, Vec2 fallback,
                    const std::string& ptr) {
    if (!obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    if (!v.IsArray() || v.ArrayLen() != 2) throw Error(file, ptr + "/" + key + ": not an array of two numbers");
    Vec2 out;
    for (int k = 0; k < 2; ++k) {
        const tinygltf::Value& e = v.Get(k);
        const double x = e.IsNumber() ? e.GetNumberAsDouble() : std::nan("");
        if (!(std::isfinite(x) && std::abs(x) <= 1e30))
            throw Error(file, ptr + "/" + key + "/" + std::to_string(k) + ": not a finite number");
        out[k] = float(x);
    }
    return out;
}

// The decoded image of texture `texture_index`, or null (with a warning) when it has no
// usable image.
std::shared_ptr<const MipMap> texture_image(Context& ctx, int texture_index, ColorEncoding encoding,
                                            const std::string& what) {
    if (texture_index < 0 || size_t(texture_index) >= ctx.model.textures.size())
        throw Error(ctx.file, what + ": texture " + std::to_string(texture_index) + " does not exist (the file has " +
                                  std::to_string(ctx.model.textures.size()) + ")");
    const int source = ctx.model.textures[size_t(texture_index)].source;
    if (source < 0 || size_t(source) >= ctx.model.images.size()) {
        ctx.warn(what + ": texture " + std::to_string(texture_index) + " has no image; the factor alone is used");
        return nullptr;
    }
    const auto key = std::make_pair(source, encoding);
    if (auto it = ctx.images.find(key); it != ctx.images.end()) return it->second;
    const tinygltf::Image& img = ctx.model.images[size_t(source)];
    std::shared_ptr<const MipMap> out;
    if (img.image.empty() || img.component != 4 || img.bits != 8 ||
        img.image.size() != size_t(img.width) * size_t(img.height) * 4) {
        ctx.warn(what + ": image " + std::to_string(source) + " was not decoded; the factor alone is used");
    } else {
        Rgba8Image base{img.width, img.height, img.image};
        const std::string name = img.name.empty() ? (img.uri.empty() ? "image " + std::to_string(source) : img.uri) : img.name;
        out = std::make_shared<const MipMap>(std::move(base), encoding, ctx.file + ": " + name);
    }
    ctx.images[key] = out;
    return out;
}

// A material's texture slot: image, UV set, sampler wrap modes and KHR_texture_transform.
TextureRef texture_ref(Context& ctx, int index, int tex_coord, const tinygltf::ExtensionMap& extensions,
                       ColorEncoding encoding, const std::string& ptr, const std::string& what) {
    TextureRef ref;
    ref.image = texture_image(ctx, index, encoding, what);
    if (!ref.image) return ref;
    ref.uv_set = tex_coord;
    const tinygltf::Texture& tex = ctx.model.textures[size_t(index)];
    if (tex.sampler >= 0 && size_t(tex.sampler) < ctx.model.samplers.size()) {
        const tinygltf::Sampler& sm = ctx.model.samplers[size_t(tex.sampler)];
        ref.wrap_s = wrap_mode(sm.wrapS);
        ref.wrap_t = wrap_mode(sm.wrapT);
    }
    if (auto ext = extensions.find("KHR_texture_transform"); ext != extensions.end()) {
        const std::string xp = ptr + "/extensions/KHR_texture_transform";
        ref.transform.offset = extension_pair(ctx.file, ext->second, "offset", Vec2(0.0f), xp);
        ref.transform.rotation = float(extension_number(ctx.file, ext->second, "rotation", 0.0, xp));
        ref.transform.scale = extension_pair(ctx.file, ext->second, "scale", Vec2(1.0f), xp);
        ref.uv_set = int(extension_number(ctx.file, ext->second, "texCoord", double(ref.uv_set), xp));
    }
    if (ref.uv_set < 0 || ref.uv_set >= kUvSetCount) {
        ctx.warn(what + ": texCoord " + std::to_string(ref.uv_set) + " is not supported (TEXCOORD_0 and _1 are); the factor alone is used");
        return TextureRef{};
    }
    return ref;
}

// KHR_materials_emissive_strength: a finite number ≥ 0 (1 when absent), checked like a
// light's intensity.
float emissive_strength(const std::string& file, const tinygltf::Material& gm, size_t index, const std::string& name) {
    auto ext = gm.extensions.find("KHR_materials_emissive_strength");
    if (ext == gm.extensions.end() || !ext->second.Has("emissiveStrength")) return 1.0f;
    const tinygltf::Value& v = ext->second.Get("emissiveStrength");
    const double strength = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
    if (!(std::isfinite(strength) && strength >= 0 && strength <= double(std::numeric_limits<float>::max())))
        throw Error(file, "/materials/" + std::to_string(index) +
                              "/extensions/KHR_materials_emissive_strength/emissiveStrength: material '" + name + "': " +
                              (v.IsNumber() ? number_as_given(strength) : std::string("not a number")) +
                              " is not a strength (need a finite number ≥ 0)");
    return float(strength);
}

Material convert_material(Context& ctx, const tinygltf::Material& gm, size_t index) {
    Material out;
    out.name = gm.name.empty() ? "material" + std::to_string(index) : gm.name;
    const auto& pbr = gm.pbrMetallicRoughness;
    Vec3 base(1.0f);
    if (pbr.baseColorFactor.size() >= 3) base = Vec3(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2]);
    const std::string ptr = "/materials/" + std::to_string(index);
    const std::string what = "material '" + out.name + "'";
    if (pbr.baseColorTexture.index >= 0)
        out.albedo_texture = texture_ref(ctx, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                         pbr.baseColorTexture.extensions, ColorEncoding::Srgb,
                                         ptr + "/pbrMetallicRoughness/baseColorTexture", what + " base colour");
    base = glm::clamp(base, Vec3(0.0f), Vec3(1.0f));
    const float metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
    const float roughness = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);
    out.albedo = base * (1.0f - metallic);
    out.specular = glm::mix(Vec3(0.04f), base, metallic);
    out.phong_exponent = exponent_from_roughness(roughness);
    // Keep albedo + specular ≤ 1 so the material never reflects more than arrives.
    float scale = 1.0f;
    for (int c = 0; c < 3; ++c)
        if (out.albedo[c] + out.specular[c] > 1.0f && out.specular[c] > 0.0f)
            scale = std::min(scale, (1.0f - out.albedo[c]) / out.specular[c]);
    out.specular *= std::max(scale, 0.0f);

    Vec3 emission(0.0f);
    if (gm.emissiveFactor.size() >= 3) emission = Vec3(gm.emissiveFactor[0], gm.emissiveFactor[1], gm.emissiveFactor[2]);
    emission *= emissive_strength(ctx.file, gm, index, out.name);
    if (gm.emissiveTexture.index >= 0 && max_component(emission) > 0.0f)
        out.emission_texture = texture_ref(ctx, gm.emissiveTexture.index, gm.emissiveTexture.texCoord,
                                           gm.emissiveTexture.extensions, ColorEncoding::Srgb, ptr + "/emissiveTexture",
                                           what + " emission");
    out.emission = glm::max(emission, Vec3(0.0f));
    if (gm.normalTexture.index >= 0) {
        out.normal_texture = texture_ref(ctx, gm.normalTexture.index, gm.normalTexture.texCoord,
                                         gm.normalTexture.extensions, ColorEncoding::Linear, ptr + "/normalTexture",
                                         what + " normal map");
        if (!std::isfinite(gm.normalTexture.scale)) throw Error(ctx.file, ptr + "/normalTexture/scale: not a finite number");
        out.normal_scale = float(gm.normalTexture.scale);
    }
    // Alpha: the base colour's alpha factor times its texture's alpha channel.
    out.alpha = pbr.baseColorFactor.size() >= 4 ? std::clamp(float(pbr.baseColorFactor[3]), 0.0f, 1.0f) : 1.0f;
    if (gm.alphaMode == "MASK" || gm.alphaMode == "BLEND") {
        out.alpha_mode = AlphaMode::Mask;
        out.alpha_texture = out.albedo_texture;
        out.alpha_cutoff = 0.5f;
        if (gm.alphaMode == "MASK") {
            if (!(std::isfinite(gm.alphaCutoff) && gm.alphaCutoff >= 0))
                throw Error(ctx.file, ptr + "/alphaCutoff: " + number_as_given(gm.alphaCutoff) + " is not a cutoff (need a finite number ≥ 0)");
            out.alpha_cutoff = float(gm.alphaCutoff);
        } else {
            ctx.warn(what + ": alphaMode BLEND is rendered as MASK at alpha 0.5 (no partial transparency)");
        }
    }
    return out;
}

// One gilab Mesh per glTF mesh: all triangle primitives merged, material ids per primitive.
struct MeshBuilder {
    Context& ctx;
    std::vector<uint32_t> material_map;  // glTF material → scene material
    uint32_t default_material = UINT32_MAX;

    uint32_t material_for(int gltf_material) {
        if (gltf_material >= 0) {
            if (size_t(gltf_material) >= material_map.size())
                throw Error(ctx.file, "primitive uses material " + std::to_string(gltf_material) +
                                          " but the file has " + std::to_string(material_map.size()) + " (out of range)");
            return material_map[size_t(gltf_material)];
        }
        if (default_material == UINT32_MAX) {
            default_material = uint32_t(ctx.scene.materials.size());
            ctx.scene.materials.push_back(Material{});
        }
        return default_material;
    }

    // Appends one primitive's joint influences, weights renormalised to sum to 1.
    // Primitives without JOINTS_0 in a skinned mesh follow joint 0 rigidly.
    void read_influences(const tinygltf::Primitive& prim, const std::string& where, size_t count, Mesh& mesh) {
        auto j_it = prim.attributes.find("JOINTS_0");
        auto w_it = prim.attributes.find("WEIGHTS_0");
        const size_t before = mesh.positions.size() - count;  // this primitive's vertices were just appended
        if (j_it == prim.attributes.end() && w_it == prim.attributes.end()) {
            if (!mesh.influences.empty()) {
                ctx.warn(where + ": no JOINTS_0 in a skinned mesh; its vertices follow joint 0");
                mesh.influences.resize(mesh.positions.size(), VertexInfluences{{}, Vec4(1, 0, 0, 0)});
            }
            return;
        }
        if (j_it == prim.attributes.end() || w_it == prim.attributes.end())
            throw Error(ctx.file, where + ": JOINTS_0 and WEIGHTS_0 must come together");
        if (prim.attributes.count("JOINTS_1") || prim.attributes.count("WEIGHTS_1"))
            ctx.warn(where + ": JOINTS_1/WEIGHTS_1 ignored; only four influences per vertex are used");
        const std::vector<uint16_t> joints = read_joints(ctx, j_it->second, where + " JOINTS_0");
        const std::vector<float> weights = read_floats(ctx, w_it->second, 4, where + " WEIGHTS_0");
        if (joints.size() != 4 * count || weights.size() != 4 * count)
            throw Error(ctx.file, where + ": " + std::to_string(joints.size() / 4) + " JOINTS_0 and " +
                                      std::to_string(weights.size() / 4) + " WEIGHTS_0 elements for " +
                                      std::to_string(count) + " vertices (count mismatch)");
        if (mesh.influences.size() < before) {
            if (before > 0) ctx.warn(where + ": earlier primitives have no JOINTS_0; their vertices follow joint 0");
            mesh.influences.resize(before, VertexInfluences{{}, Vec4(1, 0, 0, 0)});
        }
        for (size_t i = 0; i < count; ++i) {
            VertexInfluences in;
            float sum = 0.0f;
            for (int k = 0; k < 4; ++k) {
                const float w = weights[4 * i + size_t(k)];
                if (!std::isfinite(w) || w < 0.0f)
                    throw Error(ctx.file, where + ": vertex " + std::to_string(i) + " has a negative or non-finite weight");
                in.weights[k] = w;
                in.joints[size_t(k)] = w > 0.0f ? joints[4 * i + size_t(k)] : 0;
                sum += w;
            }
            if (!(sum > 0.0f))
                throw Error(ctx.file, where + ": vertex " + std::to_string(i) + " has joint weights summing to zero");
            in.weights /= sum;
            mesh.influences.push_back(in);
        }
    }

    Mesh build(size_t mesh_index) {
        const tinygltf::Mesh& gm = ctx.model.meshes[mesh_index];
        Mesh mesh;
        mesh.name = gm.name.empty() ? "mesh" + std::to_string(mesh_index) : gm.name;
        bool all_normals = true, all_uvs[kUvSetCount] = {true, true};
        for (size_t p = 0; p < gm.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = gm.primitives[p];
            const std::string where = "mesh '" + mesh.name + "' primitive " + std::to_string(p);
            const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
            if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                mode != TINYGLTF_MODE_TRIANGLE_FAN) {
                ctx.warn(where + ": points/lines primitive skipped");
                continue;
            }
            if (!prim.targets.empty()) ctx.warn(where + ": morph targets are not supported; the base shape is used");
            auto pos_it = prim.attributes.find("POSITION");
            if (pos_it == prim.attributes.end()) throw Error(ctx.file, where + ": no POSITION attribute");
            const std::vector<float> pos = read_floats(ctx, pos_it->second, 3, where + " POSITION");
            const size_t count = pos.size() / 3;
            const uint32_t base = uint32_t(mesh.positions.size());
            for (size_t i = 0; i < count; ++i) mesh.positions.emplace_back(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);

            auto nrm_it = prim.attributes.find("NORMAL");
            if (nrm_it != prim.attributes.end() && all_normals) {
                const std::vector<float> nrm = read_floats(ctx, nrm_it->second, 3, where + " NORMAL");
                if (nrm.size() != pos.size())
                    throw Error(ctx.file, where + ": NORMAL count differs from POSITION count");
                for (size_t i = 0; i < count; ++i) mesh.normals.emplace_back(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
            } else {
                all_normals = false;
            }
            read_influences(prim, where, count, mesh);
            for (int k = 0; k < kUvSetCount; ++k) {
                const std::string attribute = "TEXCOORD_" + std::to_string(k);
                std::vector<Vec2>& set = k == 0 ? mesh.uvs : mesh.uvs1;
                auto uv_it = prim.attributes.find(attribute);
                if (uv_it != prim.attributes.end() && all_uvs[k]) {
                    const std::vector<float> uv = read_floats(ctx, uv_it->second, 2, where + " " + attribute);
                    if (uv.size() / 2 != count)
                        throw Error(ctx.file, where + ": " + attribute + " count differs from POSITION count");
                    for (size_t i = 0; i < count; ++i) set.emplace_back(uv[2 * i], uv[2 * i + 1]);
                } else {
                    all_uvs[k] = false;
                }
            }

            std::vector<uint32_t> idx;
            if (prim.indices >= 0) {
                idx = read_indices(ctx, prim.indices, where + " indices");
                for (size_t i = 0; i < idx.size(); ++i)
                    if (idx[i] >= count)
                        throw Error(ctx.file, where + ": index " + std::to_string(i) + " is " + std::to_string(idx[i]) +
                                                  " but the primitive has " + std::to_string(count) +
                                                  " vertices (index out of range)");
            } else {
                idx.resize(count);
                for (size_t i = 0; i < count; ++i) idx[i] = uint32_t(i);
            }
            const uint32_t material = material_for(prim.material);
            auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
                mesh.triangles.emplace_back(base + a, base + b, base + c);
                mesh.material_ids.push_back(material);
            };
            if (mode == TINYGLTF_MODE_TRIANGLES) {
                if (idx.size() % 3 != 0)
                    throw Error(ctx.file, where + ": " + std::to_string(idx.size()) +
                                              " indices is not a multiple of 3 for a triangle list");
                for (size_t i = 0; i + 2 < idx.size(); i += 3) add(idx[i], idx[i + 1], idx[i + 2]);
            } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                for (size_t i = 0; i + 2 < idx.size(); ++i)
                    if (i % 2 == 0) add(idx[i], idx[i + 1], idx[i + 2]);
                    else add(idx[i], idx[i + 2], idx[i + 1]);
            } else {
                for (size_t i = 1; i + 1 < idx.size(); ++i) add(idx[i], idx[i + 1], idx[0]);
            }
        }
        if (!all_normals) mesh.normals.clear();
        if (!all_uvs[0]) mesh.uvs.clear();
        if (!all_uvs[1]) mesh.uvs1.clear();
        for (const Vec3& n : mesh.normals)
            if (!(glm::dot(n, n) > 0.0f) || !is_finite(n)) {
                ctx.warn("mesh '" + mesh.name + "': invalid vertex normals; using flat shading");
                mesh.normals.clear();
                break;
            }
        for (Vec3& n : mesh.normals) n = glm::normalize(n);
        return mesh;
    }
};

template <typename T>
void expand_step(KeyframeChannel<T>& c) {
    // STEP as linear keys: hold each value until just before the next key.
    KeyframeChannel<T> out;
    for (size_t i = 0; i < c.times.size(); ++i) {
        if (i > 0) {
            const float hold = std::nextafter(c.times[i], -kInfinity);
            if (hold > out.times.back()) {
                out.times.push_back(hold);
                out.values.push_back(c.values[i - 1]);
            }
        }
        out.times.push_back(c.times[i]);
        out.values.push_back(c.values[i]);
    }
    c = std::move(out);
}

struct NodeChannels {
    bool has[3] = {false, false, false};
    bool step[3] = {false, false, false};
    TrsAnimation anim;
};

void load_animations(Context& ctx, const std::vector<int>& gltf_to_node) {
    const auto& m = ctx.model;
    std::map<int, NodeChannels> per_node;
    size_t ignored_overlaps = 0, ignored_weights = 0;
    for (size_t ai = 0; ai < m.animations.size(); ++ai) {
        const tinygltf::Animation& anim = m.animations[ai];
        const std::string aname = "animation " + std::to_string(ai) + (anim.name.empty() ? "" : " '" + anim.name + "'");
        for (size_t ci = 0; ci < anim.channels.size(); ++ci) {
            const tinygltf::AnimationChannel& ch = anim.channels[ci];
            const std::string where = aname + " channel " + std::to_string(ci);
            if (ch.target_node < 0 || size_t(ch.target_node) >= m.nodes.size())
                throw Error(ctx.file, where + ": target node " + std::to_string(ch.target_node) + " is out of range");
            if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
                throw Error(ctx.file, where + ": sampler " + std::to_string(ch.sampler) + " is out of range");
            int path;
            if (ch.target_path == "translation") path = 0;
            else if (ch.target_path == "rotation") path = 1;
            else if (ch.target_path == "scale") path = 2;
            else {
                ++ignored_weights;
                continue;
            }
            const int node = gltf_to_node[size_t(ch.target_node)];
            if (node < 0) continue;  // node not in the displayed scene
            NodeChannels& nc = per_node[node];
            if (nc.has[path]) {
                ++ignored_overlaps;
                continue;
            }
            const tinygltf::AnimationSampler& s = anim.samplers[size_t(ch.sampler)];
            const bool cubic = s.interpolation == "CUBICSPLINE";
            const bool step = s.interpolation == "STEP";
            if (!cubic && !step && s.interpolation != "LINEAR")
                throw Error(ctx.file, where + ": unknown interpolation '" + s.interpolation + "'");
            std::vector<float> times = read_floats(ctx, s.input, 1, where + " input");
            const int comps = path == 1 ? 4 : 3;
            std::vector<float> values = read_floats(ctx, s.output, comps, where + " output");
            const size_t per_key = cubic ? 3 : 1;
            if (values.size() != times.size() * per_key * size_t(comps))
                throw Error(ctx.file, where + ": " + std::to_string(times.size()) + " key times but " +
                                          std::to_string(values.size() / size_t(comps)) + " output values");
            if (times.empty()) continue;
            // Keys must not go back in time; a repeated time keeps the later key.
            std::vector<size_t> keep;
            for (size_t k = 0; k < times.size(); ++k) {
                if (!std::isfinite(times[k])) throw Error(ctx.file, where + ": non-finite key time");
                if (k > 0 && times[k] < times[k - 1])
                    throw Error(ctx.file, where + ": key times decrease at key " + std::to_string(k));
                if (k + 1 < times.size() && times[k + 1] == times[k]) continue;
                keep.push_back(k);
            }
            auto value_at = [&](size_t k, int c) { return values[(k * per_key + (cubic ? 1 : 0)) * size_t(comps) + size_t(c)]; };
            for (size_t k : keep) {
                if (path == 1) {
                    Quat q(value_at(k, 3), value_at(k, 0), value_at(k, 1), value_at(k, 2));
                    float len = glm::length(q);
                    if (!(len > 0.0f) || !std::isfinite(len)) throw Error(ctx.file, where + ": invalid rotation key");
                    nc.anim.rotation.times.push_back(times[k]);
                    nc.anim.rotation.values.push_back(q / len);
                } else {
                    Vec3 v(value_at(k, 0), value_at(k, 1), value_at(k, 2));
                    if (!is_finite(v)) throw Error(ctx.file, where + ": non-finite key value");
                    auto& channel = path == 0 ? nc.anim.translation : nc.anim.scale;
                    channel.times.push_back(times[k]);
                    channel.values.push_back(v);
                }
            }
            nc.has[path] = true;
            nc.step[path] = step;
        }
    }
    for (auto& [node, nc] : per_node) {
        bool any_step = false, all_step = true;
        for (int p = 0; p < 3; ++p)
            if (nc.has[p]) {
                any_step |= nc.step[p];
                all_step &= nc.step[p];
            }
        if (all_step) {
            nc.anim.step = true;
        } else if (any_step) {  // mixed: express the STEP channels as linear ones
            if (nc.has[0] && nc.step[0]) expand_step(nc.anim.translation);
            if (nc.has[1] && nc.step[1]) expand_step(nc.anim.rotation);
            if (nc.has[2] && nc.step[2]) expand_step(nc.anim.scale);
        }
        ctx.scene.nodes[size_t(node)].animation = std::move(nc.anim);
    }
    if (ignored_overlaps)
        ctx.warn(std::to_string(ignored_overlaps) +
                 " animation channels ignored: an earlier animation already drives the same node property");
    if (ignored_weights) ctx.warn("morph-target weight animations are not supported and were ignored");
}

// tinygltf's image callback: images are decoded by gilab's texture decoder (its checks
// and memory budget). A refused or undecodable image is a warning, not an error: its
// materials keep their factors (texture_image says so again for each one).
bool load_image_tolerant(tinygltf::Image* image, const int index, std::string* err, std::string* warn, int, int,
                         const unsigned char* bytes, int size, void*) {
    (void)err;
    try {
        Rgba8Image decoded = decode_image(std::span(bytes, size_t(std::max(size, 0))),
                                          "image " + std::to_string(index) + (image->uri.empty() ? "" : " ('" + image->uri + "')"));
        image->width = decoded.width;
        image->height = decoded.height;
        image->component = 4;
        image->bits = 8;
        image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
        image->image = std::move(decoded.texels);
    } catch (const Error& e) {
        if (warn) *warn += std::string(e.what()) + "; it is ignored\n";
    }
    return true;
}

void add_lines(Context& ctx, const std::string& text) {
    std::istringstream s(text);
    std::string line;
    while (std::getline(s, line))
        if (!line.empty()) ctx.warn(line);
}

// Whether some displayed triangle keeps a non-zero area under `world` (one matrix per
// scene node). Skinned meshes count as visible: their joints give them their shape.
bool some_triangle_visible(const Scene& scene, const std::vector<Mat4>& world) {
    for (size_t i = 0; i < scene.nodes.size(); ++i)
        for (uint32_t m : scene.nodes[i].meshes) {
            if (scene.nodes[i].skin >= 0) return true;
            const Mesh& mesh = scene.meshes[m];
            auto place = [&](uint32_t v) { return Vec3(world[i] * Vec4(mesh.positions[v], 1.0f)); };
            for (const UVec3& t : mesh.triangles) {
                const Vec3 a = place(t.x);
                if (glm::length(glm::cross(place(t.y) - a, place(t.z) - a)) > 0.0f) return true;
            }
        }
    return false;
}

// A node scale of zero can collapse every triangle: the render would be black with no
// error. Checked at the rest pose and across the animation (a model may grow from zero).
void check_something_visible(const Scene& scene, const std::string& file) {
    if (some_triangle_visible(scene, scene.rest_node_transforms())) return;
    constexpr int kSampledTimes = 16;
    for (int k = 0; scene.is_animated() && k <= kSampledTimes; ++k)
        if (some_triangle_visible(scene, scene.node_transforms(scene.animation_duration() * k / kSampledTimes))) return;
    std::string culprit;
    for (size_t i = 0; i < scene.nodes.size() && culprit.empty(); ++i) {
        const Vec3& s = scene.nodes[i].local.scale;
        if (s.x == 0 || s.y == 0 || s.z == 0)
            culprit = " (node '" + scene.nodes[i].name + "' has scale [" + number_as_given(s.x) +
                      ", " + number_as_given(s.y) + ", " + number_as_given(s.z) + "])";
    }
    throw Error(file, "nothing visible: every triangle of the displayed scene has zero area in world space" +
                          (culprit.empty() ? std::string(" (check the node scales)") : culprit));
}

}  // namespace

Scene load_gltf(const fs::path& path) {
    const std::string file = path.string();
    const std::string bytes = read_input_file(path);
    const GltfInput input = check_gltf_file(path, bytes);
    if (bytes.size() > UINT32_MAX) throw Error(file, "larger than 4 GiB, which glTF readers do not support");

    tinygltf::Model model;
    tinygltf::TinyGLTF reader;
    reader.SetImageLoader(load_image_tolerant, nullptr);
    use_checked_file_access(reader);
    std::string err, warn;
    const std::string base_dir = path.parent_path().string();
    const bool ok = input.binary ? reader.LoadBinaryFromMemory(&model, &err, &warn,
                                                               reinterpret_cast<const unsigned char*>(bytes.data()),
                                                               unsigned(bytes.size()), base_dir)
                                 : reader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), unsigned(bytes.size()),
                                                              base_dir);
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    if (!ok) throw Error(file, "malformed glTF: " + (err.empty() ? std::string("could not be parsed") : err));

    Scene scene;
    scene.name = path.stem().string();
    scene.source = file;
    Context ctx{model, file, scene, input.input_bytes};
    add_lines(ctx, warn);
    if (!err.empty()) add_lines(ctx, err);

    for (size_t i = 0; i < model.materials.size(); ++i) scene.materials.push_back(convert_material(ctx, model.materials[i], i));
    MeshBuilder builder{ctx, {}, UINT32_MAX};
    builder.material_map.resize(model.materials.size());
    for (size_t i = 0; i < model.materials.size(); ++i) builder.material_map[i] = uint32_t(i);

    // Which nodes to show: the default scene, else the first, else every root node.
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        int si = model.defaultScene >= 0 ? model.defaultScene : 0;
        if (size_t(si) >= model.scenes.size()) throw Error(file, "default scene " + std::to_string(si) + " is out of range");
        roots = model.scenes[size_t(si)].nodes;
    } else {
        std::vector<bool> is_child(model.nodes.size(), false);
        for (const auto& n : model.nodes)
            for (int c : n.children)
                if (c >= 0 && size_t(c) < model.nodes.size()) is_child[size_t(c)] = true;
        for (size_t i = 0; i < model.nodes.size(); ++i)
            if (!is_child[i]) roots.push_back(int(i));
    }

    // Depth-first, so parents precede children; rest-pose world matrices on the way. An
    // explicit stack, not recursion: a valid hierarchy may be thousands of levels deep.
    std::vector<int> gltf_to_node(model.nodes.size(), -1);
    std::vector<Mat4> gltf_world(model.nodes.size(), Mat4(1.0f));
    struct PendingNode {
        int gltf_index;
        int parent;         // scene node index, -1 for a root
        int parent_gltf;    // glTF node index of the parent, -1 for a root
    };
    std::vector<PendingNode> pending;
    auto push_in_order = [&](const std::vector<int>& gltf_nodes, int parent, int parent_gltf) {
        for (auto it = gltf_nodes.rbegin(); it != gltf_nodes.rend(); ++it) pending.push_back({*it, parent, parent_gltf});
    };
    push_in_order(roots, -1, -1);
    while (!pending.empty()) {
        const auto [gi, parent, parent_gltf] = pending.back();
        pending.pop_back();
        if (gi < 0 || size_t(gi) >= model.nodes.size())
            throw Error(file, "node " + std::to_string(gi) + " is out of range (the file has " +
                                  std::to_string(model.nodes.size()) + " nodes)");
        if (gltf_to_node[size_t(gi)] >= 0)
            throw Error(file, "node " + std::to_string(gi) + " has more than one parent (or a cycle)");
        const tinygltf::Node& gn = model.nodes[size_t(gi)];
        SceneNode node;
        node.name = gn.name.empty() ? "node" + std::to_string(gi) : gn.name;
        node.parent = parent;
        check_node_transform(file, gi, gn);
        node.local = node_local_transform(gn);
        if (!is_finite(node.local.translation) || !is_finite(node.local.scale) ||
            !std::isfinite(glm::length(node.local.rotation)))
            throw Error(file, "node " + std::to_string(gi) + " ('" + node.name +
                                  "'): its matrix does not decompose into a finite translation, rotation and scale");
        const int index = int(scene.nodes.size());
        gltf_to_node[size_t(gi)] = index;
        const Mat4 parent_world = parent_gltf >= 0 ? gltf_world[size_t(parent_gltf)] : Mat4(1.0f);
        gltf_world[size_t(gi)] = parent_world * node_local_matrix(gn);
        scene.nodes.push_back(std::move(node));
        push_in_order(gn.children, index, gi);
    }

    // Skins, converted once when a displayed node first uses them.
    std::vector<int> skin_slots(model.skins.size(), -1);
    auto skin_slot = [&](int gs) {
        if (size_t(gs) >= model.skins.size())
            throw Error(file, "skin " + std::to_string(gs) + " is out of range (the file has " +
                                  std::to_string(model.skins.size()) + " skins)");
        if (skin_slots[size_t(gs)] >= 0) return skin_slots[size_t(gs)];
        const tinygltf::Skin& gskin = model.skins[size_t(gs)];
        const std::string label = "skin " + std::to_string(gs) + (gskin.name.empty() ? "" : " '" + gskin.name + "'");
        if (gskin.joints.empty()) throw Error(file, label + " has no joints");
        Skin skin;
        skin.name = gskin.name;
        for (int j : gskin.joints) {
            if (j < 0 || size_t(j) >= model.nodes.size() || gltf_to_node[size_t(j)] < 0)
                throw Error(file, label + ": joint node " + std::to_string(j) +
                                      " is out of range or not in the displayed scene");
            skin.joints.push_back(uint32_t(gltf_to_node[size_t(j)]));
        }
        if (gskin.inverseBindMatrices >= 0) {
            const std::vector<float> m16 = read_floats(ctx, gskin.inverseBindMatrices, 16, label + " inverse bind matrices");
            if (m16.size() != 16 * skin.joints.size())
                throw Error(file, label + ": " + std::to_string(m16.size() / 16) + " inverse bind matrices for " +
                                      std::to_string(skin.joints.size()) + " joints (count mismatch)");
            for (size_t k = 0; k < skin.joints.size(); ++k) {
                Mat4 m;
                for (int c = 0; c < 4; ++c)
                    for (int r = 0; r < 4; ++r) m[c][r] = m16[16 * k + size_t(c * 4 + r)];
                skin.inverse_bind.push_back(m);
            }
        } else {
            skin.inverse_bind.assign(skin.joints.size(), Mat4(1.0f));  // the specification's default
        }
        scene.skins.push_back(std::move(skin));
        skin_slots[size_t(gs)] = int(scene.skins.size() - 1);
        return skin_slots[size_t(gs)];
    };

    // Meshes (built once, shared by every node that instances them), lights, camera.
    std::vector<int> mesh_slot(model.meshes.size(), -1);
    for (size_t gi = 0; gi < model.nodes.size(); ++gi) {
        const int ni = gltf_to_node[gi];
        if (ni < 0) continue;
        const tinygltf::Node& gn = model.nodes[gi];
        if (gn.mesh >= 0) {
            if (size_t(gn.mesh) >= model.meshes.size())
                throw Error(file, "node " + std::to_string(gi) + " references mesh " + std::to_string(gn.mesh) +
                                      " but the file has " + std::to_string(model.meshes.size()) + " (out of range)");
            if (mesh_slot[size_t(gn.mesh)] < 0) {
                Mesh mesh = builder.build(size_t(gn.mesh));
                if (!mesh.triangles.empty()) {
                    scene.degenerate_triangles_dropped +=
                        validate_and_clean(mesh, scene.materials.size(), file).degenerate_triangles_dropped;
                    scene.meshes.push_back(std::move(mesh));
                    mesh_slot[size_t(gn.mesh)] = int(scene.meshes.size() - 1);
                } else {
                    mesh_slot[size_t(gn.mesh)] = INT32_MAX;  // nothing to draw
                }
            }
            const int slot = mesh_slot[size_t(gn.mesh)];
            if (slot != INT32_MAX) {
                scene.nodes[size_t(ni)].meshes.push_back(uint32_t(slot));
                if (gn.skin >= 0) {
                    if (scene.meshes[size_t(slot)].influences.empty())
                        throw Error(file, "node " + std::to_string(gi) + " has skin " + std::to_string(gn.skin) +
                                              " but mesh '" + scene.meshes[size_t(slot)].name +
                                              "' has no JOINTS_0/WEIGHTS_0");
                    scene.nodes[size_t(ni)].skin = skin_slot(gn.skin);
                }
            }
        }
        auto light_ext = gn.extensions.find("KHR_lights_punctual");
        if (light_ext != gn.extensions.end() && light_ext->second.Has("light")) {
            const tinygltf::Value& v = light_ext->second.Get("light");
            const int li = v.IsNumber() ? v.GetNumberAsInt() : -1;
            if (li < 0 || size_t(li) >= model.lights.size())
                throw Error(file, "node " + std::to_string(gi) + " references light " + std::to_string(li) +
                                      " but the file has " + std::to_string(model.lights.size()) + " (out of range)");
            PunctualLight light = convert_light(file, model.lights[size_t(li)], li);
            light.node = ni;
            scene.lights.push_back(light);
        }
        if (gn.camera >= 0) {
            if (size_t(gn.camera) >= model.cameras.size())
                throw Error(file, "node " + std::to_string(gi) + " references camera " + std::to_string(gn.camera) +
                                      " but the file has " + std::to_string(model.cameras.size()) + " (out of range)");
            const tinygltf::Camera& gc = model.cameras[size_t(gn.camera)];
            if (gc.type != "perspective") {
                ctx.warn("camera " + std::to_string(gn.camera) + " ('" + gc.name + "'): only perspective cameras are supported; '" +
                         gc.type + "' camera ignored");
            } else {
                check_perspective_camera(file, gc, gn.camera);
                if (!scene.camera) scene.camera = camera_at_node(file, gc, gn.camera, gltf_world[gi], int(gi));
            }
        }
    }
    load_animations(ctx, gltf_to_node);
    if (scene.meshes.empty()) throw Error(file, "no triangle meshes in the displayed scene");
    for (const SceneNode& node : scene.nodes)
        if (node.skin >= 0)
            for (uint32_t m : node.meshes) check_influences(scene.meshes[m], scene.skins[size_t(node.skin)].joints.size(), file);
    scene.validate();  // node transforms can carry finite geometry beyond the supported range
    check_something_visible(scene, file);
    return scene;
}

}  // namespace gilab
