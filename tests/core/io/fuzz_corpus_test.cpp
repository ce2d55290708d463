// Replays the fuzzing inputs through the same targets the libFuzzer harnesses run
// (tests/fuzz/fuzz_targets.hpp): the hand-made seeds must load, and every input in the
// regression corpus (tests/fuzz/corpus/TARGET: what the fuzzers found, fixed since)
// must load or end in gilab::Error, never in another exception. In the sanitizer build
// this also replays them under AddressSanitizer and UBSan.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include "tests/fuzz/fuzz_targets.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;

namespace {

fs::path fuzz_dir() { return fs::path(GILAB_SOURCE_DIR) / "tests" / "fuzz"; }

std::string read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<fs::path> files_in(const fs::path& dir) {
    std::vector<fs::path> files;
    if (fs::is_directory(dir))
        for (const auto& entry : fs::directory_iterator(dir))
            if (entry.is_regular_file() && entry.path().filename() != "README.md") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

class FuzzCorpus : public ::testing::TestWithParam<std::string> {
protected:
    static void SetUpTestSuite() { fuzz::initialise(); }
};

TEST_P(FuzzCorpus, SeedsLoad) {
    const fuzz::Target& target = fuzz::target(GetParam());
    const auto seeds = files_in(fuzz_dir() / "seeds" / GetParam());
    ASSERT_FALSE(seeds.empty()) << "no seeds for " << GetParam();
    for (const auto& seed : seeds) {
        const std::string bytes = read_bytes(seed);
        std::string error;
        ASSERT_NO_THROW(error = fuzz::run_checked(target, reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()))
            << seed;
        EXPECT_EQ(error, "") << seed << ": a seed must be a valid input";
    }
}

TEST_P(FuzzCorpus, RegressionInputsEndInLoadOrError) {
    const fuzz::Target& target = fuzz::target(GetParam());
    for (const auto& input : files_in(fuzz_dir() / "corpus" / GetParam())) {
        const std::string bytes = read_bytes(input);
        EXPECT_NO_THROW(fuzz::run_checked(target, reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()))
            << input;
    }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzCorpus, ::testing::Values("obj", "gltf", "ply_off", "scene_json", "settings"),
                         [](const auto& info) { return info.param; });

// The harness's own contract: a non-gilab exception is reported as an internal error.
TEST(FuzzTargets, EveryTargetIsNamedAndUnknownNamesAreRefused) {
    EXPECT_EQ(fuzz::targets().size(), 5u);
    EXPECT_THROW(fuzz::target("nope"), std::invalid_argument);
}

}  // namespace
