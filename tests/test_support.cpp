#include "tests/test_support.hpp"
#include <cctype>
#include <fstream>
#include <gtest/gtest.h>
#include "core/io/asset_paths.hpp"
#include "core/util/error.hpp"

namespace gilab::test {

std::optional<std::filesystem::path> shared_asset(const std::string& relative) {
    return AssetPaths::from_environment().find(relative);
}

// The build folder and the sanitizer pass are compiled into this file only, so that every
// test's own code compiles to the same object in both builds (ccache, setup.sh).
std::string gilab_program() { return std::string(GILAB_TEST_BINARY_DIR) + "/gilab"; }

bool code_under_test_is_sanitized() {
#if defined(__SANITIZE_ADDRESS__) || defined(GILAB_SANITIZED_BUILD)
    return true;
#else
    return false;
#endif
}

std::filesystem::path temp_dir(const std::string& name) {
    // CTest runs every test case as a process of its own, two at once: cases that ask for
    // the same name (the variants of a parameterised test) get a folder each, or one would
    // remove the other's files while it reads them.
    std::string test_case;
    if (const auto* info = ::testing::UnitTest::GetInstance()->current_test_info()) {
        test_case = std::string(info->test_suite_name()) + "." + info->name();
        for (char& c : test_case)
            if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') c = '_';
    }
    auto dir = std::filesystem::path(GILAB_TEST_BINARY_DIR) / "test_output" / name / test_case;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

std::filesystem::path write_file(const std::filesystem::path& dir, const std::string& name, const std::string& text) {
    std::filesystem::path p = dir / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "<no error>";
}

}  // namespace gilab::test
