// The P1 photon-mapping and stereo experiments in quick mode: each one runs and writes
// every column of every row, and in Tables 1–4 the `paper ms` of every row is the
// published figure for that row's paper photon count, radius and variant (written out
// here from the paper's tables, independently of the experiment's own reference data),
// never the measured frame time; Tables 1–4 run with every-hit photon storage and say so,
// and Table 4 reports the three tile_shared modes with identical images.
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
        // Table 4: without vs with shared memory (Algorithm 1): our tile_shared off | paper.
        {{"512²", 0.05, "off"}, 3.41}, {{"512²", 0.05, "paper"}, 3.18},
        {{"512²", 0.1, "off"}, 6.52}, {{"512²", 0.1, "paper"}, 6.33},
        {{"512²", 0.2, "off"}, 17.51}, {{"512²", 0.2, "paper"}, 15.88},
        {{"256²", 0.05, "off"}, 2.31}, {{"256²", 0.05, "paper"}, 2.25},
        {{"256²", 0.1, "off"}, 3.76}, {{"256²", 0.1, "paper"}, 3.06},
        {{"256²", 0.2, "off"}, 6.00}, {{"256²", 0.2, "paper"}, 5.80},
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

    // The tables run the paper's photon map and say so.
    EXPECT_EQ(out.config.value("photon_storage", ""), "every_hit") << GetParam();
    bool storage_note = false;
    for (const std::string& note : out.notes)
        storage_note = storage_note || (note.find("every_hit") != std::string::npos &&
                                        note.find("no shadow rays") != std::string::npos);
    EXPECT_TRUE(storage_note) << GetParam() << ": no note names the storage mode and what it changes";
    for (const json& row : out.tables.at(0).rows)
        EXPECT_GT(row.at("stored_first_hit").get<double>(), 0.0) << GetParam() << " " << row.dump();

    if (std::string(GetParam()) == "pm-table4") {
        // All three modes per row; only off and paper carry the paper's figures; the
        // images are identical; paper mode reports its tiles.
        std::map<std::string, int> modes;
        for (const json& row : out.tables.at(0).rows) {
            const std::string variant = row.at("variant").get<std::string>();
            ++modes[variant];
            EXPECT_EQ(row.at("paper ms").is_null(), variant == "cell_groups") << row.dump();
            if (variant == "paper") {
                EXPECT_GT(row.at("tiles_qualified").get<double>() + row.at("tiles_mixed").get<double>(), 0.0);
            }
        }
        EXPECT_EQ(modes.size(), 3u);
        for (const auto& [variant, count] : modes) EXPECT_EQ(count, 6) << variant;
        for (const json& row : out.tables.at(1).rows) EXPECT_TRUE(row.at("identical images").get<bool>()) << row.dump();
    }
}

INSTANTIATE_TEST_SUITE_P(Tables, PhotonPaperColumns,
                         testing::Values("pm-table1", "pm-table2", "pm-table3", "pm-table4"), test::test_name_of);

TEST(PhotonConvergence, RunsQuickAndFillsItsColumns) {
    // pm-convergence: every measured row has a positive time and error; per scene, each
    // variant has its points, a row of times to reach the targets (a number or a
    // string saying why there is none), and one curve in the scene's plot.
    const ExperimentOutput out = test::run_quick_experiment(photon_registry(), "pm-convergence");
    ASSERT_EQ(out.tables.size(), 2u);
    std::map<std::string, std::map<std::string, int>> points;  // scene → variant → rows
    for (const json& row : out.tables[0].rows) {
        EXPECT_GT(row.at("wall ms").get<double>(), 0.0) << row.dump();
        EXPECT_GT(row.at("relMSE").get<double>(), 0.0) << row.dump();
        ++points[row.at("scene").get<std::string>()][row.at("variant").get<std::string>()];
    }
    ASSERT_TRUE(points.count("cornell"));
    for (const auto& [scene, variants] : points) {
        EXPECT_EQ(variants.size(), 3u) << scene;
        for (const auto& [variant, count] : variants) EXPECT_GE(count, 2) << scene << " " << variant;
    }
    EXPECT_EQ(out.tables[1].rows.size(), 3 * points.size());
    for (const json& row : out.tables[1].rows)
        for (const std::string& column : out.tables[1].columns)
            if (column.rfind("ms to", 0) == 0) {
                const json& cell = row.at(column);
                EXPECT_TRUE(cell.is_string() || (cell.is_number() && cell.get<double>() > 0)) << row.dump();
            }
    ASSERT_EQ(out.plots.size(), points.size());
    for (const auto& [name, plot] : out.plots) {
        EXPECT_TRUE(plot.log_x && plot.log_y) << name;
        const std::string scene = name.substr(name.find('_') + 1);
        ASSERT_TRUE(points.count(scene)) << name;
        ASSERT_EQ(plot.series.size(), points.at(scene).size()) << name;
        for (const PlotSeries& series : plot.series) {
            ASSERT_TRUE(points.at(scene).count(series.label)) << name << ": " << series.label;
            EXPECT_EQ(int(series.x.size()), points.at(scene).at(series.label)) << name << ": " << series.label;
        }
    }
}

}  // namespace
