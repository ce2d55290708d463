#pragma once
// nanoflann (1.4.x) kd-tree behind the photon-map query interface: a reference peer for
// our own kd-tree and hash grid. nanoflann's L2_Simple_Adaptor works with squared
// distances, so radii are squared before they reach it; its leaf test is strict
// (d² < bound), so the bound handed to it is the next float above r².
#include <memory>
#include <vector>
#include "accel/photon/photon_map.hpp"

namespace gilab {

class NanoflannPhotonMap final : public PhotonMap {
public:
    explicit NanoflannPhotonMap(size_t leaf_max_size = 10);
    ~NanoflannPhotonMap() override;
    static constexpr PhotonMapKind kKind = PhotonMapKind::Nanoflann;
    PhotonMapKind kind() const override { return kKind; }
    size_t size() const override { return photons_.size(); }
    const Photon& photon(uint32_t index) const override { return photons_[index]; }
    uint32_t original_index(uint32_t index) const override { return index; }
    size_t memory_bytes() const override;

    void radius_query(const Vec3& x, float r, Visitor visit, PhotonQueryStats& stats) const override;
    void knn_query(const Vec3& x, size_t k, float max_r, NeighborHeap& heap, PhotonQueryStats& stats) const override;
    // kNN with a filter applied before candidates compete (as the other structures' knn).
    void knn_filtered(const Vec3& x, size_t k, float max_r, NeighborHeap& heap, PhotonQueryStats& stats,
                      FunctionRef<bool(uint32_t)> accept) const;

protected:
    void build_structure(std::vector<Photon> photons, float radius) override;

private:
    struct Index;
    std::vector<Photon> photons_;
    size_t leaf_max_size_;
    std::unique_ptr<Index> index_;
};

}  // namespace gilab
