#pragma once
// The unique nodes of one level of a DAG under construction. A node is a header word
// (its child mask) and the ids of its children on the level below; two nodes with the
// same header and the same child ids have identical subtrees, so bottom-up merging only
// ever compares these few words (P2 §2.2). Ids are dense, in order of first insertion.
#include <cstdint>
#include <span>
#include <vector>

namespace gilab {

class DagLevelTable {
public:
    static uint64_t hash(uint32_t header, const uint32_t* children, uint32_t count);

    // Id of the node (header, children), inserting it if new. `hash` must be
    // hash(header, children, count).
    uint32_t find_or_insert(uint32_t header, const uint32_t* children, uint32_t count, uint64_t hash);
    uint32_t find_or_insert(uint32_t header, const uint32_t* children, uint32_t count) {
        return find_or_insert(header, children, count, hash(header, children, count));
    }
    // Starts loading the slot a later lookup of this hash will probe first.
    void prefetch(uint64_t hash) const {
        if (!slots_.empty()) __builtin_prefetch(&slots_[hash & mask_]);
    }

    size_t size() const { return offsets_.size(); }
    uint32_t header(uint32_t id) const { return records_[offsets_[id] + 1]; }
    std::span<const uint32_t> children(uint32_t id) const {
        const uint32_t* r = records_.data() + offsets_[id];
        return {r + 3, r[2]};
    }
    size_t child_count_total() const { return child_total_; }
    size_t memory_bytes() const;

private:
    void grow();

    // Records back to back: id, header, child count, child ids.
    std::vector<uint32_t> records_;
    std::vector<uint32_t> offsets_;  // record of each id
    // Open addressing with linear probing; a slot is (upper hash bits << 32) | (record
    // offset + 1), 0 = empty, so one probe touches one word and a hit one record.
    std::vector<uint64_t> slots_;
    uint64_t mask_ = 0;
    size_t child_total_ = 0;
};

}  // namespace gilab
