#include "accel/shadow/light_depth_maps.hpp"
#include <algorithm>
#include <cmath>
#include <optional>
#include "core/util/error.hpp"
#include "core/scene/mesh_topology.hpp"
#include "core/util/parallel.hpp"

namespace gilab {
namespace {

Vec3 face_normal(const WorldMesh& mesh, uint32_t triangle) {
    const UVec3 t = mesh.triangles[triangle];
    return glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]);
}

// Up to this many other surfaces may lie between a closed object's entry and exit
// (interpenetrating meshes); past it the texel is treated as open.
constexpr int kMaxExitSteps = 16;

// Where a closed part's undefined space ends (D2) in a column entered at d1 and left at
// `exit`. Lookup points are moved up to 2.5 voxels off a surface (LightSpace::
// lookup_coords), so a surface lying inside the part (`inner`: the first other surface
// met between entry and exit, +inf if none) or touching it at the exit (`touching`)
// has its lookups land in the part's interior, which the merge rules may fold into lit.
// Ending the undefined space a band before such a surface stores the space its lookups
// reach as shadow, as a plain depth map would answer them: the band is the bias plus a
// voxel of quantization and a voxel of the surface's slope across a texel.
float undefined_end(float d1, float exit, float inner, bool touching) {
    const float end = std::min(touching ? exit - kContactBandVoxels : exit, inner - kContactBandVoxels);
    return std::max(d1, end);
}

// Sign of (outward normal · ray direction): < 0 entering the part, > 0 leaving it.
float facing(const SceneFrame& frame, const ClosedSurfaces& closed, const Hit& h, const Vec3& direction) {
    const Vec3 n = face_normal(frame.meshes[h.mesh], h.triangle) * float(closed.outward[h.mesh][h.triangle]);
    return glm::dot(n, direction);
}

}  // namespace

ClosedSurfaces closed_surfaces(const Scene& scene, const SceneFrame& frame) {
    std::vector<std::optional<MeshTopology>> topology(scene.meshes.size());
    ClosedSurfaces out;
    out.component.resize(frame.meshes.size());
    out.outward.resize(frame.meshes.size());
    for (size_t m = 0; m < frame.meshes.size(); ++m) {
        const WorldMesh& wm = frame.meshes[m];
        std::optional<MeshTopology>& topo = topology.at(wm.source_mesh);
        if (!topo) topo = analyze_topology(scene.meshes[wm.source_mesh]);
        if (topo->closed_components == 0 || topo->closed_component.size() != wm.triangles.size()) continue;
        // World volume of each part with CGAL's consistent winding: its sign says which
        // way that winding faces.
        std::vector<double> volume(topo->connected_components, 0.0);
        for (size_t t = 0; t < wm.triangles.size(); ++t) {
            const int32_t c = topo->closed_component[t];
            if (c < 0) continue;
            const UVec3 tri = wm.triangles[t];
            const DVec3 a(wm.positions[tri.x]), b(wm.positions[tri.y]), cc(wm.positions[tri.z]);
            volume[size_t(c)] += topo->winding[t] * glm::dot(a, glm::cross(b, cc));
        }
        out.component[m] = topo->closed_component;
        out.outward[m].assign(wm.triangles.size(), 0);
        for (size_t t = 0; t < wm.triangles.size(); ++t) {
            const int32_t c = topo->closed_component[t];
            if (c < 0) continue;
            const double v = volume[size_t(c)];
            if (v == 0) {
                out.component[m][t] = -1;  // a flat "closed" part has no inside
                continue;
            }
            out.outward[m][t] = int8_t(topo->winding[t] * (v > 0 ? 1 : -1));
        }
        out.closed_components += topo->closed_components;
    }
    return out;
}


