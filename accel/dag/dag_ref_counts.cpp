#include "accel/dag/dag_ref_counts.hpp"
#include <utility>
#include "core/util/error.hpp"

namespace gilab {

uint64_t DagRefCounts::acquire(const std::vector<DagLevelTable>& tables, int level, uint32_t id) {
    uint64_t born = 0;
    std::vector<std::pair<int, uint32_t>> stack{{level, id}};
    while (!stack.empty()) {
        auto [l, n] = stack.back();
        stack.pop_back();
        auto& c = counts_[l];
        if (n >= tables[l].size()) throw Error("DAG reference counts", "internal: node id outside its level table");
        if (c.size() < tables[l].size()) c.resize(tables[l].size(), 0);
        if (c[n]++ != 0) continue;
        ++born;
        ++live_[l];
        for (uint32_t child : tables[l].children(n)) stack.push_back({l + 1, child});
    }
    return born;
}

uint64_t DagRefCounts::release(const std::vector<DagLevelTable>& tables, int level, uint32_t id) {
    uint64_t died = 0;
    std::vector<std::pair<int, uint32_t>> stack{{level, id}};
    while (!stack.empty()) {
        auto [l, n] = stack.back();
        stack.pop_back();
        auto& c = counts_[l];
        if (n >= c.size() || c[n] == 0) throw Error("DAG reference counts", "internal: releasing a dead node");
        if (--c[n] != 0) continue;
        ++died;
        --live_[l];
        for (uint32_t child : tables[l].children(n)) stack.push_back({l + 1, child});
    }
    return died;
}

void DagRefCounts::set_level(int level, std::vector<uint32_t> counts) {
    uint64_t live = 0;
    for (uint32_t c : counts) live += c != 0;
    counts_[level] = std::move(counts);
    live_[level] = live;
}

}  // namespace gilab
