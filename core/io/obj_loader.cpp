// Wavefront OBJ + MTL through tinyobjloader. tinyobjloader reads unparsable numbers as
// 0 and skips faces with bad indices with only a warning, so the OBJ and MTL text is
// checked first (core/io/obj_check.hpp) and problems are reported with their line number.
// Polygons are triangulated in their best-fit plane (core/io/polygon_triangulation.hpp).
//
// MTL textures: map_Kd (sRGB, multiplies Kd), map_Ke (sRGB, multiplies Ke), map_d (an
// alpha mask tested at 0.5; a file without an alpha channel gives its red channel),
// norm and map_bump (read as tangent-space normal maps, -bm scaling x and y, as the
// exporters of the shipped scenes write them). Options -s and -o transform the
// coordinates, -clamp on clamps them. Texture files are looked up beside the OBJ; one
// that is missing or cannot be decoded leaves the material with its colour and a
// warning naming the file. OBJ's v axis points up the image; the texture transform
// flips it to the image's top-row-first order.
#include <tiny_obj_loader.h>

#include <map>
#include <regex>
#include <unordered_map>
#include "core/util/error.hpp"
#include "core/util/input_file.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/io/obj_check.hpp"
#include "core/io/polygon_triangulation.hpp"
#include "core/texture/image_decode.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

// tinyobjloader's messages end in "(line N.)"; move the line number to the front.
std::string locate_message(const std::string& file, const std::string& message) {
    static const std::regex line_re(R"(line:? (\d+))");
    std::smatch m;
    std::string msg = message;
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    if (std::regex_search(msg, m, line_re)) return file + ":" + m[1].str() + ": " + msg;
    return file + ": " + msg;
}

Vec3 to_vec3(const tinyobj::real_t v[3]) { return Vec3(float(v[0]), float(v[1]), float(v[2])); }

Material convert_material(const tinyobj::material_t& m, bool& rescaled, const std::string& file) {
    for (const tinyobj::real_t* v : {m.diffuse, m.specular, m.emission})
        if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
            throw Error(file, "material '" + m.name + "' has a non-finite colour");
    if (!std::isfinite(m.shininess)) throw Error(file, "material '" + m.name + "' has a non-finite Ns");
    Material out;
    out.name = m.name;
    out.albedo = glm::clamp(to_vec3(m.diffuse), Vec3(0.0f), Vec3(1.0f));
    out.specular = glm::max(to_vec3(m.specular), Vec3(0.0f));
    out.phong_exponent = std::max(float(m.shininess), 0.0f);
    out.emission = glm::max(to_vec3(m.emission), Vec3(0.0f));
    // Kd + Ks > 1 would reflect more than arrives; keep the diffuse colour and scale
    // the glossy lobe down uniformly.
    float scale = 1.0f;
    for (int c = 0; c < 3; ++c)
        if (out.albedo[c] + out.specular[c] > 1.0f && out.specular[c] > 0.0f)
            scale = std::min(scale, (1.0f - out.albedo[c]) / out.specular[c]);
    if (scale < 1.0f) {
        out.specular *= scale;
        rescaled = true;
    }
    return out;
}

// Decodes each texture file once per use, shares it between materials, and remembers
// what could not be read (one warning per file).
struct MtlTextures {
    fs::path directory;
    Scene& scene;
    std::map<std::pair<std::string, int>, std::shared_ptr<const MipMap>> loaded;  // (name, use)

    enum Use { Colour, Data, AlphaMask };

    std::shared_ptr<const MipMap> image(const std::string& name, Use use) {
        const auto key = std::make_pair(name, int(use));
        if (auto it = loaded.find(key); it != loaded.end()) return it->second;
        std::shared_ptr<const MipMap> out;
        const fs::path file = fs::path(name).is_absolute() ? fs::path(name) : directory / name;
        try {
            if (!regular_file_exists(file)) throw Error(file.string(), "texture file not found");
            Rgba8Image img = decode_image_file(file);
            if (use == AlphaMask) {
                bool opaque = true;
                for (size_t i = 3; i < img.texels.size() && opaque; i += 4) opaque = img.texels[i] == 255;
                if (opaque)  // no alpha channel: the mask is the grey level
                    for (size_t i = 0; i < img.texels.size(); i += 4) img.texels[i + 3] = img.texels[i];
            }
            out = std::make_shared<const MipMap>(std::move(img), use == Colour ? ColorEncoding::Srgb : ColorEncoding::Linear,
                                                 file.string());
        } catch (const Error& e) {
            scene.warnings.push_back(std::string(e.what()) + "; the material's colour is used without it");
        }
        loaded[key] = out;
        return out;
    }

