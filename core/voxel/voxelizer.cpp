#include "core/voxel/voxelizer.hpp"
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <mutex>
#include <string>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>
#include "core/util/error.hpp"
#include "core/util/morton.hpp"
#include "core/scene/scene.hpp"
#include "core/util/stats.hpp"
#include "core/voxel/box_clip.hpp"

namespace gilab {
namespace {

constexpr int kMaxBrickLog2 = 6;              // bricks of at most 64³ voxels (32 KiB bitmaps)
constexpr size_t kBigBrickTriangles = 16384;  // above this a brick's triangles run in parallel
constexpr size_t kBatchBricks = 256;          // bricks voxelized concurrently, then appended in order
constexpr double kCoarsePad = 1e-6;  // voxels

// A triangle in voxel units, prepared for many box tests: its bounding box plus the
// ten non-trivial separating axes of Akenine-Möller's test (normal, 9 edge × axis
// crosses) with the triangle's projected interval on each.
struct PreparedTriangle {
    DVec3 lo, hi;
    int axis_count = 0;
    DVec3 axis[10];
    double amin[10], amax[10], radius[10];  // radius: half the projection of a unit box
    // Plane as a height field over the dominant normal axis: w = c0 + cu·u + cv·v.
    bool planar = false;
    int w = 2, u = 0, v = 1;
    double c0 = 0, cu = 0, cv = 0;
    // The first column_axes axes have no w component (the edges crossed with w): along a
    // column of boxes in w they give one answer, tested once per column.
    int column_axes = 0;
};

PreparedTriangle prepare(const DVec3& a, const DVec3& b, const DVec3& c) {
    PreparedTriangle t;
    t.lo = glm::min(a, glm::min(b, c));
    t.hi = glm::max(a, glm::max(b, c));
    DVec3 e[3] = {b - a, c - b, a - c};
    DVec3 n = glm::cross(e[0], -e[2]);
    auto add_axis = [&](const DVec3& ax) {
        if (ax.x == 0 && ax.y == 0 && ax.z == 0) return;  // never separates
        int i = t.axis_count++;
        t.axis[i] = ax;
        double pa = glm::dot(ax, a), pb = glm::dot(ax, b), pc = glm::dot(ax, c);
        t.amin[i] = std::min(pa, std::min(pb, pc));
        t.amax[i] = std::max(pa, std::max(pb, pc));
        t.radius[i] = 0.5 * (std::abs(ax.x) + std::abs(ax.y) + std::abs(ax.z));
    };
    add_axis(n);
    for (const DVec3& edge : e) {
        add_axis({0, -edge.z, edge.y});  // edge × x
        add_axis({edge.z, 0, -edge.x});  // edge × y
        add_axis({-edge.y, edge.x, 0});  // edge × z
    }
    DVec3 an = glm::abs(n);
    t.w = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
    t.u = (t.w + 1) % 3;
    t.v = (t.w + 2) % 3;
    double longest = std::max(glm::dot(e[0], e[0]), std::max(glm::dot(e[1], e[1]), glm::dot(e[2], e[2])));
    // A well-shaped plane gives each column a tight height range; slivers whose normal
    // is lost in rounding fall back to their whole bounding box.
    t.planar = an[t.w] > 1e-7 * longest && longest > 0;
    if (t.planar) {
        t.cu = -n[t.u] / n[t.w];
        t.cv = -n[t.v] / n[t.w];
        t.c0 = a[t.w] - t.cu * a[t.u] - t.cv * a[t.v];
        // Any axis separates the box or not whatever its place in the list.
        for (int i = 0; i < t.axis_count; ++i)
            if (t.axis[i][t.w] == 0.0) {
                std::swap(t.axis[i], t.axis[t.column_axes]);
                std::swap(t.amin[i], t.amin[t.column_axes]);
                std::swap(t.amax[i], t.amax[t.column_axes]);
                std::swap(t.radius[i], t.radius[t.column_axes]);
                ++t.column_axes;
            }
    }
    return t;
}

// Closed box [bmin, bmin + size] against the triangle; touching counts as overlap.
inline bool overlaps(const PreparedTriangle& t, const DVec3& bmin, double size) {
    const DVec3 bmax = bmin + DVec3(size);
    if (t.lo.x > bmax.x || t.lo.y > bmax.y || t.lo.z > bmax.z || t.hi.x < bmin.x ||
        t.hi.y < bmin.y || t.hi.z < bmin.z)
        return false;
    DVec3 center = bmin + DVec3(0.5 * size);
    for (int i = 0; i < t.axis_count; ++i) {
        double s = glm::dot(t.axis[i], center);
        double r = t.radius[i] * size;
        if (t.amin[i] > s + r || t.amax[i] < s - r) return false;
    }
    return true;
}

struct CellBox {  // half-open cell index ranges
    int64_t lo[3];
    int64_t hi[3];
};

inline int64_t clamp_to_index(double x, int64_t lo, int64_t hi) {
    return static_cast<int64_t>(std::clamp(x, double(lo), double(hi)));
}

// `overlaps` split for a column of boxes along the plane's dominant axis W (t.w), with
// the same arithmetic, so with the same answers: the part that is the same for the whole
// column (the bounding box along u and v, the axes without a w component, whose w term is
// 0 for any centre) ... W is a template parameter: components picked at compile time stay
// in registers.
template <int W>
inline bool column_overlaps(const PreparedTriangle& t, const DVec3& bmin, double size) {
    constexpr int U = (W + 1) % 3, V = (W + 2) % 3;
    if (t.lo[U] > bmin[U] + size || t.lo[V] > bmin[V] + size || t.hi[U] < bmin[U] || t.hi[V] < bmin[V])
        return false;
    const DVec3 center = bmin + DVec3(0.5 * size);
    for (int i = 0; i < t.column_axes; ++i) {
        double s = glm::dot(t.axis[i], center);
        double r = t.radius[i] * size;
        if (t.amin[i] > s + r || t.amax[i] < s - r) return false;
    }
    return true;
}

// ... and the rest, for one box of the column: `center` is the box's centre.
template <int W>
inline bool overlaps_in_column(const PreparedTriangle& t, double bmin_w, const DVec3& center, double size) {
    if (t.lo[W] > bmin_w + size || t.hi[W] < bmin_w) return false;
    for (int i = t.column_axes; i < t.axis_count; ++i) {
        double s = glm::dot(t.axis[i], center);
        double r = t.radius[i] * size;
        if (t.amin[i] > s + r || t.amax[i] < s - r) return false;
    }
    return true;
}

// Narrows [a_begin, a_end], the columns of one row (centre v = center_v) along U, to
// those the column axes may accept. Each axis's test is linear in the column index a;
// the bounds are widened by two columns, far more than rounding can move them, so every
// column left out fails `column_overlaps` too and the output is unchanged: the rows of
// a large triangle's bounding box no longer visit the columns beside the triangle.
template <int W>
inline void row_span(const PreparedTriangle& t, double center_v, double s, double box, int64_t& a_begin,
                     int64_t& a_end) {
    constexpr int U = (W + 1) % 3, V = (W + 2) % 3;
    constexpr double kSlack = 2.0;  // columns
    double lo = double(a_begin), hi = double(a_end);
    for (int i = 0; i < t.column_axes; ++i) {
        const DVec3& axis = t.axis[i];
        const double slope = axis[U] * s;  // change of the centre's projection per column
        if (!(std::abs(slope) >= 1e-6 * (std::abs(axis[U]) + std::abs(axis[V])) * s)) continue;
        // Column a's centre projects to base + slope·a (centre u = (a + ½)·s); the axis
        // accepts it while that lies in [amin − r, amax + r].
        const double base = axis[U] * 0.5 * s + axis[V] * center_v;
        const double r = t.radius[i] * box;
        double from = (t.amin[i] - r - base) / slope, to = (t.amax[i] + r - base) / slope;
        if (slope < 0) std::swap(from, to);
        lo = std::max(lo, std::floor(from - kSlack));
        hi = std::min(hi, std::ceil(to + kSlack));
    }
    if (lo > hi) {
        a_end = a_begin - 1;
        return;
    }
    a_begin = int64_t(lo);
    a_end = int64_t(hi);
}

// The planar case of `rasterize`: candidates per column of the projection along W come
// from the plane's height range over the column.
template <int W, class Emit>
void rasterize_columns(const PreparedTriangle& t, const int64_t (&lo)[3], const int64_t (&hi)[3], double s, double pad,
                       uint64_t& tests, Emit&& emit) {
    constexpr int U = (W + 1) % 3, V = (W + 2) % 3;
    constexpr double kEps = 1e-6;
    const double inv = 1.0 / s;
    const double box = s + 2 * pad;
    int64_t cell[3];
    const double w_floor = double(lo[W] - 1), w_ceiling = double(hi[W] + 1);  // lo[W] ≥ 0
    const int64_t w_top = hi[W] + 3;
    for (int64_t b = lo[V]; b <= hi[V]; ++b) {
        double v0 = double(b) * s - pad, v1 = double(b + 1) * s + pad;
        double hv_min = t.cv >= 0 ? t.cv * v0 : t.cv * v1;
        double hv_max = t.cv >= 0 ? t.cv * v1 : t.cv * v0;
        int64_t a_begin = lo[U], a_end = hi[U];
        row_span<W>(t, (double(b) + 0.5) * s, s, box, a_begin, a_end);
        for (int64_t a = a_begin; a <= a_end; ++a) {
            double u0 = double(a) * s - pad, u1 = double(a + 1) * s + pad;
            double zmin = t.c0 + hv_min + (t.cu >= 0 ? t.cu * u0 : t.cu * u1);
            double zmax = t.c0 + hv_max + (t.cu >= 0 ? t.cu * u1 : t.cu * u0);
            zmin = std::max(zmin, t.lo[W]) - pad;
            zmax = std::min(zmax, t.hi[W]) + pad;
            // Ceiling and floor by truncating values shifted to be positive: the shift
            // rounds by far less than kEps, so it can only move a bound across a box that
            // the plane misses by kEps, which the exact test rejects anyway.
            const double x0 = std::clamp(zmin * inv - 1.0 - kEps, w_floor, w_ceiling);
            const double x1 = std::clamp(zmax * inv + kEps, w_floor, w_ceiling);
            int64_t k0 = std::max(lo[W], w_top - int64_t(double(w_top) - x0));
            int64_t k1 = std::min(hi[W], int64_t(x1 + 2.0) - 2);
            if (k0 > k1) continue;
            // Every candidate counts as a box test, as when each was tested whole.
            tests += uint64_t(k1 - k0 + 1);
            DVec3 bmin(0.0);
            bmin[U] = double(a) * s - pad;
            bmin[V] = double(b) * s - pad;
            if (!column_overlaps<W>(t, bmin, box)) continue;
            DVec3 center = bmin + DVec3(0.5 * box);
            cell[U] = a;
            cell[V] = b;
            for (int64_t k = k0; k <= k1; ++k) {
                const double bmin_w = double(k) * s - pad;
                center[W] = bmin_w + 0.5 * box;
                if (overlaps_in_column<W>(t, bmin_w, center, box)) {
                    cell[W] = k;
                    emit(cell[0], cell[1], cell[2]);
                }
            }
        }
    }
}

// Calls emit(x, y, z) for every cell of 2^log2 voxels inside `clip` that the triangle
// overlaps, each cell grown by `pad` on every side (coarse cells are padded so they
// never miss a voxel that the exact per-voxel test accepts). Candidates per column of
// the dominant-axis projection come from the plane's height range over the column;
// each candidate is then tested exactly.
template <class Emit>
void rasterize(const PreparedTriangle& t, int log2, double pad, const CellBox& clip, uint64_t& tests, Emit&& emit) {
    const double s = std::ldexp(1.0, log2);
    const double inv = 1.0 / s;
    int64_t lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
        // Cell k (span [k·s, (k+1)·s]) touches [lo, hi] iff lo/s − 1 ≤ k ≤ hi/s.
        lo[i] = std::max(clip.lo[i], clamp_to_index(std::ceil((t.lo[i] - pad) * inv - 1.0), clip.lo[i] - 1, clip.hi[i] + 1));
        hi[i] = std::min(clip.hi[i] - 1, clamp_to_index(std::floor((t.hi[i] + pad) * inv), clip.lo[i] - 1, clip.hi[i] + 1));
        if (lo[i] > hi[i]) return;
    }
    const double box = s + 2 * pad;
    auto test = [&](int64_t x, int64_t y, int64_t z) {
        ++tests;
        if (overlaps(t, DVec3(double(x), double(y), double(z)) * s - DVec3(pad), box)) emit(x, y, z);
    };
    if (!t.planar) {
        for (int64_t z = lo[2]; z <= hi[2]; ++z)
            for (int64_t y = lo[1]; y <= hi[1]; ++y)
                for (int64_t x = lo[0]; x <= hi[0]; ++x) test(x, y, z);
        return;
    }
    switch (t.w) {
        case 0: rasterize_columns<0>(t, lo, hi, s, pad, tests, emit); break;
        case 1: rasterize_columns<1>(t, lo, hi, s, pad, tests, emit); break;
        default: rasterize_columns<2>(t, lo, hi, s, pad, tests, emit); break;
    }
}

// Brick bitmaps are recycled through a small pool (not thread-local storage: nested
// parallel loops may run another brick on the same thread).
class BitmapPool {
public:
    explicit BitmapPool(size_t words) : words_(words) {}
    std::vector<uint64_t> take() {
        std::lock_guard lock(mutex_);
        if (free_.empty()) return std::vector<uint64_t>(words_, 0);
        auto v = std::move(free_.back());
        free_.pop_back();
        return v;
    }
    void give(std::vector<uint64_t> v) {
        std::lock_guard lock(mutex_);
        free_.push_back(std::move(v));
    }

private:
    size_t words_;
    std::mutex mutex_;
    std::vector<std::vector<uint64_t>> free_;
};

std::string gib(double bytes) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.2f GiB", bytes / double(1ull << 30));
    return buf;
}

