// The P2 multi-frame DAG experiments (dag-table5, dag-table6) in quick mode on fire
// (built in), robot and kitchen (when the shared BrainStem and kitchen are there): the
// files are written, every paper column holds the published figure of its row, and the
// measured figures hold together (the time-correlated DAG is the smallest, both build modes agree).
#include <gtest/gtest.h>
#include <algorithm>
#include <filesystem>
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/plot.hpp"
#include "tests/experiment_test_support.hpp"

namespace {

using namespace gilab;
using nlohmann::json;
namespace fs = std::filesystem;

const ExperimentRegistry& dynamic_registry() {
    static const ExperimentRegistry registry = test::registry_with({register_dynamic_dag_experiments});
    return registry;
}

ExperimentOutput run_quick(const std::string& name) { return test::run_quick_experiment(dynamic_registry(), name); }

std::vector<const json*> rows_of(const ResultTable& t, const std::string& scene) {
    std::vector<const json*> rows;
    for (const json& row : t.rows)
        if (row["scene"] == scene) rows.push_back(&row);
    return rows;
}

bool has_scene(const ResultTable& t, const std::string& scene) { return !rows_of(t, scene).empty(); }

double num(const json& row, const std::string& column) { return row.at(column).get<double>(); }

}  // namespace

TEST(DynamicDagExperiments, Table5CountsStorageAndBuilds) {
    const ExperimentOutput out = run_quick("dag-table5");
    ASSERT_EQ(out.tables.size(), 3u);
    const ResultTable& counts = out.tables[0];
    const ResultTable& storage = out.tables[1];
    const ResultTable& builds = out.tables[2];
    ASSERT_TRUE(has_scene(counts, "fire"));  // built in: always measured

    // Paper columns hold Table 5's row of the scene they stand beside.
    const json& fire = *rows_of(counts, "fire").front();
    EXPECT_EQ(fire["paper scene"], "Fire");
    EXPECT_DOUBLE_EQ(num(fire, "paper SVO N_p (nodes)"), 593e3);
    EXPECT_DOUBLE_EQ(num(fire, "paper SVO N_n (nodes)"), 192e6);
    EXPECT_DOUBLE_EQ(num(fire, "paper diff N_n (nodes)"), 158e6);
    EXPECT_DOUBLE_EQ(num(fire, "paper SVDAG N_p (nodes)"), 62.1e3);
    EXPECT_DOUBLE_EQ(num(fire, "paper TC N_n (nodes)"), 13.66e6);
    EXPECT_DOUBLE_EQ(num(fire, "paper SVO/TC N_n (×)"), 192.0 / 13.66);
    if (has_scene(counts, "robot")) {
        const json& robot = *rows_of(counts, "robot").front();
        EXPECT_EQ(robot["paper scene"], "Robot");
        EXPECT_DOUBLE_EQ(num(robot, "paper TC N_p (nodes)"), 29.3e3);
        EXPECT_DOUBLE_EQ(num(robot, "paper SVDAG N_n (nodes)"), 10.0e6);
        EXPECT_NEAR(num(robot, "paper SVO/TC N_n (×)"), 9.44, 0.01);  // the paper's text: "1/9.4"
    } else {
        GTEST_LOG_(INFO) << "robot not measured (shared BrainStem missing?)";
    }
    if (has_scene(counts, "kitchen")) {
        const json& kitchen = *rows_of(counts, "kitchen").front();
        EXPECT_EQ(kitchen["paper scene"], "Kitchen");
        EXPECT_DOUBLE_EQ(num(kitchen, "paper TC N_n (nodes)"), 0.36e6);
        EXPECT_DOUBLE_EQ(num(kitchen, "paper diff N_p (nodes)"), 15.1e3);
        // Mostly static: one frame's nodes are mostly shared with the others.
        EXPECT_LT(num(kitchen, "TC N_p (nodes)"), 0.5 * num(kitchen, "SVDAG N_p (nodes)"));
    } else {
        GTEST_LOG_(INFO) << "kitchen not measured (shared kitchen interior missing?)";
    }

    for (const json& row : counts.rows) {
        EXPECT_EQ(row["resolution (voxels/axis)"], 64);
        EXPECT_EQ(row["frames"], 8);
        const double tc = num(row, "TC N_n (nodes)"), svdag = num(row, "SVDAG N_n (nodes)"),
                     svo = num(row, "SVO N_n (nodes)");
        EXPECT_GT(tc, 0) << row.dump();
        EXPECT_LE(tc, svdag) << row.dump();
        EXPECT_LE(svdag, svo) << row.dump();
        // Every frame's root reaches exactly that frame's SVDAG.
        EXPECT_DOUBLE_EQ(num(row, "TC reachable per frame (nodes)"), num(row, "SVDAG N_p (nodes)")) << row.dump();
        // Every time-correlated node first appears as a changed difference-tree node (or is a root).
        EXPECT_LE(tc, num(row, "diff N_n (nodes)") + 8) << row.dump();
        // Likewise with the voxels in the bottom masks, where the TC DAG's one leaf node is extra.
        const double diff_masks = num(row, "diff, leaves in masks N_n (nodes)");
        EXPECT_LE(tc, diff_masks + 8 + 1) << row.dump();
        EXPECT_LT(diff_masks, num(row, "diff N_n (nodes)")) << row.dump();
        EXPECT_NEAR(num(row, "SVO/TC N_n (×)"), svo / tc, 1e-9 * svo / tc);
    }
    for (const json& row : storage.rows) {
        EXPECT_GT(num(row, "TC 32-bit (MB)"), 0);
        EXPECT_LE(num(row, "TC 32-bit (MB)"), num(row, "SVDAG 32-bit (MB)")) << row.dump();
        EXPECT_LT(num(row, "diff, leaves in masks 32-bit (MB)"), num(row, "diff 32-bit (MB)")) << row.dump();
        EXPECT_LE(num(row, "TC minimal bits, indices (MB)"), num(row, "TC minimal bits, offsets (MB)"));
        EXPECT_LT(num(row, "TC minimal bits, offsets (MB)"), num(row, "TC 32-bit (MB)"));
        EXPECT_TRUE(row["paper Kämpe 2016 (MB)"].is_null());  // quick runs have no 2048³ × 70 rows
    }
    // One row per build mode and scene; both give the same DAG.
    EXPECT_EQ(builds.rows.size(), 2 * counts.rows.size());
    for (const json& row : counts.rows) {
        const auto b = rows_of(builds, row["scene"].get<std::string>());
        ASSERT_EQ(b.size(), 2u);
        EXPECT_EQ((*b[0])["build mode"], "incremental");
        EXPECT_EQ((*b[1])["build mode"], "all_at_once");
        for (const json* r : b) {
            EXPECT_EQ((*r)["TC N_n (nodes)"], row["TC N_n (nodes)"]);
            EXPECT_TRUE((*r)["modes agree"].get<bool>());
            EXPECT_GT(num(*r, "build (ms)"), 0);
            EXPECT_GE(num(*r, "peak RSS (MiB)"), num(*r, "RSS before (MiB)"));
        }
    }
}

