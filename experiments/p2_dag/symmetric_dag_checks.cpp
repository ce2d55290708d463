#include "experiments/p2_dag/symmetric_dag_checks.hpp"
#include <optional>
#include <unordered_set>
#include "core/scene/camera.hpp"
#include "core/util/parallel.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/measures.hpp"

namespace gilab::p2 {

template <class Group>
bool same_octree(const Svdag& svdag, const SymmetricDag<Group>& dag) {
    using Dag = SymmetricDag<Group>;
    if (svdag.empty() || dag.empty()) return svdag.empty() == dag.empty();
    if (svdag.depth() != dag.depth()) return false;
    const int depth = svdag.depth();
    if (depth == 0) return dag.voxel_count() == 1;
    // First pointer met per SVDAG word, as a long pointer's bits (never all ones: that
    // would be the last transform at the last address a pointer reaches); further ones
    // in `more`.
    constexpr uint32_t kUnseen = 0xffffffffu;
    std::vector<uint32_t> first(svdag.words().size(), kUnseen);
    std::unordered_set<uint64_t> more;
    auto first_visit = [&](uint32_t node, const SymmetricDagPointer& p) {
        const uint32_t word = p.transform << Dag::kLongTransformShift | p.address;
        if (first[node] == kUnseen) {
            first[node] = word;
            return true;
        }
        return first[node] != word && more.insert(uint64_t(node) << 32 | word).second;
    };
    struct Pair {
        uint32_t node;
        SymmetricDagPointer pointer;
        int level;
    };
    std::vector<Pair> stack{{svdag.root(), dag.root(), 0}};
    while (!stack.empty()) {
        const Pair p = stack.back();
        stack.pop_back();
        const uint8_t mask = svdag.mask(p.node);
        if (mask != dag.mask(p.pointer, p.level)) return false;
        if (p.level == depth - 1) continue;  // the children are voxels
        for (int slot = 0; slot < 8; ++slot) {
            if (!(mask & (1u << slot))) continue;
            const uint32_t child = svdag.child(p.node, slot);
            const std::optional<SymmetricDagPointer> seen = dag.child(p.pointer, p.level, slot);
            if (!seen) return false;
            if (first_visit(child, *seen)) stack.push_back({child, *seen, p.level + 1});
        }
    }
    return true;
}

std::vector<Ray> camera_rays(const Model& model, int size) {
    const SceneCamera& c = model.camera;
    const EyeCamera camera = EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
    std::vector<Ray> rays;
    rays.reserve(size_t(size) * size_t(size));
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) rays.push_back(camera.generate_ray(float(x) + 0.5f, float(y) + 0.5f));
    return rays;
}

double RayRun::median_rays_per_s() const { return median(rays_per_s); }

double RayRun::hit_fraction() const {
    uint64_t hit = 0;
    for (const VoxelRayHit& h : hits) hit += h.hit;
    return hits.empty() ? 0.0 : double(hit) / double(hits.size());
}

std::vector<RayRun> cast_in_turn(const std::vector<Ray>& rays, int reps, const std::vector<RayCast>& casts) {
    std::vector<RayRun> runs(casts.size());
    for (int r = 0; r < reps; ++r)
        for (size_t c = 0; c < casts.size(); ++c) {
            RayRun& run = runs[c];
            run.hits.resize(rays.size());
            Stopwatch watch;
            parallel_for(rays.size(), 256, [&](size_t begin, size_t end) {
                for (size_t i = begin; i < end; ++i) run.hits[i] = casts[c](rays[i]);
            });
            run.rays_per_s.push_back(double(rays.size()) / (watch.elapsed_ms() * 1e-3));
        }
    return runs;
}

uint64_t disagreeing_rays(const RayRun& a, const RayRun& b) {
    uint64_t n = 0;
    for (size_t i = 0; i < a.hits.size() && i < b.hits.size(); ++i)
        n += a.hits[i].hit != b.hits[i].hit || (a.hits[i].hit && a.hits[i].voxel != b.hits[i].voxel);
    return n + (a.hits.size() > b.hits.size() ? a.hits.size() - b.hits.size() : b.hits.size() - a.hits.size());
}

template bool same_octree(const Svdag&, const Ssvdag&);
template bool same_octree(const Svdag&, const CubeSymmetricDag&);

}  // namespace gilab::p2
