// pm-radius-sweep at quick size on the conference room: every task measured, and more
// photons at the same radius lower the photon estimate's error.
#include <map>
#include <gtest/gtest.h>
#include "experiments/runner/experiment.hpp"
#include "tests/experiment_test_support.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

TEST(RadiusSweep, QuickRunMeasuresEveryTaskAndMorePhotonsLowerTheError) {
    if (!test::shared_asset("conference/conference.obj")) GTEST_SKIP() << "conference/conference.obj not found";
    const ExperimentRegistry registry = test::registry_with({register_photon_experiments});
    const ExperimentOutput out = test::run_quick_experiment(registry, "pm-radius-sweep");
    const auto& rows = out.tables.at(0).rows;
    ASSERT_EQ(rows.size(), 4u);  // 2 photon counts × 2 radii
    std::map<double, std::map<int, double>> error;  // radius → photons → relMSE of the indirect layer
    for (const auto& row : rows) {
        EXPECT_GT(row.at("frame_ms").get<double>(), 0.0) << row.dump();
        EXPECT_GT(row.at("photons_stored").get<double>(), 0.0) << row.dump();
        error[row.at("radius (scene units)").get<double>()][row.at("photons (emitted per frame)").get<int>()] = row.at("relmse_indirect").get<double>();
    }
    ASSERT_EQ(error.size(), 2u);
    for (const auto& [radius, by_photons] : error) {
        ASSERT_EQ(by_photons.size(), 2u);
        EXPECT_LT(by_photons.rbegin()->second, by_photons.begin()->second) << "radius " << radius;
    }
    EXPECT_EQ(out.config.at("name"), "pm-radius-sweep");
}

}  // namespace
}  // namespace gilab
