#pragma once
// Triangulation of one polygon face of a mesh file (OBJ, PLY, OFF). The corners are
// projected onto the polygon's best-fit plane (Newell's normal); a convex polygon is
// fanned from its first corner, a concave one is cut by ear clipping, so the triangles
// never overlap and all keep the polygon's winding.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>
#include "core/util/math.hpp"

namespace gilab {

struct PolygonTriangulation {
    std::vector<std::array<uint32_t, 3>> triangles;  // corner indices, 0..n-1
    // Largest distance of a corner from the best-fit plane over the polygon's size
    // (its bounding-box diagonal): 0 for a planar polygon.
    float non_planarity = 0;
    // The projected polygon intersects itself or is degenerate, so ear clipping stopped
    // and the rest was fanned.
    bool fallback = false;
};

// A face is reported as non-planar above this relative deviation.
inline constexpr float kNonPlanarTolerance = 0.01f;

// Triangulates corners c[0..n-1] (n ≥ 3) in order: n - 2 triangles.
PolygonTriangulation triangulate_polygon(std::span<const Vec3> corners);

// What the triangulations of one file's faces had to report, as a loader's notes.
struct TriangulationTally {
    size_t non_planar = 0;  // faces beyond kNonPlanarTolerance
    size_t fanned = 0;      // faces that fell back to a fan
    void count(const PolygonTriangulation& t) {
        non_planar += t.non_planarity > kNonPlanarTolerance;
        fanned += t.fallback;
    }
    // Appends one note per kind of face found, naming `file`.
    void add_notes(const std::string& file, std::vector<std::string>& notes) const;
};

}  // namespace gilab
