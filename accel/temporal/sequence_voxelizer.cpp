#include "accel/temporal/sequence_voxelizer.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>
#include "core/util/error.hpp"
#include "core/util/morton.hpp"

namespace gilab {
namespace {

constexpr const char* kWhat = "sequence voxelizer";
// The voxelizer counts a closed voxel box that merely touches a triangle as overlap, so a
// triangle whose box ends on a cell face must land in the cells on both sides: bins are
// padded by this much (in voxels).
constexpr double kBinPad = 1e-4;
// Nodes are flattened a few at a time, about this many triangles per call, so a large
// selection never exists as one whole SceneFrame (with its normals and materials).
constexpr size_t kChunkTriangles = size_t(1) << 14;

// A crowded cell goes through the voxelizer (about 600 B per triangle it prepares) this
// many triangles at a time.
constexpr size_t kMaxVoxelizerTriangles = 4096;

// Voxels [first, last] per axis whose closed boxes may touch triangle abc (voxel v
// touches [lo, hi] iff lo−1 ≤ v ≤ hi, padded); false when none lies inside the grid.
bool voxel_range(const VoxelGrid& grid, const Vec3& a, const Vec3& b, const Vec3& c, UVec3& first, UVec3& last) {
    const DVec3 va = grid.to_voxel_space(a), vb = grid.to_voxel_space(b), vc = grid.to_voxel_space(c);
    const DVec3 lo = glm::min(va, glm::min(vb, vc)), hi = glm::max(va, glm::max(vb, vc));
    const double last_voxel = double(grid.resolution) - 1.0;
    for (int k = 0; k < 3; ++k) {
        const double v0 = std::max(0.0, std::ceil(lo[k] - 1.0 - kBinPad));
        const double v1 = std::min(last_voxel, std::floor(hi[k] + kBinPad));
        if (!(v0 <= v1)) return false;
        first[k] = uint32_t(v0);
        last[k] = uint32_t(v1);
    }
    return true;
}

size_t node_triangles(const Scene& scene, size_t node) {
    size_t n = 0;
    for (uint32_t m : scene.nodes[node].meshes) n += m < scene.meshes.size() ? scene.meshes[m].triangles.size() : 0;
    return n;
}

// Calls take(SceneFrame&&) for consecutive groups of the selected nodes at `time`, at
// least once (an empty group still brings the lights).
template <class Take>
void flatten_in_chunks(const Scene& scene, double time, const std::vector<bool>& selected, Take&& take) {
    std::vector<bool> chunk(selected.size(), false);
    size_t triangles = 0;
    bool called = false, pending = false;
    for (size_t i = 0; i < selected.size(); ++i) {
        if (!selected[i]) continue;
        chunk[i] = true;
        pending = true;
        triangles += node_triangles(scene, i);
        if (triangles >= kChunkTriangles) {
            take(scene.evaluate(time, chunk));
            std::fill(chunk.begin(), chunk.end(), false);
            triangles = 0;
            called = true;
            pending = false;
        }
    }
    if (pending || !called) take(scene.evaluate(time, chunk));
}

}  // namespace

Bounds3 sequence_bounds(const Scene& scene, std::span<const double> times,
                        std::vector<std::vector<PunctualLight>>* lights) {
    const std::vector<bool> moving = scene.dynamic_nodes();
    std::vector<bool> still(moving.size());
    for (size_t i = 0; i < moving.size(); ++i) still[i] = !moving[i];
    Bounds3 bounds;
    flatten_in_chunks(scene, 0.0, still, [&](SceneFrame&& part) { bounds.extend(part.bounds); });
    for (double t : times) {
        bool first = true;
        flatten_in_chunks(scene, t, moving, [&](SceneFrame&& part) {
            bounds.extend(part.bounds);
            if (lights && first) lights->push_back(std::move(part.lights));
            first = false;
        });
    }
    return bounds;
}

// World-space triangles without normals or materials: all that voxelizing needs, and
// the alpha masks of the masked ones.
struct SequenceVoxelizer::TriangleSet {
    std::vector<Vec3> positions;
    std::vector<UVec3> triangles;
    std::vector<TriangleMask> masks;  // ascending triangle
    std::vector<int32_t> mask_of;     // per triangle: index into masks or −1; empty when none is masked