    TextureRef ref(const std::string& name, const tinyobj::texture_option_t& opt, Use use) {
        TextureRef t;
        if (name.empty()) return t;
        t.image = image(name, use);
        if (!t.image) return t;
        for (int k = 0; k < 2; ++k)
            if (!std::isfinite(opt.scale[k]) || !std::isfinite(opt.origin_offset[k]))
                throw Error(name, "texture option -s or -o is not a finite number");
        // uv' = uv · s + o in OBJ's v-up convention, then v flipped for the image rows.
        t.transform.scale = Vec2(float(opt.scale[0]), -float(opt.scale[1]));
        t.transform.offset = Vec2(float(opt.origin_offset[0]), 1.0f - float(opt.origin_offset[1]));
        if (opt.clamp) t.wrap_s = t.wrap_t = WrapMode::ClampToEdge;
        return t;
    }
};

void add_textures(Material& out, const tinyobj::material_t& m, MtlTextures& textures) {
    out.albedo_texture = textures.ref(m.diffuse_texname, m.diffuse_texopt, MtlTextures::Colour);
    if (out.is_emissive()) out.emission_texture = textures.ref(m.emissive_texname, m.emissive_texopt, MtlTextures::Colour);
    const bool has_norm = !m.normal_texname.empty();
    out.normal_texture = has_norm ? textures.ref(m.normal_texname, m.normal_texopt, MtlTextures::Data)
                                  : textures.ref(m.bump_texname, m.bump_texopt, MtlTextures::Data);
    const float bm = float(has_norm ? m.normal_texopt.bump_multiplier : m.bump_texopt.bump_multiplier);
    out.normal_scale = std::isfinite(bm) ? bm : 1.0f;
    out.alpha = std::clamp(std::isfinite(m.dissolve) ? float(m.dissolve) : 1.0f, 0.0f, 1.0f);
    out.alpha_texture = textures.ref(m.alpha_texname, m.alpha_texopt, MtlTextures::AlphaMask);
    if (out.alpha_texture) out.alpha_mode = AlphaMode::Mask;
}

struct CornerKey {
    int v, n, t;
    bool operator==(const CornerKey& o) const { return v == o.v && n == o.n && t == o.t; }
};
struct CornerHash {
    size_t operator()(const CornerKey& k) const {
        return (size_t(uint32_t(k.v)) * 0x9E3779B97F4A7C15ull) ^ (size_t(uint32_t(k.n)) * 0xC2B2AE3D27D4EB4Full) ^
               size_t(uint32_t(k.t));
    }
};

}  // namespace

