#include "accel/dag/dag_layout.hpp"
#include "core/util/error.hpp"

namespace gilab {

DagLayout lay_out_dag(const std::vector<DagLevelTable>& tables, std::span<const uint32_t> roots,
                      const DagLayoutOptions& options, const char* what) {
    const int levels = int(tables.size());
    DagLayout out;
    out.level_begin.assign(levels + 1, 0);
    out.level_counts.assign(levels, 0);
    if (levels == 0 || roots.empty()) return out;
    constexpr uint32_t kUnplaced = 0xffffffffu;

    // Canonical order per level: first reference from the level above.
    std::vector<std::vector<uint32_t>> order(levels);       // ids in layout order
    std::vector<std::vector<uint32_t>> position(levels);    // id → index in order
    auto place = [&](int level, uint32_t id) {
        std::vector<uint32_t>& pos = position[level];
        if (pos.empty()) pos.assign(tables[level].size(), kUnplaced);
        if (id >= pos.size()) throw Error(what, "internal: node id outside its level table");
        if (pos[id] == kUnplaced) {
            pos[id] = uint32_t(order[level].size());
            order[level].push_back(id);
        }
    };
    if (options.one_root_per_entry) {
        for (uint32_t r : roots)
            if (r >= tables[0].size()) throw Error(what, "internal: root id outside the level-0 table");
        order[0].assign(roots.begin(), roots.end());
    } else {
        for (uint32_t r : roots) place(0, r);
    }
    for (int l = 0; l + 1 < levels; ++l) {
        if (options.payload_level >= 0 && l >= options.payload_level) break;
        for (uint32_t id : order[l])
            for (uint32_t c : tables[l].children(id)) place(l + 1, c);
    }

    // Word addresses.
    std::vector<std::vector<uint64_t>> address(levels);
    uint64_t next = 0;
    for (int l = 0; l < levels; ++l) {
        const bool payload = options.payload_level >= 0 && l >= options.payload_level;
        const bool header = !payload || options.payload_header;
        out.level_begin[l] = next;
        out.level_counts[l] = order[l].size();
        address[l].resize(order[l].size());
        for (size_t i = 0; i < order[l].size(); ++i) {
            address[l][i] = next;
            next += (header ? 1 : 0) + tables[l].children(order[l][i]).size();
        }
    }
    out.level_begin[levels] = next;
    if (next >= 0xffffffffull) throw Error(what, "DAG too large for 32-bit word addresses");

    out.words.resize(next);
    for (int l = 0; l < levels; ++l) {
        const bool payload = options.payload_level >= 0 && l >= options.payload_level;
        const bool header = !payload || options.payload_header;
        for (size_t i = 0; i < order[l].size(); ++i) {
            const uint32_t id = order[l][i];
            uint64_t a = address[l][i];
            if (header) out.words[a++] = tables[l].header(id);
            for (uint32_t c : tables[l].children(id)) {
                if (payload) {
                    out.words[a++] = c;
                } else {
                    out.words[a++] = uint32_t(address[l + 1][position[l + 1][c]]);
                    ++out.pointer_count;
                }
            }
        }
    }
    if (options.one_root_per_entry) {
        for (uint64_t a : address[0]) out.root_addresses.push_back(uint32_t(a));
    } else {
        for (uint32_t r : roots) out.root_addresses.push_back(uint32_t(address[0][position[0][r]]));
    }
    return out;
}

}  // namespace gilab
