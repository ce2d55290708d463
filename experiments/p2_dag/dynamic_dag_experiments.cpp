// P2 §4 (time-correlated multi-frame DAG over animated scenes): node counts and storage
// of per-frame SVO, difference tree, per-frame SVDAG and the time-correlated DAG with
// build time and peak memory of both build modes (Table 5), and the frame rate of ray
// casting through the multi-frame DAG along the animation (Table 6). Declared
// experiments: one task per scene and grid (Table 5) or scene and image size (Table 6),
// each a probe; the reducers lay the rows out as the paper's tables.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include "accel/temporal/difference_tree.hpp"
#include "accel/temporal/minimal_bit_dag.hpp"
#include "accel/dag/svdag.hpp"
#include "accel/dag/svo.hpp"
#include "accel/temporal/laid_out_multi_frame_dag.hpp"
#include "core/scene/camera.hpp"
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/image/image_io.hpp"
#include "core/util/parallel.hpp"
#include "core/scene/scene.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxelizer.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/measures.hpp"
#include "experiments/runner/paper_figures.hpp"
#include "experiments/runner/spec_functions.hpp"
#include "scenes/scene_library.hpp"
#include "accel/temporal/animation_dag.hpp"
#include "techniques/technique.hpp"

namespace gilab {
namespace {

using nlohmann::json;

// The paper's three regimes: mostly static, moving but regular, random particles.
const std::vector<std::string>& dynamic_scenes() {
    static const std::vector<std::string> names = {"kitchen", "robot", "fire"};
    return names;
}

std::string paper_scene_of(const std::string& scene) {
    if (scene == "kitchen") return "Kitchen";
    if (scene == "robot") return "Robot";
    return "Fire";
}

// ---- The paper's published figures (experiments/papers/p2; reference data, never used as results) ----

// Table 5: N_p (average nodes per frame) and N_n (total nodes) per structure, in nodes.
struct PaperCounts {
    double svo_np, svo_nn, diff_np, diff_nn, svdag_np, svdag_nn, tc_np, tc_nn;
};
PaperCounts paper_table5(const std::string& paper_scene) {
    // Published as N_p ×10³ and N_n ×10⁶, multiplied out in decimal.
    const PaperRow& r = paper_figures("p2/table5").row({{"scene", paper_scene}});
    auto np = [&](const std::string& s) { return r.scaled(s + " N_p (×10³)", 3); };
    auto nn = [&](const std::string& s) { return r.scaled(s + " N_n (×10⁶)", 6); };
    return {np("svo"),   nn("svo"),   np("difference_tree"), nn("difference_tree"),
            np("svdag"), nn("svdag"), np("time_correlated"), nn("time_correlated")};
}

// Table 6: CPU frame rate at the paper's image size ("1024×768", "800×600", "400×300").
double paper_table6_fps(const std::string& paper_scene, const std::string& paper_size) {
    return paper_figures("p2/table6").row({{"scene", paper_scene}, {"image (pixels)", paper_size}}).number("fps");
}

// Kämpe et al. 2016, the context figure beside Table 5: a captured performer's frames
// at its grid resolution in MB.
const PaperRow& kampe_2016() { return paper_figures("p2/table5_kampe2016").row({{"sequence", "captured performer"}}); }

// The task's animated scene, or null with a note saying why it is not measured.
const Scene* open_dynamic_scene(const ProbeCall& call, ProbeOutput& out) {
    try {
        const Scene& scene = call.scene();
        if (!(scene.frames_per_second > 0))
            throw Error(call.task.scene, "has no positive frame rate to sample its animation");
        return &scene;
    } catch (const std::exception& e) {
        out.notes.push_back("Scene '" + call.task.scene + "' not measured: " + e.what());
        call.ctx.say("skipping " + call.task.scene + ": " + e.what());
        return nullptr;
    }
}

// A table row holding only `columns` (the probes' rows carry extra fields for the
// reducers' notes).
json pick(const json& row, const std::vector<std::string>& columns) {
    json picked = json::object();
    for (const std::string& c : columns) picked[c] = row.value(c, json());
    return picked;
}

// The one-minute load average at the first task's start and the last task's end, from
// the rows' "load before" / "load after" fields.
std::string load_note(const SpecReduction& r) {
    double first = -1, last = -1;
    for (const TaskResult& t : r.tasks)
        for (const json& row : t.rows) {
            if (first < 0 && row.contains("load before")) first = row["load before"];
            if (row.contains("load after")) last = row["load after"];
        }
    return "the one-minute load average was " + format_number(first) + " at the first task's start and " +
           format_number(last) + " at the last task's end";
}

// ---- dag-table5: one scene at one resolution and frame count ----

struct BuildFigures {
    DagBuildMode mode = DagBuildMode::Incremental;
    Stats stats;                 // of build_animation_dag
    size_t peak_rss = 0, rss_before = 0;
    bool per_build_peak = false;
    uint64_t tc_nodes = 0;
};

struct Table5Figures {
    uint32_t resolution = 0;
    int frames = 0;
    double voxels_per_frame = 0;
    uint64_t svo_nodes = 0;             // Σ_f |SVO_f|
    size_t svo_bytes = 0, svo_pointerless_bytes = 0, max_frame_svo_bytes = 0;
    uint64_t diff_nodes = 0, diff_steady_nodes = 0;  // steady: Σ_{f≥1} changed_f
    size_t diff_bytes = 0;
    uint64_t diff_mask_leaf_nodes = 0;  // the same tree with the voxels in the bottom masks
    size_t diff_mask_leaf_bytes = 0;
    uint64_t svdag_nodes = 0;           // Σ_f |DAG_f|
    size_t svdag_bytes = 0;
    LaidOutMultiFrameDag tc;            // from the incremental build
    double tc_reachable_per_frame = 0;
    size_t minbits_offset_bytes = 0, minbits_index_bytes = 0;
    std::vector<BuildFigures> builds;
    std::optional<bool> modes_agree;    // null when only the incremental build ran
};

BuildFigures build_tc(const Scene& scene, uint32_t resolution, int frames, DagBuildMode mode, AnimationDag& result) {
    BuildFigures b;
    b.mode = mode;
    result = AnimationDag();  // free the previous build before measuring this one
    b.per_build_peak = reset_peak_rss();
    b.rss_before = current_rss_bytes();
    AnimationDagOptions o;
    o.resolution = resolution;
    o.frames = frames;
    o.fps = scene.frames_per_second;
    o.build = mode;
    result = build_animation_dag(scene, o);
    b.peak_rss = peak_rss_bytes();
    b.stats = result.stats;
    b.tc_nodes = result.dag.node_count();
    return b;
}

Table5Figures measure_table5(const std::string& name, const Scene& scene, uint32_t resolution, int frames,
                             bool all_at_once, const ExperimentContext& ctx) {
    Table5Figures f;
    f.resolution = resolution;
    f.frames = frames;
    // The two time-correlated builds first, each from a fresh peak-RSS mark, so their
    // peaks are not the baselines' leftovers.
    AnimationDag built;
    f.builds.push_back(build_tc(scene, resolution, frames, DagBuildMode::Incremental, built));
    f.tc = std::move(built.dag);
    const std::vector<double> times = built.times;
    if (all_at_once) {
        f.builds.push_back(build_tc(scene, resolution, frames, DagBuildMode::AllAtOnce, built));
        f.modes_agree = built.dag.node_count() == f.tc.node_count() &&
                        std::ranges::equal(built.dag.words(), f.tc.words());
        built = AnimationDag();
    }
    ctx.say(name + " " + std::to_string(resolution) + "³ × " + std::to_string(frames) +
            ": time-correlated DAG " + std::to_string(f.tc.node_count()) + " nodes");

    // Baselines on the same grid, one frame's voxels at a time.
    const VoxelGrid& grid = f.tc.grid();
    DifferenceTree diff(grid);
    uint64_t voxels = 0;
    for (int k = 0; k < frames; ++k) {
        const std::vector<uint64_t> codes = voxelize(scene.evaluate(times[size_t(k)]), grid).codes;
        voxels += codes.size();
        {
            const Svo svo = Svo::build(grid, codes);
            f.svo_nodes += svo.node_count();
            f.svo_bytes += svo.bytes();
            f.svo_pointerless_bytes += svo.pointerless_bytes();
            f.max_frame_svo_bytes = std::max(f.max_frame_svo_bytes, svo.bytes());
        }
        const Svdag dag = Svdag::from_voxels(grid, codes);
        f.svdag_nodes += dag.node_count();
        f.svdag_bytes += dag.bytes();
        const uint64_t added = diff.append_frame(codes);
        if (k > 0) f.diff_steady_nodes += added;
    }
    f.voxels_per_frame = double(voxels) / double(frames);
    f.diff_nodes = diff.node_count();
    f.diff_bytes = diff.bytes();
    f.diff_mask_leaf_nodes = diff.node_count_leaves_in_masks();
    f.diff_mask_leaf_bytes = diff.bytes_leaves_in_masks();
    double reachable = 0;
    for (size_t k = 0; k < f.tc.frame_count(); ++k) reachable += double(f.tc.reachable_node_count(k));
    f.tc_reachable_per_frame = reachable / double(frames);
    f.minbits_offset_bytes = encode_minimal_bits(f.tc, PointerAddressing::BitOffset).bytes();
    f.minbits_index_bytes = encode_minimal_bits(f.tc, PointerAddressing::NodeIndex).bytes();
    return f;
}

// What an estimate of a larger block's memory scales from: one smaller run's figures.
struct EstimateBasis {
    uint32_t resolution = 0;
    int frames = 0;
    size_t max_frame_svo_bytes = 0;
    double voxels_per_frame = 0;
    uint64_t tc_nodes = 0, diff_nodes = 0;
};

EstimateBasis basis_of(const Table5Figures& f) {
    return {f.resolution, f.frames, f.max_frame_svo_bytes, f.voxels_per_frame, f.tc.node_count(), f.diff_nodes};
}

std::string basis_key(const std::string& scene, uint32_t resolution, int frames) {
    return "dag-table5:basis:" + scene + ":" + std::to_string(resolution) + ":" + std::to_string(frames);
}

// Rough upper estimate of what a resolution³ × frames block holds at once, scaled from a
// smaller run (512³ for the Kämpe block): voxels and per-frame structures grow with
// surface area (×16 for two doublings), the shared tables (about 64 B per
// time-correlated node and 12 B per difference-tree node) with the node counts, times
// frames / the basis' frames.
double estimate_block_bytes(const EstimateBasis& b, uint32_t resolution, int frames) {
    const double area = double(resolution / b.resolution) * double(resolution / b.resolution);
    const double frame_scale = double(frames) / double(b.frames);
    const double per_frame = area * (3.0 * double(b.max_frame_svo_bytes) + 16.0 * b.voxels_per_frame);
    const double shared = area * frame_scale * (64.0 * double(b.tc_nodes) + 12.0 * double(b.diff_nodes));
    return per_frame + shared;
}

// The three tables' measured rows of one run; "table" says which table a row is for.
std::vector<json> table5_rows(const Table5Figures& f) {
    std::vector<json> rows;
    const double frames = double(f.frames);
    const double tc_nn = double(f.tc.node_count());
    json c;
    c["table"] = "counts";
    c["resolution (voxels/axis)"] = f.resolution;
    c["frames"] = f.frames;
    c["voxels per frame (mean)"] = f.voxels_per_frame;
    c["SVO N_p (nodes)"] = double(f.svo_nodes) / frames;
    c["SVO N_n (nodes)"] = f.svo_nodes;
    c["diff N_p (nodes)"] = double(f.diff_nodes) / frames;
    c["diff N_p steady (nodes)"] = f.frames > 1 ? json(double(f.diff_steady_nodes) / (frames - 1)) : json(nullptr);
    c["diff N_n (nodes)"] = f.diff_nodes;
    c["diff, leaves in masks N_p (nodes)"] = double(f.diff_mask_leaf_nodes) / frames;
    c["diff, leaves in masks N_n (nodes)"] = f.diff_mask_leaf_nodes;
    c["SVDAG N_p (nodes)"] = double(f.svdag_nodes) / frames;
    c["SVDAG N_n (nodes)"] = f.svdag_nodes;
    c["TC N_p (nodes)"] = f.tc.nodes_per_frame();
    c["TC N_n (nodes)"] = f.tc.node_count();
    c["TC reachable per frame (nodes)"] = f.tc_reachable_per_frame;
    c["SVO/TC N_n (×)"] = ratio(double(f.svo_nodes), tc_nn);
    c["diff/TC N_n (×)"] = ratio(double(f.diff_nodes), tc_nn);
    c["diff, leaves in masks/TC N_n (×)"] = ratio(double(f.diff_mask_leaf_nodes), tc_nn);
    c["SVDAG/TC N_n (×)"] = ratio(double(f.svdag_nodes), tc_nn);
    rows.push_back(c);

    json m;
    m["table"] = "storage";
    m["resolution (voxels/axis)"] = f.resolution;
    m["frames"] = f.frames;
    m["SVO pointerless (MB)"] = mb(double(f.svo_pointerless_bytes));
    m["SVO stored (MB)"] = mb(double(f.svo_bytes));
    m["diff 32-bit (MB)"] = mb(double(f.diff_bytes));
    m["diff, leaves in masks 32-bit (MB)"] = mb(double(f.diff_mask_leaf_bytes));
    m["SVDAG 32-bit (MB)"] = mb(double(f.svdag_bytes));
    m["TC 32-bit (MB)"] = mb(double(f.tc.bytes()));
    m["TC minimal bits, offsets (MB)"] = mb(double(f.minbits_offset_bytes));
    m["TC minimal bits, indices (MB)"] = mb(double(f.minbits_index_bytes));
    m["TC minimal bits, offsets, per frame (MB)"] = mb(double(f.minbits_offset_bytes)) / frames;
    m["TC minimal bits, offsets, per voxel-frame (bits)"] =
        f.voxels_per_frame > 0 ? json(8.0 * double(f.minbits_offset_bytes) / (f.voxels_per_frame * frames))
                               : json(nullptr);
    rows.push_back(m);

    for (const BuildFigures& b : f.builds) {
        const double growth = double(b.peak_rss) - double(b.rss_before);
        json r;
        r["table"] = "builds";
        r["resolution (voxels/axis)"] = f.resolution;
        r["frames"] = f.frames;
        r["build mode"] = to_string(b.mode);
        r["build (ms)"] = b.stats.get("build_ms");
        r["voxelize (ms)"] = b.stats.get("voxelize_ms");
        r["merge (ms)"] = b.stats.get("merge_ms");
        r["layout (ms)"] = b.stats.get("layout_ms");
        r["TC N_n (nodes)"] = b.tc_nodes;
        r["peak RSS (MiB)"] = mib(double(b.peak_rss));
        r["RSS before (MiB)"] = mib(double(b.rss_before));
        r["peak growth (MiB)"] = mib(growth);
        r["one frame's SVO (MiB)"] = mib(double(f.max_frame_svo_bytes));
        r["shared DAG (MiB)"] = mib(b.stats.get("table_bytes"));
        r["peak / frame SVO (×)"] = ratio(double(b.peak_rss), double(f.max_frame_svo_bytes));
        r["peak growth / frame SVO (×)"] = ratio(growth, double(f.max_frame_svo_bytes));
        r["peak growth / (frame SVO + shared DAG) (×)"] =
            ratio(growth, double(f.max_frame_svo_bytes) + b.stats.get("table_bytes"));
        r["cells rebuilt"] = b.stats.has("cells_rebuilt") ? json(b.stats.get("cells_rebuilt")) : json(nullptr);
        r["per-build peak"] = b.per_build_peak;
        r["modes agree"] = f.modes_agree ? json(*f.modes_agree) : json(nullptr);
        rows.push_back(r);
    }
    return rows;
}

// Whether a block that would not fit may be built: the estimate scaled from the run at
// `memory_estimate_from` (the same task's neighbour in a one-command run, measured again
// by itself otherwise). Returns the reason it is not built, or "".
std::string block_too_large(const ProbeCall& call, const Scene& scene, uint32_t resolution, int frames) {
    const auto from = call.setting<uint32_t>("memory_estimate_from");
    const EstimateBasis& basis = call.cache.get<EstimateBasis>(basis_key(call.task.scene, from, call.frames), [&] {
        return basis_of(measure_table5(call.task.scene, scene, from, call.frames, false, call.ctx));
    });
    const double estimate = estimate_block_bytes(basis, resolution, frames);
    const double limit = double(default_memory_limit_bytes());
    if (estimate <= limit) return "";
    return call.task.scene + " at " + std::to_string(resolution) + "³ × " + std::to_string(frames) +
           " not built: estimated " + std::to_string(int(mb(estimate))) + " MB held at once, above the " +
           std::to_string(int(mb(limit))) + " MB limit (half the physical memory).";
}

// dag-table5, one scene at one grid: the time-correlated DAG built incrementally (and
// all at once when the point says so) and the per-frame baselines on the same grid.
ProbeOutput table5_probe(const ProbeCall& call) {
    ProbeOutput out;
    const Scene* scene = open_dynamic_scene(call, out);
    if (!scene) return out;
    const auto resolution = call.setting<uint32_t>("resolution");
    const int frames = call.setting<int>("frames", call.frames);
    try {
        if (call.variant.settings.contains("memory_estimate_from")) {
            const std::string too_large = block_too_large(call, *scene, resolution, frames);
            if (!too_large.empty()) {
                out.notes.push_back(too_large);
                return out;
            }
        }
        const double load_before = load_average();
        const Table5Figures f =
            measure_table5(call.task.scene, *scene, resolution, frames, call.setting<bool>("all_at_once"), call.ctx);
        call.cache.get<EstimateBasis>(basis_key(call.task.scene, resolution, frames), [&] { return basis_of(f); });
        out.rows = table5_rows(f);
        out.rows.front()["load before"] = load_before;
        out.rows.front()["load after"] = load_average();
    } catch (const Error& e) {
        out.notes.push_back(call.task.scene + " not measured: " + e.what());
        call.ctx.say(call.task.scene + " not measured: " + e.what());
    }
    return out;
}

const std::vector<std::string> kCountsColumns = {
    "scene", "paper scene", "resolution (voxels/axis)", "frames", "voxels per frame (mean)", "SVO N_p (nodes)",
    "SVO N_n (nodes)", "diff N_p (nodes)", "diff N_p steady (nodes)", "diff N_n (nodes)",
    "diff, leaves in masks N_p (nodes)", "diff, leaves in masks N_n (nodes)", "SVDAG N_p (nodes)",
    "SVDAG N_n (nodes)", "TC N_p (nodes)", "TC N_n (nodes)", "TC reachable per frame (nodes)", "SVO/TC N_n (×)",
    "diff/TC N_n (×)", "diff, leaves in masks/TC N_n (×)", "SVDAG/TC N_n (×)", "paper SVO/TC N_n (×)",
    "paper diff/TC N_n (×)", "paper SVDAG/TC N_n (×)", "paper SVO N_p (nodes)", "paper SVO N_n (nodes)",
    "paper diff N_p (nodes)", "paper diff N_n (nodes)", "paper SVDAG N_p (nodes)", "paper SVDAG N_n (nodes)",
    "paper TC N_p (nodes)", "paper TC N_n (nodes)"};
const std::vector<std::string> kStorageColumns = {
    "scene", "resolution (voxels/axis)", "frames", "SVO pointerless (MB)", "SVO stored (MB)", "diff 32-bit (MB)",
    "diff, leaves in masks 32-bit (MB)", "SVDAG 32-bit (MB)", "TC 32-bit (MB)", "TC minimal bits, offsets (MB)",
    "TC minimal bits, indices (MB)", "TC minimal bits, offsets, per frame (MB)",
    "TC minimal bits, offsets, per voxel-frame (bits)", "paper Kämpe 2016 (MB)", "paper Kämpe 2016 frames (frames)"};
const std::vector<std::string> kBuildColumns = {
    "scene", "resolution (voxels/axis)", "frames", "build mode", "build (ms)", "voxelize (ms)", "merge (ms)",
    "layout (ms)", "TC N_n (nodes)", "peak RSS (MiB)", "RSS before (MiB)", "peak growth (MiB)",
    "one frame's SVO (MiB)", "shared DAG (MiB)", "peak / frame SVO (×)", "peak growth / frame SVO (×)",
    "peak growth / (frame SVO + shared DAG) (×)", "cells rebuilt", "per-build peak", "modes agree"};

// Table 5's paper columns beside a counts row: the scene's published counts.
void add_paper_counts(const std::string& scene, json& row) {
    const PaperCounts p = paper_table5(paper_scene_of(scene));
    row["paper scene"] = paper_scene_of(scene);
    row["paper SVO/TC N_n (×)"] = p.svo_nn / p.tc_nn;
    row["paper diff/TC N_n (×)"] = p.diff_nn / p.tc_nn;
    row["paper SVDAG/TC N_n (×)"] = p.svdag_nn / p.tc_nn;
    row["paper SVO N_p (nodes)"] = p.svo_np;
    row["paper SVO N_n (nodes)"] = p.svo_nn;
    row["paper diff N_p (nodes)"] = p.diff_np;
    row["paper diff N_n (nodes)"] = p.diff_nn;
    row["paper SVDAG N_p (nodes)"] = p.svdag_np;
    row["paper SVDAG N_n (nodes)"] = p.svdag_nn;
    row["paper TC N_p (nodes)"] = p.tc_np;
    row["paper TC N_n (nodes)"] = p.tc_nn;
}

// Kämpe 2016's figure beside a storage row at its own resolution and frame count.
void add_paper_kampe(json& row) {
    const PaperRow& k = kampe_2016();
    const bool same = row["resolution (voxels/axis)"] == k.integer("resolution (voxels/axis)") &&
                      row["frames"] == k.integer("frames");
    row["paper Kämpe 2016 (MB)"] = same ? json(k.number("MB")) : json(nullptr);
    row["paper Kämpe 2016 frames (frames)"] = same ? json(k.integer("frames")) : json(nullptr);
}

ExperimentOutput table5_tables(const SpecReduction& r) {
    ResultTable counts{"Table 5 — nodes per frame (N_p) and in total (N_n): per-frame SVO, difference tree, "
                       "per-frame SVDAG, time-correlated DAG (TC)",
                       kCountsColumns, {}};
    ResultTable storage{"Table 5 — storage (MB = 10⁶ B) with 32-bit and minimal-bit pointers", kStorageColumns, {}};
    ResultTable builds{"Table 5 — building the time-correlated DAG: incremental (frame n merged into frames 0..n−1) "
                       "and all at once (per-frame DAGs merged together)",
                       kBuildColumns, {}};
    bool all_peaks = true;
    for (const TaskResult& t : r.tasks)
        for (json row : t.rows) {
            row["scene"] = t.task.scene;
            const std::string table = row.at("table");
            if (table == "counts") {
                add_paper_counts(t.task.scene, row);
                counts.rows.push_back(pick(row, counts.columns));
            } else if (table == "storage") {
                add_paper_kampe(row);
                storage.rows.push_back(pick(row, storage.columns));
            } else {
                all_peaks &= row.at("per-build peak").get<bool>();
                builds.rows.push_back(pick(row, builds.columns));
            }
        }
    ExperimentOutput out;
    out.tables = {counts, storage, builds};
    if (r.ctx.quick) out.notes.push_back("This quick run has no Kämpe 2016 block.");
    out.notes.push_back(all_peaks
                            ? "Peak RSS is per build (VmHWM reset through /proc/self/clear_refs before each)."
                            : "Peak RSS is the process's peak so far (the per-build reset was not available).");
    out.notes.push_back("Builds ran while " + load_note(r) + ".");
    return out;
}

// ---- dag-table6 ----

// The image a task renders and the paper's size it stands for.
struct ImageSize {
    int width, height;
    std::string paper_size;
    std::string pixels() const { return std::to_string(width) + "×" + std::to_string(height); }
};

ImageSize image_of(const json& point) {
    return {point.at("width").get<int>(), point.at("height").get<int>(), point.at("paper_size").get<std::string>()};
}

// Whether `image` is the largest of this run's image sizes (which writes the frame image).
bool is_largest_image(const ProbeCall& call, const ImageSize& image) {
    long largest = 0;
    for (const SpecAxis& axis : call.spec.axes)
        for (const json& point : call.ctx.quick ? axis.quick : axis.full)
            if (point.is_object() && point.contains("width"))
                largest = std::max(largest, long(image_of(point).width) * image_of(point).height);
    return long(image.width) * image.height == largest;
}

struct FrameTimes {
    double median_ms = 0, update_ms_mean = 0, render_ms_median = 0, rays_per_frame = 0, nodes_per_primary_ray = 0;
};

// Every frame in order, after one warm-up frame: update(t_k) + render, timed together.
FrameTimes time_frames(Technique& technique, const EyeCamera& camera, int frames, double fps) {
    std::vector<Film> films;
    technique.update(0);
    technique.render(ViewSet::mono(camera), films);
    std::vector<double> total, render;
    double update = 0, rays = 0, visits = 0;
    for (int k = 0; k < frames; ++k) {
        Stopwatch clock;
        technique.update(double(k) / fps);
        technique.render(ViewSet::mono(camera), films);
        total.push_back(clock.elapsed_ms());
        const Stats st = technique.stats();
        update += st.get("update_ms");
        render.push_back(st.get("render_ms"));
        rays += st.get("rays");
        visits += st.get("nodes_per_primary_ray");
    }
    return {median(total), update / frames, median(render), rays / frames, visits / frames};
}

// One scene's dag_raycast, prepared once and timed at every image size: with shadows,
// and with primary rays only (the paper does not say whether its frame rates include
// shadows).
struct PreparedDags {
    std::string key;  // scene, resolution, frames
    std::unique_ptr<Technique> with_shadows, primary_only;
    Stats prepared;
    std::string shadow_source;  // what the scene's light resolved to
    SceneCamera camera;
};

// Tasks run scene by scene, so the cache keeps one slot: the next scene's DAGs replace
// the last scene's, and a run holds one scene's DAGs at a time.
const PreparedDags& prepared_dags(const ProbeCall& call, const Scene& scene, uint32_t resolution, int frames) {
    using Slot = std::shared_ptr<PreparedDags>;
    PreparedDags& dags = *call.cache.get<Slot>("dag-table6:dags", [] { return std::make_shared<PreparedDags>(); });
    const std::string key = call.task.scene + " " + std::to_string(resolution) + "³ × " + std::to_string(frames);
    if (dags.key == key) return dags;
    dags = PreparedDags();  // free the last scene's before building
    const json settings = {{"resolution", resolution}, {"frames", frames}};
    dags.with_shadows = prepare_technique("dag_raycast", scene, Settings(settings, "dag-table6"));
    dags.prepared = dags.with_shadows->stats();
    json primary = settings;
    primary["shadows"] = "none";
    dags.primary_only = prepare_technique("dag_raycast", scene, Settings(primary, "dag-table6"));
    dags.camera = scene.camera.value_or(default_camera_for(scene.evaluate(0).bounds));
    const SceneCamera& c = dags.camera;
    std::vector<Film> probe;
    dags.with_shadows->render(ViewSet::mono(EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, 8, 6)),
                              probe);
    dags.shadow_source = probe.at(0).metadata.at("shadows");
    dags.key = key;
    call.ctx.say(call.task.scene + ": DAG built, " + std::to_string(frames) + " frames");
    return dags;
}

// dag-table6, one scene at one image size: the frame rate along the animation at all
// threads, at one thread and with primary rays only.
ProbeOutput table6_probe(const ProbeCall& call) {
    ProbeOutput out;
    const Scene* scene = open_dynamic_scene(call, out);
    if (!scene) return out;
    const auto resolution = call.setting<uint32_t>("resolution");
    const int frames = call.frames;
    const ImageSize size = image_of(call.variant.settings);
    try {
        const double load_before = load_average();
        const PreparedDags& dags = prepared_dags(call, *scene, resolution, frames);
        const SceneCamera& c = dags.camera;
        const EyeCamera camera =
            EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size.width, size.height);
        const FrameTimes all = time_frames(*dags.with_shadows, camera, frames, scene->frames_per_second);
        const FrameTimes primary = time_frames(*dags.primary_only, camera, frames, scene->frames_per_second);
        FrameTimes one;
        {
            ThreadLimit single(1);
            one = time_frames(*dags.with_shadows, camera, frames, scene->frames_per_second);
        }
        json row;
        row["image (pixels)"] = size.pixels();
        row["stands for (pixels)"] = size.paper_size;
        row["resolution (voxels/axis)"] = resolution;
        row["frames"] = frames;
        row["threads"] = call.ctx.threads > 0 ? call.ctx.threads : default_thread_count();
        row["frame median (ms)"] = all.median_ms;
        row["fps (frames/s)"] = all.median_ms > 0 ? 1000.0 / all.median_ms : 0;
        row["update mean (ms)"] = all.update_ms_mean;
        row["render median (ms)"] = all.render_ms_median;
        row["shadows"] = dags.shadow_source;
        row["rays per frame (rays)"] = all.rays_per_frame;
        row["rays per second (10⁶/s)"] =
            all.render_ms_median > 0 ? json(all.rays_per_frame / all.render_ms_median / 1e3) : json(nullptr);
        row["nodes per primary ray (nodes)"] = all.nodes_per_primary_ray;
        row["primary only fps (frames/s)"] = primary.median_ms > 0 ? 1000.0 / primary.median_ms : 0.0;
        row["1 thread frame median (ms)"] = one.median_ms;
        row["1 thread fps (frames/s)"] = one.median_ms > 0 ? 1000.0 / one.median_ms : 0;
        const bool has_shadow_dags = dags.prepared.has("shadow_dag_bytes");
        row["shadow DAGs, all frames (MB)"] = has_shadow_dags ? json(mb(dags.prepared.get("shadow_dag_bytes"))) : json(nullptr);
        row["shadow DAG build, all frames (s)"] =
            has_shadow_dags ? json(dags.prepared.get("shadow_dag_build_ms") / 1000.0) : json(nullptr);
        row["load before"] = load_before;
        row["load after"] = load_average();
        row["machine threads"] = default_thread_count();
        out.rows.push_back(row);
        if (is_largest_image(call, size)) {  // one frame from the middle of the animation
            std::vector<Film> films;
            dags.with_shadows->update(double(frames / 2) / scene->frames_per_second);
            dags.with_shadows->render(ViewSet::mono(camera), films);
            const std::string image = "frame_" + call.task.scene + ".png";
            write_png(call.ctx.output_dir / image, films.at(0));
            out.files.push_back(image);
        }
    } catch (const Error& e) {
        out.notes.push_back(call.task.scene + " not measured: " + e.what());
        call.ctx.say(call.task.scene + " not measured: " + e.what());
    }
    return out;
}

