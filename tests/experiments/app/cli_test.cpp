// End-to-end checks of the `gilab` binary: good runs write their files, bad input gives
// a clear message, a non-zero exit and no output files.
#include <gtest/gtest.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>
#include "core/image/film.hpp"
#include "core/image/image_io.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
    int exit_code;
    std::string output;  // stdout and stderr together
};

Result run(const std::string& args) {
    std::string command = gilab::test::gilab_program() + " " + args + " 2>&1";
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

TEST(Cli, ListSettingsPrintsEachTechniquesSchema) {
    for (const char* technique : {"path", "photon", "vct", "dag_shadows", "dag_raycast"}) {
        const Result r = run(std::string("list settings ") + technique);
        ASSERT_EQ(r.exit_code, 0) << r.output;
        EXPECT_TRUE(contains(r.output, std::string(technique) + ": ")) << r.output;
        EXPECT_TRUE(contains(r.output, "tile_size")) << technique;
    }
    EXPECT_TRUE(contains(run("list settings photon").output, "(searched in 1024 … 67108864)"));
    EXPECT_TRUE(contains(run("list settings vct --markdown").output, "| `diffuse_cones` | integer | 16 |"));
    const Result unknown = run("list settings photons");
    EXPECT_NE(unknown.exit_code, 0);
    EXPECT_TRUE(contains(unknown.output, "unknown technique")) << unknown.output;
    const Result misplaced = run("list scenes --markdown");
    EXPECT_NE(misplaced.exit_code, 0);
    EXPECT_TRUE(contains(misplaced.output, "go with `gilab list settings` only")) << misplaced.output;
}

TEST(Cli, DeclaredExperimentsRunTaskByTaskAndMerge) {
    const fs::path dir = gilab::test::temp_dir("cli_tasks");
    const Result plan = run("experiment plan pm-radius-sweep --quick");
    ASSERT_EQ(plan.exit_code, 0) << plan.output;
    EXPECT_EQ(std::count(plan.output.begin(), plan.output.end(), '\n'), 4) << plan.output;
    const std::string results = " --quick --results " + dir.string();
    const Result task = run("experiment run-task pm-radius-sweep 1" + results);
    if (contains(task.output, "not found")) GTEST_SKIP() << task.output;  // the conference room is a shared asset
    ASSERT_EQ(task.exit_code, 0) << task.output;
    EXPECT_TRUE(fs::exists(dir / "pm-radius-sweep" / "tasks" / "quick" / "1.json"));
    // The plan now knows what task 1 cost.
    const Result replan = run("experiment plan pm-radius-sweep" + results);
    size_t estimates = 0;
    for (size_t at = replan.output.find("seconds_last_run"); at != std::string::npos;
         at = replan.output.find("seconds_last_run", at + 1))
        ++estimates;
    EXPECT_EQ(estimates, 1u) << replan.output;
    const Result merge = run("experiment merge pm-radius-sweep" + results);
    ASSERT_EQ(merge.exit_code, 0) << merge.output;
    std::ifstream table(dir / "pm-radius-sweep" / "table.md");
    const std::string text((std::istreambuf_iterator<char>(table)), std::istreambuf_iterator<char>());
    EXPECT_TRUE(contains(text, "3 of 4 tasks have not run (0, 2, 3)")) << text;
    // An incomplete merge is not a finished run: --resume runs the experiment again.
    const Result resumed = run("experiment pm-radius-sweep --resume" + results);
    EXPECT_TRUE(contains(resumed.output, "running again (merged from some of its tasks only)")) << resumed.output;
    for (const auto& [args, message] :
         std::vector<std::pair<std::string, std::string>>{{"experiment run-task pm-radius-sweep 4" + results, "no task 4"},
                                                          {"experiment run-task pm-radius-sweep x" + results, "not a task id"},
                                                          {"experiment run-task pm-radius-sweep" + results, "needs an experiment name and a task id"},
                                                          {"experiment plan pm-table99", "pm-radius-sweep"},
                                                          {"experiment merge pm-radius-sweep --results " + (dir / "none").string(), "no such directory"}}) {
        const Result r = run(args);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_TRUE(contains(r.output, message)) << args << "\n" << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "none"));  // a failed merge creates nothing
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

namespace {

std::string head_turn_trace() { return std::string(GILAB_SOURCE_DIR) + "/scenes/traces/head_turn.csv"; }

std::vector<std::string> read_lines(const fs::path& path) {
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

std::vector<double> csv_numbers(const std::string& line) {
    std::vector<double> values;
    std::istringstream in(line);
    for (std::string field; std::getline(in, field, ',');) values.push_back(std::stod(field));
    return values;
}

const std::vector<float>& color_of(const gilab::Film& film) { return film.layer("color").data; }

}  // namespace

TEST(Cli, HeadTraceRendersAStereoSequence) {
    fs::path dir = gilab::test::temp_dir("cli_head_trace");
    const std::string size = " --spp 1 -W 20 -H 22";
    Result r = run("render cornell --hmd vive --head-trace " + head_turn_trace() + " --frames 3 --fps 30" + size +
                   " -o " + (dir / "seq").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* frame : {"0000", "0001", "0002"}) {
        EXPECT_TRUE(fs::exists(dir / ("seq_" + std::string(frame) + ".exr"))) << frame;
        EXPECT_TRUE(fs::exists(dir / ("seq_" + std::string(frame) + ".png"))) << frame;
    }
    EXPECT_TRUE(fs::exists(dir / "seq_frames.csv"));
    EXPECT_EQ(file_count(dir), 7u);  // three frames, the CSV, no temporaries
    for (const char* line : {"frame 1/3", "frame 2/3", "frame 3/3"}) EXPECT_TRUE(contains(r.output, line)) << r.output;

    auto lines = read_lines(dir / "seq_frames.csv");
    ASSERT_EQ(lines.size(), 4u);
    EXPECT_EQ(lines[0], "frame,time,px,py,pz,qw,qx,qy,qz,render_ms");
    for (int k = 0; k < 3; ++k) {
        auto row = csv_numbers(lines[size_t(k) + 1]);
        ASSERT_EQ(row.size(), 10u) << lines[size_t(k) + 1];
        EXPECT_EQ(row[0], k);
        EXPECT_NEAR(row[1], k / 30.0, 1e-6);
        EXPECT_NEAR(row[5] * row[5] + row[6] * row[6] + row[7] * row[7] + row[8] * row[8], 1.0, 1e-5);
        EXPECT_GE(row[9], 0.0);
    }

    // Both eyes of each frame are in one multi-view EXR; the head moves, so frames differ.
    gilab::Film first = gilab::read_exr(dir / "seq_0000.exr");
    gilab::Film first_right = gilab::read_exr(dir / "seq_0000.exr", "right");
    gilab::Film last = gilab::read_exr(dir / "seq_0002.exr");
    ASSERT_EQ(first.width(), 20);
    ASSERT_EQ(first.height(), 22);
    EXPECT_NE(color_of(first), color_of(last));
    EXPECT_NE(color_of(first), color_of(first_right));
    EXPECT_EQ(first.metadata["frame"], "0");
    EXPECT_EQ(last.metadata["frame"], "2");

    // Frame 0 is the scene's own HMD pose: the same image as a plain stereo render.
    Result still = run("render cornell --hmd vive" + size + " -o " + (dir / "still").string());
    ASSERT_EQ(still.exit_code, 0) << still.output;
    EXPECT_EQ(color_of(gilab::read_exr(dir / "still.exr")), color_of(first));
    EXPECT_EQ(color_of(gilab::read_exr(dir / "still.exr", "right")), color_of(first_right));
}

TEST(Cli, TraceScaleZeroKeepsTheHeadInPlaceButTurnsIt) {
    fs::path dir = gilab::test::temp_dir("cli_head_trace_scale");
    Result r = run("render cornell --hmd vive --head-trace " + head_turn_trace() +
                   " --frames 2 --fps 1 --trace-scale 0 --spp 1 -W 8 -H 8 -o " + (dir / "turn").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    auto lines = read_lines(dir / "turn_frames.csv");
    ASSERT_EQ(lines.size(), 3u);
    auto a = csv_numbers(lines[1]), b = csv_numbers(lines[2]);
    ASSERT_EQ(a.size(), 10u);
    ASSERT_EQ(b.size(), 10u);
    EXPECT_NEAR(b[1], 1.0, 1e-9);
    for (int i = 2; i < 5; ++i) EXPECT_EQ(a[size_t(i)], b[size_t(i)]) << "position column " << i;
    // One second into the trace the head has turned by about 15 degrees.
    double dot = std::abs(a[5] * b[5] + a[6] * b[6] + a[7] * b[7] + a[8] * b[8]);
    double degrees = 2.0 * std::acos(std::min(1.0, dot)) * 180.0 / 3.14159265358979;
    EXPECT_GT(degrees, 14.0);
    EXPECT_LT(degrees, 17.0);
}

TEST(Cli, BadHeadTraceOptionsGiveAClearErrorAndNoFiles) {
    fs::path dir = gilab::test::temp_dir("cli_head_trace_errors");
    fs::path out_dir = dir / "out";
    fs::create_directories(out_dir);
    std::string out = " --spp 1 -W 8 -H 8 -o " + (out_dir / "seq").string();
    expect_failure("render cornell --head-trace " + head_turn_trace() + out, {"--head-trace", "--hmd"}, out_dir);
    expect_failure("render cornell --hmd vive --head-trace " + (dir / "missing_trace.csv").string() + out,
                   {"missing_trace.csv", "cannot open"}, out_dir);
    fs::path bad = gilab::test::write_file(dir, "bad_trace.csv",
                                           "t,px,py,pz,qw,qx,qy,qz\n0,0,1.6,0,1,0,0,0\n0.1,0,oops,0,1,0,0,0\n");
    expect_failure("render cornell --hmd vive --head-trace " + bad.string() + out,
                   {"bad_trace.csv:3", "'py' is not a number"}, out_dir);
    expect_failure("render cornell --hmd vive --frames 3" + out, {"--frames", "--head-trace"}, out_dir);
    expect_failure("render cornell --hmd vive --head-trace " + head_turn_trace() + " --fps 0" + out, {"--fps"},
                   out_dir);
    expect_failure("render cornell --hmd vive --head-trace " + head_turn_trace() + " --frames 0" + out, {"--frames"},
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
    // Listed in the contents under the core measurements, its tables in scroll boxes.
    EXPECT_TRUE(contains(text, "<h3>Core measurements</h3>\n<ul>\n<li><a href=\"#experiment-core-rays\">core-rays</a>"));
    EXPECT_TRUE(contains(text, "<section class=\"result experiment\" id=\"experiment-core-rays\">"));
    EXPECT_TRUE(contains(text, "<div class=\"table-scroll\"><table>"));
}

TEST(Cli, ReportWithoutResultsIsAnError) {
    fs::path dir = gilab::test::temp_dir("cli_report_empty");
    Result r = run("report --results " + dir.string());
    EXPECT_NE(r.exit_code, 0);
    EXPECT_TRUE(contains(r.output, "no results")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "report.html"));
}

TEST(Cli, RendersShadowsFromEveryStructure) {
    const fs::path dir = gilab::test::temp_dir("cli_dag_shadows");
    for (const std::string vis : {"ray", "shadow_map", "shadow_dag", "shadow_dag_double_depth"}) {
        const fs::path out = dir / vis;
        const Result r = run("render villa -t dag_shadows --set visibility=" + vis + " --set resolution=256 -W 64 -H 48 -o " +
                             out.string());
        EXPECT_EQ(r.exit_code, 0) << r.output;
        EXPECT_TRUE(fs::exists(out.string() + ".exr")) << vis;
        EXPECT_TRUE(fs::exists(out.string() + ".png")) << vis;
    }
    const fs::path bad = gilab::test::temp_dir("cli_dag_shadows_bad");
    expect_failure("render fbm_terrain -t dag_shadows --set visibility=shadowmap -W 32 -H 32 -o " + (bad / "x").string(),
                   {"'visibility'", "shadowmap"}, bad);
}

TEST(Cli, PhotonTakesPixelSamplesAndTechniquesWithoutThemRefuseSpp) {
    const fs::path dir = gilab::test::temp_dir("cli_photon_spp");
    const std::string size = " -W 16 -H 16 --set photons=4096";
    const Result four = run("render cornell -t photon --spp 4" + size + " -o " + (dir / "four").string());
    ASSERT_EQ(four.exit_code, 0) << four.output;
    const Result one = run("render cornell -t photon --spp 1" + size + " -o " + (dir / "one").string());
    ASSERT_EQ(one.exit_code, 0) << one.output;
    gilab::Film film = gilab::read_exr(dir / "four.exr");
    EXPECT_EQ(film.metadata["spp"], "4");
    EXPECT_EQ(gilab::read_exr(dir / "one.exr").metadata["spp"], "1");
    EXPECT_NE(color_of(film), color_of(gilab::read_exr(dir / "one.exr")));

    // vct reads no 'spp': the error names the option, not an unknown --set key.
    const fs::path bad = gilab::test::temp_dir("cli_vct_spp");
    const std::string args = "render cornell -t vct --spp 4 -W 8 -H 8 --set levels=2 --set resolution=8 -o " +
                             (bad / "x").string();
    expect_failure(args, {"--spp", "'vct' takes no pixel samples"}, bad);
    EXPECT_FALSE(contains(run(args).output, "unknown setting")) << run(args).output;
}

TEST(Cli, CompareRefusesAnEmptyTechniqueNameAndABadEqualTimeOf) {
    const fs::path dir = gilab::test::temp_dir("cli_compare_empty_name");
    for (const char* list : {"path,,photon", ",path", "path,"})
        expect_failure(std::string("compare cornell -W 8 -H 8 --results ") + dir.string() + " -t " + list,
                       {"empty technique name"}, dir);
    expect_failure("compare cornell -W 8 -H 8 --equal-time 1 --equal-time-of frames --results " + dir.string(),
                   {"--equal-time-of", "'frames'"}, dir);
}
