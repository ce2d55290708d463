#include "accel/shadow/shadow_dag.hpp"
#include <algorithm>
#include <array>
#include <cmath>
#include "accel/dag/dag_layout.hpp"
#include "core/util/error.hpp"
#include "core/util/morton.hpp"
#include "core/util/parallel.hpp"
#include "core/util/stats.hpp"

namespace gilab {
namespace {

constexpr uint32_t kDefaultTile = 2048;
constexpr int kMaxSplitLevel = 6;

// Merges cell SVOs bottom-up into the shared per-level tables and joins the cells.
class ShadowDagMerger {
public:
    explicit ShadowDagMerger(int depth) : depth_(depth), leaf_level_(depth - kShadowLeafLevels), tables_(leaf_level_ + 1) {}

    // Id of the SVO's root on its cell level (the root must be Boundary).
    uint32_t merge(const ShadowSvo& svo) {
        ids_below_.resize(svo.leaves().size());
        DagLevelTable& leaves = tables_[leaf_level_];
        for (size_t i = 0; i < svo.leaves().size(); ++i) {
            const uint64_t bits = svo.leaves()[i];
            const uint32_t words[2] = {uint32_t(bits), uint32_t(bits >> 32)};
            ids_below_[i] = leaves.find_or_insert(0, words, 2);
        }
        for (size_t i = svo.interior_levels(); i-- > 0;) {
            DagLevelTable& table = tables_[svo.cell_level() + int(i)];
            const auto& masks = svo.masks(i);
            const auto& first = svo.first_child(i);
            ids_.resize(masks.size());
            for (size_t j = 0; j < masks.size(); ++j)
                ids_[j] = table.find_or_insert(masks[j], ids_below_.data() + first[j], boundary_count(masks[j]));
            ids_.swap(ids_below_);
        }
        return ids_below_.at(0);
    }

    // One interior node from its children's states and (Boundary) ids; returns its state
    // by the paper's rules and, when Boundary, its id on `level`.
    ShadowState join(int level, const std::array<ShadowState, 8>& states, const std::array<uint32_t, 8>& ids,
                     ShadowState undefined_as, uint32_t& id) {
        const ShadowState s = combine_child_states(states);
        if (s != ShadowState::Boundary) return s;
        uint32_t mask = 0, count = 0;
        std::array<uint32_t, 8> kids{};
        for (int k = 0; k < 8; ++k) {
            mask = with_child_state(mask, k, stored_child_state(states[k], undefined_as));
            if (states[k] == ShadowState::Boundary) kids[count++] = ids[k];
        }
        id = tables_[level].find_or_insert(mask, kids.data(), count);
        return s;
    }

