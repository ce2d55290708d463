#pragma once
// An experiment declared as data: scenes × sweep points × variants × measures. The
// generic runner (spec_runner.hpp) expands a spec into tasks — one task = one scene ×
// one point on the sweep axes × one variant (or all variants, rendered in turn, when
// they are interleaved) — runs each on its own, writes its raw result under
// results/NAME/tasks/, and merges whatever tasks exist into the tables. The configuration
// written next to the results is the spec itself (to_json).
//
// A variant is a technique with settings (checked against the technique's schema) or a
// named probe (spec_functions.hpp): a measurement that is not a technique run, such as a
// structure build or a ray-throughput count. A named reducer turns the tasks' rows into
// the experiment's tables when the default table (one row per task and variant) is not
// the published layout.
#include <cstdint>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

namespace gilab {

struct SpecVariant {
    std::string name;       // the table's "variant" column
    std::string technique;  // registry name, or
    std::string probe;      // a probe's name (exactly one of the two)
    nlohmann::json settings = nlohmann::json::object();
    bool is_probe() const { return !probe.empty(); }
};

// One sweep axis at full and quick size. With a setting, each value is that setting's
// value; without one, each value is an object of settings that change together (one row
// of a published table: photons and radius, say).
struct SpecAxis {
    std::string setting;
    std::vector<nlohmann::json> full, quick;
};

// What a technique task measures for each variant. Frame stats are the median over the
// task's frames (or the mean: ExperimentSpec::statistic); last-frame stats are read after the last frame; prepare stats once
// after prepare; relMSE compares the last frame's layer with the path-traced reference
// of the same scene and camera; a layer mean is the last frame's mean of that layer; an
// image digest is a hash of the last frame's layer (equal digests: identical images).
struct SpecMeasure {
    enum class Source { FrameStat, PrepareStat, RelMse, LastFrameStat, LayerMean, ImageDigest };
    std::string column;  // the table column, with its unit
    Source source = Source::FrameStat;
    std::string key;     // stats key, or the image layer
};

// Fewer frames for slow variants: when a variant's first frame takes longer than
// `frame_ms`, the task renders at most `frames` frames.
struct SpecSlowFrames {
    double frame_ms = 0;  // 0: never
    int frames = 0;
};

// How frame stats over a task's frames become one figure.
enum class FrameStatistic { Median, Mean };

struct ExperimentSpec {
    std::string name, paper, figure, description;
    // Scene names as `gilab render` takes them (technique variants), or the labels a
    // probe understands (a model, a walk).
    std::vector<std::string> scenes;
    int size = 256, quick_size = 64;  // square image, pixels per side
    int frames = 5, quick_frames = 2;  // renders per task
    int reference_spp = 1024, quick_reference_spp = 64;  // path-traced reference (RelMse measures)
    SpecSlowFrames slow;
    FrameStatistic statistic = FrameStatistic::Median;  // of FrameStat measures
    // All variants in one task, rendered in turn frame by frame (A B C A B C …), so that
    // a change in machine load hits them alike and ratios between them are fair.
    bool interleave_variants = false;
    std::vector<SpecVariant> variants;
    std::vector<SpecAxis> axes;
    std::vector<SpecMeasure> measures;  // technique variants; a probe returns its own columns
    std::string reducer;                // "" = the default table
    std::vector<std::string> notes;

    bool needs_reference() const;
    bool has_technique_variant() const;
    // The spec as written into results.json's "config"; the runner's effective sizes are
    // added beside it. from_json reads it back (a spec declared as a dict in Python).
    nlohmann::json to_json() const;
    static ExperimentSpec from_json(const nlohmann::json& j);
    // Throws Error naming the spec and the problem: unknown technique or probe or reducer,
    // a setting the technique's schema does not declare, an axis without values, a
    // technique variant without a measure.
    void check() const;
};

// One variant of a task, with the point's settings applied.
struct TaskVariant {
    std::string name, technique, probe;
    nlohmann::json settings;
};

// One unit of work: a scene, one point on the axes, one variant (all of them when
// interleaved).
struct SpecTask {
    int id = 0;  // position in the plan
    std::string scene;
    nlohmann::json axes = nlohmann::json::object();  // setting → value
    std::vector<TaskVariant> variants;
    nlohmann::json to_json() const;
};

// The spec swept along extra axes, each given as SETTING=V1,V2,… (values read as JSON
// where they parse, else as text; the same for the full and the quick plan): an axis of
// the spec on that setting gets these values, another setting becomes a new axis (the
// innermost). Checked like any spec; an Error names the text when it is not
// SETTING=VALUES, or the setting is one an axis of objects sets already.
ExperimentSpec with_extra_axes(ExperimentSpec spec, const std::vector<std::string>& axes);

// Every task of the spec, in plan order: scenes, then axes (the first axis outermost),
// then variants.
std::vector<SpecTask> plan_tasks(const ExperimentSpec& spec, bool quick);

}  // namespace gilab
