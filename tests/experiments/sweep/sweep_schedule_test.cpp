// wall_seconds_on: the wall time `gilab sweep status` gives for 1, 4 and 16 machines
// from the measured task times (longest task first, each to the machine free first).
#include <gtest/gtest.h>
#include "core/util/error.hpp"
#include "experiments/sweep/sweep.hpp"

using gilab::wall_seconds_on;

TEST(SweepSchedule, OneMachineTakesTheSumManyTakeTheLongestTask) {
    const std::vector<double> tasks = {5, 4, 3, 3, 3};
    EXPECT_DOUBLE_EQ(wall_seconds_on(tasks, 1), 18.0);
    EXPECT_DOUBLE_EQ(wall_seconds_on(tasks, 16), 5.0);
    EXPECT_DOUBLE_EQ(wall_seconds_on({}, 4), 0.0);
}

TEST(SweepSchedule, LongestFirstToTheMachineFreeFirst) {
    // 5→A, 4→B, 3→B (7), 3→A (8), 3→B (10): 10 s, where the best split ({5,4}, {3,3,3}) is 9.
    EXPECT_DOUBLE_EQ(wall_seconds_on({3, 5, 3, 4, 3}, 2), 10.0);
    EXPECT_DOUBLE_EQ(wall_seconds_on({10, 10, 10, 10}, 4), 10.0);
    EXPECT_DOUBLE_EQ(wall_seconds_on({10, 10, 10, 10, 1}, 4), 11.0);
    EXPECT_THROW(wall_seconds_on({1}, 0), gilab::Error);
}
