#include "core/render/ray_tracer.hpp"

#include <embree3/rtcore.h>
#include <cstring>
#include <vector>
#include "core/render/surface_material.hpp"
#include "core/util/error.hpp"

namespace gilab {

namespace {

void embree_error(void*, RTCError code, const char* message) {
    // Embree reports errors through this callback; they surface as exceptions at the
    // next check in the calling code (see check_device).
    (void)code;
    (void)message;
}

void check_device(RTCDevice device, const char* during) {
    RTCError err = rtcGetDeviceError(device);
    if (err != RTC_ERROR_NONE)
        throw Error("embree", std::string("error ") + std::to_string(int(err)) + " during " + during);
}

RTCRay to_embree(const Ray& r) {
    RTCRay e;
    e.org_x = r.origin.x;
    e.org_y = r.origin.y;
    e.org_z = r.origin.z;
    e.dir_x = r.direction.x;
    e.dir_y = r.direction.y;
    e.dir_z = r.direction.z;
    e.tnear = r.tmin;
    e.tfar = r.tmax;
    e.time = 0;
    e.mask = 0xffffffffu;
    e.id = 0;
    e.flags = 0;
    return e;
}

Hit from_embree(const RTCRayHit& rh) {
    Hit h;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
    h.t = rh.ray.tfar;
    h.mesh = rh.hit.geomID;
    h.triangle = rh.hit.primID;
    h.u = rh.hit.u;
    h.v = rh.hit.v;
    h.geometric_normal = Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    return h;
}

// What an alpha-tested mesh's filter reads: the world mesh and the scene's materials.
struct AlphaMesh {
    const WorldMesh* mesh = nullptr;
    const std::vector<Material>* materials = nullptr;
};

bool needs_alpha_test(const WorldMesh& m, const std::vector<Material>& materials) {
    for (uint32_t id : m.material_ids)
        if (id < materials.size() && materials[id].alpha_tested()) return true;
    return false;
}

// Embree filter for every query (closest hit and occlusion, single rays and streams):
// a hit where the material's alpha mask says nothing is there is rejected, and the ray
// goes on to the next surface.
void alpha_filter(const RTCFilterFunctionNArguments* args) {
    const auto* am = static_cast<const AlphaMesh*>(args->geometryUserPtr);
    const WorldMesh& mesh = *am->mesh;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
        if (prim >= mesh.triangles.size() || prim >= mesh.material_ids.size()) continue;
        const uint32_t id = mesh.material_ids[prim];
        if (id >= am->materials->size()) continue;
        const Material& m = (*am->materials)[id];
        if (!m.alpha_tested()) continue;
        const float b1 = RTCHitN_u(args->hit, args->N, i), b2 = RTCHitN_v(args->hit, args->N, i), b0 = 1.0f - b1 - b2;
        const UVec3 tri = mesh.triangles[prim];
        Vec2 uv[kUvSetCount]{};
        for (int k = 0; k < kUvSetCount; ++k) {
            const std::vector<Vec2>& set = mesh.uv_set(k);
            if (set.size() == mesh.positions.size()) uv[k] = b0 * set[tri.x] + b1 * set[tri.y] + b2 * set[tri.z];
        }
        if (!surface_present(m, uv)) args->valid[i] = 0;
    }
}

}  // namespace

