// Hostile input through the `gilab` binary: each case must end with exit status 1 (an
// error, not an internal error), a message naming the file or option and the problem,
// a small peak memory (the child's peak RSS, a memory bound — nothing here is timed)
// and no file left in the output directory.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include "core/image/film.hpp"
#include "core/image/image_io.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;

namespace {

fs::path bad(const std::string& name) { return fs::path(GILAB_SOURCE_DIR) / "tests" / "data" / "bad" / name; }

constexpr long kMaxPeakKb = 300 * 1024;

struct GilabRun {
    int exit_code = -1;
    std::string output;  // stdout and stderr together
    long peak_rss_kb = 0;
};

// Runs the built binary without a shell (arguments pass through untouched, unicode
// paths included), its address space capped so a regression fails fast.
GilabRun run_gilab(const std::vector<std::string>& args) {
    const std::string binary = gilab::test::gilab_program();
    if (!fs::exists(binary)) {
        ADD_FAILURE() << binary << " is not built";
        return {};
    }
    int pipe_fds[2];
    if (pipe(pipe_fds) != 0) return {};
    const pid_t pid = fork();
    if (pid == 0) {
        dup2(pipe_fds[1], 1);
        dup2(pipe_fds[1], 2);
        close(pipe_fds[0]);
        close(pipe_fds[1]);
        if (!gilab::test::code_under_test_is_sanitized()) {
            rlimit cap{rlim_t(4) << 30, rlim_t(4) << 30};
            setrlimit(RLIMIT_AS, &cap);
        }
        std::vector<char*> argv{const_cast<char*>(binary.c_str())};
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(binary.c_str(), argv.data());
        _exit(127);
    }
    close(pipe_fds[1]);
    GilabRun r;
    std::array<char, 4096> buffer{};
    for (ssize_t n; (n = read(pipe_fds[0], buffer.data(), buffer.size())) > 0;) r.output.append(buffer.data(), size_t(n));
    close(pipe_fds[0]);
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.peak_rss_kb = usage.ru_maxrss;
    return r;
}

size_t file_count(const fs::path& dir) {
    size_t n = 0;
    for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it)
        n += it->is_regular_file();
    return n;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A failing run: status 1, every part in its message, small, and nothing written.
void expect_error(const std::vector<std::string>& args, const std::vector<std::string>& parts, const fs::path& out_dir) {
    std::string line;
    for (const auto& a : args) line += a + " ";
    const GilabRun r = run_gilab(args);
    EXPECT_EQ(r.exit_code, 1) << line << "\n" << r.output;
    for (const auto& part : parts) EXPECT_TRUE(contains(r.output, part)) << "missing '" << part << "' in: " << r.output;
    EXPECT_FALSE(contains(r.output, "internal error")) << r.output;
    EXPECT_LT(r.peak_rss_kb, kMaxPeakKb) << line;
    EXPECT_EQ(file_count(out_dir), 0u) << "a failed run left files behind: " << line;
}

class CliBadInput : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = gilab::test::temp_dir(std::string("cli_bad_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        out_ = dir_ / "out";
        fs::create_directories(out_);
    }
    std::vector<std::string> render(const std::vector<std::string>& extra, const std::string& scene = "cornell") const {
        std::vector<std::string> args = {"render", scene, "-W", "8", "-H", "8", "--spp", "1", "-o", (out_ / "image").string()};
        args.insert(args.end(), extra.begin(), extra.end());
        return args;
    }
    fs::path dir_, out_;
};

}  // namespace

TEST_F(CliBadInput, HugeCountsFailFastAndSmall) {
    expect_error({"info", bad("off_huge_corner_count.off").string()},
                 {"off_huge_corner_count.off:6:", "face 0 corner count is 2000000000"}, out_);
    expect_error({"info", bad("ply_binary_huge_list.ply").string()},
                 {"ply_binary_huge_list.ply", "list 'vertex_indices' length is 4294967295"}, out_);
    expect_error({"info", bad("gltf_accessor_count_no_view.gltf").string()},
                 {"gltf_accessor_count_no_view.gltf", "4000000000"}, out_);
    expect_error({"info", bad("scene_fps_1e12.json").string()},
                 {"scene_fps_1e12.json", "/animation/frames_per_second", "1e+12"}, out_);
}

TEST_F(CliBadInput, LibraryFailuresBecomeErrorsNamingFileAndKey) {
    expect_error({"info", bad("gltf_buffer_uri_dot.gltf").string()},
                 {"gltf_buffer_uri_dot.gltf", "/buffers/0/uri", "is a directory"}, out_);
    expect_error({"info", bad("scene_number_overflow.json").string()},
                 {"scene_number_overflow.json:1:51:", "/meshes/0/scale", "1e999"}, out_);
    expect_error({"render", "cornell", "--settings", bad("settings_number_overflow.json").string(), "-o", (out_ / "x").string()},
                 {"settings_number_overflow.json", "/spp", "1e999"}, out_);
}

