#include "techniques/vct/vct_technique.hpp"

#include <atomic>
#include <cmath>
#include "core/render/bsdf.hpp"
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/render/interaction.hpp"
#include "core/render/visible_surfaces.hpp"
#include "core/util/parallel.hpp"
#include "core/util/progress.hpp"
#include "core/util/rng.hpp"
#include "core/voxel/voxel_grid.hpp"
#include "techniques/film_provenance.hpp"


namespace gilab {

namespace {

// One face of a voxel's G-buffer as the lighting passes read it.
struct FaceInput {
    float opacity = 0;
    Vec3 albedo{0}, normal{0}, position{0};
};
using VoxelInput = std::array<FaceInput, kFaceCount>;
using VoxelRadiance = std::array<Vec4, kFaceCount>;

// The Rng of one voxel face, keyed by its world voxel coordinate and level, so a voxel
// gets the same light samples wherever it is stored and whoever computes it.
Rng voxel_rng(uint64_t seed, int level, const IVec3& v, int face) {
    uint64_t key = mix64(uint64_t(uint32_t(v.x)) ^ mix64(uint64_t(uint32_t(v.y)) ^ mix64(uint64_t(uint32_t(v.z)))));
    return Rng::for_sample(seed, key, uint64_t(level) * 8 + uint64_t(face), 0x766374);
}

// Faces sharing a normal and position (one flat surface seen from several sides) share
// their lighting; returns the earlier face or -1.
int same_as_earlier(const VoxelInput& in, int f) {
    for (int g = 0; g < f; ++g)
        if (in[size_t(g)].opacity > 0 && in[size_t(g)].normal == in[size_t(f)].normal &&
            in[size_t(g)].position == in[size_t(f)].position)
            return g;
    return -1;
}

// For each face with opacity, the face whose surface it shares (itself when first); -1
// for faces without opacity. distinct_faces: faces with the same normal and position
// (one flat surface seen from several sides). sides: faces whose normals lie within ~45°
// of the first face of a side — P3 gathers the bounce once per voxel over its mean
// normal; a thin wall's two sides (opposite normals) stay two.
std::array<int, kFaceCount> distinct_faces(const VoxelInput& in) {
    std::array<int, kFaceCount> of;
    for (int f = 0; f < kFaceCount; ++f) {
        const int g = same_as_earlier(in, f);
        of[size_t(f)] = in[size_t(f)].opacity > 0 ? (g >= 0 ? g : f) : -1;
    }
    return of;
}

std::array<int, kFaceCount> sides(const VoxelInput& in) {
    constexpr float kSameSide = 0.7f;  // cos 45.6°
    std::array<int, kFaceCount> of;
    of.fill(-1);
    for (int f = 0; f < kFaceCount; ++f) {
        if (!(in[size_t(f)].opacity > 0)) continue;
        of[size_t(f)] = f;
        for (int g = 0; g < f; ++g)
            if (of[size_t(g)] == g && glm::dot(in[size_t(g)].normal, in[size_t(f)].normal) >= kSameSide) {
                of[size_t(f)] = g;
                break;
            }
    }
    return of;
}

// Calls fn(begin, end) over [0, count) in parallel, in blocks of exactly `block` (the last
// shorter): a block's shadow-ray stream then never depends on the thread count, so
// neither does anything Embree's stream traversal decides.
void parallel_blocks(size_t count, size_t block, const std::function<void(size_t, size_t)>& fn) {
    parallel_for((count + block - 1) / block, 1, [&](size_t b, size_t e) {
        for (size_t j = b; j < e; ++j) fn(j * block, std::min(count, (j + 1) * block));
    });
}

// Voxels per shadow-ray stream of the light injection (about 100 rays per light).
constexpr size_t kInjectionBlock = 32;

struct Shading {
    const RayTracer& tracer;
    const DirectLighting& lighting;
    const VctSettings& settings;
    const ConeSet& injection_set;
    Bounds3 bounds;  // of the voxelized geometry

    // Direct light leaving each face (premultiplied by its opacity) of the voxels
    // voxel(0 … n−1) → {input, world coordinates}, into out[0 … n−1]. Faces on one side
    // share one irradiance (same_as_earlier); the shadow rays of all the faces go to
    // Embree as one stream, and each face sums its unblocked queries in their order.
    template <class VoxelAt>
    void direct(size_t n, int level, float voxel, VoxelAt&& voxel_at, VoxelRadiance* out, uint64_t& faces_lit) const {
        thread_local std::vector<ShadowQuery> queries;
        thread_local std::vector<uint32_t> owner;  // voxel · 6 + face of each query
        thread_local std::vector<uint8_t> blocked;
        thread_local std::vector<VoxelInput> inputs;
        queries.clear();
        owner.clear();
        inputs.resize(n);
        for (size_t i = 0; i < n; ++i) {
            const auto [in, v] = voxel_at(i);
            inputs[i] = in;
            for (int f = 0; f < kFaceCount; ++f) {
                const FaceInput& fi = in[size_t(f)];
                if (!(fi.opacity > 0) || same_as_earlier(in, f) >= 0) continue;
                Rng rng = voxel_rng(settings.seed, level, v, f);
                float offset = std::max(1e-3f * voxel, 4.0f * ray_epsilon(fi.position));
                lighting.irradiance_queries(fi.position, fi.normal, offset, rng, queries);
                owner.resize(queries.size(), uint32_t(i * kFaceCount + size_t(f)));
                ++faces_lit;
            }
        }
        thread_local std::vector<Ray> rays;
        rays.resize(queries.size());
        for (size_t q = 0; q < queries.size(); ++q) rays[q] = queries[q].ray;
        blocked.resize(queries.size());
        tracer.occluded(rays, blocked);
        thread_local std::vector<Vec3> E;
        E.assign(n * kFaceCount, Vec3(0.0f));
        for (size_t q = 0; q < queries.size(); ++q)
            if (!blocked[q]) E[owner[q]] += queries[q].contribution;
        for (size_t i = 0; i < n; ++i) {
            const VoxelInput& in = inputs[i];
            out[i] = VoxelRadiance{};
            for (int f = 0; f < kFaceCount; ++f) {
                const FaceInput& fi = in[size_t(f)];
                if (!(fi.opacity > 0)) continue;
                const int g = same_as_earlier(in, f);
                const Vec3 L = fi.albedo * kInvPi * E[i * kFaceCount + size_t(g >= 0 ? g : f)];
                out[i][size_t(f)] = Vec4(L * fi.opacity, fi.opacity);
            }
        }
    }