const std::vector<std::string> kTable6Columns = {
    "scene", "paper scene", "image (pixels)", "stands for (pixels)", "resolution (voxels/axis)", "frames", "threads",
    "frame median (ms)", "fps (frames/s)", "update mean (ms)", "render median (ms)", "shadows",
    "rays per frame (rays)", "rays per second (10⁶/s)", "nodes per primary ray (nodes)",
    "primary only fps (frames/s)", "1 thread frame median (ms)", "1 thread fps (frames/s)",
    "paper CPU fps (frames/s)", "ours / paper fps (×)", "1 thread / paper fps (×)", "shadow DAGs, all frames (MB)",
    "shadow DAG build, all frames (s)"};

// The paper's frame rate beside a row; the ratios only where the image is the paper's own
// size, since frame time scales with the pixel count (quick runs leave them empty).
void add_paper_fps(const std::string& scene, json& row) {
    const double paper_fps = paper_table6_fps(paper_scene_of(scene), row.at("stands for (pixels)"));
    const bool paper_size = row["image (pixels)"] == row["stands for (pixels)"];
    row["paper scene"] = paper_scene_of(scene);
    row["paper CPU fps (frames/s)"] = paper_fps;
    row["ours / paper fps (×)"] = paper_size ? json(row["fps (frames/s)"].get<double>() / paper_fps) : json(nullptr);
    row["1 thread / paper fps (×)"] =
        paper_size ? json(row["1 thread fps (frames/s)"].get<double>() / paper_fps) : json(nullptr);
}