TEST_F(CliBadInput, NonFiniteGeometryIsAnErrorNotABlackImage) {
    expect_error(render({}, bad("obj_huge_coordinates.obj").string()), {"obj_huge_coordinates.obj", "beyond"}, out_);
    expect_error(render({}, bad("scene_world_overflow.json").string()), {"scene_world_overflow.json", "beyond"}, out_);
    expect_error(render({}, bad("gltf_matrix_1e38.gltf").string()), {"gltf_matrix_1e38.gltf", "node 0"}, out_);
}

TEST_F(CliBadInput, OutOfRangeOptionsAreRefusedBeforeRendering) {
    expect_error(render({"--time", "nan"}), {"--time", "nan"}, out_);
    expect_error(render({"--hmd", "vive", "--ipd", "-1"}), {"--ipd", "-1", "[0, 1)"}, out_);
    expect_error(render({"--hmd", "vive", "--ipd", "100"}), {"--ipd", "100", "[0, 1)"}, out_);
    // Used to write the EXR and then fail on the PNG.
    expect_error(render({"--exposure", "nan"}), {"--exposure", "nan"}, out_);
}

TEST_F(CliBadInput, MissingOutputDirectoryIsRefusedNotCreated) {
    const fs::path missing = dir_ / "missing" / "sub";
    expect_error({"render", "cornell", "-W", "8", "-H", "8", "--spp", "1", "-o", (missing / "x").string()},
                 {"-o", "does not exist"}, out_);
    EXPECT_FALSE(fs::exists(dir_ / "missing"));
    expect_error({"render", "cornell", "-W", "8", "-H", "8", "--spp", "1", "-o", out_.string() + "/"}, {"names a directory"},
                 out_);
}

TEST_F(CliBadInput, GlobalOptionsAreChecked) {
    expect_error({"--assets", (dir_ / "no_such_dir").string(), "info", "cornell"}, {"--assets", "no_such_dir", "not a directory"},
                 out_);
    expect_error({"--memory-limit", "banana", "info", "cornell"}, {"--memory-limit", "'banana'"}, out_);
    expect_error({"--memory-limit", "512", "info", bad("base/pyramid.ply").string()},
                 {"pyramid.ply", "more than the memory limit of 512 bytes"}, out_);
    const GilabRun threads = run_gilab({"--threads", "-3", "info", "cornell"});
    EXPECT_NE(threads.exit_code, 0);
    EXPECT_TRUE(contains(threads.output, "--threads")) << threads.output;
    EXPECT_TRUE(contains(threads.output, "'-3'")) << threads.output;
    EXPECT_FALSE(contains(threads.output, "1797693")) << "prints the largest double as a bound: " << threads.output;
    const GilabRun help = run_gilab({"--help"});
    EXPECT_TRUE(contains(help.output, "--memory-limit")) << help.output;
    EXPECT_TRUE(contains(help.output, "each request on its own")) << "--help must say how the limit applies: " << help.output;
}

TEST_F(CliBadInput, UnicodePathIsNamedInTheError) {
    expect_error({"info", bad("ünïcödé_网格.off").string()}, {"ünïcödé_网格.off", "truncated OFF"}, out_);
}

TEST_F(CliBadInput, SuccessfulRenderLeavesExactlyItsFiles) {
    const GilabRun r = run_gilab(render({}));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(fs::exists(out_ / "image.exr"));
    EXPECT_TRUE(fs::exists(out_ / "image.png"));
    EXPECT_EQ(file_count(out_), 2u) << "temporary files left behind";
}

TEST_F(CliBadInput, FlatModelWithoutCameraIsSeen) {
    // A quad in the x = 0 plane: the old default view along −Z saw it edge-on, black.
    const GilabRun r = run_gilab({"render", bad("base/flat_yz.obj").string(), "-W", "16", "-H", "16", "--spp", "4", "-o",
                             (out_ / "image").string()});
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_FALSE(contains(r.output, "sees nothing")) << r.output;
    const gilab::Film film = gilab::read_exr(out_ / "image.exr");
    float brightest = 0;
    for (float v : film.layer("color").data) brightest = std::max(brightest, v);
    EXPECT_GT(brightest, 0.0f) << "the default camera's image is black";
}

