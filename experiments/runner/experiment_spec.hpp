#pragma once
// An experiment declared as data: scenes × variants × sweep axes × measures. The generic
// runner (spec_runner.hpp) expands a spec into tasks — one task = one scene × variant ×
// point on the sweep axes, rendered `frames` times — runs each on its own, writes its raw
// result under results/NAME/tasks/, and merges whatever tasks exist into the tables. The
// configuration written next to the results is the spec itself (to_json).
#include <cstdint>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

namespace gilab {

// A technique with settings, checked against the technique's settings schema.
struct SpecVariant {
    std::string name;       // the table's "variant" column
    std::string technique;  // registry name
    nlohmann::json settings = nlohmann::json::object();
};

// One sweep axis: a technique setting and the values it takes, at full and quick size.
struct SpecAxis {
    std::string setting;
    std::vector<nlohmann::json> full, quick;
};

// What a task measures. Frame stats are the median over the task's frames; prepare stats
// are read once after prepare; relMSE compares the last frame's layer with the
// path-traced reference of the same scene and camera.
struct SpecMeasure {
    enum class Source { FrameStat, PrepareStat, RelMse };
    std::string column;  // the table column, with its unit
    Source source = Source::FrameStat;
    std::string key;     // stats key, or the image layer for RelMse
};

struct ExperimentSpec {
    std::string name, paper, figure, description;
    std::vector<std::string> scenes;  // names as `gilab render` takes them
    int size = 256, quick_size = 64;  // square image, pixels per side
    int frames = 5, quick_frames = 2;  // renders per task
    int reference_spp = 1024, quick_reference_spp = 64;  // path-traced reference (RelMse measures)
    std::vector<SpecVariant> variants;
    std::vector<SpecAxis> axes;
    std::vector<SpecMeasure> measures;
    std::vector<std::string> notes;

    bool needs_reference() const;
    // The spec as written into results.json's "config"; the runner's effective sizes
    // are added beside it.
    nlohmann::json to_json() const;
    // Throws Error naming the spec and the problem: unknown technique, a setting the
    // technique's schema does not declare, an axis without values, no measure.
    void check() const;
};

// One unit of work: a scene, a variant, one value per axis.
struct SpecTask {
    int id = 0;  // position in the plan
    std::string scene;
    std::string variant;
    std::string technique;
    nlohmann::json axes = nlohmann::json::object();  // setting → value
    nlohmann::json settings;                          // the variant's settings with the axes applied
    nlohmann::json to_json() const;
};

// Every task of the spec, in plan order: scenes, then axes (the first axis outermost),
// then variants.
std::vector<SpecTask> plan_tasks(const ExperimentSpec& spec, bool quick);

}  // namespace gilab
