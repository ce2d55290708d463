// Declared experiments: the plan, one task at a time, and merging tasks that ran
// separately into the same tables as the one-command run.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <gtest/gtest.h>
#include "core/util/error.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/spec_functions.hpp"
#include "experiments/runner/spec_runner.hpp"
#include "scenes/builtin_scenes.hpp"
#include "experiments/runner/task_command.hpp"
#include "tests/test_support.hpp"

namespace gilab {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// A small spec on the built-in Cornell box: two variants × two photon counts × one radius.
ExperimentSpec cornell_spec() {
    using Source = SpecMeasure::Source;
    return {
        .name = "test-sweep",
        .paper = "P1",
        .figure = "Test",
        .description = "two photon maps, two photon counts",
        .scenes = {"cornell"},
        .size = 24, .quick_size = 16,
        .frames = 2, .quick_frames = 2,
        .reference_spp = 8, .quick_reference_spp = 4,
        .variants = {{.name = "hash grid", .technique = "photon", .settings = {{"photon_map", "hash_grid"}}},
                     {.name = "kd-tree", .technique = "photon", .settings = {{"photon_map", "kd_tree"}}}},
        .axes = {{"photons", {4096, 8192}, {1024, 2048}}, {"radius", {0.1}, {0.1}}},
        .measures = {{"frame_ms", Source::FrameStat, "render_ms"},
                     {"photons_stored", Source::PrepareStat, "photons_stored"},
                     {"relmse_color", Source::RelMse, "color"}},
        .notes = {"a spec for the tests"},
    };
}

ExperimentContext context(const fs::path& dir, bool quick = true) {
    ExperimentContext ctx;
    ctx.quick = quick;
    ctx.output_dir = dir;
    ctx.seed = 3;
    return ctx;
}

TEST(SpecRunner, ThePlanIsEveryCombinationWithTheAxesApplied) {
    const std::vector<SpecTask> quick = plan_tasks(cornell_spec(), true);
    ASSERT_EQ(quick.size(), 4u);  // 2 photon counts × 1 radius × 2 variants
    EXPECT_EQ(quick[0].variants.at(0).settings, (json{{"photon_map", "hash_grid"}, {"photons", 1024}, {"radius", 0.1}}));
    EXPECT_EQ(quick[1].variants.at(0).name, "kd-tree");
    EXPECT_EQ(quick[3].axes, (json{{"photons", 2048}, {"radius", 0.1}}));
    for (size_t i = 0; i < quick.size(); ++i) EXPECT_EQ(quick[i].id, int(i));
    EXPECT_EQ(plan_tasks(cornell_spec(), false)[2].axes.at("photons"), 8192);
}

TEST(SpecRunner, ABadSpecIsRefusedNamingTheProblem) {
    ExperimentSpec unknown_key = cornell_spec();
    unknown_key.variants[0].settings["photon_maps"] = "kd_tree";
    EXPECT_NE(test::error_of([&] { unknown_key.check(); }).find("'photon_maps' (did you mean 'photon_map'?)"),
              std::string::npos);
    ExperimentSpec unknown_axis = cornell_spec();
    unknown_axis.axes.push_back({"cones", {1}, {1}});
    EXPECT_NE(test::error_of([&] { unknown_axis.check(); }).find("axis 'cones'"), std::string::npos);
    ExperimentSpec unknown_technique = cornell_spec();
    unknown_technique.variants[0].technique = "photons";
    EXPECT_NE(test::error_of([&] { unknown_technique.check(); }).find("unknown technique"), std::string::npos);
    ExperimentSpec empty_axis = cornell_spec();
    empty_axis.axes[0].quick.clear();
    EXPECT_NE(test::error_of([&] { empty_axis.check(); }).find("no values"), std::string::npos);
}

TEST(SpecRunner, TasksRunSeparatelyMergeIntoTheTablesOfTheWholeRun) {
    const ExperimentSpec spec = cornell_spec();
    const fs::path whole_dir = test::temp_dir("spec_whole"), parts_dir = test::temp_dir("spec_parts");
    const ExperimentOutput whole = run_spec(spec, context(whole_dir));
    // The tasks in reverse order, as separate machines might finish them.
    for (int id = 3; id >= 0; --id) run_spec_task(spec, id, context(parts_dir));
    const ExperimentOutput merged = merge_spec_tasks(spec, context(parts_dir));
    ASSERT_EQ(whole.tables.size(), 1u);
    ASSERT_EQ(merged.tables.size(), 1u);
    const ResultTable &a = whole.tables[0], &b = merged.tables[0];
    EXPECT_EQ(a.columns, b.columns);
    EXPECT_EQ(a.columns, (std::vector<std::string>{"scene", "photons (emitted per frame)", "radius (scene units)",
                                                   "variant", "frame_ms", "photons_stored", "relmse_color", "frames"}));
    ASSERT_EQ(a.rows.size(), 4u);
    ASSERT_EQ(b.rows.size(), 4u);
    for (size_t i = 0; i < a.rows.size(); ++i) {
        for (const char* key : {"scene", "photons (emitted per frame)", "radius (scene units)", "variant",
                                "photons_stored", "relmse_color", "frames"})
            EXPECT_EQ(a.rows[i].at(key), b.rows[i].at(key)) << key << " in row " << i;
        EXPECT_GT(a.rows[i].at("frame_ms").get<double>(), 0.0);
        EXPECT_GT(b.rows[i].at("frame_ms").get<double>(), 0.0);
        EXPECT_GT(a.rows[i].at("relmse_color").get<double>(), 0.0);
    }
    // More photons are stored when more are emitted, and the two maps store the same photons.
    EXPECT_LT(a.rows[0].at("photons_stored").get<double>(), a.rows[2].at("photons_stored").get<double>());
    EXPECT_EQ(a.rows[0].at("photons_stored"), a.rows[1].at("photons_stored"));
    // The path-traced reference the relMSE compares with is listed with the outputs.
    EXPECT_TRUE(std::any_of(whole.files.begin(), whole.files.end(),
                            [](const std::string& f) { return f.find("reference") != std::string::npos; }));
    EXPECT_EQ(whole.config.at("name"), "test-sweep");
    EXPECT_EQ(whole.config.at("effective").at("tasks"), 4);
}

TEST(SpecRunner, ASpecReadsBackFromItsJson) {
    ExperimentSpec spec = cornell_spec();
    spec.interleave_variants = true;
    spec.slow = {.frame_ms = 100, .frames = 1};
    spec.statistic = FrameStatistic::Mean;
    spec.axes.push_back({"", {json{{"k", 16}, {"gather", "knn"}}}, {json{{"k", 8}, {"gather", "knn"}}}});
    const ExperimentSpec back = ExperimentSpec::from_json(spec.to_json());
    EXPECT_EQ(back.to_json(), spec.to_json());
    EXPECT_EQ(plan_tasks(back, true).size(), plan_tasks(spec, true).size());
    json bad = spec.to_json();
    bad["measures"][0]["source"] = "frame stat (mean)";
    EXPECT_NE(test::error_of([&] { ExperimentSpec::from_json(bad); }).find("unknown measure source"), std::string::npos);
}

// A probe measures what is not a technique run; a reducer lays out the table. Both are
// called by name, and the probe's shared setup is built once per run.
TEST(SpecRunner, ProbesAndReducersRunByName) {
    static int loads = 0;
    add_probe("test-meshes", [](const ProbeCall& call) {
        const size_t meshes = call.cache.get<size_t>("triangles", [&] {
            ++loads;
            return call.scene().meshes.size();
        });
        return ProbeOutput{{json{{"meshes × factor", double(meshes) * call.setting<double>("factor")}}},
                           {"counted " + call.task.scene},
                           {}};
    });
    add_reducer("test-total", [](const SpecReduction& r) {
        ExperimentOutput out;
        ResultTable t{"total", {"total"}, {}};
        double total = 0;
        for (const TaskResult& task : r.tasks) total += task.row("count")->at("meshes × factor").get<double>();
        t.rows.push_back({{"total", total}});
        out.tables = {r.default_table(), t};
        return out;
    });
    const ExperimentSpec spec{.name = "test-probe",
                              .scenes = {"cornell"},
                              .variants = {{.name = "count", .probe = "test-meshes"}},
                              .axes = {{"factor", {1.0, 2.0, 3.0}, {1.0, 2.0}}},
                              .reducer = "test-total"};
    const fs::path dir = test::temp_dir("spec_probe");
    const ExperimentOutput out = run_spec(spec, context(dir));
    EXPECT_EQ(loads, 1);  // one run, one cache
    const double meshes = double(make_cornell_box().meshes.size());
    ASSERT_EQ(out.tables.size(), 2u);
    EXPECT_EQ(out.tables[0].columns, (std::vector<std::string>{"scene", "factor", "variant", "meshes × factor"}));
    EXPECT_EQ(out.tables[0].rows.at(1).at("meshes × factor").get<double>(), 2 * meshes);
    EXPECT_EQ(out.tables[1].rows.at(0).at("total").get<double>(), 3 * meshes);
    EXPECT_NE(std::find(out.notes.begin(), out.notes.end(), "counted cornell"), out.notes.end());
    // A task run on its own builds what it needs itself.
    run_spec_task(spec, 1, context(dir));
    EXPECT_EQ(loads, 2);
    ExperimentSpec unknown = spec;
    unknown.variants[0].probe = "no-such-probe";
    EXPECT_NE(test::error_of([&] { unknown.check(); }).find("no probe named 'no-such-probe'"), std::string::npos);
}

// Interleaved variants share a task: one task per point, a row per variant.
TEST(SpecRunner, InterleavedVariantsShareATask) {
    ExperimentSpec spec = cornell_spec();
    spec.interleave_variants = true;
    spec.measures.push_back({"digest", SpecMeasure::Source::ImageDigest, "color"});
    const std::vector<SpecTask> tasks = plan_tasks(spec, true);
    ASSERT_EQ(tasks.size(), 2u);
    EXPECT_EQ(tasks[0].variants.size(), 2u);
    const ExperimentOutput out = run_spec(spec, context(test::temp_dir("spec_interleaved")));
    const ResultTable& t = out.tables.at(0);
    ASSERT_EQ(t.rows.size(), 4u);
    EXPECT_EQ(t.rows[0].at("variant"), "hash grid");
    EXPECT_EQ(t.rows[1].at("variant"), "kd-tree");
    EXPECT_EQ(t.rows[0].at("digest").get<std::string>().size(), 16u);
    EXPECT_NE(t.rows[0].at("digest"), t.rows[2].at("digest"));  // more photons, another image
}

TEST(SpecRunner, ASceneThatCannotBeLoadedIsSkippedWithANote) {
    ExperimentSpec spec = cornell_spec();
    spec.scenes = {"conference"};  // a shared asset
    ExperimentContext ctx = context(test::temp_dir("spec_missing_scene"));
    ctx.assets = AssetPaths({ctx.output_dir / "no-such-assets"});
    const ExperimentOutput out = run_spec(spec, ctx);
    EXPECT_TRUE(out.tables.at(0).rows.empty());
    EXPECT_TRUE(std::any_of(out.notes.begin(), out.notes.end(), [](const std::string& n) {
        return n.find("Scene 'conference' skipped") != std::string::npos;
    }));
}

size_t merged_rows(const ExperimentSpec& spec, const fs::path& dir, bool quick) {
    return merge_spec_tasks(spec, context(dir, quick)).tables.at(0).rows.size();
}

TEST(SpecRunner, AnAxisValueOutsideTheSchemaStopsThePlan) {
    ExperimentSpec bad = cornell_spec();
    bad.axes[1].quick = {0.1, -1};
    const std::string error = test::error_of([&] { plan_tasks(bad, true); });
    EXPECT_NE(error.find("setting 'radius' must be positive"), std::string::npos) << error;
    EXPECT_NO_THROW(plan_tasks(bad, false));  // the full plan has no such value
}

TEST(SpecRunner, MergeListsMissingTasksAndRefusesAnotherPlansFiles) {
    const ExperimentSpec spec = cornell_spec();
    const fs::path dir = test::temp_dir("spec_merge");
    EXPECT_NE(test::error_of([&] { merge_spec_tasks(spec, context(dir)); }).find("no task has run yet"),
              std::string::npos);
    run_spec_task(spec, 2, context(dir));
    const ExperimentOutput partial = merge_spec_tasks(spec, context(dir));
    ASSERT_EQ(partial.tables.at(0).rows.size(), 1u);
    bool listed = false;
    for (const std::string& note : partial.notes) listed |= note.find("3 of 4 tasks have not run (0, 1, 3)") != std::string::npos;
    EXPECT_TRUE(listed);
    EXPECT_EQ(partial.config.at("effective").at("tasks_missing"), (json{0, 1, 3}));
    // The quick plan's tasks are not the full plan's: they are kept apart.
    const std::string error = test::error_of([&] { merge_spec_tasks(spec, context(dir, false)); });
    EXPECT_NE(error.find("tasks/full holds none of the 4 tasks"), std::string::npos) << error;
    EXPECT_EQ(merged_rows(spec, dir, true), 1u);
    // A task file of another spec (more frames) is refused, naming the file and the reason.
    ExperimentSpec more_frames = spec;
    more_frames.quick_frames = 3;
    const std::string changed = test::error_of([&] { merge_spec_tasks(more_frames, context(dir)); });
    EXPECT_NE(changed.find("2.json"), std::string::npos) << changed;
    EXPECT_NE(changed.find("'frames' differs"), std::string::npos) << changed;
    // A task file from another --quick is named as such.
    fs::create_directories(dir / "tasks" / "full");
    fs::copy_file(dir / "tasks" / "quick" / "2.json", dir / "tasks" / "full" / "2.json");
    const std::string other_quick = test::error_of([&] { merge_spec_tasks(spec, context(dir, false)); });
    EXPECT_NE(other_quick.find("written with --quick; merge with --quick"), std::string::npos) << other_quick;
    // A file cut short is refused naming it.
    std::ofstream(dir / "tasks" / "quick" / "0.json") << "{\"quick\": tr";
    EXPECT_NE(test::error_of([&] { merge_spec_tasks(spec, context(dir)); }).find("0.json: not a task result"),
              std::string::npos);
    EXPECT_NE(test::error_of([&] { run_spec_task(spec, 4, context(dir)); }).find("no task 4"), std::string::npos);
}

TEST(SpecRunner, TheCommandPlansDeclaredExperimentsOnly) {
    TaskCommand plan;
    plan.verb = "plan";
    plan.arguments = {"pm-radius-sweep"};
    plan.quick = true;
    std::ostringstream out;
    EXPECT_EQ(run_task_command(plan, out), 0);
    std::istringstream lines(out.str());
    int count = 0;
    for (std::string line; std::getline(lines, line); ++count) {
        const json task = json::parse(line);
        EXPECT_EQ(task.at("id"), count);
        EXPECT_EQ(task.at("variants").at(0).at("technique"), "photon");
        EXPECT_TRUE(task.at("variants").at(0).at("settings").contains("radius"));
    }
    EXPECT_EQ(count, 4);
    plan.arguments = {"pm-table99"};
    EXPECT_NE(test::error_of([&] { run_task_command(plan, out); }).find("pm-radius-sweep"), std::string::npos);
    TaskCommand bad_id;
    bad_id.verb = "run-task";
    bad_id.arguments = {"pm-radius-sweep", "two"};
    EXPECT_NE(test::error_of([&] { run_task_command(bad_id, out); }).find("not a task id"), std::string::npos);
}

// Reference groups, from the plan alone: the tasks that compare against the same
// path-traced references share one (a sweep renders each group's references once,
// first), tasks that compare against none have none.
TEST(SpecRunner, TasksThatNeedTheSameReferencesShareAGroup) {
    auto groups = [](const std::string& name, bool quick) {
        const ExperimentSpec& spec = *declared_experiment_named(name).spec;
        std::vector<std::string> out;
        for (const SpecTask& t : plan_tasks(spec, quick)) out.push_back(reference_group(spec, t, quick));
        return out;
    };
    // relMSE against the scene camera's reference: one group for the four radii.
    const std::vector<std::string> radius = groups("pm-radius-sweep", true);
    ASSERT_EQ(radius.size(), 4u);
    EXPECT_FALSE(radius[0].empty());
    EXPECT_EQ(std::count(radius.begin(), radius.end(), radius[0]), 4);
    // Ray throughput and the cone-traced images of Figs. 12/13 compare against nothing.
    for (const std::string& g : groups("core-rays", true)) EXPECT_EQ(g, "");
    for (const std::string& g : groups("vct-fig12-13", true)) EXPECT_EQ(g, "");
    // pm-convergence: one group per scene (both halves of its reference).
    const std::vector<std::string> convergence = groups("pm-convergence", false);
    EXPECT_EQ(std::set<std::string>(convergence.begin(), convergence.end()).size(), 2u);
    // vct-stability: only the path-traced leak task renders references.
    const std::vector<std::string> stability = groups("vct-stability", true);
    EXPECT_EQ(stability.size() - size_t(std::count(stability.begin(), stability.end(), "")), 1u);
}

}  // namespace
}  // namespace gilab
