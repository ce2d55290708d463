#include "tests/fuzz/fuzz_targets.hpp"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <typeinfo>
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/io/scene_file.hpp"
#include "core/util/settings.hpp"

namespace gilab::fuzz {

namespace fs = std::filesystem;

namespace {

// Small enough that a count lie is refused long before libFuzzer's RSS limit (2 GB).
constexpr uint64_t kMemoryLimit = uint64_t(256) << 20;

// An OBJ input may carry its material library after this line; it is written to
// in.mtl, which the seeds name with `mtllib in.mtl`.
constexpr std::string_view kMtlSeparator = "\n#%mtl\n";

void write_file(const fs::path& path, std::string_view bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) throw std::runtime_error("fuzz harness: cannot write " + path.string());
}

std::string_view as_text(const uint8_t* data, size_t size) {
    return {reinterpret_cast<const char*>(data), size};
}

void run_obj(const uint8_t* data, size_t size) {
    std::string_view text = as_text(data, size);
    size_t cut = text.find(kMtlSeparator);
    std::string_view obj = text.substr(0, cut);
    std::string_view mtl = cut == std::string_view::npos ? std::string_view() : text.substr(cut + kMtlSeparator.size());
    write_file(scratch_directory() / "in.mtl", mtl);
    write_file(scratch_directory() / "in.obj", obj);
    load_obj(scratch_directory() / "in.obj");
}

void run_gltf(const uint8_t* data, size_t size) {
    const bool binary = as_text(data, size).substr(0, 4) == "glTF";
    fs::path path = scratch_directory() / (binary ? "in.glb" : "in.gltf");
    write_file(path, as_text(data, size));
    load_gltf(path);
}

void run_ply_off(const uint8_t* data, size_t size) {
    const bool ply = as_text(data, size).substr(0, 3) == "ply";
    fs::path path = scratch_directory() / (ply ? "in.ply" : "in.off");
    write_file(path, as_text(data, size));
    load_ply_or_off(path);
}

// Scene files name meshes; the scratch folder holds a triangle in each mesh format
// (written by initialise) for the seeds to name.
void run_scene_json(const uint8_t* data, size_t size) {
    fs::path path = scratch_directory() / "in.json";
    write_file(path, as_text(data, size));
    load_scene_file(path, AssetPaths({scratch_directory()}));
}

// Reads every key as each type a technique reads settings as; a refusal is an Error.
void read_every_key(const Settings& settings) {
    auto attempt = [](auto&& read) {
        try {
            read();
        } catch (const Error&) {
        }
    };
    for (const auto& item : settings.json().items()) {
        const std::string key = item.key();
        attempt([&] { settings.get<int>(key, 0); });
        attempt([&] { settings.get<int64_t>(key, 0); });
        attempt([&] { settings.get<uint64_t>(key, 0); });
        attempt([&] { settings.get<float>(key, 0.0f); });
        attempt([&] { settings.get<double>(key, 0.0); });
        attempt([&] { settings.get<bool>(key, false); });
        attempt([&] { settings.get<std::string>(key, ""); });
    }
    settings.hash();
    settings.report_unused();
}

// A settings file (input starting with '{'), or lines of `--set` assignments
// (key=value) and `--memory-limit SIZE` options.
constexpr std::string_view kMemoryLimitOption = "--memory-limit ";

void run_settings(const uint8_t* data, size_t size) {
    std::string_view text = as_text(data, size);
    if (!text.empty() && text.front() == '{') {
        fs::path path = scratch_directory() / "settings.json";
        write_file(path, text);
        read_every_key(Settings::from_file(path.string()));
        return;
    }
    Settings settings(nlohmann::json::object(), "--set");
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string_view::npos) end = text.size();
        const std::string line(text.substr(start, end - start));
        if (line.rfind(kMemoryLimitOption, 0) == 0) {
            MemoryBudget::parse_size(line.substr(kMemoryLimitOption.size()), "--memory-limit");
        } else {
            settings.set_from_string(line);
        }
        start = end + 1;
    }
    read_every_key(settings);
}

}  // namespace

const std::vector<Target>& targets() {
    static const std::vector<Target> all = {
        {"obj", run_obj}, {"gltf", run_gltf}, {"ply_off", run_ply_off},
        {"scene_json", run_scene_json}, {"settings", run_settings},
    };
    return all;
}

const Target& target(const std::string& name) {
    for (const auto& t : targets())
        if (name == t.name) return t;
    throw std::invalid_argument("unknown fuzz target '" + name + "'");
}

const fs::path& scratch_directory() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("gilab-fuzz-" + std::to_string(getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

void initialise() {
    MemoryBudget::set_limit(kMemoryLimit);
    std::atexit([] {
        std::error_code ignored;
        fs::remove_all(scratch_directory(), ignored);
    });
    write_file(scratch_directory() / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write_file(scratch_directory() / "tri.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
}

std::string run_checked(const Target& target, const uint8_t* data, size_t size) {
    try {
        target.run(data, size);
    } catch (const Error& e) {
        return e.what();
    } catch (const std::exception& e) {
        throw std::runtime_error(std::string("internal error in target ") + target.name + ": " + typeid(e).name() +
                                 ": " + e.what());
    } catch (...) {
        throw std::runtime_error(std::string("internal error in target ") + target.name + ": a non-standard exception");
    }
    return "";
}

}  // namespace gilab::fuzz