    // Direct + one bounce gathered by the injection cones from `view` (the direct
    // V-buffer), premultiplied.
    VoxelRadiance bounce(const VoxelInput& in, const VoxelRadiance& direct, const VoxelConeView& view, float voxel,
                         uint64_t& cones) const {
        VoxelRadiance out{};
        Vec3 E[kFaceCount];
        ConeOptions options;
        options.step = settings.cone_step;
        options.start = settings.cone_start * voxel;
        options.ao_lambda = settings.ao_lambda;
        options.correct_opacity = settings.opacity_correction;
        options.lod_bias = settings.lod_bias;
        options.blend_levels = settings.blend_levels;
        options.bounds = bounds;
        if (settings.max_distance > 0) options.max_distance = settings.max_distance;
        // The surfaces the cones gather for: one per face, or one per side of the voxel.
        const std::array<int, kFaceCount> surface_of = settings.bounce_per_face ? distinct_faces(in) : sides(in);
        std::array<Vec3, kFaceCount> normal{}, position{};
        std::array<float, kFaceCount> weight{};
        for (int f = 0; f < kFaceCount; ++f) {
            const int g = surface_of[size_t(f)];
            if (g < 0) continue;
            const FaceInput& fi = in[size_t(f)];
            normal[size_t(g)] += fi.opacity * fi.normal;
            position[size_t(g)] += fi.opacity * fi.position;
            weight[size_t(g)] += fi.opacity;
        }
        const size_t cone_count = injection_set.directions.size();
        std::vector<Vec3> directions(cone_count);
        std::vector<ConeResult> results(cone_count);
        for (int g = 0; g < kFaceCount; ++g) {
            if (!(weight[size_t(g)] > 0)) continue;
            const float n_length = glm::length(normal[size_t(g)]);
            const Vec3 n = n_length > 0 ? normal[size_t(g)] / n_length : in[size_t(g)].normal;
            const Vec3 x = position[size_t(g)] / weight[size_t(g)];
            E[g] = Vec3(0);
            const Frame frame(n);
            ConeOptions o = options;
            o.clip = settings.clip_plane;
            o.clip_plane = Vec4(n, glm::dot(n, x));
            for (size_t c = 0; c < cone_count; ++c) directions[c] = frame.to_world(injection_set.directions[c]);
            trace_cone_fan(view, x + settings.cone_offset * voxel * n, directions, injection_set.tan_half_angle, o,
                           results);
            for (size_t c = 0; c < cone_count; ++c) {
                E[g] += results[c].radiance * (injection_set.cosines[c] * injection_set.weights[c]);
                cones += uint64_t(results[c].samples) << 32 | 1u;  // samples in the high half
            }
        }
        for (int f = 0; f < kFaceCount; ++f) {
            const FaceInput& fi = in[size_t(f)];
            if (!(fi.opacity > 0)) continue;
            E[f] = E[surface_of[size_t(f)]];
            Vec3 L = Vec3(direct[size_t(f)]) / fi.opacity + fi.albedo * kInvPi * E[f];
            out[size_t(f)] = Vec4(L * fi.opacity, fi.opacity);
        }
        return out;
    }
};

// Faces +k and −k share axis k's record; −k's normal is its negation.
VoxelInput input_of(const PackedVoxel& voxel, const VoxelLattice& lattice, const IVec3& coord) {
    VoxelInput in;
    const Vec3 center = voxel_center(lattice, coord);
    const float size = float(lattice.voxel_size);
    for (int k = 0; k < 3; ++k) {
        const PackedSurface& s = voxel.axis[size_t(k)];
        if (!s.opacity) continue;
        FaceInput plus{unpack_opacity(s), unpack_albedo(s), unpack_normal(s), unpack_position(s, center, size)};
        FaceInput minus = plus;
        minus.normal = -plus.normal;
        in[size_t(2 * k)] = plus;
        in[size_t(2 * k + 1)] = minus;
    }
    return in;
}

VoxelInput input_of(const CascadedVoxelTexture& t, int level, const IVec3& v) {
    return input_of(t.gbuffer_voxel(level, v), t.lattice(level), v);
}

VoxelInput input_of(const PackedVoxelAt& voxel, const VoxelLattice& lattice) {
    return input_of(voxel.voxel, lattice, voxel.coord);
}

// Meshes under an animated node (or an animated ancestor) are dynamic.
std::vector<bool> static_meshes(const Scene& scene, const SceneFrame& frame) {
    std::vector<bool> animated(scene.nodes.size(), false);
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        const SceneNode& n = scene.nodes[i];
        animated[i] = !n.animation.empty() || (n.parent >= 0 && animated[size_t(n.parent)]);
    }
    // A skinned mesh moves with its joints, wherever they sit in the hierarchy.
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        const int skin = scene.nodes[i].skin;
        if (skin < 0 || size_t(skin) >= scene.skins.size()) continue;
        for (uint32_t joint : scene.skins[size_t(skin)].joints)
            if (joint < animated.size() && animated[joint]) animated[i] = true;
    }
    std::vector<bool> include(frame.meshes.size(), true);
    for (size_t m = 0; m < frame.meshes.size(); ++m) {
        uint32_t node = frame.meshes[m].node;
        include[m] = !(node < animated.size() && animated[node]);
    }
    return include;
}

