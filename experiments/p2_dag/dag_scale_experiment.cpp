// dag-scale, beyond P2: the SVDAG and the symmetry-aware SSVDAG made from it (Villanueva,
// Marton & Gobbetti 2016) on P2's models, the castle and three whole scenes, 2048³ to
// 65536³: nodes, bytes, bits per voxel, build and conversion times, peak memory and
// primary-ray throughput through both. A task is one scene at one resolution; a row that would not
// fit in memory is skipped with a note before anything is built.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>
#include "accel/dag/dag_ray_caster.hpp"
#include "accel/dag/symmetric_dag.hpp"
#include "accel/dag/symmetric_dag_ray_caster.hpp"
#include "accel/dag/svdag.hpp"
#include "core/scene/camera.hpp"
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/voxelizer.hpp"
#include "experiments/p2_dag/dag_models.hpp"
#include "experiments/p2_dag/streamed_svdag_row.hpp"
#include "experiments/p2_dag/symmetric_dag_checks.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/measures.hpp"
#include "experiments/runner/spec_functions.hpp"

namespace gilab {

namespace {

using nlohmann::json;
using namespace p2;

// While the streamed build runs, the cells being voxelized (two batches of one cell per
// thread, 8 B per voxel) sit beside its merge tables; the tables get the rest of the
// row's budget and the build stops with a note past it. After the build, the SSVDAG
// conversion and the checks work beside the SVDAG: the row's peak was 4.1 times the
// SVDAG's bytes on the Happy Buddha at 32768³, so 5 times must fit the budget.
constexpr double kAfterBuildOverDag = 5;
// Literal decodes hold both voxel lists (8 B per voxel each, up to twice that while a
// list grows): only up to this many voxels, and only within the row's memory budget.
constexpr uint64_t kDecodeVoxelLimit = uint64_t(1) << 26;
constexpr uint64_t kDecodeBytesPerVoxel = 32;
// The SVDAG's bytes with its level depth-1 nodes (the voxels' parents) stored as the
// SSVDAG's 32-bit layout stores them: their 8-bit masks, four to a word, in place of a
// mask word plus one pointer per voxel each, and no word for the voxel node. Pointers to
// them keep their 4 bytes (they would hold the mask's index). This is
// Ssvdag::word_bytes() without the mirror merging, so word_bytes / this is what merging
// under reflections alone saves.
uint64_t svdag_bytes_with_packed_leaves(const Svdag& dag) {
    if (dag.empty() || dag.depth() == 0) return dag.bytes();
    const int depth = dag.depth();
    const uint64_t words = dag.words().size();
    const uint64_t first_parent = dag.level_nodes(depth - 1).front();
    const uint64_t parent_and_leaf_words = words - first_parent;  // level depth-1, then the one leaf word
    const uint64_t packed_words = (dag.level_node_counts()[size_t(depth - 1)] + 3) / 4;
    return (words - parent_and_leaf_words + packed_words) * sizeof(uint32_t);
}

double seconds_of(const Stopwatch& watch) { return watch.elapsed_ms() * 1e-3; }

// One row: the model at `resolution`, SVDAG by the split build (all threads, and on one
// thread up to `single_thread_up_to`), SSVDAG from it, checks, rays through both.
void measure_scale(const ProbeCall& call, const Model& model, ProbeOutput& out) {
    const auto res = call.setting<uint32_t>("resolution");
    const auto single_thread_up_to = call.setting<uint32_t>("single_thread_up_to");
    const int ray_reps = call.setting<int>("ray_repetitions");
    const ExperimentContext& ctx = call.ctx;
    const int threads = ctx.threads > 0 ? ctx.threads : default_thread_count();
    const StreamedSvdagRow row(model, res, threads);
    const std::string& row_name = row.name();
    auto skip = [&](const std::string& why) {
        out.notes.push_back(row_name + " skipped: " + why);
        ctx.say(row_name + ": skipped, " + why);
    };
    if (!row.refusal().empty()) {
        skip(row.refusal());
        return;
    }
    const size_t budget = row.budget_bytes();
    const uint64_t in_flight = row.in_flight_bytes();
    const int split_level = row.split_level();
    const auto say = [&](const std::string& s) { ctx.say(s); };
    const double load_before = load_average();
    if (!reset_peak_rss())
        out.notes.push_back("VmHWM could not be reset on this system: peak_rss_MiB is process-wide.");
    const size_t rss_before = current_rss_bytes();
    try {
        json single_thread_s = nullptr;
        if (res <= single_thread_up_to) {
            ctx.say(row_name + ": SVDAG, " + row.build_text() + ", 1 thread");
            ThreadLimit one(1);
            Stopwatch watch;
            row.build(say);
            single_thread_s = seconds_of(watch);
        }
        ctx.say(row_name + ": SVDAG, " + row.build_text() + ", all threads");
        Stopwatch build_watch;
        const Svdag svdag = row.build(say);
        const double build_s = seconds_of(build_watch);
        const uint64_t voxels = svdag.build_stats().input_nodes;
        const uint64_t need = uint64_t(kAfterBuildOverDag * double(svdag.bytes()));
        if (need > budget) {
            skip(budget_text(need, budget) + " for the SSVDAG conversion and the checks beside the " +
                 std::to_string(svdag.bytes() >> 20) + " MiB SVDAG (built in " + std::to_string(int(build_s)) + " s)");
            return;
        }
        ctx.say(row_name + ": " + std::to_string(voxels) + " voxels, " + std::to_string(svdag.node_count()) +
                " SVDAG nodes; SVDAG → SSVDAG");
        Stopwatch convert_watch;
        const Ssvdag ssvdag = Ssvdag::from_svdag(svdag);
        const double convert_s = seconds_of(convert_watch);

        ctx.say(row_name + ": comparing the two DAGs");
        const bool same = same_octree(svdag, ssvdag);
        json decode_equal = nullptr;
        // What the guards allowed for: the larger of the build's tables with the cells in
        // flight and the work after the build, plus the literal decode where it ran.
        uint64_t allowed = std::max<uint64_t>(svdag.build_stats().table_bytes + in_flight, need);
        if (voxels <= kDecodeVoxelLimit && need + kDecodeBytesPerVoxel * voxels <= budget) {
            allowed += kDecodeBytesPerVoxel * voxels;
            decode_equal = svdag.decode() == ssvdag.decode();
        }
        const std::vector<Ray> rays = camera_rays(model, call.size);
        ctx.say(row_name + ": casting " + std::to_string(rays.size()) + " rays ×" + std::to_string(ray_reps) +
                " through each DAG");
        const DagWordsView view = dag_view(svdag);
        const std::vector<RayRun> runs =
            cast_in_turn(rays, ray_reps,
                         {[&](const Ray& ray) { return cast_dag_ray(view, ray); },
                          [&](const Ray& ray) { return cast_symmetric_dag_ray(ssvdag, ray); }});
        const double svdag_rays_per_s = runs[0].median_rays_per_s(), ssvdag_rays_per_s = runs[1].median_rays_per_s();
        const uint64_t disagreeing = disagreeing_rays(runs[0], runs[1]);

        const double svdag_bytes = double(svdag.bytes()), ssvdag_bytes = double(ssvdag.bytes());
        const double ssvdag_word_bytes = double(ssvdag.word_bytes());
        const double packed_bytes = double(svdag_bytes_with_packed_leaves(svdag));
        const double voxel_count = double(voxels);
        out.rows.push_back(
            {{"scene", model.label},
             {"resolution", res},
             {"voxels", voxels},
             {"split_level", split_level},
             {"subtrees", svdag.build_stats().subtrees},
             {"svdag_nodes", svdag.node_count()},
             {"svdag_MB", mb(svdag_bytes)},
             {"ssvdag_nodes", ssvdag.node_count()},
             {"ssvdag_MB", mb(ssvdag_bytes)},
             {"ssvdag_over_svdag", ratio(ssvdag_bytes, svdag_bytes)},
             {"ssvdag_over_svdag_nodes", ratio(double(ssvdag.node_count()), double(svdag.node_count()))},
             {"svdag_packed_leaves_MB", mb(packed_bytes)},
             {"ssvdag_words_MB", mb(ssvdag_word_bytes)},
             {"ssvdag_words_over_packed_leaves", ratio(ssvdag_word_bytes, packed_bytes)},
             {"ssvdag_over_ssvdag_words", ratio(ssvdag_bytes, ssvdag_word_bytes)},
             {"mirrored_pointer_share", ratio(double(ssvdag.transformed_pointer_count()), double(ssvdag.pointer_count()))},
             {"long_pointer_share", ratio(double(ssvdag.long_pointer_count()), double(ssvdag.pointer_count()))},
             {"bits_per_voxel_svdag", ratio(8 * svdag_bytes, voxel_count)},
             {"bits_per_voxel_ssvdag", ratio(8 * ssvdag_bytes, voxel_count)},
             {"svdag_build (s), all threads", build_s},
             {"svdag_build (s), 1 thread", single_thread_s},
             {"voxelize_share (s/s)", ratio(svdag.build_stats().voxelize_ms * 1e-3, build_s)},
             {"ssvdag_convert (s)", convert_s},
             {"peak_rss_MiB", mib(double(peak_rss_bytes()))},
             {"rss_before_MiB", mib(double(rss_before))},
             {"rays", rays.size()},
             {"hit_fraction", runs[0].hit_fraction()},
             {"svdag_rays_per_s", svdag_rays_per_s},
             {"ssvdag_rays_per_s", ssvdag_rays_per_s},
             {"ssvdag_over_svdag_rays_per_s", ratio(ssvdag_rays_per_s, svdag_rays_per_s)},
             {"rays_disagreeing", disagreeing},
             {"same_octree", same},
             {"decode_equal", decode_equal},
             {"threads", threads},
             {"estimated_rss_MiB", mib(double(allowed))},
             {"load_average_before", load_before},
             {"load_average_after", load_average()}});
        if (!same || decode_equal == false || disagreeing > 0)
            out.notes.push_back(row_name + ": the SSVDAG disagrees with the SVDAG (see same_octree, decode_equal, "
                                           "rays_disagreeing)");
    } catch (const Error& e) {
        // A DAG beyond its pointers' reach (2^32 SVDAG words, 2^29 SSVDAG units), merge
        // tables past their limit, or a voxelization over the voxelizer's own budget.
        out.notes.push_back(row_name + " skipped: " + e.what());
        ctx.say(row_name + ": skipped, " + e.what());
    }
}

const std::vector<std::string> kColumns = {"scene",
                                           "resolution",
                                           "voxels",
                                           "split_level",
                                           "subtrees",
                                           "svdag_nodes",
                                           "svdag_MB",
                                           "ssvdag_nodes",
                                           "ssvdag_MB",
                                           "ssvdag_over_svdag",
                                           "ssvdag_over_svdag_nodes",
                                           "svdag_packed_leaves_MB",
                                           "ssvdag_words_MB",
                                           "ssvdag_words_over_packed_leaves",
                                           "ssvdag_over_ssvdag_words",
                                           "mirrored_pointer_share",
                                           "long_pointer_share",
                                           "bits_per_voxel_svdag",
                                           "bits_per_voxel_ssvdag",
                                           "svdag_build (s), all threads",
                                           "svdag_build (s), 1 thread",
                                           "voxelize_share (s/s)",
                                           "ssvdag_convert (s)",
                                           "peak_rss_MiB",
                                           "rss_before_MiB",
                                           "estimated_rss_MiB",
                                           "rays",
                                           "hit_fraction",
                                           "svdag_rays_per_s",
                                           "ssvdag_rays_per_s",
                                           "ssvdag_over_svdag_rays_per_s",
                                           "rays_disagreeing",
                                           "same_octree",
                                           "decode_equal",
                                           "threads"};

ExperimentOutput reduce_scale(const SpecReduction& r) {
    const std::vector<json> rows = rows_of(r);
    const std::vector<json>& resolutions = plan_resolutions(r);
    ExperimentOutput out;
    out.tables = scale_tables(r, rows,
                              "SVDAG and SSVDAG at scale (MB = 10⁶ bytes, MiB = 2²⁰ bytes, times in wall-clock seconds)",
                              kColumns,
                              {"ssvdag_over_svdag", "ssvdag_over_svdag_nodes", "ssvdag_words_over_packed_leaves",
                               "ssvdag_over_ssvdag_words"});

    // Which resolutions have the 1-thread build (a setting decides it by resolution).
    std::string with_one_thread, without;
    for (const json& resolution : resolutions) {
        const bool one = std::any_of(rows.begin(), rows.end(), [&](const json& row) {
            return row.at("resolution") == resolution && row.value("svdag_build (s), 1 thread", json()).is_number();
        });
        const bool present =
            std::any_of(rows.begin(), rows.end(), [&](const json& row) { return row.at("resolution") == resolution; });
        if (!present) continue;
        std::string& list = one ? with_one_thread : without;
        list += (list.empty() ? "" : ", ") + cube(resolution.get<uint32_t>());
    }
    const uint32_t limit = r.spec.variants.at(0).settings.at("single_thread_up_to").get<uint32_t>();
    out.notes.push_back("svdag_build (s), 1 thread is measured on the rows at " +
                        (with_one_thread.empty() ? std::string("none of the resolutions") : with_one_thread) +
                        "; rows above " + cube(limit) + " have none, one thread would take too long there" +
                        (without.empty() ? std::string("") : " (the rows at " + without + ")") + ".");
    if (!rows.empty())
        out.notes.push_back("Threads for the all-thread build, the conversion and the rays: " +
                            rows.front().at("threads").dump() + ".");
    if (auto note = load_note(rows)) out.notes.push_back(*note);
    return out;
}

}  // namespace

Experiment dag_scale_experiment() {
    add_probe("dag-scale", model_probe(measure_scale));
    add_reducer("dag-scale", reduce_scale);
    return declared_experiment({
        .name = "dag-scale",
        .paper = "P2",
        .figure = "beyond P2: SVDAG and symmetry-aware SSVDAG at scale",
        .description = "SVDAG (split build) and the symmetry-aware SSVDAG made from it on the P2 models, the "
                       "castle and three whole scenes, 2048³ to 65536³: nodes, MB, bits per voxel, build and "
                       "conversion times, peak RSS and primary rays/s through both, with the two DAGs checked to "
                       "hold the same voxels",
        .scenes = model_scenes(),
        .size = 256, .quick_size = 64,
        .variants = {{.name = "SVDAG, SSVDAG",
                      .probe = "dag-scale",
                      .settings = {{"single_thread_up_to", 8192}, {"ray_repetitions", 5}}}},
        .axes = {{"resolution", {2048, 4096, 8192, 16384, 32768, 65536}, {64, 128}}},
        .reducer = "dag-scale",
        .notes = {
            "Grid placement: the Stanford models and the castle are voxelized alone (floor or ground left out), "
            "Sponza, Sibenik and the conference room whole, each as placed by its scene file in scenes/, in the "
            "smallest cube enclosing its bounding box, grown by 0.1% per side (VoxelGrid::enclosing). Voxels are "
            "conservative surface voxels (triangle/box overlap), not solid.",
            "SVDAG: Svdag::from_voxelizer, the split build of dag-table3 streamed: each 256³ subtree voxelized on "
            "its own (a batch of one per thread, the next batch voxelized while this one merges), merged into "
            "shared per-level tables, the roots joined (split level = depth − 8; grids of 256³ and "
            "below are built whole, in one piece). Stored in P2's format: a 4 B mask word per node + 4 B per child "
            "pointer, and one word for the voxel node. svdag_build (s) is the wall time of the whole call, "
            "voxelization included; voxelize_share (s/s) is the part the merge spent waiting for voxelized cells (the rest of the voxelizing overlaps the merge). The 1-thread build runs "
            "first under a TBB limit of one thread (ThreadLimit), then the all-thread build the rest of the row "
            "uses.",
            "SSVDAG: Ssvdag::from_svdag (accel/dag/symmetric_dag.hpp) on that SVDAG, all threads, wall time. Implemented "
            "from the paper: subtrees equal up to any of the 8 reflections along the grid axes merged, the 3-bit "
            "mirror carried in each pointer, variable-size pointers and ray casting with the mirror applied to the "
            "child order. Storage in 16-bit units: a node is a header unit (child mask, and a bit per child whose "
            "pointer is long) and per child a short pointer (one unit: mirror and a 13-bit offset from the child "
            "level's start) or a long one (two units: mirror and a 29-bit address); each level is ordered by "
            "pointers reaching a node per unit it takes, most first, so the most reached nodes sit within a short "
            "pointer's reach; the voxels' parents are 8-bit masks, two to a unit. The paper's exact pointer "
            "encoding differs in detail. Not implemented: 4³-voxel leaves as 64-bit masks and the paper's "
            "out-of-core build (the SVDAG is streamed instead).",
            "svdag_packed_leaves_MB is the SVDAG's size if its level depth−1 nodes (the voxels' parents) were "
            "stored as 8-bit masks four to a word (no voxel node word), computed from the SVDAG's level node "
            "counts and its layout. ssvdag_words_MB is the SSVDAG's nodes with every header and pointer a 32-bit "
            "word and the same packed masks. So ssvdag_words_over_packed_leaves is what merging under reflections "
            "saves by itself, ssvdag_over_ssvdag_words what the short pointers save, and svdag_packed_leaves_MB / "
            "svdag_MB what the leaf packing saves. Node counts include the voxel node (stored by the SVDAG, "
            "implicit in the SSVDAG). mirrored_pointer_share = SSVDAG pointers with a non-zero mirror / all its "
            "pointers; long_pointer_share = its 32-bit pointers / all its pointers. bits_per_voxel = 8 × bytes / "
            "voxels.",
            "Checks: same_octree walks both DAGs from the root together and compares the child masks at every pair "
            "of nodes met (each SVDAG node once per SSVDAG pointer it meets: the DAGs' size, not the voxel count), "
            "which holds exactly when the two hold the same voxels; decode_equal compares the two decoded voxel "
            "lists (Morton codes) literally, on rows up to 2²⁶ voxels (empty above). Rays: one per pixel centre of "
            "a size² image (256² full, 64² quick) from the scene camera, the same rays cast through the SVDAG "
            "(cast_dag_ray) and the SSVDAG (cast_symmetric_dag_ray) on all threads, alternating, median rays/s over "
            "ray_repetitions passes each; rays_disagreeing counts rays whose hit or hit voxel differs (0 "
            "expected).",
            "Memory: peak_rss_MiB is the row's own peak resident memory (VmHWM reset through /proc/self/clear_refs "
            "before the row), including what the process held before it (rss_before_MiB). The row's budget is half "
            "the available memory. The cells being voxelized (two batches of one 256³ cell per thread, 8 B per "
            "voxel by the voxelizer's estimate) must fit it; the streamed build's merge tables get the rest and are "
            "checked before every cell: past it the row stops with a note saying how far it got. After the build, "
            "5 × the SVDAG's bytes must fit the budget for the SSVDAG conversion and the checks (the row's peak was "
            "4.1 × the SVDAG on the Happy Buddha at 32768³), or the row is skipped with a note giving the SVDAG's "
            "size and build time. estimated_rss_MiB is the larger of the two allowances. A row whose voxelizer "
            "estimate exceeds 2³⁷ voxels (Sponza's 110 G voxels at 131072³ pass it and build in 28.6 minutes on two "
            "cores), whose resolution exceeds the "
            "grid's 2²¹, or whose DAG is beyond its pointers' reach (2³² SVDAG words, 2²⁹ SSVDAG units), is skipped "
            "with a note too. The literal decode (decode_equal) adds up to 32 B per voxel: it runs only when that "
            "fits the budget too, once the voxel count is known, and estimated_rss_MiB includes it where it ran.",
            "paper: SSVDAG (Villanueva, Marton & Gobbetti 2016/2017) stores PowerPlant at 64K³ in 86 MB against "
            "167 MB as an SVDAG (0.123 bits per voxel) and averages 52.4 % of the SVDAG's bytes over its scenes; "
            "Kämpe et al. 2013 store Epic Citadel at 128K³ (19 G voxels) in 945 MB. None of these scenes is among "
            "ours, so the figures are not per row.",
            "Times are wall clock on this machine, single runs (no repetitions: the large rows take minutes); "
            "other work on the machine slows them (the load averages are in the last note)."},
    });
}

}  // namespace gilab
