#pragma once
// The one query interface every photon-map structure (kd-tree, hash grid, nanoflann)
// offers: radius query (a visitor sees every photon within r of x) and k nearest
// neighbours within a maximum radius (a max-heap whose root shrinks the search radius),
// plus counters of how much work a query did.
//
// "Within r" means photon_distance2(x, p) ≤ r·r, evaluated the same way everywhere, so
// structures and brute force agree exactly. Photon indices refer to the structure's own
// storage order (photon(i)); original_index(i) maps back to the build input.
//
// Each concrete structure also has inline template versions of both queries
// (for_each_in_radius, knn) for hot loops; the virtual ones here wrap them. A hot loop
// reaches them through as<Map>(), which names the concrete structure by its kind.
//
// The map owns its gather radius: build() records the radius the structure was built
// for (the hash grid's cells are sized by it) and radius() gives it to the gather.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>
#include "accel/photon/photon.hpp"

namespace gilab {

// Work done by queries. visited = photons whose distance was computed (examined);
// inside = those of them within the query radius.
struct PhotonQueryStats {
    uint64_t queries = 0;
    uint64_t visited = 0;
    uint64_t inside = 0;

    void merge(const PhotonQueryStats& o) {
        queries += o.queries;
        visited += o.visited;
        inside += o.inside;
    }
    double visited_per_query() const { return queries ? double(visited) / double(queries) : 0.0; }
    double inside_fraction() const { return visited ? double(inside) / double(visited) : 0.0; }
};

struct PhotonNeighbor {
    uint32_t index = 0;      // storage index in the structure (or in a local buffer)
    float distance2 = 0;
};

// Fixed-capacity max-heap on distance2 (Jensen's kNN). While not full every candidate
// within the maximum radius enters; once full, a candidate enters only if it is strictly
// closer than the root, which it replaces. The root is then the shrinking search radius².
class NeighborHeap {
public:
    explicit NeighborHeap(size_t k = 0) { reset(k, kInfinity); }
    void reset(size_t k, float max_distance2) {
        k_ = k;
        max_distance2_ = max_distance2;
        items_.clear();
        items_.reserve(k);
    }
    size_t capacity() const { return k_; }
    size_t size() const { return items_.size(); }
    bool full() const { return items_.size() >= k_; }
    // Current search radius²: the root once full, else the maximum radius².
    float bound2() const { return full() && k_ > 0 ? items_.front().distance2 : max_distance2_; }
    float max_distance2() const { return max_distance2_; }
    // Offers a candidate; returns true if it was kept.
    bool offer(uint32_t index, float distance2) {
        if (k_ == 0 || !(distance2 <= max_distance2_)) return false;
        if (items_.size() < k_) {
            items_.push_back({index, distance2});
            std::push_heap(items_.begin(), items_.end(), less);
            return true;
        }
        if (!(distance2 < items_.front().distance2)) return false;
        std::pop_heap(items_.begin(), items_.end(), less);
        items_.back() = {index, distance2};
        std::push_heap(items_.begin(), items_.end(), less);
        return true;
    }
    // In heap order (deterministic for a given sequence of offers).
    const std::vector<PhotonNeighbor>& items() const { return items_; }

private:
    static bool less(const PhotonNeighbor& a, const PhotonNeighbor& b) { return a.distance2 < b.distance2; }
    size_t k_ = 0;
    float max_distance2_ = kInfinity;
    std::vector<PhotonNeighbor> items_;
};

// A non-owning reference to a callable (cheap to pass to virtual functions).
template <typename Signature>
class FunctionRef;
template <typename R, typename... Args>
class FunctionRef<R(Args...)> {
public:
    template <typename F, typename = std::enable_if_t<!std::is_same_v<std::decay_t<F>, FunctionRef>>>
    FunctionRef(F&& f) : object_(const_cast<void*>(static_cast<const void*>(&f))) {
        call_ = [](void* o, Args... a) -> R { return (*static_cast<std::remove_reference_t<F>*>(o))(a...); };
    }
    R operator()(Args... a) const { return call_(object_, a...); }

private:
    void* object_;
    R (*call_)(void*, Args...);
};

enum class PhotonMapKind { KdTree, HashGrid, Nanoflann };
const char* to_string(PhotonMapKind kind);           // "kd_tree", "hash_grid", "nanoflann"
// Throws Error naming `where` and listing the valid names.
PhotonMapKind parse_photon_map_kind(const std::string& name, const std::string& where);

class PhotonMap {
public:
    virtual ~PhotonMap() = default;
    virtual PhotonMapKind kind() const = 0;
    std::string name() const { return to_string(kind()); }

    // The concrete structure (HashGridPhotonMap, KdTreePhotonMap, NanoflannPhotonMap) if
    // this map is one, else null. Each is final and the only map of its kind (Map::kKind).
    template <typename Map>
    const Map* as() const {
        static_assert(std::is_base_of_v<PhotonMap, Map> && std::is_final_v<Map>, "a concrete photon map");
        return kind() == Map::kKind ? static_cast<const Map*>(this) : nullptr;
    }
    template <typename Map>
    Map* as() {
        return const_cast<Map*>(std::as_const(*this).template as<Map>());
    }

    // Replaces the content, built for the gather radius `radius`, which radius() then
    // returns. The hash grid's cell edge derives from it (it must be positive and finite);
    // the trees do not depend on it, and 0 (the default) suits a tree queried only at
    // radii of its own. Throws Error on bad input; radius() changes only with a build
    // that succeeds.
    void build(std::vector<Photon> photons, float radius = 0) {
        build_structure(std::move(photons), radius);
        radius_ = radius;
    }
    // The gather radius of the last build (0 before the first).
    float radius() const { return radius_; }

    virtual size_t size() const = 0;
    bool empty() const { return size() == 0; }
    virtual const Photon& photon(uint32_t index) const = 0;
    virtual uint32_t original_index(uint32_t index) const = 0;
    virtual size_t memory_bytes() const = 0;

    using Visitor = FunctionRef<void(uint32_t index, float distance2)>;
    // Calls visit for every photon within r of x (any order). Counts into stats.
    virtual void radius_query(const Vec3& x, float r, Visitor visit, PhotonQueryStats& stats) const = 0;
    // Fills heap (reset to capacity k and radius max_r) with the k nearest photons
    // within max_r of x.
    virtual void knn_query(const Vec3& x, size_t k, float max_r, NeighborHeap& heap,
                           PhotonQueryStats& stats) const = 0;

protected:
    // The structure's part of build().
    virtual void build_structure(std::vector<Photon> photons, float radius) = 0;

private:
    float radius_ = 0;
};

std::unique_ptr<PhotonMap> make_photon_map(PhotonMapKind kind);

}  // namespace gilab
