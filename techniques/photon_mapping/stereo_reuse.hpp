#pragma once
// Stereo reuse (P1 §3.3): the left eye's hits fill right-eye pixels. For every left hit x
// a visibility ray runs from x to the right eye; if it is unblocked, x is projected with
// the right eye's own asymmetric projection (r_clip = M_proj · M_view · x, pixel =
// floor(0.5 (ndc + 1) · size), y flipped for top-row-first images), bounds-checked, and
// claims that right pixel. The right eye then shades only the pixels nobody claimed.
//
// Where the paper is silent or wrong:
// * Several left hits can land in one right pixel (at silhouettes, or where the right eye
//   sees a surface more obliquely). The first writer would be arbitrary — and with
//   threads, nondeterministic — so a claim is an atomic minimum over (distance to the
//   right eye, left pixel index): the hit nearest the right eye wins, ties by index.
//   `depth_conflicts` counts the right pixels whose candidates lay on different surfaces
//   (depths more than 1 % apart): the pixels a first-writer claim could get wrong.
// * The two eyes can see opposite sides of a surface (its plane passes between them).
//   The other side has its own normal, emission and photons, so such hits never claim.
// * A left hit projects to an arbitrary point inside its right pixel, not the pixel's
//   centre. Nearest mode (the paper's) accepts that; strict mode traces the right pixel's
//   own primary ray and reuses only when the claiming hit lies on the same triangle
//   group (same material, normals within ~8°) within `tolerance` pixel footprints of it.
// * Forward reprojection leaves one-pixel cracks where the right eye sees a surface less
//   obliquely than the left (its image of the surface is magnified). With `fill`, an
//   unclaimed pixel whose own hit lies within 1.5 pixel footprints of a neighbour's
//   claiming hit on the same surface reuses that hit (nearest mode only): the error is
//   of the same kind as a nearest-pixel claim's, and the pixel skips its gather.
#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>
#include "core/scene/camera.hpp"
#include "core/render/ray_tracer.hpp"
#include "techniques/photon_mapping/primary_hit.hpp"

namespace gilab {

enum class StereoMatch { Nearest, Strict };

struct StereoReuseSettings {
    bool enabled = false;
    StereoMatch match = StereoMatch::Nearest;
    float tolerance = 0.5f;   // strict mode: allowed distance in right-eye pixel footprints
    bool reshade = true;      // re-evaluate the glossy lobe for the right eye's direction
    bool fill = false;        // fill cracks from neighbouring claims (nearest mode)
};

// Footprints within which a crack takes a neighbour's claiming hit.
inline constexpr float kCrackFillTolerance = 1.5f;

const char* to_string(StereoMatch match);

// The paper's reprojection: world point → right-eye pixel through the eye's view and
// OpenGL projection matrices and the NDC → pixel index. nullopt behind the eye or
// outside the image.
class Reprojector {
public:
    explicit Reprojector(const EyeCamera& eye);
    std::optional<glm::ivec2> pixel(const Vec3& world_point) const;

private:
    const EyeCamera* eye_;
    Mat4 view_projection_;
};

struct StereoClaimStats {
    uint64_t left_hits = 0;        // valid left hits considered
    uint64_t back_side = 0;        // the right eye sees the other side of the surface
    uint64_t outside = 0;          // projected behind the right eye or off its image
    uint64_t occluded = 0;         // visibility ray to the right eye blocked
    uint64_t candidates = 0;       // hits that took part in a claim
    uint64_t claimed_pixels = 0;   // right pixels with at least one candidate
    uint64_t depth_conflicts = 0;  // claimed pixels whose candidates were on different surfaces

    void merge(const StereoClaimStats& o) {
        left_hits += o.left_hits, back_side += o.back_side, outside += o.outside, occluded += o.occluded;
        candidates += o.candidates, claimed_pixels += o.claimed_pixels, depth_conflicts += o.depth_conflicts;
    }
};

class StereoClaims {
public:
    static constexpr uint32_t kNone = 0xffffffffu;

    // Runs the claim pass over the left eye's hits (one per left pixel, row-major).
    StereoClaims(std::span<const PrimaryHit> left_hits, const EyeCamera& left, const EyeCamera& right,
                 const RayTracer& tracer);

    // Left pixel whose hit claimed this right pixel, or kNone.
    uint32_t source(size_t right_pixel) const { return source_[right_pixel]; }
    const StereoClaimStats& stats() const { return stats_; }

private:
    std::vector<uint32_t> source_;
    StereoClaimStats stats_;
};

// Strict mode's test: does the right pixel's own hit show the same surface point as the
// claiming left hit, within `tolerance` pixel footprints?
bool same_surface_point(const PrimaryHit& left_hit, const PrimaryHit& right_hit, const EyeCamera& right,
                        float tolerance);

// Crack filling: of the left hits claiming the 8 neighbours of right pixel (x, y), the one
// nearest to the pixel's own hit among those on the same surface within
// kCrackFillTolerance footprints (same_surface_point), or kNone.
uint32_t crack_fill_source(const StereoClaims& claims, std::span<const PrimaryHit> left_hits,
                           const PrimaryHit& own_hit, const EyeCamera& right, int x, int y);

}  // namespace gilab
