// Malformed and hostile input. Every file in tests/data/bad/ must end in a gilab::Error
// that names the file and the problem, and must do so without allocating much: a
// corrupt count has to be refused before anything is allocated for it, so the peak RSS
// may grow by at most 200 MB per case (a memory bound; nothing here measures time).
// Truncations of valid files at several offsets and the memory budget are checked too.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/io/scene_file.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;

namespace {

fs::path bad_dir() { return fs::path(GILAB_SOURCE_DIR) / "tests" / "data" / "bad"; }

long peak_rss_kb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_maxrss;
}

constexpr long kMaxGrowthKb = 200 * 1024;

// A regression (a count allocated before it is checked) should fail fast with
// std::bad_alloc instead of exhausting the machine: cap the address space a few GB above
// what the test process uses. AddressSanitizer reserves terabytes, so not there.
class AddressSpaceCap : public ::testing::Environment {
public:
    void SetUp() override {
        if (gilab::test::code_under_test_is_sanitized()) return;
        std::ifstream status("/proc/self/status");
        std::string line;
        while (std::getline(status, line))
            if (line.rfind("VmSize:", 0) == 0) {
                const rlim_t used = rlim_t(std::stoull(line.substr(7))) * 1024;
                rlimit cap{used + (rlim_t(3) << 30), used + (rlim_t(3) << 30)};
                setrlimit(RLIMIT_AS, &cap);
            }
    }
};
const auto* const kCap = ::testing::AddGlobalTestEnvironment(new AddressSpaceCap);

Scene load_any(const fs::path& path) {
    if (path.extension() == ".json") return load_scene_file(path, AssetPaths());
    return load_mesh_file(path);
}

// Loads `path` and returns the gilab::Error's message; anything else fails the test.
std::string error_loading(const fs::path& path) {
    try {
        load_any(path);
    } catch (const Error& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << path << ": threw " << typeid(e).name() << " (" << e.what() << "), not gilab::Error";
        return "";
    }
    ADD_FAILURE() << path << ": loaded without an error";
    return "";
}

struct BadCase {
    const char* file;                   // in tests/data/bad/
    std::vector<std::string> expected;  // substrings of the message, besides the file name
};

void PrintTo(const BadCase& c, std::ostream* out) { *out << c.file; }

