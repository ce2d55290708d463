#pragma once
// Reference counts of the nodes in per-level DagLevelTables: how many live parents
// (child pointers of live nodes, or frames for a root) point at each node. A node whose
// count drops to zero is dead: it stays in its table, so an identical subtree built
// later revives it, but layouts and node counts leave it out. Acquiring or releasing a
// node cascades only into children whose count crosses zero, so the work is
// proportional to the nodes gained or lost, not to the DAG.
#include <cstdint>
#include <vector>
#include "accel/dag/dag_level_table.hpp"

namespace gilab {

class DagRefCounts {
public:
    explicit DagRefCounts(int levels = 0) : counts_(levels), live_(levels, 0) {}

    // One more reference to (level, id); returns the nodes that became live.
    uint64_t acquire(const std::vector<DagLevelTable>& tables, int level, uint32_t id);
    // One reference fewer; returns the nodes that died.
    uint64_t release(const std::vector<DagLevelTable>& tables, int level, uint32_t id);

    uint32_t count(int level, uint32_t id) const {
        const auto& c = counts_[level];
        return id < c.size() ? c[id] : 0;
    }
    uint64_t live(int level) const { return live_[level]; }
    int levels() const { return int(counts_.size()); }
    // Replaces one level's counts (after the tables were compacted and renumbered).
    void set_level(int level, std::vector<uint32_t> counts);

private:
    std::vector<std::vector<uint32_t>> counts_;
    std::vector<uint64_t> live_;
};

}  // namespace gilab
