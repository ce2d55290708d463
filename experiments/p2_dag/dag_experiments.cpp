// P2 (sparse voxel DAGs): node and pointer totals (Table 1), storage (Table 2), SVO→SVDAG
// conversion time (Table 3) and primary-ray traversal (Fig. 13) on the Stanford models,
// with OpenVDB and OctoMap built from the same voxels as reference structures. Declared
// experiments: a task is one model at one resolution (one row of the published table);
// the probes below measure it, the reducers lay the rows out as the paper's tables.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include "accel/dag/esvo.hpp"
#include "accel/peers/octomap_tree.hpp"
#include "accel/peers/openvdb_grid.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"
#include "accel/dag/voxel_ray_traversal.hpp"
#include "core/scene/camera.hpp"
#include "core/util/error.hpp"
#include "core/image/film.hpp"
#include "core/image/image_io.hpp"
#include "core/util/parallel.hpp"
#include "core/scene/scene.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxelizer.hpp"
#include "experiments/p2_dag/dag_models.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/measures.hpp"
#include "experiments/runner/paper_figures.hpp"
#include "experiments/runner/spec_functions.hpp"
#include "scenes/scene_library.hpp"

namespace gilab {

namespace {

using nlohmann::json;
using namespace p2;

// ---- The paper's published figures (experiments/papers/p2; reference data, never used as results) ----

// Table 1 at 1000³, in units of 10⁴ as printed.
struct PaperCounts {
    double svo_nodes, svo_pointers, esvo_nodes, esvo_pointers, dag_nodes, dag_pointers;
};
std::optional<PaperCounts> paper_table1(const std::string& paper_scene) {
    const PaperRow* r = paper_figures("p2/table1").find({{"scene", paper_scene}});
    if (!r) return std::nullopt;
    return PaperCounts{r->number("svo nodes (×10⁴)"),  r->number("svo pointers (×10⁴)"),
                       r->number("esvo nodes (×10⁴)"), r->number("esvo pointers (×10⁴)"),
                       r->number("svdag nodes (×10⁴)"), r->number("svdag pointers (×10⁴)")};
}

// Table 2, MB.
struct PaperStorage {
    double svo, esvo, svdag;
};
std::optional<PaperStorage> paper_table2(const std::string& paper_scene, uint32_t res) {
    const PaperRow* r = paper_figures("p2/table2").find({{"scene", paper_scene}, {"resolution", res}});
    if (!r) return std::nullopt;
    return PaperStorage{r->number("svo MB"), r->number("esvo MB"), r->number("svdag MB")};
}

// Table 3, ms: t_A (whole conversion) and t_B (identical-node search).
struct PaperTimes {
    double t_a, t_b;
};
std::optional<PaperTimes> paper_table3(const std::string& paper_scene, uint32_t res) {
    const PaperRow* r = paper_figures("p2/table3").find({{"scene", paper_scene}, {"resolution", res}});
    if (!r) return std::nullopt;
    return PaperTimes{r->number("t_A ms"), r->number("t_B ms")};
}

// ---- Formatting ----

// The values of the spec's only axis in this run (quick or full).
const std::vector<json>& axis_points(const SpecReduction& r) {
    return r.ctx.quick ? r.spec.axes.at(0).quick : r.spec.axes.at(0).full;
}

// ---- dag-structures: every structure on one model's voxels (Tables 1 and 2) ----

void measure_structures(const ProbeCall& call, const Model& model, ProbeOutput& out) {
    const auto res = call.setting<uint32_t>("resolution");
    const ExperimentContext& ctx = call.ctx;
    ctx.say(model.label + " " + cube(res) + ": voxelizing");
    const VoxelList voxels = voxelize(model.positions, model.triangles, model_grid(model, res));
    ctx.say(model.label + " " + cube(res) + ": " + std::to_string(voxels.size()) + " voxels; SVO, ESVO, SVDAG");
    const Svo svo = Svo::build(voxels);
    const Esvo esvo = Esvo::from_svo(svo);
    const Svdag dag = Svdag::from_svo(svo);
    ctx.say(model.label + " " + cube(res) + ": OpenVDB, OctoMap");
    const OpenVdbVoxels vdb(voxels);
    const OctomapVoxels octomap(voxels);

    const uint64_t n = voxels.size();
    const bool agree = svo.voxel_count() == n && esvo.voxel_count() == n && dag.voxel_count() == n &&
                       vdb.voxel_count() == n && octomap.voxel_count() == n;
    const double svo_nodes = double(svo.node_count()), svo_ptrs = double(svo.pointer_count());
    const double dag_nodes = double(dag.node_count()), dag_ptrs = double(dag.pointer_count());
    const double svo_bytes = double(svo.pointerless_bytes()), esvo_bytes = double(esvo.bytes()),
                 dag_bytes = double(dag.bytes());
    out.rows.push_back({{"scene", model.label},
                        {"resolution", res},
                        {"voxels", n},
                        // Table 1: counts
                        {"svo_nodes", svo.node_count()},
                        {"svo_pointers", svo.pointer_count()},
                        {"esvo_nodes", esvo.node_count()},
                        {"esvo_pointers", esvo.pointer_count()},
                        {"svdag_nodes", dag.node_count()},
                        {"svdag_pointers", dag.pointer_count()},
                        {"svo_over_svdag_nodes", ratio(svo_nodes, dag_nodes)},
                        {"svo_over_svdag_pointers", ratio(svo_ptrs, dag_ptrs)},
                        {"esvo_over_svo_nodes", ratio(double(esvo.node_count()), svo_nodes)},
                        // Table 1: the reference structures and build times
                        {"svo_voxels", svo.voxel_count()},
                        {"esvo_voxels", esvo.voxel_count()},
                        {"svdag_voxels", dag.voxel_count()},
                        {"openvdb_voxels", vdb.voxel_count()},
                        {"octomap_voxels", octomap.voxel_count()},
                        {"voxel_counts_agree", agree},
                        {"openvdb_leaf_nodes", vdb.leaf_node_count()},
                        {"openvdb_internal_nodes", vdb.internal_node_count()},
                        {"openvdb_MB", mb(double(vdb.bytes()))},
                        {"octomap_nodes", octomap.node_count()},
                        {"octomap_leaf_nodes", octomap.leaf_node_count()},
                        {"octomap_MB", mb(double(octomap.bytes()))},
                        {"voxelize_ms", voxels.stats.ms},
                        {"svo_build_ms", svo.build_ms()},
                        {"esvo_build_ms", esvo.build_ms()},
                        {"svdag_build_ms", dag.build_stats().total_ms},
                        {"openvdb_build_ms", vdb.build_ms()},
                        {"octomap_build_ms", octomap.build_ms()},
                        // Table 2: storage
                        {"svo_pointerless_MB", mb(svo_bytes)},
                        {"svo_stored_MB", mb(double(svo.bytes()))},
                        {"esvo_MB", mb(esvo_bytes)},
                        {"svdag_MB", mb(dag_bytes)},
                        {"svo_over_svdag", ratio(svo_bytes, dag_bytes)},
                        {"esvo_over_svdag", ratio(esvo_bytes, dag_bytes)}});
    if (!agree) out.notes.push_back(model.label + ": the structures disagree on the voxel count (see the second table)");
}

// ---- dag-table1 ----

ExperimentOutput reduce_table1(const SpecReduction& r) {
    const uint32_t res = axis_points(r).at(0).get<uint32_t>();
    ResultTable main;
    main.title = "Nodes and pointers at " + cube(res) + " (counts; the paper's figures multiplied out from ×10⁴)";
    main.columns = {"scene",
                    "resolution",
                    "voxels",
                    "svo_nodes",
                    "svo_pointers",
                    "esvo_nodes",
                    "esvo_pointers",
                    "svdag_nodes",
                    "svdag_pointers",
                    "svo_over_svdag_nodes",
                    "paper_svo_over_svdag_nodes",
                    "svo_over_svdag_pointers",
                    "paper_svo_over_svdag_pointers",
                    "esvo_over_svo_nodes",
                    "paper_esvo_over_svo_nodes",
                    "paper_svo_nodes",
                    "paper_svo_pointers",
                    "paper_esvo_nodes",
                    "paper_esvo_pointers",
                    "paper_svdag_nodes",
                    "paper_svdag_pointers"};
    ResultTable ref;
    ref.title = "Reference structures on the same voxels, and build times";
    ref.columns = {"scene",          "resolution",      "voxels",          "svo_voxels",          "esvo_voxels",
                   "svdag_voxels",   "openvdb_voxels",  "octomap_voxels",  "voxel_counts_agree",  "openvdb_leaf_nodes",
                   "openvdb_internal_nodes", "openvdb_MB", "octomap_nodes", "octomap_leaf_nodes", "octomap_MB",
                   "voxelize_ms",    "svo_build_ms",    "esvo_build_ms",   "svdag_build_ms",      "openvdb_build_ms",
                   "octomap_build_ms"};
    for (const TaskResult& t : r.tasks)
        for (json row : t.rows) {
            if (auto p = paper_table1(model_spec(t.task.scene).paper)) {
                row["paper_svo_over_svdag_nodes"] = p->svo_nodes / p->dag_nodes;
                row["paper_svo_over_svdag_pointers"] = p->svo_pointers / p->dag_pointers;
                row["paper_esvo_over_svo_nodes"] = p->esvo_nodes / p->svo_nodes;
                row["paper_svo_nodes"] = p->svo_nodes * 1e4;
                row["paper_svo_pointers"] = p->svo_pointers * 1e4;
                row["paper_esvo_nodes"] = p->esvo_nodes * 1e4;
                row["paper_esvo_pointers"] = p->esvo_pointers * 1e4;
                row["paper_svdag_nodes"] = p->dag_nodes * 1e4;
                row["paper_svdag_pointers"] = p->dag_pointers * 1e4;
            }
            main.rows.push_back(project(row, main.columns));
            ref.rows.push_back(project(row, ref.columns));
        }
    ExperimentOutput out;
    out.tables = {std::move(main), std::move(ref)};
    return out;
}

// ---- dag-table2 ----

ExperimentOutput reduce_table2(const SpecReduction& r) {
    ResultTable table;
    table.title = "Storage (MB = 10⁶ bytes)";
    table.columns = {"scene",
                     "resolution",
                     "voxels",
                     "svo_pointerless_MB",
                     "svo_stored_MB",
                     "esvo_MB",
                     "svdag_MB",
                     "openvdb_MB",
                     "octomap_MB",
                     "svo_over_svdag",
                     "paper_svo_over_svdag",
                     "esvo_over_svdag",
                     "paper_esvo_over_svdag",
                     "paper_svo_MB",
                     "paper_esvo_MB",
                     "paper_svdag_MB"};
    for (const TaskResult& t : r.tasks)
        for (json row : t.rows) {
            if (auto p = paper_table2(model_spec(t.task.scene).paper, row["resolution"].get<uint32_t>())) {
                row["paper_svo_MB"] = p->svo;
                row["paper_esvo_MB"] = p->esvo;
                row["paper_svdag_MB"] = p->svdag;
                row["paper_svo_over_svdag"] = p->svo / p->svdag;
                row["paper_esvo_over_svdag"] = p->esvo / p->svdag;
            }
            table.rows.push_back(project(row, table.columns));
        }
    ExperimentOutput out;
    out.tables = {std::move(table)};
    return out;
}

// ---- dag-table3 ----

// t_A and t_B of repeated conversions.
struct ConversionTimes {
    std::vector<double> t_a, t_b;
    void add(const SvdagBuildStats& s) {
        t_a.push_back(s.total_ms);
        t_b.push_back(s.dedup_ms);
    }
};

// A whole-SVO conversion: voxels → SVO once, then SVO → SVDAG `reps` times at all threads
// and under a 1-thread limit, with the codes → SVDAG phase the split rows time beside it.
std::optional<json> whole_conversion(const ProbeCall& call, const Model& model, const Voxelizer& voxelizer,
                                     int reps, ProbeOutput& out) {
    const auto res = call.setting<uint32_t>("resolution");
    const size_t budget = available_memory_bytes() / 2;
    // Voxel list + SVO + merge tables: about 24 B per estimated voxel.
    const uint64_t need = voxelizer.estimate_voxels(voxelizer.grid().full_region()) * 24;
    if (need > budget) {
        out.notes.push_back(model.label + " " + cube(res) + " whole conversion skipped: " + budget_text(need, budget));
        return std::nullopt;
    }
    call.ctx.say(model.label + " " + cube(res) + ": SVO→SVDAG ×" + std::to_string(reps));
    if (!reset_peak_rss()) out.notes.push_back("VmHWM could not be reset on this system: peak_rss_MiB is process-wide.");
    const size_t before = current_rss_bytes();
    const VoxelList voxels = voxelizer.voxelize();
    const Svo svo = Svo::build(voxels);
    ConversionTimes all, one, codes_all, codes_one;
    size_t dag_nodes = 0;
    for (int r = 0; r < reps; ++r) {
        Svdag dag = Svdag::from_svo(svo);
        all.add(dag.build_stats());
        dag_nodes = dag.node_count();
        // The phase the split rows time, on the whole grid: levels built from the Morton
        // codes and merged, with no SVO given.
        codes_all.add(Svdag::from_voxels(voxels).build_stats());
        ThreadLimit single(1);
        one.add(Svdag::from_svo(svo).build_stats());
        codes_one.add(Svdag::from_voxels(voxels).build_stats());
    }
    json row = {{"method", "SVO→SVDAG (whole)"},
                {"split_level", 0},
                {"subtrees", 1},
                {"voxels", voxels.size()},
                {"svo_nodes", svo.node_count()},
                {"svdag_nodes", dag_nodes},
                {"t_A_ms (1 thread)", median(one.t_a)},
                {"t_B_ms (1 thread)", median(one.t_b)},
                {"t_A_ms (all threads)", median(all.t_a)},
                {"t_B_ms (all threads)", median(all.t_b)},
                {"codes_to_svdag_ms (1 thread)", median(codes_one.t_a)},
                {"codes_to_svdag_ms (all threads)", median(codes_all.t_a)},
                {"voxelize_ms", voxels.stats.ms},
                {"svo_build_ms", svo.build_ms()},
                {"peak_rss_MiB", mib(double(peak_rss_bytes()))},
                {"rss_before_MiB", mib(double(before))}};
    return row;
}

// The paper's split build: each subtree of `split_subtree`³ voxels voxelized on its own,
// its levels built from its Morton codes and merged into shared tables, `reps` times.
std::optional<json> split_conversion(const ProbeCall& call, const Model& model, const Voxelizer& voxelizer,
                                     int reps, ProbeOutput& out) {
    const auto res = call.setting<uint32_t>("resolution");
    const auto split_cell = call.setting<uint32_t>("split_subtree");
    const int split_level = std::max(0, voxelizer.grid().depth() - int(std::lround(std::log2(double(split_cell)))));
    const size_t budget = available_memory_bytes() / 2;
    // Finished DAG + one subtree's voxels and tables: a few bytes per voxel.
    const uint64_t need = voxelizer.estimate_voxels(voxelizer.grid().full_region()) * 4;
    if (need > budget) {
        out.notes.push_back(model.label + " " + cube(res) + " split conversion skipped: " + budget_text(need, budget));
        return std::nullopt;
    }
    call.ctx.say(model.label + " " + cube(res) + ": split build, level " + std::to_string(split_level) + " ×" +
                 std::to_string(reps));
    if (!reset_peak_rss()) out.notes.push_back("VmHWM could not be reset on this system: peak_rss_MiB is process-wide.");
    const size_t before = current_rss_bytes();
    ConversionTimes all, one;
    std::vector<double> vox_ms;
    size_t dag_nodes = 0;
    uint64_t voxels = 0, subtrees = 0;
    for (int r = 0; r < reps; ++r) {
        Svdag dag = Svdag::from_voxelizer(voxelizer, split_level);
        all.add(dag.build_stats());
        {
            ThreadLimit single(1);
            one.add(Svdag::from_voxelizer(voxelizer, split_level).build_stats());
        }
        vox_ms.push_back(dag.build_stats().voxelize_ms);
        dag_nodes = dag.node_count();
        voxels = dag.build_stats().input_nodes;
        subtrees = dag.build_stats().subtrees;
    }
    json row = {{"method", "split: " + cube(split_cell) + " subtrees, voxelized one at a time"},
                {"split_level", split_level},
                {"subtrees", subtrees},
                {"voxels", voxels},
                {"svdag_nodes", dag_nodes},
                // No SVO exists here, so there is no t_A: the timed phase builds the levels
                // from Morton codes as well, the codes_to_svdag column.
                {"t_A_ms (1 thread)", nullptr},
                {"t_B_ms (1 thread)", median(one.t_b)},
                {"t_A_ms (all threads)", nullptr},
                {"t_B_ms (all threads)", median(all.t_b)},
                {"codes_to_svdag_ms (1 thread)", median(one.t_a)},
                {"codes_to_svdag_ms (all threads)", median(all.t_a)},
                {"voxelize_ms", median(vox_ms)},
                {"peak_rss_MiB", mib(double(peak_rss_bytes()))},
                {"rss_before_MiB", mib(double(before))}};
    return row;
}

// One row of Table 3: the model at `resolution`, converted by `method` (whole or split).
void measure_conversion(const ProbeCall& call, const Model& model, ProbeOutput& out) {
    const auto res = call.setting<uint32_t>("resolution");
    const auto method = call.setting<std::string>("method");
    const int reps = call.setting<int>("repetitions");
    const Voxelizer voxelizer(model.positions, model.triangles, model_grid(model, res));
    const double load_before = load_average();
    std::optional<json> row;
    if (method == "whole") row = whole_conversion(call, model, voxelizer, reps, out);
    else if (method == "split") row = split_conversion(call, model, voxelizer, reps, out);
    else throw Error("dag-table3", "method '" + method + "' is neither 'whole' nor 'split'");
    if (!row) return;
    (*row)["scene"] = model.label;
    (*row)["resolution"] = res;
    (*row)["repetitions"] = reps;
    (*row)["load_average_before"] = load_before;
    (*row)["load_average_after"] = load_average();
    out.rows.push_back(std::move(*row));
}

ExperimentOutput reduce_table3(const SpecReduction& r) {
    ResultTable table;
    table.title = "SVO→SVDAG conversion time t_A and identical-node search time t_B (ms, median over repetitions)";
    table.columns = {"scene",        "resolution", "method",       "split_level", "subtrees",   "repetitions",
                     "voxels",       "svo_nodes",  "svdag_nodes",  "t_A_ms (1 thread)", "t_B_ms (1 thread)",
                     "t_A_ms (all threads)", "t_B_ms (all threads)",
                     "codes_to_svdag_ms (1 thread)", "codes_to_svdag_ms (all threads)", "voxelize_ms",
                     "svo_build_ms", "peak_rss_MiB", "rss_before_MiB", "paper_t_A_ms", "paper_t_B_ms",
                     "speedup_vs_paper_t_A (1 thread)", "speedup_vs_paper_t_A (all threads)"};
    for (const TaskResult& t : r.tasks)
        for (json row : t.rows) {
            const bool split = row["split_level"] != 0;
            if (const auto paper = paper_table3(model_spec(t.task.scene).paper, row["resolution"].get<uint32_t>())) {
                row["paper_t_A_ms"] = paper->t_a;
                row["paper_t_B_ms"] = paper->t_b;
                if (!split) {
                    row["speedup_vs_paper_t_A (1 thread)"] = paper->t_a / row["t_A_ms (1 thread)"].get<double>();
                    row["speedup_vs_paper_t_A (all threads)"] = paper->t_a / row["t_A_ms (all threads)"].get<double>();
                }
            }
            json projected = project(row, table.columns);
            // A split row's phase includes building the levels: no speedup against the
            // paper's t_A, not even an empty one.
            if (split) {
                projected.erase("speedup_vs_paper_t_A (1 thread)");
                projected.erase("speedup_vs_paper_t_A (all threads)");
            }
            table.rows.push_back(std::move(projected));
        }
    ExperimentOutput out;
    out.tables = {std::move(table)};
    if (auto note = load_note(rows_of(r))) out.notes.push_back(*note);
    return out;
}

// ---- dag-fig13 ----

struct TraceResult {
    std::vector<VoxelRayHit> hits;
    double mrays_per_s = 0;
    double nodes_per_ray = 0;
    double nodes_per_hitting_ray = 0;
    double hit_fraction = 0;
};

template <class Structure>
TraceResult trace_all(const Structure& s, const std::vector<Ray>& rays, int width, int height, int reps) {
    TraceResult result;
    result.hits.resize(rays.size());
    std::vector<double> rates;
    for (int r = 0; r < reps; ++r) {
        Stopwatch watch;
        parallel_for_tiles(width, height, 16, [&](const Tile& t) {
            for (int y = t.y0; y < t.y1; ++y)
                for (int x = t.x0; x < t.x1; ++x) {
                    const size_t i = size_t(y) * size_t(width) + size_t(x);
                    result.hits[i] = trace_voxel_ray(s, rays[i]);
                }
        });
        rates.push_back(double(rays.size()) / (watch.elapsed_ms() * 1e3));
    }
    result.mrays_per_s = median(rates);
    double visited = 0, hit = 0, visited_by_hits = 0;
    for (const VoxelRayHit& h : result.hits) {
        visited += h.nodes_visited;
        hit += h.hit ? 1 : 0;
        visited_by_hits += h.hit ? h.nodes_visited : 0;
    }
    result.nodes_per_ray = visited / double(rays.size());
    result.nodes_per_hitting_ray = hit > 0 ? visited_by_hits / hit : 0.0;
    result.hit_fraction = hit / double(rays.size());
    return result;
}

// Fig. 13's measurement: single rays from a fixed viewpoint, each traced alone on one
// thread. The time of one ray is the median over `batches` of a batch of `repeats`
// back-to-back traversals of that ray (a single traversal is below the clock's grain).
volatile uint64_t sink = 0;

template <class Structure>
std::vector<double> single_ray_microseconds(const Structure& s, const std::vector<Ray>& rays, int repeats,
                                            int batches) {
    std::vector<double> result;
    for (const Ray& ray : rays) {
        std::vector<double> per_ray;
        for (int b = 0; b < batches; ++b) {
            Stopwatch watch;
            for (int r = 0; r < repeats; ++r) sink = sink + trace_voxel_ray(s, ray).nodes_visited;  // kept: volatile
            per_ray.push_back(watch.elapsed_ms() * 1e3 / double(repeats));
        }
        result.push_back(median(per_ray));
    }
    return result;
}

// Up to `count` rays that hit, spread evenly over the hitting rays in image order.
std::vector<size_t> spread_hitting_rays(const std::vector<VoxelRayHit>& hits, size_t count) {
    std::vector<size_t> hitting;
    for (size_t i = 0; i < hits.size(); ++i)
        if (hits[i].hit) hitting.push_back(i);
    std::vector<size_t> chosen;
    const size_t n = std::min(count, hitting.size());
    for (size_t k = 0; k < n; ++k) chosen.push_back(hitting[(2 * k + 1) * hitting.size() / (2 * n)]);
    return chosen;
}

bool same_hits(const std::vector<VoxelRayHit>& a, const std::vector<VoxelRayHit>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i].hit != b[i].hit || a[i].nodes_visited != b[i].nodes_visited ||
            (a[i].hit && (a[i].voxel != b[i].voxel || a[i].t != b[i].t)))
            return false;
    return true;
}

