// produce_file_once: one computation however many ask at once, a dead holder taken over,
// a living one waited for, and a failed computation leaving nothing behind.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>
#include <gtest/gtest.h>
#include "core/util/produce_once.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::string contents(const fs::path& file) {
    std::ifstream in(file);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_text(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

std::string this_host() {
    char name[256] = {};
    gethostname(name, sizeof name - 1);
    return name;
}

// A process id that no process has: a child's, after it ended and was reaped.
pid_t ended_process() {
    const pid_t child = fork();
    if (child == 0) _exit(0);
    waitpid(child, nullptr, 0);
    return child;
}

size_t files_in(const fs::path& dir) { return size_t(std::distance(fs::directory_iterator(dir), {})); }

ProduceOnceOptions fast() {
    ProduceOnceOptions o;
    o.heartbeat = 50ms;
    o.stale_after = 1000ms;
    o.poll = 20ms;
    return o;
}

TEST(ProduceOnce, ManyProcessesAskingAtOnceComputeOnce) {
    const fs::path dir = test::temp_dir("produce_once_many");
    const fs::path target = dir / "reference.txt";
    const fs::path log = test::temp_dir("produce_once_many_log") / "computations";
    // Four processes, as tasks on several nodes would be; each computation adds a line.
    std::vector<pid_t> children;
    for (int i = 0; i < 4; ++i) {
        const pid_t child = fork();
        if (child == 0) {
            const bool mine = produce_file_once(target, [&](const fs::path& tmp) {
                std::ofstream(log, std::ios::app) << getpid() << "\n";
                std::this_thread::sleep_for(300ms);
                write_text(tmp, "image");
            }, fast());
            _exit(mine ? 10 : 0);
        }
        children.push_back(child);
    }
    int wrote = 0;
    for (pid_t child : children) {
        int status = 0;
        waitpid(child, &status, 0);
        ASSERT_TRUE(WIFEXITED(status));
        wrote += WEXITSTATUS(status) == 10;
    }
    EXPECT_EQ(wrote, 1);
    std::ifstream lines(log);
    EXPECT_EQ(std::count(std::istreambuf_iterator<char>(lines), {}, '\n'), 1);
    EXPECT_EQ(contents(target), "image");
    EXPECT_EQ(files_in(dir), 1u) << "the marker and the temporary are gone";
    // There already: nothing computed.
    bool computed = false;
    EXPECT_FALSE(produce_file_once(target, [&](const fs::path&) { computed = true; }, fast()));
    EXPECT_FALSE(computed);
}

TEST(ProduceOnce, HolderThatEndedOnThisHostIsTakenOverAtOnce) {
    const fs::path dir = test::temp_dir("produce_once_dead_here");
    const fs::path target = dir / "reference.txt";
    const pid_t dead = ended_process();
    write_text(dir / "reference.txt.computing", this_host() + " " + std::to_string(dead) + "\n");
    // What it was writing when it died goes too.
    const fs::path leftover = dir / (".reference.txt.tmp." + this_host() + "." + std::to_string(dead) + ".0");
    write_text(leftover, "half");
    ProduceOnceOptions o = fast();
    o.stale_after = 3600s;  // so only the process check can find it gone
    std::string said;
    o.say = [&said](const std::string& s) { said += s + "\n"; };
    EXPECT_TRUE(produce_file_once(target, [](const fs::path& tmp) { write_text(tmp, "mine"); }, o));
    EXPECT_EQ(contents(target), "mine");
    EXPECT_NE(said.find("is gone"), std::string::npos) << said;
    EXPECT_FALSE(fs::exists(dir / "reference.txt.computing"));
    EXPECT_FALSE(fs::exists(leftover));
}

TEST(ProduceOnce, MarkerFromAnotherHostNotRefreshedIsTakenOver) {
    const fs::path dir = test::temp_dir("produce_once_dead_elsewhere");
    const fs::path target = dir / "reference.txt";
    write_text(dir / "reference.txt.computing", "some-other-node 12345\n");
    EXPECT_TRUE(produce_file_once(target, [](const fs::path& tmp) { write_text(tmp, "mine"); }, fast()));
    EXPECT_EQ(contents(target), "mine");
}

TEST(ProduceOnce, LivingHolderIsWaitedForLongerThanTheStaleTime) {
    const fs::path dir = test::temp_dir("produce_once_alive");
    const fs::path target = dir / "reference.txt";
    std::atomic<int> computed{0};
    // The holder works 2.5 stale times; its heartbeat (every 50 ms) keeps the waiter from
    // taking over.
    std::thread holder([&] {
        produce_file_once(target, [&](const fs::path& tmp) {
            ++computed;
            std::this_thread::sleep_for(2500ms);
            write_text(tmp, "holder's");
        }, fast());
    });
    while (!fs::exists(dir / "reference.txt.computing") && !fs::exists(target)) std::this_thread::sleep_for(5ms);
    std::string said;
    ProduceOnceOptions o = fast();
    o.say = [&said](const std::string& s) { said += s + "\n"; };
    EXPECT_FALSE(produce_file_once(target, [&](const fs::path& tmp) {
        ++computed;
        write_text(tmp, "waiter's");
    }, o));
    holder.join();
    EXPECT_EQ(computed.load(), 1);
    EXPECT_EQ(contents(target), "holder's");
    EXPECT_NE(said.find("being computed by process"), std::string::npos) << said;
}

TEST(ProduceOnce, FailedComputationLeavesNothingAndIsTriedAgain) {
    const fs::path dir = test::temp_dir("produce_once_failed");
    const fs::path target = dir / "reference.txt";
    EXPECT_THROW(produce_file_once(target, [](const fs::path& tmp) {
        write_text(tmp, "half");
        throw std::runtime_error("renderer failed");
    }, fast()), std::runtime_error);
    EXPECT_EQ(files_in(dir), 0u) << "no target, temporary or marker";
    EXPECT_TRUE(produce_file_once(target, [](const fs::path& tmp) { write_text(tmp, "whole"); }, fast()));
    EXPECT_EQ(contents(target), "whole");
}

}  // namespace
}  // namespace gilab
