// The P1 photon-mapping and stereo experiments in quick mode: each one runs and writes
// every column of every row, and in Tables 1–4 the `paper ms` of every row is the
// published figure for that row's paper photon count, radius and variant (written out
// here from the paper's tables, independently of the experiment's own reference data),
// never the measured frame time.
#include <gtest/gtest.h>
#include <map>
#include <string>
#include <tuple>
#include "experiments/experiment.hpp"
#include "tests/experiment_test_support.hpp"

namespace {

using namespace gilab;
using nlohmann::json;

const ExperimentRegistry& photon_registry() {
    static const ExperimentRegistry registry =
        test::registry_with({register_photon_experiments, register_stereo_experiments});
    return registry;
}

class PhotonQuickExperiment : public testing::TestWithParam<const char*> {};

TEST_P(PhotonQuickExperiment, RunsAndFillsEveryColumn) {
    const ExperimentOutput out = test::run_quick_experiment(photon_registry(), GetParam());
    for (const std::string& note : out.notes) EXPECT_EQ(note.find("Target"), std::string::npos) << note;
}

INSTANTIATE_TEST_SUITE_P(All, PhotonQuickExperiment,
                         testing::Values("pm-fig8", "pm-table5", "pm-final", "pm-foveated"), test::test_name_of);

// P1 Tables 1–4 (ms): (photons, radius, variant) → published frame time.
using Key = std::tuple<std::string, double, std::string>;
const std::map<Key, double>& published_ms() {
    static const std::map<Key, double> t = {
        // Table 1: kd-tree vs hash grid.
        {{"512²", 0.02, "kd_tree"}, 7.28}, {{"512²", 0.02, "hash_grid"}, 3.89},
        {{"512²", 0.05, "kd_tree"}, 118.35}, {{"512²", 0.05, "hash_grid"}, 90.74},
        {{"512²", 0.1, "kd_tree"}, 426.39}, {{"512²", 0.1, "hash_grid"}, 501.79},
        {{"256²", 0.05, "kd_tree"}, 8.32}, {{"256²", 0.05, "hash_grid"}, 5.23},
        {{"256²", 0.1, "kd_tree"}, 72.05}, {{"256²", 0.1, "hash_grid"}, 49.29},
        {{"256²", 0.2, "kd_tree"}, 287.87}, {{"256²", 0.2, "hash_grid"}, 362.10},
        {{"128²", 0.05, "kd_tree"}, 2.57}, {{"128²", 0.05, "hash_grid"}, 1.94},
        {{"128²", 0.1, "kd_tree"}, 5.69}, {{"128²", 0.1, "hash_grid"}, 3.67},
        {{"128²", 0.2, "kd_tree"}, 36.29}, {{"128²", 0.2, "hash_grid"}, 22.90},
        // Table 2: heap vs no heap.
        {{"512²", 0.02, "heap"}, 3.89}, {{"512²", 0.02, "no heap"}, 2.33},
        {{"512²", 0.05, "heap"}, 90.74}, {{"512²", 0.05, "no heap"}, 4.36},
        {{"512²", 0.1, "heap"}, 501.79}, {{"512²", 0.1, "no heap"}, 11.43},
        {{"256²", 0.05, "heap"}, 5.23}, {{"256²", 0.05, "no heap"}, 2.30},
        {{"256²", 0.1, "heap"}, 49.29}, {{"256²", 0.1, "no heap"}, 3.94},
        {{"256²", 0.2, "heap"}, 362.10}, {{"256²", 0.2, "no heap"}, 11.24},
        // Table 3: single (fused) vs hybrid (split) kernel.
        {{"512²", 0.05, "fused"}, 4.59}, {{"512²", 0.05, "split"}, 3.41},
        {{"512²", 0.1, "fused"}, 12.39}, {{"512²", 0.1, "split"}, 6.52},
        {{"512²", 0.2, "fused"}, 37.60}, {{"512²", 0.2, "split"}, 17.51},
        {{"256²", 0.05, "fused"}, 2.60}, {{"256²", 0.05, "split"}, 2.31},
        {{"256²", 0.1, "fused"}, 4.03}, {{"256²", 0.1, "split"}, 3.76},
        {{"256²", 0.2, "fused"}, 10.66}, {{"256²", 0.2, "split"}, 6.00},
        // Table 4: without vs with shared memory (Algorithm 1).
        {{"512²", 0.05, "per-hit gather"}, 3.41}, {{"512²", 0.05, "tile-shared"}, 3.18},
        {{"512²", 0.1, "per-hit gather"}, 6.52}, {{"512²", 0.1, "tile-shared"}, 6.33},
        {{"512²", 0.2, "per-hit gather"}, 17.51}, {{"512²", 0.2, "tile-shared"}, 15.88},
        {{"256²", 0.05, "per-hit gather"}, 2.31}, {{"256²", 0.05, "tile-shared"}, 2.25},
        {{"256²", 0.1, "per-hit gather"}, 3.76}, {{"256²", 0.1, "tile-shared"}, 3.06},
        {{"256²", 0.2, "per-hit gather"}, 6.00}, {{"256²", 0.2, "tile-shared"}, 5.80},
    };
    return t;
}

class PhotonPaperColumns : public testing::TestWithParam<const char*> {};

TEST_P(PhotonPaperColumns, EveryRowCarriesItsPublishedFigure) {
    const ExperimentOutput out = test::run_quick_experiment(photon_registry(), GetParam());
    int checked = 0;
    for (const ResultTable& t : out.tables)
        for (const json& row : t.rows) {
            if (!row.contains("paper ms") || row["paper ms"].is_null()) continue;
            const Key key{row.at("paper photons").get<std::string>(), row.at("r").get<double>(),
                          row.at("variant").get<std::string>()};
            const auto it = published_ms().find(key);
            ASSERT_NE(it, published_ms().end())
                << GetParam() << ": no published figure for " << std::get<0>(key) << " r " << std::get<1>(key) << " "
                << std::get<2>(key);
            EXPECT_DOUBLE_EQ(row.at("paper ms").get<double>(), it->second) << GetParam() << " " << row.dump();
            EXPECT_NE(row.at("frame_ms").get<double>(), it->second) << "measured column copies the paper";
            ++checked;
        }
    EXPECT_GT(checked, 0) << GetParam() << ": no row carries a paper figure";
}

INSTANTIATE_TEST_SUITE_P(Tables, PhotonPaperColumns,
                         testing::Values("pm-table1", "pm-table2", "pm-table3", "pm-table4"), test::test_name_of);

}  // namespace
