#include "accel/photon/nanoflann_photon_map.hpp"

#include <cmath>
#include <nanoflann.hpp>
#include "core/util/error.hpp"

namespace gilab {

namespace {

// Counters of the query running on this thread. nanoflann computes a point's distance
// only through the metric below, so it can count examined photons and those within r.
thread_local uint64_t tls_examined = 0;
thread_local uint64_t tls_inside = 0;
thread_local float tls_r2 = 0;

struct PhotonCloud {
    const std::vector<Photon>* photons = nullptr;
    size_t kdtree_get_point_count() const { return photons->size(); }
    float kdtree_get_pt(uint32_t i, size_t dim) const { return (*photons)[i].position[int(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const { return false; }
};

// Squared Euclidean distance (as nanoflann's L2_Simple_Adaptor), evaluated exactly as
// photon_distance2 so every structure agrees on the boundary, plus the counters.
struct CountingL2 {
    using ElementType = float;
    using DistanceType = float;
    const PhotonCloud& cloud;
    explicit CountingL2(const PhotonCloud& c) : cloud(c) {}
    float evalMetric(const float* a, uint32_t index, size_t) const {
        const Vec3& p = (*cloud.photons)[index].position;
        float d2 = photon_distance2(Vec3(a[0], a[1], a[2]), p.x, p.y, p.z);
        ++tls_examined;
        if (d2 <= tls_r2) ++tls_inside;
        return d2;
    }
    template <typename U, typename V>
    float accum_dist(const U a, const V b, const size_t) const { return (a - b) * (a - b); }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<CountingL2, PhotonCloud, 3, uint32_t>;

float next_above(float r2) { return std::nextafter(r2, kInfinity); }

// Result set forwarding every photon with d² ≤ r² to a visitor.
struct VisitorResultSet {
    float bound;  // next float above r²: nanoflann keeps d² < bound
    PhotonMap::Visitor* visit;
    size_t count = 0;
    void init() {}
    size_t size() const { return count; }
    bool full() const { return true; }
    bool addPoint(float d2, uint32_t index) {
        if (d2 < bound) {
            ++count;
            (*visit)(index, d2);
        }
        return true;
    }
    float worstDist() const { return bound; }
};

// Result set feeding the shared max-heap; its root shrinks nanoflann's search bound.
struct HeapResultSet {
    NeighborHeap* heap;
    FunctionRef<bool(uint32_t)>* accept;
    void init() {}
    size_t size() const { return heap->size(); }
    bool full() const { return heap->full(); }
    bool addPoint(float d2, uint32_t index) {
        if (d2 <= heap->max_distance2() && (!accept || (*accept)(index))) heap->offer(index, d2);
        return true;
    }
    // A photon at exactly the root distance cannot enter a full heap, so the strict test
    // is right once full; before that the maximum radius itself must pass.
    float worstDist() const { return heap->full() ? heap->bound2() : next_above(heap->max_distance2()); }
};

}  // namespace

struct NanoflannPhotonMap::Index {
    PhotonCloud cloud;
    Tree tree;
    Index(const std::vector<Photon>& photons, size_t leaf)
        : cloud{&photons}, tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(leaf)) {}
};

NanoflannPhotonMap::NanoflannPhotonMap(size_t leaf_max_size) : leaf_max_size_(std::max<size_t>(1, leaf_max_size)) {}
NanoflannPhotonMap::~NanoflannPhotonMap() = default;

void NanoflannPhotonMap::build_structure(std::vector<Photon> photons, float) {
    for (size_t i = 0; i < photons.size(); ++i)
        if (!is_finite(photons[i].position))
            throw Error("nanoflann photon map", "photon " + std::to_string(i) + " has a non-finite position");
    index_.reset();
    photons_ = std::move(photons);
    if (photons_.empty()) return;
    index_ = std::make_unique<Index>(photons_, leaf_max_size_);
    index_->tree.buildIndex();
}

size_t NanoflannPhotonMap::memory_bytes() const {
    size_t tree = index_ ? index_->tree.usedMemory(index_->tree) : 0;
    return photons_.capacity() * sizeof(Photon) + tree;
}

namespace {
template <typename ResultSet>
void search(const Tree& tree, const Vec3& x, float r2, ResultSet& result, PhotonQueryStats& stats) {
    const float q[3] = {x.x, x.y, x.z};
    tls_examined = 0;
    tls_inside = 0;
    tls_r2 = r2;
    tree.findNeighbors(result, q, nanoflann::SearchParams(32, 0.0f, false));
    stats.visited += tls_examined;
    stats.inside += tls_inside;
}
}  // namespace

void NanoflannPhotonMap::radius_query(const Vec3& x, float r, Visitor visit, PhotonQueryStats& stats) const {
    ++stats.queries;
    if (!index_ || !(r >= 0.0f)) return;
    VisitorResultSet result{next_above(r * r), &visit};
    search(index_->tree, x, r * r, result, stats);
}

void NanoflannPhotonMap::knn_filtered(const Vec3& x, size_t k, float max_r, NeighborHeap& heap,
                                      PhotonQueryStats& stats, FunctionRef<bool(uint32_t)> accept) const {
    ++stats.queries;
    heap.reset(k, max_r * max_r);
    if (!index_ || k == 0 || !(max_r >= 0.0f)) return;
    HeapResultSet result{&heap, &accept};
    search(index_->tree, x, max_r * max_r, result, stats);
}

void NanoflannPhotonMap::knn_query(const Vec3& x, size_t k, float max_r, NeighborHeap& heap,
                                   PhotonQueryStats& stats) const {
    ++stats.queries;
    heap.reset(k, max_r * max_r);
    if (!index_ || k == 0 || !(max_r >= 0.0f)) return;
    HeapResultSet result{&heap, nullptr};
    search(index_->tree, x, max_r * max_r, result, stats);
}

}  // namespace gilab
