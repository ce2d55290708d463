#include "tests/test_support.hpp"
#include <fstream>
#include "core/io/asset_paths.hpp"
#include "core/util/error.hpp"

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