ExperimentOutput table6_tables(const SpecReduction& r) {
    ResultTable t{"Table 6 — frame rate of ray casting through the multi-frame DAG along the animation",
                  kTable6Columns, {}};
    Plot plot;
    plot.title = "Frame rate through the multi-frame DAG (Table 6)";
    plot.x_label = "pixels (10³)";
    plot.y_label = "frames per second";
    int cores = default_thread_count();
    for (const TaskResult& task : r.tasks)
        for (json row : task.rows) {
            const std::string& scene = task.task.scene;
            row["scene"] = scene;
            add_paper_fps(scene, row);
            cores = row.value("machine threads", cores);
            // One measured and one paper curve per scene, in the same colour.
            if (plot.series.empty() || plot.series.back().label != "paper " + paper_scene_of(scene)) {
                const int color = int(plot.series.size() / 2);
                plot.series.push_back({scene, {}, {}, false, true, color});
                plot.series.push_back({"paper " + paper_scene_of(scene), {}, {}, true, true, color});
            }
            const ImageSize size = image_of(task.task.axes);
            const double kilo_pixels = double(size.width) * size.height / 1e3;
            PlotSeries& paper = plot.series.back();
            PlotSeries& ours = plot.series[plot.series.size() - 2];
            ours.x.push_back(kilo_pixels);
            ours.y.push_back(row["fps (frames/s)"]);
            paper.x.push_back(kilo_pixels);
            paper.y.push_back(row["paper CPU fps (frames/s)"]);
            t.rows.push_back(pick(row, t.columns));
        }
    ExperimentOutput out;
    out.tables.push_back(t);
    out.plots.push_back({"table6_fps", plot});
    out.notes.push_back(
        "The paper's figures are CPU-only frame rates on its own machine and scenes (Kitchen and Robot from "
        "Chalmers); ours ran on a machine with " + std::to_string(cores) + " cores, which other work may share: " +
        load_note(r) + "." +
        std::string(r.ctx.quick ? " Quick run: small images standing for the paper's sizes, few frames, a coarse grid."
                                : ""));
    return out;
}

