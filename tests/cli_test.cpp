// End-to-end checks of the `gilab` binary: good runs write their files, bad input gives
// a clear message, a non-zero exit and no output files.
#include <gtest/gtest.h>
#include <array>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include "tests/test_support.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
    int exit_code;
    std::string output;  // stdout and stderr together
};

Result run(const std::string& args) {
    std::string command = std::string(GILAB_TEST_BINARY_DIR) + "/gilab " + args + " 2>&1";
    Result r{0, ""};
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return {-1, "popen failed"};
    std::array<char, 4096> buffer{};
    while (fgets(buffer.data(), int(buffer.size()), pipe)) r.output += buffer.data();
    int status = pclose(pipe);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

size_t file_count(const fs::path& dir) {
    size_t n = 0;
    for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it)
        n += it->is_regular_file();
    return n;
}

void expect_failure(const std::string& args, const std::vector<std::string>& message_parts, const fs::path& out_dir) {
    Result r = run(args);
    EXPECT_NE(r.exit_code, 0) << args << "\n" << r.output;
    for (const auto& part : message_parts) EXPECT_TRUE(contains(r.output, part)) << "missing '" << part << "' in: " << r.output;
    EXPECT_EQ(file_count(out_dir), 0u) << "a failed run left files behind: " << args;
}

}  // namespace

TEST(Cli, ListShowsTechniquesExperimentsScenesAndPresets) {
    Result r = run("list");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* name : {"path", "core-rays", "cornell", "vive"}) EXPECT_TRUE(contains(r.output, name)) << name;
}

TEST(Cli, InfoDescribesTheCornellBox) {
    Result r = run("info cornell");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "triangles    32")) << r.output;
    EXPECT_TRUE(contains(r.output, "open")) << r.output;
}

TEST(Cli, RendersMonoAndStereoFiles) {
    fs::path dir = gilab::test::temp_dir("cli_render");
    Result mono = run("render cornell --spp 2 -W 24 -H 16 -o " + (dir / "mono").string());
    ASSERT_EQ(mono.exit_code, 0) << mono.output;
    EXPECT_TRUE(fs::exists(dir / "mono.exr"));
    EXPECT_TRUE(fs::exists(dir / "mono.png"));
    Result stereo = run("render cornell --hmd vive --spp 1 -W 20 -H 22 -o " + (dir / "stereo").string());
    ASSERT_EQ(stereo.exit_code, 0) << stereo.output;
    EXPECT_TRUE(fs::exists(dir / "stereo.exr"));
    EXPECT_TRUE(fs::exists(dir / "stereo.png"));
    EXPECT_EQ(file_count(dir), 4u);  // no temporaries left behind
}

TEST(Cli, BadInputGivesAClearErrorAndNoFiles) {
    fs::path dir = gilab::test::temp_dir("cli_errors");
    fs::path out_dir = dir / "out";
    fs::create_directories(out_dir);
    std::string out = " -o " + (out_dir / "image").string();
    expect_failure("render cornell -t no_such_technique" + out, {"no_such_technique", "path"}, out_dir);
    expect_failure("render no_such_scene" + out, {"no_such_scene", "unknown scene"}, out_dir);
    expect_failure("render " + (dir / "missing.obj").string() + out, {"missing.obj"}, out_dir);
    expect_failure("render cornell --hmd no_such_headset" + out, {"no_such_headset", "vive"}, out_dir);
    expect_failure("render cornell -W 1000000 -H 1000000" + out, {"1000000"}, out_dir);
    expect_failure("render cornell -W 0 -H 10" + out, {"resolution"}, out_dir);
    expect_failure("render cornell --spp 1 -W 8 -H 8 --set sp=4" + out, {"'sp'"}, out_dir);
    {
        std::ofstream bad(dir / "broken.obj");
        bad << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
    }
    expect_failure("render " + (dir / "broken.obj").string() + out, {"broken.obj"}, out_dir);
    {
        std::ofstream nan(dir / "nan.obj");
        nan << "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n";
    }
    expect_failure("render " + (dir / "nan.obj").string() + out, {"nan.obj"}, out_dir);
    {
        std::ofstream empty(dir / "empty.obj");
        empty << "# nothing here\n";
    }
    expect_failure("render " + (dir / "empty.obj").string() + out, {"empty.obj"}, out_dir);
    expect_failure("experiment no_such_experiment --results " + out_dir.string(), {"no_such_experiment", "core-rays"},
                   out_dir);
}

TEST(Cli, QuickCoreRaysWritesItsTables) {
    fs::path dir = gilab::test::temp_dir("cli_experiment");
    Result r = run("experiment core-rays --quick --results " + dir.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* f : {"results.csv", "results.json", "table.md"}) EXPECT_TRUE(fs::exists(dir / "core-rays" / f)) << f;
    std::ifstream in(dir / "core-rays" / "results.json");
    auto doc = nlohmann::json::parse(in);
    EXPECT_TRUE(doc.contains("git_revision"));
    EXPECT_TRUE(doc.contains("machine"));
    ASSERT_FALSE(doc["tables"].empty());
    const auto& rows = doc["tables"][0]["rows"];
    ASSERT_GE(rows.size(), 2u);  // at least the Cornell box's primary and shadow rows
    for (const auto& row : rows) EXPECT_GT(row["single_mrays_per_s"].get<double>(), 0.0);

    Result report = run("report --results " + dir.string());
    ASSERT_EQ(report.exit_code, 0) << report.output;
    std::ifstream html(dir / "report.html");
    std::string text((std::istreambuf_iterator<char>(html)), std::istreambuf_iterator<char>());
    EXPECT_TRUE(contains(text, "core-rays"));
    EXPECT_TRUE(contains(text, "single_mrays_per_s"));
}

TEST(Cli, ReportWithoutResultsIsAnError) {
    fs::path dir = gilab::test::temp_dir("cli_report_empty");
    Result r = run("report --results " + dir.string());
    EXPECT_NE(r.exit_code, 0);
    EXPECT_TRUE(contains(r.output, "no results")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "report.html"));
}