TEST(DynamicDagExperiments, Table6FrameRates) {
    const ExperimentOutput out = run_quick("dag-table6");
    const ResultTable& t = out.tables.at(0);
    const auto fire = rows_of(t, "fire");
    ASSERT_EQ(fire.size(), 3u);
    // The paper's CPU frame rates for Fire at 1024×768, 800×600, 400×300.
    EXPECT_EQ((*fire[0])["stands for (pixels)"], "1024×768");
    EXPECT_DOUBLE_EQ(num(*fire[0], "paper CPU fps (frames/s)"), 6.20);
    EXPECT_DOUBLE_EQ(num(*fire[1], "paper CPU fps (frames/s)"), 9.90);
    EXPECT_DOUBLE_EQ(num(*fire[2], "paper CPU fps (frames/s)"), 27.1);
    EXPECT_EQ((*fire[2])["image (pixels)"], "80×60");
    const auto robot = rows_of(t, "robot");
    if (!robot.empty()) {
        ASSERT_EQ(robot.size(), 3u);
        EXPECT_DOUBLE_EQ(num(*robot[0], "paper CPU fps (frames/s)"), 12.0);
        EXPECT_DOUBLE_EQ(num(*robot[2], "paper CPU fps (frames/s)"), 53.4);
    }
    const auto kitchen = rows_of(t, "kitchen");
    if (!kitchen.empty()) {
        ASSERT_EQ(kitchen.size(), 3u);
        EXPECT_DOUBLE_EQ(num(*kitchen[1], "paper CPU fps (frames/s)"), 28.1);
        EXPECT_DOUBLE_EQ(num(*kitchen[2], "paper CPU fps (frames/s)"), 62.9);
    }
    // Quick runs render these images (not the paper's sizes), 3 frames through a 64³ DAG.
    const std::vector<std::pair<int, int>> quick_images = {{160, 120}, {120, 90}, {80, 60}};
    for (const auto& rows : {fire, robot, kitchen}) {
        for (size_t i = 0; i < rows.size(); ++i) {
            const json& row = *rows[i];
            const auto [w, h] = quick_images.at(i);
            EXPECT_EQ(row["image (pixels)"], std::to_string(w) + "×" + std::to_string(h));
            EXPECT_EQ(num(row, "frames"), 3);
            EXPECT_EQ(num(row, "resolution (voxels/axis)"), 64);
            // One primary ray per pixel; shadow rays through the DAG add to them, shadow
            // DAG lookups do not.
            const double pixels = double(w) * h;
            if (row["shadows"] == "dag_ray") {
                EXPECT_GE(num(row, "rays per frame (rays)"), pixels) << row.dump();
            } else {
                EXPECT_EQ(num(row, "rays per frame (rays)"), pixels) << row.dump();
            }
            EXPECT_GT(num(row, "fps (frames/s)"), 0) << row.dump();
            EXPECT_GT(num(row, "1 thread fps (frames/s)"), 0) << row.dump();
            EXPECT_NEAR(num(row, "fps (frames/s)"), 1000.0 / num(row, "frame median (ms)"), 1e-6);
            // A frame rate at another image size is no measure of the paper's: no ratio.
            EXPECT_TRUE(row["ours / paper fps (×)"].is_null()) << row.dump();
            EXPECT_TRUE(row["1 thread / paper fps (×)"].is_null()) << row.dump();
        }
    }
    bool says_when_comparable = false;
    for (const std::string& n : out.notes) says_when_comparable |= n.find("the paper's own size") != std::string::npos;
    EXPECT_TRUE(says_when_comparable);
    ASSERT_EQ(out.plots.size(), 1u);
    const auto images = std::count_if(out.files.begin(), out.files.end(),
                                      [](const std::string& f) { return f.starts_with("frame_"); });
    EXPECT_EQ(size_t(images), t.rows.size() / 3);  // one frame image per scene
}