// ---- The specs ----

// The grid of Table 5's main rows; the Kämpe block's memory estimate scales from it.
constexpr int kTable5Resolution = 512;

// The Kämpe 2016 block at its own grid and frame count, incremental only (all at once
// would hold every frame's DAG), built when the estimate from the main rows fits.
json kampe_point() {
    const PaperRow& k = kampe_2016();
    return {{"resolution", k.integer("resolution (voxels/axis)")},
            {"frames", k.integer("frames")},
            {"all_at_once", false},
            {"memory_estimate_from", kTable5Resolution}};
}

std::string kampe_note() {
    const PaperRow& k = kampe_2016();
    const std::string block = k.text("resolution (voxels/axis)") + "³ × " + k.text("frames");
    return "Kämpe 2016 encode " + k.text("frames") + " frames of a captured performer at " +
           k.text("resolution (voxels/axis)") + "³ in " + k.text("MB") + " MB (their unit, possibly MiB); the " + block +
           " rows (full runs only, incremental build) put our scenes beside that figure, which is a context figure for "
           "a different scene. Each is built only if a rough estimate scaled from the " +
           std::to_string(kTable5Resolution) + "³ run (×16 voxels, ×16·" + k.text("frames") +
           "/100 shared nodes at about 64 B each) fits in half the physical memory.";
}

