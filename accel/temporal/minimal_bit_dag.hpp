#pragma once
// The laid-out multi-frame DAG re-encoded with minimal-bit pointers (after Kämpe et al.
// 2016: "minimizing the number of bits per pointer and encoding the result into a dense
// bitstream"). Level by level, a node is its 8-bit child mask followed by one w_l-bit
// pointer per child. The single leaf node takes no bits: the level above it needs no
// pointers (w = 0), so a bottom node is its mask alone.
//
// Two ways to address a child, both reported:
//  * BitOffset (traversable from the stream alone): the child's bit offset within its
//    level, w_l = ceil(log2 B_{l+1}) with B the level's total bits (computed bottom-up);
//  * NodeIndex (a lower bound): the child's index within its level, w_l =
//    ceil(log2 N_{l+1}); traversal needs an index→offset table, rebuilt here by a scan.
// A level whose next level holds one node gets w = 0. On top: a root table of F fields
// (value + 1, 0 = empty frame, when some frame is empty) and a 9-byte header per stored
// level (8-byte start offset, 1-byte width).
#include <cstdint>
#include <vector>
#include "accel/temporal/laid_out_multi_frame_dag.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {

enum class PointerAddressing { BitOffset, NodeIndex };

class MinimalBitDag {
public:
    const VoxelGrid& grid() const { return grid_; }
    int depth() const { return depth_; }
    size_t frame_count() const { return frame_count_; }
    PointerAddressing addressing() const { return addressing_; }

    int pointer_bits(int level) const { return widths_.at(level); }  // w_l, levels 0..depth-1
    int root_bits() const { return root_bits_; }                     // per root table entry
    uint64_t level_bits(int level) const;                            // B_l (0 for the leaf level)
    uint64_t stream_bits() const { return stream_bits_; }
    static constexpr size_t kHeaderBytesPerLevel = 9;
    // ceil(stream bits / 8) + ceil(root table bits / 8) + the level headers.
    size_t bytes() const;

    std::vector<uint64_t> decode(size_t frame) const;  // Morton codes, ascending

private:
    friend MinimalBitDag encode_minimal_bits(const LaidOutMultiFrameDag& dag, PointerAddressing addressing);
    // Bit offset of every node of `level`, in order, found by parsing the stream.
    std::vector<uint64_t> parse_level(int level) const;

    VoxelGrid grid_;
    int depth_ = 0;
    size_t frame_count_ = 0;
    PointerAddressing addressing_ = PointerAddressing::BitOffset;
    std::vector<uint64_t> stream_;
    uint64_t stream_bits_ = 0;
    std::vector<uint64_t> level_start_;  // bit offset where each level starts; depth+2 entries
    std::vector<int> widths_;            // pointer width per level; depth entries
    std::vector<uint64_t> root_table_;
    int root_bits_ = 0;
    bool root_has_empty_marker_ = false;
};

MinimalBitDag encode_minimal_bits(const LaidOutMultiFrameDag& dag, PointerAddressing addressing);

}  // namespace gilab
