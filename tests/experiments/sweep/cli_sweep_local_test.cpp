// `gilab sweep --on local`: the tasks run as separate processes and merge into the same
// tables as `gilab experiment` (the columns that are not timings); a second run skips the
// tasks that have a result; a task that fails leaves no result, is reported missing by
// the merge and by `sweep status`, and `sweep resume` finishes the tables.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <iterator>
#include <fstream>
#include <nlohmann/json.hpp>
#include "tests/test_support.hpp"

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kExperiments = {"core-rays", "pm-radius-sweep"};
const std::vector<std::string> kAssets = {"bunny/stanford-bunny.obj", "sponza/sponza.obj", "conference/conference.obj"};

struct GilabRun {
    int exit_code = -1;
    std::string output;
};

std::string quoted(const std::string& text) { return "'" + text + "'"; }

// Runs gilab with `args` (one shell word each) and `environment` (NAME=VALUE words or "").
GilabRun run_gilab(const std::vector<std::string>& args, const std::string& environment = "") {
    std::string command = environment + " " + quoted(gilab::test::gilab_program());
    for (const std::string& a : args) {
        command += ' ';
        command += quoted(a);
    }
    command += " 2>&1";
    GilabRun run;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return run;
    char buffer[4096];
    for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) run.output.append(buffer, n);
    const int status = pclose(pipe);
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

