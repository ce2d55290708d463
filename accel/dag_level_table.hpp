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

    size_t size() const { return headers_.size(); }
    uint32_t header(uint32_t id) const { return headers_[id]; }
    std::span<const uint32_t> children(uint32_t id) const {
        return {children_.data() + child_begin_[id], children_.data() + child_begin_[id + 1]};
    }
    size_t child_count_total() const { return children_.size(); }
    size_t memory_bytes() const;
    void reserve(size_t nodes);

private:
    void grow();

    std::vector<uint32_t> headers_;
    std::vector<uint64_t> child_begin_{0};
    std::vector<uint32_t> children_;
    // Open addressing with linear probing: slot holds id + 1 (0 = empty) and the hash.
    std::vector<uint32_t> slot_ids_;
    std::vector<uint32_t> slot_tags_;
    uint64_t mask_ = 0;
};

}  // namespace gilab
