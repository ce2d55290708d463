#pragma once
// `gilab compare`: one scene rendered by several techniques from the same camera (mono,
// or an HMD stereo pair), each compared with a converged path-traced reference: time to
// prepare and per frame, peak memory, relMSE, SSIM, LDR-FLIP and HDR-FLIP, with error heat
// maps.
// Writes RESULTS/compare/SCENE/ (results.json, table.md, index.html, images) in one
// rename, like an experiment.
#include <map>
#include <optional>
#include <string>
#include <vector>
#include "core/io/asset_paths.hpp"

namespace gilab {

// What --equal-time equalises: the whole work that makes one image (prepare + one frame,
// right for a still image) or the frame alone (prepare amortised over an animation).
enum class EqualTimeOf { PrepareAndFrame, Frame };
std::string to_string(EqualTimeOf of);             // "prepare + frame" or "frame"
EqualTimeOf parse_equal_time_of(const std::string& text);  // "total" or "frame"; throws otherwise

struct CompareRequest {
    std::string scene = "cornell";
    std::vector<std::string> techniques = {"path", "photon", "vct"};
    std::optional<std::string> hmd;
    int width = 256, height = 256;             // per eye
    int reference_spp = 1024;
    int frames = 3;                            // renders per technique; the median is reported
    std::optional<double> equal_time_seconds;  // scale each quality knob until the equalised time is this
    EqualTimeOf equal_time_of = EqualTimeOf::PrepareAndFrame;
    std::optional<double> pixels_per_degree;   // FLIP viewing condition
    std::map<std::string, std::string> settings_files;            // technique → JSON file
    std::map<std::string, std::vector<std::string>> assignments;  // technique → key=value
    std::string results = "results";
    uint64_t seed = 1;
    int threads = 0;
    AssetPaths assets;
};

// Returns the folder written.
std::string run_compare(const CompareRequest& request);

// The setting each technique's quality rises with, for --equal-time ("" when none).
std::string quality_knob(const std::string& technique);

}  // namespace gilab
