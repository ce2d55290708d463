// OBJ/MTL loading: round trips on generated files, malformed inputs, and the real
// OBJ assets from ../shared/scenes checked against the MANIFEST's counts.
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>
#include <fstream>
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;
using gilab::test::error_of;
using gilab::test::write_file;

namespace {

const char* kQuadObj =
    "mtllib quad.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "v 0 0 1\nv 1 0 1\nv 1 1 1\n"
    "usemtl red\n"
    "f 1 2 3 4\n"
    "usemtl lamp\n"
    "f 5 6 7\n";

const char* kQuadMtl =
    "newmtl red\nKd 0.7 0.1 0.1\nKs 0.2 0.2 0.2\nNs 50\nmap_Kd missing_texture.png\n"
    "newmtl lamp\nKd 0 0 0\nKe 10 8 6\n";

}  // namespace

TEST(ObjLoader, RoundTripPositionsIndicesAndMaterials) {
    auto dir = test::temp_dir("obj_round_trip");
    write_file(dir, "quad.mtl", kQuadMtl);
    Scene s = load_obj(write_file(dir, "quad.obj", kQuadObj));
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.nodes.size(), 1u);
    EXPECT_EQ(s.nodes[0].parent, -1);
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.positions.size(), 7u);
    EXPECT_EQ(m.positions[2], Vec3(1, 1, 0));
    EXPECT_EQ(m.positions[6], Vec3(1, 1, 1));
    // Quad fan-triangulated into (0,1,2), (0,2,3), then the triangle.
    ASSERT_EQ(m.triangles.size(), 3u);
    EXPECT_EQ(m.triangles[0], UVec3(0, 1, 2));
    EXPECT_EQ(m.triangles[1], UVec3(0, 2, 3));
    EXPECT_EQ(m.triangles[2], UVec3(4, 5, 6));
    ASSERT_EQ(m.material_ids.size(), 3u);
    const Material& red = s.materials[m.material_ids[0]];
    const Material& lamp = s.materials[m.material_ids[2]];
    EXPECT_EQ(red.name, "red");
    EXPECT_FLOAT_EQ(red.albedo.x, 0.7f);
    EXPECT_FLOAT_EQ(red.specular.y, 0.2f);
    EXPECT_FLOAT_EQ(red.phong_exponent, 50.0f);
    EXPECT_FALSE(red.is_emissive());
    EXPECT_EQ(lamp.name, "lamp");
    EXPECT_EQ(lamp.emission, Vec3(10, 8, 6));
    EXPECT_TRUE(s.has_emitters());
    EXPECT_EQ(s.degenerate_triangles_dropped, 0u);
}

namespace {

// A w × h RGBA PNG whose texel (x, y) is f(x, y).
std::string png(int w, int h, const std::function<std::array<uint8_t, 4>(int, int)>& f) {
    std::vector<uint8_t> texels;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const auto t = f(x, y);
            texels.insert(texels.end(), t.begin(), t.end());
        }
    std::string out;
    stbi_write_png_to_func([](void* c, void* d, int n) { static_cast<std::string*>(c)->append(static_cast<char*>(d), size_t(n)); },
                           &out, w, h, 4, texels.data(), w * 4);
    return out;
}

}  // namespace

