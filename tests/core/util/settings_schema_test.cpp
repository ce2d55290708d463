// The settings schema: defaults, type and range checks, choices, unknown keys, and the
// tables it prints.
#include <gtest/gtest.h>
#include "core/util/error.hpp"
#include "core/util/settings_schema.hpp"

namespace gilab {
namespace {

SettingsSchema example() {
    SettingsSchema s("demo", "a technique for the tests");
    s.integer("spp", 16).at_least(1).unit("samples per pixel").doc("Samples.").quality_knob(1, 64);
    s.number("radius", 0.05f).above(0).unit("scene units").derived("from the scene").doc("Radius.");
    s.number("alpha", 2.0 / 3.0).above(0).below(1).doc("Fraction kept.");
    s.integer("levels", 6).range(1, 16).doc("Levels.");
    s.boolean("jitter", true).doc("Jitter.");
    s.choice("mode", "off", {"off", "paper", "cell_groups"}).booleans_mean("cell_groups", "off").doc("Mode a | b.");
    s.text("name", "x").doc("A name.");
    return s;
}

std::string error_of(const SettingsSchema& schema, const nlohmann::json& given, const std::string& key) {
    try {
        Settings s(given, "cfg");
        if (key.empty())
            schema.check_known(s);
        else if (schema.spec(key).type == SettingType::Integer)
            schema.get<int>(s, key);
        else if (schema.spec(key).type == SettingType::Number)
            schema.get<double>(s, key);
        else if (schema.spec(key).type == SettingType::Boolean)
            schema.get<bool>(s, key);
        else
            schema.get<std::string>(s, key);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

std::string test_float_error(const SettingsSchema& schema, const nlohmann::json& given) {
    try {
        schema.get<float>(Settings(given, "cfg"), given.begin().key());
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(SettingsSchema, DefaultsComeFromTheDeclaration) {
    const SettingsSchema schema = example();
    const Settings empty;
    EXPECT_EQ(schema.get<int>(empty, "spp"), 16);
    EXPECT_FLOAT_EQ(schema.get<float>(empty, "alpha"), 2.0f / 3.0f);
    EXPECT_TRUE(schema.get<bool>(empty, "jitter"));
    EXPECT_EQ(schema.get<std::string>(empty, "mode"), "off");
    EXPECT_FALSE(schema.get_given<float>(empty, "radius").has_value());
    EXPECT_TRUE(empty.was_read("spp"));
    EXPECT_TRUE(empty.was_read("radius"));
    // A float default is declared as its shortest decimal, which reads back as the float.
    EXPECT_EQ(schema.spec("radius").default_value.is_null(), true);
    SettingsSchema floats("f", "floats");
    floats.number("r", 0.05f);
    EXPECT_EQ(floats.spec("r").default_text(), "0.05");
    EXPECT_EQ(floats.get<float>(Settings(), "r"), 0.05f);
    // A derived default is read with get_given; get is a programming error.
    EXPECT_THROW(schema.get<float>(empty, "radius"), std::logic_error);
    EXPECT_THROW(schema.get<int>(empty, "undeclared"), std::logic_error);
}

TEST(SettingsSchema, GivenValuesAreChecked) {
    const SettingsSchema schema = example();
    EXPECT_EQ(schema.get<int>(Settings(nlohmann::json{{"spp", 4}}), "spp"), 4);
    EXPECT_EQ(*schema.get_given<float>(Settings(nlohmann::json{{"radius", 0.5}}), "radius"), 0.5f);
    EXPECT_NE(error_of(schema, {{"spp", 0}}, "spp").find("setting 'spp' must be at least 1 (samples per pixel), got 0"),
              std::string::npos)
        << error_of(schema, {{"spp", 0}}, "spp");
    EXPECT_NE(error_of(schema, {{"radius", 0}}, "radius").find("'radius' must be positive"), std::string::npos);
    EXPECT_NE(error_of(schema, {{"alpha", 1}}, "alpha").find("'alpha' must be in (0, 1), got 1"), std::string::npos)
        << error_of(schema, {{"alpha", 1}}, "alpha");
    EXPECT_NE(error_of(schema, {{"levels", 17}}, "levels").find("'levels' must be 1 to 16, got 17"), std::string::npos);
    EXPECT_NE(error_of(schema, {{"levels", 2.5}}, "levels").find("levels"), std::string::npos);  // not whole
    EXPECT_NE(error_of(schema, {{"spp", 1e12}}, "spp").find("spp"), std::string::npos);         // does not fit an int
    EXPECT_NE(error_of(schema, {{"jitter", "yes"}}, "jitter").find("wrong type"), std::string::npos);
    EXPECT_NE(error_of(schema, {{"mode", "on"}}, "mode").find("'mode' must be one of off, paper, cell_groups, got 'on'"),
              std::string::npos);
    EXPECT_NE(error_of(schema, {{"mode", 3}}, "mode").find("'mode' must be one of"), std::string::npos);
    EXPECT_NE(error_of(schema, {{"name", 3}}, "name").find("wrong type"), std::string::npos);
    // The declared range is what a message names, before the fit of the C++ type.
    EXPECT_NE(error_of(schema, {{"levels", -5}}, "levels").find("'levels' must be 1 to 16, got -5"), std::string::npos);
    // A float is checked as stored: 1e-50 is positive, but not as a float.
    const std::string tiny = test_float_error(schema, {{"alpha", 1e-50}});
    EXPECT_NE(tiny.find("'alpha' must be in (0, 1), got 1e-50 (0 as stored)"), std::string::npos) << tiny;
    // check_values checks every given value at once.
    EXPECT_NO_THROW(schema.check_values(Settings(nlohmann::json{{"spp", 3}, {"mode", "paper"}})));
    EXPECT_THROW(schema.check_values(Settings(nlohmann::json{{"spp", 3}, {"mode", "on"}})), Error);
    EXPECT_THROW(schema.check_values(Settings(nlohmann::json{{"spq", 3}})), Error);
    // Booleans of older settings files stand for choices.
    EXPECT_EQ(schema.get<std::string>(Settings(nlohmann::json{{"mode", true}}), "mode"), "cell_groups");
    EXPECT_EQ(schema.get<std::string>(Settings(nlohmann::json{{"mode", false}}), "mode"), "off");
}

TEST(SettingsSchema, UnknownKeysAreNamedWithTheNearestDeclaredOne) {
    const SettingsSchema schema = example();
    EXPECT_EQ(error_of(schema, {{"spp", 2}, {"mode", "paper"}}, ""), "");
    const std::string one = error_of(schema, {{"sp", 2}}, "");
    EXPECT_NE(one.find("unknown setting 'sp' (did you mean 'spp'?)"), std::string::npos) << one;
    EXPECT_NE(one.find("`gilab list settings demo`"), std::string::npos) << one;
    const std::string two = error_of(schema, {{"sp", 2}, {"completely_else", 1}}, "");
    EXPECT_NE(two.find("unknown settings 'completely_else', 'sp'"), std::string::npos) << two;
}

TEST(SettingsSchema, TablesListEveryKeyAndTheKnob) {
    const SettingsSchema schema = example();
    ASSERT_NE(schema.quality_knob(), nullptr);
    EXPECT_EQ(schema.quality_knob()->key, "spp");
    const std::string text = schema.table_text();
    for (const SettingSpec& s : schema.specs()) EXPECT_NE(text.find("  " + s.key + " "), std::string::npos) << s.key;
    EXPECT_NE(text.find("Quality knob of equal-time comparisons (searched in 1 … 64)"), std::string::npos) << text;
    EXPECT_NE(text.find("Default: from the scene."), std::string::npos) << text;
    const std::string md = schema.table_markdown();
    EXPECT_NE(md.find("| `mode` | choice | off | off \\| paper \\| cell_groups | Mode a \\| b. |"), std::string::npos) << md;
    EXPECT_NE(md.find("| `spp` | integer | 16 | ≥ 1 (samples per pixel) |"), std::string::npos) << md;
    EXPECT_THROW(SettingsSchema("d", "t").choice("c", "x", {"a", "b"}), std::logic_error);
    SettingsSchema twice("d", "t");
    twice.integer("a", 1);
    EXPECT_THROW(twice.integer("a", 2), std::logic_error);
}

}  // namespace
}  // namespace gilab
