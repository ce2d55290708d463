// The P1 photon-mapping and stereo experiments in quick mode: each one runs and writes
// every column of every row, and in Tables 1–4 the `paper ms` of every row is the
// published figure for that row's paper photon count, radius and variant (written out
// here from the paper's tables, independently of the experiment's own reference data),
// never the measured frame time; Tables 1–4 run with every-hit photon storage and say so,
// and Table 4 reports the three tile_shared modes with identical images.
#include <gtest/gtest.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/path_reference.hpp"
#include "tests/experiment_test_support.hpp"

namespace {

using namespace gilab;
using nlohmann::json;

const ExperimentRegistry& photon_registry() {
    static const ExperimentRegistry registry =
        test::registry_with({register_photon_experiments, register_stereo_experiments});
    return registry;
}

class PhotonQuickExperiment : public testing::TestWithParam<const char*> {};

TEST_P(PhotonQuickExperiment, RunsAndFillsEveryColumn) {
    const ExperimentOutput out = test::run_quick_experiment(photon_registry(), GetParam());
    for (const std::string& note : out.notes) EXPECT_EQ(note.find("Target"), std::string::npos) << note;
}

INSTANTIATE_TEST_SUITE_P(All, PhotonQuickExperiment,
                         testing::Values("pm-fig8", "pm-table5", "pm-final"), test::test_name_of);

// pm-foveated: the fovea and periphery figures of each angle come with the unfoveated
// render's figures over the same masks; the 'off' row has no mask, so it leaves them
// empty instead of printing its whole-image error as a periphery error.
// (PhotonQuickExperiment's checks included: this is pm-foveated's one quick run.)
TEST(PhotonFoveated, EachMaskedErrorHasTheUnfoveatedErrorOverTheSameMask) {
    const ExperimentOutput out = test::run_quick_experiment(photon_registry(), "pm-foveated");
    for (const std::string& note : out.notes) EXPECT_EQ(note.find("Target"), std::string::npos) << note;
    std::map<std::string, double> whole_unfoveated;  // scene → the off row's whole-image relMSE
    int angled = 0;
    for (const json& row : out.tables.at(0).rows) {
        const std::string scene = row.at("scene");
        const double whole = row.at("relmse_vs_path (whole image)").get<double>();
        EXPECT_GT(whole, 0.0) << row.dump();
        if (row.at("fovea_angle") == "off") {
            EXPECT_TRUE(row.at("relmse_periphery_vs_path").is_null()) << row.dump();
            EXPECT_TRUE(row.at("relmse_fovea_vs_path").is_null()) << row.dump();
            whole_unfoveated[scene] = whole;
            continue;
        }
        ASSERT_TRUE(whole_unfoveated.count(scene)) << "the off row comes first: " << row.dump();
        const double fovea = row.at("unfoveated relmse_fovea_vs_path (same mask)").get<double>();
        const double periphery = row.at("unfoveated relmse_periphery_vs_path (same mask)").get<double>();
        const double share = row.at("fovea_pixels").get<double>();
        ASSERT_GT(share, 0.0) << row.dump();
        ASSERT_LT(share, 1.0) << row.dump();
        // The two masks split the image: their pixel-weighted mean is the whole image's.
        EXPECT_NEAR(share * fovea + (1 - share) * periphery, whole_unfoveated[scene], 1e-6 * whole_unfoveated[scene])
            << row.dump();
        ++angled;
    }
    EXPECT_GE(angled, 3);
}

// P1 Tables 1–4 (ms): (photons, radius, variant) → published frame time.
using Key = std::tuple<std::string, double, std::string>;
const std::map<Key, double>& published_ms() {
    static const std::map<Key, double> t = {
        // Table 1: kd-tree vs hash grid.
        {{"512²", 0.02, "kd_tree"}, 7.28}, {{"512²", 0.02, "hash_grid"}, 3.89},
        {{"512²", 0.05, "kd_tree"}, 118.35}, {{"512²", 0.05, "hash_grid"}, 90.74},
        {{"512²", 0.1, "kd_tree"}, 426.39}, {{"512²", 0.1, "hash_grid"}, 501.79},
        {{"256²", 0.05, "kd_tree"}, 8.32}, {{"256²", 0.05, "hash_grid"}, 5.23},
        {{"256²", 0.1, "kd_tree"}, 72.05}, {{"256²", 0.1, "hash_grid"}, 49.29},
        {{"256²", 0.2, "kd_tree"}, 287.87}, {{"256²", 0.2, "hash_grid"}, 362.10},
        {{"128²", 0.05, "kd_tree"}, 2.57}, {{"128²", 0.05, "hash_grid"}, 1.94},
        {{"128²", 0.1, "kd_tree"}, 5.69}, {{"128²", 0.1, "hash_grid"}, 3.67},
        {{"128²", 0.2, "kd_tree"}, 36.29}, {{"128²", 0.2, "hash_grid"}, 22.90},
        // Table 2: heap vs no heap.
        {{"512²", 0.02, "heap"}, 3.89}, {{"512²", 0.02, "no heap"}, 2.33},
        {{"512²", 0.05, "heap"}, 90.74}, {{"512²", 0.05, "no heap"}, 4.36},
        {{"512²", 0.1, "heap"}, 501.79}, {{"512²", 0.1, "no heap"}, 11.43},
        {{"256²", 0.05, "heap"}, 5.23}, {{"256²", 0.05, "no heap"}, 2.30},
        {{"256²", 0.1, "heap"}, 49.29}, {{"256²", 0.1, "no heap"}, 3.94},
        {{"256²", 0.2, "heap"}, 362.10}, {{"256²", 0.2, "no heap"}, 11.24},
        // Table 3: single (fused) vs hybrid (split) kernel.
        {{"512²", 0.05, "fused"}, 4.59}, {{"512²", 0.05, "split"}, 3.41},
        {{"512²", 0.1, "fused"}, 12.39}, {{"512²", 0.1, "split"}, 6.52},
        {{"512²", 0.2, "fused"}, 37.60}, {{"512²", 0.2, "split"}, 17.51},
        {{"256²", 0.05, "fused"}, 2.60}, {{"256²", 0.05, "split"}, 2.31},
        {{"256²", 0.1, "fused"}, 4.03}, {{"256²", 0.1, "split"}, 3.76},
        {{"256²", 0.2, "fused"}, 10.66}, {{"256²", 0.2, "split"}, 6.00},
        // Table 4: without vs with shared memory (Algorithm 1): our tile_shared off | paper.
        {{"512²", 0.05, "off"}, 3.41}, {{"512²", 0.05, "paper"}, 3.18},
        {{"512²", 0.1, "off"}, 6.52}, {{"512²", 0.1, "paper"}, 6.33},
        {{"512²", 0.2, "off"}, 17.51}, {{"512²", 0.2, "paper"}, 15.88},
        {{"256²", 0.05, "off"}, 2.31}, {{"256²", 0.05, "paper"}, 2.25},
        {{"256²", 0.1, "off"}, 3.76}, {{"256²", 0.1, "paper"}, 3.06},
        {{"256²", 0.2, "off"}, 6.00}, {{"256²", 0.2, "paper"}, 5.80},
    };
    return t;
}

class PhotonPaperColumns : public testing::TestWithParam<const char*> {};

TEST_P(PhotonPaperColumns, EveryRowCarriesItsPublishedFigure) {
    const ExperimentOutput out = test::run_quick_experiment(photon_registry(), GetParam());
    int checked = 0;
    for (const ResultTable& t : out.tables)
        for (const json& row : t.rows) {
            if (!row.contains("paper ms") || row["paper ms"].is_null()) continue;
            const Key key{row.at("paper photons").get<std::string>(), row.at("r").get<double>(),
                          row.at("variant").get<std::string>()};
            const auto it = published_ms().find(key);
            ASSERT_NE(it, published_ms().end())
                << GetParam() << ": no published figure for " << std::get<0>(key) << " r " << std::get<1>(key) << " "
                << std::get<2>(key);
            EXPECT_DOUBLE_EQ(row.at("paper ms").get<double>(), it->second) << GetParam() << " " << row.dump();
            EXPECT_NE(row.at("frame_ms").get<double>(), it->second) << "measured column copies the paper";
            ++checked;
        }
    EXPECT_GT(checked, 0) << GetParam() << ": no row carries a paper figure";

    // The tables run the paper's photon map and say so.
    ASSERT_FALSE(out.config.at("variants").empty()) << GetParam();
    for (const json& variant : out.config.at("variants"))
        EXPECT_EQ(variant.at("settings").value("photon_storage", ""), "every_hit") << GetParam() << " " << variant.dump();
    bool storage_note = false;
    for (const std::string& note : out.notes)
        storage_note = storage_note || (note.find("every_hit") != std::string::npos &&
                                        note.find("no shadow rays") != std::string::npos);
    EXPECT_TRUE(storage_note) << GetParam() << ": no note names the storage mode and what it changes";
    for (const json& row : out.tables.at(0).rows)
        EXPECT_GT(row.at("stored_first_hit").get<double>(), 0.0) << GetParam() << " " << row.dump();

    if (std::string(GetParam()) == "pm-table4") {
        // All three modes per row; only off and paper carry the paper's figures; the
        // images are identical; paper mode reports its tiles.
        std::map<std::string, int> modes;
        for (const json& row : out.tables.at(0).rows) {
            const std::string variant = row.at("variant").get<std::string>();
            ++modes[variant];
            EXPECT_EQ(row.at("paper ms").is_null(), variant == "cell_groups") << row.dump();
            if (variant == "paper") {
                EXPECT_GT(row.at("tiles_qualified").get<double>() + row.at("tiles_mixed").get<double>(), 0.0);
            }
        }
        EXPECT_EQ(modes.size(), 3u);
        for (const auto& [variant, count] : modes) EXPECT_EQ(count, 6) << variant;
        for (const json& row : out.tables.at(1).rows) EXPECT_TRUE(row.at("identical images").get<bool>()) << row.dump();
    }
}

INSTANTIATE_TEST_SUITE_P(Tables, PhotonPaperColumns,
                         testing::Values("pm-table1", "pm-table2", "pm-table3", "pm-table4"), test::test_name_of);

// One quick pm-convergence run (most of it the references' rendering) shared by the
// checks below, which one test runs in one process.
const ExperimentOutput& convergence_quick() {
    static const ExperimentOutput out = test::run_quick_experiment(photon_registry(), "pm-convergence");
    return out;
}

void runs_quick_and_fills_its_columns() {
    // pm-convergence: every measured row has a positive time and an error that is either
    // blank or at least the reference's noise; per scene, each variant has its points, a
    // row of times to reach the targets (a number or a string saying why there is none),
    // and one curve in the scene's plot.
    const ExperimentOutput& out = convergence_quick();
    ASSERT_EQ(out.tables.size(), 2u);
    std::map<std::string, std::map<std::string, int>> points;  // scene → variant → rows
    for (const json& row : out.tables[0].rows) {
        EXPECT_GT(row.at("wall ms").get<double>(), 0.0) << row.dump();
        const json& relmse = row.at("relMSE");
        EXPECT_TRUE(relmse.is_null() || relmse.get<double>() >= row.at("reference noise (relMSE)").get<double>())
            << row.dump();
        ++points[row.at("scene").get<std::string>()][row.at("variant").get<std::string>()];
    }
    ASSERT_TRUE(points.count("cornell"));
    for (const auto& [scene, variants] : points) {
        EXPECT_EQ(variants.size(), 3u) << scene;
        for (const auto& [variant, count] : variants) EXPECT_GE(count, 2) << scene << " " << variant;
    }
    EXPECT_EQ(out.tables[1].rows.size(), 3 * points.size());
    for (const json& row : out.tables[1].rows)
        for (const std::string& column : out.tables[1].columns)
            if (column.rfind("ms to", 0) == 0) {
                const json& cell = row.at(column);
                EXPECT_TRUE(cell.is_string() || (cell.is_number() && cell.get<double>() > 0)) << row.dump();
            }
    ASSERT_EQ(out.plots.size(), points.size());
    for (const auto& [name, plot] : out.plots) {
        EXPECT_TRUE(plot.log_x && plot.log_y) << name;
        const std::string scene = name.substr(name.find('_') + 1);
        ASSERT_TRUE(points.count(scene)) << name;
        ASSERT_EQ(plot.series.size(), points.at(scene).size()) << name;
        for (const PlotSeries& series : plot.series) {
            ASSERT_TRUE(points.at(scene).count(series.label)) << name << ": " << series.label;
            EXPECT_LE(int(series.x.size()), points.at(scene).at(series.label)) << name << ": " << series.label;
        }
    }
}

// The leading number of a setting ("64 spp", "8 iterations", "4096 photons").
double count_in(const json& setting) { return std::stod(setting.get<std::string>()); }

// The least-squares slope of log relMSE against log count over the points given.
double log_log_slope(const std::vector<std::pair<double, double>>& points) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [count, relmse] : points) {
        const double x = std::log(count), y = std::log(relmse);
        n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// Error must fall as a variant spends more, at the rate its estimator allows: the path
// tracer's relMSE is variance, ∝ 1/spp (slope −1); progressive photon mapping shrinks
// its radius, so its bias and variance fall together, at a rate that depends on the
// scene. Measured at the quick settings (seed 1, 48²; path 4/16/64 spp, progressive
// 2/8/32 iterations): path −1.04 (cornell), −0.93 (conference); progressive −1.40
// (cornell), −0.46 (conference). The ranges leave about ±0.3 around those, and fail a
// variant whose error stops falling or falls at another rate.
void error_falls_with_samples_and_iterations_at_a_stated_rate() {
    using Range = std::pair<double, double>;
    const std::map<std::pair<std::string, std::string>, Range> slope_range = {
        {{"cornell", "path"}, {-1.3, -0.7}},
        {{"conference", "path"}, {-1.3, -0.7}},
        {{"cornell", "photon progressive"}, {-1.75, -1.05}},
        {{"conference", "photon progressive"}, {-0.75, -0.25}}};
    std::map<std::string, std::map<std::string, std::vector<std::pair<double, double>>>> curves;
    for (const json& row : convergence_quick().tables.at(0).rows) {
        const std::string variant = row.at("variant");
        if (variant != "path" && variant != "photon progressive") continue;
        ASSERT_TRUE(row.at("relMSE").is_number()) << "below the reference's noise: " << row.dump();
        curves[row.at("scene")][variant].push_back({count_in(row.at("setting")), row.at("relMSE").get<double>()});
    }
    ASSERT_TRUE(curves.count("cornell"));
    for (const auto& [scene, variants] : curves) {
        ASSERT_EQ(variants.size(), 2u) << scene;
        for (const auto& [variant, points] : variants) {
            ASSERT_GE(points.size(), 3u) << scene << " " << variant;
            for (size_t i = 1; i < points.size(); ++i)
                EXPECT_LT(points[i].second, points[i - 1].second) << scene << " " << variant << " at " << points[i].first;
            const double slope = log_log_slope(points);
            std::printf("[%s] %s: log-log slope %.3f\n", scene.c_str(), variant.c_str(), slope);
            const auto range = slope_range.find({scene, variant});
            ASSERT_NE(range, slope_range.end()) << "no slope measured for " << scene << " " << variant;
            EXPECT_GE(slope, range->second.first) << scene << " " << variant;
            EXPECT_LE(slope, range->second.second) << scene << " " << variant;
        }
    }
}

// Each scene's reference is the mean of two halves on independent seeds; the noise they
// show is printed in every row and is at most a tenth of the smallest error reported.
void the_reference_is_at_most_a_tenth_of_the_smallest_error_reported() {
    std::map<std::string, double> noise, smallest;
    for (const json& row : convergence_quick().tables.at(0).rows) {
        const std::string scene = row.at("scene");
        const double n = row.at("reference noise (relMSE)").get<double>();
        EXPECT_GT(n, 0.0) << row.dump();
        if (noise.count(scene)) {
            EXPECT_EQ(noise[scene], n) << "one reference per scene: " << row.dump();
        }
        noise[scene] = n;
        if (row.at("relMSE").is_number())
            smallest[scene] = std::min(smallest.count(scene) ? smallest[scene] : 1e300, row.at("relMSE").get<double>());
    }
    ASSERT_TRUE(noise.count("cornell"));
    for (const auto& [scene, n] : noise) {
        std::printf("[%s] reference noise %.3g, smallest error reported %.3g\n", scene.c_str(), n, smallest[scene]);
        EXPECT_LE(n, 0.1 * smallest[scene]) << scene;
    }
}

TEST(PhotonConvergence, QuickRunFillsItsColumnsFallsAtItsRatesAndOutrunsItsReferenceNoise) {
    {
        SCOPED_TRACE("columns");
        runs_quick_and_fills_its_columns();
    }
    {
        SCOPED_TRACE("rates");
        error_falls_with_samples_and_iterations_at_a_stated_rate();
    }
    {
        SCOPED_TRACE("reference noise");
        the_reference_is_at_most_a_tenth_of_the_smallest_error_reported();
    }
}

// A probe's references function names the references its task compares against:
// rendered first (`gilab experiment references`), the task finds every one in the store,
// renders none, and lists exactly the files rendered. pm-fig8 needs one reference at the
// scene camera, pm-convergence two jittered halves on different seeds; the specs are
// shrunk to 16² images and a few samples, on the Cornell box (built in).
class PhotonProbeReferences : public testing::TestWithParam<const char*> {};

ExperimentSpec small_spec(const std::string& name) {
    ExperimentSpec spec = *photon_registry().get(name).spec;
    spec.name += "-small";
    spec.scenes = {"cornell"};
    spec.quick_size = 16;
    spec.quick_frames = 1;
    spec.quick_reference_spp = 4;
    if (name == "pm-fig8") spec.axes.at(0).quick = {json{{"photons", 32 * 32}, {"radius", 0.08}}};
    if (name == "pm-convergence") spec.variants.at(0).settings["reference_spp_per_half"]["quick"]["cornell"] = 4;
    return spec;
}

TEST_P(PhotonProbeReferences, TheTaskFindsTheReferencesRenderedForIt) {
    namespace fs = std::filesystem;
    const ExperimentSpec spec = small_spec(GetParam());
    ExperimentContext ctx;
    ctx.quick = true;
    ctx.output_dir = test::temp_dir(std::string("probe_references_") + GetParam()) / spec.name;
    ctx.assets = AssetPaths::from_environment();
    std::ostringstream log;
    ctx.log = &log;
    const int rendered = render_task_references(spec, 0, ctx);
    EXPECT_EQ(rendered, std::string(GetParam()) == "pm-convergence" ? 2 : 1);
    std::set<std::string> stored;
    for (const auto& entry : fs::directory_iterator(reference_store(ctx)))
        if (entry.path().extension() == ".exr") stored.insert(entry.path().filename().string());
    ASSERT_EQ(int(stored.size()), rendered) << log.str();

    log.str("");
    const json result = run_spec_task(spec, 0, ctx);
    const std::string said = log.str();
    EXPECT_EQ(said.find("rendering the path-traced reference"), std::string::npos) << said;
    std::set<std::string> listed;
    for (const json& file : result.at("files"))
        if (file.get<std::string>().starts_with("reference_path_")) listed.insert(file.get<std::string>());
    EXPECT_EQ(listed, stored);
    size_t found = 0;
    for (size_t at = said.find("reference from the store"); at != std::string::npos;
         at = said.find("reference from the store", at + 1))
        ++found;
    EXPECT_EQ(found, stored.size()) << said;
}

INSTANTIATE_TEST_SUITE_P(Probes, PhotonProbeReferences, testing::Values("pm-fig8", "pm-convergence"),
                         test::test_name_of);

}  // namespace