std::vector<std::string> sweep_args(const fs::path& results, std::vector<std::string> more = {}) {
    std::vector<std::string> args = {"sweep"};
    args.insert(args.end(), kExperiments.begin(), kExperiments.end());
    args.insert(args.end(), {"--quick", "--results", results.string(), "--jobs", "2"});
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

nlohmann::json read_json(const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

// Timings differ from run to run; every other column must not.
bool is_timing(const std::string& column) {
    for (const char* part : {"_ms", "per_s", "_over_", "seconds"})
        if (column.find(part) != std::string::npos) return true;
    return false;
}

nlohmann::json tables_without_timings(const fs::path& experiment_dir) {
    nlohmann::json tables = read_json(experiment_dir / "results.json").at("tables");
    for (nlohmann::json& table : tables)
        for (nlohmann::json& row : table.at("rows"))
            for (auto it = row.begin(); it != row.end();)
                it = is_timing(it.key()) ? row.erase(it) : std::next(it);
    return tables;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class SweepLocal : public ::testing::Test {
protected:
    void SetUp() override {
        for (const std::string& asset : kAssets)
            if (!gilab::test::shared_asset(asset)) GTEST_SKIP() << "shared asset " << asset << " not found";
    }
};

}  // namespace

TEST_F(SweepLocal, GivesTheTablesOfGilabExperimentAndSkipsDoneTasksWhenRunAgain) {
    const fs::path reference = gilab::test::temp_dir("sweep_local_reference");
    const fs::path results = gilab::test::temp_dir("sweep_local");
    std::vector<std::string> experiment = {"experiment"};
    experiment.insert(experiment.end(), kExperiments.begin(), kExperiments.end());
    experiment.insert(experiment.end(), {"--quick", "--results", reference.string()});
    const GilabRun whole = run_gilab(experiment);
    ASSERT_EQ(whole.exit_code, 0) << whole.output;

    const GilabRun swept = run_gilab(sweep_args(results));
    ASSERT_EQ(swept.exit_code, 0) << swept.output;
    EXPECT_TRUE(contains(swept.output, "[7/7] ")) << swept.output;
    // pm-radius-sweep's four tasks share one reference, rendered once before them into
    // the store; each task then reads it from there.
    EXPECT_TRUE(contains(swept.output, "references first: 1 reference group(s)")) << swept.output;
    size_t stored = 0;
    for (const auto& entry : fs::directory_iterator(results / ".references"))
        stored += entry.path().extension() == ".exr";
    EXPECT_EQ(stored, 1u);
    // What rendering them and each task cost is kept for `sweep status`.
    const nlohmann::json cost = read_json(results / "pm-radius-sweep" / "tasks" / "quick" / "references" / "0.json");
    EXPECT_EQ(cost["references"], 1) << cost;
    EXPECT_GT(cost["cpu_seconds"].get<double>(), 0.0) << cost;
    EXPECT_GT(read_json(results / "pm-radius-sweep" / "tasks" / "quick" / "1.json")["cpu_seconds"].get<double>(), 0.0);
    for (int id = 0; id < 4; ++id) {
        std::ifstream log(results / ".sweep" / "logs" / ("pm-radius-sweep." + std::to_string(id) + ".log"));
        const std::string text{std::istreambuf_iterator<char>(log), std::istreambuf_iterator<char>()};
        EXPECT_TRUE(contains(text, "reference from the store")) << text;
        EXPECT_FALSE(contains(text, "rendering the path-traced reference")) << text;
    }
    for (const std::string& name : kExperiments) {
        EXPECT_EQ(tables_without_timings(results / name), tables_without_timings(reference / name)) << name;
        EXPECT_TRUE(read_json(results / name / "results.json")["config"]["effective"]["tasks_missing"].empty()) << name;
    }
    EXPECT_TRUE(fs::exists(results / "report.html"));

    const auto written = fs::last_write_time(results / "core-rays" / "tasks" / "quick" / "0.json");
    const GilabRun again = run_gilab(sweep_args(results));
    ASSERT_EQ(again.exit_code, 0) << again.output;
    EXPECT_TRUE(contains(again.output, "7 have a result already, 0 to run")) << again.output;
    EXPECT_FALSE(contains(again.output, "[1/")) << again.output;
    EXPECT_EQ(fs::last_write_time(results / "core-rays" / "tasks" / "quick" / "0.json"), written);
    for (const auto& entry : fs::directory_iterator(results))
        EXPECT_FALSE(entry.path().filename().string().ends_with(".partial")) << "staging folder left: " << entry.path();
}

TEST_F(SweepLocal, AFailedTaskIsMissingFromTheMergeUntilResumed) {
    const fs::path results = gilab::test::temp_dir("sweep_local_failure");
    const GilabRun failed = run_gilab(sweep_args(results), "GILAB_FAIL_TASK=pm-radius-sweep/2");
    EXPECT_EQ(failed.exit_code, 1) << failed.output;
    EXPECT_TRUE(contains(failed.output, "pm-radius-sweep task 2 FAILED")) << failed.output;
    EXPECT_TRUE(contains(failed.output, "1 task(s) failed: pm-radius-sweep task 2")) << failed.output;
    EXPECT_FALSE(fs::exists(results / "pm-radius-sweep" / "tasks" / "quick" / "2.json"));
    const nlohmann::json merged = read_json(results / "pm-radius-sweep" / "results.json");
    EXPECT_EQ(merged["config"]["effective"]["tasks_missing"], nlohmann::json::array({2}));
    EXPECT_EQ(merged["tables"][0]["rows"].size(), 3u);  // no made-up row for the missing task
    std::ifstream log(results / ".sweep" / "logs" / "pm-radius-sweep.2.log");
    const std::string log_text{std::istreambuf_iterator<char>(log), std::istreambuf_iterator<char>()};
    EXPECT_TRUE(contains(log_text, "failed on purpose")) << log_text;

    const GilabRun status = run_gilab({"sweep", "status", (results / ".sweep").string()});
    EXPECT_EQ(status.exit_code, 0) << status.output;
    EXPECT_TRUE(contains(status.output, "pm-radius-sweep: 3 done, 1 without result (2)")) << status.output;

    // The resume finds the task's references in the store: the record of what rendering
    // them cost stays the first run's.
    const fs::path reference_cost = results / "pm-radius-sweep" / "tasks" / "quick" / "references" / "0.json";
    const nlohmann::json first_cost = read_json(reference_cost);
    // The global --threads gives the resumed tasks their threads, as when a sweep starts.
    const GilabRun resumed = run_gilab({"--threads", "3", "sweep", "resume", (results / ".sweep").string()});
    ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
    EXPECT_TRUE(contains(resumed.output, "6 have a result already, 1 to run")) << resumed.output;
    EXPECT_TRUE(contains(resumed.output, "with 3 thread(s) each")) << resumed.output;
    EXPECT_EQ(read_json(reference_cost), first_cost);
    EXPECT_TRUE(read_json(results / "pm-radius-sweep" / "results.json")["config"]["effective"]["tasks_missing"].empty());
    const std::string done = run_gilab({"sweep", "status", (results / ".sweep").string()}).output;
    EXPECT_TRUE(contains(done, "total: 7 done, 0 running")) << done;
    EXPECT_TRUE(contains(done, "task time of the 7 results (CPU time of one-thread tasks, else wall time): ")) << done;
    EXPECT_TRUE(contains(done, "1 reference group(s) rendered: ")) << done;
    EXPECT_TRUE(contains(done, "16 machines ")) << done;
}

// --axis: the experiment swept along other values; the tables say so. A result written
// for another plan (another seed) is not taken for this one's.
TEST_F(SweepLocal, ExtraAxesAndOtherPlansResults) {
    const fs::path results = gilab::test::temp_dir("sweep_local_axes");
    const std::vector<std::string> args = {"sweep", "pm-radius-sweep", "--quick", "--axis", "radius=0.05,0.2",
                                           "--axis", "photons=1024", "--results", results.string()};
    const GilabRun swept = run_gilab(args);
    ASSERT_EQ(swept.exit_code, 0) << swept.output;
    EXPECT_TRUE(contains(swept.output, "2 tasks of 1 experiment(s)")) << swept.output;
    const nlohmann::json merged = read_json(results / "pm-radius-sweep" / "results.json");
    const nlohmann::json& rows = merged["tables"][0]["rows"];
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0]["radius (scene units)"], 0.05);
    EXPECT_EQ(rows[1]["radius (scene units)"], 0.2);
    EXPECT_EQ(rows[0]["photons (emitted per frame)"], 1024);
    std::ifstream table(results / "pm-radius-sweep" / "table.md");
    const std::string text{std::istreambuf_iterator<char>(table), std::istreambuf_iterator<char>()};
    EXPECT_TRUE(contains(text, "--quick --axis photons=1024 --axis radius=0.05,0.2`")) << text;

    std::vector<std::string> other_seed = args;
    other_seed.insert(other_seed.end(), {"--seed", "2"});
    const GilabRun again = run_gilab(other_seed);
    ASSERT_EQ(again.exit_code, 0) << again.output;
    EXPECT_TRUE(contains(again.output, "0 have a result already, 2 to run")) << again.output;
    EXPECT_EQ(read_json(results / "pm-radius-sweep" / "results.json")["config"]["effective"]["tasks_missing"].size(), 0u);

    const GilabRun object_axis = run_gilab({"sweep", "pm-table1", "--quick", "--axis", "radius=0.05", "--results",
                                            results.string()});
    EXPECT_NE(object_axis.exit_code, 0);
    EXPECT_TRUE(contains(object_axis.output, "cannot be swept on its own")) << object_axis.output;
}

