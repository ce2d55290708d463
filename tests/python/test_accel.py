"""Voxelizer, SVO, ESVO and SVDAG through Python: each structure decodes to the voxels it
was built from, and the three answer point and ray queries identically."""
import numpy as np
import pytest

import gilab


def cube_mesh():
    positions = np.array([[x, y, z] for x in (0.1, 0.9) for y in (0.1, 0.9) for z in (0.1, 0.9)], dtype=np.float64)
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return positions, np.array(faces, dtype=np.int32)


@pytest.fixture(scope="module")
def cornell_voxels(cornell):
    return gilab.voxelize(cornell, 32)


@pytest.fixture(scope="module")
def structures(cornell_voxels):
    svo = gilab.Svo.build(cornell_voxels)
    return {"svo": svo, "esvo": gilab.Esvo.from_svo(svo), "svdag": gilab.Svdag.from_svo(svo)}


def test_voxel_list(cornell_voxels):
    codes = cornell_voxels.codes
    assert codes.dtype == np.uint64 and len(codes) == len(cornell_voxels) > 0
    assert np.all(np.diff(codes.astype(np.int64)) > 0)  # ascending and unique
    voxels = cornell_voxels.voxels()
    assert voxels.shape == (len(codes), 3) and voxels.dtype == np.uint32 and voxels.max() < 32
    assert cornell_voxels.grid.resolution == 32 and cornell_voxels.grid.depth == 5


def test_every_structure_decodes_to_its_voxels(cornell_voxels, structures):
    for name, s in structures.items():
        assert np.array_equal(s.decode(), cornell_voxels.codes), name
        assert s.voxel_count == len(cornell_voxels), name
        assert len(s.level_node_counts) == s.depth + 1 == 6, name


def test_node_counts_and_bytes(cornell_voxels, structures):
    svo, svdag = structures["svo"], structures["svdag"]
    assert svo.level_node_counts[0] == 1 and svo.level_node_counts[-1] == len(cornell_voxels)
    assert sum(svo.level_node_counts) == svo.node_count
    assert svdag.level_node_counts[-1] == 1  # every leaf is alike
    assert sum(svdag.level_node_counts) == svdag.node_count < svo.node_count
    assert all(d <= s for d, s in zip(svdag.level_node_counts, svo.level_node_counts))
    assert svo.bytes == svo.node_count + 4 * svo.pointer_count
    assert svdag.stats["nodes"] == svdag.node_count
    split = gilab.Svdag.from_voxels(cornell_voxels, split_level=2)
    assert np.array_equal(split.decode(), svdag.decode()) and split.node_count == svdag.node_count


def test_point_queries_agree_with_the_voxel_list(cornell_voxels, structures):
    grid = cornell_voxels.grid
    occupied = {tuple(v) for v in cornell_voxels.voxels()}
    rng = np.random.default_rng(3)
    points = np.array(grid.origin) + rng.random((400, 3)) * grid.extent
    expected = np.array([grid.voxel_of(p) in occupied for p in points])
    assert expected.any() and not expected.all()
    for name, s in structures.items():
        assert np.array_equal(s.occupied(points), expected), name
        assert s.occupied(points[0]) == expected[0]
        for v in [(0, 0, 0), (15, 15, 15), (31, 31, 31), (3, 30, 9), next(iter(occupied))]:
            assert s.contains_voxel(v) == (v in occupied), (name, v)


def test_ray_queries_agree_between_structures(cornell, structures):
    camera = cornell.camera_view(12, 12)
    rays = [camera.generate_ray(x + 0.5, y + 0.5) for y in range(12) for x in range(12)]
    origins = np.array([r[0] for r in rays], dtype=np.float32)
    directions = np.array([r[1] for r in rays], dtype=np.float32)
    answers = {name: s.trace_rays(origins, directions) for name, s in structures.items()}
    assert answers["svo"]["hit"].all()  # the camera looks into the closed box
    for name in ("esvo", "svdag"):
        for key in ("hit", "t", "voxel", "nodes_visited"):
            assert np.array_equal(answers[name][key], answers["svo"][key]), (name, key)
    one = structures["svdag"].trace_ray(origins[5], directions[5])
    assert one["hit"] and one["voxel"] == tuple(answers["svo"]["voxel"][5]) and one["t"] == answers["svo"]["t"][5]
    miss = structures["svo"].trace_ray((5, 5, 5), (1, 0, 0))
    assert not miss["hit"] and miss["voxel"] is None


def test_mesh_from_arrays_and_svdag_counts_grow_with_resolution():
    positions, faces = cube_mesh()
    counts = []
    for n in (8, 16, 32):
        voxels = gilab.voxelize(positions, faces, n)
        dag = gilab.Svdag.from_voxels(voxels)
        assert np.array_equal(dag.decode(), voxels.codes)
        counts.append(dag.node_count)
    assert counts[0] < counts[1] < counts[2]


def test_bad_arrays_raise(cornell):
    positions, faces = cube_mesh()
    with pytest.raises(gilab.Error, match=r"positions.*expected \(n, 3\)"):
        gilab.voxelize(positions[:, :2], faces, 8)
    with pytest.raises(gilab.Error, match="triangles.*integer"):
        gilab.voxelize(positions, faces.astype(np.float32), 8)
    with pytest.raises(gilab.Error, match="positions.*dtype"):
        gilab.voxelize(positions.astype(np.int64), faces, 8)
    with pytest.raises(gilab.Error):
        gilab.voxelize(positions, faces + 100, 8)  # indices beyond the vertices
    with pytest.raises(gilab.Error, match="resolution"):
        gilab.voxelize(cornell, 0)
    svo = gilab.Svo.build(gilab.voxelize(positions, faces, 8))
    with pytest.raises(gilab.Error, match=r"points.*\(n, 3\)"):
        svo.occupied(np.zeros((4, 2)))


def test_explicit_grid(cornell):
    positions, faces = cube_mesh()
    grid = gilab.VoxelGrid((0, 0, 0), 1.0, 4)
    voxels = gilab.voxelize(positions, faces, 10, grid=grid)
    assert voxels.grid.resolution == 10 and voxels.grid.origin == (0, 0, 0) and voxels.grid.extent == 1.0
    # The cube's faces at 0.1 and 0.9 fall in voxels 1 and 8 of a 10³ unit grid.
    coordinates = voxels.voxels()
    assert coordinates.min() == 1 and coordinates.max() == 8
    same = gilab.voxelize(cornell, 16, grid=gilab.VoxelGrid.enclosing(*cornell.bounds, 16))
    assert np.array_equal(same.codes, gilab.voxelize(cornell, 16).codes)