// An alpha-masked triangle in voxel units, with what its mask lookups need.
struct MaskedTriangle {
    DVec3 p[3];
    DVec3 normal{0};
    Vec2 uv[3];
    float uv_per_voxel = 0;  // UV units per voxel length
    TextureRef mask;         // null: the alpha factor alone decides
    float alpha = 1, cutoff = 0.5f;
};

bool mask_reaches(const MaskedTriangle& m, int64_t x, int64_t y, int64_t z) {
    const DVec3 lo{double(x), double(y), double(z)};
    const BoxPiece piece = clip_triangle_to_box(m.p, m.normal, lo, lo + DVec3(1.0));
    if (!(piece.area > 0)) return false;
    if (!m.mask) return m.alpha >= m.cutoff;
    const DVec3 e1 = m.p[1] - m.p[0], e2 = m.p[2] - m.p[0], d = piece.centroid - m.p[0];
    const double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2), den = d11 * d22 - d12 * d12;
    if (!(den > 0)) return m.alpha >= m.cutoff;
    const float b1 = float((d22 * glm::dot(d, e1) - d12 * glm::dot(d, e2)) / den);
    const float b2 = float((d11 * glm::dot(d, e2) - d12 * glm::dot(d, e1)) / den);
    const Vec2 uv = (1.0f - b1 - b2) * m.uv[0] + b1 * m.uv[1] + b2 * m.uv[2];
    const float footprint = float(std::sqrt(piece.area)) * m.uv_per_voxel;
    const float a = m.alpha * m.mask.sample(uv, footprint).w;
    const float lod = footprint > 0 ? m.mask.image->level_for_footprint(footprint * m.mask.transform.max_stretch()) : 0.0f;
    return lod <= 0.0f ? a >= m.cutoff : a > 0.0f;
}

}  // namespace

