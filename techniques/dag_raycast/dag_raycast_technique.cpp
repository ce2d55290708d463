#include "techniques/dag_raycast/dag_raycast_technique.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include "accel/dag/dag_ray_caster.hpp"
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/util/parallel.hpp"
#include "core/render/traced_scene.hpp"
#include "techniques/dag_raycast/voxel_face.hpp"
#include "techniques/film_provenance.hpp"

namespace gilab {
namespace {

constexpr const char* kName = "dag_raycast";
constexpr float kAlbedo = 0.8f;  // voxels carry no material: one grey for all

// Where the light comes from at p and how much arrives on a surface facing it.
struct LightArrival {
    Vec3 wi{0};
    Vec3 irradiance{0};
    float distance = kInfinity;
    bool needs_shadow_ray = true;
};

LightArrival sample_light(const PunctualLight* light, const Vec3& p, const Vec3& eye) {
    LightArrival s;
    if (!light) {
        // The headlight sits at the eye, which sees p: nothing can shadow it.
        const Vec3 d = eye - p;
        const float len = glm::length(d);
        if (len > 0) s.wi = d / len;
        s.irradiance = Vec3(1);
        s.needs_shadow_ray = false;
        return s;
    }
    if (light->type == LightType::Directional) {
        s.wi = -glm::normalize(light->direction);
        s.irradiance = light->intensity;
        return s;
    }
    const Vec3 d = light->position - p;
    const float d2 = glm::dot(d, d);
    if (!(d2 > 0)) {
        s.needs_shadow_ray = false;  // wi stays 0: no N·L
        return s;
    }
    s.distance = std::sqrt(d2);
    s.wi = d / s.distance;
    s.irradiance = light->intensity / d2;
    if (light->type == LightType::Spot)
        s.irradiance *= spot_falloff(*light, glm::dot(-s.wi, glm::normalize(light->direction)));
    return s;
}

// Index of the shading light among the scene's lights, or -1 for the headlight: the
// requested one, else the first point, spot or directional light.
int choose_light(const std::vector<PunctualLight>& lights, int requested, const std::string& where) {
    auto usable = [](const PunctualLight& l) {
        return l.type == LightType::Point || l.type == LightType::Spot || l.type == LightType::Directional;
    };
    if (requested >= 0) {
        if (requested >= int(lights.size()))
            throw Error("dag_raycast.light", "the scene " + where + " has " + std::to_string(lights.size()) +
                                                 " punctual lights; index " + std::to_string(requested) +
                                                 " does not exist");
        if (!usable(lights[size_t(requested)]))
            throw Error("dag_raycast.light", "light " + std::to_string(requested) + " of " + where + " is a " +
                                                 to_string(lights[size_t(requested)].type) +
                                                 " light; only point, spot and directional lights are supported");
        return requested;
    }
    for (size_t i = 0; i < lights.size(); ++i)
        if (usable(lights[i])) return int(i);
    return -1;
}

}  // namespace

void DagRaycastTechnique::prepare(const Scene& scene, const Settings& settings) {
    Stopwatch watch;
    animation_ = AnimationDag();
    settings_ = DagRaycastSettings::from(settings);
    config_hash_ = settings.hash();
    const std::string where = scene.source.empty() ? scene.name : scene.source;
    fps_ = settings_.fps > 0 ? settings_.fps : scene.frames_per_second;
    if (!(fps_ > 0) || !std::isfinite(fps_))
        throw Error(where, "dag_raycast needs a positive frame rate, and the scene has " + std::to_string(fps_));
    light_index_ = choose_light(scene.lights, settings_.light, where);

    AnimationDagOptions options;
    options.resolution = settings_.resolution;
    options.frames = settings_.frames > 0
                         ? settings_.frames
                         : std::min(scene.animation_frame_count(), DagRaycastSettings::kDefaultMaxFrames);
    options.fps = fps_;
    options.build = settings_.build;
    animation_ = build_animation_dag(scene, options);
    frame_ = 0;

    const LaidOutMultiFrameDag& dag = animation_.dag;
    stats_ = animation_.stats;
    stats_.set("frames", double(dag.frame_count()));
    stats_.set("fps", fps_);
    stats_.set("resolution", double(settings_.resolution));
    stats_.set("nodes", double(dag.node_count()));
    stats_.set("nodes_per_frame", dag.nodes_per_frame());
    stats_.set("pointers", double(dag.pointer_count()));
    stats_.set("bytes_32bit", double(dag.bytes()));
    stats_.set("frame", 0);
    prepare_shadows(scene);
    stats_.set("prepare_ms", watch.elapsed_ms());
}

void DagRaycastTechnique::prepare_shadows(const Scene& scene) {
    shadow_dags_.clear();
    const PunctualLight* l = light();
    shadows_ = settings_.shadows == DagShadowSource::Auto ? DagShadowSource::ShadowDag : settings_.shadows;
    // The headlight sits at the eye: nothing it lights can be shadowed.
    if (!l) shadows_ = DagShadowSource::None;
    if (shadows_ != DagShadowSource::ShadowDag) return;

    // Shadow DAGs per frame over that frame's geometry and light, as the frames' voxels
    // were: the renderer then only looks up the frame's DAGs.
    Stopwatch watch;
    ShadowDagOptions o;
    o.resolution = settings_.shadow_resolution ? settings_.shadow_resolution : settings_.resolution;
    TracedScene traced;
    traced.load(scene);
    size_t bytes = 0, dags = 0;
    for (size_t k = 0; k < animation_.times.size(); ++k) {
        traced.set_time(animation_.times[k]);
        shadow_dags_.push_back(
            LightShadowDags::build(scene, traced.tracer(), animation_.lights[k][size_t(light_index_)], o));
        bytes += shadow_dags_.back().bytes();
        dags += shadow_dags_.back().dag_count();
    }
    stats_.set("shadow_dags", double(dags));
    stats_.set("shadow_dag_resolution", double(o.resolution));
    stats_.set("shadow_dag_build_ms", watch.elapsed_ms());
    stats_.set("shadow_dag_bytes", double(bytes));
}

const PunctualLight* DagRaycastTechnique::light() const {
    return light_index_ < 0 ? nullptr : &animation_.lights[frame_][size_t(light_index_)];
}

void DagRaycastTechnique::update(double time) {
    if (!prepared()) throw Error(kName, "update() called before prepare()");
    if (!std::isfinite(time)) throw Error(kName, "update() needs a finite time, not " + std::to_string(time));
    Stopwatch clock;
    // Only the root changes: the frame nearest to t, as the scene clamps past its ends.
    const double k = std::round(time * fps_);
    const size_t last = frame_count() - 1;
    frame_ = k <= 0 ? 0 : k >= double(last) ? last : size_t(k);
    stats_.set("update_ms", clock.elapsed_ms());
    stats_.set("frame", double(frame_));
}

void DagRaycastTechnique::render(const ViewSet& views, std::vector<Film>& films) {
    if (!prepared()) throw Error(kName, "render() called before prepare()");
    Stopwatch total;
    const LaidOutMultiFrameDag& dag = animation_.dag;
    const size_t frame = frame_;
    const DagWordsView frame_dag = dag_view(dag, frame);
    const PunctualLight* shading_light = light();
    const float voxel = float(dag.grid().voxel_size());
    const Vec3 ambient_scale(settings_.ambient);
    std::atomic<uint64_t> rays{0}, primary_visits{0};
    films.resize(views.views.size());
    for (size_t v = 0; v < views.views.size(); ++v) {
        const EyeCamera& cam = views.views[v];
        const int w = cam.width(), h = cam.height();
        check_resolution(w, h, 4);
        Film film(w, h);
        // Layers looked up once, not per pixel.
        float* color = film.layer("color").data.data();
        float* normal = film.add_layer("normal").data.data();
        float* depth = film.add_layer("depth", 1).data.data();
        float* visible = film.add_layer("visibility", 1).data.data();
        const LightShadowDags* shadow_dag = shadows_ == DagShadowSource::ShadowDag ? &shadow_dags_[frame] : nullptr;
        parallel_for_tiles(w, h, settings_.tile_size, [&](const Tile& t) {
            uint64_t tile_rays = 0, tile_visits = 0;
            LightShadowDags::Cursor cursor;
            for (int y = t.y0; y < t.y1; ++y)
                for (int x = t.x0; x < t.x1; ++x) {
                    const Ray r = cam.generate_ray(float(x) + 0.5f, float(y) + 0.5f);
                    const VoxelRayHit hit = cast_dag_ray(frame_dag, r);
                    ++tile_rays;
                    tile_visits += hit.nodes_visited;
                    if (!hit.hit) continue;
                    const Vec3 n = voxel_entry_normal(dag.grid(), hit.voxel, r);
                    const Vec3 p = r.at(hit.t);
                    const LightArrival ls = sample_light(shading_light, p, cam.position());
                    const float cos_theta = glm::dot(n, ls.wi);
                    float visibility = 0;
                    if (cos_theta > 0) {
                        visibility = 1;
                        if (shadow_dag) {
                            visibility = shadow_dag->visibility(p, n, 1, cursor);
                        } else if (ls.needs_shadow_ray && shadows_ == DagShadowSource::DagRay) {
                            // From the empty voxel the primary ray came through, half a
                            // voxel off the face, so the hit voxel cannot shadow itself.
                            Ray shadow;
                            shadow.origin = p + n * (0.5f * voxel);
                            shadow.direction = ls.wi;
                            shadow.tmax = ls.distance - 0.5f * voxel;
                            visibility = cast_dag_ray(frame_dag, shadow).hit ? 0.0f : 1.0f;
                            ++tile_rays;
                        }
                    }
                    const Vec3 c = (kAlbedo * kInvPi) * ls.irradiance *
                                   (ambient_scale + Vec3(std::max(0.0f, cos_theta) * visibility));
                    const size_t pixel = size_t(y) * size_t(w) + size_t(x);
                    for (int k = 0; k < 3; ++k) {
                        color[3 * pixel + size_t(k)] = c[k];
                        normal[3 * pixel + size_t(k)] = n[k];
                    }
                    depth[pixel] = hit.t * glm::length(r.direction);
                    visible[pixel] = visibility;
                }
            rays += tile_rays;
            primary_visits += tile_visits;
        });
        write_film_provenance(film, kName, views, v, settings_.seed, config_hash_);
        film.metadata["frame"] = std::to_string(frame);
        film.metadata["frame_time"] = format_number(animation_.times[frame]);
        film.metadata["build"] = to_string(settings_.build);
        film.metadata["resolution"] = std::to_string(settings_.resolution);
        film.metadata["light"] = shading_light ? shading_light->name : "headlight";
        film.metadata["shadows"] = to_string(shadows_);
        films[v] = std::move(film);
    }
    const double ms = total.elapsed_ms();
    write_render_time(films, ms);
    stats_.set("render_ms", ms);
    stats_.set("rays", double(rays.load()));
    size_t pixels = 0;
    for (const Film& film : films) pixels += size_t(film.width()) * size_t(film.height());
    stats_.set("nodes_per_primary_ray", pixels ? double(primary_visits.load()) / double(pixels) : 0.0);
}

Stats DagRaycastTechnique::stats() const { return stats_; }

void register_dag_raycast(TechniqueRegistry& registry) {
    registry.add({kName,
                  "ray casting through a time-correlated multi-frame DAG: one root per animation frame, voxel "
                  "face normals, one light; shadows from each frame's shadow DAGs (a cube of six for a point "
                  "light) or shadow rays through the same frame",
                  [] { return std::make_unique<DagRaycastTechnique>(); }, &DagRaycastSettings::schema});
}

}  // namespace gilab
