// `gilab sweep --on slurm --dry-run`: the task list, the job-array script and the merge
// script say what Slurm must run, batches keep the array small, bad options are refused,
// and a missing sbatch is said plainly. Nothing here needs Slurm (sweep_slurm.sh does).
#include <gtest/gtest.h>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include "experiments/sweep/sweep_slurm.hpp"
#include "experiments/sweep/task_costs.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;

namespace {

Sweep two_experiment_sweep(const std::string& name) {
    Sweep s;
    s.experiments = sweep_experiment_names({"core-rays", "pm-radius-sweep"});
    s.quick = true;
    s.seed = 7;
    s.results_root = test::temp_dir(name);
    s.gilab = "/opt/gilab/bin/gilab";
    s.on = "slurm";
    return s;
}

std::string read_text(const fs::path& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::stringstream s(text);
    for (std::string line; std::getline(s, line);) lines.push_back(line);
    return lines;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(SweepSlurmFiles, DryRunWritesOneTaskLinePerTaskAndOneArrayIndexPerTask) {
    Sweep sweep = two_experiment_sweep("sweep_dry_run");
    const std::vector<SweepTask> tasks = sweep_tasks(sweep);
    ASSERT_EQ(tasks.size(), 7u);  // core-rays 3 + pm-radius-sweep 4 at quick size
    SlurmSweepOptions options;
    options.dry_run = true;
    options.partition = "short";
    options.time = "00:05:00";
    options.mem = "4G";
    options.throttle = 2;
    options.sbatch_args = {"--account=rendering"};
    std::ostringstream out;
    submit_sweep_round(sweep, tasks, options, out);

    const fs::path dir = sweep.directory();
    const std::vector<std::string> lines = lines_of(read_text(dir / "tasks.1.txt"));
    ASSERT_EQ(lines.size(), 7u);
    const std::string results = sweep.results_root.string();
    EXPECT_EQ(lines[0], "core-rays 0 --quick --seed 7 --results " + results);
    EXPECT_EQ(lines[3], "pm-radius-sweep 0 --quick --seed 7 --results " + results);
    EXPECT_EQ(lines[6], "pm-radius-sweep 3 --quick --seed 7 --results " + results);

    const std::string array = read_text(dir / "array.1.sbatch");
    EXPECT_TRUE(contains(array, "#SBATCH --array=0-6%2\n")) << array;
    EXPECT_TRUE(contains(array, "#SBATCH --partition=short\n")) << array;
    EXPECT_TRUE(contains(array, "#SBATCH --time=5\n")) << array;
    EXPECT_TRUE(contains(array, "#SBATCH --mem=4G\n")) << array;
    EXPECT_TRUE(contains(array, "#SBATCH --account=rendering\n")) << array;
    EXPECT_TRUE(contains(array, "#SBATCH --output=" + (dir / "logs").string() + "/array.1_%a.out\n")) << array;
    EXPECT_TRUE(contains(array, "'/opt/gilab/bin/gilab' --threads 1 experiment run-task \"${task[@]}\"")) << array;
    EXPECT_TRUE(contains(array, "tasks='" + (dir / "tasks.1.txt").string() + "'")) << array;
    EXPECT_TRUE(contains(array, "first=$(( SLURM_ARRAY_TASK_ID * 1 + 1 ))")) << array;

    // pm-radius-sweep's four tasks share one reference (scene, size, samples): one line,
    // rendered by an array of its own before the tasks'; core-rays needs none.
    const std::vector<std::string> references = lines_of(read_text(dir / "references.1.txt"));
    ASSERT_EQ(references.size(), 1u);
    EXPECT_EQ(references[0], "pm-radius-sweep 0 --quick --seed 7 --results " + results);
    const std::string reference_array = read_text(dir / "references.1.sbatch");
    EXPECT_TRUE(contains(reference_array, "#SBATCH --array=0-0%2\n")) << reference_array;
    EXPECT_TRUE(contains(reference_array, "#SBATCH --job-name=gilab-sweep-references\n")) << reference_array;
    EXPECT_TRUE(contains(reference_array, "experiment references \"${task[@]}\"")) << reference_array;
    EXPECT_TRUE(contains(reference_array, "tasks='" + (dir / "references.1.txt").string() + "'")) << reference_array;
    EXPECT_TRUE(contains(out.str(), "--dependency=afterany:REFJOB " + (dir / "array.1.sbatch").string())) << out.str();

    const std::string merge = read_text(dir / "merge.1.sbatch");
    EXPECT_TRUE(contains(merge, "'/opt/gilab/bin/gilab' sweep merge '" + dir.string() + "'")) << merge;
    EXPECT_TRUE(contains(merge, "#SBATCH --partition=short\n")) << merge;
    EXPECT_FALSE(contains(merge, "--array")) << merge;

    // The record lets status and resume find the round; a dry run has no job ids.
    const Sweep loaded = load_sweep(dir);
    EXPECT_EQ(loaded.experiments, sweep.experiments);
    EXPECT_EQ(loaded.seed, 7u);
    ASSERT_EQ(loaded.submissions.size(), 1u);
    EXPECT_EQ(loaded.submissions[0].value("array_job", std::string("?")), "");
    EXPECT_EQ(loaded.submissions[0].value("tasks", 0), 7);
    EXPECT_TRUE(contains(out.str(), "nothing submitted")) << out.str();
}

TEST(SweepSlurmFiles, BatchesPutSeveralTasksInOneIndexAndScaleTheTimeLimit) {
    Sweep sweep = two_experiment_sweep("sweep_batches");
    SlurmSweepOptions options;
    options.dry_run = true;
    options.batch = 3;
    options.time = "10";
    options.cpus_per_task = 4;
    std::ostringstream out;
    submit_sweep_round(sweep, sweep_tasks(sweep), options, out);
    const std::string array = read_text(sweep.directory() / "array.1.sbatch");
    EXPECT_TRUE(contains(array, "#SBATCH --array=0-2\n")) << array;  // 7 tasks in indices of 3
    EXPECT_TRUE(contains(array, "#SBATCH --time=30\n")) << array;
    EXPECT_TRUE(contains(array, "#SBATCH --cpus-per-task=4\n")) << array;
    EXPECT_TRUE(contains(array, "--threads 4 experiment run-task")) << array;
    EXPECT_TRUE(contains(array, "first=$(( SLURM_ARRAY_TASK_ID * 3 + 1 ))\nlast=$(( first + 2 ))")) << array;
    // Reference groups are not batched: one long render per index, its own time limit.
    const std::string references = read_text(sweep.directory() / "references.1.sbatch");
    EXPECT_TRUE(contains(references, "#SBATCH --array=0-0\n")) << references;
    EXPECT_TRUE(contains(references, "#SBATCH --time=10\n")) << references;
    EXPECT_TRUE(contains(references, "first=$(( SLURM_ARRAY_TASK_ID * 1 + 1 ))\nlast=$(( first + 0 ))")) << references;

    // 10 000 tasks in batches of 100: one array of 100 indices.
    std::vector<SweepTask> many(10000, SweepTask{"core-rays", 0});
    EXPECT_TRUE(contains(array_script(sweep, SlurmSweepOptions{.batch = 100}, many.size(), 2), "--array=0-99\n"));
}

TEST(SweepSlurmFiles, ASecondRoundHoldsOnlyTheTasksGivenIt) {
    Sweep sweep = two_experiment_sweep("sweep_rounds");
    SlurmSweepOptions options;
    options.dry_run = true;
    std::ostringstream out;
    submit_sweep_round(sweep, sweep_tasks(sweep), options, out);
    submit_sweep_round(sweep, {SweepTask{"pm-radius-sweep", 2}}, options, out);
    EXPECT_EQ(lines_of(read_text(sweep.directory() / "tasks.2.txt")),
              std::vector<std::string>{"pm-radius-sweep 2 --quick --seed 7 --results " + sweep.results_root.string()});
    EXPECT_TRUE(contains(read_text(sweep.directory() / "array.2.sbatch"), "--array=0-0\n"));
    // The task stands for its reference group in this round.
    EXPECT_EQ(lines_of(read_text(sweep.directory() / "references.2.txt")),
              std::vector<std::string>{"pm-radius-sweep 2 --quick --seed 7 --results " + sweep.results_root.string()});
    EXPECT_EQ(load_sweep(sweep.directory()).submissions.size(), 2u);
    EXPECT_TRUE(fs::exists(sweep.directory() / "tasks.1.txt"));
    // A round of tasks that need no reference has no references array.
    submit_sweep_round(sweep, {SweepTask{"core-rays", 1}}, options, out);
    EXPECT_FALSE(fs::exists(sweep.directory() / "references.3.txt"));
    EXPECT_FALSE(fs::exists(sweep.directory() / "references.3.sbatch"));
    EXPECT_EQ(load_sweep(sweep.directory()).submissions[2]["reference_groups"], 0);
}

TEST(SweepSlurmFiles, SlurmTimesAreReadInEveryFormatSbatchTakes) {
    EXPECT_EQ(slurm_time_minutes("30"), 30);
    EXPECT_EQ(slurm_time_minutes("10:30"), 11);  // MM:SS, rounded up
    EXPECT_EQ(slurm_time_minutes("02:00:00"), 120);
    EXPECT_EQ(slurm_time_minutes("1-0"), 1440);
    EXPECT_EQ(slurm_time_minutes("1-02:30"), 1590);
    EXPECT_EQ(slurm_time_minutes("0-00:00:30"), 1);
    for (const char* bad : {"", "abc", "1:2:3:4", "-5", "1-", "10:", "0"})
        EXPECT_NE(test::error_of([&] { slurm_time_minutes(bad); }), "<no error>") << bad;
}

TEST(SweepSlurmFiles, BadOptionsAreRefusedNamingTheOption) {
    EXPECT_TRUE(contains(test::error_of([] { SlurmSweepOptions{.batch = 0}.check(); }), "--batch"));
    EXPECT_TRUE(contains(test::error_of([] { SlurmSweepOptions{.cpus_per_task = 0}.check(); }), "--cpus-per-task"));
    EXPECT_TRUE(contains(test::error_of([] { SlurmSweepOptions{.throttle = -1}.check(); }), "--throttle"));
    EXPECT_TRUE(contains(test::error_of([] { SlurmSweepOptions{.time = "soon"}.check(); }), "--time"));
    EXPECT_TRUE(contains(test::error_of([] { SlurmSweepOptions{.partition = "a b"}.check(); }), "--partition"));
    EXPECT_TRUE(contains(test::error_of([] { SlurmSweepOptions{.sbatch_args = {"account"}}.check(); }), "--sbatch-arg"));
    EXPECT_TRUE(contains(test::error_of([] { sweep_experiment_names({"no-such-experiment"}); }), "unknown experiment"));
    EXPECT_TRUE(contains(test::error_of([] { sweep_experiment_names({}); }), "experiment names"));
    EXPECT_EQ(sweep_experiment_names({"core-rays", "core-rays"}), std::vector<std::string>{"core-rays"});
}

TEST(SweepSlurmFiles, WithoutSbatchTheErrorSaysHowToGetItOrRunLocally) {
    Sweep sweep = two_experiment_sweep("sweep_no_sbatch");
    const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
    setenv("PATH", sweep.results_root.c_str(), 1);  // a folder without sbatch
    const std::string error = test::error_of([&] { std::ostringstream out; submit_sweep_round(sweep, sweep_tasks(sweep), {}, out); });
    setenv("PATH", path.c_str(), 1);
    EXPECT_TRUE(contains(error, "sbatch")) << error;
    EXPECT_TRUE(contains(error, "apt-get install slurm-wlm")) << error;
    EXPECT_TRUE(contains(error, "--on local")) << error;
    EXPECT_FALSE(fs::exists(sweep.directory() / "sweep.json")) << "a sweep that was not submitted was recorded";
}

TEST(SweepSlurmFiles, ExtraAxesGoToEveryTaskLine) {
    Sweep sweep = two_experiment_sweep("sweep_axes");
    sweep.experiments = {"pm-radius-sweep"};
    sweep.axes = {"radius=0.05,0.2"};
    const std::vector<SweepTask> tasks = sweep_tasks(sweep);
    ASSERT_EQ(tasks.size(), 4u);  // 2 photon counts × the 2 radii given
    SlurmSweepOptions options;
    options.dry_run = true;
    std::ostringstream out;
    submit_sweep_round(sweep, tasks, options, out);
    for (const std::string& line : lines_of(read_text(sweep.directory() / "tasks.1.txt")))
        EXPECT_TRUE(contains(line, " --quick --axis radius=0.05,0.2 --seed 7 ")) << line;
    EXPECT_EQ(load_sweep(sweep.directory()).axes, sweep.axes);
}

// Without --time: 3 × the longest task measured for the experiments (at least 10 min),
// or none (the cluster's default) for experiments never measured or with extra axes.
TEST(SweepSlurmFiles, DefaultTimeLimitFromTheMeasuredTaskTimes) {
    Sweep sweep = two_experiment_sweep("sweep_default_time");
    const std::vector<SweepTask> tasks = sweep_tasks(sweep);
    std::string why;
    ASSERT_TRUE(longest_task_seconds("pm-radius-sweep", true).has_value());
    const double longest = std::max(*longest_task_seconds("core-rays", true), *longest_task_seconds("pm-radius-sweep", true));
    const long expected = std::max(10L, long(std::ceil(3 * longest / 60)));
    EXPECT_EQ(default_time_limit(sweep, tasks, why), std::to_string(expected));
    EXPECT_TRUE(contains(why, "3 × the longest task measured")) << why;
    SlurmSweepOptions options;
    options.dry_run = true;
    std::ostringstream out;
    submit_sweep_round(sweep, tasks, options, out);
    EXPECT_TRUE(contains(read_text(sweep.directory() / "array.1.sbatch"), "#SBATCH --time=" + std::to_string(expected) + "\n"));
    EXPECT_EQ(load_sweep(sweep.directory()).slurm.value("time", "?"), "") << "resumed rounds take the default anew";

    sweep.axes = {"radius=0.05"};
    sweep.experiments = {"pm-radius-sweep"};
    EXPECT_EQ(default_time_limit(sweep, sweep_tasks(sweep), why), "");
    EXPECT_TRUE(contains(why, "extra axes")) << why;
    sweep.axes.clear();
    EXPECT_EQ(default_time_limit(sweep, {SweepTask{"no-such-measurement", 0}}, why), "");
    EXPECT_TRUE(contains(why, "no measured task time for no-such-measurement")) << why;
}