    // The selected nodes' world triangles at `time`.
    void gather(const Scene& scene, double time, const std::vector<bool>& selected) {
        size_t vertex_count = 0, triangle_count = 0;
        for (size_t i = 0; i < selected.size(); ++i)
            if (selected[i])
                for (uint32_t m : scene.nodes[i].meshes)
                    if (m < scene.meshes.size()) {
                        vertex_count += scene.meshes[m].positions.size();
                        triangle_count += scene.meshes[m].triangles.size();
                    }
        positions.reserve(vertex_count);
        triangles.reserve(triangle_count);
        flatten_in_chunks(scene, time, selected, [&](SceneFrame&& part) { take(std::move(part)); });
    }

    // Takes the frame's positions and triangles, releasing each mesh as it goes.
    void take(SceneFrame&& frame) {
        for (WorldMesh& mesh : frame.meshes) {
            if (positions.size() + mesh.positions.size() > std::numeric_limits<uint32_t>::max())
                throw Error(kWhat, "more than 2^32 vertices in one frame cannot be indexed");
            for (const Vec3& p : mesh.positions)
                if (!is_finite(p))
                    throw Error(kWhat, "node " + std::to_string(mesh.node) + " has a non-finite vertex position at time " +
                                           std::to_string(frame.time));
            const uint32_t base = uint32_t(positions.size());
            const size_t first_mask = masks.size();
            append_triangle_masks(mesh, frame.materials, uint32_t(triangles.size()), masks);
            for (const UVec3& t : mesh.triangles) {
                for (int k = 0; k < 3; ++k)
                    if (t[k] >= mesh.positions.size())
                        throw Error(kWhat, "mesh " + std::to_string(mesh.source_mesh) +
                                               " has a triangle referring to vertex " + std::to_string(t[k]) + " of " +
                                               std::to_string(mesh.positions.size()));
                triangles.push_back(t + UVec3(base));
            }
            if (!masks.empty()) {  // from the first masked mesh on, every triangle has an entry
                mask_of.resize(triangles.size(), -1);
                for (size_t k = first_mask; k < masks.size(); ++k) mask_of[masks[k].triangle] = int32_t(k);
            }
            positions.insert(positions.end(), mesh.positions.begin(), mesh.positions.end());
            mesh = WorldMesh();
        }
    }
    size_t bytes() const {
        return positions.capacity() * sizeof(Vec3) + triangles.capacity() * sizeof(UVec3) +
               masks.capacity() * sizeof(TriangleMask) + mask_of.capacity() * sizeof(int32_t);
    }
};

// Triangle ids per aligned cell, compact (CSR) over the cells that hold any.
struct SequenceVoxelizer::CellBins {
    std::vector<uint64_t> cells;  // Morton codes of cell coordinates, ascending
    std::vector<uint32_t> begin;  // cells.size() + 1 offsets into ids
    std::vector<uint32_t> ids;

    CellBins() = default;
    // A triangle goes into every cell its (padded) bounding box meets inside the grid:
    // a voxel the voxelizer accepts always lies inside that box.
    CellBins(const TriangleSet& set, const VoxelGrid& grid, int cell_log2) {
        struct Entry {
            uint64_t cell;
            uint32_t triangle;
            bool operator<(const Entry& o) const { return cell != o.cell ? cell < o.cell : triangle < o.triangle; }
        };
        // Cells [first, last] per axis that triangle i may touch; false if none is in the grid.
        auto cell_box = [&](size_t i, UVec3& first, UVec3& last) {
            const UVec3& t = set.triangles[i];
            if (!voxel_range(grid, set.positions[t.x], set.positions[t.y], set.positions[t.z], first, last))
                return false;
            first = UVec3(first.x >> cell_log2, first.y >> cell_log2, first.z >> cell_log2);
            last = UVec3(last.x >> cell_log2, last.y >> cell_log2, last.z >> cell_log2);
            return true;
        };
        // Two passes (count, then fill at exact offsets) so the entries are allocated once.
        const size_t n = set.triangles.size();
        std::vector<uint64_t> offset(n + 1, 0);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
            UVec3 first, last;
            for (size_t i = r.begin(); i < r.end(); ++i)
                if (cell_box(i, first, last))
                    offset[i + 1] = uint64_t(last.x - first.x + 1) * (last.y - first.y + 1) * (last.z - first.z + 1);
        });
        for (size_t i = 0; i < n; ++i) offset[i + 1] += offset[i];
        if (offset[n] > std::numeric_limits<uint32_t>::max())
            throw Error(kWhat, "more than 2^32 triangle/cell pairs in one frame cannot be indexed");
        std::vector<Entry> entries(offset[n]);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
            UVec3 first, last;
            for (size_t i = r.begin(); i < r.end(); ++i) {
                if (!cell_box(i, first, last)) continue;
                Entry* out = entries.data() + offset[i];
                for (uint32_t z = first.z; z <= last.z; ++z)
                    for (uint32_t y = first.y; y <= last.y; ++y)
                        for (uint32_t x = first.x; x <= last.x; ++x) *out++ = {morton_encode(x, y, z), uint32_t(i)};
            }
        });
        std::vector<uint64_t>().swap(offset);
        tbb::parallel_sort(entries.begin(), entries.end());
        ids.resize(entries.size());
        for (size_t i = 0; i < entries.size(); ++i) {
            if (i == 0 || entries[i].cell != entries[i - 1].cell) {
                cells.push_back(entries[i].cell);
                begin.push_back(uint32_t(i));
            }
            ids[i] = entries[i].triangle;
        }
        begin.push_back(uint32_t(ids.size()));
        cells.shrink_to_fit();
        begin.shrink_to_fit();
    }

    std::span<const uint32_t> of(uint64_t cell) const {
        auto it = std::lower_bound(cells.begin(), cells.end(), cell);
        if (it == cells.end() || *it != cell) return {};
        const size_t c = size_t(it - cells.begin());
        return std::span<const uint32_t>(ids).subspan(begin[c], begin[c + 1] - begin[c]);
    }
    size_t bytes() const {
        return cells.capacity() * sizeof(uint64_t) + (begin.capacity() + ids.capacity()) * sizeof(uint32_t);
    }
};