Vec3 initial_viewer(const Scene& scene, const Bounds3& bounds) {
    if (scene.camera) return scene.camera->position;
    if (scene.hmd) return scene.hmd->pose.position;
    return bounds.empty() ? Vec3(0) : bounds.center();
}

}  // namespace

// ---------------------------------------------------------------------------------

const SettingsSchema& VctSettings::schema() {
    static const SettingsSchema schema = [] {
        const VctSettings d;
        SettingsSchema s("vct", "voxel cone tracing on cascaded voxel textures (P3)");
        s.choice("structure", "cascaded", {"cascaded", "dense"})
            .doc("cascaded: P3's viewer-centred cascades | dense: one 3D texture with a full anisotropic mip chain "
                 "(the VXGI-style baseline).");
        s.integer("levels", d.levels).range(1, 16).unit("cascades").doc("Cascade levels, each twice the size of the last.");
        s.integer("resolution", d.resolution).range(4, 1024).unit("voxels per axis, a power of two")
            .doc("Resolution of every cascade.");
        s.number("voxel_size", d.voxel_size).at_least(0).unit("scene units")
            .doc("Finest voxel; 0: the scene's bounding cube / dense_resolution (shared by both structures).");
        s.integer("dense_resolution", d.dense_resolution).range(2, 2048).unit("voxels per axis, a power of two")
            .doc("Resolution of the dense texture.");
        s.boolean("diffuse", d.diffuse).doc("Trace diffuse cones for indirect light.");
        s.integer("diffuse_cones", d.diffuse_cones).range(1, 256).unit("per pixel")
            .doc("Diffuse cones over the hemisphere.")
            .quality_knob(1, 256);
        s.boolean("specular", d.specular).doc("One cone along the mirror direction, its aperture from the Phong exponent.");
        s.boolean("second_bounce", d.second_bounce).doc("Gather a bounce into the voxels before the final gather.");
        s.boolean("temporal_bounces", d.temporal_bounces)
            .doc("Gather the voxel bounce from the radiance of the frames before (direct light and every bounce so "
                 "far) instead of this frame's direct light: one more bounce each frame at no extra cone cost (off: "
                 "P3's two bounces).");
        s.boolean("bounce_per_face", d.bounce_per_face)
            .doc("Gather the voxel bounce for every distinct face (true), or once per side of the voxel over its mean "
                 "normal (false: P3 gathers once per voxel; a thin wall's two sides stay two).");
        s.integer("injection_cones", d.injection_cones).range(1, 256).unit("per side of a voxel")
            .doc("Cones gathering the second bounce.");
        s.number("ao_lambda", d.ao_lambda).at_least(0).doc("Eq. 4's ambient-occlusion fall-off per finest voxel of cone radius.");
        s.number("cone_step", d.cone_step).above(0.01).at_most(4).unit("voxels of the sampled level")
            .doc("Step between cone samples.");
        s.number("cone_offset", d.cone_offset).range(0, 16).unit("voxels").doc("Cone apex moved off the surface along its normal.");
        s.number("cone_start", d.cone_start).range(0, 16).unit("voxels").doc("First sample this far from the apex.");
        s.boolean("opacity_correction", d.opacity_correction).doc("Correct each sample's opacity for the step length.");
        s.number("lod_bias", d.lod_bias).doc("Added to every sample's mip level.");
        s.boolean("clip_plane", d.clip_plane).doc("A cone ignores the back side of its own surface.");
        s.boolean("blend_levels", d.blend_levels).doc("Blend the two cascade levels around a sample.");
        s.number("max_distance", d.max_distance).at_least(0).unit("scene units").doc("Longest cone; 0: unbounded.");
        s.choice("update", "strategy", {"strategy", "everything"})
            .doc("strategy: level d re-centred on update_schedule with toroidal scrolling | everything: every level "
                 "re-voxelized every frame.");
        s.choice("update_schedule", "log2", {"log2", "pow2", "every"})
            .doc("Frames between updates of level d: ⌈log2 d⌉ (P3 eq. 5), 2^(d−1), or 1.");
        s.integer("light_samples", d.light_samples).range(1, 1024).doc("Samples per area-light evaluation.");
        s.integer("seed", int64_t(d.seed)).at_least(0).doc("Seed of every random stream (same seed, same image).");
        s.integer("tile_size", d.tile_size).at_least(1).unit("pixels").doc("Square screen tile of one parallel task.");
        return s;
    }();
    return schema;
}

