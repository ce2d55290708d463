#pragma once
// What the technique tests share: a technique prepared with settings, one mono render,
// and a viewer inside the Cornell box (the viewer-centred grids of vct and lpv then hold
// the box in their finer levels).
#include <memory>
#include <vector>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include "core/image/film.hpp"
#include "core/scene/camera.hpp"
#include "core/scene/scene.hpp"
#include "core/util/settings.hpp"
#include "techniques/technique.hpp"

namespace gilab::test {

template <class T>
std::unique_ptr<T> prepared_technique(const Scene& scene, nlohmann::json settings_json) {
    auto t = std::make_unique<T>();
    prepare_technique(*t, scene, Settings(std::move(settings_json), "test settings"));
    return t;
}

inline Film render_one(Technique& t, const EyeCamera& camera) {
    std::vector<Film> films;
    t.render(ViewSet::mono(camera), films);
    EXPECT_EQ(films.size(), 1u);
    return films.at(0);
}

inline EyeCamera inside_camera(int size) {
    return EyeCamera::look_at(Vec3(0.5f, 0.45f, 0.06f), Vec3(0.5f, 0.42f, 1.0f), Vec3(0, 1, 0), 75.0f, size, size);
}

}  // namespace gilab::test