// What one frame's slice callback needs; it lives as long as the callback.
struct SequenceVoxelizer::FrameState {
    TriangleSet dynamic;
    CellBins dynamic_bins;
    std::vector<uint64_t> cells, dirty;
    // Voxelized together with an earlier request, not asked for yet (at most one batch).
    std::vector<std::pair<uint64_t, std::vector<uint64_t>>> batch;
};

SequenceVoxelizer::SequenceVoxelizer(const Scene& scene, const VoxelGrid& grid, int split_level,
                                     VoxelizeOptions options)
    : grid_(grid), split_level_(split_level), options_(options), scene_(scene) {
    grid_.validate(kWhat);
    if (split_level < 0 || split_level > grid_.depth())
        throw Error(kWhat, "split level " + std::to_string(split_level) + " is outside 0.." +
                               std::to_string(grid_.depth()) + " (the grid's octree depth)");
    cell_log2_ = grid_.depth() - split_level;
    dynamic_nodes_ = scene.dynamic_nodes();
    std::vector<bool> static_nodes(dynamic_nodes_.size());
    for (size_t i = 0; i < static_nodes.size(); ++i) static_nodes[i] = !dynamic_nodes_[i];
    static_triangles_ = std::make_unique<TriangleSet>();
    // Time does not matter to nodes without animation above them.
    static_triangles_->gather(scene, 0.0, static_nodes);
    static_bins_ = std::make_unique<CellBins>(*static_triangles_, grid_, cell_log2_);
}

SequenceVoxelizer::~SequenceVoxelizer() = default;

size_t SequenceVoxelizer::static_triangle_count() const { return static_triangles_->triangles.size(); }

size_t SequenceVoxelizer::static_bytes() const { return static_triangles_->bytes() + static_bins_->bytes(); }

FrameCells SequenceVoxelizer::frame_cells(double time) {
    auto state = std::make_shared<FrameState>();
    if (std::find(dynamic_nodes_.begin(), dynamic_nodes_.end(), true) != dynamic_nodes_.end())
        state->dynamic.gather(scene_, time, dynamic_nodes_);
    state->dynamic_bins = CellBins(state->dynamic, grid_, cell_log2_);
    const std::vector<uint64_t>& moving = state->dynamic_bins.cells;

    const std::vector<uint64_t>& fixed = static_bins_->cells;
    std::set_union(fixed.begin(), fixed.end(), moving.begin(), moving.end(), std::back_inserter(state->cells));
    if (first_frame_) {
        state->dirty = state->cells;
    } else {
        // Only cells a moving triangle touches now or touched before can differ.
        std::vector<uint64_t> touched;
        std::set_union(moving.begin(), moving.end(), previous_dynamic_cells_.begin(), previous_dynamic_cells_.end(),
                       std::back_inserter(touched));
        std::set_intersection(touched.begin(), touched.end(), state->cells.begin(), state->cells.end(),
                              std::back_inserter(state->dirty));
    }
    previous_dynamic_cells_ = moving;
    first_frame_ = false;

    FrameCells frame;
    frame.split_level = split_level_;
    frame.cells = state->cells;
    frame.dirty = state->dirty;
    frame.slice = [this, state](uint64_t cell) { return slice(cell, *state); };
    return frame;
}

