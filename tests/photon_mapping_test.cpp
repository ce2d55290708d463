#include <gtest/gtest.h>

#include "core/image_metrics.hpp"
#include "core/parallel.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/technique.hpp"

namespace gilab {
namespace {

Film render(const std::string& technique, const Scene& scene, const EyeCamera& camera, nlohmann::json settings_json,
            Stats* stats = nullptr) {
    auto t = TechniqueRegistry::builtin().create(technique);
    Settings settings(std::move(settings_json), "test settings");
    t->prepare(scene, settings);
    settings.report_unused();
    std::vector<Film> films;
    t->render(ViewSet::mono(camera), films);
    if (stats) *stats = t->stats();
    return films.at(0);
}

EyeCamera cornell_camera(const Scene& scene, int size) {
    const SceneCamera& c = *scene.camera;
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
}

TEST(PhotonMapping, Explore) {
    Scene scene = make_cornell_box();
    EyeCamera cam = cornell_camera(scene, 64);
    Film pt = render("path", scene, cam, {{"spp", 1024}, {"seed", 3}, {"jitter", false}});
    double pt_ind = mean_value(pt, "indirect"), pt_dir = mean_value(pt, "direct");
    std::printf("path: direct %.5f indirect %.5f\n", pt_dir, pt_ind);
    for (int photons : {256 * 256})
        for (float r : {0.02f, 0.05f, 0.1f}) {
            Stats st;
            Film pm = render("photon", scene, cam, {{"photons", photons}, {"radius", r}, {"light_samples", 16}}, &st);
            std::printf("pm %d r=%.2f: direct %.5f (%.4f) indirect %.5f (%.4f) stored %.0f relmse_ind %.4f\n", photons, r,
                        mean_value(pm, "direct"), mean_value(pm, "direct") / pt_dir - 1, mean_value(pm, "indirect"),
                        mean_value(pm, "indirect") / pt_ind - 1, st.get("photons_stored"),
                        relative_mse(pm, pt, "indirect"));
        }
}

}  // namespace
}  // namespace gilab
