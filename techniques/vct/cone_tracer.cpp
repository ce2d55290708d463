#include "techniques/vct/cone_tracer.hpp"

#include <cmath>
#include "core/util/error.hpp"

namespace gilab {

VoxelConeView VoxelConeView::cascade(const CascadedVoxelTexture& t, const std::vector<Vec4>& buffer) {
    if (buffer.size() != t.cell_count()) throw Error("cone tracer", "radiance buffer does not match the cascade texture");
    VoxelConeView view;
    view.anchor_ = Vec3(t.config().anchor);
    view.nested_ = true;
    const int R = t.resolution();
    for (int k = 0; k < t.levels(); ++k) {
        ConeLevel l;
        l.data = buffer.data() + t.index(0, k, UVec3(0));
        l.face_stride = size_t(R);
        l.row_stride = t.width();
        l.slice_stride = t.width() * t.height();
        l.origin = t.origin(k);
        l.size = R;
        l.texel_base = IVec3(0);
        l.wrap_mask = R - 1;
        l.voxel_size = float(t.voxel_size(k));
        l.inv_voxel_size = float(1.0 / t.voxel_size(k));
        view.levels_.push_back(l);
    }
    return view;
}

VoxelConeView VoxelConeView::dense(const DenseMipTexture& t, const std::vector<std::vector<Vec4>>& buffer) {
    if (int(buffer.size()) != t.level_count()) throw Error("cone tracer", "radiance buffer does not match the mip chain");
    VoxelConeView view;
    view.anchor_ = Vec3(t.config().anchor);
    view.nested_ = false;
    for (int k = 0; k < t.level_count(); ++k) {
        const size_t r = size_t(t.resolution(k));
        ConeLevel l;
        l.data = buffer[size_t(k)].data();
        l.face_stride = r * r * r;
        l.row_stride = r;
        l.slice_stride = r * r;
        l.origin = IVec3(0);
        l.size = int(r);
        l.texel_base = IVec3(0);
        l.wrap_mask = -1;
        l.voxel_size = float(t.voxel_size(k));
        l.inv_voxel_size = float(1.0 / t.voxel_size(k));
        view.levels_.push_back(l);
    }
    return view;
}

int VoxelConeView::finest_level_containing(const Vec3& p, float margin) const {
    const int n = nested_ ? level_count() : std::min(level_count(), 1);
    for (int k = 0; k < n; ++k) {
        const ConeLevel& l = levels_[size_t(k)];
        Vec3 q = (p - anchor_) * l.inv_voxel_size - Vec3(l.origin);
        const float hi = float(l.size) - margin;
        if (q.x >= margin && q.y >= margin && q.z >= margin && q.x < hi && q.y < hi && q.z < hi) return k;
    }
    return -1;
}

Vec4 VoxelConeView::sample_level(int level, const Vec3& p, const FaceWeights& faces, const Vec4* plane) const {
    const ConeLevel& l = levels_[size_t(level)];
    Vec3 q = (p - anchor_) * l.inv_voxel_size;
    const Vec3 lo = Vec3(l.origin) + Vec3(0.5f), hi = Vec3(l.origin + IVec3(l.size)) - Vec3(0.5f);
    q = glm::clamp(q, lo, hi) - Vec3(0.5f);
    const Vec3 fl = glm::floor(q);
    const Vec3 t = q - fl;
    IVec3 i0(int(fl.x), int(fl.y), int(fl.z));
    IVec3 i1 = glm::min(i0 + IVec3(1), l.origin + IVec3(l.size - 1));
    const IVec3 a = (i0 - l.texel_base) & IVec3(l.wrap_mask);
    const IVec3 b = (i1 - l.texel_base) & IVec3(l.wrap_mask);
    const size_t x[2] = {size_t(a.x), size_t(b.x)};
    const size_t y[2] = {size_t(a.y) * l.row_stride, size_t(b.y) * l.row_stride};
    const size_t z[2] = {size_t(a.z) * l.slice_stride, size_t(b.z) * l.slice_stride};
    const float wx[2] = {1.0f - t.x, t.x}, wy[2] = {1.0f - t.y, t.y}, wz[2] = {1.0f - t.z, t.z};
    // Clip plane: voxels entirely behind it are empty; voxels it cuts hold the cone's own
    // surface, so their faces turned away from the plane (the surface's back side, seen
    // only through the wide trilinear footprint of a coarse level) are skipped.
    float keep_back[8] = {1, 1, 1, 1, 1, 1, 1, 1}, keep_front[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    bool face_front[3] = {true, true, true};
    if (plane) {
        const Vec3 n(*plane);
        // A hair more than half a voxel, so a surface lying on a voxel face counts as cut.
        const float half = 0.501f * l.voxel_size * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z));
        const IVec3 i[2] = {i0, i1};
        float sx[2], sy[2], sz[2];
        for (int k = 0; k < 2; ++k) {
            sx[k] = n.x * (anchor_.x + (float(i[k].x) + 0.5f) * l.voxel_size);
            sy[k] = n.y * (anchor_.y + (float(i[k].y) + 0.5f) * l.voxel_size);
            sz[k] = n.z * (anchor_.z + (float(i[k].z) + 0.5f) * l.voxel_size);
        }
        for (int c = 0; c < 8; ++c) {
            const float s = sx[c & 1] + sy[(c >> 1) & 1] + sz[c >> 2] - plane->w;
            if (s + half <= 0.0f) keep_back[c] = keep_front[c] = 0.0f;  // behind
            else if (s - half <= 0.0f) keep_back[c] = 0.0f;              // cut
        }
        for (int i = 0; i < 3; ++i) face_front[i] = glm::dot(face_direction(faces.face[size_t(i)]), n) >= -1e-6f;
    }
    Vec4 sum(0.0f);
    for (int i = 0; i < 3; ++i) {
        const float fw = faces.weight[size_t(i)];
        if (fw <= 0.0f) continue;
        const Vec4* base = l.data + size_t(faces.face[size_t(i)]) * l.face_stride;
        const float* keep = face_front[i] ? keep_front : keep_back;
        Vec4 s(0.0f);
        for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy) {
                const Vec4* row = base + z[dz] + y[dy];
                const float w = wz[dz] * wy[dy];
                const int c = 2 * dy + 4 * dz;
                s += (w * wx[0] * keep[c]) * row[x[0]] + (w * wx[1] * keep[c + 1]) * row[x[1]];
            }
        sum += fw * s;
    }
    return sum;
}

