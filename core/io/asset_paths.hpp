#pragma once
// Where scene assets are looked up: --assets flag, then $GILAB_ASSETS (colon-separated),
// then ../shared/scenes next to the source tree.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace gilab {

class AssetPaths {
public:
    AssetPaths() = default;
    explicit AssetPaths(std::vector<std::filesystem::path> dirs) : dirs_(std::move(dirs)) {}
    // flag_value: the --assets option if given (may itself be colon-separated).
    static AssetPaths from_environment(const std::optional<std::string>& flag_value = {});

    // An absolute path or one relative to the working directory is used if it exists;
    // otherwise each search directory is tried in order. Throws Error listing the
    // directories searched when nothing is found (resolve), and Error(candidate, "is a
    // ..., not a regular file") when the first candidate there is a device, FIFO or
    // directory (both).
    std::filesystem::path resolve(const std::string& relative) const;
    std::optional<std::filesystem::path> find(const std::string& relative) const;
    const std::vector<std::filesystem::path>& dirs() const { return dirs_; }
    std::string describe() const;  // "dir1:dir2"

    // Throws Error(context, …) naming the first entry of a colon-separated directory list
    // that is not a directory (a typo in --assets is an error, not a silent fall-back to
    // other copies of the files).
    static void require_directories(const std::string& list, const std::string& context);
    // The entries of a colon-separated list that are not directories (empty ones skipped).
    static std::vector<std::string> missing_directories(const std::string& list);

private:
    std::vector<std::filesystem::path> dirs_;
};

}  // namespace gilab