Experiment table5_experiment() {
    return declared_experiment({
        .name = "dag-table5",
        .paper = "P2",
        .figure = "Table 5",
        .description = "nodes per frame and in total of per-frame SVO, difference tree, per-frame SVDAG and the "
                       "time-correlated multi-frame DAG on kitchen, robot and fire, MB with 32-bit and minimal-bit "
                       "pointers, build time and peak RSS of the incremental and all-at-once builds, and a 2048³ × 70 "
                       "block beside Kämpe 2016 (Table 5)",
        .scenes = dynamic_scenes(),
        .frames = 100, .quick_frames = 8,  // animation frames per DAG, unless a point gives its own
        .variants = {{.name = "time-correlated DAG and baselines", .probe = "dag-table5"}},
        .axes = {{"",
                  {{{"resolution", kTable5Resolution}, {"all_at_once", true}}, kampe_point()},
                  {{{"resolution", 64}, {"all_at_once", true}}}}},
        .reducer = "dag-table5",
        .notes = {
            "Frames: frame k is the scene at time k / fps (the scene's frame rate, 30 fps here), k = 0..F−1, all "
            "voxelized (conservative triangle/box overlap) on one grid that encloses the union of every frame's "
            "bounds, so a voxel is the same box in every frame.",
            "Counting, as in dag-table1: SVO nodes include the leaf voxels; an SVDAG counts its single leaf node. "
            "Per-frame SVO and SVDAG: N_n = Σ over frames of the frame's nodes, N_p = N_n / F. Difference tree (Ma & "
            "Shen 2000, path copying): N_n = frame 0's SVO plus, per later frame, every node whose voxels below differ "
            "from the previous frame's at the same place; N_p = N_n / F, and 'diff N_p steady' is the mean over frames "
            "1..F−1 only. 'diff, leaves in masks' is the same tree with the voxel level held in the child masks of the "
            "level above (as the SVDAG and TC DAG hold it): no voxel nodes, and no pointers to them. Time-correlated "
            "DAG: N_n = one root per non-empty frame plus the unique nodes below shared across space and time; N_p = "
            "N_n / F. 'TC reachable per frame' is the mean number of nodes under one frame's root, which equals the "
            "per-frame SVDAG N_p when the merge is right.",
            "The paper gives neither its resolution nor its frame count, and its N_n / N_p differ per structure (they "
            "cannot share one frame count), so only the N_n ratios and the ordering compare; its Kitchen and Robot "
            "are not our scenes. Paper columns are Table 5's figures multiplied out (N_p ×10³, N_n ×10⁶).",
            "Storage: 32-bit = 4 B per node word (8-bit child mask) + 4 B per child pointer (P2 §2.2); the TC layout "
            "stores one root node per frame in time order and needs no root table. Difference tree: the same node "
            "format plus a 4 B root per frame; with voxels as nodes each changed voxel costs 8 B (its word and its "
            "parent's pointer), with leaves in masks nothing beyond its bottom node's copy. SVO: pointerless 1 B per "
            "node, and as stored (1 B mask per node + 4 B first-child index per inner node). Minimal bits (our "
            "reading of Kämpe et al. 2016, whose body text we could not check): the laid-out TC DAG as a dense "
            "bitstream, per node an 8-bit mask and one pointer per child of ⌈log2⌉ of the next level's bits "
            "(offsets: traversable) or of its node count (indices: a lower bound that needs an index table), plus a "
            "root table and a 9-byte header per level.",
            kampe_note(),
            "Build: the whole of build_animation_dag (the dag_raycast technique's build), timed: a pass over the "
            "frames for the bounds (the static nodes once, the moving nodes per frame), voxelizing, merging, and "
            "laying the DAG out. Incremental streams: the static nodes' triangles are flattened once and kept "
            "(positions and triangles only) binned into the split cells of 32³ voxels; per frame only the moving "
            "nodes are flattened and binned, and each frame goes into the DAG of the frames before it cell by cell, "
            "each cell voxelized from its own triangles alone (batches of cells in parallel). Only dirty cells, those "
            "a moving triangle touches in this frame or the one before, are voxelized again; every other cell takes "
            "the previous frame's subtree. No whole frame's voxels or voxelizer input is ever held. 'cells rebuilt' "
            "counts the cells voxelized and merged over all frames (every cell holding triangles in frame 0, then the "
            "dirty ones). All at once voxelizes every frame whole, keeps every frame's SVDAG and merges them level by "
            "level at the end. 'modes agree' = both builds give the same node count and the same layout words. One "
            "frame's SVO is the largest frame's SVO as stored; the shared DAG is the merged DAG's node tables (hash "
            "tables included) at the end of the build, before layout. Peak growth is the peak minus the RSS just "
            "before the build, so it leaves out the loaded scene."},
    });
}