void LightDepthTile::render(const RayTracer& tracer, const LightSpace& space, const ClosedSurfaces* closed,
                            uint32_t x0, uint32_t y0, uint32_t size) {
    if (size == 0 || (size & (size - 1))) throw Error("light depth map", "tile size must be a power of two");
    x0_ = x0;
    y0_ = y0;
    size_ = size;
    max_d1_.assign(1, std::vector<float>(size_t(size) * size, kInfinity));
    min_d2_.assign(1, std::vector<float>(size_t(size) * size, kInfinity));
    const uint32_t n = space.resolution();
    const SceneFrame& frame = tracer.frame();
    std::vector<uint64_t> row_rays(size, 0);
    parallel_for(size, 1, [&](size_t begin, size_t end) {
        std::vector<Ray> rays, exit_rays;
        std::vector<Hit> hits, exit_hits;
        for (size_t row = begin; row < end; ++row) {
            const uint32_t y = y0 + uint32_t(row);
            if (y >= n) continue;
            const uint32_t count = std::min(size, n > x0 ? n - x0 : 0u);
            rays.resize(count);
            hits.resize(count);
            for (uint32_t i = 0; i < count; ++i) rays[i] = space.texel_ray(x0 + i, y);
            tracer.intersect(rays, hits);
            uint64_t cast = count;
            float* d1 = max_d1_[0].data() + row * size;
            float* d2 = min_d2_[0].data() + row * size;
            // Texels that entered a closed part through its outside search for the exit,
            // all of the row's continuation rays going out together as one stream.
            struct Search {
                uint32_t texel;
                uint32_t mesh;
                int32_t part;
                float inner = kInfinity;  // depth of the first other surface met inside the part
            };
            std::vector<Search> searches;
            struct Exit {
                uint32_t texel;
                float depth, inner;
            };
            std::vector<Exit> exits;
            for (uint32_t i = 0; i < count; ++i) {
                const Hit& h = hits[i];
                if (!h.valid()) continue;
                d1[i] = d2[i] = h.t;
                if (!closed || closed->empty() || closed->component[h.mesh].empty()) continue;
                const int32_t part = closed->component[h.mesh][h.triangle];
                if (part < 0 || facing(frame, *closed, h, rays[i].direction) >= 0) continue;
                searches.push_back({i, h.mesh, part, kInfinity});
                rays[i].tmin = h.t;
            }
            // The continuation rays keep their texel's place in a full-row stream (the rest
            // inactive, tmin > tmax), so Embree groups them the same way whatever the
            // tile: the answers then do not depend on how light space was tiled.
            exit_rays.resize(count);
            exit_hits.resize(count);
            for (int step = 0; step < kMaxExitSteps && !searches.empty(); ++step) {
                for (uint32_t i = 0; i < count; ++i) {
                    exit_rays[i] = rays[i];
                    exit_rays[i].tmin = 1.0f;
                    exit_rays[i].tmax = 0.0f;
                }
                for (const Search& q : searches) {
                    Ray& r = exit_rays[q.texel];
                    r.tmin = rays[q.texel].tmin + std::max(1e-4f, rays[q.texel].tmin * 1e-6f);
                    r.tmax = kInfinity;
                }
                tracer.intersect(exit_rays, exit_hits);
                cast += searches.size();
                size_t kept = 0;
                for (size_t k = 0; k < searches.size(); ++k) {
                    Search q = searches[k];
                    const Hit& e = exit_hits[q.texel];
                    if (!e.valid()) continue;  // slipped out of the part unseen: leave the texel open
                    if (e.mesh != q.mesh || closed->component[e.mesh][e.triangle] != q.part) {
                        rays[q.texel].tmin = e.t;  // another surface inside: look further
                        q.inner = std::min(q.inner, e.t);
                        searches[kept++] = q;
                        continue;
                    }
                    // The exit is a face of the same part turned away from the light; a
                    // face turned toward it means the real exit was missed (a ray through
                    // a shared edge): leave the texel open rather than guess.
                    if (facing(frame, *closed, e, rays[q.texel].direction) > 0) exits.push_back({q.texel, e.t, q.inner});
                }
                searches.resize(kept);
            }
            // Does another surface begin within the band behind the exit (a part resting on
            // or against this one)? One short ray per exit, again as one full-row stream.
            for (uint32_t i = 0; i < count; ++i) {
                exit_rays[i] = rays[i];
                exit_rays[i].tmin = 1.0f;
                exit_rays[i].tmax = 0.0f;
            }
            for (const Exit& x : exits) {
                Ray& r = exit_rays[x.texel];
                r.tmin = x.depth + std::max(1e-4f, x.depth * 1e-6f);
                r.tmax = x.depth + kContactBandVoxels;
            }
            if (!exits.empty()) {
                tracer.intersect(exit_rays, exit_hits);
                cast += exits.size();
            }
            for (const Exit& x : exits) {
                const bool touching = exit_hits[x.texel].valid();
                d2[x.texel] = undefined_end(d1[x.texel], x.depth, x.inner, touching);
            }
            row_rays[row] = cast;
        }
    });
    rays_ = 0;
    for (uint64_t r : row_rays) rays_ += r;
    build_pyramids();
}