const BadCase kCases[] = {
    // Huge counts: refused before anything is allocated for them.
    {"off_huge_corner_count.off", {":6:", "face 0 corner count is 2000000000"}},
    {"off_huge_vertex_count.off", {"truncated OFF", "2000000000 vertices", "before vertex 4"}},
    {"ply_binary_huge_list.ply", {"face 0 list 'vertex_indices' length is 4294967295", "only 12 bytes are left"}},
    {"ply_huge_vertex_count.ply", {"element 'vertex' count is 4000000000"}},
    {"gltf_accessor_count_no_view.gltf", {"accessor 1", "count (no buffer view) is 4000000000"}},
    // Length lies: a declared length larger than the bytes that are there.
    {"ply_binary_list_length_lie.ply", {"list 'vertex_indices' length is 200"}},
    {"gltf_buffer_length_lie.gltf", {"/buffers/0/byteLength", "1000000000", "holds only 36"}},
    {"glb_json_length_lie.glb", {"GLB JSON chunk length is 2147483632"}},
    {"glb_bin_length_lie.glb", {"/buffers/0/byteLength", "4000", "BIN chunk holds only 36"}},
    {"gltf_accessor_count_lie.gltf", {"accessor 0", "1000 elements reach past the end of buffer view 0"}},
    // Truncated files.
    {"off_truncated.off", {"truncated OFF", "before vertex 2"}},
    {"ply_ascii_truncated.ply", {":14:", "face 1 list 'vertex_indices' length is 3"}},
    {"ply_binary_truncated.ply", {"element 'vertex' count is 3", "only 28 bytes are left"}},
    {"obj_truncated.obj", {":4:", "face has 2 vertices", "truncated"}},
    {"glb_truncated.glb", {"truncated GLB", "declares 424 bytes but the file has 60"}},
    {"scene_truncated.json", {":1:42:", "/meshes/0", "JSON syntax error"}},
    {"ünïcödé_网格.off", {"truncated OFF", "before vertex 2"}},  // a unicode path
    // Out-of-range and negative indices.
    {"off_index_out_of_range.off", {":6:", "references vertex '7'", "out of range"}},
    {"off_negative_index.off", {":6:", "references vertex '-1'", "out of range"}},
    {"ply_negative_index.ply", {":13:", "references vertex -1", "out of range"}},
    {"obj_negative_index.obj", {":4:", "references vertex -9", "out of range"}},
    {"obj_zero_index.obj", {":4:", "index 0 is invalid"}},
    {"obj_index_beyond_64_bits.obj", {":4:", "'99999999999999999999999'", "out of range"}},
    {"gltf_index_out_of_range.gltf", {"indices", "out of bounds"}},
    // NaN, infinity and values beyond single precision, in files and after transforms.
    {"off_nan.off", {":4:", "vertex 1 coordinate 'nan' is not finite"}},
    {"ply_ascii_nan.ply", {":11:", "vertex 1 has a non-finite coordinate x = nan"}},
    {"obj_nan.obj", {":2:", "'nan' is not finite"}},
    {"obj_coordinate_overflow.obj", {":2:", "'1e39' is not finite"}},
    {"obj_mtl_kd_nan.obj", {"material library", "obj_mtl_kd_nan.mtl:2:", "Kd value 'nan' is not a finite number"}},
    {"obj_mtl_ke_inf.obj", {"material library", "obj_mtl_ke_inf.mtl:3:", "Ke value 'inf' is not a finite number"}},
    {"obj_huge_coordinates.obj", {"vertex 0", "-3e+38", "beyond the supported coordinate range"}},
    {"gltf_number_overflow.gltf", {"/accessors/0/count", "number 1e999 is out of range"}},
    {"gltf_node_scale_1e300.gltf", {"/nodes/0/scale/0", "1e+300 is out of range"}},
    {"gltf_matrix_1e38.gltf", {"node 0", "matrix does not decompose into a finite"}},
    {"gltf_node_scale_overflow.gltf", {"node 0", "mesh 'mesh0'", "beyond the supported range"}},
    {"scene_number_overflow.json", {":1:51:", "/meshes/0/scale", "number 1e999 is out of range"}},
    {"scene_scale_1e300.json", {"/meshes/0/scale", "1e+300 is out of range"}},
    {"scene_world_overflow.json", {"mesh 'tri'", "1e+30", "beyond the supported range"}},
    {"scene_fps_1e12.json", {"/animation/frames_per_second", "1e+12 is out of range"}},
    {"scene_fps_1e-300.json", {"/animation/frames_per_second", "1e-300 is too small"}},  // not "0.000000"
    {"scene_key_time_huge.json", {"lasts 1e+30 s", "more than the 1000000 supported"}},
    {"scene_ipd.json", {"/hmd/ipd", "[0, 1)"}},
    // glTF extension and camera numbers, and transforms that leave nothing to see.
    {"gltf_light_negative_color.gltf", {"/extensions/KHR_lights_punctual/lights/0/color/0", "light 'lamp'", "-1"}},
    {"gltf_camera_znear_negative.gltf", {"/cameras/0/perspective/znear", "camera 0 'view'", "-0.1"}},
    {"gltf_node_scale_zero.gltf", {"nothing visible", "node 'model' has scale [0, 0, 0]"}},
    // Wrong types, unknown keys and keywords, malformed headers.
    {"scene_wrong_type.json", {"/meshes/0/scale", "expected a number or an array of 3 numbers, got string"}},
    {"scene_unknown_key.json", {"/meshes/0/scal", "unknown key 'scal'"}},
    {"scene_deep_nesting.json", {"/description/0/0", "nested deeper than 256 levels"}},
    {"ply_value_not_a_number.ply", {":11:", "vertex 1 property 'y' value 'abc' is not a number"}},
    {"ply_unknown_type.ply", {":4:", "unknown type 'flaot'"}},
    {"ply_negative_count.ply", {":3:", "count '-5' is not a non-negative integer"}},
    {"off_count_not_a_number.off", {":2:", "vertex count 'three'"}},
    {"obj_index_not_a_number.obj", {":4:", "vertex index 'x' is not an integer"}},
    {"gltf_asset_wrong_type.gltf", {"/asset", "missing"}},
    // Versions and features that are not supported, said as such.
    {"gltf_version_3.gltf", {"/asset/version", "glTF version '3.0' is not supported"}},
    {"gltf_1_0.gltf", {"glTF 1.0 is not supported"}},
    {"gltf_1_0_no_asset.gltf", {"glTF 1.0 is not supported"}},
    {"glb_version_1.glb", {"GLB version 1", "not supported"}},
    {"ply_version.ply", {":2:", "PLY version '2.0' is not supported"}},
    // Properties CGAL would cast to the wrong type (null pointers, found by fuzzing).
    {"off_counts_line_extra_numbers.off", {":2:", "'3' follows the vertex, face and edge counts"}},
    {"off_huge_edge_count.off", {":2:", "edge count 2000000000 is larger than 1073741823"}},
    {"ply_integer_coordinate.ply", {"vertex property 'x' must be a float or double"}},
    {"ply_mixed_colour_types.ply", {"mixes uchar and other colour properties ('green'"}},
    {"ply_duplicate_property.ply", {"declares property 'x' twice"}},
    {"ply_real_face_indices.ply", {"face property 'vertex_indices' must be a list of integers"}},
    {"gltf_draco.gltf", {"/extensionsRequired/0", "Draco compression", "not supported"}},
    {"gltf_draco_not_required.gltf", {"/meshes/0/primitives/0", "Draco compression", "not supported"}},
    {"gltf_unknown_required_extension.gltf", {"required extension 'EXT_imaginary' is not supported"}},
    {"off_binary.off", {"binary OFF is not supported"}},
    {"off_utf16.off", {"UTF-16", "not supported"}},
    {"obj_utf16.obj", {"UTF-16", "not supported"}},
    {"scene_utf16.json", {"UTF-16", "not supported"}},
    // Paths that are not mesh files.
    {"directory.obj", {"is a directory, not a regular file"}},
    {"gltf_buffer_uri_dot.gltf", {"/buffers/0/uri", "'.'", "is a directory, not a regular file"}},
    {"scene_directory_mesh.json", {"/meshes/0/file", "'directory.obj'", "is a directory, not a regular file"}},
    {"scene_missing_mesh.json", {"/meshes/0/file", "'base/no_such_mesh.obj' not found"}},
};

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, EndsInAnErrorNamingFileAndProblemWithoutBigAllocations) {
    const BadCase& c = GetParam();
    const fs::path path = bad_dir() / c.file;
    const long before = peak_rss_kb();
    const std::string message = error_loading(path);
    EXPECT_NE(message.find(path.filename().string()), std::string::npos) << "the message does not name the file: " << message;
    for (const std::string& part : c.expected)
        EXPECT_NE(message.find(part), std::string::npos) << "missing '" << part << "' in: " << message;
    EXPECT_LT(peak_rss_kb() - before, kMaxGrowthKb) << "loading " << c.file << " allocated too much";
}

