// PLY and OFF loading through CGAL: ASCII and binary round trips, polygons fan-
// triangulated, and malformed files rejected with the file name.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;
using gilab::test::error_of;
using gilab::test::write_file;

namespace {

// A unit square pyramid: 5 vertices, one quad base and four triangles.
const char* kPyramidPly =
    "ply\nformat ascii 1.0\ncomment pyramid\n"
    "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 5\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n"
    "4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";

const char* kPyramidOff =
    "OFF\n# pyramid\n5 5 8\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n"
    "4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";

void check_pyramid(const Scene& s) {
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.positions.size(), 5u);
    EXPECT_EQ(m.positions[4], Vec3(0.5f, 0.5f, 1.0f));
    ASSERT_EQ(m.triangles.size(), 6u);  // quad → 2
    EXPECT_EQ(m.triangles[0], UVec3(0, 3, 2));
    EXPECT_EQ(m.triangles[1], UVec3(0, 2, 1));
    EXPECT_EQ(m.triangles[2], UVec3(0, 1, 4));
    EXPECT_EQ(m.material_ids.size(), 6u);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.degenerate_triangles_dropped, 0u);
}

}  // namespace

TEST(PlyLoader, AsciiPlyRoundTrip) {
    auto dir = test::temp_dir("ply_ascii");
    check_pyramid(load_ply_or_off(write_file(dir, "pyramid.ply", kPyramidPly)));
}

TEST(PlyLoader, FreeTextHeaderLinesAreSkippedWithAWarning) {
    // Exporters write lines such as "Created by ..." between the header keywords; other
    // readers skip them, and so did gilab before the header was checked strictly.
    std::string text = kPyramidPly;
    text.insert(text.find("element vertex"), "Created by ExampleScanner 2.1\n");
    text.insert(text.find("end_header"), "units mm\n");
    auto dir = test::temp_dir("ply_free_text_header");
    const Scene s = load_ply_or_off(write_file(dir, "annotated.ply", text));
    check_pyramid(s);
    std::vector<std::string> notes;
    for (const std::string& w : s.warnings)
        if (w.find("annotated.ply:4:") != std::string::npos || w.find("annotated.ply:11:") != std::string::npos) notes.push_back(w);
    ASSERT_EQ(notes.size(), 2u) << "expected a warning for each free-text header line";
    EXPECT_NE(notes[0].find("'Created'"), std::string::npos) << notes[0];
    EXPECT_NE(notes[0].find("ignored"), std::string::npos) << notes[0];
}

TEST(PlyLoader, BinaryPlyRoundTrip) {
    auto dir = test::temp_dir("ply_binary");
    std::string bytes =
        "ply\nformat binary_little_endian 1.0\n"
        "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 5\nproperty list uchar int vertex_indices\nend_header\n";
    const float v[15] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5f, 0.5f, 1};
    bytes.append(reinterpret_cast<const char*>(v), sizeof v);
    auto face = [&](std::vector<int32_t> idx) {
        bytes.push_back(char(idx.size()));
        bytes.append(reinterpret_cast<const char*>(idx.data()), idx.size() * 4);
    };
    face({0, 3, 2, 1});
    face({0, 1, 4});
    face({1, 2, 4});
    face({2, 3, 4});
    face({3, 0, 4});
    check_pyramid(load_mesh_file(write_file(dir, "pyramid.ply", bytes)));
}

TEST(PlyLoader, OffRoundTrip) {
    auto dir = test::temp_dir("off_ascii");
    check_pyramid(load_mesh_file(write_file(dir, "pyramid.off", kPyramidOff)));
}

// Colours, normals and texture coordinates are ignored, whatever their count per line:
// CGAL's own colour reader indexed past the numbers of a vertex line without a colour.
TEST(PlyLoader, OffVariantsReadPositionsWhateverTheirExtraNumbers) {
    auto dir = test::temp_dir("off_variants");
    const char* vertices = "0 0 0 255 0 0\n1 0 0\n1 1 0 7\n0 1 0 1 2\n0.5 0.5 1 0 0 255 255 9\n";
    const char* faces = "4 0 3 2 1\n3 0 1 4 255 0 0\n3 1 2 4\n3 2 3 4 12\n3 3 0 4 1 2\n";
    for (const char* keyword : {"COFF", "NOFF", "CNOFF", "STOFF", "STCNOFF"}) {
        SCOPED_TRACE(keyword);
        check_pyramid(load_mesh_file(write_file(dir, std::string(keyword) + ".off",
                                                std::string(keyword) + "\n5 5 8\n" + vertices + faces)));
    }
}