UVec3 VoxelList::voxel(size_t i) const { return morton_decode(codes[i]); }

uint64_t VoxelBlocks::voxel_count() const {
    uint64_t n = 0;
    for (uint64_t m : masks) n += uint64_t(std::popcount(m));
    return n;
}

std::vector<uint64_t> VoxelBlocks::codes() const {
    std::vector<uint64_t> codes;
    codes.reserve(voxel_count());
    for (size_t i = 0; i < blocks.size(); ++i)
        for (uint64_t m = masks[i]; m; m &= m - 1) codes.push_back(blocks[i] << 6 | uint64_t(std::countr_zero(m)));
    return codes;
}

void blocks_from_codes(std::span<const uint64_t> codes, std::vector<uint64_t>& blocks, std::vector<uint64_t>& masks) {
    blocks.clear();
    masks.clear();
    for (uint64_t code : codes) {
        if (blocks.empty() || blocks.back() != code >> 6) {
            blocks.push_back(code >> 6);
            masks.push_back(0);
        }
        masks.back() |= uint64_t(1) << (code & 63);
    }
}

void append_triangle_masks(const WorldMesh& mesh, const std::vector<Material>& materials, uint32_t first_triangle,
                           std::vector<TriangleMask>& out) {
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const uint32_t id = t < mesh.material_ids.size() ? mesh.material_ids[t] : 0;
        if (id >= materials.size() || !materials[id].alpha_tested()) continue;
        const Material& mat = materials[id];
        TriangleMask m;
        m.triangle = first_triangle + uint32_t(t);
        m.alpha = mat.alpha;
        m.cutoff = mat.alpha_cutoff;
        const std::vector<Vec2>& uvs = mesh.uv_set(std::clamp(mat.alpha_texture.uv_set, 0, kUvSetCount - 1));
        if (mat.alpha_texture && uvs.size() == mesh.positions.size()) {
            m.texture = mat.alpha_texture;
            for (int k = 0; k < 3; ++k) m.uv[k] = uvs[mesh.triangles[t][k]];
        }
        out.push_back(std::move(m));
    }
}