void LightDepthTile::assign(uint32_t x0, uint32_t y0, uint32_t size, std::vector<float> d1, std::vector<float> d2) {
    if (size == 0 || (size & (size - 1)) || d1.size() != size_t(size) * size || d2.size() != d1.size())
        throw Error("light depth map", "tile maps must be size × size with size a power of two");
    for (size_t i = 0; i < d1.size(); ++i)
        if (std::isnan(d1[i]) || std::isnan(d2[i]) || d2[i] < d1[i])
            throw Error("light depth map", "texel " + std::to_string(i) + ": need D1 ≤ D2, no NaN");
    x0_ = x0;
    y0_ = y0;
    size_ = size;
    max_d1_.assign(1, std::move(d1));
    min_d2_.assign(1, std::move(d2));
    rays_ = 0;
    build_pyramids();
}

void LightDepthTile::build_pyramids() {
    for (uint32_t side = size_ / 2, level = 1; side >= 1; side /= 2, ++level) {
        const std::vector<float>& a = max_d1_[level - 1];
        const std::vector<float>& b = min_d2_[level - 1];
        std::vector<float> ma(size_t(side) * side), mb(size_t(side) * side);
        const uint32_t below = side * 2;
        for (uint32_t y = 0; y < side; ++y)
            for (uint32_t x = 0; x < side; ++x) {
                const size_t i = size_t(2 * y) * below + 2 * x, j = i + below;
                ma[size_t(y) * side + x] = std::max(std::max(a[i], a[i + 1]), std::max(a[j], a[j + 1]));
                mb[size_t(y) * side + x] = std::min(std::min(b[i], b[i + 1]), std::min(b[j], b[j + 1]));
            }
        max_d1_.push_back(std::move(ma));
        min_d2_.push_back(std::move(mb));
    }
}

ShadowState LightDepthTile::cell_state(const UVec3& first, uint32_t size) const {
    const int level = __builtin_ctz(size);
    const size_t i = local(first.x, first.y, level);
    const float first_centre = float(first.z) + 0.5f, last_centre = float(first.z + size) - 0.5f;
    return gilab::cell_state(max_d1_[level][i] > first_centre, min_d2_[level][i] <= last_centre);
}

ShadowState LightDepthTile::voxel_state(uint32_t x, uint32_t y, uint32_t z) const {
    const size_t i = local(x, y, 0);
    const float c = float(z) + 0.5f;
    if (c < max_d1_[0][i]) return ShadowState::Lit;
    if (c >= min_d2_[0][i]) return ShadowState::Shadow;
    return ShadowState::Undefined;
}

size_t LightDepthTile::memory_bytes() const {
    size_t b = 0;
    for (const auto& v : max_d1_) b += v.capacity() * sizeof(float);
    for (const auto& v : min_d2_) b += v.capacity() * sizeof(float);
    return b;
}

}  // namespace gilab
