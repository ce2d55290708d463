#include "techniques/dag_shadows/dag_shadows_technique.hpp"
#include <cmath>
#include "core/render/surface_material.hpp"
#include "core/util/error.hpp"
#include "core/render/interaction.hpp"
#include "core/util/parallel.hpp"
#include "techniques/film_provenance.hpp"

namespace gilab {
namespace {

constexpr const char* kName = "dag_shadows";

VisibilitySource parse_visibility(const std::string& s) {
    if (s == "ray") return VisibilitySource::Ray;
    if (s == "shadow_map") return VisibilitySource::ShadowMap;
    if (s == "shadow_dag") return VisibilitySource::ShadowDag;
    if (s == "shadow_dag_double_depth") return VisibilitySource::ShadowDagDoubleDepth;
    throw std::logic_error("dag_shadows: visibility '" + s + "' is declared but not handled");
}

// Irradiance from the light on a surface facing it head-on, at p (unoccluded).
Vec3 light_irradiance(const PunctualLight& light, const Vec3& p, Vec3& wi) {
    if (light.type == LightType::Directional) {
        wi = -glm::normalize(light.direction);
        return light.intensity;
    }
    const Vec3 d = light.position - p;
    const float d2 = glm::dot(d, d);
    if (!(d2 > 0)) return Vec3(0);
    wi = d / std::sqrt(d2);
    float falloff = 1.0f;
    if (light.type == LightType::Spot) falloff = spot_falloff(light, glm::dot(-wi, glm::normalize(light.direction)));
    return light.intensity * (falloff / d2);
}

}  // namespace

const char* to_string(VisibilitySource source) {
    switch (source) {
        case VisibilitySource::Ray: return "ray";
        case VisibilitySource::ShadowMap: return "shadow_map";
        case VisibilitySource::ShadowDag: return "shadow_dag";
        case VisibilitySource::ShadowDagDoubleDepth: return "shadow_dag_double_depth";
    }
    return "?";
}

const SettingsSchema& DagShadowsSettings::schema() {
    static const SettingsSchema schema = [] {
        const DagShadowsSettings d;
        SettingsSchema s(kName, "direct light with visibility from a chosen structure (P2 §3)");
        s.choice("visibility", to_string(d.visibility), {"shadow_dag", "shadow_dag_double_depth", "shadow_map", "ray"})
            .doc("shadow_dag: P2's shadow DAG (S2) | shadow_dag_double_depth: over double depth maps (S3) | "
                 "shadow_map: a plain shadow map at the same x–y resolution (S1) | ray: Embree shadow rays.");
        s.integer("resolution", d.resolution).range(8, kMaxLightSpaceResolution).unit("light-space voxels per axis")
            .doc("Resolution of the light space (and of the shadow map's x–y).");
        s.integer("light", d.light).at_least(-1)
            .doc("Index of the shadow light among the scene's punctual lights; -1: the first directional or spot "
                 "light (point lights are refused).");
        s.integer("pcf", d.pcf).range(1, 9).unit("k for a k×k filter").doc("Percentage-closer filtering.");
        s.integer("shadow_map_bits", d.shadow_map_bits).range(16, 32).doc("Depth precision of the shadow map: 16 or 32.");
        s.integer("tile", d.tile).range(0, kMaxLightSpaceResolution).unit("voxels, a power of two")
            .doc("x–y tile side of the DAG build; 0: automatic.");
        s.choice("undefined_as", "shadow", {"shadow", "lit"})
            .doc("How undefined space inside boundary nodes is stored, and what lookups there answer.");
        s.number("ambient", d.ambient).range(0, 1).unit("of the light's irradiance")
            .doc("Unshadowed ambient light, so shadowed surfaces stay visible.");
        s.integer("tile_size", d.tile_size).range(1, 1024).unit("pixels").doc("Square screen tile of one parallel task.");
        s.integer("seed", int64_t(d.seed)).at_least(0).doc("Recorded only: nothing in this technique is random.");
        return s;
    }();
    return schema;
}

DagShadowsSettings DagShadowsSettings::from(const Settings& s) {
    const SettingsSchema& schema = DagShadowsSettings::schema();
    const std::string& where = s.context();
    DagShadowsSettings o;
    o.visibility = parse_visibility(schema.get<std::string>(s, "visibility"));
    o.resolution = schema.get<uint32_t>(s, "resolution");
    o.light = schema.get<int>(s, "light");
    o.pcf = schema.get<int>(s, "pcf");
    o.shadow_map_bits = schema.get<int>(s, "shadow_map_bits");
    if (o.shadow_map_bits != 16 && o.shadow_map_bits != 32)
        throw Error(where, "setting 'shadow_map_bits' must be 16 or 32, got " + std::to_string(o.shadow_map_bits));
    o.tile = schema.get<uint32_t>(s, "tile");
    if (o.tile & (o.tile - 1))
        throw Error(where, "setting 'tile' must be 0 (automatic) or a power of two, got " + std::to_string(o.tile));
    o.undefined_as = schema.get<std::string>(s, "undefined_as") == "lit" ? ShadowState::Lit : ShadowState::Shadow;
    o.ambient = schema.get<float>(s, "ambient");
    o.tile_size = schema.get<int>(s, "tile_size");
    o.seed = uint64_t(schema.get<int64_t>(s, "seed"));
    return o;
}

void DagShadowsTechnique::prepare(const Scene& scene, const Settings& settings) {
    Stopwatch watch;
    settings_ = DagShadowsSettings::from(settings);
    config_hash_ = settings.hash();
    scene_.load(scene);
    source_ = &scene;
    const auto& lights = scene_.frame().lights;
    if (settings_.light >= 0) {
        if (settings_.light >= int(lights.size()))
            throw Error(std::string(kName) + ".light", "the scene has " + std::to_string(lights.size()) +
                                                           " punctual lights; index " +
                                                           std::to_string(settings_.light) + " does not exist");
        light_index_ = settings_.light;
    } else {
        light_index_ = -1;
        for (size_t i = 0; i < lights.size() && light_index_ < 0; ++i)
            if (lights[i].type != LightType::Point) light_index_ = int(i);
        if (light_index_ < 0)
            throw Error(scene.source, "dag_shadows needs a directional or spot light, and the scene has none");
    }
    stats_ = Stats();
    build_structure();
    stats_.set("prepare_ms", watch.elapsed_ms());
}

Stats DagShadowsTechnique::stats() const {
    Stats out = stats_;
    out.merge(structure_stats_);
    return out;
}

void DagShadowsTechnique::build_structure() {
    dag_.reset();
    map_.reset();
    structure_stats_ = Stats();
    const PunctualLight& l = light();
    Stopwatch watch;
    switch (settings_.visibility) {
        case VisibilitySource::Ray:
            structure_stats_.set("structure_bytes", 0);  // shadow rays: no structure is held
            break;
        case VisibilitySource::ShadowMap:
            map_ = std::make_unique<ShadowMap>(
                ShadowMap::build(scene_.tracer(), l, settings_.resolution, settings_.shadow_map_bits));
            structure_stats_.set("structure_bytes", double(map_->bytes()));
            break;
        case VisibilitySource::ShadowDag:
        case VisibilitySource::ShadowDagDoubleDepth: {
            ShadowDagOptions o;
            o.resolution = settings_.resolution;
            o.double_depth = settings_.visibility == VisibilitySource::ShadowDagDoubleDepth;
            o.tile_texels = settings_.tile;
            o.undefined_as = settings_.undefined_as;
            dag_ = std::make_unique<ShadowDag>(ShadowDag::build(*source_, scene_.tracer(), l, o));
            structure_stats_.merge(dag_->stats(), "dag_");
            structure_stats_.set("structure_bytes", double(dag_->bytes()));
            break;
        }
    }
    structure_stats_.set("structure_build_ms", watch.elapsed_ms());
}

void DagShadowsTechnique::update(double time) {
    if (!scene_.loaded()) throw Error(kName, "update() called before prepare()");
    if (!scene_.animated()) return;
    scene_.set_time(time, &stats_);
    build_structure();  // light space moves with the geometry: rebuilt per frame
}

void DagShadowsTechnique::render(const ViewSet& views, std::vector<Film>& films) {
    if (!scene_.loaded()) throw Error(kName, "render() called before prepare()");
    Stopwatch total;
    films.resize(views.views.size());
    const SceneFrame& frame = scene_.frame();
    const auto& materials = scene_.materials();
    const PunctualLight& l = light();
    double shadow_ms = 0;
    size_t lookups = 0;
    for (size_t v = 0; v < views.views.size(); ++v) {
        const EyeCamera& cam = views.views[v];
        const int w = cam.width(), h = cam.height();
        check_resolution(w, h, 2);
        Film film(w, h);
        film.add_layer("visibility", 1);
        const size_t n = size_t(w) * h;
        // Pass 1: primary hits.
        std::vector<SurfaceInteraction> si(n);
        std::vector<SurfaceMaterial> surface(n);
        std::vector<uint8_t> hit(n, 0);
        const float spread = cam.pixel_spread_angle();
        parallel_for_tiles(w, h, settings_.tile_size, [&](const Tile& t) {
            for (int y = t.y0; y < t.y1; ++y)
                for (int x = t.x0; x < t.x1; ++x) {
                    const Ray r = cam.generate_ray(x + 0.5f, y + 0.5f);
                    const Hit hh = scene_.tracer().intersect(r);
                    if (!hh.valid()) continue;
                    const size_t i = size_t(y) * w + x;
                    si[i] = make_interaction(frame, r, hh);
                    const float width = cone_width(spread, hh.t * glm::length(r.direction));
                    apply_normal_map(materials[si[i].material], si[i], width);
                    surface[i] = at_surface(materials[si[i].material], si[i], width);
                    hit[i] = 1;
                }
        });
        // Pass 2: the visibility of every hit point that faces the light, from the chosen
        // structure, timed. A surface turned away from the light is unlit whatever the
        // structure says (its own object stands in the way), so it is not looked up.
        std::vector<Vec3> points, normals;
        std::vector<size_t> index, unlit;
        for (size_t i = 0; i < n; ++i) {
            if (!hit[i]) continue;
            Vec3 wi(0);
            light_irradiance(l, si[i].position, wi);
            if (glm::dot(si[i].geometric_normal, wi) <= 0) {
                unlit.push_back(i);
                continue;
            }
            points.push_back(si[i].position);
            normals.push_back(si[i].geometric_normal);
            index.push_back(i);
        }
        std::vector<float> vis(points.size(), 1.0f);
        lookups += points.size();
        Stopwatch shadow_clock;
        if (dag_) {
            dag_->visibility(points, normals, vis, settings_.pcf);
        } else if (map_) {
            map_->visibility(points, normals, vis, settings_.pcf);
        } else {
            parallel_for(points.size(), 1024, [&](size_t b, size_t e) {
                for (size_t k = b; k < e; ++k) {
                    Vec3 wi;
                    light_irradiance(l, points[k], wi);
                    Ray r;
                    r.origin = si[index[k]].spawn_origin(wi);
                    if (l.type == LightType::Directional) {
                        r.direction = wi;
                    } else {
                        r.direction = l.position - r.origin;
                        r.tmax = 1.0f - 1e-4f;
                    }
                    vis[k] = scene_.tracer().occluded(r) ? 0.0f : 1.0f;
                }
            });
        }
        shadow_ms += shadow_clock.elapsed_ms();
        // Pass 3: shading.
        const Vec3 ambient_irradiance = l.intensity * settings_.ambient;
        for (size_t i : unlit) {
            const SurfaceMaterial& m = surface[i];
            film.set("color", int(i % w), int(i / w), m.emission + m.albedo * kInvPi * ambient_irradiance);
        }
        parallel_for(points.size(), 1024, [&](size_t b, size_t e) {
            for (size_t k = b; k < e; ++k) {
                const SurfaceInteraction& s = si[index[k]];
                const SurfaceMaterial& m = surface[index[k]];
                Vec3 wi(0);
                const Vec3 E = light_irradiance(l, s.position, wi);
                const float cos_theta = std::max(0.0f, glm::dot(s.shading_normal, wi));
                const Vec3 c = m.emission + m.albedo * kInvPi * (E * (cos_theta * vis[k]) + ambient_irradiance);
                const int x = int(index[k] % w), y = int(index[k] / w);
                film.set("color", x, y, c);
                film.set("visibility", x, y, vis[k]);
            }
        });
        write_film_provenance(film, kName, views, v, settings_.seed, config_hash_);
        film.metadata["visibility"] = to_string(settings_.visibility);
        film.metadata["resolution"] = std::to_string(settings_.resolution);
        films[v] = std::move(film);
    }
    const double ms = total.elapsed_ms();
    write_render_time(films, ms);
    stats_.set("render_ms", ms);
    stats_.set("shadow_ms", shadow_ms);
    stats_.set("lookups", double(lookups));
}

void register_dag_shadows(TechniqueRegistry& registry) {
    registry.add({kName,
                  "direct light with visibility from shadow rays, a shadow map, or the shadow DAG (with or "
                  "without double depth maps)",
                  [] { return std::make_unique<DagShadowsTechnique>(); }, &DagShadowsSettings::schema});
}

}  // namespace gilab