// map_Kd, map_d (grey, no alpha channel), norm with -bm, -s/-o, -clamp; the image is
// read per texel, OBJ's v axis is flipped onto the image rows, and one decoded file
// serves every material that names it. A missing texture is a warning naming it.
TEST(ObjLoader, TexturesArePerTexelWithTheirOptions) {
    auto dir = test::temp_dir("obj_textures");
    // Left column red, right column blue; top row first in the file.
    write_file(dir, "colour.png", png(2, 2, [](int x, int) { return std::array<uint8_t, 4>{uint8_t(x ? 0 : 255), 0, uint8_t(x ? 255 : 0), 255}; }));
    // Grey mask: the top row open (0), the bottom row opaque (255).
    write_file(dir, "mask.png", png(2, 2, [](int, int y) { const uint8_t g = y ? 255 : 0; return std::array<uint8_t, 4>{g, g, g, 255}; }));
    write_file(dir, "flat.png", png(1, 1, [](int, int) { return std::array<uint8_t, 4>{128, 128, 255, 255}; }));
    write_file(dir, "t.mtl",
               "newmtl a\nKd 1 1 1\nmap_Kd colour.png\nmap_d mask.png\nnorm -bm 0.5 flat.png\n"
               "newmtl b\nKd 0.5 0.5 0.5\nmap_Kd -s 2 3 1 -o 0.25 0.5 0 -clamp on colour.png\n"
               "newmtl c\nKd 0.2 0.2 0.2\nmap_Kd nowhere.png\n");
    Scene s = load_obj(write_file(dir, "t.obj",
                                  "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                                  "usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 2/2 3/3\nusemtl c\nf 1/1 2/2 3/3\n"));
    ASSERT_EQ(s.materials.size(), 3u);
    const Material &a = s.materials[0], &b = s.materials[1], &c = s.materials[2];
    ASSERT_TRUE(a.albedo_texture);
    EXPECT_EQ(a.albedo_texture.image->encoding(), ColorEncoding::Srgb);
    // OBJ v = 0 is the image's bottom row; u = 0 its left column.
    const Vec4 bottom_left = a.albedo_texture.sample(Vec2(0.25f, 0.25f), 0.0f);
    EXPECT_NEAR(bottom_left.x, 1.0f, 1e-6f);
    EXPECT_NEAR(bottom_left.z, 0.0f, 1e-6f);
    ASSERT_TRUE(a.alpha_tested());
    ASSERT_TRUE(a.alpha_texture);
    EXPECT_EQ(a.alpha_texture.sample(Vec2(0.5f, 0.25f), 0.0f).w, 1.0f);  // bottom row: opaque
    EXPECT_EQ(a.alpha_texture.sample(Vec2(0.5f, 0.75f), 0.0f).w, 0.0f);  // top row: open
    ASSERT_TRUE(a.normal_texture);
    EXPECT_FLOAT_EQ(a.normal_scale, 0.5f);
    EXPECT_EQ(a.normal_texture.image->encoding(), ColorEncoding::Linear);
    EXPECT_EQ(b.albedo_texture.image, a.albedo_texture.image) << "one file, decoded once";
    EXPECT_EQ(b.albedo_texture.transform.scale, Vec2(2.0f, -3.0f));
    EXPECT_EQ(b.albedo_texture.transform.offset, Vec2(0.25f, 0.5f));
    EXPECT_EQ(b.albedo_texture.wrap_s, WrapMode::ClampToEdge);
    EXPECT_FALSE(b.alpha_tested());
    EXPECT_FALSE(c.albedo_texture);
    EXPECT_EQ(c.albedo, Vec3(0.2f));
    bool warned = false;
    for (const std::string& w : s.warnings) warned |= w.find("nowhere.png") != std::string::npos && w.find("not found") != std::string::npos;
    EXPECT_TRUE(warned);
    EXPECT_EQ(s.meshes[0].uvs.size(), s.meshes[0].positions.size());
}

TEST(ObjLoader, MissingMtlFallsBackToDefaultMaterial) {
    auto dir = test::temp_dir("obj_missing_mtl");
    Scene s = load_obj(write_file(dir, "a.obj", "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n"));
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].name, "default");
    EXPECT_EQ(s.meshes[0].material_ids[0], 0u);
    EXPECT_FALSE(s.warnings.empty());
}

