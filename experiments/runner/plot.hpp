#pragma once
// Paper-style line plots, declared as data and drawn to SVG by gnuplot. Experiments put
// them next to their tables so a figure can be compared with the paper's at a glance.
#include <filesystem>
#include <string>
#include <vector>

namespace gilab {

struct PlotSeries {
    std::string label;
    std::vector<double> x, y;    // same length; non-finite points are skipped
    bool dashed = false;         // paper curves are drawn dashed, measured ones solid
    bool points = true;          // mark each data point (lines only when false)
    int color = -1;              // palette slot; -1 = by position. Give a paper curve the
                                 // slot of its measured twin so the pair reads as one.
};

struct Plot {
    std::string title, x_label, y_label;
    bool log_x = false, log_y = false;  // points with a non-positive coordinate on a log axis are skipped
    std::vector<PlotSeries> series;     // series left with no points are left out
};

// Writes dir/NAME.svg (720x480, legend, grid) by running gnuplot on a generated script
// fed through stdin; the file appears atomically. NAME may hold letters, digits, '_', '-'
// and '.'. Returns the file name written ("NAME.svg"). The same plot gives the same bytes.
// Throws Error if the plot is malformed (x/y lengths differ, no plottable point at all,
// bad name), if gnuplot is not on PATH, or if gnuplot fails (its stderr is included).
std::string write_svg_plot(const Plot& plot, const std::filesystem::path& dir, const std::string& name);

// The gnuplot script write_svg_plot runs (SVG goes to stdout); exposed for tests and
// for reproducing a figure by hand.
std::string gnuplot_script(const Plot& plot);

// True if a gnuplot executable is found on PATH.
bool plotting_available();

}  // namespace gilab
