// What texturing costs each technique: one frame's render() (prepare excluded on both
// sides) of the same scene with its textures and with them stripped (factors kept, alpha
// masks off), 128² from the scene camera, all threads, same run. Scenes: the built-in
// textured Cornell box and the CesiumMan glTF (skipped, saying so, without the shared
// assets). Counters: the texture images' memory (MB = 10⁶ bytes, every mip level) and
// their count.
#include <benchmark/benchmark.h>

#include <map>
#include "core/io/asset_paths.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

using namespace gilab;

namespace {

Scene stripped(Scene scene) {
    for (Material& m : scene.materials) {
        m.albedo_texture = m.emission_texture = m.normal_texture = m.alpha_texture = TextureRef{};
        m.alpha_mode = AlphaMode::Opaque;
    }
    return scene;
}

const Scene* scene_named(const std::string& name) {
    static std::map<std::string, std::unique_ptr<Scene>> scenes;
    auto it = scenes.find(name);
    if (it != scenes.end()) return it->second.get();
    std::unique_ptr<Scene> s;
    try {
        s = std::make_unique<Scene>(name == "cornell_textured" ? make_textured_cornell_box()
                                                               : open_scene(name, AssetPaths::from_environment()).scene);
    } catch (const std::exception&) {
        s = nullptr;
    }
    return (scenes[name] = std::move(s)).get();
}

nlohmann::json settings_of(const std::string& technique) {
    if (technique == "path") return {{"spp", 4}};
    return nlohmann::json::object();
}

void BM_RenderFrame(benchmark::State& state, const std::string& scene_name, const std::string& technique, bool textured) {
    const Scene* source = scene_named(scene_name);
    if (!source) {
        state.SkipWithError(("scene " + scene_name + " not found (shared assets not installed?)").c_str());
        return;
    }
    const Scene scene = textured ? *source : stripped(*source);
    auto t = prepare_technique(technique, scene, Settings(settings_of(technique), "bench settings"));
    const SceneCamera c = scene.camera.value_or(default_camera_for(scene.evaluate(0).bounds));
    const EyeCamera camera = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, 128, 128);
    std::vector<Film> films;
    for (auto _ : state) {
        t->render(ViewSet::mono(camera), films);
        benchmark::DoNotOptimize(films.data());
    }
    const TextureUse use = scene.texture_use();
    state.counters["texture_MB"] = double(use.bytes) / 1e6;
    state.counters["textures"] = double(use.images);
    state.SetLabel(textured ? "textured" : "untextured");
}

void register_all() {
    for (const char* scene : {"cornell_textured", "cesium_man"})
        for (const char* technique : {"path", "photon", "vct", "lpv"})
            for (bool textured : {true, false})
                benchmark::RegisterBenchmark(
                    (std::string("BM_RenderFrame/") + scene + "/" + technique + "/" + (textured ? "textured" : "untextured")).c_str(),
                    [=](benchmark::State& s) { BM_RenderFrame(s, scene, technique, textured); })
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime();
}

const int registered = (register_all(), 0);

}  // namespace
