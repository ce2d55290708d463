#include "techniques/photon_mapping/tile_share.hpp"

#include <optional>
#include "core/util/error.hpp"

namespace gilab {

const char* to_string(TileShare mode) {
    switch (mode) {
        case TileShare::Paper: return "paper";
        case TileShare::CellGroups: return "cell_groups";
        default: return "off";
    }
}

TileShare parse_tile_share(const nlohmann::json& value, const std::string& where) {
    if (value.is_boolean()) return value.get<bool>() ? TileShare::CellGroups : TileShare::Off;
    if (value.is_string()) {
        const std::string name = value.get<std::string>();
        if (name == "off") return TileShare::Off;
        if (name == "paper") return TileShare::Paper;
        if (name == "cell_groups") return TileShare::CellGroups;
    }
    throw Error(where, "setting 'tile_shared' must be 'off', 'paper' or 'cell_groups' (or a boolean: false = off, "
                       "true = cell_groups), got " + value.dump());
}

void gather_tile_paper(const PhotonGatherer& gatherer, std::span<const GatherPoint* const> points,
                       std::span<PhotonEstimate> out, GatherScratch& scratch, PhotonQueryStats& stats,
                       TileShareCounts& counts) {
    // Algorithm 1, lines 5–10: every thread hashes its hit; one differing cell clears the flag.
    std::optional<glm::ivec3> cell;
    bool one_cell = true;
    size_t hits = 0;
    for (const GatherPoint* p : points) {
        if (!p) continue;
        const glm::ivec3 c = gatherer.cell_of(p->position);
        if (!cell) cell = c;
        one_cell = one_cell && c == *cell;
        ++hits;
    }
    if (hits == 0) return;
    if (!one_cell) {
        ++counts.tiles_mixed;
        for (size_t i = 0; i < points.size(); ++i)
            if (points[i]) out[i] = gatherer.estimate_parts(*points[i], scratch, stats);
        return;
    }
    ++counts.tiles_qualified;
    ++counts.groups;
    counts.grouped_hits += hits;
    thread_local std::vector<const GatherPoint*> hit_points;
    thread_local std::vector<PhotonEstimate> hit_out;
    hit_points.clear();
    for (const GatherPoint* p : points)
        if (p) hit_points.push_back(p);
    hit_out.resize(hits);
    gatherer.estimate_group(*cell, hit_points, hit_out, scratch, stats);
    for (size_t i = 0, k = 0; i < points.size(); ++i)
        if (points[i]) out[i] = hit_out[k++];
}

void gather_cell_groups(const PhotonGatherer& gatherer, std::span<const uint64_t> keys,
                        std::span<const GatherPoint* const> points, std::span<PhotonEstimate> out,
                        GatherScratch& scratch, PhotonQueryStats& stats, TileShareCounts& counts) {
    const size_t n = points.size();
    for (size_t i = 0; i < n;) {
        size_t j = i + 1;
        if (keys[i] < PhotonGatherer::kUngrouped)
            while (j < n && keys[j] == keys[i]) ++j;
        if (j - i >= 2) {
            gatherer.estimate_group(gatherer.cell_of(points[i]->position), points.subspan(i, j - i),
                                    out.subspan(i, j - i), scratch, stats);
            ++counts.groups;
            counts.grouped_hits += j - i;
        } else {
            out[i] = gatherer.estimate_parts(*points[i], scratch, stats);
        }
        i = j;
    }
}

}  // namespace gilab
