#include "accel/photon/hash_grid_photon_map.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include "core/util/error.hpp"

namespace gilab {

const char* to_string(HashQuery mode) { return mode == HashQuery::Cells27 ? "cells27" : "runs9"; }

HashQuery parse_hash_query(const std::string& name, const std::string& where) {
    if (name == "cells27") return HashQuery::Cells27;
    if (name == "runs9") return HashQuery::Runs9;
    throw Error(where, "unknown hash_query '" + name + "' (expected cells27 or runs9)");
}

glm::ivec3 HashGridPhotonMap::cell_of(const Vec3& x) const {
    constexpr double kLimit = double(1 << 30);
    glm::ivec3 c;
    for (int a = 0; a < 3; ++a) {
        double v = std::floor((double(x[a]) - double(origin_[a])) * inv_cell_);
        // Comparisons are false for NaN: a non-finite point lands far outside the grid.
        c[a] = v >= -kLimit && v <= kLimit ? int(v) : -(1 << 30);
    }
    return c;
}

void HashGridPhotonMap::build_structure(std::vector<Photon> photons, float radius) {
    const char* where = "photon hash grid";
    if (!(radius > 0.0f) || !std::isfinite(radius)) {
        std::ostringstream m;
        m << "radius must be positive and finite, got " << radius;
        throw Error(where, m.str());
    }
    if (photons.size() >= (size_t(1) << 32) - 1) throw Error(where, "too many photons: " + std::to_string(photons.size()));
    Bounds3 box;
    for (size_t i = 0; i < photons.size(); ++i) {
        if (!is_finite(photons[i].position))
            throw Error(where, "photon " + std::to_string(i) + " has a non-finite position");
        box.extend(photons[i].position);
    }
    cell_ = radius * (1.0f + 0x1p-16f);
    inv_cell_ = 1.0 / double(cell_);
    start_.clear();
    photons_.clear();
    original_.clear();
    soa_.clear();
    size_ = glm::ivec3(0);
    origin_ = Vec3(0);
    if (photons.empty()) return;

    // One cell of padding below the minimum (nudged down if rounding ate into it) and,
    // via the size, at least one above the maximum.
    double cells = 1;
    for (int a = 0; a < 3; ++a) {
        float o = box.min[a] - cell_;
        while (std::floor((double(box.min[a]) - double(o)) * inv_cell_) < 1.0) o = std::nextafter(o, -kInfinity);
        origin_[a] = o;
        double top = std::floor((double(box.max[a]) - double(o)) * inv_cell_);
        cells *= top + 2.0;
        size_[a] = int(std::min(top + 2.0, double(1 << 30)));
    }
    if (cells > double(max_cells_)) {
        std::ostringstream m;
        m << "radius " << radius << " is too small for the photons' extent (" << box.extent().x << " × "
          << box.extent().y << " × " << box.extent().z << "): the grid would need " << cells
          << " cells, more than the limit of " << max_cells_;
        throw Error(where, m.str());
    }
    const size_t cell_count = size_t(cells);

    // Counting sort by cell: stable, so equal cells keep the input order.
    std::vector<uint32_t> key(photons.size());
    start_.assign(cell_count + 1, 0);
    for (size_t i = 0; i < photons.size(); ++i) {
        glm::ivec3 c = glm::clamp(cell_of(photons[i].position), glm::ivec3(0), size_ - 1);
        key[i] = hash(c);
        ++start_[key[i] + 1];
    }
    for (size_t c = 0; c < cell_count; ++c) start_[c + 1] += start_[c];
    std::vector<uint32_t> cursor(start_.begin(), start_.end() - 1);
    photons_.resize(photons.size());
    original_.resize(photons.size());
    // The first-hit flags only when some photon is a first-hit copy (direct light in the map).
    const bool with_first = std::any_of(photons.begin(), photons.end(), [](const Photon& p) { return p.first_hit(); });
    soa_.resize(photons.size(), with_first);
    for (size_t i = 0; i < photons.size(); ++i) {
        uint32_t slot = cursor[key[i]]++;
        photons_[slot] = photons[i];
        original_[slot] = uint32_t(i);
        soa_.set(slot, photons[i]);
    }

    // Offsets of the 27 neighbours, and of the 9 x-runs (each starting at dx = −1).
    const int gx = size_.x, gxy = size_.x * size_.y;
    int j9 = 0, j27 = 0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
            offsets9_[size_t(j9++)] = dz * gxy + dy * gx - 1;
            for (int dx = -1; dx <= 1; ++dx) offsets27_[size_t(j27++)] = dz * gxy + dy * gx + dx;
        }
}

size_t HashGridPhotonMap::memory_bytes() const {
    return start_.capacity() * sizeof(uint32_t) + photons_.capacity() * sizeof(Photon) +
           original_.capacity() * sizeof(uint32_t) + soa_.memory_bytes();
}

}  // namespace gilab