std::string case_name(const ::testing::TestParamInfo<BadCase>& info) {
    std::string name;
    for (unsigned char ch : std::string(info.param.file))
        name += std::isalnum(ch) ? char(ch) : '_';
    return name;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, ::testing::ValuesIn(kCases), case_name);

// Every file in the corpus is in the table (a new file without expectations is a mistake).
TEST(BadInputCorpus, EveryFileHasACase) {
    for (const auto& entry : fs::directory_iterator(bad_dir())) {
        const std::string name = entry.path().filename().string();
        if (name == "base" || name == "README.md" || entry.path().extension() == ".mtl" ||
            name == "settings_number_overflow.json")
            continue;
        bool listed = false;
        for (const BadCase& c : kCases) listed |= name == c.file;
        EXPECT_TRUE(listed) << name << " has no entry in kCases";
    }
}

// Valid files cut at several offsets: never a crash, a non-Error exception or a big
// allocation. Binary and JSON files must be refused; a text mesh cut at a line boundary
// may still be a valid, smaller file.
TEST(BadInputTruncation, ValidFilesCutAtSeveralOffsets) {
    const fs::path dir = test::temp_dir("bad_input_truncation");
    fs::copy_file(bad_dir() / "base" / "tri.obj", dir / "tri.obj");
    for (const char* name : {"pyramid.ply", "pyramid.off", "tri.obj", "triangle.gltf", "triangle.glb", "scene.json"}) {
        std::ifstream in(bad_dir() / "base" / name, std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        ASSERT_GT(bytes.size(), 20u) << name;
        ASSERT_NO_THROW(load_any(bad_dir() / "base" / name)) << name << " itself must load";
        const fs::path ext = fs::path(name).extension();
        const bool must_fail = ext != ".obj" && ext != ".off";
        for (size_t cut : {size_t(1), size_t(7), bytes.size() / 4, bytes.size() / 2, 3 * bytes.size() / 4, bytes.size() - 1}) {
            std::string cut_name = "cut_";
            cut_name += std::to_string(cut);
            cut_name += '_';
            cut_name += name;
            const fs::path path = test::write_file(dir, cut_name, bytes.substr(0, cut));
            const long before = peak_rss_kb();
            try {
                load_any(path);
                EXPECT_FALSE(must_fail) << cut_name << " loaded although it was cut at byte " << cut;
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find(cut_name), std::string::npos) << e.what();
            } catch (const std::exception& e) {
                ADD_FAILURE() << cut_name << ": threw " << e.what() << ", not gilab::Error";
            }
            EXPECT_LT(peak_rss_kb() - before, kMaxGrowthKb) << cut_name;
        }
    }
}