struct Voxelizer::Impl {
    VoxelGrid grid;
    VoxelizeOptions options;
    std::vector<PreparedTriangle> triangles;  // in voxel units
    std::vector<double> estimate;             // per triangle, voxels
    std::vector<int32_t> masked;              // per triangle: index into masks, or −1 (empty: none masked)
    std::vector<MaskedTriangle> masks;

    void add_masks(std::span<const Vec3> positions, std::span<const UVec3> tris, std::span<const TriangleMask> input);

    void init(std::span<const Vec3> positions, std::span<const UVec3> tris);
    // `subset`: indices of the triangles to voxelize (all when absent).
    VoxelBlocks run(VoxelRegion region, const std::span<const uint32_t>* subset = nullptr) const;
    VoxelList run_codes(const VoxelRegion& region, const std::span<const uint32_t>* subset = nullptr) const;
    uint64_t estimate_in(const VoxelRegion& region, const std::span<const uint32_t>* subset = nullptr) const;
};

void Voxelizer::Impl::init(std::span<const Vec3> positions, std::span<const UVec3> tris) {
    grid.validate("voxelizer");
    if (tris.empty()) throw Error("voxelizer", "nothing to voxelize: the input has no triangles");
    for (size_t i = 0; i < positions.size(); ++i)
        if (!is_finite(positions[i]))
            throw Error("voxelizer", "vertex " + std::to_string(i) + " has a non-finite position");
    for (size_t i = 0; i < tris.size(); ++i)
        for (int k = 0; k < 3; ++k)
            if (tris[i][k] >= positions.size())
                throw Error("voxelizer", "triangle " + std::to_string(i) + " refers to vertex " +
                                             std::to_string(tris[i][k]) + " but there are only " +
                                             std::to_string(positions.size()) + " vertices");
    triangles.resize(tris.size());
    estimate.resize(tris.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tris.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
            DVec3 a = grid.to_voxel_space(positions[tris[i].x]);
            DVec3 b = grid.to_voxel_space(positions[tris[i].y]);
            DVec3 c = grid.to_voxel_space(positions[tris[i].z]);
            triangles[i] = prepare(a, b, c);
            // Voxels a plane crosses per unit area = L1 norm of its unit normal, so the
            // projected areas on the three axes count the interior; edges add a border.
            DVec3 n = glm::abs(glm::cross(b - a, c - a));
            auto l1 = [](const DVec3& d) { return std::abs(d.x) + std::abs(d.y) + std::abs(d.z); };
            estimate[i] = 0.5 * (n.x + n.y + n.z) + l1(b - a) + l1(c - b) + l1(a - c) + 8.0;
        }
    });
}