VctSettings VctSettings::from(const Settings& s) {
    const SettingsSchema& schema = VctSettings::schema();
    VctSettings v;
    const std::string& where = s.context();
    v.structure = schema.get<std::string>(s, "structure") == "dense" ? Structure::Dense : Structure::Cascaded;
    v.levels = schema.get<int>(s, "levels");
    v.resolution = schema.get<int>(s, "resolution");
    v.voxel_size = schema.get<double>(s, "voxel_size");
    v.dense_resolution = schema.get<int>(s, "dense_resolution");
    v.diffuse = schema.get<bool>(s, "diffuse");
    v.diffuse_cones = schema.get<int>(s, "diffuse_cones");
    v.specular = schema.get<bool>(s, "specular");
    v.second_bounce = schema.get<bool>(s, "second_bounce");
    v.bounce_per_face = schema.get<bool>(s, "bounce_per_face");
    v.temporal_bounces = schema.get<bool>(s, "temporal_bounces");
    v.injection_cones = schema.get<int>(s, "injection_cones");
    v.ao_lambda = schema.get<float>(s, "ao_lambda");
    v.cone_step = schema.get<float>(s, "cone_step");
    v.cone_offset = schema.get<float>(s, "cone_offset");
    v.cone_start = schema.get<float>(s, "cone_start");
    v.opacity_correction = schema.get<bool>(s, "opacity_correction");
    v.lod_bias = schema.get<float>(s, "lod_bias");
    v.clip_plane = schema.get<bool>(s, "clip_plane");
    v.blend_levels = schema.get<bool>(s, "blend_levels");
    v.max_distance = schema.get<float>(s, "max_distance");
    v.update = schema.get<std::string>(s, "update") == "everything" ? Update::Everything : Update::Strategy;
    const std::string schedule = schema.get<std::string>(s, "update_schedule");
    v.schedule = schedule == "pow2" ? Schedule::Pow2 : schedule == "every" ? Schedule::Every : Schedule::Log2;
    v.light_samples = schema.get<int>(s, "light_samples");
    v.seed = uint64_t(schema.get<int64_t>(s, "seed"));
    v.tile_size = schema.get<int>(s, "tile_size");
    for (const auto& [key, value] : {std::pair{"resolution", v.resolution}, std::pair{"dense_resolution", v.dense_resolution}})
        if (value & (value - 1))
            throw Error(where, std::string("setting '") + key + "' must be a power of two, got " + std::to_string(value));
    return v;
}

int update_period(VctSettings::Schedule schedule, int level) {
    const int d = level + 1;
    switch (schedule) {
        case VctSettings::Schedule::Every: return 1;
        case VctSettings::Schedule::Pow2: return 1 << std::min(level, 30);
        case VctSettings::Schedule::Log2: break;
    }
    return std::max(1, int(std::ceil(std::log2(double(d)) - 1e-9)));
}

// ---------------------------------------------------------------------------------

VctTechnique::VctTechnique() = default;
VctTechnique::~VctTechnique() = default;

void VctTechnique::prepare(const Scene& scene, const Settings& settings) {
    Stopwatch watch;
    settings_ = VctSettings::from(settings);
    config_hash_ = settings.hash();
    cascade_.reset();
    dense_.reset();
    scene_.load(scene);
    lighting_ = DirectLighting(scene_.frame(), scene_.materials(), settings_.light_samples);
    diffuse_set_ = hemisphere_cones(settings_.diffuse_cones);
    injection_set_ = hemisphere_cones(settings_.injection_cones);
    stats_ = Stats();

    std::vector<bool> include = static_meshes(scene, scene_.frame());
    voxelizer_ = FragmentVoxelizer(scene_.frame(), scene_.materials(), include);
    Bounds3 bounds = voxelizer_.triangle_count() > 0 ? voxelizer_.bounds() : scene_.frame().bounds;
    const VoxelGrid grid = VoxelGrid::enclosing(bounds, uint32_t(settings_.dense_resolution));
    const double w0 = settings_.voxel_size > 0 ? settings_.voxel_size : grid.voxel_size();

    Stopwatch voxelize_watch;
    if (settings_.structure == VctSettings::Structure::Cascaded) {
        CascadeConfig config;
        config.levels = settings_.levels;
        config.resolution = settings_.resolution;
        config.voxel_size = w0;
        config.anchor = DVec3(grid.origin);
        cascade_.emplace(config);
        const DVec3 viewer(initial_viewer(scene, bounds));
        for (int k = cascade_->levels() - 1; k >= 0; --k) cascade_->place(k, cascade_->origin_for(viewer, k));
        for (int k = cascade_->levels() - 1; k >= 0; --k) cascade_->voxelize_own(k, voxelizer_);
        stats_.set("voxelize_ms", voxelize_watch.elapsed_ms());
        Stopwatch light_watch;
        light_cascade(std::vector<bool>(size_t(cascade_->levels()), true));
        stats_.set("injection_ms", light_watch.elapsed_ms());
    } else {
        DenseMipConfig config;
        config.resolution = settings_.dense_resolution;
        config.voxel_size = grid.voxel_size();
        config.anchor = DVec3(grid.origin);
        dense_.emplace(config);
        dense_->voxelize(voxelizer_);
        stats_.set("voxelize_ms", voxelize_watch.elapsed_ms());
        Stopwatch light_watch;
        light_dense();
        stats_.set("injection_ms", light_watch.elapsed_ms());
    }
    frame_index_ = 0;
    stats_.set("update_ms", 0);  // no update since the build: a frame's total counts none
    stats_.set("prepare_ms", watch.elapsed_ms());
    stats_.set("triangles", double(scene_.frame().triangle_count()));
    stats_.set("voxelized_triangles", double(voxelizer_.triangle_count()));
    stats_.set("base_voxel_size", w0);
    stats_.set("structure_bytes", double(structure_bytes()));
}

void VctTechnique::update(double time) {
    if (!scene_.loaded()) throw Error("vct", "update() called before prepare()");
    if (!scene_.animated()) return;
    Stopwatch watch;
    scene_.set_time(time);
    lighting_ = DirectLighting(scene_.frame(), scene_.materials(), settings_.light_samples);
    stats_.set("scene_update_ms", watch.elapsed_ms());
}

