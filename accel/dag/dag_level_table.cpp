#include "accel/dag/dag_level_table.hpp"
#include <algorithm>
#include "core/util/error.hpp"

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
    for (; i + 1 < count; i += 2)
        h = (h ^ (uint64_t(children[i]) | uint64_t(children[i + 1]) << 32)) * 0x100000001b3ull + (h >> 29);
    if (i < count) h = (h ^ children[i]) * 0x100000001b3ull + (h >> 29);
    return mix(h);
}

size_t DagLevelTable::memory_bytes() const {
    return records_.capacity() * 4 + offsets_.capacity() * 4 + slots_.capacity() * 8;
}

void DagLevelTable::grow() {
    size_t want = std::max<size_t>(64, slots_.size() * 2);
    std::vector<uint64_t> slots(want, 0);
    const uint64_t m = want - 1;
    for (uint32_t id = 0; id < offsets_.size(); ++id) {
        const uint32_t* r = records_.data() + offsets_[id];
        uint64_t h = hash(r[1], r + 3, r[2]);
        uint64_t s = h & m;
        while (slots[s]) s = (s + 1) & m;
        slots[s] = (h >> 32) << 32 | (uint64_t(offsets_[id]) + 1);
    }
    slots_.swap(slots);
    mask_ = m;
}

uint32_t DagLevelTable::find_or_insert(uint32_t header, const uint32_t* children, uint32_t count, uint64_t h) {
    if ((offsets_.size() + 1) * 2 > slots_.size()) grow();
    const uint64_t tag = h >> 32;
    uint64_t s = h & mask_;
    while (uint64_t slot = slots_[s]) {
        if ((slot >> 32) == tag) {
            const uint32_t* r = records_.data() + (uint32_t(slot) - 1);
            if (r[1] == header && r[2] == count) {
                uint32_t i = 0;
                while (i < count && r[3 + i] == children[i]) ++i;
                if (i == count) return r[0];
            }
        }
        s = (s + 1) & mask_;
    }
    if (offsets_.size() >= 0xfffffffeu || records_.size() + 3 + count >= 0xfffffffeu)
        throw Error("DAG", "one level of the DAG exceeds 2^32 nodes or words");
    const uint32_t id = uint32_t(offsets_.size());
    const uint32_t offset = uint32_t(records_.size());
    offsets_.push_back(offset);
    records_.push_back(id);
    records_.push_back(header);
    records_.push_back(count);
    records_.insert(records_.end(), children, children + count);
    child_total_ += count;
    slots_[s] = tag << 32 | (uint64_t(offset) + 1);
    return id;
}

}  // namespace gilab
