// Interrupted experiment batches: a run stopped by SIGINT, SIGTERM or SIGKILL midway
// leaves only complete results (results/NAME holds a finished run or nothing), says what
// it kept, and `--resume` skips exactly the finished experiments.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <fstream>
#include <iterator>
#include "tests/test_support.hpp"

namespace fs = std::filesystem;

namespace {

// Quick experiments that need no shared assets.
const std::vector<std::string> kBatch = {"vct-table1", "dag-fig15"};
const char* const kBatchAsset = "bunny/stanford-bunny.obj";  // vct-table1 voxelizes it

struct Child {
    pid_t pid = -1;
    int out = -1;  // stdout and stderr together
};

Child start_gilab(const std::vector<std::string>& args) {
    const std::string binary = gilab::test::gilab_program();
    int fds[2];
    if (pipe(fds) != 0) return {};
    const pid_t pid = fork();
    if (pid == 0) {
        dup2(fds[1], 1);
        dup2(fds[1], 2);
        close(fds[0]);
        close(fds[1]);
        std::vector<char*> argv{const_cast<char*>(binary.c_str())};
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(binary.c_str(), argv.data());
        _exit(127);
    }
    close(fds[1]);
    return {pid, fds[0]};
}

// Reads the child's output until it contains `marker` (or ends); returns what was read.
std::string read_until(const Child& child, const std::string& marker) {
    std::string text;
    std::array<char, 1024> buffer{};
    while (text.find(marker) == std::string::npos) {
        const ssize_t n = read(child.out, buffer.data(), buffer.size());
        if (n <= 0) break;
        text.append(buffer.data(), size_t(n));
    }
    return text;
}

// Reads the rest of the output and waits; returns (exit code or 128 + signal, output).
std::pair<int, std::string> finish(const Child& child, std::string text = "") {
    std::array<char, 1024> buffer{};
    for (ssize_t n; (n = read(child.out, buffer.data(), buffer.size())) > 0;) text.append(buffer.data(), size_t(n));
    close(child.out);
    int status = 0;
    waitpid(child.pid, &status, 0);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), text};
}

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every visible folder under results holds a finished run: results.json and table.md.
void expect_only_complete_results(const fs::path& results) {
    for (const auto& entry : fs::directory_iterator(results)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind(".", 0) == 0) continue;  // staging folders are hidden
        EXPECT_TRUE(fs::exists(entry.path() / "results.json")) << name << " is half-written";
        EXPECT_TRUE(fs::exists(entry.path() / "table.md")) << name << " is half-written";
    }
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class ExperimentResume : public ::testing::TestWithParam<int> {};