size_t VctTechnique::structure_bytes() const {
    if (cascade_) return cascade_->bytes();
    if (dense_) return dense_->bytes();
    return 0;
}

VoxelConeView VctTechnique::radiance_view() const {
    if (cascade_) return VoxelConeView::cascade(*cascade_, cascade_->radiance);
    if (dense_) return VoxelConeView::dense(*dense_, dense_->radiance);
    throw Error("vct", "no voxel structure: prepare() first");
}

void VctTechnique::light_cascade(const std::vector<bool>& levels) {
    CascadedVoxelTexture& t = *cascade_;
    const Shading shading{scene_.tracer(), lighting_, settings_, injection_set_, voxelizer_.bounds()};
    std::atomic<uint64_t> cones{0}, lit{0}, faces_lit{0};
    uint64_t filter_cells = 0;
    double direct_ms = 0, bounce_ms = 0, filter_ms = 0;
    // Voxels a level lights itself: its region minus the part the finer level covers.
    auto own_voxels = [&](int k) {
        std::vector<IVec3> own;
        const VoxelBox inner = t.inner_box(k);
        for (const IVec3& v : t.occupied_in(k, t.region(k)))
            if (!inner.contains(v)) own.push_back(v);
        return own;
    };
    auto clear_own = [&](int k, std::vector<HalfRGBA>& buffer) {
        const VoxelBox box = t.region(k), inner = t.inner_box(k);
        for (int z = box.begin.z; z < box.end.z; ++z)
            for (int y = box.begin.y; y < box.end.y; ++y)
                for (int x = box.begin.x; x < box.end.x; ++x) {
                    IVec3 v(x, y, z);
                    if (inner.contains(v)) continue;
                    for (int f = 0; f < kFaceCount; ++f) buffer[t.index_of_voxel(f, k, v)] = HalfRGBA{};
                }
    };
    std::vector<std::vector<IVec3>> own(size_t(t.levels()));
    for (int k = 0; k < t.levels(); ++k)
        if (levels[size_t(k)]) own[size_t(k)] = own_voxels(k);
    // The direct light of each own voxel at full precision, for its bounce.
    std::vector<std::vector<VoxelRadiance>> own_direct(size_t(t.levels()));

    // The anisotropic filter of one level, timed and counted (cells written).
    auto filter = [&](int k) {
        Stopwatch watch;
        t.downsample(k, t.radiance);
        filter_ms += watch.elapsed_ms();
        filter_cells += uint64_t(t.inner_box(k).volume()) * kFaceCount;
    };
    // A level's own voxels take new values (one per voxel, six faces), then the level
    // is filtered from the finer one (levels in increasing order).
    auto write_own = [&](int k, const std::vector<VoxelRadiance>& values) {
        clear_own(k, t.radiance);
        const auto& list = own[size_t(k)];
        for (size_t i = 0; i < list.size(); ++i) {
            const size_t first = t.index_of_voxel(0, k, list[i]);
            for (int f = 0; f < kFaceCount; ++f) t.radiance[first + size_t(f)] = to_half_rgba(values[i][size_t(f)]);
        }
        filter(k);
    };

    // Direct light by shadow rays.
    for (int k = 0; k < t.levels(); ++k) {
        if (!levels[size_t(k)]) continue;
        Stopwatch watch;
        const auto& list = own[size_t(k)];
        auto& values = own_direct[size_t(k)];
        values.resize(list.size());
        const float voxel = float(t.voxel_size(k));
        parallel_blocks(list.size(), kInjectionBlock, [&](size_t b, size_t e) {
            uint64_t local = 0;
            shading.direct(e - b, k, voxel, [&](size_t i) { return std::pair(input_of(t, k, list[b + i]), list[b + i]); },
                           values.data() + b, local);
            faces_lit += local;
        });
        lit += list.size();
        direct_ms += watch.elapsed_ms();
    }
    // The V-buffer the bounce gathers from: this frame's direct light in the updated
    // levels (the other levels keep direct + bounce of their last update, as one
    // radiance texture on a GPU does) — or, with temporal bounces, the radiance of the
    // frames before everywhere.
    const bool temporal = settings_.temporal_bounces;
    if (!temporal)
        for (int k = 0; k < t.levels(); ++k)
            if (levels[size_t(k)]) write_own(k, own_direct[size_t(k)]);
    // Cones skip what holds no opacity.
    for (int k = 0; k < t.levels(); ++k)
        if (levels[size_t(k)] || temporal) t.refresh_occupancy(k, t.radiance);
    if (settings_.second_bounce) {
        // Every updated level gathers before any is rewritten with direct + bounce.
        const VoxelConeView view = VoxelConeView::cascade(t, t.radiance);
        std::vector<std::vector<VoxelRadiance>> bounced(size_t(t.levels()));
        for (int k = 0; k < t.levels(); ++k) {
            if (!levels[size_t(k)]) continue;
            Stopwatch watch;
            const auto& list = own[size_t(k)];
            const auto& values = own_direct[size_t(k)];
            auto& out = bounced[size_t(k)];
            out.resize(list.size());
            const float voxel = float(t.voxel_size(k));
            parallel_for(list.size(), 4, [&](size_t b, size_t e) {
                uint64_t local = 0;
                for (size_t i = b; i < e; ++i) out[i] = shading.bounce(input_of(t, k, list[i]), values[i], view, voxel, local);
                cones += local;
            });
            bounce_ms += watch.elapsed_ms();
        }
        for (int k = 0; k < t.levels(); ++k)
            if (levels[size_t(k)]) write_own(k, bounced[size_t(k)]);
    } else if (temporal) {
        for (int k = 0; k < t.levels(); ++k)
            if (levels[size_t(k)]) write_own(k, own_direct[size_t(k)]);
    }
    if (temporal)
        for (int k = 0; k < t.levels(); ++k) t.refresh_occupancy(k, t.radiance);
    stats_.add("injection_cones_traced", double(cones.load() & 0xffffffffu));
    stats_.add("injection_cone_samples", double(cones.load() >> 32));
    stats_.set("voxels_lit", double(lit.load()));
    stats_.set("injection_faces_lit", double(faces_lit.load()));
    stats_.set("injection_direct_ms", direct_ms);
    stats_.set("injection_bounce_ms", bounce_ms);
    stats_.set("filter_ms", filter_ms);
    stats_.set("filter_cells", double(filter_cells));
}