    const std::vector<DagLevelTable>& tables() const { return tables_; }
    size_t table_bytes() const {
        size_t b = 0;
        for (const auto& t : tables_) b += t.memory_bytes();
        return b;
    }

private:
    int depth_, leaf_level_;
    std::vector<DagLevelTable> tables_;
    std::vector<uint32_t> ids_, ids_below_;
};

}  // namespace

ShadowDag ShadowDag::build(int grid_depth, const TileFill& fill, const ShadowDagOptions& options) {
    Stopwatch clock;
    if (grid_depth < 3 || grid_depth > 17)
        throw Error("shadow DAG", "light-space octree depth " + std::to_string(grid_depth) + " is outside 3..17");
    const ShadowState undefined_as = options.undefined_as;
    const uint32_t size = 1u << grid_depth;
    const uint32_t tile = options.tile_texels == 0 ? std::min(size, kDefaultTile) : options.tile_texels;
    if (tile < 4 || tile > size || (tile & (tile - 1)))
        throw Error("shadow DAG", "tile size " + std::to_string(tile) + " must be a power of two in 4.." +
                                      std::to_string(size));
    const int split = grid_depth - __builtin_ctz(tile);  // level of the tile-sized cells
    // Cells are kept as one state and id each, 8^split of them: at most 2^18.
    if (split > kMaxSplitLevel)
        throw Error("shadow DAG", "tile size " + std::to_string(tile) + " is too small for a " + std::to_string(size) +
                                      "³ octree: at least " + std::to_string(size >> kMaxSplitLevel));
    const size_t limit = options.memory_limit_bytes ? options.memory_limit_bytes : default_memory_limit_bytes();
    // A depth tile holds two float pyramids (4/3 of the texels each).
    const size_t tile_bytes = size_t(tile) * tile * 2 * sizeof(float) * 4 / 3;
    if (tile_bytes > limit)
        throw Error("shadow DAG", "a " + std::to_string(tile) + "² depth tile needs " + std::to_string(tile_bytes / 1000000) +
                                      " MB, over the " + std::to_string(limit / 1000000) + " MB memory limit");
    const auto& progress = options.progress;
    const uint32_t cells_per_axis = 1u << split;

    ShadowDag dag;
    dag.depth_ = grid_depth;
    dag.undefined_as_ = undefined_as;
    ShadowDagBuildStats& st = dag.stats_;
    st.tile_texels = tile;
    ShadowDagMerger merger(grid_depth);
    const size_t cell_count = size_t(1) << (3 * split);
    std::vector<ShadowState> states(cell_count, ShadowState::Lit);
    std::vector<uint32_t> ids(cell_count, 0);

    LightDepthTile depth;
    for (uint32_t ty = 0; ty < cells_per_axis; ++ty)
        for (uint32_t tx = 0; tx < cells_per_axis; ++tx) {
            Stopwatch t;
            fill(tx * tile, ty * tile, tile, depth);
            if (depth.size() != tile || depth.x0() != tx * tile || depth.y0() != ty * tile)
                throw Error("shadow DAG", "internal: a depth tile was filled for the wrong texels");
            st.depth_ms += t.elapsed_ms();
            st.rays += depth.rays_cast();
            for (uint32_t cz = 0; cz < cells_per_axis; ++cz) {
                t.reset();
                const ShadowSvo svo = ShadowSvo::build(depth, UVec3(tx, ty, cz) * tile, split, grid_depth, undefined_as);
                st.svo_ms += t.elapsed_ms();
                st.svo_nodes += svo.node_count();
                const uint64_t code = morton_encode(tx, ty, cz);
                states[code] = svo.root_state();
                if (svo.root_state() == ShadowState::Boundary) {
                    t.reset();
                    ids[code] = merger.merge(svo);
                    st.merge_ms += t.elapsed_ms();
                }
            }
            ++st.tiles;
            if (progress) progress(double(st.tiles) / (double(cells_per_axis) * cells_per_axis));
            if (merger.table_bytes() + tile_bytes > limit)
                throw Error("shadow DAG", "the merge tables outgrew the " + std::to_string(limit / 1000000) +
                                              " MB memory limit after " + std::to_string(st.tiles) + " of " +
                                              std::to_string(size_t(cells_per_axis) * cells_per_axis) +
                                              " tiles; use a lower resolution");
        }

    // Join the cells under the root, level by level, by the same rules.
    Stopwatch t;
    for (int level = split - 1; level >= 0; --level) {
        const size_t parents = size_t(1) << (3 * level);
        std::vector<ShadowState> up_states(parents);
        std::vector<uint32_t> up_ids(parents, 0);
        for (size_t p = 0; p < parents; ++p) {
            std::array<ShadowState, 8> s;
            std::array<uint32_t, 8> c;
            for (int k = 0; k < 8; ++k) {
                s[k] = states[p * 8 + k];
                c[k] = ids[p * 8 + k];
            }
            up_states[p] = merger.join(level, s, c, undefined_as, up_ids[p]);
        }
        states.swap(up_states);
        ids.swap(up_ids);
    }
    st.merge_ms += t.elapsed_ms();
    dag.root_state_ = states[0];

    t.reset();
    st.table_bytes = merger.table_bytes();
    DagLayoutOptions layout_options;
    layout_options.payload_level = grid_depth - kShadowLeafLevels;
    layout_options.payload_header = false;
    std::vector<uint32_t> roots;
    if (dag.root_state_ == ShadowState::Boundary) roots.push_back(ids[0]);
    DagLayout layout = lay_out_dag(merger.tables(), roots, layout_options, "shadow DAG");
    dag.words_ = std::move(layout.words);
    dag.level_counts_ = std::move(layout.level_counts);
    dag.level_begin_ = std::move(layout.level_begin);
    dag.pointer_count_ = layout.pointer_count;
    st.layout_ms = t.elapsed_ms();
    st.total_ms = clock.elapsed_ms();
    st.peak_rss_bytes = peak_rss_bytes();
    return dag;
}

ShadowDag ShadowDag::build(const Scene& scene, const RayTracer& tracer, const PunctualLight& light,
                           const ShadowDagOptions& options) {
    const LightSpace space(light, tracer.frame().bounds, options.resolution);
    // A cheap look first, so a light that sees nothing is refused at once.
    if (!light_sees_geometry(tracer, light))
        throw Error("shadow DAG (light '" + light.name + "')",
                    "the light sees no geometry in its view volume (no triangle overlaps it)");
    Stopwatch closed_clock;
    const ClosedSurfaces closed = options.double_depth ? closed_surfaces(scene, tracer.frame()) : ClosedSurfaces{};
    const double closed_ms = closed_clock.elapsed_ms();
    ShadowDag dag = build(
        space.depth(),
        [&](uint32_t x0, uint32_t y0, uint32_t size, LightDepthTile& tile) { tile.render(tracer, space, &closed, x0, y0, size); },
        options);
    dag.stats_.closed_ms = closed_ms;
    dag.stats_.total_ms += closed_ms;
    dag.space_ = space;
    return dag;
}

bool ShadowDag::light_sees_geometry(const RayTracer& tracer, const PunctualLight& light) {
    const SceneFrame& frame = tracer.frame();
    if (!LightSpace::faces_any_of(light, frame.bounds)) return false;
    // Every triangle against the view volume, not rays through texel centres: a triangle
    // smaller than the gaps between rays (a fire particle) must still count.
    const LightSpace space(light, frame.bounds, 8);  // the frustum only; the resolution does not matter
    for (const WorldMesh& m : frame.meshes)
        for (const UVec3& t : m.triangles)
            if (space.may_overlap_triangle(m.positions[t.x], m.positions[t.y], m.positions[t.z])) return true;
    return false;
}

size_t ShadowDag::node_count() const {
    size_t n = 0;
    for (uint64_t c : level_counts_) n += c;
    return n;
}

ShadowState ShadowDag::voxel_state(const UVec3& v, Cursor& cur) const {
    if (root_state_ != ShadowState::Boundary) return root_state_;
    const int leaf_level = depth_ - kShadowLeafLevels;
    // The node on level k depends only on the top k bits of each coordinate: restart from
    // the deepest level above the highest bit in which this voxel differs from the last.
    const uint32_t diff = (v.x ^ cur.voxel.x) | (v.y ^ cur.voxel.y) | (v.z ^ cur.voxel.z);
    const int same = diff == 0 ? leaf_level : std::min(leaf_level, depth_ - 1 - (31 - __builtin_clz(diff)));
    int level = std::min(same, cur.levels - 1);
    uint32_t node = cur.node[level];
    cur.voxel = v;
    for (; level < leaf_level; ++level) {
        const int bit = depth_ - 1 - level;
        const int slot = int((v.x >> bit) & 1u) | int((v.y >> bit) & 1u) << 1 | int((v.z >> bit) & 1u) << 2;
        const uint32_t mask = words_[node] & 0xffffu;
        const ShadowState s = child_state(mask, slot);
        if (s != ShadowState::Boundary) {
            cur.levels = level + 1;
            return s;
        }
        node = words_[node + 1 + boundary_rank(mask, slot)];
        cur.node[level + 1] = node;
    }
    cur.levels = leaf_level + 1;
    const uint64_t bits = uint64_t(words_[node]) | uint64_t(words_[node + 1]) << 32;
    const uint32_t k = (v.x & 3u) + 4 * (v.y & 3u) + 16 * (v.z & 3u);
    return (bits >> k) & 1u ? ShadowState::Shadow : ShadowState::Lit;
}

bool ShadowDag::lit_at(const DVec3& c, Cursor& cursor) const {
    const double n = space_ ? double(space_->resolution()) : double(octree_size());
    if (!(c.x >= 0 && c.y >= 0 && c.x < n && c.y < n) || !(c.z >= 0)) return true;
    const uint32_t z = uint32_t(std::min(c.z, double(octree_size() - 1)));
    return state_is_lit(voxel_state(UVec3(uint32_t(c.x), uint32_t(c.y), z), cursor), undefined_as_);
}

float ShadowDag::visibility(const Vec3& p, const Vec3& normal, int pcf, Cursor& cursor) const {
    if (!space_) throw Error("shadow DAG", "world lookups need a DAG built from a scene");
    if (!space_->faces_light(p, normal)) return 0.0f;
    return pcf_visibility(space_->lookup_coords(p, normal), pcf, [&](const DVec3& c) { return lit_at(c, cursor); });
}

void ShadowDag::visibility(std::span<const Vec3> points, std::span<const Vec3> normals, std::span<float> out,
                           int pcf) const {
    if (points.size() != normals.size() || points.size() != out.size())
        throw Error("shadow DAG", "batched lookup needs as many normals and outputs as points");
    parallel_for(points.size(), 4096, [&](size_t begin, size_t end) {
        Cursor cursor;  // points arrive in pixel order: neighbours share most of their path
        for (size_t i = begin; i < end; ++i) out[i] = visibility(points[i], normals[i], pcf, cursor);
    });
}

ShadowSvo ShadowDag::expand() const {
    const int leaf_level = depth_ - kShadowLeafLevels;
    std::vector<std::vector<uint16_t>> masks;
    std::vector<std::vector<uint32_t>> first;
    std::vector<uint64_t> leaves;
    if (root_state_ == ShadowState::Boundary) {
        std::vector<uint32_t> nodes{0}, next;
        for (int level = 0; level < leaf_level; ++level) {
            std::vector<uint16_t> m(nodes.size());
            std::vector<uint32_t> f(nodes.size());
            next.clear();
            for (size_t i = 0; i < nodes.size(); ++i) {
                const uint32_t mask = words_[nodes[i]] & 0xffffu;
                m[i] = uint16_t(mask);
                f[i] = uint32_t(next.size());
                for (uint32_t k = 0; k < boundary_count(mask); ++k) next.push_back(words_[nodes[i] + 1 + k]);
            }
            masks.push_back(std::move(m));
            first.push_back(std::move(f));
            nodes.swap(next);
        }
        for (uint32_t a : nodes) leaves.push_back(uint64_t(words_[a]) | uint64_t(words_[a + 1]) << 32);
    }
    return ShadowSvo::from_parts(root_state_, 0, depth_, std::move(masks), std::move(first), std::move(leaves));
}

Stats ShadowDag::stats() const {
    Stats s;
    s.set("nodes", double(node_count()));
    s.set("leaves", double(leaf_count()));
    s.set("pointers", double(pointer_count_));
    s.set("bytes", double(bytes()));
    s.set("total_ms", stats_.total_ms);
    s.set("closed_ms", stats_.closed_ms);
    s.set("depth_ms", stats_.depth_ms);
    s.set("svo_ms", stats_.svo_ms);
    s.set("merge_ms", stats_.merge_ms);
    s.set("layout_ms", stats_.layout_ms);
    s.set("rays", double(stats_.rays));
    s.set("svo_nodes", double(stats_.svo_nodes));
    s.set("tiles", double(stats_.tiles));
    s.set("tile_texels", double(stats_.tile_texels));
    s.set("peak_rss_bytes", double(stats_.peak_rss_bytes));
    for (size_t l = 0; l < level_counts_.size(); ++l) s.set("nodes_level_" + std::to_string(l), double(level_counts_[l]));
    return s;
}

}  // namespace gilab