json image_point(int width, int height, const std::string& paper_size) {
    return {{"width", width}, {"height", height}, {"paper_size", paper_size}};
}

Experiment table6_experiment() {
    return declared_experiment({
        .name = "dag-table6",
        .paper = "P2",
        .figure = "Table 6",
        .description = "frame rate of ray casting through the multi-frame DAG along the animation at 1024×768, "
                       "800×600 and 400×300, at all threads and at one (Table 6)",
        .scenes = dynamic_scenes(),
        .frames = 100, .quick_frames = 3,  // animation frames in the DAG, each timed once per image size
        .variants = {{.name = "dag_raycast", .probe = "dag-table6"}},
        // The paper's three image sizes; a quick run renders small images standing for them.
        .axes = {{"resolution", {512}, {64}},
                 {"",
                  {image_point(1024, 768, "1024×768"), image_point(800, 600, "800×600"),
                   image_point(400, 300, "400×300")},
                  {image_point(160, 120, "1024×768"), image_point(120, 90, "800×600"),
                   image_point(80, 60, "400×300")}}},
        .reducer = "dag-table6",
        .notes = {
            "Renderer: the dag_raycast technique, prepared once per scene (incremental build of the multi-frame DAG "
            "at the resolution shown over the frames shown). Per frame: update(t_k), which only selects frame k's "
            "root, then one primary ray per pixel from the scene camera through that root (single-precision octree "
            "walk after Laine & Karras 2010), the hit shaded with the voxel face normal and the scene's first point, "
            "spot or directional light. Shadows (column 'shadows'): shadow_dag = a lookup in that frame's shadow DAGs "
            "(P2 §3; built at prepare at the voxel resolution from the frame's triangles, so not part of the frame "
            "time: one over a directional light's light space, or a cube of six spot frusta around a point light); "
            "dag_ray = a shadow ray through the same frame's DAG. Each image size renders every frame in order after "
            "one warm-up frame; a frame's time is update + render, and fps = 1000 / the median frame time. The same "
            "is repeated at 1 thread (ThreadLimit), and with shadows off ('primary only', all threads), since the "
            "paper does not say whether its figures include shadows. frame_<scene>.png: frame F/2 at the largest "
            "size. 'ours / paper' is filled only where the image is the paper's own size (full runs); a row whose "
            "image differs from the size it stands for leaves it empty, since frame time scales with the pixel "
            "count."},
    });
}

}  // namespace

void register_dynamic_dag_experiments(ExperimentRegistry& registry) {
    add_probe("dag-table5", table5_probe);
    add_reducer("dag-table5", table5_tables);
    add_probe("dag-table6", table6_probe);
    add_reducer("dag-table6", table6_tables);
    registry.add(table5_experiment());
    registry.add(table6_experiment());
}

}  // namespace gilab
