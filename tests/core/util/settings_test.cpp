#include <gtest/gtest.h>
#include <cmath>
#include "core/util/format.hpp"
#include "core/util/settings.hpp"
#include "tests/test_support.hpp"

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
    // Settings are JSON text: a stray byte is refused when set, not when hashed.
    const std::string message = test::error_of([&] { s.set_from_string("name=caf\xE9"); });
    EXPECT_NE(message.find("not valid UTF-8"), std::string::npos) << message;
    EXPECT_NO_THROW(s.hash());
    EXPECT_THROW(s.get<int>("map", 0), Error);
    EXPECT_THROW(s.require<int>("missing"), Error);
}

// A number must fit the type it is read as: nothing wraps, truncates or turns infinite.
TEST(Settings, NumbersMustBeFiniteWholeWhereIntegralAndInRange) {
    Settings s(nlohmann::json{{"big", 1e19},
                              {"half", 2.5},
                              {"huge_float", 1e39},
                              {"three_billion", 3000000000ull},
                              {"million", 1e6},
                              {"nan", std::nan("")},
                              {"negative", -1}},
               "numbers");
    auto message = [&](auto read) {
        try {
            read();
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(message([&] { s.get<int64_t>("big", 0); }).find("'big' = 1e+19 is out of range"), std::string::npos);
    EXPECT_NE(message([&] { s.get<int>("half", 0); }).find("'half' must be a whole number"), std::string::npos);
    EXPECT_NE(message([&] { s.get<float>("huge_float", 0); }).find("'huge_float'"), std::string::npos);
    EXPECT_NE(message([&] { s.get<int>("three_billion", 0); }).find("out of range"), std::string::npos);
    EXPECT_NE(message([&] { s.get<uint32_t>("negative", 0); }).find("out of range"), std::string::npos);
    EXPECT_NE(message([&] { s.get<double>("nan", 0); }).find("'nan' is not a finite number"), std::string::npos);
    EXPECT_EQ(s.get<int64_t>("million", 0), 1000000);
    EXPECT_DOUBLE_EQ(s.get<double>("half", 0), 2.5);
    EXPECT_EQ(s.get<int64_t>("three_billion", 0), 3000000000);
    EXPECT_EQ(s.get<int>("negative", 0), -1);
}

TEST(Settings, HashIsStableAndSensitive) {
    Settings a(nlohmann::json{{"spp", 4}, {"seed", 1}});
    Settings b(nlohmann::json{{"seed", 1}, {"spp", 4}});
    Settings c(nlohmann::json{{"seed", 2}, {"spp", 4}});
    EXPECT_EQ(a.hash(), b.hash());
    EXPECT_NE(a.hash(), c.hash());
}

TEST(Settings, RangesInMessagesAreExact) {
    // Six significant digits made the bounds of an int read "[-2.14748e+09, 2.14748e+09]".
    Settings s(nlohmann::json{{"three_billion", 3000000000ull}}, "numbers");
    const std::string msg = test::error_of([&] { s.get<int>("three_billion", 0); });
    EXPECT_NE(msg.find("[-2147483648, 2147483647]"), std::string::npos) << msg;
}

TEST(NumberAsGiven, ShortestTextThatReadsBackExactly) {
    EXPECT_EQ(number_as_given(1e-300), "1e-300");
    EXPECT_EQ(number_as_given(0.1), "0.1");
    EXPECT_EQ(number_as_given(1234.5678), "1234.5678");
    EXPECT_EQ(number_as_given(-2.5), "-2.5");
    EXPECT_EQ(number_as_given(1e12), "1e+12");
    EXPECT_EQ(number_as_given(100.0), "100");
    EXPECT_EQ(number_as_given(0.1f), "0.1");  // single precision: not 0.100000001
    EXPECT_EQ(number_as_given(3.4028235e38f), "3.4028235e+38");
    for (double v : {1e-300, 0.1, 1.0 / 3.0, 6.02214076e23, -1.7976931348623157e308})
        EXPECT_EQ(std::stod(number_as_given(v)), v) << number_as_given(v);
}
