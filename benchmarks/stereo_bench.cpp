// Both eyes of the Cornell box with the photon technique (Vive frusta and head pose,
// 540×600 per eye, 256² photons, r = 0.1): eyes rendered separately, with stereo reuse
// (nearest claim, strict, crack fill), foveated, and foveated with reuse. Each variant is
// prepared once; an iteration is one stereo render(). Counters: the share of right-eye
// pixels reused and the right eye's cost over the left's.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include "core/scene/hmd.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"

using namespace gilab;

namespace {

const char* const kVariants[] = {"separate", "reuse", "reuse_strict", "reuse_fill", "foveated", "foveated_reuse"};

nlohmann::json settings_of(const std::string& variant) {
    nlohmann::json s = {{"photons", 256 * 256}, {"radius", 0.1}, {"seed", 1}};
    if (variant.rfind("reuse", 0) == 0 || variant == "foveated_reuse") s["stereo_reuse"] = true;
    if (variant == "reuse_strict") s["stereo_match"] = "strict";
    if (variant == "reuse_fill") s["stereo_fill"] = true;
    if (variant.rfind("foveated", 0) == 0) s["foveated"] = true;
    return s;
}

struct Fixture {
    Scene scene = make_cornell_box();
    ViewSet views;
    std::map<std::string, std::unique_ptr<PhotonMappingTechnique>> techniques;
    Fixture() {
        HmdRig rig(find_hmd_preset("vive"), scene.hmd->pose);
        rig.set_resolution(540, 600);
        views = ViewSet::stereo_pair(rig.eye(Eye::Left), rig.eye(Eye::Right));
    }
    PhotonMappingTechnique& technique(const std::string& variant) {
        auto& slot = techniques[variant];
        if (!slot) {
            slot = std::make_unique<PhotonMappingTechnique>();
            prepare_technique(*slot, scene, Settings(settings_of(variant), "stereo benchmark"));
        }
        return *slot;
    }
};

Fixture& fixture() {
    static Fixture f;
    return f;
}

void BM_StereoFrame(benchmark::State& state) {
    const std::string variant = kVariants[state.range(0)];
    state.SetLabel(variant);
    PhotonMappingTechnique& t = fixture().technique(variant);
    std::vector<Film> films;
    for (auto _ : state) {
        t.render(fixture().views, films);
        benchmark::DoNotOptimize(films.data());
    }
    const Stats stats = t.stats();
    state.counters["reuse_fraction"] = stats.get("reuse_fraction");
    state.counters["right_over_left"] = stats.get("right_ms") / stats.get("left_ms");
}

}  // namespace

BENCHMARK(BM_StereoFrame)->DenseRange(0, 5)->Unit(benchmark::kMillisecond)->UseRealTime();