void VctTechnique::light_dense() {
    DenseMipTexture& t = *dense_;
    const Shading shading{scene_.tracer(), lighting_, settings_, injection_set_, voxelizer_.bounds()};
    const float voxel = float(t.voxel_size(0));
    const auto& list = t.voxels;
    std::atomic<uint64_t> faces_lit{0};
    double filter_ms = 0, bounce_ms = 0;
    int mip_builds = 0;
    Stopwatch watch;
    std::vector<VoxelRadiance> values(list.size());  // full precision, for the bounce
    parallel_blocks(list.size(), kInjectionBlock, [&](size_t b, size_t e) {
        uint64_t local = 0;
        shading.direct(e - b, 0, voxel, [&](size_t i) { return std::pair(input_of(list[b + i], t.lattice()), list[b + i].coord); },
                       values.data() + b, local);
        faces_lit += local;
    });
    const double direct_ms = watch.elapsed_ms();
    // Level 0 takes one value per voxel (six faces), then the mips are filtered from it.
    auto write_level0 = [&](const std::vector<VoxelRadiance>& radiance) {
        Stopwatch filter_watch;
        DenseMipTexture::clear_level0(t.radiance);
        for (size_t i = 0; i < list.size(); ++i) {
            const size_t first = t.index(0, 0, list[i].coord);
            for (int f = 0; f < kFaceCount; ++f) t.radiance[0][first + size_t(f)] = to_half_rgba(radiance[i][size_t(f)]);
        }
        t.build_mips(t.radiance);
        filter_ms += filter_watch.elapsed_ms();
        ++mip_builds;
    };
    // The bounce gathers from this frame's direct light — or, with temporal bounces, from
    // the radiance of the frames before, still in the buffer.
    const bool temporal = settings_.temporal_bounces;
    if (!temporal) write_level0(values);
    t.refresh_occupancy(t.radiance);  // cones skip what holds no opacity
    watch.reset();
    std::atomic<uint64_t> cones{0};
    if (settings_.second_bounce) {
        const VoxelConeView view = VoxelConeView::dense(t, t.radiance);
        std::vector<VoxelRadiance> bounced(list.size());
        parallel_for(list.size(), 4, [&](size_t b, size_t e) {
            uint64_t local = 0;
            for (size_t i = b; i < e; ++i)
                bounced[i] = shading.bounce(input_of(list[i], t.lattice()), values[i], view, voxel, local);
            cones += local;
        });
        bounce_ms = watch.elapsed_ms();
        write_level0(bounced);
    } else if (temporal) {
        write_level0(values);
    }
    if (temporal) t.refresh_occupancy(t.radiance);
    uint64_t filter_cells = 0;
    for (int k = 1; k < t.level_count(); ++k) filter_cells += uint64_t(mip_builds) * uint64_t(t.cells(k));
    stats_.add("injection_cones_traced", double(cones.load() & 0xffffffffu));
    stats_.add("injection_cone_samples", double(cones.load() >> 32));
    stats_.set("voxels_lit", double(list.size()));
    stats_.set("injection_faces_lit", double(faces_lit.load()));
    stats_.set("injection_direct_ms", direct_ms);
    stats_.set("injection_bounce_ms", bounce_ms);
    stats_.set("filter_ms", filter_ms);
    stats_.set("filter_cells", double(filter_cells));
}