uint64_t Voxelizer::Impl::estimate_in(const VoxelRegion& region, const std::span<const uint32_t>* subset) const {
    if (region.empty()) return 0;
    double total = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, subset ? subset->size() : triangles.size(), 4096), 0.0,
        [&](const tbb::blocked_range<size_t>& r, double sum) {
            for (size_t j = r.begin(); j < r.end(); ++j) {
                const size_t i = subset ? (*subset)[j] : j;
                const PreparedTriangle& t = triangles[i];
                double cells = 1;
                for (int k = 0; k < 3; ++k) {
                    double lo = std::max(std::ceil(t.lo[k] - 1.0), double(region.begin[k]));
                    double hi = std::min(std::floor(t.hi[k]), double(region.end[k]) - 1.0);
                    cells *= std::max(0.0, hi - lo + 1.0);
                }
                sum += std::min(cells, estimate[i]);
            }
            return sum;
        },
        std::plus<double>());
    return static_cast<uint64_t>(std::min(total, double(region.volume())));
}

VoxelList Voxelizer::Impl::run_codes(const VoxelRegion& region, const std::span<const uint32_t>* subset) const {
    Stopwatch clock;
    VoxelBlocks blocks = run(region, subset);
    VoxelList out;
    out.grid = blocks.grid;
    out.codes = blocks.codes();
    out.stats = blocks.stats;
    out.stats.ms = clock.elapsed_ms();
    return out;
}

