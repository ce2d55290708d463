#include "tests/test_support.hpp"
#include "core/asset_paths.hpp"

namespace gilab::test {

std::optional<std::filesystem::path> shared_asset(const std::string& relative) {
    return AssetPaths::from_environment().find(relative);
}

std::filesystem::path temp_dir(const std::string& name) {
    auto dir = std::filesystem::path(GILAB_TEST_BINARY_DIR) / "test_output" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace gilab::test
