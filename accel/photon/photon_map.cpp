#include "accel/photon/photon_map.hpp"

#include "accel/photon/hash_grid_photon_map.hpp"
#include "accel/photon/kd_tree_photon_map.hpp"
#include "accel/photon/nanoflann_photon_map.hpp"
#include "core/util/error.hpp"

namespace gilab {

const char* to_string(PhotonMapKind kind) {
    switch (kind) {
        case PhotonMapKind::KdTree: return "kd_tree";
        case PhotonMapKind::HashGrid: return "hash_grid";
        case PhotonMapKind::Nanoflann: return "nanoflann";
    }
    return "unknown";
}

PhotonMapKind parse_photon_map_kind(const std::string& name, const std::string& where) {
    for (PhotonMapKind k : {PhotonMapKind::HashGrid, PhotonMapKind::KdTree, PhotonMapKind::Nanoflann})
        if (name == to_string(k)) return k;
    throw Error(where, "unknown photon_map '" + name + "' (expected hash_grid, kd_tree or nanoflann)");
}

std::unique_ptr<PhotonMap> make_photon_map(PhotonMapKind kind) {
    switch (kind) {
        case PhotonMapKind::KdTree: return std::make_unique<KdTreePhotonMap>();
        case PhotonMapKind::HashGrid: return std::make_unique<HashGridPhotonMap>();
        case PhotonMapKind::Nanoflann: return std::make_unique<NanoflannPhotonMap>();
    }
    throw Error("photon map", "unknown kind");
}

}  // namespace gilab
