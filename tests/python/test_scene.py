"""gilab.load_scene / gilab.Scene against `gilab info` for the same scene."""
import re

import numpy as np
import pytest

import gilab
from conftest import require_shared_asset


def info_figures(text):
    figures = {}
    figures["triangles"] = int(re.search(r"^triangles\s+(\d+)", text, re.M).group(1))
    m = re.search(r"^materials\s+(\d+) \((\d+) emissive\)", text, re.M)
    figures["materials"], figures["emissive"] = int(m.group(1)), int(m.group(2))
    figures["lights"] = int(re.search(r"^lights\s+(\d+) punctual", text, re.M).group(1))
    m = re.search(r"^meshes\s+(\d+) in (\d+) nodes", text, re.M)
    figures["meshes"], figures["nodes"] = int(m.group(1)), int(m.group(2))
    figures["closed"] = re.findall(r"^  \d+ .*: (\d+) triangles, (open|closed), (\d+) boundary edges, (\d+) components \((\d+) closed\)", text, re.M)
    return figures


def check_against_info(scene, info_text):
    figures = info_figures(info_text)
    assert scene.triangle_count == figures["triangles"]
    assert scene.material_count == figures["materials"]
    assert scene.emissive_material_count == figures["emissive"]
    assert scene.light_count == figures["lights"]
    assert (scene.mesh_count, scene.node_count) == (figures["meshes"], figures["nodes"])
    report = [(str(m["triangles"]), "closed" if m["closed"] else "open", str(m["boundary_edges"]), str(m["components"]),
               str(m["closed_components"])) for m in scene.closed_meshes()]
    assert report and report == [tuple(row) for row in figures["closed"]]
    assert scene.describe() == info_text


def test_cornell_matches_gilab_info(run_cli, cornell):
    check_against_info(cornell, run_cli("info", "cornell").stdout)
    assert cornell.name == "cornell" and cornell.source == "builtin:cornell"
    (lo, hi) = cornell.bounds
    assert lo == (0.0, 0.0, 0.0) and all(1.0 < h < 1.01 for h in (hi[0], hi[2]))


def test_shared_obj_matches_gilab_info(run_cli):
    path = require_shared_asset("cornell-box/CornellBox-Original.obj")
    scene = gilab.load_scene(path)
    check_against_info(scene, run_cli("info", path).stdout)


def test_evaluate_gives_world_geometry(cornell):
    frame = cornell.evaluate(0.0)
    assert frame.triangle_count == cornell.triangle_count
    positions, triangles = frame.merged()
    assert positions.dtype == np.float32 and positions.shape[1] == 3
    assert triangles.dtype == np.uint32 and triangles.shape == (cornell.triangle_count, 3)
    lo, hi = np.array(frame.bounds[0]), np.array(frame.bounds[1])
    assert np.array_equal(positions.min(axis=0), lo.astype(np.float32))
    assert np.array_equal(positions.max(axis=0), hi.astype(np.float32))
    mesh = frame.meshes[0]
    assert np.shares_memory(mesh["positions"], frame.meshes[0]["positions"])


def test_animated_scene_moves():
    fire = gilab.load_scene("fire")
    assert fire.is_animated and fire.frame_count == 100
    a, b = fire.evaluate(0.0).merged()[0], fire.evaluate(1.0).merged()[0]
    assert a.shape == b.shape and not np.array_equal(a, b)


def test_bad_paths_raise_gilab_error_naming_them(tmp_path):
    with pytest.raises(gilab.Error, match="no_such_scene"):
        gilab.load_scene("no_such_scene")
    with pytest.raises(gilab.Error, match="missing.obj"):
        gilab.load_scene(tmp_path / "missing.obj")
    with pytest.raises(gilab.Error, match="not a directory"):
        gilab.load_scene("cornell", assets=tmp_path / "no_such_dir")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 9\n")
    with pytest.raises(gilab.Error, match="bad.obj"):
        gilab.load_scene(bad)
    with pytest.raises(gilab.Error, match="time"):
        gilab.load_scene("cornell").evaluate(float("nan"))