std::vector<uint64_t> SequenceVoxelizer::voxelize_cell(uint64_t cell, const FrameState& frame) const {
    // The cell's own triangles, three corners each, so the voxelizer's input checks and
    // preparation cost only this cell.
    std::vector<Vec3> corners;
    std::vector<TriangleMask> masks;  // of the cell's triangles, by their index here (ascending)
    const auto fixed = static_bins_->of(cell);
    const auto moving = frame.dynamic_bins.of(cell);
    corners.reserve(3 * (fixed.size() + moving.size()));
    auto add = [&](const TriangleSet& set, std::span<const uint32_t> ids) {
        for (uint32_t id : ids) {
            const UVec3& t = set.triangles[id];
            if (!set.mask_of.empty() && set.mask_of[id] >= 0) {
                masks.push_back(set.masks[size_t(set.mask_of[id])]);
                masks.back().triangle = uint32_t(corners.size() / 3);
            }
            corners.insert(corners.end(), {set.positions[t.x], set.positions[t.y], set.positions[t.z]});
        }
    };
    add(*static_triangles_, fixed);
    add(frame.dynamic, moving);

    const size_t count = corners.size() / 3;
    const UVec3 first = morton_decode(cell) * (1u << cell_log2_);
    const VoxelRegion region{first, first + UVec3(1u << cell_log2_)};
    std::vector<UVec3> triangles(std::min(count, kMaxVoxelizerTriangles));
    for (uint32_t i = 0; i < triangles.size(); ++i) triangles[i] = UVec3(3 * i, 3 * i + 1, 3 * i + 2);
    // A voxel's overlap test looks at one triangle at a time, so the union of the chunks'
    // voxels is the cell's.
    std::vector<uint64_t> codes, merged;
    for (size_t begin = 0; begin < count; begin += kMaxVoxelizerTriangles) {
        const size_t n = std::min(kMaxVoxelizerTriangles, count - begin);
        const std::span<const Vec3> chunk(corners.data() + 3 * begin, 3 * n);
        // This chunk's masks, renumbered from its first triangle.
        auto by_triangle = [](const TriangleMask& m, size_t t) { return m.triangle < t; };
        const auto m0 = std::lower_bound(masks.begin(), masks.end(), begin, by_triangle);
        const auto m1 = std::lower_bound(m0, masks.end(), begin + n, by_triangle);
        std::vector<TriangleMask> chunk_masks(m0, m1);
        for (TriangleMask& m : chunk_masks) m.triangle -= uint32_t(begin);
        std::vector<uint64_t> part =
            Voxelizer(chunk, std::span<const UVec3>(triangles.data(), n), grid_, options_, chunk_masks).voxelize(region).codes;
        if (codes.empty()) {
            codes = std::move(part);
            continue;
        }
        merged.clear();
        std::set_union(codes.begin(), codes.end(), part.begin(), part.end(), std::back_inserter(merged));
        codes.swap(merged);
    }
    return codes;
}

std::vector<uint64_t> SequenceVoxelizer::slice(uint64_t cell, FrameState& frame) const {
    for (auto it = frame.batch.begin(); it != frame.batch.end(); ++it)
        if (it->first == cell) {
            std::vector<uint64_t> codes = std::move(it->second);
            frame.batch.erase(it);
            return codes;
        }
    frame.batch.clear();
    // This cell and the ones likely asked for next (the following dirty cells when it is
    // dirty, else the following cells), voxelized in parallel.
    const auto& order = std::binary_search(frame.dirty.begin(), frame.dirty.end(), cell) ? frame.dirty : frame.cells;
    std::vector<uint64_t> batch_cells{cell};
    for (auto it = std::upper_bound(order.begin(), order.end(), cell);
         it != order.end() && batch_cells.size() < kBatchCells; ++it)
        batch_cells.push_back(*it);
    std::vector<std::vector<uint64_t>> results(batch_cells.size());
    // Isolated, so a thread waiting inside one cell's voxelizer never starts another
    // cell: at most one voxelizer per thread is alive.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, batch_cells.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i)
            tbb::this_task_arena::isolate([&] { results[i] = voxelize_cell(batch_cells[i], frame); });
    });
    for (size_t i = 1; i < batch_cells.size(); ++i) frame.batch.emplace_back(batch_cells[i], std::move(results[i]));
    return std::move(results[0]);
}

}  // namespace gilab