// ---------------------------------------------------------------- files that are not files

// Puts something that is not a regular file at `at`: /dev/zero (reads without end), a
// FIFO (blocks on open until a writer comes) or a directory.
void make_non_regular(const fs::path& at, const std::string& kind) {
    if (kind == "device") fs::create_symlink("/dev/zero", at);
    else if (kind == "fifo") ASSERT_EQ(mkfifo(at.c_str(), 0600), 0) << at;
    else fs::create_directory(at);
}

// Loading `path`, which references `referenced`, fails at once naming both, with the
// words "not a regular file" (not "not found"), without allocating much.
void expect_refused(const fs::path& path, const std::string& referenced) {
    const long before = peak_rss_kb();
    const std::string message = error_loading(path);
    EXPECT_NE(message.find(path.filename().string()), std::string::npos) << message;
    EXPECT_NE(message.find(referenced), std::string::npos) << message;
    EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
    EXPECT_EQ(message.find("not found"), std::string::npos) << message;
    EXPECT_LT(peak_rss_kb() - before, kMaxGrowthKb) << path;
}

std::string triangle_gltf_with(const std::function<void(nlohmann::json&)>& change) {
    std::ifstream in(bad_dir() / "base" / "triangle.gltf");
    nlohmann::json doc = nlohmann::json::parse(in);
    change(doc);
    return doc.dump();
}

class NonRegularFile : public ::testing::TestWithParam<std::string> {
protected:
    fs::path dir() const { return test::temp_dir("non_regular_" + GetParam()); }
};

