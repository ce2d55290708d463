#pragma once
// Tile-shared gather: hits whose photon neighbourhoods coincide fetch that neighbourhood
// once into a local buffer and are all evaluated against it (the CPU form of P1's
// Algorithm 1, whose GPU thread groups stage the photons in shared memory). Every hit
// gets the same value, bit for bit, as its own gather (PhotonGatherer::estimate_group).
//
// Two ways to form the groups:
// * Paper (Algorithm 1): the screen is cut into square tiles (one thread group each). A
//   tile shares only if every hit in it lies in one hash cell; otherwise each of its
//   hits gathers on its own. Pixels without a gather point (the ray missed) do not break
//   the condition: on the GPU their threads still help load the photons. A tile without
//   any hit is neither qualified nor mixed.
// * Cell groups (relaxed, ours): hits sorted by cell; every run of two or more hits in
//   one in-grid cell shares its fetch, whatever screen tile they come from.
#include <cstdint>
#include <span>
#include <string>
#include <nlohmann/json.hpp>
#include "techniques/photon_mapping/photon_gather.hpp"

namespace gilab {

enum class TileShare { Off, Paper, CellGroups };

const char* to_string(TileShare mode);  // "off", "paper", "cell_groups"
// "off" | "paper" | "cell_groups"; the JSON booleans of older settings files mean
// false → off, true → cell_groups. Throws Error naming `where` otherwise.
TileShare parse_tile_share(const nlohmann::json& value, const std::string& where);

struct TileShareCounts {
    uint64_t groups = 0;           // shared fetches
    uint64_t grouped_hits = 0;     // hits evaluated against a shared fetch
    uint64_t tiles_qualified = 0;  // paper: tiles whose hits all lie in one cell
    uint64_t tiles_mixed = 0;      // paper: tiles whose hits span two or more cells

    void merge(const TileShareCounts& o) {
        groups += o.groups;
        grouped_hits += o.grouped_hits;
        tiles_qualified += o.tiles_qualified;
        tiles_mixed += o.tiles_mixed;
    }
};

// Paper mode for one screen tile: points[i] is the gather point of the tile's i-th
// pixel, or null if it has none; out[i] is written for every non-null point.
void gather_tile_paper(const PhotonGatherer& gatherer, std::span<const GatherPoint* const> points,
                       std::span<PhotonEstimate> out, GatherScratch& scratch, PhotonQueryStats& stats,
                       TileShareCounts& counts);

// Cell groups over points sorted by keys[i] = PhotonGatherer::sort_key (equal in-grid
// keys ⇔ same cell); a run of ≥ 2 equal keys shares one fetch, the rest gather alone.
void gather_cell_groups(const PhotonGatherer& gatherer, std::span<const uint64_t> keys,
                        std::span<const GatherPoint* const> points, std::span<PhotonEstimate> out,
                        GatherScratch& scratch, PhotonQueryStats& stats, TileShareCounts& counts);

}  // namespace gilab