TEST_F(CliBadInput, DeepNodeHierarchyRenders) {
    // 20000 nested nodes above one triangle: a stack overflow (SIGSEGV) when the
    // hierarchy was walked recursively.
    constexpr int kDepth = 20000;
    std::string nodes;
    for (int i = 0; i < kDepth; ++i) {
        if (i > 0) nodes += ',';
        if (i + 1 < kDepth) {
            nodes += R"({"children":[)";
            nodes += std::to_string(i + 1);
            nodes += "]}";
        } else {
            nodes += R"({"mesh":0})";
        }
    }
    const std::string triangle = R"("buffers":[{"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA","byteLength":36}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}])";
    const fs::path chain = gilab::test::write_file(dir_, "chain.gltf",
                                                   R"({"asset":{"version":"2.0"},)" + triangle + R"(,"nodes":[)" + nodes +
                                                       R"(],"scenes":[{"nodes":[0]}],"scene":0})");
    const GilabRun r = run_gilab(render({}, chain.string()));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(fs::exists(out_ / "image.exr"));
    EXPECT_LT(r.peak_rss_kb, kMaxPeakKb);
}

TEST_F(CliBadInput, ReferencedFilesThatAreNotFilesAreRefusedAtOnce) {
    // An MTL pointing to /dev/zero read for 95 s and reached 15 GB; a FIFO blocks on open.
    fs::create_symlink("/dev/zero", dir_ / "zero.mtl");
    ASSERT_EQ(mkfifo((dir_ / "fifo.mtl").c_str(), 0600), 0);
    const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const fs::path zero = gilab::test::write_file(dir_, "zero.obj", "mtllib zero.mtl\n" + triangle);
    const fs::path fifo = gilab::test::write_file(dir_, "fifo.obj", "mtllib fifo.mtl\n" + triangle);
    expect_error(render({}, zero.string()), {"zero.obj", "zero.mtl", "is a character device, not a regular file"}, out_);
    expect_error(render({}, fifo.string()), {"fifo.obj", "fifo.mtl", "is a FIFO (named pipe), not a regular file"}, out_);
    fs::create_symlink("/dev/zero", dir_ / "part.obj");
    const fs::path scene = gilab::test::write_file(dir_, "scene.json", R"({"meshes": [{"file": "part.obj"}]})");
    expect_error(render({}, scene.string()), {"scene.json", "/meshes/0/file", "part.obj", "not a regular file"}, out_);
    // A glTF whose buffer is a FIFO and one whose texture is /dev/zero.
    ASSERT_EQ(mkfifo((dir_ / "fifo.bin").c_str(), 0600), 0);
    fs::create_symlink("/dev/zero", dir_ / "zero.png");
    const std::string gltf_start = R"({"asset":{"version":"2.0"},"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)";
    const fs::path buffer = gilab::test::write_file(dir_, "buffer.gltf", gltf_start + R"(
        "buffers":[{"uri":"fifo.bin","byteLength":36}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]})");
    expect_error(render({}, buffer.string()), {"buffer.gltf", "/buffers/0/uri", "fifo.bin", "not a regular file"}, out_);
    const fs::path texture = gilab::test::write_file(dir_, "texture.gltf", gltf_start + R"(
        "buffers":[{"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA","byteLength":36}],
        "images":[{"uri":"zero.png"}],"textures":[{"source":0}],
        "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}]})");
    expect_error(render({}, texture.string()), {"texture.gltf", "/images/0/uri", "zero.png", "not a regular file"}, out_);
}

TEST_F(CliBadInput, ZeroScaleAndNegativeLightAreErrorsNotImages) {
    // Both rendered and exited 0: an all-black image, and one with negative pixels.
    const std::string triangle = R"({"asset":{"version":"2.0"},
        "buffers":[{"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA","byteLength":36}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)";
    const fs::path zero = gilab::test::write_file(
        dir_, "zero_scale.gltf", triangle + R"("nodes":[{"mesh":0,"scale":[0,0,0]}],"scenes":[{"nodes":[0]}]})");
    expect_error(render({}, zero.string()), {"zero_scale.gltf", "nothing visible"}, out_);
    const fs::path light = gilab::test::write_file(
        dir_, "negative_light.gltf",
        triangle + R"("extensionsUsed":["KHR_lights_punctual"],
        "extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","name":"lamp","color":[1,-2,1]}]}},
        "nodes":[{"mesh":0},{"translation":[0,0,2],"extensions":{"KHR_lights_punctual":{"light":0}}}],
        "scenes":[{"nodes":[0,1]}]})");
    expect_error(render({}, light.string()), {"negative_light.gltf", "light 'lamp'", "color/1", "-2"}, out_);
}