Scene load_obj(const fs::path& path) {
    const std::string file = path.string();
    const ObjScan scan = scan_obj(path, read_input_file(path));
    for (const fs::path& mtl : scan.material_libraries) {
        try {
            check_mtl(mtl);
        } catch (const Error& e) {
            throw Error(file, std::string("material library: ") + e.what());
        }
    }

    tinyobj::ObjReaderConfig config;
    config.triangulate = false;  // triangulated below, after the indices are checked
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(file, config))
        throw Error(locate_message(file, "malformed OBJ: " + reader.Error()));
    if (!reader.Error().empty()) throw Error(locate_message(file, "malformed OBJ: " + reader.Error()));

    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    const auto& shapes = reader.GetShapes();
    const auto& materials = reader.GetMaterials();
    const int nv = int(attrib.vertices.size() / 3);
    const int nn = int(attrib.normals.size() / 3);
    const int nt = int(attrib.texcoords.size() / 2);

    Scene scene;
    scene.name = path.stem().string();
    scene.source = file;
    if (reader.Warning().find("not found") != std::string::npos)
        scene.warnings.push_back(file + ": material library not found; using the default material");

    bool rescaled = false;
    MtlTextures textures{path.parent_path(), scene, {}};
    for (const auto& m : materials) {
        scene.materials.push_back(convert_material(m, rescaled, file));
        add_textures(scene.materials.back(), m, textures);
    }
    if (rescaled) scene.warnings.push_back(file + ": Kd + Ks > 1 in some materials; Ks scaled down to conserve energy");

    // Index checks first, with the OBJ line of the offending face.
    size_t face_ordinal = 0;
    bool all_normals = nn > 0, all_uvs = nt > 0;
    size_t bad_normal_line = 0, bad_uv_line = 0;
    for (const auto& shape : shapes) {
        size_t offset = 0;
        for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f, ++face_ordinal) {
            const size_t corners = shape.mesh.num_face_vertices[f];
            if (offset + corners > shape.mesh.indices.size())
                throw Error(file, "inconsistent face data (parser error)");
            auto where_line = [&]() -> size_t {
                return face_ordinal < scan.face_lines.size() ? scan.face_lines[face_ordinal] : 0;
            };
            auto where = [&]() { return where_line() ? file + ":" + std::to_string(where_line()) : file; };
            for (size_t k = 0; k < corners; ++k) {
                const tinyobj::index_t& idx = shape.mesh.indices[offset + k];
                if (idx.vertex_index < 0 || idx.vertex_index >= nv)
                    throw Error(where(), "face references vertex " + std::to_string(idx.vertex_index + 1) +
                                             " but the file has " + std::to_string(nv) +
                                             " vertices (index out of range)");
                // Normals and uvs are optional: exporters that write "f 1/1/1" without any
                // vt lines are common, so a bad normal/uv index only drops that attribute.
                if ((idx.normal_index >= nn || idx.normal_index < -1) && !bad_normal_line) bad_normal_line = where_line();
                if ((idx.texcoord_index >= nt || idx.texcoord_index < -1) && !bad_uv_line) bad_uv_line = where_line();
                all_normals &= idx.normal_index >= 0 && idx.normal_index < nn;
                all_uvs &= idx.texcoord_index >= 0 && idx.texcoord_index < nt;
            }
            const int mat = f < shape.mesh.material_ids.size() ? shape.mesh.material_ids[f] : -1;
            if (mat >= int(materials.size())) throw Error(where(), "face uses an unknown material");
            offset += corners;
        }
    }

    if (bad_normal_line)
        scene.warnings.push_back(file + ":" + std::to_string(bad_normal_line) +
                                 ": normal index out of range; vertex normals ignored");
    if (bad_uv_line)
        scene.warnings.push_back(file + ":" + std::to_string(bad_uv_line) +
                                 ": texture coordinate index out of range; texture coordinates ignored");

    Mesh mesh;
    mesh.name = scene.name;
    uint32_t default_material = UINT32_MAX;
    auto material_of = [&](int id) -> uint32_t {
        if (id >= 0) return uint32_t(id);
        if (default_material == UINT32_MAX) {
            default_material = uint32_t(scene.materials.size());
            scene.materials.push_back(Material{});
        }
        return default_material;
    };

    // Without per-corner normals/uvs the OBJ position indices are used as they are;
    // otherwise every distinct (position, normal, uv) corner becomes one vertex.
    const bool split_corners = all_normals || all_uvs;
    std::unordered_map<CornerKey, uint32_t, CornerHash> corner_index;
    if (!split_corners) {
        mesh.positions.resize(size_t(nv));
        for (int i = 0; i < nv; ++i) mesh.positions[size_t(i)] = to_vec3(&attrib.vertices[3 * size_t(i)]);
    }
    auto vertex_of = [&](const tinyobj::index_t& idx) -> uint32_t {
        if (!split_corners) return uint32_t(idx.vertex_index);
        CornerKey key{idx.vertex_index, all_normals ? idx.normal_index : -1, all_uvs ? idx.texcoord_index : -1};
        auto [it, inserted] = corner_index.try_emplace(key, uint32_t(mesh.positions.size()));
        if (inserted) {
            mesh.positions.push_back(to_vec3(&attrib.vertices[3 * size_t(key.v)]));
            if (all_normals) mesh.normals.push_back(to_vec3(&attrib.normals[3 * size_t(key.n)]));
            if (all_uvs)
                mesh.uvs.emplace_back(attrib.texcoords[2 * size_t(key.t)], attrib.texcoords[2 * size_t(key.t) + 1]);
        }
        return it->second;
    };

    TriangulationTally tally;
    std::vector<Vec3> corner_positions;
    std::vector<uint32_t> corner_vertices;
    for (const auto& shape : shapes) {
        size_t offset = 0;
        for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
            const size_t corners = shape.mesh.num_face_vertices[f];
            const uint32_t mat = material_of(f < shape.mesh.material_ids.size() ? shape.mesh.material_ids[f] : -1);
            corner_positions.clear();
            corner_vertices.clear();
            for (size_t k = 0; k < corners; ++k) {
                const tinyobj::index_t& idx = shape.mesh.indices[offset + k];
                corner_positions.push_back(to_vec3(&attrib.vertices[3 * size_t(idx.vertex_index)]));
                corner_vertices.push_back(vertex_of(idx));
            }
            const PolygonTriangulation t = triangulate_polygon(corner_positions);
            tally.count(t);
            for (const auto& tri : t.triangles) {
                mesh.triangles.emplace_back(corner_vertices[tri[0]], corner_vertices[tri[1]], corner_vertices[tri[2]]);
                mesh.material_ids.push_back(mat);
            }
            offset += corners;
        }
    }
    tally.add_notes(file, scene.warnings);
    // Zero-length normals (seen in exported files) are dropped with the whole set.
    for (const Vec3& n : mesh.normals)
        if (!(glm::dot(n, n) > 0.0f)) {
            mesh.normals.clear();
            scene.warnings.push_back(file + ": zero-length vertex normals; using flat shading");
            break;
        }
    for (Vec3& n : mesh.normals) n = glm::normalize(n);

    if (mesh.triangles.empty()) throw Error(file, "no faces (empty or truncated OBJ)");
    scene.degenerate_triangles_dropped += validate_and_clean(mesh, scene.materials.size(), file).degenerate_triangles_dropped;
    scene.add_mesh_instance(std::move(mesh));
    return scene;
}

}  // namespace gilab
