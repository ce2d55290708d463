#include "core/scene/scene_hash.hpp"

#include <cstdint>
#include <cstdio>
#include <span>
#include <type_traits>
#include <vector>

namespace gilab {
namespace {

// FNV-1a, fed field by field. Floats are hashed by their bytes, so −0 and +0 differ; that
// can only make a cache miss, never a stale hit.
class Fnv1a {
public:
    void bytes(const void* data, size_t size) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < size; ++i) {
            h_ ^= p[i];
            h_ *= 1099511628211ull;
        }
    }
    template <class T>
    void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes(&v, sizeof v);
    }
    template <class T>
    void array(const std::vector<T>& v) {  // the length first, so [a][b,c] ≠ [a,b][c]
        value(uint64_t(v.size()));
        if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
    }
    uint64_t digest() const { return h_; }

private:
    uint64_t h_ = 14695981039346656037ull;
};

void add(Fnv1a& h, const Transform& t) {
    h.value(t.translation);
    h.value(t.rotation);
    h.value(t.scale);
}

template <class T>
void add(Fnv1a& h, const KeyframeChannel<T>& c) {
    h.array(c.times);
    h.array(c.values);
}

// A texture by its content, not its address: the same image loaded twice hashes alike.
void add(Fnv1a& h, const TextureRef& t) {
    h.value(uint8_t(t.image != nullptr));
    if (!t.image) return;
    const Rgba8Image& base = t.image->level(0);
    h.value(base.width);
    h.value(base.height);
    h.array(base.texels);
    h.value(t.image->encoding());
    h.value(t.uv_set);
    h.value(t.transform.offset);
    h.value(t.transform.rotation);
    h.value(t.transform.scale);
    h.value(t.wrap_s);
    h.value(t.wrap_t);
}

}  // namespace

std::string scene_content_hash(const Scene& scene) {
    Fnv1a h;
    h.value(uint64_t(scene.meshes.size()));
    for (const Mesh& m : scene.meshes) {
        h.array(m.positions);
        h.array(m.normals);
        h.array(m.uvs);
        h.array(m.uvs1);
        h.array(m.triangles);
        h.array(m.material_ids);
        h.array(m.influences);
    }
    h.value(uint64_t(scene.materials.size()));
    for (const Material& m : scene.materials) {
        h.value(m.albedo);
        h.value(m.specular);
        h.value(m.phong_exponent);
        h.value(m.emission);
        for (const TextureRef* t : {&m.albedo_texture, &m.emission_texture, &m.normal_texture, &m.alpha_texture})
            add(h, *t);
        h.value(m.normal_scale);
        h.value(m.alpha_mode);
        h.value(m.alpha);
        h.value(m.alpha_cutoff);
    }
    h.value(uint64_t(scene.nodes.size()));
    for (const SceneNode& n : scene.nodes) {
        h.value(n.parent);
        add(h, n.local);
        add(h, n.animation.translation);
        add(h, n.animation.rotation);
        add(h, n.animation.scale);
        h.value(n.animation.step);
        h.array(n.meshes);
        h.value(n.skin);
    }
    h.value(uint64_t(scene.skins.size()));
    for (const Skin& s : scene.skins) {
        h.array(s.joints);
        h.array(s.inverse_bind);
    }
    h.value(uint64_t(scene.lights.size()));
    for (const PunctualLight& l : scene.lights) {
        h.value(l.type);
        h.value(l.position);
        h.value(l.direction);
        h.value(l.intensity);
        h.value(l.cos_inner);
        h.value(l.cos_outer);
        h.value(l.node);
    }
    h.value(scene.frames_per_second);
    char out[17];
    std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h.digest()));
    return out;
}

}  // namespace gilab
