// dag-scale in quick mode: every row is filled, the SSVDAG holds the SVDAG's voxels (the
// decoded lists, the paired walk and every camera ray agree), it is never larger than
// the SVDAG nor than the SVDAG with packed leaves, and bits per voxel follow from the
// bytes and voxels. Rows too large for the grid or for memory are skipped with a note.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/spec_runner.hpp"
#include "tests/experiments/p2_dag/dag_model_test_support.hpp"

namespace {

using namespace gilab;
using nlohmann::json;

using test::dag_registry;
using test::num;

bool any_note_contains(const std::vector<std::string>& notes, const std::string& text) {
    for (const std::string& n : notes)
        if (n.find(text) != std::string::npos) return true;
    return false;
}

class DagScaleTest : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string missing = test::missing_model_mesh();
        if (!missing.empty()) GTEST_SKIP() << missing << " not found in the shared scenes (set GILAB_ASSETS)";
    }

    // One quick run shared by the tests (the same path as every experiment's quick test).
    static const ExperimentOutput& quick() {
        static const ExperimentOutput out = test::run_quick_experiment(dag_registry(), "dag-scale");
        return out;
    }
};

TEST(DagScaleRegistry, RegisteredUnderP2WithItsProbe) {
    const Experiment* e = dag_registry().find("dag-scale");
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->paper, "P2");
    ASSERT_NE(e->spec, nullptr);
    EXPECT_EQ(e->spec->scenes.size(), 7u);
    EXPECT_EQ(e->spec->axes.at(0).setting, "resolution");
    EXPECT_EQ(e->spec->axes.at(0).full.back(), 65536);
    EXPECT_EQ(e->spec->variants.at(0).probe, "dag-scale");
}

TEST_F(DagScaleTest, EveryRowIsFilledAndTheTwoDagsHoldTheSameVoxels) {
    const ExperimentOutput& out = quick();
    ASSERT_EQ(out.tables.size(), 2u);
    const ResultTable& table = out.tables[0];
    EXPECT_EQ(table.rows.size(), 14u);  // 7 scenes × 64³, 128³
    for (const json& row : table.rows) {
        for (const std::string& c : table.columns) EXPECT_FALSE(row.at(c).is_null()) << c << " empty: " << row.dump();
        EXPECT_TRUE(row.at("decode_equal") == true) << row.dump();
        EXPECT_TRUE(row.at("same_octree") == true) << row.dump();
        EXPECT_EQ(num(row, "rays_disagreeing"), 0) << row.dump();
        EXPECT_EQ(num(row, "rays"), 64 * 64);
        EXPECT_GT(num(row, "hit_fraction"), 0);
        EXPECT_GT(num(row, "voxels"), 0);
    }
}