// First-hit distance as grey (near = bright), misses black.
void write_depth_png(const std::filesystem::path& path, const std::vector<VoxelRayHit>& hits, int width, int height) {
    float lo = kInfinity, hi = 0;
    for (const VoxelRayHit& h : hits)
        if (h.hit) lo = std::min(lo, h.t), hi = std::max(hi, h.t);
    Film film(width, height);
    const float span = hi > lo ? hi - lo : 1.0f;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const VoxelRayHit& h = hits[size_t(y) * size_t(width) + size_t(x)];
            const float v = h.hit ? 1.0f - 0.85f * (h.t - lo) / span : 0.0f;
            film.set("color", x, y, Vec3(v));
        }
    film.metadata["content"] = "first-hit distance through the SVDAG (near = bright)";
    write_png(path, film);
}

// Primary rays from the scene camera through the SVO, ESVO and SVDAG of one model: a
// "throughput" row (all threads, median over repetitions), ten "single ray" rows (the
// paper's plot) and the depth image.
void measure_traversal(const ProbeCall& call, const Model& model, ProbeOutput& out) {
    const auto res = call.setting<uint32_t>("resolution");
    const int reps = call.setting<int>("repetitions");
    const int single_repeats = call.setting<int>("single_ray_repeats");
    const int single_batches = call.setting<int>("single_ray_batches");
    const int size = call.size;
    const ExperimentContext& ctx = call.ctx;
    ctx.say(model.label + " " + cube(res) + ": building SVO, ESVO, SVDAG");
    const VoxelList voxels = voxelize(model.positions, model.triangles, model_grid(model, res));
    const Svo svo = Svo::build(voxels);
    const Esvo esvo = Esvo::from_svo(svo);
    const Svdag dag = Svdag::from_svo(svo);
    const SceneCamera& c = model.camera;
    const EyeCamera camera = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
    std::vector<Ray> rays(size_t(size) * size_t(size));
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) rays[size_t(y) * size + x] = camera.generate_ray(x + 0.5f, y + 0.5f);
    ctx.say(model.label + ": tracing " + std::to_string(rays.size()) + " rays ×" + std::to_string(reps) +
            " per structure");
    const double load_before = load_average();
    const TraceResult r_svo = trace_all(svo, rays, size, size, reps);
    const TraceResult r_esvo = trace_all(esvo, rays, size, size, reps);
    const TraceResult r_dag = trace_all(dag, rays, size, size, reps);
    const bool same = same_hits(r_svo.hits, r_esvo.hits) && same_hits(r_svo.hits, r_dag.hits);
    const std::string file = "depth_" + model.scene + ".png";
    write_depth_png(ctx.output_dir / file, r_dag.hits, size, size);
    out.files.push_back(file);

    // The paper's plot: ten rays from the fixed viewpoint, one at a time.
    const std::vector<size_t> chosen = spread_hitting_rays(r_svo.hits, 10);
    std::vector<Ray> single;
    for (size_t i : chosen) single.push_back(rays[i]);
    ctx.say(model.label + ": timing " + std::to_string(single.size()) + " single rays");
    const std::vector<double> t_svo = single_ray_microseconds(svo, single, single_repeats, single_batches);
    const std::vector<double> t_esvo = single_ray_microseconds(esvo, single, single_repeats, single_batches);
    const std::vector<double> t_dag = single_ray_microseconds(dag, single, single_repeats, single_batches);
    out.rows.push_back({{"kind", "throughput"},
                        {"scene", model.label},
                        {"resolution", res},
                        {"rays", rays.size()},
                        {"hit_fraction", r_svo.hit_fraction},
                        {"svo_nodes_per_ray", r_svo.nodes_per_ray},
                        {"esvo_nodes_per_ray", r_esvo.nodes_per_ray},
                        {"svdag_nodes_per_ray", r_dag.nodes_per_ray},
                        {"nodes_per_hitting_ray", r_svo.nodes_per_hitting_ray},
                        {"svo_mrays_per_s", r_svo.mrays_per_s},
                        {"esvo_mrays_per_s", r_esvo.mrays_per_s},
                        {"svdag_mrays_per_s", r_dag.mrays_per_s},
                        {"svdag_over_svo_throughput", ratio(r_dag.mrays_per_s, r_svo.mrays_per_s)},
                        {"esvo_over_svo_throughput", ratio(r_esvo.mrays_per_s, r_svo.mrays_per_s)},
                        {"same_hits_in_all_three", same},
                        {"load_average_before", load_before},
                        {"load_average_after", load_average()}});
    for (size_t k = 0; k < chosen.size(); ++k) {
        const size_t i = chosen[k];
        out.rows.push_back({{"kind", "single ray"},
                            {"scene", model.label},
                            {"resolution", res},
                            {"ray", k + 1},
                            {"pixel", {i % size_t(size), i / size_t(size)}},
                            {"nodes_visited", r_svo.hits[i].nodes_visited},
                            {"svo_us", t_svo[k]},
                            {"esvo_us", t_esvo[k]},
                            {"svdag_us", t_dag[k]},
                            {"svdag_over_svo_time", ratio(t_dag[k], t_svo[k])}});
    }
}