// The plans: Table 5 measures each scene at 512³ and (full runs) the Kämpe 2016 block at
// the grid and frame count of its published figure; Table 6 one task per scene and image.
TEST(DynamicDagExperiments, PlansOneTaskPerSceneAndPoint) {
    const Experiment& table5 = dynamic_registry().get("dag-table5");
    ASSERT_TRUE(table5.spec);
    const std::vector<SpecTask> full = plan_tasks(*table5.spec, false);
    ASSERT_EQ(full.size(), 6u);
    const std::vector<std::string> scenes = {"kitchen", "robot", "fire"};
    for (size_t s = 0; s < scenes.size(); ++s) {
        const SpecTask& main = full[2 * s];
        const SpecTask& kampe = full[2 * s + 1];
        EXPECT_EQ(main.scene, scenes[s]);
        EXPECT_EQ(kampe.scene, scenes[s]);
        EXPECT_EQ(main.axes, json({{"resolution", 512}, {"all_at_once", true}}));
        EXPECT_EQ(kampe.axes,
                  json({{"resolution", 2048}, {"frames", 70}, {"all_at_once", false}, {"memory_estimate_from", 512}}));
    }
    EXPECT_EQ(plan_tasks(*table5.spec, true).size(), 3u);

    const Experiment& table6 = dynamic_registry().get("dag-table6");
    ASSERT_TRUE(table6.spec);
    const std::vector<SpecTask> quick = plan_tasks(*table6.spec, true);
    ASSERT_EQ(quick.size(), 9u);
    EXPECT_EQ(quick[0].axes, json({{"resolution", 64}, {"width", 160}, {"height", 120}, {"paper_size", "1024×768"}}));
    const std::vector<SpecTask> full6 = plan_tasks(*table6.spec, false);
    ASSERT_EQ(full6.size(), 9u);
    EXPECT_EQ(full6[8].axes, json({{"resolution", 512}, {"width", 400}, {"height", 300}, {"paper_size", "400×300"}}));
    EXPECT_EQ(full6[8].scene, "fire");
}