struct RayTracer::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<AlphaMesh> alpha_meshes;  // per geometry; stable addresses between builds
    std::vector<size_t> vertex_counts, triangle_counts;

    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }

    void build(const SceneFrame& frame) {
        if (scene) rtcReleaseScene(scene);
        scene = rtcNewScene(device);
        // Dynamic + refit-quality geometries let animated frames update the BVH in place.
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_DYNAMIC);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
        vertex_counts.clear();
        triangle_counts.clear();
        alpha_meshes.assign(frame.meshes.size(), AlphaMesh{});
        for (size_t i = 0; i < frame.meshes.size(); ++i) {
            const WorldMesh& m = frame.meshes[i];
            RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
            rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_REFIT);
            auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
                geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), std::max<size_t>(m.positions.size(), 1)));
            auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
                geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m.triangles.size()));
            check_device(device, "geometry allocation");
            if (!m.positions.empty()) std::memcpy(vertices, m.positions.data(), m.positions.size() * sizeof(Vec3));
            if (!m.triangles.empty()) std::memcpy(indices, m.triangles.data(), m.triangles.size() * sizeof(UVec3));
            alpha_meshes[i] = AlphaMesh{&m, &frame.materials};
            if (needs_alpha_test(m, frame.materials)) {
                rtcSetGeometryUserData(geom, &alpha_meshes[i]);
                rtcSetGeometryIntersectFilterFunction(geom, alpha_filter);
                rtcSetGeometryOccludedFilterFunction(geom, alpha_filter);
            }
            rtcCommitGeometry(geom);
            // Geometry ids equal world-mesh indices: attach in order on a fresh scene.
            unsigned id = rtcAttachGeometry(scene, geom);
            (void)id;
            rtcReleaseGeometry(geom);
            vertex_counts.push_back(m.positions.size());
            triangle_counts.push_back(m.triangles.size());
        }
        rtcCommitScene(scene);
        check_device(device, "BVH build");
    }

    bool same_topology(const SceneFrame& frame) const {
        if (frame.meshes.size() != vertex_counts.size()) return false;
        for (size_t i = 0; i < frame.meshes.size(); ++i)
            if (frame.meshes[i].positions.size() != vertex_counts[i] ||
                frame.meshes[i].triangles.size() != triangle_counts[i])
                return false;
        return true;
    }

    void refit(const SceneFrame& frame) {
        for (size_t i = 0; i < frame.meshes.size(); ++i) {
            alpha_meshes[i] = AlphaMesh{&frame.meshes[i], &frame.materials};  // the filters read the new frame
            RTCGeometry geom = rtcGetGeometry(scene, unsigned(i));
            auto* vertices = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
            const auto& p = frame.meshes[i].positions;
            if (!p.empty()) std::memcpy(vertices, p.data(), p.size() * sizeof(Vec3));
            rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
            rtcCommitGeometry(geom);
        }
        rtcCommitScene(scene);
        check_device(device, "BVH refit");
    }
};

RayTracer::RayTracer(const SceneFrame& frame) : impl_(std::make_unique<Impl>()), frame_(&frame) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) throw Error("embree", "could not create an Embree device");
    rtcSetDeviceErrorFunction(impl_->device, embree_error, nullptr);
    impl_->build(frame);
}

RayTracer::~RayTracer() = default;

RayTracer::UpdateKind RayTracer::update(const SceneFrame& frame) {
    frame_ = &frame;
    if (impl_->same_topology(frame)) {
        impl_->refit(frame);
        return UpdateKind::Refit;
    }
    impl_->build(frame);
    return UpdateKind::Rebuild;
}

Hit RayTracer::intersect(const Ray& ray) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray = to_embree(ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &context, &rh);
    return from_embree(rh);
}

bool RayTracer::occluded(const Ray& ray) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r = to_embree(ray);
    rtcOccluded1(impl_->scene, &context, &r);
    return r.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

void RayTracer::intersect(std::span<const Ray> rays, std::span<Hit> hits) const {
    if (hits.size() < rays.size()) throw Error("RayTracer::intersect", "hit buffer smaller than ray batch");
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    constexpr size_t kBatch = 256;
    RTCRayHit batch[kBatch];
    for (size_t begin = 0; begin < rays.size(); begin += kBatch) {
        size_t n = std::min(kBatch, rays.size() - begin);
        for (size_t i = 0; i < n; ++i) {
            batch[i].ray = to_embree(rays[begin + i]);
            batch[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
            batch[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect1M(impl_->scene, &context, batch, unsigned(n), sizeof(RTCRayHit));
        for (size_t i = 0; i < n; ++i) hits[begin + i] = from_embree(batch[i]);
    }
}

void RayTracer::occluded(std::span<const Ray> rays, std::span<uint8_t> blocked) const {
    if (blocked.size() < rays.size()) throw Error("RayTracer::occluded", "result buffer smaller than ray batch");
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    constexpr size_t kBatch = 256;
    RTCRay batch[kBatch];
    for (size_t begin = 0; begin < rays.size(); begin += kBatch) {
        size_t n = std::min(kBatch, rays.size() - begin);
        for (size_t i = 0; i < n; ++i) batch[i] = to_embree(rays[begin + i]);
        rtcOccluded1M(impl_->scene, &context, batch, unsigned(n), sizeof(RTCRay));
        for (size_t i = 0; i < n; ++i) blocked[begin + i] = batch[i].tfar < 0.0f ? 1 : 0;
    }
}

}  // namespace gilab
