#pragma once
// Shared helpers for tests: where the shared assets are, temp directories.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace gilab::test {

// Path of an asset under the shared scenes directory, or nullopt if it is not there
// (tests then GTEST_SKIP with a message naming the missing file).
std::optional<std::filesystem::path> shared_asset(const std::string& relative);
// The gilab program of the build the tests belong to.
std::string gilab_program();
// Whether the code under test carries AddressSanitizer (the sanitizer pass of setup.sh),
// which reserves terabytes of address space: no address-space cap then.
bool code_under_test_is_sanitized();
// A fresh empty directory under the build tree for this test's outputs.
std::filesystem::path temp_dir(const std::string& name);

// Writes `text` to dir/name (creating subdirectories) and returns the path.
std::filesystem::path write_file(const std::filesystem::path& dir, const std::string& name, const std::string& text);

// The message of the gilab::Error that f throws, or "<no error>" if it throws none.
std::string error_of(const std::function<void()>& f);

}  // namespace gilab::test
