// `gilab compare` (experiments/app/compare_command.hpp): what it writes, that its figures are
// measured against the reference it writes, equal-time tuning, and its refusals.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include "core/util/error.hpp"
#include "core/image/image_io.hpp"
#include "core/image/image_metrics.hpp"
#include "experiments/app/compare_command.hpp"
#include "tests/test_support.hpp"

namespace fs = std::filesystem;
using namespace gilab;

namespace {

CompareRequest small_request(const std::string& name) {
    CompareRequest r;
    r.scene = "cornell";
    r.techniques = {"path", "photon"};
    r.width = r.height = 24;
    r.reference_spp = 64;
    r.frames = 1;
    r.results = test::temp_dir(name).string();
    r.assignments["path"] = {"spp=4"};
    r.assignments["photon"] = {"photons=4096"};
    return r;
}

nlohmann::json read_json(const fs::path& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
}

TEST(Compare, WritesImagesHeatMapsTableAndFiguresMeasuredAgainstTheReference) {
    const CompareRequest r = small_request("compare_basic");
    const fs::path dir = run_compare(r);
    EXPECT_EQ(dir, fs::path(r.results) / "compare" / "cornell");
    for (const char* f : {"results.json", "table.md", "index.html", "reference.exr", "reference.png"})
        EXPECT_TRUE(fs::exists(dir / f)) << f;
    const nlohmann::json doc = read_json(dir / "results.json");
    ASSERT_EQ(doc["techniques"].size(), 2u);
    const Film reference = read_exr(dir / "reference.exr");
    for (const auto& e : doc["techniques"]) {
        const std::string t = e["technique"];
        for (const std::string suffix : {".exr", ".png", "_flip.png", "_hdrflip.png", "_ssim.png"})
            EXPECT_TRUE(fs::exists(dir / (t + suffix))) << t << suffix;
        // The figures are those of the images written.
        const Film image = read_exr(dir / (t + ".exr"));
        EXPECT_NEAR(e["relmse"].get<double>(), relative_mse(image, reference), 1e-9) << t;
        EXPECT_NEAR(e["ssim"].get<double>(), ssim_map(image, reference).mean, 1e-9) << t;
        EXPECT_NEAR(e["flip"].get<double>(), flip_map(image, reference).mean, 1e-9) << t;
        const HdrFlip hdr = hdr_flip_map(image, reference);
        EXPECT_NEAR(e["hdr_flip"].get<double>(), hdr.flip.mean, 1e-9) << t;
        EXPECT_EQ(e["hdr_flip_exposures"][0]["count"].get<int>(), hdr.exposures) << t;
        EXPECT_GT(e["hdr_flip"].get<double>(), 0.0);
        EXPECT_NEAR(e["prepare_plus_frame_ms"].get<double>(), e["prepare_ms"].get<double>() + e["frame_ms"].get<double>(),
                    1e-9);
        EXPECT_GT(e["frame_ms"].get<double>(), 0.0);
        EXPECT_GT(e["flip"].get<double>(), 0.0);
        EXPECT_LT(e["ssim"].get<double>(), 1.0);
    }
    // No staging folder is left behind (.references is the reference store).
    for (const auto& entry : fs::directory_iterator(dir.parent_path())) {
        if (entry.path().filename() != ".references") {
            EXPECT_NE(entry.path().filename().string().rfind(".", 0), 0u) << entry.path();
        }
    }
    EXPECT_TRUE(fs::is_directory(dir.parent_path() / ".references"));
}

TEST(Compare, MoreSamplesGiveLessErrorAgainstTheSameReference) {
    CompareRequest r = small_request("compare_spp");
    r.techniques = {"path"};
    r.assignments["path"] = {"spp=1"};
    r.assignments.erase("photon");
    const double one = read_json(fs::path(run_compare(r)) / "results.json")["techniques"][0]["relmse"];
    r.assignments["path"] = {"spp=32"};
    const double many = read_json(fs::path(run_compare(r)) / "results.json")["techniques"][0]["relmse"];
    EXPECT_LT(many, 0.5 * one);
}

TEST(Compare, EqualTimeScalesTheQualitySettingAndSaysSo) {
    CompareRequest r = small_request("compare_equal_time");
    r.techniques = {"path"};
    r.assignments.clear();
    r.equal_time_seconds = 0.002;  // far below 16 spp at 24×24: the tuning must lower spp
    const nlohmann::json doc = read_json(fs::path(run_compare(r)) / "results.json");
    const std::string knob = doc["techniques"][0]["quality_setting"];
    ASSERT_EQ(knob.rfind("spp=", 0), 0u) << knob;
    EXPECT_LT(std::stoi(knob.substr(4)), 16) << knob;
    EXPECT_EQ(doc["techniques"][0]["settings"]["spp"].get<int>(), std::stoi(knob.substr(4)));
    EXPECT_EQ(quality_knob("photon"), "photons");
    EXPECT_EQ(quality_knob("dag_raycast"), "");
}

// A still image's cost is its prepare (the photon pass, the voxelization) and its frame:
// equal time holds both unless the frame alone is asked for, and the outputs say which.
TEST(Compare, EqualTimeEqualisesPrepareAndFrameUnlessTheFrameIsAskedFor) {
    CompareRequest r = small_request("compare_equal_total");
    r.techniques = {"photon"};
    r.assignments.clear();
    r.equal_time_seconds = 0.05;
    const fs::path dir = run_compare(r);
    nlohmann::json doc = read_json(dir / "results.json");
    EXPECT_EQ(doc["equal_time_of"], "prepare + frame");
    std::ifstream md(dir / "table.md");
    const std::string table((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
    EXPECT_NE(table.find("Equal time of prepare + frame"), std::string::npos) << table;
    EXPECT_NE(table.find("prepare + frame (ms)"), std::string::npos) << table;

    r.equal_time_of = EqualTimeOf::Frame;
    r.techniques = {"path"};  // the photon frame alone would want millions of photons
    r.equal_time_seconds = 0.002;
    doc = read_json(fs::path(run_compare(r)) / "results.json");
    EXPECT_EQ(doc["equal_time_of"], "frame");
    EXPECT_EQ(parse_equal_time_of("total"), EqualTimeOf::PrepareAndFrame);
    EXPECT_EQ(parse_equal_time_of("frame"), EqualTimeOf::Frame);
    EXPECT_THROW(parse_equal_time_of("prepare"), Error);
}

TEST(Compare, BadRequestsAreRefusedAndLeaveNothing) {
    CompareRequest r = small_request("compare_bad");
    r.techniques = {"path", "nope"};
    EXPECT_THROW(run_compare(r), Error);
    r.techniques = {"path", "path"};
    EXPECT_THROW(run_compare(r), Error);
    r.techniques = {"path", "", "photon"};
    EXPECT_NE(test::error_of([&] { run_compare(r); }).find("empty technique name"), std::string::npos);
    r.techniques = {"path"};
    r.assignments["photon"] = {"radius=0.1"};  // a setting for a technique not compared
    EXPECT_THROW(run_compare(r), Error);
    r.assignments.clear();
    r.assignments["path"] = {"no_such_setting=1"};
    const std::string message = test::error_of([&] { run_compare(r); });
    EXPECT_NE(message.find("no_such_setting"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(fs::path(r.results) / "compare" / "cornell"));
    EXPECT_FALSE(fs::exists(fs::path(r.results) / "compare" / ".cornell.partial"));
}

}  // namespace
