"""gilab.ShadowDag and the time-correlated multi-frame DAG (gilab.MultiFrameDag,
gilab.LaidOutMultiFrameDag, gilab.build_animation_dag) against the same figures computed by
`gilab experiment dag-table4 / dag-table5 --quick`, and against invariants that can fail:
the depth-map rule, ray-traced shadows, decoding, static scenes."""
import json
import subprocess

import numpy as np
import pytest

import gilab
from conftest import require_shared_asset

# Scenes of the two experiments, with the shared asset each needs (None: built in).
TABLE4_SCENES = {"villa": None, "fbm_terrain": None, "castle": "castle/fincastel.obj",
                 "terrain_lidar": "terrain/terrain.obj"}
TABLE5_SCENES = {"fire": None, "kitchen": "kitchen-interior/part0.obj", "robot": "animated/BrainStem.glb"}
QUICK_TABLE5 = {"resolution": 64, "frames": 8}  # what dag-table5 --quick measures


class QuickRuns:
    """`gilab experiment NAME --quick` for both experiments, started side by side when the
    module starts (so the other tests run meanwhile); results["NAME"] waits for NAME and
    returns its results.json."""

    NAMES = ("dag-table4", "dag-table5")

    def __init__(self, cli, root):
        self.root = root
        self.runs = {name: subprocess.Popen([str(cli), "--threads", "2", "experiment", name, "--quick", "--results",
                                             str(root)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                     for name in self.NAMES}
        self.results = {}

    def __getitem__(self, name):
        if name not in self.results:
            _, err = self.runs[name].communicate()
            assert self.runs[name].returncode == 0, f"gilab experiment {name} --quick failed:\n{err}"
            self.results[name] = json.loads((self.root / name / "results.json").read_text())
        return self.results[name]

    def finish(self):
        for run in self.runs.values():
            if run.returncode is None:  # not waited for (a test failed or was skipped)
                run.kill()
                run.communicate()


@pytest.fixture(scope="module", autouse=True)
def quick_tables(cli, tmp_path_factory):
    runs = QuickRuns(cli, tmp_path_factory.mktemp("dag_experiments"))
    yield runs
    runs.finish()


def rows_of(results, scene, title_start=""):
    table = next(t for t in results["tables"] if t["title"].startswith(title_start))
    return [r for r in table["rows"] if r["scene"] == scene]


def scene_or_skip(name, asset):
    if asset is not None:
        require_shared_asset(asset)
    return gilab.load_scene(name)


@pytest.fixture(scope="module")
def villa():
    return gilab.load_scene("villa")


@pytest.fixture(scope="module")
def fire():
    return gilab.load_scene("fire")


# ---- Shadow DAG ----

def test_shadow_dag_counts_and_bytes_are_consistent(villa):
    dag = gilab.ShadowDag.build(villa, resolution=1000)
    assert dag.depth == 10 and dag.octree_size == 1024 and not dag.perspective
    assert dag.root_state == "boundary" and len(dag.level_node_counts) == dag.depth - 1
    assert sum(dag.level_node_counts) == dag.node_count and dag.level_node_counts[-1] == dag.leaf_count
    # Interior node: mask word + one word per boundary child; leaf: 64-bit mask.
    interior = dag.node_count - dag.leaf_count
    assert dag.bytes == 4 * (interior + dag.pointer_count) + 8 * dag.leaf_count == 4 * dag.words.size
    assert dag.words.dtype == np.uint32 and dag.stats["bytes"] == dag.bytes
    assert dag.build_stats["tiles"] == 1 and dag.build_stats["rays"] > 0
    # Tiling is a memory bound only: 16 tiles give the same words.
    tiled = gilab.ShadowDag.build(villa, resolution=1000, tile_texels=256)
    assert tiled.build_stats["tiles"] == 16 and np.array_equal(tiled.words, dag.words)


def test_from_depth_maps_follows_the_depth_rule():
    rng = np.random.default_rng(3)
    size = 32
    d1 = rng.uniform(0, 40, (size, size)).astype(np.float32)
    d1[rng.random((size, size)) < 0.2] = np.inf  # columns that hit nothing
    d1[:8, :8] = 10.0                              # a flat block merges
    d2 = d1 + np.where(rng.random((size, size)) < 0.5, rng.uniform(0, 10, (size, size)), 0).astype(np.float32)
    x, y, z = np.meshgrid(np.arange(size), np.arange(size), np.arange(size), indexing="ij")
    voxels = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    centre = voxels[:, 2] + 0.5
    first, exit_ = d1[voxels[:, 1], voxels[:, 0]], d2[voxels[:, 1], voxels[:, 0]]

    plain = gilab.ShadowDag.from_depth_maps(d1)
    assert plain.octree_size == size and plain.light is None
    np.testing.assert_array_equal(plain.voxel_states(voxels), np.where(centre < first, 1, 0))
    np.testing.assert_array_equal(plain.lit_at(voxels + 0.5), centre < first)
    assert plain.voxel_state((0, 0, 0)) == "lit" and plain.voxel_state((0, 0, 31)) == "shadow"
    assert plain.lit_at((-5.0, 3.0, 3.0)) is True  # outside the x–y square

    expected = np.where(centre < first, 1, np.where(centre < exit_, 3, 0))
    defined = expected != 3
    for undefined_as in ("lit", "shadow"):
        double = gilab.ShadowDag.from_depth_maps(d1, d2, undefined_as=undefined_as)
        states = double.voxel_states(voxels)
        np.testing.assert_array_equal(states[defined], expected[defined])
        assert set(np.unique(states[~defined])) <= {0, 1, 3}
        assert double.node_count <= plain.node_count
        for tile in (4, 16):
            again = gilab.ShadowDag.from_depth_maps(d1, d2, tile_texels=tile, undefined_as=undefined_as)
            assert np.array_equal(again.words, double.words)


def test_shadow_query_agrees_with_ray_traced_shadows(villa):
    """visibility() against shadow rays cast in NumPy toward the same sun, on 1200 random
    surface points facing it (n·L > 0.2). Depth quantization and the lookup bias disagree
    only near shadow edges: S2 at 1024³ agrees on ≥ 97 % of points, and S3 at least as
    well (≥ 99 % here): lookups of surfaces touching or inside a closed part land in its
    undefined interior, which ends a band before such surfaces and is stored as shadow."""
    positions, triangles = villa.evaluate(0).merged()
    p = positions.astype(np.float64)
    a, b, c = p[triangles[:, 0]], p[triangles[:, 1]], p[triangles[:, 2]]
    normal = np.cross(b - a, c - a)
    area = np.linalg.norm(normal, axis=1)
    normal /= np.maximum(area, 1e-30)[:, None]

    s2 = gilab.ShadowDag.build(villa, resolution=1024)
    to_light = -np.asarray(s2.light["direction"], np.float64)
    to_light /= np.linalg.norm(to_light)

    rng = np.random.default_rng(1)
    tri = rng.choice(len(triangles), size=4000, p=area / area.sum())
    u, v = rng.random(len(tri)), rng.random(len(tri))
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    points = a[tri] + u[:, None] * (b[tri] - a[tri]) + v[:, None] * (c[tri] - a[tri])
    normals = normal[tri]
    facing = normals @ to_light > 0.2
    points, normals = points[facing][:1200], normals[facing][:1200]
    assert len(points) == 1200

    e1, e2 = b - a, c - a
    pvec = np.cross(to_light, e2)
    det = np.einsum("ij,ij->i", e1, pvec)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)

    def occluded(origin):  # Möller–Trumbore against every triangle
        s = origin - a
        uu = np.einsum("ij,ij->i", s, pvec) * inv
        q = np.cross(s, e1)
        vv = (q @ to_light) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        return bool(np.any(ok & (uu >= 0) & (vv >= 0) & (uu + vv <= 1) & (t > 1e-4)))

    reference = np.array([not occluded(o) for o in points + 1e-3 * normals])
    assert 0.3 < reference.mean() < 0.95  # both lit and shadowed points are tested

    pts, nrm = points.astype(np.float32), normals.astype(np.float32)
    vis = s2.visibility(pts, nrm)
    assert vis.dtype == np.float32 and vis.shape == (1200,) and set(np.unique(vis)) <= {0.0, 1.0}
    s2_agree = ((vis > 0.5) == reference).mean()
    assert s2_agree >= 0.97
    s3 = gilab.ShadowDag.build(villa, resolution=1024, double_depth=True)
    s3_agree = ((s3.visibility(pts, nrm) > 0.5) == reference).mean()
    assert s3_agree >= 0.99 and s3_agree >= s2_agree

    # One point → float; surfaces turned away are unlit; PCF gives fractions.
    assert s2.visibility(pts[0], nrm[0]) == vis[0]
    assert (s2.visibility(pts, -nrm) == 0).all()
    soft = s2.visibility(pts, nrm, pcf=3)
    assert ((soft >= 0) & (soft <= 1)).all() and ((soft > 0) & (soft < 1)).any()
    # lit() looks up world points as they are: high above the scene toward the sun is lit.
    above = points + 200.0 * to_light
    assert s2.lit(above.astype(np.float32)).all() and s2.lit(above[0]) is True
    np.testing.assert_allclose(s2.to_light_direction(pts), np.tile(to_light, (len(pts), 1)), atol=1e-6)
    coords = s2.to_light(pts)
    np.testing.assert_array_equal(s2.lit(pts), s2.lit_at(coords))


def test_shadow_dag_bad_input_raises_the_cpp_message(villa):
    with pytest.raises(gilab.Error, match="outside 8..131072"):
        gilab.ShadowDag.build(villa, resolution=4)
    with pytest.raises(gilab.Error, match="no light named 'moon'"):
        gilab.ShadowDag.build(villa, light="moon", resolution=64)
    with pytest.raises(gilab.Error, match="index 5"):
        gilab.ShadowDag.build(villa, light=5, resolution=64)
    with pytest.raises(gilab.Error, match="tile size 3"):
        gilab.ShadowDag.build(villa, resolution=64, tile_texels=3)
    with pytest.raises(gilab.Error, match="undefined_as"):
        gilab.ShadowDag.build(villa, resolution=64, undefined_as="maybe")
    with pytest.raises(gilab.Error, match="no directional or spot light"):
        gilab.ShadowDag.build(gilab.load_scene("cornell"))
    with pytest.raises(gilab.Error, match="power of two"):
        gilab.ShadowDag.from_depth_maps(np.zeros((12, 12), np.float32))
    maps = np.full((8, 8), 3.0, np.float32)
    with pytest.raises(gilab.Error, match="d2 < d1"):
        gilab.ShadowDag.from_depth_maps(maps, maps - 1)
    dag = gilab.ShadowDag.from_depth_maps(maps)
    with pytest.raises(gilab.Error, match="world lookups"):
        dag.lit(np.zeros((2, 3), np.float32))
    with pytest.raises(gilab.Error, match="outside 0..8"):
        dag.voxel_state((0, 0, 8))
    with pytest.raises(gilab.Error, match=r"expected \(n, 3\)"):
        gilab.ShadowDag.build(villa, resolution=64).visibility(np.zeros((4, 2), np.float32), np.zeros((4, 2), np.float32))


# ---- Time-correlated multi-frame DAG ----

def per_frame_voxels(scene, animation):
    grid = animation.dag.grid
    return [gilab.voxelize(scene, grid.resolution, time=t, grid=grid) for t in animation.times]


def test_multi_frame_builds_agree(fire):
    animation = gilab.build_animation_dag(fire, resolution=32, frames=5)
    frames = per_frame_voxels(fire, animation)
    incremental = gilab.MultiFrameDag(animation.dag.grid)
    for voxels in frames:
        stats = incremental.append_frame(voxels)
        assert stats["nodes_added"] > 0 and stats["cells_rebuilt"] >= 1
    merged = gilab.MultiFrameDag.merge_all([gilab.Svdag.from_voxels(v) for v in frames])
    all_at_once = gilab.build_animation_dag(fire, resolution=32, frames=5, build="all_at_once")
    words = animation.dag.words
    for other in (incremental.lay_out(), merged.lay_out(), all_at_once.dag):
        assert np.array_equal(other.words, words)
    assert incremental.node_count == animation.dag.node_count == merged.node_count
    # Level 0: the table holds each distinct root once, the layout one per frame.
    assert incremental.frame_count == 5 and incremental.live_level_counts[0] <= 5
    assert incremental.live_level_counts[1:] == animation.dag.level_node_counts[1:]
    assert sum(animation.dag.level_node_counts) == animation.dag.node_count

    # Replacing frame 3 by frame 0: its own nodes die, the DAG is that of the new frames.
    incremental.update_frame(3, frames[0])
    assert incremental.table_level_counts != incremental.live_level_counts
    incremental.compact()
    assert incremental.table_level_counts == incremental.live_level_counts
    again = gilab.MultiFrameDag(animation.dag.grid)
    for voxels in (frames[0], frames[1], frames[2], frames[0], frames[4]):
        again.append_frame(voxels.codes)
    assert np.array_equal(incremental.lay_out().words, again.lay_out().words)
    assert incremental.node_count == again.node_count

    # Point queries: voxel centres of frame 2 are occupied in frame 2.
    grid, dag = animation.dag.grid, animation.dag
    centres = (frames[2].voxels()[:200] + 0.5) * grid.voxel_size + np.asarray(grid.origin)
    assert dag.occupied(2, centres.astype(np.float32)).all()
    assert dag.contains_voxel(2, tuple(int(c) for c in frames[2].voxels()[0]))
    assert not dag.occupied(2, np.asarray([grid.origin], np.float32) - 1).any()


def test_static_scene_shares_everything_but_the_roots(villa):
    """A static scene: every frame's subtree is the one SVDAG; N_n counts it once plus one
    root per further frame (the C++ keeps a root per frame, in time order)."""
    frames = 4
    animation = gilab.build_animation_dag(villa, resolution=64, frames=frames)
    dag = animation.dag
    svdag = gilab.Svdag.from_voxels(gilab.voxelize(villa, 64, grid=dag.grid))
    assert [dag.reachable_node_count(k) for k in range(frames)] == [svdag.node_count] * frames
    assert dag.node_count == svdag.node_count + frames - 1
    assert dag.level_node_counts == [frames] + svdag.level_node_counts[1:]
    root_mask = int(dag.words[dag.root(0)]) & 0xFF
    assert dag.bytes == svdag.bytes + (frames - 1) * 4 * (1 + bin(root_mask).count("1"))  # mask word + pointers
    assert len({dag.root(k) for k in range(frames)}) == frames
    for k in range(frames):
        np.testing.assert_array_equal(dag.decode(k), svdag.decode())


def test_multi_frame_bad_input_raises_the_cpp_message(fire, villa):
    animation = gilab.build_animation_dag(fire, resolution=16, frames=2)
    dag = gilab.MultiFrameDag(animation.dag.grid)
    with pytest.raises(gilab.Error, match="strictly ascending"):
        dag.append_frame(np.array([5, 3], np.uint64))
    with pytest.raises(gilab.Error, match="different grid"):
        dag.append_frame(gilab.voxelize(villa, 16))
    with pytest.raises(gilab.Error, match="cannot update frame 4"):
        dag.update_frame(4, np.array([], np.uint64))
    with pytest.raises(gilab.Error, match="frame 2 is outside"):
        animation.dag.decode(2)
    with pytest.raises(gilab.Error, match="must be a frame index"):
        animation.dag.decode(-1)
    with pytest.raises(gilab.Error, match="at least one frame"):
        gilab.MultiFrameDag.merge_all([])
    with pytest.raises(gilab.Error, match="frames"):
        gilab.build_animation_dag(fire, frames=0)
    with pytest.raises(gilab.Error, match="build mode"):
        gilab.build_animation_dag(fire, resolution=16, build="sideways")


# ---- Against dag-table4 / dag-table5 --quick (last: the experiments run meanwhile) ----

@pytest.mark.parametrize("name", TABLE4_SCENES)
def test_shadow_dag_matches_dag_table4(name, quick_tables):
    scene = scene_or_skip(name, TABLE4_SCENES[name])
    rows = rows_of(quick_tables["dag-table4"], name)
    assert [r["N"] for r in rows] == [500, 1000], "dag-table4 --quick did not measure this scene"
    for row in rows:
        s2 = gilab.ShadowDag.build(scene, resolution=row["N"])
        s3 = gilab.ShadowDag.build(scene, resolution=row["N"], double_depth=True)
        assert s2.resolution == row["N"] and s2.light["type"] != "point"
        assert (s2.node_count, s3.node_count) == (row["S2 nodes"], row["S3 nodes"])
        assert (s2.bytes / 1e6, s3.bytes / 1e6) == (row["S2 (MB)"], row["S3 (MB)"])
        if name == "villa":  # the other storage of undefined space (cheap here)
            s3_lit = gilab.ShadowDag.build(scene, resolution=row["N"], double_depth=True, undefined_as="lit")
            assert s3_lit.bytes / 1e6 == row["S3, undefined as lit (MB)"]


@pytest.mark.parametrize("name", TABLE5_SCENES)
def test_animation_dag_matches_dag_table5(name, quick_tables):
    scene = scene_or_skip(name, TABLE5_SCENES[name])
    counts = rows_of(quick_tables["dag-table5"], name, "Table 5 — nodes")
    storage = rows_of(quick_tables["dag-table5"], name, "Table 5 — storage")
    assert len(counts) == len(storage) == 1, "dag-table5 --quick did not measure this scene"
    counts, storage = counts[0], storage[0]
    assert (counts["resolution (voxels/axis)"], counts["frames"]) == (64, 8)

    animation = gilab.build_animation_dag(scene, **QUICK_TABLE5)
    dag = animation.dag
    assert dag.frame_count == len(animation.times) == 8
    assert animation.times == [k / scene.frames_per_second for k in range(8)]
    assert dag.node_count == counts["TC N_n (nodes)"] and dag.nodes_per_frame == counts["TC N_p (nodes)"]
    assert dag.bytes / 1e6 == storage["TC 32-bit (MB)"]
    reachable = [dag.reachable_node_count(k) for k in range(8)]
    assert sum(reachable) / 8 == counts["TC reachable per frame (nodes)"]

    # The per-frame SVDAG baseline on the same grid, and what the DAG decodes to.
    frames = per_frame_voxels(scene, animation)
    svdags = [gilab.Svdag.from_voxels(v) for v in frames]
    assert sum(s.node_count for s in svdags) == counts["SVDAG N_n (nodes)"]
    assert sum(s.bytes for s in svdags) / 1e6 == storage["SVDAG 32-bit (MB)"]
    assert reachable == [s.node_count for s in svdags]
    assert dag.node_count <= sum(s.node_count for s in svdags)
    for k, voxels in enumerate(frames):
        np.testing.assert_array_equal(dag.decode(k), voxels.codes)
