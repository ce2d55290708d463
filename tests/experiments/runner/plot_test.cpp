// SVG plots drawn by gnuplot: the file is a complete SVG holding every legend label, log
// axes and non-finite points are handled, hostile labels neither break the script nor
// run anything, bad plots throw, output is byte-for-byte deterministic, and the
// experiment runner writes, lists and links the figures (or notes why it could not).
#include <gtest/gtest.h>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include "core/util/error.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/report/html_report.hpp"
#include "experiments/runner/plot.hpp"
#include "tests/test_support.hpp"

namespace {

using namespace gilab;
namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

size_t file_count(const fs::path& dir) {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
}

bool looks_like_svg(const std::string& text) {
    return (text.rfind("<?xml", 0) == 0 || text.rfind("<svg", 0) == 0) && text.find("</svg>") != std::string::npos;
}

// The message write_svg_plot throws for this plot, or "<no error>".
std::string plot_error(const Plot& plot, const fs::path& dir, const std::string& name) {
    return test::error_of([&] { write_svg_plot(plot, dir, name); });
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

Plot two_series_plot() {
    Plot plot;
    plot.title = "Build time against photon count";
    plot.x_label = "photons";
    plot.y_label = "build time (ms)";
    plot.series.push_back({"ours kd-tree", {1e3, 1e4, 1e5}, {0.5, 6.0, 70.0}});
    PlotSeries paper{"paper kd-tree", {1e3, 1e4, 1e5}, {0.4, 5.0, 65.0}};
    paper.dashed = true;
    paper.color = 0;  // same colour as its measured twin
    plot.series.push_back(paper);
    return plot;
}

class PlotTest : public ::testing::Test {
protected:
    void SetUp() override {
        if (!plotting_available()) GTEST_SKIP() << "gnuplot not found on PATH (install the Debian package gnuplot-nox)";
    }
};

TEST_F(PlotTest, WritesCompleteSvgWithEveryLabel) {
    fs::path dir = test::temp_dir("plot_basic");
    Plot plot = two_series_plot();
    EXPECT_EQ(write_svg_plot(plot, dir, "build_time"), "build_time.svg");
    std::string svg = read(dir / "build_time.svg");
    EXPECT_TRUE(looks_like_svg(svg)) << svg.substr(0, 200);
    for (const std::string& text : {plot.title, plot.x_label, plot.y_label, plot.series[0].label, plot.series[1].label})
        EXPECT_NE(svg.find(text), std::string::npos) << "missing text: " << text;
    EXPECT_NE(svg.find("width=\"720\" height=\"480\""), std::string::npos);
    EXPECT_EQ(file_count(dir), 1u);  // no temporaries left behind
}

TEST_F(PlotTest, LogAxesTickByDecadesAndSkipNonPositivePoints) {
    fs::path dir = test::temp_dir("plot_log");
    Plot plot;
    plot.series.push_back({"memory", {0.0, 1.0, 10.0, 100.0, 1000.0, 10000.0}, {5.0, 1.0, -3.0, 10.0, 100.0, 1000.0}});
    Plot linear = plot;
    plot.log_x = plot.log_y = true;
    write_svg_plot(plot, dir, "log");
    write_svg_plot(linear, dir, "linear");
    std::string log_svg = read(dir / "log.svg"), linear_svg = read(dir / "linear.svg");
    ASSERT_TRUE(looks_like_svg(log_svg));
    ASSERT_TRUE(looks_like_svg(linear_svg));
    // A linear x axis over 0..10000 ticks every 1000 (or 2000); a log one only by decades.
    EXPECT_NE(log_svg.find("> 100</text>"), std::string::npos);
    EXPECT_EQ(log_svg.find("> 2000</text>"), std::string::npos);
    EXPECT_NE(linear_svg.find("> 2000</text>"), std::string::npos);
    // The log script carries only the points a log axis can show.
    std::string script = gnuplot_script(plot);
    EXPECT_NE(script.find("set logscale x"), std::string::npos);
    EXPECT_EQ(script.find("\n0 5\n"), std::string::npos);
    EXPECT_EQ(script.find("-3"), std::string::npos);
    EXPECT_NE(script.find("\n1000 100\n"), std::string::npos);

    Plot nothing_positive;
    nothing_positive.log_y = true;
    nothing_positive.series.push_back({"zeros", {1, 2, 3}, {0, 0, -1}});
    EXPECT_PRED2(contains, plot_error(nothing_positive, dir, "zeros"), "no plottable point");
}

TEST_F(PlotTest, NonFinitePointsAreSkipped) {
    fs::path dir = test::temp_dir("plot_nan");
    Plot with_gaps;
    with_gaps.title = "gaps";
    with_gaps.series.push_back({"ours", {1, 2, 3, 4, 5, kNaN}, {1, kNaN, 3, kInf, 5, 6}});
    with_gaps.series.push_back({"all missing", {1, 2}, {kNaN, -kInf}});
    with_gaps.series.push_back({"empty", {}, {}});
    Plot clean;
    clean.title = "gaps";
    clean.series.push_back({"ours", {1, 3, 5}, {1, 3, 5}});
    std::string script = gnuplot_script(with_gaps);
    EXPECT_EQ(script.find("nan"), std::string::npos);
    EXPECT_EQ(script.find("inf"), std::string::npos);
    write_svg_plot(with_gaps, dir, "with_gaps");
    write_svg_plot(clean, dir, "clean");
    std::string svg = read(dir / "with_gaps.svg");
    ASSERT_TRUE(looks_like_svg(svg));
    // Series with no point left are not drawn and not in the legend.
    EXPECT_EQ(svg.find("all missing"), std::string::npos);
    EXPECT_EQ(svg.find(">empty<"), std::string::npos);
    EXPECT_EQ(svg, read(dir / "clean.svg"));  // skipping a point == never having had it
}

TEST_F(PlotTest, HostileLabelsAreWrittenLiterally) {
    fs::path dir = test::temp_dir("plot_escape");
    fs::path marker = dir / "marker";
    Plot plot;
    plot.title = "it's \"quoted\"; t_build^2 {x} @macro $var \\n";
    plot.x_label = "set output '/tmp/x'";
    plot.y_label = "`touch " + marker.string() + "`";
    plot.series.push_back({"ours_kd; plot sin(x)", {1, 2}, {3, 4}});
    plot.series.push_back({"line\nbreak", {1, 2}, {4, 3}});
    write_svg_plot(plot, dir, "escape");
    std::string svg = read(dir / "escape.svg");
    ASSERT_TRUE(looks_like_svg(svg));
    // Literal text: underscores and carets are not sub/superscripts, quotes survive.
    EXPECT_NE(svg.find("it's \"quoted\"; t_build^2 {x} @macro $var \\n"), std::string::npos);
    EXPECT_NE(svg.find("set output '/tmp/x'"), std::string::npos);
    EXPECT_NE(svg.find("ours_kd; plot sin(x)"), std::string::npos);
    EXPECT_NE(svg.find("line break"), std::string::npos);  // control characters become spaces
    EXPECT_FALSE(fs::exists(marker)) << "a backquoted label ran a command";
}

TEST_F(PlotTest, BadPlotsThrow) {
    fs::path dir = test::temp_dir("plot_errors");
    EXPECT_PRED2(contains, plot_error(Plot{}, dir, "none"), "no plottable point");
    Plot empty_series;
    empty_series.series.push_back({"empty", {}, {}});
    EXPECT_PRED2(contains, plot_error(empty_series, dir, "empty"), "no plottable point");
    Plot all_nan;
    all_nan.series.push_back({"nan", {kNaN, 1}, {1, kInf}});
    EXPECT_PRED2(contains, plot_error(all_nan, dir, "nan"), "no plottable point");
    Plot ragged;
    ragged.series.push_back({"ragged", {1, 2, 3}, {1, 2}});
    EXPECT_PRED2(contains, plot_error(ragged, dir, "ragged"), "3 x values but 2 y values");
    for (const char* name : {"", "../escape", "a/b", ".hidden", "with space"})
        EXPECT_PRED2(contains, plot_error(two_series_plot(), dir, name), "plot name") << name;
    EXPECT_EQ(file_count(dir), 0u);
}

TEST_F(PlotTest, SameInputGivesSameBytes) {
    fs::path a = test::temp_dir("plot_determinism_a"), b = test::temp_dir("plot_determinism_b");
    write_svg_plot(two_series_plot(), a, "fig");
    write_svg_plot(two_series_plot(), b, "fig");
    std::string first = read(a / "fig.svg");
    EXPECT_FALSE(first.empty());
    EXPECT_EQ(first, read(b / "fig.svg"));
    // Overwriting in place gives the same bytes again.
    write_svg_plot(two_series_plot(), a, "fig");
    EXPECT_EQ(first, read(a / "fig.svg"));
}

Experiment fake_experiment() {
    Experiment e;
    e.name = "fake-plot";
    e.paper = "core";
    e.description = "a table and two figures";
    e.run = [](const ExperimentContext&) {
        ExperimentOutput out;
        ResultTable table;
        table.title = "numbers";
        table.columns = {"photons", "ms", "paper ms"};
        table.rows.push_back({{"photons", 1000}, {"ms", 0.5}, {"paper ms", 0.4}});
        out.tables.push_back(table);
        out.plots.emplace_back("build_time", two_series_plot());
        Plot empty;
        empty.title = "nothing";
        out.plots.emplace_back("empty_fig", empty);
        return out;
    };
    return e;
}

TEST_F(PlotTest, RunnerWritesListsAndLinksFigures) {
    fs::path root = test::temp_dir("plot_runner");
    ExperimentContext context;
    context.output_dir = root / "fake-plot";
    ExperimentOutput out = run_and_write(fake_experiment(), context);

    std::string svg = read(context.output_dir / "build_time.svg");
    EXPECT_TRUE(looks_like_svg(svg));
    EXPECT_NE(svg.find("paper kd-tree"), std::string::npos);
    EXPECT_FALSE(fs::exists(context.output_dir / "empty_fig.svg"));
    ASSERT_EQ(out.files.size(), 1u);
    EXPECT_EQ(out.files[0], "build_time.svg");

    std::string md = read(context.output_dir / "table.md");
    EXPECT_NE(md.find("![Build time against photon count](build_time.svg)"), std::string::npos) << md;
    // A figure that cannot be drawn is a note, not a failed run.
    EXPECT_NE(md.find("Plot empty_fig was not drawn"), std::string::npos) << md;
    nlohmann::json doc = nlohmann::json::parse(read(context.output_dir / "results.json"));
    EXPECT_EQ(doc["files"], nlohmann::json::array({"build_time.svg"}));

    EXPECT_EQ(write_html_report(root), 1);
    EXPECT_NE(read(root / "report.html").find("<img src=\"fake-plot/build_time.svg\">"), std::string::npos);
}

// Sets PATH for one scope and restores it.
class ScopedPath {
public:
    explicit ScopedPath(const fs::path& dir) {
        if (const char* old = std::getenv("PATH")) saved_ = old;
        ::setenv("PATH", dir.c_str(), 1);
    }
    ~ScopedPath() {
        if (saved_) ::setenv("PATH", saved_->c_str(), 1);
        else ::unsetenv("PATH");
    }

private:
    std::optional<std::string> saved_;
};

// A stand-in gnuplot that fails at once: its stderr must reach the message, and the
// script it never reads (large, so the write cannot fit a socket buffer) must not kill
// us with SIGPIPE.
TEST(PlotWithFailingGnuplot, ErrorCarriesExitStatusAndStderr) {
    fs::path dir = test::temp_dir("plot_failing_gnuplot");
    fs::path bin = dir / "bin";
    fs::path fake = test::write_file(bin, "gnuplot", "#!/bin/sh\necho 'line 7: unexpected thing' >&2\nexit 3\n");
    fs::permissions(fake, fs::perms::owner_all);
    fs::path silent = test::write_file(dir / "silent_bin", "gnuplot", "#!/bin/sh\nexit 0\n");
    fs::permissions(silent, fs::perms::owner_all);
    Plot big;
    PlotSeries series{"many", {}, {}};
    for (int i = 0; i < 200000; ++i) series.x.push_back(i), series.y.push_back(std::sin(i * 0.001));
    big.series.push_back(series);
    {
        ScopedPath path(bin);
        ASSERT_TRUE(plotting_available());
        std::string error = plot_error(big, dir, "big");
        EXPECT_PRED2(contains, error, "gnuplot failed (exit status 3)");
        EXPECT_PRED2(contains, error, "line 7: unexpected thing");
    }
    {
        ScopedPath path(dir / "silent_bin");
        EXPECT_PRED2(contains, plot_error(two_series_plot(), dir, "silent"), "gnuplot wrote no complete SVG");
    }
    EXPECT_FALSE(fs::exists(dir / "big.svg"));
    EXPECT_FALSE(fs::exists(dir / "silent.svg"));
}

// Runs without gnuplot on purpose, so it is not a PlotTest.
TEST(PlotWithoutGnuplot, RunnerNotesMissingGnuplotAndKeepsTables) {
    fs::path root = test::temp_dir("plot_no_gnuplot");
    fs::path empty_bin = root / "empty_bin";
    fs::create_directories(empty_bin);
    ExperimentContext context;
    context.output_dir = root / "fake-plot";
    std::string error;
    ExperimentOutput out;
    {
        ScopedPath path(empty_bin);
        EXPECT_FALSE(plotting_available());
        try {
            out = run_and_write(fake_experiment(), context);
        } catch (const std::exception& e) {
            error = e.what();
        }
    }
    ASSERT_EQ(error, "");
    EXPECT_FALSE(fs::exists(context.output_dir / "build_time.svg"));
    EXPECT_TRUE(out.files.empty());
    EXPECT_TRUE(fs::exists(context.output_dir / "results.json"));
    std::string md = read(context.output_dir / "table.md");
    EXPECT_NE(md.find("Plot build_time was not drawn"), std::string::npos) << md;
    EXPECT_NE(md.find("gnuplot not found on PATH"), std::string::npos) << md;
    EXPECT_NE(md.find("| 1000 |"), std::string::npos) << md;  // the table is still there
}

}  // namespace
