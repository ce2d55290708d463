#include "core/io/polygon_triangulation.hpp"

namespace gilab {

namespace {

using P2 = glm::dvec2;

double cross2(const P2& a, const P2& b, const P2& c) { return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x); }

// Pathological concave faces cost n × (reflex corners) per clipped ear; beyond this the
// face is fanned instead (and reported) so a hostile file cannot stall loading.
constexpr double kMaxEarClipWork = 5e7;

}  // namespace

PolygonTriangulation triangulate_polygon(std::span<const Vec3> corners) {
    const size_t n = corners.size();
    PolygonTriangulation out;
    if (n < 3) return out;
    out.triangles.reserve(n - 2);
    auto fan = [&](uint32_t first, const std::vector<uint32_t>& next, size_t count) {
        uint32_t b = next[first];
        for (size_t k = 2; k < count; ++k) {
            const uint32_t c = next[b];
            out.triangles.push_back({first, b, c});
            b = c;
        }
    };
    std::vector<uint32_t> prev(n), next(n);
    for (size_t i = 0; i < n; ++i) {
        prev[i] = uint32_t((i + n - 1) % n);
        next[i] = uint32_t((i + 1) % n);
    }
    if (n == 3) {
        out.triangles.push_back({0, 1, 2});
        return out;
    }

    // Best-fit plane: Newell's normal through the centroid, in double precision.
    DVec3 centroid(0), lo(corners[0]), hi(corners[0]);
    for (const Vec3& c : corners) {
        centroid += DVec3(c);
        lo = glm::min(lo, DVec3(c));
        hi = glm::max(hi, DVec3(c));
    }
    centroid /= double(n);
    DVec3 normal(0);
    for (size_t i = 0; i < n; ++i) {
        const DVec3 a = DVec3(corners[i]) - centroid, b = DVec3(corners[(i + 1) % n]) - centroid;
        normal += DVec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    const double size = glm::length(hi - lo), area2 = glm::length(normal);
    if (!(size > 0) || !(area2 > 1e-300) || !std::isfinite(area2)) {  // degenerate: every triangle has zero area
        fan(0, next, n);
        return out;
    }
    const DVec3 nrm = normal / area2;
    double off_plane = 0;
    for (const Vec3& c : corners) off_plane = std::max(off_plane, std::abs(glm::dot(DVec3(c) - centroid, nrm)));
    out.non_planarity = float(off_plane / size);

    // 2D coordinates in the plane, oriented so the polygon runs counter-clockwise.
    const DVec3 axis = std::abs(nrm.x) < 0.5 ? DVec3(1, 0, 0) : DVec3(0, 1, 0);
    const DVec3 u = glm::normalize(glm::cross(nrm, axis)), v = glm::cross(nrm, u);
    std::vector<P2> p(n);
    for (size_t i = 0; i < n; ++i) {
        const DVec3 d = DVec3(corners[i]) - centroid;
        p[i] = P2(glm::dot(d, u), glm::dot(d, v));
    }
    const double eps = 1e-12 * size * size;
    auto turn = [&](uint32_t i) { return cross2(p[prev[i]], p[i], p[next[i]]); };
    // Reflex and collinear corners: never ear tips, and the only corners that can lie in
    // a candidate ear (a collinear one on its diagonal would leave a zero-area sliver).
    std::vector<uint32_t> reflex;
    for (uint32_t i = 0; i < n; ++i)
        if (turn(i) <= eps) reflex.push_back(i);
    // Convex: the fan from corner 0 is what ear clipping from corner 1 would give.
    if (reflex.empty()) {
        fan(0, next, n);
        return out;
    }
    if (double(n) * double(reflex.size()) > kMaxEarClipWork) {
        out.fallback = true;
        fan(0, next, n);
        return out;
    }

    std::vector<bool> removed(n, false);
    auto inside = [&](const P2& q, const P2& a, const P2& b, const P2& c) {
        return cross2(a, b, q) >= -eps && cross2(b, c, q) >= -eps && cross2(c, a, q) >= -eps;
    };
    // An ear: a strictly convex corner whose triangle holds no reflex or collinear corner
    // (only those can lie inside it in a simple polygon).
    auto is_ear = [&](uint32_t i) {
        const uint32_t a = prev[i], c = next[i];
        if (turn(i) <= eps) return false;
        for (uint32_t j : reflex) {
            if (removed[j] || j == a || j == i || j == c) continue;
            if (p[j] == p[a] || p[j] == p[i] || p[j] == p[c]) continue;  // a corner repeated (bridged hole)
            if (turn(j) > eps) continue;                                 // has become convex
            if (inside(p[j], p[a], p[i], p[c])) return false;
        }
        return true;
    };
    size_t remaining = n;
    uint32_t i = 1;
    size_t misses = 0;
    while (remaining > 3) {
        if (is_ear(i)) {
            out.triangles.push_back({prev[i], i, next[i]});
            const uint32_t a = prev[i], c = next[i];
            next[a] = c;
            prev[c] = a;
            removed[i] = true;
            --remaining;
            i = c;
            misses = 0;
            continue;
        }
        i = next[i];
        if (++misses > remaining) {  // no ear in a full turn: self-intersecting projection
            out.fallback = true;
            fan(i, next, remaining);
            return out;
        }
    }
    out.triangles.push_back({prev[i], i, next[i]});
    return out;
}

void TriangulationTally::add_notes(const std::string& file, std::vector<std::string>& notes) const {
    if (non_planar)
        notes.push_back(file + ": " + std::to_string(non_planar) +
                        " faces are not planar; triangulated in their best-fit planes");
    if (fanned)
        notes.push_back(file + ": " + std::to_string(fanned) +
                        " faces intersect themselves (or are too large to cut into ears); fanned from their first corner");
}

}  // namespace gilab
