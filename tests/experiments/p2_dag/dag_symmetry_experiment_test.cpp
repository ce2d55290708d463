// dag-symmetries in quick mode: every row is filled, the cube-symmetric DAG never keeps
// more nodes or words than the SSVDAG, both hold the SVDAG's voxels and hit the same
// voxels, the shares and ratios follow from the counts, and the summary is the mean of
// the rows.
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
        const double svdag = num(row, "svdag_nodes"), reflections = num(row, "ssvdag_nodes");
        const double cube = num(row, "cube_nodes");
        EXPECT_LE(reflections, svdag) << row.dump();
        EXPECT_LE(cube, reflections) << row.dump();
        EXPECT_NEAR(num(row, "cube_over_ssvdag_nodes"), cube / reflections, 1e-12);
        const double reflection_words = num(row, "ssvdag_words_MB"), cube_words = num(row, "cube_words_MB");
        EXPECT_LE(cube_words, reflection_words) << row.dump();
        EXPECT_LT(reflection_words, num(row, "svdag_MB")) << row.dump();
        EXPECT_NEAR(num(row, "cube_words_over_ssvdag_words"), cube_words / reflection_words, 1e-9);
        // Stored: short pointers make each smaller than its words.
        const double ssvdag_mb = num(row, "ssvdag_MB"), cube_mb = num(row, "cube_MB");
        EXPECT_LT(ssvdag_mb, reflection_words) << row.dump();
        EXPECT_LT(cube_mb, cube_words) << row.dump();
        EXPECT_NEAR(num(row, "cube_over_ssvdag"), cube_mb / ssvdag_mb, 1e-9);
        EXPECT_NEAR(num(row, "cube_over_svdag"), cube_mb / num(row, "svdag_MB"), 1e-9);
        EXPECT_NEAR(num(row, "bits_per_voxel_cube"), 8e6 * cube_mb / num(row, "voxels"), 1e-9 * num(row, "bits_per_voxel_cube"));
        const double transformed = num(row, "cube_transformed_pointer_share");
        const double permuting = num(row, "cube_permuting_pointer_share");
        EXPECT_GE(permuting, 0.0);
        EXPECT_LE(permuting, transformed);
        EXPECT_LT(transformed, 1.0);
        for (const char* c : {"ssvdag_long_pointer_share", "cube_long_pointer_share"}) {
            EXPECT_GE(num(row, c), 0.0) << c;
            EXPECT_LE(num(row, c), 1.0) << c;
        }
        EXPECT_TRUE(row.at("same_octree") == true) << row.dump();
        EXPECT_EQ(num(row, "rays_disagreeing"), 0.0) << row.dump();
        EXPECT_EQ(num(row, "rays"), 64.0 * 64.0);
        EXPECT_GT(num(row, "hit_fraction"), 0.0) << row.dump();
        for (const char* c : {"svdag_build (s)", "ssvdag_convert (s)", "cube_convert (s)", "svdag_rays_per_s",
                              "ssvdag_rays_per_s", "cube_rays_per_s"})
            EXPECT_GT(num(row, c), 0) << c;
        EXPECT_NEAR(num(row, "cube_over_ssvdag_rays_per_s"), num(row, "cube_rays_per_s") / num(row, "ssvdag_rays_per_s"), 1e-9);
        sum += num(row, "cube_over_ssvdag_nodes");
    }
    // Real scenes hold some subtrees that only a permutation maps onto each other.
    EXPECT_LT(sum / double(table.rows.size()), 1.0);
    const json& all = out.tables[1].rows.back();
    EXPECT_EQ(all["resolution"], "all");
    EXPECT_NEAR(num(all, "mean_cube_over_ssvdag_nodes"), sum / double(table.rows.size()), 1e-12);
}

}  // namespace