VoxelBlocks Voxelizer::Impl::run(VoxelRegion region, const std::span<const uint32_t>* subset) const {
    Stopwatch clock;
    VoxelBlocks out;
    out.grid = grid;
    region = region.intersect(grid.full_region());
    if (region.empty()) return out;

    const uint64_t estimated = estimate_in(region, subset);
    out.stats.estimated_voxels = estimated;
    if (double(estimated) * 8.0 > double(options.max_bytes))
        throw Error("voxelizer", "resolution " + std::to_string(grid.resolution) + " would give about " +
                                     std::to_string(estimated) + " voxels (" + gib(double(estimated) * 8.0) +
                                     "), more than the memory budget of " + gib(double(options.max_bytes)) +
                                     "; use a lower resolution or a split build over sub-regions");

    const int brick_log2 = std::min(grid.depth(), kMaxBrickLog2);
    const int64_t brick = int64_t(1) << brick_log2;
    CellBox brick_clip, voxel_clip;
    for (int k = 0; k < 3; ++k) {
        voxel_clip.lo[k] = region.begin[k];
        voxel_clip.hi[k] = region.end[k];
        brick_clip.lo[k] = region.begin[k] >> brick_log2;
        brick_clip.hi[k] = ((region.end[k] - 1) >> brick_log2) + 1;
    }

    // 1. (brick, triangle) pairs, sorted by brick Morton code then triangle.
    struct Pair {
        uint64_t brick;
        uint32_t triangle;
        bool operator<(const Pair& o) const { return brick != o.brick ? brick < o.brick : triangle < o.triangle; }
    };
    tbb::enumerable_thread_specific<std::vector<Pair>> local_pairs;
    std::atomic<uint64_t> tests_total{0}, triangles_used{0};
    const size_t input_count = subset ? subset->size() : triangles.size();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, input_count, 256), [&](const tbb::blocked_range<size_t>& r) {
        auto& pairs = local_pairs.local();
        uint64_t tests = 0, used = 0;
        for (size_t j = r.begin(); j < r.end(); ++j) {
            const size_t i = subset ? (*subset)[j] : j;
            size_t before = pairs.size();
            rasterize(triangles[i], brick_log2, kCoarsePad, brick_clip, tests, [&](int64_t x, int64_t y, int64_t z) {
                pairs.push_back({morton_encode(uint32_t(x), uint32_t(y), uint32_t(z)), uint32_t(i)});
            });
            used += pairs.size() != before;
        }
        tests_total += tests;
        triangles_used += used;
    });
    std::vector<Pair> pairs;
    for (auto& p : local_pairs) pairs.insert(pairs.end(), p.begin(), p.end());
    local_pairs.clear();
    tbb::parallel_sort(pairs.begin(), pairs.end());
    std::vector<size_t> group_begin;  // pairs of one brick are contiguous
    for (size_t i = 0; i < pairs.size(); ++i)
        if (i == 0 || pairs[i].brick != pairs[i - 1].brick) group_begin.push_back(i);
    group_begin.push_back(pairs.size());
    const size_t groups = group_begin.size() - 1;
    out.stats.triangles = triangles_used;
    out.stats.bricks = groups;

    // 2. Each brick: mark overlapped voxels in a bitmap indexed by local Morton code,
    // then read its words in order — each a 4³ block: sorted, unique output without a
    // global sort.
    const size_t bitmap_words = std::max<size_t>(1, (size_t(1) << (3 * brick_log2)) / 64);
    BitmapPool pool(bitmap_words);
    auto fill_brick = [&](size_t g, std::vector<uint64_t>& bitmap, bool parallel) {
        const uint64_t key = pairs[group_begin[g]].brick;
        const UVec3 bc = morton_decode(key);
        CellBox clip;
        for (int k = 0; k < 3; ++k) {
            clip.lo[k] = std::max<int64_t>(voxel_clip.lo[k], int64_t(bc[k]) * brick);
            clip.hi[k] = std::min<int64_t>(voxel_clip.hi[k], int64_t(bc[k] + 1) * brick);
        }
        const uint32_t bx = bc.x * uint32_t(brick), by = bc.y * uint32_t(brick), bz = bc.z * uint32_t(brick);
        auto run_range = [&](size_t p0, size_t p1, auto set_bit) {
            uint64_t tests = 0;
            for (size_t p = p0; p < p1; ++p)
                rasterize(triangles[pairs[p].triangle], 0, 0.0, clip, tests, [&](int64_t x, int64_t y, int64_t z) {
                    const int32_t mask = masked.empty() ? -1 : masked[pairs[p].triangle];
                    if (mask >= 0 && !mask_reaches(masks[size_t(mask)], x, y, z)) return;
                    uint64_t local = morton_encode(uint32_t(x) - bx, uint32_t(y) - by, uint32_t(z) - bz);
                    set_bit(local >> 6, uint64_t(1) << (local & 63));
                });
            tests_total += tests;
        };
        if (parallel) {
            tbb::parallel_for(tbb::blocked_range<size_t>(group_begin[g], group_begin[g + 1], 64),
                              [&](const tbb::blocked_range<size_t>& r) {
                                  run_range(r.begin(), r.end(), [&](uint64_t word, uint64_t bit) {
                                      std::atomic_ref<uint64_t>(bitmap[word]).fetch_or(bit, std::memory_order_relaxed);
                                  });
                              });
        } else {
            run_range(group_begin[g], group_begin[g + 1], [&](uint64_t word, uint64_t bit) { bitmap[word] |= bit; });
        }
    };
    struct Blocks {
        std::vector<uint64_t> blocks, masks;
    };
    auto drain = [&](size_t g, std::vector<uint64_t>& bitmap, Blocks& to) {
        // A brick smaller than 4³ is a whole grid of at most 2³ voxels, whose one brick
        // starts at code 0: its word is block 0 too.
        const uint64_t first_block = (pairs[group_begin[g]].brick << (3 * brick_log2)) >> 6;
        for (size_t i = 0; i < bitmap.size(); ++i) {
            if (!bitmap[i]) continue;
            to.blocks.push_back(first_block | uint64_t(i));
            to.masks.push_back(bitmap[i]);
            bitmap[i] = 0;  // leave the bitmap clean for reuse
        }
    };
    auto append = [&](Blocks& from) {
        out.blocks.insert(out.blocks.end(), from.blocks.begin(), from.blocks.end());
        out.masks.insert(out.masks.end(), from.masks.begin(), from.masks.end());
    };

    size_t g = 0;
    while (g < groups) {
        size_t size = group_begin[g + 1] - group_begin[g];
        if (size >= kBigBrickTriangles) {
            auto bitmap = pool.take();
            fill_brick(g, bitmap, true);
            Blocks blocks;
            drain(g, bitmap, blocks);
            append(blocks);
            pool.give(std::move(bitmap));
            ++g;
            continue;
        }
        size_t end = g;
        while (end < groups && end - g < kBatchBricks && group_begin[end + 1] - group_begin[end] < kBigBrickTriangles) ++end;
        std::vector<Blocks> results(end - g);
        tbb::parallel_for(tbb::blocked_range<size_t>(g, end, 1), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                auto bitmap = pool.take();
                fill_brick(i, bitmap, false);
                drain(i, bitmap, results[i - g]);
                pool.give(std::move(bitmap));
            }
        });
        for (Blocks& blocks : results) append(blocks);
        g = end;
    }
    out.stats.box_tests = tests_total;
    out.stats.ms = clock.elapsed_ms();
    return out;
}