TEST_F(DagScaleTest, TheSsvdagIsNeverLargerAndBitsPerVoxelFollowFromBytes) {
    for (const json& row : quick().tables[0].rows) {
        const double voxels = num(row, "voxels");
        const double svdag_mb = num(row, "svdag_MB"), ssvdag_mb = num(row, "ssvdag_MB");
        const double packed_mb = num(row, "svdag_packed_leaves_MB");
        EXPECT_LE(num(row, "ssvdag_nodes"), num(row, "svdag_nodes")) << row.dump();
        EXPECT_LE(num(row, "ssvdag_over_svdag"), 1.0) << row.dump();
        EXPECT_NEAR(num(row, "ssvdag_over_svdag"), ssvdag_mb / svdag_mb, 1e-9) << row.dump();
        EXPECT_NEAR(num(row, "ssvdag_over_svdag_nodes"), num(row, "ssvdag_nodes") / num(row, "svdag_nodes"), 1e-9);
        // Packing the voxels' parents saves bytes, merging under reflections more, short
        // pointers more again; the ratios follow from the sizes.
        const double words_mb = num(row, "ssvdag_words_MB");
        EXPECT_LT(packed_mb, svdag_mb) << row.dump();
        EXPECT_LE(words_mb, packed_mb) << row.dump();
        EXPECT_LT(ssvdag_mb, words_mb) << row.dump();
        EXPECT_NEAR(num(row, "ssvdag_words_over_packed_leaves"), words_mb / packed_mb, 1e-9) << row.dump();
        EXPECT_NEAR(num(row, "ssvdag_over_ssvdag_words"), ssvdag_mb / words_mb, 1e-9) << row.dump();
        EXPECT_GE(num(row, "long_pointer_share"), 0.0);
        EXPECT_LT(num(row, "long_pointer_share"), 1.0);
        EXPECT_NEAR(num(row, "bits_per_voxel_svdag"), 8e6 * svdag_mb / voxels, 1e-9 * num(row, "bits_per_voxel_svdag"));
        EXPECT_NEAR(num(row, "bits_per_voxel_ssvdag"), 8e6 * ssvdag_mb / voxels,
                    1e-9 * num(row, "bits_per_voxel_ssvdag"));
        EXPECT_GE(num(row, "peak_rss_MiB"), num(row, "rss_before_MiB"));
        for (const char* c : {"svdag_build (s), all threads", "svdag_build (s), 1 thread", "ssvdag_convert (s)",
                              "svdag_rays_per_s", "ssvdag_rays_per_s"})
            EXPECT_GT(num(row, c), 0) << c;
        const double share = num(row, "voxelize_share (s/s)");
        EXPECT_GT(share, 0);
        EXPECT_LT(share, 1);
    }
}

TEST_F(DagScaleTest, FinerGridsHoldMoreVoxelsAndTheSummaryIsTheMeanOfTheRows) {
    const ExperimentOutput& out = quick();
    std::map<std::string, double> voxels_at_64;
    double sum = 0;
    for (const json& row : out.tables[0].rows) {
        const std::string scene = row["scene"];
        if (num(row, "resolution") == 64) voxels_at_64[scene] = num(row, "voxels");
        else EXPECT_GT(num(row, "voxels"), voxels_at_64.at(scene)) << scene;
        sum += num(row, "ssvdag_over_svdag");
    }
    const ResultTable& summary = out.tables[1];
    ASSERT_EQ(summary.rows.size(), 3u);  // 64³, 128³, all
    const json& all = summary.rows.back();
    EXPECT_EQ(all["resolution"], "all");
    EXPECT_EQ(num(all, "rows"), double(out.tables[0].rows.size()));
    EXPECT_NEAR(num(all, "mean_ssvdag_over_svdag"), sum / double(out.tables[0].rows.size()), 1e-12);
    EXPECT_TRUE(any_note_contains(out.notes, "52.4 %")) << "no note with the SSVDAG paper's figures";
    EXPECT_TRUE(any_note_contains(out.notes, "1 thread is measured on the rows at 64³, 128³"));
}

// A row beyond the grid's 2^21 voxels per axis, and one far beyond half the memory, are
// skipped before anything is built, each with a note naming it.
TEST_F(DagScaleTest, RowsThatCannotFitAreSkippedWithANote) {
    ExperimentSpec spec = *dag_registry().get("dag-scale").spec;
    spec.scenes = {"bunny"};
    spec = with_extra_axes(spec, {"resolution=4194304,1048576"});
    ExperimentContext ctx;
    ctx.quick = true;
    ctx.output_dir = test::temp_dir("dag_scale_skips");
    ctx.assets = AssetPaths::from_environment();
    const ExperimentOutput out = run_spec(spec, ctx);
    EXPECT_TRUE(out.tables.at(0).rows.empty());
    EXPECT_TRUE(any_note_contains(out.notes, "Bunny 4194304³ skipped: the grid holds at most")) << json(out.notes);
    EXPECT_TRUE(any_note_contains(out.notes, "Bunny 1048576³ skipped: about")) << json(out.notes);
}

}  // namespace
