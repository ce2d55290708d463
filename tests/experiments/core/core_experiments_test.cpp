// core-rays in quick mode: the quick table keeps its shape (scenes × primary and shadow
// rows), every scene found traces one primary ray per pixel, and the figures are rates.
#include <gtest/gtest.h>
#include "experiments/runner/experiment.hpp"
#include "tests/experiment_test_support.hpp"

namespace gilab {
namespace {

using nlohmann::json;

TEST(CoreExperiments, RayThroughputPerSceneAndRayKind) {
    const ExperimentRegistry registry = test::registry_with({register_core_experiments});
    const ExperimentOutput out = test::run_quick_experiment(registry, "core-rays");
    ASSERT_EQ(out.tables.size(), 1u);
    const ResultTable& t = out.tables[0];
    EXPECT_EQ(t.title, "Embree ray throughput, 256² primary rays from the scene camera");
    ASSERT_GE(t.rows.size(), 2u);
    ASSERT_EQ(t.rows.size() % 2, 0u);
    EXPECT_EQ(t.rows[0]["scene"], "cornell");  // built in: always measured
    for (size_t i = 0; i < t.rows.size(); i += 2) {
        const json& primary = t.rows[i];
        const json& shadow = t.rows[i + 1];
        EXPECT_EQ(primary["ray_kind"], "primary (closest hit)");
        EXPECT_EQ(shadow["ray_kind"], "shadow (occlusion)");
        EXPECT_EQ(primary["scene"], shadow["scene"]);
        EXPECT_EQ(primary["hit_fraction"], shadow["hit_fraction"]);  // one shadow ray per primary ray
        for (const json* row : {&primary, &shadow}) {
            EXPECT_EQ((*row)["rays"], 256 * 256) << row->dump();
            EXPECT_GT((*row)["triangles"].get<double>(), 0) << row->dump();
            const double single = (*row)["single_mrays_per_s"], stream = (*row)["stream_mrays_per_s"];
            EXPECT_GT(single, 0) << row->dump();
            EXPECT_GT(stream, 0) << row->dump();
            EXPECT_DOUBLE_EQ((*row)["stream_over_single"].get<double>(), stream / single);
            const double hits = (*row)["hit_fraction"];
            EXPECT_GT(hits, 0) << row->dump();
            EXPECT_LE(hits, 1) << row->dump();
        }
    }
    // The spec is the configuration: its tile and the quick run's size and repeats.
    EXPECT_EQ(out.config.at("variants").at(0).at("settings").at("tile"), 16);
    EXPECT_EQ(out.config.at("effective").at("size"), 256);
    EXPECT_EQ(out.config.at("effective").at("frames"), 3);
}

}  // namespace
}  // namespace gilab