Voxelizer::Voxelizer(std::span<const Vec3> positions, std::span<const UVec3> triangles, const VoxelGrid& grid,
                     VoxelizeOptions options, std::span<const TriangleMask> masks)
    : impl_(std::make_unique<Impl>()) {
    impl_->grid = grid;
    impl_->options = options;
    impl_->init(positions, triangles);
    impl_->add_masks(positions, triangles, masks);
}

Voxelizer::Voxelizer(const SceneFrame& frame, const VoxelGrid& grid, VoxelizeOptions options)
    : impl_(std::make_unique<Impl>()) {
    impl_->grid = grid;
    impl_->options = options;
    std::vector<Vec3> positions;
    std::vector<UVec3> triangles;
    for (size_t m = 0; m < frame.meshes.size(); ++m) {
        const WorldMesh& mesh = frame.meshes[m];
        uint32_t base = static_cast<uint32_t>(positions.size());
        for (const UVec3& t : mesh.triangles) {
            for (int k = 0; k < 3; ++k)
                if (t[k] >= mesh.positions.size())
                    throw Error("voxelizer", "mesh " + std::to_string(m) + " has a triangle referring to vertex " +
                                                 std::to_string(t[k]) + " of " +
                                                 std::to_string(mesh.positions.size()));
            triangles.push_back(t + UVec3(base));
        }
        positions.insert(positions.end(), mesh.positions.begin(), mesh.positions.end());
    }
    impl_->init(positions, triangles);
    std::vector<TriangleMask> masks;
    uint32_t first = 0;
    for (const WorldMesh& mesh : frame.meshes) {
        append_triangle_masks(mesh, frame.materials, first, masks);
        first += uint32_t(mesh.triangles.size());
    }
    impl_->add_masks(positions, triangles, masks);
}

void Voxelizer::Impl::add_masks(std::span<const Vec3> positions, std::span<const UVec3> tris,
                                std::span<const TriangleMask> input) {
    for (const TriangleMask& in : input) {
        if (in.triangle >= tris.size())
            throw Error("voxelizer", "a mask names triangle " + std::to_string(in.triangle) + " of " + std::to_string(tris.size()));
        MaskedTriangle m;
        for (int k = 0; k < 3; ++k) m.p[k] = grid.to_voxel_space(positions[tris[in.triangle][k]]);
        const DVec3 n = glm::cross(m.p[1] - m.p[0], m.p[2] - m.p[0]);
        const double len = glm::length(n);
        m.normal = len > 0 ? n / len : DVec3(0);
        m.alpha = in.alpha;
        m.cutoff = in.cutoff;
        m.mask = in.texture;
        for (int k = 0; k < 3; ++k) m.uv[k] = in.uv[k];
        if (in.texture && len > 0) {
            const Vec2 d1 = m.uv[1] - m.uv[0], d2 = m.uv[2] - m.uv[0];
            m.uv_per_voxel = float(std::sqrt(std::abs(double(d1.x) * d2.y - double(d1.y) * d2.x) / len));
        }
        if (masked.empty()) masked.assign(triangles.size(), -1);
        masked[in.triangle] = int32_t(masks.size());
        masks.push_back(std::move(m));
    }
}

Voxelizer::~Voxelizer() = default;
Voxelizer::Voxelizer(Voxelizer&&) noexcept = default;
Voxelizer& Voxelizer::operator=(Voxelizer&&) noexcept = default;