TEST(PlyLoader, MissingFile) {
    std::string msg = error_of([] { load_ply_or_off("/nonexistent/mesh.ply"); });
    EXPECT_NE(msg.find("mesh.ply"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not found"), std::string::npos) << msg;
}

TEST(PlyLoader, TruncatedPly) {
    auto dir = test::temp_dir("ply_truncated");
    std::string text = kPyramidPly;
    auto p = write_file(dir, "cut.ply", text.substr(0, text.find("3 1 2 4")));
    std::string msg = error_of([&] { load_ply_or_off(p); });
    EXPECT_NE(msg.find("cut.ply"), std::string::npos) << msg;
    EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;

    auto header_only = write_file(dir, "header.ply", text.substr(0, text.find("end_header")));
    msg = error_of([&] { load_ply_or_off(header_only); });
    EXPECT_NE(msg.find("header.ply"), std::string::npos) << msg;
    EXPECT_NE(msg.find("malformed PLY"), std::string::npos) << msg;
}

TEST(PlyLoader, TruncatedOff) {
    auto dir = test::temp_dir("off_truncated");
    std::string text = kPyramidOff;
    auto p = write_file(dir, "cut.off", text.substr(0, text.find("1 1 0")));
    std::string msg = error_of([&] { load_ply_or_off(p); });
    EXPECT_NE(msg.find("cut.off"), std::string::npos) << msg;
    EXPECT_NE(msg.find("truncated OFF"), std::string::npos) << msg;
    EXPECT_NE(msg.find("vertex 2"), std::string::npos) << msg;
}

TEST(PlyLoader, OutOfRangeIndex) {
    auto dir = test::temp_dir("ply_bad_index");
    std::string text = kPyramidPly;
    text.replace(text.find("3 3 0 4"), 7, "3 3 0 9");
    auto p = write_file(dir, "bad.ply", text);
    std::string msg = error_of([&] { load_ply_or_off(p); });
    EXPECT_NE(msg.find("bad.ply"), std::string::npos) << msg;
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;

    std::string off = kPyramidOff;
    off.replace(off.find("3 3 0 4"), 7, "3 3 0 5");
    auto q = write_file(dir, "bad.off", off);
    msg = error_of([&] { load_ply_or_off(q); });
    EXPECT_NE(msg.find("bad.off"), std::string::npos) << msg;
    EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
}

TEST(PlyLoader, NanVertex) {
    auto dir = test::temp_dir("ply_nan");
    std::string bytes =
        "ply\nformat binary_little_endian 1.0\n"
        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const float v[9] = {0, 0, 0, std::numeric_limits<float>::quiet_NaN(), 0, 0, 0, 1, 0};
    bytes.append(reinterpret_cast<const char*>(v), sizeof v);
    const int32_t f[3] = {0, 1, 2};
    bytes.push_back(3);
    bytes.append(reinterpret_cast<const char*>(f), sizeof f);
    auto p = write_file(dir, "nan.ply", bytes);
    std::string msg = error_of([&] { load_ply_or_off(p); });
    EXPECT_NE(msg.find("nan.ply"), std::string::npos) << msg;
    EXPECT_NE(msg.find("vertex 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;
}

TEST(PlyLoader, ZeroAreaTriangleDropped) {
    auto dir = test::temp_dir("off_degenerate");
    auto p = write_file(dir, "deg.off", "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n3 0 1 2\n3 0 1 3\n3 2 1 0\n");
    Scene s = load_ply_or_off(p);
    EXPECT_EQ(s.degenerate_triangles_dropped, 1u);
    EXPECT_EQ(s.meshes[0].triangles.size(), 2u);
}

TEST(PlyLoader, GarbageIsMalformed) {
    auto dir = test::temp_dir("ply_garbage");
    auto p = write_file(dir, "garbage.off", "this is not an OFF file\n");
    std::string msg = error_of([&] { load_ply_or_off(p); });
    EXPECT_NE(msg.find("garbage.off"), std::string::npos) << msg;
}
