#include "accel/dag_level_table.hpp"
#include <algorithm>
#include <cstring>
#include "core/error.hpp"

namespace gilab {
namespace {

inline uint64_t mix(uint64_t h) {  // murmur3 finalizer
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    h ^= h >> 33;
    return h;
}

}  // namespace

uint64_t DagLevelTable::hash(uint32_t header, const uint32_t* children, uint32_t count) {
    uint64_t h = 0x9e3779b97f4a7c15ull ^ (uint64_t(header) << 32 | count);
    uint32_t i = 0;
    for (; i + 1 < count; i += 2) h = (h ^ (uint64_t(children[i]) | uint64_t(children[i + 1]) << 32)) * 0x100000001b3ull + (h >> 29);
    if (i < count) h = (h ^ children[i]) * 0x100000001b3ull + (h >> 29);
    return mix(h);
}

size_t DagLevelTable::memory_bytes() const {
    return headers_.capacity() * 4 + child_begin_.capacity() * 8 + children_.capacity() * 4 +
           slot_ids_.capacity() * 4 + slot_tags_.capacity() * 4;
}

void DagLevelTable::reserve(size_t nodes) {
    headers_.reserve(nodes);
    child_begin_.reserve(nodes + 1);
    size_t want = 16;
    while (want < nodes * 2) want *= 2;
    if (want > slot_ids_.size()) {
        // Rehash into the larger table.
        std::vector<uint32_t> ids(want, 0), tags(want, 0);
        uint64_t m = want - 1;
        for (uint32_t id = 0; id < headers_.size(); ++id) {
            uint64_t h = hash(headers_[id], children_.data() + child_begin_[id],
                              uint32_t(child_begin_[id + 1] - child_begin_[id]));
            uint64_t s = h & m;
            while (ids[s]) s = (s + 1) & m;
            ids[s] = id + 1;
            tags[s] = uint32_t(h >> 32);
        }
        slot_ids_.swap(ids);
        slot_tags_.swap(tags);
        mask_ = m;
    }
}

void DagLevelTable::grow() { reserve(std::max<size_t>(16, headers_.size() * 2)); }

uint32_t DagLevelTable::find_or_insert(uint32_t header, const uint32_t* children, uint32_t count, uint64_t h) {
    if ((headers_.size() + 1) * 2 > slot_ids_.size()) grow();
    const uint32_t tag = uint32_t(h >> 32);
    uint64_t s = h & mask_;
    while (uint32_t id1 = slot_ids_[s]) {
        if (slot_tags_[s] == tag) {
            uint32_t id = id1 - 1;
            uint64_t b = child_begin_[id];
            if (headers_[id] == header && child_begin_[id + 1] - b == count &&
                std::memcmp(children_.data() + b, children, count * sizeof(uint32_t)) == 0)
                return id;
        }
        s = (s + 1) & mask_;
    }
    if (headers_.size() >= 0xfffffffeu) throw Error("DAG", "more than 2^32 unique nodes on one level");
    uint32_t id = uint32_t(headers_.size());
    headers_.push_back(header);
    children_.insert(children_.end(), children, children + count);
    child_begin_.push_back(children_.size());
    slot_ids_[s] = id + 1;
    slot_tags_[s] = tag;
    return id;
}

}  // namespace gilab
