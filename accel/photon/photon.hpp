#pragma once
// A stored photon (32 bytes) and the structure-of-arrays copy the gather loops read.
// Directions are unit vectors quantised to signed 8-bit per component (error < 0.5°),
// enough for the hemisphere test and for glossy lobes of moderate exponent. The spare
// byte of `wi` records at which surface hit of its path the copy was stored, so a
// density estimate can tell direct light (first hit) from indirect light.
#include <cstdint>
#include <span>
#include <vector>
#include "core/util/math.hpp"

namespace gilab {

// Unit vector ↔ 3 × snorm8 (component · 127, rounded).
struct PackedDirection {
    int8_t x = 0, y = 0, z = 0, pad = 0;

    static PackedDirection pack(const Vec3& d) {
        auto q = [](float v) { return int8_t(std::lround(std::clamp(v, -1.0f, 1.0f) * 127.0f)); };
        return {q(d.x), q(d.y), q(d.z), 0};
    }
    // Not renormalised: |unpack()| = 1 ± 0.01, and only signs and lobes depend on it.
    Vec3 unpack() const { return Vec3(float(x), float(y), float(z)) * (1.0f / 127.0f); }
};

struct Photon {
    Vec3 position{0};
    Vec3 power{0};            // flux ΔΦ carried (already divided by the emitted count)
    PackedDirection wi;       // unit, from the surface towards where the photon came from
    PackedDirection normal;   // geometric normal on the side the photon arrived from

    Vec3 incoming() const { return glm::normalize(wi.unpack()); }
    Vec3 surface_normal() const { return glm::normalize(normal.unpack()); }

    // Surface hit along the photon's path where this copy was stored: 1 = first hit
    // (light straight from a light source), 2.. later (saturating at 127); 0 = not
    // recorded, which counts as a later hit.
    int hit_index() const { return wi.pad; }
    void set_hit_index(int index) { wi.pad = int8_t(std::clamp(index, 0, 127)); }
    bool first_hit() const { return wi.pad == 1; }
};
static_assert(sizeof(Photon) == 32, "a photon record is 32 bytes");

// The photons of a structure in its storage order, one array per field, so a gather
// over a contiguous range is a loop the compiler can vectorise. `first` (1 for a copy
// stored at its path's first hit, else 0) exists only for maps that hold first-hit
// photons; maps of indirect light alone keep it empty and pay nothing for it.
struct PhotonSoA {
    std::vector<float> x, y, z;       // position
    std::vector<float> wx, wy, wz;    // incoming direction (unpacked)
    std::vector<float> r, g, b;       // power
    std::vector<float> first;         // 1: stored at the first hit; empty: none was

    size_t size() const { return x.size(); }
    bool has_first_hits() const { return !first.empty(); }
    void clear() { resize(0, false); }
    void resize(size_t n, bool with_first) {
        for (auto* v : {&x, &y, &z, &wx, &wy, &wz, &r, &g, &b}) v->resize(n);
        first.resize(with_first ? n : 0);
    }
    void set(size_t i, const Photon& p) {
        Vec3 w = p.incoming();
        x[i] = p.position.x, y[i] = p.position.y, z[i] = p.position.z;
        wx[i] = w.x, wy[i] = w.y, wz[i] = w.z;
        r[i] = p.power.x, g[i] = p.power.y, b[i] = p.power.z;
        if (!first.empty()) first[i] = p.first_hit() ? 1.0f : 0.0f;
    }
    size_t memory_bytes() const { return (9 * x.capacity() + first.capacity()) * sizeof(float); }
};

// Read-only pointers into a PhotonSoA (or any buffer with the same layout); first is
// null when the photons hold no first-hit copies.
struct PhotonSoAView {
    const float *x = nullptr, *y = nullptr, *z = nullptr;
    const float *wx = nullptr, *wy = nullptr, *wz = nullptr;
    const float *r = nullptr, *g = nullptr, *b = nullptr;
    const float* first = nullptr;

    static PhotonSoAView of(const PhotonSoA& s) {
        return {s.x.data(), s.y.data(), s.z.data(), s.wx.data(), s.wy.data(), s.wz.data(),
                s.r.data(), s.g.data(), s.b.data(), s.has_first_hits() ? s.first.data() : nullptr};
    }
};

// A contiguous range [begin, end) of a structure's storage order.
struct PhotonRun {
    uint32_t begin = 0, end = 0;
    uint32_t size() const { return end - begin; }
};

// Squared distance, always evaluated in this order (x, y, z) so that every structure
// and the brute-force reference agree bit for bit on which photons lie within r.
inline float photon_distance2(const Vec3& q, float px, float py, float pz) {
    float dx = q.x - px, dy = q.y - py, dz = q.z - pz;
    return dx * dx + dy * dy + dz * dz;
}

}  // namespace gilab