void VctTechnique::update_voxels(const Vec3& viewer) {
    if (!scene_.loaded()) throw Error("vct", "render() called before prepare()");
    ++frame_index_;
    Stopwatch update_watch;
    uint64_t revoxelized = 0, clips = 0;
    double revoxelize_ms = 0;
    int updated_levels = 0;
    std::vector<bool> scheduled;
    if (cascade_) {
        CascadedVoxelTexture& t = *cascade_;
        scheduled.assign(size_t(t.levels()), false);
        const DVec3 p(viewer);
        // Coarse levels first: a scrolling level fills its new border from the next
        // coarser one, which should already have moved.
        std::vector<std::vector<VoxelBox>> exposed(size_t(t.levels()));
        for (int k = t.levels() - 1; k >= 0; --k) {
            const IVec3 target = t.origin_for(p, k);
            const IVec3 shift = glm::abs(target - t.origin(k));
            if (settings_.update == VctSettings::Update::Everything) {
                t.place(k, target);
                scheduled[size_t(k)] = true;
                continue;
            }
            // A level that fell a quarter of its width behind is updated at once, so the
            // finer level never leaves it.
            const bool due = frame_index_ % update_period(settings_.schedule, k) == 0;
            const bool forced = std::max(shift.x, std::max(shift.y, shift.z)) > t.resolution() / 4;
            if (!due && !forced) continue;
            scheduled[size_t(k)] = true;
            if (target != t.origin(k)) exposed[size_t(k)] = t.scroll(k, target);
        }
        // Every level re-voxelized in full, or only its new border slabs and the band its
        // finer level uncovered — one pass over the triangles per level.
        Stopwatch voxelize_watch;
        for (int k = t.levels() - 1; k >= 0; --k) {
            FragmentVoxelizeStats s = settings_.update == VctSettings::Update::Everything
                                          ? t.voxelize_own(k, voxelizer_)
                                          : t.follow_inner(k, voxelizer_, exposed[size_t(k)]);
            revoxelized += s.voxels;
            clips += s.clips;
        }
        revoxelize_ms = voxelize_watch.elapsed_ms();
        for (bool s : scheduled) updated_levels += s;
    } else if (dense_) {
        if (settings_.update == VctSettings::Update::Everything) {
            Stopwatch voxelize_watch;
            FragmentVoxelizeStats s = dense_->voxelize(voxelizer_);
            revoxelized = s.voxels;
            clips = s.clips;
            revoxelize_ms = voxelize_watch.elapsed_ms();
        }
        updated_levels = 1;
    }
    stats_.set("update_ms", update_watch.elapsed_ms());
    stats_.set("revoxelize_ms", revoxelize_ms);
    stats_.set("levels_updated", double(updated_levels));
    stats_.set("voxels_revoxelized", double(revoxelized));
    stats_.set("voxelize_clips", double(clips));

    Stopwatch light_watch;
    stats_.set("injection_cones_traced", 0);
    stats_.set("injection_cone_samples", 0);
    if (cascade_)
        light_cascade(scheduled);
    else if (dense_)
        light_dense();
    stats_.set("injection_ms", light_watch.elapsed_ms());
    stats_.set("frame", double(frame_index_));
}

// ---------------------------------------------------------------------------------