// One plot per model: the single rays' times, a curve per structure.
Plot single_ray_plot(const std::string& label, uint32_t res, const std::vector<json>& rows) {
    Plot plot;
    plot.title = "Fig. 13: single primary rays through SVO, ESVO and SVDAG, " + label + " " + cube(res);
    plot.x_label = "ray (hitting rays spread over the image)";
    plot.y_label = "time per ray (µs, one thread)";
    PlotSeries s_svo{"SVO", {}, {}}, s_esvo{"ESVO", {}, {}}, s_dag{"SVDAG", {}, {}};
    for (const json& row : rows) {
        const double x = row["ray"].get<double>();
        s_svo.x.push_back(x), s_esvo.x.push_back(x), s_dag.x.push_back(x);
        s_svo.y.push_back(row["svo_us"].get<double>());
        s_esvo.y.push_back(row["esvo_us"].get<double>());
        s_dag.y.push_back(row["svdag_us"].get<double>());
    }
    plot.series = {s_svo, s_esvo, s_dag};
    return plot;
}

ExperimentOutput reduce_fig13(const SpecReduction& r) {
    const json& point = axis_points(r).at(0);
    const uint32_t res = point.at("resolution").get<uint32_t>();
    // Fig. 13 prints no values; the text says the times are about equal.
    const std::string paper_time_ratio =
        paper_figures("p2/fig13").row({{"structures", "SVO, ESVO, SVDAG"}}).text("time ratio");
    ExperimentOutput out;
    ResultTable table;
    table.title = "Primary rays (" + std::to_string(r.size()) + "² from the scene camera) through SVO, ESVO and SVDAG at " +
                  cube(res);
    table.columns = {"scene",
                     "resolution",
                     "rays",
                     "hit_fraction",
                     "svo_nodes_per_ray",
                     "esvo_nodes_per_ray",
                     "svdag_nodes_per_ray",
                     "nodes_per_hitting_ray",
                     "svo_mrays_per_s",
                     "esvo_mrays_per_s",
                     "svdag_mrays_per_s",
                     "svdag_over_svo_throughput",
                     "esvo_over_svo_throughput",
                     "same_hits_in_all_three",
                     "paper_time_ratio"};
    ResultTable single_table;
    single_table.title = "Fig. 13: ten single primary rays (hitting rays spread over the image), each traced alone on "
                         "one thread, median over " + r.spec.variants.at(0).settings.at("single_ray_batches").dump() +
                         " batches of " + point.at("single_ray_repeats").dump() + " traversals";
    single_table.columns = {"scene", "ray", "pixel", "nodes_visited", "svo_us", "esvo_us", "svdag_us",
                            "svdag_over_svo_time"};
    for (const TaskResult& t : r.tasks) {
        std::vector<json> single;
        for (json row : t.rows) {
            if (row["kind"] == "throughput") {
                row["paper_time_ratio"] = paper_time_ratio;
                table.rows.push_back(project(row, table.columns));
            } else {
                single_table.rows.push_back(project(row, single_table.columns));
                single.push_back(row);
            }
        }
        if (!single.empty())
            out.plots.push_back({"fig13_" + t.task.scene,
                                 single_ray_plot(model_spec(t.task.scene).label, res, single)});
    }
    out.tables = {std::move(table), std::move(single_table)};
    if (auto note = load_note(rows_of(r, "throughput"))) out.notes.push_back(*note);
    return out;
}

}  // namespace

