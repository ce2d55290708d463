#pragma once
// Random photon sets and brute-force references shared by the photon-map tests.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>
#include "accel/photon/photon_map.hpp"

namespace gilab::test {

// Photons in the unit cube: half uniform in the volume, half on a few planes (like
// photons on walls), with duplicated positions and some on exact multiples of 1/16.
inline std::vector<Photon> random_photons(size_t n, uint32_t seed) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<Photon> photons;
    photons.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        Photon p;
        switch (i % 4) {
            case 0:
            case 1: p.position = Vec3(u(gen), u(gen), u(gen)); break;
            case 2: p.position = Vec3(u(gen), 0.0f, u(gen)); break;  // a floor
            default: p.position = Vec3(std::floor(u(gen) * 16) / 16, u(gen), 1.0f); break;
        }
        if (i % 97 == 5 && !photons.empty()) p.position = photons[i / 2].position;  // duplicates
        Vec3 w = glm::normalize(Vec3(u(gen) - 0.5f, u(gen), u(gen) - 0.5f) + Vec3(0, 0.1f, 0));
        p.wi = PackedDirection::pack(w);
        p.normal = PackedDirection::pack(Vec3(0, 1, 0));
        p.power = Vec3(u(gen), u(gen), u(gen));
        photons.push_back(p);
    }
    return photons;
}

// Indices (into `photons`) within r of x, ascending.
inline std::vector<uint32_t> brute_radius(const std::vector<Photon>& photons, const Vec3& x, float r) {
    std::vector<uint32_t> out;
    for (uint32_t i = 0; i < photons.size(); ++i) {
        const Vec3& p = photons[i].position;
        if (photon_distance2(x, p.x, p.y, p.z) <= r * r) out.push_back(i);
    }
    return out;
}

// Original indices a structure reports for a radius query, ascending.
inline std::vector<uint32_t> map_radius(const PhotonMap& map, const Vec3& x, float r, PhotonQueryStats* stats = nullptr) {
    std::vector<uint32_t> out;
    PhotonQueryStats local;
    map.radius_query(x, r, [&](uint32_t i, float d2) {
        // An index past the end would be a read outside the structure.
        out.push_back(i < map.size() ? map.original_index(i) : 0xffffffffu);
    }, stats ? *stats : local);
    std::sort(out.begin(), out.end());
    return out;
}

struct KnnAnswer {
    std::vector<float> distances2;     // ascending
    std::vector<uint32_t> indices;     // ascending original indices
    bool tie_at_boundary = false;      // the k-th and (k+1)-th distances are equal
};

inline KnnAnswer brute_knn(const std::vector<Photon>& photons, const Vec3& x, size_t k, float r) {
    std::vector<std::pair<float, uint32_t>> c;
    for (uint32_t i = 0; i < photons.size(); ++i) {
        const Vec3& p = photons[i].position;
        float d2 = photon_distance2(x, p.x, p.y, p.z);
        if (d2 <= r * r) c.push_back({d2, i});
    }
    std::sort(c.begin(), c.end());
    KnnAnswer a;
    a.tie_at_boundary = c.size() > k && k > 0 && c[k].first == c[k - 1].first;
    c.resize(std::min(c.size(), k));
    for (auto& [d2, i] : c) {
        a.distances2.push_back(d2);
        a.indices.push_back(i);
    }
    std::sort(a.indices.begin(), a.indices.end());
    return a;
}

inline KnnAnswer map_knn(const PhotonMap& map, const Vec3& x, size_t k, float r) {
    NeighborHeap heap;
    PhotonQueryStats stats;
    map.knn_query(x, k, r, heap, stats);
    KnnAnswer a;
    for (const PhotonNeighbor& n : heap.items()) {
        a.distances2.push_back(n.distance2);
        a.indices.push_back(n.index < map.size() ? map.original_index(n.index) : 0xffffffffu);
    }
    std::sort(a.distances2.begin(), a.distances2.end());
    std::sort(a.indices.begin(), a.indices.end());
    return a;
}

// Query points: random inside and around the cube, photon positions, exact grid-line
// points, far outside, and on the bounding box faces.
inline std::vector<Vec3> query_points(const std::vector<Photon>& photons, float cell, uint32_t seed, size_t n) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<float> u(-0.3f, 1.3f);
    std::vector<Vec3> q;
    for (size_t i = 0; i < n; ++i) q.push_back(Vec3(u(gen), u(gen), u(gen)));
    for (size_t i = 0; i < photons.size() && q.size() < 2 * n; i += photons.size() / n + 1) q.push_back(photons[i].position);
    for (int i = 0; i < 8; ++i) q.push_back(Vec3(float(i) * cell, float(i % 3) * cell, 0.5f));
    q.push_back(Vec3(0.0f));
    q.push_back(Vec3(1.0f));
    q.push_back(Vec3(-5.0f, 0.5f, 0.5f));
    q.push_back(Vec3(0.5f, 100.0f, 0.5f));
    q.push_back(Vec3(1e30f, -1e30f, 0.0f));
    return q;
}

}  // namespace gilab::test