TEST(ObjLoader, NormalsAndUvsSplitVerticesPerCorner) {
    auto dir = test::temp_dir("obj_normals");
    Scene s = load_obj(write_file(dir, "n.obj",
                                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                  "vn 0 0 2\nvn 0 0 -1\nvt 0 0\nvt 1 1\n"
                                  "f 1/1/1 2/1/1 3/2/1\nf 2/1/2 4/1/2 3/2/2\n"));
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.triangles.size(), 2u);
    // Vertex 2 and 3 appear with two different normals: 3 + 3 distinct corners.
    EXPECT_EQ(m.positions.size(), 6u);
    ASSERT_EQ(m.normals.size(), m.positions.size());
    ASSERT_EQ(m.uvs.size(), m.positions.size());
    EXPECT_FLOAT_EQ(glm::length(m.normals[0]), 1.0f);  // normalized on load
    EXPECT_EQ(m.uvs[m.triangles[0].z], Vec2(1, 1));
}

TEST(ObjLoader, NegativeRelativeIndices) {
    auto dir = test::temp_dir("obj_relative");
    Scene s = load_obj(write_file(dir, "r.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"));
    EXPECT_EQ(s.meshes[0].triangles[0], UVec3(0, 1, 2));
}

TEST(ObjLoader, MissingFile) {
    std::string msg = error_of([] { load_obj("/nonexistent/dir/missing.obj"); });
    EXPECT_NE(msg.find("missing.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not found"), std::string::npos) << msg;
}