Experiment dag_scale_experiment();     // dag-scale, dag_scale_experiment.cpp
Experiment dag_symmetry_experiment();  // dag-symmetries, dag_symmetry_experiment.cpp

void register_dag_experiments(ExperimentRegistry& registry) {
    add_probe("dag-structures", model_probe(measure_structures));
    add_probe("dag-conversion", model_probe(measure_conversion));
    add_probe("dag-traversal", model_probe(measure_traversal));
    add_reducer("dag-table1", reduce_table1);
    add_reducer("dag-table2", reduce_table2);
    add_reducer("dag-table3", reduce_table3);
    add_reducer("dag-fig13", reduce_fig13);
    const SpecVariant structures{.name = "SVO, ESVO, SVDAG, OpenVDB, OctoMap", .probe = "dag-structures"};

    registry.add(declared_experiment({
        .name = "dag-table1",
        .paper = "P2",
        .figure = "Table 1",
        .description = "nodes and pointers of SVO, ESVO and SVDAG (plus OpenVDB and OctoMap) for the bunny, Buddha and "
                       "dragon at 1000³ (Table 1)",
        .scenes = paper_model_scenes(),
        .variants = {structures},
        .axes = {{"resolution", {1000}, {128}}},
        .reducer = "dag-table1",
        .notes = {kGridNote,
                  "Counting: SVO nodes = every node, root to leaf voxels; SVO pointers = one first-child index per node "
                  "with children. ESVO nodes = 64-bit child descriptors (nodes with children; leaf voxels have none, as "
                  "in Laine & Karras); ESVO pointers = child pointers stored + far pointers. SVDAG nodes = unique nodes "
                  "after merging, the single leaf node included; SVDAG pointers = one 32-bit pointer per non-empty "
                  "child of each unique node.",
                  "The paper counts nodes differently from ours in ways it does not define: its ESVO has more nodes "
                  "than its SVO for the bunny and the Buddha but four times fewer for the dragon, and its SVO "
                  "pointer/node ratio is ~0.23. Our ESVO is always smaller than our SVO in nodes because leaves have "
                  "no descriptor.",
                  "OpenVDB: openvdb::MaskGrid (5-4-3 tree) with one active voxel per occupied voxel; internal nodes = "
                  "16³ and 32³ nodes, root not counted; MB = memUsage(). OctoMap: octomap::OcTree at the voxel size, "
                  "unpruned (octomap_prune = false); nodes = size(), MB = memoryUsage(). MB = 10⁶ bytes."},
    }));
    registry.add(declared_experiment({
        .name = "dag-table2",
        .paper = "P2",
        .figure = "Table 2",
        .description = "storage of SVO, ESVO and SVDAG (plus OpenVDB and OctoMap) at 512³ and 1000³ (Table 2)",
        .scenes = paper_model_scenes(),
        .variants = {structures},
        .axes = {{"resolution", {512, 1000}, {64, 128}}},
        .reducer = "dag-table2",
        .notes = {kGridNote,
                  "svo_pointerless = 1 B per node (child mask only, the Schnabel & Klein layout the paper prices its "
                  "SVO at); svo_stored = as our SVO holds it in memory (1 B mask per node + 4 B first-child index per "
                  "node with children); esvo = 8 B per child descriptor + 4 B per far pointer (no page headers, no "
                  "contour data); svdag = the paper's format, a 4 B mask word per unique node + 4 B per child pointer; "
                  "openvdb = MaskGrid memUsage(); octomap = OcTree memoryUsage() (unpruned). MB = 10⁶ bytes."},
    }));
    // Whole conversion up to 2000³, the paper's split rule above 256³ (split level = depth −
    // log2(subtree size)); quick runs scale the rule down to 64³ subtrees so the split path
    // still runs. Repetitions: 7 up to 256³, 5 at 512³, 3 at 1000³, 1 above (quick: 3).
    auto row = [](uint32_t res, const char* method, int reps, uint32_t subtree) {
        json point = {{"resolution", res}, {"method", method}, {"repetitions", reps}};
        if (std::string(method) == "split") point["split_subtree"] = subtree;
        return point;
    };
    registry.add(declared_experiment({
        .name = "dag-table3",
        .paper = "P2",
        .figure = "Table 3",
        .description = "SVO→SVDAG conversion time t_A and identical-node search time t_B, 128³ to 8192³, with the split "
                       "build and per-row peak memory (Table 3)",
        .scenes = paper_model_scenes(),
        .variants = {{.name = "SVO→SVDAG", .probe = "dag-conversion"}},
        .axes = {{"",
                  {row(128, "whole", 7, 256), row(256, "whole", 7, 256), row(512, "whole", 5, 256),
                   row(512, "split", 5, 256), row(1000, "whole", 3, 256), row(1000, "split", 3, 256),
                   row(2000, "whole", 1, 256), row(2000, "split", 1, 256), row(4096, "split", 1, 256),
                   row(8192, "split", 1, 256)},
                  {row(64, "whole", 3, 64), row(128, "whole", 3, 64), row(128, "split", 3, 64),
                   row(256, "whole", 3, 64), row(256, "split", 3, 64)}}},
        .reducer = "dag-table3",
        .notes = {kGridNote,
                  "Whole rows: t_A = Svdag::from_svo on an SVO already in memory (bottom-up merge + layout in the "
                  "paper's format), t_B = the part spent hashing nodes and finding identical ones; voxelization and "
                  "SVO build are reported apart and not in t_A. Split rows (the paper's rule above 256³): each 256³ "
                  "subtree is voxelized on its own, its levels are built from its Morton codes, merged into shared "
                  "per-level tables, and the roots joined. A split row has no SVO to convert, so it has no t_A: its "
                  "time is codes_to_svdag (levels built from the Morton codes + merge + layout, voxelization "
                  "excluded), a longer phase than t_A. Whole rows time that same phase too (Svdag::from_voxels on the "
                  "whole voxel list), so codes_to_svdag compares whole with split rows and t_A compares with the "
                  "paper. In both, t_B is the same thing: the time spent hashing parents' keys and looking them up in "
                  "the per-level tables of unique nodes.",
                  "peak_rss_MiB is the row's own peak resident memory (VmHWM reset through /proc/self/clear_refs "
                  "before the row), which includes what the process held before the row (rss_before_MiB: program, "
                  "mesh, allocator caches); for whole rows it covers the voxel list, the SVO and the conversions, for "
                  "split rows the voxelizer and one subtree at a time. A row whose estimated memory exceeds half the "
                  "available memory is skipped with a note.",
                  "The paper's times are on its own CPU. It does not state a thread count; that it ran on one thread "
                  "is our reading, so it is compared with our 1-thread figures (each repetition converts once at all "
                  "threads and once under a 1-thread limit), and the all-thread figures stand beside. The paper "
                  "converted above 256³ with its split rule; its t_A there is still an SVO→SVDAG conversion, so "
                  "speedup_vs_paper_t_A = paper t_A / our whole-row t_A, and split rows give none (their phase "
                  "includes building the levels). Our whole conversion hashes each level's nodes in parallel and "
                  "looks them up in one open-addressing table per level; the final layout is cheap, so t_B is most of "
                  "t_A here, while the paper's t_B is 12–40% of its t_A.",
                  "Times are medians over the row's repetitions, wall clock; other work on the machine slows them "
                  "(the load averages are in the last note)."},
    }));
    registry.add(declared_experiment({
        .name = "dag-fig13",
        .paper = "P2",
        .figure = "Fig. 13",
        .description = "primary-ray throughput and nodes visited per ray through SVO, ESVO and SVDAG (Fig. 13)",
        .scenes = paper_model_scenes(),
        .size = 512, .quick_size = 128,
        .variants = {{.name = "SVO, ESVO, SVDAG",
                      .probe = "dag-traversal",
                      .settings = {{"single_ray_batches", 5}}}},
        .axes = {{"",
                  {json{{"resolution", 512}, {"repetitions", 7}, {"single_ray_repeats", 2000}}},
                  {json{{"resolution", 128}, {"repetitions", 3}, {"single_ray_repeats", 200}}}}},
        .reducer = "dag-fig13",
        .notes = {kGridNote,
                  "One ray per pixel centre (an image of size² pixels from each scene file's camera), traced with the "
                  "same stack-based front-to-back octree walk over each structure (accel/dag/voxel_ray_traversal), "
                  "all threads, 16×16 tiles; Mrays/s is the median over the repetitions. nodes_per_ray counts the "
                  "nodes whose box a ray entered, root and hit leaf included, over all rays (most miss the model: the "
                  "scene camera frames the floor too); nodes_per_hitting_ray averages over the rays that hit. The "
                  "three encode the same tree, so their hits and visit counts must match (same_hits_in_all_three), "
                  "and only the cost of reading a node differs.",
                  "The paper gives Fig. 13 only as a plot of per-ray intersection times that are about equal for SVO, "
                  "ESVO and SVDAG (the DAG visits the same nodes); paper_time_ratio records that finding. "
                  "depth_<scene>.png: first-hit distance through the SVDAG (near = bright, misses black).",
                  "The second table and the fig13_<scene> plots repeat the paper's setting: 10 rays from a fixed "
                  "viewpoint (the scene camera), primary rays only; the paper's ray choice is not given, so ours are "
                  "hitting rays spread evenly over the image. The paper plots times without numbers, so there is no "
                  "paper curve."},
    }));
    registry.add(dag_scale_experiment());
    registry.add(dag_symmetry_experiment());
}

}  // namespace gilab
