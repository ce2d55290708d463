#include <gtest/gtest.h>
#include "core/settings.hpp"

using namespace gilab;

TEST(Settings, ReadsTypedValuesAndDefaults) {
    Settings s(nlohmann::json{{"spp", 4}, {"mode", "knn"}});
    EXPECT_EQ(s.get<int>("spp", 1), 4);
    EXPECT_EQ(s.get<std::string>("mode", ""), "knn");
    EXPECT_DOUBLE_EQ(s.get<double>("radius", 0.1), 0.1);
    EXPECT_NO_THROW(s.report_unused());
}

TEST(Settings, ReportsUnreadKeysByName) {
    Settings s(nlohmann::json{{"sp", 4}, {"seed", 1}}, "path");
    s.get<int>("spp", 16);
    s.get<int>("seed", 0);
    try {
        s.report_unused();
        FAIL() << "misspelt key was not reported";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("'sp'"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("path"), std::string::npos);
    }
}

TEST(Settings, ParsesAssignmentsAndRejectsWrongTypes) {
    Settings s;
    s.set_from_string("radius=0.05");
    s.set_from_string("map=hash_grid");
    s.set_from_string("flags=[1,2]");
    EXPECT_DOUBLE_EQ(s.get<double>("radius", 0), 0.05);
    EXPECT_EQ(s.get<std::string>("map", ""), "hash_grid");
    EXPECT_EQ(s.get<std::vector<int>>("flags", {}).size(), 2u);
    EXPECT_THROW(s.set_from_string("novalue"), Error);
    EXPECT_THROW(s.get<int>("map", 0), Error);
    EXPECT_THROW(s.require<int>("missing"), Error);
}

TEST(Settings, HashIsStableAndSensitive) {
    Settings a(nlohmann::json{{"spp", 4}, {"seed", 1}});
    Settings b(nlohmann::json{{"seed", 1}, {"spp", 4}});
    Settings c(nlohmann::json{{"seed", 2}, {"spp", 4}});
    EXPECT_EQ(a.hash(), b.hash());
    EXPECT_NE(a.hash(), c.hash());
}
