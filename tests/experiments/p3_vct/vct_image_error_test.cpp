// The cone tracer's image error must not grow: cascaded and dense VCT on Cornell, Sponza
// and Sibenik at 64² against a 256-spp path-traced reference (`gilab compare` with these
// sizes), relMSE and LDR-FLIP at most 2 % above what the float32, one-block-per-face
// implementation measured at the same settings (the bounds below; a faster cone tracer
// may change the image only within them). Scenes missing from the assets are skipped.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include "experiments/app/compare_command.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;

namespace {

struct ErrorBound {
    const char* scene;
    const char* structure;
    double relmse, flip;  // measured by the float32 implementation (gilab e5645f6)
};

// gilab compare SCENE -t vct --set vct:structure=S -W 64 -H 64 --reference-spp 256 --frames 1
constexpr ErrorBound kBounds[] = {
    {"cornell", "cascaded", 0.02757543509767831, 0.22617765966333536},
    {"cornell", "dense", 0.02245610966313419, 0.21930596436027372},
    {"sponza", "cascaded", 0.1334987620647544, 0.3939150077699196},
    {"sponza", "dense", 0.10455115338341932, 0.3395950685937805},
    {"sibenik", "cascaded", 0.07369715311923973, 0.32679345246287994},
    {"sibenik", "dense", 0.06333418017134253, 0.2966222169561661},
};

void PrintTo(const ErrorBound& b, std::ostream* os) { *os << b.scene << ", " << b.structure; }

class VctImageError : public ::testing::TestWithParam<ErrorBound> {};

TEST_P(VctImageError, StaysWithinTwoPercentOfTheFloatImplementation) {
    const ErrorBound& b = GetParam();
    CompareRequest r;
    r.scene = b.scene;
    r.techniques = {"vct"};
    r.width = r.height = 64;
    r.reference_spp = 256;
    r.frames = 1;
    r.results = test::temp_dir(std::string("vct_error_") + b.scene + "_" + b.structure).string();
    r.assignments["vct"] = {std::string("structure=") + b.structure};
    r.assets = AssetPaths::from_environment();
    if (std::string(b.scene) != "cornell" && !r.assets.find(std::string(b.scene) + "/" + b.scene + ".obj"))
        GTEST_SKIP() << b.scene << " is not in the assets (set GILAB_ASSETS)";
    const fs::path dir = run_compare(r);
    std::ifstream in(dir / "results.json");
    const nlohmann::json doc = nlohmann::json::parse(in);
    const nlohmann::json& e = doc["techniques"].at(0);
    const double relmse = e["relmse"].get<double>(), flip = e["flip"].get<double>();
    std::printf("%s %s: relMSE %.5f (bound %.5f), FLIP %.5f (bound %.5f)\n", b.scene, b.structure, relmse,
                1.02 * b.relmse, flip, 1.02 * b.flip);
    EXPECT_LE(relmse, 1.02 * b.relmse);
    EXPECT_LE(flip, 1.02 * b.flip);
}

INSTANTIATE_TEST_SUITE_P(All, VctImageError, ::testing::ValuesIn(kBounds), [](const auto& info) {
    return std::string(info.param.scene) + "_" + info.param.structure;
});

}  // namespace