ConeResult trace_cone(const VoxelConeView& view, const Cone& cone, const ConeOptions& options) {
    ConeResult r;
    const int n = view.level_count();
    if (n == 0) return r;
    const float w0 = view.base_voxel_size();
    const FaceWeights faces = faces_seen_along(cone.direction);
    float dist = options.start;
    while (dist < options.max_distance) {
        const Vec3 p = cone.origin + dist * cone.direction;
        const int finest = view.finest_level_containing(p, 1.0f);
        if (finest < 0) break;  // left the structure
        const float diameter = std::max(2.0f * cone.tan_half_angle * dist, w0);
        if (!options.bounds.empty()) {
            // The footprint has left the box (convex): nothing further along is met.
            const Vec3 grow(0.5f * diameter + 2.0f * w0);
            const Vec3 lo = options.bounds.min - grow, hi = options.bounds.max + grow;
            if (p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z) break;
        }
        const float level = std::min(std::max(cone_level(diameter, w0) + options.lod_bias, float(finest)), float(n - 1));
        const int l0 = int(level);
        const float frac = level - float(l0);
        const Vec4* plane = options.clip ? &options.clip_plane : nullptr;
        Vec4 s = view.sample_level(l0, p, faces, plane);
        if (options.blend_levels && frac > 0.0f && l0 + 1 < n)
            s = glm::mix(s, view.sample_level(l0 + 1, p, faces, plane), frac);
        const float voxel = w0 * std::exp2(level);
        const float step = voxel * options.step;  // the sampled level's voxel: never skips over it
        ++r.samples;
        if (s.a > 1e-6f) {
            const float a = std::min(s.a, 0.9999f);
            const float corrected = options.correct_opacity ? 1.0f - std::pow(1.0f - a, step / voxel) : a;
            const Vec3 c = Vec3(s) * (corrected / s.a);
            const float t = 1.0f - r.opacity;
            r.radiance += t * c;
            const float radius = 0.5f * diameter / w0;
            r.occlusion += (1.0f - r.occlusion) * corrected / (1.0f + options.ao_lambda * radius);
            r.opacity += t * corrected;
            if (r.opacity >= options.opacity_cutoff) break;
        }
        dist += step;
    }
    return r;
}

ConeSet hemisphere_cones(int count) {
    if (count < 1) throw Error("cone tracer", "a cone set needs at least one cone, got " + std::to_string(count));
    ConeSet set;
    const float golden = kPi * (3.0f - std::sqrt(5.0f));
    const float solid_angle = 2.0f * kPi / float(count);
    for (int i = 0; i < count; ++i) {
        float z = 1.0f - (float(i) + 0.5f) / float(count);
        float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
        float phi = golden * float(i);
        set.directions.push_back(Vec3(s * std::cos(phi), s * std::sin(phi), z));
        set.weights.push_back(solid_angle);
        set.cosines.push_back(z);
    }
    // A cone of solid angle Ω = 2π(1 − cos β).
    float cos_beta = 1.0f - solid_angle / (2.0f * kPi);
    float sin_beta = std::sqrt(std::max(0.0f, 1.0f - cos_beta * cos_beta));
    set.tan_half_angle = cos_beta > 0.25f ? sin_beta / cos_beta : 4.0f;  // one or two cones: very wide
    return set;
}

float phong_cone_tan(float exponent) {
    const float min_angle = 0.5f * kPi / 180.0f, max_angle = 0.25f * kPi;
    float angle = max_angle;
    if (exponent > 0.0f) angle = std::acos(std::pow(0.5f, 1.0f / exponent));
    return std::tan(std::clamp(angle, min_angle, max_angle));
}

}  // namespace gilab
