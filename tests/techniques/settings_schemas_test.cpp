// Every technique's settings schema against its parser: the parser reads every declared
// key, the defaults parse, and the README's settings tables are the schemas'.
#include <fstream>
#include <sstream>
#include <gtest/gtest.h>
#include "core/util/error.hpp"
#include "scenes/builtin_scenes.hpp"
#include "techniques/technique.hpp"

namespace gilab {
namespace {

TEST(TechniqueSettingsSchemas, EveryTechniqueDeclaresItsSettingsAndReadsEveryDeclaredKey) {
    const Scene scene = make_cornell_box();
    for (const TechniqueInfo& info : TechniqueRegistry::builtin().list()) {
        const SettingsSchema& schema = info.settings_schema();
        EXPECT_EQ(schema.technique(), info.name);
        ASSERT_FALSE(schema.specs().empty()) << info.name;
        // Small sizes so the prepare is quick; every key must be asked for by the parser,
        // given or not (a declared key nobody reads would be a setting that does nothing).
        nlohmann::json small = nlohmann::json::object();
        for (const char* key : {"resolution", "photons", "frames"})
            if (schema.declares(key)) small[key] = std::string(key) == "photons" ? 1024 : 8;
        if (info.name == "vct") small["resolution"] = 8;
        Settings settings(small, info.name + " settings");
        auto technique = info.create();
        try {
            technique->prepare(scene, settings);
        } catch (const Error&) {
            // A scene the technique refuses (no light of the kind it needs) still parsed first.
        }
        for (const SettingSpec& spec : schema.specs())
            EXPECT_TRUE(settings.was_read(spec.key)) << info.name << ": '" << spec.key << "' is declared but not read";
        EXPECT_NO_THROW(settings.report_unused()) << info.name;
        EXPECT_NO_THROW(schema.check_known(settings)) << info.name;
    }
}

TEST(TechniqueSettingsSchemas, EachDefaultGivenExplicitlyIsAccepted) {
    const Scene scene = make_cornell_box();
    for (const TechniqueInfo& info : TechniqueRegistry::builtin().list()) {
        for (const SettingSpec& spec : info.settings_schema().specs()) {
            if (spec.default_value.is_null()) continue;
            if (info.name == "photon" && spec.key == "light_samples") continue;  // fine alone; refused with every_hit
            nlohmann::json given = {{spec.key, spec.default_value}};
            for (const char* key : {"resolution", "photons", "frames"})
                if (info.settings_schema().declares(key) && key != spec.key)
                    given[key] = std::string(key) == "photons" ? 1024 : 8;
            auto technique = info.create();
            try {
                technique->prepare(scene, Settings(given, "cfg"));
            } catch (const Error& e) {
                // Only a refusal unrelated to the value is fine: the scene lacks a light kind,
                // or the key needs another setting (iterations needs progressive=true).
                const std::string what = e.what();
                if (what.find("'" + spec.key + "' needs ") != std::string::npos) continue;
                EXPECT_EQ(what.find("'" + spec.key + "'"), std::string::npos)
                    << info.name << ": the default of '" << spec.key << "' is refused: " << e.what();
            }
        }
    }
}

TEST(TechniqueSettingsSchemas, TheReadmeTablesAreTheSchemas) {
    std::ifstream in(std::string(GILAB_SOURCE_DIR) + "/README.md");
    ASSERT_TRUE(in) << "README.md not found";
    std::stringstream text;
    text << in.rdbuf();
    const std::string readme = text.str();
    for (const TechniqueInfo& info : TechniqueRegistry::builtin().list()) {
        const std::string begin = "<!-- settings " + info.name + ": ";
        const std::string end = "<!-- end settings " + info.name + " -->";
        const size_t b = readme.find(begin);
        ASSERT_NE(b, std::string::npos) << "README.md has no settings table for " << info.name;
        const size_t table = readme.find('\n', b) + 1;
        const size_t e = readme.find(end, table);
        ASSERT_NE(e, std::string::npos) << "README.md: the settings table for " << info.name << " has no end marker";
        EXPECT_EQ(readme.substr(table, e - table), info.settings_schema().table_markdown())
            << "README.md's settings table for " << info.name << " differs from the schema; replace it with the output "
            << "of `gilab list settings " << info.name << " --markdown`";
    }
}

}  // namespace
}  // namespace gilab
