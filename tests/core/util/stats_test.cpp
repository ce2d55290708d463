// Stats: a figure asked for under a key that was never set must not read as 0.
#include <gtest/gtest.h>

#include "core/util/error.hpp"
#include "core/util/stats.hpp"

using namespace gilab;

TEST(Stats, GetReturnsTheFigureSet) {
    Stats s;
    s.set("render_ms", 12.5);
    s.add("render_ms", 0.5);
    EXPECT_EQ(s.get("render_ms"), 13.0);
}

TEST(Stats, GetOfAMissingKeyThrowsNamingTheKeyAndThoseThatExist) {
    Stats s;
    s.set("render_ms", 1);
    s.set("rays", 2);
    try {
        (void)s.get("rendr_ms");
        FAIL() << "a missing key read as a figure";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("rendr_ms"), std::string::npos) << what;
        EXPECT_NE(what.find("render_ms"), std::string::npos) << what;
        EXPECT_NE(what.find("rays"), std::string::npos) << what;
    }
}

TEST(Stats, GetOfAnEmptyStatsThrows) { EXPECT_THROW((void)Stats().get("anything"), Error); }

TEST(Stats, GetOrGivesTheFallbackOnlyWhenTheKeyIsMissing) {
    Stats s;
    s.set("zero", 0);
    EXPECT_EQ(s.get_or("zero", -1), 0.0);
    EXPECT_EQ(s.get_or("absent", -1), -1.0);
}
