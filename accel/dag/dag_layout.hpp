#pragma once
// Lays the unique nodes of per-level DagLevelTables out as one array of 32-bit words,
// top-down from the given roots, in a canonical order: level 0 holds the roots in the
// order given (each once, unless one_root_per_entry), and level l+1 holds the nodes in
// the order they are first referenced while scanning level l in order, children in
// stored order. The order depends only on the DAG's shape, not on the order nodes were
// inserted, so two builds of the same DAG (tiled or not, frames merged at once or one
// by one) give the same words. Nodes that no root reaches are left out, which reclaims them.
//
// A node is its header word followed by its children, each child id turned into the
// word address of that child. Levels at or below `payload_level` are different: their
// "children" words are data (a leaf bitmask, say) copied as they are, and with
// `payload_header == false` the header word is not stored either.
#include <cstdint>
#include <span>
#include <vector>
#include "accel/dag/dag_level_table.hpp"

namespace gilab {

struct DagLayoutOptions {
    int payload_level = -1;        // -1: every level's child words are ids of the level below
    bool payload_header = true;    // store the header word of payload-level nodes
    // Level 0 holds one copy of the root per entry given, repeats included, in the
    // order given (one root per frame even when two frames are identical, P2 §4).
    bool one_root_per_entry = false;
};

struct DagLayout {
    std::vector<uint32_t> words;
    std::vector<uint64_t> level_begin;    // word address where each level starts; levels+1 entries
    std::vector<uint64_t> level_counts;   // nodes laid out per level
    std::vector<uint32_t> root_addresses; // one per root given, in order
    uint64_t pointer_count = 0;           // child pointers stored (payload words excluded)
};

// `what` prefixes errors (the DAG exceeding 32-bit word addresses).
DagLayout lay_out_dag(const std::vector<DagLevelTable>& tables, std::span<const uint32_t> roots,
                      const DagLayoutOptions& options, const char* what);

}  // namespace gilab
