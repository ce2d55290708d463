#pragma once
// What `gilab compare` writes beside its images: results.json (every figure, the
// settings and stats of each technique), table.md and index.html (the table, then the
// reference and each technique's image with its FLIP, HDR-FLIP and 1 − SSIM heat maps,
// each flipping to the reference in place).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

namespace gilab {

struct CompareEntry {
    std::string technique;
    std::string knob;  // equal time: the quality setting chosen
    double prepare_ms = 0, frame_ms = 0;
    double peak_rss_mib = 0;
    bool peak_rss_exact = false;
    double relmse = 0, ssim = 0, flip = 0, hdr_flip = 0;  // means over the image (and both eyes)
    struct ExposureRange {
        double start, stop;  // stops
        int count;
    };
    std::vector<ExposureRange> hdr_flip_exposures;  // HDR-FLIP's range, one per eye
    nlohmann::json settings, stats;
};

struct CompareReport {
    std::string scene, views;
    int width = 0, height = 0, reference_spp = 0, frames = 0, threads = 0;
    double pixels_per_degree = 0;
    std::optional<double> equal_time_seconds;
    std::string equal_time_of;  // what the equal time holds: "prepare + frame" or "frame"
    std::vector<CompareEntry> entries;
};

void write_compare_report(const std::filesystem::path& dir, const CompareReport& report);

// A few lines a person reads at the end of a run: for each technique compared under
// RESULTS/compare/, its frame time, relMSE and FLIP on each scene. Empty when nothing
// was compared; a comparison whose results.json cannot be read is named as such.
std::string comparison_summary(const std::filesystem::path& results_root);

}  // namespace gilab