// Interrupts the batch as soon as the first experiment is written, then resumes it.
TEST_P(ExperimentResume, InterruptedBatchKeepsFinishedExperimentsAndResumes) {
    const int signal_number = GetParam();
    if (!gilab::test::shared_asset(kBatchAsset))
        GTEST_SKIP() << "shared asset " << kBatchAsset << " not found (vct-table1 needs it)";
    const fs::path results = gilab::test::temp_dir("experiment_resume_" + std::to_string(signal_number));
    const std::vector<std::string> args = with({"--threads", "2", "experiment"}, with(kBatch, {"--quick", "--results", results.string()}));

    Child child = start_gilab(args);
    ASSERT_GT(child.pid, 0);
    std::string text = read_until(child, "wrote " + (results / "vct-table1" / "table.md").string());
    ASSERT_TRUE(contains(text, "vct-table1/table.md")) << text;
    kill(child.pid, signal_number);
    const auto [code, output] = finish(child, text);
    EXPECT_EQ(code, 128 + signal_number) << output;

    // Which experiment was running when the signal came: the batch says so (normally
    // dag-fig15; a slow signal may land later). Everything before it is kept, nothing after.
    size_t running = kBatch.size();
    for (size_t i = 1; i < kBatch.size(); ++i)
        if (contains(output, "interrupted during " + kBatch[i])) running = i;
    if (signal_number == SIGKILL) {
        running = 1;
        while (running < kBatch.size() && fs::exists(results / kBatch[running] / "results.json")) ++running;
    } else {
        ASSERT_LT(running, kBatch.size()) << "no interruption message in: " << output;
        EXPECT_TRUE(contains(output, "Kept " + std::to_string(running) + " finished experiment")) << output;
        EXPECT_TRUE(contains(output, "--resume")) << output;
    }
    expect_only_complete_results(results);
    for (size_t i = 0; i < kBatch.size(); ++i)
        EXPECT_EQ(fs::exists(results / kBatch[i]), i < running) << kBatch[i];
    const std::string first_run = read_file(results / "vct-table1" / "results.json");

    const auto [resumed_code, resumed] = finish(start_gilab(with(args, {"--resume"})));
    ASSERT_EQ(resumed_code, 0) << resumed;
    for (size_t i = 0; i < kBatch.size(); ++i) {
        EXPECT_EQ(contains(resumed, "experiment " + kBatch[i] + ": kept"), i < running) << resumed;
        EXPECT_TRUE(fs::exists(results / kBatch[i] / "results.json")) << kBatch[i];
    }
    EXPECT_EQ(read_file(results / "vct-table1" / "results.json"), first_run) << "a kept experiment was rewritten";
    for (const auto& entry : fs::directory_iterator(results))
        EXPECT_NE(entry.path().filename().string().rfind(".", 0), 0u) << "staging folder left: " << entry.path();
    expect_only_complete_results(results);
}

INSTANTIATE_TEST_SUITE_P(Signals, ExperimentResume, ::testing::Values(SIGINT, SIGTERM, SIGKILL),
                         [](const auto& info) { return std::string(sigabbrev_np(info.param)); });

// A run killed while replacing an earlier run's results keeps the earlier results whole;
// --resume with another seed runs everything again.
TEST(ExperimentResume, KilledRerunKeepsThePreviousResultsAndResumeChecksTheSeed) {
    if (!gilab::test::shared_asset(kBatchAsset))
        GTEST_SKIP() << "shared asset " << kBatchAsset << " not found (vct-table1 needs it)";
    const fs::path results = gilab::test::temp_dir("experiment_rerun_killed");
    const std::vector<std::string> args = {"--threads", "2", "experiment", "vct-table1", "dag-fig15", "--quick",
                                           "--results", results.string()};
    ASSERT_EQ(finish(start_gilab(args)).first, 0);
    const std::string previous = read_file(results / "dag-fig15" / "results.json");

    Child child = start_gilab(args);
    std::string text = read_until(child, "experiment dag-fig15");
    kill(child.pid, SIGKILL);
    finish(child, text);
    EXPECT_EQ(read_file(results / "dag-fig15" / "results.json"), previous);
    expect_only_complete_results(results);

    const auto [code, output] = finish(start_gilab(with(args, {"--resume", "--seed", "7"})));
    EXPECT_EQ(code, 0) << output;
    EXPECT_TRUE(contains(output, "vct-table1: running again (finished with another seed)")) << output;
    EXPECT_NE(read_file(results / "dag-fig15" / "results.json"), previous);

    // A run along other axis values is another run: --resume keeps only its own.
    const std::vector<std::string> swept = {"--threads", "2", "experiment", "dag-fig15", "--quick", "--seed", "7",
                                            "--results", results.string(), "--resume"};
    const auto [kept_code, kept] = finish(start_gilab(swept));
    EXPECT_EQ(kept_code, 0) << kept;
    EXPECT_TRUE(contains(kept, "dag-fig15: kept")) << kept;
    const auto [axis_code, axis_output] = finish(start_gilab(with(swept, {"--axis", "resolution=32"})));
    EXPECT_EQ(axis_code, 0) << axis_output;
    EXPECT_TRUE(contains(axis_output, "dag-fig15: running again (finished with another spec")) << axis_output;
    // One resolution holds no doubling: the table says so instead of dividing by nothing.
    EXPECT_TRUE(contains(read_file(results / "dag-fig15" / "table.md"), "hold no such pair")) << axis_output;
}

}  // namespace
