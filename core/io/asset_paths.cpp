#include "core/io/asset_paths.hpp"

#include <cstdlib>
#include <filesystem>
#include "core/util/build_info.hpp"
#include "core/util/error.hpp"
#include "core/util/input_file.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

void append_colon_separated(const std::string& list, std::vector<fs::path>& out) {
    size_t start = 0;
    while (start <= list.size()) {
        size_t end = list.find(':', start);
        if (end == std::string::npos) end = list.size();
        if (end > start) out.emplace_back(list.substr(start, end - start));
        start = end + 1;
    }
}

}  // namespace

AssetPaths AssetPaths::from_environment(const std::optional<std::string>& flag_value) {
    std::vector<fs::path> dirs;
    if (flag_value) append_colon_separated(*flag_value, dirs);
    if (const char* env = std::getenv("GILAB_ASSETS")) append_colon_separated(env, dirs);
    dirs.push_back((fs::path(build_source_directory()) / "../shared/scenes").lexically_normal());
    return AssetPaths(std::move(dirs));
}

std::optional<fs::path> AssetPaths::find(const std::string& relative) const {
    if (relative.empty()) return std::nullopt;
    const fs::path p(relative);
    if (regular_file_exists(p)) return p;
    if (p.is_absolute()) return std::nullopt;
    for (const fs::path& dir : dirs_) {
        fs::path candidate = dir / p;
        if (regular_file_exists(candidate)) return candidate;
    }
    return std::nullopt;
}

fs::path AssetPaths::resolve(const std::string& relative) const {
    if (auto found = find(relative)) return *found;
    std::string searched = "the working directory";
    if (!fs::path(relative).is_absolute() && !dirs_.empty()) searched += ", " + describe();
    throw Error("asset '" + relative + "' not found (searched " + searched +
                "; add a directory with --assets or GILAB_ASSETS)");
}

std::string AssetPaths::describe() const {
    std::string s;
    for (const fs::path& dir : dirs_) {
        if (!s.empty()) s += ":";
        s += dir.string();
    }
    return s;
}

std::vector<std::string> AssetPaths::missing_directories(const std::string& list) {
    std::vector<std::string> missing;
    size_t start = 0;
    while (start <= list.size()) {
        size_t end = list.find(':', start);
        if (end == std::string::npos) end = list.size();
        if (end > start) {
            std::string dir = list.substr(start, end - start);
            std::error_code ec;
            if (!std::filesystem::is_directory(dir, ec)) missing.push_back(std::move(dir));
        }
        start = end + 1;
    }
    return missing;
}

void AssetPaths::require_directories(const std::string& list, const std::string& context) {
    const std::vector<std::string> missing = missing_directories(list);
    if (missing.empty()) return;
    std::error_code ec;
    throw Error(context, "'" + missing.front() + "' is not a directory" +
                             (std::filesystem::exists(missing.front(), ec) ? "" : " (it does not exist)"));
}

}  // namespace gilab
