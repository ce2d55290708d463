#include "accel/temporal/minimal_bit_dag.hpp"
#include <algorithm>
#include <string>
#include "accel/dag/bit_stream.hpp"
#include "accel/dag/child_mask.hpp"
#include "core/util/error.hpp"

namespace gilab {
namespace {
constexpr const char* kWhat = "minimal-bit DAG";
}  // namespace

MinimalBitDag encode_minimal_bits(const LaidOutMultiFrameDag& dag, PointerAddressing addressing) {
    MinimalBitDag out;
    out.grid_ = dag.grid();
    out.depth_ = dag.depth();
    out.frame_count_ = dag.frame_count();
    out.addressing_ = addressing;
    const int depth = dag.depth();
    const auto words = dag.words();
    const bool by_offset = addressing == PointerAddressing::BitOffset;

    // Nodes of each level in layout order, and each node's index within its level.
    std::vector<std::vector<uint32_t>> nodes(depth + 1);
    std::vector<uint32_t> index_of(words.size(), 0);
    if (!words.empty())
        for (int l = 0; l <= depth; ++l)
            for (uint64_t a = dag.level_begin()[l]; a < dag.level_begin()[l + 1];
                 a += 1 + (l < depth ? child_count(words[a]) : 0)) {
                index_of[a] = uint32_t(nodes[l].size());
                nodes[l].push_back(uint32_t(a));
            }

    // Widths bottom-up: a level's pointer width depends on the size of the level below.
    std::vector<std::vector<uint64_t>> offset(depth + 1);
    std::vector<uint64_t> level_bits(depth + 1, 0);
    offset[depth].assign(nodes[depth].size(), 0);  // the leaf takes no bits
    auto targets = [&](int level) -> uint64_t {
        if (!by_offset) return nodes[level].size();
        // The leaf takes no bits, so every copy of it sits at offset 0.
        return nodes[level].size() > 1 ? std::max<uint64_t>(level_bits[level], 1) : 1;
    };
    out.widths_.assign(depth, 0);
    for (int l = depth - 1; l >= 0; --l) {
        const int w = bits_for_count(targets(l + 1));
        out.widths_[l] = w;
        uint64_t bits = 0;
        for (uint32_t a : nodes[l]) {
            offset[l].push_back(bits);
            bits += 8 + uint64_t(child_count(words[a])) * uint64_t(w);
        }
        level_bits[l] = bits;
    }

    BitWriter stream;
    out.level_start_.assign(depth + 2, 0);
    for (int l = 0; l < depth; ++l) {
        out.level_start_[l] = stream.size();
        const int w = out.widths_[l];
        for (uint32_t a : nodes[l]) {
            const uint32_t mask = words[a] & 0xffu;
            stream.write(mask, 8);
            for (uint32_t k = 0; k < child_count(mask); ++k) {
                const uint32_t child = words[a + 1 + k];
                const uint64_t i = index_of[child];
                stream.write(by_offset ? offset[l + 1][i] : i, w);
            }
        }
    }
    out.level_start_[depth] = out.level_start_[depth + 1] = stream.size();
    out.stream_bits_ = stream.size();
    out.stream_ = stream.release();

    BitWriter roots;
    for (size_t f = 0; f < dag.frame_count(); ++f)
        out.root_has_empty_marker_ |= dag.root(f) == LaidOutMultiFrameDag::kEmptyFrame;
    out.root_bits_ = bits_for_count(targets(0) + (out.root_has_empty_marker_ ? 1 : 0));
    for (size_t f = 0; f < dag.frame_count(); ++f) {
        const uint32_t r = dag.root(f);
        uint64_t value = 0;
        if (r != LaidOutMultiFrameDag::kEmptyFrame) value = by_offset ? offset[0][index_of[r]] : index_of[r];
        if (out.root_has_empty_marker_) value = r == LaidOutMultiFrameDag::kEmptyFrame ? 0 : value + 1;
        roots.write(value, out.root_bits_);
    }
    out.root_table_ = roots.release();
    return out;
}

uint64_t MinimalBitDag::level_bits(int level) const {
    if (level < 0 || level > depth_) throw Error(kWhat, "level " + std::to_string(level) + " does not exist");
    return level_start_[level + 1] - level_start_[level];
}

size_t MinimalBitDag::bytes() const {
    const uint64_t root_table_bits = uint64_t(root_bits_) * frame_count_;
    return size_t((stream_bits_ + 7) / 8 + (root_table_bits + 7) / 8) + kHeaderBytesPerLevel * size_t(depth_);
}

std::vector<uint64_t> MinimalBitDag::parse_level(int level) const {
    std::vector<uint64_t> starts;
    for (uint64_t pos = level_start_[level]; pos < level_start_[level + 1];) {
        starts.push_back(pos);
        pos += 8 + uint64_t(child_count(uint32_t(read_bits(stream_, pos, 8)))) * uint64_t(widths_[level]);
    }
    return starts;
}

std::vector<uint64_t> MinimalBitDag::decode(size_t frame) const {
    if (frame >= frame_count_)
        throw Error(kWhat, "frame " + std::to_string(frame) + " is outside 0.." + std::to_string(frame_count_) +
                               " (exclusive)");
    uint64_t root = read_bits(root_table_, uint64_t(frame) * uint64_t(root_bits_), root_bits_);
    if (root_has_empty_marker_) {
        if (root == 0) return {};
        --root;
    }
    if (depth_ == 0) return {0};
    const bool by_offset = addressing_ == PointerAddressing::BitOffset;
    std::vector<std::vector<uint64_t>> starts(depth_);
    if (!by_offset)
        for (int l = 0; l < depth_; ++l) starts[l] = parse_level(l);
    auto position = [&](int level, uint64_t pointer) -> uint64_t {
        if (level == depth_) return 0;
        if (by_offset) return level_start_[level] + pointer;
        if (pointer >= starts[level].size()) throw Error(kWhat, "corrupt stream: node index out of range");
        return starts[level][pointer];
    };
    struct Item {
        int level;
        uint64_t pos;
        uint64_t code;
    };
    std::vector<uint64_t> out;
    std::vector<Item> stack{{0, position(0, root), 0}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        if (it.level == depth_) {
            out.push_back(it.code);
            continue;
        }
        const uint32_t mask = uint32_t(read_bits(stream_, it.pos, 8));
        const int w = widths_[it.level];
        for (int s = 7; s >= 0; --s) {  // reversed so slot 0 pops first: Morton order
            if (!(mask & (1u << s))) continue;
            const uint64_t pointer = read_bits(stream_, it.pos + 8 + uint64_t(child_rank(mask, s)) * uint64_t(w), w);
            stack.push_back({it.level + 1, position(it.level + 1, pointer), it.code << 3 | uint64_t(s)});
        }
    }
    return out;
}

}  // namespace gilab
