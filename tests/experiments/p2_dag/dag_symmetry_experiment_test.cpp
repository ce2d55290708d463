// dag-symmetries in quick mode: every row is filled, the 48 cube symmetries never keep
// more nodes or bytes than the 8 reflections, the shares and ratios follow from the
// counts, and the summary is the mean of the rows.
#include <gtest/gtest.h>

#include <string>
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/spec_runner.hpp"
#include "tests/experiments/p2_dag/dag_model_test_support.hpp"

namespace {

using namespace gilab;
using nlohmann::json;

using test::dag_registry;
using test::num;

class DagSymmetryTest : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string missing = test::missing_model_mesh();
        if (!missing.empty()) GTEST_SKIP() << missing << " not found in the shared scenes (set GILAB_ASSETS)";
    }

    static const ExperimentOutput& quick() {
        static const ExperimentOutput out = test::run_quick_experiment(dag_registry(), "dag-symmetries");
        return out;
    }
};

TEST(DagSymmetryRegistry, RegisteredUnderP2WithItsProbe) {
    const Experiment* e = dag_registry().find("dag-symmetries");
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->paper, "P2");
    ASSERT_NE(e->spec, nullptr);
    EXPECT_EQ(e->spec->scenes.size(), 7u);
    EXPECT_EQ(e->spec->axes.at(0).setting, "resolution");
    EXPECT_EQ(e->spec->variants.at(0).probe, "dag-symmetries");
}

TEST_F(DagSymmetryTest, CubeSymmetriesNeverKeepMoreAndTheRatiosFollowFromTheCounts) {
    const ExperimentOutput& out = quick();
    ASSERT_EQ(out.tables.size(), 2u);
    const ResultTable& table = out.tables[0];
    EXPECT_EQ(table.rows.size(), 14u);  // 7 scenes × 64³, 128³
    double sum = 0;
    for (const json& row : table.rows) {
        for (const std::string& c : table.columns) EXPECT_FALSE(row.at(c).is_null()) << c << " empty: " << row.dump();
        const double svdag = num(row, "svdag_nodes"), reflections = num(row, "reflection_nodes");
        const double cube = num(row, "cube_nodes");
        EXPECT_LE(reflections, svdag) << row.dump();
        EXPECT_LE(cube, reflections) << row.dump();
        EXPECT_NEAR(num(row, "cube_over_reflection_nodes"), cube / reflections, 1e-12);
        const double reflection_mb = num(row, "reflection_words_MB"), cube_mb = num(row, "cube_words_MB");
        EXPECT_LE(cube_mb, reflection_mb) << row.dump();
        EXPECT_LT(reflection_mb, num(row, "svdag_MB")) << row.dump();
        EXPECT_NEAR(num(row, "cube_words_over_reflection_words"), cube_mb / reflection_mb, 1e-9);
        const double transformed = num(row, "cube_transformed_pointer_share");
        const double permuting = num(row, "cube_permuting_pointer_share");
        EXPECT_GE(permuting, 0.0);
        EXPECT_LE(permuting, transformed);
        EXPECT_LT(transformed, 1.0);
        EXPECT_TRUE(row.at("cube_fits_26_bit_addresses") == true);
        for (const char* c : {"svdag_build (s)", "reflection_merge (s)", "cube_merge (s)"}) EXPECT_GT(num(row, c), 0) << c;
        sum += num(row, "cube_over_reflection_nodes");
    }
    // Real scenes hold some subtrees that only a permutation maps onto each other.
    EXPECT_LT(sum / double(table.rows.size()), 1.0);
    const json& all = out.tables[1].rows.back();
    EXPECT_EQ(all["resolution"], "all");
    EXPECT_NEAR(num(all, "mean_cube_over_reflection_nodes"), sum / double(table.rows.size()), 1e-12);
}

}  // namespace