TEST(ObjLoader, OutOfRangeIndexNamesFileAndLine) {
    auto dir = test::temp_dir("obj_out_of_range");
    auto p = write_file(dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
    std::string msg = error_of([&] { load_obj(p); });
    EXPECT_NE(msg.find("bad.obj:5"), std::string::npos) << msg;
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
}

TEST(ObjLoader, OutOfRangeQuadIsNotSilentlySkipped) {
    auto dir = test::temp_dir("obj_out_of_range_quad");
    auto p = write_file(dir, "quad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 40\n");
    std::string msg = error_of([&] { load_obj(p); });
    EXPECT_NE(msg.find("quad.obj:4"), std::string::npos) << msg;
    EXPECT_NE(msg.find("vertex 40"), std::string::npos) << msg;
}

TEST(ObjLoader, NegativeIndexBeyondStart) {
    auto dir = test::temp_dir("obj_negative");
    auto p = write_file(dir, "neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -7\n");
    std::string msg = error_of([&] { load_obj(p); });
    EXPECT_NE(msg.find("neg.obj:4"), std::string::npos) << msg;
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
}

TEST(ObjLoader, ZeroIndexIsMalformed) {
    auto dir = test::temp_dir("obj_zero_index");
    auto p = write_file(dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    std::string msg = error_of([&] { load_obj(p); });
    EXPECT_NE(msg.find("zero.obj:4"), std::string::npos) << msg;
}

TEST(ObjLoader, TruncatedFileIsAnError) {
    auto dir = test::temp_dir("obj_truncated");
    // Cut in the middle of a face line, and in the middle of a vertex line.
    auto face_cut = write_file(dir, "face_cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4");
    std::string msg = error_of([&] { load_obj(face_cut); });
    EXPECT_NE(msg.find("face_cut.obj:6"), std::string::npos) << msg;
    EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;

    auto vertex_cut = write_file(dir, "vertex_cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 0.5 0.");
    msg = error_of([&] { load_obj(vertex_cut); });
    EXPECT_NE(msg.find("vertex_cut.obj:5"), std::string::npos) << msg;
    EXPECT_NE(msg.find("coordinates"), std::string::npos) << msg;
}

TEST(ObjLoader, NanVertexNamesLine) {
    auto dir = test::temp_dir("obj_nan");
    auto p = write_file(dir, "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    std::string msg = error_of([&] { load_obj(p); });
    EXPECT_NE(msg.find("nan.obj:2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
    auto q = write_file(dir, "garbage.obj", "v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n");
    msg = error_of([&] { load_obj(q); });
    EXPECT_NE(msg.find("garbage.obj:2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'abc'"), std::string::npos) << msg;
}

TEST(ObjLoader, ZeroAreaTrianglesAreDroppedAndCounted) {
    auto dir = test::temp_dir("obj_degenerate");
    auto p = write_file(dir, "deg.obj",
                        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nusemtl a\n"
                        "f 1 2 3\n"   // fine
                        "f 1 2 4\n"   // collinear
                        "f 1 1 3\n"   // repeated index
                        "f 3 2 1\n");  // fine
    Scene s = load_obj(p);
    EXPECT_EQ(s.degenerate_triangles_dropped, 2u);
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.triangles.size(), 2u);
    EXPECT_EQ(m.material_ids.size(), 2u);
    EXPECT_EQ(m.triangles[1], UVec3(2, 1, 0));
}

TEST(ObjLoader, MaterialIdsStayAlignedWhenDropping) {
    auto dir = test::temp_dir("obj_degenerate_materials");
    write_file(dir, "m.mtl", "newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n");
    Scene s = load_obj(write_file(dir, "m.obj",
                                  "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
                                  "usemtl a\nf 1 2 4\nusemtl b\nf 1 2 3\n"));
    ASSERT_EQ(s.meshes[0].triangles.size(), 1u);
    EXPECT_EQ(s.materials[s.meshes[0].material_ids[0]].name, "b");
}

TEST(ObjLoader, EmptyFileIsAnError) {
    auto dir = test::temp_dir("obj_empty");
    auto p = write_file(dir, "empty.obj", "# nothing here\n");
    std::string msg = error_of([&] { load_obj(p); });
    EXPECT_NE(msg.find("empty.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("no faces"), std::string::npos) << msg;
}

TEST(MeshFile, DispatchesByExtension) {
    auto dir = test::temp_dir("mesh_file_dispatch");
    auto p = write_file(dir, "T.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    EXPECT_EQ(load_mesh_file(p).meshes[0].triangles.size(), 1u);
    std::string msg = error_of([&] { load_mesh_file(dir / "thing.stl"); });
    EXPECT_NE(msg.find("thing.stl"), std::string::npos) << msg;
    EXPECT_NE(msg.find("unknown mesh file extension"), std::string::npos) << msg;
}

TEST(MeshValidation, DirectChecks) {
    Mesh m;
    m.name = "tri";
    m.positions = {Vec3(0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    m.triangles = {UVec3(0, 1, 2)};
    m.material_ids = {0};
    EXPECT_EQ(validate_and_clean(m, 1, "src").degenerate_triangles_dropped, 0u);
    Bounds3 b = m.bounds();
    EXPECT_EQ(b.min, Vec3(0));
    EXPECT_EQ(b.max, Vec3(1, 1, 0));

    Mesh bad_material = m;
    std::string msg = error_of([&] { validate_and_clean(bad_material, 0, "src.obj"); });
    EXPECT_NE(msg.find("src.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("material 0"), std::string::npos) << msg;

    Mesh bad_normals = m;
    bad_normals.normals = {Vec3(0, 0, 1)};
    msg = error_of([&] { validate_and_clean(bad_normals, 1, "src.obj"); });
    EXPECT_NE(msg.find("1 normals for 3 vertices"), std::string::npos) << msg;

    Mesh bad_uvs = m;
    bad_uvs.uvs = {Vec2(0), Vec2(1)};
    msg = error_of([&] { validate_and_clean(bad_uvs, 1, "src.obj"); });
    EXPECT_NE(msg.find("2 texture coordinates for 3 vertices"), std::string::npos) << msg;

    Mesh inf = m;
    inf.positions[1].y = std::numeric_limits<float>::infinity();
    msg = error_of([&] { validate_and_clean(inf, 1, "src.obj"); });
    EXPECT_NE(msg.find("vertex 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;

    Mesh index = m;
    index.triangles[0].z = 3;
    msg = error_of([&] { validate_and_clean(index, 1, "src.obj"); });
    EXPECT_NE(msg.find("references vertex 3"), std::string::npos) << msg;

    Mesh tiny = m;  // a sliver whose height is 1e-12 of its length: zero area for us
    tiny.positions[2] = Vec3(0.5f, 1e-13f, 0);
    EXPECT_EQ(validate_and_clean(tiny, 1, "src").degenerate_triangles_dropped, 1u);
    EXPECT_TRUE(tiny.triangles.empty());
}

// ---- Real assets (skipped when ../shared/scenes is absent) ----

struct ObjAsset {
    const char* path;
    size_t vertices;
    size_t triangles;
};

class RealObj : public ::testing::TestWithParam<ObjAsset> {};

TEST_P(RealObj, MatchesManifestCounts) {
    const ObjAsset a = GetParam();
    auto path = test::shared_asset(a.path);
    if (!path) GTEST_SKIP() << "shared asset " << a.path << " not found";
    Scene s = load_obj(*path);
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& m = s.meshes[0];
    // No normals/uvs in these files, so OBJ vertices map one to one.
    if (m.normals.empty() && m.uvs.empty()) {
        EXPECT_EQ(m.positions.size(), a.vertices);
    }
    EXPECT_EQ(m.triangles.size() + s.degenerate_triangles_dropped, a.triangles)
        << "loaded " << m.triangles.size() << ", dropped " << s.degenerate_triangles_dropped;
    EXPECT_EQ(m.material_ids.size(), m.triangles.size());
    for (uint32_t id : m.material_ids) ASSERT_LT(id, s.materials.size());
}

INSTANTIATE_TEST_SUITE_P(Manifest, RealObj,
                         ::testing::Values(ObjAsset{"bunny/stanford-bunny.obj", 35947, 69451},
                                           ObjAsset{"dragon/dragon.obj", 50000, 100000},
                                           ObjAsset{"buddha/buddha.obj", 49950, 100000},
                                           ObjAsset{"cornell-box/CornellBox-Original.obj", 72, 36},
                                           ObjAsset{"terrain/terrain.obj", 41420, 82026},
                                           ObjAsset{"castle/fincastel.obj", 4706, 9352},
                                           ObjAsset{"sponza/sponza.obj", 39999, 66454}),
                         [](const auto& info) {
                             std::string n = fs::path(info.param.path).stem().string();
                             for (char& c : n)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return n;
                         });

TEST(RealObj, BunnyBoundsMatchManifest) {
    auto path = test::shared_asset("bunny/stanford-bunny.obj");
    if (!path) GTEST_SKIP() << "shared asset bunny/stanford-bunny.obj not found";
    Bounds3 b = load_obj(*path).meshes[0].bounds();
    EXPECT_NEAR(b.min.x, -0.09469f, 1e-5f);
    EXPECT_NEAR(b.max.y, 0.187321f, 1e-5f);
}

TEST(RealObj, CornellBoxMaterialsAndLight) {
    auto path = test::shared_asset("cornell-box/CornellBox-Original.obj");
    if (!path) GTEST_SKIP() << "shared asset cornell-box/CornellBox-Original.obj not found";
    Scene s = load_obj(*path);
    size_t emissive_triangles = 0;
    for (size_t t = 0; t < s.meshes[0].triangles.size(); ++t)
        emissive_triangles += s.materials[s.meshes[0].material_ids[t]].is_emissive();
    EXPECT_EQ(emissive_triangles, 2u);  // the ceiling light quad
    bool found_left = false;
    for (const auto& m : s.materials)
        if (m.name == "leftWall") {
            found_left = true;
            EXPECT_NEAR(m.albedo.x, 0.63f, 1e-6f);
        } else if (m.name == "light") {
            EXPECT_EQ(m.emission, Vec3(17, 12, 4));
        }
    EXPECT_TRUE(found_left);
}

TEST(RealObj, DragonWithMissingMtlLoads) {
    auto path = test::shared_asset("dragon/dragon.obj");
    if (!path) GTEST_SKIP() << "shared asset dragon/dragon.obj not found";
    Scene s = load_obj(*path);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].name, "default");
}
