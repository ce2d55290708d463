"""gilab.PhotonMap: radius and kNN queries of every kind equal brute force over the same
float32 positions (distances summed in the order the C++ code uses)."""
import numpy as np
import pytest

import gilab

KINDS = ["hash_grid", "kd_tree", "nanoflann"]


@pytest.fixture(scope="module")
def photons():
    rng = np.random.default_rng(7)
    return rng.random((3000, 3)).astype(np.float32)


def distance2(points, q):
    q = np.asarray(q, dtype=np.float32)
    d = points - q
    return d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]  # float32, x then y then z


@pytest.mark.parametrize("kind", KINDS)
def test_radius_query_equals_brute_force(photons, kind):
    r = np.float32(0.08)
    pm = gilab.PhotonMap(photons, radius=0.08, kind=kind)
    assert len(pm) == len(photons) and pm.kind == kind and pm.memory_bytes > 0
    queries = np.random.default_rng(1).random((25, 3)).astype(np.float32)
    found = pm.radius_query(queries, 0.08)
    assert len(found) == 25
    for q, indices in zip(queries, found):
        expected = np.flatnonzero(distance2(photons, q) <= r * r)
        assert indices.dtype == np.uint32
        assert np.array_equal(indices, expected)
    assert np.array_equal(pm.radius_query(queries[0], 0.08), found[0])
    assert pm.query_stats["queries"] == 26


@pytest.mark.parametrize("kind", KINDS)
def test_knn_equals_brute_force(photons, kind):
    pm = gilab.PhotonMap(photons, radius=0.05, kind=kind)
    q = (0.4, 0.5, 0.6)
    indices, d2 = pm.knn(q, 12, return_distances=True)
    all_d2 = distance2(photons, q)
    order = np.lexsort((np.arange(len(photons)), all_d2))[:12]
    assert np.array_equal(indices, order)
    assert np.array_equal(d2, all_d2[order])
    limited = pm.knn(q, 12, max_radius=float(np.sqrt(all_d2[order[4]])))
    assert np.array_equal(limited, order[:5])


def test_float64_positions_are_read_as_float32(photons):
    a = gilab.PhotonMap(photons.astype(np.float64), radius=0.1).radius_query((0.5, 0.5, 0.5), 0.1)
    b = gilab.PhotonMap(photons, radius=0.1).radius_query((0.5, 0.5, 0.5), 0.1)
    assert np.array_equal(a, b)


def test_bad_input_raises(photons):
    with pytest.raises(gilab.Error, match=r"positions.*\(n, 3\)"):
        gilab.PhotonMap(photons[:, :2])
    with pytest.raises(gilab.Error, match="positions.*dtype"):
        gilab.PhotonMap(photons.astype(np.int32))
    with pytest.raises(gilab.Error, match="kind"):
        gilab.PhotonMap(photons, kind="octree")
    with pytest.raises(gilab.Error, match="radius"):
        gilab.PhotonMap(photons, radius=-1)
    with pytest.raises(gilab.Error, match="powers"):
        gilab.PhotonMap(photons, powers=np.ones((5, 3)))
    pm = gilab.PhotonMap(photons)
    with pytest.raises(gilab.Error, match="point"):
        pm.knn((0, 0), 3)
