#include "techniques/photon_mapping/stereo_reuse.hpp"

#include <bit>
#include <cmath>
#include "core/render/interaction.hpp"
#include "core/util/parallel.hpp"

namespace gilab {

namespace {

constexpr uint64_t kUnclaimed = ~uint64_t(0);

// Claim key: distance bits above the left pixel index. Non-negative floats order like
// their bit patterns, so the smallest key is the nearest hit (ties: lowest index).
uint64_t claim_key(float distance, uint32_t left_pixel) {
    return (uint64_t(std::bit_cast<uint32_t>(distance)) << 32) | left_pixel;
}

template <typename T>
void atomic_min(std::atomic<T>& a, T v) {
    T cur = a.load(std::memory_order_relaxed);
    while (v < cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
    }
}

template <typename T>
void atomic_max(std::atomic<T>& a, T v) {
    T cur = a.load(std::memory_order_relaxed);
    while (v > cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
    }
}

}  // namespace

const char* to_string(StereoMatch match) { return match == StereoMatch::Strict ? "strict" : "nearest"; }

Reprojector::Reprojector(const EyeCamera& eye)
    // Only x, y and w of the clip position are used, so the depth range is arbitrary.
    : eye_(&eye), view_projection_(eye.projection_matrix(1.0f, 2.0f) * eye.view_matrix()) {}

std::optional<glm::ivec2> Reprojector::pixel(const Vec3& x) const {
    glm::vec4 clip = view_projection_ * glm::vec4(x, 1.0f);
    if (!(clip.w > 0.0f)) return std::nullopt;
    return eye_->pixel_from_ndc(Vec2(clip.x / clip.w, clip.y / clip.w));
}

StereoClaims::StereoClaims(std::span<const PrimaryHit> left_hits, const EyeCamera& left, const EyeCamera& right,
                           const RayTracer& tracer) {
    const size_t right_pixels = size_t(right.width()) * size_t(right.height());
    std::vector<std::atomic<uint64_t>> nearest(right_pixels);
    std::vector<std::atomic<uint32_t>> farthest(right_pixels);
    parallel_for(right_pixels, 1 << 16, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) nearest[i].store(kUnclaimed, std::memory_order_relaxed);
    });
    const Reprojector reproject(right);
    const Vec3 left_eye = left.position(), right_eye = right.position();
    std::atomic<uint64_t> hits{0}, back_side{0}, outside{0}, occluded{0}, candidates{0};

    parallel_for(left_hits.size(), 4096, [&](size_t begin, size_t end) {
        struct Pending {
            uint32_t left_pixel, right_pixel;
            float distance;
        };
        std::vector<Pending> pending;
        std::vector<Ray> rays;
        uint64_t n_hits = 0, n_back = 0, n_out = 0;
        for (size_t i = begin; i < end; ++i) {
            const PrimaryHit& h = left_hits[i];
            if (!h.valid) continue;
            ++n_hits;
            const Vec3& x = h.point.position;
            const Vec3& ng = h.geometric_normal;  // on the left eye's side
            const Vec3 to_right = right_eye - x;
            if (!(glm::dot(ng, to_right) > 0.0f) || !(glm::dot(ng, left_eye - x) > 0.0f)) {
                ++n_back;
                continue;
            }
            std::optional<glm::ivec2> p = reproject.pixel(x);
            if (!p) {
                ++n_out;
                continue;
            }
            const float distance = glm::length(to_right);
            Ray ray;
            float eps = ray_epsilon(x);
            ray.origin = x + eps * ng;
            Vec3 d = right_eye - ray.origin;
            float len = glm::length(d);
            ray.direction = d / len;
            ray.tmax = std::max(0.0f, len - eps);
            rays.push_back(ray);
            pending.push_back({uint32_t(i), uint32_t(size_t(p->y) * size_t(right.width()) + size_t(p->x)), distance});
        }
        std::vector<uint8_t> blocked(rays.size());
        tracer.occluded(rays, blocked);  // one coherent stream: every ray ends at the eye
        uint64_t n_occ = 0, n_cand = 0;
        for (size_t k = 0; k < pending.size(); ++k) {
            if (blocked[k]) {
                ++n_occ;
                continue;
            }
            ++n_cand;
            const Pending& c = pending[k];
            atomic_min(nearest[c.right_pixel], claim_key(c.distance, c.left_pixel));
            atomic_max(farthest[c.right_pixel], std::bit_cast<uint32_t>(c.distance));
        }
        hits += n_hits, back_side += n_back, outside += n_out, occluded += n_occ, candidates += n_cand;
    });

    source_.resize(right_pixels);
    std::atomic<uint64_t> claimed{0}, conflicts{0};
    parallel_for(right_pixels, 1 << 16, [&](size_t begin, size_t end) {
        uint64_t n_claimed = 0, n_conflicts = 0;
        for (size_t i = begin; i < end; ++i) {
            const uint64_t key = nearest[i].load(std::memory_order_relaxed);
            if (key == kUnclaimed) {
                source_[i] = kNone;
                continue;
            }
            source_[i] = uint32_t(key & 0xffffffffu);
            ++n_claimed;
            const float near = std::bit_cast<float>(uint32_t(key >> 32));
            const float far = std::bit_cast<float>(farthest[i].load(std::memory_order_relaxed));
            n_conflicts += far > near * 1.01f;
        }
        claimed += n_claimed, conflicts += n_conflicts;
    });
    stats_ = {hits.load(), back_side.load(), outside.load(), occluded.load(), candidates.load(), claimed.load(),
              conflicts.load()};
}

bool same_surface_point(const PrimaryHit& left_hit, const PrimaryHit& right_hit, const EyeCamera& right,
                        float tolerance) {
    if (!left_hit.valid || !right_hit.valid) return false;
    if (left_hit.point.material != right_hit.point.material) return false;
    if (glm::dot(left_hit.geometric_normal, right_hit.geometric_normal) < 0.99f) return false;
    const FrustumTangents& f = right.fov();
    const float footprint = glm::length(right_hit.point.position - right.position()) * (f.right - f.left) /
                            float(right.width());
    return glm::length(left_hit.point.position - right_hit.point.position) <= tolerance * footprint;
}

uint32_t crack_fill_source(const StereoClaims& claims, std::span<const PrimaryHit> left_hits,
                           const PrimaryHit& own_hit, const EyeCamera& right, int x, int y) {
    uint32_t best = StereoClaims::kNone;
    float best_distance = kInfinity;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= right.width() || ny >= right.height()) continue;
            const uint32_t source = claims.source(size_t(ny) * size_t(right.width()) + size_t(nx));
            if (source == StereoClaims::kNone) continue;
            const PrimaryHit& candidate = left_hits[source];
            if (!same_surface_point(candidate, own_hit, right, kCrackFillTolerance)) continue;
            const float d = glm::length(candidate.point.position - own_hit.point.position);
            if (d < best_distance) best = source, best_distance = d;
        }
    return best;
}

}  // namespace gilab