const VoxelGrid& Voxelizer::grid() const { return impl_->grid; }
const VoxelizeOptions& Voxelizer::options() const { return impl_->options; }
size_t Voxelizer::triangle_count() const { return impl_->triangles.size(); }
VoxelList Voxelizer::voxelize() const { return impl_->run_codes(impl_->grid.full_region()); }
VoxelList Voxelizer::voxelize(const VoxelRegion& region) const { return impl_->run_codes(region); }

namespace {
void check_triangle_indices(std::span<const uint32_t> triangles, size_t count) {
    for (uint32_t t : triangles)
        if (t >= count)
            throw Error("voxelizer", "triangle " + std::to_string(t) + " does not exist (there are " +
                                         std::to_string(count) + ")");
}
}  // namespace

VoxelList Voxelizer::voxelize(const VoxelRegion& region, std::span<const uint32_t> triangles) const {
    check_triangle_indices(triangles, impl_->triangles.size());
    return impl_->run_codes(region, &triangles);
}
VoxelBlocks Voxelizer::voxelize_blocks(const VoxelRegion& region, std::span<const uint32_t> triangles) const {
    check_triangle_indices(triangles, impl_->triangles.size());
    return impl_->run(region, &triangles);
}
uint64_t Voxelizer::estimate_voxels(const VoxelRegion& region) const {
    return impl_->estimate_in(region.intersect(impl_->grid.full_region()));
}

std::vector<uint64_t> Voxelizer::touched_cells(int cell_log2) const { return bin_triangles(cell_log2).cells; }

CellTriangles Voxelizer::bin_triangles(int cell_log2) const {
    const VoxelGrid& grid = impl_->grid;
    cell_log2 = std::clamp(cell_log2, 0, grid.depth());
    CellBox clip;
    for (int k = 0; k < 3; ++k) {
        clip.lo[k] = 0;
        clip.hi[k] = ((int64_t(grid.resolution) - 1) >> cell_log2) + 1;
    }
    const auto& triangles = impl_->triangles;
    // Counted first, so that a binning too large for the budget fails before it allocates.
    const uint64_t pair_count = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, triangles.size(), 256), uint64_t(0),
        [&](const tbb::blocked_range<size_t>& r, uint64_t sum) {
            uint64_t tests = 0;
            for (size_t i = r.begin(); i < r.end(); ++i)
                rasterize(triangles[i], cell_log2, kCoarsePad, clip, tests, [&](int64_t, int64_t, int64_t) { ++sum; });
            return sum;
        },
        std::plus<uint64_t>());
    struct Pair {
        uint64_t cell;
        uint32_t triangle;
        bool operator<(const Pair& o) const { return cell != o.cell ? cell < o.cell : triangle < o.triangle; }
    };
    if (double(pair_count) * 2.0 * sizeof(Pair) > double(impl_->options.max_bytes))
        throw Error("voxelizer", "binning " + std::to_string(triangles.size()) + " triangles into cells of " +
                                     std::to_string(uint64_t(1) << cell_log2) + "³ voxels gives " +
                                     std::to_string(pair_count) + " (cell, triangle) pairs (" +
                                     gib(double(pair_count) * 2.0 * sizeof(Pair)) + "), more than the memory budget of " +
                                     gib(double(impl_->options.max_bytes)) + "; use larger cells");
    tbb::enumerable_thread_specific<std::vector<Pair>> local;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        auto& pairs = local.local();
        uint64_t tests = 0;
        for (size_t i = r.begin(); i < r.end(); ++i)
            rasterize(triangles[i], cell_log2, kCoarsePad, clip, tests, [&](int64_t x, int64_t y, int64_t z) {
                pairs.push_back({morton_encode(uint32_t(x), uint32_t(y), uint32_t(z)), uint32_t(i)});
            });
    });
    std::vector<Pair> pairs;
    pairs.reserve(pair_count);
    for (auto& p : local) {
        pairs.insert(pairs.end(), p.begin(), p.end());
        std::vector<Pair>().swap(p);
    }
    tbb::parallel_sort(pairs.begin(), pairs.end());
    CellTriangles bins;
    bins.triangles.reserve(pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
        if (i == 0 || pairs[i].cell != pairs[i - 1].cell) {
            bins.cells.push_back(pairs[i].cell);
            bins.begin.push_back(i);
        }
        bins.triangles.push_back(pairs[i].triangle);
    }
    bins.begin.push_back(pairs.size());
    return bins;
}

VoxelList voxelize(std::span<const Vec3> positions, std::span<const UVec3> triangles, const VoxelGrid& grid,
                   VoxelizeOptions options) {
    return Voxelizer(positions, triangles, grid, options).voxelize();
}

VoxelList voxelize(const SceneFrame& frame, const VoxelGrid& grid, VoxelizeOptions options) {
    return Voxelizer(frame, grid, options).voxelize();
}

}  // namespace gilab