void VctTechnique::render(const ViewSet& views, std::vector<Film>& films) {
    if (!scene_.loaded()) throw Error("vct", "render() called before prepare()");
    if (views.views.empty()) throw Error("vct", "render() needs at least one view");
    Stopwatch total_watch;
    Vec3 viewer(0);
    for (const EyeCamera& c : views.views) viewer += c.position();
    viewer /= float(views.views.size());
    update_voxels(viewer);

    const VoxelConeView view = radiance_view();
    const float w0 = view.base_voxel_size();
    ConeOptions options;
    options.step = settings_.cone_step;
    options.ao_lambda = settings_.ao_lambda;
    options.correct_opacity = settings_.opacity_correction;
    options.lod_bias = settings_.lod_bias;
    options.blend_levels = settings_.blend_levels;
    options.bounds = voxelizer_.bounds();
    if (settings_.max_distance > 0) options.max_distance = settings_.max_distance;
    // Voxel size at a surface point: cones start a few of them away from their apex.
    auto voxel_at = [&](const Vec3& p) {
        int k = view.finest_level_containing(p, 1.0f);
        return k < 0 ? w0 : view.level(k).voxel_size;
    };
    // Cones gathered at a visible surface: apex lifted off the surface, first sample a
    // few voxels out, and (optionally) clipped to the surface's front half-space.
    struct SurfaceCones {
        ConeOptions options;
        Vec3 apex;
    };
    auto cones_at = [&](const PixelHit& ph) {
        SurfaceCones sc{options, Vec3(0)};
        const float w = voxel_at(ph.position);
        sc.options.start = settings_.cone_start * w;
        sc.options.clip = settings_.clip_plane;
        sc.options.clip_plane = Vec4(ph.normal, glm::dot(ph.normal, ph.position));
        sc.apex = ph.position + settings_.cone_offset * w * ph.normal;
        return sc;
    };

    double primary_ms = 0, direct_ms = 0, diffuse_ms = 0, specular_ms = 0;
    std::atomic<uint64_t> cones{0};
    std::atomic<uint64_t> diffuse_cones{0}, diffuse_samples{0}, specular_cones{0}, specular_samples{0};
    films.resize(views.views.size());
    for (size_t vi = 0; vi < views.views.size(); ++vi) {
        const EyeCamera& camera = views.views[vi];
        const int width = camera.width(), height = camera.height();
        check_resolution(width, height, 10);
        Film film(width, height);
        for (const char* name : {"direct", "indirect", "specular", "albedo", "normal"}) film.add_layer(name);
        film.add_layer("ao", 1);
        film.add_layer("depth", 1);
        const size_t pixels = film.pixel_count();
        const int ts = settings_.tile_size;

        Stopwatch watch;
        const std::vector<PixelHit> hits = trace_visible_surfaces(scene_, camera, ts);
        primary_ms += watch.elapsed_ms();

        Layer& color = film.layer("color");
        Layer& direct = film.layer("direct");
        Layer& indirect = film.layer("indirect");
        Layer& specular = film.layer("specular");
        Layer& ao = film.layer("ao");
        auto put = [](Layer& l, size_t i, const Vec3& v) {
            for (int k = 0; k < 3; ++k) l.data[3 * i + size_t(k)] = v[k];
        };

        watch.reset();
        std::fill(ao.data.begin(), ao.data.end(), 1.0f);
        shade_direct_light(scene_, lighting_, hits, settings_.seed, vi, ts, film);
        direct_ms += watch.elapsed_ms();

        watch.reset();
        if (settings_.diffuse) {
            Progress progress("vct " + (vi < views.names.size() ? views.names[vi] : std::string("mono")),
                              size_t((width + ts - 1) / ts) * size_t((height + ts - 1) / ts));
            parallel_for_tiles(width, height, ts, [&](const Tile& tile) {
                uint64_t local = 0, samples = 0;
                const size_t cone_count = diffuse_set_.directions.size();
                std::vector<Vec3> directions(cone_count);
                std::vector<ConeResult> results(cone_count);
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x) {
                        const size_t i = size_t(y) * size_t(width) + size_t(x);
                        const PixelHit& ph = hits[i];
                        if (!ph.hit) continue;
                        const SurfaceMaterial& m = ph.surface;
                        const SurfaceCones sc = cones_at(ph);
                        const Frame frame(ph.normal);
                        for (size_t c = 0; c < cone_count; ++c) directions[c] = frame.to_world(diffuse_set_.directions[c]);
                        trace_cone_fan(view, sc.apex, directions, diffuse_set_.tan_half_angle, sc.options, results);
                        Vec3 E(0);
                        float occlusion = 0;
                        for (size_t c = 0; c < cone_count; ++c) {
                            const ConeResult& r = results[c];
                            const float w = diffuse_set_.cosines[c] * diffuse_set_.weights[c];
                            E += r.radiance * w;
                            occlusion += r.occlusion * w;
                            ++local;
                            samples += uint64_t(r.samples);
                        }
                        put(indirect, i, m.albedo * kInvPi * E);
                        ao.data[i] = std::clamp(1.0f - occlusion * kInvPi, 0.0f, 1.0f);
                    }
                cones += local;
                diffuse_cones += local;
                diffuse_samples += samples;
                progress.advance();
            });
            progress.finish();
        }
        diffuse_ms += watch.elapsed_ms();

        watch.reset();
        if (settings_.specular) {
            // A tile's glossy pixels, in scanline order, go out together: neighbours' mirror
            // cones are alike in length, so a batch's lanes stay busy.
            parallel_for_tiles(width, height, ts, [&](const Tile& tile) {
                uint64_t local = 0, samples = 0;
                std::vector<ConeLaunch> launches;
                std::vector<size_t> pixel;
                std::vector<float> cosine;
                for (int y = tile.y0; y < tile.y1; ++y)
                    for (int x = tile.x0; x < tile.x1; ++x) {
                        const size_t i = size_t(y) * size_t(width) + size_t(x);
                        const PixelHit& ph = hits[i];
                        if (!ph.hit) continue;
                        const SurfaceMaterial& m = ph.surface;
                        if (!m.has_glossy_lobe()) continue;
                        const Vec3 r = glm::reflect(-ph.wo, ph.normal);
                        const float cos_r = glm::dot(r, ph.normal);
                        if (cos_r <= 0.0f) continue;
                        const SurfaceCones sc = cones_at(ph);
                        launches.push_back({Cone{sc.apex, r, phong_cone_tan(m.phong_exponent)}, sc.options.start,
                                            sc.options.clip_plane});
                        pixel.push_back(i);
                        cosine.push_back(cos_r);
                    }
                std::vector<ConeResult> results(launches.size());
                ConeOptions shared = options;
                shared.clip = settings_.clip_plane;
                trace_cones(view, launches, shared, results);
                for (size_t j = 0; j < launches.size(); ++j) {
                    put(specular, pixel[j], hits[pixel[j]].surface.specular * results[j].radiance * cosine[j]);
                    ++local;
                    samples += uint64_t(results[j].samples);
                }
                cones += local;
                specular_cones += local;
                specular_samples += samples;
            });
        }
        specular_ms += watch.elapsed_ms();

        for (size_t i = 0; i < pixels; ++i)
            for (int k = 0; k < 3; ++k) {
                size_t j = 3 * i + size_t(k);
                color.data[j] = direct.data[j] + indirect.data[j] + specular.data[j];
            }

        write_film_provenance(film, name(), views, vi, settings_.seed, config_hash_);
        film.metadata["structure"] = settings_.structure == VctSettings::Structure::Dense ? "dense" : "cascaded";
        film.metadata["frame"] = std::to_string(frame_index_);
        films[vi] = std::move(film);
    }
    const double update_ms = stats_.get("update_ms"), injection_ms = stats_.get("injection_ms");
    stats_.set("primary_ms", primary_ms);
    stats_.set("direct_ms", direct_ms);
    stats_.set("diffuse_ms", diffuse_ms);
    stats_.set("specular_ms", specular_ms);
    stats_.set("total_ms", update_ms + injection_ms + primary_ms + direct_ms + diffuse_ms + specular_ms);
    stats_.set("pixel_cones_traced", double(cones.load()));
    stats_.set("diffuse_cones_traced", double(diffuse_cones.load()));
    stats_.set("diffuse_cone_samples", double(diffuse_samples.load()));
    stats_.set("specular_cones_traced", double(specular_cones.load()));
    stats_.set("specular_cone_samples", double(specular_samples.load()));
    stats_.set("structure_bytes", double(structure_bytes()));
    if (cascade_) {
        size_t occupied = 0;
        for (int k = 0; k < cascade_->levels(); ++k) occupied += cascade_->occupied_voxels(k);
        stats_.set("occupied_voxels", double(occupied));
    } else if (dense_) {
        stats_.set("occupied_voxels", double(dense_->voxels.size()));
    }
    const double ms = total_watch.elapsed_ms();
    stats_.set("render_ms", ms);
    write_render_time(films, ms);
}

void register_vct(TechniqueRegistry& registry) {
    registry.add({"vct",
                  "voxel cone tracing on cascaded anisotropic voxel textures (P3); structure=dense gives the "
                  "mip-mapped 3D texture baseline",
                  [] { return std::make_unique<VctTechnique>(); }, &VctSettings::schema});
}

}  // namespace gilab