TEST(SweepLocalBadInput, ErrorsNameTheProblemAndExitNonZero) {
    const fs::path results = gilab::test::temp_dir("sweep_bad_input");
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"sweep", "no-such-experiment"}, "unknown experiment"},
        {{"sweep", "core-rays", "--batch", "3"}, "go with --on slurm only"},
        {{"sweep", "core-rays", "--on", "slurm", "--jobs", "2", "--dry-run"}, "--jobs"},
        {{"sweep", "core-rays", "--on", "slurm", "--time", "soon", "--dry-run"}, "is not a Slurm time"},
        {{"sweep", "core-rays", "--on", "cloud"}, "cloud"},
        {{"sweep", "status", results.string()}, "no sweep here"},
        {{"sweep", "status"}, "needs one folder"},
        {{"sweep", "resume", results.string(), "--quick"}, "takes the sweep's own options"},
        {{"sweep", "merge", results.string(), "--on", "slurm"}, "takes the sweep's own options"},
        {{"sweep", "core-rays", "--axis", "threads"}, "give SETTING=V1,V2"},
        {{"sweep", "pm-radius-sweep", "--axis", "no_such_setting=1"}, "is not a setting of technique"},
        {{"sweep", "status", results.string(), "--axis", "radius=1"}, "takes the sweep's own options"},
    };
    for (const auto& [args, message] : cases) {
        std::vector<std::string> with_results = args;
        if (args[1] != "status" && args[1] != "resume" && args[1] != "merge")
            with_results.insert(with_results.end(), {"--results", results.string()});
        const GilabRun run = run_gilab(with_results);
        EXPECT_NE(run.exit_code, 0) << run.output;
        EXPECT_TRUE(contains(run.output, message)) << "expected '" << message << "' in: " << run.output;
    }
}