TEST_P(NonRegularFile, AsMaterialLibrary) {
    // An MTL that was /dev/zero read for 95 s and reached 15 GB.
    const fs::path d = dir();
    make_non_regular(d / "lib.mtl", GetParam());
    expect_refused(test::write_file(d, "mesh.obj", "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "lib.mtl");
}

TEST_P(NonRegularFile, AsGltfBuffer) {
    const fs::path d = dir();
    make_non_regular(d / "data.bin", GetParam());
    expect_refused(test::write_file(d, "buffer.gltf", triangle_gltf_with([](nlohmann::json& doc) {
                                        doc["buffers"][0]["uri"] = "data.bin";
                                    })),
                   "data.bin");
}

TEST_P(NonRegularFile, AsGltfImage) {
    const fs::path d = dir();
    make_non_regular(d / "texture.png", GetParam());
    expect_refused(test::write_file(d, "image.gltf", triangle_gltf_with([](nlohmann::json& doc) {
                                        doc["images"] = {{{"uri", "texture.png"}}};
                                        doc["textures"] = {{{"source", 0}}};
                                        doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
                                        doc["meshes"][0]["primitives"][0]["material"] = 0;
                                    })),
                   "texture.png");
}

TEST_P(NonRegularFile, AsSceneFileMesh) {
    const fs::path d = dir();
    make_non_regular(d / "part.obj", GetParam());
    expect_refused(test::write_file(d, "scene.json", R"({"meshes": [{"file": "part.obj"}]})"), "part.obj");
}

INSTANTIATE_TEST_SUITE_P(Kinds, NonRegularFile, ::testing::Values("device", "fifo", "directory"),
                         [](const auto& info) { return info.param; });

// ---------------------------------------------------------------- memory budget

TEST(MemoryBudget, ParsesSizes) {
    EXPECT_EQ(MemoryBudget::parse_size("8G", "--memory-limit"), uint64_t(8) << 30);
    EXPECT_EQ(MemoryBudget::parse_size("512M", "--memory-limit"), uint64_t(512) << 20);
    EXPECT_EQ(MemoryBudget::parse_size("64k", "--memory-limit"), uint64_t(64) << 10);
    EXPECT_EQ(MemoryBudget::parse_size("1.5G", "--memory-limit"), uint64_t(3) << 29);
    EXPECT_EQ(MemoryBudget::parse_size("2GiB", "--memory-limit"), uint64_t(2) << 30);
    EXPECT_EQ(MemoryBudget::parse_size("1000000", "--memory-limit"), 1000000u);
    for (const char* bad : {"", "banana", "-1G", "8X", "0", "1e3"}) {
        const std::string msg = test::error_of([&] { MemoryBudget::parse_size(bad, "--memory-limit"); });
        EXPECT_NE(msg.find("--memory-limit"), std::string::npos) << bad << ": " << msg;
        std::string quoted(1, '\'');
        quoted += bad;
        quoted += '\'';
        EXPECT_NE(msg.find(quoted), std::string::npos) << bad << ": " << msg;
    }
    EXPECT_NE(test::error_of([] { MemoryBudget::parse_size("99999999T", "--memory-limit"); }).find("16 EiB"),
              std::string::npos);
}

TEST(MemoryBudget, DefaultsToAFractionOfPhysicalMemory) {
    EXPECT_GT(MemoryBudget::default_limit(), uint64_t(64) << 20);
    {
        ScopedMemoryLimit limit(12345);
        EXPECT_EQ(MemoryBudget::limit(), 12345u);
    }
    EXPECT_EQ(MemoryBudget::limit(), MemoryBudget::default_limit());
}

TEST(MemoryBudget, ChecksNameWhatAndWhere) {
    ScopedMemoryLimit limit(1000);
    EXPECT_NO_THROW(MemoryBudget::check(1000, "a film", "--width"));
    std::string msg = test::error_of([] { MemoryBudget::check(4096, "a 32×32 film", "--width/--height"); });
    EXPECT_NE(msg.find("--width/--height: a 32×32 film needs 4 KiB (4096 bytes)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("memory limit of 1000 bytes"), std::string::npos) << msg;
    // A count the file cannot hold is a lie, whatever the budget says.
    msg = test::error_of([] { MemoryBudget::check_count(50, 4, 100, 1, "face count", "x.ply"); });
    EXPECT_NE(msg.find("x.ply: face count is 50, which needs at least 200 bytes of file data, but only 100"),
              std::string::npos)
        << msg;
    msg = test::error_of([] { MemoryBudget::check_count(20, 4, 100, 64, "face count", "x.ply"); });
    EXPECT_NE(msg.find("x.ply: face count 20 needs 1.2 KiB (1280 bytes)"), std::string::npos) << msg;
    EXPECT_EQ(MemoryBudget::times(uint64_t(1) << 40, uint64_t(1) << 40), UINT64_MAX);  // saturates
}

TEST(MemoryBudget, AppliesToEachRequestOnItsOwn) {
    // The documented rule (README, --help): no running total, so requests that each fit
    // pass however many there are, and one that does not fit is refused alone.
    ScopedMemoryLimit limit(1000);
    for (int i = 0; i < 3; ++i) EXPECT_NO_THROW(MemoryBudget::check(600, "a 600-byte request", "test"));
    EXPECT_NE(test::error_of([] { MemoryBudget::check(1001, "a 1001-byte request", "test"); }).find("memory limit of 1000"),
              std::string::npos);
    for (int i = 0; i < 3; ++i) EXPECT_NO_THROW(load_any(bad_dir() / "base" / "tri.obj"));
}

TEST(MemoryBudget, LoadersRefuseFilesBeyondTheBudget) {
    ScopedMemoryLimit limit(512);
    for (const char* name : {"pyramid.ply", "pyramid.off", "triangle.gltf", "triangle.glb"}) {
        const std::string msg = test::error_of([&] { load_any(bad_dir() / "base" / name); });
        EXPECT_NE(msg.find(name), std::string::npos) << msg;
        EXPECT_NE(msg.find("more than the memory limit of 512 bytes"), std::string::npos) << msg;
    }
    ScopedMemoryLimit tiny(64);
    const std::string msg = test::error_of([&] { load_any(bad_dir() / "base" / "tri.obj"); });
    EXPECT_NE(msg.find("tri.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("memory limit of 64 bytes"), std::string::npos) << msg;
}

TEST(MemoryBudget, TexturesBeyondTheBudgetAreSkippedNotDecoded) {
    const fs::path dir = test::temp_dir("bad_input_texture_budget");
    // A PNG header declaring 4096 × 4096 pixels (128 MiB in the decoder's buffer, 85 MiB of
    // 8-bit mip pyramid).
    std::string png = "\x89PNG\r\n\x1a\n";
    png += std::string("\0\0\0\x0dIHDR", 8);
    png += std::string("\0\0\x10\0\0\0\x10\0\x08\x06\0\0\0\0\0\0\0", 17);
    test::write_file(dir, "big.png", png);
    std::ifstream in(bad_dir() / "base" / "triangle.gltf");
    nlohmann::json doc = nlohmann::json::parse(in);
    doc["images"] = {{{"uri", "big.png"}}};
    doc["textures"] = {{{"source", 0}}};
    doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    doc["meshes"][0]["primitives"][0]["material"] = 0;
    const fs::path path = test::write_file(dir, "textured.gltf", doc.dump());
    ScopedMemoryLimit limit(uint64_t(64) << 20);
    const Scene s = load_mesh_file(path);
    bool skipped = false;
    for (const std::string& w : s.warnings)
        skipped |= w.find("big.png") != std::string::npos && w.find("4096 × 4096") != std::string::npos &&
                   w.find("memory limit") != std::string::npos;
    EXPECT_TRUE(skipped) << "no warning about the oversized texture";
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_FALSE(s.materials[0].albedo_texture) << "a refused image leaves the material untextured";
}

}  // namespace
